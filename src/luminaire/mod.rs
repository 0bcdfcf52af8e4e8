//! Photometric files of real luminaires: IES LM-63 (`.ies`, [`ies`]) and EULUMDAT (`.ldt`,
//! [`ldt`]), read into one [`Photometry`] type, expanded to a full [`Distribution`] that is
//! interpolated, integrated (lumens) and importance-sampled.
//!
//! ## Coordinate conventions (the luminaire's own frame; docs/luminaires.md)
//! The luminaire frame coincides with the world frame when the light has no rotation:
//! - photometric nadir (type C γ = 0; the type A/B main axis H = V = 0) is **−Y**;
//! - type C: the C0 half-plane contains **+X**, C90 contains **−Z** (C grows counter-clockwise
//!   seen from above, i.e. right-handed about +Y); a direction is
//!   `(sin γ cos C, −cos γ, −sin γ sin C)`;
//! - type B (polar axis along the luminaire's C90 direction −Z):
//!   `cos H cos V (−Y) + cos H sin V (+X) + sin H (−Z)`;
//! - type A (polar axis along +X): `cos V cos H (−Y) + cos V sin H (−Z) + sin V (+X)`.
//!
//! Candela is bilinear in the two file angles between table entries (continuous everywhere the
//! table is, exact at the entries) and 0 outside the table's range of vertical angles.

pub mod diagram;
pub mod ies;
pub mod ldt;
pub mod summary;

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

/// A parse error: file, 1-based line, the field being read, and what is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}:{line}: {field}: {message}", file.display())]
pub struct ParseError {
    pub file: PathBuf,
    pub line: usize,
    pub field: String,
    pub message: String,
}

/// Errors of [`load`].
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    #[error("cannot read luminaire file {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error(transparent)]
    Parse(#[from] ParseError),
}

/// The photometric coordinate system (IES "photometric type").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// C planes around the vertical axis, γ from nadir (interior and road luminaires).
    C,
    /// Polar axis horizontal, across the luminaire (floodlights).
    B,
    /// Polar axis horizontal, along the luminaire (automotive).
    A,
}

/// Which part of the distribution the file tabulates; the rest follows by mirroring.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Symmetry {
    /// Every plane given (type C: C0…C360; type A/B: H −90…90).
    None,
    /// One plane, the same in every C (type C).
    Rotational,
    /// Mirror-symmetric about the C0–C180 plane: C0…C180 given.
    C0C180,
    /// Mirror-symmetric about the C90–C270 plane: C90…C270 given.
    C90C270,
    /// Symmetric about both planes: C0…C90 given.
    Quadrant,
    /// Type A/B: H ≥ 0 given, I(−H, V) = I(H, V).
    Lateral,
}

/// Which file format a [`Photometry`] came from.
#[derive(Clone, Debug, PartialEq)]
pub enum Format {
    /// IES LM-63, with its version string ("LM-63-1986" when the file has none).
    Ies(String),
    Eulumdat,
}

/// The contents of a photometric file, normalised: angles in degrees, candela absolute
/// (every multiplier of the file applied).
#[derive(Clone, Debug, PartialEq)]
pub struct Photometry {
    pub format: Format,
    /// Descriptive header: (keyword, value) pairs in file order (IES keywords without brackets;
    /// EULUMDAT line names).
    pub header: Vec<(String, String)>,
    pub kind: Kind,
    pub symmetry: Symmetry,
    /// Plane angles of the tabulated planes (type C: C; type A/B: horizontal angle H), strictly
    /// increasing.
    pub planes: Vec<f64>,
    /// Angles within each plane (type C: γ; type A/B: vertical angle V), strictly increasing.
    pub angles: Vec<f64>,
    /// `candela[plane][angle]`, cd.
    pub candela: Vec<Vec<f64>>,
    /// Luminous flux the file states for the luminaire, lm, if it states one (IES: lamps ×
    /// lumens per lamp for relative photometry; EULUMDAT: lamp flux × LOR).
    pub stated_lumens: Option<f64>,
    /// Luminaire (or luminous opening) size, m: length (along C0), width, height.
    pub size_m: [f64; 3],
}

/// Largest photometric file read, in bytes. Real IES and EULUMDAT files are kilobytes to a few
/// megabytes; the parsers hold about 24 bytes per number of the file, so this bounds their
/// memory to under a gigabyte.
pub const MAX_FILE_BYTES: u64 = 32 << 20;

/// Read a photometric file; the format is chosen by the extension (`.ldt` → EULUMDAT,
/// anything else → IES). Bytes that are not UTF-8 are read as Latin-1; a UTF-8 byte-order mark
/// is skipped. A file over [`MAX_FILE_BYTES`], a FIFO, a device or a directory is refused
/// before it is read.
pub fn load(path: &Path) -> Result<Photometry, LoadError> {
    let bytes = crate::limits::read_file(path, MAX_FILE_BYTES).map_err(|source| LoadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let text = decode(&bytes);
    let is_ldt = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("ldt"));
    Ok(if is_ldt {
        ldt::parse(&text, path)?
    } else {
        ies::parse(&text, path)?
    })
}

/// UTF-8 if valid, otherwise Latin-1 (each byte one code point); a leading UTF-8 byte-order
/// mark is dropped either way.
pub fn decode(bytes: &[u8]) -> String {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    match std::str::from_utf8(bytes) {
        Ok(s) => s.to_string(),
        Err(_) => bytes.iter().map(|&b| b as char).collect(),
    }
}

const ANGLE_EPS: f64 = 1e-6;

fn wrap360(c: f64) -> f64 {
    let r = c.rem_euclid(360.0);
    if r >= 360.0 - ANGLE_EPS {
        0.0
    } else {
        r
    }
}

impl Photometry {
    /// Fold a plane angle into the range the file tabulates (applies the symmetry).
    pub fn fold_plane(&self, a: f64) -> f64 {
        match self.symmetry {
            Symmetry::None => match self.kind {
                Kind::C => wrap360(a),
                _ => a,
            },
            Symmetry::Rotational => self.planes[0],
            Symmetry::C0C180 => {
                let c = wrap360(a);
                if c > 180.0 {
                    360.0 - c
                } else {
                    c
                }
            }
            Symmetry::C90C270 => {
                let c = wrap360(a);
                if c < 90.0 {
                    180.0 - c
                } else if c > 270.0 {
                    540.0 - c
                } else {
                    c
                }
            }
            Symmetry::Quadrant => {
                let mut c = wrap360(a);
                if c > 180.0 {
                    c = 360.0 - c;
                }
                if c > 90.0 {
                    c = 180.0 - c;
                }
                c
            }
            Symmetry::Lateral => a.abs(),
        }
    }

    /// Images of a tabulated plane angle under the symmetry (type C: in [0, 360)).
    fn plane_images(&self, a: f64) -> Vec<f64> {
        match self.symmetry {
            Symmetry::None => vec![if self.kind == Kind::C { wrap360(a) } else { a }],
            Symmetry::Rotational => vec![0.0],
            Symmetry::C0C180 => vec![wrap360(a), wrap360(360.0 - a)],
            Symmetry::C90C270 => vec![wrap360(a), wrap360(180.0 - a)],
            Symmetry::Quadrant => vec![
                wrap360(a),
                wrap360(180.0 - a),
                wrap360(180.0 + a),
                wrap360(360.0 - a),
            ],
            Symmetry::Lateral => vec![a, -a],
        }
    }

    /// Candela of the tabulated plane whose angle is nearest to `a` (after folding).
    fn plane_index(&self, a: f64) -> usize {
        let f = self.fold_plane(a);
        let mut best = 0;
        for (i, &p) in self.planes.iter().enumerate() {
            if (p - f).abs() < (self.planes[best] - f).abs() {
                best = i;
            }
        }
        best
    }

    /// The full distribution: every plane (type C: 0…360 with 360 ≡ 0), ready to evaluate.
    pub fn distribution(&self) -> Distribution {
        let mut planes: Vec<f64> = self
            .planes
            .iter()
            .flat_map(|&a| self.plane_images(a))
            .collect();
        if self.kind == Kind::C {
            planes.push(0.0);
            planes.push(360.0);
        }
        planes.sort_by(f64::total_cmp);
        planes.dedup_by(|a, b| (*a - *b).abs() < ANGLE_EPS);
        let rows: Vec<&Vec<f64>> = planes
            .iter()
            .map(|&a| &self.candela[self.plane_index(a)])
            .collect();
        let values = rows.iter().flat_map(|r| r.iter().copied()).collect();
        Distribution::new(self.kind, planes, self.angles.clone(), values)
    }

    /// Largest candela value of the table.
    pub fn max_candela(&self) -> f64 {
        self.candela.iter().flatten().copied().fold(0.0, f64::max)
    }
}

/// A full distribution: `values[i * angles.len() + j]` is the candela at plane `planes[i]`,
/// angle `angles[j]`; bilinear between entries; importance-sampling tables.
#[derive(Clone, Debug)]
pub struct Distribution {
    pub kind: Kind,
    pub planes: Vec<f64>,
    pub angles: Vec<f64>,
    pub values: Vec<f64>,
    /// Integral of the interpolated intensity over each cell (plane i…i+1 × angle j…j+1), lm.
    cell_flux: Vec<f64>,
    cell_cdf: Vec<f64>,
    total: f64,
}

/// ∫_a^b w(x) m(x) dx for the two linear hat weights w0 = (b−x)/h, w1 = (x−a)/h and the
/// measure m = 1, sin or cos (angles in radians).
fn hat_integrals(a: f64, b: f64, measure: Measure) -> (f64, f64) {
    let h = b - a;
    if h <= 0.0 {
        return (0.0, 0.0);
    }
    let (total, first_moment) = match measure {
        Measure::One => (h, h * h / 2.0),
        // ∫ sin = cos a − cos b; ∫ (x−a) sin x = −h cos b + sin b − sin a
        Measure::Sin => (a.cos() - b.cos(), -h * b.cos() + b.sin() - a.sin()),
        // ∫ cos = sin b − sin a; ∫ (x−a) cos x = h sin b − (cos a − cos b)
        Measure::Cos => (b.sin() - a.sin(), h * b.sin() - (a.cos() - b.cos())),
    };
    let w1 = first_moment / h;
    (total - w1, w1)
}

#[derive(Clone, Copy)]
enum Measure {
    One,
    Sin,
    Cos,
}

impl Kind {
    /// Solid-angle measure per axis: dω = m_plane(a) m_angle(b) da db.
    fn measures(self) -> (Measure, Measure) {
        match self {
            Kind::C => (Measure::One, Measure::Sin),
            Kind::B => (Measure::Cos, Measure::One),
            Kind::A => (Measure::One, Measure::Cos),
        }
    }
}

/// Bracketing index and weight: `xs[i] ≤ x ≤ xs[i+1]`, t in [0, 1]; None outside.
fn bracket(xs: &[f64], x: f64) -> Option<(usize, f64)> {
    let n = xs.len();
    if n == 0 || !(x >= xs[0] - ANGLE_EPS && x <= xs[n - 1] + ANGLE_EPS) {
        return None;
    }
    if n == 1 {
        return Some((0, 0.0));
    }
    let i = bracket_index(xs, x);
    let h = xs[i + 1] - xs[i];
    let t = if h > 0.0 {
        ((x - xs[i]) / h).clamp(0.0, 1.0)
    } else {
        0.0
    };
    Some((i, t))
}

/// `xs.partition_point(|&v| v <= x).clamp(1, n - 1) - 1` for sorted `xs` of n ≥ 2 values: the
/// last i ≤ n − 2 with xs[i] ≤ x (0 below xs[0]). Tables are mostly evenly spaced, so the
/// index the spacing predicts is tried first and the binary search, whose mispredicted
/// branches cost a goniometric light's every evaluation, only runs where it fails.
#[inline]
fn bracket_index(xs: &[f64], x: f64) -> usize {
    let n = xs.len();
    let span = xs[n - 1] - xs[0];
    if span > 0.0 {
        let g = ((x - xs[0]) / span * (n - 1) as f64) as usize;
        if g < n - 1 && xs[g] <= x && x < xs[g + 1] {
            return g;
        }
    }
    xs.partition_point(|&v| v <= x).clamp(1, n - 1) - 1
}

impl Distribution {
    pub fn new(kind: Kind, planes: Vec<f64>, angles: Vec<f64>, values: Vec<f64>) -> Self {
        let (mp, ma) = kind.measures();
        let (np, na) = (planes.len(), angles.len());
        let pw: Vec<(f64, f64)> = (0..np.saturating_sub(1))
            .map(|i| hat_integrals(planes[i].to_radians(), planes[i + 1].to_radians(), mp))
            .collect();
        let aw: Vec<(f64, f64)> = (0..na.saturating_sub(1))
            .map(|j| hat_integrals(angles[j].to_radians(), angles[j + 1].to_radians(), ma))
            .collect();
        let mut cell_flux = Vec::with_capacity(pw.len() * aw.len());
        for (i, &(p0, p1)) in pw.iter().enumerate() {
            for (j, &(a0, a1)) in aw.iter().enumerate() {
                let v = |ii: usize, jj: usize| values[ii * na + jj];
                let f = p0 * (a0 * v(i, j) + a1 * v(i, j + 1))
                    + p1 * (a0 * v(i + 1, j) + a1 * v(i + 1, j + 1));
                cell_flux.push(f.max(0.0));
            }
        }
        let mut cell_cdf = Vec::with_capacity(cell_flux.len());
        let mut acc = 0.0;
        for &f in &cell_flux {
            acc += f;
            cell_cdf.push(acc);
        }
        Self {
            kind,
            planes,
            angles,
            values,
            cell_flux,
            cell_cdf,
            total: acc,
        }
    }

    /// Total luminous flux of the interpolated distribution, lm (exact for the bilinear
    /// interpolant).
    pub fn lumens(&self) -> f64 {
        self.total
    }

    /// Candela at file angles (plane angle, in-plane angle), degrees; 0 outside the table.
    pub fn eval_angles(&self, plane: f64, angle: f64) -> f64 {
        let plane = if self.kind == Kind::C {
            plane.rem_euclid(360.0)
        } else {
            plane
        };
        self.eval_in_range(plane, angle)
    }

    /// [`Self::eval_angles`] of a Type C plane angle already in [0°, 360°).
    #[inline]
    fn eval_in_range(&self, plane: f64, angle: f64) -> f64 {
        let na = self.angles.len();
        let (Some((i, s)), Some((j, t))) =
            (bracket(&self.planes, plane), bracket(&self.angles, angle))
        else {
            return 0.0;
        };
        let i1 = (i + 1).min(self.planes.len() - 1);
        let j1 = (j + 1).min(na - 1);
        let v = |ii: usize, jj: usize| self.values[ii * na + jj];
        (1.0 - s) * ((1.0 - t) * v(i, j) + t * v(i, j1))
            + s * ((1.0 - t) * v(i1, j) + t * v(i1, j1))
    }

    /// File angles (degrees) of a unit direction in the luminaire frame.
    pub fn angles_of(&self, d: [f64; 3]) -> (f64, f64) {
        let [x, y, z] = d;
        let deg = f64::to_degrees;
        match self.kind {
            Kind::C => {
                let gamma = deg((-y).clamp(-1.0, 1.0).acos());
                let c = deg((-z).atan2(x)).rem_euclid(360.0);
                (c, gamma)
            }
            Kind::B => (deg((-z).clamp(-1.0, 1.0).asin()), deg(x.atan2(-y))),
            Kind::A => (deg((-z).atan2(-y)), deg(x.clamp(-1.0, 1.0).asin())),
        }
    }

    /// Unit direction in the luminaire frame of file angles (degrees).
    pub fn direction(&self, plane: f64, angle: f64) -> [f64; 3] {
        let (a, b) = (plane.to_radians(), angle.to_radians());
        match self.kind {
            Kind::C => [b.sin() * a.cos(), -b.cos(), -b.sin() * a.sin()],
            Kind::B => [a.cos() * b.sin(), -a.cos() * b.cos(), -a.sin()],
            Kind::A => [b.sin(), -b.cos() * a.cos(), -b.cos() * a.sin()],
        }
    }

    /// [`Distribution::eval`] of a single-precision direction, as rendering asks for it: Type C
    /// angles come from the single-precision `acos` and `atan2`, about twice as fast as the
    /// double ones and as accurate as the direction itself (10⁻⁷ rad, 6·10⁻⁶°).
    #[inline]
    pub fn eval_f32(&self, d: [f32; 3]) -> f64 {
        if self.kind != Kind::C {
            return self.eval(d.map(f64::from));
        }
        let [x, y, z] = d;
        let gamma = ((-y).clamp(-1.0, 1.0).acos() as f64).to_degrees();
        // atan2 lies in [−180°, 180°]: one addition instead of a floating-point remainder.
        let c = (((-z).atan2(x)) as f64).to_degrees();
        let c = if c < 0.0 { c + 360.0 } else { c };
        self.eval_in_range(c, gamma)
    }

    /// Candela toward a unit direction of the luminaire frame.
    pub fn eval(&self, d: [f64; 3]) -> f64 {
        let (p, a) = self.angles_of(d);
        self.eval_angles(p, a)
    }

    /// Sample a direction (luminaire frame) with density proportional to the cell-average
    /// intensity: a cell is chosen by its flux, then a direction uniformly in solid angle
    /// inside it. Returns the direction and its density per steradian; None if the
    /// distribution is dark.
    pub fn sample(&self, u0: f64, u1: f64, u2: f64) -> Option<([f64; 3], f64)> {
        if self.total <= 0.0 || !self.total.is_finite() {
            return None;
        }
        let target = u0 * self.total;
        let k = self
            .cell_cdf
            .partition_point(|&c| c <= target)
            .min(self.cell_cdf.len() - 1);
        let na1 = self.angles.len() - 1;
        let (i, j) = (k / na1, k % na1);
        let (p0, p1) = (self.planes[i].to_radians(), self.planes[i + 1].to_radians());
        let (a0, a1) = (self.angles[j].to_radians(), self.angles[j + 1].to_radians());
        let (mp, ma) = self.kind.measures();
        let pick = |lo: f64, hi: f64, m: Measure, u: f64| -> f64 {
            match m {
                Measure::One => lo + u * (hi - lo),
                Measure::Sin => {
                    let c = lo.cos() + u * (hi.cos() - lo.cos());
                    c.clamp(-1.0, 1.0).acos()
                }
                Measure::Cos => {
                    let s = lo.sin() + u * (hi.sin() - lo.sin());
                    s.clamp(-1.0, 1.0).asin()
                }
            }
        };
        let p = pick(p0, p1, mp, u1);
        let a = pick(a0, a1, ma, u2);
        let d = self.direction(p.to_degrees(), a.to_degrees());
        let pdf = self.pdf_cell(i, j);
        (pdf > 0.0).then_some((d, pdf))
    }

    fn cell_solid_angle(&self, i: usize, j: usize) -> f64 {
        let (mp, ma) = self.kind.measures();
        let (pa, pb) = hat_integrals(
            self.planes[i].to_radians(),
            self.planes[i + 1].to_radians(),
            mp,
        );
        let (aa, ab) = hat_integrals(
            self.angles[j].to_radians(),
            self.angles[j + 1].to_radians(),
            ma,
        );
        (pa + pb) * (aa + ab)
    }

    fn pdf_cell(&self, i: usize, j: usize) -> f64 {
        let na1 = self.angles.len() - 1;
        let sa = self.cell_solid_angle(i, j);
        if sa <= 0.0 {
            return 0.0;
        }
        self.cell_flux[i * na1 + j] / self.total / sa
    }

    /// Density (per steradian) with which [`Distribution::sample`] picks direction `d`.
    pub fn pdf(&self, d: [f64; 3]) -> f64 {
        if self.total <= 0.0 || self.planes.len() < 2 || self.angles.len() < 2 {
            return 0.0;
        }
        let (p, a) = self.angles_of(d);
        let p = if self.kind == Kind::C {
            p.rem_euclid(360.0)
        } else {
            p
        };
        let (Some((i, _)), Some((j, _))) = (bracket(&self.planes, p), bracket(&self.angles, a))
        else {
            return 0.0;
        };
        self.pdf_cell(i.min(self.planes.len() - 2), j.min(self.angles.len() - 2))
    }

    /// The maximum candela over a fine scan and its file angles.
    pub fn max_direction(&self) -> (f64, f64, f64) {
        let na = self.angles.len();
        let mut best = (0.0, self.planes[0], self.angles[0]);
        for (i, &p) in self.planes.iter().enumerate() {
            for (j, &a) in self.angles.iter().enumerate() {
                let v = self.values[i * na + j];
                if v > best.0 {
                    best = (v, p, a);
                }
            }
        }
        best
    }
}

/// Total lumens by brute-force midpoint quadrature of any intensity function over the sphere
/// (C, γ), for tests and cross-checks. `n` steps in γ, 2n in C.
pub fn integrate_sphere(n: usize, f: impl Fn(f64, f64) -> f64) -> f64 {
    let (dg, dc) = (PI / n as f64, 2.0 * PI / (2 * n) as f64);
    let mut sum = 0.0;
    for j in 0..n {
        let g = (j as f64 + 0.5) * dg;
        let w = (g - dg / 2.0).cos() - (g + dg / 2.0).cos();
        for i in 0..2 * n {
            let c = (i as f64 + 0.5) * dc;
            sum += f(c.to_degrees(), g.to_degrees()) * w * dc;
        }
    }
    sum
}

/// Beam (50 %) and field (10 %) angles in one vertical plane through the luminaire: the plane
/// of C angle `c` and `c + 180` (type C; for type A/B the plane H = 0 … through V), degrees.
/// The curve is scanned at 0.1°; the angle is the full width around the plane's maximum
/// where the intensity stays above the fraction of that maximum.
pub fn spread_angle(dist: &Distribution, c: f64, fraction: f64) -> f64 {
    let steps = 3600;
    let curve: Vec<f64> = (0..steps)
        .map(|k| {
            let t = -180.0 + 360.0 * k as f64 / steps as f64;
            polar_value(dist, c, t)
        })
        .collect();
    let (imax, &vmax) = curve
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .unwrap_or((0, &0.0));
    if vmax <= 0.0 {
        return 0.0;
    }
    let thr = fraction * vmax;
    let mut width = 0;
    // Walk both ways from the maximum (the curve is periodic).
    for dir in [1isize, -1] {
        let mut k = 0isize;
        while k < steps as isize {
            let idx = (imax as isize + dir * (k + 1)).rem_euclid(steps as isize) as usize;
            if curve[idx] < thr {
                break;
            }
            k += 1;
        }
        width += k;
    }
    (width as f64 * 360.0 / steps as f64).min(360.0)
}

/// Intensity on the polar curve of the vertical plane C = `c` / `c + 180`: `t` in (−180, 180],
/// t ≥ 0 on the C = c side at γ = t, t < 0 on the c + 180 side at γ = −t. For type A/B the
/// plane is the one through the main axis containing the luminaire's C direction.
pub fn polar_value(dist: &Distribution, c: f64, t: f64) -> f64 {
    match dist.kind {
        Kind::C => {
            if t >= 0.0 {
                dist.eval_angles(c, t)
            } else {
                dist.eval_angles(c + 180.0, -t)
            }
        }
        _ => {
            // Direction in the type C sense, then evaluated through the file's system.
            let (cc, g) = if t >= 0.0 { (c, t) } else { (c + 180.0, -t) };
            let (a, b) = (cc.to_radians(), g.to_radians());
            dist.eval([b.sin() * a.cos(), -b.cos(), -b.sin() * a.sin()])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn single_precision_directions_give_the_double_precision_candela() {
        // A batwing-like Type C table, full circle of planes, evaluated from f32 directions
        // all round the sphere: within the angles' f32 rounding of the f64 evaluation.
        let planes: Vec<f64> = (0..=24).map(|i| i as f64 * 15.0).collect();
        let angles: Vec<f64> = (0..=36).map(|j| j as f64 * 2.5).collect();
        let values: Vec<f64> = planes
            .iter()
            .flat_map(|&c| {
                angles.iter().map(move |&g| {
                    400.0 + 900.0 * (g.to_radians()).sin() * (1.0 + 0.2 * c.to_radians().cos())
                })
            })
            .collect();
        let d = Distribution::new(Kind::C, planes, angles, values);
        let mut worst = 0.0f64;
        for k in 0..20_000 {
            let (u, v) = (
                (k as f64 + 0.5) / 20_000.0,
                (k as f64 * 0.618_033_988_75).fract(),
            );
            let z = 1.0 - 2.0 * u;
            let r = (1.0 - z * z).sqrt();
            let phi = std::f64::consts::TAU * v;
            let w = [r * phi.cos(), z, r * phi.sin()].map(|c| c as f32);
            let exact = d.eval(w.map(f64::from));
            let fast = d.eval_f32(w);
            worst = worst.max((fast - exact).abs() / 1300.0);
        }
        assert!(worst < 1e-5, "{worst}");
    }

    #[test]
    fn bracket_index_agrees_with_the_binary_search() {
        let tables: [&[f64]; 5] = [
            &[0.0, 2.5, 5.0, 7.5, 10.0, 90.0],
            &[0.0, 5.0, 5.0, 10.0, 15.0],
            &[0.0, 1.0, 10.0, 11.0, 12.0, 80.0, 90.0],
            &[0.0, 22.5, 45.0, 67.5, 90.0],
            &[3.0, 3.0],
        ];
        for xs in tables {
            let (a, b) = (xs[0] - 1.0, xs[xs.len() - 1] + 1.0);
            for k in 0..=4000 {
                let x = a + (b - a) * k as f64 / 4000.0;
                for x in [x, xs[k % xs.len()]] {
                    let want = xs.partition_point(|&v| v <= x).clamp(1, xs.len() - 1) - 1;
                    assert_eq!(bracket_index(xs, x), want, "{xs:?} at {x}");
                }
            }
        }
    }

    fn rot(values: impl Fn(f64) -> f64, angles: &[f64]) -> Photometry {
        Photometry {
            format: Format::Ies("test".into()),
            header: vec![],
            kind: Kind::C,
            symmetry: Symmetry::Rotational,
            planes: vec![0.0],
            angles: angles.to_vec(),
            candela: vec![angles.iter().map(|&g| values(g)).collect()],
            stated_lumens: None,
            size_m: [0.0; 3],
        }
    }

    #[test]
    fn isotropic_gives_four_pi() {
        let p = rot(|_| 100.0, &[0.0, 45.0, 90.0, 180.0]);
        let d = p.distribution();
        assert!((d.lumens() - 400.0 * PI).abs() < 1e-9 * d.lumens());
        let n = (0.3f64 * 0.3 + 0.5 * 0.5 + 0.2 * 0.2).sqrt();
        assert!((d.eval([0.3 / n, -0.5 / n, 0.2 / n]) - 100.0).abs() < 1e-9);
    }

    #[test]
    fn sampling_estimates_flux_without_bias() {
        let angles: Vec<f64> = (0..=18).map(|k| k as f64 * 10.0).collect();
        let p = rot(|g| (g.to_radians().cos()).max(0.0) * 50.0 + 1.0, &angles);
        let d = p.distribution();
        let n = 20000;
        let (mut sum, mut sum2) = (0.0, 0.0);
        let mut rng = 12345u64;
        let mut u = || {
            rng = rng
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (rng >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..n {
            let (dir, pdf) = d.sample(u(), u(), u()).unwrap();
            assert!((d.pdf(dir) - pdf).abs() < 1e-6 * pdf);
            let x = d.eval(dir) / pdf;
            sum += x;
            sum2 += x * x;
        }
        // Mean of eval/pdf and its standard error from the sample variance.
        let est = sum / n as f64;
        let var = (sum2 / n as f64 - est * est).max(0.0) * n as f64 / (n - 1) as f64;
        let se = (var / n as f64).sqrt();
        println!("flux {est} ± {se} lm, expected {}", d.lumens());
        assert!(
            (est - d.lumens()).abs() <= 5.0 * se && se < 0.005 * d.lumens(),
            "{est} ± {se} vs {}",
            d.lumens()
        );
    }
}
