//! Illuminant generation: CIE daylight (D series) at any chromaticity or CCT, and CIE standard
//! illuminant A from its formula.

use crate::colour::tables::daylight_basis;

use crate::colour::grid::LEN;
use crate::colour::temperature::cct_to_xy_cie_d;

/// numpy's `around(x, 3)` (round half to even at the third decimal).
fn around3(x: f64) -> f64 {
    (x * 1000.0).round_ties_even() / 1000.0
}

/// CIE daylight illuminant (relative spectral power, S(560) ≈ 100) with chromaticity `xy`
/// on the daylight locus, 360–830 nm at 1 nm: S = S0 + M1·S1 + M2·S2 with
/// M = 0.0241 + 0.2562x − 0.7341y, M1 = (−1.3515 − 1.7703x + 5.9114y)/M,
/// M2 = (0.0300 − 31.4424x + 30.0717y)/M, M1 and M2 rounded to 3 decimals (CIE 15:2018
/// note 4 to §4.1.2).
///
/// Reference: CIE 15:2018 eq. 4.10–4.12; colour-science `sd_CIE_illuminant_D_series(xy)`
/// (`M1_M2_rounding=True`), whose 5 nm result is linearly interpolated to 1 nm — the basis
/// functions here are the same linear interpolation, so the results agree to rounding.
pub fn sd_cie_illuminant_d_series(xy: [f64; 2]) -> [f64; LEN] {
    let [x, y] = xy;
    let m = 0.0241 + 0.2562 * x - 0.7341 * y;
    let m1 = around3((-1.3515 - 1.7703 * x + 5.9114 * y) / m);
    let m2 = around3((0.0300 - 31.4424 * x + 30.0717 * y) / m);
    let [s0, s1, s2] = daylight_basis();
    let mut out = [0.0; LEN];
    for i in 0..LEN {
        out[i] = s0[i] + m1 * s1[i] + m2 * s2[i];
    }
    out
}

/// CIE daylight illuminant at correlated colour temperature `cct_k` (4000–25 000 K):
/// [`sd_cie_illuminant_d_series`] at [`cct_to_xy_cie_d`]`(cct_k)`.  The CCT is used as
/// given (D65 is 6504 K on the current c₂ scale).
///
/// Reference: CIE 15:2018 §4.1.2; colour-science
/// `sd_CIE_illuminant_D_series(CCT_to_xy_CIE_D(cct))`.
pub fn sd_cie_daylight(cct_k: f64) -> [f64; LEN] {
    sd_cie_illuminant_d_series(cct_to_xy_cie_d(cct_k))
}

/// Relative spectral power of CIE standard illuminant A at `nm`:
/// S_A(λ) = 100 (560/λ)⁵ (exp(1.435e7/(2848·560)) − 1) / (exp(1.435e7/(2848 λ)) − 1).
///
/// Reference: CIE 15:2018 eq. 4.1 (ISO 11664-2); colour-science
/// `sd_CIE_standard_illuminant_A`.
pub fn cie_illuminant_a(nm: f64) -> f64 {
    let c2: f64 = 1.435e7;
    100.0 * (560.0 / nm).powi(5) * ((c2 / (2848.0 * 560.0)).exp() - 1.0)
        / ((c2 / (2848.0 * nm)).exp() - 1.0)
}

/// [`cie_illuminant_a`] evaluated at 360–830 nm every 1 nm.  Unlike the tabulated `A` from
/// `data/illuminants.csv` (colour-science's 300–780 nm table, constant beyond 780 nm as
/// colour-science's `align` extrapolates it), this follows the formula up to 830 nm.
pub fn sd_cie_standard_illuminant_a() -> [f64; LEN] {
    let mut out = [0.0; LEN];
    for (i, o) in out.iter_mut().enumerate() {
        *o = cie_illuminant_a(360.0 + i as f64);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::tables::named_spectrum;

    #[test]
    fn illuminant_a_closed_form() {
        // closed-forms.md §2.9: S_A(560) = 100, S_A(300) = 0.930483, S_A(830) = 261.602.
        assert!((cie_illuminant_a(560.0) - 100.0).abs() < 1e-12);
        assert!((cie_illuminant_a(300.0) - 0.930483).abs() < 5e-7);
        assert!((cie_illuminant_a(830.0) - 261.602).abs() < 5e-4);
        // The tabulated A agrees with the formula at its 5 nm nodes (6 significant digits).
        let a = named_spectrum("A").unwrap();
        for nm in (360..=780).step_by(5) {
            let f = cie_illuminant_a(nm as f64);
            assert!((a.value(nm as f64) - f).abs() / f < 1e-5, "{nm}");
        }
        // Beyond 780 nm the table is colour-science's constant extrapolation.
        assert_eq!(a.value(830.0), a.value(780.0));
        assert!((sd_cie_standard_illuminant_a()[830 - 360] - 261.602).abs() < 5e-4);
    }

    #[test]
    fn d65_from_its_chromaticity() {
        // D65 regenerated from CCT 6504 K is close to the tabulated D65 (differences come
        // from the rounded M1, M2 and the tabulated values' own rounding).
        let d = sd_cie_daylight(6500.0 * 1.4388 / 1.4380);
        let t = named_spectrum("D65").unwrap().to_table();
        for i in 0..=(780 - 360) {
            assert!(
                (d[i] - t[i]).abs() < 0.05 * t[i].max(1.0),
                "{} {} {}",
                360 + i,
                d[i],
                t[i]
            );
        }
        assert!((d[560 - 360] - 100.0).abs() < 0.5);
    }
}
