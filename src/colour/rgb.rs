//! RGB colourspaces: sRGB (IEC 61966-2-1), Display P3, ITU-R BT.2020 and ACEScg, with
//! optional chromatic adaptation from the XYZ white to the colourspace white.

use crate::colour::adaptation::{matrix_chromatic_adaptation_von_kries, Cat};
use crate::colour::matrix::{mat3_inverse, mat3_mul_vec, Mat3};
use crate::colour::models::xy_to_xyz;

/// XYZ → linear sRGB matrix of IEC 61966-2-1:1999 (4 decimals), exactly as colour-science's
/// `MATRIX_XYZ_TO_sRGB` / `RGB_COLOURSPACE_sRGB.matrix_XYZ_to_RGB`.
pub const MATRIX_XYZ_TO_SRGB: Mat3 = [
    [3.2406, -1.5372, -0.4986],
    [-0.9689, 1.8758, 0.0415],
    [0.0557, -0.2040, 1.0570],
];

/// Linear sRGB → XYZ matrix of IEC 61966-2-1:1999, colour-science `MATRIX_sRGB_TO_XYZ`.
pub const MATRIX_SRGB_TO_XYZ: Mat3 = [
    [0.4124, 0.3576, 0.1805],
    [0.2126, 0.7152, 0.0722],
    [0.0193, 0.1192, 0.9505],
];

/// Normalised primary matrix (RGB → XYZ) from primaries' and white point's chromaticities.
///
/// Reference: SMPTE RP 177-1993; colour-science `normalised_primary_matrix`.
pub fn normalised_primary_matrix(primaries: [[f64; 2]; 3], white_xy: [f64; 2]) -> Mat3 {
    let p = [
        xy_to_xyz(primaries[0]),
        xy_to_xyz(primaries[1]),
        xy_to_xyz(primaries[2]),
    ];
    // Columns are the primaries' XYZ.
    let pm = [
        [p[0][0], p[1][0], p[2][0]],
        [p[0][1], p[1][1], p[2][1]],
        [p[0][2], p[1][2], p[2][2]],
    ];
    let s = mat3_mul_vec(&mat3_inverse(&pm), xy_to_xyz(white_xy));
    [
        [pm[0][0] * s[0], pm[0][1] * s[1], pm[0][2] * s[2]],
        [pm[1][0] * s[0], pm[1][1] * s[1], pm[1][2] * s[2]],
        [pm[2][0] * s[0], pm[2][1] * s[1], pm[2][2] * s[2]],
    ]
}

/// An RGB colourspace known to candela.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RgbColourspace {
    /// sRGB, IEC 61966-2-1:1999 (D65; 4-decimal matrices; sRGB transfer function).
    Srgb,
    /// Display P3 (DCI-P3 primaries, D65, sRGB transfer function).
    DisplayP3,
    /// ITU-R BT.2020 (D65; BT.2020 OETF with the 10-bit constants α = 1.099, β = 0.018).
    Rec2020,
    /// ACEScg (AP1 primaries, ACES white ≈ D60; linear).
    AcesCg,
}

impl RgbColourspace {
    /// All supported colourspaces.
    pub const ALL: [RgbColourspace; 4] = [
        RgbColourspace::Srgb,
        RgbColourspace::DisplayP3,
        RgbColourspace::Rec2020,
        RgbColourspace::AcesCg,
    ];

    /// Short name used by candela ("srgb", "display-p3", "rec2020", "acescg").
    pub fn name(self) -> &'static str {
        match self {
            RgbColourspace::Srgb => "srgb",
            RgbColourspace::DisplayP3 => "display-p3",
            RgbColourspace::Rec2020 => "rec2020",
            RgbColourspace::AcesCg => "acescg",
        }
    }

    /// colour-science `RGB_COLOURSPACES` key.
    pub fn colour_science_name(self) -> &'static str {
        match self {
            RgbColourspace::Srgb => "sRGB",
            RgbColourspace::DisplayP3 => "Display P3",
            RgbColourspace::Rec2020 => "ITU-R BT.2020",
            RgbColourspace::AcesCg => "ACEScg",
        }
    }

    /// Parses a name case-insensitively ("srgb", "display-p3"/"p3", "rec2020"/"bt2020",
    /// "acescg").
    pub fn parse(s: &str) -> Option<Self> {
        match s
            .trim()
            .to_lowercase()
            .replace([' ', '-', '_', '.'], "")
            .as_str()
        {
            "srgb" => Some(RgbColourspace::Srgb),
            "displayp3" | "p3" => Some(RgbColourspace::DisplayP3),
            "rec2020" | "bt2020" | "iturbt2020" => Some(RgbColourspace::Rec2020),
            "acescg" => Some(RgbColourspace::AcesCg),
            _ => None,
        }
    }

    /// Primaries' chromaticities (R, G, B).
    pub fn primaries(self) -> [[f64; 2]; 3] {
        match self {
            RgbColourspace::Srgb => [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]],
            RgbColourspace::DisplayP3 => [[0.68, 0.32], [0.265, 0.69], [0.15, 0.06]],
            RgbColourspace::Rec2020 => [[0.708, 0.292], [0.17, 0.797], [0.131, 0.046]],
            RgbColourspace::AcesCg => [[0.713, 0.293], [0.165, 0.83], [0.128, 0.044]],
        }
    }

    /// White point chromaticity (D65 = (0.3127, 0.3290); ACES = (0.32168, 0.33767)).
    pub fn whitepoint_xy(self) -> [f64; 2] {
        match self {
            RgbColourspace::AcesCg => [0.32168, 0.33767],
            _ => [0.3127, 0.3290],
        }
    }

    /// XYZ → RGB matrix, exactly colour-science's `matrix_XYZ_to_RGB` (the IEC rounded
    /// matrix for sRGB; the inverse normalised primary matrix otherwise).
    pub fn matrix_xyz_to_rgb(self) -> Mat3 {
        match self {
            RgbColourspace::Srgb => MATRIX_XYZ_TO_SRGB,
            RgbColourspace::DisplayP3 => [
                [2.4934969119414263, -0.9313836179191245, -0.4027107844507171],
                [
                    -0.8294889695615748,
                    1.7626640603183463,
                    0.023624685841943605,
                ],
                [
                    0.035845830243784474,
                    -0.07617238926804183,
                    0.9568845240076874,
                ],
            ],
            RgbColourspace::Rec2020 => [
                [
                    1.7166511879712678,
                    -0.35567078377639244,
                    -0.2533662813736598,
                ],
                [
                    -0.6666843518324888,
                    1.6164812366349386,
                    0.015768545813911117,
                ],
                [
                    0.01763985744531079,
                    -0.04277061325780853,
                    0.9421031212354739,
                ],
            ],
            RgbColourspace::AcesCg => [
                [
                    1.6410233796943254,
                    -0.3248032941847899,
                    -0.23642469523761217,
                ],
                [-0.663662858722983, 1.615331591657338, 0.016756347685530137],
                [
                    0.011721894328375376,
                    -0.00828444199623741,
                    0.9883948585390218,
                ],
            ],
        }
    }

    /// RGB → XYZ matrix, exactly colour-science's `matrix_RGB_to_XYZ`.
    pub fn matrix_rgb_to_xyz(self) -> Mat3 {
        match self {
            RgbColourspace::Srgb => MATRIX_SRGB_TO_XYZ,
            RgbColourspace::DisplayP3 => [
                [0.486570948648216, 0.2656676931690931, 0.1982172852343625],
                [0.2289745640697487, 0.6917385218365064, 0.079286914093745],
                [
                    -3.9720755169334855e-17,
                    0.04511338185890264,
                    1.0439443689009757,
                ],
            ],
            RgbColourspace::Rec2020 => [
                [0.6369580483012912, 0.1446169035862084, 0.16888097516417208],
                [0.262700212011267, 0.6779980715188711, 0.05930171646986195],
                [
                    4.994106574466074e-17,
                    0.028072693049087445,
                    1.0609850577107909,
                ],
            ],
            RgbColourspace::AcesCg => [
                [0.6624541811085055, 0.13400420645643313, 0.15618768700490773],
                [0.2722287167809146, 0.6740817658111483, 0.05368951740793703],
                [
                    -0.005574649490394109,
                    0.004060733528982825,
                    1.010339100312997,
                ],
            ],
        }
    }

    /// Encoding transfer function (linear → non-linear signal), no clamping.
    pub fn encode(self, v: f64) -> f64 {
        match self {
            RgbColourspace::Srgb | RgbColourspace::DisplayP3 => srgb_encode(v),
            RgbColourspace::Rec2020 => bt2020_oetf(v),
            RgbColourspace::AcesCg => v,
        }
    }

    /// Decoding transfer function (non-linear signal → linear), no clamping.
    pub fn decode(self, v: f64) -> f64 {
        match self {
            RgbColourspace::Srgb | RgbColourspace::DisplayP3 => srgb_decode(v),
            RgbColourspace::Rec2020 => bt2020_oetf_inverse(v),
            RgbColourspace::AcesCg => v,
        }
    }
}

/// XYZ → RGB in `space`.  `xyz` is on the 0–1 scale (Y = 1 for the adopted white) and
/// relative to the white with chromaticity `illuminant_xy`; if `cat` is given, XYZ is first
/// adapted from that white to the colourspace white (complete von Kries adaptation, even
/// when the two are equal, as colour-science does).  With `encode` the colourspace's
/// transfer function is applied.
///
/// Reference: colour-science `XYZ_to_RGB(XYZ, colourspace, illuminant,
/// chromatic_adaptation_transform, apply_cctf_encoding)`.
pub fn xyz_to_rgb(
    xyz: [f64; 3],
    space: RgbColourspace,
    illuminant_xy: [f64; 2],
    cat: Option<Cat>,
    encode: bool,
) -> [f64; 3] {
    let mut v = xyz;
    if let Some(cat) = cat {
        let m = matrix_chromatic_adaptation_von_kries(
            xy_to_xyz(illuminant_xy),
            xy_to_xyz(space.whitepoint_xy()),
            cat,
        );
        v = mat3_mul_vec(&m, v);
    }
    let rgb = mat3_mul_vec(&space.matrix_xyz_to_rgb(), v);
    if encode {
        rgb.map(|c| space.encode(c))
    } else {
        rgb
    }
}

/// RGB in `space` → XYZ relative to the white `illuminant_xy` (inverse of [`xyz_to_rgb`]).
///
/// Reference: colour-science `RGB_to_XYZ`.
pub fn rgb_to_xyz(
    rgb: [f64; 3],
    space: RgbColourspace,
    illuminant_xy: [f64; 2],
    cat: Option<Cat>,
    decode: bool,
) -> [f64; 3] {
    let lin = if decode {
        rgb.map(|c| space.decode(c))
    } else {
        rgb
    };
    let mut v = mat3_mul_vec(&space.matrix_rgb_to_xyz(), lin);
    if let Some(cat) = cat {
        let m = matrix_chromatic_adaptation_von_kries(
            xy_to_xyz(space.whitepoint_xy()),
            xy_to_xyz(illuminant_xy),
            cat,
        );
        v = mat3_mul_vec(&m, v);
    }
    v
}

/// XYZ (D65-relative, scaled so Y = 1 is white) → linear sRGB, no chromatic adaptation and
/// no clamping.
///
/// Reference: IEC 61966-2-1:1999 §5.2; colour-science `XYZ_to_RGB(XYZ, "sRGB",
/// chromatic_adaptation_transform=None)`.
pub fn xyz_to_linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    mat3_mul_vec(&MATRIX_XYZ_TO_SRGB, xyz)
}

/// Linear sRGB → XYZ (inverse direction, IEC 61966-2-1 matrix).
pub fn linear_srgb_to_xyz(rgb: [f64; 3]) -> [f64; 3] {
    mat3_mul_vec(&MATRIX_SRGB_TO_XYZ, rgb)
}

/// IEC 61966-2-1 sRGB encoding (inverse EOTF): `12.92·v` for `v ≤ 0.0031308`, else
/// `1.055·v^(1/2.4) − 0.055`.  No clamping: values above 1 follow the power segment and
/// negative values pass through the **linear** segment (`12.92·v`, not mirrored), exactly
/// as colour-science's `eotf_inverse_sRGB` (`np.where(L <= 0.0031308, L * 12.92, ...)`).
pub fn srgb_encode(v: f64) -> f64 {
    if v <= 0.0031308 {
        v * 12.92
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// IEC 61966-2-1 sRGB decoding (EOTF): `v/12.92` up to the encoded break point
/// `srgb_encode(0.0031308)` ≈ 0.0404499, else `((v + 0.055)/1.055)^2.4`; negative values
/// pass through the linear segment (colour-science `eotf_sRGB`).
pub fn srgb_decode(v: f64) -> f64 {
    if v <= srgb_encode(0.0031308) {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// ITU-R BT.2020 OETF with the 10-bit constants α = 1.099, β = 0.018: `4.5·E` for E < β,
/// else `α·E^0.45 − (α − 1)`.
///
/// Reference: ITU-R BT.2020-2 Table 4; colour-science `oetf_BT2020`.
pub fn bt2020_oetf(e: f64) -> f64 {
    const A: f64 = 1.099;
    const B: f64 = 0.018;
    if e < B {
        e * 4.5
    } else {
        A * e.powf(0.45) - (A - 1.0)
    }
}

/// Inverse of [`bt2020_oetf`] (colour-science `oetf_inverse_BT2020`).
pub fn bt2020_oetf_inverse(ep: f64) -> f64 {
    const A: f64 = 1.099;
    if ep < bt2020_oetf(0.018) {
        ep / 4.5
    } else {
        ((ep + (A - 1.0)) / A).powf(1.0 / 0.45)
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
        // colour-science docstring: oetf_inverse_BT2020(0.705515089922121) = 0.4999999...
        assert!((bt2020_oetf(0.5) - 0.705515089922121).abs() < 1e-12);
        assert!((bt2020_oetf_inverse(0.705515089922121) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn white_maps_to_white() {
        let w = linear_srgb_to_xyz([1.0, 1.0, 1.0]);
        assert!((w[1] - 1.0).abs() < 1e-12);
        let rgb = xyz_to_linear_srgb(w);
        for c in rgb {
            assert!((c - 1.0).abs() < 1e-3, "{rgb:?}");
        }
        for s in RgbColourspace::ALL {
            let w = xy_to_xyz(s.whitepoint_xy());
            let rgb = xyz_to_rgb(w, s, s.whitepoint_xy(), Some(Cat::Bradford), false);
            for c in rgb {
                assert!((c - 1.0).abs() < 2e-4, "{s:?} {rgb:?}");
            }
            assert_eq!(RgbColourspace::parse(s.name()), Some(s));
        }
    }

    #[test]
    fn matrices_are_normalised_primary_matrices() {
        for s in [
            RgbColourspace::DisplayP3,
            RgbColourspace::Rec2020,
            RgbColourspace::AcesCg,
        ] {
            let npm = normalised_primary_matrix(s.primaries(), s.whitepoint_xy());
            let m = s.matrix_rgb_to_xyz();
            let inv = mat3_inverse(&npm);
            let mi = s.matrix_xyz_to_rgb();
            for i in 0..3 {
                for j in 0..3 {
                    assert!((npm[i][j] - m[i][j]).abs() < 1e-14, "{s:?}");
                    assert!((inv[i][j] - mi[i][j]).abs() < 1e-13, "{s:?}");
                }
            }
        }
    }
}
