//! Conductors: a smooth mirror (delta lobe) or Torrance–Sparrow microfacet reflection
//! f = D(ωm) F(ωo·ωm) G(ωo, ωi) / (4 cos θo cos θi) with the exact complex-index Fresnel
//! factor per wavelength (pbrt-v4 §9.6, `ConductorBxDF`; Walter et al. 2007).
//! Two-sided: it reflects on whichever side `wo` is.

use super::fresnel::{fr_conductor, reflect};
use super::ior::ConductorIor;
use super::microfacet::Microfacet;
use super::{same_hemisphere, BsdfSample, MaterialFlags};
use crate::description::context::{Context, SceneError};
use crate::description::schema::{DistributionDesc, MaskingDesc, SpectrumDesc};
use crate::spectrum::{SampledSpectrum, SampledWavelengths, N_LAMBDA};
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct Conductor {
    pub ior: ConductorIor,
    pub mf: Microfacet,
}

impl Conductor {
    /// The material at `field` from its description: a named `metal` or `n` and `k` spectra,
    /// and the microfacet roughness.
    #[allow(clippy::too_many_arguments)]
    pub fn build(
        ctx: &Context,
        field: &str,
        metal: Option<&str>,
        n: Option<&SpectrumDesc>,
        k: Option<&SpectrumDesc>,
        roughness: f32,
        roughness_v: Option<f32>,
        distribution: DistributionDesc,
        masking: MaskingDesc,
    ) -> Result<Self, SceneError> {
        Ok(Conductor {
            ior: ConductorIor::build(ctx, field, metal, n, k)?,
            mf: Microfacet::build(ctx, field, distribution, masking, roughness, roughness_v)?,
        })
    }

    /// A smooth mirror is all delta; a rough one has no delta lobe.
    pub fn flags(&self) -> MaterialFlags {
        if self.mf.effectively_smooth() {
            MaterialFlags::ALL_DELTA
        } else {
            MaterialFlags::NONE
        }
    }

    #[inline]
    fn fresnel(&self, cos: f32, wl: &SampledWavelengths) -> SampledSpectrum {
        let (n, k) = self.ior.sample(wl);
        let mut f = SampledSpectrum::ZERO;
        for i in 0..N_LAMBDA {
            f[i] = fr_conductor(cos.abs(), n[i], k[i]);
        }
        f
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3, wl: &SampledWavelengths) -> SampledSpectrum {
        eval_with(&self.mf, wo, wi, |c| self.fresnel(c, wl))
    }

    pub fn sample(&self, wo: Vec3, u: Vec2, wl: &SampledWavelengths) -> Option<BsdfSample> {
        sample_with(&self.mf, wo, u, |c| self.fresnel(c, wl))
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        pdf_with(&self.mf, wo, wi)
    }
}

/// A conductor of index n = 1 and extinction k per lane of the path's wavelengths (a
/// textured glTF metal at one hit: k from its base colour, as [`Material::MetalRough`]
/// resolves it).
#[derive(Clone, Copy, Debug)]
pub struct ConductorAt {
    pub mf: Microfacet,
    pub k: SampledSpectrum,
}

impl ConductorAt {
    /// The extinction coefficient k = 2√(F₀/(1 − F₀)) that gives a conductor of n = 1 the
    /// normal-incidence reflectance F₀ (capped at `max`): F₀ = k²/(4 + k²).
    #[inline]
    pub fn k_of_reflectance(f0: f64, max: f64) -> f64 {
        let f0 = f0.clamp(0.0, max);
        2.0 * (f0 / (1.0 - f0)).sqrt()
    }

    #[inline]
    fn fresnel(&self, cos: f32) -> SampledSpectrum {
        let mut f = SampledSpectrum::ZERO;
        for i in 0..N_LAMBDA {
            f[i] = fr_conductor(cos.abs(), 1.0, self.k[i]);
        }
        f
    }

    pub fn flags(&self) -> MaterialFlags {
        if self.mf.effectively_smooth() {
            MaterialFlags::ALL_DELTA
        } else {
            MaterialFlags::NONE
        }
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3) -> SampledSpectrum {
        eval_with(&self.mf, wo, wi, |c| self.fresnel(c))
    }

    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        sample_with(&self.mf, wo, u, |c| self.fresnel(c))
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        pdf_with(&self.mf, wo, wi)
    }
}

/// f(wo, wi) of a conductor of roughness `mf` and Fresnel reflectance `fresnel(cos θ)`.
#[inline]
fn eval_with(
    mf: &Microfacet,
    wo: Vec3,
    wi: Vec3,
    fresnel: impl Fn(f32) -> SampledSpectrum,
) -> SampledSpectrum {
    if !same_hemisphere(wo, wi) || mf.effectively_smooth() {
        return SampledSpectrum::ZERO;
    }
    let (co, ci) = (wo.z.abs(), wi.z.abs());
    // On the +z side, as `pdf` and the sampling work.
    let (wo_u, wi_u) = (flip_up(wo), flip_up(wi));
    let wm = (wo_u + wi_u).normalize_or_zero();
    if wm == Vec3::ZERO || co == 0.0 || ci == 0.0 {
        return SampledSpectrum::ZERO;
    }
    // A back-facing microfacet reflects nothing (and `pdf` is 0 there). Rounding makes
    // the half vector tilt so far only for grazing pairs of nearly opposite azimuth.
    let cos_o = wo_u.dot(wm);
    if cos_o <= 0.0 || wi_u.dot(wm) <= 0.0 {
        return SampledSpectrum::ZERO;
    }
    let v = mf.d(wm) * mf.g(wo_u, wi_u, wm) / (4.0 * co * ci);
    fresnel(cos_o) * v
}

/// BSDF sampling of a conductor (see [`eval_with`]).
#[inline]
fn sample_with(
    mf: &Microfacet,
    wo: Vec3,
    u: Vec2,
    fresnel: impl Fn(f32) -> SampledSpectrum,
) -> Option<BsdfSample> {
    if wo.z == 0.0 {
        return None;
    }
    if mf.effectively_smooth() {
        let wi = Vec3::new(-wo.x, -wo.y, wo.z);
        let c = wi.z.abs();
        return Some(BsdfSample {
            wi,
            f: fresnel(c) / c,
            pdf: 1.0,
            specular: true,
        });
    }
    let wi = sample_microfacet_reflection(mf, wo, u)?;
    let pdf = pdf_with(mf, wo, wi);
    if pdf <= 0.0 {
        return None;
    }
    Some(BsdfSample {
        wi,
        f: eval_with(mf, wo, wi, fresnel),
        pdf,
        specular: false,
    })
}

/// Density of [`sample_with`].
#[inline]
fn pdf_with(mf: &Microfacet, wo: Vec3, wi: Vec3) -> f32 {
    if !same_hemisphere(wo, wi) || mf.effectively_smooth() {
        return 0.0;
    }
    let (wo_u, wi_u) = (flip_up(wo), flip_up(wi));
    let wm = (wo_u + wi_u).normalize_or_zero();
    if wm == Vec3::ZERO {
        return 0.0;
    }
    let c = wo_u.dot(wm);
    if c <= 0.0 {
        return 0.0;
    }
    mf.pdf_wm(wo_u, wm) / (4.0 * c)
}

#[inline]
/// Sample a microfacet normal visible from `wo` and reflect `wo` about it, working on the +z
/// side and mirroring back: the reflected direction on `wo`'s side, or None if it points
/// below the surface.
pub(crate) fn sample_microfacet_reflection(mf: &Microfacet, wo: Vec3, u: Vec2) -> Option<Vec3> {
    let wo_u = flip_up(wo);
    let wi_u = reflect(wo_u, mf.sample_wm(wo_u, u));
    if wi_u.z <= 0.0 {
        return None;
    }
    Some(Vec3::new(wi_u.x, wi_u.y, wi_u.z.copysign(wo.z)))
}

#[inline]
pub(crate) fn flip_up(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, w.z.abs())
}
