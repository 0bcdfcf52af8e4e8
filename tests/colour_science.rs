//! Validation of candela's colour library against colour-science 0.4.7.
//!
//! The test builds a battery of cases (every illuminant in data/, blackbodies 1000–25000 K,
//! CIE daylight at several CCTs, the 24 ColorChecker patches under D65, A and FL2 for both
//! observers, narrow spectral lines across 360–830 nm, seeded random smooth spectra),
//! computes every quantity with candela, asks `scripts/colour_reference.py` (run with the
//! pinned colour-science in the project venv) for the same quantities, and fails on any
//! deviation beyond the tolerance each check gives.  It prints the number of cases and the
//! largest deviation per quantity.
//!
//! Python: `$CANDELA_PYTHON` if set, else `<repo>/target/venv/bin/python` (created by
//! `scripts/setup_python.sh`).  A missing interpreter is a failure, not a skip.

mod common;
use common::python;

use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Stdio};

use candela::colour::adaptation::Cat;
use candela::colour::colorimetry::{
    sd_to_xyz_absolute, sd_to_xyz_emissive, sd_to_xyz_emissive_with, sd_to_xyz_relative,
    sd_to_xyz_relative_with, XyzMethod,
};
use candela::colour::cri::colour_rendering_index;
use candela::colour::illuminants::sd_cie_daylight;
use candela::colour::models::{
    delta_e_ciede2000, xyz_to_lab, xyz_to_upvp, xyz_to_uv1960, xyz_to_xy,
};
use candela::colour::planck::blackbody_table;
use candela::colour::rgb::{xyz_to_rgb, RgbColourspace};
use candela::colour::tables::{named_spectrum, Observer};

use candela::colour::grid::LEN;
use candela::colour::temperature::{uv_to_cct_ohno2013, uv_to_cct_robertson1968};
use candela::photometry::{
    luminous_efficiency_trapezoid, luminous_flux_trapezoid, scotopic_luminous_efficiency_trapezoid,
};
use serde_json::{json, Value};

/// SplitMix64: small deterministic generator for the random spectra.
struct SplitMix(u64);
impl SplitMix {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Smooth positive spectrum: a base plus 1–4 Gaussian bumps; `max` bounds reflectances.
fn random_smooth(rng: &mut SplitMix, max: Option<f64>) -> Vec<f64> {
    let base = 0.05 + 0.3 * rng.next();
    let n = 1 + (rng.next() * 4.0) as usize;
    let bumps: Vec<(f64, f64, f64)> = (0..n)
        .map(|_| {
            (
                360.0 + 470.0 * rng.next(),
                10.0 + 110.0 * rng.next(),
                rng.next(),
            )
        })
        .collect();
    let mut v: Vec<f64> = (0..LEN)
        .map(|i| {
            let l = 360.0 + i as f64;
            base + bumps
                .iter()
                .map(|(c, w, a)| a * (-0.5 * ((l - c) / w).powi(2)).exp())
                .sum::<f64>()
        })
        .collect();
    if let Some(m) = max {
        let peak = v.iter().cloned().fold(0.0, f64::max);
        for x in &mut v {
            *x *= m / peak;
        }
    }
    v
}

fn table_of(spec: &Value) -> [f64; LEN] {
    if let Some(n) = spec.get("named") {
        let n = n.as_str().unwrap();
        return named_spectrum(n)
            .unwrap_or_else(|| panic!("unknown {n}"))
            .to_table();
    }
    if let Some(t) = spec.get("blackbody") {
        return blackbody_table(t.as_f64().unwrap());
    }
    let v = spec["values"].as_array().unwrap();
    let mut out = [0.0; LEN];
    for (o, x) in out.iter_mut().zip(v) {
        *o = x.as_f64().unwrap();
    }
    out
}

fn observer(s: &str) -> Observer {
    match s {
        "1931" => Observer::Cie1931_2,
        _ => Observer::Cie1964_10,
    }
}

fn rgb_specs(i: usize, emissive: bool) -> Value {
    let d50 = json!([0.3457, 0.3585]);
    let mut specs = vec![json!({"space": "sRGB", "cat": null, "illuminant_xy": null})];
    let extra = match i % 4 {
        0 => json!({"space": "Display P3", "cat": "Bradford", "illuminant_xy": d50}),
        1 => json!({"space": "ITU-R BT.2020", "cat": "CAT02", "illuminant_xy": d50}),
        2 => json!({"space": "ACEScg", "cat": "Von Kries", "illuminant_xy": null}),
        _ => json!({"space": "sRGB", "cat": "Bradford", "illuminant_xy": null}),
    };
    specs.push(extra);
    if !emissive {
        // Object colours: adapt from the illuminant's white (filled in by both sides).
        for s in &mut specs {
            s["illuminant_xy"] = Value::Null;
            if s["cat"].is_null() {
                s["cat"] = json!("CAT02");
            }
        }
    }
    Value::Array(specs)
}

fn build_cases() -> Vec<Value> {
    let mut cases = Vec::new();
    let illuminants: Vec<String> = ["A", "D50", "D55", "D65", "D75", "E"]
        .iter()
        .map(|s| s.to_string())
        .chain((1..=12).map(|i| format!("FL{i}")))
        .chain((1..=5).map(|i| format!("LED-B{i}")))
        .chain(
            ["LED-BH1", "LED-RGB1", "LED-V1", "LED-V2"]
                .iter()
                .map(|s| s.to_string()),
        )
        .collect();
    let mut k = 0;
    for obs in ["1931", "1964"] {
        let main = obs == "1931";
        for n in &illuminants {
            k += 1;
            cases.push(
                json!({"id": format!("illuminant {n} / {obs}"), "kind": "emissive",
                "observer": obs, "spectrum": {"named": n}, "cct": main, "cri": main,
                "photometry": main, "rgb": rgb_specs(k, true)}),
            );
        }
        let mut temps: Vec<f64> = (1..=25).map(|t| t as f64 * 1000.0).collect();
        temps.extend([1500.0, 2856.0, 6504.0]);
        for t in temps {
            k += 1;
            cases.push(
                json!({"id": format!("blackbody {t} K / {obs}"), "kind": "emissive",
                "observer": obs, "spectrum": {"blackbody": t}, "cct": main, "cri": main,
                "photometry": main, "rgb": rgb_specs(k, true)}),
            );
        }
        for l in (360..=830).step_by(10) {
            k += 1;
            let mut v = vec![0.0; LEN];
            v[l - 360] = 1.0;
            cases.push(
                json!({"id": format!("line {l} nm / {obs}"), "kind": "emissive",
                "observer": obs, "spectrum": {"values": v}, "cct": false, "cri": false,
                "photometry": main, "rgb": rgb_specs(k, true)}),
            );
        }
        for ill in ["D65", "A", "FL2"] {
            for p in 1..=24 {
                k += 1;
                let next = p % 24 + 1;
                cases.push(
                    json!({"id": format!("colorchecker {p} under {ill} / {obs}"),
                    "kind": "object", "observer": obs,
                    "spectrum": {"named": format!("colorchecker:{p}")},
                    "illuminant": {"named": ill},
                    "next": {"named": format!("colorchecker:{next}")},
                    "rgb": rgb_specs(k, false)}),
                );
            }
        }
        let mut rng = SplitMix(if main { 0x00C0_FFEE } else { 0x0BAD_CAFE });
        for i in 0..15 {
            k += 1;
            cases.push(
                json!({"id": format!("random emissive {i} / {obs}"), "kind": "emissive",
                "observer": obs, "spectrum": {"values": random_smooth(&mut rng, None)},
                "cct": main, "cri": main, "photometry": main, "rgb": rgb_specs(k, true)}),
            );
        }
        for i in 0..15 {
            k += 1;
            let r = random_smooth(&mut rng, Some(0.95));
            let r2 = random_smooth(&mut rng, Some(0.95));
            cases.push(
                json!({"id": format!("random reflectance {i} under D65 / {obs}"),
                "kind": "object", "observer": obs, "spectrum": {"values": r},
                "illuminant": {"named": "D65"}, "next": {"values": r2},
                "rgb": rgb_specs(k, false)}),
            );
        }
    }
    for t in [
        4000.0, 5000.0, 5500.0, 6504.0, 7500.0, 10000.0, 15000.0, 25000.0,
    ] {
        k += 1;
        cases.push(
            json!({"id": format!("CIE daylight {t} K"), "kind": "daylight",
            "observer": "1931", "spectrum": {"cct": t}, "cct": true, "cri": true,
            "photometry": true, "rgb": rgb_specs(k, true)}),
        );
    }
    cases
}

#[derive(Default)]
struct Stat {
    count: usize,
    max: f64,
    worst: String,
    tol: f64,
    unit: &'static str,
}

#[derive(Default)]
struct Checker {
    stats: BTreeMap<&'static str, Stat>,
    failures: Vec<String>,
}

impl Checker {
    fn record(
        &mut self,
        q: &'static str,
        unit: &'static str,
        tol: f64,
        id: &str,
        dev: f64,
        detail: String,
    ) {
        let s = self.stats.entry(q).or_default();
        s.tol = tol;
        s.unit = unit;
        s.count += 1;
        if dev > s.max || dev.is_nan() {
            s.max = dev;
            s.worst = id.to_string();
        }
        if dev.is_nan() || dev > tol {
            self.failures.push(format!(
                "{id}: {q} deviates by {dev:.3e} (tolerance {tol:e}): {detail}"
            ));
        }
    }

    /// Relative deviation of a vector: max |a − b| / max(max |b|, 1e-12) (the floor keeps
    /// ~1e-20 residue colour-science leaves where candela has an exact 0 from blowing up).
    fn vec_rel(&mut self, q: &'static str, id: &str, ours: &[f64], theirs: &Value, tol: f64) {
        let t: Vec<f64> = theirs
            .as_array()
            .unwrap_or_else(|| panic!("{id}: {q}: missing reference value"))
            .iter()
            .map(|v| v.as_f64().unwrap_or(f64::NAN))
            .collect();
        assert_eq!(ours.len(), t.len(), "{id}: {q}");
        let scale = t.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = ours.iter().zip(&t).fold(0.0f64, |m, (a, b)| {
            if (a - b).is_nan() {
                f64::NAN
            } else {
                m.max((a - b).abs())
            }
        });
        let dev = diff / scale.max(1e-12);
        self.record(
            q,
            "relative",
            tol,
            id,
            dev,
            format!("candela {ours:?}, colour-science {t:?}"),
        );
    }

    fn abs(
        &mut self,
        q: &'static str,
        unit: &'static str,
        id: &str,
        ours: f64,
        theirs: &Value,
        tol: f64,
    ) {
        let t = theirs.as_f64().unwrap_or(f64::NAN);
        self.record(
            q,
            unit,
            tol,
            id,
            (ours - t).abs(),
            format!("candela {ours}, colour-science {t}"),
        );
    }

    fn rel(&mut self, q: &'static str, id: &str, ours: f64, theirs: &Value, tol: f64) {
        let t = theirs.as_f64().unwrap_or(f64::NAN);
        let dev = if t == 0.0 {
            ours.abs()
        } else {
            ((ours - t) / t).abs()
        };
        self.record(
            q,
            "relative",
            tol,
            id,
            dev,
            format!("candela {ours}, colour-science {t}"),
        );
    }
}

const REL: f64 = 1e-6;

fn check_rgb(
    c: &mut Checker,
    id: &str,
    xyz1: [f64; 3],
    specs: &Value,
    res: &Value,
    white: Option<[f64; 2]>,
) {
    for (spec, r) in specs
        .as_array()
        .unwrap()
        .iter()
        .zip(res.as_array().unwrap())
    {
        let space = RgbColourspace::parse(spec["space"].as_str().unwrap()).unwrap();
        let cat = spec["cat"].as_str().map(|s| Cat::parse(s).unwrap());
        let ill = match spec["illuminant_xy"].as_array() {
            Some(a) => [a[0].as_f64().unwrap(), a[1].as_f64().unwrap()],
            None => white.unwrap_or(space.whitepoint_xy()),
        };
        let lin = xyz_to_rgb(xyz1, space, ill, cat, false);
        let enc = xyz_to_rgb(xyz1, space, ill, cat, true);
        let (ql, qe) = if space == RgbColourspace::Srgb {
            ("sRGB linear", "sRGB encoded")
        } else {
            (
                "RGB linear (P3/2020/ACEScg)",
                "RGB encoded (P3/2020/ACEScg)",
            )
        };
        c.vec_rel(ql, id, &lin, &r["linear"], REL);
        c.vec_rel(qe, id, &enc, &r["encoded"], REL);
    }
}

fn check_case(c: &mut Checker, case: &Value, res: &Value) {
    let id = case["id"].as_str().unwrap();
    if let Some(e) = res.get("error") {
        c.failures.push(format!("{id}: colour-science raised {e}"));
        return;
    }
    let obs = observer(case["observer"].as_str().unwrap());
    let kind = case["kind"].as_str().unwrap();
    if kind == "object" {
        let refl = table_of(&case["spectrum"]);
        let ill = table_of(&case["illuminant"]);
        let xyz = sd_to_xyz_relative(&refl, &ill, obs);
        c.vec_rel("XYZ (Integration, 360-830)", id, &xyz, &res["xyz"], REL);
        let xa = sd_to_xyz_relative_with(&refl, &ill, obs, XyzMethod::AstmE308);
        c.vec_rel(
            "XYZ (ASTM E308 default, 360-780)",
            id,
            &xa,
            &res["xyz_astm"],
            REL,
        );
        c.vec_rel("xy", id, &xyz_to_xy(xyz), &res["xy"], REL);
        c.vec_rel("u'v' (CIE 1976)", id, &xyz_to_upvp(xyz), &res["upvp"], REL);
        let white = xyz_to_xy(sd_to_xyz_emissive(&ill, obs));
        c.vec_rel("xy", id, &white, &res["white_xy"], REL);
        let xyz1 = xyz.map(|v| v / 100.0);
        let lab = xyz_to_lab(xyz1, white);
        c.vec_rel("CIELAB", id, &lab, &res["lab"], REL);
        let next = table_of(&case["next"]);
        let lab2 = xyz_to_lab(
            sd_to_xyz_relative(&next, &ill, obs).map(|v| v / 100.0),
            white,
        );
        c.abs(
            "CIEDE2000",
            "absolute",
            id,
            delta_e_ciede2000(lab, lab2),
            &res["de2000"],
            1e-6,
        );
        check_rgb(c, id, xyz1, &case["rgb"], &res["rgb"], Some(white));
        return;
    }
    let s = if kind == "daylight" {
        let d = sd_cie_daylight(case["spectrum"]["cct"].as_f64().unwrap());
        c.vec_rel("CIE daylight SPD", id, &d, &res["spd"], REL);
        d
    } else {
        table_of(&case["spectrum"])
    };
    let xyz = sd_to_xyz_emissive(&s, obs);
    c.vec_rel("XYZ (Integration, 360-830)", id, &xyz, &res["xyz"], REL);
    let xa = sd_to_xyz_emissive_with(&s, obs, XyzMethod::AstmE308);
    c.vec_rel(
        "XYZ (ASTM E308 default, 360-780)",
        id,
        &xa,
        &res["xyz_astm"],
        REL,
    );
    c.vec_rel(
        "XYZ absolute (K_m)",
        id,
        &sd_to_xyz_absolute(&s, obs),
        &res["xyz_abs"],
        REL,
    );
    c.vec_rel("xy", id, &xyz_to_xy(xyz), &res["xy"], REL);
    let uv = xyz_to_uv1960(xyz);
    c.vec_rel("uv (CIE 1960)", id, &uv, &res["uv"], REL);
    c.vec_rel("u'v' (CIE 1976)", id, &xyz_to_upvp(xyz), &res["upvp"], REL);
    if case["cct"].as_bool() == Some(true) {
        let o = uv_to_cct_ohno2013(uv);
        c.abs("CCT Ohno 2013", "K", id, o[0], &res["cct_ohno"][0], 0.5);
        c.abs(
            "Duv Ohno 2013",
            "absolute",
            id,
            o[1],
            &res["cct_ohno"][1],
            5e-5,
        );
        let r = uv_to_cct_robertson1968(uv);
        c.abs(
            "CCT Robertson 1968",
            "K",
            id,
            r[0],
            &res["cct_robertson"][0],
            0.5,
        );
        c.abs(
            "Duv Robertson 1968",
            "absolute",
            id,
            r[1],
            &res["cct_robertson"][1],
            5e-5,
        );
    }
    if case["photometry"].as_bool() == Some(true) {
        let f = luminous_flux_trapezoid(&s);
        c.rel("luminous flux (trapezoid)", id, f, &res["flux_trapz"], REL);
        let e = luminous_efficiency_trapezoid(&s);
        c.rel(
            "luminous efficiency (trapezoid)",
            id,
            e,
            &res["efficiency_trapz"],
            REL,
        );
        let e = scotopic_luminous_efficiency_trapezoid(&s);
        c.rel(
            "scotopic efficiency (trapezoid)",
            id,
            e,
            &res["scotopic_efficiency_trapz"],
            REL,
        );
    }
    if case["cri"].as_bool() == Some(true) {
        let cri = colour_rendering_index(&s);
        c.abs("Ra", "absolute", id, cri.ra, &res["ra"], 0.01);
        for i in 0..14 {
            c.abs("R1-R14", "absolute", id, cri.r[i], &res["ri"][i], 0.01);
        }
    }
    let xyz1 = if xyz[1] != 0.0 {
        xyz.map(|v| v / xyz[1])
    } else {
        xyz
    };
    check_rgb(c, id, xyz1, &case["rgb"], &res["rgb"], None);
}

#[test]
fn candela_matches_colour_science() {
    let t0 = std::time::Instant::now();
    let cases = build_cases();
    let input = serde_json::to_vec(&json!({ "cases": cases })).unwrap();
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scripts/colour_reference.py");
    let py = python();
    let mut child = Command::new(&py)
        .arg(&script)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", py.display()));
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(&input));
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap().unwrap();
    assert!(
        out.status.success(),
        "{} {} failed ({}):\n{}\nIf colour-science is missing, run scripts/setup_python.sh.",
        py.display(),
        script.display(),
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: Value = serde_json::from_slice(&out.stdout).expect("reference script output is JSON");
    assert_eq!(
        doc["colour_science"], "0.4.7",
        "colour-science must be the pinned 0.4.7"
    );
    let results = doc["results"].as_array().unwrap();
    assert_eq!(results.len(), cases.len());

    let mut c = Checker::default();
    for (case, res) in cases.iter().zip(results) {
        check_case(&mut c, case, res);
    }

    println!(
        "colour-science {} comparison: {} cases, {} values compared, {:.1} s",
        doc["colour_science"].as_str().unwrap(),
        cases.len(),
        c.stats.values().map(|s| s.count).sum::<usize>(),
        t0.elapsed().as_secs_f64()
    );
    println!(
        "{:<36} {:>6} {:>11} {:>9}  {:<9} worst case",
        "quantity", "n", "max dev", "tol", "unit"
    );
    for (q, s) in &c.stats {
        println!(
            "{:<36} {:>6} {:>11.3e} {:>9.0e}  {:<9} {}",
            q, s.count, s.max, s.tol, s.unit, s.worst
        );
    }
    assert!(cases.len() >= 200);
    assert!(
        c.failures.is_empty(),
        "{} mismatches with colour-science:\n{}",
        c.failures.len(),
        c.failures.join("\n")
    );
}
