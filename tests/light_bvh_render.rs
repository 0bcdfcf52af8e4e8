//! Many lights, closed-form illuminance: 80 isotropic points (some below the meters, which
//! face up and receive nothing from them) and 40 downward Lambertian rectangles above them all,
//! parallel to the meters' plane, with nothing else in the scene (no light is shaded). A meter at p facing +y reads
//! E = Σ I cos θ / d² + Σ π L F, F the view factor of each rectangle from p (the corner
//! formula, summed with signs over the four corners). Meters with the BVH light sampler and
//! with the power-proportional one must both agree with E within 5 standard errors (their
//! batch-means error), and with each other.

mod common;
use candela::meter::measure_all;
use common::world;
use std::f64::consts::PI;

struct Rng(u64);
impl Rng {
    fn range(&mut self, a: f64, b: f64) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let f = (self.0 >> 11) as f64 / (1u64 << 53) as f64;
        // Round to 3 decimals, as the scene text does.
        ((a + (b - a) * f) * 1000.0).round() / 1000.0
    }
}

/// View factor from a point to a parallel rectangle of sides x, z (m) with one corner above
/// it at height h (m).
fn corner(x: f64, z: f64, h: f64) -> f64 {
    let (a, b) = (x / h, z / h);
    let (sa, sb) = ((1.0 + a * a).sqrt(), (1.0 + b * b).sqrt());
    (a / sa * (b / sa).atan() + b / sb * (a / sb).atan()) / (2.0 * PI)
}

/// Signed corner term for a corner at offsets (x, z) from the point.
fn signed(x: f64, z: f64, h: f64) -> f64 {
    x.signum() * z.signum() * corner(x.abs(), z.abs(), h)
}

struct Scene {
    text: String,
    meters: Vec<[f64; 2]>,
    expected: Vec<f64>,
}

fn scene(sampler: &str) -> Scene {
    let mut r = Rng(5);
    let mut lights = Vec::new();
    let mut objects = Vec::new();
    let meters = vec![[0.0, 0.0], [3.3, -2.1], [-7.0, 6.0], [9.5, 9.5]];
    let mut expected = vec![0.0; meters.len()];
    for i in 0..80 {
        let (x, z) = (r.range(-12.0, 12.0), r.range(-12.0, 12.0));
        let y = if i % 8 == 0 { -1.0 } else { r.range(1.5, 3.5) };
        let cd = r.range(20.0, 400.0);
        lights.push(format!(
            "Point(position: ({x}, {y}, {z}), spectrum: Named(\"D65\"), amount: Intensity({cd}))"
        ));
        for (k, m) in meters.iter().enumerate() {
            let d = [x - m[0], y, z - m[1]];
            let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let cos = y / d2.sqrt();
            if cos > 0.0 {
                expected[k] += cd * cos / d2;
            }
        }
    }
    // In one plane above every point light, in separate 3 m cells: no emitter shades another.
    for i in 0..40 {
        let (x0, z0) = (
            -12.0 + 3.0 * (i % 8) as f64 + r.range(0.0, 1.4),
            -7.5 + 3.0 * (i / 8) as f64 + r.range(0.0, 1.4),
        );
        let (a, b) = (r.range(0.3, 1.5), r.range(0.3, 1.5));
        let h = 4.0;
        let l = r.range(200.0, 3000.0);
        objects.push(format!(
            "(shape: Quad(origin: ({x0}, {h}, {z0}), edge_u: ({a}, 0, 0), edge_v: (0, 0, {b})), material: \"black\", emission: (spectrum: Named(\"D65\"), amount: Luminance({l})))"
        ));
        for (k, m) in meters.iter().enumerate() {
            let (x0, x1, z0, z1) = (x0 - m[0], x0 + a - m[0], z0 - m[1], z0 + b - m[1]);
            let f = signed(x1, z1, h) - signed(x0, z1, h) - signed(x1, z0, h) + signed(x0, z0, h);
            expected[k] += PI * l * f;
        }
    }
    let meter_text: Vec<String> = meters
        .iter()
        .enumerate()
        .map(|(i, m)| {
            format!(
                "Illuminance(name: \"m{i}\", position: ({}, 0, {}), normal: (0, 1, 0))",
                m[0], m[1]
            )
        })
        .collect();
    let text = format!(
        "(camera: (position: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 10, resolution: (1, 1)),
          render: (spp: 1, max_depth: 1, light_sampler: {sampler}),
          objects: [{}],
          lights: [{}],
          meters: [{}],
          measure: (samples: 65536))",
        objects.join(",\n"),
        lights.join(",\n"),
        meter_text.join(", ")
    );
    Scene {
        text,
        meters,
        expected,
    }
}

#[test]
fn many_lights_meters_match_closed_form_with_both_samplers() {
    let bvh = scene("Bvh");
    let power = scene("Power");
    let mb = measure_all(&world(&bvh.text)).meters;
    let mp = measure_all(&world(&power.text)).meters;
    for k in 0..bvh.meters.len() {
        let e = bvh.expected[k];
        let (b, p) = (&mb[k], &mp[k]);
        eprintln!(
            "meter {k}: expected {e:.4} lx; BVH {:.4} ± {:.4}; power {:.4} ± {:.4} (σ ratio {:.2})",
            b.mean,
            b.stderr,
            p.mean,
            p.stderr,
            p.stderr / b.stderr
        );
        for (name, m) in [("BVH", b), ("power", p)] {
            assert!(
                (m.mean - e).abs() <= 5.0 * m.stderr && m.stderr < 0.02 * e,
                "{name} meter {k}: {} ± {}, expected {e}",
                m.mean,
                m.stderr
            );
        }
        let se = (b.stderr * b.stderr + p.stderr * p.stderr).sqrt();
        assert!((b.mean - p.mean).abs() <= 5.0 * se);
    }
}

#[test]
fn render_state_hash_covers_the_light_sampler() {
    // The same scene text hashed with worlds that differ only in their sampler: a state
    // written with one must not resume with the other.
    let (bvh, power) = (scene("Bvh"), scene("Power"));
    let (wb, wp) = (world(&bvh.text), world(&power.text));
    let text = bvh.text.as_bytes();
    assert_eq!(
        candela::state::scene_hash(text, &wb),
        candela::state::scene_hash(text, &world(&bvh.text))
    );
    assert_ne!(
        candela::state::scene_hash(text, &wb),
        candela::state::scene_hash(text, &wp)
    );
}
