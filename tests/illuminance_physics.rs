//! Illuminance (per pixel and from meters and grids) against closed forms
//! (../shared/reference/closed-forms.md §2.2–2.6), with tolerances from the estimated
//! standard errors.

mod common;
use candela::meter::{grid_stats, measure_all};
use common::*;
use glam::Vec3;
use std::f64::consts::PI;

const I_CD: f64 = 250.0;
const H: f64 = 2.0;

fn point_over_plane(rho: f64, extra: &str) -> candela::world::World {
    world(&format!(
        r#"(
        camera: (position: (0.3, 3.0, -1.0), look_at: (0.5, 0.0, 0.5), vfov_deg: 40, resolution: (12, 12)),
        render: (spp: 64, illuminance: true),
        materials: {{ "plane": Diffuse(reflectance: Constant({rho})) }},
        objects: [(shape: Quad(origin: (-50, 0, -50), edge_u: (0, 0, 100), edge_v: (100, 0, 0)), material: "plane")],
        lights: [Point(position: (0, {H}, 0), spectrum: Named("D65"), amount: Intensity({I_CD}))],
        {extra}
    )"#
    ))
}

/// E = I cos θ / d² at a point of the plane y = 0 (or of a receiver at height y facing up).
fn e_point(p: Vec3) -> f64 {
    let d = Vec3::new(0.0, H as f32, 0.0) - p;
    let d2 = d.length_squared() as f64;
    I_CD * (d.y as f64 / d2.sqrt()) / d2
}

/// The filter-weighted mean of E over a pixel's footprint on the plane (box filter: the
/// pixel square), by a 16×16 midpoint quadrature.
fn e_pixel(w: &candela::world::World, x: usize, y: usize) -> f64 {
    floor_footprint_mean(w, x, y, e_point)
}

#[test]
fn point_light_illuminance_channel_whatever_the_reflectance() {
    for rho in [0.0, 0.5, 0.95] {
        let w = point_over_plane(rho, "");
        let film = render(&w, 2);
        for y in 0..film.height {
            for x in 0..film.width {
                let p = film.pixel_e(y * film.width + x).unwrap();
                let e = p.mean_e().expect("every pixel sees the plane");
                let se = p.e_standard_error();
                let expected = e_pixel(&w, x, y);
                assert!(
                    (e - expected).abs() <= 5.0 * se && se < 0.05 * expected,
                    "ρ = {rho}, pixel ({x}, {y}): E = {e} ± {se}, expected {expected}"
                );
                assert_eq!(p.e_coverage(), 1.0);
            }
        }
    }
}

/// A Lambertian surface's illuminance comes from the camera path's own radiance (π L/ρ), so
/// the channel is checked against L here with the plane under a flat normal map, which makes
/// the illuminance an estimate of its own (a path from the surface) that does not share L's
/// samples.
#[test]
fn luminance_is_rho_e_over_pi_of_the_illuminance_channel() {
    let rho = 0.5;
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("illuminance_rho_e");
    std::fs::create_dir_all(&dir).unwrap();
    image::RgbImage::from_pixel(1, 1, image::Rgb([128, 128, 255]))
        .save(dir.join("flat.png"))
        .unwrap();
    let text = format!(
        r#"(
        camera: (position: (0.3, 3.0, -1.0), look_at: (0.5, 0.0, 0.5), vfov_deg: 40, resolution: (12, 12)),
        render: (spp: 64, illuminance: true),
        materials: {{ "plane": NormalMapped(material: Diffuse(reflectance: Constant({rho})), file: "flat.png") }},
        objects: [(shape: Quad(origin: (-50, 0, -50), edge_u: (0, 0, 100), edge_v: (100, 0, 0)), material: "plane")],
        lights: [Point(position: (0, {H}, 0), spectrum: Named("D65"), amount: Intensity({I_CD}))],
    )"#
    );
    let film = render(&world_in(&text, &dir), 2);
    for (i, p) in film.pixels_e().enumerate() {
        let l = p.mean_xyz()[1];
        let e = p.mean_e().unwrap();
        let se = (p
            .y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES)
            .powi(2)
            + (rho / PI * p.e_standard_error()).powi(2))
        .sqrt();
        assert!(
            (l - rho * e / PI).abs() <= 5.0 * se,
            "pixel {i}: L = {l}, ρE/π = {} (± {se})",
            rho * e / PI
        );
    }
}

#[test]
fn point_light_grid_of_meters() {
    let w = point_over_plane(
        0.7,
        r#"grids: [(name: "g", origin: (-1.5, 0.01, -1.0), edge_u: (3.0, 0, 0), edge_v: (0, 0, 2.5), nx: 4, ny: 3)],
           meters: [Illuminance(name: "tilted", position: (1.0, 0.5, 0.0), normal: (-0.6, 0.8, 0.0))],
           measure: (samples: 256),"#,
    );
    let m = measure_all(&w);
    let g = &w.grids[0];
    for j in 0..g.ny {
        for i in 0..g.nx {
            let p = g.point(i, j);
            let e = m.grids[0][(j * g.nx + i) as usize];
            let expected = e_point(p);
            assert!(
                (e.mean - expected).abs() <= 5.0 * e.stderr.max(1e-9 * expected),
                "grid point ({i}, {j}) at {p}: E = {} ± {}, expected {expected}",
                e.mean,
                e.stderr
            );
        }
    }
    // A tilted receiver: E = I cos θᵢ / d² with θᵢ between its normal and the light.
    let p = Vec3::new(1.0, 0.5, 0.0);
    let to_light = Vec3::new(0.0, H as f32, 0.0) - p;
    let d2 = to_light.length_squared() as f64;
    let cos_i = to_light.normalize().dot(Vec3::new(-0.6, 0.8, 0.0)) as f64;
    let expected = I_CD * cos_i / d2;
    let e = m.meters[0];
    assert!(
        (e.mean - expected).abs() <= 5.0 * e.stderr.max(1e-9 * expected),
        "tilted meter: {} ± {}, expected {expected}",
        e.mean,
        e.stderr
    );
    let s = grid_stats(&m.grids[0]);
    let values: Vec<f64> = m.grids[0].iter().map(|e| e.mean).collect();
    assert_eq!(s.min, values.iter().cloned().fold(f64::INFINITY, f64::min));
    assert_eq!(
        s.max,
        values.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
    );
    assert!((s.avg - values.iter().sum::<f64>() / values.len() as f64).abs() < 1e-12 * s.avg);
    assert!((s.u0.unwrap() - s.min / s.avg).abs() < 1e-15);
}

fn meter_under(emitter: &str, position: [f64; 3], samples: u64) -> candela::meter::Estimate {
    let w = world(&format!(
        r#"(
        camera: (position: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 10, resolution: (1, 1)),
        render: (spp: 1, max_depth: 4),
        objects: [{emitter}],
        meters: [Illuminance(name: "m", position: ({}, {}, {}), normal: (0, 1, 0))],
        measure: (samples: {samples}),
    )"#,
        position[0], position[1], position[2]
    ));
    measure_all(&w).meters[0]
}

#[test]
fn lambertian_disc_on_axis() {
    // R = 0.5, h = 2, L = 1000 cd/m²: E = π L sin²α = 184.7996 lx.
    let e = meter_under(
        r#"(shape: Disk(center: (0, 2, 0), normal: (0, -1, 0), radius: 0.5), material: "black",
            emission: (spectrum: Named("A"), amount: Luminance(1000.0)))"#,
        [0.0, 0.0, 0.0],
        8192,
    );
    assert!(
        (e.mean - 184.7996).abs() <= 5.0 * e.stderr && e.stderr < 0.01 * 184.8,
        "E = {} ± {}",
        e.mean,
        e.stderr
    );
}

#[test]
fn rectangle_source_below_a_corner() {
    // Parallel rectangle a = 1, b = 2 at h = 3 above the receiver under one corner:
    // F = 0.0522678, E = π L F.
    let l = 2000.0;
    let e = meter_under(
        r#"(shape: Quad(origin: (0, 3, 0), edge_u: (1, 0, 0), edge_v: (0, 0, 2)), material: "black",
            emission: (spectrum: Named("D65"), amount: Luminance(2000.0)))"#,
        [0.0, 0.0, 0.0],
        8192,
    );
    let expected = PI * l * 0.0522678;
    assert!(
        (e.mean - expected).abs() <= 5.0 * e.stderr && e.stderr < 0.01 * expected,
        "E = {} ± {}, expected {expected}",
        e.mean,
        e.stderr
    );
}

/// An isotropic source of flux Φ at the centre of a closed sphere (radius R, area A = 4πR²,
/// Lambertian walls of reflectance ρ): closed-forms.md §2.6. Every wall point receives
/// E_dir = Φ/A directly and E_ind = ρΦ/(A(1 − ρ)) by inter-reflection, so
/// E = Φ/(A(1 − ρ)) and the wall's luminance L = ρE/π = ρΦ/(πA(1 − ρ)) everywhere.
#[test]
fn integrating_sphere_interreflection() {
    // Φ = 1000 lm, R = 1, ρ = 0.6: E = 198.944 lx, L = 37.995 cd/m².
    let (phi, r, rho) = (1000.0, 1.0, 0.6);
    let area = 4.0 * PI * r * r;
    let expected = phi / (area * (1.0 - rho));
    let expected_l = rho * phi / (PI * area * (1.0 - rho));
    let w = world(&format!(
        r#"(
        camera: (position: (0.2, 0.1, -0.3), look_at: (0, 0, 1), vfov_deg: 100, resolution: (8, 8)),
        render: (spp: 256, max_depth: 64, illuminance: true),
        materials: {{ "wall": Diffuse(reflectance: Constant({rho})) }},
        objects: [(shape: Sphere(center: (0, 0, 0), radius: {r}), material: "wall")],
        lights: [Point(position: (0, 0, 0), spectrum: Named("FL2"), amount: Flux({phi}))],
        meters: [Illuminance(name: "wall", position: (0, -0.99999, 0), normal: (0, 1, 0))],
        measure: (samples: 131072),
    )"#
    ));
    // 256 samples: 16 per batch of the pixels' standard errors, which the interreflections'
    // skewed samples need for near-normal batch means (docs/uncertainty.md, pixels).
    let film = render(&w, 2);
    let n = film.pixels.len() as f64;
    let (mut sum_e, mut var_e, mut sum_l, mut var_l) = (0.0, 0.0, 0.0, 0.0);
    for (i, p) in film.pixels_e().enumerate() {
        let e = p.mean_e().unwrap();
        let se = p.e_standard_error();
        assert!(
            (e - expected).abs() <= 5.0 * se,
            "pixel {i}: E = {e} ± {se}, expected {expected}"
        );
        // The wall's luminance: L = ρ E / π.
        let l = p.mean_xyz()[1];
        let lse = p.y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES);
        assert!(
            (l - expected_l).abs() <= 5.0 * lse,
            "pixel {i}: L = {l} ± {lse}, expected {expected_l}"
        );
        sum_e += e;
        var_e += se * se;
        sum_l += l;
        var_l += lse * lse;
    }
    // Pooled over the (independent) pixels, whose expectations are all equal: a systematic
    // error of a few per cent cannot hide in the per-pixel noise.
    let (mean_e, se_e) = (sum_e / n, var_e.sqrt() / n);
    let (mean_l, se_l) = (sum_l / n, var_l.sqrt() / n);
    println!(
        "integrating sphere: mean E = {mean_e} ± {se_e} (expected {expected}, rel. se {:.4}), \
         mean L = {mean_l} ± {se_l} (expected {expected_l}, rel. se {:.4})",
        se_e / expected,
        se_l / expected_l
    );
    assert!(
        (mean_e - expected).abs() <= 4.0 * se_e && se_e < 0.01 * expected,
        "pixel-mean E = {mean_e} ± {se_e}, expected {expected}"
    );
    assert!(
        (mean_l - expected_l).abs() <= 4.0 * se_l && se_l < 0.01 * expected_l,
        "pixel-mean L = {mean_l} ± {se_l}, expected {expected_l}"
    );
    // The meter sits 10 µm inside the wall: E_dir = Φ/(4π d²) at d = 0.99999 m, plus E_ind.
    let d = 0.99999;
    let expected_meter = phi / (4.0 * PI * d * d) + rho * phi / (area * (1.0 - rho));
    let m = measure_all(&w).meters[0];
    println!(
        "integrating sphere meter: {} ± {} (expected {expected_meter}, rel. se {:.5})",
        m.mean,
        m.stderr,
        m.stderr / expected_meter
    );
    assert!(
        (m.mean - expected_meter).abs() <= 5.0 * m.stderr && m.stderr < 0.005 * expected_meter,
        "meter: {} ± {}, expected {expected_meter}",
        m.mean,
        m.stderr
    );
}

#[test]
fn target_error_stops_when_reached() {
    let w = world(
        r#"(
        camera: (position: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 10, resolution: (1, 1)),
        render: (spp: 1),
        objects: [(shape: Disk(center: (0, 2, 0), normal: (0, -1, 0), radius: 0.5), material: "black",
                   emission: (spectrum: Named("D65"), amount: Luminance(1000.0)))],
        meters: [Illuminance(name: "m", position: (0, 0, 0), normal: (0, 1, 0))],
        measure: (samples: 256, target_relative_error: 0.0002, max_samples: 1000000),
    )"#,
    );
    let e = measure_all(&w).meters[0];
    assert!(e.relative_error() <= 0.0002, "{e:?}");
    assert!(e.samples > 256 && e.samples < 1_000_000, "{e:?}");
    // It stopped at the first doubling that met the target: half as many did not.
    let mut half = w;
    half.measure.samples = e.samples / 2;
    half.measure.target_relative_error = None;
    let h = measure_all(&half).meters[0];
    assert!(h.relative_error() > 0.0002, "{h:?}");
    assert!((e.mean - 184.7996).abs() <= 5.0 * e.stderr, "{e:?}");
}

#[test]
fn pixels_seeing_the_sky_or_an_emitter_have_no_illuminance() {
    let w = world(
        r#"(
        camera: (position: (0, 1, -3), look_at: (0, 1, 0), vfov_deg: 60, resolution: (8, 8)),
        render: (spp: 4, illuminance: true),
        objects: [(shape: Quad(origin: (-1, 0, 0), edge_u: (0, 2, 0), edge_v: (2, 0, 0)), material: "black",
                   emission: (spectrum: Named("D65"), amount: Luminance(10.0)))],
        lights: [Environment(spectrum: Named("D65"), amount: Luminance(1.0))],
    )"#,
    );
    let film = render(&w, 2);
    assert_eq!(film.pixels_e().count(), film.pixels.len());
    assert!(film
        .pixels_e()
        .all(|p| p.mean_e().is_none() && p.e_coverage() == 0.0));
    let (e, se, mask) = film.illuminance_images();
    assert!(e
        .iter()
        .all(|&v| v == candela::output::ILLUMINANCE_SENTINEL));
    assert!(se.iter().all(|&v| v == 0.0) && mask.iter().all(|&v| v == 0.0));
}

/// A uniform sky (L = 4000 cd/m²) seen through a 1 m × 2 m skylight in an opaque black
/// ceiling 3 m up, from a meter under one corner of the opening: E = π L F with the same
/// parallel-rectangle form factor as `rectangle_source_below_a_corner` (F = 0.0522678). The
/// ceiling reaches 10 km in every direction, so the sky beyond it (below 0.02° of elevation)
/// adds less than 10⁻⁷ of the result. With the opening declared as a portal of the sky,
/// light sampling aims through it; without, the sky is sampled over the whole sphere. Both
/// are unbiased; the portal must cut the standard error severalfold, also for a meter right
/// under the opening (where sampling the portal by area would not).
#[test]
fn skylight_through_an_opening_with_and_without_a_portal() {
    let l = 4000.0;
    let meter = |portals: &str| {
        let w = world(&format!(
            r#"(
            camera: (position: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 10, resolution: (1, 1)),
            render: (spp: 1, max_depth: 4),
            objects: [
                (shape: Quad(origin: (-1e4, 3, -1e4), edge_u: (1e4, 0, 0), edge_v: (0, 0, 2e4)), material: "black"),
                (shape: Quad(origin: (1, 3, -1e4), edge_u: (9999, 0, 0), edge_v: (0, 0, 2e4)), material: "black"),
                (shape: Quad(origin: (0, 3, -1e4), edge_u: (1, 0, 0), edge_v: (0, 0, 1e4)), material: "black"),
                (shape: Quad(origin: (0, 3, 2), edge_u: (1, 0, 0), edge_v: (0, 0, 9998)), material: "black"),
            ],
            lights: [Environment(spectrum: Named("D65"), amount: Luminance({l}), portals: [{portals}])],
            meters: [
                Illuminance(name: "m", position: (0, 0, 0), normal: (0, 1, 0)),
                Illuminance(name: "roof", position: (0.5, 4, 1), normal: (0, 1, 0)),
                Illuminance(name: "near", position: (0, 2.75, 0), normal: (0, 1, 0)),
            ],
            measure: (samples: 262144),
        )"#
        ));
        let m = measure_all(&w).meters;
        (m[0], m[1], m[2])
    };
    let expected = PI * l * 0.0522678;
    let (with, roof, near) = meter("(origin: (0, 3, 0), edge_u: (1, 0, 0), edge_v: (0, 0, 2))");
    let (without, _, near_without) = meter("");
    // A meter 0.25 m under the corner, where sampling the portal by area did worst. The form
    // factor from a point under the corner of a parallel a × b rectangle at distance c, with
    // A = a/c, B = b/c, is F = 1/(2π) [A/√(1+A²) atan(B/√(1+A²)) + B/√(1+B²) atan(A/√(1+B²))]
    // (Howell's catalogue of configuration factors, B-4; the F above is its value for 1, 2, 3).
    let corner_f = |a: f64, b: f64, c: f64| {
        let (x, y) = (a / c, b / c);
        let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
    };
    assert!((corner_f(1.0, 2.0, 3.0) - 0.0522678).abs() < 1e-6);
    let expected_near = PI * l * corner_f(1.0, 2.0, 0.25);
    println!(
        "meters (portal / none): 3 m below the corner {} ± {} / {} ± {}; 0.25 m below {} ± {} / {} ± {} (expected {expected_near})",
        with.mean, with.stderr, without.mean, without.stderr, near.mean, near.stderr, near_without.mean, near_without.stderr
    );
    for (e, label) in [(&near, "near, portal"), (&near_without, "near, no portal")] {
        assert_estimate_near(e.mean, e.stderr, expected_near, 0.01, label);
    }
    // Above the roof the portal lies behind the meter: light sampling through it finds
    // nothing, and the open sky comes from the cosine-sampled paths alone (their MIS weight
    // is 1 where the portals' density is 0): E = π L.
    assert_estimate_near(roof.mean, roof.stderr, PI * l, 0.01, "roof");
    for (e, label) in [(&with, "portal"), (&without, "no portal")] {
        assert_estimate_near(e.mean, e.stderr, expected, 0.01, label);
    }
    // Measured: 62× and 4.2× lower (uniform sampling of the portal's area gave 19× and 1.06×).
    assert!(
        with.stderr * 20.0 < without.stderr && near.stderr * 3.0 < near_without.stderr,
        "standard errors, portal vs none: {} vs {} and near the opening {} vs {}",
        with.stderr,
        without.stderr,
        near.stderr,
        near_without.stderr
    );
}

/// The two illuminance estimators agree: in a closed grey room lit by a point light, the
/// channel of a Lambertian surface (π L/ρ from the camera path) and of the same surface under
/// a flat normal map (a path of its own from the surface) match block by block within their
/// standard errors, and both match the point light's direct illuminance plus the same
/// inter-reflected light on average.
#[test]
fn lambertian_illuminance_from_the_camera_path_matches_a_path_of_its_own() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("illuminance_reuse");
    std::fs::create_dir_all(&dir).unwrap();
    image::RgbImage::from_pixel(1, 1, image::Rgb([128, 128, 255]))
        .save(dir.join("flat.png"))
        .unwrap();
    let scene = |material: &str| {
        format!(
            r#"(
        camera: (position: (0, 1.5, -1.9), look_at: (0, 0.8, 1), vfov_deg: 70, resolution: (16, 16)),
        render: (spp: 256, illuminance: true),
        materials: {{ "grey": {material} }},
        objects: [
            (shape: Quad(origin: (-2, 0, -2), edge_u: (0, 0, 4), edge_v: (4, 0, 0)), material: "grey"),
            (shape: Quad(origin: (-2, 3, -2), edge_u: (4, 0, 0), edge_v: (0, 0, 4)), material: "grey"),
            (shape: Quad(origin: (-2, 0, -2), edge_u: (4, 0, 0), edge_v: (0, 3, 0)), material: "grey"),
            (shape: Quad(origin: (-2, 0, 2), edge_u: (0, 3, 0), edge_v: (4, 0, 0)), material: "grey"),
            (shape: Quad(origin: (-2, 0, -2), edge_u: (0, 3, 0), edge_v: (0, 0, 4)), material: "grey"),
            (shape: Quad(origin: (2, 0, -2), edge_u: (0, 0, 4), edge_v: (0, 3, 0)), material: "grey"),
        ],
        lights: [Point(position: (0.3, 2.5, 0.4), spectrum: Named("D65"), amount: Intensity(300.0))],
    )"#
        )
    };
    let diffuse = "Diffuse(reflectance: Rgb(0.9, 0.8, 0.7))";
    let reused = render(&world_in(&scene(diffuse), &dir), 2);
    let own = render(
        &world_in(
            &scene(&format!(
                "NormalMapped(material: {diffuse}, file: \"flat.png\")"
            )),
            &dir,
        ),
        2,
    );
    // 4 × 4 blocks of the E channel.
    let blocks = |f: &candela::film::Film| -> Vec<(f64, f64)> {
        let mut out = vec![(0.0, 0.0); 16];
        for (i, p) in f.pixels_e().enumerate() {
            let (x, y) = (i % 16, i / 16);
            let b = &mut out[(y / 4) * 4 + x / 4];
            b.0 += p.mean_e().unwrap() / 16.0;
            b.1 += (p.e_standard_error() / 16.0).powi(2);
        }
        out.into_iter().map(|(m, v)| (m, v.sqrt())).collect()
    };
    let (a, b) = (blocks(&reused), blocks(&own));
    let mut worst = 0.0f64;
    for (k, ((ma, sa), (mb, sb))) in a.iter().zip(&b).enumerate() {
        let z = (ma - mb) / (sa * sa + sb * sb).sqrt();
        worst = worst.max(z.abs());
        assert!(
            z.abs() < 4.5,
            "block {k}: {ma} ± {sa} lx (π L/ρ) vs {mb} ± {sb} lx (own path)"
        );
        assert!(
            *sa < 0.03 * ma && *sb < 0.03 * mb,
            "block {k}: too noisy to compare"
        );
    }
    eprintln!("largest block |z| {worst:.2}");
}
