//! Caustics by light tracing: paths whose light leaves the source by a specular scattering
//! (smooth glass, mirror) and reaches the camera from a non-specular surface are traced from
//! the light and connected to the camera (Veach 1997 §10.2, pbrt-v4's `LightPathIntegrator`).
//! They are a partition of path space with the camera paths ([`super::path::trace`]), so the
//! sum is unbiased without MIS weights; the method is in docs/methods.md.

use super::stats::RayStats;
use super::transmit::{choose_pane_lobe, transmittance_counted, PaneLobe, MAX_STRAIGHT_THROUGH};
use crate::bxdf::Frame;
use crate::film::radiance_to_xyz;
use crate::light::Light;
use crate::sampling::pick_from_cdf;
use crate::sampling::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::{CausticLights, World};
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// One camera connection of a light path: its film position and its contribution (absolute
/// XYZ, Y in cd/m², before the pixel filter's density and the division by the number of light
/// paths), expanded over the pixels the filter covers when the splats are applied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Splat {
    /// Index of the light path (consecutive splats of one path share it).
    pub path: u64,
    /// Film position (pixels).
    pub film: Vec2,
    pub xyz: [f64; 3],
    /// Illuminance (lx) on the surface, for the per-pixel illuminance channel.
    pub e: f64,
}

/// Light paths per work item (the unit of parallelism and of the deterministic order).
const CHUNK: u64 = 4096;
/// Work items whose splats are held at once (bounds the memory of a pass's splats).
const CHUNKS_PER_BATCH: u64 = 64;

/// Trace light paths `first .. first + count` of stream `seed`, in parallel on the current
/// rayon pool, and add their splats to `sums` (per pixel: Σ X, Σ Y, Σ Z, Σ Y², Σ E, Σ E²) in
/// path order, so the sums do not depend on the number of threads. None if `stop` was raised meanwhile
/// (`sums` is then partial).
pub fn trace_light_paths(
    world: &World,
    caustics: &CausticLights,
    seed: u64,
    first: u64,
    count: u64,
    stop: &AtomicBool,
    sums: &mut [[f64; 6]],
) -> Option<RayStats> {
    let mut stats = RayStats::default();
    let chunks = count.div_ceil(CHUNK);
    for batch in (0..chunks).step_by(CHUNKS_PER_BATCH as usize) {
        let parts: Vec<Option<(Vec<Splat>, RayStats)>> = (batch
            ..(batch + CHUNKS_PER_BATCH).min(chunks))
            .into_par_iter()
            .map(|c| {
                if stop.load(Ordering::Relaxed) {
                    return None;
                }
                let mut splats = Vec::new();
                let mut stats = RayStats::default();
                let lo = first + c * CHUNK;
                let hi = (lo + CHUNK).min(first + count);
                for index in lo..hi {
                    trace_light_path(world, caustics, seed, index, &mut splats, &mut stats);
                }
                Some((splats, stats))
            })
            .collect();
        let mut path_pixels = Vec::new();
        for part in parts {
            let (splats, st) = part?;
            stats.merge(&st);
            // One path at a time: its contributions per pixel are summed before they are
            // squared (the variance is over paths, and one path may reach a pixel twice).
            for path in splats.chunk_by(|a, b| a.path == b.path) {
                for s in path {
                    expand_splat(world, s, &mut path_pixels);
                }
                path_pixels.sort_unstable_by_key(|&(pixel, _, _)| pixel);
                for run in path_pixels.chunk_by(|a, b| a.0 == b.0) {
                    let (mut xyz, mut e) = ([0.0f64; 3], 0.0f64);
                    for &(_, x, ei) in run {
                        (0..3).for_each(|k| xyz[k] += x[k]);
                        e += ei;
                    }
                    let t = &mut sums[run[0].0 as usize];
                    t[0] += xyz[0];
                    t[1] += xyz[1];
                    t[2] += xyz[2];
                    t[3] += xyz[1] * xyz[1];
                    t[4] += e;
                    t[5] += e * e;
                }
                path_pixels.clear();
            }
        }
    }
    Some(stats)
}

/// The pixels a splat's filter footprint covers, with the splat weighted by the filter
/// density at each pixel centre, appended to `out` as (pixel, XYZ, E).
fn expand_splat(world: &World, s: &Splat, out: &mut Vec<(u32, [f64; 3], f64)>) {
    let filter = &world.settings.filter;
    let (w, h) = (world.camera.width as i64, world.camera.height as i64);
    let r = filter.radius();
    let x0 = ((s.film.x - r).floor() as i64).max(0);
    let x1 = ((s.film.x + r).floor() as i64).min(w - 1);
    let y0 = ((s.film.y - r).floor() as i64).max(0);
    let y1 = ((s.film.y + r).floor() as i64).min(h - 1);
    for y in y0..=y1 {
        for x in x0..=x1 {
            let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let wgt = filter.density(s.film - centre) as f64;
            if wgt > 0.0 {
                out.push(((y * w + x) as u32, s.xyz.map(|v| v * wgt), s.e * wgt));
            }
        }
    }
}

/// |wo·ns||wi·ng| / (|wo·ng||wi·ns|): the factor that makes a BSDF with shading normals
/// adjoint for light travelling from `wo` to `wi` (Veach 1997, §5.3; 1 without shading
/// normals). 0 where a denominator vanishes.
#[inline]
fn shading_normal_correction(wo: Vec3, wi: Vec3, ns: Vec3, ng: Vec3) -> f32 {
    let den = wo.dot(ng).abs() * wi.dot(ns).abs();
    if den == 0.0 {
        return 0.0;
    }
    wo.dot(ns).abs() * wi.dot(ng).abs() / den
}

/// Trace light path `index` of stream `seed`, appending its splats.
pub fn trace_light_path(
    world: &World,
    caustics: &CausticLights,
    seed: u64,
    index: u64,
    splats: &mut Vec<Splat>,
    stats: &mut RayStats,
) {
    let mut sampler = Sampler::new(seed, 0, index);
    let Some((mut path, mut wl, u_lens)) = LightPath::start(world, caustics, &mut sampler, stats)
    else {
        return;
    };
    loop {
        stats.light_rays += 1;
        let Some(hit) = world
            .geometry
            .intersect(path.ray_o, path.ray_d, f32::INFINITY)
        else {
            return;
        };
        let object = world.objects[hit.object as usize];
        let material = &world.materials[object.material as usize];
        let (material, normal_map) = material.normal_map();
        let hit = match normal_map {
            Some(m) => super::normal_mapped(world, m, hit),
            None => hit,
        };
        let textured;
        let material = match material.at_texture(hit.tex, &wl) {
            Some(m) => {
                textured = m;
                &textured
            }
            None => material,
        };
        // A black surface ends the path, but still receives illuminance (below).
        let black = material.flags().contains(crate::bxdf::MaterialFlags::BLACK);
        path.depth += 1;
        material.prepare(&mut wl);
        let frame = material.shading_frame(hit.ns);
        let wo_world = -path.ray_d;
        let wo = frame.to_local(wo_world);
        if wo.z == 0.0 {
            return;
        }
        let at = Vertex {
            material,
            hit: &hit,
            frame: &frame,
            wo,
            wo_world,
            normal_mapped: normal_map.is_some(),
        };

        // A surface after the first (which scattered specularly): connect to the camera, for
        // the luminance the surface sends toward it (non-specular surfaces) and, with the
        // per-pixel illuminance on, for the illuminance on it (any surface but an emitter,
        // on the side the camera sees).
        let want_l = !black
            && !material
                .flags()
                .contains(crate::bxdf::MaterialFlags::ALL_DELTA);
        let want_e = world.settings.illuminance && object.light.is_none();
        if path.depth >= 2 && (want_l || want_e) {
            let want = (want_l, want_e);
            connect_to_camera(
                world, &at, want, path.beta, &wl, u_lens, index, splats, stats,
            );
        }

        let chosen = match path.pane(material, wo, &hit, &mut sampler, &mut wl) {
            Pane::Absorbed => return,
            Pane::Through => continue,
            Pane::Scatter(chosen) => chosen,
        };
        if path.ends_at(world, material, black, stats) {
            return;
        }
        if !path.scatter(world, &at, chosen, &mut sampler, &mut wl) {
            return;
        }
    }
}

/// The state of a light path between its vertices: its flux, the ray it follows, and what
/// Russian roulette and the depth limits need.
struct LightPath {
    /// Flux per path (W/nm at the path's wavelengths).
    beta: SampledSpectrum,
    /// The BSDF factors alone, for Russian roulette.
    throughput: f32,
    ray_o: Vec3,
    ray_d: Vec3,
    /// Scattering events so far, counting the surface being processed.
    depth: u32,
    /// Null events (straight through window panes) since the last scattering.
    straight_through: u32,
}

/// What a window pane did with the path.
enum Pane {
    /// Nothing more comes along the path.
    Absorbed,
    /// Straight through: a null event, the ray goes on from the far side.
    Through,
    /// A lobe that scatters (reflection or a rough lobe), or None for another material.
    Scatter(Option<crate::bxdf::BsdfSample>),
}

impl LightPath {
    /// The path leaving its light, with its wavelengths and the lens point of its camera
    /// connections; None when its sample carries nothing. Dimension sets led by their 2-D
    /// pairs: point on the light and direction; light choice, primitive, wavelengths, target
    /// cone; lens point. Bounces take one set each from dimension 12.
    #[inline(always)]
    fn start(
        world: &World,
        caustics: &CausticLights,
        sampler: &mut Sampler,
        stats: &mut RayStats,
    ) -> Option<(Self, SampledWavelengths, Vec2)> {
        let [px, py, dx, dy] = sampler.get4();
        let [u_light, u_prim, u_wl, u_dir] = sampler.get4();
        let [lx, ly, _, _] = sampler.get4();
        stats.light_paths += 1;
        let (k, p_select) = pick_from_cdf(&caustics.cdf, u_light);
        if p_select <= 0.0 {
            return None;
        }
        let light = &world.lights[caustics.lights[k] as usize];
        let wl = SampledWavelengths::sample_visible(u_wl);
        let u = (u_prim, u_dir, Vec2::new(px, py), Vec2::new(dx, dy));
        let (origin, dir, beta) = leave_light(world, caustics, light, p_select, u, &wl)?;
        let path = LightPath {
            beta,
            throughput: 1.0,
            ray_o: origin,
            ray_d: dir,
            depth: 0,
            straight_through: 0,
        };
        Some((path, wl, Vec2::new(lx, ly)))
    }

    /// A window pane: passing straight through is a null event, as for the camera paths
    /// (not a scattering: the depth and the "first scattering is specular" rule are those of
    /// the path without it). The illuminance on the pane itself is recorded on arrival,
    /// whichever lobe is then chosen.
    #[inline(always)]
    fn pane(
        &mut self,
        material: &crate::bxdf::Material,
        wo: Vec3,
        hit: &crate::geometry::Hit,
        sampler: &mut Sampler,
        wl: &mut SampledWavelengths,
    ) -> Pane {
        if !material
            .flags()
            .contains(crate::bxdf::MaterialFlags::STRAIGHT_THROUGH)
        {
            return Pane::Scatter(None);
        }
        match choose_pane_lobe(material, wo, sampler, wl) {
            None => Pane::Absorbed,
            Some(PaneLobe::Straight(weight)) => {
                self.beta *= weight;
                self.depth -= 1;
                self.straight_through += 1;
                if self.beta.is_black() || self.straight_through > MAX_STRAIGHT_THROUGH {
                    return Pane::Absorbed;
                }
                self.ray_o = hit.spawn_origin(self.ray_d);
                Pane::Through
            }
            Some(PaneLobe::Scatter(bs)) => Pane::Scatter(Some(bs)),
        }
    }

    /// Whether the path ends at this surface rather than scatter: it continues while a
    /// further surface is within the depth limit, and its first scattering must be specular
    /// (the paths whose light-side end is non-specular are the camera paths' part).
    #[inline(always)]
    fn ends_at(
        &self,
        world: &World,
        material: &crate::bxdf::Material,
        black: bool,
        stats: &mut RayStats,
    ) -> bool {
        let depth = self.depth;
        if black || (depth == 1 && !material.flags().contains(crate::bxdf::MaterialFlags::DELTA)) {
            return true;
        }
        if world.settings.max_depth.is_some_and(|max| depth >= max) {
            stats.truncated_paths += 1;
            return true;
        }
        false
    }

    /// Continue the path by sampling the BSDF at `at` (or the pane's `chosen` lobe) with its
    /// adjoint, then Russian roulette; false when the path ends.
    #[inline(always)]
    fn scatter(
        &mut self,
        world: &World,
        at: &Vertex,
        chosen: Option<crate::bxdf::BsdfSample>,
        sampler: &mut Sampler,
        wl: &mut SampledWavelengths,
    ) -> bool {
        let (material, hit, wo, wo_world) = (at.material, at.hit, at.wo, at.wo_world);
        let [ux, uy, uc, u_rr] = sampler.get4();
        let Some(bs) = chosen.or_else(|| material.sample(wo, uc, Vec2::new(ux, uy), wl)) else {
            return false;
        };
        if (self.depth == 1 && !bs.specular) || bs.pdf.is_nan() || bs.pdf <= 0.0 {
            return false;
        }
        let wi_world = at.frame.to_world(bs.wi);
        if at.normal_mapped && crate::bxdf::normal_map::leaks(wo_world, wi_world, hit.ns, hit.ng) {
            return false;
        }
        // Adjoint BSDF: f·|cos|/pdf with the refraction's 1/η′² undone, and the
        // shading-normal correction.
        let k = bs.wi.z.abs() / bs.pdf
            * material.eta_scale(wo, bs.wi, wl)
            * shading_normal_correction(wo_world, wi_world, hit.ns, hit.ng);
        self.beta *= bs.f * k;
        self.throughput *= bs.f.max_component() * k;
        if self.beta.is_black() || !k.is_finite() {
            return false;
        }
        if self.depth > world.settings.rr_depth {
            let p = super::survival_probability(self.throughput);
            if u_rr < 1.0 - p {
                return false;
            }
            self.beta = self.beta / p;
            self.throughput /= p;
        }
        self.straight_through = 0;
        self.ray_o = hit.spawn_origin(wi_world);
        self.ray_d = wi_world.normalize();
        true
    }
}

/// Where light path leaves `light` (chosen with probability `p_select`) and its flux per path
/// (W/nm at `wl`); None when the sample carries nothing. `u` are the primitive's and the
/// direction's numbers and the 2-D pairs of the point and the direction.
fn leave_light(
    world: &World,
    caustics: &CausticLights,
    light: &Light,
    p_select: f32,
    (u_prim, u_dir, u_point, u_cone): (f32, f32, Vec2, Vec2),
    wl: &SampledWavelengths,
) -> Option<(Vec3, Vec3, SampledSpectrum)> {
    if let Light::Distant(crate::light::DistantLight {
        to_light,
        irradiance,
    }) = light
    {
        // Parallel light: flux per path = irradiance normal to the beam / density per area.
        let dir = -*to_light;
        let (origin, pdf_area) = caustics.sample_parallel(dir, u_dir, u_cone)?;
        let e = irradiance.sample(wl);
        if e.is_black() || pdf_area.is_nan() || pdf_area <= 0.0 {
            return None;
        }
        return Some((origin, dir, e * (1.0 / (pdf_area * p_select))));
    }
    let at = light.sample_emission_point(&world.geometry, u_prim, u_point)?;
    let (dir, pdf_dir) = caustics.sample_direction(at.p, u_dir, u_cone)?;
    let le = light.emission_toward(&at, dir, wl);
    if le.is_black() || pdf_dir.is_nan() || pdf_dir <= 0.0 {
        return None;
    }
    let origin = match at.n {
        Some(n) => crate::geometry::offset_ray_origin(
            at.p,
            crate::geometry::point_error_bound(at.p),
            n,
            dir,
        ),
        None => at.p,
    };
    Some((origin, dir, le * (at.inv_pdf / (pdf_dir * p_select))))
}

/// A surface a light path reached: its material (normal-mapped and textured), hit, shading
/// frame and the direction back toward the light.
struct Vertex<'a> {
    material: &'a crate::bxdf::Material,
    hit: &'a crate::geometry::Hit,
    frame: &'a Frame,
    /// The direction toward the light, local and in the world.
    wo: Vec3,
    wo_world: Vec3,
    normal_mapped: bool,
}

/// Connect a surface after the first (which scattered specularly) to the camera, for the
/// luminance the surface sends toward it and the illuminance on it (`want`: each of them),
/// with the path's flux `beta`; a visible connection is appended to `splats` as path `index`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn connect_to_camera(
    world: &World,
    at: &Vertex,
    (want_l, want_e): (bool, bool),
    beta: SampledSpectrum,
    wl: &SampledWavelengths,
    u_lens: Vec2,
    index: u64,
    splats: &mut Vec<Splat>,
    stats: &mut RayStats,
) {
    let (hit, wo_world) = (at.hit, at.wo_world);
    let Some(c) = world
        .camera
        .connect(hit.p, u_lens, world.settings.filter.radius())
    else {
        return;
    };
    let cos_cam = c.wi.dot(hit.ng).abs();
    let mut l = SampledSpectrum::ZERO;
    let leak = at.normal_mapped && crate::bxdf::normal_map::leaks(wo_world, c.wi, hit.ns, hit.ng);
    if want_l && !leak {
        let wi = at.frame.to_local(c.wi);
        // Radiance convention: out toward the camera, in from the light.
        let f = at.material.eval(wi, at.wo, wl);
        let g = cos_cam * wo_world.dot(hit.ns).abs() / wo_world.dot(hit.ng).abs();
        if !f.is_black() && g > 0.0 && g.is_finite() {
            l = beta * f * (g * c.importance);
        }
    }
    let mut e = SampledSpectrum::ZERO;
    if want_e && c.wi.dot(hit.ng) * wo_world.dot(hit.ng) > 0.0 {
        e = beta * (cos_cam * c.importance);
    }
    if l.is_black() && e.is_black() {
        return;
    }
    stats.shadow_rays += 1;
    let origin = hit.spawn_origin(c.wi);
    let t_max = (c.lens_point - origin).length();
    // Through window panes with their transmittance, as the camera paths see through them (a
    // pane's straight transmission is a null event). The illuminance channel is the
    // illuminance on the first surface the camera ray meets, so a surface behind a pane gives
    // it nothing (the pane itself receives its own splats on arrival).
    let Some((tr, panes)) = transmittance_counted(world, origin, c.wi, t_max, wl) else {
        return;
    };
    let xyz = radiance_to_xyz(&(l * tr), wl);
    let e = if panes == 0 {
        radiance_to_xyz(&e, wl)[1]
    } else {
        0.0
    };
    if !(xyz.iter().all(|v| v.is_finite()) && e.is_finite()) {
        stats.non_finite += 1;
    } else if xyz.iter().any(|&v| v != 0.0) || e != 0.0 {
        splats.push(Splat {
            path: index,
            film: c.film,
            xyz,
            e,
        });
    }
}
