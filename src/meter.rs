//! Measuring the meters and grids of a world ([`crate::world::measure`]): illuminance at a
//! point, luminance in a cone of directions, and calculation grids of illuminance meters (a
//! work plane). Each result carries its standard error; each meter runs its own sample budget,
//! or samples until a target relative error is reached.
//!
//! Every meter point has its own random stream, so results do not depend on the thread count.

use crate::film::{radiance_to_xyz, standard_error};
use crate::integrator::{irradiance, trace, PathStart, RayStart, RayStats};
use crate::sampling::{mix64, Sampler};
use crate::spectrum::SampledWavelengths;
use crate::world::{MeasureSettings, MeterKind, World};
use glam::Vec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// A measured value with its standard error, both in the meter's SI unit: lx for illuminance,
/// cd/m² for luminance.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Estimate {
    /// The estimate (lx or cd/m²).
    pub mean: f64,
    /// Its standard error (lx or cd/m²).
    pub stderr: f64,
    /// Samples taken.
    pub samples: u64,
    /// Samples whose value was not finite (NaN or infinite), counted as 0 in `mean`: a meter
    /// with any is not a measurement to trust, and the report and the summary say so.
    pub non_finite: u64,
}

impl Estimate {
    /// Half-width of the 95 % confidence interval (normal approximation), in the unit of `mean`.
    pub fn ci95(&self) -> f64 {
        1.959_963_984_540_054 * self.stderr
    }
    pub fn relative_error(&self) -> f64 {
        if self.mean != 0.0 {
            self.stderr / self.mean.abs()
        } else if self.stderr == 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    }
}

const BATCH: u64 = 1024;

/// One sample of a meter (lx or cd/m²); `None` if it was not finite.
fn sample_meter(
    world: &World,
    kind: &MeterKind,
    stream: u64,
    s: u64,
    stats: &mut RayStats,
) -> Option<f64> {
    let mut sampler = Sampler::new(world.settings.seed, stream, s);
    let mut wl = SampledWavelengths::sample_visible(sampler.get1d());
    let v = match kind {
        MeterKind::Illuminance { position, normal } => {
            let e = irradiance(
                world,
                &RayStart::free(*position),
                *normal,
                false,
                &mut wl,
                &mut sampler,
                stats,
            );
            radiance_to_xyz(&e, &wl)[1]
        }
        MeterKind::Luminance {
            position,
            direction,
            half_angle_rad,
        } => {
            let u = sampler.get2d();
            // Uniform in solid angle within the cone.
            let cos_max = half_angle_rad.cos();
            let cos_t = 1.0 - u.x * (1.0 - cos_max);
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            let phi = 2.0 * std::f32::consts::PI * u.y;
            let local = Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t);
            let dir = crate::bxdf::Frame::from_normal(*direction)
                .to_world(local)
                .normalize();
            stats.camera_rays += 1;
            let start = PathStart::camera(*position);
            let l = trace(world, *position, dir, start, &mut wl, &mut sampler, stats);
            radiance_to_xyz(&l, &wl)[1]
        }
    };
    if v.is_finite() {
        Some(v)
    } else {
        stats.non_finite += 1;
        None
    }
}

/// Measure one meter with its own stream.
pub fn measure(
    world: &World,
    kind: &MeterKind,
    stream: u64,
    settings: &MeasureSettings,
    stats: &mut RayStats,
) -> Estimate {
    measure_until(
        world,
        kind,
        stream,
        settings,
        stats,
        &AtomicBool::new(false),
    )
    .expect("never stopped")
}

/// [`measure`], giving up (`None`) once `stop` is set; it is polled every `BATCH` samples.
fn measure_until(
    world: &World,
    kind: &MeterKind,
    stream: u64,
    settings: &MeasureSettings,
    stats: &mut RayStats,
    stop: &AtomicBool,
) -> Option<Estimate> {
    accumulate(settings, stop, |s| {
        sample_meter(world, kind, stream, s, stats)
    })
}

/// The estimate from `sample(0)`, `sample(1)`, … within `settings`' budget, giving up (`None`)
/// once `stop` is set (polled every `BATCH` samples). A sample that is `None` (not finite)
/// counts as 0 and in [`Estimate::non_finite`].
fn accumulate(
    settings: &MeasureSettings,
    stop: &AtomicBool,
    mut sample: impl FnMut(u64) -> Option<f64>,
) -> Option<Estimate> {
    let (mut sum, mut sum2, mut n, mut non_finite) = (0.0f64, 0.0f64, 0u64, 0u64);
    let min = settings.samples.max(2);
    let max = settings.max_samples.max(min);
    loop {
        let target = match settings.target_relative_error {
            None => min,
            Some(_) if n < min => min,
            Some(_) => (n + BATCH).min(max),
        };
        while n < target {
            if n % BATCH == 0 && stop.load(Ordering::Relaxed) {
                return None;
            }
            let v = sample(n).unwrap_or_else(|| {
                non_finite += 1;
                0.0
            });
            sum += v;
            sum2 += v * v;
            n += 1;
        }
        let est = Estimate {
            mean: sum / n as f64,
            stderr: standard_error(sum, sum2, n),
            samples: n,
            non_finite,
        };
        match settings.target_relative_error {
            Some(t) if n < max && est.relative_error() > t => continue,
            _ => return Some(est),
        }
    }
}

/// Results of all meters and grids of a world.
#[derive(Clone, Debug, Default)]
pub struct Measurements {
    pub meters: Vec<Estimate>,
    /// Per grid, row-major (j·nx + i).
    pub grids: Vec<Vec<Estimate>>,
    pub stats: RayStats,
}

/// Measure every meter and grid point in parallel (each with its own stream).
pub fn measure_all(world: &World) -> Measurements {
    measure_all_until(world, &AtomicBool::new(false)).expect("never stopped")
}

/// [`measure_all`], giving up (`None`) soon after `stop` is set (e.g. by Ctrl-C).
pub fn measure_all_until(world: &World, stop: &AtomicBool) -> Option<Measurements> {
    let mut jobs: Vec<(MeterKind, u64)> = Vec::new();
    for (k, m) in world.meters.iter().enumerate() {
        jobs.push((m.kind.clone(), mix64(0x6d65_7465_7200 ^ k as u64)));
    }
    for (g, grid) in world.grids.iter().enumerate() {
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                jobs.push((
                    MeterKind::Illuminance {
                        position: grid.point(i, j),
                        normal: grid.normal,
                    },
                    mix64(((g as u64) << 40) ^ ((j as u64) << 20) ^ i as u64 ^ 0x6772_6964),
                ));
            }
        }
    }
    let results: Vec<(Estimate, RayStats)> = jobs
        .par_iter()
        .map(|(kind, stream)| {
            let mut stats = RayStats::default();
            let e = measure_until(world, kind, *stream, &world.measure, &mut stats, stop)?;
            Some((e, stats))
        })
        .collect::<Option<_>>()?;
    let mut out = Measurements::default();
    let mut it = results.into_iter();
    for _ in &world.meters {
        let (e, s) = it.next().expect("one result per job");
        out.stats.merge(&s);
        out.meters.push(e);
    }
    for grid in &world.grids {
        let mut v = Vec::with_capacity((grid.nx * grid.ny) as usize);
        for _ in 0..grid.nx * grid.ny {
            let (e, s) = it.next().expect("one result per job");
            out.stats.merge(&s);
            v.push(e);
        }
        out.grids.push(v);
    }
    Some(out)
}

/// Samples of a grid's points that were not finite (see [`Estimate::non_finite`]).
pub fn grid_non_finite(values: &[Estimate]) -> u64 {
    values.iter().map(|e| e.non_finite).sum()
}

/// Statistics of a grid, in the units of the values they were computed from.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct GridStats {
    /// Smallest value (Emin).
    pub min: f64,
    /// Arithmetic mean over the points (Eavg).
    pub avg: f64,
    /// Largest value (Emax).
    pub max: f64,
    /// Uniformity U₀ = Emin / Eavg (`None` if Eavg = 0).
    pub u0: Option<f64>,
    /// Emin / Emax (`None` if Emax = 0).
    pub min_over_max: Option<f64>,
    /// Largest standard error of a point (`None` if no errors are given).
    pub max_stderr: Option<f64>,
}

impl GridStats {
    /// Statistics of `values` (with optional per-point standard errors); `None` if empty.
    pub fn of(values: &[f64], stderr: &[f64]) -> Option<GridStats> {
        if values.is_empty() {
            return None;
        }
        let min = values.iter().copied().fold(f64::INFINITY, f64::min);
        let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let avg = values.iter().sum::<f64>() / values.len() as f64;
        let ratio = |a: f64, b: f64| (b != 0.0).then(|| a / b);
        Some(GridStats {
            min,
            avg,
            max,
            u0: ratio(min, avg),
            min_over_max: ratio(min, max),
            max_stderr: (!stderr.is_empty()).then(|| stderr.iter().copied().fold(0.0f64, f64::max)),
        })
    }
}

/// E_min, E_avg, E_max, U0 = E_min/E_avg and E_min/E_max of a grid's estimates (all zero for
/// an empty grid, which scene validation never builds).
pub fn grid_stats(values: &[Estimate]) -> GridStats {
    let means: Vec<f64> = values.iter().map(|e| e.mean).collect();
    let errors: Vec<f64> = values.iter().map(|e| e.stderr).collect();
    GridStats::of(&means, &errors).unwrap_or(GridStats {
        min: 0.0,
        avg: 0.0,
        max: 0.0,
        u0: None,
        min_over_max: None,
        max_stderr: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_that_are_not_finite_are_counted_per_meter() {
        let settings = MeasureSettings {
            samples: 1000,
            target_relative_error: None,
            max_samples: 1000,
        };
        let stop = AtomicBool::new(false);
        // Every third sample is lost: the mean counts it as 0, and the estimate says how many.
        let e = accumulate(&settings, &stop, |s| (s % 3 != 0).then_some(3.0)).unwrap();
        assert_eq!((e.samples, e.non_finite), (1000, 334));
        assert!((e.mean - 3.0 * 666.0 / 1000.0).abs() < 1e-12);
        let clean = accumulate(&settings, &stop, |_| Some(1.0)).unwrap();
        assert_eq!(clean.non_finite, 0);
        let est = [e, clean, e];
        assert_eq!(grid_non_finite(&est), 668);
    }
}
