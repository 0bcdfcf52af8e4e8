//! Lambertian diffuse reflection: f = ρ(λ)/π, sampled with the cosine-weighted hemisphere.
//! Two-sided: it reflects on whichever side `wo` is.

use super::{same_hemisphere, BsdfSample, MaterialFlags};
use crate::description::context::{Context, Role, SceneError};
use crate::description::schema::SpectrumDesc;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Debug)]
pub struct Diffuse {
    /// Reflectance ρ(λ) ∈ [0, 1].
    pub reflectance: DenseSpectrum,
}

impl Diffuse {
    pub const FLAGS: MaterialFlags = MaterialFlags::NONE;

    /// The material at `field` from its description.
    pub fn build(
        ctx: &Context,
        field: &str,
        reflectance: &SpectrumDesc,
    ) -> Result<Self, SceneError> {
        Ok(Diffuse {
            reflectance: ctx.spectrum(
                &format!("{field}.reflectance"),
                reflectance,
                Role::Reflectance,
            )?,
        })
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3, wl: &SampledWavelengths) -> SampledSpectrum {
        if !same_hemisphere(wo, wi) {
            return SampledSpectrum::ZERO;
        }
        self.reflectance.sample(wl) * FRAC_1_PI
    }
    pub fn sample(&self, wo: Vec3, u: Vec2, wl: &SampledWavelengths) -> Option<BsdfSample> {
        let mut wi = crate::sampling::cosine_hemisphere(u);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        let pdf = crate::sampling::cosine_hemisphere_pdf(wi.z.abs());
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: self.reflectance.sample(wl) * FRAC_1_PI,
            pdf,
            specular: false,
        })
    }
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        crate::sampling::cosine_hemisphere_pdf(wi.z.abs())
    }
}
