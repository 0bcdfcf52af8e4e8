//! Rendering an image: tiles in parallel (rayon), every sample regenerated from
//! (seed, pixel, sample index), so the result does not depend on the number of threads.

use crate::film::{radiance_to_xyz, Film, PixelSums};
use crate::integrator::{radiance, RayStats};
use crate::sampler::Sampler;
use crate::spectrum::SampledWavelengths;
use crate::world::World;
use rayon::prelude::*;
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

/// Render one pixel's samples `first..first+count` into `sums`.
pub fn render_pixel(
    world: &World,
    x: usize,
    y: usize,
    first: u64,
    count: u64,
    sums: &mut PixelSums,
    stats: &mut RayStats,
) {
    let cam = &world.camera;
    let pixel = (y * cam.width + x) as u64;
    for s in first..first + count {
        let mut sampler = Sampler::new(world.settings.seed, pixel, s);
        let u_wl = sampler.get1d();
        let off = world.settings.filter.sample(sampler.get2d());
        let u_lens = sampler.get2d();
        let mut wl = SampledWavelengths::sample_visible(u_wl);
        let ray = cam.generate_ray(x as f32 + 0.5 + off.x, y as f32 + 0.5 + off.y, u_lens);
        stats.camera_rays += 1;
        let l = radiance(world, ray.origin, ray.dir, &mut wl, &mut sampler, stats);
        if world.settings.illuminance {
            if let Some(e) = surface_illuminance(world, ray.origin, ray.dir, pixel, s, stats) {
                sums.add_illuminance(e);
            }
        }
        let xyz = radiance_to_xyz(&l, &wl);
        if xyz.iter().all(|v| v.is_finite()) {
            sums.add(xyz);
        } else {
            stats.non_finite += 1;
            sums.add([0.0; 3]);
        }
    }
}

/// Stream id of the illuminance estimates (independent of the radiance samples).
const ILLUMINANCE_STREAM: u64 = 0x11_1c_e5_7a_u64 << 20;

/// Illuminance (lx) on the surface a camera ray sees, or None if it sees no receiving surface
/// (nothing, the sky, or an emitter).
fn surface_illuminance(
    world: &World,
    origin: glam::Vec3,
    dir: glam::Vec3,
    pixel: u64,
    sample: u64,
    stats: &mut RayStats,
) -> Option<f64> {
    let hit = world.geometry.intersect(origin, dir, f32::INFINITY)?;
    stats.camera_rays += 1;
    if world.objects[hit.object as usize].light.is_some() {
        return None;
    }
    // The hemisphere on the side of the surface facing the camera.
    let n = if hit.ng.dot(dir) > 0.0 {
        -hit.ng
    } else {
        hit.ng
    };
    let mut sampler = Sampler::new(world.settings.seed ^ ILLUMINANCE_STREAM, pixel, sample);
    let mut wl = SampledWavelengths::sample_visible(sampler.get1d());
    let at = crate::integrator::RayStart::surface(&hit);
    let e = crate::integrator::irradiance(world, &at, n, &mut wl, &mut sampler, stats);
    let lux = radiance_to_xyz(&e, &wl)[1];
    if lux.is_finite() {
        Some(lux)
    } else {
        stats.non_finite += 1;
        Some(0.0)
    }
}

/// Render the whole image with `threads` worker threads (None = all cores), calling
/// `progress(done_tiles, total_tiles)` as tiles finish.
pub fn render(
    world: &World,
    threads: Option<usize>,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> anyhow::Result<RenderResult> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()?;
    let (w, h) = (world.camera.width, world.camera.height);
    let tiles_x = w.div_ceil(TILE);
    let tiles_y = h.div_ceil(TILE);
    let n_tiles = tiles_x * tiles_y;
    let spp = world.settings.spp as u64;
    let done = std::sync::atomic::AtomicU64::new(0);
    let start = Instant::now();
    let results: Vec<(usize, Vec<PixelSums>, RayStats)> = pool.install(|| {
        (0..n_tiles)
            .into_par_iter()
            .map(|t| {
                let (tx, ty) = (t % tiles_x, t / tiles_x);
                let mut stats = RayStats::default();
                let mut sums = Vec::with_capacity(TILE * TILE);
                for y in ty * TILE..((ty + 1) * TILE).min(h) {
                    for x in tx * TILE..((tx + 1) * TILE).min(w) {
                        let mut p = PixelSums::default();
                        render_pixel(world, x, y, 0, spp, &mut p, &mut stats);
                        sums.push(p);
                    }
                }
                let d = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress(d, n_tiles as u64);
                (t, sums, stats)
            })
            .collect()
    });
    let elapsed = start.elapsed();
    let mut film = Film::new(w, h);
    let mut stats = RayStats::default();
    for (t, sums, s) in results {
        stats.merge(&s);
        let (tx, ty) = (t % tiles_x, t / tiles_x);
        let mut k = 0;
        for y in ty * TILE..((ty + 1) * TILE).min(h) {
            for x in tx * TILE..((tx + 1) * TILE).min(w) {
                film.pixels[y * w + x] = sums[k];
                k += 1;
            }
        }
    }
    Ok(RenderResult {
        film,
        stats,
        elapsed,
        threads: pool.current_num_threads(),
    })
}
