//! Correlated colour temperature (CCT) and distance from the Planckian locus (Duv):
//! Robertson (1968) and Ohno (2013), plus the Planckian locus and the CIE daylight locus.
//!
//! CCT and Duv are defined in the CIE 1960 UCS (u, v) of the CIE 1931 2° observer (CIE
//! 15:2018 §9.5); colour-science computes its Planckian locus with the CIE 1931 2° CMFs
//! trimmed to its default shape 360–780 nm, and so does candela (for exact agreement).

use std::sync::LazyLock;

use crate::colour::models::xyz_to_uv1960;
use crate::colour::planck::planck_law;
use crate::colour::tables::{cmfs, Observer};

/// Robertson (1968) iso-temperature lines: (mired, u, v, slope t), with Lindbloom's
/// correction at 325 mired (colour-science `DATA_ISOTEMPERATURE_LINES_ROBERTSON1968`).
const ROBERTSON: [[f64; 4]; 31] = [
    [0.0, 0.18006, 0.26352, -0.24341],
    [10.0, 0.18066, 0.26589, -0.25479],
    [20.0, 0.18133, 0.26846, -0.26876],
    [30.0, 0.18208, 0.27119, -0.28539],
    [40.0, 0.18293, 0.27407, -0.30470],
    [50.0, 0.18388, 0.27709, -0.32675],
    [60.0, 0.18494, 0.28021, -0.35156],
    [70.0, 0.18611, 0.28342, -0.37915],
    [80.0, 0.18740, 0.28668, -0.40955],
    [90.0, 0.18880, 0.28997, -0.44278],
    [100.0, 0.19032, 0.29326, -0.47888],
    [125.0, 0.19462, 0.30141, -0.58204],
    [150.0, 0.19962, 0.30921, -0.70471],
    [175.0, 0.20525, 0.31647, -0.84901],
    [200.0, 0.21142, 0.32312, -1.0182],
    [225.0, 0.21807, 0.32909, -1.2168],
    [250.0, 0.22511, 0.33439, -1.4512],
    [275.0, 0.23247, 0.33904, -1.7298],
    [300.0, 0.24010, 0.34308, -2.0637],
    [325.0, 0.24792, 0.34655, -2.4681],
    [350.0, 0.25591, 0.34951, -2.9641],
    [375.0, 0.26400, 0.35200, -3.5814],
    [400.0, 0.27218, 0.35407, -4.3633],
    [425.0, 0.28039, 0.35577, -5.3762],
    [450.0, 0.28863, 0.35714, -6.7262],
    [475.0, 0.29685, 0.35823, -8.5955],
    [500.0, 0.30505, 0.35907, -11.324],
    [525.0, 0.31320, 0.35968, -15.628],
    [550.0, 0.32129, 0.36011, -23.325],
    [575.0, 0.32931, 0.36038, -40.770],
    [600.0, 0.33724, 0.36051, -116.45],
];

/// CCT (K) and Duv from CIE 1960 (u, v) by Robertson's (1968) iso-temperature lines.
///
/// Returns `[CCT, Duv]`, Duv positive above the Planckian locus.  Valid for roughly
/// 1667 K–∞ (0–600 mired); outside that the last segment is extrapolated, as in
/// colour-science.
///
/// Reference: Robertson, A. R. (1968), "Computation of correlated color temperature and
/// distribution temperature", JOSA 58(11); Wyszecki & Stiles (2000) §3.11;
/// colour-science `uv_to_CCT_Robertson1968` (its vectorised crossing search reproduced
/// exactly).
pub fn uv_to_cct_robertson1968(uv: [f64; 2]) -> [f64; 2] {
    let [u, v] = uv;
    let du: Vec<f64> = ROBERTSON.iter().map(|l| 1.0 / 1.0f64.hypot(l[3])).collect();
    let dv: Vec<f64> = ROBERTSON
        .iter()
        .map(|l| l[3] / 1.0f64.hypot(l[3]))
        .collect();
    // dt[j] for lines j = 1..=30 (stored at j - 1).
    let dt: Vec<f64> = (1..31)
        .map(|j| {
            let uu = u - ROBERTSON[j][1];
            let vv = v - ROBERTSON[j][2];
            -uu * dv[j] + vv * du[j]
        })
        .collect();
    let i = dt
        .iter()
        .position(|&d| d <= 0.0)
        .map(|p| p + 1)
        .unwrap_or(30);
    let f = if i == 1 {
        0.0
    } else {
        let dt_current = -dt[i - 1].min(0.0);
        let dt_previous = dt[i - 2];
        dt_current / (dt_previous + dt_current)
    };
    let mired = ROBERTSON[i - 1][0] * f + ROBERTSON[i][0] * (1.0 - f);
    let t = 1.0e6 / mired;
    let u_i = ROBERTSON[i - 1][1] * f + ROBERTSON[i][1] * (1.0 - f);
    let v_i = ROBERTSON[i - 1][2] * f + ROBERTSON[i][2] * (1.0 - f);
    let mut du_i = du[i] * (1.0 - f) + du[i - 1] * f;
    let mut dv_i = dv[i] * (1.0 - f) + dv[i - 1] * f;
    let len = du_i.hypot(dv_i);
    du_i /= len;
    dv_i /= len;
    let d_uv = (u - u_i) * du_i + (v - v_i) * dv_i;
    [t, -d_uv]
}

/// CIE 1960 (u, v) of a blackbody at `cct_k`, integrated with `observer`'s CMFs over
/// 360–780 nm at 1 nm (colour-science's default shape).
///
/// Reference: colour-science `CCT_to_uv_Planck1900(CCT, cmfs)` with the default
/// `cmfs` (CIE 1931 2°, `SPECTRAL_SHAPE_DEFAULT` = 360–780 nm, 1 nm).
pub fn cct_to_uv_planck(cct_k: f64, observer: Observer) -> [f64; 2] {
    let c = cmfs(observer);
    let mut xyz = [0.0; 3];
    for i in 0..=(780 - 360) {
        let nm = 360.0 + i as f64;
        let p = planck_law(nm * 1e-9, cct_k) * 1e-9;
        xyz[0] += p * c.x[i];
        xyz[1] += p * c.y[i];
        xyz[2] += p * c.z[i];
    }
    xyz_to_uv1960(xyz)
}

/// Lowest temperature of Ohno's (2013) Planckian table, K (colour-science
/// `CCT_MINIMAL_OHNO2013`).
pub const CCT_MINIMAL_OHNO2013: f64 = 1000.0;
/// Highest temperature of the table, K (`CCT_MAXIMAL_OHNO2013`).
pub const CCT_MAXIMAL_OHNO2013: f64 = 100000.0;
/// Geometric spacing of the table (`CCT_DEFAULT_SPACING_OHNO2013`).
pub const CCT_DEFAULT_SPACING_OHNO2013: f64 = 1.001;

/// Ohno's Planckian table: rows `[T, u, v]`, built exactly as colour-science's
/// `planckian_table(cmfs, 1000, 100000, 1.001)`.
fn planckian_table(observer: Observer) -> Vec<[f64; 3]> {
    let (start, end, spacing) = (
        CCT_MINIMAL_OHNO2013,
        CCT_MAXIMAL_OHNO2013,
        CCT_DEFAULT_SPACING_OHNO2013,
    );
    let mut ti = vec![start, start + 1.0];
    let mut next_ti = start + 1.0;
    let mut next_spacing = spacing;
    loop {
        next_ti *= next_spacing;
        if next_ti >= end {
            break;
        }
        ti.push(next_ti);
        let d = ((next_ti - CCT_MINIMAL_OHNO2013) / (CCT_MAXIMAL_OHNO2013 - CCT_MINIMAL_OHNO2013))
            .clamp(0.0, 1.0);
        next_spacing = spacing * (1.0 - d) + (1.0 + (spacing - 1.0) / 10.0) * d;
    }
    ti.push(end - 1.0);
    ti.push(end);
    ti.iter()
        .map(|&t| {
            let uv = cct_to_uv_planck(t, observer);
            [t, uv[0], uv[1]]
        })
        .collect()
}

static TABLE_2: LazyLock<Vec<[f64; 3]>> = LazyLock::new(|| planckian_table(Observer::Cie1931_2));

/// CCT (K) and Duv from CIE 1960 (u, v) by Ohno's (2013) combined triangular/parabolic
/// solution on a Planckian table (1000–100 000 K, spacing 1.001) computed with the CIE
/// 1931 2° observer over 360–780 nm.  Returns `[CCT, Duv]`.
///
/// Reference: Ohno, Y. (2014), "Practical Use and Calculation of CCT and Duv", LEUKOS
/// 10(1) 47–55; colour-science `uv_to_CCT_Ohno2013(uv)` (default arguments).
pub fn uv_to_cct_ohno2013(uv: [f64; 2]) -> [f64; 2] {
    let table: &[[f64; 3]] = &TABLE_2;
    let dist = |r: &[f64; 3]| (r[1] - uv[0]).hypot(r[2] - uv[1]);
    let mut index = 0;
    let mut best = f64::INFINITY;
    for (k, r) in table.iter().enumerate() {
        let d = dist(r);
        if d < best {
            best = d;
            index = k;
        }
    }
    if index == 0 {
        index = 1;
    } else if index == table.len() - 1 {
        index -= 1;
    }
    let (p, c, n) = (table[index - 1], table[index], table[index + 1]);
    let (tip, uip, vip, dip) = (p[0], p[1], p[2], dist(&p));
    let (ti, di) = (c[0], dist(&c));
    let (tin, uin, vin, din) = (n[0], n[1], n[2], dist(&n));

    let l = (uin - uip).hypot(vin - vip);
    let x = (dip * dip - din * din + l * l) / (2.0 * l);
    let t_t = tip + (tin - tip) * (x / l);
    let vtx = vip + (vin - vip) * (x / l);
    let sign = signum0(uv[1] - vtx);
    let d_uv_t = (dip * dip - x * x).sqrt() * sign;

    let xx = (tin - ti) * (tip - tin) * (ti - tip);
    let a = (tip * (din - di) + ti * (dip - din) + tin * (di - dip)) / xx;
    let b = -(tip * tip * (din - di) + ti * ti * (dip - din) + tin * tin * (di - dip)) / xx;
    let cc =
        -(dip * (tin - ti) * ti * tin + di * (tip - tin) * tip * tin + din * (ti - tip) * tip * ti)
            / xx;
    let t_p = -b / (2.0 * a);
    let d_uv_p = (a * t_p * t_p + b * t_p + cc) * sign;
    if d_uv_t.abs() >= 0.002 {
        [t_p, d_uv_p]
    } else {
        [t_t, d_uv_t]
    }
}

/// numpy's `sign`: −1, 0 or +1.
fn signum0(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// CIE 1960 (u, v) of the point at `cct_k` and `duv` (Ohno 2013): the Planckian point
/// displaced by Duv along the normal to the locus.
///
/// Reference: Ohno (2014) eq. 12–14; colour-science `CCT_to_uv_Ohno2013`.
pub fn cct_to_uv_ohno2013(cct_k: f64, duv: f64) -> [f64; 2] {
    let uv0 = cct_to_uv_planck(cct_k, Observer::Cie1931_2);
    if duv == 0.0 {
        return uv0;
    }
    let uv1 = cct_to_uv_planck(cct_k + 0.01, Observer::Cie1931_2);
    let du = uv0[0] - uv1[0];
    let dv = uv0[1] - uv1[1];
    let h = du.hypot(dv);
    [uv0[0] - duv * dv / h, uv0[1] + duv * du / h]
}

/// CCT and Duv of a tristimulus value (any scale) by Ohno (2013).
///
/// Reference: colour-science `XYZ_to_CCT_Ohno2013`.
pub fn xyz_to_cct_ohno2013(xyz: [f64; 3]) -> [f64; 2] {
    uv_to_cct_ohno2013(xyz_to_uv1960(xyz))
}

/// Chromaticity (x, y) on the CIE daylight locus at correlated colour temperature `cct_k`
/// (intended domain 4000–25 000 K).  The CCT is used as given: for the nominal D65 use
/// 6500 × 1.4388/1.4380 ≈ 6504 K.
///
/// Reference: CIE 15:2018 eq. 4.6–4.8; colour-science `CCT_to_xy_CIE_D`.
pub fn cct_to_xy_cie_d(cct_k: f64) -> [f64; 2] {
    let t = cct_k;
    let t2 = t * t;
    let t3 = t2 * t;
    let x = if t <= 7000.0 {
        -4.607e9 / t3 + 2.9678e6 / t2 + 0.09911e3 / t + 0.244063
    } else {
        -2.0064e9 / t3 + 1.9018e6 / t2 + 0.24748e3 / t + 0.23704
    };
    [x, daylight_locus_y(x)]
}

/// CIE daylight locus y(x) = −3.000x² + 2.870x − 0.275.
///
/// Reference: CIE 15:2018 eq. 4.9; colour-science `daylight_locus_function`.
pub fn daylight_locus_y(x: f64) -> f64 {
    -3.000 * x * x + 2.870 * x - 0.275
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planck_uv_docstring() {
        // colour-science: CCT_to_uv_Planck1900(6504) = [0.2004280..., 0.3103334...]
        let uv = cct_to_uv_planck(6504.0, Observer::Cie1931_2);
        assert!(
            (uv[0] - 0.2004280).abs() < 1e-7 && (uv[1] - 0.3103334).abs() < 1e-7,
            "{uv:?}"
        );
    }

    #[test]
    fn roundtrip_ohno_and_robertson() {
        for &(t, duv) in &[
            (2856.0, 0.0),
            (4000.0, 0.01),
            (6504.0, -0.005),
            (10000.0, 0.02),
        ] {
            let uv = cct_to_uv_ohno2013(t, duv);
            let r = uv_to_cct_ohno2013(uv);
            assert!(
                (r[0] - t).abs() < 0.5 && (r[1] - duv).abs() < 1e-5,
                "{t} {duv} {r:?}"
            );
            let r = uv_to_cct_robertson1968(uv);
            assert!(
                (r[0] - t).abs() / t < 2e-3 && (r[1] - duv).abs() < 2e-4,
                "{t} {duv} {r:?}"
            );
        }
    }

    #[test]
    fn daylight_locus() {
        // colour-science: CCT_to_xy_CIE_D(6500 * 1.4388 / 1.4380) = [0.31272027, 0.32912528].
        let xy = cct_to_xy_cie_d(6500.0 * 1.4388 / 1.4380);
        assert!((xy[0] - 0.31272027).abs() < 1e-8, "{xy:?}");
        assert!((xy[1] - 0.32912528).abs() < 1e-8, "{xy:?}");
    }
}
