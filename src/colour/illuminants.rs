//! Illuminant generation: CIE daylight (D series) at any CCT, blackbodies.

use crate::colour::tables::{daylight_basis, LEN};
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::tables::named_spectrum;

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
