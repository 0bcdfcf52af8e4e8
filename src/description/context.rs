//! Reading a scene value: errors that name the scene file and the field, checked numbers and
//! vectors, paths relative to the scene, spectra, and photometric amounts turned into
//! radiometric spectra. Every type that builds itself from its description uses it.

use super::schema::{SpectrumDesc, V3};
use crate::colour::sd::{Interpolation, SpectralDistribution};
use crate::colour::{planck::planck_law, tables};
use crate::photometry::photometric_scale;
use crate::spectrum::rgb_upsample::fit_linear_srgb;
use crate::spectrum::DenseSpectrum;
use glam::Vec3;
use std::path::{Path, PathBuf};

/// A scene that cannot be read or built, with the file, the position or the field.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("cannot read scene file {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}:{line}:{col}: the scene file is not valid: {message}", path.display())]
    Parse {
        path: PathBuf,
        line: usize,
        col: usize,
        message: String,
    },
    #[error("{}: `{field}`: {message}", path.display())]
    Invalid {
        path: PathBuf,
        field: String,
        message: String,
    },
}

/// Largest spectral value of a light (W·m⁻²·sr⁻¹·nm⁻¹ for radiance, W·sr⁻¹·nm⁻¹ for
/// intensity, W·m⁻²·nm⁻¹ for irradiance) — some 10¹⁸ times the sun's radiance — so that the
/// single-precision light spectra and the f32 image channels cannot overflow to infinity.
pub const MAX_SPECTRAL_VALUE: f64 = 1e25;

/// Smallest spectral value of a light that is not off (same units): below it the light's
/// contributions fall into single precision's subnormal range and round to 0.
pub const MIN_SPECTRAL_VALUE: f64 = 1e-25;

/// What building a scene value needs: the scene file (for messages), its directory (for
/// relative paths) and the files it refers to.
pub struct Context<'a> {
    pub path: &'a Path,
    /// Directory relative paths are resolved against.
    pub dir: PathBuf,
    /// Every file the scene refers to, in the order first resolved (see [`crate::world::World::sources`]).
    pub sources: std::cell::RefCell<Vec<PathBuf>>,
}

impl Context<'_> {
    /// An error naming the scene file and `field`.
    pub fn err(&self, field: impl Into<String>, message: impl Into<String>) -> SceneError {
        SceneError::Invalid {
            path: self.path.to_path_buf(),
            field: field.into(),
            message: message.into(),
        }
    }
    pub fn finite(&self, field: &str, v: f64) -> Result<f64, SceneError> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(field, format!("{v} is not a finite number")))
        }
    }
    pub fn positive(&self, field: &str, v: f64) -> Result<f64, SceneError> {
        self.finite(field, v)?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(field, format!("must be greater than 0, got {v}")))
        }
    }
    pub fn vec3(&self, field: &str, v: V3) -> Result<Vec3, SceneError> {
        for (k, c) in v.iter().enumerate() {
            if !c.is_finite() {
                return Err(self.err(
                    format!("{field}.{}", ["x", "y", "z"][k]),
                    format!("{c} is not a finite number"),
                ));
            }
        }
        Ok(Vec3::from_array(v))
    }
    /// A path of the scene relative to its directory, recorded among the scene's sources.
    pub fn resolve(&self, rel: &str) -> PathBuf {
        let p = self.dir.join(rel);
        let mut sources = self.sources.borrow_mut();
        if !sources.contains(&p) {
            sources.push(p.clone());
        }
        p
    }

    /// A unit direction (refusing the zero vector).
    pub fn unit(&self, field: &str, v: V3) -> Result<Vec3, SceneError> {
        let v = self.vec3(field, v)?;
        if v.length_squared() == 0.0 {
            return Err(self.err(field, "the direction is the zero vector"));
        }
        Ok(v.normalize())
    }

    /// A photometric amount: finite and ≥ 0.
    pub fn nonneg(&self, field: &str, v: f64) -> Result<f64, SceneError> {
        self.finite(field, v)?;
        if v < 0.0 {
            return Err(self.err(
                field,
                format!("a photometric amount cannot be negative, got {v}"),
            ));
        }
        Ok(v)
    }

    /// Check that spectrum `s` scaled by `k` stays finite with headroom (see
    /// [`MAX_SPECTRAL_VALUE`]).
    pub fn representable(&self, afield: &str, s: &DenseSpectrum, k: f32) -> Result<(), SceneError> {
        let peak = s.max_value() as f64 * k as f64;
        if peak <= MAX_SPECTRAL_VALUE {
            Ok(())
        } else {
            Err(self.err(
                afield,
                format!(
                    "the amount is too large: the light's spectral value would reach {peak:e} (more than {MAX_SPECTRAL_VALUE:e} in W, m, sr, nm), beyond any physical source"
                ),
            ))
        }
    }

    /// An emission spectrum (`sfield`) scaled to carry `amount` photometric units (checked by
    /// the caller; reported at `afield` if too large): spectrum × amount / (K_m ∫ S V dλ).
    pub fn emission(
        &self,
        sfield: &str,
        afield: &str,
        desc: &SpectrumDesc,
        amount: f64,
    ) -> Result<DenseSpectrum, SceneError> {
        let s = self.spectrum(sfield, desc, Role::Emission)?;
        self.scaled_emission(sfield, afield, &s, amount)
    }

    /// [`Context::emission`] of a resolved spectrum `s`.
    pub fn scaled_emission(
        &self,
        sfield: &str,
        afield: &str,
        s: &DenseSpectrum,
        amount: f64,
    ) -> Result<DenseSpectrum, SceneError> {
        let k = photometric_scale(s, amount).map_err(|m| self.err(sfield, m))?;
        self.representable(afield, s, k)?;
        let peak = s.max_value() as f64 * k as f64;
        if amount > 0.0 && peak < MIN_SPECTRAL_VALUE {
            return Err(self.err(
                afield,
                format!(
                    "the amount is too small: the light's spectral value would be {peak:e} (less than {MIN_SPECTRAL_VALUE:e} in W, m, sr, nm), which single precision rounds to 0; use 0 for a light that is off"
                ),
            ));
        }
        Ok(s.scaled(k))
    }

    /// The spectrum `desc` describes, checked for its `role` (finite, ≥ 0; a reflectance ≤ 1).
    pub fn spectrum(
        &self,
        field: &str,
        desc: &SpectrumDesc,
        role: Role,
    ) -> Result<DenseSpectrum, SceneError> {
        let dense = match desc {
            SpectrumDesc::Constant(v) => {
                let v = self.finite(field, *v)?;
                DenseSpectrum::constant(v as f32)
            }
            SpectrumDesc::Blackbody(t) => self.blackbody(field, *t, role)?,
            SpectrumDesc::Daylight(cct) => self.daylight(field, *cct, role)?,
            SpectrumDesc::Named(name) => self.named(field, name)?,
            SpectrumDesc::Tabulated(pairs) => self.tabulated(field, pairs)?,
            SpectrumDesc::Csv(rel, interpolation) => self.csv(field, rel, *interpolation, role)?,
            SpectrumDesc::Texture { .. } => {
                return Err(self.err(
                    field,
                    "an image texture can only be a `Diffuse` material's reflectance or an object's emission spectrum",
                ));
            }
            SpectrumDesc::Rgb(r, g, b) => self.rgb(field, [*r, *g, *b], false, role)?,
            SpectrumDesc::Srgb(r, g, b) => self.rgb(field, [*r, *g, *b], true, role)?,
        };
        self.valid_spectrum(field, dense, role)
    }

    /// A blackbody's relative spectrum at `t` K (emission only).
    fn blackbody(&self, field: &str, t: f64, role: Role) -> Result<DenseSpectrum, SceneError> {
        if role == Role::Reflectance {
            return Err(self.err(
                field,
                "a blackbody spectrum describes emission, not a reflectance",
            ));
        }
        let t = self.positive(field, t)?;
        // Relative shape only: normalise to 1 at 560 nm to keep f32 in range.
        let norm = planck_law(560e-9, t);
        Ok(DenseSpectrum::from_fn(|nm| planck_law(nm * 1e-9, t) / norm))
    }

    /// CIE daylight of correlated colour temperature `cct` K (emission only).
    fn daylight(&self, field: &str, cct: f64, role: Role) -> Result<DenseSpectrum, SceneError> {
        if role == Role::Reflectance {
            return Err(self.err(
                field,
                "a daylight spectrum describes emission, not a reflectance",
            ));
        }
        let t = self.finite(field, cct)?;
        if !(4000.0..=25_000.0).contains(&t) {
            return Err(self.err(
                field,
                format!("CIE daylight is defined from 4000 K to 25 000 K, not {t} K"),
            ));
        }
        let sd = crate::colour::illuminants::sd_cie_daylight(t);
        Ok(DenseSpectrum::from_fn(|nm| {
            let x = (nm - 360.0).clamp(0.0, (sd.len() - 1) as f64);
            let (i, f) = (x.floor() as usize, x.fract());
            let j = (i + 1).min(sd.len() - 1);
            sd[i] * (1.0 - f) + sd[j] * f
        }))
    }

    /// A spectrum candela ships, by name.
    fn named(&self, field: &str, name: &str) -> Result<DenseSpectrum, SceneError> {
        let sd = tables::named_spectrum(name).ok_or_else(|| {
            self.err(
                field,
                format!(
                    "unknown spectrum name {name:?}; known names: {}",
                    tables::named_spectrum_names().join(", ")
                ),
            )
        })?;
        Ok(DenseSpectrum::from_fn(|nm| sd.value(nm)))
    }

    /// A spectrum given as (wavelength nm, value) pairs.
    fn tabulated(&self, field: &str, pairs: &[(f64, f64)]) -> Result<DenseSpectrum, SceneError> {
        let (w, v): (Vec<f64>, Vec<f64>) = pairs.iter().copied().unzip();
        let sd = SpectralDistribution::new(w, v).map_err(|e| self.err(field, e.to_string()))?;
        in_range(self, field, &sd, "the table")?;
        Ok(DenseSpectrum::from_fn(|nm| sd.value(nm)))
    }

    /// A spectrum read from the CSV file `rel` (relative to the scene), interpolated by
    /// `interpolation`.
    fn csv(
        &self,
        field: &str,
        rel: &str,
        interpolation: Interpolation,
        role: Role,
    ) -> Result<DenseSpectrum, SceneError> {
        let p = self.resolve(rel);
        let sd =
            SpectralDistribution::from_csv_path(&p).map_err(|e| self.err(field, e.to_string()))?;
        in_range(self, field, &sd, &format!("{}", p.display()))?;
        // CIE 167's interpolants can ring below 0 next to a sharp line (and a reflectance
        // above 1): held at those bounds, valid samples stay valid and invalid ones are still
        // refused by the checks of every spectrum.
        let t = sd.to_table_with(interpolation);
        let max = sd.values.iter().fold(f64::NEG_INFINITY, |m, &v| v.max(m));
        let lo = sd.min_value().min(0.0);
        let hi = if role == Role::Reflectance {
            max.max(1.0)
        } else {
            f64::INFINITY
        };
        let start = crate::colour::grid::START_NM as f64;
        Ok(DenseSpectrum::from_fn(|nm| {
            t[(nm - start) as usize].clamp(lo, hi)
        }))
    }

    /// The smooth spectrum of linear (or, `encoded`, sRGB-encoded) RGB components in [0, 1]:
    /// a reflectance, or for emission that shape times D65.
    fn rgb(
        &self,
        field: &str,
        rgb: [f64; 3],
        encoded: bool,
        role: Role,
    ) -> Result<DenseSpectrum, SceneError> {
        for (k, c) in rgb.iter().enumerate() {
            self.finite(field, *c)?;
            if !(0.0..=1.0).contains(c) {
                return Err(self.err(
                    field,
                    format!(
                        "RGB component {} is {c}; sRGB components must lie in [0, 1]",
                        ["r", "g", "b"][k]
                    ),
                ));
            }
        }
        let rgb = if encoded {
            rgb.map(crate::colour::rgb::srgb_decode)
        } else {
            rgb
        };
        let (sig, _residual) = fit_linear_srgb(rgb).map_err(|e| self.err(field, e.to_string()))?;
        Ok(match role {
            Role::Reflectance => DenseSpectrum::from_fn(|nm| sig.value(nm)),
            Role::Emission => {
                // An RGB emitter is the smooth reflectance-like shape times D65, so that
                // white (1,1,1) emits D65 (pbrt-v4's RGBIlluminantSpectrum).
                let d65 = tables::named_spectrum("D65").expect("D65 ships with candela");
                DenseSpectrum::from_fn(|nm| sig.value(nm) * d65.value(nm))
            }
        })
    }

    /// `dense`, refused unless finite and ≥ 0 (and, a reflectance, ≤ 1).
    fn valid_spectrum(
        &self,
        field: &str,
        dense: DenseSpectrum,
        role: Role,
    ) -> Result<DenseSpectrum, SceneError> {
        if dense.values.iter().any(|v| !v.is_finite()) {
            return Err(self.err(field, "the spectrum has non-finite values"));
        }
        let min = dense.min_value();
        if min < 0.0 {
            return Err(self.err(
                field,
                format!("the spectrum is negative (minimum {min}); spectra must be ≥ 0"),
            ));
        }
        if role == Role::Reflectance {
            let max = dense.max_value();
            if max > 1.0 {
                let at = dense.values.iter().position(|&v| v == max).unwrap_or(0) + 360;
                return Err(self.err(
                    field,
                    format!(
                        "reflectance {max} at {at} nm is above 1; a passive surface cannot reflect more light than it receives"
                    ),
                ));
            }
        }
        Ok(dense)
    }
}

#[derive(Clone, Copy, PartialEq)]
/// What a spectrum describes: reflectances must lie in [0, 1]; emission may not be a
/// blackbody reflectance.
pub enum Role {
    Reflectance,
    Emission,
}

/// Refuse a table that lies entirely outside 360–830 nm: it would be zero at every wavelength
/// candela renders (as `candela spectrum` refuses it).
fn in_range(
    ctx: &Context,
    field: &str,
    sd: &SpectralDistribution,
    what: &str,
) -> Result<(), SceneError> {
    use crate::colour::grid::{END_NM, START_NM};
    let (Some(&first), Some(&last)) = (sd.wavelengths_nm.first(), sd.wavelengths_nm.last()) else {
        return Ok(());
    };
    if last < START_NM as f64 || first > END_NM as f64 {
        return Err(ctx.err(
            field,
            format!(
                "{what} covers {first}–{last} nm, entirely outside candela's {START_NM}–{END_NM} nm range (it would be 0 at every wavelength rendered)"
            ),
        ));
    }
    Ok(())
}
