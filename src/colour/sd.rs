//! Spectral distributions: tabulated (wavelength, value) pairs, read from CSV and resampled to
//! the 1 nm grid, linearly or as CIE 167:2005 recommends (Sprague 1880 for uniformly spaced
//! data, a not-a-knot cubic spline otherwise, both exactly as colour-science 0.4.7).

use std::path::Path;

use crate::colour::grid::{LEN, START_NM};

/// A tabulated spectral distribution: `values[i]` at `wavelengths_nm[i]`.
///
/// Invariants (checked by [`SpectralDistribution::new`]): at least two samples, wavelengths
/// strictly increasing, every number finite.  Between samples the distribution is linearly
/// interpolated; outside the tabulated range it is zero.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectralDistribution {
    pub wavelengths_nm: Vec<f64>,
    pub values: Vec<f64>,
}

/// Why a spectral distribution could not be built or read.
///
/// The message is one paragraph naming the origin (file path or a description), the line
/// (1-based) and the field when known, and what is wrong.
#[derive(Debug, thiserror::Error)]
pub enum SpectrumError {
    /// The file could not be read.
    #[error("cannot read spectrum file '{path}': {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    /// The content is malformed or violates an invariant.
    #[error("{}", format_invalid(origin, *line, field.as_deref(), message))]
    Invalid {
        /// File path or description of where the data came from.
        origin: String,
        /// 1-based line number, if the data came from text.
        line: Option<usize>,
        /// Field (column) concerned, if any.
        field: Option<String>,
        /// What is wrong.
        message: String,
    },
}

fn format_invalid(origin: &str, line: Option<usize>, field: Option<&str>, message: &str) -> String {
    let mut s = format!("invalid spectrum in {origin}");
    if let Some(l) = line {
        s.push_str(&format!(", line {l}"));
    }
    if let Some(f) = field {
        s.push_str(&format!(", field {f}"));
    }
    s.push_str(": ");
    s.push_str(message);
    s
}

impl SpectrumError {
    fn invalid(origin: &str, line: Option<usize>, field: Option<&str>, message: String) -> Self {
        SpectrumError::Invalid {
            origin: origin.to_string(),
            line,
            field: field.map(str::to_string),
            message,
        }
    }
}

impl SpectralDistribution {
    /// Builds a distribution, checking: equal lengths, at least two samples, strictly
    /// increasing wavelengths and finite numbers.
    pub fn new(wavelengths_nm: Vec<f64>, values: Vec<f64>) -> Result<Self, SpectrumError> {
        Self::checked(wavelengths_nm, values, "spectral distribution", None)
    }

    fn checked(
        wavelengths_nm: Vec<f64>,
        values: Vec<f64>,
        origin: &str,
        lines: Option<&[usize]>,
    ) -> Result<Self, SpectrumError> {
        let line = |i: usize| lines.map(|l| l[i]);
        if wavelengths_nm.len() != values.len() {
            return Err(SpectrumError::invalid(
                origin,
                None,
                None,
                format!(
                    "{} wavelengths but {} values; they must have the same length",
                    wavelengths_nm.len(),
                    values.len()
                ),
            ));
        }
        if wavelengths_nm.len() < 2 {
            return Err(SpectrumError::invalid(
                origin,
                None,
                None,
                format!(
                    "{} sample(s); a spectrum needs at least 2 (wavelength, value) samples",
                    wavelengths_nm.len()
                ),
            ));
        }
        for (i, (&w, &v)) in wavelengths_nm.iter().zip(&values).enumerate() {
            if !w.is_finite() {
                return Err(SpectrumError::invalid(
                    origin,
                    line(i),
                    Some("1 (wavelength)"),
                    format!("sample {} has non-finite wavelength {w}", i + 1),
                ));
            }
            if !v.is_finite() {
                return Err(SpectrumError::invalid(
                    origin,
                    line(i),
                    Some("2 (value)"),
                    format!("sample {} has non-finite value {v}", i + 1),
                ));
            }
            if i > 0 && w <= wavelengths_nm[i - 1] {
                return Err(SpectrumError::invalid(
                    origin,
                    line(i),
                    Some("1 (wavelength)"),
                    format!(
                        "wavelength {w} nm does not increase (previous sample is {} nm); \
                         wavelengths must be strictly increasing",
                        wavelengths_nm[i - 1]
                    ),
                ));
            }
        }
        Ok(Self {
            wavelengths_nm,
            values,
        })
    }

    /// Value at `nm`: linear interpolation between the bracketing samples, exactly the
    /// sample value at a tabulated wavelength, 0 outside `[first, last]`.
    pub fn value(&self, nm: f64) -> f64 {
        let w = &self.wavelengths_nm;
        let n = w.len();
        if !(nm >= w[0] && nm <= w[n - 1]) {
            return 0.0;
        }
        // First index with w[i] > nm, in 1..=n.
        let hi = w.partition_point(|&x| x <= nm);
        if hi == n {
            return self.values[n - 1];
        }
        let lo = hi - 1;
        if w[lo] == nm {
            return self.values[lo];
        }
        let t = (nm - w[lo]) / (w[hi] - w[lo]);
        self.values[lo] + t * (self.values[hi] - self.values[lo])
    }

    /// Samples the distribution at 360..=830 nm every 1 nm with [`Self::value`] (linear).
    pub fn to_table(&self) -> [f64; LEN] {
        let mut out = [0.0; LEN];
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.value(START_NM as f64 + i as f64);
        }
        out
    }

    /// Builds a distribution from a 1 nm table over 360..=830 nm.
    pub fn from_table(values: &[f64; LEN]) -> Self {
        Self {
            wavelengths_nm: (0..LEN).map(|i| START_NM as f64 + i as f64).collect(),
            values: values.to_vec(),
        }
    }

    /// Smallest tabulated value.
    pub fn min_value(&self) -> f64 {
        self.values.iter().copied().fold(f64::INFINITY, f64::min)
    }

    /// Returns an error naming `origin` if any value is negative (for spectra where a
    /// negative value makes no sense: emission, reflectance).
    pub fn check_non_negative(&self, origin: &str) -> Result<(), SpectrumError> {
        for (w, v) in self.wavelengths_nm.iter().zip(&self.values) {
            if *v < 0.0 {
                return Err(SpectrumError::invalid(
                    origin,
                    None,
                    None,
                    format!(
                        "value {v} at {w} nm is negative; spectral power and reflectance \
                         must be >= 0"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Reads a two-column CSV file (`nm,value`) of at most [`crate::limits::MAX_TEXT_BYTES`]
    /// (a FIFO, device or directory is refused unread), see [`Self::from_csv_str`].
    pub fn from_csv_path(path: &Path) -> Result<Self, SpectrumError> {
        let text =
            crate::limits::read_text(path, crate::limits::MAX_TEXT_BYTES).map_err(|source| {
                SpectrumError::Io {
                    path: path.display().to_string(),
                    source,
                }
            })?;
        Self::from_csv_str(&text, &path.display().to_string())
    }

    /// Parses two-column CSV text: wavelength in nm, value.
    ///
    /// Lines starting with `#` (after optional whitespace) and blank lines are ignored; a
    /// trailing `# comment` after the data is allowed too.  The first data line may be a
    /// header (it is skipped if its first field is not a number).  Fields are separated by
    /// commas (a tab or semicolon is accepted as well); whitespace around fields is ignored.
    /// `origin` names the source in error messages.
    pub fn from_csv_str(text: &str, origin: &str) -> Result<Self, SpectrumError> {
        let mut wl = Vec::new();
        let mut vals = Vec::new();
        let mut lines = Vec::new();
        let mut seen_data_or_header = false;
        for (idx, raw) in text.lines().enumerate() {
            let lineno = idx + 1;
            let content = match raw.find('#') {
                Some(p) => &raw[..p],
                None => raw,
            };
            let content = content.trim().trim_start_matches('\u{feff}');
            if content.is_empty() {
                continue;
            }
            let fields: Vec<&str> = content.split([',', ';', '\t']).map(str::trim).collect();
            let first_is_number = fields[0].parse::<f64>().is_ok();
            if !seen_data_or_header && !first_is_number {
                // Header line.
                seen_data_or_header = true;
                if fields.len() != 2 {
                    return Err(SpectrumError::invalid(
                        origin,
                        Some(lineno),
                        None,
                        format!(
                            "header '{content}' has {} fields; expected 2 columns \
                             (wavelength in nm, value)",
                            fields.len()
                        ),
                    ));
                }
                continue;
            }
            seen_data_or_header = true;
            if fields.len() != 2 {
                return Err(SpectrumError::invalid(
                    origin,
                    Some(lineno),
                    None,
                    format!(
                        "'{content}' has {} fields; expected 2 columns (wavelength in nm, value)",
                        fields.len()
                    ),
                ));
            }
            let parse = |s: &str, field: &str| -> Result<f64, SpectrumError> {
                s.parse::<f64>().map_err(|_| {
                    SpectrumError::invalid(
                        origin,
                        Some(lineno),
                        Some(field),
                        format!("'{s}' is not a number"),
                    )
                })
            };
            wl.push(parse(fields[0], "1 (wavelength)")?);
            vals.push(parse(fields[1], "2 (value)")?);
            lines.push(lineno);
        }
        Self::checked(wl, vals, origin, Some(&lines))
    }
}

/// How a tabulated spectrum is resampled onto the 1 nm grid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Interpolation {
    /// Straight lines between the samples.
    Linear,
    /// CIE 167:2005's recommendation, colour-science's default: Sprague (1880) for uniformly
    /// spaced samples (at least 6), a not-a-knot cubic spline otherwise (at least 4); fewer
    /// samples fall back to straight lines.
    #[default]
    Cie167,
}

impl Interpolation {
    /// Parses `linear` or `cie167` (also `sprague`), case-insensitive.
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "linear" => Some(Self::Linear),
            "cie167" | "cie-167" | "sprague" => Some(Self::Cie167),
            _ => None,
        }
    }

    /// The name [`Self::parse`] accepts.
    pub fn name(self) -> &'static str {
        match self {
            Self::Linear => "linear",
            Self::Cie167 => "cie167",
        }
    }
}

/// The interpolant a distribution is resampled with (see [`SpectralDistribution::method`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    Linear,
    Sprague,
    CubicSpline,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Linear => "linear interpolation",
            Method::Sprague => "Sprague (1880) interpolation (CIE 167)",
            Method::CubicSpline => "not-a-knot cubic spline (CIE 167)",
        }
    }
}

/// Sampling interval above which linear resampling visibly changes integrals (the s-cone
/// irradiance of a smooth 5 nm spectrum is already 0.2 % off) and CIE 224 / TM-30 refuse data.
pub const COARSE_INTERVAL_NM: f64 = 5.0;

/// Sprague's boundary coefficients (CIE 167:2005 table 1, divided by 209): two extra samples
/// below the first from the first six, two above the last from the last six.
const SPRAGUE_BOUNDARY: [[f64; 6]; 4] = [
    [884.0, -1960.0, 3033.0, -2648.0, 1080.0, -180.0],
    [508.0, -540.0, 488.0, -367.0, 144.0, -24.0],
    [-24.0, 144.0, -367.0, 488.0, -540.0, 508.0],
    [-180.0, 1080.0, -2648.0, 3033.0, -1960.0, 884.0],
];

/// Sprague's polynomial coefficients a₁…a₅ (×24) from the six samples around an interval.
const SPRAGUE_W: [[f64; 6]; 5] = [
    [2.0, -16.0, 0.0, 16.0, -2.0, 0.0],
    [-1.0, 16.0, -30.0, 16.0, -1.0, 0.0],
    [-9.0, 39.0, -70.0, 66.0, -33.0, 7.0],
    [13.0, -64.0, 126.0, -124.0, 61.0, -12.0],
    [-5.0, 25.0, -50.0, 50.0, -25.0, 5.0],
];

impl SpectralDistribution {
    /// The common spacing if the wavelengths are uniformly spaced — every difference exactly
    /// equal, colour-science's `is_uniform` — else `None`.
    pub fn uniform_interval_nm(&self) -> Option<f64> {
        let w = &self.wavelengths_nm;
        let d0 = w[1] - w[0];
        w.windows(2).all(|p| p[1] - p[0] == d0).then_some(d0)
    }

    /// The largest spacing between neighbouring samples, nm.
    pub fn max_interval_nm(&self) -> f64 {
        self.wavelengths_nm
            .windows(2)
            .map(|p| p[1] - p[0])
            .fold(0.0, f64::max)
    }

    /// The interpolant `interpolation` gives this distribution.
    pub fn method(&self, interpolation: Interpolation) -> Method {
        let n = self.values.len();
        match interpolation {
            Interpolation::Linear => Method::Linear,
            Interpolation::Cie167 => match self.uniform_interval_nm() {
                Some(_) if n >= 6 => Method::Sprague,
                None if n >= 4 => Method::CubicSpline,
                _ => Method::Linear,
            },
        }
    }

    /// Samples the distribution at 360..=830 nm every 1 nm with `interpolation`; 0 outside the
    /// tabulated range, exactly the sample at a tabulated wavelength.
    pub fn to_table_with(&self, interpolation: Interpolation) -> [f64; LEN] {
        let nm: [f64; LEN] = std::array::from_fn(|i| START_NM as f64 + i as f64);
        let v = self.values_with(interpolation, &nm);
        std::array::from_fn(|i| v[i])
    }

    /// Values at `nm` by `interpolation` (0 outside the tabulated range), for any wavelengths.
    pub fn values_with(&self, interpolation: Interpolation, nm: &[f64]) -> Vec<f64> {
        // The interpolants are linear in the values, and their sums of up to 3033 times a
        // value would overflow near f64::MAX: such data are interpolated at a smaller scale.
        let peak = self.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if peak > 1e300 && self.method(interpolation) != Method::Linear {
            let scaled = Self {
                wavelengths_nm: self.wavelengths_nm.clone(),
                values: self.values.iter().map(|v| v / peak).collect(),
            };
            return scaled
                .values_unscaled(interpolation, nm)
                .into_iter()
                .map(|v| v * peak)
                .collect();
        }
        self.values_unscaled(interpolation, nm)
    }

    fn values_unscaled(&self, interpolation: Interpolation, nm: &[f64]) -> Vec<f64> {
        match self.method(interpolation) {
            Method::Linear => nm.iter().map(|&x| self.value(x)).collect(),
            Method::Sprague => {
                let s = Sprague::new(self);
                nm.iter().map(|&x| s.value(x)).collect()
            }
            Method::CubicSpline => {
                let s = CubicSpline::new(self);
                nm.iter().map(|&x| s.value(x)).collect()
            }
        }
    }

    /// A warning when data coarser than [`COARSE_INTERVAL_NM`] are resampled linearly,
    /// naming `origin` and the interval.
    pub fn coarse_linear_warning(
        &self,
        origin: &str,
        interpolation: Interpolation,
    ) -> Option<String> {
        let step = self.max_interval_nm();
        (self.method(interpolation) == Method::Linear && step > COARSE_INTERVAL_NM).then(|| {
            format!(
                "{origin}: samples up to {step} nm apart are resampled to 1 nm by linear \
                 interpolation, which bends smooth spectra between the samples (integrals can be \
                 off by a few tenths of a percent or more); interpolation cie167 (Sprague / cubic \
                 spline, CIE 167) is the recommended method{}",
                if self.values.len() < 6 {
                    " but needs at least 6 uniformly spaced or 4 samples"
                } else {
                    ""
                }
            )
        })
    }

    /// The index `hi` with `w[hi - 1] < nm <= w[hi]`, or `None` outside `[first, last]`, and
    /// whether `nm` is a tabulated wavelength (then the sample is returned as it is).
    fn bracket(&self, nm: f64) -> Option<Result<usize, usize>> {
        let w = &self.wavelengths_nm;
        if !(nm >= w[0] && nm <= w[w.len() - 1]) {
            return None;
        }
        let hi = w.partition_point(|&x| x < nm);
        Some(if w[hi] == nm { Err(hi) } else { Ok(hi) })
    }
}

/// Sprague (1880) interpolation of uniformly spaced samples, as colour-science's
/// `SpragueInterpolator`: the samples extended by two extrapolated ones at each end, a
/// fifth-order polynomial through the six samples around each interval.
struct Sprague<'a> {
    sd: &'a SpectralDistribution,
    /// The values with two boundary samples before and two after.
    yp: Vec<f64>,
}

impl<'a> Sprague<'a> {
    fn new(sd: &'a SpectralDistribution) -> Self {
        let y = &sd.values;
        let n = y.len();
        let ends = [&y[..6], &y[..6], &y[n - 6..], &y[n - 6..]];
        let extra: Vec<f64> = SPRAGUE_BOUNDARY
            .iter()
            .zip(ends)
            .map(|(c, v)| c.iter().zip(v).map(|(c, v)| c * v).sum::<f64>() / 209.0)
            .collect();
        let mut yp = Vec::with_capacity(n + 4);
        yp.extend_from_slice(&extra[..2]);
        yp.extend_from_slice(y);
        yp.extend_from_slice(&extra[2..]);
        Self { sd, yp }
    }

    fn value(&self, nm: f64) -> f64 {
        let hi = match self.sd.bracket(nm) {
            None => return 0.0,
            Some(Err(k)) => return self.sd.values[k],
            Some(Ok(hi)) => hi,
        };
        let w = &self.sd.wavelengths_nm;
        let lo = hi - 1;
        let x = (nm - w[lo]) / (w[hi] - w[lo]);
        // yp[lo + 2] is the sample at w[lo]; the polynomial uses yp[lo..lo + 6].
        let r = &self.yp[lo..lo + 6];
        let mut y = r[2];
        let mut xk = 1.0;
        for w in SPRAGUE_W {
            xk *= x;
            let a: f64 = w.iter().zip(r).map(|(w, r)| w * r).sum::<f64>() / 24.0;
            y += a * xk;
        }
        y
    }
}

/// The interpolating cubic spline with not-a-knot ends (the third derivative continuous at
/// the second and the last but one sample), as scipy's `interp1d(kind="cubic")` that
/// colour-science's `CubicSplineInterpolator` is: stored as the slope at every sample.
struct CubicSpline<'a> {
    sd: &'a SpectralDistribution,
    slopes: Vec<f64>,
}

impl<'a> CubicSpline<'a> {
    /// Needs at least 4 samples.
    fn new(sd: &'a SpectralDistribution) -> Self {
        let (x, y) = (&sd.wavelengths_nm, &sd.values);
        let n = x.len();
        let dx: Vec<f64> = x.windows(2).map(|p| p[1] - p[0]).collect();
        let m: Vec<f64> = (0..n - 1).map(|i| (y[i + 1] - y[i]) / dx[i]).collect();
        // Tridiagonal system for the slopes s: sub[i]·s[i-1] + diag[i]·s[i] + sup[i]·s[i+1] = b[i].
        let (mut sub, mut diag, mut sup, mut b) =
            (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for i in 1..n - 1 {
            sub[i] = dx[i];
            diag[i] = 2.0 * (dx[i - 1] + dx[i]);
            sup[i] = dx[i - 1];
            b[i] = 3.0 * (dx[i] * m[i - 1] + dx[i - 1] * m[i]);
        }
        let d = x[2] - x[0];
        diag[0] = dx[1];
        sup[0] = d;
        b[0] = ((dx[0] + 2.0 * d) * dx[1] * m[0] + dx[0] * dx[0] * m[1]) / d;
        let d = x[n - 1] - x[n - 3];
        diag[n - 1] = dx[n - 3];
        sub[n - 1] = d;
        b[n - 1] =
            (dx[n - 2] * dx[n - 2] * m[n - 3] + (2.0 * d + dx[n - 2]) * dx[n - 3] * m[n - 2]) / d;
        Self {
            sd,
            slopes: solve_tridiagonal(&sub, &diag, &sup, &b),
        }
    }

    fn value(&self, nm: f64) -> f64 {
        let hi = match self.sd.bracket(nm) {
            None => return 0.0,
            Some(Err(k)) => return self.sd.values[k],
            Some(Ok(hi)) => hi,
        };
        let (x, y, s) = (&self.sd.wavelengths_nm, &self.sd.values, &self.slopes);
        let lo = hi - 1;
        let h = x[hi] - x[lo];
        let m = (y[hi] - y[lo]) / h;
        let c2 = (3.0 * m - 2.0 * s[lo] - s[hi]) / h;
        let c3 = (s[lo] + s[hi] - 2.0 * m) / (h * h);
        let t = nm - x[lo];
        y[lo] + t * (s[lo] + t * (c2 + t * c3))
    }
}

/// Solves a tridiagonal system by Gaussian elimination with partial pivoting (the not-a-knot
/// rows are not diagonally dominant), as LAPACK's `gtsv` that scipy's banded solver uses.
fn solve_tridiagonal(sub: &[f64], diag: &[f64], sup: &[f64], b: &[f64]) -> Vec<f64> {
    let n = diag.len();
    // Row i holds columns i, i+1, i+2 after elimination (the third from pivoting).
    let mut d = diag.to_vec();
    let mut du = sup.to_vec();
    let mut du2 = vec![0.0; n];
    let mut dl = sub.to_vec(); // dl[i] is row i's entry in column i-1
    let mut b = b.to_vec();
    for i in 0..n - 1 {
        let below = dl[i + 1];
        if below.abs() > d[i].abs() {
            // Swap rows i and i+1.
            let (ri, ri1) = (
                (d[i], du[i], du2[i], b[i]),
                (below, d[i + 1], du[i + 1], b[i + 1]),
            );
            d[i] = ri1.0;
            du[i] = ri1.1;
            du2[i] = ri1.2;
            b[i] = ri1.3;
            let f = ri.0 / d[i];
            d[i + 1] = ri.1 - f * du[i];
            du[i + 1] = ri.2 - f * du2[i];
            b[i + 1] = ri.3 - f * b[i];
        } else {
            let f = below / d[i];
            d[i + 1] -= f * du[i];
            b[i + 1] -= f * b[i];
        }
        dl[i + 1] = 0.0;
    }
    let mut s = vec![0.0; n];
    for i in (0..n).rev() {
        let mut v = b[i];
        if i + 1 < n {
            v -= du[i] * s[i + 1];
        }
        if i + 2 < n {
            v -= du2[i] * s[i + 2];
        }
        s[i] = v / d[i];
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_and_range() {
        let sd =
            SpectralDistribution::new(vec![400.0, 500.0, 600.0], vec![0.0, 8.0, 16.0]).unwrap();
        assert_eq!(sd.value(399.9), 0.0);
        assert_eq!(sd.value(400.0), 0.0);
        assert_eq!(sd.value(450.0), 4.0);
        assert_eq!(sd.value(500.0), 8.0);
        assert_eq!(sd.value(600.0), 16.0);
        assert_eq!(sd.value(600.1), 0.0);
        assert_eq!(sd.value(f64::NAN), 0.0);
    }

    #[test]
    fn cie167_of_values_near_the_largest_float_stays_finite() {
        // Sprague's boundary sums reach 3033 times a value: interpolated at a smaller scale.
        let w: Vec<f64> = (0..7).map(|i| 400.0 + 10.0 * i as f64).collect();
        let sd = SpectralDistribution::new(w, vec![1e308; 7]).unwrap();
        let t = sd.to_table_with(Interpolation::Cie167);
        for (i, v) in t.iter().enumerate() {
            let inside = (40..=100).contains(&i);
            assert!(
                if inside {
                    (v / 1e308 - 1.0).abs() < 1e-12
                } else {
                    *v == 0.0
                },
                "{} nm: {v}",
                360 + i
            );
        }
    }

    #[test]
    fn csv_parsing_and_errors() {
        let sd = SpectralDistribution::from_csv_str(
            "# comment\nnm,value\n400, 1\n\n500,2 # trailing\n",
            "t.csv",
        )
        .unwrap();
        assert_eq!(sd.wavelengths_nm, vec![400.0, 500.0]);
        assert_eq!(sd.values, vec![1.0, 2.0]);

        let e = SpectralDistribution::from_csv_str("400,1\n500,x\n", "t.csv").unwrap_err();
        let m = e.to_string();
        assert!(
            m.contains("t.csv") && m.contains("line 2") && m.contains("value"),
            "{m}"
        );

        let e = SpectralDistribution::from_csv_str("400,1\n400,2\n", "t.csv").unwrap_err();
        let m = e.to_string();
        assert!(m.contains("line 2") && m.contains("increas"), "{m}");

        let e = SpectralDistribution::from_csv_str("400,1,3\n", "t.csv").unwrap_err();
        assert!(e.to_string().contains("expected 2 columns"));

        let e = SpectralDistribution::from_csv_str("400,1\n", "t.csv").unwrap_err();
        assert!(e.to_string().contains("at least 2"));

        let e = SpectralDistribution::from_csv_str("400,1\n500,inf\n", "t.csv").unwrap_err();
        assert!(e.to_string().contains("non-finite"));
    }
}
