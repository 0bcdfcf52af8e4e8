//! Colour rendition by CIE 224:2017 (colour fidelity index R_f) and ANSI/IES TM-30-20 (R_f,
//! gamut index R_g, and per hue bin the local chroma shift R_cs,hj, hue shift R_hs,hj and
//! local fidelity R_f,hj), with the 99 colour evaluation samples (CES) of `data/ces-cie2017.csv`.
//!
//! The computation is colour-science 0.4.7's `colour_fidelity_index_CIE2017` and
//! `colour_fidelity_index_ANSIIESTM3018` step by step (TM-30-20 computes R_f, R_g and the
//! hue-bin values as TM-30-18 does):
//! 1. The test spectrum is taken on 380–780 nm at 1 nm.
//! 2. Its CCT is Ohno's (2013) from the CIE 1931 2° XYZ over 380–780 nm.
//! 3. The reference is a blackbody below 4000 K, CIE daylight at `CCT_to_xy_CIE_D(CCT)` above
//!    5000 K (its basis functions Sprague-interpolated to 1 nm, as colour-science does), and
//!    between them the mixture (1 − m)·P/Y_P + m·D/Y_D, m = (CCT − 4000)/1000.
//! 4. For test and reference, the CES under the source (CIE 1964 10° XYZ, Y_white = 100)
//!    go through CIECAM02 (L_A = 100 cd/m², Y_b = 20, average surround, illuminant
//!    discounted, D = 1) into CAM02-UCS J′a′b′.
//! 5. ΔE_i is the J′a′b′ distance; R_f,i = 10 ln(1 + e^{(100 − 6.73 ΔE_i)/10}); R_f uses the
//!    mean ΔE.
//! 6. TM-30: each sample goes to hue bin ⌊h_ref/22.5°⌋ by its CIECAM02 hue under the
//!    reference; the bins' mean a′b′ under test and reference give R_g = 100·A_test/A_ref
//!    (polygon areas), R_cs = 100·(Δa′cos θ + Δb′sin θ)/|ref|, R_hs = (−Δa′sin θ +
//!    Δb′cos θ)/|ref| with θ the bin centre, and R_f,hj from the bin's mean ΔE.
//!
//! One difference from colour-science by construction: the CCT search uses candela's Ohno
//! table (1000–100 000 K), colour-science's CIE 2017 code one ending at 25 000 K. The tables
//! share every point below 25 000 K, so the CCT is the same there; above it colour-science
//! extrapolates its last segment.

use std::sync::LazyLock;

use crate::colour::grid::{LEN, START_NM};
use crate::colour::matrix::{mat3_inverse, mat3_mul, mat3_mul_vec, Mat3};
use crate::colour::models::xyz_to_uv1960;
use crate::colour::planck::blackbody_table;
use crate::colour::tables::{cmfs, parse_table, Observer};
use crate::colour::temperature::{cct_to_xy_cie_d, uv_to_cct_ohno2013};

/// Number of colour evaluation samples.
pub const N_CES: usize = 99;
/// Number of TM-30 hue bins (22.5° each).
pub const N_BINS: usize = 16;

/// First and number of 1 nm samples of CIE 224's 380–780 nm range in the 360–830 nm tables.
const FIRST: usize = 380 - START_NM as usize;
const N: usize = 401;

const CES_CSV: &str = include_str!("../../data/ces-cie2017.csv");
const BASIS_CSV: &str = include_str!("../../data/daylight-basis-sprague.csv");

/// CIE daylight at chromaticity `xy` on 380–780 nm from the Sprague-interpolated 1 nm basis,
/// with M1 and M2 rounded to 3 decimals: colour-science's `sd_CIE_illuminant_D_series(xy,
/// shape)` as its CIE 2017 code calls it (it reshapes the basis before combining, unlike
/// `sd_cie_illuminant_d_series`, which interpolates the 5 nm combination linearly).
fn daylight_sprague(xy: [f64; 2]) -> [f64; N] {
    static B: LazyLock<[Vec<f64>; 3]> = LazyLock::new(|| {
        let o = "data/daylight-basis-sprague.csv";
        let t = parse_table(BASIS_CSV, o);
        assert_eq!(t.nm.len(), LEN, "{o}: rows");
        ["S0", "S1", "S2"].map(|name| {
            let c = t
                .names
                .iter()
                .position(|n| n == name)
                .expect("basis column");
            t.cols[c].iter().map(|v| v.expect("basis value")).collect()
        })
    });
    let around3 = |x: f64| (x * 1000.0).round_ties_even() / 1000.0;
    let [x, y] = xy;
    let m = 0.0241 + 0.2562 * x - 0.7341 * y;
    let m1 = around3((-1.3515 - 1.7703 * x + 5.9114 * y) / m);
    let m2 = around3((0.0300 - 31.4424 * x + 30.0717 * y) / m);
    std::array::from_fn(|i| B[0][FIRST + i] + m1 * B[1][FIRST + i] + m2 * B[2][FIRST + i])
}

/// The 99 CES reflectances, 380–780 nm at 1 nm (`[sample][nm − 380]`).
fn ces() -> &'static [[f64; N]; N_CES] {
    static T: LazyLock<Box<[[f64; N]; N_CES]>> = LazyLock::new(|| {
        let o = "data/ces-cie2017.csv";
        let t = parse_table(CES_CSV, o);
        assert_eq!(t.names.len(), N_CES, "{o}: columns");
        assert_eq!(t.nm.len(), N, "{o}: rows");
        let mut out = Box::new([[0.0; N]; N_CES]);
        for (c, row) in out.iter_mut().enumerate() {
            for (i, v) in row.iter_mut().enumerate() {
                assert_eq!(t.nm[i], 380.0 + i as f64, "{o}: row {i}");
                *v = t.cols[c][i].unwrap_or_else(|| panic!("{o}: empty cell"));
            }
        }
        out
    });
    &T
}

/// Which reference illuminant CIE 224 chose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reference {
    /// Planckian radiator (CCT < 4000 K).
    Blackbody,
    /// Blend of blackbody and CIE daylight, with the daylight fraction m = (CCT − 4000 K)/1000 K.
    Mixture { daylight_fraction: f64 },
    /// CIE daylight (CCT > 5000 K).
    Daylight,
}

/// One TM-30 hue bin.
#[derive(Clone, Debug, PartialEq)]
pub struct HueBin {
    /// Samples whose reference hue falls in this bin.
    pub n_samples: usize,
    /// Local chroma shift R_cs,hj, percent.
    pub chroma_shift_percent: f64,
    /// Local hue shift R_hs,hj, radians (as a fraction of the reference chroma).
    pub hue_shift_rad: f64,
    /// Local colour fidelity R_f,hj (0–100).
    pub fidelity: f64,
    /// Mean CAM02-UCS (a′, b′) of the bin's samples under the test source.
    pub test_ab: [f64; 2],
    /// Mean CAM02-UCS (a′, b′) of the bin's samples under the reference.
    pub reference_ab: [f64; 2],
}

/// CIE 224:2017 and TM-30-20 colour rendition of a light source.
#[derive(Clone, Debug, PartialEq)]
pub struct ColourRendition {
    /// Colour fidelity index R_f (CIE 224:2017 = TM-30-20), 0–100.
    pub rf: f64,
    /// Special colour fidelity indices R_f,CESi of the 99 samples.
    pub rf_samples: [f64; N_CES],
    /// TM-30 gamut index R_g (100 = reference gamut area).
    pub rg: f64,
    /// The 16 hue bins, bin j covering reference hues [22.5 j°, 22.5 (j + 1)°).
    pub bins: Vec<HueBin>,
    /// CCT of the test source (Ohno 2013, CIE 1931 2°, 380–780 nm), K.
    pub cct_k: f64,
    /// Duv of the test source.
    pub duv: f64,
    /// The reference illuminant used.
    pub reference: Reference,
}

/// R_f from a colour difference in CAM02-UCS: 10 ln(1 + exp((100 − 6.73 ΔE)/10)).
fn delta_e_to_rf(delta_e: f64) -> f64 {
    10.0 * ((100.0 - 6.73 * delta_e) / 10.0).exp().ln_1p()
}

/// Σ w(λ)·cmf(λ) over 380–780 nm for one observer: `[X, Y, Z]` sums.
fn sums(w: impl Fn(usize) -> f64, observer: Observer) -> [f64; 3] {
    let c = cmfs(observer);
    let mut s = [0.0; 3];
    for i in 0..N {
        let wi = w(i);
        s[0] += wi * c.x[FIRST + i];
        s[1] += wi * c.y[FIRST + i];
        s[2] += wi * c.z[FIRST + i];
    }
    s
}

/// The CIE 224 reference illuminant for `cct_k` on 380–780 nm.
fn reference_illuminant(cct_k: f64) -> ([f64; N], Reference) {
    let slice = |t: [f64; LEN]| -> [f64; N] { std::array::from_fn(|i| t[FIRST + i]) };
    let planck = || slice(blackbody_table(cct_k));
    let daylight = || daylight_sprague(cct_to_xy_cie_d(cct_k));
    if cct_k < 4000.0 {
        (planck(), Reference::Blackbody)
    } else if cct_k <= 5000.0 {
        let (p, d) = (planck(), daylight());
        // Each normalised to Y = 100 as colour-science's sd_to_XYZ does (illuminant E, 2°).
        let ybar = sums(|_| 1.0, Observer::Cie1931_2)[1];
        let yp = 100.0 * sums(|i| p[i], Observer::Cie1931_2)[1] / ybar;
        let yd = 100.0 * sums(|i| d[i], Observer::Cie1931_2)[1] / ybar;
        let m = (cct_k - 4000.0) / 1000.0;
        (
            std::array::from_fn(|i| (1.0 - m) * (p[i] / yp) + m * (d[i] / yd)),
            Reference::Mixture {
                daylight_fraction: m,
            },
        )
    } else {
        (daylight(), Reference::Daylight)
    }
}

const CAT02: Mat3 = [
    [0.7328, 0.4296, -0.1624],
    [-0.7036, 1.6975, 0.0061],
    [0.0030, 0.0136, 0.9834],
];
const XYZ_TO_HPE: Mat3 = [
    [0.38971, 0.68898, -0.07868],
    [-0.22981, 1.18340, 0.04641],
    [0.00000, 0.00000, 1.00000],
];

/// CIECAM02 J, M, h (degrees) of `xyz` under white `xyz_w` (Y_w = 100) for CIE 224's viewing
/// conditions: L_A = 100 cd/m², Y_b = 20, average surround (F = 1, c = 0.69, N_c = 1),
/// illuminant discounted (D = 1). CIE 159:2004; colour-science `XYZ_to_CIECAM02`.
struct Ciecam02 {
    rgb_w: [f64; 3],
    y_w: f64,
    f_l: f64,
    n: f64,
    n_bb: f64,
    z: f64,
    a_w: f64,
    hpe_cat02_inv: Mat3,
}

const L_A: f64 = 100.0;
const Y_B: f64 = 20.0;
const SURROUND_C: f64 = 0.69;
const SURROUND_NC: f64 = 1.0;

impl Ciecam02 {
    fn new(xyz_w: [f64; 3]) -> Self {
        let y_w = xyz_w[1];
        let n = Y_B / y_w;
        let k = 1.0 / (5.0 * L_A + 1.0);
        let k4 = k.powi(4);
        let f_l = 0.2 * k4 * (5.0 * L_A) + 0.1 * (1.0 - k4).powi(2) * (5.0 * L_A).cbrt();
        let n_bb = 0.725 * (1.0 / n).powf(0.2);
        let z = 1.48 + n.sqrt();
        let hpe_cat02_inv = mat3_mul(&XYZ_TO_HPE, &mat3_inverse(&CAT02));
        let rgb_w = mat3_mul_vec(&CAT02, xyz_w);
        let mut s = Self {
            rgb_w,
            y_w,
            f_l,
            n,
            n_bb,
            z,
            a_w: 0.0,
            hpe_cat02_inv,
        };
        let aw = s.compressed(rgb_w);
        s.a_w = (2.0 * aw[0] + aw[1] + aw[2] / 20.0 - 0.305) * n_bb;
        s
    }

    /// Post-adaptation compressed cone responses R′_a, G′_a, B′_a of CAT02 RGB.
    fn compressed(&self, rgb: [f64; 3]) -> [f64; 3] {
        let rgb_c: [f64; 3] = std::array::from_fn(|i| (self.y_w / self.rgb_w[i]) * rgb[i]);
        let p = mat3_mul_vec(&self.hpe_cat02_inv, rgb_c);
        p.map(|v| {
            let f = (self.f_l * v.abs() / 100.0).powf(0.42);
            400.0 * v.signum() * f / (27.13 + f) + 0.1
        })
    }

    /// [J, M, h°].
    fn jmh(&self, xyz: [f64; 3]) -> [f64; 3] {
        let ra = self.compressed(mat3_mul_vec(&CAT02, xyz));
        let a = ra[0] - 12.0 * ra[1] / 11.0 + ra[2] / 11.0;
        let b = (ra[0] + ra[1] - 2.0 * ra[2]) / 9.0;
        let h = b.atan2(a).to_degrees().rem_euclid(360.0);
        let e_t = 0.25 * ((h * std::f64::consts::PI / 180.0 + 2.0).cos() + 3.8);
        let aa = (2.0 * ra[0] + ra[1] + ra[2] / 20.0 - 0.305) * self.n_bb;
        let j = 100.0 * (aa / self.a_w).powf(SURROUND_C * self.z);
        let t = (50000.0 / 13.0 * SURROUND_NC * self.n_bb) * (e_t * (a * a + b * b).sqrt())
            / (ra[0] + ra[1] + 21.0 * ra[2] / 20.0);
        let c = t.powf(0.9) * (j / 100.0).sqrt() * (1.64 - 0.29f64.powf(self.n)).powf(0.73);
        let m = c * self.f_l.powf(0.25);
        [j, m, h]
    }
}

/// CAM02-UCS J′a′b′ (Luo et al. 2006) of CIECAM02 J, M, h.
fn cam02_ucs(jmh: [f64; 3]) -> [f64; 3] {
    let [j, m, h] = jmh;
    let jp = 1.7 * j / (1.0 + 0.007 * j);
    let mp = (0.0228 * m).ln_1p() / 0.0228;
    let hr = h.to_radians();
    [jp, mp * hr.cos(), mp * hr.sin()]
}

/// (J′a′b′, hue °) of every CES under `source` (380–780 nm, any scale).
fn ces_appearance(source: &[f64; N]) -> Vec<([f64; 3], f64)> {
    let o = Observer::Cie1964_10;
    let w = sums(|i| source[i], o);
    let k = 100.0 / w[1];
    let cam = Ciecam02::new(w.map(|v| v * k));
    ces()
        .iter()
        .map(|r| {
            let xyz = sums(|i| r[i] * source[i], o).map(|v| v * k);
            let jmh = cam.jmh(xyz);
            (cam02_ucs(jmh), jmh[2])
        })
        .collect()
}

/// Signed area of the polygon through `pts` (shoelace), as colour-science's `averages_area`.
fn polygon_area(pts: &[[f64; 2]]) -> f64 {
    let n = pts.len();
    (0..n)
        .map(|i| {
            let (u, v) = (pts[i], pts[(i + 1) % n]);
            (u[0] * v[1] - u[1] * v[0]) / 2.0
        })
        .sum()
}

/// CIE 224:2017 R_f and TM-30-20 R_g with the 16 hue bins of a light source with relative
/// spectral power `spectrum` (1 nm, 360–830 nm; only 380–780 nm is used). Returns `None` if the
/// spectrum has no power under ȳ in 380–780 nm.
///
/// Reference: CIE 224:2017 "CIE 2017 Colour Fidelity Index for accurate scientific use";
/// ANSI/IES TM-30-20 "Method for Evaluating Light Source Color Rendition"; colour-science
/// `colour_fidelity_index_CIE2017`, `colour_fidelity_index_ANSIIESTM3018`.
pub fn colour_rendition(spectrum: &[f64; LEN]) -> Option<ColourRendition> {
    let test: [f64; N] = std::array::from_fn(|i| spectrum[FIRST + i]);
    let xyz2 = sums(|i| test[i], Observer::Cie1931_2);
    if xyz2[1] <= 0.0 || !xyz2.iter().all(|v| v.is_finite()) {
        return None;
    }
    let [cct_k, duv] = uv_to_cct_ohno2013(xyz_to_uv1960(xyz2));
    let (reference_sd, reference) = reference_illuminant(cct_k);
    let t = ces_appearance(&test);
    let r = ces_appearance(&reference_sd);
    let de: Vec<f64> = t
        .iter()
        .zip(&r)
        .map(|(a, b)| {
            ((a.0[0] - b.0[0]).powi(2) + (a.0[1] - b.0[1]).powi(2) + (a.0[2] - b.0[2]).powi(2))
                .sqrt()
        })
        .collect();
    let rf = delta_e_to_rf(de.iter().sum::<f64>() / N_CES as f64);
    let rf_samples: [f64; N_CES] = std::array::from_fn(|i| delta_e_to_rf(de[i]));

    let mut acc = vec![([0.0; 2], [0.0; 2], 0.0, 0usize); N_BINS];
    for i in 0..N_CES {
        let bin = ((r[i].1 / 22.5).floor() as usize).min(N_BINS - 1);
        let e = &mut acc[bin];
        e.0[0] += t[i].0[1];
        e.0[1] += t[i].0[2];
        e.1[0] += r[i].0[1];
        e.1[1] += r[i].0[2];
        e.2 += de[i];
        e.3 += 1;
    }
    let bins: Vec<HueBin> = acc
        .iter()
        .enumerate()
        .map(|(j, (ts, rs, des, n))| {
            let nf = *n as f64;
            let ta = [ts[0] / nf, ts[1] / nf];
            let ra = [rs[0] / nf, rs[1] / nf];
            let theta = (22.5 * j as f64 + 11.25).to_radians();
            let norm = ra[0].hypot(ra[1]);
            let (da, db) = (ta[0] - ra[0], ta[1] - ra[1]);
            HueBin {
                n_samples: *n,
                chroma_shift_percent: 100.0 * (da * theta.cos() + db * theta.sin()) / norm,
                hue_shift_rad: (-da * theta.sin() + db * theta.cos()) / norm,
                fidelity: delta_e_to_rf(des / nf),
                test_ab: ta,
                reference_ab: ra,
            }
        })
        .collect();
    let area = |f: fn(&HueBin) -> [f64; 2]| polygon_area(&bins.iter().map(f).collect::<Vec<_>>());
    let rg = 100.0 * area(|b| b.test_ab) / area(|b| b.reference_ab);
    Some(ColourRendition {
        rf,
        rf_samples,
        rg,
        bins,
        cct_k,
        duv,
        reference,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::tables::named_spectrum;

    #[test]
    fn reference_renders_perfectly_and_fl2_matches_colour_science_doc() {
        // A blackbody is its own reference up to Ohno's CCT error (a fraction of a kelvin):
        // R_f within 1e-3 of the perfect 10 ln(1 + e^10), R_g within 1e-3 of 100.
        let bb = blackbody_table(3000.0);
        let c = colour_rendition(&bb).unwrap();
        let perfect = 10.0 * (10f64.exp()).ln_1p();
        assert!((c.rf - perfect).abs() < 1e-3, "{}", c.rf);
        assert!((c.rg - 100.0).abs() < 1e-3, "{}", c.rg);
        assert_eq!(c.bins.iter().map(|b| b.n_samples).sum::<usize>(), N_CES);
        // colour-science's docstring: colour_fidelity_index_CIE2017(SDS_ILLUMINANTS["FL2"]) =
        // 70.1208244… (its native 5 nm FL2; candela's 1 nm table interpolates it linearly, so
        // only the first digits agree; the 1 nm comparison is in tests/colour_health.rs).
        let fl2 = named_spectrum("FL2").unwrap().to_table();
        let c = colour_rendition(&fl2).unwrap();
        assert!((c.rf - 70.12).abs() < 0.2, "{}", c.rf);
    }
}
