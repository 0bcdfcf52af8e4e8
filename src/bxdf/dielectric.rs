//! Dielectric interface (glass): smooth (delta reflection + refraction) or rough
//! (microfacet reflection and transmission, Walter et al. 2007, "Microfacet Models for
//! Refraction through Rough Surfaces"; pbrt-v4 §9.5/§9.7 `DielectricBxDF`), with the exact
//! unpolarised Fresnel factor. The index may depend on wavelength ([`Ior`]): then refraction
//! disperses and the path keeps only its hero wavelength
//! ([`SampledWavelengths::terminate_secondary`]).
//!
//! Sign conventions: the normal +z points to the outside; `eta` = n_inside/n_outside.
//! Radiance is carried (camera paths), so transmitted f is divided by η'² (pbrt-v4 §9.5.2);
//! the BSDF is then reciprocal in the generalised sense f(ωo,ωi)/η_i² = f(ωi,ωo)/η_o².

use super::fresnel::{fr_dielectric, reflect, refract};
use super::ior::Ior;
use super::microfacet::Microfacet;
use super::{BsdfSample, MaterialFlags};
use crate::description::context::{Context, SceneError};
use crate::description::schema::{DistributionDesc, IorDesc, MaskingDesc};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct Dielectric {
    pub ior: Ior,
    pub mf: Microfacet,
}

/// A value for the hero lane only (the others are dropped) or for every lane.
#[inline]
fn lanes(v: f32, hero_only: bool) -> SampledSpectrum {
    if hero_only {
        let mut s = SampledSpectrum::ZERO;
        s[0] = v;
        s
    } else {
        SampledSpectrum::splat(v)
    }
}

impl Dielectric {
    /// The material at `field` from its description (Smith masking).
    pub fn build(
        ctx: &Context,
        field: &str,
        ior: &IorDesc,
        roughness: f32,
        roughness_v: Option<f32>,
        distribution: DistributionDesc,
    ) -> Result<Self, SceneError> {
        let ior = Ior::build(ctx, &format!("{field}.ior"), ior)?;
        let mut mf = Microfacet::build(
            ctx,
            field,
            distribution,
            MaskingDesc::Smith,
            roughness,
            roughness_v,
        )?;
        // An index of 1 hides the interface: every microfacet passes light straight on, a delta
        // that a rough lobe cannot represent (its density is infinite; within 10⁻⁵ of 1 the
        // transmitted lobe is narrower than single precision resolves). Within that distance
        // of 1 the smooth interface is exact to 10⁻⁵ rad in direction and 10⁻¹⁰ in reflectance.
        let (lo, hi) = ior.range();
        if (lo - 1.0).abs() <= 1e-5 && (hi - 1.0).abs() <= 1e-5 {
            mf = Microfacet::isotropic(mf.dist, 0.0);
        }
        Ok(Dielectric { ior, mf })
    }

    /// A smooth interface is all delta; a rough one has no delta lobe.
    pub fn flags(&self) -> MaterialFlags {
        if self.mf.effectively_smooth() {
            MaterialFlags::ALL_DELTA
        } else {
            MaterialFlags::NONE
        }
    }

    /// True if the index varies with wavelength.
    pub fn dispersive(&self) -> bool {
        !self.ior.is_constant()
    }

    /// Called at each hit before eval/pdf/sample: a rough dispersive interface refracts each
    /// wavelength into a different lobe, so the path keeps only its hero wavelength (as pbrt-v4
    /// does at BSDF creation). A smooth one terminates only when it refracts (in `sample`).
    pub fn prepare(&self, wl: &mut SampledWavelengths) {
        if self.dispersive() && !self.mf.effectively_smooth() {
            wl.terminate_secondary();
        }
    }

    #[inline]
    pub(crate) fn eta(&self, wl: &SampledWavelengths) -> f32 {
        self.ior.at(wl.lambda[0])
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3, wl: &SampledWavelengths) -> SampledSpectrum {
        if self.mf.effectively_smooth() {
            return SampledSpectrum::ZERO;
        }
        let eta = self.eta(wl);
        lanes(self.eval_scalar(wo, wi, eta), self.dispersive())
    }

    /// Generalised half vector and (reflect?, η') for a pair, or None if degenerate.
    #[inline]
    fn half_vector(wo: Vec3, wi: Vec3, eta: f32) -> Option<(Vec3, bool, f32)> {
        let (co, ci) = (wo.z, wi.z);
        if co == 0.0 || ci == 0.0 {
            return None;
        }
        let reflect = co * ci > 0.0;
        let etap = if reflect {
            1.0
        } else if co > 0.0 {
            eta
        } else {
            1.0 / eta
        };
        let wm = wi * etap + wo;
        if wm.length_squared() == 0.0 {
            return None;
        }
        let mut wm = wm.normalize();
        if wm.z < 0.0 {
            wm = -wm;
        }
        // Discard back-facing microfacets.
        if wm.dot(wi) * ci < 0.0 || wm.dot(wo) * co < 0.0 {
            return None;
        }
        Some((wm, reflect, etap))
    }

    pub fn eval_scalar(&self, wo: Vec3, wi: Vec3, eta: f32) -> f32 {
        let Some((wm, reflect, etap)) = Self::half_vector(wo, wi, eta) else {
            return 0.0;
        };
        let (co, ci) = (wo.z, wi.z);
        let f = fr_dielectric(wo.dot(wm), eta);
        let d = self.mf.d(wm);
        let g = self.mf.g(wo, wi, wm);
        if reflect {
            d * g * f / (4.0 * ci * co).abs()
        } else {
            let denom = (wi.dot(wm) + wo.dot(wm) / etap).powi(2) * ci * co;
            let ft = d * (1.0 - f) * g * (wi.dot(wm) * wo.dot(wm) / denom).abs();
            ft / (etap * etap)
        }
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3, wl: &SampledWavelengths) -> f32 {
        if self.mf.effectively_smooth() {
            return 0.0;
        }
        self.pdf_scalar(wo, wi, self.eta(wl))
    }

    pub fn pdf_scalar(&self, wo: Vec3, wi: Vec3, eta: f32) -> f32 {
        let Some((wm, reflect, etap)) = Self::half_vector(wo, wi, eta) else {
            return 0.0;
        };
        let r = fr_dielectric(wo.dot(wm), eta);
        let t = 1.0 - r;
        if reflect {
            self.mf.pdf_wm(wo, wm) / (4.0 * wo.dot(wm).abs()) * r
        } else {
            let denom = (wi.dot(wm) + wo.dot(wm) / etap).powi(2);
            let dwm_dwi = wi.dot(wm).abs() / denom;
            self.mf.pdf_wm(wo, wm) * dwm_dwi * t
        }
    }

    pub fn sample(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        wl: &mut SampledWavelengths,
    ) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let eta = self.eta(wl);
        if self.mf.effectively_smooth() {
            let r = fr_dielectric(wo.z, eta);
            let t = 1.0 - r;
            if uc < r {
                let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                // Reflection does not depend on λ but its weight does: per-lane R.
                let mut f = SampledSpectrum::ZERO;
                for i in 0..crate::spectrum::N_LAMBDA {
                    f[i] = if self.dispersive() {
                        fr_dielectric(wo.z, self.ior.at(wl.lambda[i]))
                    } else {
                        r
                    } / wi.z.abs();
                }
                if wl.secondary_terminated() {
                    f = lanes(f[0], true);
                }
                return Some(BsdfSample {
                    wi,
                    f,
                    pdf: r,
                    specular: true,
                });
            }
            let (wi, etap) = refract(wo, Vec3::Z, eta)?;
            if self.dispersive() {
                wl.terminate_secondary();
            }
            let ft = t / wi.z.abs() / (etap * etap);
            return Some(BsdfSample {
                wi,
                f: lanes(ft, self.dispersive()),
                pdf: t,
                specular: true,
            });
        }
        // Rough: sample a visible normal, then reflect or refract through it.
        let wm = self.mf.sample_wm(wo, u);
        let r = fr_dielectric(wo.dot(wm), eta);
        let wi = if uc < r {
            let wi = reflect(wo, wm);
            if wi.z * wo.z <= 0.0 {
                return None;
            }
            wi
        } else {
            let (wi, _) = refract(wo, wm, eta)?;
            if wi.z * wo.z >= 0.0 {
                return None;
            }
            wi
        };
        let pdf = self.pdf_scalar(wo, wi, eta);
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: lanes(self.eval_scalar(wo, wi, eta), self.dispersive()),
            pdf,
            specular: false,
        })
    }
}
