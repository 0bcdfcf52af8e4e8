//! NIST Colour Quality Scale 9.0 (Davis & Ohno 2010): the general scale Q_a, the fidelity
//! scale Q_f, the gamut area scale Q_g and, per test colour sample VS1–VS15, its CIELAB
//! colour difference, chroma difference and saturation-tolerant difference ΔE′, with the 15
//! reflectances of `data/vs-nist-cqs9.csv`.
//!
//! The computation is colour-science 0.4.7's `colour_quality_scale(sd, method="NIST CQS 9.0")`
//! step by step:
//! 1. Everything is evaluated on 360–780 nm at 1 nm with the CIE 1931 2° observer (the
//!    ASTM E308 practice range of colour-science's default `sd_to_XYZ`).
//! 2. The CCT is Ohno's (2013); the reference is a blackbody below 5000 K, else CIE daylight
//!    at `CCT_to_xy_CIE_D(CCT)`.
//! 3. Each sample's XYZ under the test source (white Y = 1) is adapted to the reference white
//!    by a von Kries transform in CMCCAT2000 cone space, then taken to CIELAB with the
//!    reference white.
//! 4. ΔE_i is the CIELAB distance to the sample under the reference, ΔC_i the chroma
//!    difference, ΔE′_i = √(ΔE_i² − ΔC_i²) when ΔC_i > 0 (chroma gains are not penalised),
//!    else ΔE_i.
//! 5. Q_a = 10 ln(1 + e^{(100 − 3.2 ΔE′_rms)/10}), Q_f likewise from ΔE_rms with the factor
//!    2.93 · 1.0343; Q_a,i from each ΔE′_i; Q_g = 100 · G_test / 8210, G the area of the
//!    polygon of the 15 samples' (a*, b*) under the test source.
//!
//! Version 9.0 drops the CCT factor of 7.x (it is 1) and defines no preference scale Q_p and
//! no relative gamut Q_d; colour-science returns `None` for both and so does [`Cqs`].

use std::sync::LazyLock;

use crate::colour::colorimetry::{sd_to_xyz_emissive_with, sd_to_xyz_relative_with, XyzMethod};
use crate::colour::grid::LEN;
use crate::colour::illuminants::sd_cie_illuminant_d_series;
use crate::colour::matrix::{mat3_inverse, mat3_mul_vec, Mat3};
use crate::colour::models::{xyz_to_lab, xyz_to_uv1960, xyz_to_xy};
use crate::colour::planck::blackbody_table;
use crate::colour::tables::{parse_table, Observer};
use crate::colour::temperature::{cct_to_xy_cie_d, uv_to_cct_ohno2013};

/// Number of NIST CQS test colour samples.
pub const N_VS: usize = 15;

/// Gamut area of the 15 samples under CIE D65 (colour-science `GAMUT_AREA_D65`), the
/// denominator of Q_g.
pub const GAMUT_AREA_D65: f64 = 8210.0;

const VS_CSV: &str = include_str!("../../data/vs-nist-cqs9.csv");

/// CMCCAT2000's cone-response matrix (colour-science `CAT_CMCCAT2000`), in which CQS 9.0
/// adapts the samples from the test white to the reference white.
const CMCCAT2000: Mat3 = [
    [0.7982, 0.3389, -0.1371],
    [-0.5918, 1.5512, 0.0406],
    [0.0008, 0.0239, 0.9753],
];

/// One test colour sample's result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CqsSample {
    /// Q_a,i: the sample's scale from its ΔE′.
    pub q_a: f64,
    /// ΔC*_ab: chroma under the test source minus chroma under the reference.
    pub delta_c_ab: f64,
    /// ΔE*_ab between the sample under the (adapted) test source and under the reference.
    pub delta_e_ab: f64,
    /// ΔE′: ΔE*_ab without its chroma gain (equal to ΔE*_ab when the chroma drops).
    pub delta_e_p_ab: f64,
}

/// Result of [`colour_quality_scale`] (NIST CQS 9.0).
#[derive(Clone, Debug, PartialEq)]
pub struct Cqs {
    /// General colour quality scale Q_a (0–100).
    pub q_a: f64,
    /// Colour fidelity scale Q_f (0–100).
    pub q_f: f64,
    /// Colour preference scale Q_p: not defined by CQS 9.0, always `None`.
    pub q_p: Option<f64>,
    /// Gamut area scale Q_g, % of D65's gamut area (can exceed 100).
    pub q_g: f64,
    /// VS1–VS15 (`samples[0]` is VS1).
    pub samples: [CqsSample; N_VS],
    /// CCT of the test source by Ohno (2013), K, which selects the reference.
    pub cct_k: f64,
    /// Duv of the test source by Ohno (2013).
    pub duv: f64,
    /// True if the reference is a blackbody (CCT < 5000 K), false if CIE daylight.
    pub reference_is_blackbody: bool,
}

/// The 15 sample reflectances on the 1 nm grid.
fn vs() -> &'static [[f64; LEN]; N_VS] {
    static T: LazyLock<Box<[[f64; LEN]; N_VS]>> = LazyLock::new(|| {
        let o = "data/vs-nist-cqs9.csv";
        let t = parse_table(VS_CSV, o);
        assert_eq!(t.names.len(), N_VS, "{o}: columns");
        assert_eq!(t.nm.len(), LEN, "{o}: rows");
        let mut out = Box::new([[0.0; LEN]; N_VS]);
        for (s, col) in out.iter_mut().zip(&t.cols) {
            for (v, c) in s.iter_mut().zip(col) {
                *v = c.expect("VS value");
            }
        }
        out
    });
    &T
}

/// CIELAB (reference white `white_xy`) of every sample under `source`, adapted from the
/// source's white `xyz_t` to `xyz_r` (both Y = 1) when `adapt` is set.
fn vs_lab(
    source: &[f64; LEN],
    xyz_t: [f64; 3],
    xyz_r: [f64; 3],
    white_xy: [f64; 2],
    adapt: bool,
) -> [[f64; 3]; N_VS] {
    let (o, m) = (Observer::Cie1931_2, XyzMethod::AstmE308);
    let cone_t = mat3_mul_vec(&CMCCAT2000, xyz_t);
    let cone_r = mat3_mul_vec(&CMCCAT2000, xyz_r);
    let inv = mat3_inverse(&CMCCAT2000);
    std::array::from_fn(|i| {
        let x = sd_to_xyz_relative_with(&vs()[i], source, o, m);
        let mut xyz = [x[0] / 100.0, x[1] / 100.0, x[2] / 100.0];
        if adapt {
            let c = mat3_mul_vec(&CMCCAT2000, xyz);
            let c = std::array::from_fn(|k| c[k] * cone_r[k] / cone_t[k]);
            xyz = mat3_mul_vec(&inv, c);
        }
        xyz_to_lab(xyz, white_xy)
    })
}

/// 10 ln(1 + e^{(100 − f·ΔE)/10}): CQS's map from an rms colour difference to 0–100.
fn scale_conversion(delta_e: f64, scaling: f64) -> f64 {
    10.0 * ((100.0 - scaling * delta_e) / 10.0).exp().ln_1p()
}

/// Area of the polygon through the samples' (a*, b*), summed as triangles with the origin by
/// Heron's formula (colour-science's `gamut_area`).
fn gamut_area(lab: &[[f64; 3]; N_VS]) -> f64 {
    (0..N_VS)
        .map(|i| {
            let (p, q) = (lab[i], lab[(i + 1) % N_VS]);
            let a = p[1].hypot(p[2]);
            let b = q[1].hypot(q[2]);
            let c = (q[1] - p[1]).hypot(q[2] - p[2]);
            let t = (a + b + c) / 2.0;
            (t * (t - a) * (t - b) * (t - c)).sqrt()
        })
        .sum()
}

/// NIST CQS 9.0 of a light source with relative spectral power `spectrum` (1 nm,
/// 360–830 nm; only 360–780 nm is used).
///
/// Reference: W. Davis & Y. Ohno, "Color quality scale", Opt. Eng. 49(3) 033602 (2010);
/// NIST CQS 9.0 spreadsheet; colour-science `colour.quality.colour_quality_scale`.
pub fn colour_quality_scale(spectrum: &[f64; LEN]) -> Cqs {
    let (o, m) = (Observer::Cie1931_2, XyzMethod::AstmE308);
    let xyz = sd_to_xyz_emissive_with(spectrum, o, m);
    let [cct, duv] = uv_to_cct_ohno2013(xyz_to_uv1960(xyz));
    let reference_is_blackbody = cct < 5000.0;
    let reference = if reference_is_blackbody {
        blackbody_table(cct)
    } else {
        sd_cie_illuminant_d_series(cct_to_xy_cie_d(cct))
    };
    let unit_y = |v: [f64; 3]| [v[0] / v[1], 1.0, v[2] / v[1]];
    let xyz_t = unit_y(xyz);
    let xyz_r = unit_y(sd_to_xyz_emissive_with(&reference, o, m));
    let xy_r = xyz_to_xy(xyz_r);
    let test = vs_lab(spectrum, xyz_t, xyz_r, xy_r, true);
    let refr = vs_lab(&reference, xyz_r, xyz_r, xy_r, false);
    let samples: [CqsSample; N_VS] = std::array::from_fn(|i| {
        let (t, r) = (test[i], refr[i]);
        let delta_c_ab = t[1].hypot(t[2]) - r[1].hypot(r[2]);
        let delta_e_ab =
            ((t[0] - r[0]).powi(2) + (t[1] - r[1]).powi(2) + (t[2] - r[2]).powi(2)).sqrt();
        let delta_e_p_ab = if delta_c_ab > 0.0 {
            (delta_e_ab.powi(2) - delta_c_ab.powi(2)).sqrt()
        } else {
            delta_e_ab
        };
        CqsSample {
            q_a: scale_conversion(delta_e_p_ab, 3.2),
            delta_c_ab,
            delta_e_ab,
            delta_e_p_ab,
        }
    });
    let rms = |f: fn(&CqsSample) -> f64| {
        (samples.iter().map(|s| f(s).powi(2)).sum::<f64>() / N_VS as f64).sqrt()
    };
    Cqs {
        q_a: scale_conversion(rms(|s| s.delta_e_p_ab), 3.2),
        q_f: scale_conversion(rms(|s| s.delta_e_ab), 2.93 * 1.0343),
        q_p: None,
        q_g: gamut_area(&test) / GAMUT_AREA_D65 * 100.0,
        samples,
        cct_k: cct,
        duv,
        reference_is_blackbody,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::tables::named_spectrum;

    #[test]
    fn fl2_matches_colour_science_docstring() {
        // colour-science's docstring: colour_quality_scale(SDS_ILLUMINANTS["FL2"]) = 64.1118220...
        let fl2 = named_spectrum("FL2").unwrap().to_table();
        let c = colour_quality_scale(&fl2);
        assert!((c.q_a - 64.1118220).abs() < 1e-6, "{c:?}");
    }

    #[test]
    fn reference_source_scores_full_marks() {
        // A 3000 K blackbody is its own reference but for Ohno's CCT (within a kelvin of
        // 3000 K): every ΔE is near 0 and each scale near 10 ln(1 + e^10) = 100.00045.
        let c = colour_quality_scale(&blackbody_table(3000.0));
        let top = 10.0 * 10f64.exp().ln_1p();
        assert!((c.cct_k - 3000.0).abs() < 1.0, "{c:?}");
        assert!(c.samples.iter().all(|s| s.delta_e_ab < 1e-3), "{c:?}");
        assert!((c.q_a - top).abs() < 1e-3 && (c.q_f - top).abs() < 1e-3);
    }
}
