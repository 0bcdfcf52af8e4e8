//! Chromatic adaptation (von Kries-type transforms: Bradford, CAT02, von Kries).

use crate::colour::matrix::{mat3_inverse, mat3_mul, mat3_mul_vec, Mat3};

/// Chromatic adaptation transform (the cone-response matrix of a von Kries-type CAT).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cat {
    /// Bradford (Lam 1985), colour-science `CAT_BRADFORD`.
    Bradford,
    /// CAT02 (CIECAM02, CIE 159:2004), colour-science `CAT_CAT02`.
    Cat02,
    /// von Kries (Hunt–Pointer–Estévez, normalised to D65), colour-science `CAT_VON_KRIES`.
    VonKries,
}

impl Cat {
    /// The cone-response (sharpened) matrix M of the transform, as colour-science
    /// `CHROMATIC_ADAPTATION_TRANSFORMS[name]`.
    pub fn matrix(self) -> Mat3 {
        match self {
            Cat::Bradford => [
                [0.8951, 0.2664, -0.1614],
                [-0.7502, 1.7135, 0.0367],
                [0.0389, -0.0685, 1.0296],
            ],
            Cat::Cat02 => [
                [0.7328, 0.4296, -0.1624],
                [-0.7036, 1.6975, 0.0061],
                [0.003, 0.0136, 0.9834],
            ],
            Cat::VonKries => [
                [0.40024, 0.7076, -0.08081],
                [-0.2263, 1.16532, 0.0457],
                [0.0, 0.0, 0.91822],
            ],
        }
    }

    /// colour-science's name for the transform.
    pub fn colour_science_name(self) -> &'static str {
        match self {
            Cat::Bradford => "Bradford",
            Cat::Cat02 => "CAT02",
            Cat::VonKries => "Von Kries",
        }
    }

    /// Parses "bradford", "cat02", "vonkries"/"von kries"/"von-kries" (case-insensitive).
    pub fn parse(s: &str) -> Option<Cat> {
        match s
            .trim()
            .to_lowercase()
            .replace([' ', '-', '_'], "")
            .as_str()
        {
            "bradford" => Some(Cat::Bradford),
            "cat02" => Some(Cat::Cat02),
            "vonkries" => Some(Cat::VonKries),
            _ => None,
        }
    }
}

/// Adaptation matrix from source white `xyz_w` to destination white `xyz_wr`:
/// M_CAT = M⁻¹ · diag(M·XYZ_wr / M·XYZ_w) · M (complete adaptation, D = 1).
///
/// Reference: Fairchild, *Color Appearance Models* (3rd ed.) §9; colour-science
/// `matrix_chromatic_adaptation_VonKries(XYZ_w, XYZ_wr, transform)`.
pub fn matrix_chromatic_adaptation_von_kries(xyz_w: [f64; 3], xyz_wr: [f64; 3], cat: Cat) -> Mat3 {
    let m = cat.matrix();
    let rgb_w = mat3_mul_vec(&m, xyz_w);
    let rgb_wr = mat3_mul_vec(&m, xyz_wr);
    let d = [
        [
            if rgb_w[0] == 0.0 {
                0.0
            } else {
                rgb_wr[0] / rgb_w[0]
            },
            0.0,
            0.0,
        ],
        [
            0.0,
            if rgb_w[1] == 0.0 {
                0.0
            } else {
                rgb_wr[1] / rgb_w[1]
            },
            0.0,
        ],
        [
            0.0,
            0.0,
            if rgb_w[2] == 0.0 {
                0.0
            } else {
                rgb_wr[2] / rgb_w[2]
            },
        ],
    ];
    let m_cat = mat3_mul(&mat3_inverse(&m), &d);
    mat3_mul(&m_cat, &m)
}

/// Adapts `xyz` seen under white `xyz_w` to the corresponding colour under `xyz_wr`.
///
/// Reference: colour-science `chromatic_adaptation_VonKries`.
pub fn chromatic_adaptation(
    xyz: [f64; 3],
    xyz_w: [f64; 3],
    xyz_wr: [f64; 3],
    cat: Cat,
) -> [f64; 3] {
    mat3_mul_vec(
        &matrix_chromatic_adaptation_von_kries(xyz_w, xyz_wr, cat),
        xyz,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_science_docstring_bradford() {
        // colour-science: matrix_chromatic_adaptation_VonKries(XYZ_w=[0.95045593,1,1.08905775],
        // XYZ_wr=[0.96429568,1,0.8251046], "Bradford") ≈ [[1.0479298, 0.0229469, -0.0501923],
        // [0.0296278, 0.9904344, -0.0170738], [-0.0092430, 0.0150551, 0.7518742]]
        let m = matrix_chromatic_adaptation_von_kries(
            [0.95045593, 1.0, 1.08905775],
            [0.96429568, 1.0, 0.8251046],
            Cat::Bradford,
        );
        let e = [
            [1.0479298, 0.0229469, -0.0501923],
            [0.0296278, 0.9904344, -0.0170738],
            [-0.0092430, 0.0150551, 0.7518742],
        ];
        for i in 0..3 {
            for j in 0..3 {
                assert!((m[i][j] - e[i][j]).abs() < 1e-6, "{m:?}");
            }
        }
        // Adapting the source white gives the destination white.
        let w = chromatic_adaptation(
            [0.95045593, 1.0, 1.08905775],
            [0.95045593, 1.0, 1.08905775],
            [0.96429568, 1.0, 0.8251046],
            Cat::Cat02,
        );
        assert!((w[2] - 0.8251046).abs() < 1e-12);
    }
}
