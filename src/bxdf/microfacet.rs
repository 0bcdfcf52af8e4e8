//! Microfacet normal distributions and masking-shadowing.
//!
//! * GGX / Trowbridge–Reitz and Beckmann, isotropic or anisotropic (α_x along the tangent,
//!   α_y along the bitangent) — Walter et al. 2007, "Microfacet Models for Refraction through
//!   Rough Surfaces"; Heitz 2014, "Understanding the Masking-Shadowing Function in
//!   Microfacet-Based BRDFs".
//! * Masking-shadowing: Smith height-correlated G₂ = 1/(1 + Λ(ωo) + Λ(ωi)) (Heitz 2014, §6),
//!   or the V-cavity G of Torrance–Sparrow / Cook–Torrance (Cook & Torrance 1982).
//! * Sampling: with Smith masking, the distribution of visible normals D_ωo(ωm) =
//!   G₁(ωo) max(0, ωo·ωm) D(ωm) / cos θo — GGX by Heitz 2018, "Sampling the GGX Distribution
//!   of Visible Normals" (JCGT 7(4)); Beckmann by the stretched 1-D slope inversion of
//!   Heitz & d'Eon 2014, "Importance Sampling Microfacet-Based BSDFs using the Distribution of
//!   Visible Normals", solved here by safeguarded Newton iteration in f64 (as pbrt-v3's
//!   numerical inversion). With V-cavity masking the normals are drawn from D(ωm) cos θm.

use crate::description::context::{Context, SceneError};
use crate::description::schema::{DistributionDesc, MaskingDesc};
use crate::sampling::special::{erf_inv, erfc};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Distribution {
    Ggx,
    Beckmann,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Masking {
    /// Smith, height-correlated; normals sampled from the visible-normal distribution.
    Smith,
    /// V-cavity (Torrance–Sparrow / Cook–Torrance); normals sampled from D cos θm.
    VCavity,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    pub dist: Distribution,
    pub alpha_x: f32,
    pub alpha_y: f32,
    pub masking: Masking,
}

impl Microfacet {
    pub fn new(dist: Distribution, alpha_x: f32, alpha_y: f32, masking: Masking) -> Self {
        Self {
            dist,
            alpha_x,
            alpha_y,
            masking,
        }
    }
    /// The microfacet lobe of the material at `field` from its description: `roughness` (α
    /// along the tangent) and `roughness_v` (α along the bitangent; default: isotropic).
    pub fn build(
        ctx: &Context,
        field: &str,
        dist: DistributionDesc,
        masking: MaskingDesc,
        roughness: f32,
        roughness_v: Option<f32>,
    ) -> Result<Self, SceneError> {
        let check = |name: &str, v: f32| {
            if !v.is_finite() || v < 0.0 {
                Err(ctx.err(
                    format!("{field}.{name}"),
                    format!("roughness must be a finite number ≥ 0, got {v}"),
                ))
            } else {
                Ok(v)
            }
        };
        let ax = check("roughness", roughness)?;
        let ay = match roughness_v {
            Some(v) => check("roughness_v", v)?,
            None => ax,
        };
        let dist = match dist {
            DistributionDesc::Ggx => Distribution::Ggx,
            DistributionDesc::Beckmann => Distribution::Beckmann,
        };
        let masking = match masking {
            MaskingDesc::Smith => Masking::Smith,
            MaskingDesc::VCavity => Masking::VCavity,
        };
        // Below 1e-3 the lobe is a delta; keep both axes consistent.
        let (ax, ay) = if ax.max(ay) < 1e-3 {
            (0.0, 0.0)
        } else {
            (ax.max(1e-3), ay.max(1e-3))
        };
        Ok(Self::new(dist, ax, ay, masking))
    }
    pub fn isotropic(dist: Distribution, alpha: f32) -> Self {
        Self::new(dist, alpha, alpha, Masking::Smith)
    }
    /// Below this roughness the material is treated as perfectly smooth (a delta lobe).
    pub fn effectively_smooth(&self) -> bool {
        self.alpha_x.max(self.alpha_y) < 1e-3
    }

    /// The normal distribution D(ωm), sr⁻¹ (projected-area normalised: ∫ D cos θm dωm = 1).
    #[inline]
    pub fn d(&self, wm: Vec3) -> f32 {
        let z = wm.z;
        if z <= 0.0 {
            return 0.0;
        }
        let z2 = z * z;
        let x = wm.x / self.alpha_x;
        let y = wm.y / self.alpha_y;
        let e = (x * x + y * y) / z2; // tan²θ (cos²φ/αx² + sin²φ/αy²)
        let norm = PI * self.alpha_x * self.alpha_y * z2 * z2;
        match self.dist {
            Distribution::Ggx => 1.0 / (norm * (1.0 + e) * (1.0 + e)),
            Distribution::Beckmann => (-e).exp() / norm,
        }
    }

    /// Smith's Λ(ω).
    #[inline]
    pub fn lambda(&self, w: Vec3) -> f32 {
        let z2 = w.z * w.z;
        let a2t2 = (self.alpha_x * self.alpha_x * w.x * w.x
            + self.alpha_y * self.alpha_y * w.y * w.y)
            / z2; // α(φ)² tan²θ
        if !a2t2.is_finite() {
            return f32::INFINITY;
        }
        match self.dist {
            Distribution::Ggx => 0.5 * ((1.0 + a2t2).sqrt() - 1.0),
            Distribution::Beckmann => {
                if a2t2 <= 0.0 {
                    return 0.0;
                }
                let a = 1.0 / a2t2.sqrt() as f64; // 1/(α tan θ)
                let l = 0.5 * (-erfc(a) + (-a * a).exp() / (a * std::f64::consts::PI.sqrt()));
                l.max(0.0) as f32
            }
        }
    }

    /// Smith's masking G₁(ω) = 1/(1 + Λ(ω)).
    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Masking-shadowing G(ωo, ωi) for the half vector ωm (used by the V-cavity form).
    #[inline]
    pub fn g(&self, wo: Vec3, wi: Vec3, wm: Vec3) -> f32 {
        match self.masking {
            Masking::Smith => 1.0 / (1.0 + self.lambda(wo) + self.lambda(wi)),
            Masking::VCavity => {
                let (o, i) = (wo.dot(wm), wi.dot(wm));
                if o * wo.z <= 0.0 || i * wi.z <= 0.0 {
                    return 0.0;
                }
                let nm = wm.z.abs();
                (2.0 * nm * wo.z.abs() / o.abs())
                    .min(2.0 * nm * wi.z.abs() / i.abs())
                    .min(1.0)
            }
        }
    }

    /// Density (w.r.t. solid angle of ωm) with which [`Self::sample_wm`] returns ωm given ω.
    #[inline]
    pub fn pdf_wm(&self, w: Vec3, wm: Vec3) -> f32 {
        match self.masking {
            Masking::Smith => {
                let w = if w.z < 0.0 { -w } else { w };
                let c = w.dot(wm);
                if c <= 0.0 {
                    return 0.0;
                }
                self.g1(w) / w.z * self.d(wm) * c
            }
            Masking::VCavity => self.d(wm) * wm.z.max(0.0),
        }
    }

    /// Sample a microfacet normal (upper hemisphere) for the direction `w` (either side).
    pub fn sample_wm(&self, w: Vec3, u: Vec2) -> Vec3 {
        if self.masking == Masking::VCavity {
            return self.sample_d_cos(u);
        }
        let w = if w.z < 0.0 { -w } else { w };
        match self.dist {
            Distribution::Ggx => self.sample_ggx_vndf(w, u),
            Distribution::Beckmann => self.sample_beckmann_vndf(w, u),
        }
    }

    /// Normals distributed as D(ωm) cos θm: sample the standard slope distribution and
    /// stretch it.
    fn sample_d_cos(&self, u: Vec2) -> Vec3 {
        let u1 = u.x.min(0.999_999);
        let r = match self.dist {
            // P(r) = 2r/(1+r²)²: CDF 1 − 1/(1+r²).
            Distribution::Ggx => (u1 / (1.0 - u1)).sqrt(),
            // P(r) = 2r e^{−r²}.
            Distribution::Beckmann => (-(1.0 - u1).ln()).sqrt(),
        };
        let phi = 2.0 * PI * u.y;
        let (s, c) = phi.sin_cos();
        Vec3::new(-r * c * self.alpha_x, -r * s * self.alpha_y, 1.0).normalize()
    }

    /// Heitz 2018, listing 1.
    fn sample_ggx_vndf(&self, w: Vec3, u: Vec2) -> Vec3 {
        let vh = Vec3::new(self.alpha_x * w.x, self.alpha_y * w.y, w.z).normalize();
        let lensq = vh.x * vh.x + vh.y * vh.y;
        let t1 = if lensq > 0.0 {
            Vec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt()
        } else {
            Vec3::X
        };
        let t2 = vh.cross(t1);
        let r = u.x.sqrt();
        let phi = 2.0 * PI * u.y;
        let (sp, cp) = phi.sin_cos();
        let p1 = r * cp;
        let mut p2 = r * sp;
        let s = 0.5 * (1.0 + vh.z);
        p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
        let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
        Vec3::new(self.alpha_x * nh.x, self.alpha_y * nh.y, nh.z.max(1e-6)).normalize()
    }

    /// Heitz & d'Eon 2014 / pbrt-v3 `BeckmannSample`: stretch, sample the visible slopes of
    /// the unit-roughness distribution, rotate, unstretch.
    fn sample_beckmann_vndf(&self, w: Vec3, u: Vec2) -> Vec3 {
        let ws = Vec3::new(self.alpha_x * w.x, self.alpha_y * w.y, w.z).normalize();
        let (sx, sy) = beckmann_sample11(ws.z as f64, u.x as f64, u.y as f64);
        let sin_t = (ws.x * ws.x + ws.y * ws.y).sqrt();
        let (cos_phi, sin_phi) = if sin_t > 0.0 {
            ((ws.x / sin_t) as f64, (ws.y / sin_t) as f64)
        } else {
            (1.0, 0.0)
        };
        let rx = cos_phi * sx - sin_phi * sy;
        let ry = sin_phi * sx + cos_phi * sy;
        let (x, y) = (self.alpha_x as f64 * rx, self.alpha_y as f64 * ry);
        Vec3::new(-x as f32, -y as f32, 1.0).normalize()
    }
}

const SQRT_PI: f64 = 1.772_453_850_905_516;

/// Visible slopes (x along the incident azimuth, y across) of the α = 1 Beckmann surface seen
/// from elevation cos θ: x has CDF F(x) = (erfc(−x) + tanθ/√π e^{−x²}) / (erfc(−cotθ) +
/// tanθ/√π e^{−cot²θ}) on x < cot θ, y ~ e^{−y²}/√π.
fn beckmann_sample11(cos_t: f64, u1: f64, u2: f64) -> (f64, f64) {
    let u2 = u2.clamp(1e-7, 1.0 - 1e-7);
    if cos_t > 0.99999 {
        let r = (-(1.0 - u1.min(1.0 - 1e-12)).ln()).sqrt();
        let phi = 2.0 * std::f64::consts::PI * u2;
        return (r * phi.cos(), r * phi.sin());
    }
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let tan_t = sin_t / cos_t;
    let cot_t = cos_t / sin_t;
    let u = u1.clamp(1e-9, 1.0 - 1e-9);
    let cdf_un = |x: f64| erfc(-x) + tan_t / SQRT_PI * (-x * x).exp();
    let norm = cdf_un(cot_t);
    let (mut lo, mut hi) = (-7.0f64, cot_t);
    let mut x = 0.0f64.min(cot_t - 1e-3).max(lo);
    for _ in 0..60 {
        let f = cdf_un(x) / norm - u;
        if f.abs() < 1e-10 {
            break;
        }
        if f > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let df = 2.0 / SQRT_PI * (-x * x).exp() * (1.0 - x * tan_t) / norm;
        let mut xn = x - f / df;
        if !(xn > lo && xn < hi) {
            xn = 0.5 * (lo + hi);
        }
        if (xn - x).abs() < 1e-12 {
            x = xn;
            break;
        }
        x = xn;
    }
    (x, erf_inv(2.0 * u2 - 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projected_area_is_one() {
        // ∫ D(ωm) cos θm dωm = 1 by a midpoint rule in (θ, φ).
        for dist in [Distribution::Ggx, Distribution::Beckmann] {
            for (ax, ay) in [(0.2f32, 0.2f32), (0.5, 0.1), (0.8, 0.8)] {
                let m = Microfacet::new(dist, ax, ay, Masking::Smith);
                let (nt, np) = (2000, 200);
                let mut s = 0.0f64;
                for i in 0..nt {
                    let t = (i as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
                    for j in 0..np {
                        let p = (j as f64 + 0.5) / np as f64 * 2.0 * std::f64::consts::PI;
                        let wm = Vec3::new(
                            (t.sin() * p.cos()) as f32,
                            (t.sin() * p.sin()) as f32,
                            t.cos() as f32,
                        );
                        s += m.d(wm) as f64 * t.cos() * t.sin();
                    }
                }
                s *= std::f64::consts::FRAC_PI_2 / nt as f64 * 2.0 * std::f64::consts::PI
                    / np as f64;
                assert!((s - 1.0).abs() < 2e-3, "{dist:?} {ax} {ay}: {s}");
            }
        }
    }
}
