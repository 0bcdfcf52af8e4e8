//! Spectral distributions: tabulated (wavelength, value) pairs with linear interpolation, read
//! from CSV and resampled to the 1 nm grid.

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

    /// Samples the distribution at 360..=830 nm every 1 nm with [`Self::value`].
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
