//! A year of daylight, piece by piece against closed forms and direct renders:
//! - an hour rebuilt from sky coefficients and its own sun's coefficient equals a direct render
//!   of that hour's Perez sky with its sun, in a glazed side-lit room (three hours);
//! - the direct sun behind the pane is E_n cos θ T(θ), T the thin slab's Fresnel transmittance;
//! - a year of uniform skies of constant horizontal illuminance E_h over a black room with a
//!   roof opening gives each point E_h F (F the opening's configuration factor), so DA is 1
//!   where E_h F ≥ 300 lx and 0 elsewhere, and sDA the fraction of such points.

mod common;
use candela::annual::coefficients::sky_coefficients;
use candela::annual::metrics::{Schedule, Thresholds};
use candela::annual::results::{hourly, metrics};
use candela::annual::sun::{sun_coefficients, SunCoefficients};
use candela::annual::year::HourSky;
use candela::daylight::patches::{SkyPatches, SkyVector};
use candela::daylight::perez::DEFAULT_DEW_POINT_C;
use candela::light::Light;
use candela::meter::measure_all;
use common::world;
use glam::Vec3;

/// The side-lit room (tests/common), grey (ρ = 0.5) inside, its window glazed with a clear
/// pane of index 1.5.
const ROOM: &str = concat!(
    r#"materials: {"grey": Diffuse(reflectance: Constant(0.5)), "pane": ThinDielectric(ior: Constant(1.5))},
    objects: ["#,
    crate::side_lit_room_walls!(),
    r#"(material: "pane", shape: Quad(origin: (-1, 0.9, 2), edge_u: (0, 1.2, 0), edge_v: (2, 0, 0)))]"#
);
use common::{SIDE_LIT_CAMERA as CAMERA, SIDE_LIT_PORTAL as PORTAL};

/// Work-plane points (0.8 m): in the sun patch of the high sun near the window, mid-room, at
/// the back.
const POINTS: [[f32; 3]; 3] = [[0.0, 0.8, 1.2], [-0.8, 0.8, 0.0], [0.5, 0.8, -1.5]];

fn unit_sky_world(room: &str, portal: &str) -> candela::world::World {
    world(&format!(
        "({CAMERA}, {room}, lights: [Sky(model: Uniform, amount: ZenithLuminance(1.0), \
         ground_reflectance: 1.0, {portal})])"
    ))
}

/// The sun's world: the room lit by a sun of 1 lx (its direction set per hour).
fn sun_world(room: &str) -> candela::world::World {
    let w = world(&format!(
        "({CAMERA}, {room}, lights: [Sun(sun: (altitude_deg: 45.0, azimuth_deg: 180.0), \
         amount: NormalIlluminance(1.0))])"
    ));
    let lights = w.lights.clone();
    w.relit(lights)
}

#[test]
fn an_hour_with_its_sun_from_coefficients_equals_its_direct_render() {
    let patches = SkyPatches::new(4).unwrap();
    let receivers: Vec<(Vec3, Vec3)> = POINTS.iter().map(|p| (Vec3::from(*p), Vec3::Y)).collect();
    let c = sky_coefficients(&unit_sky_world(ROOM, PORTAL), &receivers, &patches, 1 << 16).unwrap();
    // (direct-normal W/m², diffuse-horizontal W/m², sun altitude °, azimuth °)
    let hours = [
        (0.0, 180.0, 30.0, 170.0),
        (650.0, 110.0, 55.0, 190.0),
        (300.0, 70.0, 12.0, 235.0),
    ];
    let dirs: Vec<[f64; 3]> = hours.iter().map(|h| common::to_sun(h.2, h.3).0).collect();
    let mut sw = sun_world(ROOM);
    let s: SunCoefficients = sun_coefficients(
        &mut sw,
        &receivers,
        &dirs,
        &common::default_site(),
        45.0,
        1 << 16,
        256,
        &mut |_, _| {},
    )
    .unwrap();
    let meters: Vec<String> = POINTS
        .iter()
        .enumerate()
        .map(|(i, p)| {
            format!(
                "Illuminance(name: \"p{i}\", position: ({}, {}, {}), normal: (0, 1, 0))",
                p[0], p[1], p[2]
            )
        })
        .collect();
    let mut worst = 0.0f64;
    for (h, (dn, dh, alt, az)) in hours.into_iter().enumerate() {
        let v = SkyVector::perez(
            &patches,
            dh,
            dn,
            common::to_sun(alt, az).0,
            1.0,
            DEFAULT_DEW_POINT_C,
            0.2,
        )
        .unwrap();
        let scene = format!(
            "({CAMERA}, {ROOM}, lights: [Sky(model: PerezIrradiance(direct_normal_w_m2: {dn}, \
             diffuse_horizontal_w_m2: {dh}), sun: (altitude_deg: {alt}, azimuth_deg: {az}), \
             ground_reflectance: 0.2, {PORTAL})], meters: [{}], measure: (samples: 65536))",
            meters.join(", ")
        );
        let direct = measure_all(&world(&scene));
        for (r, m) in direct.meters.iter().enumerate() {
            let (e_sky, se_sky) = c.illuminance(r, &v.luminance_cd_m2);
            let (t, _) = s.batches(h, r);
            let k = t.len() as f64;
            let mu = t.iter().sum::<f64>() / k;
            let se_sun = (t.iter().map(|x| (x - mu).powi(2)).sum::<f64>() / (k - 1.0) / k).sqrt();
            let e = e_sky + v.direct_normal_lx * mu;
            let se = (se_sky.powi(2) + (v.direct_normal_lx * se_sun).powi(2)).sqrt();
            let z = (e - m.mean) / (se * se + m.stderr * m.stderr).sqrt();
            worst = worst.max(z.abs());
            println!(
                "hour {h} ({dn}, {dh}, sun {alt}° {az}°) point {r}: coefficients {e:.2} ± {se:.2} lx \
                 (sky ± {se_sky:.2}, sun {:.2} ± {:.2}), direct render {:.2} ± {:.2} lx ({:+.2} %, {z:+.2} σ)",
                v.direct_normal_lx * mu,
                v.direct_normal_lx * se_sun,
                m.mean,
                m.stderr,
                100.0 * (e / m.mean - 1.0)
            );
            // The errors must stay small enough for the comparison to have power (the sun's
            // light reflected from a sun patch the receiver does not face is the noisiest
            // part: about 2 % at 2¹⁶ paths, in both estimates).
            assert!(
                se / e < 0.025 && m.stderr / m.mean < 0.025,
                "too noisy: {se} {}",
                m.stderr
            );
        }
    }
    // 9 readings: 4 σ is a 1-in-1700 event for one; the patch discretisation at MF 2 is well
    // within it (tests/annual_coefficients.rs).
    assert!(worst < 4.0, "worst {worst:.2} σ");
}

#[test]
fn direct_sun_behind_the_pane_is_cosine_times_slab_transmittance() {
    // The high sun (55°, azimuth 190°) lights point 0 through the pane (checked below: the
    // ray to the sun's centre crosses the window).
    let (enu, dir) = common::to_sun(55.0, 190.0);
    let p = Vec3::from(POINTS[0]);
    let t = (2.0 - p.z) / dir.z;
    let at = p + dir * t;
    assert!(at.x.abs() < 0.9 && at.y > 1.0 && at.y < 2.0, "{at:?}");
    let mut sw = sun_world(ROOM);
    let s = sun_coefficients(
        &mut sw,
        &[(p, Vec3::Y)],
        &[enu],
        &common::default_site(),
        45.0,
        16,
        4096,
        &mut |_, _| {},
    )
    .unwrap();
    let (_, d) = s.batches(0, 0);
    let k = d.len() as f64;
    let mu = d.iter().sum::<f64>() / k;
    let se = (d.iter().map(|x| (x - mu).powi(2)).sum::<f64>() / (k - 1.0) / k).sqrt();
    // Incidence on the pane (normal +z): cos θ = the sun's z component.
    let cos_pane = dir.z as f64;
    let expected = enu[2] * common::thin_slab_transmittance(cos_pane, 1.5);
    println!("direct sun: {mu:.6} ± {se:.6} lx per lx, expected {expected:.6}");
    // The disk (0.27° radius) averages the cosine and the transmittance over it: a relative
    // change below 10⁻⁵ here.
    assert!(
        (mu - expected).abs() < 4.0 * se + 1e-5 * expected,
        "{mu} ± {se} vs {expected}"
    );
    // With the pane's transmittance left out the test fails.
    assert!((mu - enu[2]).abs() > 20.0 * se.max(1e-6));
}

/// Configuration factor from a point to a rectangle in a parallel plane at height `c`, the
/// point below one corner, the rectangle a × b.
fn corner_factor(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    ((x / sx) * (y / sx).atan() + (y / sy) * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
}

/// Factor from a point (px, pz) on the floor to the opening x ∈ [x0, x1], z ∈ [z0, z1] at
/// height `c`, by superposing corner rectangles (signed).
fn opening_factor(px: f64, pz: f64, x: (f64, f64), z: (f64, f64), c: f64) -> f64 {
    let f = |dx: f64, dz: f64| dx.signum() * dz.signum() * corner_factor(dx.abs(), dz.abs(), c);
    f(x.1 - px, z.1 - pz) - f(x.0 - px, z.1 - pz) - f(x.1 - px, z.0 - pz) + f(x.0 - px, z.0 - pz)
}

#[test]
fn a_year_of_uniform_skies_gives_daylight_autonomy_from_the_configuration_factor() {
    // A black room 4 × 4 m, 3 m high, with a 1.2 × 1.2 m roof opening centred over it.
    let room = r#"
        materials: {},
        objects: [
            (material: "black", shape: Quad(origin: (-2, 0, -2), edge_u: (0, 0, 4), edge_v: (4, 0, 0))),
            (material: "black", shape: Quad(origin: (-2, 3, -2), edge_u: (1.4, 0, 0), edge_v: (0, 0, 4))),
            (material: "black", shape: Quad(origin: (0.6, 3, -2), edge_u: (1.4, 0, 0), edge_v: (0, 0, 4))),
            (material: "black", shape: Quad(origin: (-0.6, 3, -2), edge_u: (1.2, 0, 0), edge_v: (0, 0, 1.4))),
            (material: "black", shape: Quad(origin: (-0.6, 3, 0.6), edge_u: (1.2, 0, 0), edge_v: (0, 0, 1.4))),
            (material: "black", shape: Quad(origin: (-2, 0, -2), edge_u: (4, 0, 0), edge_v: (0, 3, 0))),
            (material: "black", shape: Quad(origin: (-2, 0, -2), edge_u: (0, 3, 0), edge_v: (0, 0, 4))),
            (material: "black", shape: Quad(origin: (2, 0, -2), edge_u: (0, 0, 4), edge_v: (0, 3, 0))),
            (material: "black", shape: Quad(origin: (-2, 0, 2), edge_u: (0, 3, 0), edge_v: (4, 0, 0))),
        ]"#;
    let portal = "portals: [(origin: (-0.6, 3, -0.6), edge_u: (0, 0, 1.2), edge_v: (1.2, 0, 0))]";
    let patches = SkyPatches::new(1).unwrap();
    // A 7 × 7 grid on the floor (z up to 1.5 m off centre).
    let pts: Vec<(f64, f64)> = (0..49)
        .map(|k| (-1.5 + 0.5 * (k % 7) as f64, -1.5 + 0.5 * (k / 7) as f64))
        .collect();
    let receivers: Vec<(Vec3, Vec3)> = pts
        .iter()
        .map(|&(x, z)| (Vec3::new(x as f32, 0.0, z as f32), Vec3::Y))
        .collect();
    let c = sky_coefficients(&unit_sky_world(room, portal), &receivers, &patches, 4096).unwrap();
    // E_h chosen so that the 300 lx contour crosses the grid.
    let e_h = 12_000.0;
    let l = e_h / std::f64::consts::PI;
    let mut lum = vec![l; patches.len()];
    lum[0] = 0.0;
    let year: Vec<HourSky> = (0..8760)
        .map(|h| HourSky {
            month: 1,
            day: 1,
            hour: (h % 24) as u32 + 1,
            sun_altitude_deg: if (6..18).contains(&(h % 24)) {
                30.0
            } else {
                -10.0
            },
            to_sun_enu: [0.0, -0.866, 0.5],
            sky: SkyVector {
                luminance_cd_m2: if (6..18).contains(&(h % 24)) {
                    lum.clone()
                } else {
                    vec![0.0; patches.len()]
                },
                diffuse_horizontal_lx: if (6..18).contains(&(h % 24)) {
                    e_h
                } else {
                    0.0
                },
                direct_normal_lx: 0.0,
            },
        })
        .collect();
    let no_sun = SunCoefficients {
        receivers: receivers.len(),
        ..Default::default()
    };
    let hy = hourly(&c, &no_sun, &year);
    let occupied = Schedule::daily(365, 8, 18);
    let t = Thresholds::default();
    let g = metrics(
        &hy,
        std::slice::from_ref(&(0..receivers.len())),
        &occupied,
        &occupied,
        &t,
        100,
        1,
    );
    let (mut decided, mut lit) = (0, 0);
    for (k, &(x, z)) in pts.iter().enumerate() {
        let f = opening_factor(x, z, (-0.6, 0.6), (-0.6, 0.6), 3.0);
        let e = e_h * f;
        let i = 9 * receivers.len() + k; // 09:00–10:00 of 1 January
        let (m, se) = (hy.mean[i], hy.stderr[i]);
        assert!(
            (m - e).abs() < 4.0 * se + 1e-9,
            "point {k}: {m} ± {se} lx vs E_h F = {e}"
        );
        let da = g[0].points[k].da;
        if (e - t.da_lx).abs() > 4.0 * se {
            decided += 1;
            let want = if e >= t.da_lx { 1.0 } else { 0.0 };
            lit += want as usize;
            assert_eq!(da.value, want, "point {k}: E = {e} lx, DA {da:?}");
            assert_eq!(da.ci95, Some((want, want)), "point {k}");
        } else {
            // Undecided within the error: the interval must say so.
            println!("point {k}: E = {e:.1} lx ≈ 300, DA {da:?}");
        }
    }
    assert!(decided >= 40 && lit > 0 && lit < decided, "{decided} {lit}");
    let sda = g[0].sda.value;
    println!("sDA {sda}, {lit} of {decided} decided points lit");
    assert!(sda * 49.0 >= lit as f64 && sda * 49.0 <= (lit + 49 - decided) as f64);
}

#[test]
fn sun_coefficients_need_a_unit_sun() {
    let sun_of_2_lx = world(&format!(
        "({CAMERA}, {ROOM}, lights: [Sun(sun: (altitude_deg: 45.0, azimuth_deg: 180.0), \
         amount: NormalIlluminance(2.0))])"
    ));
    assert!(matches!(sun_of_2_lx.lights[0], Light::Sun(_)));
    for mut w in [unit_sky_world(ROOM, PORTAL), sun_of_2_lx] {
        let r = sun_coefficients(
            &mut w,
            &[(Vec3::Y, Vec3::Y)],
            &[[0.0, 0.0, 1.0]],
            &common::default_site(),
            45.0,
            16,
            16,
            &mut |_, _| {},
        );
        assert!(r.is_err());
    }
}
