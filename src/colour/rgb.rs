//! RGB colourspaces: sRGB (IEC 61966-2-1) and friends.

/// XYZ → linear sRGB matrix of IEC 61966-2-1:1999 (4 decimals), exactly as colour-science's
/// `MATRIX_XYZ_TO_sRGB` / `RGB_COLOURSPACE_sRGB.matrix_XYZ_to_RGB`.
pub const MATRIX_XYZ_TO_SRGB: [[f64; 3]; 3] = [
    [3.2406, -1.5372, -0.4986],
    [-0.9689, 1.8758, 0.0415],
    [0.0557, -0.2040, 1.0570],
];

/// Linear sRGB → XYZ matrix of IEC 61966-2-1:1999, colour-science `MATRIX_sRGB_TO_XYZ`.
pub const MATRIX_SRGB_TO_XYZ: [[f64; 3]; 3] = [
    [0.4124, 0.3576, 0.1805],
    [0.2126, 0.7152, 0.0722],
    [0.0193, 0.1192, 0.9505],
];

/// Multiplies a 3×3 matrix by a column vector.
pub fn mat3_mul_vec(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// XYZ (D65-relative, scaled so Y = 1 is white) → linear sRGB, no chromatic adaptation and
/// no clamping.
///
/// Reference: IEC 61966-2-1:1999 §5.2; colour-science `XYZ_to_RGB(XYZ, "sRGB")` with the
/// D65 white point (which then performs no adaptation).
pub fn xyz_to_linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    mat3_mul_vec(&MATRIX_XYZ_TO_SRGB, xyz)
}

/// Linear sRGB → XYZ (inverse direction, IEC 61966-2-1 matrix).
pub fn linear_srgb_to_xyz(rgb: [f64; 3]) -> [f64; 3] {
    mat3_mul_vec(&MATRIX_SRGB_TO_XYZ, rgb)
}

/// IEC 61966-2-1 sRGB encoding (inverse EOTF): `12.92·v` for `v ≤ 0.0031308`, else
/// `1.055·v^(1/2.4) − 0.055`.  No clamping: values above 1 follow the power segment and
/// negative values pass through the **linear** segment (`12.92·v`), exactly as
/// colour-science's `eotf_inverse_sRGB` (`np.where(L <= 0.0031308, L * 12.92, ...)`).
pub fn srgb_encode(v: f64) -> f64 {
    if v <= 0.0031308 {
        v * 12.92
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// IEC 61966-2-1 sRGB decoding (EOTF): `v/12.92` for `v ≤ 0.04045`, else
/// `((v + 0.055)/1.055)^2.4`; negative values pass through the linear segment, as
/// colour-science's `eotf_sRGB`.
pub fn srgb_decode(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encode_reference_values() {
        // colour-science docstring: eotf_inverse_sRGB(0.18) = 0.4613561...
        assert!((srgb_encode(0.18) - 0.4613561).abs() < 1e-7);
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-15);
        assert_eq!(srgb_encode(-0.5), -0.5 * 12.92);
        assert!((srgb_decode(srgb_encode(0.7)) - 0.7).abs() < 1e-12);
    }

    #[test]
    fn white_maps_to_white() {
        // D65 white (IEC 61966-2-1 matrix rows sum to the D65 white point).
        let w = linear_srgb_to_xyz([1.0, 1.0, 1.0]);
        assert!((w[1] - 1.0).abs() < 1e-12);
        let rgb = xyz_to_linear_srgb(w);
        for c in rgb {
            assert!((c - 1.0).abs() < 1e-3, "{rgb:?}");
        }
    }
}
