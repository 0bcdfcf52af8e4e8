//! The input of a glare evaluation: a luminance image as plain per-pixel arrays (luminance,
//! optional standard error, direction, solid angle, an inside mask), so that the evaluation
//! does not depend on the camera that made it; and the pixel geometry of Radiance's angular
//! fisheye (`-vta`), the projection evalglare is meant for.

use std::fmt;

/// A luminance image seen from one eye point, with its view direction and up vector.
///
/// Pixels are stored row-major, row 0 at the top of the image (the order of a Radiance
/// picture's scanlines and of an EXR), column 0 at the left.
#[derive(Clone, Debug)]
pub struct GlareImage {
    pub width: usize,
    pub height: usize,
    /// Luminance of each pixel, cd/m².
    pub luminance_cd_m2: Vec<f64>,
    /// Standard error of each pixel's luminance, cd/m² (`None`: exact, e.g. a measured image).
    pub stderr_cd_m2: Option<Vec<f64>>,
    /// Unit direction from the eye through each pixel, in the frame of `view_dir` and `up`.
    pub direction: Vec<[f64; 3]>,
    /// Solid angle of each pixel, sr.
    pub solid_angle_sr: Vec<f64>,
    /// Pixels that belong to the view (false for a fisheye's corners); others are ignored.
    pub inside: Vec<bool>,
    /// Unit line of sight.
    pub view_dir: [f64; 3],
    /// Up vector (need not be perpendicular to `view_dir`: the image's vertical is its
    /// component across it; the position index takes it as given or made perpendicular,
    /// [`super::PositionIndexUp`]).
    pub up: [f64; 3],
}

/// Why an image cannot be evaluated.
#[derive(Clone, Debug, PartialEq)]
pub enum ImageError {
    /// An array's length is not width × height.
    Length {
        what: &'static str,
        len: usize,
        expected: usize,
    },
    /// A luminance, standard error or solid angle of an inside pixel is negative or not finite.
    Value {
        what: &'static str,
        index: usize,
        value: f64,
    },
    /// The view direction or up vector is zero, or up is parallel to the view direction.
    Frame,
}

impl fmt::Display for ImageError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            ImageError::Length {
                what,
                len,
                expected,
            } => {
                write!(
                    f,
                    "glare image: {what} has {len} values, expected {expected}"
                )
            }
            ImageError::Value { what, index, value } => {
                write!(f, "glare image: {what} of pixel {index} is {value}")
            }
            ImageError::Frame => write!(
                f,
                "glare image: view direction or up vector is zero, or they are parallel"
            ),
        }
    }
}

impl std::error::Error for ImageError {}

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn normalize(a: [f64; 3]) -> Option<[f64; 3]> {
    let n = dot(a, a).sqrt();
    (n > 0.0 && n.is_finite()).then(|| a.map(|v| v / n))
}

impl GlareImage {
    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.width * self.height
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether pixel `i` takes part in the evaluation: inside the view, with a positive solid
    /// angle (evalglare's "valid pixel").
    pub fn valid(&self, i: usize) -> bool {
        self.inside[i] && self.solid_angle_sr[i] > 0.0
    }

    /// Check the array lengths, the values of inside pixels and the view frame.
    pub fn validate(&self) -> Result<(), ImageError> {
        let n = self.len();
        let lens = [
            ("luminance", self.luminance_cd_m2.len()),
            ("direction", self.direction.len()),
            ("solid angle", self.solid_angle_sr.len()),
            ("inside mask", self.inside.len()),
        ];
        for (what, len) in lens {
            if len != n {
                return Err(ImageError::Length {
                    what,
                    len,
                    expected: n,
                });
            }
        }
        if let Some(se) = &self.stderr_cd_m2 {
            if se.len() != n {
                return Err(ImageError::Length {
                    what: "standard error",
                    len: se.len(),
                    expected: n,
                });
            }
        }
        for i in 0..n {
            if !self.inside[i] {
                continue;
            }
            let mut vals = vec![
                ("luminance", self.luminance_cd_m2[i]),
                ("solid angle", self.solid_angle_sr[i]),
            ];
            if let Some(se) = &self.stderr_cd_m2 {
                vals.push(("standard error", se[i]));
            }
            for (what, value) in vals {
                if !(value >= 0.0 && value.is_finite()) {
                    return Err(ImageError::Value {
                        what,
                        index: i,
                        value,
                    });
                }
            }
        }
        let v = normalize(self.view_dir).ok_or(ImageError::Frame)?;
        normalize(cross(v, self.up)).ok_or(ImageError::Frame)?;
        Ok(())
    }

    /// The unit view direction and the unit up vector made perpendicular to it.
    pub(crate) fn frame(&self) -> ([f64; 3], [f64; 3]) {
        let v = normalize(self.view_dir).expect("validated");
        let right = normalize(cross(v, self.up)).expect("validated");
        (v, cross(right, v))
    }

    /// The unit up vector the position index measures from.
    pub(crate) fn position_up(&self, convention: super::PositionIndexUp) -> [f64; 3] {
        match convention {
            super::PositionIndexUp::AsGiven => normalize(self.up).expect("validated"),
            super::PositionIndexUp::Perpendicular => self.frame().1,
        }
    }
}

/// Per-pixel directions, solid angles (sr) and inside mask of a Radiance angular fisheye view
/// (`rpict -vta -vh h_deg -vv v_deg`, no view shift) of `width` × `height` pixels, row 0 at
/// the top, in the frame where the view direction is +z and up is +y (x to the right).
///
/// A pixel's direction is that of its centre (Radiance's `viewray`); its solid angle is that
/// of the spherical quadrilateral through its four corners' directions (as evalglare
/// computes it); it is inside when its centre lies within the view circle and not behind the
/// eye (the rule evalglare applies to `-vta` images).
pub fn angular_fisheye(
    width: usize,
    height: usize,
    h_deg: f64,
    v_deg: f64,
) -> (Vec<[f64; 3]>, Vec<f64>, Vec<bool>) {
    radiance_view_pixels('a', width, height, h_deg, v_deg, (0.0, 0.0))
}

/// Radiance's `viewray` for view type `kind` (`a` angular fisheye, `h` hemispherical, `s`
/// stereographic, `v` perspective) at image location (`lx`, `ly`) in [0, 1]² (y up), for the
/// full angles `h_deg`, `v_deg` and the view shift and lift `offset`; `None` outside the view.
fn radiance_ray(
    kind: char,
    h_deg: f64,
    v_deg: f64,
    offset: (f64, f64),
    lx: f64,
    ly: f64,
) -> Option<[f64; 3]> {
    use std::f64::consts::PI;
    let (x, y) = (lx + offset.0 - 0.5, ly + offset.1 - 0.5);
    let half = |deg: f64| 0.5 * deg.to_radians();
    match kind {
        'v' => normalize([
            2.0 * x * half(h_deg).tan(),
            2.0 * y * half(v_deg).tan(),
            1.0,
        ]),
        'h' => {
            let (x, y) = (2.0 * x * half(h_deg).sin(), 2.0 * y * half(v_deg).sin());
            let d2 = x * x + y * y;
            (d2 <= 1.0).then(|| [x, y, (1.0 - d2).sqrt()])
        }
        's' => {
            // r = tan(θ/2): the image edge at half the view angle.
            let (x, y) = (
                2.0 * x * (0.5 * half(h_deg)).tan(),
                2.0 * y * (0.5 * half(v_deg)).tan(),
            );
            let d2 = x * x + y * y;
            let z = (1.0 - d2) / (1.0 + d2);
            let s = if d2 <= 1e-12 {
                1.0
            } else {
                ((1.0 - z * z).max(0.0) / d2).sqrt()
            };
            Some([x * s, y * s, z])
        }
        _ => {
            let (x, y) = (x * h_deg / 180.0, y * v_deg / 180.0);
            let d2 = x * x + y * y;
            if d2 > 1.0 {
                return None;
            }
            let d = d2.sqrt();
            let z = (PI * d).cos();
            let s = if d <= 1e-6 {
                PI
            } else {
                (1.0 - z * z).max(0.0).sqrt() / d
            };
            Some([x * s, y * s, z])
        }
    }
}

/// Per-pixel directions, solid angles (sr) and inside mask of a Radiance view of type `kind`
/// (`a`, `h`, `s` or `v`, as in `-vta`) with full angles `h_deg` × `v_deg` and view shift and
/// lift `offset` (`-vs`, `-vl`), as evalglare takes them: the direction through each pixel's
/// centre, the solid angle of the spherical quadrilateral through its corners' directions (0
/// if a corner is outside the view), inside when that is positive and, for `-vta`, the centre
/// is not behind the eye. Row 0 at the top; view direction +z, up +y.
///
/// A stereographic view wider than 180° sees behind the eye in its corners; evalglare counts
/// those pixels (with cos θ < 0 in E_v), candela leaves them out as for `-vta`.
pub fn radiance_view_pixels(
    kind: char,
    width: usize,
    height: usize,
    h_deg: f64,
    v_deg: f64,
    offset: (f64, f64),
) -> (Vec<[f64; 3]>, Vec<f64>, Vec<bool>) {
    let ray = |lx: f64, ly: f64| radiance_ray(kind, h_deg, v_deg, offset, lx, ly);
    let n = width * height;
    let (mut dirs, mut omega, mut inside) = (vec![[0.0; 3]; n], vec![0.0; n], vec![false; n]);
    for row in 0..height {
        // Image location y grows upwards: the bottom row is at ly = 0.5/height.
        let yb = (height - 1 - row) as f64;
        for col in 0..width {
            let i = row * width + col;
            let (lx, ly) = (
                (col as f64 + 0.5) / width as f64,
                (yb + 0.5) / height as f64,
            );
            let Some(d) = ray(lx, ly) else { continue };
            dirs[i] = d;
            let (x0, x1) = (col as f64 / width as f64, (col as f64 + 1.0) / width as f64);
            let (y0, y1) = (yb / height as f64, (yb + 1.0) / height as f64);
            let corners = [ray(x0, y0), ray(x0, y1), ray(x1, y1), ray(x1, y0)];
            if let [Some(a), Some(b), Some(c), Some(e)] = corners {
                omega[i] = spherical_quad_area(a, b, c, e);
            }
            let behind = matches!(kind, 'a' | 's') && d[2] < 0.0;
            inside[i] = !behind && omega[i] > 0.0 && omega[i].is_finite();
        }
    }
    (dirs, omega, inside)
}

/// Solid angle (sr) of the spherical quadrilateral with corners `a`, `b`, `c`, `d` (unit
/// vectors, in order): the sum of the two triangles' solid angles (Van Oosterom & Strackee).
pub fn spherical_quad_area(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> f64 {
    let tri = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
        let num = dot(a, cross(b, c)).abs();
        let den = 1.0 + dot(a, b) + dot(b, c) + dot(c, a);
        2.0 * num.atan2(den)
    };
    tri(a, b, c) + tri(a, c, d)
}
