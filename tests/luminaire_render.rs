//! Rendered illuminance below a goniometric light against the file's table: a Lambertian floor
//! of reflectance ρ under a luminaire at height h shows luminance L = ρ E / π with
//! E = I(C, γ) cos γ / d², I interpolated from the table at the documented angles (nadir −Y,
//! C0 toward +X, C90 toward −Z). Asymmetric directions make a sign or axis mistake fail.
//! Tolerances: 5 standard errors of the rendered pixel (from its own sample variance).

mod common;
use candela::luminaire;
use common::*;
use std::path::Path;

const RHO: f64 = 0.5;

fn meter(light: &str, target: [f64; 3], spp: u32) -> (f64, f64) {
    let eye = [target[0] + 0.3, 1.0, target[2] + 0.4];
    let text = format!(
        "(camera: (position: ({}, {}, {}), look_at: ({}, {}, {}), vfov_deg: 0.02, resolution: (1, 1)),
          render: (spp: {spp}, max_depth: 4),
          materials: {{ \"grey\": Diffuse(reflectance: Constant({RHO})) }},
          objects: [(shape: Quad(origin: (-50, 0, -50), edge_u: (0, 0, 100), edge_v: (100, 0, 0)), material: \"grey\")],
          lights: [{light}])",
        eye[0], eye[1], eye[2], target[0], target[1], target[2]
    );
    let film = render(&world(&text), 2);
    (
        film.pixels[0].mean_xyz()[1],
        film.pixels[0].y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES),
    )
}

/// (C, γ) in degrees of the direction from the light at `light` to `p` with no rotation.
fn c_gamma(light: [f64; 3], p: [f64; 3]) -> (f64, f64, f64, f64) {
    let d = [p[0] - light[0], p[1] - light[1], p[2] - light[2]];
    let dist2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let dist = dist2.sqrt();
    let gamma = (-d[1] / dist).acos().to_degrees();
    let c = (-d[2]).atan2(d[0]).to_degrees().rem_euclid(360.0);
    (c, gamma, dist2, -d[1] / dist)
}

#[test]
fn illuminance_below_the_wall_washer_follows_the_table() {
    let file = Path::new("data/luminaires/wall-washer.ies");
    let dist = luminaire::load(file).unwrap().distribution();
    let h = 2.0;
    let light = "Goniometric(file: \"data/luminaires/wall-washer.ies\", position: (0, 2, 0), spectrum: Blackbody(3000))";
    // Nadir, the C0 / C180 sides (+X / −X), C90 / C270 (−Z / +Z), and off-plane points.
    let points = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [-2.0, 0.0, 0.0],
        [0.0, 0.0, -2.0],
        [0.0, 0.0, 2.0],
        [1.3, 0.0, -0.7],
        [-0.9, 0.0, 1.6],
    ];
    let mut seen = Vec::new();
    for p in points {
        let (c, g, d2, cos) = c_gamma([0.0, h, 0.0], p);
        let i = dist.eval_angles(c, g);
        let expected = RHO / std::f64::consts::PI * i * cos / d2;
        let (l, se) = meter(light, p, 256);
        println!(
            "C {c:6.1}° γ {g:5.1}°: I = {i:8.2} cd, L = {l:.5} ± {se:.5}, expected {expected:.5}"
        );
        assert!(
            (l - expected).abs() <= 5.0 * se && se < 0.01 * expected,
            "point {p:?} (C {c}°, γ {g}°): L = {l} ± {se}, expected {expected}"
        );
        seen.push(l);
    }
    // The distribution really is asymmetric where we looked.
    assert!(
        seen[1] > 2.0 * seen[2],
        "C0 side must be brighter than C180"
    );
    assert!(
        seen[3] > 1.3 * seen[4],
        "C90 (−Z) side must be brighter than C270 (+Z)"
    );
}

#[test]
fn rotation_aims_the_luminaire() {
    // rotate_deg (0, 90, 0): the luminaire's +X (C0) turns to world −Z, its −Z (C90) to −X.
    let dist = luminaire::load(Path::new("data/luminaires/wall-washer.ies"))
        .unwrap()
        .distribution();
    let light = "Goniometric(file: \"data/luminaires/wall-washer.ies\", position: (0, 2, 0), rotate_deg: (0, 90, 0), spectrum: Named(\"D65\"), multiplier: 2.0)";
    for (p, c) in [
        ([0.0, 0.0, -2.0], 0.0),
        ([-2.0, 0.0, 0.0], 90.0),
        ([0.0, 0.0, 2.0], 180.0),
        ([2.0, 0.0, 0.0], 270.0),
    ] {
        let expected =
            2.0 * RHO / std::f64::consts::PI * dist.eval_angles(c, 45.0) * 0.5f64.sqrt() / 8.0;
        let (l, se) = meter(light, p, 256);
        assert!(
            (l - expected).abs() <= 5.0 * se && se < 0.01 * expected,
            "{p:?} should see C{c}: L = {l} ± {se}, expected {expected}"
        );
    }
}

#[test]
fn lumen_scaling_and_spot_axis() {
    // The narrow spot scaled to 1000 lm: on axis I = 5000 cd · 1000 / Φ_table.
    let dist = luminaire::load(Path::new("data/luminaires/narrow-spot.ies"))
        .unwrap()
        .distribution();
    let light = "Goniometric(file: \"data/luminaires/narrow-spot.ies\", position: (0, 3, 0), spectrum: Named(\"LED-B3\"), lumens: 1000)";
    let k = 1000.0 / dist.lumens();
    for x in [0.0, 0.3] {
        let (c, g, d2, cos) = c_gamma([0.0, 3.0, 0.0], [x, 0.0, 0.0]);
        let expected = RHO / std::f64::consts::PI * k * dist.eval_angles(c, g) * cos / d2;
        let (l, se) = meter(light, [x, 0.0, 0.0], 256);
        assert!(
            (l - expected).abs() <= 5.0 * se && se < 0.01 * expected,
            "x = {x}: L = {l} ± {se}, expected {expected}"
        );
    }
}

#[test]
fn light_power_and_emission_sampling() {
    use candela::light::Light;
    let w = world(
        "(camera: (position: (0, 0, 0), look_at: (0, 0, 1), vfov_deg: 10, resolution: (1, 1)),
          lights: [Goniometric(file: \"data/luminaires/batwing-office.ldt\", position: (0, 2, 0), spectrum: Blackbody(4000), multiplier: 0.5)])",
    );
    let Light::Goniometric(g) = &w.lights[0] else {
        panic!("not a goniometric light")
    };
    let table = g.distribution.lumens();
    assert!((g.power_lm() / (0.5 * table) - 1.0).abs() < 1e-4);
    // Emission sampling: E[I/pdf] = Φ_table; 5 standard errors from the sample variance.
    let n = 40_000;
    let (mut s, mut s2) = (0.0, 0.0);
    let mut state = 0x9e3779b97f4a7c15u64;
    let mut u = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    for _ in 0..n {
        let (dir, pdf, cd) = g.sample_emission(u(), glam::Vec2::new(u(), u())).unwrap();
        assert!(dir.y <= 1e-6, "a downlight emits downward");
        let x = cd / pdf as f64;
        s += x;
        s2 += x * x;
    }
    let mean = s / n as f64;
    let se = ((s2 / n as f64 - mean * mean) / n as f64).sqrt();
    assert!((mean - table).abs() <= 5.0 * se, "{mean} ± {se} vs {table}");
}

#[test]
fn scene_errors_name_the_light_and_the_file() {
    let scene = |light: &str| {
        let text = format!(
            "(camera: (position: (0, 0, 0), look_at: (0, 0, 1), vfov_deg: 10, resolution: (1, 1)), lights: [{light}])"
        );
        let path = Path::new("test-scene.ron");
        let s = candela::scene::parse(&text, path).unwrap();
        candela::scene::build(&s, path, &Default::default())
            .err()
            .expect("an error")
            .to_string()
    };
    let e = scene("Goniometric(file: \"data/luminaires/missing.ies\", position: (0, 2, 0), spectrum: Blackbody(3000))");
    assert!(
        e.contains("lights[0].file") && e.contains("missing.ies"),
        "{e}"
    );
    let e = scene("Goniometric(file: \"data/luminaires/narrow-spot.ies\", position: (0, 2, 0), spectrum: Blackbody(3000), lumens: -5)");
    assert!(e.contains("lights[0].lumens"), "{e}");
    let e = scene("Goniometric(file: \"data/luminaires/narrow-spot.ies\", position: (0, 2, 0), spectrum: Constant(0))");
    assert!(e.contains("lights[0].spectrum"), "{e}");
}
