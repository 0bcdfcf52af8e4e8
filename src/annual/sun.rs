//! The sun's part of an annual calculation: for each receiver and each hour with the sun up,
//! the illuminance (lx) a sun of 1 lx direct-normal illuminance at that hour's position gives
//! it, in total and directly (the disk seen from the receiver through the panes, as LM-83's
//! annual sunlight exposure counts it).
//!
//! The two parts are estimated differently, each where it is cheap and exact:
//! - **Direct**: each hour's own sun, by shadow rays over its disk, through the panes. No
//!   interpolation between sun positions: shadow edges stay where they are.
//! - **Inter-reflected**: at the nodes of a grid in declination δ and hour angle ω covering
//!   the year's sun positions (at most 6° × 7.5° apart), from paths that count only light
//!   scattered at least once ([`indirect_irradiance`]); each hour bilinearly interpolated from
//!   the four nodes around its sun. This light varies smoothly with the sun's position, and
//!   each node's many paths serve every hour near it, so an hour's inter-reflected sun is far
//!   less noisy than paths traced for that hour alone could make it. Nodes below the horizon
//!   (around sunrise and sunset) are taken at 1° altitude on the same azimuth.
//!
//! Both come in [`BATCHES`] independent batches, as the sky coefficients do, so an hour's
//! illuminance carries a standard error and replicate years can be drawn.

use crate::annual::coefficients::CoefficientError;
use crate::film::radiance_to_xyz;
use crate::integrator::path::{indirect_irradiance, RayStart};
use crate::integrator::stats::RayStats;
use crate::integrator::transmit::transmittance;
use crate::light::sky::SiteFrame;
use crate::light::Light;
use crate::meter::BATCHES;
use crate::sampling::sobol::batch_stream;
use crate::sampling::Sampler;
use crate::spectrum::SampledWavelengths;
use crate::world::World;
use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;

/// Largest node spacing in declination and hour angle, degrees.
const MAX_STEP_DEG: (f64, f64) = (6.0, 7.5);

/// Sun illuminances per unit direct-normal illuminance (lx per lx), for `hours` sun
/// positions × `receivers`, each as [`BATCHES`] batch values: `total[(h * receivers + r) *
/// BATCHES + b]` (direct + inter-reflected), and the direct part alone in `direct`.
#[derive(Clone, Debug, Default)]
pub struct SunCoefficients {
    pub hours: usize,
    pub receivers: usize,
    pub total: Vec<f64>,
    pub direct: Vec<f64>,
    /// Paths per receiver and node for the inter-reflected part; shadow rays per receiver and
    /// hour for the direct part.
    pub samples: u64,
    pub direct_samples: u64,
    /// Grid nodes traced.
    pub nodes: usize,
}

impl SunCoefficients {
    /// Batch values of hour `h` at receiver `r`: (total, direct).
    pub fn batches(&self, h: usize, r: usize) -> (&[f64], &[f64]) {
        let k = BATCHES as usize;
        let i = (h * self.receivers + r) * k;
        (&self.total[i..i + k], &self.direct[i..i + k])
    }
}

/// Bytes [`sun_coefficients`] holds for `hours` × `receivers` (the nodes' are fewer).
pub fn sun_coefficient_bytes(hours: usize, receivers: usize) -> u64 {
    3 * hours as u64 * receivers as u64 * BATCHES as u64 * 8
}

/// Equatorial coordinates at latitude φ: the unit vectors toward the celestial pole, the
/// equator on the meridian, and the west, in (east, north, up).
fn equatorial(latitude_deg: f64) -> (DVec3, DVec3, DVec3) {
    let (s, c) = latitude_deg.to_radians().sin_cos();
    (
        DVec3::new(0.0, c, s),
        DVec3::new(0.0, -s, c),
        DVec3::new(-1.0, 0.0, 0.0),
    )
}

/// (δ, ω) in radians of unit direction `d` (east, north, up).
pub(super) fn declination_hour_angle(d: DVec3, latitude_deg: f64) -> (f64, f64) {
    let (p, q, w) = equatorial(latitude_deg);
    (d.dot(p).clamp(-1.0, 1.0).asin(), d.dot(w).atan2(d.dot(q)))
}

/// The direction (east, north, up) of (δ, ω), raised to 1° altitude if below it.
pub(super) fn node_direction(delta: f64, omega: f64, latitude_deg: f64) -> DVec3 {
    let (p, q, w) = equatorial(latitude_deg);
    let d = (q * omega.cos() + w * omega.sin()) * delta.cos() + p * delta.sin();
    let min = 1f64.to_radians().sin();
    if d.z >= min {
        return d;
    }
    let h = DVec3::new(d.x, d.y, 0.0);
    let h = if h.length() > 1e-9 {
        h.normalize()
    } else {
        DVec3::Y
    };
    h * (1.0 - min * min).sqrt() + DVec3::Z * min
}

/// A regular (δ, ω) grid over the hours' suns and, per hour, its cell and weights.
#[derive(Clone, Debug)]
pub(super) struct Grid {
    delta0: f64,
    omega0: f64,
    step: (f64, f64),
    pub(super) n: (usize, usize),
}

impl Grid {
    pub(super) fn over(dw: &[(f64, f64)]) -> Self {
        Self::with_step(dw, MAX_STEP_DEG)
    }

    /// A grid over `dw` with nodes at most `max_step_deg` (δ, ω) apart.
    pub(super) fn with_step(dw: &[(f64, f64)], max_step_deg: (f64, f64)) -> Self {
        let (mut d0, mut d1, mut w0, mut w1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for &(d, w) in dw {
            d0 = d0.min(d);
            d1 = d1.max(d);
            w0 = w0.min(w);
            w1 = w1.max(w);
        }
        let cells = |lo: f64, hi: f64, max_deg: f64| {
            (((hi - lo) / max_deg.to_radians()).ceil() as usize).max(1)
        };
        let (cd, cw) = (cells(d0, d1, max_step_deg.0), cells(w0, w1, max_step_deg.1));
        Grid {
            delta0: d0,
            omega0: w0,
            step: (
                ((d1 - d0) / cd as f64).max(1e-9),
                ((w1 - w0) / cw as f64).max(1e-9),
            ),
            n: (cd + 1, cw + 1),
        }
    }

    /// The four nodes around (δ, ω) and their bilinear weights.
    pub(super) fn corners(&self, (d, w): (f64, f64)) -> [(usize, f64); 4] {
        let fd = ((d - self.delta0) / self.step.0).clamp(0.0, (self.n.0 - 1) as f64);
        let fw = ((w - self.omega0) / self.step.1).clamp(0.0, (self.n.1 - 1) as f64);
        // The grid has at least 2 × 2 nodes.
        let (i, j) = (
            (fd.floor() as usize).min(self.n.0 - 2),
            (fw.floor() as usize).min(self.n.1 - 2),
        );
        let (i1, j1) = (i + 1, j + 1);
        let (a, b) = (fd - i as f64, fw - j as f64);
        let node = |i: usize, j: usize| i * self.n.1 + j;
        [
            (node(i, j), (1.0 - a) * (1.0 - b)),
            (node(i1, j), a * (1.0 - b)),
            (node(i, j1), (1.0 - a) * b),
            (node(i1, j1), a * b),
        ]
    }

    pub(super) fn node(&self, k: usize) -> (f64, f64) {
        let (i, j) = (k / self.n.1, k % self.n.1);
        (
            self.delta0 + i as f64 * self.step.0,
            self.omega0 + j as f64 * self.step.1,
        )
    }
}

pub(super) fn set_sun(world: &mut World, to_sun: Vec3) {
    if let Light::Sun(s) = &mut world.lights[0] {
        s.to_sun = to_sun.normalize();
    }
}

/// The sun coefficients of `receivers` ((point, unit normal), scene frame) for the sun toward
/// each of `to_sun_enu` (unit (east, north, up) directions of a site at `latitude_deg` whose
/// frame in the scene is `frame`), from `samples` paths per receiver and node for the
/// inter-reflected part and `direct_samples` shadow rays per receiver and hour for the direct
/// part (each rounded up to a multiple of [`BATCHES`]). `world` must be lit by one
/// [`Light::Sun`] of 1 lx direct-normal illuminance alone; its direction is changed.
/// `progress` is called with (steps done, steps): the nodes, then the hours.
#[allow(clippy::too_many_arguments)]
pub fn sun_coefficients(
    world: &mut World,
    receivers: &[(Vec3, Vec3)],
    to_sun_enu: &[[f64; 3]],
    frame: &SiteFrame,
    latitude_deg: f64,
    samples: u64,
    direct_samples: u64,
    progress: &mut dyn FnMut(usize, usize),
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
    let n_r = receivers.len();
    let n_h = to_sun_enu.len();
    let scene_dir = |d: DVec3| frame.to_world(d).normalize().as_vec3();

    let dw: Vec<(f64, f64)> = to_sun_enu
        .iter()
        .map(|d| declination_hour_angle(DVec3::from_array(*d).normalize(), latitude_deg))
        .collect();
    let grid = Grid::over(&dw);
    let n_nodes = grid.n.0 * grid.n.1;
    let mut used = vec![false; n_nodes];
    for &x in &dw {
        for (node, w) in grid.corners(x) {
            used[node] |= w > 0.0;
        }
    }
    let nodes: Vec<usize> = (0..n_nodes).filter(|&i| used[i]).collect();
    let steps = nodes.len() + n_h;

    // The inter-reflected sun at the nodes: `indirect[(node * receivers + r) * K + b]`.
    let mut indirect = vec![0.0f64; n_nodes * n_r * k];
    for (done, &node) in nodes.iter().enumerate() {
        let (d, w) = grid.node(node);
        set_sun(world, scene_dir(node_direction(d, w, latitude_deg)));
        let world = &*world;
        let rows: Vec<Vec<f64>> = receivers
            .par_iter()
            .enumerate()
            .map(|(r, &(p, normal))| {
                let stream = ((node as u64 + 1) << 40) | r as u64;
                let mut stats = RayStats::default();
                (0..BATCHES)
                    .map(|b| {
                        let bs = batch_stream(stream, b);
                        let mut sum = 0.0;
                        for s in 0..per_batch {
                            let mut sampler = Sampler::new(world.settings.seed, bs, s);
                            let mut wl = SampledWavelengths::sample_visible(sampler.get1d());
                            let e = indirect_irradiance(
                                world,
                                &RayStart::free(p),
                                normal,
                                &mut wl,
                                &mut sampler,
                                &mut stats,
                            );
                            let y = radiance_to_xyz(&e, &wl)[1];
                            if y.is_finite() {
                                sum += y;
                            }
                        }
                        sum / per_batch as f64
                    })
                    .collect()
            })
            .collect();
        for (r, row) in rows.into_iter().enumerate() {
            let i = (node * n_r + r) * k;
            indirect[i..i + k].copy_from_slice(&row);
        }
        progress(done + 1, steps);
    }

    let mut out = SunCoefficients {
        hours: n_h,
        receivers: n_r,
        total: vec![0.0; n_h * n_r * k],
        direct: vec![0.0; n_h * n_r * k],
        samples: per_batch * BATCHES as u64,
        direct_samples: direct_per_batch * BATCHES as u64,
        nodes: nodes.len(),
    };
    for (h, d) in to_sun_enu.iter().enumerate() {
        set_sun(world, scene_dir(DVec3::from_array(*d)));
        let world = &*world;
        let corners = grid.corners(dw[h]);
        let rows: Vec<Vec<f64>> = receivers
            .par_iter()
            .enumerate()
            .map(|(r, &(p, normal))| {
                let stream = ((h as u64 + 1) << 20) | r as u64;
                (0..BATCHES)
                    .map(|b| {
                        let bs = batch_stream(stream, b);
                        let mut sum = 0.0;
                        for s in 0..direct_per_batch {
                            let mut sampler = Sampler::new(world.settings.seed, bs, s);
                            sum += direct_sun(world, p, normal, &mut sampler);
                        }
                        sum / direct_per_batch as f64
                    })
                    .collect()
            })
            .collect();
        for (r, row) in rows.into_iter().enumerate() {
            let i = (h * n_r + r) * k;
            for b in 0..k {
                let ind: f64 = corners
                    .iter()
                    .map(|&(node, w)| w * indirect[(node * n_r + r) * k + b])
                    .sum();
                out.direct[i + b] = row[b];
                out.total[i + b] = row[b] + ind;
            }
        }
        progress(nodes.len() + h + 1, steps);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn declination_and_hour_angle_round_trip() {
        for lat in [-60.0, -10.0, 0.0, 45.0, 70.0] {
            for d in [-23.0f64, 0.0, 20.0] {
                for w in [-100.0f64, -30.0, 0.0, 45.0] {
                    let v = node_direction(d.to_radians(), w.to_radians(), lat);
                    if v.z < 0.02 {
                        continue;
                    }
                    let (d2, w2) = declination_hour_angle(v, lat);
                    assert!((d2.to_degrees() - d).abs() < 1e-9, "{lat} {d} {w}");
                    assert!((w2.to_degrees() - w).abs() < 1e-9, "{lat} {d} {w}");
                }
            }
        }
        // At noon (ω = 0) the sun of the equinox is due south at 90° − φ in the north.
        let v = node_direction(0.0, 0.0, 45.0);
        assert!((v - DVec3::new(0.0, -1.0, 1.0).normalize()).length() < 1e-12);
    }

    #[test]
    fn bilinear_weights_reproduce_a_linear_function() {
        let pts = [(-0.3, -1.2), (0.35, 1.4), (0.1, 0.2)];
        let g = Grid::over(&pts);
        for &(d, w) in &pts {
            let c = g.corners((d, w));
            let f = |(d, w): (f64, f64)| 2.0 * d - 0.5 * w + 1.0;
            let est: f64 = c.iter().map(|&(n, wt)| wt * f(g.node(n))).sum();
            assert!((est - f((d, w))).abs() < 1e-12);
            assert!((c.iter().map(|c| c.1).sum::<f64>() - 1.0).abs() < 1e-12);
        }
    }
}
