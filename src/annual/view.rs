//! Annual glare of a view: per-pixel daylight coefficients of the scene's camera at a reduced
//! resolution, an hourly luminance image rebuilt from them for every occupied hour, and the
//! daylight glare probability (DGP) of each image evaluated as `candela glare` does.
//!
//! Each pixel's luminance under an hour's daylight is the sum of three parts:
//! - **Sky**: Σᵢ Cₚᵢ L̄ᵢ, the pixel's coefficient for each sky patch (cd/m² per cd/m²) times
//!   the patch's mean luminance that hour: camera paths under a unit sky, each one's light
//!   credited to the patch it arrives from (the sky seen through the window included).
//! - **Sun on surfaces**: everything the sun gives after at least one scattering (sunlit
//!   floors and walls, their inter-reflections), traced at the nodes of the sun-position grid
//!   the grid points use ([`super::sun`]) and bilinearly interpolated to each hour's sun.
//! - **The sun's disk**: deposited directly into the pixels its directions fall in, with the
//!   transmittance of the panes on the way from the eye, for each hour's own sun: no path
//!   has to find it, so it adds no noise, and shadow edges of the window frame stay sharp.
//!
//! The vertical illuminance at the eye, E_v = Σ L cos θ ω over the pixels, is kept per batch
//! (the [`BATCHES`] independent batches of the coefficients), so every hour's E_v carries its
//! standard error, and replicate years (as the grid metrics draw them) give the annual glare
//! metrics their intervals. The glare sources of an hour are those of its mean image: DGP's
//! uncertainty is carried through E_v, which dominates it unless the sun is in view (when
//! DGP saturates).

use super::coefficients::CoefficientError;
use super::metrics::{replicate_interval, Schedule};
use super::results::{multipliers, Estimate};
use super::sun::{declination_hour_angle, node_direction, set_sun, Grid};
use super::year::HourSky;
use crate::camera::Camera;
use crate::daylight::patches::SkyPatches;
use crate::film::radiance_to_xyz;
use crate::glare::indices::{dgp, evaluate_luminance, SourceTerm};
use crate::glare::{GlareImage, GlareOptions};
use crate::integrator::path::{trace, trace_tallied, PathStart};
use crate::integrator::stats::RayStats;
use crate::integrator::transmit::transmittance;
use crate::light::sky::SiteFrame;
use crate::light::Light;
use crate::meter::BATCHES;
use crate::sampling::sobol::batch_stream;
use crate::sampling::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;
use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;

/// Shadow rays over the sun's disk per hour and batch (stratified over the disk, each with its
/// own wavelengths): a disk mostly hidden behind a window's edge is resolved to 1/1024 of its
/// light, and each batch's own points give the disk's part of E_v its standard error.
const DISK_POINTS: u32 = 64;

/// Largest sun-node spacing in declination and hour angle (degrees) for the sun on the view's
/// surfaces: half the grid points' ([`super::sun`]), since a sunlit patch seen from the eye
/// moves across many pixels between nodes (bilinear interpolation of the view's E_v at the
/// grid points' spacing was off by 0.4 % of the sun's part for a 12° sun; the error falls
/// with the square of the spacing).
const NODE_STEP_DEG: (f64, f64) = (3.0, 3.75);

/// DGP limits: imperceptible below 0.35, perceptible, disturbing from 0.40, intolerable from
/// 0.45 (Wienold 2009); EN 17037's glare protection uses the same values for the DGP exceeded
/// in 5 % of the occupied hours (high, medium, minimum).
pub const DGP_LIMITS: [f64; 3] = [0.35, 0.40, 0.45];

/// The sun disk's E_v per lx of direct-normal illuminance, per batch.
type DiskEv = [f64; BATCHES as usize];

/// How finely a view is computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSettings {
    /// Pixels along the image's longer side (the aspect ratio is the camera's).
    pub resolution: usize,
    /// Camera paths per pixel for the sky coefficients.
    pub sky_samples: u64,
    /// Camera paths per pixel and sun-grid node for the sun on surfaces.
    pub sun_samples: u64,
}

impl Default for ViewSettings {
    fn default() -> Self {
        Self {
            resolution: 64,
            sky_samples: 256,
            sun_samples: 16,
        }
    }
}

/// The camera a view is computed with: the scene's, at `resolution` pixels along its longer side.
pub fn view_camera(camera: &Camera, resolution: usize) -> Camera {
    let (w, h) = (camera.width.max(1), camera.height.max(1));
    let (w2, h2) = if w >= h {
        (resolution, (resolution * h).div_ceil(w).max(1))
    } else {
        ((resolution * w).div_ceil(h).max(1), resolution)
    };
    let (forward, _, up) = camera.frame();
    Camera::with_projection(
        camera.position,
        camera.position + forward,
        up,
        camera.projection(),
        (w2, h2),
        None,
    )
}

/// Bytes [`view_coefficients`] holds for a view of `pixels` pixels, `patches` sky patches,
/// `nodes` sun-grid nodes at most and `sunny` hours with sun.
pub fn view_bytes(pixels: usize, patches: usize, nodes: usize, sunny: usize) -> u64 {
    let p = pixels as u64;
    4 * p * patches as u64
        + 4 * p * nodes as u64
        + 8 * BATCHES as u64 * (patches + nodes) as u64
        + 40 * p
        + sunny as u64 * (64 + 8 * BATCHES as u64)
}

/// A view's coefficients.
#[derive(Clone, Debug)]
pub struct ViewMatrix {
    /// Pixel geometry in the camera's frame (its luminances unused).
    pub image: GlareImage,
    /// Indices (into the image) of the pixels inside the view.
    inside: Vec<usize>,
    /// Per inside pixel: cos θ ω (sr), its weight in E_v.
    cos_w: Vec<f64>,
    n_patches: usize,
    /// `sky[q * n_patches + i]`: mean coefficient of inside pixel q for patch i (cd/m² per cd/m²).
    sky: Vec<f32>,
    /// `sky_ev[b * n_patches + i]`: E_v of patch i at unit luminance in batch b (lx per cd/m²).
    sky_ev: Vec<f64>,
    grid: Grid,
    /// Node → slot in `sun` (usize::MAX: not traced).
    node_slot: Vec<usize>,
    /// `sun[slot * inside + q]`: luminance of the sun on surfaces per lx of direct-normal
    /// illuminance (cd/m² per lx).
    sun: Vec<f32>,
    /// `sun_ev[slot * BATCHES + b]`: its E_v per lx, batch b.
    sun_ev: Vec<f64>,
    /// Per sunny hour: (δ, ω) of its sun, the pixels its disk falls in (inside index,
    /// luminance per lx) and the disk's E_v per lx.
    sun_dw: Vec<(f64, f64)>,
    disk: Vec<Vec<(u32, f32)>>,
    disk_ev: Vec<DiskEv>,
    pub sky_samples: u64,
    pub sun_samples: u64,
    pub nodes: usize,
}

/// Calls `sample` with `per_batch` camera rays through pixel `pix` (film jittered by the
/// sampler) and returns the mean of what it returns over the rays inside the view (a
/// fisheye's rim pixels see the scene over part of their area) and their number.
fn pixel_batch(
    camera: &Camera,
    pix: usize,
    seed: u64,
    stream: u64,
    per_batch: u64,
    sample: &mut dyn FnMut(Vec3, Vec3, &mut SampledWavelengths, &mut Sampler) -> f64,
) -> (f64, u64) {
    let (x, y) = ((pix % camera.width) as f32, (pix / camera.width) as f32);
    let (mut sum, mut n) = (0.0, 0u64);
    for s in 0..per_batch {
        let mut sampler = Sampler::new(seed, stream, s);
        let u = sampler.get2d();
        let Some(ray) = camera.try_ray(x + u.x, y + u.y, Vec2::splat(0.5)) else {
            continue;
        };
        let mut wl = SampledWavelengths::sample_visible(sampler.get1d());
        sum += sample(ray.origin, ray.dir, &mut wl, &mut sampler);
        n += 1;
    }
    (if n > 0 { sum / n as f64 } else { 0.0 }, n)
}

fn luminance(c: &SampledSpectrum, wl: &SampledWavelengths) -> f64 {
    let y = radiance_to_xyz(c, wl)[1];
    if y.is_finite() {
        y
    } else {
        0.0
    }
}

/// The sky coefficients of the view of `camera` (see [`view_camera`]) in `sky_world`, lit by
/// a unit sky alone; the sun's are added by [`ViewMatrix::add_sun`].
pub fn view_coefficients(
    sky_world: &World,
    camera: &Camera,
    patches: &SkyPatches,
    settings: &ViewSettings,
) -> Result<ViewMatrix, CoefficientError> {
    let Some(Light::Sky(sky)) = sky_world.lights.first() else {
        return Err(CoefficientError::Lights(
            "no sky; view coefficients need a unit sky".into(),
        ));
    };
    if sky_world.lights.len() != 1 || !sky.is_unit() {
        return Err(CoefficientError::NotUnit);
    }
    let sky_frame = sky.frame;
    let k = BATCHES as usize;
    let n_p = patches.len();
    let n_pixels = camera.width * camera.height;
    let image = GlareImage::of_projection(
        camera.projection(),
        camera.width,
        camera.height,
        vec![0.0; n_pixels],
        None,
    );
    let inside: Vec<usize> = (0..image.len()).filter(|&i| image.valid(i)).collect();
    let n_in = inside.len();
    let cos_w: Vec<f64> = inside
        .iter()
        .map(|&i| image.direction[i][2] * image.solid_angle_sr[i])
        .collect();
    let seed = sky_world.settings.seed;

    // Sky: per pixel, per batch, per patch.
    let sky_per_batch = settings.sky_samples.div_ceil(BATCHES as u64).max(1);
    let rows: Vec<(Vec<f32>, Vec<f64>)> = inside
        .par_iter()
        .enumerate()
        .map(|(q, &pix)| {
            let mut stats = RayStats::default();
            let mut parts: Vec<(Vec3, SampledSpectrum)> = Vec::new();
            let mut mean = vec![0.0f64; n_p];
            let mut ev = vec![0.0f64; k * n_p];
            for b in 0..BATCHES {
                let mut row = vec![0.0f64; n_p];
                let (_, inside_rays) = pixel_batch(
                    camera,
                    pix,
                    seed,
                    batch_stream(pix as u64, b),
                    sky_per_batch,
                    &mut |o, d, wl, sampler| {
                        trace_tallied(
                            sky_world,
                            o,
                            d,
                            PathStart::camera(o),
                            wl,
                            sampler,
                            &mut stats,
                            &mut |dir, c| parts.push((dir, c)),
                        );
                        for (dir, c) in parts.drain(..) {
                            let local = sky_frame.to_local(dir.as_dvec3());
                            row[patches.index(local.to_array())] += luminance(&c, wl);
                        }
                        0.0
                    },
                );
                let scale = if inside_rays > 0 {
                    1.0 / inside_rays as f64
                } else {
                    0.0
                };
                for i in 0..n_p {
                    let c = row[i] * scale;
                    mean[i] += c / k as f64;
                    ev[b as usize * n_p + i] = c * cos_w[q];
                }
            }
            (mean.iter().map(|&c| c as f32).collect(), ev)
        })
        .collect();
    let mut sky_c = Vec::with_capacity(n_in * n_p);
    let mut sky_ev = vec![0.0f64; k * n_p];
    for (mean, ev) in rows {
        sky_c.extend(mean);
        for (a, b) in sky_ev.iter_mut().zip(ev) {
            *a += b;
        }
    }
    Ok(ViewMatrix {
        image,
        inside,
        cos_w,
        n_patches: n_p,
        sky: sky_c,
        sky_ev,
        grid: Grid::over(&[(0.0, 0.0)]),
        node_slot: Vec::new(),
        sun: Vec::new(),
        sun_ev: Vec::new(),
        sun_dw: Vec::new(),
        disk: Vec::new(),
        disk_ev: Vec::new(),
        sky_samples: sky_per_batch * BATCHES as u64,
        sun_samples: 0,
        nodes: 0,
    })
}

impl ViewMatrix {
    /// Adds the sun's coefficients for the suns toward `to_sun_enu` ((east, north, up) at a
    /// site of latitude `latitude_deg` whose frame is `frame`), traced in `sun_world` (lit by
    /// one sun of 1 lx alone; its direction is changed) with the camera of
    /// [`view_coefficients`]. `progress` gets (steps done, steps): the nodes, then the disks.
    #[allow(clippy::too_many_arguments)]
    pub fn add_sun(
        &mut self,
        sun_world: &mut World,
        camera: &Camera,
        frame: &SiteFrame,
        to_sun_enu: &[[f64; 3]],
        latitude_deg: f64,
        settings: &ViewSettings,
        progress: &mut dyn FnMut(usize, usize),
    ) {
        let k = BATCHES as usize;
        let n_in = self.inside.len();
        let (inside, cos_w) = (&self.inside, &self.cos_w);
        let seed = sun_world.settings.seed;
        // Sun grid, as the grid points' (same hours, same nodes).
        let dw: Vec<(f64, f64)> = to_sun_enu
            .iter()
            .map(|d| declination_hour_angle(DVec3::from_array(*d).normalize(), latitude_deg))
            .collect();
        let grid = Grid::with_step(
            if dw.is_empty() { &[(0.0, 0.0)] } else { &dw },
            NODE_STEP_DEG,
        );
        let n_nodes = grid.n.0 * grid.n.1;
        let mut node_slot = vec![usize::MAX; n_nodes];
        let mut nodes = Vec::new();
        for &x in &dw {
            for (node, w) in grid.corners(x) {
                if w > 0.0 && node_slot[node] == usize::MAX {
                    node_slot[node] = nodes.len();
                    nodes.push(node);
                }
            }
        }
        let steps = nodes.len() + 1;

        // The sun on surfaces at the nodes.
        let scene_dir = |d: DVec3| frame.to_world(d).normalize().as_vec3();
        let sun_per_batch = settings.sun_samples.div_ceil(BATCHES as u64).max(1);
        let mut sun = vec![0f32; nodes.len() * n_in];
        let mut sun_ev = vec![0f64; nodes.len() * k];
        for (slot, &node) in nodes.iter().enumerate() {
            let (d, w) = grid.node(node);
            set_sun(sun_world, scene_dir(node_direction(d, w, latitude_deg)));
            let world = &*sun_world;
            let rows: Vec<Vec<f64>> = inside
                .par_iter()
                .map(|&pix| {
                    let mut stats = RayStats::default();
                    let stream = ((node as u64 + 1) << 40) | pix as u64;
                    (0..BATCHES)
                        .map(|b| {
                            pixel_batch(
                                camera,
                                pix,
                                seed,
                                batch_stream(stream, b),
                                sun_per_batch,
                                &mut |o, d, wl, sampler| {
                                    let start = PathStart {
                                        unscattered_escapes: false,
                                        ..PathStart::camera(o)
                                    };
                                    let c = trace(world, o, d, start, wl, sampler, &mut stats);
                                    luminance(&c, wl)
                                },
                            )
                            .0
                        })
                        .collect()
                })
                .collect();
            for (q, row) in rows.iter().enumerate() {
                sun[slot * n_in + q] = (row.iter().sum::<f64>() / k as f64) as f32;
                for b in 0..k {
                    sun_ev[slot * k + b] += row[b] * cos_w[q];
                }
            }
            progress(slot + 1, steps);
        }

        // The disk of each hour's sun.
        let mut index_of = vec![u32::MAX; self.image.len()];
        for (q, &i) in inside.iter().enumerate() {
            index_of[i] = q as u32;
        }
        let world = &*sun_world;
        let disks: Vec<(Vec<(u32, f32)>, DiskEv)> = to_sun_enu
            .par_iter()
            .enumerate()
            .map(|(h, d)| {
                let to_sun = scene_dir(DVec3::from_array(*d));
                sun_disk(world, camera, to_sun, &index_of, cos_w, h)
            })
            .collect();
        progress(steps, steps);
        let (disk, disk_ev): (Vec<_>, Vec<_>) = disks.into_iter().unzip();
        self.grid = grid;
        self.node_slot = node_slot;
        self.sun = sun;
        self.sun_ev = sun_ev;
        self.sun_dw = dw;
        self.disk = disk;
        self.disk_ev = disk_ev;
        self.sun_samples = sun_per_batch * BATCHES as u64;
        self.nodes = nodes.len();
    }
}

/// The sun's disk toward `to_sun` (world must be lit by one sun of 1 lx) as seen from the
/// camera: per pixel it falls in (inside index), the luminance it adds there per lx of
/// direct-normal illuminance, and its E_v per lx in each batch. Each of the [`DISK_POINTS`]
/// directions of a batch carries E_n T / [`DISK_POINTS`] of that batch's estimate (T the panes'
/// transmittance from the eye); its pixel's luminance is set so that the pixel's share of E_v
/// is E cos θ of the direction itself (the pixel's centre would be off by the cosine's change
/// across the pixel).
fn sun_disk(
    world: &World,
    camera: &Camera,
    to_sun: Vec3,
    index_of: &[u32],
    cos_w: &[f64],
    hour: usize,
) -> (Vec<(u32, f32)>, DiskEv) {
    let mut ev = [0.0; BATCHES as usize];
    let Light::Sun(sun) = &world.lights[0] else {
        return (Vec::new(), ev);
    };
    let mut sun = sun.clone();
    sun.to_sun = to_sun.normalize();
    let (forward, _, _) = camera.frame();
    let mut out: Vec<(u32, f32)> = Vec::new();
    let side = (DISK_POINTS as f64).sqrt() as u32;
    let n = DISK_POINTS as f64;
    for (b, ev_b) in ev.iter_mut().enumerate() {
        let stream = batch_stream(((hour as u64 + 1) << 24) | 7, b as u32);
        for j in 0..DISK_POINTS {
            let mut sampler = Sampler::new(world.settings.seed, stream, j as u64);
            // Stratified over the disk and, in another order, over the wavelengths.
            let jitter = sampler.get2d();
            let u = Vec2::new(
                ((j % side) as f32 + jitter.x) / side as f32,
                ((j / side) as f32 + jitter.y) / side as f32,
            );
            let wl = SampledWavelengths::sample_visible(
                ((j * 29 % DISK_POINTS) as f32 + sampler.get1d()) / DISK_POINTS as f32,
            );
            let Some(ls) = sun.sample_li(u, &wl) else {
                continue;
            };
            let Some((fx, fy)) = camera.film_position(ls.wi) else {
                continue;
            };
            let (x, y) = (fx.floor(), fy.floor());
            if x < 0.0 || y < 0.0 || x >= camera.width as f64 || y >= camera.height as f64 {
                continue;
            }
            let q = index_of[y as usize * camera.width + x as usize];
            if q == u32::MAX || ls.pdf <= 0.0 {
                continue;
            }
            let Some(tr) = transmittance(world, camera.position, ls.wi, f32::INFINITY, &wl) else {
                continue;
            };
            let e = luminance(&(tr * ls.li * (1.0 / ls.pdf)), &wl) / n;
            let cos = ls.wi.dot(forward) as f64;
            if e <= 0.0 || cos <= 0.0 || cos_w[q as usize] <= 0.0 {
                continue;
            }
            *ev_b += e * cos;
            // The image holds the mean over the batches.
            let l = e * cos / cos_w[q as usize] / BATCHES as f64;
            match out.iter_mut().find(|(p, _)| *p == q) {
                Some((_, v)) => *v += l as f32,
                None => out.push((q, l as f32)),
            }
        }
    }
    (out, ev)
}

/// The glare of one hour.
#[derive(Clone, Debug)]
pub struct HourGlare {
    /// Index of the hour in the year.
    pub hour: usize,
    pub dgp: f64,
    /// E_v at the eye (lx), its standard error, and the sun disk's part of it.
    pub ev_lx: f64,
    pub ev_stderr_lx: f64,
    pub ev_disk_lx: f64,
    pub sources: usize,
    /// Per-batch E_v (lx) for the replicate years, and the sources' terms.
    ev_batches: [f32; BATCHES as usize],
    terms: Vec<SourceTerm>,
}

impl ViewMatrix {
    /// The luminance image (cd/m², one value per pixel of [`Self::image`]) of an hour, its
    /// per-batch E_v (lx) and the disk's E_v (lx). `sunny` is the hour's index among the sun
    /// hours given to [`view_coefficients`] (None without sun).
    pub fn hour_image(&self, hs: &HourSky, sunny: Option<usize>) -> (Vec<f64>, Vec<f64>, f64) {
        let n_p = self.n_patches;
        let k = BATCHES as usize;
        let l = &hs.sky.luminance_cd_m2;
        let mut lum = vec![0.0; self.image.len()];
        for (q, &pix) in self.inside.iter().enumerate() {
            let row = &self.sky[q * n_p..(q + 1) * n_p];
            lum[pix] = row.iter().zip(l).map(|(&c, &l)| c as f64 * l).sum();
        }
        let mut ev: Vec<f64> = (0..k)
            .map(|b| {
                self.sky_ev[b * n_p..(b + 1) * n_p]
                    .iter()
                    .zip(l)
                    .map(|(c, l)| c * l)
                    .sum()
            })
            .collect();
        let mut disk_ev = 0.0;
        if let Some(s) = sunny {
            let en = hs.sky.direct_normal_lx;
            let n_in = self.inside.len();
            for (node, w) in self.grid.corners(self.sun_dw[s]) {
                if w <= 0.0 {
                    continue;
                }
                let slot = self.node_slot[node];
                let row = &self.sun[slot * n_in..(slot + 1) * n_in];
                for (q, &pix) in self.inside.iter().enumerate() {
                    lum[pix] += w * en * row[q] as f64;
                }
                for (b, e) in ev.iter_mut().enumerate() {
                    *e += w * en * self.sun_ev[slot * k + b];
                }
            }
            for &(q, l) in &self.disk[s] {
                lum[self.inside[q as usize]] += en * l as f64;
            }
            let d = &self.disk_ev[s];
            disk_ev = en * d.iter().sum::<f64>() / k as f64;
            for (e, d) in ev.iter_mut().zip(d) {
                *e += en * d;
            }
        }
        (lum, ev, disk_ev)
    }

    /// The glare of every hour of `hours` (indices into `year`) that has daylight; `sun_index`
    /// maps an hour to its index among the sun hours (usize::MAX without sun).
    pub fn glare(
        &self,
        year: &[HourSky],
        hours: &[usize],
        sun_index: &[usize],
        options: &GlareOptions,
    ) -> Vec<HourGlare> {
        let k = BATCHES as usize;
        hours
            .par_iter()
            .filter(|&&h| year[h].is_daylight())
            .map(|&h| {
                let s = (sun_index[h] != usize::MAX).then_some(sun_index[h]);
                let (lum, ev, disk_ev) = self.hour_image(&year[h], s);
                let r = evaluate_luminance(&self.image, &lum, options);
                let mean = ev.iter().sum::<f64>() / k as f64;
                let var = ev.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (k - 1) as f64;
                let mut batches = [0f32; BATCHES as usize];
                for (a, e) in batches.iter_mut().zip(&ev) {
                    *a = (e - mean) as f32;
                }
                HourGlare {
                    hour: h,
                    dgp: r.dgp,
                    ev_lx: r.ev_lx,
                    ev_stderr_lx: (var / k as f64).sqrt(),
                    ev_disk_lx: disk_ev,
                    sources: r.sources.len(),
                    ev_batches: batches,
                    terms: r
                        .sources
                        .iter()
                        .map(|s| SourceTerm {
                            luminance_cd_m2: s.luminance_cd_m2,
                            solid_angle_sr: s.solid_angle_sr,
                            position_index: s.position_index,
                        })
                        .collect(),
                }
            })
            .collect()
    }
}

/// Annual glare metrics of a view over the occupied hours (hours without daylight count as
/// without glare).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ViewResult {
    /// Fractions of the occupied hours with DGP ≥ 0.35, 0.40 and 0.45.
    pub hours_above: [Estimate; 3],
    /// The DGP exceeded in 5 % of the occupied hours (EN 17037's glare criterion).
    pub dgp_5_percent: Estimate,
}

/// One year's metrics from its hourly DGPs (occupied hours with daylight; `occupied` in all).
fn view_values(dgps: &mut [f64], occupied: usize) -> [f64; 4] {
    let n = occupied.max(1) as f64;
    let above = DGP_LIMITS.map(|t| dgps.iter().filter(|&&d| d >= t).count() as f64 / n);
    // The 95th percentile over all occupied hours, the dark ones at 0: the value exceeded by
    // at most 5 % of them (nearest rank).
    dgps.sort_by(|a, b| b.total_cmp(a));
    let rank = (0.05 * occupied as f64).floor() as usize;
    let p95 = dgps.get(rank).copied().unwrap_or(0.0);
    [above[0], above[1], above[2], p95]
}

/// The annual glare metrics of `hours` (the occupied hours with daylight, from
/// [`ViewMatrix::glare`]) over `occupied`'s hours, with intervals from `draws` replicate
/// years of E_v (the multipliers of the grid metrics' draws, for the same `seed`).
pub fn view_metrics(
    hours: &[HourGlare],
    occupied: &Schedule,
    options: &GlareOptions,
    draws: usize,
    seed: u64,
) -> ViewResult {
    let n_occ = occupied.hours.len();
    let mut d: Vec<f64> = hours.iter().map(|h| h.dgp).collect();
    let mean = view_values(&mut d, n_occ);
    let k = BATCHES as usize;
    let c =
        crate::sampling::t95(BATCHES - 1) / 1.959_963_984_540_054 / ((k * (k - 1)) as f64).sqrt();
    let reps: Vec<[f64; 4]> = (0..draws)
        .into_par_iter()
        .map(|r| {
            let g = multipliers(seed, r);
            let mut d: Vec<f64> = hours
                .iter()
                .map(|h| {
                    let s: f64 = g
                        .iter()
                        .zip(&h.ev_batches)
                        .map(|(g, &e)| g * e as f64)
                        .sum();
                    let ev = (h.ev_lx + c * s).max(0.0);
                    dgp(ev, &h.terms, &options.dgp, options.low_light_correction)
                })
                .collect();
            view_values(&mut d, n_occ)
        })
        .collect();
    let est = |i: usize| {
        let mut v: Vec<f64> = reps.iter().map(|r| r[i]).collect();
        Estimate {
            value: mean[i],
            ci95: replicate_interval(&mut v),
        }
    };
    ViewResult {
        hours_above: [est(0), est(1), est(2)],
        dgp_5_percent: est(3),
    }
}

/// EN 17037's glare protection level for the DGP exceeded in 5 % of the occupied hours.
pub fn en17037_glare_level(dgp_5_percent: f64) -> &'static str {
    if dgp_5_percent < DGP_LIMITS[0] {
        "high"
    } else if dgp_5_percent < DGP_LIMITS[1] {
        "medium"
    } else if dgp_5_percent < DGP_LIMITS[2] {
        "minimum"
    } else {
        "below minimum"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn annual_values_count_dark_hours_as_without_glare() {
        // 100 occupied hours, 13 with daylight: 3 at 0.5, 5 at 0.42, 5 at 0.2.
        let mut d: Vec<f64> = [vec![0.5; 3], vec![0.42; 5], vec![0.2; 5]].concat();
        let v = view_values(&mut d, 100);
        assert_eq!(v[0], 0.08);
        assert_eq!(v[1], 0.08);
        assert_eq!(v[2], 0.03);
        // Exceeded in at most 5 of the 100 hours: the 6th highest, 0.42 (3 hours above it).
        assert_eq!(v[3], 0.42);
        // With 10 hours at 0.5, 0.5 itself.
        let mut d: Vec<f64> = [vec![0.5; 10], vec![0.2; 5]].concat();
        assert_eq!(view_values(&mut d, 100)[3], 0.5);
        assert_eq!(en17037_glare_level(0.42), "minimum");
        assert_eq!(en17037_glare_level(0.2), "high");
    }
}
