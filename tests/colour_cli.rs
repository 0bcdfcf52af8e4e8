//! The library side of `candela spectrum` / `candela convert`: output shape, the JSON keys
//! documented in docs/colour.md, and their values against closed forms.
//!
//! References:
//! * closed-forms.md (the project's reference of closed forms) §2.1 (photometric quantities, K_m = 683 lm/W,
//!   K′_m = 1700 lm/W, Y = K_m ∫ L ȳ dλ with no normalisation) and §2.9 (luminous efficacy of
//!   blackbody radiation K = K_m Σ L_λ V Δλ (360–830 nm, 1 nm) / (σT⁴/π), printed to 3
//!   decimals; scotopic efficacy with K′_m = 1700 and V′ on 380–780 nm).
//! * The S/P ratio definition (K′_m ∫ S V′)/(K_m ∫ S V) (IES TM-12-12), evaluated here from the
//!   1 nm tables that tests/colour_science.rs validates against colour-science.
//! * Exact unit definitions (NIST SP 811, 1 ft = 0.3048 m): 1 fc = 1 lm/ft², 1 fL = (1/π)
//!   cd/ft².

#[path = "../src/cli/colour.rs"]
#[allow(dead_code)]
mod colour;

use candela::colour::tables::{cmfs, named_spectrum, photopic_v, scotopic_v, Observer};

use candela::colour::grid::LEN;
use colour::{convert_command, spectrum_command};
use serde_json::Value;

fn json(source: &str, observer: Observer) -> Value {
    serde_json::from_str(&spectrum_command(source, observer, true).unwrap()).unwrap()
}

fn num(j: &Value, k: &str) -> f64 {
    j[k].as_f64()
        .unwrap_or_else(|| panic!("{k} is not a number: {}", j[k]))
}

fn arr(j: &Value, k: &str) -> Vec<f64> {
    j[k].as_array()
        .unwrap_or_else(|| panic!("{k} is not an array"))
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

fn close(what: &str, got: f64, want: f64, rel: f64) {
    assert!(
        (got - want).abs() <= rel * want.abs(),
        "{what}: {got} vs expected {want} (relative difference {:+.3e}, tolerance {rel:e})",
        got / want - 1.0
    );
}

fn dot(a: &[f64; LEN], b: &[f64; LEN]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Parses "VALUE FROM = RESULT TO (…)" from `convert_command`.
fn converted(s: &str) -> f64 {
    s.split('=')
        .nth(1)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

#[test]
fn spectrum_text_and_json_keys() {
    let text = spectrum_command("FL2", Observer::Cie1931_2, false).unwrap();
    println!("{text}");
    for k in [
        "XYZ (Y = 100)",
        "xy",
        "u'v'",
        "CCT, Duv (Ohno 2013)",
        "S/P ratio",
        "sRGB encoded",
        "Ra",
    ] {
        assert!(text.contains(k), "missing {k}");
    }
    let j = json("LED-B3", Observer::Cie1964_10);
    for k in [
        "source",
        "description",
        "observer",
        "xyz",
        "xyz_absolute",
        "luminance_cd_m2_if_radiance",
        "xy",
        "upvp",
        "uv_1960",
        "cct_k",
        "duv",
        "cct_robertson_k",
        "duv_robertson",
        "luminous_efficacy_lm_per_w",
        "sp_ratio",
        "srgb_linear",
        "srgb_encoded",
        "cri",
        "alpha_opic",
        "colour_rendition",
    ] {
        assert!(j.get(k).is_some(), "JSON key {k} missing");
    }
    // Reflectances get neither α-opic quantities nor colour rendition.
    let r = json("colorchecker:1", Observer::Cie1931_2);
    assert!(r.get("alpha_opic").is_none() && r.get("colour_rendition").is_none());
    assert_eq!(j["cri"]["r"].as_array().unwrap().len(), 14);
}

/// The photometric keys of a JSON report against the definitions, evaluated independently
/// here from the 1 nm tables (validated against colour-science by tests/colour_science.rs):
/// xyz_absolute = K_m Σ S x̄ Δλ with K_m = 683 (closed-forms.md §2.1: no 100/ΣSȳ
/// normalisation), luminance_cd_m2_if_radiance = its Y, xyz = 100·xyz_absolute/Y_abs,
/// xy = (X, Y)/(X + Y + Z), efficacy = K_m Σ S V / Σ S (radiant power over 360–830 nm,
/// docs/colour.md), S/P = (1700 Σ S V′)/(683 Σ S V). The sums are the same 471 products as
/// candela's, so only summation order differs: relative 1e-12.
fn check_photometric_keys(source: &str, observer: Observer) {
    let j = json(source, observer);
    let s = match source.strip_prefix("blackbody:") {
        Some(t) => {
            candela::colour::planck::blackbody_table(t.trim_end_matches('K').parse().unwrap())
        }
        None => named_spectrum(source).unwrap().to_table(),
    };
    let c = cmfs(observer);
    let sums = [dot(&s, &c.x), dot(&s, &c.y), dot(&s, &c.z)];
    let xyz_abs = arr(&j, "xyz_absolute");
    for i in 0..3 {
        close(
            &format!("{source}: xyz_absolute[{i}] = 683 Σ S cmf"),
            xyz_abs[i],
            683.0 * sums[i],
            1e-12,
        );
    }
    close(
        &format!("{source}: luminance_cd_m2_if_radiance = Y_abs"),
        num(&j, "luminance_cd_m2_if_radiance"),
        683.0 * sums[1],
        1e-12,
    );
    let xyz = arr(&j, "xyz");
    for i in 0..3 {
        close(
            &format!("{source}: xyz[{i}] (Y = 100)"),
            xyz[i],
            100.0 * sums[i] / sums[1],
            1e-12,
        );
    }
    let xy = arr(&j, "xy");
    let total: f64 = sums.iter().sum();
    close(&format!("{source}: x"), xy[0], sums[0] / total, 1e-12);
    close(&format!("{source}: y"), xy[1], sums[1] / total, 1e-12);
    let sv = dot(&s, photopic_v());
    let svp = dot(&s, scotopic_v());
    let power: f64 = s.iter().sum();
    close(
        &format!("{source}: luminous efficacy of radiation (360–830 nm)"),
        num(&j, "luminous_efficacy_lm_per_w"),
        683.0 * sv / power,
        1e-12,
    );
    close(
        &format!("{source}: S/P ratio"),
        num(&j, "sp_ratio"),
        1700.0 * svp / (683.0 * sv),
        1e-12,
    );
}

#[test]
fn photometric_keys_match_their_definitions() {
    check_photometric_keys("A", Observer::Cie1931_2);
    check_photometric_keys("LED-B3", Observer::Cie1964_10);
    check_photometric_keys("FL2", Observer::Cie1931_2);
    check_photometric_keys("D65", Observer::Cie1964_10);
    check_photometric_keys("blackbody:2856K", Observer::Cie1931_2);
    // Sanity of the independent sums themselves: V = ȳ (1931) to 5e-13 (closed-forms.md §2.1).
    let c = cmfs(Observer::Cie1931_2);
    for i in 0..LEN {
        assert!((photopic_v()[i] - c.y[i]).abs() < 5e-13);
    }
}

#[test]
fn blackbody_2856k_against_closed_forms() {
    // closed-forms.md §2.9, T = 2856 K (illuminant A's temperature): photopic K = 16.446 lm/W,
    // scotopic K′ = 23.230 lm/W, both over the *whole* blackbody radiance σT⁴/π. Printed to 3
    // decimals, so each is known to ±0.0005 lm/W: 3.04e-5 relative for K, 2.15e-5 for K′.
    let j = json("blackbody:2856K", Observer::Cie1931_2);
    let (k, kp) = (16.446, 23.230);
    let (ek, ekp) = (0.0005 / k, 0.0005 / kp);
    // S/P of a blackbody = K′/K (the σT⁴ denominators cancel): 1.412501, known to ek + ekp.
    close(
        "blackbody 2856 K S/P ratio vs K′/K of closed-forms.md §2.9",
        num(&j, "sp_ratio"),
        kp / k,
        ek + ekp,
    );
    // The efficacy itself: closed-forms.md computes σT⁴ and L_λ from CODATA 2018 constants,
    // candela (as colour-science) from CIE 015's c1 = 3.741771e-16 W·m², c2 = 1.4388e-2 m·K,
    // which gives 16.44495 lm/W (colour-science 0.4.7's `planck_law`, same sums), 6.4e-5 below
    // the table; up to 1.4e-4 over §2.9's temperatures (see photometry.rs). Allow for that
    // difference of constants plus the table's rounding.
    close(
        "blackbody 2856 K luminous efficacy (σT⁴/π denominator) vs closed-forms.md §2.9",
        num(&j, "blackbody_luminous_efficacy_lm_per_w"),
        k,
        ek + 1.5e-4,
    );
}

#[test]
fn convert_against_exact_unit_definitions() {
    // 1 ft = 0.3048 m exactly (NIST SP 811).
    let ft2 = 0.3048f64 * 0.3048;
    let pi = std::f64::consts::PI;
    for (v, from, to, want) in [
        // 1 fL = (1/π) cd/ft² = 3.426259 cd/m².
        (1.0, "footlambert", "nit", 1.0 / (pi * ft2)),
        (1.0, "nit", "footlambert", pi * ft2),
        // 1 fc = 1 lm/ft² = 10.763910 lx.
        (1.0, "fc", "lux", 1.0 / ft2),
        (100.0, "fc", "lux", 100.0 / ft2),
        (1.0, "lux", "fc", ft2),
    ] {
        let s = convert_command(v, from, to).unwrap();
        print!("{s}");
        close(&format!("{v} {from} → {to}"), converted(&s), want, 1e-12);
    }
    close("1 fL", 1.0 / (pi * ft2), 3.426_259_099_635_39, 1e-12);
    close("1 fc", 1.0 / ft2, 10.763_910_416_709_722, 1e-12);
}

#[test]
fn coarse_csv_interpolation_and_warnings() {
    use candela::colour::sd::Interpolation;
    use colour::health::SpectrumOptions;
    // LED-B3 sampled every 10 nm over 380–780 nm. colour-science 0.4.7 refuses CIE 2017 for
    // it; after `sd.interpolate(SpectralShape(380, 780, 1))` (Sprague) its
    // colour_fidelity_index_ANSIIESTM3018 gives Rf 85.330047305, Rg 97.854788808 (computed in
    // target/venv). tests/colour_health.rs compares 1 nm TM-30 to 1e-6.
    let dir = tempfile::tempdir().unwrap();
    let led = named_spectrum("LED-B3").unwrap();
    let csv = |step: usize| {
        let p = dir.path().join(format!("led-{step}nm.csv"));
        let text: String = (380..=780)
            .step_by(step)
            .map(|l| format!("{l},{}\n", led.value(l as f64)))
            .collect();
        std::fs::write(&p, format!("nm,value\n{text}")).unwrap();
        p
    };
    let run = |p: &std::path::Path, interpolation| -> Value {
        let opts = SpectrumOptions {
            interpolation,
            ..Default::default()
        };
        let s =
            colour::spectrum_command_with(p.to_str().unwrap(), Observer::Cie1931_2, true, &opts)
                .unwrap();
        serde_json::from_str(&s).unwrap()
    };
    let warnings = |j: &Value| -> Vec<String> {
        j["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .map(|w| w.as_str().unwrap().to_string())
            .collect()
    };
    let p10 = csv(10);
    let j = run(&p10, Interpolation::default());
    let rf = j["colour_rendition"]["rf"].as_f64().unwrap();
    let rg = j["colour_rendition"]["rg"].as_f64().unwrap();
    assert!((rf - 85.330_047_305).abs() <= 1e-6, "Rf {rf}");
    assert!((rg - 97.854_788_808).abs() <= 1e-6, "Rg {rg}");
    let w = warnings(&j);
    assert!(
        w.len() == 1
            && w[0].contains("10 nm")
            && w[0].contains("CIE 224")
            && w[0].contains("CIE 167"),
        "{w:?}"
    );
    assert!(
        j["description"].as_str().unwrap().contains("Sprague"),
        "{}",
        j["description"]
    );
    // Linear on request: the CSV and its interval named, and Rf moves by 0.24.
    let j = run(&p10, Interpolation::Linear);
    let w = warnings(&j);
    assert!(
        w.iter()
            .any(|w| w.contains("led-10nm.csv") && w.contains("10 nm") && w.contains("linear")),
        "{w:?}"
    );
    let rf_lin = j["colour_rendition"]["rf"].as_f64().unwrap();
    assert!(
        (rf_lin - rf).abs() > 0.1,
        "linear Rf {rf_lin} vs CIE 167 {rf}"
    );
    // 5 nm data: nothing to say, either way.
    let p5 = csv(5);
    assert!(warnings(&run(&p5, Interpolation::Linear)).is_empty());
    assert!(warnings(&run(&p5, Interpolation::Cie167)).is_empty());
}
