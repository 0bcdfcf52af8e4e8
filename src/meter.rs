//! Measuring the meters and grids of a world ([`crate::world::measure`]): illuminance at a
//! point, luminance in a cone of directions, and calculation grids of illuminance meters (a
//! work plane). Each result carries its standard error, from the spread of [`BATCHES`]
//! independently scrambled batches (randomised quasi-Monte Carlo, docs/uncertainty.md); each
//! meter runs its own sample budget, or samples until a target relative error is reached.
//!
//! Every meter point has its own random streams, so results do not depend on the thread count.

use crate::film::radiance_to_xyz;
use crate::integrator::{irradiance, trace, PathStart, RayStart, RayStats};
use crate::sampling::{batch_stream, mix64, Sampler};
use crate::spectrum::SampledWavelengths;
use crate::world::{MeasureSettings, MeterKind, World};
use glam::Vec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// Independent randomisations per meter and grid point: each takes its samples in this many
/// batches, each batch a prefix of its own independently scrambled Sobol sequence, and its
/// standard error is the spread of the batch means (randomised quasi-Monte Carlo). Sixteen
/// batches give the standard error to about ±18 % (1/√(2·15)) and a 95 % interval only 9 %
/// wider than a normal one (t₁₅ = 2.131), while leaving each batch enough points to keep most
/// of what stratification gains (docs/uncertainty.md).
pub const BATCHES: u32 = 16;

/// A measured value with its standard error, both in the meter's SI unit: lx for illuminance,
/// cd/m² for luminance.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Estimate {
    /// The estimate (lx or cd/m²): the mean of the batch means.
    pub mean: f64,
    /// Its standard error (lx or cd/m²): the standard deviation of the batch means over
    /// √`batches`.
    pub stderr: f64,
    /// Samples taken, over all batches.
    pub samples: u64,
    /// Samples whose value was not finite (NaN or infinite), counted as 0 in `mean`: a meter
    /// with any is not a measurement to trust, and the report and the summary say so.
    pub non_finite: u64,
    /// Independent batches behind `stderr`; its 95 % interval uses Student's t with
    /// `batches − 1` degrees of freedom (none, an unknown interval, below 2 batches).
    pub batches: u32,
}

impl Estimate {
    /// Degrees of freedom of `stderr`.
    pub fn dof(&self) -> u32 {
        self.batches.saturating_sub(1)
    }

    /// Half-width of the 95 % confidence interval (Student's t with [`Estimate::dof`] degrees
    /// of freedom), in the unit of `mean`; infinite when the spread is unknown (fewer than 2
    /// batches) unless nothing varied at all.
    pub fn ci95(&self) -> f64 {
        if self.stderr == 0.0 {
            0.0
        } else {
            t95(self.dof()) * self.stderr
        }
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

pub use crate::sampling::student::t95;

/// Stop is polled every this many samples.
const POLL: u64 = 1024;

/// One sample of a meter (lx or cd/m²): sample `s` of batch `batch`; `None` if it was not
/// finite.
fn sample_meter(
    world: &World,
    kind: &MeterKind,
    stream: u64,
    batch: u32,
    s: u64,
    stats: &mut RayStats,
) -> Option<f64> {
    let mut sampler = Sampler::new(world.settings.seed, batch_stream(stream, batch), s);
    let mut wl = SampledWavelengths::sample_visible(sampler.get1d());
    let v = match kind {
        MeterKind::Illuminance { position, normal }
        | MeterKind::Melanopic {
            position,
            direction: normal,
        }
        | MeterKind::Ugr {
            position,
            direction: normal,
            ..
        } => {
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

/// [`measure`], giving up (`None`) once `stop` is set; it is polled every `POLL` samples.
fn measure_until(
    world: &World,
    kind: &MeterKind,
    stream: u64,
    settings: &MeasureSettings,
    stats: &mut RayStats,
    stop: &AtomicBool,
) -> Option<Estimate> {
    accumulate(settings, stop, |batch, s| {
        sample_meter(world, kind, stream, batch, s, stats)
    })
}

/// Samples per batch for a budget of `samples` per meter: a power of two (a Sobol sequence is
/// balanced at powers of two), at least 1, whose [`BATCHES`] batches hold at least `samples`.
pub fn batch_size(samples: u64) -> u64 {
    samples.div_ceil(BATCHES as u64).max(1).next_power_of_two()
}

/// The estimate from [`BATCHES`] batches, batch b made of `sample(b, 0)`, `sample(b, 1)`, …,
/// within `settings`' budget: [`batch_size`] samples each, doubled in every batch until the
/// relative standard error meets `settings.target_relative_error` or another doubling would
/// pass `settings.max_samples`. Gives up (`None`) once `stop` is set (polled every `POLL`
/// samples). A sample that is `None` (not finite) counts as 0 and in [`Estimate::non_finite`].
fn accumulate(
    settings: &MeasureSettings,
    stop: &AtomicBool,
    mut sample: impl FnMut(u32, u64) -> Option<f64>,
) -> Option<Estimate> {
    let k = BATCHES as usize;
    let mut per = batch_size(settings.samples);
    let (mut sums, mut n, mut non_finite, mut taken) = (vec![0.0f64; k], 0u64, 0u64, 0u64);
    loop {
        for (b, sum) in sums.iter_mut().enumerate() {
            for s in n..per {
                if taken % POLL == 0 && stop.load(Ordering::Relaxed) {
                    return None;
                }
                taken += 1;
                *sum += sample(b as u32, s).unwrap_or_else(|| {
                    non_finite += 1;
                    0.0
                });
            }
        }
        n = per;
        let est = from_batches(&sums, n, non_finite);
        match settings.target_relative_error {
            Some(t) if 2 * per * k as u64 <= settings.max_samples && est.relative_error() > t => {
                per *= 2
            }
            _ => return Some(est),
        }
    }
}

/// The estimate from the sums of `n` samples in each batch: the mean of the batch means and
/// their standard deviation over √(number of batches).
fn from_batches(sums: &[f64], n: u64, non_finite: u64) -> Estimate {
    let k = sums.len() as f64;
    let means: Vec<f64> = sums.iter().map(|s| s / n as f64).collect();
    let mean = means.iter().sum::<f64>() / k;
    let var = means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (k - 1.0);
    Estimate {
        mean,
        stderr: (var / k).sqrt(),
        samples: n * sums.len() as u64,
        non_finite,
        batches: sums.len() as u32,
    }
}

/// The batch sums behind one meter's or grid point's estimate, as a shard of a render stores
/// them so that `candela merge` can add the shards' samples: batch b of every shard continues
/// the same scrambled sequence (shard I takes samples I·P … (I+1)·P − 1 of it, P =
/// `per_batch`), so the merged batches stay independent of each other.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MeterSums {
    /// The meter's name, or the grid's name for a grid point.
    pub name: String,
    /// A grid point's (i, j, nx, ny); None for a meter.
    pub grid: Option<[u32; 4]>,
    /// Whether the meter measures luminance (cd/m²); else illuminance (lx).
    pub luminance: bool,
    /// Σ of each batch's samples (lx or cd/m²).
    pub sums: [f64; BATCHES as usize],
    /// Samples in each batch.
    pub per_batch: u64,
    /// Samples that were not finite (counted as 0).
    pub non_finite: u64,
}

impl MeterSums {
    /// The estimate from these sums (zero without samples).
    pub fn estimate(&self) -> Estimate {
        if self.per_batch == 0 {
            return Estimate::default();
        }
        from_batches(&self.sums, self.per_batch, self.non_finite)
    }
    /// Add the sums of the next shard of the same meter.
    pub fn merge(&mut self, o: &MeterSums) {
        for (a, b) in self.sums.iter_mut().zip(&o.sums) {
            *a += b;
        }
        self.per_batch += o.per_batch;
        self.non_finite += o.non_finite;
    }
}

/// Samples per batch of one shard of `count` for a meter budget of `samples`: the batch size of
/// the whole budget ([`batch_size`]) shared out, rounded up; a target relative error is not
/// pursued (each shard would stop on its own share's error).
pub fn shard_batch_size(samples: u64, count: u32) -> u64 {
    batch_size(samples).div_ceil(count as u64)
}

/// Measure shard `index` of `count` of every meter and grid point: samples
/// index·P … (index+1)·P − 1 of each batch ([`shard_batch_size`]), with their batch sums.
pub fn measure_shard_until(
    world: &World,
    index: u32,
    count: u32,
    stop: &AtomicBool,
) -> Option<(Measurements, Vec<MeterSums>)> {
    let per = shard_batch_size(world.measure.samples, count);
    let first = index as u64 * per;
    let mut labels = Vec::new();
    for m in &world.meters {
        let luminance = matches!(m.kind, MeterKind::Luminance { .. });
        labels.push((m.name.clone(), None, luminance));
    }
    for grid in &world.grids {
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                labels.push((grid.name.clone(), Some([i, j, grid.nx, grid.ny]), false));
            }
        }
    }
    let results: Vec<(([f64; BATCHES as usize], u64), RayStats)> = jobs(world)
        .par_iter()
        .map(|(kind, stream)| {
            let mut stats = RayStats::default();
            let r = sum_range(first, per, stop, |batch, s| {
                sample_meter(world, kind, *stream, batch, s, &mut stats)
            })?;
            Some((r, stats))
        })
        .collect::<Option<_>>()?;
    let mut sums = Vec::with_capacity(results.len());
    let mut estimates = Vec::with_capacity(results.len());
    for (((batch_sums, non_finite), stats), (name, grid, luminance)) in
        results.into_iter().zip(labels)
    {
        let m = MeterSums {
            name,
            grid,
            luminance,
            sums: batch_sums,
            per_batch: per,
            non_finite,
        };
        estimates.push((m.estimate(), stats));
        sums.push(m);
    }
    Some((collect(world, estimates), sums))
}

/// The batch sums of samples `first .. first + per` of every batch, and how many were not
/// finite; `None` once `stop` is set.
fn sum_range(
    first: u64,
    per: u64,
    stop: &AtomicBool,
    mut sample: impl FnMut(u32, u64) -> Option<f64>,
) -> Option<([f64; BATCHES as usize], u64)> {
    let (mut sums, mut non_finite) = ([0.0f64; BATCHES as usize], 0u64);
    let mut taken = 0u64;
    for (b, sum) in sums.iter_mut().enumerate() {
        for s in first..first + per {
            if taken % POLL == 0 && stop.load(Ordering::Relaxed) {
                return None;
            }
            taken += 1;
            *sum += sample(b as u32, s).unwrap_or_else(|| {
                non_finite += 1;
                0.0
            });
        }
    }
    Some((sums, non_finite))
}

/// Rebuild a world's [`Measurements`] from one estimate per meter and grid point, in the
/// order of [`jobs`].
pub fn collect(world: &World, results: Vec<(Estimate, RayStats)>) -> Measurements {
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
    out
}

/// Every meter and grid point with its stream: the meters, then each grid's points row by row.
fn jobs(world: &World) -> Vec<(MeterKind, u64)> {
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
    jobs
}

/// Results of all meters and grids of a world.
#[derive(Clone, Debug, Default)]
pub struct Measurements {
    pub meters: Vec<Estimate>,
    /// Per meter, the melanopic quantities of a `Melanopic` meter (None for other kinds; empty
    /// for a shard, whose merge reports E_v only).
    pub melanopic: Vec<Option<MelanopicEstimate>>,
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
    let results: Vec<(Estimate, RayStats)> = jobs(world)
        .par_iter()
        .map(|(kind, stream)| {
            let mut stats = RayStats::default();
            let e = measure_until(world, kind, *stream, &world.measure, &mut stats, stop)?;
            Some((e, stats))
        })
        .collect::<Option<_>>()?;
    let mut out = collect(world, results);
    for (k, m) in world.meters.iter().enumerate() {
        let v = match m.kind {
            MeterKind::Melanopic {
                position,
                direction,
            } => {
                let stream = mix64(0x6d65_7465_7200 ^ k as u64);
                Some(measure_melanopic(
                    world,
                    position,
                    direction,
                    stream,
                    &world.measure,
                    stop,
                )?)
            }
            _ => None,
        };
        out.melanopic.push(v);
    }
    Some(out)
}

/// A `Melanopic` meter's result: vertical illuminance and melanopic EDI at the eye, both in lx
/// from the same samples, and their ratio (the melanopic DER of the light reaching the eye).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MelanopicEstimate {
    pub illuminance_lx: Estimate,
    pub m_edi_lx: Estimate,
    /// m-EDI / E_v (dimensionless) and its standard error from the batches (the ratio
    /// estimator's √(Σᵦ (mᵦ − R eᵦ)² / (K(K−1))) / ē over the batch means mᵦ, eᵦ).
    pub ratio: f64,
    pub ratio_stderr: f64,
}

/// Measure a `Melanopic` meter: E_v and m-EDI on the receiver at `position` facing
/// `direction`, from [`BATCHES`] batches of [`batch_size`]`(settings.samples)` samples each of
/// the meter's stream (the budget without a target's doubling). None once `stop` is set.
pub fn measure_melanopic(
    world: &World,
    position: Vec3,
    direction: Vec3,
    stream: u64,
    settings: &MeasureSettings,
    stop: &AtomicBool,
) -> Option<MelanopicEstimate> {
    let per = batch_size(settings.samples);
    let k = BATCHES as usize;
    let (mut ev, mut mel, mut non_finite) = (vec![0.0f64; k], vec![0.0f64; k], 0u64);
    let mut stats = RayStats::default();
    for b in 0..k {
        for s in 0..per {
            if s % POLL == 0 && stop.load(Ordering::Relaxed) {
                return None;
            }
            let mut sampler = Sampler::new(world.settings.seed, batch_stream(stream, b as u32), s);
            let mut wl = SampledWavelengths::sample_visible(sampler.get1d());
            let at = RayStart::free(position);
            let e = irradiance(
                world,
                &at,
                direction,
                false,
                &mut wl,
                &mut sampler,
                &mut stats,
            );
            let (v, m) = (
                radiance_to_xyz(&e, &wl)[1],
                crate::film::health_melanopic_edi(&e, &wl),
            );
            if v.is_finite() && m.is_finite() {
                ev[b] += v;
                mel[b] += m;
            } else {
                non_finite += 1;
            }
        }
    }
    let (e, m) = (
        from_batches(&ev, per, non_finite),
        from_batches(&mel, per, non_finite),
    );
    let ratio = if e.mean > 0.0 { m.mean / e.mean } else { 0.0 };
    let ss: f64 = ev
        .iter()
        .zip(&mel)
        .map(|(e, m)| ((m - ratio * e) / per as f64).powi(2))
        .sum();
    let ratio_stderr = if e.mean > 0.0 {
        (ss / (k * (k - 1)) as f64).sqrt() / e.mean
    } else {
        0.0
    };
    Some(MelanopicEstimate {
        illuminance_lx: e,
        m_edi_lx: m,
        ratio,
        ratio_stderr,
    })
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

    fn budget(samples: u64, target: Option<f64>, max_samples: u64) -> MeasureSettings {
        MeasureSettings {
            samples,
            target_relative_error: target,
            max_samples,
        }
    }

    #[test]
    fn samples_that_are_not_finite_are_counted_per_meter() {
        let stop = AtomicBool::new(false);
        // 1000 samples → 16 batches of 64. Every third sample of a batch is lost: the mean
        // counts it as 0 (22 of 64), and the estimate says how many.
        let settings = budget(1000, None, 1000);
        let e = accumulate(&settings, &stop, |_, s| (s % 3 != 0).then_some(3.0)).unwrap();
        assert_eq!((e.samples, e.non_finite, e.batches), (1024, 16 * 22, 16));
        assert!((e.mean - 3.0 * 42.0 / 64.0).abs() < 1e-12);
        let clean = accumulate(&settings, &stop, |_, _| Some(1.0)).unwrap();
        assert_eq!(clean.non_finite, 0);
        let est = [e, clean, e];
        assert_eq!(grid_non_finite(&est), 704);
    }

    #[test]
    fn the_standard_error_is_the_spread_of_the_batch_means() {
        // Batch b's samples all equal b: batch means 0 … 15, whose mean is 7.5 and whose
        // standard deviation is √(Σ(b − 7.5)²/15) = √(340/15).
        let stop = AtomicBool::new(false);
        let e = accumulate(&budget(64, None, 64), &stop, |b, _| Some(b as f64)).unwrap();
        assert_eq!((e.samples, e.batches, e.dof()), (64, 16, 15));
        assert!((e.mean - 7.5).abs() < 1e-12);
        assert!((e.stderr - (340.0f64 / 15.0 / 16.0).sqrt()).abs() < 1e-12);
        assert!((e.ci95() - 2.131_449_545_6 * e.stderr).abs() < 1e-9);
        // Samples that differ only within a batch leave no spread between batch means: a
        // stratified estimator's error, which the sample variance would overstate.
        let e = accumulate(&budget(64, None, 64), &stop, |_, s| Some((s % 4) as f64)).unwrap();
        assert_eq!((e.mean, e.stderr, e.ci95()), (1.5, 0.0, 0.0));
    }

    #[test]
    fn batches_are_powers_of_two_holding_the_budget() {
        for (samples, per) in [
            (1, 1),
            (16, 1),
            (17, 2),
            (1000, 64),
            (4096, 256),
            (5000, 512),
        ] {
            assert_eq!(batch_size(samples), per, "{samples}");
        }
    }

    #[test]
    fn target_error_doubles_every_batch_until_met() {
        // iid noise of sd 1/√12 around 1: the relative standard error after N samples is
        // about 0.289/√N, so a 0.2 % target needs about 21 000 samples; 2048 (0.64 %) cannot
        // meet it, even with the estimate's ±18 % spread.
        let stop = AtomicBool::new(false);
        let noise = |b: u32, s: u64| {
            let u = (mix64(((b as u64) << 40) ^ s) >> 11) as f64 / (1u64 << 53) as f64;
            Some(0.5 + u)
        };
        let e = accumulate(&budget(1024, Some(0.002), 1 << 22), &stop, noise).unwrap();
        assert!(e.relative_error() <= 0.002, "{e:?}");
        assert!(e.samples.is_power_of_two() && e.samples > 2048, "{e:?}");
        assert!(e.samples <= 65_536, "{e:?}");
        // The previous size missed the target (else it would have stopped there).
        let half = accumulate(&budget(e.samples / 2, None, 1 << 22), &stop, noise).unwrap();
        assert!(half.relative_error() > 0.002, "{half:?}");
        // max_samples bounds the doubling: 16 × 256 = 4096 ≤ 5000 < 8192.
        let capped = accumulate(&budget(1024, Some(0.002), 5000), &stop, noise).unwrap();
        assert_eq!(capped.samples, 4096);
        // A target already met stops at the first round.
        let easy = accumulate(&budget(1024, Some(0.5), 1 << 22), &stop, noise).unwrap();
        assert_eq!(easy.samples, 1024);
    }

    #[test]
    fn student_t_quantiles() {
        // t₀.₉₇₅ (e.g. Abramowitz & Stegun table 26.10; NIST handbook 1.3.6.7.2).
        for (dof, t) in [
            (1, 12.706_204_736),
            (2, 4.302_652_730),
            (5, 2.570_581_836),
            (15, 2.131_449_546),
            (30, 2.042_272_456),
            (31, 2.039_513_446),
            (40, 2.021_075_390),
            (60, 2.000_297_822),
            (120, 1.979_930_405),
        ] {
            assert!(
                (t95(dof) - t).abs() < 1e-7,
                "dof {dof}: {} vs {t}",
                t95(dof)
            );
        }
        assert!((t95(1 << 30) - 1.959_963_985).abs() < 1e-8);
        assert_eq!(t95(0), f64::INFINITY);
        for dof in 1..200 {
            assert!(
                t95(dof + 1) < t95(dof),
                "t must fall with the degrees of freedom"
            );
        }
        let unknown = Estimate {
            mean: 1.0,
            stderr: 0.1,
            samples: 1,
            non_finite: 0,
            batches: 1,
        };
        assert_eq!(unknown.ci95(), f64::INFINITY);
    }
}
