//! sRGB → smooth reflectance spectrum ("spectral upsampling") after Jakob & Hanika 2019:
//! R(λ) = S(c0·λ² + c1·λ + c2) with a sigmoid S, its coefficients fitted per colour by
//! Levenberg–Marquardt in CIELAB when a scene is loaded. Greys are exactly flat, black exactly
//! 0, white exactly 1; the method, its colour definition and its edges are in docs/methods.md.

use std::sync::OnceLock;

use crate::colour::rgb::xyz_to_linear_srgb;
use crate::colour::tables::{cmfs, named_spectrum, Observer};

const LAMBDA_MIN: f64 = 360.0;
const LAMBDA_MAX: f64 = 830.0;
const N: usize = 471;
const SPAN: f64 = LAMBDA_MAX - LAMBDA_MIN;

/// The residual ΔE\*ab below which a fit counts as converged.
const CONVERGED_DELTA_E: f64 = 1e-9;
/// Bound on |coefficient| in normalised wavelength units, keeping evaluation well conditioned.
const MAX_COEFFICIENT: f64 = 1e4;

/// A smooth reflectance spectrum `R(λ) = S(c0·λ² + c1·λ + c2)` (λ in nm), or a constant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SigmoidSpectrum {
    /// Polynomial coefficients `[c0, c1, c2]` for λ in **nanometres** (as in the paper and
    /// PBRT-v4). Zero when `constant` is set.
    pub c: [f64; 3],
    /// `Some(v)`: the spectrum is exactly `v` everywhere (used for black, 0, and white, 1,
    /// which the sigmoid only reaches in the limit); `c` is then ignored.
    pub constant: Option<f64>,
}

/// Why a colour cannot be upsampled.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum UpsampleError {
    /// A component is outside [0, 1] (or not finite): not a reflectance colour.
    #[error(
        "linear sRGB reflectance colour {rgb:?} is out of range: each component must be in [0, 1]"
    )]
    OutOfRange {
        /// The colour given.
        rgb: [f64; 3],
    },
}

/// The sigmoid `S(x) = ½ + x / (2√(1+x²))`, robust for huge |x|.
fn sigmoid(x: f64) -> f64 {
    if x.is_nan() {
        return 0.5;
    }
    if x.abs() > 1e10 {
        // 1 − S(x) ≈ 1/(4x²) < 1e-20: indistinguishable from the limit in f64.
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    (0.5 + x / (2.0 * (1.0 + x * x).sqrt())).clamp(0.0, 1.0)
}

/// dS/dx = ½ (1 + x²)^(−3/2).
fn sigmoid_derivative(x: f64) -> f64 {
    let q = 1.0 + x * x;
    0.5 / (q * q.sqrt())
}

/// The inverse of `S` on (0, 1).
fn sigmoid_inverse(y: f64) -> f64 {
    let u = 2.0 * y - 1.0;
    u / (1.0 - u * u).sqrt()
}

impl SigmoidSpectrum {
    /// Reflectance at wavelength `nm` (any wavelength; always in [0, 1]).
    pub fn value(&self, nm: f64) -> f64 {
        match self.constant {
            Some(v) => v,
            None => {
                let [c0, c1, c2] = self.c;
                sigmoid((c0 * nm + c1) * nm + c2)
            }
        }
    }

    /// The flat spectrum of value `v` (clamped to [0, 1]): exact constants at 0 and 1,
    /// `c = (0, 0, S⁻¹(v))` otherwise.
    pub fn flat(v: f64) -> Self {
        let v = v.clamp(0.0, 1.0);
        if v == 0.0 || v == 1.0 {
            SigmoidSpectrum {
                c: [0.0; 3],
                constant: Some(v),
            }
        } else {
            SigmoidSpectrum {
                c: [0.0, 0.0, sigmoid_inverse(v)],
                constant: None,
            }
        }
    }

    /// CIE 1931 XYZ of this reflectance under D65, white (R ≡ 1) at Y = 1 (see module docs).
    pub fn xyz(&self) -> [f64; 3] {
        let t = tables();
        let mut xyz = [0.0; 3];
        for i in 0..N {
            let r = self.value(LAMBDA_MIN + i as f64);
            for (k, v) in xyz.iter_mut().enumerate() {
                *v += r * t.w[k][i];
            }
        }
        xyz
    }

    /// The (white-balanced) linear sRGB colour of this reflectance, the quantity
    /// [`fit_linear_srgb`] matches (see module docs).
    pub fn linear_srgb(&self) -> [f64; 3] {
        let t = tables();
        let rgb = xyz_to_linear_srgb(self.xyz());
        [
            rgb[0] / t.white_rgb[0],
            rgb[1] / t.white_rgb[1],
            rgb[2] / t.white_rgb[2],
        ]
    }
}

/// CIELAB ΔE\*ab (CIE 1976) between two linear sRGB reflectance colours, with the white
/// balance and white point of the module docs (so it measures the fit's residual).
pub fn delta_e_linear_srgb(a: [f64; 3], b: [f64; 3]) -> f64 {
    let t = tables();
    dist(lab(t.rgb_to_xyz(a), t), lab(t.rgb_to_xyz(b), t))
}

struct Tables {
    /// Per wavelength (1 nm, 360..=830): D65·x̄, D65·ȳ, D65·z̄ normalised by Σ D65·ȳ.
    w: [[f64; N]; 3],
    /// Normalised wavelength t ∈ [0, 1] per sample.
    t: [f64; N],
    /// XYZ of the perfect reflector (Y = 1).
    white_xyz: [f64; 3],
    /// Linear sRGB of the perfect reflector.
    white_rgb: [f64; 3],
    /// Exact inverse of the XYZ → linear sRGB matrix.
    rgb_to_xyz_matrix: [[f64; 3]; 3],
}

impl Tables {
    fn rgb_to_xyz(&self, rgb: [f64; 3]) -> [f64; 3] {
        let v = [
            rgb[0] * self.white_rgb[0],
            rgb[1] * self.white_rgb[1],
            rgb[2] * self.white_rgb[2],
        ];
        let m = &self.rgb_to_xyz_matrix;
        [
            m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
            m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
            m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
        ]
    }
}

fn invert3(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    let mut inv = [[0.0; 3]; 3];
    for (i, row) in inv.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            // Cofactor C[j][i] / det (adjugate = transposed cofactors).
            let (r0, r1) = ((j + 1) % 3, (j + 2) % 3);
            let (c0, c1) = ((i + 1) % 3, (i + 2) % 3);
            *v = (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / det;
        }
    }
    inv
}

fn tables() -> &'static Tables {
    static TABLES: OnceLock<Tables> = OnceLock::new();
    TABLES.get_or_init(|| {
        let cmf = cmfs(Observer::Cie1931_2);
        let d65 = named_spectrum("D65").expect("the colour module provides CIE D65");
        let mut w = [[0.0; N]; 3];
        let mut t = [0.0; N];
        let mut norm = 0.0;
        for i in 0..N {
            let nm = LAMBDA_MIN + i as f64;
            let e = d65.value(nm);
            w[0][i] = e * cmf.x[i];
            w[1][i] = e * cmf.y[i];
            w[2][i] = e * cmf.z[i];
            norm += w[1][i];
            t[i] = (nm - LAMBDA_MIN) / SPAN;
        }
        let mut white_xyz = [0.0; 3];
        for (wk, white) in w.iter_mut().zip(white_xyz.iter_mut()) {
            for v in wk.iter_mut() {
                *v /= norm;
                *white += *v;
            }
        }
        let mut m = [[0.0; 3]; 3];
        for j in 0..3 {
            let mut e = [0.0; 3];
            e[j] = 1.0;
            let col = xyz_to_linear_srgb(e);
            for i in 0..3 {
                m[i][j] = col[i];
            }
        }
        Tables {
            w,
            t,
            white_xyz,
            white_rgb: xyz_to_linear_srgb(white_xyz),
            rgb_to_xyz_matrix: invert3(m),
        }
    })
}

const LAB_EPS: f64 = 216.0 / 24389.0; // (6/29)³
const LAB_KAPPA: f64 = 24389.0 / 27.0; // (29/3)³

fn lab_f(t: f64) -> f64 {
    if t > LAB_EPS {
        t.cbrt()
    } else {
        (LAB_KAPPA * t + 16.0) / 116.0
    }
}

fn lab_f_derivative(t: f64) -> f64 {
    if t > LAB_EPS {
        let c = t.cbrt();
        1.0 / (3.0 * c * c)
    } else {
        LAB_KAPPA / 116.0
    }
}

fn lab(xyz: [f64; 3], t: &Tables) -> [f64; 3] {
    let f = [
        lab_f(xyz[0] / t.white_xyz[0]),
        lab_f(xyz[1] / t.white_xyz[1]),
        lab_f(xyz[2] / t.white_xyz[2]),
    ];
    [
        116.0 * f[1] - 16.0,
        500.0 * (f[0] - f[1]),
        200.0 * (f[1] - f[2]),
    ]
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Residual `Lab(a) − target` and its Jacobian w.r.t. the normalised coefficients
/// `a = [a0, a1, a2]` of `S(a0 t² + a1 t + a2)`.
fn residual(a: [f64; 3], target: [f64; 3], t: &Tables) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut xyz = [0.0; 3];
    let mut dxyz = [[0.0; 3]; 3]; // dxyz[k][j] = dXYZ_k / da_j
    for i in 0..N {
        let ti = t.t[i];
        let x = (a[0] * ti + a[1]) * ti + a[2];
        let s = sigmoid(x);
        let ds = sigmoid_derivative(x);
        let basis = [ti * ti, ti, 1.0];
        for k in 0..3 {
            let wk = t.w[k][i];
            xyz[k] += s * wk;
            for j in 0..3 {
                dxyz[k][j] += ds * basis[j] * wk;
            }
        }
    }
    let l = lab(xyz, t);
    let df = [
        lab_f_derivative(xyz[0] / t.white_xyz[0]) / t.white_xyz[0],
        lab_f_derivative(xyz[1] / t.white_xyz[1]) / t.white_xyz[1],
        lab_f_derivative(xyz[2] / t.white_xyz[2]) / t.white_xyz[2],
    ];
    let mut jac = [[0.0; 3]; 3];
    for j in 0..3 {
        let fx = df[0] * dxyz[0][j];
        let fy = df[1] * dxyz[1][j];
        let fz = df[2] * dxyz[2][j];
        jac[0][j] = 116.0 * fy;
        jac[1][j] = 500.0 * (fx - fy);
        jac[2][j] = 200.0 * (fy - fz);
    }
    let r = [l[0] - target[0], l[1] - target[1], l[2] - target[2]];
    (r, jac)
}

fn norm(r: [f64; 3]) -> f64 {
    (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt()
}

/// Solves the 3×3 system `m x = b` by Gaussian elimination with partial pivoting.
fn solve3(mut m: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let pivot = (col..3).max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs()))?;
        if m[pivot][col].abs() < 1e-300 {
            return None;
        }
        m.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..3 {
            let f = m[row][col] / m[col][col];
            let pivot_row = m[col];
            for (k, v) in m[row].iter_mut().enumerate().skip(col) {
                *v -= f * pivot_row[k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let mut s = b[row];
        for k in row + 1..3 {
            s -= m[row][k] * x[k];
        }
        x[row] = s / m[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Levenberg–Marquardt from `start`; returns the best coefficients and their ΔE.
fn levenberg_marquardt(
    start: [f64; 3],
    target: [f64; 3],
    iterations: usize,
    t: &Tables,
) -> ([f64; 3], f64) {
    let mut a = start;
    let (mut r, mut jac) = residual(a, target, t);
    let mut err = norm(r);
    let mut mu = 1e-3;
    for _ in 0..iterations {
        if err < CONVERGED_DELTA_E {
            break;
        }
        // Normal equations (JᵀJ + μ·diag(JᵀJ)) δ = −Jᵀr.
        let mut jtj = [[0.0; 3]; 3];
        let mut jtr = [0.0; 3];
        for i in 0..3 {
            for j in 0..3 {
                jtj[i][j] = (0..3).map(|k| jac[k][i] * jac[k][j]).sum();
            }
            jtr[i] = -(0..3).map(|k| jac[k][i] * r[k]).sum::<f64>();
        }
        let mut improved = false;
        for _ in 0..30 {
            let mut m = jtj;
            for (i, row) in m.iter_mut().enumerate() {
                row[i] += mu * jtj[i][i].max(1e-12);
            }
            let Some(delta) = solve3(m, jtr) else {
                mu *= 10.0;
                continue;
            };
            let candidate = [
                (a[0] + delta[0]).clamp(-MAX_COEFFICIENT, MAX_COEFFICIENT),
                (a[1] + delta[1]).clamp(-MAX_COEFFICIENT, MAX_COEFFICIENT),
                (a[2] + delta[2]).clamp(-MAX_COEFFICIENT, MAX_COEFFICIENT),
            ];
            let (r2, jac2) = residual(candidate, target, t);
            let err2 = norm(r2);
            if err2 < err {
                a = candidate;
                r = r2;
                jac = jac2;
                improved = err2 < err * (1.0 - 1e-12) || err2 < CONVERGED_DELTA_E;
                err = err2;
                mu = (mu * 0.3).max(1e-12);
                break;
            }
            mu *= 10.0;
        }
        if !improved {
            break;
        }
    }
    (a, err)
}

/// Normalised-wavelength coefficients → coefficients for λ in nm.
fn to_nm(a: [f64; 3]) -> [f64; 3] {
    // a0 t² + a1 t + a2 with t = (λ − L)/S.
    let (l, s) = (LAMBDA_MIN, SPAN);
    let c0 = a[0] / (s * s);
    let c1 = a[1] / s - 2.0 * a[0] * l / (s * s);
    let c2 = a[0] * l * l / (s * s) - a[1] * l / s + a[2];
    [c0, c1, c2]
}

/// Fit to a linear-sRGB reflectance colour (each component in [0,1]; Err otherwise).
/// Returns the spectrum and the residual ΔE\*ab of the fit (see the module docs for the
/// method, the colour definition and the edge cases).
pub fn fit_linear_srgb(rgb: [f64; 3]) -> Result<(SigmoidSpectrum, f64), UpsampleError> {
    if rgb.iter().any(|v| !(0.0..=1.0).contains(v)) {
        return Err(UpsampleError::OutOfRange { rgb });
    }
    if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
        let s = SigmoidSpectrum::flat(rgb[0]);
        let residual = delta_e_linear_srgb(s.linear_srgb(), rgb);
        return Ok((s, residual));
    }
    let t = tables();
    let target_xyz = t.rgb_to_xyz(rgb);
    let target = lab(target_xyz, t);
    // Start from the flat spectrum of the target's luminance.
    let y = (target_xyz[1] / t.white_xyz[1]).clamp(1e-4, 1.0 - 1e-4);
    let grey = [0.0, 0.0, sigmoid_inverse(y)];

    let (mut best, best_err) = levenberg_marquardt(grey, target, 100, t);
    if best_err > CONVERGED_DELTA_E {
        // Continuation: move the target from the grey of equal luminance to the real one,
        // warm-starting each step from the previous solution.
        const STEPS: usize = 16;
        let grey_rgb = [y, y, y];
        let mut a = grey;
        for step in 1..=STEPS {
            let f = step as f64 / STEPS as f64;
            let rgb_step = [
                grey_rgb[0] + f * (rgb[0] - grey_rgb[0]),
                grey_rgb[1] + f * (rgb[1] - grey_rgb[1]),
                grey_rgb[2] + f * (rgb[2] - grey_rgb[2]),
            ];
            let target_step = lab(t.rgb_to_xyz(rgb_step), t);
            let iterations = if step == STEPS { 200 } else { 50 };
            a = levenberg_marquardt(a, target_step, iterations, t).0;
        }
        let (a, err) = levenberg_marquardt(a, target, 200, t);
        if err < best_err {
            best = a;
        }
    }
    let spectrum = SigmoidSpectrum {
        c: to_nm(best),
        constant: None,
    };
    // Report the residual of the spectrum as returned (coefficients in nm).
    let residual = delta_e_linear_srgb(spectrum.linear_srgb(), rgb);
    Ok((spectrum, residual))
}
