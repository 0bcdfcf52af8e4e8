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
        if !same_hemisphere(wo, wi) || self.mf.effectively_smooth() {
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
        let v = self.mf.d(wm) * self.mf.g(wo_u, wi_u, wm) / (4.0 * co * ci);
        self.fresnel(cos_o, wl) * v
    }

    pub fn sample(&self, wo: Vec3, u: Vec2, wl: &SampledWavelengths) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        if self.mf.effectively_smooth() {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            let c = wi.z.abs();
            return Some(BsdfSample {
                wi,
                f: self.fresnel(c, wl) / c,
                pdf: 1.0,
                specular: true,
            });
        }
        let wi = sample_microfacet_reflection(&self.mf, wo, u)?;
        let pdf = self.pdf(wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: self.eval(wo, wi, wl),
            pdf,
            specular: false,
        })
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !same_hemisphere(wo, wi) || self.mf.effectively_smooth() {
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
        self.mf.pdf_wm(wo_u, wm) / (4.0 * c)
    }
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
