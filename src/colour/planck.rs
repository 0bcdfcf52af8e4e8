//! Planck's law for blackbody radiators.

use crate::colour::grid::{LEN, START_NM};
use crate::colour::sd::SpectralDistribution;

/// First radiation constant c₁ = 2πhc², W·m² (colour-science `CONSTANT_C1`).
pub const C1: f64 = 3.741771e-16;
/// Second radiation constant c₂ = hc/k, m·K (CIE value; colour-science `CONSTANT_C2`).
pub const C2: f64 = 1.4388e-2;

/// Spectral radiance of a blackbody, W·m⁻²·sr⁻¹·m⁻¹, wavelength in metres (colour-science's
/// planck_law convention).
///
/// L(λ, T) = c₁ / (π λ⁵ (exp(c₂ / (λT)) − 1)), refractive index n = 1.
///
/// Reference: CIE 15:2018 §3.1 (c₂ = 1.4388e-2 m·K); colour-science
/// `colour.colorimetry.planck_law`, which evaluates `1 / expm1(c2 / (l * t))`.
pub fn planck_law(wavelength_m: f64, temperature_k: f64) -> f64 {
    let l = wavelength_m;
    let d = 1.0 / (C2 / (l * temperature_k)).exp_m1();
    (C1 * l.powi(-5) / std::f64::consts::PI) * d
}

/// Blackbody spectral radiance at 360–830 nm every 1 nm, in W·m⁻²·sr⁻¹·nm⁻¹ (colour-science
/// `sd_blackbody(T)` divided by 1e9; candela's radiometric unit is per nanometre).
///
/// Reference: colour-science `colour.sd_blackbody`, which returns W·m⁻²·sr⁻¹·m⁻¹.
pub fn blackbody_table(temperature_k: f64) -> [f64; LEN] {
    let mut out = [0.0; LEN];
    for (i, o) in out.iter_mut().enumerate() {
        let nm = START_NM as f64 + i as f64;
        *o = planck_law(nm * 1e-9, temperature_k) * 1e-9;
    }
    out
}

/// [`blackbody_table`] as a [`SpectralDistribution`] (W·m⁻²·sr⁻¹·nm⁻¹).
pub fn sd_blackbody(temperature_k: f64) -> SpectralDistribution {
    SpectralDistribution::from_table(&blackbody_table(temperature_k))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_science_doc_value() {
        // colour-science docstring: planck_law(500e-9, 5500) = 20472701909806.5...
        let v = planck_law(500e-9, 5500.0);
        assert!((v - 20472701909806.5).abs() < 1.0, "{v}");
        let v = planck_law(500e-9, 5000.0);
        assert!((v / 1.2106064e13 - 1.0).abs() < 1e-7, "{v}");
    }
}
