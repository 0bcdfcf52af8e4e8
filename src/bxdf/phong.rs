//! Energy-normalised modified Phong (Lafortune & Willems 1994, "Using the Modified Phong
//! Reflectance Model for Physically Based Rendering"):
//! f = k_d/π + k_s (n + 2)/(2π) cosⁿ α, α the angle between ωi and the mirror direction of ωo.
//! Reciprocal; energy-conserving when k_d + k_s ≤ 1 (checked at scene build). Sampled by
//! choosing the lobe in proportion to the mean k_d and k_s, then cosine-weighted or
//! cosⁿ-around-the-mirror-direction. Two-sided.

use super::{same_hemisphere, BsdfSample, Frame, MaterialFlags};
use crate::description::context::{Context, Role, SceneError};
use crate::description::schema::SpectrumDesc;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

#[derive(Clone, Debug)]
pub struct Phong {
    pub diffuse: DenseSpectrum,
    pub specular: DenseSpectrum,
    pub exponent: f32,
    /// Probability of sampling the specular lobe.
    p_spec: f32,
}

impl Phong {
    pub const FLAGS: MaterialFlags = MaterialFlags::NONE;

    /// The material at `field` from its description, refusing diffuse + specular > 1 at any
    /// wavelength.
    pub fn build(
        ctx: &Context,
        field: &str,
        diffuse: &SpectrumDesc,
        specular: &SpectrumDesc,
        exponent: f32,
    ) -> Result<Self, SceneError> {
        let kd = ctx.spectrum(&format!("{field}.diffuse"), diffuse, Role::Reflectance)?;
        let ks = ctx.spectrum(&format!("{field}.specular"), specular, Role::Reflectance)?;
        if !exponent.is_finite() || exponent < 0.0 {
            return Err(ctx.err(
                format!("{field}.exponent"),
                format!("must be a finite number ≥ 0, got {exponent}"),
            ));
        }
        if let Some(i) = (0..kd.values.len()).find(|&i| kd.values[i] + ks.values[i] > 1.0) {
            return Err(ctx.err(
                field,
                format!(
                    "diffuse + specular = {} at {} nm exceeds 1; the surface would create energy",
                    kd.values[i] + ks.values[i],
                    360 + i
                ),
            ));
        }
        Ok(Self::new(kd, ks, exponent))
    }

    pub fn new(diffuse: DenseSpectrum, specular: DenseSpectrum, exponent: f32) -> Self {
        let d = diffuse.values.iter().sum::<f32>();
        let s = specular.values.iter().sum::<f32>();
        let p_spec = if d + s > 0.0 { s / (d + s) } else { 0.5 };
        Self {
            diffuse,
            specular,
            exponent,
            p_spec,
        }
    }

    #[inline]
    fn mirror(wo: Vec3) -> Vec3 {
        Vec3::new(-wo.x, -wo.y, wo.z)
    }

    fn lobe(&self, wo: Vec3, wi: Vec3) -> f32 {
        let c = Self::mirror(wo).dot(wi).max(0.0);
        c.powf(self.exponent)
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3, wl: &SampledWavelengths) -> SampledSpectrum {
        if !same_hemisphere(wo, wi) {
            return SampledSpectrum::ZERO;
        }
        let n = self.exponent;
        self.diffuse.sample(wl) * FRAC_1_PI
            + self.specular.sample(wl) * ((n + 2.0) / (2.0 * PI) * self.lobe(wo, wi))
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        let n = self.exponent;
        (1.0 - self.p_spec) * wi.z.abs() * FRAC_1_PI
            + self.p_spec * (n + 1.0) / (2.0 * PI) * self.lobe(wo, wi)
    }

    pub fn sample(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        wl: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let wi = if uc < self.p_spec {
            // cosⁿ lobe about the mirror direction: cos α = u^(1/(n+1)).
            let cos_a = u.x.powf(1.0 / (self.exponent + 1.0));
            let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
            let phi = 2.0 * PI * u.y;
            let local = Vec3::new(sin_a * phi.cos(), sin_a * phi.sin(), cos_a);
            Frame::from_normal(Self::mirror(wo).normalize()).to_world(local)
        } else {
            let mut wi = crate::sampling::cosine_hemisphere(u);
            if wo.z < 0.0 {
                wi.z = -wi.z;
            }
            wi
        };
        if !same_hemisphere(wo, wi) {
            return None;
        }
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
}
