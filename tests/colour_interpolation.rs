//! Resampling of tabulated spectra to 1 nm against colour-science 0.4.7: CIE 167 (Sprague for
//! uniform data, not-a-knot cubic spline otherwise) must give colour-science's values, and
//! CIE 2017 / TM-30 of coarse data interpolated that way colour-science's R_f and R_g.
//! The reference is `scripts/interpolation_reference.py` run with the project's Python
//! (`$CANDELA_PYTHON` or target/venv); a missing interpreter is a failure, not a skip.

mod common;
use common::python_json;

use candela::colour::alpha_opic::alpha_opic_irradiance;
use candela::colour::grid::{LEN, START_NM};
use candela::colour::sd::{Interpolation, Method, SpectralDistribution};
use candela::colour::tables::named_spectrum;
use candela::colour::tm30::colour_rendition;
use serde_json::{json, Value};

const REFERENCE: &str = "../scripts/interpolation_reference.py";

/// A smooth positive spectrum at any wavelength: a base plus Gaussian bumps.
fn smooth(seed: u64) -> impl Fn(f64) -> f64 {
    let mut s = seed;
    let mut next = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let base = 0.05 + 0.3 * next();
    let bumps: Vec<(f64, f64, f64)> = (0..1 + (next() * 4.0) as usize)
        .map(|_| (380.0 + 420.0 * next(), 15.0 + 100.0 * next(), next()))
        .collect();
    move |l| {
        base + bumps
            .iter()
            .map(|(c, w, a)| a * (-0.5 * ((l - c) / w).powi(2)).exp())
            .sum::<f64>()
    }
}

/// The cases: (name, wavelengths, values).
fn cases() -> Vec<(String, Vec<f64>, Vec<f64>)> {
    let mut out = Vec::new();
    let uniform = |start: f64, end: f64, step: f64| -> Vec<f64> {
        let n = ((end - start) / step).round() as usize;
        (0..=n).map(|i| start + step * i as f64).collect()
    };
    for (k, step) in [5.0, 10.0, 20.0].into_iter().enumerate() {
        for seed in 0..3u64 {
            let f = smooth(seed + 10 * k as u64);
            let w = uniform(360.0, 830.0, step);
            let v = w.iter().map(|&l| f(l)).collect();
            out.push((format!("smooth {seed}, {step} nm"), w, v));
        }
        // A line spectrum (fluorescent FL2) sampled coarsely: Sprague rings around the lines.
        let fl2 = named_spectrum("FL2").unwrap();
        let w = uniform(380.0, 780.0, step);
        let v = w.iter().map(|&l| fl2.value(l)).collect();
        out.push((format!("FL2, {step} nm"), w, v));
    }
    // Uniform but not on whole nanometres, and the shortest Sprague input (6 samples).
    let f = smooth(99);
    let w = uniform(402.5, 697.5, 12.5);
    out.push((
        "smooth, 12.5 nm from 402.5".into(),
        w.clone(),
        w.iter().map(|&l| f(l)).collect(),
    ));
    let w = uniform(500.0, 600.0, 20.0);
    let v = vec![0.0651, 0.0705, 0.0772, 0.0870, 0.1128, 0.1360];
    out.push(("6 samples, 20 nm".into(), w, v));
    // Non-uniform: irregular gaps 2–17 nm, a measured-looking range, and 4 samples (the
    // fewest the cubic spline takes).
    let mut w = vec![361.0];
    let mut s = 7u64;
    while *w.last().unwrap() < 820.0 {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1);
        w.push(w.last().unwrap() + 2.0 + ((s >> 33) % 16) as f64);
    }
    let f = smooth(5);
    out.push((
        "irregular 2–17 nm".into(),
        w.clone(),
        w.iter().map(|&l| f(l)).collect(),
    ));
    let w = vec![
        380.0, 385.0, 390.0, 400.0, 420.0, 450.0, 500.0, 560.0, 640.0, 780.0,
    ];
    let f = smooth(6);
    out.push((
        "widening steps 5–140 nm".into(),
        w.clone(),
        w.iter().map(|&l| f(l)).collect(),
    ));
    out.push((
        "4 samples".into(),
        vec![400.0, 450.0, 520.0, 700.0],
        vec![1.0, 3.0, 2.0, 2.5],
    ));
    out
}

#[test]
fn cie167_matches_colour_science() {
    let cases = cases();
    // Every whole nanometre in 360–830 nm and points between them.
    let at: Vec<f64> = (0..LEN)
        .map(|i| START_NM as f64 + i as f64)
        .chain((0..470).map(|i| 360.37 + i as f64))
        .collect();
    let input: Vec<Value> = cases
        .iter()
        .map(|(id, w, v)| {
            let lo = w[0];
            let hi = *w.last().unwrap();
            let inside: Vec<f64> = at
                .iter()
                .copied()
                .filter(|x| *x >= lo && *x <= hi)
                .collect();
            json!({"id": id, "wavelengths": w, "values": v, "at": inside})
        })
        .collect();
    let r = python_json(
        REFERENCE,
        &[],
        Some(&json!({"task": "interpolate", "cases": input})),
    );
    assert_eq!(r["colour_science"], "0.4.7");
    let mut worst = 0.0f64;
    for ((id, w, v), (case, want)) in cases
        .iter()
        .zip(input.iter().zip(r["results"].as_array().unwrap()))
    {
        let sd = SpectralDistribution::new(w.clone(), v.clone()).unwrap();
        let method = sd.method(Interpolation::Cie167);
        let expected = match want["interpolator"].as_str().unwrap() {
            "SpragueInterpolator" => Method::Sprague,
            "CubicSplineInterpolator" => Method::CubicSpline,
            other => panic!("{id}: colour-science picked {other}"),
        };
        assert_eq!(method, expected, "{id}");
        // Deviations relative to the spectrum's peak: an interpolant that rings through zero
        // has no meaningful relative error there.
        let scale = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let xs: Vec<f64> = case["at"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let got = sd.values_with(Interpolation::Cie167, &xs);
        let mut dev = 0.0f64;
        for ((x, g), e) in xs.iter().zip(&got).zip(want["values"].as_array().unwrap()) {
            let e = e.as_f64().unwrap();
            let d = (g - e).abs() / scale;
            assert!(
                d <= 1e-14,
                "{id} at {x} nm: candela {g}, colour-science {e}"
            );
            dev = dev.max(d);
        }
        // The 1 nm table equals colour-science's `interpolate` to 1 nm where that applies.
        if let Some(i) = want["interpolated"].as_object() {
            let t = sd.to_table_with(Interpolation::Cie167);
            for (x, e) in i["wavelengths"]
                .as_array()
                .unwrap()
                .iter()
                .zip(i["values"].as_array().unwrap())
            {
                let (x, e) = (x.as_f64().unwrap(), e.as_f64().unwrap());
                if !(360.0..=830.0).contains(&x) {
                    continue;
                }
                let g = t[(x - START_NM as f64) as usize];
                let d = (g - e).abs() / scale;
                assert!(
                    d <= 1e-14,
                    "{id} table at {x} nm: candela {g}, colour-science {e}"
                );
                dev = dev.max(d);
            }
        }
        // What linear resampling gave instead, for the record.
        let lin = sd.values_with(Interpolation::Linear, &xs);
        let lin_dev = lin
            .iter()
            .zip(want["values"].as_array().unwrap())
            .map(|(g, e)| (g - e.as_f64().unwrap()).abs() / scale)
            .fold(0.0f64, f64::max);
        println!(
            "{id:<28} {:<40} max |Δ|/peak: cie167 {dev:.1e}, linear {lin_dev:.1e}",
            method.name()
        );
        worst = worst.max(dev);
    }
    println!(
        "{} cases, largest deviation {worst:.2e} of the peak",
        cases.len()
    );
}

#[test]
fn few_samples_and_linear_choice() {
    // Too few samples for Sprague (6) or the spline (4): straight lines, and said so.
    let sd = SpectralDistribution::new(
        vec![400.0, 420.0, 440.0, 460.0, 480.0],
        vec![1.0, 2.0, 3.0, 2.0, 1.0],
    )
    .unwrap();
    assert_eq!(sd.method(Interpolation::Cie167), Method::Linear);
    assert_eq!(sd.to_table_with(Interpolation::Cie167), sd.to_table());
    let w = sd
        .coarse_linear_warning("s.csv", Interpolation::Cie167)
        .unwrap();
    assert!(
        w.contains("s.csv") && w.contains("20 nm") && w.contains("at least 6"),
        "{w}"
    );
    // Coarse data resampled linearly on request: warned; 5 nm data: not.
    let coarse = SpectralDistribution::new(
        (0..10).map(|i| 400.0 + 10.0 * i as f64).collect(),
        vec![1.0; 10],
    )
    .unwrap();
    assert!(coarse
        .coarse_linear_warning("c.csv", Interpolation::Linear)
        .is_some());
    assert!(coarse
        .coarse_linear_warning("c.csv", Interpolation::Cie167)
        .is_none());
    let fine = SpectralDistribution::new(
        (0..10).map(|i| 400.0 + 5.0 * i as f64).collect(),
        vec![1.0; 10],
    )
    .unwrap();
    assert!(fine
        .coarse_linear_warning("f.csv", Interpolation::Linear)
        .is_none());
    // Samples at every whole nanometre come back exactly, whatever the interpolation.
    let d65 = named_spectrum("D65").unwrap();
    assert_eq!(d65.to_table_with(Interpolation::Cie167), d65.to_table());
}

#[test]
fn s_cone_irradiance_of_coarse_smooth_spectra() {
    // A smooth spectrum known at every nanometre, sampled at 5, 10 and 20 nm and resampled
    // back: CIE 167 recovers the s-cone (short-wavelength) α-opic irradiance far better than
    // straight lines (whose error grows with the square of the interval).
    let f = smooth(3);
    let truth: [f64; LEN] = std::array::from_fn(|i| f(START_NM as f64 + i as f64));
    let e_true = alpha_opic_irradiance(&truth)[0];
    for step in [5.0, 10.0, 20.0] {
        let w: Vec<f64> = (0..=(470.0 / step) as usize)
            .map(|i| 360.0 + step * i as f64)
            .collect();
        let v = w.iter().map(|&l| f(l)).collect();
        let sd = SpectralDistribution::new(w, v).unwrap();
        let err = |i: Interpolation| alpha_opic_irradiance(&sd.to_table_with(i))[0] / e_true - 1.0;
        let (lin, cie) = (err(Interpolation::Linear), err(Interpolation::Cie167));
        println!("{step} nm: s-cone irradiance linear {lin:+.2e}, cie167 {cie:+.2e}");
        assert!(
            cie.abs() < lin.abs() / 5.0,
            "{step} nm: cie167 {cie:e} vs linear {lin:e}"
        );
    }
}

#[test]
fn tm30_of_coarse_data_as_colour_science_after_interpolation() {
    // colour-science refuses CIE 2017 for data coarser than 5 nm; interpolated to 1 nm by its
    // `interpolate` (CIE 167) it computes R_f and R_g, which candela's CIE 167 table must give
    // to the precision of the 1 nm TM-30 comparison (tests/colour_health.rs: 1e-6).
    let mut input = Vec::new();
    let mut sds = Vec::new();
    for step in [10.0, 20.0] {
        let w: Vec<f64> = (0..=(400.0 / step) as usize)
            .map(|i| 380.0 + step * i as f64)
            .collect();
        for (name, f) in [
            ("LED-B3", named_spectrum("LED-B3").unwrap().clone()),
            ("FL2", named_spectrum("FL2").unwrap().clone()),
            ("A", named_spectrum("A").unwrap().clone()),
        ] {
            let v: Vec<f64> = w.iter().map(|&l| f.value(l)).collect();
            let id = format!("{name} at {step} nm");
            input.push(json!({"id": id, "wavelengths": w, "values": v}));
            sds.push((id, SpectralDistribution::new(w.clone(), v).unwrap()));
        }
    }
    let r = python_json(
        REFERENCE,
        &[],
        Some(&json!({"task": "tm30_coarse", "cases": input})),
    );
    for ((id, sd), want) in sds.iter().zip(r["results"].as_array().unwrap()) {
        assert!(
            want["refused"].as_str().is_some_and(|m| m.contains("5nm")),
            "{id}: colour-science accepted it: {want}"
        );
        let c = colour_rendition(&sd.to_table_with(Interpolation::Cie167)).unwrap();
        let f = |k: &str| want[k].as_f64().unwrap();
        println!(
            "{id:<16} Rf {:.6} ({:.6}) Rg {:.6} ({:.6}) CCT {:.3} ({:.3})",
            c.rf,
            f("rf"),
            c.rg,
            f("rg"),
            c.cct_k,
            f("cct")
        );
        assert!((c.cct_k / f("cct") - 1.0).abs() <= 1e-9, "{id}: CCT");
        assert!((c.rf - f("rf_cie2017")).abs() <= 1e-6, "{id}: Rf CIE 2017");
        assert!((c.rf - f("rf")).abs() <= 1e-6, "{id}: Rf TM-30");
        assert!((c.rg - f("rg")).abs() <= 1e-6, "{id}: Rg");
        // Linear resampling moves them measurably.
        let l = colour_rendition(&sd.to_table_with(Interpolation::Linear)).unwrap();
        println!("{id:<16} linear: Rf {:.4} Rg {:.4}", l.rf, l.rg);
    }
}
