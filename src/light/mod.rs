//! Light sources, in radiometric units (each type's `build` converts the user's photometric
//! amount: see [`crate::photometry::photometric_scale`]). One file per type; [`Light`]
//! dispatches to them.
//!
//! | light | stored spectrum | unit |
//! |---|---|---|
//! | point, spot, goniometric | radiant intensity I_e(λ) | W·sr⁻¹·nm⁻¹ (goniometric: per table cd) |
//! | distant | irradiance at normal incidence E_e(λ) | W·m⁻²·nm⁻¹ |
//! | environment, area, sun | radiance L_e(λ) | W·m⁻²·sr⁻¹·nm⁻¹ |
//! | sky | radiance per unit relative luminance, and the ground's radiance | W·m⁻²·sr⁻¹·nm⁻¹ |

pub mod area;
pub mod bounds;
pub mod bvh;
pub mod distant;
pub mod environment;
pub mod goniometric;
pub mod point;
pub mod portal;
pub mod sampler;
pub mod sky;
pub mod spot;
pub mod sun;

use crate::description::context::{Context, SceneError};
use crate::description::schema::Amount;
use crate::geometry::{Hit, SceneGeometry};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

pub use area::{AreaLight, EmissionShape};
pub use distant::DistantLight;
pub use environment::EnvironmentLight;
pub use goniometric::GoniometricLight;
pub use point::PointLight;
pub use portal::{Portal, Portals};
pub use sampler::{LightSampler, LightSamplerKind};
pub use sky::{SiteFrame, SkyLight};
pub use spot::SpotLight;
pub use sun::SunLight;

#[derive(Clone, Debug)]
pub enum Light {
    /// Isotropic point source.
    Point(PointLight),
    /// Point source with a smooth cone falloff.
    Spot(SpotLight),
    /// Parallel light from one direction.
    Distant(DistantLight),
    /// Uniform radiance from every direction at infinity.
    Environment(EnvironmentLight),
    /// Emission from the primitives of one scene object.
    Area(AreaLight),
    /// A luminaire measured by a photometric file (IES/EULUMDAT): see [`goniometric`].
    Goniometric(Box<GoniometricLight>),
    /// A CIE or Perez sky over a ground: see [`sky`].
    Sky(Box<SkyLight>),
    /// The sun's disk: see [`sun`].
    Sun(SunLight),
}

/// What kind of distribution a light type is (each type's `FLAGS`), as a set of bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightFlags(u8);

impl LightFlags {
    /// Emits from a single point (point, spot, goniometric): rays cannot hit it.
    pub const DELTA_POSITION: Self = Self(1);
    /// Emits along a single direction (distant): rays cannot hit it.
    pub const DELTA_DIRECTION: Self = Self(2);
    /// Emits from surfaces of the scene, which rays hit ([`Light::emitted`]).
    pub const AREA: Self = Self(4);
    /// Radiance at infinity that escaped rays receive ([`Light::escaped`]); light tracing
    /// cannot start paths from it.
    pub const INFINITE: Self = Self(8);

    /// Whether every flag of `other` is set.
    pub const fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// A delta distribution in position or direction (cannot be hit by rays).
    pub const fn is_delta(self) -> bool {
        self.0 & (Self::DELTA_POSITION.0 | Self::DELTA_DIRECTION.0) != 0
    }

    /// Whether light tracing can start paths at such a light: sources at a finite position
    /// (from [`Light::sample_emission_point`]) and distant lights (parallel beams, started
    /// across the scene by [`crate::integrator::light_path`]); not an environment.
    pub const fn can_emit_paths(self) -> bool {
        !self.contains(Self::INFINITE)
    }
}

/// A sampled direction toward a light.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the shading point toward the light.
    pub wi: Vec3,
    /// Incident radiance (or, for delta lights, irradiance-like quantity I/d² or E) carried
    /// along `wi`, before the cosine at the receiver.
    pub li: SampledSpectrum,
    /// Density of `wi` w.r.t. solid angle (1 for delta lights); excludes light selection.
    pub pdf: f32,
    /// Distance to the sampled point (∞ for lights at infinity).
    pub dist: f32,
    /// The sampled point on an area light and its normal, for the shadow ray.
    pub point: Option<(Vec3, Vec3)>,
    pub delta: bool,
}

/// A point light leaves from, for light tracing (see [`Light::sample_emission_point`]).
#[derive(Clone, Copy, Debug)]
pub struct EmissionPoint {
    pub p: Vec3,
    /// Front normal of an area light's surface (None for point-like sources).
    pub n: Option<Vec3>,
    /// Texture coordinates of the point on an area light (zero for point-like sources).
    pub tex: glam::Vec2,
    /// 1 / (density of the point w.r.t. area) for area lights (their area), 1 for point-like
    /// sources.
    pub inv_pdf: f32,
}

impl Light {
    /// The type's [`LightFlags`].
    pub fn flags(&self) -> LightFlags {
        match self {
            Light::Point(_) => PointLight::FLAGS,
            Light::Spot(_) => SpotLight::FLAGS,
            Light::Distant(_) => DistantLight::FLAGS,
            Light::Environment(_) => EnvironmentLight::FLAGS,
            Light::Area(_) => AreaLight::FLAGS,
            Light::Goniometric(_) => GoniometricLight::FLAGS,
            Light::Sky(_) => SkyLight::FLAGS,
            Light::Sun(_) => SunLight::FLAGS,
        }
    }

    /// Sample the point light leaves from (light tracing): uniform by area on an area light
    /// (`uc` chooses the primitive, `u` the point), the position of point-like sources. None
    /// for lights at infinity.
    pub fn sample_emission_point(
        &self,
        geom: &SceneGeometry,
        uc: f32,
        u: Vec2,
    ) -> Option<EmissionPoint> {
        let at = |p: Vec3| {
            Some(EmissionPoint {
                p,
                n: None,
                tex: glam::Vec2::ZERO,
                inv_pdf: 1.0,
            })
        };
        match self {
            Light::Point(l) => at(l.position),
            Light::Spot(l) => at(l.position),
            Light::Goniometric(g) => at(g.position),
            Light::Area(a) => Some(a.sample_emission_point(geom, uc, u)),
            Light::Distant(_) | Light::Environment(_) | Light::Sky(_) | Light::Sun(_) => None,
        }
    }

    /// What leaves `at` toward unit direction `dir`, per steradian: radiant intensity for
    /// point-like sources (W·sr⁻¹·nm⁻¹), radiance × |cos θ| for area lights (W·m⁻²·sr⁻¹·nm⁻¹,
    /// zero behind a one-sided emitter).
    pub fn emission_toward(
        &self,
        at: &EmissionPoint,
        dir: Vec3,
        wl: &SampledWavelengths,
    ) -> SampledSpectrum {
        match self {
            Light::Point(l) => l.intensity(wl),
            Light::Spot(l) => l.intensity_toward(dir, wl),
            Light::Goniometric(g) => g.intensity_toward(dir, wl),
            Light::Area(a) => a.emission_toward(at, dir, wl),
            Light::Distant(_) | Light::Environment(_) | Light::Sky(_) | Light::Sun(_) => {
                SampledSpectrum::ZERO
            }
        }
    }

    /// Photometric power proxy (lm) used to choose lights in proportion to their output.
    pub fn power_lm(&self, geom: &SceneGeometry, scene_radius: f32) -> f64 {
        match self {
            Light::Point(l) => l.power_lm(),
            Light::Spot(l) => l.power_lm(),
            Light::Distant(l) => l.power_lm(scene_radius),
            Light::Environment(l) => l.power_lm(scene_radius),
            Light::Area(a) => a.power_lm(geom),
            Light::Goniometric(g) => g.power_lm(),
            Light::Sky(l) => l.power_lm(scene_radius),
            Light::Sun(l) => l.power_lm(scene_radius),
        }
    }

    /// Sample incident light at point `p`. `u` is a 2-D sample, `uc` a 1-D one (primitive choice).
    pub fn sample_li(
        &self,
        geom: &SceneGeometry,
        p: Vec3,
        uc: f32,
        u: Vec2,
        wl: &SampledWavelengths,
    ) -> Option<LightSample> {
        match self {
            Light::Point(l) => self.sample_li_from(l.position, p, wl),
            Light::Spot(l) => self.sample_li_from(l.position, p, wl),
            Light::Goniometric(g) => self.sample_li_from(g.position, p, wl),
            Light::Distant(l) => Some(l.sample_li(wl)),
            Light::Environment(l) => l.sample_li(p, uc, u, wl),
            Light::Area(a) => a.sample_li(geom, p, uc, u, wl),
            Light::Sky(l) => l.sample_li(p, uc, u, wl),
            Light::Sun(l) => l.sample_li(u, wl),
        }
    }

    /// [`Light::sample_li`] with the primitive of an area light already chosen (`prim`, a
    /// primitive id of the light, as [`LightSampler`] returns it): `pdf` is then the density
    /// within that primitive. Other lights ignore `prim`.
    pub fn sample_li_prim(
        &self,
        geom: &SceneGeometry,
        p: Vec3,
        prim: u32,
        uc: f32,
        u: Vec2,
        wl: &SampledWavelengths,
    ) -> Option<LightSample> {
        match self {
            Light::Area(a) => a.sample_li_prim(geom, p, prim, u, wl),
            _ => self.sample_li(geom, p, uc, u, wl),
        }
    }

    /// The single direction from `p` toward a point-like source at `position`, with
    /// li = I_e(ω)/d² (None if the source sends nothing toward `p`).
    fn sample_li_from(
        &self,
        position: Vec3,
        p: Vec3,
        wl: &SampledWavelengths,
    ) -> Option<LightSample> {
        let (wi, dist, dist2) = toward(position, p)?;
        let at = EmissionPoint {
            p: position,
            n: None,
            tex: glam::Vec2::ZERO,
            inv_pdf: 1.0,
        };
        let intensity = self.emission_toward(&at, -wi, wl);
        if intensity.is_black() {
            return None;
        }
        Some(LightSample {
            wi,
            li: intensity / dist2,
            pdf: 1.0,
            dist,
            point: None,
            delta: true,
        })
    }

    /// Density (solid angle, excluding light selection) with which `sample_li` from `p` would
    /// have produced the ray that hit this area light at `hit`.
    pub fn pdf_li_hit(&self, geom: &SceneGeometry, p: Vec3, hit: &Hit) -> f32 {
        match self {
            Light::Area(a) => a.pdf_li_hit(geom, p, hit),
            _ => 0.0,
        }
    }

    /// Density (solid angle) with which [`Light::sample_li_prim`] from `p`, given the primitive
    /// hit, would have produced the ray that hit this area light at `hit`.
    pub fn pdf_li_hit_prim(&self, geom: &SceneGeometry, p: Vec3, hit: &Hit) -> f32 {
        match self {
            Light::Area(a) => a.pdf_li_hit_prim(geom, p, hit),
            _ => 0.0,
        }
    }

    /// Density (solid angle) with which [`Light::sample_li`] at `p` picks unit direction `wi`,
    /// for a light at infinity (zero for the others).
    pub fn pdf_li_escape(&self, p: Vec3, wi: Vec3) -> f32 {
        match self {
            Light::Environment(l) => l.pdf_li(p, wi),
            Light::Sky(l) => l.pdf_li(p, wi),
            Light::Sun(l) => l.pdf_li(wi),
            _ => 0.0,
        }
    }

    /// Radiance leaving an area light's surface toward the viewer, given the hit.
    pub fn emitted(&self, hit: &Hit, wl: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Light::Area(a) => a.emitted(hit, wl),
            _ => SampledSpectrum::ZERO,
        }
    }

    /// Radiance arriving along an escaped ray of unit direction `wi`.
    pub fn escaped(&self, wi: Vec3, wl: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Light::Environment(l) => l.escaped(wl),
            Light::Sky(l) => l.escaped(wi, wl),
            Light::Sun(l) => l.escaped(wi, wl),
            _ => SampledSpectrum::ZERO,
        }
    }
}

/// Unit direction, distance and squared distance from `p` to a point light at `position`
/// (None if they coincide).
pub(crate) fn toward(position: Vec3, p: Vec3) -> Option<(Vec3, f32, f32)> {
    let d = position - p;
    let dist2 = d.length_squared();
    if dist2 == 0.0 || !dist2.is_finite() {
        return None;
    }
    let dist = dist2.sqrt();
    Some((d / dist, dist, dist2))
}

/// The error for an amount of the wrong kind at `afield`; `allowed` lists the right ones.
fn wrong_amount(ctx: &Context, afield: &str, a: &Amount, allowed: &str) -> SceneError {
    ctx.err(
        afield,
        format!("{a:?} is not an amount for this light; use {allowed}"),
    )
}

/// The intensity (cd) of a point-like source given as `Intensity(cd)` or as `Flux(lm)`, where
/// `flux_per_cd` is the flux (lm) it sends per candela of its axial intensity.
fn intensity_cd(
    ctx: &Context,
    afield: &str,
    amount: Amount,
    flux_per_cd: f64,
) -> Result<f64, SceneError> {
    match amount {
        Amount::Intensity(i) => ctx.nonneg(afield, i),
        Amount::Flux(phi) => Ok(ctx.nonneg(afield, phi)? / flux_per_cd),
        a => Err(wrong_amount(ctx, afield, &a, "Intensity(cd) or Flux(lm)")),
    }
}
