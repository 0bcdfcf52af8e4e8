//! CIE 13.3-1995 colour rendering index: general index Ra and special indices R1–R14.

use std::sync::LazyLock;

use crate::colour::colorimetry::{sd_to_xyz_emissive_with, sd_to_xyz_relative_with, XyzMethod};
use crate::colour::illuminants::sd_cie_illuminant_d_series;
use crate::colour::models::{xyz_to_uv1960, xyz_to_xyy};
use crate::colour::planck::blackbody_table;
use crate::colour::tables::{named_spectrum, Observer};

use crate::colour::grid::LEN;
use crate::colour::temperature::{cct_to_xy_cie_d, uv_to_cct_robertson1968};

/// Result of [`colour_rendering_index`].
#[derive(Clone, Debug, PartialEq)]
pub struct Cri {
    /// General colour rendering index Ra (mean of R1–R8).
    pub ra: f64,
    /// Special colour rendering indices R1–R14 (`r[0]` is R1).
    pub r: [f64; 14],
    /// CCT of the test source by Robertson (1968), K, which selects the reference.
    pub cct_k: f64,
    /// Duv of the test source by Robertson (1968).
    pub duv: f64,
    /// True if the reference illuminant is a blackbody (CCT < 5000 K), false if CIE
    /// daylight.
    pub reference_is_blackbody: bool,
}

static TCS: LazyLock<Vec<[f64; LEN]>> = LazyLock::new(|| {
    (1..=14)
        .map(|i| {
            named_spectrum(&format!("TCS{i:02}"))
                .expect("TCS table")
                .to_table()
        })
        .collect()
});

/// (U*, V*, W*) of every test colour sample under `illuminant`, CIE 13.3 §5, with the von
/// Kries-type adaptation of §5.5 towards the reference when `adapt_to` is given as the
/// reference's (u, v).
fn tcs_uvw(illuminant: &[f64; LEN], uv_r: [f64; 2], adapt_to: Option<[f64; 2]>) -> Vec<[f64; 3]> {
    let m = XyzMethod::AstmE308;
    let o = Observer::Cie1931_2;
    let uv_t = xyz_to_uv1960(sd_to_xyz_emissive_with(illuminant, o, m));
    let c = |u: f64, v: f64| {
        if v == 0.0 {
            0.0
        } else {
            (4.0 - u - 10.0 * v) / v
        }
    };
    let d = |u: f64, v: f64| {
        if v == 0.0 {
            0.0
        } else {
            (1.708 * v + 0.404 - 1.481 * u) / v
        }
    };
    TCS.iter()
        .map(|tcs| {
            let xyz = sd_to_xyz_relative_with(tcs, illuminant, o, m);
            let y = xyz_to_xyy(xyz)[2];
            let [mut u, mut v] = xyz_to_uv1960(xyz);
            if adapt_to.is_some() {
                let (c_t, d_t) = (c(uv_t[0], uv_t[1]), d(uv_t[0], uv_t[1]));
                let (c_r, d_r) = (c(uv_r[0], uv_r[1]), d(uv_r[0], uv_r[1]));
                let (tc, td) = (c(u, v), d(u, v));
                let crct = if c_t == 0.0 { 0.0 } else { c_r / c_t };
                let drdt = if d_t == 0.0 { 0.0 } else { d_r / d_t };
                let den = 16.518 + 1.481 * crct * tc - drdt * td;
                u = (10.872 + 0.404 * crct * tc - 4.0 * drdt * td) / den;
                v = 5.52 / den;
            }
            let w = 25.0 * y.cbrt() - 17.0;
            [w * 13.0 * (u - uv_r[0]), w * 13.0 * (v - uv_r[1]), w]
        })
        .collect()
}

/// CIE 13.3-1995 colour rendering index of a light source with relative spectral power
/// `spectrum` (1 nm, 360–830 nm).
///
/// Procedure, exactly as colour-science's `colour_rendering_index(sd, method="CIE 1995")`:
/// everything is evaluated on 360–780 nm at 1 nm with the CIE 1931 2° observer; the CCT is
/// found with Robertson (1968); the reference is a blackbody below 5000 K and a CIE daylight
/// illuminant (at `CCT_to_xy_CIE_D(CCT)`) otherwise; test colour samples TCS01–TCS14 are
/// adapted with the CIE 13.3 von Kries transform in the CIE 1960 UCS; Ri = 100 − 4.6 ΔE
/// in CIE 1964 U*V*W*; Ra is the mean of R1–R8.
///
/// Reference: CIE 13.3-1995, "Method of Measuring and Specifying Colour Rendering Properties
/// of Light Sources"; colour-science `colour.quality.colour_rendering_index`.
pub fn colour_rendering_index(spectrum: &[f64; LEN]) -> Cri {
    let o = Observer::Cie1931_2;
    let m = XyzMethod::AstmE308;
    let uv = xyz_to_uv1960(sd_to_xyz_emissive_with(spectrum, o, m));
    let [cct, duv] = uv_to_cct_robertson1968(uv);
    let reference_is_blackbody = cct < 5000.0;
    let reference = if reference_is_blackbody {
        blackbody_table(cct)
    } else {
        sd_cie_illuminant_d_series(cct_to_xy_cie_d(cct))
    };
    let uv_r = xyz_to_uv1960(sd_to_xyz_emissive_with(&reference, o, m));
    let test = tcs_uvw(spectrum, uv_r, Some(uv_r));
    let refr = tcs_uvw(&reference, uv_r, None);
    let mut r = [0.0; 14];
    for i in 0..14 {
        let d = ((refr[i][0] - test[i][0]).powi(2)
            + (refr[i][1] - test[i][1]).powi(2)
            + (refr[i][2] - test[i][2]).powi(2))
        .sqrt();
        r[i] = 100.0 - 4.6 * d;
    }
    let ra = r[..8].iter().sum::<f64>() / 8.0;
    Cri {
        ra,
        r,
        cct_k: cct,
        duv,
        reference_is_blackbody,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_illuminants_render_perfectly() {
        // A source identical to its own reference has Ra = 100 (blackbody below 5000 K).
        let bb = blackbody_table(3000.0);
        let c = colour_rendering_index(&bb);
        assert!((c.ra - 100.0).abs() < 0.05, "{c:?}");
        assert!(c.reference_is_blackbody);
        // FL2 (cool white fluorescent): colour-science gives Ra ≈ 64.15, R9 ≈ -... (CIE 15
        // table: Ra 64).
        let fl2 = named_spectrum("FL2").unwrap().to_table();
        let c = colour_rendering_index(&fl2);
        assert!((c.ra - 64.0).abs() < 1.0, "{c:?}");
    }
}
