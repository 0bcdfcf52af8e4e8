//! The light BVH sampler's probabilities: over a few hundred lights of every type (points,
//! spots, downlight-only goniometric luminaires aimed every way, one- and two-sided quads, a
//! sphere, a 72-triangle emissive mesh, a sun and a sky), at several receivers with and
//! without normals:
//! - `sample` reports exactly `pmf` of what it chose, and Σ pmf over every (light, primitive)
//!   is 1;
//! - the empirical frequencies of `sample` over many u match `pmf` (χ², bins merged below an
//!   expected count of 5, failing at p < 1e-4 by the Wilson–Hilferty normal approximation);
//! - every light that sends light to the receiver has pmf > 0 (a zero would bias the
//!   estimate), a point light behind the receiver's normal included (transmission), and a
//!   downlight seen from above has pmf 0 (its table's cone is used).

mod common;
use candela::light::{Light, LightSampler};
use candela::spectrum::SampledWavelengths;
use common::world;
use glam::{Vec2, Vec3};
use std::collections::HashMap;

struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.f()
    }
}

/// A scene text with `n` lights of each point-like type and emitters of every shape.
fn many_lights_scene(seed: u64, n: usize) -> String {
    let mut r = Rng(seed);
    let mut lights = Vec::new();
    let mut objects = Vec::new();
    let pos = |r: &mut Rng| {
        format!(
            "({:.3}, {:.3}, {:.3})",
            r.range(-20.0, 20.0),
            r.range(0.0, 6.0),
            r.range(-20.0, 20.0)
        )
    };
    for _ in 0..n {
        let p = pos(&mut r);
        lights.push(format!(
            "Point(position: {p}, spectrum: Blackbody(3000), amount: Flux({:.1}))",
            r.range(10.0, 5000.0)
        ));
        let (p, t) = (pos(&mut r), pos(&mut r));
        lights.push(format!(
            "Spot(position: {p}, look_at: {t}, inner_deg: {:.1}, outer_deg: {:.1}, spectrum: Blackbody(4000), amount: Intensity({:.1}))",
            r.range(5.0, 20.0),
            r.range(25.0, 60.0),
            r.range(10.0, 3000.0)
        ));
        let p = pos(&mut r);
        lights.push(format!(
            "Goniometric(file: \"data/luminaires/batwing-office.ies\", position: {p}, rotate_deg: ({:.1}, {:.1}, {:.1}), spectrum: Blackbody(4000), lumens: {:.1})",
            r.range(-180.0, 180.0),
            r.range(-180.0, 180.0),
            r.range(-180.0, 180.0),
            r.range(100.0, 6000.0)
        ));
    }
    // Downlights without rotation (nadir −y) in a row along x at height 4.
    for i in 0..10 {
        lights.push(format!(
            "Goniometric(file: \"data/luminaires/batwing-office.ies\", position: ({}, 4, 7.5), spectrum: Blackbody(4000), lumens: 3000)",
            -9 + 2 * i
        ));
    }
    for i in 0..n / 2 {
        let p = pos(&mut r);
        let (a, b) = (r.range(0.1, 1.5), r.range(0.1, 1.5));
        let two = i % 3 == 0;
        let u = if i % 2 == 0 {
            format!("({a:.2}, 0, 0)")
        } else {
            format!("(0, {a:.2}, 0)")
        };
        objects.push(format!(
            "(shape: Quad(origin: {p}, edge_u: {u}, edge_v: (0, {:.2}, {b:.2})), material: \"grey\", emission: (spectrum: Blackbody(5000), amount: Luminance({:.0}), two_sided: {two}))",
            r.range(-0.5, 0.5),
            r.range(100.0, 20000.0)
        ));
    }
    objects.push("(shape: Sphere(center: (3, 2, -4), radius: 0.3), material: \"grey\", emission: (spectrum: Blackbody(2700), amount: Flux(2000)))".into());
    // A luminous ceiling of 72 triangles facing down, one object.
    let (mut positions, mut indices) = (Vec::new(), Vec::new());
    for j in 0..7 {
        for i in 0..7 {
            positions.push(format!("({}, 5, {})", -6 + 2 * i, -6 + 2 * j));
        }
    }
    for j in 0..6u32 {
        for i in 0..6u32 {
            let v = j * 7 + i;
            indices.push(format!("({}, {}, {})", v, v + 1, v + 7));
            indices.push(format!("({}, {}, {})", v + 1, v + 8, v + 7));
        }
    }
    objects.push(format!(
        "(shape: Triangles(positions: [{}], indices: [{}]), material: \"grey\", emission: (spectrum: Blackbody(6500), amount: Luminance(500)))",
        positions.join(", "),
        indices.join(", ")
    ));
    lights.push(
        "Distant(direction: (0.3, -1, 0.2), spectrum: Named(\"D65\"), amount: Illuminance(50000))"
            .into(),
    );
    lights.push("Environment(spectrum: Named(\"D65\"), amount: Luminance(3000))".into());
    format!(
        "(camera: (position: (0, 1, -30), look_at: (0, 1, 0), vfov_deg: 40, resolution: (1, 1)),
          materials: {{ \"grey\": Diffuse(reflectance: Constant(0.5)) }},
          objects: [{}],
          lights: [{}])",
        objects.join(",\n"),
        lights.join(",\n")
    )
}

/// Every (light, primitive) the sampler can return.
fn choices(lights: &[Light]) -> Vec<(usize, u32)> {
    let mut out = Vec::new();
    for (i, l) in lights.iter().enumerate() {
        match l {
            Light::Area(a) => out.extend(a.prims.iter().map(|&p| (i, p))),
            _ => out.push((i, 0)),
        }
    }
    out
}

/// Upper tail probability of χ² with `k` degrees of freedom (Wilson–Hilferty).
fn chi2_p_value(chi2: f64, k: f64) -> f64 {
    let z = ((chi2 / k).cbrt() - (1.0 - 2.0 / (9.0 * k))) / (2.0 / (9.0 * k)).sqrt();
    0.5 * erfc(z / std::f64::consts::SQRT_2)
}

/// Complementary error function (Numerical Recipes' erfcc, relative error < 1.2e-7).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let r = t
        * (-z * z - 1.26551223
            + t * (1.00002368
                + t * (0.37409196
                    + t * (0.09678418
                        + t * (-0.18628806
                            + t * (0.27886807
                                + t * (-1.13520398
                                    + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277)))))))))
            .exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

fn receivers() -> Vec<(Vec3, Option<Vec3>)> {
    vec![
        (Vec3::new(0.0, 0.0, 0.0), Some(Vec3::Y)),
        (Vec3::new(5.0, 1.0, -3.0), None),
        (Vec3::new(-12.0, 3.0, 8.0), Some(Vec3::new(0.6, 0.0, -0.8))),
        (Vec3::new(1.0, 5.5, 1.0), Some(-Vec3::Y)),
        (Vec3::new(30.0, 2.0, 30.0), Some(Vec3::new(-0.6, 0.0, -0.8))),
        (Vec3::new(0.0, 4.5, 7.5), Some(Vec3::Y)),
    ]
}

#[test]
fn bvh_sample_frequencies_match_pmf_and_pmf_sums_to_one() {
    let w = world(&many_lights_scene(1, 100));
    assert!(matches!(w.light_sampler, LightSampler::Bvh(_)));
    let all = choices(&w.lights);
    assert!(all.len() > 400, "{} choices", all.len());
    let samples = 400_000usize;
    for (p, n) in receivers() {
        let pmf: HashMap<(usize, u32), f64> = all
            .iter()
            .map(|&(l, q)| ((l, q), w.light_sampler.pmf(p, n, l, q) as f64))
            .collect();
        let total: f64 = pmf.values().sum();
        assert!((total - 1.0).abs() < 1e-5, "Σ pmf = {total} at {p} {n:?}");
        let mut counts: HashMap<(usize, u32), u64> = HashMap::new();
        let mut r = Rng(42);
        for _ in 0..samples {
            let u = r.f() as f32;
            let (l, q, pr) = w.light_sampler.sample(p, n, u).expect("a light");
            assert_eq!(pr as f64, pmf[&(l, q)], "sample's pmf ≠ pmf() for {l}/{q}");
            *counts.entry((l, q)).or_default() += 1;
        }
        // χ² with bins of expected count < 5 merged.
        let (mut chi2, mut dof) = (0.0, 0usize);
        let (mut small_e, mut small_o) = (0.0, 0.0);
        for (&k, &pk) in &pmf {
            let e = pk * samples as f64;
            let o = counts.get(&k).copied().unwrap_or(0) as f64;
            if pk == 0.0 {
                assert_eq!(o, 0.0, "{k:?} sampled with pmf 0");
                continue;
            }
            if e < 5.0 {
                small_e += e;
                small_o += o;
            } else {
                chi2 += (o - e) * (o - e) / e;
                dof += 1;
            }
        }
        if small_e >= 5.0 {
            chi2 += (small_o - small_e) * (small_o - small_e) / small_e;
            dof += 1;
        }
        let pv = chi2_p_value(chi2, (dof - 1) as f64);
        eprintln!("receiver {p} {n:?}: χ² = {chi2:.1}, {dof} bins, p = {pv:.3}");
        assert!(pv > 1e-4, "χ² = {chi2} over {dof} bins: p = {pv}");
    }
}

#[test]
fn every_light_that_reaches_the_receiver_has_positive_pmf() {
    let w = world(&many_lights_scene(2, 100));
    let wl = SampledWavelengths::sample_visible(0.37);
    let mut r = Rng(9);
    for (p, n) in receivers() {
        let mut checked = 0;
        for &(l, q) in &choices(&w.lights) {
            let light = &w.lights[l];
            // Does this light (primitive) send anything toward p? A few points on it.
            let reaches = (0..16).any(|_| {
                let u = Vec2::new(r.f() as f32, r.f() as f32);
                light
                    .sample_li_prim(&w.geometry, p, q, r.f() as f32, u, &wl)
                    .is_some_and(|ls| !ls.li.is_black() && ls.pdf > 0.0)
            });
            if reaches {
                checked += 1;
                let pmf = w.light_sampler.pmf(p, n, l, q);
                assert!(
                    pmf > 0.0,
                    "light {l} primitive {q} ({:?}) reaches {p} but has pmf 0",
                    light.flags()
                );
            }
        }
        assert!(checked > 200, "only {checked} lights reach {p}");
    }
}

#[test]
fn light_behind_the_normal_counts_and_dark_side_of_downlight_does_not() {
    let text = "(camera: (position: (0, 1, -30), look_at: (0, 1, 0), vfov_deg: 40, resolution: (1, 1)),
        lights: [Point(position: (0, -2, 0), spectrum: Blackbody(3000), amount: Flux(100)),
                 Goniometric(file: \"data/luminaires/batwing-office.ies\", position: (5, 3, 0), spectrum: Blackbody(4000), lumens: 3000),
                 Point(position: (-5, 3, 0), spectrum: Blackbody(3000), amount: Flux(100))])";
    let w = world(text);
    let p = Vec3::new(0.0, 0.0, 0.0);
    // Below the receiver's tangent plane: a transmitting surface still sees it.
    assert!(w.light_sampler.pmf(p, Some(Vec3::Y), 0, 0) > 0.0);
    assert!(w.light_sampler.pmf(p, None, 0, 0) > 0.0);
    // The downlight lights p (below it)…
    assert!(w.light_sampler.pmf(p, Some(Vec3::Y), 1, 0) > 0.0);
    // …but not a point above it, which its table leaves dark.
    let above = Vec3::new(5.0, 3.5, 0.5);
    assert_eq!(w.light_sampler.pmf(above, None, 1, 0), 0.0);
    assert!(w.light_sampler.pmf(above, None, 2, 0) > 0.0);
    let total: f32 = (0..3).map(|l| w.light_sampler.pmf(above, None, l, 0)).sum();
    assert!((total - 1.0).abs() < 1e-6, "{total}");
}
