//! The CIE sky luminance distributions: the 15 standard general skies of ISO 15469:2004 /
//! CIE S 011/E:2003, the traditional CIE overcast sky (Moon & Spencer 1942), the uniform sky
//! and the CIE 1973 clear sky that Radiance's `gensky +s` draws.
//!
//! Each gives the sky's luminance relative to its zenith luminance, L(Z, γ)/L_z, for a view
//! direction at zenith angle Z and angular distance γ from the sun (the sun at zenith angle
//! Z_s). The general skies are the product of a gradation φ(Z) and an indicatrix f(χ):
//!
//! φ(Z) = 1 + a·exp(b / cos Z)  (φ(π/2) = 1),
//! f(χ) = 1 + c·(exp(d·χ) − exp(d·π/2)) + e·cos²χ,
//! L(Z, γ)/L_z = f(γ)·φ(Z) / (f(Z_s)·φ(0)),
//!
//! with (a, b, c, d, e) from the standard's Table 1 ([`GENERAL_SKIES`]).

use std::f64::consts::FRAC_PI_2;

/// Gradation (a, b) and indicatrix (c, d, e) of the 15 CIE standard general skies, types 1–15
/// in order (ISO 15469:2004 / CIE S 011/E:2003, Table 1), with the standard's descriptions.
pub const GENERAL_SKIES: [([f64; 5], &str); 15] = [
    (
        [4.0, -0.70, 0.0, -1.0, 0.00],
        "overcast, steep gradation towards the zenith, azimuthal uniformity",
    ),
    (
        [4.0, -0.70, 2.0, -1.5, 0.15],
        "overcast, steep gradation, slight brightening towards the sun",
    ),
    (
        [1.1, -0.8, 0.0, -1.0, 0.00],
        "overcast, moderate gradation, azimuthal uniformity",
    ),
    (
        [1.1, -0.8, 2.0, -1.5, 0.15],
        "overcast, moderate gradation, slight brightening towards the sun",
    ),
    ([0.0, -1.0, 0.0, -1.0, 0.00], "sky of uniform luminance"),
    (
        [0.0, -1.0, 2.0, -1.5, 0.15],
        "partly cloudy, no gradation towards the zenith, slight brightening towards the sun",
    ),
    (
        [0.0, -1.0, 5.0, -2.5, 0.30],
        "partly cloudy, no gradation, brighter circumsolar region",
    ),
    (
        [0.0, -1.0, 10.0, -3.0, 0.45],
        "partly cloudy, no gradation, distinct solar corona",
    ),
    (
        [-1.0, -0.55, 2.0, -1.5, 0.15],
        "partly cloudy, the sun obscured",
    ),
    (
        [-1.0, -0.55, 5.0, -2.5, 0.30],
        "partly cloudy, brighter circumsolar region",
    ),
    (
        [-1.0, -0.55, 10.0, -3.0, 0.45],
        "white-blue sky with a distinct solar corona",
    ),
    (
        [-1.0, -0.32, 10.0, -3.0, 0.45],
        "CIE standard clear sky, low luminance turbidity",
    ),
    (
        [-1.0, -0.32, 16.0, -3.0, 0.30],
        "CIE standard clear sky, polluted atmosphere",
    ),
    (
        [-1.0, -0.15, 16.0, -3.0, 0.30],
        "cloudless turbid sky with a broad solar corona",
    ),
    (
        [-1.0, -0.15, 24.0, -2.8, 0.15],
        "white-blue turbid sky with a broad solar corona",
    ),
];

/// A CIE sky's relative luminance distribution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CieSky {
    /// One of the 15 standard general skies (type 1–15) of ISO 15469 / CIE S 011.
    General {
        /// Gradation a, b and indicatrix c, d, e.
        params: [f64; 5],
    },
    /// The traditional CIE overcast sky: L(Z) = L_z·(1 + 2 cos Z)/3, independent of the sun.
    Overcast,
    /// The same luminance in every direction.
    Uniform,
    /// The CIE 1973 clear sky as Radiance's `gensky ±s` draws it:
    /// L/L_z = (0.91 + 10 e^{−3γ} + 0.45 cos²γ)(1 − e^{−0.32/cos Z}) /
    /// ((0.91 + 10 e^{−3Z_s} + 0.45 cos²Z_s)(1 − e^{−0.32})).
    Clear,
}

impl CieSky {
    /// Standard general sky `kind` (1–15); None for any other number.
    pub fn general(kind: u32) -> Option<Self> {
        let i = (kind as usize).checked_sub(1)?;
        GENERAL_SKIES
            .get(i)
            .map(|&(params, _)| Self::General { params })
    }

    /// Whether the distribution depends on where the sun is.
    pub fn needs_sun(&self) -> bool {
        match self {
            Self::General { params } => params[2] != 0.0 || params[4] != 0.0,
            Self::Overcast | Self::Uniform => false,
            Self::Clear => true,
        }
    }

    /// L(Z, γ)/L_z for a direction above the horizon with cos Z = `cos_z` (> 0) at angle
    /// `gamma` (radians) from the sun, the sun at zenith angle `sun_zenith` (radians). Zero for
    /// directions at or below the horizon, where the ground takes over.
    pub fn relative_luminance(&self, cos_z: f64, gamma: f64, sun_zenith: f64) -> f64 {
        if cos_z.is_nan() || cos_z <= 0.0 {
            return 0.0;
        }
        match *self {
            Self::General {
                params: [a, b, c, d, e],
            } => {
                let gradation = |cos: f64| 1.0 + a * (b / cos).exp();
                let indicatrix = |chi: f64| {
                    1.0 + c * ((d * chi).exp() - (d * FRAC_PI_2).exp()) + e * chi.cos().powi(2)
                };
                indicatrix(gamma) * gradation(cos_z) / (indicatrix(sun_zenith) * gradation(1.0))
            }
            Self::Overcast => (1.0 + 2.0 * cos_z) / 3.0,
            Self::Uniform => 1.0,
            Self::Clear => {
                let f = |g: f64| 0.91 + 10.0 * (-3.0 * g).exp() + 0.45 * g.cos().powi(2);
                f(gamma) * (1.0 - (-0.32 / cos_z).exp())
                    / (f(sun_zenith) * (1.0 - (-0.32f64).exp()))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::daylight::horizontal_integral;
    use std::f64::consts::PI;

    #[test]
    fn zenith_is_one() {
        for kind in 1..=15 {
            let sky = CieSky::general(kind).unwrap();
            for zs in [0.1, 0.5, 1.0, 1.4] {
                // At the zenith, γ = Z_s.
                let r = sky.relative_luminance(1.0, zs, zs);
                assert!((r - 1.0).abs() < 1e-12, "type {kind}: {r}");
            }
        }
        assert!(CieSky::general(0).is_none() && CieSky::general(16).is_none());
    }

    #[test]
    fn overcast_and_uniform_integrals() {
        // E_h = ∫ L cos Z dω: π L for the uniform sky, 7π L_z / 9 for the traditional overcast
        // (∫₀^{π/2} (1 + 2 cos Z)/3 · cos Z sin Z dZ · 2π = 2π (1/2 + 2/3)/3 = 7π/9).
        let e = horizontal_integral(0.3, |cz, _| {
            CieSky::Uniform.relative_luminance(cz, 0.0, 0.0)
        });
        assert!((e / PI - 1.0).abs() < 1e-6, "{e}");
        let e = horizontal_integral(0.3, |cz, _| {
            CieSky::Overcast.relative_luminance(cz, 0.0, 0.0)
        });
        assert!((e / (7.0 * PI / 9.0) - 1.0).abs() < 1e-6, "{e}");
        // Type 5 is the uniform sky.
        let sky = CieSky::general(5).unwrap();
        assert!(!sky.needs_sun());
        let e = horizontal_integral(0.7, |cz, g| sky.relative_luminance(cz, g, 0.7));
        assert!((e / PI - 1.0).abs() < 1e-6, "{e}");
    }

    #[test]
    fn type_12_is_the_clear_sky_of_gensky() {
        // 1 + 10(e^{−3χ} − e^{−3π/2}) + 0.45 cos²χ = 0.9101 + 10 e^{−3χ} + 0.45 cos²χ: type 12
        // differs from the CIE 1973 clear sky only by 0.91 against 0.9101.
        let t12 = CieSky::general(12).unwrap();
        for (cz, g, zs) in [(0.9, 0.3, 0.5), (0.2, 2.0, 1.2), (0.6, 0.05, 0.9)] {
            let a = t12.relative_luminance(cz, g, zs);
            let b = CieSky::Clear.relative_luminance(cz, g, zs);
            assert!((a / b - 1.0).abs() < 2e-4, "{a} {b}");
        }
    }
}
