//! The renderer against closed forms (../shared/reference/closed-forms.md): a Lambertian
//! emitter of known luminance, inverse-square and cosine laws, a uniform sky, a disc source,
//! the white furnace. Every tolerance is a multiple of the standard error estimated from the
//! samples themselves.

mod common;
use common::*;

/// CIE 1931 chromaticity of a named spectrum from the colour library's tables (1 nm sums).
fn library_xy(name: &str) -> (f64, f64) {
    use candela::colour::tables::{cmfs, named_spectrum, Observer};
    let c = cmfs(Observer::Cie1931_2);
    let s = named_spectrum(name).unwrap();
    let (mut x, mut y, mut z) = (0.0, 0.0, 0.0);
    for i in 0..471 {
        let v = s.value(360.0 + i as f64);
        x += v * c.x[i];
        y += v * c.y[i];
        z += v * c.z[i];
    }
    (x / (x + y + z), y / (x + y + z))
}

#[test]
fn lambertian_emitter_of_100_nits_with_d65() {
    let w = world(
        r#"(
        camera: (position: (0, 0, 0), look_at: (0, 0, 1), vfov_deg: 30, resolution: (16, 16)),
        render: (spp: 256),
        objects: [(
            shape: Quad(origin: (-5, -5, 1), edge_u: (0, 10, 0), edge_v: (10, 0, 0)),
            material: "black",
            emission: (spectrum: Named("D65"), amount: Luminance(100.0)),
        )],
    )"#,
    );
    let film = render(&w, 2);
    assert_every_pixel(&film, 100.0, 5.0);
    let (m, _) = image_mean(&film);
    let (x, y) = (m[0] / (m[0] + m[1] + m[2]), m[1] / (m[0] + m[1] + m[2]));
    let (x0, y0) = library_xy("D65");
    assert!(
        (x - x0).abs() < 1e-3 && (y - y0).abs() < 1e-3,
        "xy = ({x}, {y}), D65 = ({x0}, {y0})"
    );
}

#[test]
fn back_face_of_one_sided_emitter_is_dark() {
    let w = world(
        r#"(
        camera: (position: (0, 0, 0), look_at: (0, 0, 1), vfov_deg: 30, resolution: (4, 4)),
        render: (spp: 16),
        objects: [(
            shape: Quad(origin: (-5, -5, 1), edge_u: (10, 0, 0), edge_v: (0, 10, 0)),
            material: "black",
            emission: (spectrum: Named("D65"), amount: Luminance(100.0)),
        )],
    )"#,
    );
    let film = render(&w, 2);
    assert!(film.pixels.iter().all(|p| p.mean_xyz()[1] == 0.0));
}

/// Luminance seen by a one-pixel camera with a tiny field of view aimed at `target`.
fn spot_meter(scene_body: &str, eye: [f64; 3], target: [f64; 3], spp: u32) -> (f64, f64) {
    let text = format!(
        "(camera: (position: ({}, {}, {}), look_at: ({}, {}, {}), vfov_deg: 0.02, resolution: (1, 1)),
          render: (spp: {spp}, max_depth: 8), {scene_body})",
        eye[0], eye[1], eye[2], target[0], target[1], target[2]
    );
    let film = render(&world(&text), 2);
    (
        film.pixels[0].mean_xyz()[1],
        film.pixels[0].y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES),
    )
}

#[test]
fn point_light_inverse_square_and_cosine_laws() {
    // I = 100 cd at h = 2 m above a plane of ρ = 0.5: L = ρ I cos θ / (π d²).
    let body = r#"
        materials: { "grey": Diffuse(reflectance: Constant(0.5)) },
        objects: [(shape: Quad(origin: (-50, 0, -50), edge_u: (0, 0, 100), edge_v: (100, 0, 0)), material: "grey")],
        lights: [Point(position: (0, 2, 0), spectrum: Named("A"), amount: Intensity(100.0))],
    "#;
    for x in [0.0f64, 1.0, 2.0, 3.5] {
        let d2 = 4.0 + x * x;
        let cos = 2.0 / d2.sqrt();
        let expected = 0.5 * 100.0 * cos / (std::f64::consts::PI * d2);
        let (l, se) = spot_meter(body, [x, 1.0, -1.0], [x, 0.0, 0.0], 1024);
        assert!(
            (l - expected).abs() <= 5.0 * se && se < 0.01 * expected,
            "x = {x}: L = {l} ± {se}, expected {expected}"
        );
    }
}

#[test]
fn point_light_given_in_lumens() {
    // Φ = 4π·50 lm isotropic ⇒ I = 50 cd; below it at h = 1: L = ρ I / π.
    let body = r#"
        materials: { "grey": Diffuse(reflectance: Constant(0.8)) },
        objects: [(shape: Disk(center: (0, 0, 0), normal: (0, 1, 0), radius: 10), material: "grey")],
        lights: [Point(position: (0, 1, 0), spectrum: Blackbody(2700), amount: Flux(628.3185307179587))],
    "#;
    let expected = 0.8 * 50.0 / std::f64::consts::PI;
    let (l, se) = spot_meter(body, [0.3, 0.5, 0.0], [0.0, 0.0, 0.0], 1024);
    assert_meter(l, se, expected);
}

#[test]
fn spot_light_inside_its_cone_obeys_inverse_square() {
    let body = r#"
        materials: { "grey": Diffuse(reflectance: Constant(0.5)) },
        objects: [(shape: Quad(origin: (-50, 0, -50), edge_u: (0, 0, 100), edge_v: (100, 0, 0)), material: "grey")],
        lights: [Spot(position: (0, 3, 0), look_at: (0, 0, 0), inner_deg: 30, outer_deg: 40,
                      spectrum: Named("D50"), amount: Intensity(1000.0))],
    "#;
    // Inside the inner cone (θ = atan(1/3) = 18.4°): full intensity.
    let d2: f64 = 9.0 + 1.0;
    let expected = 0.5 * 1000.0 * (3.0 / d2.sqrt()) / (std::f64::consts::PI * d2);
    let (l, se) = spot_meter(body, [1.0, 1.0, -1.0], [1.0, 0.0, 0.0], 1024);
    assert_meter(l, se, expected);
    // Outside the outer cone (θ = atan(3/3) = 45°): dark.
    let (l, _) = spot_meter(body, [3.0, 1.0, -1.0], [3.0, 0.0, 0.0], 64);
    assert_eq!(l, 0.0);
}

#[test]
fn distant_light_cosine_law() {
    // E = 10 000 lx along a direction 60° from the normal: E cos 60° on the plane, L = ρ E cos θ / π.
    let body = r#"
        materials: { "grey": Diffuse(reflectance: Constant(0.25)) },
        objects: [(shape: Disk(center: (0, 0, 0), normal: (0, 1, 0), radius: 10), material: "grey")],
        lights: [Distant(direction: (0.8660254037844386, -0.5, 0), spectrum: Named("D65"), amount: Illuminance(10000.0))],
    "#;
    let expected = 0.25 * 10000.0 * 0.5 / std::f64::consts::PI;
    let (l, se) = spot_meter(body, [0.0, 1.0, -1.0], [0.0, 0.0, 0.0], 1024);
    assert_meter(l, se, expected);
}

#[test]
fn uniform_sky_on_a_convex_lambertian_surface() {
    // A convex Lambertian surface of albedo ρ under a uniform environment L shows ρ·L
    // (E = π L on the upward face); its edge sees the sky too.
    let body = r#"
        materials: { "grey": Diffuse(reflectance: Constant(0.6)) },
        objects: [(shape: Sphere(center: (0, 0, 0), radius: 1), material: "grey")],
        lights: [Environment(spectrum: Named("D65"), amount: Luminance(500.0))],
    "#;
    for target in [[0.0, 1.0, 0.0], [0.6, 0.8, 0.0], [0.0, 0.0, -1.0]] {
        // Look from outside, slightly off the normal (a view straight down would make `up`
        // parallel to the view axis).
        let eye = [
            target[0] * 3.0 + 0.3,
            target[1] * 3.0,
            target[2] * 3.0 - 0.4,
        ];
        let (l, se) = spot_meter(body, eye, target, 2048);
        assert!(
            (l - 300.0).abs() <= 5.0 * se && se < 3.0,
            "at {target:?}: L = {l} ± {se}"
        );
    }
}

#[test]
fn lambertian_disc_source_on_axis() {
    // Disc of radius R = 0.5 m and luminance 1000 cd/m² at h = 2 m above a plane of ρ = 0.5:
    // E = π L R²/(R² + h²) = 184.7996 lx, so the plane below shows L = ρ E / π.
    let body = r#"
        materials: { "grey": Diffuse(reflectance: Constant(0.5)) },
        objects: [
            (shape: Disk(center: (0, 0, 0), normal: (0, 1, 0), radius: 0.2), material: "grey"),
            (shape: Disk(center: (0, 2, 0), normal: (0, -1, 0), radius: 0.5), material: "black",
             emission: (spectrum: Named("FL2"), amount: Luminance(1000.0))),
        ],
    "#;
    let expected = 0.5 * 184.7996 / std::f64::consts::PI;
    let (l, se) = spot_meter(body, [0.1, 0.3, -0.3], [0.0, 0.0, 0.0], 4096);
    assert!(
        (l - expected).abs() <= 5.0 * se && se < 0.02 * expected,
        "L = {l} ± {se}, expected {expected}"
    );
}

fn furnace(rho: f64, max_depth: u32) -> candela::film::Film {
    // 256 samples: 16 per batch of the pixels' standard errors, which the interreflections'
    // skewed samples need for near-normal batch means (docs/uncertainty.md, pixels).
    let w = world(&format!(
        r#"(
        camera: (position: (0.1, -0.2, 0.05), look_at: (0, 0, 1), vfov_deg: 120, resolution: (12, 12)),
        render: (spp: 256, max_depth: {max_depth}),
        materials: {{ "wall": Diffuse(reflectance: Constant({rho})) }},
        objects: [(
            shape: Sphere(center: (0, 0, 0), radius: 1),
            material: "wall",
            emission: (spectrum: Named("E"), amount: Luminance(1.0), two_sided: true),
        )],
    )"#
    ));
    render(&w, 2)
}

#[test]
fn white_furnace_converges_to_le_over_one_minus_rho() {
    // ρ = 0.5, depth 64: L = 1/(1 − ρ) = 2 (truncation error 0.5^65 ≈ 3e-20).
    assert_every_pixel(&furnace(0.5, 64), 2.0, 5.0);
}

#[test]
fn white_furnace_truncated_sum() {
    // ρ = 0.8 stopped after 5 scattering events: L = (1 − ρ⁶)/(1 − ρ) = 3.68928.
    let expected = (1.0 - 0.8f64.powi(6)) / 0.2;
    assert_every_pixel(&furnace(0.8, 5), expected, 5.0);
}

#[test]
fn same_seed_same_image_for_any_thread_count() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/cornell-box.ron"
    ))
    .unwrap()
    .replace("resolution: (256, 256)", "resolution: (24, 24)")
    .replace("spp: 64", "spp: 4");
    let w = world(&text);
    let a = render(&w, 1);
    let b = render(&w, 2);
    assert_eq!(a.pixels, b.pixels);
    assert!(a.total_samples() == 24 * 24 * 4);
}

/// A meter reading `l` ± `se` agrees with `expected` within 5 standard errors, and the standard
/// error is below 1 % of it (so the check keeps its power).
fn assert_meter(l: f64, se: f64, expected: f64) {
    assert!(
        (l - expected).abs() <= 5.0 * se,
        "L = {l} ± {se}, expected {expected}"
    );
    assert!(
        se <= 0.01 * expected.abs(),
        "L = {l} ± {se}: standard error above 1 % of {expected}"
    );
}
