//! The default settings are unbiased in bright rooms: with no `max_depth` the paths end by
//! Russian roulette alone, so inter-reflection is counted to every order. Checked on the
//! CIE 171:2006 test case 5.8 (closed cube, inter-reflected illuminance) and a furnace against
//! their closed forms (closed-forms.md §2.6), and on a closed box of reflectance 1, which must
//! still end its paths after a bounded expected number of bounces.

mod common;
use candela::meter::measure_all;
use candela::sampling::mix64;
use common::*;
use std::f64::consts::PI;

/// Flux of the isotropic source at the cube's centre (lm).
const PHI: f64 = 10_000.0;
/// Height of the meters above the floor (m): a meter on a surface is ambiguous.
const LIFT: f64 = 0.001;
/// Meters at random points of the floor, and samples per meter: many meters with few samples
/// each, as the illuminance varies over the floor by about 4 % (one meter's standard deviation
/// at ρ = 0.8) and one meter's Monte Carlo error at 128 samples is about 6 % (at ρ = 0.95).
const METERS: usize = 1024;
const SAMPLES: u64 = 128;

/// The six inward-facing walls of the cube [−1, 1] × [0, 2] × [−1, 1] (side 2 m, area 24 m²).
const CUBE: &str = r#"
    (material: "wall", shape: Quad(origin: (-1, 0, -1), edge_u: (0, 0, 2), edge_v: (2, 0, 0))),
    (material: "wall", shape: Quad(origin: (-1, 2, -1), edge_u: (2, 0, 0), edge_v: (0, 0, 2))),
    (material: "wall", shape: Quad(origin: (-1, 0, -1), edge_u: (0, 2, 0), edge_v: (0, 0, 2))),
    (material: "wall", shape: Quad(origin: (1, 0, -1), edge_u: (0, 0, 2), edge_v: (0, 2, 0))),
    (material: "wall", shape: Quad(origin: (-1, 0, 1), edge_u: (0, 2, 0), edge_v: (2, 0, 0))),
    (material: "wall", shape: Quad(origin: (-1, 0, -1), edge_u: (2, 0, 0), edge_v: (0, 2, 0))),
"#;

/// A uniform random number in [0, 1) from a counter.
fn uniform(k: u64) -> f64 {
    (mix64(k ^ 0x005e_ed0f_c0be) >> 11) as f64 / (1u64 << 53) as f64
}

/// CIE 171:2006 test case 5.8: an isotropic point source of flux Φ at the centre of a closed
/// cube whose walls are Lambertian of reflectance ρ. The flux reaching the walls after one or
/// more reflections is Φ(ρ + ρ² + …) = Φρ/(1 − ρ), so the inter-reflected illuminance averaged
/// over the walls is exactly E_ind = ρΦ/(S(1 − ρ)), S = 24 m² (closed-forms.md §2.6); by the
/// cube's symmetry the floor's average is the same. It is estimated by illuminance meters at
/// uniformly random points of the floor, each reading minus the exact direct illuminance
/// E_dir = Φh/(4π(h² + r²)^{3/2}) at its point: the mean of those differences is an unbiased
/// estimate of the floor's average, and as the meters are independent (random points, own
/// random streams) the spread of the differences gives its standard error, position and Monte
/// Carlo noise together. Returns (mean, standard error, exact).
fn cie_171_5_8(rho: f64) -> (f64, f64, f64) {
    let mut points = Vec::with_capacity(METERS);
    let mut meters = String::new();
    for i in 0..METERS as u64 {
        let (x, z) = (2.0 * uniform(2 * i) - 1.0, 2.0 * uniform(2 * i + 1) - 1.0);
        meters.push_str(&format!(
            "Illuminance(name: \"m{i}\", position: ({x}, {LIFT}, {z}), normal: (0, 1, 0)),"
        ));
        points.push((x, z));
    }
    // Default render settings: no max_depth, the default rr_depth.
    let w = world(&format!(
        r#"(
        camera: (position: (0, 1, 0), look_at: (0, 0, 1), vfov_deg: 60, resolution: (1, 1)),
        materials: {{ "wall": Diffuse(reflectance: Constant({rho})) }},
        objects: [{CUBE}],
        lights: [Point(position: (0, 1, 0), spectrum: Named("D65"), amount: Flux({PHI}))],
        meters: [{meters}],
        measure: (samples: {SAMPLES}),
    )"#
    ));
    assert!(
        w.settings.max_depth.is_none(),
        "the default has a depth limit"
    );
    let m = measure_all(&w);
    let h = 1.0 - LIFT;
    let ind: Vec<f64> = m
        .meters
        .iter()
        .zip(&points)
        .map(|(e, &(x, z))| {
            let r2 = x * x + z * z;
            e.mean - PHI / (4.0 * PI) * h / (h * h + r2).powf(1.5)
        })
        .collect();
    let n = ind.len() as f64;
    let mean = ind.iter().sum::<f64>() / n;
    let var = ind.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let exact = rho * PHI / (24.0 * (1.0 - rho));
    assert_eq!(m.stats.truncated_paths, 0);
    (mean, (var / n).sqrt(), exact)
}

/// Within 1 % of the exact value, within 4 standard errors of it, and with a standard error
/// below 0.25 % (so that a bias of 1 % cannot hide in the noise).
fn check_cube(rho: f64) {
    let (mean, se, exact) = cie_171_5_8(rho);
    let rel = mean / exact - 1.0;
    println!(
        "CIE 171 5.8, ρ = {rho}: E_ind = {mean:.3} ± {se:.3} lx (95 % CI {:.3} … {:.3}), exact {exact:.3}: {:+.3} % ({:+.2} σ)",
        mean - 1.96 * se,
        mean + 1.96 * se,
        100.0 * rel,
        (mean - exact) / se
    );
    assert!(se < 0.0025 * exact, "standard error {se} too large");
    assert!(
        rel.abs() < 0.01 && (mean - exact).abs() <= 4.0 * se,
        "ρ = {rho}: E_ind = {mean} ± {se} lx, exact {exact} ({:+.2} %)",
        100.0 * rel
    );
}

#[test]
fn cie_171_5_8_closed_cube_rho_0_8() {
    check_cube(0.8);
}

#[test]
fn cie_171_5_8_closed_cube_rho_0_9() {
    check_cube(0.9);
}

#[test]
fn cie_171_5_8_closed_cube_rho_0_95() {
    check_cube(0.95);
}

/// Furnace (closed-forms.md §2.6): a closed sphere whose wall emits L_e = 1 cd/m² and reflects
/// ρ = 0.9 shows L = L_e/(1 − ρ) = 10 cd/m² everywhere, with the default settings (a depth
/// limit of N would show (1 − ρ^(N+1))/(1 − ρ)).
#[test]
fn furnace_with_default_depth() {
    let w = world(
        r#"(
        camera: (position: (0.1, -0.2, 0.05), look_at: (0, 0, 1), vfov_deg: 120, resolution: (12, 12)),
        render: (spp: 128),
        materials: { "wall": Diffuse(reflectance: Constant(0.9)) },
        objects: [(
            shape: Sphere(center: (0, 0, 0), radius: 1),
            material: "wall",
            emission: (spectrum: Named("E"), amount: Luminance(1.0), two_sided: true),
        )],
    )"#,
    );
    let film = render(&w, 2);
    let (m, se) = image_mean(&film);
    println!("furnace ρ = 0.9: L = {} ± {se} cd/m², exact 10", m[1]);
    // The furnace's per-sample values are skewed (every path's first bounces are alike; the
    // spread is in Russian roulette's geometric tail), so a single pixel's t statistic from its
    // 16 batches of 8 samples has heavy tails: over 576 such pixels, |z| reached 4.1–6.0 at
    // seeds 0–3 while 93–96 % of the 95 % intervals held the exact value. The image mean tests
    // the depth; the coverage, the intervals.
    assert_pixel_coverage(&film, 10.0, 0.90);
}

/// A closed box of reflectance exactly 1 (nothing absorbs; the light it holds makes the exact
/// illuminance infinite) with no depth limit: Russian roulette still ends every path, each
/// bounce past `rr_depth` surviving with probability 0.99. An illuminance meter's sample traces
/// its receiver's cosine-sampled ray, the bounces from depth 1 to `rr_depth` (rr_depth − 1
/// rays) and then a geometric number of further bounces of mean 0.99/(1 − 0.99) = 99: 102 rays
/// at the default rr_depth 3. The mean over the samples is checked against that.
#[test]
fn white_box_paths_end_with_unlimited_depth() {
    let w = world(&format!(
        r#"(
        camera: (position: (0, 1, 0), look_at: (0, 0, 1), vfov_deg: 60, resolution: (1, 1)),
        materials: {{ "wall": Diffuse(reflectance: Constant(1.0)) }},
        objects: [{CUBE}],
        lights: [Point(position: (0, 1, 0), spectrum: Named("D65"), amount: Flux(1000))],
        meters: [Illuminance(name: "floor", position: (0.3, 0.001, -0.2), normal: (0, 1, 0))],
        measure: (samples: 16384),
    )"#
    ));
    assert_eq!(w.settings.rr_depth, 3);
    let m = measure_all(&w);
    let samples = m.meters[0].samples as f64;
    let rays = m.stats.bounce_rays as f64 / samples;
    // The geometric count has standard deviation √0.99/(1 − 0.99) ≈ 99.5.
    let se = 0.99f64.sqrt() / 0.01 / samples.sqrt();
    println!("white box: {rays:.2} bounce rays per sample (expected 102 ± {se:.2})");
    assert!(
        (rays - 102.0).abs() <= 5.0 * se,
        "{rays} bounce rays per sample, expected 102"
    );
    assert_eq!(m.stats.truncated_paths, 0);
}

/// The report and the closing summary say when a finite `max_depth` cut paths short, and
/// count them; with the default (no limit) there are none.
#[test]
fn report_counts_paths_cut_at_a_finite_max_depth() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("s.ron"),
        format!(
            r#"(
            camera: (position: (0, 1, -0.9), look_at: (0, 1, 1), vfov_deg: 90, resolution: (4, 4)),
            render: (spp: 4),
            materials: {{ "wall": Diffuse(reflectance: Constant(0.5)) }},
            objects: [{CUBE}],
            lights: [Point(position: (0, 1, 0), spectrum: Named("D65"), amount: Flux(1000))],
            meters: [Illuminance(name: "floor", position: (0, 0.001, 0), normal: (0, 1, 0))],
            measure: (samples: 64),
        )"#
        ),
    )
    .unwrap();
    let report = || -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("s.report.json")).unwrap())
            .unwrap()
    };
    let (code, _, stderr) = cli(&["render", "--quiet", "s.ron"], dir.path());
    assert_eq!(code, 0, "{stderr}");
    let r = report();
    assert!(r["settings"]["max_depth"].is_null());
    assert_eq!(r["timing"]["truncated_paths"], 0);
    assert!(!stderr.contains("max_depth"), "{stderr}");
    let (code, _, stderr) = cli(
        &[
            "render",
            "--quiet",
            "--overwrite",
            "--max-depth",
            "2",
            "s.ron",
        ],
        dir.path(),
    );
    assert_eq!(code, 0, "{stderr}");
    let r = report();
    assert_eq!(r["settings"]["max_depth"], 2);
    // In a closed room with ρ = 0.5 every path that scatters twice is cut: far more than 0.
    assert!(r["timing"]["truncated_paths"].as_u64().unwrap() > 16, "{r}");
    let warnings = r["warnings"].to_string();
    assert!(warnings.contains("max_depth 2"), "{warnings}");
    assert!(stderr.contains("reached max_depth 2"), "{stderr}");
}
