//! The sun's part of an annual calculation, hour by hour: for each receiver and each hour with
//! the sun up, the illuminance (lx) a sun of 1 lx direct-normal illuminance at that hour's own
//! position gives it, in total (through openings and inter-reflections) and directly (the
//! disk seen from the receiver through the panes, as LM-83's annual sunlight exposure counts
//! it). Tracing each hour's own sun, rather than a few hundred fixed sun positions, keeps
//! shadow edges where they are: no interpolation between positions, no bias.
//!
//! Both come in [`BATCHES`] independent batches, as the sky coefficients do, so an hour's
//! illuminance carries a standard error and replicate years can be drawn.

use crate::annual::coefficients::CoefficientError;
use crate::film::radiance_to_xyz;
use crate::integrator::path::{irradiance, RayStart};
use crate::integrator::stats::RayStats;
use crate::integrator::transmit::transmittance;
use crate::light::Light;
use crate::meter::BATCHES;
use crate::sampling::sobol::batch_stream;
use crate::sampling::Sampler;
use crate::spectrum::SampledWavelengths;
use crate::world::World;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// Sun illuminances per unit direct-normal illuminance (lx per lx), for `hours` sun
/// positions × `receivers`, each as [`BATCHES`] batch means: `total[(h * receivers + r) *
/// BATCHES + b]`, and the same for `direct`.
#[derive(Clone, Debug, Default)]
pub struct SunCoefficients {
    pub hours: usize,
    pub receivers: usize,
    pub total: Vec<f64>,
    pub direct: Vec<f64>,
    /// Paths per receiver and hour for `total`, shadow rays for `direct`.
    pub samples: u64,
    pub direct_samples: u64,
}

impl SunCoefficients {
    /// Batch means of hour `h` at receiver `r`: (total, direct).
    pub fn batches(&self, h: usize, r: usize) -> (&[f64], &[f64]) {
        let k = BATCHES as usize;
        let i = (h * self.receivers + r) * k;
        (&self.total[i..i + k], &self.direct[i..i + k])
    }
}

/// Bytes [`sun_coefficients`] holds for `hours` × `receivers`.
pub fn sun_coefficient_bytes(hours: usize, receivers: usize) -> u64 {
    2 * hours as u64 * receivers as u64 * BATCHES as u64 * 8
}

/// The sun coefficients of `receivers` ((point, unit normal), scene frame) for the sun toward
/// each of `to_sun` (unit scene directions), from `samples` paths and `direct_samples` shadow
/// rays per receiver and hour (each rounded up to a multiple of [`BATCHES`]). `world` must be
/// lit by one [`Light::Sun`] of 1 lx direct-normal illuminance alone; its direction is set to
/// each hour's in turn. `progress` is called with the number of hours done.
pub fn sun_coefficients(
    world: &mut World,
    receivers: &[(Vec3, Vec3)],
    to_sun: &[Vec3],
    samples: u64,
    direct_samples: u64,
    progress: &mut dyn FnMut(usize),
) -> Result<SunCoefficients, CoefficientError> {
    match world.lights.as_slice() {
        [Light::Sun(s)] if (s.normal_illuminance_lx - 1.0).abs() < 1e-12 => {}
        lights => {
            return Err(CoefficientError::Lights(format!(
                "{} light(s); sun coefficients need one sun of 1 lx",
                lights.len()
            )))
        }
    }
    let k = BATCHES as usize;
    let per_batch = samples.div_ceil(BATCHES as u64).max(1);
    let direct_per_batch = direct_samples.div_ceil(BATCHES as u64).max(1);
    let r_n = receivers.len();
    let mut out = SunCoefficients {
        hours: to_sun.len(),
        receivers: r_n,
        total: vec![0.0; to_sun.len() * r_n * k],
        direct: vec![0.0; to_sun.len() * r_n * k],
        samples: per_batch * BATCHES as u64,
        direct_samples: direct_per_batch * BATCHES as u64,
    };
    for (h, &dir) in to_sun.iter().enumerate() {
        if let Light::Sun(s) = &mut world.lights[0] {
            s.to_sun = dir.normalize();
        }
        let world = &*world;
        let rows: Vec<(Vec<f64>, Vec<f64>)> = receivers
            .par_iter()
            .enumerate()
            .map(|(r, &(p, normal))| {
                let stream = ((h as u64 + 1) << 32) | r as u64;
                let mut stats = RayStats::default();
                let mut total = vec![0.0; k];
                let mut direct = vec![0.0; k];
                for b in 0..BATCHES {
                    let bs = batch_stream(stream, b);
                    let mut sum = 0.0;
                    for s in 0..per_batch {
                        let mut sampler = Sampler::new(world.settings.seed, bs, s);
                        let mut wl = SampledWavelengths::sample_visible(sampler.get1d());
                        let e = irradiance(
                            world,
                            &RayStart::free(p),
                            normal,
                            false,
                            &mut wl,
                            &mut sampler,
                            &mut stats,
                        );
                        let y = radiance_to_xyz(&e, &wl)[1];
                        if y.is_finite() {
                            sum += y;
                        }
                    }
                    total[b as usize] = sum / per_batch as f64;
                    let mut sum = 0.0;
                    for s in 0..direct_per_batch {
                        // A stream of its own, after the paths' indices.
                        let mut sampler = Sampler::new(world.settings.seed, bs, per_batch + s);
                        sum += direct_sun(world, p, normal, &mut sampler);
                    }
                    direct[b as usize] = sum / direct_per_batch as f64;
                }
                (total, direct)
            })
            .collect();
        for (r, (t, d)) in rows.into_iter().enumerate() {
            let i = (h * r_n + r) * k;
            out.total[i..i + k].copy_from_slice(&t);
            out.direct[i..i + k].copy_from_slice(&d);
        }
        progress(h + 1);
    }
    Ok(out)
}

/// One sample of the sun's direct illuminance (lx) at `p` facing `normal`: a direction drawn
/// over the disk, its cosine, and the transmittance of the panes on the way.
fn direct_sun(world: &World, p: Vec3, normal: Vec3, sampler: &mut Sampler) -> f64 {
    let Light::Sun(sun) = &world.lights[0] else {
        return 0.0;
    };
    let wl = SampledWavelengths::sample_visible(sampler.get1d());
    let u = sampler.get2d();
    let Some(ls) = sun.sample_li(Vec2::new(u.x, u.y), &wl) else {
        return 0.0;
    };
    let cos = ls.wi.dot(normal);
    if cos <= 0.0 || ls.pdf <= 0.0 {
        return 0.0;
    }
    let Some(tr) = transmittance(world, p, ls.wi, f32::INFINITY, &wl) else {
        return 0.0;
    };
    let y = radiance_to_xyz(&(tr * ls.li * (cos / ls.pdf)), &wl)[1];
    if y.is_finite() {
        y
    } else {
        0.0
    }
}
