//! Camera paths: unidirectional spectral path tracing with next-event estimation and multiple
//! importance sampling (Veach 1997, power heuristic β = 2), Russian roulette (see
//! [`super::survival_probability`]) and an optional maximum depth; and the irradiance at a
//! point, from the same paths.
//!
//! The integrator only talks to materials through [`crate::bxdf::Material`]'s interface and to
//! lights through [`crate::light::Light`]'s, so new families slot in without touching it.

use super::stats::RayStats;
use super::transmit::{choose_pane_lobe, transmittance, PaneLobe, MAX_STRAIGHT_THROUGH};
use crate::bxdf::Frame;
use crate::geometry::{offset_ray_origin, point_error_bound, shadow_ray_between, Hit};
use crate::sampling::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;
use glam::Vec3;

#[inline]
fn power_heuristic(f: f32, g: f32) -> f32 {
    let (f2, g2) = (f * f, g * g);
    if f2.is_infinite() {
        return 1.0;
    }
    if f2 + g2 == 0.0 {
        return 0.0;
    }
    f2 / (f2 + g2)
}

/// How the ray being traced was generated, for MIS of the emission it finds first.
#[derive(Clone, Copy, Debug)]
pub struct PathStart {
    /// The direction was not sampled from a density light sampling could also produce
    /// (camera rays, specular bounces): emission found is counted in full.
    pub specular: bool,
    /// Solid-angle density with which the direction was sampled.
    pub pdf: f32,
    /// The point the ray leaves (for the light-sampling density of what it hits).
    pub p: Vec3,
    /// The normal light selection used at `p` (None for a camera).
    pub n: Option<Vec3>,
    /// Scattering events already on the path (0 for a camera ray).
    pub depth: u32,
    /// A camera ray whose caustic paths (first surface scattered non-specularly, last
    /// scattering before a light that [`crate::world::CausticLights`] handles specular)
    /// are left to light tracing.
    pub caustics_by_light_tracing: bool,
    /// Lights at infinity reached before the path scatters again count (false: only light
    /// that has scattered at least once more, as [`indirect_irradiance`] needs).
    pub unscattered_escapes: bool,
    /// A camera ray whose straight view of the sun's disk (no scattering, only passages
    /// through window panes) [`super::sun_view::SunInView`] deposits in the pixels: the disk
    /// is left out of such rays.
    pub sun_deposited: bool,
}

impl PathStart {
    /// A ray from a camera or meter at `p` that counts every path (meters, probes).
    pub fn camera(p: Vec3) -> Self {
        Self {
            specular: true,
            pdf: 0.0,
            p,
            n: None,
            depth: 0,
            caustics_by_light_tracing: false,
            unscattered_escapes: true,
            sun_deposited: false,
        }
    }

    /// A camera ray of the image: without the caustic paths that light tracing estimates when
    /// the world has it on (see [`super::light_path`]).
    pub fn image(world: &World, p: Vec3) -> Self {
        Self {
            caustics_by_light_tracing: world.caustics.is_some(),
            ..Self::camera(p)
        }
    }
}

/// Spectral radiance (W·m⁻²·sr⁻¹·nm⁻¹ at each of `wl`'s wavelengths) arriving at `origin`
/// from unit direction `dir`, along a ray that starts in state `start`.
pub fn trace(
    world: &World,
    origin: Vec3,
    dir: Vec3,
    start: PathStart,
    wl: &mut SampledWavelengths,
    sampler: &mut Sampler,
    stats: &mut RayStats,
) -> SampledSpectrum {
    trace_tallied(
        world,
        origin,
        dir,
        start,
        wl,
        sampler,
        stats,
        &mut |_, _| {},
    )
}

/// [`trace`], also handing `tally` each part of the result that comes from a light at
/// infinity, with the direction (scene frame) it arrives from at its last vertex: daylight
/// coefficients sort the sky's light into patches by it. The parts sum to the result less the
/// emission of lights in the scene.
#[allow(clippy::too_many_arguments)]
pub fn trace_tallied<T: FnMut(Vec3, SampledSpectrum)>(
    world: &World,
    origin: Vec3,
    dir: Vec3,
    start: PathStart,
    wl: &mut SampledWavelengths,
    sampler: &mut Sampler,
    stats: &mut RayStats,
    tally: &mut T,
) -> SampledSpectrum {
    trace_impl(world, origin, dir, start, wl, sampler, stats, tally, false).0
}

/// [`trace`], and with `keep_first_hit` the first intersection of the ray (`intersect`'s hit,
/// before any normal map): the surface the camera sees, for estimates at it that would
/// otherwise trace the ray again.
#[allow(clippy::too_many_arguments)]
pub fn trace_seen(
    world: &World,
    origin: Vec3,
    dir: Vec3,
    start: PathStart,
    wl: &mut SampledWavelengths,
    sampler: &mut Sampler,
    stats: &mut RayStats,
    keep_first_hit: bool,
) -> (SampledSpectrum, Option<Hit>) {
    let mut no_tally = |_, _| {};
    trace_impl(
        world,
        origin,
        dir,
        start,
        wl,
        sampler,
        stats,
        &mut no_tally,
        keep_first_hit,
    )
}

#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn trace_impl<T: FnMut(Vec3, SampledSpectrum)>(
    world: &World,
    origin: Vec3,
    dir: Vec3,
    start: PathStart,
    wl: &mut SampledWavelengths,
    sampler: &mut Sampler,
    stats: &mut RayStats,
    tally: &mut T,
    keep_first_hit: bool,
) -> (SampledSpectrum, Option<Hit>) {
    let mut path = Path::new(origin, dir, &start);
    let mut first_hit = None;
    let mut seen_first = false;
    loop {
        let hit = world
            .geometry
            .intersect(path.ray_o, path.ray_d, f32::INFINITY);
        if keep_first_hit && !seen_first {
            first_hit = hit;
        }
        seen_first = true;
        let Some(hit) = hit else {
            path.escape(world, &start, wl, tally);
            break;
        };
        let object = world.objects[hit.object as usize];
        if let Some(li) = object.light {
            path.add_emission(world, &start, &hit, li, wl);
        }
        let material = &world.materials[object.material as usize];
        let (material, normal_map) = material.normal_map();
        let hit = match normal_map {
            Some(m) => crate::integrator::normal_mapped(world, m, hit),
            None => hit,
        };
        let textured;
        let material = match material.at_texture(hit.tex, wl) {
            Some(m) => {
                textured = m;
                &textured
            }
            None => material,
        };
        if material.flags().contains(crate::bxdf::MaterialFlags::BLACK) {
            break;
        }
        let frame = material.shading_frame(hit.ns);
        let wo = frame.to_local(-path.ray_d);
        if wo.z == 0.0 {
            break;
        }
        let chosen = match path.pane(material, wo, &hit, sampler, wl, stats) {
            Pane::Absorbed => break,
            Pane::Through => continue,
            Pane::Scatter(chosen) => chosen,
        };
        if world
            .settings
            .max_depth
            .is_some_and(|max| path.depth >= max)
        {
            stats.truncated_paths += 1;
            break;
        }
        material.prepare(wl);
        let at = Shading {
            material,
            hit: &hit,
            frame: &frame,
            wo,
            normal_mapped: normal_map.is_some(),
        };
        path.next_event(world, &at, sampler, wl, stats, tally);
        if !path.scatter(world, &at, chosen, sampler, wl) {
            break;
        }
        stats.bounce_rays += 1;
    }
    (path.l, first_hit)
}

/// The state of a camera path between its vertices: what it has gathered, its throughput,
/// the ray it follows and what MIS and Russian roulette need of the vertex it left.
struct Path {
    /// Radiance gathered so far.
    l: SampledSpectrum,
    /// Throughput.
    beta: SampledSpectrum,
    ray_o: Vec3,
    ray_d: Vec3,
    /// For MIS of emission found by BSDF sampling: how the ray's direction was sampled, and
    /// the point and normal it leaves.
    prev_specular: bool,
    prev_pdf: f32,
    prev_p: Vec3,
    prev_n: Option<Vec3>,
    depth: u32,
    /// Product of η′² over the refractions so far (see `Material::eta_scale`), for Russian
    /// roulette only.
    eta_scale: f32,
    /// Russian roulette weighs the throughput relative to its value after the first
    /// scattering of a path from a camera or a luminance meter (set at that scattering): its
    /// value is about that surface's albedo times the light it receives, so what the rest of
    /// the path brings matters relative to that albedo, not to 1. A dark surface's pixel is
    /// then as precise, for its value, as a bright one's. A receiver's path (depth ≥ 1 at the
    /// start) keeps 1.
    roulette_scale: f32,
    /// Whether the path's first scattering (at the surface the camera sees) was non-specular:
    /// with `start.caustics_by_light_tracing`, such paths that reach a light through a
    /// specular scattering are light tracing's part (see `super::light_path`). (A receiver's
    /// path, started at depth 1, begins at that non-specular receiver.)
    first_non_specular: bool,
    /// Null events (straight through window panes) since the last scattering.
    straight_through: u32,
}

/// A surface point as the path scatters there: its material (normal-mapped and textured),
/// hit, shading frame and the local direction back along the ray.
struct Shading<'a> {
    material: &'a crate::bxdf::Material,
    hit: &'a Hit,
    frame: &'a Frame,
    wo: Vec3,
    normal_mapped: bool,
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

impl Path {
    #[inline(always)]
    fn new(origin: Vec3, dir: Vec3, start: &PathStart) -> Self {
        Self {
            l: SampledSpectrum::ZERO,
            beta: SampledSpectrum::ONE,
            ray_o: origin,
            ray_d: dir,
            prev_specular: start.specular,
            prev_pdf: start.pdf,
            prev_p: start.p,
            prev_n: start.n,
            depth: start.depth,
            eta_scale: 1.0,
            roulette_scale: 1.0,
            first_non_specular: start.depth >= 1,
            straight_through: 0,
        }
    }

    /// The ray left the scene: the lights at infinity it reaches, weighed by MIS.
    #[inline(always)]
    fn escape<T: FnMut(Vec3, SampledSpectrum)>(
        &mut self,
        world: &World,
        start: &PathStart,
        wl: &SampledWavelengths,
        tally: &mut T,
    ) {
        if self.depth == start.depth && !start.unscattered_escapes {
            return;
        }
        for &li in &world.infinite_lights {
            let light = &world.lights[li as usize];
            if start.sun_deposited
                && self.depth == start.depth
                && matches!(light, crate::light::Light::Sun(_))
            {
                continue;
            }
            let le = light.escaped(self.ray_d, wl);
            if le.is_black() {
                continue;
            }
            let c = if self.prev_specular {
                self.beta * le
            } else {
                let p_light = world
                    .light_sampler
                    .pmf(self.prev_p, self.prev_n, li as usize, 0)
                    * light.pdf_li_escape(self.prev_p, self.ray_d);
                self.beta * le * power_heuristic(self.prev_pdf, p_light)
            };
            self.l += c;
            tally(self.ray_d, c);
        }
    }

    /// Emission of light `li` seen at `hit`, weighed by MIS; none for the caustic paths light
    /// tracing estimates.
    #[inline(always)]
    fn add_emission(
        &mut self,
        world: &World,
        start: &PathStart,
        hit: &Hit,
        li: u32,
        wl: &SampledWavelengths,
    ) {
        let light = &world.lights[li as usize];
        let le = light.emitted(hit, wl);
        let light_traced = start.caustics_by_light_tracing
            && self.first_non_specular
            && self.prev_specular
            && self.depth >= 2
            && world
                .caustics
                .as_ref()
                .is_some_and(|c| c.handles(li as usize));
        if le.is_black() || light_traced {
            return;
        }
        if self.prev_specular {
            self.l += self.beta * le;
        } else {
            let p_light = world
                .light_sampler
                .pmf(self.prev_p, self.prev_n, li as usize, hit.prim)
                * light.pdf_li_hit_prim(&world.geometry, self.prev_p, hit);
            self.l += self.beta * le * power_heuristic(self.prev_pdf, p_light);
        }
    }

    /// A window pane's lobe is chosen first. Passing straight through is a null event (no
    /// scattering vertex: depth, MIS state and the caustic partition stay those of the last
    /// real vertex), which matches next-event estimation, whose shadow rays pass through the
    /// pane with its transmittance (see `transmittance`).
    #[inline(always)]
    fn pane(
        &mut self,
        material: &crate::bxdf::Material,
        wo: Vec3,
        hit: &Hit,
        sampler: &mut Sampler,
        wl: &mut SampledWavelengths,
        stats: &mut RayStats,
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
                self.straight_through += 1;
                if self.beta.is_black() || self.straight_through > MAX_STRAIGHT_THROUGH {
                    return Pane::Absorbed;
                }
                self.ray_o = hit.spawn_origin(self.ray_d);
                stats.bounce_rays += 1;
                Pane::Through
            }
            Some(PaneLobe::Scatter(mut bs)) => {
                // Light sampling at this vertex happens only when the pane scatters (probability
                // 1 − q): it is weighed by 1/(1 − q), and the sampled lobe's weight keeps its
                // value (and its pdf, which MIS shares with light sampling).
                let q = material.straight_probability(wo);
                if q > 0.0 && q < 1.0 {
                    self.beta = self.beta / (1.0 - q);
                    bs.f = bs.f * (1.0 - q);
                }
                Pane::Scatter(Some(bs))
            }
        }
    }

    /// Next-event estimation at `at`. Each bounce takes two sets of four dimensions, each led
    /// by its 2-D pair (see `Sampler`): the point on the light, then the BSDF direction.
    #[inline(always)]
    fn next_event<T: FnMut(Vec3, SampledSpectrum)>(
        &mut self,
        world: &World,
        at: &Shading,
        sampler: &mut Sampler,
        wl: &SampledWavelengths,
        stats: &mut RayStats,
        tally: &mut T,
    ) {
        let (material, hit) = (at.material, at.hit);
        let [ptx, pty, u_light, u_prim] = sampler.get4();
        let u_pt = glam::Vec2::new(ptx, pty);
        if material
            .flags()
            .contains(crate::bxdf::MaterialFlags::ALL_DELTA)
        {
            return;
        }
        let Some((k, prim, p_select)) = world.light_sampler.sample(hit.p, Some(hit.ns), u_light)
        else {
            return;
        };
        let light = &world.lights[k];
        let Some(ls) = light.sample_li_prim(&world.geometry, hit.p, prim, u_prim, u_pt, wl) else {
            return;
        };
        let leak =
            at.normal_mapped && crate::bxdf::normal_map::leaks(-self.ray_d, ls.wi, hit.ns, hit.ng);
        // (A NaN density is no sample either.)
        let usable = ls.pdf > 0.0 && !ls.li.is_black() && !leak;
        if !usable {
            return;
        }
        let wi = at.frame.to_local(ls.wi);
        let f = material.eval(at.wo, wi, wl) * wi.z.abs();
        if f.is_black() {
            return;
        }
        stats.shadow_rays += 1;
        if let Some(tr) = shadow_transmittance(world, &RayStart::surface(hit), &ls, wl) {
            let pdf = p_select * ls.pdf;
            let w = if ls.delta {
                1.0
            } else {
                power_heuristic(pdf, material.pdf(at.wo, wi, wl))
            };
            let c = self.beta * f * tr * ls.li * (w / pdf);
            self.l += c;
            if ls.dist.is_infinite() {
                tally(ls.wi, c);
            }
        }
    }

    /// Continue the path by sampling the BSDF at `at` (or the pane's `chosen` lobe), then
    /// Russian roulette; false when the path ends.
    #[inline(always)]
    fn scatter(
        &mut self,
        world: &World,
        at: &Shading,
        chosen: Option<crate::bxdf::BsdfSample>,
        sampler: &mut Sampler,
        wl: &mut SampledWavelengths,
    ) -> bool {
        let (material, hit, wo) = (at.material, at.hit, at.wo);
        let [ux, uy, uc, u_rr] = sampler.get4();
        let u = glam::Vec2::new(ux, uy);
        let Some(bs) = chosen.or_else(|| material.sample(wo, uc, u, wl)) else {
            return false;
        };
        if bs.pdf.is_nan() || bs.pdf <= 0.0 {
            return false;
        }
        let wi_world = at.frame.to_world(bs.wi);
        if at.normal_mapped && crate::bxdf::normal_map::leaks(-self.ray_d, wi_world, hit.ns, hit.ng)
        {
            return false;
        }
        self.beta *= bs.f * (bs.wi.z.abs() / bs.pdf);
        if self.beta.is_black() {
            return false;
        }
        self.eta_scale *= material.eta_scale(wo, bs.wi, wl);
        if self.depth == 0 {
            self.first_non_specular = !bs.specular;
            self.roulette_scale = first_scatter_roulette_scale(self.beta.max_component());
        }
        self.prev_specular = bs.specular;
        self.straight_through = 0;
        self.prev_pdf = bs.pdf;
        self.prev_p = hit.p;
        self.prev_n = Some(hit.ns);
        self.ray_o = hit.spawn_origin(wi_world);
        self.ray_d = wi_world.normalize();
        self.depth += 1;
        if self.depth > world.settings.rr_depth {
            let p = super::survival_probability(
                self.beta.max_component() * self.eta_scale * self.roulette_scale,
            );
            if u_rr < 1.0 - p {
                return false;
            }
            self.beta = self.beta / p;
        }
        true
    }
}

/// Factor on the throughput for Russian roulette after a camera path's first scattering left it
/// at `beta` (its largest component): 1/beta for a surface that absorbs (a survival
/// probability of min(throughput/beta, 0.99)), at most 10⁶; 1 where the scattering did not
/// lower the throughput (the roulette is never made more eager to end a path than its
/// throughput says). Unbiased whatever the factor: a surviving path's weight is divided by its
/// survival probability.
#[inline]
fn first_scatter_roulette_scale(beta: f32) -> f32 {
    if beta > 0.0 && beta < 1.0 {
        1.0 / beta.max(1e-6)
    } else {
        1.0
    }
}

/// Where a shadow ray starts: a surface point with its error bound and geometric normal, or a
/// free-standing point (zero error and zero normal: no offset).
#[derive(Clone, Copy, Debug)]
pub struct RayStart {
    pub p: Vec3,
    pub error: Vec3,
    pub ng: Vec3,
}

impl RayStart {
    pub fn surface(hit: &Hit) -> Self {
        Self {
            p: hit.p,
            error: hit.error,
            ng: hit.ng,
        }
    }
    pub fn free(p: Vec3) -> Self {
        Self {
            p,
            error: Vec3::ZERO,
            ng: Vec3::ZERO,
        }
    }
}

/// Transmittance of the shadow ray between a point and a light sample (None when blocked).
fn shadow_transmittance(
    world: &World,
    from: &RayStart,
    ls: &crate::light::LightSample,
    wl: &SampledWavelengths,
) -> Option<SampledSpectrum> {
    let (origin, dir, t_max) = match ls.point {
        Some((p, n)) => shadow_ray_between(from.p, from.error, from.ng, p, point_error_bound(p), n),
        None => {
            let origin = offset_ray_origin(from.p, from.error, from.ng, ls.wi);
            let t_max = if ls.dist.is_finite() {
                (from.p + ls.wi * ls.dist - origin).length()
            } else {
                f32::INFINITY
            };
            (origin, ls.wi, t_max)
        }
    };
    if t_max <= 0.0 {
        return Some(SampledSpectrum::ONE);
    }
    transmittance(world, origin, dir, t_max, wl)
}

/// Spectral irradiance (W·m⁻²·nm⁻¹) on the hemisphere around unit normal `n` at `at`: light
/// sampling and cosine-weighted hemisphere sampling combined by MIS (power heuristic) for
/// directly visible emitters; light reflected by the scene arrives through the cosine-sampled
/// path. The receiver counts as the first scattering event of its paths, so with the same
/// `max_depth` a Lambertian surface's luminance is exactly ρE/π of this estimate.
///
/// With `caustics_by_light_tracing` (the image's per-pixel illuminance when the world traces
/// caustics from the lights), the paths whose scattering next to the light is specular are
/// left out: light tracing estimates them (see [`super::light_path`]).
///
/// With `max_depth` 0 no path may scatter, the receiver included, so the irradiance is 0 (as
/// the luminance of a Lambertian surface is then): direct illuminance alone is `max_depth` 1.
pub fn irradiance(
    world: &World,
    at: &RayStart,
    n: Vec3,
    caustics_by_light_tracing: bool,
    wl: &mut SampledWavelengths,
    sampler: &mut Sampler,
    stats: &mut RayStats,
) -> SampledSpectrum {
    irradiance_tallied(
        world,
        at,
        n,
        caustics_by_light_tracing,
        wl,
        sampler,
        stats,
        &mut |_, _| {},
    )
}

/// [`irradiance`], handing `tally` each part that comes from a light at infinity with the
/// direction it arrives from at its last vertex (see [`trace_tallied`]).
#[allow(clippy::too_many_arguments)]
pub fn irradiance_tallied<T: FnMut(Vec3, SampledSpectrum)>(
    world: &World,
    at: &RayStart,
    n: Vec3,
    caustics_by_light_tracing: bool,
    wl: &mut SampledWavelengths,
    sampler: &mut Sampler,
    stats: &mut RayStats,
    tally: &mut T,
) -> SampledSpectrum {
    use std::f32::consts::PI;
    let mut e = SampledSpectrum::ZERO;
    if world.settings.max_depth == Some(0) {
        // (Light sampling alone would also be wrong here: its MIS weight assumes the cosine
        // strategy below, which a depth of 0 rules out.)
        stats.truncated_paths += 1;
        return e;
    }
    let u_light = sampler.get1d();
    let u_prim = sampler.get1d();
    let u_pt = sampler.get2d();
    if let Some((k, prim, p_select)) = world.light_sampler.sample(at.p, Some(n), u_light) {
        let light = &world.lights[k];
        if let Some(ls) = light.sample_li_prim(&world.geometry, at.p, prim, u_prim, u_pt, wl) {
            let cos = ls.wi.dot(n);
            if cos > 0.0 && ls.pdf > 0.0 && !ls.li.is_black() {
                stats.shadow_rays += 1;
                if let Some(tr) = shadow_transmittance(world, at, &ls, wl) {
                    let pdf = p_select * ls.pdf;
                    let w = if ls.delta {
                        1.0
                    } else {
                        power_heuristic(pdf, crate::sampling::cosine_hemisphere_pdf(cos))
                    };
                    let c = tr * ls.li * (cos * w / pdf);
                    e += c;
                    if ls.dist.is_infinite() {
                        tally(ls.wi, c);
                    }
                }
            }
        }
    }
    // cos θ / pdf = π.
    let mut scaled = |d: Vec3, c: SampledSpectrum| tally(d, c * PI);
    let start = |p, n, pdf| PathStart {
        specular: false,
        pdf,
        p,
        n: Some(n),
        depth: 1,
        caustics_by_light_tracing,
        unscattered_escapes: true,
        sun_deposited: false,
    };
    e += receiver_path(world, at, n, start, wl, sampler, stats, &mut scaled) * PI;
    e
}

/// The irradiance at `at` on the side of unit normal `n` from light that has scattered at
/// least once on its way (the lights' direct light, straight or through window panes, left
/// out): a cosine-sampled path from the receiver that counts what it finds after its first
/// scattering. Annual daylight adds each hour's direct sun, traced on its own, to it.
pub fn indirect_irradiance(
    world: &World,
    at: &RayStart,
    n: Vec3,
    wl: &mut SampledWavelengths,
    sampler: &mut Sampler,
    stats: &mut RayStats,
) -> SampledSpectrum {
    if world.settings.max_depth == Some(0) {
        return SampledSpectrum::ZERO;
    }
    let start = |p, n, pdf| PathStart {
        specular: false,
        pdf,
        p,
        n: Some(n),
        depth: 1,
        caustics_by_light_tracing: false,
        unscattered_escapes: false,
        sun_deposited: false,
    };
    // cos θ / pdf = π.
    receiver_path(world, at, n, start, wl, sampler, stats, &mut |_, _| {}) * std::f32::consts::PI
}

/// The radiance a cosine-sampled direction from a receiver brings (zero below its horizon),
/// the path started as `start(p, n, pdf)` says.
#[allow(clippy::too_many_arguments)]
fn receiver_path<T: FnMut(Vec3, SampledSpectrum)>(
    world: &World,
    at: &RayStart,
    n: Vec3,
    start: impl Fn(Vec3, Vec3, f32) -> PathStart,
    wl: &mut SampledWavelengths,
    sampler: &mut Sampler,
    stats: &mut RayStats,
    tally: &mut T,
) -> SampledSpectrum {
    let local = crate::sampling::cosine_hemisphere(sampler.get2d());
    if local.z <= 0.0 {
        return SampledSpectrum::ZERO;
    }
    let wi = Frame::from_normal(n).to_world(local);
    let origin = offset_ray_origin(at.p, at.error, at.ng, wi);
    stats.bounce_rays += 1;
    let start = start(at.p, n, crate::sampling::cosine_hemisphere_pdf(local.z));
    trace_tallied(world, origin, wi, start, wl, sampler, stats, tally)
}
