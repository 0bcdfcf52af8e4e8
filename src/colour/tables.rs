//! Spectral tables shipped in `data/` (generated from colour-science 0.4.7 by
//! `scripts/gen_data.py`), embedded with `include_str!` and parsed once.
//!
//! All 1 nm tables cover 360..=830 nm: index `i` ↔ `360 + i` nm.

use std::sync::LazyLock;

use crate::colour::sd::SpectralDistribution;

/// The tables' wavelength grid.
use crate::colour::grid::{LEN, START_NM};

/// CIE standard colorimetric observer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Observer {
    /// CIE 1931 2° standard observer.
    Cie1931_2,
    /// CIE 1964 10° supplementary standard observer.
    Cie1964_10,
}

impl Observer {
    /// colour-science's name for the observer (`colour.MSDS_CMFS` key).
    pub fn colour_science_name(self) -> &'static str {
        match self {
            Observer::Cie1931_2 => "CIE 1931 2 Degree Standard Observer",
            Observer::Cie1964_10 => "CIE 1964 10 Degree Standard Observer",
        }
    }
}

/// Colour-matching functions x̄, ȳ, z̄ at 1 nm; index `i` ↔ `360 + i` nm.
pub struct Cmfs {
    pub x: [f64; LEN],
    pub y: [f64; LEN],
    pub z: [f64; LEN],
}

impl Cmfs {
    /// x̄, ȳ, z̄ at wavelength `nm` (linear interpolation between the 1 nm samples, 0 outside
    /// 360–830 nm) — for Monte Carlo wavelength sampling in the renderer.
    pub fn at(&self, nm: f64) -> [f64; 3] {
        [
            interp_table(&self.x, nm),
            interp_table(&self.y, nm),
            interp_table(&self.z, nm),
        ]
    }
}

/// Value of a 1 nm table (index `i` ↔ `360 + i` nm) at wavelength `nm`: linear interpolation,
/// exact at integer nm, 0 outside 360–830 nm (same rule as
/// [`SpectralDistribution::value`]).
pub fn interp_table(table: &[f64; LEN], nm: f64) -> f64 {
    let x = nm - START_NM as f64;
    if !(x >= 0.0 && x <= (LEN - 1) as f64) {
        return 0.0;
    }
    let i = x.floor() as usize;
    if i >= LEN - 1 {
        return table[LEN - 1];
    }
    let t = x - i as f64;
    if t == 0.0 {
        table[i]
    } else {
        table[i] + t * (table[i + 1] - table[i])
    }
}

/// A parsed multi-column table: column names and, per column, optional values per row.
pub(crate) struct Table {
    pub names: Vec<String>,
    pub nm: Vec<f64>,
    pub cols: Vec<Vec<Option<f64>>>,
}

/// Parses one of the CSV files in `data/`: `#` comment lines, then a header line
/// `nm,name1,name2,...`, then rows of numbers (empty cells allowed).  Panics with the file
/// and line on malformed data (the files are embedded at compile time and tested).
pub(crate) fn parse_table(text: &str, origin: &str) -> Table {
    let mut names: Option<Vec<String>> = None;
    let mut nm = Vec::new();
    let mut cols: Vec<Vec<Option<f64>>> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        match &names {
            None => {
                assert_eq!(
                    fields[0],
                    "nm",
                    "{origin}:{}: header must start with 'nm'",
                    i + 1
                );
                names = Some(fields[1..].iter().map(|s| s.to_string()).collect());
                cols = vec![Vec::new(); fields.len() - 1];
            }
            Some(n) => {
                assert_eq!(
                    fields.len(),
                    n.len() + 1,
                    "{origin}:{}: wrong field count",
                    i + 1
                );
                nm.push(
                    fields[0]
                        .parse::<f64>()
                        .unwrap_or_else(|_| panic!("{origin}:{}: bad wavelength", i + 1)),
                );
                for (c, f) in fields[1..].iter().enumerate() {
                    cols[c].push(if f.is_empty() {
                        None
                    } else {
                        Some(
                            f.parse::<f64>()
                                .unwrap_or_else(|_| panic!("{origin}:{}: bad number '{f}'", i + 1)),
                        )
                    });
                }
            }
        }
    }
    Table {
        names: names.unwrap_or_else(|| panic!("{origin}: no header")),
        nm,
        cols,
    }
}

impl Table {
    fn column_1nm(&self, name: &str, origin: &str) -> [f64; LEN] {
        let c = self
            .names
            .iter()
            .position(|n| n == name)
            .unwrap_or_else(|| panic!("{origin}: no column {name}"));
        assert_eq!(self.nm.len(), LEN, "{origin}: expected {LEN} rows");
        let mut out = [0.0; LEN];
        for (i, o) in out.iter_mut().enumerate() {
            assert_eq!(self.nm[i], START_NM as f64 + i as f64, "{origin}: row {i}");
            *o = self.cols[c][i].unwrap_or_else(|| panic!("{origin}: empty cell in {name}"));
        }
        out
    }

    fn column_sd(&self, c: usize) -> SpectralDistribution {
        let (w, v): (Vec<f64>, Vec<f64>) = self
            .nm
            .iter()
            .zip(&self.cols[c])
            .filter_map(|(w, v)| v.map(|v| (*w, v)))
            .unzip();
        SpectralDistribution::new(w, v).expect("embedded table column is a valid spectrum")
    }
}

const CMFS_1931: &str = include_str!("../../data/cmfs-cie1931-2.csv");
const CMFS_1964: &str = include_str!("../../data/cmfs-cie1964-10.csv");
const LEF: &str = include_str!("../../data/luminous-efficiency.csv");
const ILLUMINANTS: &str = include_str!("../../data/illuminants.csv");
const DAYLIGHT: &str = include_str!("../../data/daylight-basis.csv");
const COLORCHECKER: &str = include_str!("../../data/colorchecker-ohta.csv");
const TCS: &str = include_str!("../../data/tcs-cie13.3.csv");
const CORNELL: &str = include_str!("../../data/cornell-box.csv");
const ALPHA_OPIC: &str = include_str!("../../data/alpha-opic-cie-s026.csv");

fn load_cmfs(text: &str, origin: &str) -> Cmfs {
    let t = parse_table(text, origin);
    Cmfs {
        x: t.column_1nm("x_bar", origin),
        y: t.column_1nm("y_bar", origin),
        z: t.column_1nm("z_bar", origin),
    }
}

static CMFS_2: LazyLock<Cmfs> = LazyLock::new(|| load_cmfs(CMFS_1931, "data/cmfs-cie1931-2.csv"));
static CMFS_10: LazyLock<Cmfs> = LazyLock::new(|| load_cmfs(CMFS_1964, "data/cmfs-cie1964-10.csv"));
static LEFS: LazyLock<([f64; LEN], [f64; LEN])> = LazyLock::new(|| {
    let o = "data/luminous-efficiency.csv";
    let t = parse_table(LEF, o);
    (t.column_1nm("photopic", o), t.column_1nm("scotopic", o))
});
static BASIS: LazyLock<[[f64; LEN]; 3]> = LazyLock::new(|| {
    let o = "data/daylight-basis.csv";
    let t = parse_table(DAYLIGHT, o);
    [
        t.column_1nm("S0", o),
        t.column_1nm("S1", o),
        t.column_1nm("S2", o),
    ]
});

/// Colour-matching functions of `observer` (colour-science `MSDS_CMFS`, 360–830 nm, 1 nm).
pub fn cmfs(observer: Observer) -> &'static Cmfs {
    match observer {
        Observer::Cie1931_2 => &CMFS_2,
        Observer::Cie1964_10 => &CMFS_10,
    }
}

/// CIE 1924 photopic luminous efficiency V(λ), 360–830 nm at 1 nm.
pub fn photopic_v() -> &'static [f64; LEN] {
    &LEFS.0
}

/// CIE 1951 scotopic luminous efficiency V′(λ), 360–830 nm at 1 nm (zero outside its
/// defined 380–780 nm range, as colour-science's `luminous_flux` aligns it).
pub fn scotopic_v() -> &'static [f64; LEN] {
    &LEFS.1
}

/// CIE S 026 α-opic action spectra `[s-cone, m-cone, l-cone, rhodopic, melanopic]`, each 1 at
/// its peak, 360–830 nm at 1 nm (zero outside S 026's 380–780 nm); see `colour::alpha_opic`.
pub fn alpha_opic_action_spectra() -> &'static [[f64; LEN]; 5] {
    static T: LazyLock<[[f64; LEN]; 5]> = LazyLock::new(|| {
        let o = "data/alpha-opic-cie-s026.csv";
        let t = parse_table(ALPHA_OPIC, o);
        ["s_cone", "m_cone", "l_cone", "rhodopic", "melanopic"].map(|c| t.column_1nm(c, o))
    });
    &T
}

/// CIE daylight basis functions `[S0, S1, S2]`, 360–830 nm at 1 nm (CIE 15:2018 table,
/// linearly interpolated from 5 nm as colour-science does).
pub fn daylight_basis() -> &'static [[f64; LEN]; 3] {
    &BASIS
}

/// One named spectrum.
struct Named {
    /// Display name (canonical spelling).
    name: String,
    /// Lower-case alias used for lookup (several per spectrum allowed).
    aliases: Vec<String>,
    sd: SpectralDistribution,
}

static NAMED: LazyLock<Vec<Named>> = LazyLock::new(|| {
    let mut out = Vec::new();
    let mut add_table = |text: &str, origin: &str, prefix: &str, numbered: bool| {
        let t = parse_table(text, origin);
        for (c, name) in t.names.iter().enumerate() {
            let sd = t.column_sd(c);
            let (display, aliases) = if numbered {
                let num = format!("{prefix}{}", c + 1);
                let by_name = format!("{prefix}{name}");
                (
                    num.clone(),
                    vec![num.to_lowercase(), by_name.to_lowercase()],
                )
            } else {
                let d = format!("{prefix}{name}");
                (d.clone(), vec![d.to_lowercase()])
            };
            out.push(Named {
                name: display,
                aliases,
                sd,
            });
        }
    };
    add_table(ILLUMINANTS, "data/illuminants.csv", "", false);
    add_table(CORNELL, "data/cornell-box.csv", "cornell-", false);
    add_table(
        COLORCHECKER,
        "data/colorchecker-ohta.csv",
        "colorchecker:",
        true,
    );
    add_table(TCS, "data/tcs-cie13.3.csv", "", false);
    out
});

/// Named spectra, case-insensitive: "A","D50","D55","D65","D75","E","FL1".."FL12",
/// "LED-B1".."LED-B5","LED-BH1","LED-RGB1","LED-V1","LED-V2", "cornell-white",
/// "cornell-green","cornell-red","cornell-light", ColorChecker patches as
/// "colorchecker:1".."colorchecker:24" (also by name e.g. "colorchecker:dark skin"),
/// "TCS01".."TCS14".
///
/// The CIE illuminants, ColorChecker and TCS spectra are tabulated at 1 nm over 360–830 nm
/// exactly as colour-science aligns them; the Cornell spectra keep their native sampling.
pub fn named_spectrum(name: &str) -> Option<&'static SpectralDistribution> {
    let key = name.trim().to_lowercase();
    NAMED
        .iter()
        .find(|n| n.aliases.contains(&key))
        .map(|n| &n.sd)
}

/// Canonical names of all spectra accepted by [`named_spectrum`].
pub fn named_spectrum_names() -> Vec<&'static str> {
    NAMED.iter().map(|n| n.name.as_str()).collect()
}

/// ColorChecker patch names in chart order (1–24), as in colour-science.
pub fn colorchecker_patch_names() -> Vec<&'static str> {
    NAMED
        .iter()
        .filter(|n| n.name.starts_with("colorchecker:"))
        .map(|n| n.aliases[1].trim_start_matches("colorchecker:"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_load() {
        let c = cmfs(Observer::Cie1931_2);
        // ȳ(555) = 1 and ∫ȳ = 106.856917 (1 nm sum, colour-science).
        assert_eq!(c.y[555 - 360], 1.0);
        let s: f64 = c.y.iter().sum();
        assert!((s - 106.856917).abs() < 5e-7, "{s}");
        // V(λ) equals ȳ to within 5e-13.
        for i in 0..LEN {
            assert!((photopic_v()[i] - c.y[i]).abs() < 5e-13);
        }
        assert_eq!(scotopic_v()[0], 0.0);
        assert!(scotopic_v()[507 - 360] > 0.999);
        assert_eq!(cmfs(Observer::Cie1964_10).y.len(), LEN);
        assert!((daylight_basis()[0][560 - 360] - 100.0).abs() < 1e-9);
    }

    #[test]
    fn table_interpolation_matches_sd() {
        let d65 = named_spectrum("D65").unwrap();
        let t = d65.to_table();
        for nm in [359.0, 360.0, 360.25, 555.5, 829.9, 830.0, 830.1] {
            assert!((interp_table(&t, nm) - d65.value(nm)).abs() < 1e-12, "{nm}");
        }
        assert_eq!(cmfs(Observer::Cie1931_2).at(555.0)[1], 1.0);
    }

    #[test]
    fn named_lookup() {
        let names = named_spectrum_names();
        assert_eq!(names.len(), 27 + 4 + 24 + 14, "{names:?}");
        for n in &names {
            assert!(named_spectrum(n).is_some(), "{n}");
        }
        assert!(named_spectrum("d65").is_some());
        assert!(named_spectrum("led-b3").is_some());
        assert!(named_spectrum("ColorChecker:Dark Skin").is_some());
        assert_eq!(
            named_spectrum("colorchecker:1"),
            named_spectrum("colorchecker:dark skin")
        );
        assert!(named_spectrum("tcs14").is_some());
        assert!(named_spectrum("nope").is_none());
        let light = named_spectrum("cornell-light").unwrap();
        assert_eq!(light.wavelengths_nm, vec![400.0, 500.0, 600.0, 700.0]);
        assert!((light.value(550.0) - 11.8).abs() < 1e-12);
        let white = named_spectrum("cornell-white").unwrap();
        assert_eq!(white.wavelengths_nm.len(), 76);
        assert_eq!(white.value(399.0), 0.0);
        assert_eq!(colorchecker_patch_names().len(), 24);
        // Illuminant A at 560 nm is 100.
        assert!((named_spectrum("A").unwrap().value(560.0) - 100.0).abs() < 1e-9);
    }
}
