//! Coated diffuse ("plastic"): a Lambertian base of reflectance ρ(λ) under a smooth,
//! non-absorbing dielectric layer of index η (Weidlich & Wilkie 2007, "Arbitrarily Layered
//! Micro-Facet Surfaces"; Mitsuba 0.6 `plastic`, Jakob's documentation §8.2). Two lobes:
//!
//! * specular: the coating's Fresnel reflection F(θo, η) (a delta lobe);
//! * diffuse: f = (1 − F(θi)) (1 − F(θo)) ρ / (π η² (1 − ρ F̄ᵢ)), where F̄ᵢ is the
//!   cosine-weighted hemispherical reflectance of the layer seen from inside, so that light
//!   bouncing between base and coating is summed in closed form.
//!
//! With 1 − F̄ᵢ = (1 − F̄ₑ)/η² (reciprocity of the averages), the diffuse albedo is
//! (1 − F(θo)) ρ (1 − F̄ᵢ)/(1 − ρ F̄ᵢ) ≤ 1 − F(θo): a white base (ρ = 1) loses nothing, which
//! the furnace tests check. f is symmetric in ωo, ωi (reciprocal).

use super::fresnel::fr_dielectric;
use super::{same_hemisphere, sample_cosine_hemisphere, BsdfSample};
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Debug)]
pub struct Coated {
    pub base: DenseSpectrum,
    pub eta: f32,
    /// Internal diffuse reflectance F̄ᵢ of the coating.
    pub fdr_internal: f32,
}

/// Cosine-weighted hemispherical average of the Fresnel reflectance, 2∫F(μ,η) μ dμ, for light
/// arriving from outside (η = n_in/n_out; pass 1/η for the inside view). Gauss–Legendre on
/// sub-intervals in μ (the integrand has a kink at the critical angle when η < 1).
pub fn fresnel_diffuse_reflectance(eta: f32) -> f64 {
    // 8-point Gauss–Legendre on 256 sub-intervals.
    const X: [f64; 4] = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    const W: [f64; 4] = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    let n = 256;
    let mut s = 0.0;
    for k in 0..n {
        let (a, b) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
        let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
        for j in 0..4 {
            for sgn in [-1.0, 1.0] {
                let mu = m + sgn * h * X[j];
                s += W[j] * h * fr_dielectric(mu as f32, eta) as f64 * mu;
            }
        }
    }
    2.0 * s
}

impl Coated {
    pub fn new(base: DenseSpectrum, eta: f32) -> Self {
        let fe = fresnel_diffuse_reflectance(eta);
        let eta2 = (eta as f64) * (eta as f64);
        // 1 − F̄ᵢ = (1 − F̄ₑ)/η², exact for a non-absorbing interface.
        let fdr_internal = (1.0 - (1.0 - fe) / eta2) as f32;
        Self {
            base,
            eta,
            fdr_internal,
        }
    }

    #[inline]
    fn specular_probability(&self, wo: Vec3) -> f32 {
        fr_dielectric(wo.z.abs(), self.eta)
    }

    fn diffuse(&self, wo: Vec3, wi: Vec3, wl: &SampledWavelengths) -> SampledSpectrum {
        let fo = fr_dielectric(wo.z.abs(), self.eta);
        let fi = fr_dielectric(wi.z.abs(), self.eta);
        let rho = self.base.sample(wl);
        let mut f = SampledSpectrum::ZERO;
        let k = (1.0 - fo) * (1.0 - fi) * FRAC_1_PI / (self.eta * self.eta);
        for i in 0..crate::spectrum::N_LAMBDA {
            f[i] = k * rho[i] / (1.0 - rho[i] * self.fdr_internal);
        }
        f
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3, wl: &SampledWavelengths) -> SampledSpectrum {
        if !same_hemisphere(wo, wi) {
            return SampledSpectrum::ZERO;
        }
        self.diffuse(wo, wi, wl)
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        (1.0 - self.specular_probability(wo)) * wi.z.abs() * FRAC_1_PI
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
        let ps = self.specular_probability(wo);
        if uc < ps {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return Some(BsdfSample {
                wi,
                f: SampledSpectrum::splat(ps / wi.z.abs()),
                pdf: ps,
                specular: true,
            });
        }
        let mut wi = sample_cosine_hemisphere(u);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        let pdf = self.pdf(wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: self.diffuse(wo, wi, wl),
            pdf,
            specular: false,
        })
    }
}
