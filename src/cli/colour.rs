//! `candela spectrum` and `candela convert`: the text and JSON they print (the values come
//! from [`candela::report::spectrum`] and [`candela::photometry`]). See `docs/colour.md`.
//!
//! `tests/colour_cli.rs` includes this file with `#[path]`, so it names the library only
//! through `candela::` paths.

use serde_json::json;

#[path = "colour/health.rs"]
pub mod health;
use health::SpectrumOptions;

use candela::colour::tables::Observer;

use candela::colour::cri::Cri;
use candela::colour::grid::{END_NM, START_NM};
use candela::colour::sd::Interpolation;
use candela::photometry::{Quantity, UNITS};
use candela::report::spectrum::{
    resolve_source_with, spectrum_colorimetry, ObjectColour, SpectrumColorimetry, SpectrumSource,
};

fn observer_name(o: Observer) -> &'static str {
    match o {
        Observer::Cie1931_2 => "CIE 1931 2°",
        Observer::Cie1964_10 => "CIE 1964 10°",
    }
}

/// `candela spectrum SOURCE [--observer 1931|1964] [--json]`.
///
/// SOURCE is a two-column CSV file (nm, value), a named spectrum (see
/// [`candela::colour::tables::named_spectrum_names`]), `blackbody:3000K` or `daylight:6504K`
/// ([`candela::report::spectrum::resolve_source`]).  The spectrum is treated as a light source (for reflectances the
/// object colour under D65 is added).  Returns the human-readable table, or JSON with the keys
/// documented in `docs/colour.md`.
///
/// XYZ, xy and u′v′ use `observer`; CCT, Duv, sRGB and the CRI are defined for (and always
/// use) the CIE 1931 2° observer.
/// The binary calls [`spectrum_command_with`]; the tests call this.
#[allow(dead_code)]
pub fn spectrum_command(source: &str, observer: Observer, json: bool) -> anyhow::Result<String> {
    spectrum_command_with(source, observer, json, &SpectrumOptions::default())
}

/// [`spectrum_command`] with the options of [`SpectrumOptions`]: lights also get their CIE
/// S 026 α-opic quantities and TM-30-20 / CIE 224:2017 colour rendition; `--method` and
/// `--efficacy-rule` add XYZ and efficacy by the chosen method; `--cvg` writes TM-30's colour
/// vector graphic.
pub fn spectrum_command_with(
    source: &str,
    observer: Observer,
    json: bool,
    opts: &SpectrumOptions,
) -> anyhow::Result<String> {
    let src = resolve_source_with(source, opts.interpolation)?;
    let c = spectrum_colorimetry(&src, observer)?;
    let extras = health::extras(&src.table, src.reflectance, observer, opts)?;
    let warnings = spectrum_warnings(source, &src, &extras, opts);
    for w in &warnings {
        eprintln!("warning: {}", candela::limits::printable(w, 4096));
    }
    if json {
        return spectrum_json(source, &src, observer, &c, &extras, &warnings);
    }
    let mut out = String::new();
    let mut line = |k: &str, v: String| out.push_str(&format!("{k:<34} {v}\n"));
    colorimetry_text(&mut line, &src, observer, &c);
    if let Some(cri) = &c.cri {
        cri_text(&mut line, cri);
    }
    if let Some(o) = &c.object_under_d65 {
        object_text(&mut line, o);
    }
    health::add_text(&mut line, &extras);
    for n in &c.notes {
        line("note", n.clone());
    }
    Ok(out)
}

/// The source's own warnings, and one when colour rendition is computed from samples coarser
/// than 5 nm.
fn spectrum_warnings(
    source: &str,
    src: &SpectrumSource,
    extras: &health::Extras,
    opts: &SpectrumOptions,
) -> Vec<String> {
    let mut warnings = src.warnings.clone();
    if let (Some(step), true) = (src.coarse_nm, extras.has_rendition()) {
        // colour-science refuses such data; interpolated to 1 nm it computes them, as here.
        warnings.push(format!(
            "{source}: CIE 224:2017 and TM-30 need spectral data at 5 nm or finer; the samples \
             are up to {step} nm apart, so Rf and Rg are those of the spectrum interpolated to \
             1 nm ({}), not of a measurement",
            match opts.interpolation {
                Interpolation::Linear => "linearly",
                Interpolation::Cie167 => "as CIE 167 recommends",
            }
        ));
    }
    warnings
}

/// `candela spectrum --json`: the keys documented in `docs/colour.md`.
fn spectrum_json(
    source: &str,
    src: &SpectrumSource,
    observer: Observer,
    c: &SpectrumColorimetry,
    extras: &health::Extras,
    warnings: &[String],
) -> anyhow::Result<String> {
    let (ohno, rob) = (c.cct_duv_ohno, c.cct_duv_robertson);
    let mut j = json!({
        "source": source,
        "description": src.description,
        "observer": match observer { Observer::Cie1931_2 => "1931", Observer::Cie1964_10 => "1964" },
        "xyz": c.xyz_y100,
        "xyz_absolute": c.xyz_absolute,
        "luminance_cd_m2_if_radiance": c.xyz_absolute[1],
        "xy": c.xy,
        "upvp": c.upvp,
        "uv_1960": c.uv_1960,
        "cct_k": ohno[0],
        "duv": ohno[1],
        "cct_robertson_k": rob[0],
        "duv_robertson": rob[1],
        "luminous_efficacy_lm_per_w": c.luminous_efficacy_lm_per_w,
        "sp_ratio": c.sp_ratio,
        "srgb_linear": c.srgb_linear,
        "srgb_encoded": c.srgb_encoded,
        "notes": c.notes,
        "warnings": warnings,
    });
    if let Some(e) = c.blackbody_luminous_efficacy_lm_per_w {
        j["blackbody_luminous_efficacy_lm_per_w"] = json!(e);
    }
    if let Some(cri) = &c.cri {
        j["cri"] = json!({"ra": cri.ra, "r": cri.r, "cct_k": cri.cct_k,
            "reference": if cri.reference_is_blackbody { "blackbody" } else { "CIE daylight" }});
    }
    if let Some(o) = &c.object_under_d65 {
        j["object_under_d65"] = json!({"xyz": o.xyz, "lab": o.lab, "srgb_linear": o.srgb_linear,
            "srgb_encoded": o.srgb_encoded});
    }
    health::add_json(&mut j, extras);
    Ok(serde_json::to_string_pretty(&j)? + "\n")
}

/// The text lines of the colorimetry every spectrum gets: XYZ to sRGB.
fn colorimetry_text(
    line: &mut dyn FnMut(&str, String),
    src: &SpectrumSource,
    observer: Observer,
    c: &SpectrumColorimetry,
) {
    let (xyz_n, xyz_abs, xy, upvp, uv) = (c.xyz_y100, c.xyz_absolute, c.xy, c.upvp, c.uv_1960);
    let (ohno, rob) = (c.cct_duv_ohno, c.cct_duv_robertson);
    let (efficacy, sp) = (c.luminous_efficacy_lm_per_w, c.sp_ratio);
    let (srgb_lin, srgb_enc) = (c.srgb_linear, c.srgb_encoded);
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
    if let Some(e) = c.blackbody_luminous_efficacy_lm_per_w {
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
}

/// The text lines of the CIE 13.3 colour rendering index.
fn cri_text(line: &mut dyn FnMut(&str, String), c: &Cri) {
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

/// The text lines of a reflectance's colour under D65.
fn object_text(line: &mut dyn FnMut(&str, String), o: &ObjectColour) {
    let (xyz_o, lab, lin, enc) = (o.xyz, o.lab, o.srgb_linear, o.srgb_encoded);
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

/// `candela convert VALUE FROM TO`: photometric unit conversion (see
/// [`candela::photometry::convert`] and the unit table in `docs/colour.md`).  Returns one
/// line, e.g. `100 footcandle = 1076.391041670972 lux`.
pub fn convert_command(value: f64, from: &str, to: &str) -> anyhow::Result<String> {
    let v = candela::photometry::convert(value, from, to)?;
    let f = candela::photometry::parse_unit(from)?;
    let t = candela::photometry::parse_unit(to)?;
    Ok(format!(
        "{value} {} = {v} {} ({})\n",
        f.name,
        t.name,
        f.quantity.name()
    ))
}

/// Human-readable list of the units `convert` accepts, grouped by quantity. No subcommand
/// prints it yet; its test keeps the list complete.
#[allow(dead_code)]
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
