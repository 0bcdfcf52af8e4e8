//! Fresnel equations (Born & Wolf, *Principles of Optics*, §1.5; pbrt-v4 §9.3): exact
//! unpolarised reflectance of a dielectric interface and of a conductor with a complex index
//! η = n + ik, plus the reflection and refraction directions in the local frame (normal +z).

use glam::Vec3;

/// s- and p-polarised reflectances of a dielectric interface.
///
/// `cos_i` is the cosine of the incident angle measured on the side the light arrives from
/// when positive; a negative `cos_i` means the light arrives from inside (the `−z` side), in
/// which case the relative index is inverted. `eta` = n_inside / n_outside (the medium on the
/// −z side over the one on the +z side). Returns (R_s, R_p); both are 1 past the critical angle.
pub fn fr_dielectric_sp(cos_i: f32, eta: f32) -> (f32, f32) {
    let mut cos_i = cos_i.clamp(-1.0, 1.0);
    let mut eta = eta;
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return (1.0, 1.0);
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    // r_s = (n1 cos_i − n2 cos_t)/(n1 cos_i + n2 cos_t) with n2/n1 = eta.
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    (rs * rs, rp * rp)
}

/// Unpolarised dielectric reflectance (R_s + R_p)/2; see [`fr_dielectric_sp`].
#[inline]
pub fn fr_dielectric(cos_i: f32, eta: f32) -> f32 {
    let (s, p) = fr_dielectric_sp(cos_i, eta);
    0.5 * (s + p)
}

/// Unpolarised transmittance 1 − R of a dielectric interface (arguments as
/// [`fr_dielectric_sp`]), in f64 and without forming 1 − R: each polarisation's 1 − r² is
/// 4ab with a = x/(x + y), b = y/(x + y) for its two terms x, y, so an index of 10⁻³⁰ or 10³⁰
/// still gives its tiny transmittance instead of 0 or NaN.
pub fn tr_dielectric(cos_i: f64, eta: f64) -> f64 {
    let mut cos_i = cos_i.clamp(-1.0, 1.0);
    let mut eta = eta;
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    // sin²θt = sin²θi / η², with sin²θi = (1 − cos)(1 + cos) exact near normal incidence.
    let sin2_t = ((1.0 - cos_i) * (1.0 + cos_i)) / eta / eta;
    if sin2_t >= 1.0 || sin2_t.is_nan() || cos_i == 0.0 {
        return 0.0;
    }
    let cos_t = ((1.0 - sin2_t).max(0.0)).sqrt();
    let t = |x: f64, y: f64| {
        let s = x + y;
        4.0 * (x / s) * (y / s)
    };
    0.5 * (t(cos_i, eta * cos_t) + t(eta * cos_i, cos_t))
}

/// Unpolarised reflectance of a conductor with complex index n + ik (relative to the outside
/// medium) at incidence cosine `cos_i` ∈ [0, 1]. Evaluated in f64 complex arithmetic.
pub fn fr_conductor(cos_i: f32, n: f32, k: f32) -> f32 {
    let ci = (cos_i as f64).clamp(0.0, 1.0);
    let eta = C64::new(n as f64, k as f64);
    let sin2_i = 1.0 - ci * ci;
    // sin²θt = sin²θi / η²; cos θt = √(1 − sin²θt) (principal branch).
    let sin2_t = C64::new(sin2_i, 0.0) / (eta * eta);
    let cos_t = (C64::new(1.0, 0.0) - sin2_t).sqrt();
    let ci_c = C64::new(ci, 0.0);
    let r_parl = (eta * ci_c - cos_t) / (eta * ci_c + cos_t);
    let r_perp = (ci_c - eta * cos_t) / (ci_c + eta * cos_t);
    (0.5 * (r_parl.norm2() + r_perp.norm2())) as f32
}

/// Mirror `wo` about the normal `n`.
#[inline]
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    -wo + 2.0 * wo.dot(n) * n
}

/// Refract `wi` through an interface with normal `n` and relative index `eta`
/// (n on the side opposite to `n` over n on the side of `n`). `wi` may be on either side.
/// Returns the transmitted direction and the relative index actually crossed
/// (η_t/η_i for this direction), or `None` on total internal reflection.
#[inline]
pub fn refract(wi: Vec3, n: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let mut cos_i = n.dot(wi);
    let (mut eta, mut n) = (eta, n);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        n = -n;
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let wt = -wi / eta + (cos_i / eta - cos_t) * n;
    Some((wt, eta))
}

/// Minimal f64 complex number for [`fr_conductor`].
#[derive(Clone, Copy, Debug)]
struct C64 {
    re: f64,
    im: f64,
}

impl C64 {
    fn new(re: f64, im: f64) -> Self {
        Self { re, im }
    }
    fn norm2(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
    fn sqrt(self) -> Self {
        let r = self.norm2().sqrt();
        if r == 0.0 {
            return Self::new(0.0, 0.0);
        }
        let re = (0.5 * (r + self.re)).max(0.0).sqrt();
        let im = (0.5 * (r - self.re)).max(0.0).sqrt().copysign(self.im);
        Self::new(re, im)
    }
}

impl std::ops::Add for C64 {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self::new(self.re + o.re, self.im + o.im)
    }
}
impl std::ops::Sub for C64 {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Self::new(self.re - o.re, self.im - o.im)
    }
}
impl std::ops::Mul for C64 {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        Self::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
}
impl std::ops::Div for C64 {
    type Output = Self;
    fn div(self, o: Self) -> Self {
        let d = o.norm2();
        Self::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn complex_sqrt() {
        let z = C64::new(-3.0, 4.0).sqrt();
        assert!((z.re - 1.0).abs() < 1e-12 && (z.im - 2.0).abs() < 1e-12);
    }

    #[test]
    fn conductor_with_zero_k_is_dielectric() {
        for c in [1.0f32, 0.7, 0.3, 0.05] {
            let a = fr_conductor(c, 1.5, 0.0);
            let b = fr_dielectric(c, 1.5);
            assert!((a - b).abs() < 1e-6, "{c}: {a} vs {b}");
        }
    }

    #[test]
    fn refract_obeys_snell() {
        let wi = Vec3::new(0.6, 0.0, 0.8);
        let (wt, eta) = refract(wi, Vec3::Z, 1.5).unwrap();
        assert_eq!(eta, 1.5);
        assert!((wt.length() - 1.0).abs() < 1e-6 && wt.z < 0.0);
        assert!((wi.x - 1.5 * -wt.x).abs() < 1e-6);
    }
}
