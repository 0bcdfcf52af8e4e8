//! The renderer's wavelength sampling is unbiased: a flat Lambertian emitter rendered with each
//! of several spectra gives a mean absolute XYZ equal to the colour library's deterministic
//! XYZ of the same radiance spectrum (colour::colorimetry::sd_to_xyz_absolute, the function the
//! colour-science validation covers), within the Monte Carlo error.

mod common;
use candela::colour::colorimetry::sd_to_xyz_absolute;
use candela::colour::tables::Observer;
use candela::light::Light;
use common::*;

/// Mean over pixels of the pixel means, and its standard error from the spread of the pixel
/// means (pixels are independent estimates of the same value here).
fn mean_and_se(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let m = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, (var / n).sqrt())
}

fn check(spectrum: &str, luminance: f64) {
    // 256 samples (16 per batch of independently scrambled wavelengths): a narrow band needs
    // them for the 1 % standard error asked below.
    let w = world(&format!(
        r#"(
        camera: (position: (0, 0, 0), look_at: (0, 0, 1), vfov_deg: 20, resolution: (16, 16)),
        render: (spp: 256),
        objects: [(
            shape: Quad(origin: (-5, -5, 1), edge_u: (0, 10, 0), edge_v: (10, 0, 0)),
            material: "black",
            emission: (spectrum: {spectrum}, amount: Luminance({luminance})),
        )],
    )"#
    ));
    let Light::Area(light) = &w.lights[0] else {
        panic!("expected an area light")
    };
    let radiance = light.uniform_radiance().expect("an untextured emitter");
    let expected = sd_to_xyz_absolute(&radiance.to_f64_array(), Observer::Cie1931_2);
    // The photometric scaling itself: Y of the radiance is the requested luminance.
    assert!(
        (expected[1] - luminance).abs() < 1e-5 * luminance,
        "{spectrum}: library Y = {} for requested {luminance}",
        expected[1]
    );
    let film = render(&w, 2);
    for k in 0..3 {
        let v: Vec<f64> = film.pixels.iter().map(|p| p.mean_xyz()[k]).collect();
        let (m, se) = mean_and_se(&v);
        assert!(
            (m - expected[k]).abs() <= 4.0 * se + 1e-9 * expected[k].abs(),
            "{spectrum}: {} = {m} ± {se}, library {}",
            ["X", "Y", "Z"][k],
            expected[k]
        );
        assert!(
            se <= 0.01 * expected[k].abs(),
            "{spectrum}: {} standard error {se} above 1 % of {}",
            ["X", "Y", "Z"][k],
            expected[k]
        );
    }
    eprintln!(
        "{spectrum:<24} library XYZ = ({:.4}, {:.4}, {:.4})",
        expected[0], expected[1], expected[2]
    );
}

#[test]
fn flat_emitters_match_the_library_xyz() {
    for (s, l) in [
        ("Named(\"D65\")", 100.0),
        ("Named(\"A\")", 250.0),
        ("Named(\"FL2\")", 80.0),
        ("Named(\"FL11\")", 80.0),
        ("Named(\"LED-B3\")", 500.0),
        ("Named(\"cornell-light\")", 10000.0),
        ("Blackbody(1800)", 30.0),
        ("Blackbody(12000)", 30.0),
        ("Rgb(0.9, 0.2, 0.05)", 42.0),
        ("Tabulated([(540, 0), (550, 1), (560, 0)])", 10.0),
        ("Tabulated([(440, 0), (450, 1), (460, 0)])", 10.0),
    ] {
        check(s, l);
    }
}

/// The emitter's radiance of a scene whose emission is `spectrum`, as f64.
fn radiance_of(spectrum: &str) -> Vec<f64> {
    let w = world(&format!(
        r#"(
        camera: (position: (0, 0, 0), look_at: (0, 0, 1), vfov_deg: 20, resolution: (4, 4)),
        objects: [(
            shape: Quad(origin: (-5, -5, 1), edge_u: (0, 10, 0), edge_v: (10, 0, 0)),
            material: "black",
            emission: (spectrum: {spectrum}, amount: Luminance(100)),
        )],
    )"#
    ));
    let Light::Area(light) = &w.lights[0] else {
        panic!("expected an area light")
    };
    light.uniform_radiance().unwrap().to_f64_array().to_vec()
}

#[test]
fn coarse_csv_spectra_are_resampled_as_cie167_recommends() {
    use candela::colour::sd::{Interpolation, SpectralDistribution};
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, w: &[f64], v: &[f64]| {
        let p = dir.path().join(name);
        let text: String = w.iter().zip(v).map(|(w, v)| format!("{w},{v}\n")).collect();
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    // A smooth bump every 20 nm: the scene's shape is the Sprague table (colour-science's
    // interpolate, tests/colour_interpolation.rs), `Linear` the straight lines.
    let w: Vec<f64> = (0..=20).map(|i| 380.0 + 20.0 * i as f64).collect();
    let v: Vec<f64> = w
        .iter()
        .map(|l| 0.2 + (-0.5 * ((l - 530.0) / 45.0f64).powi(2)).exp())
        .collect();
    let f = write("bump.csv", &w, &v);
    let sd = SpectralDistribution::new(w.clone(), v.clone()).unwrap();
    for (spec, interp) in [
        (format!("Csv({f:?})"), Interpolation::Cie167),
        (format!("Csv({f:?}, Cie167)"), Interpolation::Cie167),
        (format!("Csv({f:?}, Linear)"), Interpolation::Linear),
    ] {
        let got = radiance_of(&spec);
        let want = sd.to_table_with(interp);
        // Same shape: the ratio is the photometric scale at every wavelength with light.
        let k = got[170] / want[170];
        for (i, (g, e)) in got.iter().zip(&want).enumerate() {
            assert!(
                (g - k * e).abs() <= 1e-6 * k * e.abs().max(0.2),
                "{spec}: {} nm: {g} vs {}",
                360 + i,
                k * e
            );
        }
    }
    let (cie, lin) = (
        radiance_of(&format!("Csv({f:?})")),
        radiance_of(&format!("Csv({f:?}, Linear)")),
    );
    let dev = cie
        .iter()
        .zip(&lin)
        .map(|(a, b)| (a / b - 1.0).abs())
        .filter(|d| d.is_finite())
        .fold(0.0, f64::max);
    eprintln!("20 nm bump: CIE 167 vs linear radiance differ by up to {dev:.2e}");
    assert!(dev > 1e-3, "the two interpolations agree to {dev:e}");

    // A sharp line sampled every 10 nm: Sprague rings below 0 beside it, which is held at 0
    // (the scene loads).
    let w: Vec<f64> = (0..=40).map(|i| 380.0 + 10.0 * i as f64).collect();
    let v: Vec<f64> = w
        .iter()
        .map(|&l| if l == 550.0 { 1.0 } else { 0.0 })
        .collect();
    let sd = SpectralDistribution::new(w.clone(), v.clone()).unwrap();
    assert!(sd
        .to_table_with(Interpolation::Cie167)
        .iter()
        .any(|&x| x < 0.0));
    let f = write("line.csv", &w, &v);
    let r = radiance_of(&format!("Csv({f:?})"));
    let t = sd.to_table_with(Interpolation::Cie167);
    for (i, (&x, &y)) in r.iter().zip(&t).enumerate() {
        assert!(
            x >= 0.0 && (y >= 0.0 || x == 0.0),
            "{} nm: {x} ({y})",
            360 + i
        );
    }

    // A reflectance edge up to 1: Sprague overshoots above 1, held at 1; samples above 1
    // are still refused.
    let w: Vec<f64> = (0..=12).map(|i| 400.0 + 25.0 * i as f64).collect();
    let v: Vec<f64> = w
        .iter()
        .map(|&l| if l < 550.0 { 0.05 } else { 1.0 })
        .collect();
    let sd = SpectralDistribution::new(w.clone(), v.clone()).unwrap();
    assert!(sd
        .to_table_with(Interpolation::Cie167)
        .iter()
        .any(|&x| x > 1.0));
    let f = write("edge.csv", &w, &v);
    let scene = |f: &str| {
        format!(
            r#"(
            camera: (position: (0, 0, 0), look_at: (0, 0, 1), vfov_deg: 20, resolution: (4, 4)),
            materials: {{"edge": Diffuse(reflectance: Csv({f:?}))}},
            objects: [(shape: Sphere(center: (0, 0, 3), radius: 1), material: "edge")],
        )"#
        )
    };
    let path = std::path::Path::new("test-scene.ron");
    let s = candela::scene::parse(&scene(&f), path).unwrap();
    candela::scene::build(&s, path, &Default::default()).unwrap();
    let over: Vec<f64> = v.iter().map(|x| x * 1.01).collect();
    let f = write("over.csv", &w, &over);
    let s = candela::scene::parse(&scene(&f), path).unwrap();
    let Err(e) = candela::scene::build(&s, path, &Default::default()) else {
        panic!("a reflectance above 1 was accepted")
    };
    assert!(e.to_string().contains("above 1"), "{e}");
}
