//! Tests of `candela::output`: EXR round trip, NaN refusal, atomic writes, corrupt files,
//! PNG exposure.

use std::fs;
use std::io;
use std::path::Path;

use candela::output::*;

fn dir_entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn sample_layers() -> Layers {
    let (w, h) = (5, 3);
    let xyz: Vec<[f32; 3]> = (0..w * h)
        .map(|i| {
            let f = i as f32;
            [0.25 * f, 1.0e-3 + 7.5 * f, 1.0e4 + f]
        })
        .collect();
    let stderr: Vec<f32> = (0..w * h).map(|i| 0.01 * i as f32).collect();
    let mut layers = Layers::from_xyz(w, h, &xyz, &stderr);
    layers
        .attributes
        .push(("scene".into(), "cornell box (test) — ünïcode".into()));
    layers
        .attributes
        .push(("software".into(), "candela 0.1.0".into()));
    layers.attributes.push((
        "a_rather_long_attribute_name_over_31_bytes".into(),
        "x".into(),
    ));
    layers
}

fn sorted(mut l: Layers) -> Layers {
    l.channels.sort_by(|a, b| a.0.cmp(&b.0));
    l.attributes.sort();
    l
}

/// The same image is the same file: the header's attributes come out in one order (the exr
/// crate keeps custom attributes in a hash map whose order changes from map to map).
#[test]
fn the_same_image_is_written_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let mut layers = sample_layers();
    for k in 0..8 {
        layers
            .attributes
            .push((format!("extra_{k}"), format!("value {k}")));
    }
    let first = dir.path().join("0.exr");
    write_exr(&first, &layers).unwrap();
    let bytes = fs::read(&first).unwrap();
    for k in 1..12 {
        let p = dir.path().join(format!("{k}.exr"));
        write_exr(&p, &layers).unwrap();
        assert!(
            fs::read(&p).unwrap() == bytes,
            "write {k} differs from the first"
        );
    }
    assert_eq!(read_exr(&first).unwrap(), sorted(layers));
}

#[test]
fn exr_round_trip_values_names_attributes() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("image.exr");
    let layers = sample_layers();
    write_exr(&path, &layers).unwrap();
    let back = read_exr(&path).unwrap();
    assert_eq!((back.width, back.height), (5, 3));
    assert_eq!(back, sorted(layers.clone()));
    assert_eq!(back.attribute(ATTRIBUTE_UNITS), Some(UNITS_CD_PER_M2));
    assert_eq!(back.channel(CHANNEL_Y), layers.channel("Y"));
    assert_eq!(back.channel("stderr.Y"), layers.channel(CHANNEL_Y_STDERR));
    // No temporary file left beside it.
    assert_eq!(dir_entries(dir.path()), vec!["image.exr".to_string()]);
}

#[test]
fn exr_overwrites_existing_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("image.exr");
    fs::write(&path, b"old contents").unwrap();
    let layers = sample_layers();
    write_exr(&path, &layers).unwrap();
    assert_eq!(read_exr(&path).unwrap(), sorted(layers));
}

#[test]
fn exr_rejects_nan_and_inf_without_writing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("nan.exr");
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let mut layers = sample_layers();
        layers.channels[1].1[7] = bad; // channel Y, pixel (2, 1)
        let err = write_exr(&path, &layers).unwrap_err();
        match &err {
            OutputError::NonFinite { channel, x, y, .. } => {
                assert_eq!((channel.as_str(), *x, *y), ("Y", 2, 1));
            }
            other => panic!("unexpected error {other:?}"),
        }
        assert!(err.to_string().contains("nan.exr"), "{err}");
        assert!(!path.exists());
        assert!(dir_entries(dir.path()).is_empty());

        // Replacing is the caller's explicit choice.
        assert_eq!(layers.replace_non_finite(0.0), 1);
        write_exr(&path, &layers).unwrap();
        assert_eq!(read_exr(&path).unwrap().channel("Y").unwrap()[7], 0.0);
        fs::remove_file(&path).unwrap();
    }
}

#[test]
fn exr_rejects_inconsistent_images() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.exr");
    let mut short = sample_layers();
    short.channels[0].1.pop();
    let mut dup = sample_layers();
    dup.channels[1].0 = "X".into();
    let mut reserved = sample_layers();
    reserved
        .attributes
        .push(("dataWindow".into(), "nope".into()));
    let empty = Layers::new(0, 3);
    for bad in [short, dup, reserved, empty] {
        let err = write_exr(&path, &bad).unwrap_err();
        assert!(matches!(err, OutputError::InvalidImage { .. }), "{err:?}");
        assert!(err.to_string().contains("bad.exr"));
        assert!(!path.exists());
    }
}

#[test]
fn corrupt_and_truncated_exr_give_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.exr");
    write_exr(&good, &sample_layers()).unwrap();
    let bytes = fs::read(&good).unwrap();

    let mut cases: Vec<(&str, Vec<u8>)> = vec![
        ("empty.exr", Vec::new()),
        (
            "garbage.exr",
            (0..4096u32).map(|i| (i * 7919 % 251) as u8).collect(),
        ),
        ("magic_only.exr", bytes[..4].to_vec()),
    ];
    for cut in [8, 40, bytes.len() / 2, bytes.len() - 1] {
        cases.push(("truncated.exr", bytes[..cut].to_vec()));
    }
    // Flip bytes in the pixel data and in the header.
    for pos in [20, bytes.len() - 10, bytes.len() / 2] {
        let mut b = bytes.clone();
        b[pos] ^= 0xff;
        cases.push(("flipped.exr", b));
    }
    for (name, content) in cases {
        let path = dir.path().join(name);
        fs::write(&path, &content).unwrap();
        match read_exr(&path) {
            Err(err) => assert!(err.to_string().contains(name), "{err}"),
            // A flipped byte inside compressed data may still decode to other numbers;
            // it must at least not panic.
            Ok(_) => assert_eq!(name, "flipped.exr"),
        }
    }
    let missing = dir.path().join("missing.exr");
    let err = read_exr(&missing).unwrap_err();
    assert!(matches!(err, OutputError::Io { .. }));
    assert!(err.to_string().contains("missing.exr"));
}

#[test]
fn atomic_failing_writer_leaves_no_target_and_no_temp() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.bin");
    let err = write_atomic(&path, |w| {
        w.write_all(b"partial")?;
        Err(io::Error::other("simulated failure"))
    })
    .unwrap_err();
    assert!(err.to_string().contains("out.bin"), "{err}");
    assert!(err.to_string().contains("simulated failure"), "{err}");
    assert!(dir_entries(dir.path()).is_empty());
}

#[test]
fn atomic_existing_target_survives_failed_write() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.bin");
    fs::write(&path, b"precious").unwrap();
    // Large enough to spill out of the write buffer before failing.
    let big = vec![b'x'; 1 << 20];
    let res = write_atomic(&path, |w| {
        w.write_all(&big)?;
        Err(io::Error::other("disk full"))
    });
    assert!(res.is_err());
    assert_eq!(fs::read(&path).unwrap(), b"precious");
    assert_eq!(dir_entries(dir.path()), vec!["out.bin".to_string()]);
}

#[test]
fn atomic_panicking_writer_leaves_no_temp() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.bin");
    fs::write(&path, b"precious").unwrap();
    let res = std::panic::catch_unwind(|| {
        let _ = write_atomic(&path, |w| {
            w.write_all(b"partial")?;
            panic!("writer panicked");
        });
    });
    assert!(res.is_err());
    assert_eq!(fs::read(&path).unwrap(), b"precious");
    assert_eq!(dir_entries(dir.path()), vec!["out.bin".to_string()]);
}

#[test]
fn atomic_success_replaces_and_relative_paths_work() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.bin");
    fs::write(&path, b"old").unwrap();
    write_atomic(&path, |w| w.write_all(b"new")).unwrap();
    assert_eq!(fs::read(&path).unwrap(), b"new");
    assert_eq!(dir_entries(dir.path()), vec!["out.bin".to_string()]);
    // Into a missing directory: an error naming the file, not a panic.
    let err = write_atomic(&dir.path().join("nope/out.bin"), |w| w.write_all(b"x")).unwrap_err();
    assert!(err.to_string().contains("out.bin"));
    // A directory as target.
    assert!(write_atomic(dir.path(), |w| w.write_all(b"x")).is_err());
}

/// IEC 61966-2-1 encoding, written out independently of the crate.
fn encode8(v: f64) -> u8 {
    let e = if v <= 0.0031308 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (e * 255.0).round() as u8
}

/// XYZ of a D65-white (achromatic) surface of luminance `y`.
fn grey(y: f64) -> [f32; 3] {
    [(0.95047 * y) as f32, y as f32, (1.08883 * y) as f32]
}

fn read_png(path: &Path) -> image::RgbImage {
    image::open(path).unwrap().to_rgb8()
}

#[test]
fn png_auto_exposure_maps_uniform_grey_to_18_percent() {
    // 1.055·0.18^(1/2.4) − 0.055 = 0.46135; ×255 = 117.6 → 118.
    assert_eq!(encode8(0.18), 118);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("grey.png");
    for luminance in [0.18, 1.0, 57.3, 3.0e4] {
        let (w, h) = (7, 4);
        let xyz = vec![grey(luminance); w * h];
        let info = write_srgb_png(&path, w, h, &xyz, &PngSettings { exposure_ev: None }).unwrap();
        // Meter reading: L = 12.5·2^EV/100.
        let expected_ev = (luminance * 100.0 / 12.5).log2();
        assert!((info.exposure_ev - expected_ev).abs() < 1e-6, "{info:?}");
        assert!((info.scale * luminance - 0.18).abs() < 1e-6, "{info:?}");
        let img = read_png(&path);
        assert_eq!(img.dimensions(), (7, 4));
        for p in img.pixels() {
            assert_eq!(p.0, [118, 118, 118], "luminance {luminance}");
        }
    }
    assert_eq!(dir_entries(dir.path()), vec!["grey.png".to_string()]);
}

#[test]
fn png_auto_exposure_ignores_brightest_percent_and_zeros() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.png");
    let (w, h) = (20, 15); // 300 pixels: 250 at 40 cd/m², 48 black, 2 lamps (1 % of 252)
    let mut xyz = vec![grey(40.0); w * h];
    for p in xyz.iter_mut().take(48) {
        *p = [0.0; 3];
    }
    xyz[100] = grey(1.0e7);
    xyz[101] = grey(1.0e8);
    let info = write_srgb_png(&path, w, h, &xyz, &PngSettings::default()).unwrap();
    assert!(
        (info.exposure_ev - (40.0f64 * 8.0).log2()).abs() < 1e-9,
        "{info:?}"
    );
    let img = read_png(&path);
    assert_eq!(img.get_pixel(0, 0).0, [0, 0, 0]);
    assert_eq!(img.get_pixel(0, 5).0, [255, 255, 255]); // lamp, clipped
    assert_eq!(img.get_pixel(19, 14).0, [118, 118, 118]);

    // All black: EV 0, all zeros.
    let info = write_srgb_png(&path, 2, 2, &[[0.0; 3]; 4], &PngSettings::default()).unwrap();
    assert_eq!(info.exposure_ev, 0.0);
    assert!(read_png(&path).pixels().all(|p| p.0 == [0, 0, 0]));
}

#[test]
fn png_fixed_ev_follows_documented_mapping() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fixed.png");
    for ev in [-3.0, 0.0, 7.5, 10.0, 15.0] {
        let scale = 0.18 * 100.0 / (12.5 * f64::exp2(ev));
        assert!((ev_to_scale(ev) - scale).abs() < 1e-12 * scale);
        assert!((ev_to_scale(ev) - 1.44 * f64::exp2(-ev)).abs() < 1e-12 * scale);
        // Metered grey (L = 12.5·2^EV/100) → 0.18; other display values along a ramp.
        let displays = [0.0, 0.002, 0.01, 0.05, 0.18, 0.3, 0.7, 0.95, 1.0, 1.5, 40.0];
        let xyz: Vec<[f32; 3]> = displays.iter().map(|d| grey(d / scale)).collect();
        let info = write_srgb_png(
            &path,
            displays.len(),
            1,
            &xyz,
            &PngSettings {
                exposure_ev: Some(ev),
            },
        )
        .unwrap();
        assert_eq!(info.exposure_ev, ev);
        assert!((info.scale - scale).abs() < 1e-12 * scale);
        let img = read_png(&path);
        for (i, d) in displays.iter().enumerate() {
            let expected = encode8(d.min(1.0));
            let got = img.get_pixel(i as u32, 0).0;
            for c in got {
                assert!(
                    (c as i32 - expected as i32).abs() <= 1,
                    "EV {ev}, display {d}: got {got:?}, expected {expected}"
                );
            }
        }
        assert_eq!(img.get_pixel(4, 0).0, [118, 118, 118]);
    }
    // At EV 10 a 128 cd/m² surface is middle grey.
    let info = write_srgb_png(
        &path,
        1,
        1,
        &[grey(128.0)],
        &PngSettings {
            exposure_ev: Some(10.0),
        },
    )
    .unwrap();
    assert!((info.scale * 128.0 - 0.18).abs() < 1e-12);
    assert_eq!(read_png(&path).get_pixel(0, 0).0, [118, 118, 118]);
}

#[test]
fn png_colour_and_errors() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.png");
    // sRGB red primary (x=0.64, y=0.33) at display-linear 0.5 under EV 0.
    let scale = ev_to_scale(0.0);
    let y = 0.2126 * 0.5 / scale;
    let red = [
        (0.4124 * 0.5 / scale) as f32,
        y as f32,
        (0.0193 * 0.5 / scale) as f32,
    ];
    write_srgb_png(
        &path,
        1,
        1,
        &[red],
        &PngSettings {
            exposure_ev: Some(0.0),
        },
    )
    .unwrap();
    let p = read_png(&path).get_pixel(0, 0).0;
    assert!(
        (p[0] as i32 - encode8(0.5) as i32).abs() <= 1 && p[1] <= 1 && p[2] <= 1,
        "{p:?}"
    );

    // Errors name the file and write nothing.
    let bad = dir.path().join("bad.png");
    let nan = [[f32::NAN, 0.0, 0.0]];
    let err = write_srgb_png(&bad, 1, 1, &nan, &PngSettings::default()).unwrap_err();
    assert!(matches!(err, OutputError::NonFinite { .. }) && err.to_string().contains("bad.png"));
    let err = write_srgb_png(&bad, 2, 1, &[red], &PngSettings::default()).unwrap_err();
    assert!(matches!(err, OutputError::InvalidImage { .. }) && err.to_string().contains("bad.png"));
    let inf_ev = PngSettings {
        exposure_ev: Some(f64::INFINITY),
    };
    assert!(write_srgb_png(&bad, 1, 1, &[red], &inf_ev).is_err());
    assert!(!bad.exists());
}
