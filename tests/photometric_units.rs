//! Every photometric amount a scene can give a light (docs/scene-format.md: `Luminance`, `Flux`
//! of area emitters one- and two-sided, `Intensity` and `Flux` of spots, …) checked against the
//! closed forms of ../shared/reference/closed-forms.md §2.2–2.5 through meters and pixels. Each
//! estimate must lie within 5 of its own standard errors of the closed form, with a standard
//! error below 1 % of it (so that a few per cent of systematic error cannot pass).

mod common;
use candela::meter::{measure_all, Estimate};
use common::*;
use std::f64::consts::PI;

/// Meters only: a 1-pixel camera that is never rendered, `body` holding objects, lights and
/// `meters`, each meter measured with `samples` samples.
fn meters(body: &str, samples: u64) -> Vec<Estimate> {
    let w = world(&format!(
        r#"(
        camera: (position: (0, -50, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 1, resolution: (1, 1)),
        render: (spp: 1, max_depth: 8),
        {body}
        measure: (samples: {samples}),
    )"#
    ));
    measure_all(&w).meters
}

fn check(e: &Estimate, expected: f64, label: &str) {
    println!(
        "{label}: {} ± {} (expected {expected}, rel. se {:.5})",
        e.mean,
        e.stderr,
        e.stderr / expected
    );
    assert_estimate_near(e.mean, e.stderr, expected, 0.01, label);
}

/// Configuration factor from a point to a parallel a × b rectangle at distance h, the point
/// on the normal through one corner (closed-forms.md §2.4, Siegel & Howell B-4).
fn corner_f(a: f64, b: f64, h: f64) -> f64 {
    let (x, y) = (a / h, b / h);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
}

/// The same factor on the axis through the rectangle's centre: four corner rectangles.
fn centre_f(a: f64, b: f64, h: f64) -> f64 {
    4.0 * corner_f(a / 2.0, b / 2.0, h)
}

#[test]
fn form_factor_check_value() {
    // closed-forms.md §2.4: a = 1, b = 2, h = 3 → F = 0.0522678.
    assert!((corner_f(1.0, 2.0, 3.0) - 0.0522678).abs() < 1e-7);
    // Far away F → A/(π h²) (a small source), and close up F → 1 (an infinite plane).
    let f = centre_f(0.1, 0.2, 100.0);
    assert!((f / (0.02 / (PI * 1e4)) - 1.0).abs() < 1e-5, "{f}");
    assert!((centre_f(1e4, 1e4, 1e-3) - 1.0).abs() < 1e-6);
}

/// A 1 m × 2 m quad (A = 2 m²) in the plane y = 2, front face down (edge_u × edge_v = −y),
/// emitting Φ = 1000 lm of D65 from its front face only: L = Φ/(πA) = 159.155 cd/m²
/// (closed-forms.md §2.3: Φ = π L A for a Lambertian planar emitter).
///
/// Checked by luminance meters (one direction, a 2° cone, and an oblique look: a Lambertian
/// emitter has the same luminance in every direction), by an illuminance meter 1.5 m below
/// its centre (E = π L F, F from the corner formula by superposition) and by one above its
/// back, which must see nothing.
#[test]
fn area_emitter_flux_one_sided() {
    let (phi, a, b, h) = (1000.0, 1.0, 2.0, 1.5);
    let l = phi / (PI * a * b);
    let m = meters(
        r#"objects: [(shape: Quad(origin: (-0.5, 2, -1), edge_u: (1, 0, 0), edge_v: (0, 0, 2)), material: "black",
                      emission: (spectrum: Named("D65"), amount: Flux(1000.0)))],
           meters: [
               Luminance(name: "straight", position: (0, 0.5, 0), direction: (0, 1, 0)),
               Luminance(name: "cone", position: (0.1, 0.0, 0.2), direction: (0, 1, 0), half_angle_deg: 2.0),
               Luminance(name: "oblique", position: (-2, 0.5, 0.3), direction: (2, 1.5, -0.3)),
               Illuminance(name: "below", position: (0, 0.5, 0), normal: (0, 1, 0)),
               Illuminance(name: "behind", position: (0, 3, 0), normal: (0, -1, 0)),
               Luminance(name: "back", position: (0, 3, 0), direction: (0, -1, 0)),
           ],"#,
        16384,
    );
    check(&m[0], l, "one-sided: luminance, one direction");
    check(&m[1], l, "one-sided: luminance, 2° cone");
    check(&m[2], l, "one-sided: luminance, oblique");
    check(
        &m[3],
        PI * l * centre_f(a, b, h),
        "one-sided: E below the centre",
    );
    assert_eq!(
        (m[4].mean, m[5].mean),
        (0.0, 0.0),
        "behind a one-sided emitter"
    );
}

/// The same quad with `two_sided: true`: the flux is shared by both faces, L = Φ/(2πA), and
/// each face lights its own side.
#[test]
fn area_emitter_flux_two_sided() {
    let (phi, a, b, h) = (1000.0, 1.0, 2.0, 1.5);
    let l = phi / (2.0 * PI * a * b);
    let m = meters(
        r#"objects: [(shape: Quad(origin: (-0.5, 2, -1), edge_u: (1, 0, 0), edge_v: (0, 0, 2)), material: "black",
                      emission: (spectrum: Named("D65"), amount: Flux(1000.0), two_sided: true))],
           meters: [
               Luminance(name: "front", position: (0, 0.5, 0), direction: (0, 1, 0)),
               Luminance(name: "back", position: (0.2, 3.5, -0.4), direction: (0, -1, 0)),
               Illuminance(name: "below", position: (0, 0.5, 0), normal: (0, 1, 0)),
               Illuminance(name: "above", position: (0, 3.5, 0), normal: (0, -1, 0)),
           ],"#,
        16384,
    );
    check(&m[0], l, "two-sided: luminance of the front");
    check(&m[1], l, "two-sided: luminance of the back");
    let e = PI * l * centre_f(a, b, h);
    check(&m[2], e, "two-sided: E below the centre");
    check(&m[3], e, "two-sided: E above the centre");
}

/// The camera as a luminance meter: a 12 × 12 image filled by a one-sided quad of Φ = 500 lm
/// and A = 4 × 3 m² seen obliquely; every pixel must show L = Φ/(πA) (and the image mean,
/// within 4σ with a standard error below 1 %).
#[test]
fn area_emitter_flux_seen_by_the_camera() {
    let (phi, area) = (500.0, 12.0);
    let w = world(
        r#"(
        camera: (position: (0.5, -1, 0.5), look_at: (0, 0.6, 0), vfov_deg: 20, resolution: (12, 12)),
        render: (spp: 64),
        objects: [(shape: Quad(origin: (-2, 2, -1.5), edge_u: (4, 0, 0), edge_v: (0, 0, 3)), material: "black",
                   emission: (spectrum: Named("A"), amount: Flux(500.0)))],
    )"#,
    );
    let film = render(&w, 2);
    let (m, se) = image_mean(&film);
    println!(
        "camera on a Flux emitter: mean L = {} ± {se} (expected {}, rel. se {:.5})",
        m[1],
        phi / (PI * area),
        se / (phi / (PI * area))
    );
    check_pixels(&film, "camera on a Flux emitter", luminance, |_, _| {
        phi / (PI * area)
    });
}

/// Φ = ∫ I(θ) dω of a spot of axial intensity I whose falloff is, as docs/scene-format.md
/// says, 1 inside the inner half-angle, a smoothstep in cos θ from 0 at the outer half-angle
/// to 1 at the inner one, and 0 outside: by a 20 000-interval midpoint rule in μ = cos θ
/// (dω = 2π dμ), not by the closed form, so that the closed form is checked as well.
fn spot_flux_per_candela(inner_deg: f64, outer_deg: f64) -> f64 {
    let (ci, co) = (inner_deg.to_radians().cos(), outer_deg.to_radians().cos());
    let n = 20_000;
    let mut sum = 0.0;
    for k in 0..n {
        let mu = -1.0 + (k as f64 + 0.5) * 2.0 / n as f64;
        sum += spot_falloff(mu, ci, co) * 2.0 / n as f64;
    }
    2.0 * PI * sum
}

/// The documented falloff: smoothstep in cos θ between the outer and the inner cone.
fn spot_falloff(cos_t: f64, ci: f64, co: f64) -> f64 {
    if ci == co {
        return if cos_t < co { 0.0 } else { 1.0 };
    }
    let t = ((cos_t - co) / (ci - co)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[test]
fn spot_flux_integral_matches_the_closed_form() {
    // ∫₀¹ (3t² − 2t³) dt = 1/2, so Φ = 2π I [(1 − cos θi) + (cos θi − cos θo)/2].
    for (i, o) in [(20.0, 40.0), (0.0, 30.0), (30.0, 30.0), (10.0, 120.0)] {
        let (ci, co) = (f64::cos(i * PI / 180.0), f64::cos(o * PI / 180.0));
        let closed = 2.0 * PI * ((1.0 - ci) + (ci - co) / 2.0);
        let numeric = spot_flux_per_candela(i, o);
        // The midpoint rule is O(h²) on the C¹ smoothstep; a hard edge (inner = outer) costs
        // at most one interval, 2π·10⁻⁴.
        let tol = if i == o {
            2.0 * PI * 1e-4
        } else {
            1e-7 * closed
        };
        assert!(
            (numeric - closed).abs() < tol,
            "inner {i}°, outer {o}°: {numeric} vs {closed}"
        );
    }
}

/// A spot of Φ = 2000 lm (inner 20°, outer 40°) 3 m above the floor, aimed straight down.
/// Its axial intensity is I = Φ / ∫ falloff dω; on the axis E = I/d², and across the falloff
/// zone on a horizontal receiver E = I·falloff(θ)·cos θ/d² with d = h/cos θ. Outside the
/// outer cone E = 0. The same spot given as Intensity(I) must give the same numbers. A
/// linear instead of smoothstep falloff would be 6 %, 11 %, 37 % and 190 % off at
/// 30°, 25°, 35° and 38°.
#[test]
fn spot_flux_on_axis_and_in_the_falloff_zone() {
    let (phi, inner, outer, h) = (2000.0, 20.0f64, 40.0f64, 3.0);
    let i_cd = phi / spot_flux_per_candela(inner, outer);
    let (ci, co) = (inner.to_radians().cos(), outer.to_radians().cos());
    let angles = [0.0f64, 10.0, 25.0, 30.0, 35.0, 38.0];
    let mut meter_list = String::new();
    for (k, t) in angles.iter().enumerate() {
        let x = h * t.to_radians().tan();
        meter_list +=
            &format!("Illuminance(name: \"m{k}\", position: ({x}, 0, 0), normal: (0, 1, 0)),\n");
    }
    // Just outside the outer cone (41°), and one facing the spot on its axis 2 m from it.
    let x_out = h * 41f64.to_radians().tan();
    meter_list += &format!(
        "Illuminance(name: \"out\", position: ({x_out}, 0, 0), normal: (0, 1, 0)),
         Illuminance(name: \"axis\", position: (0, 1, 0), normal: (0, 1, 0)),"
    );
    for amount in [format!("Flux({phi})"), format!("Intensity({i_cd})")] {
        let m = meters(
            &format!(
                r#"lights: [Spot(position: (0, {h}, 0), look_at: (0, 0, 0), inner_deg: {inner}, outer_deg: {outer},
                                spectrum: Named("LED-B3"), amount: {amount})],
                   meters: [{meter_list}],"#
            ),
            4096,
        );
        for (k, t) in angles.iter().enumerate() {
            let c = t.to_radians().cos();
            let d2 = (h / c).powi(2);
            let expected = i_cd * spot_falloff(c, ci, co) * c / d2;
            check(
                &m[k],
                expected,
                &format!("spot {amount}, {t}° off the axis"),
            );
        }
        assert_eq!(m[angles.len()].mean, 0.0, "spot {amount}: outside the cone");
        check(
            &m[angles.len() + 1],
            i_cd / 4.0,
            &format!("spot {amount}, on the axis at 2 m"),
        );
    }
}

/// Luminance meters aimed at a Lambertian emitter of known luminance (a disc and a sphere,
/// from several directions) read that luminance. FL11's spiky spectrum makes the wavelength
/// sampling noisy (1.2 % at 8192 samples), hence 65 536 samples.
#[test]
fn luminance_meter_on_an_emitter_of_known_luminance() {
    let m = meters(
        r#"objects: [
               (shape: Disk(center: (0, 0, 0), normal: (0, 0, -1), radius: 0.5), material: "black",
                emission: (spectrum: Named("FL11"), amount: Luminance(350.0))),
               (shape: Sphere(center: (3, 0, 0), radius: 0.4), material: "black",
                emission: (spectrum: Blackbody(2700), amount: Luminance(80.0))),
           ],
           meters: [
               Luminance(name: "disc, normal", position: (0, 0, -2), direction: (0, 0, 1)),
               Luminance(name: "disc, 60°", position: (1.732, 0, -1), direction: (-1.732, 0.05, 1)),
               Luminance(name: "sphere, centre", position: (3, 0, -3), direction: (0, 0, 1), half_angle_deg: 4.0),
               Luminance(name: "sphere, edge", position: (3, 2, 0), direction: (0.18, -1, 0)),
           ],"#,
        65536,
    );
    check(&m[0], 350.0, "disc seen along its normal");
    check(&m[1], 350.0, "disc seen at 60°");
    check(&m[2], 80.0, "sphere, 4° cone");
    check(&m[3], 80.0, "sphere near its limb");
}

/// A Lambertian floor of reflectance ρ = 0.35 lit by a point light of I = 400 cd (illuminant
/// A) 2.5 m straight above one point: there E = I/d² and L = ρE/π = ρI/(πd²)
/// (closed-forms.md §2.2, §2.5), whatever the direction it is looked at from. The emission
/// spectrum is normalised photometrically and the reflectance is flat, so the photometric
/// result does not depend on it. Given as Flux(Φ) the point light has I = Φ/(4π).
#[test]
fn luminance_meter_on_a_plane_under_a_point_light() {
    let (rho, i_cd, d) = (0.35, 400.0, 2.5);
    let expected = rho * i_cd / (PI * d * d);
    for amount in [
        format!("Intensity({i_cd})"),
        format!("Flux({})", 4.0 * PI * i_cd),
    ] {
        let m = meters(
            &format!(
                r#"materials: {{ "floor": Diffuse(reflectance: Constant({rho})) }},
                   objects: [(shape: Quad(origin: (-50, 0, -50), edge_u: (0, 0, 100), edge_v: (100, 0, 0)), material: "floor")],
                   lights: [Point(position: (1, {d}, 2), spectrum: Named("A"), amount: {amount})],
                   meters: [
                       Luminance(name: "steep", position: (1.2, 1.5, 2.1), direction: (-0.2, -1.5, -0.1)),
                       Luminance(name: "grazing", position: (-2, 1, 0), direction: (3, -1, 2)),
                       Illuminance(name: "foot", position: (1, 0.001, 2), normal: (0, 1, 0)),
                   ],"#
            ),
            8192,
        );
        check(&m[0], expected, &format!("{amount}: L at the foot, steep"));
        check(
            &m[1],
            expected,
            &format!("{amount}: L at the foot, grazing"),
        );
        let d2 = (d - 0.001) * (d - 0.001);
        check(&m[2], i_cd / d2, &format!("{amount}: E at the foot"));
    }
}

/// A Lambertian sphere of luminance L = 1000 cd/m² and radius R = 0.5 m seen from D = 2 m
/// and D = 0.8 m from its centre by a receiver facing the centre: E = π L R²/D²
/// (closed-forms.md §2.3; the whole sphere is above the receiver's horizon).
#[test]
fn sphere_emitter_illuminance_from_outside() {
    let (l, r) = (1000.0, 0.5);
    let m = meters(
        r#"objects: [(shape: Sphere(center: (0, 1, 0), radius: 0.5), material: "black",
                      emission: (spectrum: Named("D50"), amount: Luminance(1000.0)))],
           meters: [
               Illuminance(name: "far", position: (0, -1, 0), normal: (0, 1, 0)),
               Illuminance(name: "near", position: (0.48, 1.64, 0), normal: (-0.6, -0.8, 0)),
           ],"#,
        16384,
    );
    check(&m[0], PI * l * r * r / 4.0, "sphere at D = 2 m");
    check(&m[1], PI * l * r * r / 0.64, "sphere at D = 0.8 m");
}

/// The remaining amounts: a `Distant` light's `Illuminance(lx)` is the illuminance on a
/// surface facing it, so a receiver tilted by θ gets E cos θ (§2.2); an `Environment` of
/// `Luminance(L)` gives E = π L on an unoccluded receiver (§2.3, uniform hemisphere) and a
/// luminance meter looking at it reads L.
#[test]
fn distant_and_environment_amounts() {
    let m = meters(
        r#"lights: [Distant(direction: (0, -1, 0), spectrum: Named("D75"), amount: Illuminance(20000.0))],
           meters: [
               Illuminance(name: "facing", position: (0, 0, 0), normal: (0, 1, 0)),
               Illuminance(name: "tilted", position: (0, 0, 0), normal: (0.6, 0.8, 0)),
           ],"#,
        4096,
    );
    check(&m[0], 20000.0, "distant light, facing");
    check(&m[1], 20000.0 * 0.8, "distant light, tilted by acos 0.8");
    let m = meters(
        r#"lights: [Environment(spectrum: Named("D65"), amount: Luminance(3000.0))],
           meters: [
               Illuminance(name: "up", position: (0, 0, 0), normal: (0, 1, 0)),
               Illuminance(name: "slanted", position: (0, 0, 0), normal: (0.3, -0.2, 0.9)),
               Luminance(name: "sky", position: (0, 0, 0), direction: (0.2, 1, 0.1), half_angle_deg: 5.0),
           ],"#,
        16384,
    );
    check(&m[0], PI * 3000.0, "environment, E on a receiver");
    check(&m[1], PI * 3000.0, "environment, E on a slanted receiver");
    check(&m[2], 3000.0, "environment, luminance");
}

/// Illuminance 2 m below a one-sided disc of luminance L = 100 cd/m² and radius 0.5 m, on its
/// axis: E = πL·R²/(R² + h²) (closed-forms.md §2.3). Direct illuminance is `max_depth` 1 (the
/// receiver is the path's one scattering event); at `max_depth` 0 nothing may scatter and the
/// meter reads 0. (Before, depth 0 kept light sampling with its MIS weight but dropped the
/// cosine-sampled half, and read 3 % low.)
#[test]
fn direct_illuminance_is_max_depth_one() {
    let (l, r, h) = (100.0, 0.5, 2.0);
    let expected = PI * l * r * r / (r * r + h * h);
    let scene = |depth: u32| {
        world(&format!(
            r#"(
            camera: (position: (0, -50, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 1, resolution: (1, 1)),
            render: (spp: 1, max_depth: {depth}),
            objects: [(shape: Disk(center: (0, 0, 0), normal: (0, 0, -1), radius: {r}), material: "black",
                       emission: (spectrum: Named("D65"), amount: Luminance({l})))],
            meters: [Illuminance(name: "below", position: (0, 0, -{h}), normal: (0, 0, 1))],
            measure: (samples: 65536),
        )"#
        ))
    };
    check(&measure_all(&scene(1)).meters[0], expected, "depth 1");
    let e0 = measure_all(&scene(0)).meters[0];
    assert_eq!((e0.mean, e0.stderr), (0.0, 0.0), "depth 0");
}
