//! Rendering an image: tiles in parallel (rayon), every sample regenerated from
//! (seed, pixel, sample index), so the result does not depend on the number of threads.

use crate::film::{radiance_to_xyz, Film, HealthPixel, IlluminanceSums, PixelE, PixelSums};
use crate::integrator::sun_view::SunInView;
use crate::integrator::{PathStart, RayStats};
use crate::sampling::{batch_stream, Sampler};
use crate::spectrum::SampledWavelengths;
use crate::world::World;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

const TILE: usize = 16;

/// A finished render.
pub struct RenderResult {
    pub film: Film,
    pub stats: RayStats,
    pub elapsed: Duration,
    pub threads: usize,
}

impl RenderResult {
    pub fn samples_per_second(&self) -> f64 {
        self.film.total_samples() as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }
    pub fn rays_per_second(&self) -> f64 {
        self.stats.total_rays() as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }
}

/// Render one pixel's samples `first..first+count` of the random stream `seed` into `sums`,
/// and their illuminance into `e` (which the film has when the render estimates illuminance),
/// and their light-and-health channels into `health` (when the film keeps them).
#[allow(clippy::too_many_arguments)]
pub fn render_pixel(
    world: &World,
    seed: u64,
    x: usize,
    y: usize,
    first: u64,
    count: u64,
    sums: &mut PixelSums,
    mut e: Option<&mut IlluminanceSums>,
    mut health: Option<HealthPixel>,
    stats: &mut RayStats,
    sun: Option<&SunInView>,
) {
    let cam = &world.camera;
    let pixel = (y * cam.width + x) as u64;
    // The directly seen sun, the same for every sample (see `SunInView`).
    let deposit = sun.and_then(|s| s.at(pixel)).unwrap_or([0.0; 3]);
    let with_sun = |v: [f64; 3]| [v[0] + deposit[0], v[1] + deposit[1], v[2] + deposit[2]];
    for s in first..first + count {
        // Sample s is sample s / K of batch s mod K, whose independently scrambled sequence
        // makes the batch means independent (the pixel's standard error is their spread).
        let (batch, index) = pixel_batch(pixel, s, world.settings.pixel_batches);
        let mut sampler = Sampler::new(seed, batch, index);
        // Dimensions 0–1: position in the pixel (the best-stratified Sobol pair), 2–3: lens,
        // 4: wavelengths; paths continue from dimension 8.
        let [fx, fy, lx, ly] = sampler.get4();
        let [u_wl, ..] = sampler.get4();
        let off = world.settings.filter.sample(glam::Vec2::new(fx, fy));
        let u_lens = glam::Vec2::new(lx, ly);
        let mut wl = SampledWavelengths::sample_visible(u_wl);
        let Some(ray) = cam.try_ray(x as f32 + 0.5 + off.x, y as f32 + 0.5 + off.y, u_lens) else {
            // Film outside a fisheye's image circle sees nothing.
            sums.add(with_sun([0.0; 3]));
            continue;
        };
        stats.camera_rays += 1;
        let start = PathStart {
            sun_deposited: sun.is_some(),
            ..PathStart::image(world, ray.origin)
        };
        let (l, first_hit) = crate::integrator::path::trace_seen(
            world,
            ray.origin,
            ray.dir,
            start,
            &mut wl,
            &mut sampler,
            stats,
            e.is_some(),
        );
        if let Some(e) = e.as_deref_mut() {
            let mel = health.as_ref().is_some_and(|h| h.wants_irradiance());
            let seen = (ray.dir, first_hit, &l, &wl);
            let v = surface_illuminance(world, seed, seen, batch, index, mel, stats);
            if let (Some(h), Some((_, m))) = (health.as_mut(), v) {
                h.add_edi(sums.count, m);
            }
            e.add(sums.count, v.map(|v| v.0));
        }
        let xyz = radiance_to_xyz(&l, &wl);
        if xyz.iter().all(|v| v.is_finite()) && (health.is_none() || l.is_finite()) {
            if let Some(h) = health.as_mut() {
                h.add_radiance(sums.count, &l, &wl);
            }
            sums.add(with_sun(xyz));
        } else {
            stats.non_finite += 1;
            sums.add(with_sun([0.0; 3]));
        }
    }
}

/// The stream and index of sample `s` of pixel `pixel` in a render of `k` batches per pixel
/// (a divisor of [`crate::film::PIXEL_BATCHES`]): sample s / k of the pixel's batch s mod k, each batch its
/// own scramble, so each batch is a prefix of its sequence however the samples are split into
/// passes. Fewer batches put more samples in each well-stratified sequence: a lower error for
/// the same samples, from fewer independent batch means.
#[inline]
pub fn pixel_batch(pixel: u64, s: u64, k: u32) -> (u64, u64) {
    let k = k as u64;
    (batch_stream(pixel, (s % k) as u32), s / k)
}

/// Stream id of the illuminance estimates (independent of the radiance samples).
const ILLUMINANCE_STREAM: u64 = 0x11_1c_e5_7a_u64 << 20;

/// Smallest reflectance at each of the camera path's wavelengths for its radiance to give the
/// illuminance (below it, or at a surface that is not Lambertian, a path of its own does). The
/// camera path's Russian roulette weighs its throughput relative to this first surface's albedo
/// (see [`crate::integrator::trace`]), so π L/ρ is as precise for its value on a dark surface
/// as on a bright one; the floor only keeps 1/ρ finite.
const MIN_REUSED_REFLECTANCE: f32 = 1e-4;

/// Illuminance (lx) on the surface a camera ray sees, or None if it sees no receiving surface
/// (nothing, the sky, or an emitter). `seen` is the camera ray's direction, its first
/// intersection (the camera path's own, not traced again), the radiance its path brought and
/// that path's wavelengths. At a flat-shaded Lambertian surface
/// of reflectance ρ(λ) the surface reflects ρ/π of its irradiance, so π L/ρ is an irradiance
/// estimator of the same form as [`crate::integrator::irradiance`] (light sampling weighed
/// against the cosine-sampled continuation, which Lambertian sampling is) at no further cost;
/// elsewhere a path of its own estimates it: `seed` is the buffer's stream (the decision buffer
/// of adaptive mode has its own), so each buffer's illuminance samples are independent of its
/// other buffers'; `pixel` and `sample` are the camera sample's batch stream and index in it
/// ([`pixel_batch`]). With `melanopic`, the second value is the melanopic EDI (lx) of the same
/// estimate, else 0.
#[allow(clippy::too_many_arguments)]
fn surface_illuminance(
    world: &World,
    seed: u64,
    (dir, hit, l, wl_cam): (
        glam::Vec3,
        Option<crate::geometry::Hit>,
        &crate::spectrum::SampledSpectrum,
        &SampledWavelengths,
    ),
    pixel: u64,
    sample: u64,
    melanopic: bool,
    stats: &mut RayStats,
) -> Option<(f64, f64)> {
    let hit = hit?;
    let object = world.objects[hit.object as usize];
    if object.light.is_some() {
        return None;
    }
    let material = &world.materials[object.material as usize];
    let reused = (hit.ns.dot(hit.ng) >= 1.0 - 1e-6)
        .then(|| material.lambertian_reflectance(hit.tex, wl_cam))
        .flatten()
        .filter(|rho| rho.0.iter().all(|&r| r >= MIN_REUSED_REFLECTANCE));
    let (e, wl) = match reused {
        Some(rho) => ((*l * std::f32::consts::PI).safe_div(rho), *wl_cam),
        None => {
            // The hemisphere on the side of the surface facing the camera.
            let n = if hit.ng.dot(dir) > 0.0 {
                -hit.ng
            } else {
                hit.ng
            };
            let mut sampler = Sampler::new(seed ^ ILLUMINANCE_STREAM, pixel, sample);
            let mut wl = SampledWavelengths::sample_visible(sampler.get1d());
            let at = crate::integrator::RayStart::surface(&hit);
            let light_traced = world.caustics.is_some();
            let e = crate::integrator::irradiance(
                world,
                &at,
                n,
                light_traced,
                &mut wl,
                &mut sampler,
                stats,
            );
            (e, wl)
        }
    };
    let lux = radiance_to_xyz(&e, &wl)[1];
    let m = if melanopic {
        crate::film::health_melanopic_edi(&e, &wl)
    } else {
        0.0
    };
    if lux.is_finite() && m.is_finite() {
        Some((lux, m))
    } else {
        stats.non_finite += 1;
        Some((0.0, 0.0))
    }
}

/// How long to render and when to stop.
#[derive(Clone, Debug, Default)]
pub struct Progressive {
    /// Most samples per pixel (image and decision buffers together).
    pub max_spp: u32,
    /// Render until this error is reached (adaptive sampling).
    pub target: Option<TargetError>,
    /// Stop after this much time (at the end of the pass in progress).
    pub max_time: Option<Duration>,
    /// Call the checkpoint callback at the end of the first pass after each interval.
    pub checkpoint_interval: Option<Duration>,
    /// Index of every pixel's first sample in its random stream, and of the first caustic light
    /// path: a shard of a render takes its own range of the sequences (0 for a whole render).
    pub first_sample: u64,
    pub first_light_path: u64,
}

/// "Every pixel's luminance known to ±`relative` at 95 % confidence".
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TargetError {
    /// Half-width of the 95 % confidence interval relative to the value (0.01 = 1 %).
    pub relative: f64,
    /// Fraction of the eligible pixels that must meet it (default 1).
    pub fraction: f64,
    /// Pixels darker than this luminance (cd/m²) are not required to meet it; None = 0.1 % of
    /// the image's mean luminance.
    pub floor_cd_m2: Option<f64>,
}

/// Stream of the decision buffer's samples (statistically independent of the image's).
const DECISION_STREAM: u64 = 0xdec1_5104_0000_0000;
/// Stream of the caustic light paths (see [`crate::integrator::light_path`]).
const CAUSTIC_STREAM: u64 = 0xca05_71c5_0000_0000;

/// Samples a pixel's decision buffer needs before its error estimate is trusted.
pub const MIN_DECISION_SAMPLES: u64 = 8;
/// Largest number of samples one pixel receives in one pass.
const MAX_PASS_SPP: u64 = 64;

/// Progress of a progressive render after a pass.
#[derive(Clone, Copy, Debug, Default)]
pub struct PassStatus {
    pub passes: u32,
    /// Samples taken so far, all pixels.
    pub samples: u64,
    /// Upper bound of samples (pixels × max_spp).
    pub max_samples: u64,
    /// With a target error: fraction of eligible pixels that meet it.
    pub converged_fraction: Option<f64>,
}

/// Why a progressive render ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// No pixel needs more samples: every pixel has max_spp samples, or (with a target) every
    /// pixel either meets the target or has max_spp samples while too few meet it.
    Done,
    TargetReached,
    MaxTime,
    Interrupted,
}

/// Whether pixel `i` still needs samples under `target`, judged on its decision buffer of `k`
/// batches per pixel; and whether it counts toward the fraction (not below the floor).
fn pixel_converged(
    d: &PixelSums,
    e: Option<PixelE>,
    target: &TargetError,
    floor: f64,
    k: u32,
) -> (bool, bool) {
    if d.count < MIN_DECISION_SAMPLES {
        return (false, true);
    }
    let y = d.mean_xyz()[1];
    if y < floor {
        return (true, false);
    }
    let mut ok = d.y_ci95_half_width(k) <= target.relative * y;
    if let Some(pe) = e {
        if let Some(mean) = pe.mean_e() {
            if pe.e.count_e >= MIN_DECISION_SAMPLES && mean > 0.0 {
                ok &= pe.e_ci95_half_width() <= target.relative * mean;
            }
        }
    }
    (ok, true)
}

/// Per-pixel sample counts to add in the next pass (0 = pixel done), and the fraction of
/// eligible pixels that meet the target.
fn plan_pass(world: &World, film: &Film, prog: &Progressive) -> (Vec<u64>, Option<f64>) {
    let max = prog.max_spp as u64;
    let n = film.pixels.len();
    let mut plan = vec![0u64; n];
    let (mut eligible, mut converged) = (0u64, 0u64);
    let floor = match (&prog.target, &film.decision) {
        (Some(t), Some(d)) => t.floor_cd_m2.unwrap_or_else(|| {
            1e-3 * d.iter().map(|p| p.mean_xyz()[1]).sum::<f64>() / n.max(1) as f64
        }),
        _ => 0.0,
    };
    for (i, slot) in plan.iter_mut().enumerate() {
        if !world.camera.pixel_inside(i % film.width, i / film.width) {
            continue;
        }
        let taken = film.samples_taken(i);
        if let (Some(t), Some(d)) = (&prog.target, &film.decision) {
            // A pixel at max_spp that misses the target still counts against the fraction:
            // running out of samples is not reaching the target.
            let e = film.decision_e.as_ref().map(|e| PixelE {
                sums: &d[i],
                e: &e[i],
                batches: film.pixel_batches,
            });
            let (ok, counts) = pixel_converged(&d[i], e, t, floor, film.pixel_batches);
            if counts {
                eligible += 1;
                converged += ok as u64;
            }
            if ok || taken >= max {
                continue;
            }
            // Even sample counts keep the two buffers balanced.
            let add = taken.clamp(2, MAX_PASS_SPP).min(max - taken);
            *slot = add + (add & 1);
        } else if taken < max {
            *slot = taken.clamp(1, MAX_PASS_SPP).min(max - taken);
        }
    }
    let frac = prog.target.map(|_| {
        if eligible == 0 {
            1.0
        } else {
            converged as f64 / eligible as f64
        }
    });
    (plan, frac)
}

/// Render progressively into `film` (which may hold a resumed state): passes over all pixels
/// that still need samples, each pixel's samples indexed from where it stopped, so an
/// interrupted and resumed render equals an uninterrupted one. `stop` is polled between tiles;
/// a pass that is interrupted is discarded. `on_pass` runs after every pass; `on_checkpoint`
/// after the passes that close a checkpoint interval.
pub fn render_progressive(
    world: &World,
    film: &mut Film,
    threads: Option<usize>,
    prog: &Progressive,
    stop: &AtomicBool,
    on_pass: &mut dyn FnMut(&PassStatus),
    on_checkpoint: &mut dyn FnMut(&Film) -> anyhow::Result<()>,
) -> anyhow::Result<(RenderResult, StopReason)> {
    check_film(world, film)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()?;
    // The light-and-health channels weight the spectrum their own way: with them the sun in
    // view is left to the camera rays, which every channel sees alike.
    let sun = if film.health.is_some() {
        None
    } else {
        SunInView::new(world)
    };
    let tiling = Tiling::new(world.camera.width, world.camera.height);
    let start = Instant::now();
    let mut last_checkpoint = start;
    let mut stats = RayStats::default();
    let mut status = PassStatus {
        max_samples: world.camera.inside_pixels() as u64 * prog.max_spp as u64,
        ..Default::default()
    };
    // Each tile's results, kept from pass to pass: the memory is reused instead of allocated
    // (and its pages faulted in afresh) for every pass.
    let mut tiles: Vec<TileResult> = (0..tiling.count()).map(|_| TileResult::default()).collect();
    // The image sums after the pass: a second film buffer that the tiles write in place and
    // that replaces the film's when the pass completes (an interrupted pass leaves the film
    // as it was). Gathering them per tile and copying them back took 5–15 % of the render's
    // time on a small scene: memory a long pass leaves untouched is slow to walk again.
    let mut next_pixels = vec![PixelSums::default(); tiling.w * tiling.h];
    let reason = loop {
        let (plan, frac) = plan_pass(world, film, prog);
        status.converged_fraction = frac;
        status.samples = film_samples(film);
        if let Some(reason) = stop_before_pass(prog, &plan, frac, stop, start) {
            break reason;
        }
        let pass = Pass {
            world,
            prog,
            plan: &plan,
            sun: sun.as_ref(),
            tiling: &tiling,
            stop,
        };
        if !pool.install(|| pass.render_tiles(film, &mut tiles, &mut next_pixels)) {
            break StopReason::Interrupted;
        }
        let Some(light) = pool.install(|| pass.trace_caustics(film, &mut stats)) else {
            break StopReason::Interrupted;
        };
        std::mem::swap(&mut film.pixels, &mut next_pixels);
        pass.gather_tiles(film, &tiles, &mut stats);
        add_light_paths(film, light);
        status.passes += 1;
        status.samples = film_samples(film);
        on_pass(&status);
        if let Some(iv) = prog.checkpoint_interval {
            if last_checkpoint.elapsed() >= iv {
                on_checkpoint(film)?;
                last_checkpoint = Instant::now();
            }
        }
    };
    // The status the stop decision saw (the last pass's report predates it).
    on_pass(&status);
    // The pass buffers go before the film is copied: the render's peak holds two copies of
    // the sums (see `crate::scene::build::bytes_per_pixel`).
    drop(tiles);
    drop(next_pixels);
    Ok((
        RenderResult {
            film: film.clone(),
            stats,
            elapsed: start.elapsed(),
            threads: pool.current_num_threads(),
        },
        reason,
    ))
}

/// Refuse a film that does not fit the world's render (its batches, size, illuminance and
/// light-and-health sums); a fresh film is given illuminance sums when the render needs them.
fn check_film(world: &World, film: &mut Film) -> anyhow::Result<()> {
    // The samples are drawn in the world's batches and their errors taken in the film's: one
    // number, or the standard errors would be wrong.
    anyhow::ensure!(
        film.pixel_batches == world.settings.pixel_batches,
        "the film holds samples in {} batches per pixel, but the scene renders {} (render.pixel_batches)",
        film.pixel_batches,
        world.settings.pixel_batches
    );
    let (w, h) = (world.camera.width, world.camera.height);
    anyhow::ensure!(
        film.width == w && film.height == h,
        "the film is {}×{} but the camera is {w}×{h}",
        film.width,
        film.height
    );
    if world.settings.illuminance && film.total_samples() == 0 {
        film.estimate_illuminance();
    }
    anyhow::ensure!(
        film.e.is_some() == world.settings.illuminance,
        "the film {} illuminance sums but the render {} illuminance",
        if film.e.is_some() { "holds" } else { "lacks" },
        if world.settings.illuminance {
            "estimates"
        } else {
            "does not estimate"
        }
    );
    if let Some(h) = &film.health {
        // Light-traced caustics splat XYZ and E only: the health channels would miss them.
        anyhow::ensure!(
            world.caustics.is_none(),
            "the light-and-health channels (--alpha-opic, --mesopic, --spectral-bands) include no light-traced caustics: render this scene with --caustics path-tracing"
        );
        anyhow::ensure!(
            h.illuminance == film.e.is_some() && h.sums.len() == film.pixels.len() * h.stride(),
            "the film's light-and-health sums do not match its pixels"
        );
    }
    Ok(())
}

/// The samples the film holds, all pixels together.
fn film_samples(film: &Film) -> u64 {
    (0..film.width * film.height)
        .map(|i| film.samples_taken(i))
        .sum()
}

/// Why the render ends before the pass `plan` (`frac`: the fraction of pixels that meet the
/// target), if it does.
fn stop_before_pass(
    prog: &Progressive,
    plan: &[u64],
    frac: Option<f64>,
    stop: &AtomicBool,
    start: Instant,
) -> Option<StopReason> {
    if let (Some(t), Some(f)) = (&prog.target, frac) {
        if f >= t.fraction {
            return Some(StopReason::TargetReached);
        }
    }
    if plan.iter().all(|&n| n == 0) {
        return Some(StopReason::Done);
    }
    if stop.load(Ordering::Relaxed) {
        return Some(StopReason::Interrupted);
    }
    if prog.max_time.is_some_and(|t| start.elapsed() >= t) {
        return Some(StopReason::MaxTime);
    }
    None
}

/// The image in square tiles of [`TILE`] pixels, row by row.
struct Tiling {
    w: usize,
    h: usize,
    tiles_x: usize,
}

impl Tiling {
    fn new(w: usize, h: usize) -> Self {
        Self {
            w,
            h,
            tiles_x: w.div_ceil(TILE),
        }
    }
    fn count(&self) -> usize {
        self.tiles_x * self.h.div_ceil(TILE)
    }
    /// Tile t's pixel indices, row by row: the order in which a tile renders its pixels and
    /// keeps their other sums, and in which they are put back into the film.
    fn pixels(&self, t: usize) -> impl Iterator<Item = usize> {
        let (w, h) = (self.w, self.h);
        let (x0, y0) = ((t % self.tiles_x) * TILE, (t / self.tiles_x) * TILE);
        let xs = x0..(x0 + TILE).min(w);
        (y0..(y0 + TILE).min(h)).flat_map(move |y| xs.clone().map(move |x| y * w + x))
    }
}

/// One pass of a progressive render: `plan` holds the samples each pixel gets.
struct Pass<'a> {
    world: &'a World,
    prog: &'a Progressive,
    plan: &'a [u64],
    sun: Option<&'a SunInView>,
    tiling: &'a Tiling,
    stop: &'a AtomicBool,
}

/// Light paths a pass traced into one buffer (0 the image, 1 the decision buffer): their XYZ
/// and illuminance sums per pixel, and their number.
type LightPass = (usize, Vec<[f64; 6]>, u64);

impl Pass<'_> {
    /// Render every tile (in the calling thread pool): the image sums into `next`, the other
    /// sums into `tiles`. False when `stop` interrupted it.
    fn render_tiles(&self, film: &Film, tiles: &mut [TileResult], next: &mut [PixelSums]) -> bool {
        let next = DisjointSlice::new(next);
        let completed: Vec<bool> = tiles
            .par_iter_mut()
            .enumerate()
            .map(|(t, r)| {
                if self.stop.load(Ordering::Relaxed) {
                    return false;
                }
                r.clear();
                for i in self.tiling.pixels(t) {
                    let est = self.render_plan_pixel(film, i, r);
                    // SAFETY: pixel i belongs to this tile alone, and the buffer is read only
                    // after the pass.
                    unsafe { next.write(i, est) };
                }
                true
            })
            .collect();
        !completed.contains(&false)
    }

    /// Pixel i's samples of this pass, continuing the film's sums: the image sums returned,
    /// the others appended to the tile's `r`.
    fn render_plan_pixel(&self, film: &Film, i: usize, r: &mut TileResult) -> PixelSums {
        let (world, prog, sun) = (self.world, self.prog, self.sun);
        let (x, y) = (i % self.tiling.w, i / self.tiling.w);
        let mut est = film.pixels[i];
        let mut dec = film.decision.as_ref().map(|d| d[i]);
        let mut est_e = film.e.as_ref().map(|e| e[i]);
        let mut dec_e = film.decision_e.as_ref().map(|e| e[i]);
        let mut hp = film.health.as_ref().map(|h| h.pixel(i).to_vec());
        let hv = film
            .health
            .as_ref()
            .zip(hp.as_deref_mut())
            .map(|(h, s)| h.view(s));
        let seed = world.settings.seed;
        match dec.as_mut() {
            // Independent streams: the image's samples continue its own sequence, the decision
            // buffer draws from another scramble.
            Some(d) => {
                let half = self.plan[i] / 2;
                let first = prog.first_sample + est.count;
                let (e, stats) = (est_e.as_mut(), &mut r.stats);
                render_pixel(world, seed, x, y, first, half, &mut est, e, hv, stats, sun);
                let first = prog.first_sample + d.count;
                let (e, stats) = (dec_e.as_mut(), &mut r.stats);
                let seed = seed ^ DECISION_STREAM;
                render_pixel(world, seed, x, y, first, half, d, e, None, stats, sun);
            }
            None => {
                let first = prog.first_sample + est.count;
                let (n, e, stats) = (self.plan[i], est_e.as_mut(), &mut r.stats);
                render_pixel(world, seed, x, y, first, n, &mut est, e, hv, stats, sun);
            }
        }
        r.decision.extend(dec);
        r.e.extend(est_e);
        r.decision_e.extend(dec_e);
        r.health.extend(hp.into_iter().flatten());
        est
    }

    /// Caustic light paths: `light_paths_per_sample` per camera sample each buffer received
    /// in this pass. None when `stop` interrupted them (the pass is discarded too).
    fn trace_caustics(&self, film: &Film, stats: &mut RayStats) -> Option<Vec<LightPass>> {
        let world = self.world;
        let mut light = Vec::new();
        let Some(caustics) = &world.caustics else {
            return Some(light);
        };
        let adaptive = film.decision.is_some();
        let samples: u64 = if adaptive {
            self.plan.iter().map(|n| n / 2).sum()
        } else {
            self.plan.iter().sum()
        };
        let per_buffer =
            (samples as f64 * world.settings.light_paths_per_sample as f64).ceil() as u64;
        let streams: &[u64] = if adaptive {
            &[CAUSTIC_STREAM, CAUSTIC_STREAM ^ DECISION_STREAM]
        } else {
            &[CAUSTIC_STREAM]
        };
        for (b, &stream) in streams.iter().enumerate() {
            let first = self.prog.first_light_path + film.light_paths[b];
            let seed = world.settings.seed ^ stream;
            let mut sums = vec![[0.0f64; 6]; self.tiling.w * self.tiling.h];
            let st = crate::integrator::light_path::trace_light_paths(
                world, caustics, seed, first, per_buffer, self.stop, &mut sums,
            )?;
            stats.merge(&st);
            light.push((b, sums, per_buffer));
        }
        Some(light)
    }

    /// Put the tiles' other sums (decision buffer, illuminance, light and health) and ray
    /// counts back into the film and `stats`.
    fn gather_tiles(&self, film: &mut Film, tiles: &[TileResult], stats: &mut RayStats) {
        for (t, r) in tiles.iter().enumerate() {
            stats.merge(&r.stats);
            for (k, i) in self.tiling.pixels(t).enumerate() {
                if let Some(d) = film.decision.as_mut() {
                    d[i] = r.decision[k];
                }
                if let Some(e) = film.e.as_mut() {
                    e[i] = r.e[k];
                }
                if let Some(e) = film.decision_e.as_mut() {
                    e[i] = r.decision_e[k];
                }
                if let Some(h) = film.health.as_mut() {
                    let s = h.stride();
                    h.sums[i * s..(i + 1) * s].copy_from_slice(&r.health[k * s..(k + 1) * s]);
                }
            }
        }
    }
}

/// Add a pass's light paths to the film's buffers.
fn add_light_paths(film: &mut Film, light: Vec<LightPass>) {
    for (b, sums, paths) in light {
        film.light_paths[b] += paths;
        let (buf, e) = if b == 0 {
            (&mut film.pixels, &mut film.e)
        } else {
            let d = film.decision.as_mut().expect("adaptive film");
            (d, &mut film.decision_e)
        };
        for (p, s) in buf.iter_mut().zip(&sums) {
            p.add_light_paths(&[s[0], s[1], s[2], s[3]], paths);
        }
        if let Some(e) = e.as_mut() {
            for (p, s) in e.iter_mut().zip(&sums) {
                p.add_light_paths(s[4], s[5]);
            }
        }
    }
}

/// A slice that several threads write at distinct indices.
struct DisjointSlice<'a, T> {
    ptr: *mut T,
    len: usize,
    _slice: std::marker::PhantomData<&'a mut [T]>,
}

// SAFETY: the slice is borrowed mutably for 'a, and `write`'s contract keeps the threads'
// writes apart.
unsafe impl<T: Send> Sync for DisjointSlice<'_, T> {}

impl<'a, T: Copy> DisjointSlice<'a, T> {
    fn new(s: &'a mut [T]) -> Self {
        Self {
            ptr: s.as_mut_ptr(),
            len: s.len(),
            _slice: std::marker::PhantomData,
        }
    }
    /// Set item `i`.
    ///
    /// # Safety
    /// No other thread writes or reads item `i` while the slice lives.
    unsafe fn write(&self, i: usize, v: T) {
        assert!(i < self.len);
        // SAFETY: in bounds; `T: Copy` has nothing to drop; exclusive by the contract.
        unsafe { self.ptr.add(i).write(v) };
    }
}

#[derive(Default)]
struct TileResult {
    /// The pixels' decision buffer's and illuminance sums (image, decision), when the film has
    /// them, pixel by pixel (row by row within the tile): apart, so that a render without them
    /// carries none. (The image sums go straight to the next film buffer.)
    decision: Vec<PixelSums>,
    e: Vec<IlluminanceSums>,
    decision_e: Vec<IlluminanceSums>,
    /// The pixels' light-and-health sums, when the film keeps them, one pixel after another.
    health: Vec<f64>,
    stats: RayStats,
}

impl TileResult {
    /// Empty, keeping the vectors' memory for the next pass.
    fn clear(&mut self) {
        self.decision.clear();
        self.e.clear();
        self.decision_e.clear();
        self.health.clear();
        self.stats = RayStats::default();
    }
}

/// Render the whole image at the scene's samples per pixel with `threads` worker threads
/// (None = all cores), calling `progress(samples_done, samples_total)` after each pass.
pub fn render(
    world: &World,
    threads: Option<usize>,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> anyhow::Result<RenderResult> {
    let mut film = Film::new(world.camera.width, world.camera.height);
    film.pixel_batches = world.settings.pixel_batches;
    let prog = Progressive {
        max_spp: world.settings.spp,
        ..Default::default()
    };
    let never = AtomicBool::new(false);
    let (r, _) = render_progressive(
        world,
        &mut film,
        threads,
        &prog,
        &never,
        &mut |s| progress(s.samples, s.max_samples),
        &mut |_| Ok(()),
    )?;
    Ok(r)
}
