//! Room for an annual run's outputs, checked before the long computation: the names fit, none
//! is a directory, the directory takes a file, and the file system has space for the CSVs.

use std::path::Path;

/// What a run will write, for [`check_room`].
#[derive(Clone, Copy, Debug)]
pub struct Planned {
    pub points: usize,
    pub hours: usize,
    pub sunny_hours: usize,
    pub patches: usize,
    pub grids: usize,
    pub glare: bool,
    pub coefficients: bool,
}

impl Planned {
    /// The fewest bytes the CSV files take: every value is written with 6 decimals, so
    /// ",0.000000" (9 bytes) at the least. The JSON report and the heat maps come on top.
    pub fn minimum_bytes(&self) -> u64 {
        let (p, h) = (self.points as u64, self.hours as u64);
        // NAME.annual.csv: "m,d,h" and three values per point, each hour.
        let mut n = h * (6 + 27 * p);
        if self.glare {
            n += h * (6 + 5 * 9);
        }
        if self.coefficients {
            n += p * self.patches as u64 * 30 + self.sunny_hours as u64 * p * 40;
        }
        n
    }
}

/// Checks, before the computation, that the directory of `stem` takes the run's files: their
/// names fit, none is a directory, a file can be created there, and the file system has at
/// least [`Planned::minimum_bytes`] free.
pub fn check_room(stem: &Path, planned: &Planned) -> anyhow::Result<()> {
    use crate::job::files::{bytes_text, check_outputs, free_bytes, Planned as File};
    let named = |suffix: &str, what: &str| File {
        path: crate::output::with_suffix(stem, suffix),
        what: what.to_string(),
    };
    let mut files = vec![
        named(".annual.json", "the report"),
        named(".annual.csv", "the hourly illuminances"),
    ];
    if planned.glare {
        files.push(named(".annual-glare.csv", "the hourly glare"));
    }
    if planned.coefficients {
        files.push(named(".annual-sky-dc.csv", "the sky coefficients"));
        files.push(named(".annual-sun-dc.csv", "the sun coefficients"));
    }
    check_outputs(&files, &[], 0)?;
    let dir = match stem.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let need = planned.minimum_bytes();
    if let Some(free) = free_bytes(dir) {
        if free < need {
            anyhow::bail!(
                "not enough free disk space in {}: the annual results of {} points over {} hours need at least {}, {} are free; free some space or choose another --out",
                crate::limits::printable(&dir.display().to_string(), 300),
                planned.points,
                planned.hours,
                bytes_text(need),
                bytes_text(free)
            );
        }
    }
    Ok(())
}
