//! Caustics by light tracing: the paths whose light leaves the source by a *specular*
//! scattering (smooth glass, mirror) and reaches the camera from a *non-specular* surface —
//! L S (S|D)* D E in Heckbert's notation: the caustic under a glass sphere, and the light that
//! caustic sends on to walls and ceiling, directly or again through the glass — are traced
//! from the light and connected to the camera at every non-specular surface they reach
//! (Veach 1997, §10.2, the t = 1 strategy of bidirectional path tracing; pbrt-v4's
//! `LightPathIntegrator`), instead of being found by the camera paths' BSDF sampling.
//!
//! A camera path finds such a path only when BSDF sampling at its last surface happens to aim
//! through the specular surface at the (small) light: rare samples of very large value, the
//! bright speckles of caustics. Next-event estimation cannot help (the light is behind glass).
//! A light path finds the same light transport with an ordinary density, so caustics converge
//! like direct light. Point and spot lights, whose caustics camera paths cannot find at all (a
//! delta light behind a delta surface), get theirs here.
//!
//! **Partition, not combination.** Path space is split by two vertices: the one next to the
//! light and the one next to the camera. Paths whose light-side vertex scattered specularly
//! and whose camera-side vertex scattered non-specularly (with at least two scattering
//! events), from a light this module starts paths from ([`CausticLights::handles`]), are light
//! tracing's; the camera paths' estimator ([`crate::integrator::trace`]) drops the emission it
//! finds along them and keeps every other path (next-event estimation only ever connects a
//! non-specular vertex to the light, so it keeps all of its own). Each estimator is unbiased on
//! its part, so the sum is unbiased, without MIS weights. Paths the camera sees through glass
//! (camera-side vertex specular) stay with the camera paths. The same max depth applies.
//! Passing straight through a window pane ([`crate::bxdf::MaterialFlags::STRAIGHT_THROUGH`]) is a
//! null event on both sides, not a scattering: it neither counts as a vertex nor decides the
//! split, and next-event estimation and the camera connections cross panes with their
//! transmittance ([`crate::integrator::transmittance`]). Sunlight through a window is thus the
//! camera paths' (light sampling) part; the pane's mirror reflection stays light tracing's.
//!
//! **Estimator.** A light path starts at a point on a light and leaves toward the bounding
//! sphere of one of the objects that can scatter specularly (the other directions cannot start
//! a path of this part). Its weight β is the emission toward that direction (radiance × cos,
//! or intensity) over the densities of point and direction ([`crate::light::EmissionPoint`]),
//! times f·|cos|/pdf at each scattering, with the
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
use crate::integrator::{
    choose_pane_lobe, transmittance_counted, PaneLobe, RayStats, MAX_STRAIGHT_THROUGH,
};
use crate::light::Light;
use crate::sampling::Sampler;
use crate::sampling::{choose_by_weight, pick_from_cdf};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// The lights light tracing starts paths from (all but environments), chosen in
/// proportion to their luminous power, and where their paths are aimed.
#[derive(Clone, Debug)]
pub struct CausticLights {
    /// Light indices (into [`World::lights`]).
    lights: Vec<u32>,
    cdf: Vec<f32>,
    /// Per light of the world: whether it is one of `lights`.
    handled: Vec<bool>,
    /// Bounding spheres (centre, radius) of the objects with a delta lobe. A light path is
    /// only light tracing's if its first scattering is specular, so emission directions are
    /// sampled only toward these (uniformly within the cones they subtend), not wasted on
    /// the rest of the scene.
    targets: Vec<(Vec3, f32)>,
    /// Bounding sphere (centre, radius) of the scene: paths of distant lights start outside it.
    scene: (Vec3, f32),
}

/// Most target spheres kept separately; more are merged into one.
const MAX_TARGETS: usize = 16;

/// A bounding sphere of a shape (of its bounding box, for flat and meshed shapes).
pub fn bounding_sphere(shape: &crate::geometry::Shape) -> Option<(Vec3, f32)> {
    use crate::geometry::Shape;
    let from_points = |pts: &mut dyn Iterator<Item = Vec3>| {
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for p in pts {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        (lo.cmple(hi).all()).then(|| sphere_of_box(lo, hi))
    };
    match shape {
        // The same slack as boxes get (rays may hit a hair outside the exact radius).
        Shape::Sphere { center, radius } | Shape::Disk { center, radius, .. } => {
            Some((*center, *radius * (1.0 + 1e-4) + 1e-6))
        }
        Shape::Quad {
            origin,
            edge_u,
            edge_v,
        } => from_points(
            &mut [
                *origin,
                *origin + *edge_u,
                *origin + *edge_v,
                *origin + *edge_u + *edge_v,
            ]
            .into_iter(),
        ),
        Shape::Mesh(m) => from_points(&mut m.positions.iter().copied()),
    }
}

fn sphere_of_box(lo: Vec3, hi: Vec3) -> (Vec3, f32) {
    let c = 0.5 * (lo + hi);
    // A little slack: the sphere must contain every point a ray can hit.
    (c, 0.5 * (hi - lo).length() * (1.0 + 1e-4) + 1e-6)
}

impl CausticLights {
    /// `targets`: bounding spheres of the objects whose material has a delta lobe. None when
    /// light tracing has nothing to do: no such object, or no light other than an environment with
    /// power.
    pub fn new(
        lights: &[Light],
        mut targets: Vec<(Vec3, f32)>,
        geom: &SceneGeometry,
        scene_radius: f32,
    ) -> Option<Self> {
        targets.retain(|(c, r)| c.is_finite() && r.is_finite() && *r > 0.0);
        if targets.is_empty() {
            return None;
        }
        if targets.len() > MAX_TARGETS {
            let lo = targets
                .iter()
                .fold(Vec3::splat(f32::INFINITY), |a, (c, r)| a.min(*c - *r));
            let hi = targets
                .iter()
                .fold(Vec3::splat(f32::NEG_INFINITY), |a, (c, r)| a.max(*c + *r));
            targets = vec![sphere_of_box(lo, hi)];
        }
        let mut chosen = Vec::new();
        let mut powers = Vec::new();
        for (i, l) in lights.iter().enumerate() {
            let p = l.power_lm(geom, scene_radius);
            if l.flags().can_emit_paths() && p > 0.0 && p.is_finite() {
                chosen.push(i as u32);
                powers.push(p);
            }
        }
        if chosen.is_empty() {
            return None;
        }
        let cdf = crate::sampling::cdf_from_weights(&powers);
        let mut handled = vec![false; lights.len()];
        for &i in &chosen {
            handled[i as usize] = true;
        }
        let (lo, hi) = geom.bounds();
        let scene = if lo.is_finite() && hi.is_finite() && hi.cmpge(lo).all() {
            sphere_of_box(lo, hi)
        } else {
            (Vec3::ZERO, scene_radius)
        };
        Some(Self {
            lights: chosen,
            cdf,
            handled,
            targets,
            scene,
        })
    }

    /// Where a path of a distant light travelling along `dir` starts: a point of the disks the
    /// targets' bounding spheres project onto a plane normal to `dir` (a disk chosen in
    /// proportion to its area, uniform within it), moved back along `dir` to outside the
    /// scene. Returns the origin and the density per unit area normal to `dir`: (number of
    /// disks containing the point) / (sum of the disks' areas).
    fn sample_parallel(&self, dir: Vec3, uc: f32, u: Vec2) -> Option<(Vec3, f32)> {
        use std::f32::consts::PI;
        let area = |&(_, r): &(Vec3, f32)| PI * r * r;
        let total: f32 = self.targets.iter().map(area).sum();
        if total.is_nan() || total <= 0.0 {
            return None;
        }
        let chosen = choose_by_weight(
            self.targets.iter().map(|t| area(t) as f64),
            (uc * total) as f64,
        );
        let (c, r) = self.targets[chosen];
        let (t, b) = dir.any_orthonormal_pair();
        let (s, phi) = crate::sampling::uniform_disk_polar(u);
        let rad = r * s;
        let p = c + rad * (phi.cos() * t + phi.sin() * b);
        let count = 1 + self
            .targets
            .iter()
            .enumerate()
            .filter(|&(k, &(cj, rj))| {
                let v = p - cj;
                k != chosen && (v - v.dot(dir) * dir).length_squared() <= rj * rj
            })
            .count();
        // Back along the line to outside the scene's bounding sphere.
        let (cs, rs) = self.scene;
        let back = (p - cs).dot(dir) + 1.01 * rs + 1e-3;
        Some((p - back * dir, count as f32 / total))
    }

    /// A direction from `p` toward the targets and its density (solid angle): a cone chosen in
    /// proportion to its solid angle, uniform within it, so the density is (number of cones
    /// containing the direction) / (sum of the cones' solid angles). Uniform over the sphere
    /// when the cones would cover more than it.
    fn sample_direction(&self, p: Vec3, uc: f32, u: Vec2) -> Option<(Vec3, f32)> {
        use glam::DVec3;
        use std::f64::consts::PI;
        // In f64 and without cancellation, so that small or distant targets (r/d down to
        // ~1e-150) keep their exact cones: per cone, the axis, sin²θmax = r²/d² (≥ 1: the
        // point is inside, the cone is the whole sphere) and 1 − cos θmax = s / (1 + √(1 − s)).
        let p = p.as_dvec3();
        let mut cones = [(DVec3::ZERO, 0.0f64, 0.0f64); MAX_TARGETS];
        let mut total = 0.0f64;
        for (k, &(c, r)) in self.targets.iter().enumerate() {
            let d = c.as_dvec3() - p;
            let dist2 = d.length_squared();
            let r = r as f64;
            let sin2 = if dist2 > 0.0 { r * r / dist2 } else { 1.0 };
            let omc = if sin2 >= 1.0 {
                2.0
            } else {
                sin2 / (1.0 + (1.0 - sin2).sqrt())
            };
            let axis = if dist2 > 0.0 {
                d / dist2.sqrt()
            } else {
                DVec3::Z
            };
            cones[k] = (axis, sin2, omc);
            total += 2.0 * PI * omc;
        }
        let cones = &cones[..self.targets.len()];
        if total.is_nan() || total <= 0.0 {
            return None;
        }
        if total >= 4.0 * PI {
            return Some((
                crate::sampling::uniform_sphere(u),
                (1.0 / (4.0 * PI)) as f32,
            ));
        }
        // Choose a cone in proportion to its solid angle.
        let chosen = choose_by_weight(cones.iter().map(|c| 2.0 * PI * c.2), uc as f64 * total);
        let (axis, _, omc) = cones[chosen];
        // Uniform within the cone: 1 − cos θ uniform in [0, 1 − cos θmax].
        let (cos_t, sin_t, phi) = crate::sampling::uniform_cone(u.x as f64, u.y as f64, omc);
        let (t, b) = axis.any_orthonormal_pair();
        let dir = (sin_t * phi.cos() * t + sin_t * phi.sin() * b + cos_t * axis).normalize();
        // Inside cone k: the whole sphere, or on the axis' side within sin²θ ≤ sin²θmax.
        let count = 1 + cones
            .iter()
            .enumerate()
            .filter(|&(k, c)| {
                k != chosen
                    && (c.1 >= 1.0
                        || (dir.dot(c.0) > 0.0 && dir.cross(c.0).length_squared() <= c.1))
            })
            .count();
        Some((dir.as_vec3(), (count as f64 / total) as f32))
    }

    /// Whether emission from light `light` reached through a caustic chain is this module's
    /// part of path space (and so not the camera path's).
    #[inline]
    pub fn handles(&self, light: usize) -> bool {
        self.handled.get(light).copied().unwrap_or(false)
    }
}

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
    let settings = &world.settings;
    let mut sampler = Sampler::new(seed, 0, index);
    // Dimension sets led by their 2-D pairs: point on the light and direction; light choice,
    // primitive, wavelengths, target cone; lens point. Bounces take one set each from dimension 12.
    let [px, py, dx, dy] = sampler.get4();
    let [u_light, u_prim, u_wl, u_dir] = sampler.get4();
    let [lx, ly, _, _] = sampler.get4();
    stats.light_paths += 1;
    let (k, p_select) = pick_from_cdf(&caustics.cdf, u_light);
    if p_select <= 0.0 {
        return;
    }
    let light = &world.lights[caustics.lights[k] as usize];
    let mut wl = SampledWavelengths::sample_visible(u_wl);
    let (origin, dir, mut beta) = if let Light::Distant(crate::light::DistantLight {
        to_light,
        irradiance,
    }) = light
    {
        // Parallel light: flux per path = irradiance normal to the beam / density per area.
        let dir = -*to_light;
        let Some((origin, pdf_area)) = caustics.sample_parallel(dir, u_dir, Vec2::new(dx, dy))
        else {
            return;
        };
        let e = irradiance.sample(&wl);
        if e.is_black() || pdf_area.is_nan() || pdf_area <= 0.0 {
            return;
        }
        (origin, dir, e * (1.0 / (pdf_area * p_select)))
    } else {
        let Some(at) = light.sample_emission_point(&world.geometry, u_prim, Vec2::new(px, py))
        else {
            return;
        };
        let Some((dir, pdf_dir)) = caustics.sample_direction(at.p, u_dir, Vec2::new(dx, dy)) else {
            return;
        };
        let le = light.emission_toward(&at, dir, &wl);
        if le.is_black() || pdf_dir.is_nan() || pdf_dir <= 0.0 {
            return;
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
        (origin, dir, le * (at.inv_pdf / (pdf_dir * p_select)))
    };
    // The BSDF factors alone, for Russian roulette.
    let mut throughput = 1.0f32;
    let (mut ray_o, mut ray_d) = (origin, dir);
    let filter = &settings.filter;
    let camera = &world.camera;
    // Scattering events so far, counting the surface being processed.
    let mut depth = 0u32;
    // Null events (straight through window panes) since the last scattering.
    let mut straight_through = 0u32;
    loop {
        stats.light_rays += 1;
        let Some(hit) = world.geometry.intersect(ray_o, ray_d, f32::INFINITY) else {
            return;
        };
        let object = world.objects[hit.object as usize];
        let material = &world.materials[object.material as usize];
        // A black surface ends the path, but still receives illuminance (below).
        let black = material.flags().contains(crate::bxdf::MaterialFlags::BLACK);
        depth += 1;
        material.prepare(&mut wl);
        let frame = Frame::from_normal(hit.ns);
        let wo_world = -ray_d;
        let wo = frame.to_local(wo_world);
        if wo.z == 0.0 {
            return;
        }

        // A surface after the first (which scattered specularly): connect to the camera, for
        // the luminance the surface sends toward it (non-specular surfaces) and, with the
        // per-pixel illuminance on, for the illuminance on it (any surface but an emitter,
        // on the side the camera sees).
        let want_l = !black
            && !material
                .flags()
                .contains(crate::bxdf::MaterialFlags::ALL_DELTA);
        let want_e = settings.illuminance && object.light.is_none();
        if depth >= 2 && (want_l || want_e) {
            if let Some(c) = camera.connect(hit.p, Vec2::new(lx, ly), filter.radius()) {
                let cos_cam = c.wi.dot(hit.ng).abs();
                let mut l = SampledSpectrum::ZERO;
                if want_l {
                    let wi = frame.to_local(c.wi);
                    // Radiance convention: out toward the camera, in from the light.
                    let f = material.eval(wi, wo, &wl);
                    let g = cos_cam * wo_world.dot(hit.ns).abs() / wo_world.dot(hit.ng).abs();
                    if !f.is_black() && g > 0.0 && g.is_finite() {
                        l = beta * f * (g * c.importance);
                    }
                }
                let mut e = SampledSpectrum::ZERO;
                if want_e && c.wi.dot(hit.ng) * wo_world.dot(hit.ng) > 0.0 {
                    e = beta * (cos_cam * c.importance);
                }
                if !(l.is_black() && e.is_black()) {
                    stats.shadow_rays += 1;
                    let origin = hit.spawn_origin(c.wi);
                    let t_max = (c.lens_point - origin).length();
                    // Through window panes with their transmittance, as the camera paths
                    // see through them (a pane's straight transmission is a null event). The
                    // illuminance channel is the illuminance on the first surface the camera
                    // ray meets, so a surface behind a pane gives it nothing (the pane itself
                    // receives its own splats on arrival).
                    if let Some((tr, panes)) =
                        transmittance_counted(world, origin, c.wi, t_max, &wl)
                    {
                        let xyz = radiance_to_xyz(&(l * tr), &wl);
                        let e = if panes == 0 {
                            radiance_to_xyz(&e, &wl)[1]
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
                }
            }
        }

        // A window pane: passing straight through is a null event, as for the camera paths
        // (not a scattering: the depth and the "first scattering is specular" rule are those
        // of the path without it). The illuminance on the pane itself was recorded above, on
        // arrival, whichever lobe is then chosen.
        let mut chosen = None;
        if material
            .flags()
            .contains(crate::bxdf::MaterialFlags::STRAIGHT_THROUGH)
        {
            match choose_pane_lobe(material, wo, &mut sampler, &mut wl) {
                None => return,
                Some(PaneLobe::Straight(weight)) => {
                    beta *= weight;
                    depth -= 1;
                    straight_through += 1;
                    if beta.is_black() || straight_through > MAX_STRAIGHT_THROUGH {
                        return;
                    }
                    ray_o = hit.spawn_origin(ray_d);
                    continue;
                }
                Some(PaneLobe::Scatter(bs)) => chosen = Some(bs),
            }
        }

        // Continue while a further surface is within the depth limit; the first scattering
        // must be specular (the paths whose light-side end is non-specular are the camera
        // paths' part).
        if black
            || depth >= settings.max_depth
            || (depth == 1 && !material.flags().contains(crate::bxdf::MaterialFlags::DELTA))
        {
            return;
        }
        let [ux, uy, uc, u_rr] = sampler.get4();
        let Some(bs) = chosen.or_else(|| material.sample(wo, uc, Vec2::new(ux, uy), &mut wl))
        else {
            return;
        };
        if (depth == 1 && !bs.specular) || bs.pdf.is_nan() || bs.pdf <= 0.0 {
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
        if depth > settings.rr_depth && throughput < 1.0 {
            let q = (1.0 - throughput).max(0.0);
            if u_rr < q {
                return;
            }
            beta = beta / (1.0 - q);
            throughput /= 1.0 - q;
        }
        straight_through = 0;
        ray_o = hit.spawn_origin(wi_world);
        ray_d = wi_world.normalize();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::uniform_sphere;

    fn lights_with_targets(targets: Vec<(Vec3, f32)>) -> CausticLights {
        CausticLights {
            lights: vec![0],
            cdf: vec![1.0],
            handled: vec![true],
            targets,
            scene: (Vec3::ZERO, 1e5),
        }
    }

    /// E[1{dir in a cone}/pdf] over the sampled directions is the solid angle of the union of
    /// the cones, which uniform sampling of the sphere measures independently.
    #[test]
    fn target_direction_density_integrates_to_the_union_of_the_cones() {
        let p = Vec3::new(0.1, 2.0, -0.3);
        let targets = vec![
            (Vec3::new(0.0, 0.0, 0.0), 0.5),
            (Vec3::new(0.4, 0.2, 0.1), 0.3),
            (Vec3::new(-2.0, 2.5, 1.0), 0.2),
        ];
        let c = lights_with_targets(targets.clone());
        let inside = |d: Vec3| {
            targets.iter().any(|&(ctr, r)| {
                let v = ctr - p;
                let cos_max = (1.0 - r * r / v.length_squared()).sqrt();
                d.dot(v.normalize()) >= cos_max
            })
        };
        let n = 400_000;
        let (mut est, mut est2) = (0.0f64, 0.0f64);
        let mut rng = 0x1234_5678_u64;
        let mut u = || {
            rng = crate::sampling::mix64(rng.wrapping_add(0x9e37_79b9_7f4a_7c15));
            (rng >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..n {
            let (d, pdf) = c
                .sample_direction(p, u(), Vec2::new(u(), u()))
                .expect("a direction");
            assert!(pdf > 0.0 && pdf.is_finite());
            if inside(d) {
                est += 1.0 / pdf as f64;
                est2 += 1.0 / (pdf as f64 * pdf as f64);
            }
        }
        // Midpoint quadrature over (z, φ), where the sphere's measure is uniform.
        let grid = |m: usize| {
            let mut inside_cells = 0usize;
            for i in 0..m {
                for j in 0..m {
                    let d = uniform_sphere(Vec2::new(
                        (i as f32 + 0.5) / m as f32,
                        (j as f32 + 0.5) / m as f32,
                    ));
                    inside_cells += inside(d) as usize;
                }
            }
            4.0 * std::f64::consts::PI * inside_cells as f64 / (m * m) as f64
        };
        let uniform = grid(3000);
        let coarse = grid(2000);
        // The estimate's standard error from the sample variance of 1{inside}/pdf. The
        // reference's own error (the grid cells cut by the cones' rims) must be far below it:
        // the 3000² and 2000² grids agree to a fifth of it.
        let nf = n as f64;
        let est = est / nf;
        let se = ((est2 / nf - est * est).max(0.0) / (nf - 1.0)).sqrt();
        println!("union of the cones: {est} ± {se} sr, quadrature {uniform} sr (2000²: {coarse})");
        assert!(
            (uniform - coarse).abs() < 0.2 * se,
            "{uniform} vs {coarse} sr"
        );
        assert!(
            (est - uniform).abs() <= 5.0 * se && se < 0.003 * uniform,
            "{est} ± {se} vs {uniform} sr"
        );
    }

    #[test]
    fn small_distant_targets_keep_their_exact_cones() {
        // r/d from 1e-2 down to 1e-7: f32's 1 − √(1 − r²/d²) loses the cone below ~2e-4 (and
        // collapsed it to nothing below 1.7e-4, dropping such a target's caustics).
        for (r, d) in [(0.01f32, 1.0f32), (0.01, 100.0), (0.01, 1e4), (1e-3, 1e4)] {
            let c = lights_with_targets(vec![(Vec3::new(0.0, 0.0, d), r)]);
            let omega = std::f64::consts::PI * (r as f64 / d as f64).powi(2);
            for k in 0..64 {
                let u = |i: u32| ((k * 7 + i * 13) % 64) as f32 / 64.0 + 1.0 / 128.0;
                let (dir, pdf) = c
                    .sample_direction(Vec3::ZERO, u(0), Vec2::new(u(1), u(2)))
                    .unwrap();
                // Density: 1/Ω within 1e-3 (Ω ≈ π r²/d² for small cones).
                assert!(
                    ((pdf as f64 * omega) - 1.0).abs() < 1e-3,
                    "r {r}, d {d}: pdf·Ω = {}",
                    pdf as f64 * omega
                );
                // The direction passes within the (slightly padded) sphere.
                let miss = dir
                    .as_dvec3()
                    .cross(glam::DVec3::new(0.0, 0.0, d as f64))
                    .length();
                assert!(
                    miss <= r as f64 * 1.001 + 1e-6,
                    "r {r}, d {d}: passes at {miss}"
                );
            }
        }
    }

    #[test]
    fn a_point_inside_a_target_samples_the_whole_sphere() {
        let c = lights_with_targets(vec![(Vec3::ZERO, 1.0)]);
        let (_, pdf) = c
            .sample_direction(Vec3::new(0.1, 0.2, 0.0), 0.3, Vec2::new(0.4, 0.5))
            .unwrap();
        assert!((pdf - 1.0 / (4.0 * std::f32::consts::PI)).abs() < 1e-7);
    }
}
