//! Colour models: CIE xyY, CIE 1960 UCS (u, v), CIE 1976 UCS (u′, v′), CIELAB, CIELUV, and
//! the CIEDE2000 colour difference.
//!
//! Each function follows the colour-science 0.4.7 implementation named in its doc comment,
//! including its conventions for the black point (divisions by zero give 0, colour-science's
//! `sdiv_mode()` default).

/// Division returning 0 when the denominator is 0 (colour-science `sdiv` default mode
/// "Ignore Zero Conversion").
fn sdiv(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        0.0
    } else {
        a / b
    }
}

/// XYZ → xyY.  x = X/(X+Y+Z), y = Y/(X+Y+Z), Y unchanged; black gives x = y = 0.
///
/// Reference: CIE 15:2018 eq. 7.5; colour-science `XYZ_to_xyY`.
pub fn xyz_to_xyy(xyz: [f64; 3]) -> [f64; 3] {
    let s = xyz[0] + xyz[1] + xyz[2];
    [sdiv(xyz[0], s), sdiv(xyz[1], s), xyz[1]]
}

/// XYZ → chromaticity (x, y).
///
/// Reference: CIE 15:2018 eq. 7.5; colour-science `XYZ_to_xy`.
pub fn xyz_to_xy(xyz: [f64; 3]) -> [f64; 2] {
    let v = xyz_to_xyy(xyz);
    [v[0], v[1]]
}

/// xyY → XYZ: X = xY/y, Z = (1 − x − y)Y/y; y = 0 gives X = Z = 0.
///
/// Reference: CIE 15:2018 eq. 7.6; colour-science `xyY_to_XYZ`.
pub fn xyy_to_xyz(xyy: [f64; 3]) -> [f64; 3] {
    let [x, y, yy] = xyy;
    [sdiv(x * yy, y), yy, sdiv((1.0 - x - y) * yy, y)]
}

/// Chromaticity (x, y) → XYZ with Y = 1.
///
/// Reference: colour-science `xy_to_XYZ`.
pub fn xy_to_xyz(xy: [f64; 2]) -> [f64; 3] {
    xyy_to_xyz([xy[0], xy[1], 1.0])
}

/// XYZ → CIE 1960 UCS chromaticity (u, v), via U = 2X/3, V = Y, W = (−X + 3Y + Z)/2:
/// u = U/(U+V+W) = 4X/(X+15Y+3Z), v = V/(U+V+W) = 6Y/(X+15Y+3Z).
///
/// Reference: CIE 15:2018 §8.1 (1960 UCS, used for CCT); colour-science
/// `UCS_to_uv(XYZ_to_UCS(XYZ))`.
pub fn xyz_to_uv1960(xyz: [f64; 3]) -> [f64; 2] {
    let [x, y, z] = xyz;
    let u = 2.0 / 3.0 * x;
    let v = y;
    let w = 0.5 * (-x + 3.0 * y + z);
    let s = u + v + w;
    [sdiv(u, s), sdiv(v, s)]
}

/// CIE 1960 (u, v) → chromaticity (x, y): x = 3u/(2u − 8v + 4), y = 2v/(2u − 8v + 4).
///
/// Reference: colour-science `UCS_uv_to_xy`.
pub fn uv1960_to_xy(uv: [f64; 2]) -> [f64; 2] {
    let d = 2.0 * uv[0] - 8.0 * uv[1] + 4.0;
    [3.0 * uv[0] / d, 2.0 * uv[1] / d]
}

/// XYZ → CIE 1976 UCS chromaticity (u′, v′): u′ = 4X/(X+15Y+3Z), v′ = 9Y/(X+15Y+3Z).
///
/// Reference: CIE 15:2018 eq. 8.6–8.7; colour-science `Luv_to_uv(XYZ_to_Luv(XYZ))`
/// (and `xy_to_Luv_uv`).
pub fn xyz_to_upvp(xyz: [f64; 3]) -> [f64; 2] {
    let d = xyz[0] + 15.0 * xyz[1] + 3.0 * xyz[2];
    [sdiv(4.0 * xyz[0], d), sdiv(9.0 * xyz[1], d)]
}

/// CIE 1976 (u′, v′) → chromaticity (x, y): x = 9u′/(6u′ − 16v′ + 12),
/// y = 4v′/(6u′ − 16v′ + 12).
///
/// Reference: colour-science `Luv_uv_to_xy`.
pub fn upvp_to_xy(upvp: [f64; 2]) -> [f64; 2] {
    let d = 6.0 * upvp[0] - 16.0 * upvp[1] + 12.0;
    [9.0 * upvp[0] / d, 4.0 * upvp[1] / d]
}

/// CIE 1976 intermediate function f(t): t^(1/3) if t > (24/116)³, else (841/108)t + 16/116.
///
/// Reference: CIE 15:2018 eq. 8.11; colour-science `intermediate_lightness_function_CIE1976`.
fn f_cie1976(t: f64) -> f64 {
    if t > (24.0f64 / 116.0).powi(3) {
        t.cbrt()
    } else {
        (841.0 / 108.0) * t + 16.0 / 116.0
    }
}

/// Inverse of [`f_cie1976`].
fn f_cie1976_inv(f: f64) -> f64 {
    if f > 24.0 / 116.0 {
        f * f * f
    } else {
        (108.0 / 841.0) * (f - 16.0 / 116.0)
    }
}

/// XYZ → CIELAB (L*, a*, b*) relative to the white point with chromaticity `white_xy`
/// (Y_n = 1).  XYZ on the 0–1 scale (divide colour-science's "reference" 0–100 values by
/// 100).
///
/// Reference: CIE 15:2018 §8.2.1; colour-science `XYZ_to_Lab(XYZ, illuminant)`.
pub fn xyz_to_lab(xyz: [f64; 3], white_xy: [f64; 2]) -> [f64; 3] {
    let n = xy_to_xyz(white_xy);
    let fx = f_cie1976(xyz[0] / n[0]);
    let fy = f_cie1976(xyz[1] / n[1]);
    let fz = f_cie1976(xyz[2] / n[2]);
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// CIELAB → XYZ (0–1 scale) relative to the white point `white_xy`.
///
/// Reference: CIE 15:2018 §8.2.1; colour-science `Lab_to_XYZ`.
pub fn lab_to_xyz(lab: [f64; 3], white_xy: [f64; 2]) -> [f64; 3] {
    let n = xy_to_xyz(white_xy);
    let fy = (lab[0] + 16.0) / 116.0;
    let fx = lab[1] / 500.0 + fy;
    let fz = fy - lab[2] / 200.0;
    [
        n[0] * f_cie1976_inv(fx),
        n[1] * f_cie1976_inv(fy),
        n[2] * f_cie1976_inv(fz),
    ]
}

/// XYZ → CIELUV (L*, u*, v*) relative to the white point `white_xy`; XYZ on the 0–1 scale.
///
/// Reference: CIE 15:2018 §8.2.2; colour-science `XYZ_to_Luv`.
pub fn xyz_to_luv(xyz: [f64; 3], white_xy: [f64; 2]) -> [f64; 3] {
    let n = xy_to_xyz(white_xy);
    let l = 116.0 * f_cie1976(xyz[1] / n[1]) - 16.0;
    let [up, vp] = xyz_to_upvp(xyz);
    let [upn, vpn] = xyz_to_upvp(n);
    [l, 13.0 * l * (up - upn), 13.0 * l * (vp - vpn)]
}

/// CIEDE2000 colour difference ΔE₀₀ between two CIELAB colours (k_L = k_C = k_H = 1).
///
/// Reference: CIE 142-2001; Sharma, Wu & Dalal (2005), "The CIEDE2000 color-difference
/// formula: implementation notes"; colour-science `delta_E_CIE2000` (textiles=False).
pub fn delta_e_ciede2000(lab1: [f64; 3], lab2: [f64; 3]) -> f64 {
    let [l1, a1, b1] = lab1;
    let [l2, a2, b2] = lab2;
    let c1_ab = a1.hypot(b1);
    let c2_ab = a2.hypot(b2);
    let c_bar_ab = (c1_ab + c2_ab) / 2.0;
    let c_bar_ab_7 = c_bar_ab.powi(7);
    let p25_7 = 25.0f64.powi(7);
    let g = 0.5 * (1.0 - (c_bar_ab_7 / (c_bar_ab_7 + p25_7)).sqrt());
    let a_p_1 = (1.0 + g) * a1;
    let a_p_2 = (1.0 + g) * a2;
    let c_p_1 = a_p_1.hypot(b1);
    let c_p_2 = a_p_2.hypot(b2);
    let hue = |b: f64, ap: f64| {
        if b == 0.0 && ap == 0.0 {
            0.0
        } else {
            b.atan2(ap).to_degrees().rem_euclid(360.0)
        }
    };
    let h_p_1 = hue(b1, a_p_1);
    let h_p_2 = hue(b2, a_p_2);
    let delta_l_p = l2 - l1;
    let delta_c_p = c_p_2 - c_p_1;
    let h21 = h_p_2 - h_p_1;
    let c12 = c_p_1 * c_p_2;
    let delta_h_p = if c12 == 0.0 {
        0.0
    } else if h21.abs() <= 180.0 {
        h21
    } else if h21 > 180.0 {
        h21 - 360.0
    } else {
        h21 + 360.0
    };
    let delta_big_h_p = 2.0 * c12.sqrt() * (delta_h_p / 2.0).to_radians().sin();
    let l_bar_p = (l1 + l2) / 2.0;
    let c_bar_p = (c_p_1 + c_p_2) / 2.0;
    let a_h = (h_p_1 - h_p_2).abs();
    let h_sum = h_p_1 + h_p_2;
    let h_bar_p = if c12 == 0.0 {
        h_sum
    } else if a_h <= 180.0 {
        h_sum / 2.0
    } else if h_sum < 360.0 {
        (h_sum + 360.0) / 2.0
    } else {
        (h_sum - 360.0) / 2.0
    };
    let t = 1.0 - 0.17 * (h_bar_p - 30.0).to_radians().cos()
        + 0.24 * (2.0 * h_bar_p).to_radians().cos()
        + 0.32 * (3.0 * h_bar_p + 6.0).to_radians().cos()
        - 0.20 * (4.0 * h_bar_p - 63.0).to_radians().cos();
    let delta_theta = 30.0 * (-((h_bar_p - 275.0) / 25.0).powi(2)).exp();
    let c_bar_p_7 = c_bar_p.powi(7);
    let r_c = 2.0 * (c_bar_p_7 / (c_bar_p_7 + p25_7)).sqrt();
    let l_bar_p_2 = (l_bar_p - 50.0).powi(2);
    let s_l = 1.0 + (0.015 * l_bar_p_2) / (20.0 + l_bar_p_2).sqrt();
    let s_c = 1.0 + 0.045 * c_bar_p;
    let s_h = 1.0 + 0.015 * c_bar_p * t;
    let r_t = -(2.0 * delta_theta).to_radians().sin() * r_c;
    let dl = delta_l_p / s_l;
    let dc = delta_c_p / s_c;
    let dh = delta_big_h_p / s_h;
    (dl * dl + dc * dc + dh * dh + r_t * dc * dh).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sharma_reference_pairs() {
        // Sharma, Wu & Dalal (2005) test data, pairs 1, 7, 17, 25.
        let cases = [
            ([50.0, 2.6772, -79.7751], [50.0, 0.0, -82.7485], 2.0425),
            ([50.0, 0.0, 0.0], [50.0, -1.0, 2.0], 2.3669),
            ([50.0, 2.5, 0.0], [73.0, 25.0, -18.0], 27.1492),
            (
                [60.2574, -34.0099, 36.2677],
                [60.4626, -34.1751, 39.4387],
                1.2644,
            ),
        ];
        for (a, b, e) in cases {
            let d = delta_e_ciede2000(a, b);
            assert!((d - e).abs() < 5e-5, "{a:?} {b:?} {d} vs {e}");
        }
    }

    #[test]
    fn roundtrips() {
        let xyz = [0.2, 0.3, 0.4];
        let wp = [0.3127, 0.3290];
        let back = lab_to_xyz(xyz_to_lab(xyz, wp), wp);
        for i in 0..3 {
            assert!((back[i] - xyz[i]).abs() < 1e-14);
        }
        let xy = xyz_to_xy(xyz);
        let uv = xyz_to_uv1960(xyz);
        let up = xyz_to_upvp(xyz);
        let a = uv1960_to_xy(uv);
        let b = upvp_to_xy(up);
        assert!((a[0] - xy[0]).abs() < 1e-15 && (b[1] - xy[1]).abs() < 1e-15);
        assert!((up[1] - 1.5 * uv[1]).abs() < 1e-15);
        let l = xyz_to_lab(xy_to_xyz(wp), wp);
        assert!((l[0] - 100.0).abs() < 1e-12 && l[1].abs() < 1e-12);
    }
}
