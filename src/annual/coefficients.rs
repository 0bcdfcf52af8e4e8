//! Daylight coefficients: for each receiver (a point and its normal), the illuminance (lx)
//! each sky patch gives it when that patch glows at 1 cd/m², through the scene's openings and
//! inter-reflections, with a standard error per coefficient. An hour's illuminance is then
//! Σᵢ Cᵢ L̄ᵢ over the patches' mean luminances L̄ᵢ of that hour's sky ([`SkyVector`]).
//!
//! One rendering pass gives every patch's coefficient: the world is lit by a sky of 1 cd/m²
//! in every direction (sky and ground), and each path's light is credited to the patch it
//! arrives from. The coefficients hold for the sky spectrum of that unit sky; an hour's sky of
//! another colour changes them only where surfaces are coloured.
//!
//! [`SkyVector`]: crate::daylight::patches::SkyVector

use crate::daylight::patches::SkyPatches;
use crate::film::radiance_to_xyz;
use crate::integrator::path::{irradiance_tallied, RayStart};
use crate::integrator::stats::RayStats;
use crate::light::Light;
use crate::meter::BATCHES;
use crate::sampling::sobol::batch_stream;
use crate::sampling::Sampler;
use crate::spectrum::SampledWavelengths;
use crate::world::World;
use glam::Vec3;
use rayon::prelude::*;

/// Coefficients of `receivers` × patches, lx per cd/m², as the means of [`BATCHES`]
/// independent batches (their estimate is the batches' mean), so that any sky's illuminance gets the
/// standard error of its own linear combination (the patches' errors are correlated: one path
/// credits several patches).
#[derive(Clone, Debug)]
pub struct Coefficients {
    pub patches: SkyPatches,
    pub receivers: usize,
    /// `batches[(r * BATCHES + b) * patches + i]`.
    pub batches: Vec<f64>,
    /// Samples per receiver.
    pub samples: u64,
}

impl Coefficients {
    /// Illuminance (lx) and its standard error at receiver `r` under a sky vector's patch
    /// luminances (cd/m²).
    pub fn illuminance(&self, r: usize, luminance_cd_m2: &[f64]) -> (f64, f64) {
        let n = self.patches.len();
        let k = BATCHES as usize;
        let dot =
            |row: &[f64]| -> f64 { row.iter().zip(luminance_cd_m2).map(|(c, l)| c * l).sum() };
        let e: Vec<f64> = (0..k)
            .map(|b| dot(&self.batches[(r * k + b) * n..(r * k + b + 1) * n]))
            .collect();
        let mu = e.iter().sum::<f64>() / k as f64;
        let var = e.iter().map(|x| (x - mu) * (x - mu)).sum::<f64>() / (k - 1) as f64;
        (mu, (var / k as f64).sqrt())
    }

    /// Coefficient `i` of receiver `r` (lx per cd/m²): the mean of its batches.
    pub fn mean(&self, r: usize, i: usize) -> f64 {
        let n = self.patches.len();
        let k = BATCHES as usize;
        (0..k)
            .map(|b| self.batches[(r * k + b) * n + i])
            .sum::<f64>()
            / k as f64
    }

    /// The standard error of coefficient `i` of receiver `r` (lx per cd/m²).
    pub fn stderr(&self, r: usize, i: usize) -> f64 {
        let n = self.patches.len();
        let k = BATCHES as usize;
        let mu = self.mean(r, i);
        let var = (0..k)
            .map(|b| (self.batches[(r * k + b) * n + i] - mu).powi(2))
            .sum::<f64>()
            / (k - 1) as f64;
        (var / k as f64).sqrt()
    }
}

/// Why coefficients cannot be computed for a world.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CoefficientError {
    #[error("daylight coefficients need a world lit by one sky and nothing else, found {0}")]
    Lights(String),
    #[error("the sky of a daylight-coefficient world must have a luminance of 1 cd/m² in every direction (a Uniform sky of ZenithLuminance(1.0) over a ground of reflectance 1.0)")]
    NotUnit,
}

/// The coefficients of `receivers` ((point, unit normal), scene frame) over `patches`, from
/// `samples` paths per receiver (rounded up to a multiple of the meters' batches, whose spread
/// gives the standard errors). `world` must be lit by a unit sky alone (see
/// [`CoefficientError::NotUnit`]).
pub fn sky_coefficients(
    world: &World,
    receivers: &[(Vec3, Vec3)],
    patches: &SkyPatches,
    samples: u64,
) -> Result<Coefficients, CoefficientError> {
    let sky = match world.lights.as_slice() {
        [Light::Sky(s)] => s,
        lights => {
            return Err(CoefficientError::Lights(format!(
                "{} light(s) of which {} are skies",
                lights.len(),
                lights.iter().filter(|l| matches!(l, Light::Sky(_))).count()
            )))
        }
    };
    if !sky.is_unit() {
        return Err(CoefficientError::NotUnit);
    }
    let frame = sky.frame;
    let n = patches.len();
    let per_batch = samples.div_ceil(BATCHES as u64).max(1);
    let rows: Vec<Vec<f64>> = receivers
        .par_iter()
        .enumerate()
        .map(|(r, &(p, normal))| {
            let mut sums = vec![0.0f64; BATCHES as usize * n];
            let mut stats = RayStats::default();
            // One buffer for every sample's tallied parts (a path credits a few patches).
            let mut parts: Vec<(Vec3, crate::spectrum::SampledSpectrum)> = Vec::new();
            for b in 0..BATCHES {
                let stream = batch_stream(r as u64, b);
                let row = &mut sums[b as usize * n..(b as usize + 1) * n];
                for s in 0..per_batch {
                    let mut sampler = Sampler::new(world.settings.seed, stream, s);
                    let mut wl = SampledWavelengths::sample_visible(sampler.get1d());
                    irradiance_tallied(
                        world,
                        &RayStart::free(p),
                        normal,
                        false,
                        &mut wl,
                        &mut sampler,
                        &mut stats,
                        &mut |d, c| parts.push((d, c)),
                    );
                    for (d, c) in parts.drain(..) {
                        let y = radiance_to_xyz(&c, &wl)[1];
                        if y.is_finite() {
                            let local = frame.to_local(d.as_dvec3());
                            row[patches.index(local.to_array())] += y;
                        }
                    }
                }
            }
            for v in sums.iter_mut() {
                *v /= per_batch as f64;
            }
            sums
        })
        .collect();
    let mut c = Coefficients {
        patches: patches.clone(),
        receivers: receivers.len(),
        batches: Vec::with_capacity(receivers.len() * n * BATCHES as usize),
        samples: per_batch * BATCHES as u64,
    };
    for b in rows {
        c.batches.extend(b);
    }
    Ok(c)
}
