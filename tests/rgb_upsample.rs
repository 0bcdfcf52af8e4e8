//! Tests of the Jakob–Hanika sRGB → reflectance upsampler, checked against an independent
//! re-computation of each fitted spectrum's colour from `SigmoidSpectrum::value`.

use candela::colour::rgb::xyz_to_linear_srgb;
use candela::colour::tables::{cmfs, named_spectrum, Observer};
use candela::spectrum::rgb_upsample::{fit_linear_srgb, SigmoidSpectrum, UpsampleError};

/// XYZ of a reflectance under D65, 1 nm sums over 360–830 nm, perfect white at Y = 1.
fn xyz_of(r: impl Fn(f64) -> f64) -> [f64; 3] {
    let cmf = cmfs(Observer::Cie1931_2);
    let d65 = named_spectrum("D65").unwrap();
    let (mut xyz, mut norm) = ([0.0; 3], 0.0);
    for i in 0..471 {
        let nm = 360.0 + i as f64;
        let e = d65.value(nm);
        let v = r(nm);
        xyz[0] += v * e * cmf.x[i];
        xyz[1] += v * e * cmf.y[i];
        xyz[2] += v * e * cmf.z[i];
        norm += e * cmf.y[i];
    }
    xyz.map(|v| v / norm)
}

fn lab(xyz: [f64; 3], white: [f64; 3]) -> [f64; 3] {
    let f = |t: f64| {
        if t > (6.0f64 / 29.0).powi(3) {
            t.cbrt()
        } else {
            t / (3.0 * (6.0f64 / 29.0).powi(2)) + 4.0 / 29.0
        }
    };
    let (fx, fy, fz) = (
        f(xyz[0] / white[0]),
        f(xyz[1] / white[1]),
        f(xyz[2] / white[2]),
    );
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// ΔE*ab between the spectrum's colour and the target linear sRGB colour, where the target
/// is taken to XYZ with the same white-balanced sRGB convention (documented in the module).
fn independent_delta_e(s: &SigmoidSpectrum, rgb: [f64; 3]) -> f64 {
    let white = xyz_of(|_| 1.0);
    let w_rgb = xyz_to_linear_srgb(white);
    let xyz = xyz_of(|nm| s.value(nm));
    // Target XYZ: solve M·xyz = rgb ⊙ W by bisection-free linear algebra (Cramer).
    let m: Vec<[f64; 3]> = (0..3)
        .map(|j| {
            let mut e = [0.0; 3];
            e[j] = 1.0;
            xyz_to_linear_srgb(e)
        })
        .collect(); // columns
    let b = [rgb[0] * w_rgb[0], rgb[1] * w_rgb[1], rgb[2] * w_rgb[2]];
    let det = |c0: [f64; 3], c1: [f64; 3], c2: [f64; 3]| {
        c0[0] * (c1[1] * c2[2] - c2[1] * c1[2]) - c1[0] * (c0[1] * c2[2] - c2[1] * c0[2])
            + c2[0] * (c0[1] * c1[2] - c1[1] * c0[2])
    };
    let d = det(m[0], m[1], m[2]);
    let target = [
        det(b, m[1], m[2]) / d,
        det(m[0], b, m[2]) / d,
        det(m[0], m[1], b) / d,
    ];
    let (a, t) = (lab(xyz, white), lab(target, white));
    ((a[0] - t[0]).powi(2) + (a[1] - t[1]).powi(2) + (a[2] - t[2]).powi(2)).sqrt()
}

fn assert_valid_values(s: &SigmoidSpectrum) {
    for nm in (300..=900).map(f64::from).chain([360.5, 829.9, 1e4, -1e4]) {
        let v = s.value(nm);
        assert!((0.0..=1.0).contains(&v), "{s:?} at {nm} nm = {v}");
    }
}

#[test]
fn grid_of_in_gamut_colours_round_trips() {
    let levels: Vec<f64> = (0..6).map(|i| 0.02 + 0.96 * i as f64 / 5.0).collect();
    let (mut max_reported, mut max_independent) = (0.0f64, 0.0f64);
    let mut worst = [0.0; 3];
    for &r in &levels {
        for &g in &levels {
            for &b in &levels {
                let rgb = [r, g, b];
                let (s, residual) = fit_linear_srgb(rgb).unwrap();
                let de = independent_delta_e(&s, rgb);
                assert!((de - residual).abs() < 1e-6, "{rgb:?}: {de} vs {residual}");
                if de > max_independent {
                    worst = rgb;
                }
                max_reported = max_reported.max(residual);
                max_independent = max_independent.max(de);
                assert_valid_values(&s);
            }
        }
    }
    println!("6³ grid: max ΔE*ab reported {max_reported:.3e}, recomputed {max_independent:.3e} at {worst:?}");
    assert!(
        max_independent < 1e-3,
        "max ΔE {max_independent} at {worst:?}"
    );
}

#[test]
fn greys_are_flat_and_black_white_are_exact() {
    for g in [1e-6, 0.02, 0.18, 0.5, 0.9, 0.999999] {
        let (s, residual) = fit_linear_srgb([g, g, g]).unwrap();
        assert_eq!(s.c[0], 0.0);
        assert_eq!(s.c[1], 0.0);
        assert!(residual < 1e-9, "{g}: {residual}");
        for nm in [360.0, 555.0, 830.0] {
            assert!(
                (s.value(nm) - g).abs() < 1e-12,
                "{g} at {nm}: {}",
                s.value(nm)
            );
        }
    }
    let (black, r) = fit_linear_srgb([0.0; 3]).unwrap();
    assert_eq!(black.constant, Some(0.0));
    assert!(r < 1e-9);
    assert!((360..=830).all(|nm| black.value(nm as f64) == 0.0));
    let (white, r) = fit_linear_srgb([1.0; 3]).unwrap();
    assert_eq!(white.constant, Some(1.0));
    assert!(r < 1e-9);
    assert!((360..=830).all(|nm| white.value(nm as f64) == 1.0));
}

fn srgb_decode(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

#[test]
fn colorchecker_colours_round_trip() {
    // Commonly published 8-bit sRGB values of the 24 ColorChecker patches (X-Rite, 2009+).
    const PATCHES: [[u8; 3]; 24] = [
        [115, 82, 68],
        [194, 150, 130],
        [98, 122, 157],
        [87, 108, 67],
        [133, 128, 177],
        [103, 189, 170],
        [214, 126, 44],
        [80, 91, 166],
        [193, 90, 99],
        [94, 60, 108],
        [157, 188, 64],
        [224, 163, 46],
        [56, 61, 150],
        [70, 148, 73],
        [175, 54, 60],
        [231, 199, 31],
        [187, 86, 149],
        [8, 133, 161],
        [243, 243, 242],
        [200, 200, 200],
        [160, 160, 160],
        [122, 122, 121],
        [85, 85, 85],
        [52, 52, 52],
    ];
    let mut max = 0.0f64;
    for p in PATCHES {
        let rgb = p.map(|c| srgb_decode(c as f64 / 255.0));
        let (s, residual) = fit_linear_srgb(rgb).unwrap();
        let de = independent_delta_e(&s, rgb);
        assert!((de - residual).abs() < 1e-6);
        assert_valid_values(&s);
        max = max.max(de);
    }
    println!("ColorChecker sRGB: max ΔE*ab {max:.3e}");
    assert!(max < 1e-6, "{max}");
}

#[test]
fn colours_of_measured_colorchecker_spectra_round_trip() {
    // The colours of real reflectances (those inside sRGB) must be reachable.
    let white = xyz_of(|_| 1.0);
    let w_rgb = xyz_to_linear_srgb(white);
    let mut tested = 0;
    for i in 1..=24 {
        let sd = named_spectrum(&format!("colorchecker:{i}")).unwrap();
        let rgb = xyz_to_linear_srgb(xyz_of(|nm| sd.value(nm)));
        let rgb = [rgb[0] / w_rgb[0], rgb[1] / w_rgb[1], rgb[2] / w_rgb[2]];
        if rgb.iter().any(|v| !(0.0..=1.0).contains(v)) {
            assert!(matches!(
                fit_linear_srgb(rgb),
                Err(UpsampleError::OutOfRange { .. })
            ));
            continue;
        }
        let (s, _) = fit_linear_srgb(rgb).unwrap();
        let de = independent_delta_e(&s, rgb);
        assert!(de < 1e-3, "patch {i} {rgb:?}: ΔE {de}");
        tested += 1;
    }
    assert!(tested >= 20, "only {tested} patches inside sRGB");
}

#[test]
fn saturated_edge_colours_report_their_residual() {
    for rgb in [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 1.0],
        [1.0, 0.0, 1.0],
        [0.5, 0.0, 0.0],
        [1.0, 0.999, 0.999],
    ] {
        let (s, residual) = fit_linear_srgb(rgb).unwrap();
        let de = independent_delta_e(&s, rgb);
        assert!(residual.is_finite() && (de - residual).abs() < 1e-6 * (1.0 + de));
        assert_valid_values(&s);
        println!("{rgb:?}: residual ΔE*ab {residual:.3e}, c = {:?}", s.c);
        // Cube faces are not limits of the family (see module docs): they converge.
        assert!(residual < 1e-6, "{rgb:?}: {residual}");
    }
}

#[test]
fn out_of_range_input_is_an_error() {
    for rgb in [
        [-0.01, 0.5, 0.5],
        [0.5, 1.01, 0.5],
        [0.5, 0.5, f64::NAN],
        [f64::INFINITY, 0.5, 0.5],
    ] {
        let err = fit_linear_srgb(rgb).unwrap_err();
        assert!(matches!(err, UpsampleError::OutOfRange { .. }));
        assert!(err.to_string().contains("[0, 1]"));
    }
}

#[test]
fn fitting_is_deterministic() {
    for rgb in [[0.7, 0.2, 0.1], [0.05, 0.6, 0.9], [0.98, 0.02, 0.5]] {
        let a = fit_linear_srgb(rgb).unwrap();
        let b = fit_linear_srgb(rgb).unwrap();
        assert_eq!(a.0.c.map(f64::to_bits), b.0.c.map(f64::to_bits));
        assert_eq!(a.1.to_bits(), b.1.to_bits());
    }
}

#[test]
fn whole_cube_including_faces_converges() {
    let levels = [
        0.0, 0.001, 0.01, 0.05, 0.2, 0.5, 0.8, 0.95, 0.99, 0.999, 1.0,
    ];
    let mut worst = (0.0f64, [0.0; 3]);
    for &r in &levels {
        for &g in &levels {
            for &b in &levels {
                let (s, residual) = fit_linear_srgb([r, g, b]).unwrap();
                assert_valid_values(&s);
                if residual > worst.0 {
                    worst = (residual, [r, g, b]);
                }
            }
        }
    }
    println!(
        "11³ cube incl. faces: max ΔE*ab {:.3e} at {:?}",
        worst.0, worst.1
    );
    assert!(worst.0 < 1e-6, "{worst:?}");
}
