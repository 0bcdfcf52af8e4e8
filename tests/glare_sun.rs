//! The sun's disk seen straight from the camera is deposited into its pixels deterministically
//! (`integrator::sun_view`): in a scene that is black but for the sun,
//! - the image's vertical illuminance Σ L ∫cos θ dω equals E_n cos θ_sun (closed form), and
//!   behind a thin glass pane E_n cos θ T(θ) with T the slab's Fresnel transmittance, to 10⁻³
//!   (the sun placed on a pixel centre, where a pixel's mean of cos θ · dω/dA over its square
//!   equals its value at the disk to second order);
//! - the disk's pixels' luminance × solid angle sums to E_n (times T);
//! - every pixel's standard error is zero: the deposit adds the same to every sample;
//! - a disk seen in a reflection is still found by the camera paths (the deposit is the
//!   straight line of sight only);
//!
//! For the angular fisheye and a perspective camera, with the box and a tent pixel filter.

mod common;
use candela::camera::vertical_illuminance_lx;

const E_N: f64 = 100_000.0;
/// Square image of an odd number of pixels, so that the view axis is a pixel centre.
const RES: usize = 81;
/// The sun this many pixel rows above the image's centre.
const ROWS_UP: f64 = 10.0;

/// A camera at (0, 1, 0) looking south (+z) horizontally, the sun due south at `altitude_deg`,
/// a black wall behind the camera, and optionally a clear pane (n = 1.52) across the view at
/// z = 1 or a glass floor.
fn scene(projection: &str, altitude_deg: f64, extra: &str, filter: &str) -> String {
    format!(
        r#"(
    camera: (position: (0, 1, 0), look_at: (0, 1, 1), resolution: ({RES}, {RES}),
             projection: {projection}),
    render: (spp: 32, seed: 5{filter}),
    materials: {{
        "pane": ThinDielectric(ior: Constant(1.52)),
    }},
    objects: [
        (material: "black", shape: Quad(origin: (-1, 0, -1), edge_u: (2, 0, 0), edge_v: (0, 2, 0))),
        {extra}
    ],
    lights: [Sun(sun: (altitude_deg: {altitude_deg}, azimuth_deg: 180.0),
                 amount: NormalIlluminance({E_N}))],
)"#
    )
}

const PANE: &str = r#"(material: "pane", shape: Quad(origin: (-5, -5, 1), edge_u: (10, 0, 0), edge_v: (0, 10, 0))),"#;

struct Seen {
    ev: f64,
    disk: f64,
    max_stderr: f64,
    max_y: f64,
}

fn render(text: &str) -> Seen {
    let world = common::world(text);
    let film = common::render(&world, 2);
    let cam = &world.camera;
    let y: Vec<f32> = film.xyz_image().iter().map(|p| p[1]).collect();
    let se = film.y_stderr_image();
    let ev = vertical_illuminance_lx(cam, &y);
    let mut disk = 0.0;
    for (i, &l) in y.iter().enumerate() {
        if l > 0.0 {
            disk += l as f64 * cam.pixel_solid_angle_sr(i % cam.width, i / cam.width);
        }
    }
    Seen {
        ev,
        disk,
        max_stderr: se.iter().fold(0.0f64, |a, &b| a.max(b as f64)),
        max_y: y.iter().fold(0.0f64, |a, &b| a.max(b as f64)),
    }
}

fn check(label: &str, s: &Seen, altitude_deg: f64, t: f64) {
    let cos = altitude_deg.to_radians().cos();
    println!(
        "{label}: E_v {:.3} lx against {:.3} (E_n cos θ T), disk Σ L ω {:.3} against {:.3}, \
         max stderr {:.3e} of max L {:.3e} cd/m²",
        s.ev,
        E_N * cos * t,
        s.disk,
        E_N * t,
        s.max_stderr,
        s.max_y
    );
    assert!(
        (s.ev / (E_N * cos * t) - 1.0).abs() < 1e-3,
        "{label}: E_v {} lx, expected {}",
        s.ev,
        E_N * cos * t
    );
    assert!(
        (s.disk / (E_N * t) - 1.0).abs() < 1e-3,
        "{label}: disk {}",
        s.disk
    );
    assert!(
        s.max_stderr <= 1e-6 * s.max_y,
        "{label}: a deterministic deposit has no variance: stderr {} of {}",
        s.max_stderr,
        s.max_y
    );
}

fn fisheye_altitude() -> f64 {
    // Equidistant 180°: the image's half-height is 90°, so a row is 180°/RES.
    ROWS_UP * 180.0 / RES as f64
}

fn perspective_altitude(vfov_deg: f64) -> f64 {
    let scale = 2.0 * (0.5 * vfov_deg.to_radians()).tan() / RES as f64;
    (ROWS_UP * scale).atan().to_degrees()
}

#[test]
fn fisheye_sun_gives_closed_form_illuminance_without_variance() {
    let fish = "Fisheye(mapping: Equidistant, fov_deg: 180.0)";
    let a = fisheye_altitude();
    check("fisheye", &render(&scene(fish, a, "", "")), a, 1.0);
    let t = common::thin_slab_transmittance(a.to_radians().cos(), 1.52);
    check(
        "fisheye behind a pane",
        &render(&scene(fish, a, PANE, "")),
        a,
        t,
    );
}

#[test]
fn perspective_sun_gives_closed_form_illuminance_without_variance() {
    let persp = "Perspective(vfov_deg: 60.0)";
    let a = perspective_altitude(60.0);
    check("perspective", &render(&scene(persp, a, "", "")), a, 1.0);
    // A tent of radius 1 sums to one over the pixel centres, as the box does, so the image's
    // Σ L ω keeps the disk's flux (a Gaussian's ripple over the pixel grid would not).
    let tent = ", filter: Tent(radius: 1.0)";
    check(
        "perspective, tent filter",
        &render(&scene(persp, a, "", tent)),
        a,
        1.0,
    );
    let t = common::thin_slab_transmittance(a.to_radians().cos(), 1.52);
    check(
        "perspective behind a pane",
        &render(&scene(persp, a, PANE, "")),
        a,
        t,
    );
}

/// The sun in view over a horizontal glass floor: its reflection below the horizon is no
/// straight view, so the camera paths keep finding it while the deposit gives the disk itself.
#[test]
fn sun_reflected_in_glass_is_still_found_by_the_paths() {
    let fish = "Fisheye(mapping: Equidistant, fov_deg: 180.0)";
    let floor = r#"(material: "pane", shape: Quad(origin: (-50, 0, -1), edge_u: (0, 0, 100), edge_v: (100, 0, 0))),"#;
    let a = fisheye_altitude();
    let world = common::world(&scene(fish, a, floor, "").replace("spp: 32", "spp: 1024"));
    let film = common::render(&world, 2);
    let y: Vec<f32> = film.xyz_image().iter().map(|p| p[1]).collect();
    let below: f64 = (RES / 2 + 1..RES)
        .flat_map(|r| (0..RES).map(move |c| (r, c)))
        .map(|(r, c)| y[r * RES + c] as f64 * world.camera.pixel_solid_angle_sr(c, r))
        .sum();
    let r = 1.0 - common::thin_slab_transmittance(a.to_radians().sin(), 1.52);
    println!(
        "sun reflected in a glass floor: Σ L ω below the horizon {below:.1} lx, R E_n {:.1}",
        r * E_N
    );
    assert!(below > 0.0, "the reflected sun is seen");
}
