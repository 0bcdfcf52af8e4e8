//! Library side of the `candela spectrum` and `candela convert` commands (the binary only
//! parses arguments and prints the returned text).  See `docs/colour.md`.

use std::path::Path;

use anyhow::{bail, Context};
use serde_json::json;

use crate::colour::colorimetry::{sd_to_xyz_absolute, sd_to_xyz_emissive, sd_to_xyz_relative};
use crate::colour::cri::colour_rendering_index;
use crate::colour::illuminants::sd_cie_daylight;
use crate::colour::models::{xyz_to_lab, xyz_to_upvp, xyz_to_uv1960, xyz_to_xy};
use crate::colour::planck::blackbody_table;
use crate::colour::rgb::{srgb_encode, xyz_to_linear_srgb};
use crate::colour::sd::SpectralDistribution;
use crate::colour::tables::{
    named_spectrum, named_spectrum_names, Observer, END_NM, LEN, START_NM,
};
use crate::colour::temperature::{uv_to_cct_ohno2013, uv_to_cct_robertson1968};
use crate::photometry::{
    blackbody_luminous_efficacy, luminous_efficacy, sp_ratio, Quantity, UNITS,
};

/// What a SOURCE argument resolved to.
struct Source {
    /// Description for the output.
    description: String,
    /// 1 nm table over 360–830 nm.
    table: [f64; LEN],
    /// Blackbody temperature, if the source is `blackbody:T`.
    blackbody_k: Option<f64>,
    /// True for reflectance spectra (ColorChecker, TCS, Cornell surfaces).
    reflectance: bool,
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

fn resolve(source: &str) -> anyhow::Result<Source> {
    let lower = source.trim().to_lowercase();
    if let Some(rest) = lower.strip_prefix("blackbody:") {
        let t = parse_temperature(rest, "blackbody")?;
        return Ok(Source {
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
        });
    }
    if let Some(rest) = lower.strip_prefix("daylight:") {
        let t = parse_temperature(rest, "daylight")?;
        if !(4000.0..=25000.0).contains(&t) {
            bail!("CIE daylight is defined for 4000 K to 25000 K; got {t} K");
        }
        return Ok(Source {
            description: format!("CIE daylight illuminant at {t} K (relative, S(560) ≈ 100)"),
            table: sd_cie_daylight(t),
            blackbody_k: None,
            reflectance: false,
        });
    }
    if let Some(sd) = named_spectrum(source) {
        let reflectance = lower.starts_with("colorchecker:")
            || lower.starts_with("tcs")
            || (lower.starts_with("cornell-") && lower != "cornell-light");
        return Ok(Source {
            description: format!("named spectrum {}", source.trim()),
            table: sd.to_table(),
            blackbody_k: None,
            reflectance,
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
    Ok(Source {
        description: format!(
            "CSV file {} ({} samples, {first}–{last} nm, linearly interpolated to 1 nm over \
             {START_NM}–{END_NM} nm, zero outside its range)",
            path.display(),
            sd.values.len()
        ),
        table: sd.to_table(),
        blackbody_k: None,
        reflectance: false,
    })
}

fn observer_name(o: Observer) -> &'static str {
    match o {
        Observer::Cie1931_2 => "CIE 1931 2°",
        Observer::Cie1964_10 => "CIE 1964 10°",
    }
}

/// `candela spectrum SOURCE [--observer 1931|1964] [--json]`.
///
/// SOURCE is a two-column CSV file (nm, value), a named spectrum (see
/// [`named_spectrum_names`]), `blackbody:3000K` or `daylight:6504K`.  The spectrum is treated
/// as a light source (for reflectances the object colour under D65 is added).  Returns the
/// human-readable table, or JSON with the keys documented in `docs/colour.md`.
///
/// XYZ, xy and u′v′ use `observer`; CCT, Duv, sRGB and the CRI are defined for (and always
/// use) the CIE 1931 2° observer.
pub fn spectrum_command(source: &str, observer: Observer, json: bool) -> anyhow::Result<String> {
    let src = resolve(source)?;
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
        (xyz_o, lab, lin, lin.map(srgb_encode))
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

    if json {
        let mut j = json!({
            "source": source,
            "description": src.description,
            "observer": match observer { Observer::Cie1931_2 => "1931", Observer::Cie1964_10 => "1964" },
            "xyz": xyz_n,
            "xyz_absolute": xyz_abs,
            "luminance_cd_m2_if_radiance": xyz_abs[1],
            "xy": xy,
            "upvp": upvp,
            "uv_1960": uv,
            "cct_k": ohno[0],
            "duv": ohno[1],
            "cct_robertson_k": rob[0],
            "duv_robertson": rob[1],
            "luminous_efficacy_lm_per_w": efficacy,
            "sp_ratio": sp,
            "srgb_linear": srgb_lin,
            "srgb_encoded": srgb_enc,
            "notes": notes,
        });
        if let Some(e) = bb_eff {
            j["blackbody_luminous_efficacy_lm_per_w"] = json!(e);
        }
        if let Some(c) = &cri {
            j["cri"] = json!({"ra": c.ra, "r": c.r, "cct_k": c.cct_k,
                "reference": if c.reference_is_blackbody { "blackbody" } else { "CIE daylight" }});
        }
        if let Some((xyz_o, lab, lin, enc)) = object {
            j["object_under_d65"] =
                json!({"xyz": xyz_o, "lab": lab, "srgb_linear": lin, "srgb_encoded": enc});
        }
        return Ok(serde_json::to_string_pretty(&j)? + "\n");
    }

    let mut out = String::new();
    let mut line = |k: &str, v: String| out.push_str(&format!("{k:<34} {v}\n"));
    line("source", src.description.clone());
    line(
        "observer",
        format!(
            "{} (CCT, Duv, sRGB, CRI: CIE 1931 2°)",
            observer_name(observer)
        ),
    );
    line(
        "XYZ (Y = 100)",
        format!("{:.6} {:.6} {:.6}", xyz_n[0], xyz_n[1], xyz_n[2]),
    );
    line(
        "XYZ absolute (683·Σ S x̄ Δλ)",
        format!("{:.6e} {:.6e} {:.6e}", xyz_abs[0], xyz_abs[1], xyz_abs[2]),
    );
    line(
        "  luminance if S is radiance",
        format!("{:.6e} cd/m² (W·m⁻²·sr⁻¹·nm⁻¹ input)", xyz_abs[1]),
    );
    line("xy", format!("{:.6} {:.6}", xy[0], xy[1]));
    line("u'v' (CIE 1976)", format!("{:.6} {:.6}", upvp[0], upvp[1]));
    line("uv (CIE 1960)", format!("{:.6} {:.6}", uv[0], uv[1]));
    line(
        "CCT, Duv (Ohno 2013)",
        format!("{:.1} K, {:+.5}", ohno[0], ohno[1]),
    );
    line(
        "CCT, Duv (Robertson 1968)",
        format!("{:.1} K, {:+.5}", rob[0], rob[1]),
    );
    line(
        "luminous efficacy of radiation",
        format!("{efficacy:.3} lm/W (radiant power over {START_NM}–{END_NM} nm)"),
    );
    if let Some(e) = bb_eff {
        line(
            "  of the whole blackbody spectrum",
            format!("{e:.3} lm/W (total radiance σT⁴/π)"),
        );
    }
    line("S/P ratio", format!("{sp:.4}"));
    line(
        "sRGB linear (Y = 1, no adaptation)",
        format!("{:.6} {:.6} {:.6}", srgb_lin[0], srgb_lin[1], srgb_lin[2]),
    );
    line(
        "sRGB encoded (IEC 61966-2-1)",
        format!("{:.6} {:.6} {:.6}", srgb_enc[0], srgb_enc[1], srgb_enc[2]),
    );
    if let Some(c) = &cri {
        line(
            "CRI (CIE 13.3) Ra",
            format!(
                "{:.2} (reference: {} at {:.0} K)",
                c.ra,
                if c.reference_is_blackbody {
                    "blackbody"
                } else {
                    "CIE daylight"
                },
                c.cct_k
            ),
        );
        let r: Vec<String> =
            c.r.iter()
                .enumerate()
                .map(|(i, v)| format!("R{}={v:.2}", i + 1))
                .collect();
        line("  R1–R7", r[..7].join(" "));
        line("  R8–R14", r[7..].join(" "));
    }
    if let Some((xyz_o, lab, lin, enc)) = object {
        line(
            "reflectance under D65: XYZ",
            format!("{:.6} {:.6} {:.6}", xyz_o[0], xyz_o[1], xyz_o[2]),
        );
        line(
            "  CIELAB (D65 white)",
            format!("{:.4} {:.4} {:.4}", lab[0], lab[1], lab[2]),
        );
        line(
            "  sRGB linear / encoded",
            format!(
                "{:.6} {:.6} {:.6} / {:.6} {:.6} {:.6}",
                lin[0], lin[1], lin[2], enc[0], enc[1], enc[2]
            ),
        );
    }
    for n in &notes {
        line("note", n.clone());
    }
    Ok(out)
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

/// `candela convert VALUE FROM TO`: photometric unit conversion (see
/// [`crate::photometry::convert`] and the unit table in `docs/colour.md`).  Returns one
/// line, e.g. `100 footcandle = 1076.391041670972 lux`.
pub fn convert_command(value: f64, from: &str, to: &str) -> anyhow::Result<String> {
    let v = crate::photometry::convert(value, from, to)?;
    let f = crate::photometry::parse_unit(from)?;
    let t = crate::photometry::parse_unit(to)?;
    Ok(format!(
        "{value} {} = {v} {} ({})\n",
        f.name,
        t.name,
        f.quantity.name()
    ))
}

/// Human-readable list of the units `convert` accepts, grouped by quantity.
pub fn units_help() -> String {
    let mut out = String::new();
    for q in [
        Quantity::Illuminance,
        Quantity::Luminance,
        Quantity::LuminousFlux,
        Quantity::LuminousIntensity,
        Quantity::LuminousEnergy,
    ] {
        let names: Vec<String> = UNITS
            .iter()
            .filter(|u| u.quantity == q)
            .map(|u| format!("{} ({})", u.name, u.symbol))
            .collect();
        out.push_str(&format!("{}: {}\n", q.name(), names.join(", ")));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spectrum_named_and_blackbody() {
        let t = spectrum_command("D65", Observer::Cie1931_2, false).unwrap();
        assert!(
            t.contains("CCT") && t.contains("Ra") && t.contains("R14="),
            "{t}"
        );
        let j = spectrum_command("blackbody:2856K", Observer::Cie1931_2, true).unwrap();
        let v: serde_json::Value = serde_json::from_str(&j).unwrap();
        assert!((v["cct_k"].as_f64().unwrap() - 2856.0).abs() < 1.0);
        assert!(v["duv"].as_f64().unwrap().abs() < 1e-4);
        assert!((v["cri"]["ra"].as_f64().unwrap() - 100.0).abs() < 0.05);
        // Luminous efficacy of blackbody radiation, K = K_m Σ L_λ V Δλ (360–830 nm, 1 nm) /
        // (σT⁴/π). candela, like colour-science, uses CIE 015's radiation constants
        // (c1 = 3.741771e-16 W·m², c2 = 1.4388e-2 m·K, σ = π⁴c1/(15c2⁴)); colour-science 0.4.7
        // `planck_law` with those constants and its photopic V gives 16.4449497 lm/W at 2856 K
        // (computed in target/venv). closed-forms.md §2.9 lists 16.446 from CODATA 2018
        // constants, 6.4e-5 higher; photometry.rs's table test allows for that difference.
        let k = v["blackbody_luminous_efficacy_lm_per_w"].as_f64().unwrap();
        let k_ref = 16.444_949_7;
        assert!(
            (k / k_ref - 1.0).abs() <= 1e-6,
            "blackbody 2856 K efficacy {k} lm/W vs colour-science {k_ref} lm/W \
             (difference {:+.2e} relative)",
            k / k_ref - 1.0
        );
    }

    #[test]
    fn colorchecker_dark_skin_lab() {
        // ColorChecker "dark skin" (colour-science "ColorChecker N Ohta" spectrum) under D65,
        // CIE 1964 10° observer, 1 nm integration, white = D65 under the same observer:
        // colour-science 0.4.7 `XYZ_to_Lab(sd_to_XYZ(sd, cmfs_10, D65, method="Integration")
        // / 100, xy(D65, 10°))` = (36.785872, 13.942426, 14.586083). Both use the same 1 nm
        // tables, so they agree to rounding; 1e-4 in L*, a*, b* is far below any data error
        // (a 1 % error in Y moves L* by ~0.3).
        let j = spectrum_command("colorchecker:dark skin", Observer::Cie1964_10, true).unwrap();
        let v: serde_json::Value = serde_json::from_str(&j).unwrap();
        let lab_ref = [36.785872, 13.942426, 14.586083];
        for (i, r) in lab_ref.iter().enumerate() {
            let l = v["object_under_d65"]["lab"][i].as_f64().unwrap();
            assert!(
                (l - r).abs() < 1e-4,
                "dark skin CIELAB[{i}] {l} vs colour-science {r}"
            );
        }
    }

    #[test]
    fn spectrum_errors() {
        let e = spectrum_command("no-such-thing", Observer::Cie1931_2, false).unwrap_err();
        assert!(e.to_string().contains("Named spectra") && e.to_string().contains("D65"));
        let e = spectrum_command("blackbody:-5K", Observer::Cie1931_2, false).unwrap_err();
        assert!(e.to_string().contains("positive"), "{e}");
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("neg.csv");
        std::fs::write(&p, "nm,v\n400,1\n500,-2\n").unwrap();
        let e = spectrum_command(p.to_str().unwrap(), Observer::Cie1931_2, false).unwrap_err();
        assert!(e.to_string().contains("negative"), "{e}");
        std::fs::write(&p, "nm,v\n400,1\n390,2\n").unwrap();
        let e = spectrum_command(p.to_str().unwrap(), Observer::Cie1931_2, false).unwrap_err();
        assert!(e.to_string().contains("line 3"), "{e}");
        std::fs::write(&p, "400,0\n500,0\n").unwrap();
        assert!(spectrum_command(p.to_str().unwrap(), Observer::Cie1931_2, false).is_err());
        std::fs::write(&p, "400,1\n500,1\n600,1\n").unwrap();
        assert!(spectrum_command(p.to_str().unwrap(), Observer::Cie1931_2, false).is_ok());
        // Sums that overflow f64 are refused rather than printed as inf and NaN; the scale-free
        // results of huge and tiny spectra are those of the same shape at a normal scale.
        std::fs::write(&p, "nm,v\n400,1e308\n700,1e308\n").unwrap();
        let e = spectrum_command(p.to_str().unwrap(), Observer::Cie1931_2, true).unwrap_err();
        assert!(e.to_string().contains("overflow"), "{e}");
        let flat = |v: &str| {
            std::fs::write(&p, format!("nm,v\n360,{v}\n830,{v}\n")).unwrap();
            let j = spectrum_command(p.to_str().unwrap(), Observer::Cie1931_2, true);
            j.map(|j| serde_json::from_str::<serde_json::Value>(&j).unwrap())
        };
        let one = flat("1").unwrap();
        for v in ["1e-315", "1e300"] {
            let j = flat(v).unwrap();
            for key in [
                "xy",
                "cct_k",
                "duv",
                "sp_ratio",
                "luminous_efficacy_lm_per_w",
            ] {
                assert_eq!(j[key], one[key], "{v}: {key}");
            }
            assert_eq!(j["cri"]["ra"], one["cri"]["ra"], "{v}: Ra");
        }
        assert!(flat("1e305").unwrap_err().to_string().contains("overflow"));
        let e = spectrum_command("blackbody:1e300K", Observer::Cie1931_2, false).unwrap_err();
        assert!(
            e.to_string().contains("overflow") && e.to_string().contains("1e300 K"),
            "{e}"
        );
    }

    #[test]
    fn notes_flag_values_outside_their_methods_domain() {
        let notes = |src: &str| -> Vec<String> {
            let j = spectrum_command(src, Observer::Cie1931_2, true).unwrap();
            let v: serde_json::Value = serde_json::from_str(&j).unwrap();
            v["notes"]
                .as_array()
                .unwrap()
                .iter()
                .map(|n| n.as_str().unwrap().to_string())
                .collect()
        };
        assert!(notes("blackbody:2856K").is_empty());
        assert!(notes("D65").is_empty());
        let cool = notes("blackbody:1200K");
        assert!(cool.iter().any(|n| n.contains("Robertson")), "{cool:?}");
        assert!(cool.iter().any(|n| n.starts_with("CRI")), "{cool:?}");
        assert!(notes("blackbody:150000K")
            .iter()
            .any(|n| n.contains("outside the 1000–100 000 K")));
        // A deep-red line: no power where z̄ > 0 (and a CCT far below the table).
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("red.csv");
        std::fs::write(&p, "nm,v\n688,0\n690,1\n692,0\n").unwrap();
        let red = notes(p.to_str().unwrap());
        assert!(red.iter().any(|n| n.contains("Z ≈ 0")), "{red:?}");
        assert!(red.iter().any(|n| n.contains("extrapolated")), "{red:?}");
        // A green line lies far above the Planckian locus.
        std::fs::write(&p, "nm,v\n528,0\n530,1\n532,0\n").unwrap();
        let green = notes(p.to_str().unwrap());
        assert!(
            green.iter().any(|n| n.contains("|Duv| > 0.05")),
            "{green:?}"
        );
    }

    #[test]
    fn observers() {
        assert_eq!(parse_observer("1931").unwrap(), Observer::Cie1931_2);
        assert_eq!(parse_observer("1964").unwrap(), Observer::Cie1964_10);
        assert!(parse_observer("1976").is_err());
    }

    #[test]
    fn convert() {
        let s = convert_command(100.0, "fc", "lux").unwrap();
        assert!(s.starts_with("100 footcandle = "), "{s}");
        // The value (100 fc = 1076.391041670972 lx, 1 ft = 0.3048 m exactly) is checked with
        // every other conversion in tests/colour_cli.rs.
        let e = convert_command(1.0, "lux", "nit").unwrap_err();
        assert!(e.to_string().contains("different quantities"), "{e}");
        assert!(convert_command(1.0, "lux", "bogus").is_err());
        assert!(units_help().contains("talbot"));
    }
}
