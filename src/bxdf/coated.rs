//! Coated diffuse ("plastic"): a Lambertian base of reflectance ρ(λ) under a non-absorbing
//! dielectric coat of index η, smooth or rough (Weidlich & Wilkie 2007, "Arbitrarily Layered
//! Micro-Facet Surfaces"; Mitsuba 0.6 `plastic` / `roughplastic`). Two lobes:
//!
//! * specular: the coat's reflection — a delta lobe of weight F(θo, η) when smooth, else
//!   Torrance–Sparrow microfacet reflection D G F / (4 cos θo cos θi) (Smith, height-correlated);
//! * diffuse: f = (1 − E(θi)) (1 − E(θo)) ρ / (π η² (1 − ρ F̄ᵢ)), where E(θ) is the directional
//!   albedo of the specular lobe (F(θ) when smooth; tabulated at construction when rough) and
//!   F̄ᵢ = 1 − (1 − Ē)/η² the coat's reflectance for diffuse light from inside (Ē = 2∫E μ dμ),
//!   which sums the bounces between base and coat in closed form.
//!
//! The diffuse albedo is then (1 − E(θo)) ρ (1 − F̄ᵢ)/(1 − ρ F̄ᵢ) ≤ 1 − E(θo): a white base
//! (ρ = 1) loses nothing (exactly when smooth; to the accuracy of the E table when rough), which
//! the furnace tests check. f is symmetric in ωo, ωi (reciprocal). Two-sided.
//!
//! The diffuse lobe is evaluated as T(θi) T(θo) ρ / (π (η² (1 − ρ) + ρ T̄)) with T = 1 − E
//! computed directly (never as 1 minus a reflectance) and T̄ = 1 − Ē, in f64: the same value,
//! but finite and exact for any index, where 1 − ρ F̄ᵢ rounds to 0 for a white base under a
//! coat of index 10⁴ and η² leaves single precision past 10¹⁹.

use super::conductor::{flip_up, sample_microfacet_reflection};
use super::fresnel::{fr_dielectric, reflect, tr_dielectric};
use super::microfacet::Microfacet;
use super::{same_hemisphere, BsdfSample, MaterialFlags};
use crate::description::context::{Context, Role, SceneError};
use crate::description::schema::{DistributionDesc, MaskingDesc, SpectrumDesc};
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// Entries of the specular-albedo table, uniform in √(cos θ) on [0, 1]: a nearly smooth coat's
/// albedo changes within cos θ ≲ α of grazing, which a grid uniform in cos θ steps over.
const E_N: usize = 64;

#[derive(Clone, Debug)]
pub struct Coated {
    pub base: DenseSpectrum,
    pub eta: f32,
    /// Roughness of the coat (effectively smooth: a delta specular lobe).
    pub mf: Microfacet,
    /// η².
    eta2: f64,
    /// T̄ = 1 − Ē, the cosine-weighted average of the coat's transmittance T(μ) = 1 − E(μ).
    t_avg: f64,
    /// T(μ) = 1 − E(μ) at μ = (k/(E_N − 1))² (rough coats only).
    t_table: Vec<f32>,
}

/// Cosine-weighted hemispherical average 2∫g(μ) μ dμ by 8-point Gauss–Legendre on 256
/// sub-intervals of [0, 1].
fn hemispherical_average(g: impl Fn(f64) -> f64) -> f64 {
    cosine_integral(&g, 0.0, 1.0)
}

/// 2∫ₐᵇ g(μ) μ dμ by 8-point Gauss–Legendre on 256 sub-intervals of [a, b].
fn cosine_integral(g: &impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
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
    let w = b - a;
    for k in 0..n {
        let (a, b) = (
            a + w * k as f64 / n as f64,
            a + w * (k + 1) as f64 / n as f64,
        );
        let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
        for j in 0..4 {
            for sgn in [-1.0, 1.0] {
                let mu = m + sgn * h * X[j];
                s += W[j] * h * g(mu) * mu;
            }
        }
    }
    2.0 * s
}

/// Cosine-weighted hemispherical average of the Fresnel reflectance, 2∫F(μ,η) μ dμ, for light
/// arriving from outside (η = n_in/n_out).
pub fn fresnel_diffuse_reflectance(eta: f32) -> f64 {
    hemispherical_average(|mu| fr_dielectric(mu as f32, eta) as f64)
}

impl Coated {
    /// The material at `field` from its description (`ior` the coat's constant index;
    /// isotropic roughness, Smith masking).
    pub fn build(
        ctx: &Context,
        field: &str,
        base: &SpectrumDesc,
        ior: f32,
        roughness: f32,
        distribution: DistributionDesc,
    ) -> Result<Self, SceneError> {
        if !ior.is_finite() || ior <= 0.0 {
            return Err(ctx.err(
                format!("{field}.ior"),
                format!("the refractive index must be finite and greater than 0, got {ior}"),
            ));
        }
        Ok(Self::new(
            ctx.spectrum(&format!("{field}.base"), base, Role::Reflectance)?,
            ior,
            Microfacet::build(
                ctx,
                field,
                distribution,
                MaskingDesc::Smith,
                roughness,
                None,
            )?,
        ))
    }

    /// A smooth coat reflects through a delta lobe (beside the diffuse one).
    pub fn flags(&self) -> MaterialFlags {
        if self.mf.effectively_smooth() {
            MaterialFlags::DELTA
        } else {
            MaterialFlags::NONE
        }
    }

    pub fn new(base: DenseSpectrum, eta: f32, mf: Microfacet) -> Self {
        let eta64 = eta as f64;
        let mut c = Self {
            base,
            eta,
            mf,
            eta2: eta64 * eta64,
            t_avg: 0.0,
            t_table: Vec::new(),
        };
        c.t_avg = if mf.effectively_smooth() {
            // Below 1 the coat transmits only inside the critical cone μ > √(1 − η²): the
            // quadrature is split there, or it would miss a narrow cone altogether.
            let t = |mu: f64| tr_dielectric(mu, eta64);
            let mu_c = if eta < 1.0 {
                ((1.0 - eta64) * (1.0 + eta64)).sqrt()
            } else {
                0.0
            };
            cosine_integral(&t, 0.0, mu_c) + cosine_integral(&t, mu_c, 1.0)
        } else {
            c.t_table = (0..E_N)
                .map(|k| {
                    let mu = (k as f32 / (E_N - 1) as f32).powi(2).max(1e-6);
                    c.rough_transmittance(mu)
                })
                .collect();
            hemispherical_average(|mu| c.t(mu as f32) as f64)
        };
        c
    }

    /// 1 − E of the rough specular lobe at cos θo = `mu`, E its directional albedo: the
    /// visible-normal estimator of E is F(ωo·ωm) G₂/G₁(ωo), so 1 − E is the mean of
    /// (1 − F) G₂/G₁ + (1 − G₂/G₁), with 1 − F and 1 − G₂/G₁ = Λ(ωi)/(1 + Λ(ωo) + Λ(ωi))
    /// formed directly, on a stratified 64 × 64 grid (the lobe is isotropic in the tangent
    /// plane only for isotropic α; the azimuth φo = 45° is used otherwise).
    fn rough_transmittance(&self, mu: f32) -> f32 {
        let s = (1.0 - mu * mu).max(0.0).sqrt();
        let wo = Vec3::new(
            s * std::f32::consts::FRAC_1_SQRT_2,
            s * std::f32::consts::FRAC_1_SQRT_2,
            mu,
        );
        let n = 64;
        let mut sum = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let wm = self.mf.sample_wm(wo, u);
                let wi = reflect(wo, wm);
                if wi.z <= 0.0 {
                    sum += 1.0;
                    continue;
                }
                let (lo, li) = (self.mf.lambda(wo) as f64, self.mf.lambda(wi) as f64);
                let (kept, masked) = if li.is_infinite() {
                    (0.0, 1.0)
                } else if lo.is_infinite() {
                    (1.0, 0.0)
                } else {
                    ((1.0 + lo) / (1.0 + lo + li), li / (1.0 + lo + li))
                };
                sum += tr_dielectric(wo.dot(wm) as f64, self.eta as f64) * kept + masked;
            }
        }
        (sum / (n * n) as f64) as f32
    }

    /// Specular albedo E(μ).
    #[inline]
    fn e(&self, mu: f32) -> f32 {
        if self.t_table.is_empty() {
            return fr_dielectric(mu.abs().min(1.0), self.eta);
        }
        1.0 - self.t(mu)
    }

    /// The coat's transmittance T(μ) = 1 − E(μ), formed without the subtraction.
    #[inline]
    fn t(&self, mu: f32) -> f32 {
        let mu = mu.abs().min(1.0);
        if self.t_table.is_empty() {
            return tr_dielectric(mu as f64, self.eta as f64) as f32;
        }
        let x = mu.sqrt() * (E_N - 1) as f32;
        let i = (x as usize).min(E_N - 2);
        let t = x - i as f32;
        self.t_table[i] * (1.0 - t) + self.t_table[i + 1] * t
    }

    /// Probability of choosing the specular lobe.
    #[inline]
    fn specular_probability(&self, wo: Vec3) -> f32 {
        self.e(wo.z)
    }

    fn diffuse(&self, wo: Vec3, wi: Vec3, rho: SampledSpectrum) -> SampledSpectrum {
        let k = self.t(wo.z) as f64 * self.t(wi.z) as f64 * std::f64::consts::FRAC_1_PI;
        let mut f = SampledSpectrum::ZERO;
        for i in 0..crate::spectrum::N_LAMBDA {
            let r = rho[i] as f64;
            // η² (1 − ρ F̄ᵢ); 0 only for a white base under a coat that transmits nothing.
            let d = self.eta2 * (1.0 - r) + r * self.t_avg;
            if d > 0.0 {
                f[i] = (k * r / d) as f32;
            }
        }
        f
    }

    /// Rough specular lobe (scalar: the coat is not dispersive).
    fn specular(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (wo, wi) = (flip_up(wo), flip_up(wi));
        let wm = (wo + wi).normalize_or_zero();
        if wm == Vec3::ZERO || wo.z == 0.0 || wi.z == 0.0 {
            return 0.0;
        }
        // A back-facing microfacet reflects nothing (and `specular_pdf` is 0 there). Rounding
        // makes the half vector tilt so far only for grazing pairs of nearly opposite azimuth.
        if wo.dot(wm) <= 0.0 || wi.dot(wm) <= 0.0 {
            return 0.0;
        }
        self.mf.d(wm) * self.mf.g(wo, wi, wm) * fr_dielectric(wo.dot(wm), self.eta)
            / (4.0 * wo.z * wi.z)
    }

    fn specular_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (wo, wi) = (flip_up(wo), flip_up(wi));
        let wm = (wo + wi).normalize_or_zero();
        let c = wo.dot(wm);
        if wm == Vec3::ZERO || c <= 0.0 {
            return 0.0;
        }
        self.mf.pdf_wm(wo, wm) / (4.0 * c)
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3, wl: &SampledWavelengths) -> SampledSpectrum {
        self.eval_base(wo, wi, self.base.sample(wl))
    }

    /// [`Coated::eval`] with the base reflectance `rho` (per lane) in place of `base`.
    pub fn eval_base(&self, wo: Vec3, wi: Vec3, rho: SampledSpectrum) -> SampledSpectrum {
        if !same_hemisphere(wo, wi) {
            return SampledSpectrum::ZERO;
        }
        let mut f = self.diffuse(wo, wi, rho);
        if !self.mf.effectively_smooth() {
            f += SampledSpectrum::splat(self.specular(wo, wi));
        }
        f
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        let ps = self.specular_probability(wo);
        let mut p = (1.0 - ps) * wi.z.abs() * FRAC_1_PI;
        if !self.mf.effectively_smooth() {
            p += ps * self.specular_pdf(wo, wi);
        }
        p
    }

    pub fn sample(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        wl: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        self.sample_base(wo, uc, u, self.base.sample(wl))
    }

    /// [`Coated::sample`] with the base reflectance `rho` (per lane) in place of `base`.
    pub fn sample_base(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        rho: SampledSpectrum,
    ) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let ps = self.specular_probability(wo);
        if uc < ps {
            if self.mf.effectively_smooth() {
                let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                return Some(BsdfSample {
                    wi,
                    f: SampledSpectrum::splat(ps / wi.z.abs()),
                    pdf: ps,
                    specular: true,
                });
            }
            let wi = sample_microfacet_reflection(&self.mf, wo, u)?;
            let pdf = self.pdf(wo, wi);
            if pdf <= 0.0 {
                return None;
            }
            return Some(BsdfSample {
                wi,
                f: self.eval_base(wo, wi, rho),
                pdf,
                specular: false,
            });
        }
        let mut wi = crate::sampling::cosine_hemisphere(u);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        let pdf = self.pdf(wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: self.eval_base(wo, wi, rho),
            pdf,
            specular: false,
        })
    }
}
