//! Light through window panes (`ThinDielectric`): passing straight through a pane is a null
//! event, and shadow rays cross panes with the slab's transmittance, so light sampling, meters
//! and both caustics modes see the sun, lamps and the sky through glass. Checked against
//! closed forms and quadratures with the thin-slab transmittance written out independently
//! (`common::thin_slab_transmittance`), with tolerances from the estimated standard errors.

mod common;
use candela::meter::{measure_all, Estimate};
use candela::world::Caustics;
use common::*;
use glam::Vec3;
use std::f64::consts::PI;

const RHO: f64 = 0.5;
const ETA: f64 = 1.5;

#[test]
fn sunlight_through_a_window_pane_in_both_caustics_modes() {
    // The sun (a distant light, 100 klx normal to the beam) shines through a thin glass pane
    // onto a Lambertian floor. Under the pane the floor receives E⊥·cos θ·T(θ), with the thin
    // slab's transmittance T (both faces and their inter-reflections, per polarisation);
    // elsewhere E⊥·cos θ. Light sampling finds both through the pane's null event, whether or
    // not light tracing runs beside it (it then carries only the pane's reflection, which
    // goes up and away). Each pixel is the box-filter mean over its footprint, so the pane's
    // shadow edge is checked too.
    let sun = Vec3::new(0.2, -1.0, 0.1);
    let text = format!(
        r#"(
        camera: (position: (0, 0.6, -1.2), look_at: (0, 0, 0.1), vfov_deg: 36, resolution: (16, 16)),
        render: (spp: 64, max_depth: 2, light_paths_per_sample: 1),
        materials: {{ "floor": Diffuse(reflectance: Constant({RHO})), "pane": ThinDielectric(ior: Constant({ETA})) }},
        objects: [
            (shape: Quad(origin: (-50, 0, -50), edge_u: (0, 0, 100), edge_v: (100, 0, 0)), material: "floor"),
            (shape: Quad(origin: (-0.5, 1, -0.5), edge_u: (1, 0, 0), edge_v: (0, 0, 1)), material: "pane"),
        ],
        lights: [Distant(direction: ({}, {}, {}), spectrum: Named("D65"), amount: Illuminance(100000.0))],
    )"#,
        sun.x, sun.y, sun.z
    );
    let to_sun = -sun.normalize();
    let cos = to_sun.y as f64;
    let t = thin_slab_transmittance(cos, ETA);
    for mode in [Caustics::LightTracing, Caustics::PathTracing] {
        let w = world_with(&text, mode);
        assert!(w.see_through.contains(&true));
        let film = render(&w, 2);
        let e_floor = |p: Vec3| {
            let q = p + to_sun * ((1.0 - p.y) / to_sun.y);
            let under = q.x.abs() <= 0.5 && q.z.abs() <= 0.5;
            1e5 * cos * if under { t } else { 1.0 }
        };
        check_pixels(&film, &format!("{mode:?}"), luminance, |x, y| {
            RHO / PI * floor_footprint_mean(&w, x, y, e_floor)
        });
        // And some pixels do see the floor under the pane.
        let under = (0..16 * 16)
            .filter(|&i| floor_footprint_mean(&w, i % 16, i / 16, e_floor) < 1e5 * cos * 0.95)
            .count();
        assert!(under > 40, "{under} pixels under the pane");
    }
}

/// The illuminance meter at the origin (normal +y) of a scene with a 20 m × 20 m pane at
/// height 1 and the given lights and objects, with no floor (nothing below reflects).
fn meter_under_a_pane(lights: &str, objects: &str, samples: u64) -> Estimate {
    let w = world(&format!(
        r#"(
        camera: (position: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 10, resolution: (1, 1)),
        render: (spp: 1, max_depth: 6),
        materials: {{ "pane": ThinDielectric(ior: Constant({ETA})) }},
        objects: [
            (shape: Quad(origin: (-10, 1, -10), edge_u: (20, 0, 0), edge_v: (0, 0, 20)), material: "pane"),
            {objects}
        ],
        lights: [{lights}],
        meters: [Illuminance(name: "m", position: (0, 0, 0), normal: (0, 1, 0))],
        measure: (samples: {samples}),
    )"#
    ));
    assert!(w.see_through.contains(&true));
    measure_all(&w).meters[0]
}

fn assert_estimate(e: &Estimate, expected: f64, label: &str) {
    // A delta light's estimate has no variance (the meter's cosine-sampled paths find nothing
    // to reflect), so allow the f32 arithmetic's rounding besides 5 standard errors.
    assert!(
        (e.mean - expected).abs() <= 5.0 * e.stderr + 1e-4 * expected
            && e.stderr <= 0.01 * expected,
        "{label}: E = {} ± {}, expected {expected}",
        e.mean,
        e.stderr
    );
}

#[test]
fn a_meter_reads_the_sun_through_a_pane() {
    // E = E⊥ cos θ T(θ), at several sun elevations (T falls steeply toward grazing).
    for dir in [
        Vec3::new(0.0, -1.0, 0.0),
        Vec3::new(0.3, -1.0, 0.2),
        Vec3::new(1.0, -0.6, 0.0),
        Vec3::new(-1.0, -0.35, 0.4),
    ] {
        let e = meter_under_a_pane(
            &format!(
                r#"Distant(direction: ({}, {}, {}), spectrum: Named("D65"), amount: Illuminance(80000.0))"#,
                dir.x, dir.y, dir.z
            ),
            "",
            64,
        );
        let cos = (-dir.normalize()).y as f64;
        assert_estimate(
            &e,
            8e4 * cos * thin_slab_transmittance(cos, ETA),
            &format!("sun from {dir}"),
        );
    }
}

#[test]
fn a_meter_reads_a_point_light_through_a_pane() {
    // E = I cos θ T(θ) / d² for a 300 cd lamp 2 m up and 1.2 m across.
    let (x, h) = (1.2f64, 2.0f64);
    let e = meter_under_a_pane(
        &format!(
            r#"Point(position: ({x}, {h}, 0), spectrum: Named("A"), amount: Intensity(300.0))"#
        ),
        "",
        64,
    );
    let d2 = x * x + h * h;
    let cos = h / d2.sqrt();
    assert_estimate(
        &e,
        300.0 * cos * thin_slab_transmittance(cos, ETA) / d2,
        "point light",
    );
}

#[test]
fn a_meter_reads_an_area_light_through_a_pane() {
    // A 4 m × 4 m Lambertian emitter (L = 1000 cd/m², facing down) at height 1.5 above a
    // meter, with the pane between them: E = ∫ L T(θ) cos θ cos θ′ / r² dA. Light sampling
    // and the meter's cosine-sampled paths both cross the pane and are combined by MIS; a
    // mismatch between the shadow rays' transmittance and the pane's sampled transmission
    // would bias the sum. The midpoint quadrature (800²) is exact to well below the noise.
    let (h, half, l) = (1.5f64, 2.0f64, 1000.0f64);
    let e = meter_under_a_pane(
        "",
        &format!(
            r#"(shape: Quad(origin: (-{half}, {h}, -{half}), edge_u: ({s}, 0, 0), edge_v: (0, 0, {s})), material: "black",
                emission: (spectrum: Named("D65"), amount: Luminance({l})))"#,
            s = 2.0 * half
        ),
        65536,
    );
    let n = 800;
    let cell = 2.0 * half / n as f64;
    let mut sum = 0.0;
    for j in 0..n {
        for i in 0..n {
            let (px, pz) = (
                -half + (i as f64 + 0.5) * cell,
                -half + (j as f64 + 0.5) * cell,
            );
            let r2 = px * px + pz * pz + h * h;
            let cos = h / r2.sqrt();
            sum += l * thin_slab_transmittance(cos, ETA) * cos * cos / r2 * cell * cell;
        }
    }
    // Without the pane the same quad gives about 1.5·10³ lx; the pane takes 8–20 % of it.
    assert_estimate(&e, sum, "area light");
}

#[test]
fn a_pane_in_a_uniform_sky_is_invisible() {
    // A uniform environment of luminance L: looking up through the pane a meter sees T·L
    // from above plus R·L mirrored from the sky below, and T + R = 1, so E = πL exactly,
    // whichever way each path crosses the pane. Light sampling of the environment (through
    // the pane, with its transmittance) and the cosine-sampled paths (through it or mirrored
    // by it) are combined by MIS. A camera looking at a dispersive pane (SF11: R and T differ per wavelength) sees
    // L in every pixel.
    let l = 500.0;
    let e = meter_under_a_pane(
        &format!(r#"Environment(spectrum: Named("D65"), amount: Luminance({l}))"#),
        "",
        65536,
    );
    assert_estimate_near(
        e.mean,
        e.stderr,
        PI * l,
        0.005,
        "meter under a pane in the sky",
    );
    let w = world(&format!(
        r#"(
        camera: (position: (0.3, -1, 0.2), look_at: (0, 1, 0), vfov_deg: 60, resolution: (8, 8)),
        render: (spp: 256, max_depth: 6),
        materials: {{ "pane": ThinDielectric(ior: Glass("SF11")) }},
        objects: [(shape: Quad(origin: (-10, 1, -10), edge_u: (20, 0, 0), edge_v: (0, 0, 20)), material: "pane")],
        lights: [Environment(spectrum: Named("D65"), amount: Luminance({l}))],
    )"#
    ));
    assert_every_pixel(&render(&w, 2), l, 5.0);
}

#[test]
fn caustics_and_direct_light_seen_through_a_pane() {
    // A point light (100 cd, 0.4 m up) between a Lambertian floor and a horizontal pane at
    // 0.7 m, a smooth metal ceiling (facing down) at 1 m, and the camera at 0.9 m looking down
    // through the pane. With max_depth 2 the floor receives
    // - the direct light (below the pane: untouched);
    // - the pane's mirror image of the lamp (height 2·0.7 − 0.4 = 1.0), of intensity scaled by
    //   the slab's reflectance R′ = 1 − T: a light-traced caustic;
    // - the metal's mirror image (height 2·1 − 0.4 = 1.6), scaled by the metal's reflectance
    //   and by T² (up and down through the pane at the same angle): a light-traced caustic
    //   whose light path crosses the pane twice;
    // and the camera sees it through the pane, scaled by T at the camera ray's angle: the
    // light-traced connections and the camera paths both look through the pane.
    // Many light paths per sample: the pane's own illuminance (checked last) is light tracing's
    // alone.
    let (i_cd, h_light, h_pane, h_metal, n, k) = (100.0, 0.4, 0.7, 1.0, 0.2, 3.0);
    let text = format!(
        r#"(
        camera: (position: (0.1, 0.9, 0.0), look_at: (0.1, 0, 0), up: (0, 0, 1), vfov_deg: 60, resolution: (16, 16)),
        render: (spp: 256, max_depth: 2, light_paths_per_sample: 64, illuminance: true),
        materials: {{
            "floor": Diffuse(reflectance: Constant({RHO})),
            "pane": ThinDielectric(ior: Constant({ETA})),
            "metal": Conductor(n: Constant({n}), k: Constant({k})),
        }},
        objects: [
            (shape: Quad(origin: (-50, 0, -50), edge_u: (0, 0, 100), edge_v: (100, 0, 0)), material: "floor"),
            (shape: Quad(origin: (-50, {h_pane}, -50), edge_u: (0, 0, 100), edge_v: (100, 0, 0)), material: "pane"),
            (shape: Quad(origin: (-50, {h_metal}, -50), edge_u: (100, 0, 0), edge_v: (0, 0, 100)), material: "metal"),
        ],
        lights: [Point(position: (0, {h_light}, 0), spectrum: Named("D65"), amount: Intensity({i_cd}))],
    )"#
    );
    let w = world_with(&text, Caustics::LightTracing);
    let film = render(&w, 2);
    // Illuminance at floor point p from a source of intensity i at height h above the origin,
    // and the cosine of its incidence.
    let from = |p: Vec3, h: f64, i: f64| {
        let d = Vec3::new(0.0, h as f32, 0.0) - p;
        let d2 = d.length_squared() as f64;
        let cos = d.y as f64 / d2.sqrt();
        (i * cos / d2, cos)
    };
    let e_floor = |p: Vec3| {
        let (direct, _) = from(p, h_light, i_cd);
        let (e1, c1) = from(p, 2.0 * h_pane - h_light, i_cd);
        let (e2, c2) = from(p, 2.0 * h_metal - h_light, i_cd);
        direct
            + e1 * (1.0 - thin_slab_transmittance(c1, ETA))
            + e2 * conductor_reflectance(c2, n, k) * thin_slab_transmittance(c2, ETA).powi(2)
    };
    check_pixels(&film, "through the pane", luminance, |x, y| {
        pixel_footprint_mean(&w, x, y, |o, d| {
            let p = o + d * (-o.y / d.y);
            let cos_cam = (d.y / d.length()).abs() as f64;
            thin_slab_transmittance(cos_cam, ETA) * RHO / PI * e_floor(p)
        })
    });
    // The illuminance channel is the illuminance on the first surface the camera ray meets:
    // the pane's top. Only the metal's image of the lamp lights it from above (through the
    // pane once); the lamp itself and its image in the pane are below. None of the light on
    // the floor behind the pane may leak into it through the light-traced connections.
    check_pixels_e(
        &film,
        "illuminance on the pane",
        |p| (p.mean_e().unwrap(), p.e_standard_error()),
        |x, y| {
            pixel_footprint_mean(&w, x, y, |o, d| {
                let p = o + d * ((h_pane as f32 - o.y) / d.y);
                let (e, c) = from(p, 2.0 * h_metal - h_light, i_cd);
                e * conductor_reflectance(c, n, k) * thin_slab_transmittance(c, ETA)
            })
        },
    );
}

#[test]
fn a_meter_reads_the_sun_through_both_walls_of_a_glass_bubble() {
    // A thin-walled glass sphere (ThinDielectric, radius 0.5 m, centre 1 m up) between the sun
    // (straight down, 80 klx) and a meter offset x from the axis: the ray to the sun enters and
    // leaves the sphere at the same incidence angle, sin θ = x / r, so E = E⊥·T(θ)².
    for x in [0.0f64, 0.2, 0.4] {
        let w = world(&format!(
            r#"(
            camera: (position: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 10, resolution: (1, 1)),
            render: (spp: 1, max_depth: 6),
            materials: {{ "glass": ThinDielectric(ior: Constant({ETA})) }},
            objects: [(shape: Sphere(center: (0, 1, 0), radius: 0.5), material: "glass")],
            lights: [Distant(direction: (0, -1, 0), spectrum: Named("D65"), amount: Illuminance(80000.0))],
            meters: [Illuminance(name: "m", position: ({x}, 0, 0), normal: (0, 1, 0))],
            measure: (samples: 64),
        )"#
        ));
        let e = measure_all(&w).meters[0];
        let cos = (1.0 - (x / 0.5).powi(2)).sqrt();
        assert_estimate(
            &e,
            8e4 * thin_slab_transmittance(cos, ETA).powi(2),
            &format!("bubble, x = {x}"),
        );
    }
}

#[test]
fn a_seam_between_pane_pieces_is_one_crossing() {
    // A 1000 cd lamp 2 m above meters on the floor, and a pane at 1 m made of two pieces:
    // two triangles (seam along the diagonal x = z), or two quads meeting at x = 0. Meters
    // whose shadow ray runs exactly through the seam hit both pieces at one point; that is one
    // crossing, E = I cos θ T(θ) / d², not T².
    for (pane, meters) in [
        (
            r#"(shape: Triangles(positions: [(-2, 1, -2), (2, 1, -2), (2, 1, 2), (-2, 1, 2)], indices: [(0, 1, 2), (0, 2, 3)]), material: "pane")"#,
            [[0.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.1, 0.0, 0.0]],
        ),
        (
            r#"(shape: Quad(origin: (-2, 1, -2), edge_u: (2, 0, 0), edge_v: (0, 0, 4)), material: "pane"),
               (shape: Quad(origin: (0, 1, -2), edge_u: (2, 0, 0), edge_v: (0, 0, 4)), material: "pane")"#,
            [[0.0, 0.0, 0.0], [0.0, 0.0, 0.7], [0.01, 0.0, 0.0]],
        ),
    ] {
        let list: Vec<String> = meters
            .iter()
            .enumerate()
            .map(|(i, m)| {
                format!(
                    r#"Illuminance(name: "m{i}", position: ({}, {}, {}), normal: (0, 1, 0))"#,
                    m[0], m[1], m[2]
                )
            })
            .collect();
        let w = world(&format!(
            r#"(
            camera: (position: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 10, resolution: (1, 1)),
            render: (spp: 1, max_depth: 1),
            materials: {{ "pane": ThinDielectric(ior: Constant({ETA})) }},
            objects: [{pane}],
            lights: [Point(position: (0, 2, 0), spectrum: Named("D65"), amount: Intensity(1000.0))],
            meters: [{}],
            measure: (samples: 16),
        )"#,
            list.join(", ")
        ));
        let results = measure_all(&w).meters;
        for (m, e) in meters.iter().zip(&results) {
            let d = Vec3::new(-m[0] as f32, 2.0, -m[2] as f32);
            let d2 = d.length_squared() as f64;
            let cos = 2.0 / d2.sqrt();
            assert_estimate(
                e,
                1000.0 * cos * thin_slab_transmittance(cos, ETA) / d2,
                &format!("meter at {m:?}"),
            );
        }
    }
}
