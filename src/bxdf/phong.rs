//! Energy-normalised modified Phong (Lafortune & Willems 1994, "Using the Modified Phong
//! Reflectance Model for Physically Based Rendering"):
//! f = k_d/π + k_s (n + 2)/(2π) cosⁿ α, α the angle between ωi and the mirror direction of ωo.
//! Reciprocal; energy-conserving when k_d + k_s ≤ 1 (checked at scene build). Sampled by
//! choosing the lobe in proportion to the mean k_d and k_s, then cosine-weighted or
//! cosⁿ-around-the-mirror-direction. Two-sided.
//!
//! A large exponent makes a lobe narrower than single precision resolves through cos α (at
//! n = 10⁹ it is 3·10⁻⁵ rad wide, while cos α near 1 moves in steps of 6·10⁻⁸, a factor e⁶⁰
//! in cosⁿ α): the lobe is evaluated as exp(n ln(1 − d²/2)) with d = |ωr − ωi| the chord
//! between the unit mirror direction and ωi, and sampled through 1 − cos α =
//! −expm1(ln u / (n + 1)), both in f64.

use super::{same_hemisphere, BsdfSample, Frame, MaterialFlags};
use crate::description::context::{Context, Role, SceneError};
use crate::description::schema::SpectrumDesc;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

/// Largest exponent accepted: a lobe about 10⁻⁵ rad wide, still some hundred times the angular
/// resolution of single-precision directions (beyond 10¹⁵ the lobe vanishes between two
/// representable directions), and its peak (n + 2)/(2π) ≈ 1.6·10⁹ sr⁻¹ leaves headroom for the
/// brightest light (see `description::context::MAX_SPECTRAL_VALUE`).
pub const MAX_EXPONENT: f32 = 1e10;

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
        if !(0.0..=MAX_EXPONENT).contains(&exponent) {
            return Err(ctx.err(
                format!("{field}.exponent"),
                format!("must be a number ≥ 0 and ≤ {MAX_EXPONENT:e}, got {exponent}"),
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

    /// cosⁿ α, α the angle between `wi` and the mirror direction of `wo` (0 beyond 90°).
    fn lobe(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.exponent == 0.0 {
            return 1.0;
        }
        let d = Self::mirror(wo).normalize_or_zero() - wi.normalize_or_zero();
        // cos α = 1 − d²/2 for unit vectors.
        let half_d2 = 0.5 * d.length_squared() as f64;
        if half_d2 >= 1.0 {
            return 0.0;
        }
        (self.exponent as f64 * (-half_d2).ln_1p()).exp() as f32
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
            let one_minus_cos = -((u.x as f64).ln() / (self.exponent as f64 + 1.0)).exp_m1();
            let cos_a = (1.0 - one_minus_cos) as f32;
            let sin_a = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt() as f32;
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
