//! False-colour maps agree with the EXR they came from: legend ticks are the step boundaries,
//! and every pixel is painted with the colour of the step its value lies in.

mod common;
use common::cli;
use std::path::Path;

use candela::output::{self, Layers, CHANNEL_E, CHANNEL_E_MASK, CHANNEL_E_STDERR};
use candela::photometry::{Quantity, LX_PER_FC};
use candela::report::falsecolour::{write_falsecolour, FalsecolourSettings, LegendInfo, Scale};
use candela::report::units::UnitSystem;

/// A `w`×`h` EXR whose luminance depends on the column only: Y(x) = `f(x)`.
fn ramp(path: &Path, w: usize, h: usize, f: impl Fn(usize) -> f32) -> Layers {
    let mut xyz = Vec::new();
    for _ in 0..h {
        for x in 0..w {
            let y = f(x);
            xyz.push([0.95 * y, y, 1.09 * y]);
        }
    }
    let layers = Layers::from_xyz(w, h, &xyz, &vec![0.1; w * h]);
    output::write_exr(path, &layers).unwrap();
    output::read_exr(path).unwrap()
}

fn map_pixel(img: &image::RgbImage, info: &LegendInfo, x: usize, y: usize) -> [u8; 3] {
    let z = info.zoom;
    let px = info.map_origin.0 + x as u32 * z + z / 2;
    let py = info.map_origin.1 + y as u32 * z + z / 2;
    img.get_pixel(px, py).0
}

fn check_steps(img: &image::RgbImage, info: &LegendInfo, layers: &Layers, expected: &[f64]) {
    let ticks = &info.scale.ticks;
    assert_eq!(ticks.len(), expected.len(), "ticks {ticks:?}");
    for (t, e) in ticks.iter().zip(expected) {
        assert!(
            (t - e).abs() <= 1e-9 * e.abs().max(1.0),
            "ticks {ticks:?} vs {expected:?}"
        );
    }
    let n = info.step_colours.len();
    assert_eq!(n + 1, ticks.len());
    // Neighbouring steps are distinguishable.
    for k in 1..n {
        assert_ne!(info.step_colours[k - 1], info.step_colours[k]);
    }
    let y = layers.channel("Y").unwrap();
    let mut checked = 0;
    for (x, &v) in y.iter().enumerate().take(layers.width) {
        let v = v as f64;
        // The step v lies in, from the boundaries alone (skip values on a boundary).
        if ticks
            .iter()
            .any(|b| (v - b).abs() < 1e-6 * b.abs().max(1.0))
        {
            continue;
        }
        let k = ticks[1..n].iter().filter(|&&b| v > b).count();
        for row in [0, layers.height / 2, layers.height - 1] {
            assert_eq!(
                map_pixel(img, info, x, row),
                info.step_colours[k],
                "pixel ({x}, {row}) with Y = {v} should have the colour of step {k}"
            );
        }
        checked += 1;
    }
    assert!(checked > layers.width / 2);
}

#[test]
fn linear_steps_match_the_exr() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("ramp.exr");
    let layers = ramp(&exr, 100, 12, |x| x as f32 * 10.0 + 5.0);
    let png = dir.path().join("ramp.png");
    let settings = FalsecolourSettings {
        min: Some(0.0),
        max: Some(1000.0),
        steps: Some(10),
        ..Default::default()
    };
    let info = write_falsecolour(&png, &layers, &settings).unwrap();
    let img = image::open(&png).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), info.image_size);
    assert_eq!(info.unit, "cd/m²");
    let expected: Vec<f64> = (0..=10).map(|k| k as f64 * 100.0).collect();
    check_steps(&img, &info, &layers, &expected);
    let (lo, mean, hi) = info.stats.unwrap();
    assert_eq!((lo, hi), (5.0, 995.0));
    assert!((mean - 500.0).abs() < 1e-9);
    assert_eq!(info.undefined_pixels, 0);
    assert_eq!((info.below_range, info.above_range), (0, 0));
}

#[test]
fn log_steps_match_the_exr() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("log.exr");
    // 1 … 10^3.96 cd/m²; automatic range = whole decades 1 … 10^4.
    let layers = ramp(&exr, 100, 8, |x| 10f32.powf(x as f32 / 25.0));
    let png = dir.path().join("log.png");
    let settings = FalsecolourSettings {
        scale: Scale::Log,
        steps: Some(8),
        ..Default::default()
    };
    let info = write_falsecolour(&png, &layers, &settings).unwrap();
    assert_eq!((info.scale.min, info.scale.max), (1.0, 1e4));
    let img = image::open(&png).unwrap().to_rgb8();
    let expected: Vec<f64> = (0..=8).map(|k| 10f64.powf(k as f64 / 2.0)).collect();
    check_steps(&img, &info, &layers, &expected);
}

#[test]
fn continuous_scale_automatic_range_and_contours() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("ramp.exr");
    let layers = ramp(&exr, 100, 6, |x| x as f32 * 10.0 + 5.0);
    let png = dir.path().join("c.png");
    let settings = FalsecolourSettings {
        contours: true,
        ..Default::default()
    };
    let info = write_falsecolour(&png, &layers, &settings).unwrap();
    // 0 … 99th percentile (985) rounded up to a nice number; ticks every tenth.
    assert_eq!((info.scale.min, info.scale.max), (0.0, 1000.0));
    let expected: Vec<f64> = (0..=10).map(|k| k as f64 * 100.0).collect();
    assert_eq!(info.scale.ticks, expected);
    assert!(info.step_colours.is_empty());
    let img = image::open(&png).unwrap().to_rgb8();
    let z = info.zoom;
    let (ox, oy) = info.map_origin;
    // Column 9 (95 cd/m²) and 10 (105 cd/m²) lie either side of the 100 tick: a contour on
    // the right edge of column 9; none between columns 4 and 5.
    let edge = |col: u32| img.get_pixel(ox + col * z + z - 1, oy + 2 * z + z / 2).0;
    assert_eq!(edge(9), [0, 0, 0]);
    assert_ne!(edge(4), [0, 0, 0]);
    // Continuous colours increase along the ramp (different at the two ends).
    assert_ne!(map_pixel(&img, &info, 2, 1), map_pixel(&img, &info, 97, 1));
}

fn illuminance_image(path: &Path) -> Layers {
    let (w, h) = (40, 20);
    let mut layers = Layers::from_xyz(w, h, &vec![[1.0, 1.0, 1.0]; w * h], &vec![0.0; w * h]);
    let mut e = Vec::new();
    let mut mask = Vec::new();
    for y in 0..h {
        for x in 0..w {
            if y < 5 {
                // The top rows see the sky: undefined.
                e.push(output::ILLUMINANCE_SENTINEL);
                mask.push(0.0);
            } else {
                e.push(x as f32 * LX_PER_FC as f32);
                mask.push(1.0);
            }
        }
    }
    layers.channels.push((CHANNEL_E.into(), e));
    layers
        .channels
        .push((CHANNEL_E_STDERR.into(), vec![0.0; w * h]));
    layers.channels.push((CHANNEL_E_MASK.into(), mask));
    output::write_exr(path, &layers).unwrap();
    output::read_exr(path).unwrap()
}

#[test]
fn illuminance_honours_the_mask_and_imperial_units() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("e.exr");
    let layers = illuminance_image(&exr);
    let png = dir.path().join("e.png");
    let settings = FalsecolourSettings {
        quantity: Quantity::Illuminance,
        units: UnitSystem::Imperial,
        min: Some(0.0),
        max: Some(40.0),
        steps: Some(4),
        ..Default::default()
    };
    let info = write_falsecolour(&png, &layers, &settings).unwrap();
    assert_eq!(info.unit, "fc");
    assert_eq!(info.undefined_pixels, 5 * 40);
    assert_eq!(info.scale.ticks, vec![0.0, 10.0, 20.0, 30.0, 40.0]);
    assert_eq!((info.below_range, info.above_range), (0, 0));
    // Column x has x fc: columns 0..9 step 0, 10..19 step 1 (skip the boundaries).
    let img = image::open(&png).unwrap().to_rgb8();
    for (x, k) in [(3, 0), (15, 1), (25, 2), (35, 3), (39, 3)] {
        assert_eq!(
            map_pixel(&img, &info, x, 10),
            info.step_colours[k],
            "column {x}"
        );
    }
    // Undefined pixels are neutral grey (hatched), never a scale colour.
    let (a, b) = candela::report::falsecolour::UNDEFINED_HATCH;
    for x in [0, 20, 39] {
        let p = map_pixel(&img, &info, x, 2);
        assert!(p == a.0 || p == b.0, "undefined pixel ({x}, 2) is {p:?}");
        assert!(p[0] == p[1] && p[1] == p[2]);
    }
    let (lo, _, hi) = info.stats.unwrap();
    assert!(lo.abs() < 1e-5 && (hi - 39.0).abs() < 1e-4, "{lo} {hi}");
}

#[test]
fn imperial_luminance_ticks_are_footlamberts() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("fl.exr");
    let fl = candela::photometry::CD_M2_PER_FL as f32;
    let layers = ramp(&exr, 50, 4, |x| (x as f32 + 0.5) * fl);
    let png = dir.path().join("fl.png");
    let settings = FalsecolourSettings {
        units: UnitSystem::Imperial,
        min: Some(0.0),
        max: Some(50.0),
        steps: Some(5),
        ..Default::default()
    };
    let info = write_falsecolour(&png, &layers, &settings).unwrap();
    assert_eq!(info.unit, "fL");
    let img = image::open(&png).unwrap().to_rgb8();
    for x in 0..50 {
        assert_eq!(map_pixel(&img, &info, x, 1), info.step_colours[x / 10]);
    }
}

fn pngs(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".png") || n.ends_with(".tmp"))
        .collect();
    v.sort();
    v
}

#[test]
fn command_line() {
    let dir = tempfile::tempdir().unwrap();
    ramp(&dir.path().join("ramp.exr"), 60, 10, |x| x as f32);
    let (code, out, err) = cli(
        &[
            "falsecolour",
            "ramp.exr",
            "--range",
            "0:60",
            "--steps",
            "6",
            "--contours",
        ],
        dir.path(),
    );
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("ramp.luminance.png"), "{out}");
    assert!(dir.path().join("ramp.luminance.png").exists());
    let (code, _, err) = cli(
        &[
            "falsecolour",
            "ramp.exr",
            "--scale",
            "log",
            "--units",
            "imperial",
            "-o",
            "x.png",
        ],
        dir.path(),
    );
    assert_eq!(code, 0, "{err}");
    assert!(dir.path().join("x.png").exists());
}

#[test]
fn command_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ramp(&d.join("ramp.exr"), 8, 8, |x| x as f32);
    std::fs::write(d.join("text.exr"), "not an image").unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["falsecolour", "missing.exr"], "missing.exr"),
        (&["falsecolour", "text.exr"], "text.exr"),
        (
            &["falsecolour", "ramp.exr", "--quantity", "illuminance"],
            "'E'",
        ),
        (&["falsecolour", "ramp.exr", "--range", "5:1"], "range"),
        (&["falsecolour", "ramp.exr", "--range", "abc"], "range"),
        (
            &[
                "falsecolour",
                "ramp.exr",
                "--scale",
                "log",
                "--range",
                "0:10",
            ],
            "positive",
        ),
        (&["falsecolour", "ramp.exr", "-o", "ramp.exr"], "overwrite"),
    ];
    for (args, needle) in cases {
        let (code, _, err) = cli(args, d);
        // A wrong --range is a wrong command line (exit 2); the rest concern the files (1).
        let expected = if args.contains(&"--range") { 2 } else { 1 };
        assert_eq!(code, expected, "{args:?}: {err}");
        assert!(
            err.contains(needle),
            "{args:?}: '{err}' should mention {needle}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert!(pngs(d).is_empty(), "{args:?} left {:?}", pngs(d));
    }
}

#[test]
fn values_outside_the_range_take_the_end_colours() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("ramp.exr");
    let layers = ramp(&exr, 100, 3, |x| x as f32 * 10.0 + 5.0);
    let png = dir.path().join("clip.png");
    let settings = FalsecolourSettings {
        min: Some(100.0),
        max: Some(900.0),
        steps: Some(8),
        ..Default::default()
    };
    let info = write_falsecolour(&png, &layers, &settings).unwrap();
    // Columns 0..9 (5…95) lie below, 90..99 (905…995) above.
    assert_eq!((info.below_range, info.above_range), (30, 30));
    let img = image::open(&png).unwrap().to_rgb8();
    assert_eq!(map_pixel(&img, &info, 0, 1), info.step_colours[0]);
    assert_eq!(map_pixel(&img, &info, 99, 1), info.step_colours[7]);
}
