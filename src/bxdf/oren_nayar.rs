//! Oren–Nayar rough diffuse reflection, the qualitative model (Oren & Nayar 1994,
//! "Generalization of Lambert's Reflectance Model", eq. 30; pbrt-v3 §8.4.2):
//! f = ρ/π (A + B max(0, cos(φi − φo)) sin α tan β), α = max(θi, θo), β = min(θi, θo),
//! A = 1 − σ²/(2(σ² + 0.33)), B = 0.45 σ²/(σ² + 0.09), σ the facet slope deviation (radians).
//! Sampled with the cosine-weighted hemisphere. Two-sided like [`super::Diffuse`].

use super::{same_hemisphere, BsdfSample, MaterialFlags};
use crate::description::context::{Context, Role, SceneError};
use crate::description::schema::SpectrumDesc;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Debug)]
pub struct OrenNayar {
    pub reflectance: DenseSpectrum,
    a: f32,
    b: f32,
}

impl OrenNayar {
    pub const FLAGS: MaterialFlags = MaterialFlags::NONE;

    /// The material at `field` from its description (`sigma_deg` in degrees, [0, 90]).
    pub fn build(
        ctx: &Context,
        field: &str,
        reflectance: &SpectrumDesc,
        sigma_deg: f32,
    ) -> Result<Self, SceneError> {
        let s = sigma_deg;
        if !s.is_finite() || !(0.0..=90.0).contains(&s) {
            return Err(ctx.err(
                format!("{field}.sigma_deg"),
                format!("must be an angle in [0, 90] degrees, got {s}"),
            ));
        }
        Ok(Self::new(
            ctx.spectrum(
                &format!("{field}.reflectance"),
                reflectance,
                Role::Reflectance,
            )?,
            s.to_radians(),
        ))
    }

    /// `sigma` in radians.
    pub fn new(reflectance: DenseSpectrum, sigma: f32) -> Self {
        let s2 = sigma * sigma;
        Self {
            reflectance,
            a: 1.0 - s2 / (2.0 * (s2 + 0.33)),
            b: 0.45 * s2 / (s2 + 0.09),
        }
    }

    fn factor(&self, wo: Vec3, wi: Vec3) -> f32 {
        let sin_i = (1.0 - wi.z * wi.z).max(0.0).sqrt();
        let sin_o = (1.0 - wo.z * wo.z).max(0.0).sqrt();
        let mut max_cos = 0.0;
        if sin_i > 1e-4 && sin_o > 1e-4 {
            let (ci, co) = (wi.x / sin_i, wo.x / sin_o);
            let (si, so) = (wi.y / sin_i, wo.y / sin_o);
            max_cos = (ci * co + si * so).max(0.0);
        }
        let (ai, ao) = (wi.z.abs(), wo.z.abs());
        let (sin_a, tan_b) = if ai > ao {
            (sin_o, sin_i / ai)
        } else {
            (sin_i, sin_o / ao)
        };
        self.a + self.b * max_cos * sin_a * tan_b
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3, wl: &SampledWavelengths) -> SampledSpectrum {
        if !same_hemisphere(wo, wi) {
            return SampledSpectrum::ZERO;
        }
        self.reflectance.sample(wl) * (FRAC_1_PI * self.factor(wo, wi))
    }

    pub fn sample(&self, wo: Vec3, u: Vec2, wl: &SampledWavelengths) -> Option<BsdfSample> {
        let (wi, pdf) = super::diffuse::cosine_direction(wo, u)?;
        Some(BsdfSample {
            wi,
            f: self.eval(wo, wi, wl),
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
