//! `candela probe` agrees with the EXR it reads: means, 95 % intervals (±1.96·SE), disc
//! averaging, chromaticity, JSON and imperial units; bad input gives exit 1 naming the file.

mod common;
use common::cli;
use std::path::Path;

use candela::output::{self, Layers, CHANNEL_E, CHANNEL_E_MASK, CHANNEL_E_STDERR};
use candela::photometry::{CD_M2_PER_FL, LX_PER_FC};
use candela::report::probe::{probe, IlluminanceProbe};
use candela::report::units::UnitSystem;
use serde_json::Value;

const W: usize = 9;
const H: usize = 7;
/// D65 chromaticity.
const XY: [f64; 2] = [0.3127, 0.3290];

fn lum(x: usize, y: usize) -> f64 {
    100.0 + x as f64 + 10.0 * y as f64
}

/// Y = 100 + x + 10 y cd/m² with D65 chromaticity, stderr.Y = 2; E = 3 Y lx with
/// stderr.E = 5, undefined (sentinel, mask 0) at pixel (0, 0).
fn image(path: &Path) -> Layers {
    let mut xyz = Vec::new();
    let (mut e, mut mask) = (Vec::new(), Vec::new());
    for y in 0..H {
        for x in 0..W {
            let l = lum(x, y);
            xyz.push([
                (l * XY[0] / XY[1]) as f32,
                l as f32,
                (l * (1.0 - XY[0] - XY[1]) / XY[1]) as f32,
            ]);
            if (x, y) == (0, 0) {
                e.push(output::ILLUMINANCE_SENTINEL);
                mask.push(0.0);
            } else {
                e.push((3.0 * l) as f32);
                mask.push(1.0);
            }
        }
    }
    let mut layers = Layers::from_xyz(W, H, &xyz, &vec![2.0; W * H]);
    layers.channels.push((CHANNEL_E.into(), e));
    layers
        .channels
        .push((CHANNEL_E_STDERR.into(), vec![5.0; W * H]));
    layers.channels.push((CHANNEL_E_MASK.into(), mask));
    output::write_exr(path, &layers).unwrap();
    output::read_exr(path).unwrap()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1.0)
}

#[test]
fn single_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let layers = image(&dir.path().join("p.exr"));
    let r = probe(&layers, 4, 3, None, UnitSystem::Si).unwrap();
    assert_eq!(r.pixels, 1);
    assert!(close(r.luminance.mean, 134.0, 1e-6));
    assert_eq!(r.luminance.stderr, Some(2.0));
    let (lo, hi) = r.luminance.ci95().unwrap();
    assert!(close(lo, 134.0 - 1.96 * 2.0, 1e-6) && close(hi, 134.0 + 1.96 * 2.0, 1e-6));
    match r.illuminance {
        IlluminanceProbe::Defined {
            estimate, pixels, ..
        } => {
            assert_eq!(pixels, 1);
            assert!(close(estimate.mean, 402.0, 1e-6));
            let (lo, hi) = estimate.ci95().unwrap();
            assert!(close(lo, 402.0 - 9.8, 1e-6) && close(hi, 402.0 + 9.8, 1e-6));
        }
        ref other => panic!("{other:?}"),
    }
    let xy = r.xy.unwrap();
    assert!(
        close(xy[0], XY[0], 1e-6) && close(xy[1], XY[1], 1e-6),
        "{xy:?}"
    );
    let xyz = r.xyz.unwrap();
    assert!(close(xyz[1], 134.0, 1e-6));
    let [cct, duv] = r.cct_duv.unwrap();
    assert!(
        (cct - 6504.0).abs() < 10.0 && (duv - 0.0032).abs() < 0.001,
        "{cct} {duv}"
    );
    // D65 white: linear sRGB ≈ (1, 1, 1) relative to Y, encoded likewise.
    for c in r
        .srgb_linear
        .unwrap()
        .iter()
        .chain(&r.srgb_encoded.unwrap())
    {
        assert!((c - 1.0).abs() < 2e-3, "{c}");
    }
    let uv = r.upvp.unwrap();
    assert!(
        close(uv[0], 0.1978, 1e-3) && close(uv[1], 0.4683, 1e-3),
        "{uv:?}"
    );
}

#[test]
fn one_sample_per_pixel_has_an_unknown_interval() {
    // A render with 1 spp writes 0 into stderr.Y (no sample variance) and spp "1.00": the
    // probe must not claim ± 0. With spp "2.00" the same channel is a real standard error.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.exr");
    for (spp, known) in [("1.00", false), ("2.00", true)] {
        let mut layers = image(&path);
        layers.attributes.push(("spp".into(), spp.into()));
        output::write_exr(&path, &layers).unwrap();
        let r = probe(
            &output::read_exr(&path).unwrap(),
            4,
            3,
            None,
            UnitSystem::Si,
        )
        .unwrap();
        assert_eq!(r.luminance.stderr.is_some(), known, "spp {spp}");
        assert_eq!(r.luminance.ci95().is_some(), known, "spp {spp}");
        match r.illuminance {
            IlluminanceProbe::Defined { estimate, .. } => {
                assert_eq!(estimate.stderr.is_some(), known, "spp {spp}")
            }
            ref other => panic!("{other:?}"),
        }
    }
}

#[test]
fn one_illuminance_sample_has_an_unknown_interval() {
    // 4 samples per pixel, but at pixel (4, 3) only a quarter of them saw a receiving surface:
    // its E rests on one sample, whose variance is unknown; the luminance interval stays known.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.exr");
    let mut layers = image(&path);
    layers.attributes.push(("spp".into(), "4.00".into()));
    let mask = &mut layers
        .channels
        .iter_mut()
        .find(|(n, _)| n == CHANNEL_E_MASK)
        .unwrap()
        .1;
    mask[3 * W + 4] = 0.25;
    output::write_exr(&path, &layers).unwrap();
    let layers = output::read_exr(&path).unwrap();
    let r = probe(&layers, 4, 3, None, UnitSystem::Si).unwrap();
    assert!(r.luminance.stderr.is_some());
    match r.illuminance {
        IlluminanceProbe::Defined { estimate, .. } => assert_eq!(estimate.stderr, None),
        ref other => panic!("{other:?}"),
    }
    // An adaptive render's mean spp can be high while a pixel stopped with one E sample: its
    // stderr.E is 0 with only some samples on a surface, which is taken as unknown too.
    let mut adaptive = layers.clone();
    adaptive.attributes.retain(|(n, _)| n != "spp");
    adaptive.attributes.push(("spp".into(), "400.00".into()));
    for (name, v) in adaptive.channels.iter_mut() {
        match name.as_str() {
            CHANNEL_E_MASK => v[3 * W + 4] = 0.5,
            CHANNEL_E_STDERR => v[3 * W + 4] = 0.0,
            _ => {}
        }
    }
    match probe(&adaptive, 4, 3, None, UnitSystem::Si)
        .unwrap()
        .illuminance
    {
        IlluminanceProbe::Defined { estimate, .. } => assert_eq!(estimate.stderr, None),
        ref other => panic!("{other:?}"),
    }
    // Its neighbour, with all 4 samples on a surface, keeps its interval.
    match probe(&layers, 5, 3, None, UnitSystem::Si)
        .unwrap()
        .illuminance
    {
        IlluminanceProbe::Defined { estimate, .. } => assert_eq!(estimate.stderr, Some(5.0)),
        ref other => panic!("{other:?}"),
    }
}

#[test]
fn values_candela_never_writes_are_refused() {
    // A negative luminance, a negative standard error or a mask above 1 means a corrupt or
    // edited file: probe and falsecolour refuse it, naming the file, the channel and the pixel.
    let dir = tempfile::tempdir().unwrap();
    for (channel, value) in [("Y", -5.0f32), ("stderr.Y", -1.0), ("mask.E", 1.5)] {
        let path = dir.path().join("bad.exr");
        let mut layers = image(&path);
        let c = &mut layers
            .channels
            .iter_mut()
            .find(|(n, _)| n == channel)
            .unwrap()
            .1;
        c[2 * W + 6] = value;
        output::write_exr(&path, &layers).unwrap();
        for args in [
            vec!["probe", "bad.exr", "0", "0"],
            vec!["falsecolour", "bad.exr", "-o", "bad.png"],
        ] {
            let (code, _, err) = cli(&args, dir.path());
            assert_eq!(code, 1, "{args:?} on {channel} = {value}: {err}");
            assert!(
                err.contains("bad.exr")
                    && err.contains(&format!("channel {channel}"))
                    && err.contains("(6, 2)"),
                "{err}"
            );
        }
        assert!(!dir.path().join("bad.png").exists());
    }
}

#[test]
fn disc_average() {
    let dir = tempfile::tempdir().unwrap();
    let layers = image(&dir.path().join("p.exr"));
    // Radius 1: the pixel and its 4 neighbours; the mean of a linear function is the centre.
    let r = probe(&layers, 4, 3, Some(1.0), UnitSystem::Si).unwrap();
    assert_eq!(r.pixels, 5);
    assert!(close(r.luminance.mean, 134.0, 1e-6));
    let se = r.luminance.stderr.unwrap();
    assert!(close(se, (5.0f64 * 4.0).sqrt() / 5.0, 1e-9), "{se}");
    // Radius 1.5: the 3×3 block.
    let r = probe(&layers, 4, 3, Some(1.5), UnitSystem::Si).unwrap();
    assert_eq!(r.pixels, 9);
    assert!(close(r.luminance.stderr.unwrap(), 2.0 / 3.0, 1e-9));
    // At the corner the disc is clipped, and E is averaged over the defined pixels only.
    let r = probe(&layers, 0, 0, Some(1.0), UnitSystem::Si).unwrap();
    assert_eq!(r.pixels, 3);
    assert!(close(r.luminance.mean, (100.0 + 101.0 + 110.0) / 3.0, 1e-6));
    match r.illuminance {
        IlluminanceProbe::Defined {
            estimate,
            pixels,
            mask_mean,
        } => {
            assert_eq!(pixels, 2);
            assert!(close(estimate.mean, 3.0 * (101.0 + 110.0) / 2.0, 1e-6));
            assert!(close(
                estimate.stderr.unwrap(),
                (2.0f64 * 25.0).sqrt() / 2.0,
                1e-9
            ));
            assert!(close(mask_mean.unwrap(), 2.0 / 3.0, 1e-6));
        }
        ref other => panic!("{other:?}"),
    }
    // Pixel (0, 0) alone sees no surface.
    let r = probe(&layers, 0, 0, None, UnitSystem::Si).unwrap();
    assert_eq!(
        r.illuminance,
        IlluminanceProbe::Undefined {
            mask_mean: Some(0.0)
        }
    );
    // The terminal text is the command's: probe the same pixel of the EXR on disc.
    let (_, text, _) = cli(&["probe", "p.exr", "0", "0"], dir.path());
    assert!(text.contains("undefined: pixel sees no surface"));
}

#[test]
fn json_and_imperial_units() {
    let dir = tempfile::tempdir().unwrap();
    image(&dir.path().join("p.exr"));
    let (code, out, err) = cli(&["probe", "p.exr", "4", "3", "--json"], dir.path());
    assert_eq!(code, 0, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["file"], "p.exr");
    assert_eq!(v["units"]["system"], "si");
    assert_eq!(v["units"]["luminance"], "cd/m²");
    assert!(close(v["luminance"]["mean"].as_f64().unwrap(), 134.0, 1e-6));
    let ci = &v["luminance"]["ci95"];
    assert!(close(ci[0].as_f64().unwrap(), 134.0 - 3.92, 1e-6));
    assert!(close(ci[1].as_f64().unwrap(), 134.0 + 3.92, 1e-6));
    assert_eq!(v["illuminance"]["defined"], true);
    assert!(close(
        v["illuminance"]["mean"].as_f64().unwrap(),
        402.0,
        1e-6
    ));
    assert!(close(v["xy"][0].as_f64().unwrap(), XY[0], 1e-6));
    assert!((v["cct_k"].as_f64().unwrap() - 6504.0).abs() < 10.0);
    for key in [
        "x",
        "y",
        "radius_px",
        "pixels",
        "xyz",
        "upvp",
        "duv",
        "srgb_linear",
        "srgb_encoded",
    ] {
        assert!(v.get(key).is_some(), "missing key {key}");
    }

    let (code, out, err) = cli(
        &[
            "probe", "p.exr", "4", "3", "--radius", "1", "--json", "--units", "imperial",
        ],
        dir.path(),
    );
    assert_eq!(code, 0, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["units"]["system"], "imperial");
    assert_eq!(v["units"]["luminance"], "fL");
    assert_eq!(v["units"]["illuminance"], "fc");
    assert_eq!(v["pixels"], 5);
    assert!(close(
        v["luminance"]["mean"].as_f64().unwrap(),
        134.0 / CD_M2_PER_FL,
        1e-6
    ));
    assert!(close(
        v["illuminance"]["mean"].as_f64().unwrap(),
        402.0 / LX_PER_FC,
        1e-6
    ));
    let se = v["illuminance"]["stderr"].as_f64().unwrap();
    assert!(close(se, (5.0f64 * 25.0).sqrt() / 5.0 / LX_PER_FC, 1e-6));
    assert!(close(
        v["xyz"][1].as_f64().unwrap(),
        134.0 / CD_M2_PER_FL,
        1e-6
    ));

    // Text output.
    let (code, out, _) = cli(&["probe", "p.exr", "4", "3"], dir.path());
    assert_eq!(code, 0);
    assert!(out.contains("134 ± 3.92 cd/m²"), "{out}");
    assert!(out.contains("402 ± 9.8 lx"), "{out}");
    assert!(out.contains("0.3127 0.3290"), "{out}");
    let (_, out, _) = cli(&["probe", "p.exr", "0", "0"], dir.path());
    assert!(out.contains("undefined: pixel sees no surface"), "{out}");
}

#[test]
fn errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    image(&d.join("p.exr"));
    std::fs::write(d.join("text.exr"), "not an image").unwrap();
    let mut no_y = Layers::new(2, 2);
    no_y.channels.push(("A".into(), vec![0.0; 4]));
    output::write_exr(&d.join("noy.exr"), &no_y).unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["probe", "missing.exr", "0", "0"], "missing.exr"),
        (&["probe", "text.exr", "0", "0"], "text.exr"),
        (&["probe", "noy.exr", "0", "0"], "'Y'"),
        (&["probe", "p.exr", "9", "0"], "outside the 9×7 image"),
        (&["probe", "p.exr", "0", "7"], "outside"),
        (&["probe", "p.exr", "-1", "2"], "outside"),
    ];
    // A negative radius is a wrong command line: exit 2, before the file is read.
    let (code, _, err) = cli(&["probe", "p.exr", "1", "1", "--radius", "-2"], d);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--radius"), "{err}");
    for (args, needle) in cases {
        let (code, _, err) = cli(args, d);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(
            err.contains(needle),
            "{args:?}: '{err}' should mention {needle}"
        );
        assert!(
            err.contains(args[1]),
            "{args:?}: '{err}' should name the file"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
}
