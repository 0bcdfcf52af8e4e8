//! Camera projections: each pixel's solid angle sums to the field's closed form, a direction
//! lands on the pixel the mapping predicts and comes back, and a fisheye inside a uniform sky
//! integrates to the illuminance at the eye (π L), as a lux meter there measures it.

mod common;

use candela::camera::{vertical_illuminance_lx, Camera, FisheyeMapping as M, Projection, ThinLens};
use glam::{Vec2, Vec3};
use std::f64::consts::PI;

fn fisheye(mapping: M, fov_deg: f64) -> Projection {
    Projection::Fisheye { mapping, fov_deg }
}

fn camera(p: Projection, w: usize, h: usize) -> Camera {
    Camera::with_projection(
        Vec3::new(0.5, 1.0, -2.0),
        Vec3::new(0.1, 1.3, 0.0),
        Vec3::Y,
        p,
        (w, h),
        None,
    )
}

/// Σ ω and Σ ∫max(cos θ, 0) dω over every pixel.
fn sums(c: &Camera) -> (f64, f64) {
    let (mut w, mut p) = (0.0f64, 0.0f64);
    for y in 0..c.height {
        for x in 0..c.width {
            let o = c.pixel_solid_angle_sr(x, y);
            let q = c.pixel_projected_solid_angle_sr(x, y);
            assert!(
                o >= 0.0 && q >= 0.0 && q <= o * (1.0 + 1e-9) + 1e-15,
                "{:?} ({x}, {y}): ω = {o}, cos·ω = {q}",
                c.projection()
            );
            if !c.pixel_inside(x, y) {
                assert_eq!(
                    o, 0.0,
                    "pixel ({x}, {y}) outside the circle has a solid angle"
                );
            }
            w += o;
            p += q;
        }
    }
    (w, p)
}

/// Quadrature tolerance: the per-pixel integrals are exact up to the Gauss–Legendre rule along
/// each pixel edge, far below this.
const QUAD: f64 = 1e-12;

#[test]
fn pixel_solid_angles_sum_to_the_field_of_view() {
    let hemi = 2.0 * PI;
    let mut cases: Vec<(Projection, f64, f64)> = [
        M::Equidistant,
        M::Orthographic,
        M::Equisolid,
        M::Stereographic,
    ]
    .into_iter()
    .map(|m| (fisheye(m, 180.0), hemi, PI))
    .collect();
    cases.push((fisheye(M::Equidistant, 360.0), 4.0 * PI, PI));
    // A 120° cone: 2π(1 − cos 60°); its projected solid angle π sin² 60°.
    cases.push((fisheye(M::Equisolid, 120.0), PI, PI * 0.75));
    cases.push((Projection::Equirectangular, 4.0 * PI, PI));
    let mut worst = 0.0f64;
    for (w, h) in [(64, 64), (41, 29)] {
        for &(p, omega, projected) in &cases {
            let c = camera(p, w, h);
            let (s, q) = sums(&c);
            worst = worst
                .max((s / omega - 1.0).abs())
                .max((q / projected - 1.0).abs());
            assert!(
                (s / omega - 1.0).abs() < QUAD,
                "{p:?} {w}×{h}: Σω = {s}, expected {omega}"
            );
            assert!(
                (q / projected - 1.0).abs() < QUAD,
                "{p:?} {w}×{h}: Σ cos·ω = {q}, expected {projected}"
            );
        }
        // A rectangular pyramid of half-angles α, β: Ω = 4 asin(sin α sin β).
        let vfov = 50.0f64;
        let b = (vfov / 2.0).to_radians();
        let a = ((w as f64 / h as f64) * b.tan()).atan();
        let c = camera(Projection::Perspective { vfov_deg: vfov }, w, h);
        let (s, _) = sums(&c);
        let omega = 4.0 * (a.sin() * b.sin()).asin();
        assert!(
            (s / omega - 1.0).abs() < QUAD,
            "perspective: Σω = {s}, expected {omega}"
        );
        worst = worst.max((s / omega - 1.0).abs());
    }
    eprintln!("largest relative error of a sum: {worst:.1e}");
}

/// The image radius each mapping predicts for angle θ off axis, as a fraction of the circle's
/// radius (the textbook formulas, independent of the camera code).
fn predicted_radius(m: M, theta: f64, half_fov: f64) -> f64 {
    let f = |t: f64| match m {
        M::Equidistant => t,
        M::Orthographic => t.sin(),
        M::Equisolid => 2.0 * (t / 2.0).sin(),
        M::Stereographic => 2.0 * (t / 2.0).tan(),
    };
    f(theta) / f(half_fov)
}

#[test]
fn a_direction_lands_on_the_predicted_pixel_and_comes_back() {
    let (w, h) = (120usize, 90usize);
    let projections = [
        Projection::Perspective { vfov_deg: 60.0 },
        fisheye(M::Equidistant, 180.0),
        fisheye(M::Equidistant, 360.0),
        fisheye(M::Orthographic, 180.0),
        fisheye(M::Equisolid, 150.0),
        fisheye(M::Stereographic, 180.0),
        Projection::Equirectangular,
    ];
    for p in projections {
        let c = camera(p, w, h);
        let (fwd, right, up) = c.frame();
        // A direction θ = 40° off axis, toward the upper right at azimuth 30° above "right".
        let (theta, psi) = (40f64.to_radians(), 30f64.to_radians());
        let d = (fwd * theta.cos() as f32
            + right * (theta.sin() * psi.cos()) as f32
            + up * (theta.sin() * psi.sin()) as f32)
            .normalize();
        let (cx, cy) = (w as f64 / 2.0, h as f64 / 2.0);
        let expected = match p {
            Projection::Perspective { vfov_deg } => {
                let s = (vfov_deg / 2.0).to_radians().tan() / cy;
                let (x, y) = (theta.tan() * psi.cos(), theta.tan() * psi.sin());
                (cx + x / s, cy - y / s)
            }
            Projection::Fisheye { mapping, fov_deg } => {
                let r = predicted_radius(mapping, theta, (fov_deg / 2.0).to_radians()) * cy;
                (cx + r * psi.cos(), cy - r * psi.sin())
            }
            Projection::Equirectangular => {
                let (x, y, z) = (
                    theta.sin() * psi.cos(),
                    theta.sin() * psi.sin(),
                    theta.cos(),
                );
                let (phi, beta) = (x.atan2(z), y.asin());
                (cx + phi / (2.0 * PI) * w as f64, cy - beta / PI * h as f64)
            }
        };
        let got = c.film_position(d).expect("in view");
        assert!(
            (got.0 - expected.0).abs() < 1e-3 && (got.1 - expected.1).abs() < 1e-3,
            "{p:?}: film {got:?}, predicted {expected:?}"
        );
        // Light tracing finds the same spot for a point in that direction.
        let k = c
            .connect(c.position + d * 3.0, Vec2::ZERO, 0.5)
            .expect("connects");
        assert!((k.film - Vec2::new(got.0 as f32, got.1 as f32)).length() < 2e-3);
        // Pixel centre → direction → film position: the centre again.
        for (x, y) in [(3, 44), (60, 45), (100, 10), (70, 80), (59, 44)] {
            if !c.pixel_inside(x, y) {
                continue;
            }
            let cov = c.pixel_coverage(x, y);
            if cov < 1.0 {
                continue;
            }
            let d = c.pixel_direction(x, y);
            let (fx, fy) = c.film_position(d).expect("seen");
            assert!(
                (fx - (x as f64 + 0.5)).abs() < 2e-3 && (fy - (y as f64 + 0.5)).abs() < 2e-3,
                "{p:?} pixel ({x}, {y}) came back at ({fx}, {fy})"
            );
        }
    }
    // Beyond the field: behind a 180° fisheye and outside its circle.
    let c = camera(fisheye(M::Equisolid, 180.0), w, h);
    let (fwd, _, _) = c.frame();
    assert!(c.film_position(-fwd).is_none());
    assert!(!c.pixel_inside(0, 0) && c.pixel_inside(60, 45));
    assert!(c.try_ray(1.0, 1.0, Vec2::ZERO).is_none());
}

/// The importance of every projection integrates, over a sphere of points around the camera,
/// to the film area that sees the scene: Σ importance·cos·dA = inside pixel area (px²).
#[test]
fn connect_importance_integrates_to_the_film() {
    let (w, h) = (24usize, 16usize);
    for p in [
        fisheye(M::Equidistant, 360.0),
        fisheye(M::Orthographic, 180.0),
        fisheye(M::Stereographic, 180.0),
        Projection::Equirectangular,
    ] {
        let c = camera(p, w, h);
        let radius = 2.0f64;
        let (nt, np) = (600usize, 1200usize);
        let mut sum = 0.0f64;
        for i in 0..nt {
            let t = (i as f64 + 0.5) * PI / nt as f64;
            let da = radius * radius * t.sin() * (PI / nt as f64) * (2.0 * PI / np as f64);
            for j in 0..np {
                let ph = (j as f64 + 0.5) * 2.0 * PI / np as f64;
                let d = Vec3::new(
                    (t.sin() * ph.cos()) as f32,
                    t.cos() as f32,
                    (t.sin() * ph.sin()) as f32,
                );
                if let Some(k) = c.connect(c.position + d * radius as f32, Vec2::ZERO, 0.0) {
                    // The sphere faces the camera: cos = 1.
                    sum += k.importance as f64 * da;
                }
            }
        }
        let area: f64 = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| c.pixel_coverage(x, y))
            .sum();
        assert!((sum / area - 1.0).abs() < 5e-3, "{p:?}: {sum} vs {area}");
    }
}

#[test]
fn a_thin_lens_needs_the_perspective() {
    // The lens is ignored by `with_projection` for other projections; the scene refuses it.
    let text = r#"(camera: (position: (0, 0, 0), look_at: (0, 0, 1), resolution: (8, 8),
        projection: Fisheye(mapping: Equisolid, fov_deg: 180),
        lens: (aperture_radius: 0.01, focus_distance: 1.0)))"#;
    let e = scene_error(text);
    assert!(
        e.contains("`camera.lens`") && e.contains("perspective"),
        "{e}"
    );
    let _ = ThinLens {
        radius: 0.0,
        focus_distance: 1.0,
    };
}

fn scene_error(text: &str) -> String {
    let path = std::path::Path::new("t.ron");
    match candela::scene::parse(text, path) {
        Err(e) => e.to_string(),
        Ok(s) => match candela::scene::build(&s, path, &Default::default()) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted: {text}"),
        },
    }
}

#[test]
fn projection_fields_are_checked() {
    let cam = |body: &str| {
        format!("(camera: (position: (0, 0, 0), look_at: (0, 0, 1), resolution: (8, 8), {body}))")
    };
    for (body, want) in [
        (
            "projection: Fisheye(mapping: Orthographic, fov_deg: 200)",
            "`camera.projection.fov_deg`",
        ),
        (
            "projection: Fisheye(mapping: Stereographic, fov_deg: 181)",
            "(0, 180]",
        ),
        (
            "projection: Fisheye(mapping: Equidistant, fov_deg: 361)",
            "(0, 360]",
        ),
        (
            "projection: Fisheye(mapping: Equisolid, fov_deg: 0)",
            "`camera.projection.fov_deg`",
        ),
        (
            "vfov_deg: 40, projection: Equirectangular",
            "`camera.vfov_deg`: conflicts with `projection`",
        ),
        ("", "`camera.vfov_deg`: missing"),
        (
            "projection: Perspective(vfov_deg: 180)",
            "`camera.projection.vfov_deg`",
        ),
        ("projection: Fisheye(mapping: Equisolid, fov: 90)", "fov"),
    ] {
        let e = scene_error(&cam(body));
        assert!(e.contains(want), "{body}: {e}");
    }
}

/// A sky of luminance L above the horizon (a Uniform sky of horizontal illuminance πL) over a
/// ground of luminance ρL, seen by 180° fisheyes: looking at the zenith they see E = πL,
/// looking at the horizon πL(1 + ρ)/2, as a lux meter at the eye facing the view direction.
#[test]
fn fisheyes_in_a_uniform_sky_integrate_to_the_illuminance_at_the_eye() {
    let (l, rho) = (1000.0f64, 0.4f64);
    for mapping in ["Equidistant", "Orthographic", "Equisolid", "Stereographic"] {
        for (look, expected) in [
            ("(0.0, 1.0, 0.001)", PI * l),
            ("(0.0, 0.0, 1.0)", PI * l * (1.0 + rho) / 2.0),
        ] {
            let normal = look;
            let text = format!(
                r#"(camera: (position: (0, 0, 0), look_at: {look}, resolution: (48, 48),
                    projection: Fisheye(mapping: {mapping}, fov_deg: 180)),
                  render: (spp: 8),
                  lights: [Sky(model: Uniform, amount: HorizontalIlluminance({e_h}),
                               ground_reflectance: {rho})],
                  meters: [Illuminance(name: "eye", position: (0, 0, 0), normal: {normal})],
                  measure: (samples: 40000))"#,
                e_h = PI * l
            );
            let world = common::world(&text);
            let film = common::render(&world, 1);
            // The pixels outside the circle take no samples and do not count as pixels.
            assert_eq!(film.samples_per_pixel(), 8.0, "{mapping}");
            let c = &world.camera;
            let lum: Vec<f32> = film.pixels.iter().map(|p| p.mean_xyz()[1] as f32).collect();
            let e = vertical_illuminance_lx(c, &lum);
            // Standard error of E from the pixels' (independent) standard errors.
            let mut var = 0.0f64;
            for y in 0..c.height {
                for x in 0..c.width {
                    if !c.pixel_inside(x, y) {
                        assert_eq!(film.pixels[y * c.width + x].count, 0);
                        continue;
                    }
                    let wgt = c.pixel_projected_solid_angle_sr(x, y) / c.pixel_coverage(x, y);
                    var += (wgt
                        * film.pixels[y * c.width + x]
                            .y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES))
                    .powi(2);
                }
            }
            let se = var.sqrt();
            assert!(
                se < 0.01 * expected,
                "{mapping}: standard error {se} too large"
            );
            assert!(
                (e - expected).abs() < 4.0 * se,
                "{mapping} looking {look}: E = {e} ± {se} lx, expected {expected}"
            );
            let m = &candela::meter::measure_all(&world).meters[0];
            eprintln!(
                "{mapping} looking {look}: image {e:.2} ± {se:.2} lx, meter {:.2} ± {:.2}, expected {expected:.2}",
                m.mean, m.stderr
            );
            let both = (se * se + m.stderr * m.stderr).sqrt();
            assert!(
                (e - m.mean).abs() < 4.0 * both,
                "{mapping} looking {look}: image {e} ± {se}, meter {} ± {}",
                m.mean,
                m.stderr
            );
        }
    }
}

/// Light tracing through a fisheye: a point light between a Lambertian floor and a metal
/// ceiling, seen by an equisolid fisheye looking down. Light paths (the light's mirror image)
/// are splatted through the fisheye's inverse map and importance; every pixel wholly inside the
/// circle must show ρ/π · (direct + mirrored illuminance), the image-source law, averaged over
/// its footprint, within 5 standard errors.
#[test]
fn light_traced_caustics_work_through_a_fisheye() {
    use candela::world::Caustics;
    let (i_cd, h_light, h_mirror, rho, n, k) = (100.0f64, 0.4f64, 1.0f64, 0.5f64, 0.2, 3.0);
    let text = format!(
        r#"(camera: (position: (0.1, 0.9, 0.0), look_at: (0.1, 0, 0), up: (0, 0, 1), resolution: (12, 12),
            projection: Fisheye(mapping: Equisolid, fov_deg: 120)),
          render: (spp: 256, max_depth: 2, light_paths_per_sample: 4),
          materials: {{ "floor": Diffuse(reflectance: Constant({rho})),
                        "mirror": Conductor(n: Constant({n}), k: Constant({k})) }},
          objects: [
            (shape: Quad(origin: (-50, 0, -50), edge_u: (0, 0, 100), edge_v: (100, 0, 0)), material: "floor"),
            (shape: Quad(origin: (-50, {h_mirror}, -50), edge_u: (100, 0, 0), edge_v: (0, 0, 100)), material: "mirror"),
          ],
          lights: [Point(position: (0, {h_light}, 0), spectrum: Named("D65"), amount: Intensity({i_cd}))])"#
    );
    let w = common::world_with(&text, Caustics::LightTracing);
    assert!(w.caustics.is_some());
    let film = common::render(&w, 2);
    let e_from = |p: Vec3, h: f64, i: f64| {
        let d = Vec3::new(0.0, h as f32, 0.0) - p;
        let d2 = d.length_squared() as f64;
        i * (d.y as f64 / d2.sqrt()) / d2
    };
    let e = |p: Vec3| {
        let d = Vec3::new(0.0, (2.0 * h_mirror - h_light) as f32, 0.0) - p;
        let c = d.y as f64 / d.length() as f64;
        let r = common::conductor_reflectance(c, n, k);
        e_from(p, h_light, i_cd) + e_from(p, 2.0 * h_mirror - h_light, i_cd * r)
    };
    let (mut sum, mut sum_exp, mut var, mut checked) = (0.0, 0.0, 0.0, 0);
    for y in 0..12 {
        for x in 0..12 {
            if w.camera.pixel_coverage(x, y) < 1.0 {
                continue;
            }
            let (v, se) = common::luminance(&film.pixels[y * 12 + x]);
            let want = rho / PI * common::floor_footprint_mean(&w, x, y, e);
            assert!(
                (v - want).abs() <= 5.0 * se,
                "pixel ({x}, {y}): {v} ± {se}, expected {want}"
            );
            sum += v;
            sum_exp += want;
            var += se * se;
            checked += 1;
        }
    }
    assert!(checked >= 60, "{checked} pixels checked");
    let se = var.sqrt();
    eprintln!("{checked} pixels: Σ {sum:.4} ± {se:.4}, expected {sum_exp:.4}");
    assert!(se < 0.01 * sum_exp, "standard error {se} of {sum_exp}");
    assert!(
        (sum - sum_exp).abs() <= 4.0 * se,
        "Σ {sum} ± {se}, expected {sum_exp}"
    );
}
