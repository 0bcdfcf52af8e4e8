//! Caustics by light tracing: the paths light → specular chain → a non-specular surface seen
//! by the camera (L S⁺ D E in Heckbert's notation) are traced from the light and connected
//! to the camera (Veach 1997, §10.2, the t = 1 strategy of bidirectional path tracing; pbrt-v4's
//! `LightPathIntegrator`), instead of being found by the camera path's BSDF sampling.
//!
//! The path tracer finds such a path only when BSDF sampling at the first surface happens to
//! aim through the specular chain at the (small) light: a few rare samples of very large
//! value, the bright speckles of a caustic. A light path finds the same light transport with
//! an ordinary density, so the caustic converges like direct light. Point and spot lights,
//! whose caustics the path tracer cannot find at all (a delta light behind a delta surface),
//! get theirs here.
//!
//! **Partition, not combination.** Path space is split: the camera path's estimator
//! ([`crate::integrator::trace`]) drops emission reached through "first vertex non-specular,
//! then only specular vertices" when the light is one the light tracer starts paths from
//! ([`CausticLights::handles`]); this module estimates exactly those paths and nothing else.
//! Each estimator is unbiased on its part, so the sum is unbiased, with no MIS weights. The
//! same max depth applies (the non-specular vertex counts as a scattering event, as it does
//! for the camera path).
//!
//! **Estimator.** A light path with weight β (emitted radiance × cos / densities, see
//! [`crate::light::EmissionSample`]; times f·|cos|/pdf at each specular vertex, with the
//! adjoint BSDF: refraction is not scaled by 1/η′²) reaching the non-specular point x adds,
//! to every pixel whose reconstruction filter covers x's film position,
//! `β · f(x; →camera, →light) · |cos θ_x| · importance · filter density`
//! ([`crate::camera::CameraConnection::importance`]). The mean over N light paths is the
//! pixel's value from these paths; its variance is estimated per pixel from Σ and Σ² of the
//! splats with N in the denominator (most light paths add nothing to a given pixel).
//! Shading normals get Veach's adjoint correction |wo·ns||wi·ng| / (|wo·ng||wi·ns|).
//!
//! Light paths are indexed like camera samples and traced in fixed chunks whose splats are
//! applied in order, so images do not depend on the number of threads, and a resumed render
//! equals an uninterrupted one.

use crate::bxdf::Frame;
use crate::film::radiance_to_xyz;
use crate::geometry::SceneGeometry;
use crate::integrator::RayStats;
use crate::light::{pick_from_cdf, Light};
use crate::sampler::Sampler;
use crate::spectrum::SampledWavelengths;
use crate::world::World;
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// The lights light tracing starts paths from (all at a finite position), chosen in
/// proportion to their luminous power.
#[derive(Clone, Debug)]
pub struct CausticLights {
    /// Light indices (into [`World::lights`]).
    lights: Vec<u32>,
    cdf: Vec<f32>,
    /// Per light of the world: whether it is one of `lights`.
    handled: Vec<bool>,
}

impl CausticLights {
    /// None when light tracing has nothing to do: no material with a delta lobe, or no light
    /// at a finite position with power.
    pub fn new(
        lights: &[Light],
        materials: &[crate::bxdf::Material],
        geom: &SceneGeometry,
        scene_radius: f32,
    ) -> Option<Self> {
        if !materials.iter().any(|m| m.has_delta_lobe()) {
            return None;
        }
        let mut chosen = Vec::new();
        let mut powers = Vec::new();
        for (i, l) in lights.iter().enumerate() {
            let p = l.power_lm(geom, scene_radius);
            if l.can_emit_paths() && p > 0.0 && p.is_finite() {
                chosen.push(i as u32);
                powers.push(p);
            }
        }
        if chosen.is_empty() {
            return None;
        }
        let total: f64 = powers.iter().sum();
        let mut acc = 0.0;
        let mut cdf: Vec<f32> = powers
            .iter()
            .map(|p| {
                acc += p / total;
                acc as f32
            })
            .collect();
        *cdf.last_mut().unwrap() = 1.0;
        let mut handled = vec![false; lights.len()];
        for &i in &chosen {
            handled[i as usize] = true;
        }
        Some(Self {
            lights: chosen,
            cdf,
            handled,
        })
    }

    /// Whether emission from light `light` reached through a caustic chain is this module's
    /// part of path space (and so not the camera path's).
    #[inline]
    pub fn handles(&self, light: usize) -> bool {
        self.handled.get(light).copied().unwrap_or(false)
    }
}

/// One light path's contribution to one pixel: absolute XYZ (Y in cd/m²) before division by
/// the number of light paths.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Splat {
    pub pixel: u32,
    pub xyz: [f64; 3],
}

/// Light paths per work item (the unit of parallelism and of the deterministic order).
const CHUNK: u64 = 4096;

/// Trace light paths `first .. first + count` of stream `seed`, in parallel on the current
/// rayon pool; the splats come back in path order. None if `stop` was raised meanwhile.
pub fn trace_light_paths(
    world: &World,
    caustics: &CausticLights,
    seed: u64,
    first: u64,
    count: u64,
    stop: &AtomicBool,
) -> Option<(Vec<Splat>, RayStats)> {
    let chunks = count.div_ceil(CHUNK);
    let parts: Vec<Option<(Vec<Splat>, RayStats)>> = (0..chunks)
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
    let mut splats = Vec::new();
    let mut stats = RayStats::default();
    for part in parts {
        let (s, st) = part?;
        splats.extend(s);
        stats.merge(&st);
    }
    Some((splats, stats))
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
    let settings = &world.settings;
    let mut sampler = Sampler::new(seed, 0, index);
    // Dimension sets led by their 2-D pairs: point on the light and direction; light choice,
    // primitive, wavelengths; lens point. Bounces take one set each from dimension 12.
    let [px, py, dx, dy] = sampler.get4();
    let [u_light, u_prim, u_wl, _] = sampler.get4();
    let [lx, ly, _, _] = sampler.get4();
    stats.light_paths += 1;
    let (k, p_select) = pick_from_cdf(&caustics.cdf, u_light);
    if p_select <= 0.0 {
        return;
    }
    let light = &world.lights[caustics.lights[k] as usize];
    let mut wl = SampledWavelengths::sample_visible(u_wl);
    let Some(es) = light.sample_emission(
        &world.geometry,
        u_prim,
        Vec2::new(px, py),
        Vec2::new(dx, dy),
        &wl,
    ) else {
        return;
    };
    let mut beta = es.weight / p_select;
    // The BSDF factors alone, for Russian roulette.
    let mut throughput = 1.0f32;
    let (mut ray_o, mut ray_d) = (es.origin, es.dir);
    let filter = &settings.filter;
    let camera = &world.camera;
    let (w, h) = (camera.width as i64, camera.height as i64);
    let mut n_specular = 0u32;
    // Scattering events so far, counting the surface being processed.
    let mut depth = 0u32;
    loop {
        stats.light_rays += 1;
        let Some(hit) = world.geometry.intersect(ray_o, ray_d, f32::INFINITY) else {
            return;
        };
        let material = &world.materials[world.objects[hit.object as usize].material as usize];
        if material.is_black() {
            return;
        }
        depth += 1;
        material.prepare(&mut wl);
        let frame = Frame::from_normal(hit.ns);
        let wo_world = -ray_d;
        let wo = frame.to_local(wo_world);
        if wo.z == 0.0 {
            return;
        }

        // The caustic's receiver: connect to the camera.
        if n_specular >= 1 && !material.is_specular() {
            if let Some(c) = camera.connect(hit.p, Vec2::new(lx, ly), filter.radius()) {
                let wi = frame.to_local(c.wi);
                // Radiance convention: out toward the camera, in from the light.
                let f = material.eval(wi, wo, &wl);
                let g = c.wi.dot(hit.ng).abs() * wo_world.dot(hit.ns).abs()
                    / wo_world.dot(hit.ng).abs();
                if !f.is_black() && g > 0.0 && g.is_finite() {
                    stats.shadow_rays += 1;
                    let origin = hit.spawn_origin(c.wi);
                    let t_max = (c.lens_point - origin).length();
                    if !world.geometry.occluded(origin, c.wi, t_max) {
                        let l = beta * f * (g * c.importance);
                        let xyz = radiance_to_xyz(&l, &wl);
                        if xyz.iter().all(|v| v.is_finite()) {
                            let r = filter.radius();
                            let x0 = ((c.film.x - r).floor() as i64).max(0);
                            let x1 = ((c.film.x + r).floor() as i64).min(w - 1);
                            let y0 = ((c.film.y - r).floor() as i64).max(0);
                            let y1 = ((c.film.y + r).floor() as i64).min(h - 1);
                            for y in y0..=y1 {
                                for x in x0..=x1 {
                                    let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                                    let wgt = filter.density(c.film - centre) as f64;
                                    if wgt > 0.0 {
                                        splats.push(Splat {
                                            pixel: (y * w + x) as u32,
                                            xyz: xyz.map(|v| v * wgt),
                                        });
                                    }
                                }
                            }
                        } else {
                            stats.non_finite += 1;
                        }
                    }
                }
            }
        }

        // Only specular scattering continues a caustic chain, and only while the receiver
        // it may still reach is within the depth limit.
        if depth >= settings.max_depth || !material.has_delta_lobe() {
            return;
        }
        let [ux, uy, uc, u_rr] = sampler.get4();
        let Some(bs) = material.sample(wo, uc, Vec2::new(ux, uy), &mut wl) else {
            return;
        };
        if !bs.specular || bs.pdf.is_nan() || bs.pdf <= 0.0 {
            return;
        }
        let wi_world = frame.to_world(bs.wi);
        // Adjoint BSDF: f·|cos|/pdf with the refraction's 1/η′² undone, and the
        // shading-normal correction.
        let k = bs.wi.z.abs() / bs.pdf
            * material.eta_scale(wo, bs.wi, &wl)
            * shading_normal_correction(wo_world, wi_world, hit.ns, hit.ng);
        beta *= bs.f * k;
        throughput *= bs.f.max_component() * k;
        if beta.is_black() || !k.is_finite() {
            return;
        }
        n_specular += 1;
        if depth > settings.rr_depth && throughput < 1.0 {
            let q = (1.0 - throughput).max(0.0);
            if u_rr < q {
                return;
            }
            beta = beta / (1.0 - q);
            throughput /= 1.0 - q;
        }
        ray_o = hit.spawn_origin(wi_world);
        ray_d = wi_world.normalize();
    }
}
