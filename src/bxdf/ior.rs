//! Refractive indices: dielectric dispersion (constant, Cauchy, Sellmeier) and the complex
//! indices n + ik of named metals, all from `data/ior/` (exported from the refractiveindex.info
//! database by `scripts/gen_ior.py`; sources are in each file's header and data/README.md).
//!
//! Sellmeier: n² = 1 + Σᵢ Bᵢ λ² / (λ² − Cᵢ), λ in µm, Cᵢ in µm² (SCHOTT catalogue form).
//! Cauchy: n = A + B/λ² + C/λ⁴, λ in nm.

use crate::description::context::{Context, Role, SceneError};
use crate::description::schema::{IorDesc, SpectrumDesc};
use crate::spectrum::{DenseSpectrum, SampledWavelengths, N_LAMBDA};
use std::sync::OnceLock;

/// Smallest and largest relative index a dielectric may have (anywhere in 360–830 nm): far
/// beyond any material, and η² stays within single precision (10¹²), which the refracted
/// radiance and Russian roulette's η′² products need.
pub const MIN_IOR: f32 = 1e-6;
/// See [`MIN_IOR`].
pub const MAX_IOR: f32 = 1e6;

/// The real index of a dielectric as a function of wavelength.
#[derive(Clone, Debug, PartialEq)]
pub enum Ior {
    Constant(f32),
    /// n = a + b/λ² + c/λ⁴ with λ in nm.
    Cauchy {
        a: f64,
        b: f64,
        c: f64,
    },
    /// n² = 1 + Σ bᵢ λ²/(λ² − cᵢ), λ in µm, cᵢ in µm².
    Sellmeier {
        b: [f64; 3],
        c: [f64; 3],
    },
}

impl Ior {
    /// A dielectric's index from its description at `field`, positive and finite over
    /// 360–830 nm.
    pub fn build(ctx: &Context, field: &str, desc: &IorDesc) -> Result<Self, SceneError> {
        let ior = match desc {
            IorDesc::Constant(n) => Ior::Constant(*n),
            IorDesc::Glass(name) => named_glass(name)
                .ok_or_else(|| {
                    ctx.err(
                        field,
                        format!(
                            "unknown glass {name:?}; known glasses: {}",
                            glass_names().join(", ")
                        ),
                    )
                })?
                .ior
                .clone(),
            IorDesc::Cauchy { a, b, c } => {
                for v in [a, b, c] {
                    ctx.finite(field, *v)?;
                }
                Ior::Cauchy {
                    a: *a,
                    b: *b,
                    c: *c,
                }
            }
            IorDesc::Sellmeier { b, c } => {
                for v in b.iter().chain(c) {
                    ctx.finite(field, *v)?;
                }
                Ior::Sellmeier { b: *b, c: *c }
            }
        };
        let (lo, hi) = ior.range();
        if !(lo.is_finite() && hi.is_finite()) || lo <= 0.0 {
            return Err(ctx.err(
                field,
                format!(
                    "the refractive index must be finite and greater than 0 over 360–830 nm (range {lo} to {hi})"
                ),
            ));
        }
        if lo < MIN_IOR || hi > MAX_IOR {
            return Err(ctx.err(
                field,
                format!(
                    "the refractive index must lie between {MIN_IOR:e} and {MAX_IOR:e} over 360–830 nm (range {lo} to {hi}); beyond, single precision cannot carry η² through refraction"
                ),
            ));
        }
        Ok(ior)
    }

    /// Index at wavelength `nm`.
    #[inline]
    pub fn at(&self, nm: f32) -> f32 {
        match *self {
            Ior::Constant(n) => n,
            Ior::Cauchy { a, b, c } => {
                let l2 = (nm as f64) * (nm as f64);
                (a + b / l2 + c / (l2 * l2)) as f32
            }
            Ior::Sellmeier { b, c } => sellmeier(&b, &c, nm as f64 * 1e-3) as f32,
        }
    }
    /// Index in f64 (for tests against catalogue values).
    pub fn at_f64(&self, nm: f64) -> f64 {
        match *self {
            Ior::Constant(n) => n as f64,
            Ior::Cauchy { a, b, c } => a + b / (nm * nm) + c / (nm * nm * nm * nm),
            Ior::Sellmeier { b, c } => sellmeier(&b, &c, nm * 1e-3),
        }
    }
    /// True if the index does not depend on wavelength (no dispersion).
    pub fn is_constant(&self) -> bool {
        matches!(self, Ior::Constant(_))
    }
    /// Smallest and largest index over 360–830 nm (for validation; NaN if any value is not
    /// finite).
    pub fn range(&self) -> (f32, f32) {
        let mut lo = f32::MAX;
        let mut hi = f32::MIN;
        for nm in 360..=830 {
            let n = self.at(nm as f32);
            if !n.is_finite() {
                return (f32::NAN, f32::NAN);
            }
            lo = lo.min(n);
            hi = hi.max(n);
        }
        (lo, hi)
    }
}

fn sellmeier(b: &[f64; 3], c: &[f64; 3], um: f64) -> f64 {
    let l2 = um * um;
    let mut n2 = 1.0;
    for i in 0..3 {
        n2 += b[i] * l2 / (l2 - c[i]);
    }
    n2.max(0.0).sqrt()
}

/// A named glass from `data/ior/glasses.csv`.
#[derive(Clone, Debug)]
pub struct Glass {
    pub name: String,
    pub ior: Ior,
    /// refractiveindex.info page (shelf/book/page) and citation.
    pub source: String,
}

const GLASSES_CSV: &str = include_str!("../../data/ior/glasses.csv");

/// Every named glass (case-insensitive lookup via [`named_glass`]).
pub fn glasses() -> &'static [Glass] {
    static G: OnceLock<Vec<Glass>> = OnceLock::new();
    G.get_or_init(|| {
        let mut out = Vec::new();
        let mut header = true;
        for line in GLASSES_CSV.lines() {
            if line.starts_with('#') || line.trim().is_empty() {
                continue;
            }
            if header {
                header = false;
                continue;
            }
            let cells: Vec<&str> = line.split(',').collect();
            let num = |i: usize| -> f64 { cells[i].parse().expect("data/ior/glasses.csv number") };
            out.push(Glass {
                name: cells[0].to_string(),
                ior: Ior::Sellmeier {
                    b: [num(1), num(3), num(5)],
                    c: [num(2), num(4), num(6)],
                },
                source: format!("{} ({})", cells[7], cells[8]),
            });
        }
        out
    })
}

/// Look up a named glass (`BK7`, `fused-silica`, `SF11`, `F2`, `BaK4`), case-insensitively.
pub fn named_glass(name: &str) -> Option<&'static Glass> {
    glasses()
        .iter()
        .find(|g| g.name.eq_ignore_ascii_case(name.trim()))
}

/// Names of the glasses [`named_glass`] accepts.
pub fn glass_names() -> Vec<&'static str> {
    glasses().iter().map(|g| g.name.as_str()).collect()
}

/// A conductor's complex index n + ik baked on the 1 nm grid.
#[derive(Clone, Debug)]
pub struct ConductorIor {
    pub n: DenseSpectrum,
    pub k: DenseSpectrum,
}

impl ConductorIor {
    /// The conductor's index of the material at `field`: either a named `metal` or both
    /// optical constants `n` and `k` as spectra.
    pub fn build(
        ctx: &Context,
        field: &str,
        metal: Option<&str>,
        n: Option<&SpectrumDesc>,
        k: Option<&SpectrumDesc>,
    ) -> Result<Self, SceneError> {
        Ok(match (metal, n, k) {
            (Some(name), None, None) => named_metal(name)
                .ok_or_else(|| {
                    ctx.err(
                        format!("{field}.metal"),
                        format!(
                            "unknown metal {name:?}; known metals: {}",
                            metal_names().join(", ")
                        ),
                    )
                })?
                .clone(),
            (None, Some(n), Some(k)) => {
                for (name, d) in [("n", n), ("k", k)] {
                    if matches!(d, SpectrumDesc::Blackbody(_) | SpectrumDesc::Rgb(..)) {
                        return Err(ctx.err(
                            format!("{field}.{name}"),
                            "an optical constant must be Constant, Tabulated, Csv or Named",
                        ));
                    }
                }
                let n = ctx.spectrum(&format!("{field}.n"), n, Role::Emission)?;
                let k = ctx.spectrum(&format!("{field}.k"), k, Role::Emission)?;
                if n.min_value() <= 0.0 {
                    return Err(ctx.err(
                        format!("{field}.n"),
                        "the refractive index n must be greater than 0",
                    ));
                }
                ConductorIor { n, k }
            }
            _ => {
                return Err(ctx.err(
                    field,
                    "give either `metal` (a name) or both `n` and `k` (spectra)",
                ))
            }
        })
    }

    #[inline]
    pub fn sample(&self, wl: &SampledWavelengths) -> ([f32; N_LAMBDA], [f32; N_LAMBDA]) {
        (self.n.sample(wl).0, self.k.sample(wl).0)
    }
}

const METALS: [(&str, &str); 5] = [
    ("Au", include_str!("../../data/ior/Au.csv")),
    ("Ag", include_str!("../../data/ior/Ag.csv")),
    ("Cu", include_str!("../../data/ior/Cu.csv")),
    ("Al", include_str!("../../data/ior/Al.csv")),
    ("Cr", include_str!("../../data/ior/Cr.csv")),
];

/// Names accepted by [`named_metal`] (chemical symbols).
pub fn metal_names() -> Vec<&'static str> {
    METALS.iter().map(|m| m.0).collect()
}

/// The complex index of a named metal (`Au`, `Ag`, `Cu`, `Al`, `Cr`; case-insensitive, also
/// `gold`, `silver`, `copper`, `aluminium`/`aluminum`, `chromium`).
pub fn named_metal(name: &str) -> Option<&'static ConductorIor> {
    static M: OnceLock<Vec<ConductorIor>> = OnceLock::new();
    let key = name.trim().to_ascii_lowercase();
    let sym = match key.as_str() {
        "gold" => "au",
        "silver" => "ag",
        "copper" => "cu",
        "aluminium" | "aluminum" => "al",
        "chromium" | "chrome" => "cr",
        k => k,
    };
    let i = METALS.iter().position(|m| m.0.eq_ignore_ascii_case(sym))?;
    let all = M.get_or_init(|| METALS.iter().map(|m| parse_nk(m.0, m.1)).collect());
    Some(&all[i])
}

fn parse_nk(name: &str, text: &str) -> ConductorIor {
    let mut n = DenseSpectrum::constant(0.0);
    let mut k = DenseSpectrum::constant(0.0);
    let mut rows = 0;
    for line in text.lines() {
        if line.starts_with('#') || line.starts_with("nm") || line.trim().is_empty() {
            continue;
        }
        let c: Vec<f32> = line
            .split(',')
            .map(|s| {
                s.parse()
                    .unwrap_or_else(|_| panic!("data/ior/{name}.csv: {line}"))
            })
            .collect();
        let i = c[0] as usize - 360;
        n.values[i] = c[1];
        k.values[i] = c[2];
        rows += 1;
    }
    assert_eq!(
        rows, 471,
        "data/ior/{name}.csv must cover 360–830 nm at 1 nm"
    );
    ConductorIor { n, k }
}
