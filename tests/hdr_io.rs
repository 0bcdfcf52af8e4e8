//! Radiance HDR output: candela's pictures read back (by candela and by Radiance's own
//! `pvalue` and `getinfo`, from PyPI `pyradiance`) to the luminance written, within RGBE
//! precision; malformed pictures are refused with errors naming the file.

mod common;

use candela::output::{read_hdr, read_hdr_luminance, read_image, write_hdr};
use common::pyradiance_dir;
use std::path::Path;
use std::process::Command;

/// Runs a Radiance tool from pyradiance; returns its standard output.
fn radiance(tool: &str, args: &[&str]) -> String {
    let pkg = pyradiance_dir();
    let out = Command::new(pkg.join("bin").join(tool))
        .args(args)
        .env("RAYPATH", pkg.join("lib"))
        .output()
        .unwrap_or_else(|e| panic!("run {tool}: {e}"));
    assert!(
        out.status.success(),
        "{tool} {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// XYZ of a test image: greys and in-gamut colours over six decades of luminance.
fn test_image(w: usize, h: usize) -> Vec<[f32; 3]> {
    (0..w * h)
        .map(|i| {
            let y = 10f64.powf(-2.0 + 6.0 * ((i * 37) % 101) as f64 / 100.0);
            // Chromaticities inside the Radiance primaries' gamut, around the white point.
            let (cx, cy) = match i % 4 {
                0 => (1.0 / 3.0, 1.0 / 3.0),
                1 => (0.45, 0.40),
                2 => (0.25, 0.30),
                _ => (0.31, 0.45),
            };
            let x = y * cx / cy;
            let z = y * (1.0 - cx - cy) / cy;
            [x as f32, y as f32, z as f32]
        })
        .collect()
}

/// The luminance Radiance reads from RGBE (R, G, B decoded at the middle of their step) can
/// differ from the value written by half a step of the largest component, 2⁻⁸ of it: below
/// 1 % of the luminance for these colours (each component ≤ 1.7 × Y here).
const RGBE_RELATIVE: f64 = 0.01;

#[test]
fn written_pictures_read_back_to_the_luminance() {
    let dir = tempfile::tempdir().unwrap();
    // 40 wide: run-length encoded; 5 wide: flat scanlines.
    for (w, h) in [(40usize, 7usize), (5, 3)] {
        let path = dir.path().join(format!("t{w}.hdr"));
        let xyz = test_image(w, h);
        write_hdr(
            &path,
            w,
            h,
            &xyz,
            Some("-vta -vp 0 0 0 -vd 0 0 1 -vu 0 1 0 -vh 180 -vv 180"),
            &[],
        )
        .unwrap();
        let (rw, rh, lum, view) = read_hdr_luminance(&path).unwrap();
        assert_eq!((rw, rh), (w, h));
        assert!(view.unwrap().starts_with("-vta"));
        for (i, (p, l)) in xyz.iter().zip(&lum).enumerate() {
            let rel = (*l as f64 / p[1] as f64 - 1.0).abs();
            assert!(rel < RGBE_RELATIVE, "pixel {i}: wrote {} read {l}", p[1]);
        }
        // Colour too: x and y chromaticity within RGBE precision.
        let back = read_hdr(&path).unwrap();
        for (p, q) in xyz.iter().zip(&back.xyz) {
            let s = |v: &[f32; 3]| v[0] as f64 + v[1] as f64 + v[2] as f64;
            assert!((p[0] as f64 / s(p) - q[0] as f64 / s(q)).abs() < 0.01);
        }
        // `read_image` recognises the picture and gives candela's channels.
        let layers = read_image(&path).unwrap();
        assert_eq!(layers.attribute("units"), Some("cd/m^2"));
        assert_eq!(layers.channel("Y").unwrap(), lum.as_slice());
    }
}

#[test]
fn out_of_gamut_colours_keep_their_luminance() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("g.hdr");
    // Spectral green and violet: far outside the primaries.
    let xyz = [[0.02f32, 0.9, 0.05], [0.9, 0.05, 4.5]];
    write_hdr(&path, 2, 1, &xyz, None, &[]).unwrap();
    let (_, _, lum, view) = read_hdr_luminance(&path).unwrap();
    assert!(view.is_none());
    for (p, l) in xyz.iter().zip(&lum) {
        assert!((*l / p[1] - 1.0).abs() < 0.02, "{} vs {l}", p[1]);
    }
}

/// Radiance's `pvalue -o -b` (brightness with the exposure undone) × 179 is candela's
/// luminance; `getinfo` shows the VIEW line.
#[test]
fn radiance_reads_candelas_luminance_and_view() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.hdr");
    let (w, h) = (40usize, 6usize);
    let xyz = test_image(w, h);
    let view = "-vta -vp 1 2 3 -vd 0 0 1 -vu 0 1 0 -vh 180 -vv 180";
    write_hdr(
        &path,
        w,
        h,
        &xyz,
        Some(view),
        &["CANDELA_PROJECTION=x".into()],
    )
    .unwrap();
    let p = path.to_str().unwrap();
    let values = radiance("pvalue", &["-h", "-H", "-o", "-b", "-d", p]);
    let lum: Vec<f64> = values
        .split_whitespace()
        .map(|t| t.parse::<f64>().unwrap() * 179.0)
        .collect();
    assert_eq!(lum.len(), w * h);
    for (i, (q, l)) in xyz.iter().zip(&lum).enumerate() {
        let rel = (l / q[1] as f64 - 1.0).abs();
        assert!(
            rel < RGBE_RELATIVE,
            "pixel {i}: wrote {} cd/m², pvalue {l}",
            q[1]
        );
    }
    let info = radiance("getinfo", &[p]);
    assert!(info.contains(&format!("VIEW= {view}")), "{info}");
    assert!(info.contains("FORMAT=32-bit_rle_rgbe"), "{info}");
    // And candela reads a picture Radiance wrote (pvalue -r: flat, no run-length encoding).
    let made = dir.path().join("made.hdr");
    let text: String = (0..8 * 2)
        .map(|i| {
            format!(
                "{} {} {}\n",
                0.1 * i as f64,
                0.2 * i as f64,
                0.05 * i as f64
            )
        })
        .collect();
    let src = dir.path().join("v.txt");
    std::fs::write(&src, text).unwrap();
    let out = Command::new(pyradiance_dir().join("bin/pvalue"))
        .args([
            "-r",
            "-h",
            "-y",
            "2",
            "+x",
            "8",
            "-d",
            src.to_str().unwrap(),
        ])
        .env("RAYPATH", pyradiance_dir().join("lib"))
        .output()
        .unwrap();
    assert!(out.status.success());
    std::fs::write(&made, &out.stdout).unwrap();
    let (_, _, lum, _) = read_hdr_luminance(&made).unwrap();
    for (i, l) in lum.iter().enumerate() {
        let want = 179.0 * (0.26510582 * 0.1 + 0.67010582 * 0.2 + 0.06478836 * 0.05) * i as f64;
        assert!(
            (*l as f64 - want).abs() <= 0.01 * want + 1e-9,
            "pixel {i}: {l} vs {want}"
        );
    }
}

fn refused(name: &str, bytes: &[u8], want: &str) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    let e = read_hdr(&path).unwrap_err().to_string();
    assert!(
        e.contains(name),
        "{name}: error does not name the file: {e}"
    );
    assert!(e.contains(want), "{name}: {e}");
    let e = read_image(&path).unwrap_err().to_string();
    assert!(e.contains(name), "{e}");
}

#[test]
fn malformed_pictures_are_refused_naming_the_file() {
    let head = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n".to_vec();
    let with = |tail: &[u8]| [head.as_slice(), tail].concat();
    refused(
        "nohead.hdr",
        b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n",
        "does not end",
    );
    refused("nores.hdr", &head, "resolution");
    refused("badres.hdr", &with(b"-Y two +X 3\n"), "resolution line");
    refused("turned.hdr", &with(b"+X 3 -Y 2\n"), "resolution line");
    refused(
        "short.hdr",
        &with(b"-Y 2 +X 3\n\x01\x02\x03\x80"),
        "truncated",
    );
    refused(
        "format.hdr",
        b"#?RADIANCE\nFORMAT=32-bit_rle_xyz\n\n-Y 1 +X 1\n\0\0\0\0",
        "unsupported FORMAT",
    );
    refused(
        "exposure.hdr",
        b"#?RADIANCE\nEXPOSURE=-1\n\n-Y 1 +X 1\n\0\0\0\0",
        "EXPOSURE",
    );
    // Brighter than f32 holds, and an exposure that underflows.
    refused(
        "bright.hdr",
        &with(b"-Y 1 +X 1\n\xff\xff\xff\xff"),
        "too bright",
    );
    let mut tiny = b"#?RADIANCE\n".to_vec();
    for _ in 0..4 {
        tiny.extend(b"EXPOSURE=1e-300\n");
    }
    tiny.extend(b"\n-Y 1 +X 1\n\x80\x80\x80\x80");
    refused("exposures.hdr", &tiny, "out of range");
    // A run longer than its scanline.
    let mut rle = with(b"-Y 1 +X 8\n");
    rle.extend([2, 2, 0, 8, 128 + 9, 5, 0, 0]);
    refused("overrun.hdr", &rle, "overruns");
    // An old-style run with nothing to repeat.
    refused(
        "orphan.hdr",
        &with(b"-Y 1 +X 2\n\x01\x01\x01\x05\0\0\0\0"),
        "repeats no previous",
    );
    // Huge: refused before allocating, from the header alone: more scanlines than the file
    // could hold, or more pixels than memory (16 scanlines of 2³¹ − 1 pixels, 20 bytes each
    // in old-style runs, 412 GB decoded).
    refused(
        "huge.hdr",
        &with(b"-Y 2000000000 +X 2000000000\n"),
        "take at least 40000000000 bytes",
    );
    let mut line = vec![128, 128, 128, 129];
    for digit in [255, 255, 255, 127] {
        line.extend([1, 1, 1, digit]);
    }
    refused(
        "wide.hdr",
        &with(&[&b"-Y 16 +X 2147483647\n"[..], &line.repeat(16)].concat()),
        "memory",
    );
    // Not a Radiance picture at all.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plain.hdr");
    std::fs::write(&path, b"P6\n1 1\n255\n\0\0\0").unwrap();
    let e = read_hdr(&path).unwrap_err().to_string();
    assert!(e.contains("plain.hdr") && e.contains("#?"), "{e}");
    assert!(read_hdr(Path::new("/nonexistent/x.hdr"))
        .unwrap_err()
        .to_string()
        .contains("x.hdr"));
}

/// Old-style run-length scanlines (a pixel 1,1,1,n repeats the previous one n times, shifted
/// by 8 bits per consecutive run) and bottom-to-top rows.
#[test]
fn old_run_lengths_and_flipped_rows_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("old.hdr");
    let mut b = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n+Y 2 +X 3\n".to_vec();
    // Bottom row: one pixel repeated; top row: three different pixels.
    b.extend([128, 128, 128, 129, 1, 1, 1, 2]);
    b.extend([128, 128, 128, 130, 128, 128, 128, 131, 128, 128, 128, 132]);
    std::fs::write(&path, &b).unwrap();
    let (w, h, lum, _) = read_hdr_luminance(&path).unwrap();
    assert_eq!((w, h), (3, 2));
    // 128 at exponent 129 is (128.5/256)·2 = 1.00390625 (Radiance's colr_color).
    let unit = (179.0 * 1.003_906_25f64) as f32;
    let want = [2.0, 4.0, 8.0, 1.0, 1.0, 1.0].map(|k| k * unit);
    for (l, w) in lum.iter().zip(want) {
        assert!((l / w - 1.0).abs() < 1e-5, "{lum:?}");
    }
}

/// A render writes NAME.hdr beside the EXR, with the camera's VIEW; the EXR carries the view
/// and projection; `candela probe` reads the .hdr.
#[test]
fn a_fisheye_render_writes_its_view_into_the_hdr_and_the_exr() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("eye.ron");
    std::fs::write(
        &scene,
        r#"(camera: (position: (0, 1, 0), look_at: (0, 1, 1), resolution: (16, 16),
             projection: Fisheye(mapping: Equidistant, fov_deg: 180)),
           render: (spp: 2),
           lights: [Sky(model: Uniform, amount: HorizontalIlluminance(3141.592653589793))])"#,
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .args([
            "render",
            scene.to_str().unwrap(),
            "--threads",
            "1",
            "--quiet",
        ])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let hdr = dir.path().join("eye.hdr");
    let (w, h, lum, view) = read_hdr_luminance(&hdr).unwrap();
    assert_eq!((w, h), (16, 16));
    let view = view.expect("VIEW line");
    assert!(
        view.starts_with("-vta -vp 0 1 0 -vd 0 0 1 -vu 0 1 0 -vh 180 -vv 180"),
        "{view}"
    );
    // Corners are outside the image circle: black.
    assert_eq!(lum[0], 0.0);
    let info = radiance("getinfo", &[hdr.to_str().unwrap()]);
    assert!(info.contains("VIEW= -vta"), "{info}");
    let exr = candela::output::read_exr(&dir.path().join("eye.exr")).unwrap();
    assert_eq!(exr.attribute("radiance_view"), Some(view.as_str()));
    assert_eq!(
        exr.attribute("projection"),
        Some("Fisheye(mapping: Equidistant, fov_deg: 180)")
    );
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .args(["probe", hdr.to_str().unwrap(), "8", "8", "--json"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let l = v["luminance"]["mean"].as_f64().or(v["luminance"].as_f64());
    assert!(l.is_some(), "{v}");
}

/// A constant picture in the densest scanlines the reader takes: one literal pixel, then
/// old-style runs of it whose counts are the base-256 digits of the remaining width − 1.
fn densest_picture(w: usize, h: usize, flip: bool) -> (Vec<u8>, usize) {
    let mut b = format!(
        "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n{} {h} +X {w}\n",
        if flip { "+Y" } else { "-Y" }
    )
    .into_bytes();
    let head = b.len();
    let mut line = vec![128, 128, 128, 129];
    let mut rest = w - 1;
    while rest > 0 {
        line.extend([1, 1, 1, (rest & 255) as u8]);
        rest >>= 8;
    }
    for _ in 0..h {
        b.extend(&line);
    }
    (b, head)
}

/// The size check from the resolution line is exact: a picture in the densest scanlines
/// (`min_scanline_bytes` each) is read, to the values Radiance's `pvalue` reads from it, and
/// the same picture one byte short is refused before any pixel is decoded, naming the file
/// and the bytes the declared size needs.
#[test]
fn the_densest_scanlines_pass_the_size_check_and_one_byte_less_does_not() {
    use candela::output::min_scanline_bytes;
    let dir = tempfile::tempdir().unwrap();
    // 128 at exponent 129 is (128.5/256)·2 = 1.00390625 in every channel: a grey.
    let want = 179.0 * 1.003_906_25f64;
    for (w, h) in [
        (1, 3),
        (2, 2),
        (7, 2),
        (256, 2),
        (257, 3),
        (300, 2),
        (65537, 2),
    ] {
        for flip in [false, true] {
            let (bytes, head) = densest_picture(w, h, flip);
            assert_eq!(
                (bytes.len() - head) as u64,
                h as u64 * min_scanline_bytes(w)
            );
            let path = dir.path().join(format!("dense-{w}.hdr"));
            std::fs::write(&path, &bytes).unwrap();
            let (rw, rh, lum, _) = read_hdr_luminance(&path).unwrap();
            assert_eq!((rw, rh, lum.len()), (w, h, w * h));
            for l in &lum {
                assert!((*l as f64 / want - 1.0).abs() < 1e-6, "{w}×{h}: {l}");
            }
            let layers = read_image(&path).unwrap();
            assert_eq!(layers.channel("Y").unwrap(), lum.as_slice());
            let cut = dir.path().join(format!("cut-{w}.hdr"));
            std::fs::write(&cut, &bytes[..bytes.len() - 1]).unwrap();
            let e = read_hdr(&cut).unwrap_err().to_string();
            let need = h as u64 * min_scanline_bytes(w);
            assert!(
                e.contains(&format!("cut-{w}.hdr"))
                    && e.contains(&format!("at least {need} bytes")),
                "{e}"
            );
        }
    }
    // Radiance reads the densest picture to the same brightness (its getinfo, then pvalue).
    let (bytes, _) = densest_picture(300, 2, false);
    let path = dir.path().join("dense.hdr");
    std::fs::write(&path, &bytes).unwrap();
    let out = radiance("pvalue", &["-h", "-H", "-b", "-d", path.to_str().unwrap()]);
    let values: Vec<f64> = out.split_whitespace().map(|t| t.parse().unwrap()).collect();
    assert_eq!(values.len(), 600, "{out}");
    // pvalue prints 4 significant digits: half a unit of the last is 5e-4 of 1.004.
    for v in values {
        assert!((v * 179.0 / want - 1.0).abs() < 5e-4, "pvalue gives {v}");
    }
}

/// Rows are placed by the resolution line's orientation: a `+Y` picture's first scanline is
/// the bottom row, read the same through `read_hdr` and `read_image`.
#[test]
fn bottom_to_top_pictures_read_the_same_both_ways() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rows.hdr");
    let mut b = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n+Y 3 +X 1\n".to_vec();
    for e in [129, 130, 131] {
        b.extend([128, 128, 128, e]);
    }
    std::fs::write(&path, &b).unwrap();
    let img = read_hdr(&path).unwrap();
    let layers = read_image(&path).unwrap();
    let y: Vec<f32> = img.xyz.iter().map(|p| p[1]).collect();
    assert_eq!(layers.channel("Y").unwrap(), y.as_slice());
    assert_eq!(layers, img.to_layers());
    // Top row first: the last scanline in the file (exponent 131) is 4 × the first.
    assert!((y[0] / y[2] - 4.0).abs() < 1e-6, "{y:?}");
}
