//! What `candela spectrum` computes: a spectrum source named on the command line (a CSV
//! file, a named spectrum, `blackbody:3000K`, `daylight:6504K`) resolved to a 1 nm table, and
//! its colorimetry (XYZ, chromaticities, CCT and Duv, efficacy, S/P, sRGB, CRI, object colour),
//! with notes where a value lies outside its method's domain. See `docs/colour.md`.

use std::path::Path;

use anyhow::{bail, Context};

use crate::colour::colorimetry::{sd_to_xyz_absolute, sd_to_xyz_emissive, sd_to_xyz_relative};
use crate::colour::cri::{colour_rendering_index, Cri};
use crate::colour::grid::{END_NM, LEN, START_NM};
use crate::colour::illuminants::sd_cie_daylight;
use crate::colour::models::{xyz_to_lab, xyz_to_upvp, xyz_to_uv1960, xyz_to_xy};
use crate::colour::planck::blackbody_table;
use crate::colour::rgb::{srgb_encode, xyz_to_linear_srgb};
use crate::colour::sd::{Interpolation, SpectralDistribution, COARSE_INTERVAL_NM};
use crate::colour::tables::{named_spectrum, named_spectrum_names, Observer};
use crate::colour::temperature::{uv_to_cct_ohno2013, uv_to_cct_robertson1968};
use crate::photometry::{blackbody_luminous_efficacy, luminous_efficacy, sp_ratio};

/// What a SOURCE argument resolved to.
pub struct SpectrumSource {
    /// Description for the output.
    pub description: String,
    /// 1 nm table over 360–830 nm.
    pub table: [f64; LEN],
    /// Blackbody temperature, if the source is `blackbody:T`.
    pub blackbody_k: Option<f64>,
    /// True for reflectance spectra (ColorChecker, TCS, Cornell surfaces).
    pub reflectance: bool,
    /// A CSV file's largest sample interval when it is coarser than 5 nm (CIE 224 and TM-30
    /// need 5 nm or finer).
    pub coarse_nm: Option<f64>,
    /// What the output must say about how the source was resampled.
    pub warnings: Vec<String>,
}

fn parse_temperature(spec: &str, what: &str) -> anyhow::Result<f64> {
    let s = spec.trim();
    let s = s.strip_suffix(['K', 'k']).unwrap_or(s).trim();
    let t: f64 = s
        .parse()
        .with_context(|| format!("'{spec}' is not a temperature; write e.g. {what}:3000K"))?;
    if !(t.is_finite() && t > 0.0) {
        bail!("temperature {t} K must be a positive finite number");
    }
    Ok(t)
}

/// Resolves SOURCE: a two-column CSV file (nm, value), a named spectrum (see
/// [`named_spectrum_names`]), `blackbody:3000K` or `daylight:6504K`.
pub fn resolve_source(source: &str) -> anyhow::Result<SpectrumSource> {
    resolve_source_with(source, Interpolation::default())
}

/// [`resolve_source`] with a CSV file resampled by `interpolation`.
pub fn resolve_source_with(
    source: &str,
    interpolation: Interpolation,
) -> anyhow::Result<SpectrumSource> {
    let lower = source.trim().to_lowercase();
    if let Some(rest) = lower.strip_prefix("blackbody:") {
        let t = parse_temperature(rest, "blackbody")?;
        return Ok(SpectrumSource {
            description: format!(
                "blackbody at {} K (Planck's law, c2 = 1.4388e-2 m·K; spectral radiance in \
                 W·m⁻²·sr⁻¹·nm⁻¹)",
                if t < 1e7 {
                    format!("{t}")
                } else {
                    format!("{t:e}")
                }
            ),
            table: blackbody_table(t),
            blackbody_k: Some(t),
            reflectance: false,
            coarse_nm: None,
            warnings: Vec::new(),
        });
    }
    if let Some(rest) = lower.strip_prefix("daylight:") {
        let t = parse_temperature(rest, "daylight")?;
        if !(4000.0..=25000.0).contains(&t) {
            bail!("CIE daylight is defined for 4000 K to 25000 K; got {t} K");
        }
        return Ok(SpectrumSource {
            description: format!("CIE daylight illuminant at {t} K (relative, S(560) ≈ 100)"),
            table: sd_cie_daylight(t),
            blackbody_k: None,
            reflectance: false,
            coarse_nm: None,
            warnings: Vec::new(),
        });
    }
    if let Some(sd) = named_spectrum(source) {
        let reflectance = lower.starts_with("colorchecker:")
            || lower.starts_with("tcs")
            || (lower.starts_with("cornell-") && lower != "cornell-light");
        return Ok(SpectrumSource {
            description: format!("named spectrum {}", source.trim()),
            table: sd.to_table(),
            blackbody_k: None,
            reflectance,
            coarse_nm: None,
            warnings: Vec::new(),
        });
    }
    let path = Path::new(source);
    if !path.is_file() {
        bail!(
            "'{source}' is not an existing CSV file, a named spectrum, blackbody:<T>K or \
             daylight:<T>K.\nNamed spectra (case-insensitive): {}",
            named_spectrum_names().join(", ")
        );
    }
    let sd = SpectralDistribution::from_csv_path(path)?;
    sd.check_non_negative(&path.display().to_string())?;
    let first = sd.wavelengths_nm[0];
    let last = *sd.wavelengths_nm.last().unwrap();
    if last < START_NM as f64 || first > END_NM as f64 {
        bail!(
            "{}: the spectrum covers {first}–{last} nm, entirely outside candela's \
             {START_NM}–{END_NM} nm range",
            path.display()
        );
    }
    let step = sd.max_interval_nm();
    Ok(SpectrumSource {
        description: format!(
            "CSV file {} ({} samples, {first}–{last} nm, at most {step} nm apart, resampled by {} to 1 nm \
             over {START_NM}–{END_NM} nm, zero outside its range)",
            path.display(),
            sd.values.len(),
            sd.method(interpolation).name()
        ),
        table: sd.to_table_with(interpolation),
        blackbody_k: None,
        reflectance: false,
        coarse_nm: (step > COARSE_INTERVAL_NM).then_some(step),
        warnings: sd
            .coarse_linear_warning(&path.display().to_string(), interpolation)
            .into_iter()
            .collect(),
    })
}

/// The object colour of a reflectance under D65.
#[derive(Clone, Debug)]
pub struct ObjectColour {
    /// XYZ of the reflectance under D65 (Y of the perfect white = 100), in the chosen observer.
    pub xyz: [f64; 3],
    /// CIELAB with D65 (same observer) as white.
    pub lab: [f64; 3],
    /// Linear sRGB (CIE 1931 2°, Y of the white = 1).
    pub srgb_linear: [f64; 3],
    /// Encoded sRGB (IEC 61966-2-1).
    pub srgb_encoded: [f64; 3],
}

/// The colorimetry of a spectrum, treated as a light source (plus the object colour under D65
/// for reflectances).
#[derive(Clone, Debug)]
pub struct SpectrumColorimetry {
    /// XYZ normalised to Y = 100, in the chosen observer.
    pub xyz_y100: [f64; 3],
    /// Absolute XYZ, 683·Σ S x̄ Δλ (Y is the luminance in cd/m² if S is spectral radiance in
    /// W·m⁻²·sr⁻¹·nm⁻¹).
    pub xyz_absolute: [f64; 3],
    pub xy: [f64; 2],
    /// u′v′ (CIE 1976).
    pub upvp: [f64; 2],
    /// uv (CIE 1960).
    pub uv_1960: [f64; 2],
    /// CCT in K and Duv by Ohno (2013), CIE 1931 2°.
    pub cct_duv_ohno: [f64; 2],
    /// CCT in K and Duv by Robertson (1968), CIE 1931 2°.
    pub cct_duv_robertson: [f64; 2],
    /// Luminous efficacy of the radiation over 360–830 nm, lm/W.
    pub luminous_efficacy_lm_per_w: f64,
    pub sp_ratio: f64,
    /// Linear sRGB of the CIE 1931 2° XYZ scaled to Y = 1 (no adaptation).
    pub srgb_linear: [f64; 3],
    pub srgb_encoded: [f64; 3],
    /// CIE 13.3 colour rendering (light sources only).
    pub cri: Option<Cri>,
    /// Luminous efficacy of the whole blackbody spectrum (total radiance σT⁴/π), lm/W, for
    /// `blackbody:T` sources.
    pub blackbody_luminous_efficacy_lm_per_w: Option<f64>,
    /// Object colour under D65, for reflectances.
    pub object_under_d65: Option<ObjectColour>,
    /// Where a result is outside its method's domain: why it is not meaningful.
    pub notes: Vec<String>,
}

/// Colorimetry of `src`. XYZ, xy and u′v′ use `observer`; CCT, Duv, sRGB and the CRI are
/// defined for (and always use) the CIE 1931 2° observer. Refuses spectra that are zero
/// everywhere, not finite, or whose absolute XYZ overflows.
pub fn spectrum_colorimetry(
    src: &SpectrumSource,
    observer: Observer,
) -> anyhow::Result<SpectrumColorimetry> {
    let s = &src.table;
    if !s.iter().all(|v| v.is_finite()) {
        bail!(
            "{}: its values overflow 64-bit floats (not finite)",
            src.description
        );
    }
    // Everything but the absolute XYZ is independent of the spectrum's scale, so it is computed
    // from the spectrum divided by its peak: values near the ends of the f64 range (a CSV of
    // 1e305s or 1e-315s) then neither overflow nor lose precision in subnormals. A reflectance
    // keeps its scale (it is meaningful).
    let peak = s.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if peak == 0.0 {
        bail!(
            "{}: the spectrum is zero everywhere in {START_NM}–{END_NM} nm",
            src.description
        );
    }
    let xyz_abs = sd_to_xyz_absolute(s, observer);
    if !xyz_abs.iter().all(|v| v.is_finite()) {
        bail!(
            "{}: values up to {peak:e} overflow the absolute XYZ (683·Σ S x̄ Δλ) in 64-bit floats; scale the spectrum down (only its shape matters for xy, CCT and the indices)",
            src.description
        );
    }
    let scaled;
    let s = if src.reflectance {
        s
    } else {
        scaled = s.map(|v| v / peak);
        &scaled
    };
    let o2 = Observer::Cie1931_2;
    let xyz = sd_to_xyz_emissive(s, observer);
    let xyz_n = xyz.map(|v| v * 100.0 / xyz[1]);
    let xy = xyz_to_xy(xyz);
    let upvp = xyz_to_upvp(xyz);
    let uv = xyz_to_uv1960(xyz);
    let xyz2 = sd_to_xyz_emissive(s, o2);
    let uv2 = xyz_to_uv1960(xyz2);
    let ohno = uv_to_cct_ohno2013(uv2);
    let rob = uv_to_cct_robertson1968(uv2);
    let efficacy = luminous_efficacy(s);
    let sp = sp_ratio(s);
    let y2 = if xyz2[1] != 0.0 { xyz2[1] } else { 1.0 };
    let srgb_lin = xyz_to_linear_srgb(xyz2.map(|v| v / y2));
    let srgb_enc = srgb_lin.map(srgb_encode);
    let cri = (!src.reflectance).then(|| colour_rendering_index(s));
    let bb_eff = src.blackbody_k.map(blackbody_luminous_efficacy);
    // Object colour under D65 for reflectances.
    let object = src.reflectance.then(|| {
        let d65 = named_spectrum("D65").expect("D65").to_table();
        let xyz_o = sd_to_xyz_relative(s, &d65, observer);
        let white = xyz_to_xy(sd_to_xyz_emissive(&d65, observer));
        let lab = xyz_to_lab(xyz_o.map(|v| v / 100.0), white);
        let xyz_o2 = sd_to_xyz_relative(s, &d65, o2);
        let lin = xyz_to_linear_srgb(xyz_o2.map(|v| v / 100.0));
        ObjectColour {
            xyz: xyz_o,
            lab,
            srgb_linear: lin,
            srgb_encoded: lin.map(srgb_encode),
        }
    });

    // Where a result is outside its method's domain it is still printed (it is what
    // colour-science computes too), with a note saying why it is not meaningful.
    let mut notes: Vec<String> = Vec::new();
    // (One step of the table's 1.001 spacing beyond its ends is still interpolation noise.)
    if !(999.0..=100_100.0).contains(&ohno[0]) {
        notes.push(format!(
            "CCT (Ohno 2013) {:.1} K lies outside the 1000–100 000 K Planckian table: it is extrapolated and not meaningful",
            ohno[0]
        ));
    }
    if ohno[1].abs() > 0.05 {
        notes.push(format!(
            "Duv {:+.4}: the chromaticity is far from the Planckian locus (|Duv| > 0.05), where CCT is not defined (CIE 015)",
            ohno[1]
        ));
    }
    if rob[0] <= ROBERTSON_MIN_K {
        notes.push(format!(
            "CCT (Robertson 1968) is at its table's lower limit ({ROBERTSON_MIN_K:.0} K, 600 mired); the source's CCT is lower"
        ));
    }
    if let Some(c) = &cri {
        if xyz2[2] <= 1e-9 * xyz2[1] {
            notes.push("CRI: the source has no power where z̄ > 0 (Z ≈ 0), so CIE 13.3's chromatic adaptation is undefined; Ra and Ri are not meaningful".into());
        } else if c.cct_k <= ROBERTSON_MIN_K {
            notes.push(format!(
                "CRI: the reference illuminant is taken at the Robertson table's limit {ROBERTSON_MIN_K:.0} K although the source's CCT is lower, so Ra and Ri are not meaningful"
            ));
        }
    }

    Ok(SpectrumColorimetry {
        xyz_y100: xyz_n,
        xyz_absolute: xyz_abs,
        xy,
        upvp,
        uv_1960: uv,
        cct_duv_ohno: ohno,
        cct_duv_robertson: rob,
        luminous_efficacy_lm_per_w: efficacy,
        sp_ratio: sp,
        srgb_linear: srgb_lin,
        srgb_encoded: srgb_enc,
        cri,
        blackbody_luminous_efficacy_lm_per_w: bb_eff,
        object_under_d65: object,
        notes,
    })
}

/// Lowest CCT of the Robertson (1968) table: 600 mired.
const ROBERTSON_MIN_K: f64 = 1e6 / 600.0 + 1e-6;

/// Parses the `--observer` value: "1931" / "2" / "cie1931" → CIE 1931 2°, "1964" / "10" /
/// "cie1964" → CIE 1964 10°.
pub fn parse_observer(s: &str) -> anyhow::Result<Observer> {
    match s
        .trim()
        .to_lowercase()
        .replace([' ', '-', '_', '°'], "")
        .as_str()
    {
        "1931" | "2" | "cie1931" | "cie19312" => Ok(Observer::Cie1931_2),
        "1964" | "10" | "cie1964" | "cie196410" => Ok(Observer::Cie1964_10),
        _ => bail!("unknown observer '{s}': use 1931 (CIE 1931 2°) or 1964 (CIE 1964 10°)"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn observers() {
        assert_eq!(parse_observer("1931").unwrap(), Observer::Cie1931_2);
        assert_eq!(parse_observer("1964").unwrap(), Observer::Cie1964_10);
        assert!(parse_observer("1976").is_err());
    }
}
