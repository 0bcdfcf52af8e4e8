//! The `Translucent` material (Radiance's `trans`, docs/fenestration.md): reciprocity, energy
//! (ρ + τ ≤ 1 over wavelengths and angles, a white closed sheet in a uniform environment shows
//! that environment's luminance), sampling against `eval`/`pdf` (χ²), a meter under a pane in a
//! uniform sky and the sun through a pure pane against closed forms. Tolerances come from the
//! estimates' standard errors. The comparison with Radiance itself is `translucent_radiance.rs`.

mod bxdf_util;
mod common;
use bxdf_util::*;
use candela::bxdf::{Material, Translucent};
use candela::meter::measure_all;
use candela::spectrum::{DenseSpectrum, SampledWavelengths};
use common::*;
use glam::Vec3;
use std::f64::consts::PI;
use std::sync::Arc;

fn translucent(rd: f32, td: f32, ts: f32, rs: f32, alpha: f32, fresnel: bool) -> Material {
    let c = DenseSpectrum::constant;
    Material::Translucent(Arc::new(
        Translucent::new(c(rd), c(td), c(ts), rs, alpha, fresnel).unwrap(),
    ))
}

/// A coloured sheet: ρd rises and τd falls with wavelength, ρd + τd + τs + ρs = 1 everywhere.
fn coloured(alpha: f32) -> Material {
    let rd = DenseSpectrum::from_fn(|nm| 0.1 + 0.5 * (nm - 360.0) / 470.0);
    let td = DenseSpectrum::from_fn(|nm| 0.6 - 0.5 * (nm - 360.0) / 470.0);
    Material::Translucent(Arc::new(
        Translucent::new(rd, td, DenseSpectrum::constant(0.2), 0.1, alpha, false).unwrap(),
    ))
}

/// (name, material) of the cases of the direction-level tests.
fn materials() -> Vec<(String, Material)> {
    let mut v = vec![
        (
            "pure diffuse".to_string(),
            translucent(0.3, 0.5, 0.0, 0.0, 0.0, false),
        ),
        (
            "pure, all lobes, Fresnel".into(),
            translucent(0.3, 0.4, 0.2, 0.05, 0.0, true),
        ),
        ("pure coloured".into(), coloured(0.0)),
    ];
    for a in [0.05f32, 0.2, 0.5] {
        v.push((
            format!("rough α={a}"),
            translucent(0.2, 0.3, 0.3, 0.1, a, false),
        ));
        v.push((
            format!("rough specular only α={a}"),
            translucent(0.0, 0.0, 0.6, 0.3, a, false),
        ));
    }
    v.push(("rough coloured α=0.3".into(), coloured(0.3)));
    v
}

#[test]
fn eval_is_reciprocal_on_both_sides() {
    // f(wo, wi) = f(wi, wo) (f without the cosine), for reflection and transmission, from
    // either face.
    let wl = wavelengths();
    let mut rng = Rng::new(7);
    for (name, m) in materials() {
        let mut worst = 0.0f32;
        for _ in 0..20_000 {
            let (a, b) = (rng.sphere(), rng.sphere());
            let (f, g) = (m.eval(a, b, &wl), m.eval(b, a, &wl));
            for k in 0..4 {
                let rel = (f[k] - g[k]).abs() / f[k].abs().max(g[k].abs()).max(1e-12);
                worst = worst.max(rel);
            }
        }
        println!("{name:32} largest relative asymmetry {worst:.2e}");
        assert!(worst < 1e-4, "{name}: f(wo, wi) ≠ f(wi, wo) by {worst}");
    }
}

/// Directional albedo ∫ f |cos θi| dωi plus the delta lobes' weights at `wo`, per lane, by
/// sampling (mean, standard error).
fn albedo(m: &Material, wo: Vec3, wl: &SampledWavelengths, n: usize, seed: u64) -> [(f64, f64); 4] {
    let mut rng = Rng::new(seed);
    let (mut s, mut s2) = ([0.0f64; 4], [0.0f64; 4]);
    for _ in 0..n {
        let mut w = *wl;
        let (uc, u) = (rng.f32(), rng.vec2());
        if let Some(bs) = m.sample(wo, uc, u, &mut w) {
            for k in 0..4 {
                let x = (bs.f[k] * bs.wi.z.abs() / bs.pdf) as f64;
                s[k] += x;
                s2[k] += x * x;
            }
        }
    }
    let nf = n as f64;
    std::array::from_fn(|k| {
        let mean = s[k] / nf;
        (mean, ((s2[k] / nf - mean * mean).max(0.0) / nf).sqrt())
    })
}

#[test]
fn energy_is_conserved_over_wavelengths_and_angles() {
    // ρ + τ ≤ 1 at every angle and lane; a pure sheet without Fresnel returns exactly
    // ρd + τd + τs + ρs (here 1 at every wavelength).
    let n = 200_000;
    for (name, m) in materials() {
        let mut worst = 0.0f64;
        for (i, theta) in [0.0f32, 30.0, 60.0, 85.0, 120.0, 175.0]
            .into_iter()
            .enumerate()
        {
            let wo = dir_deg(theta, 40.0);
            let wl = SampledWavelengths::sample_uniform(0.13 + 0.2 * i as f32);
            for (k, (a, se)) in albedo(&m, wo, &wl, n, 11 + i as u64)
                .into_iter()
                .enumerate()
            {
                worst = worst.max(a);
                assert!(
                    a <= 1.0 + 5.0 * se + 1e-6,
                    "{name} θo={theta} lane {k}: albedo {a} ± {se}"
                );
            }
        }
        println!("{name:32} largest albedo {worst:.5}");
    }
    for (name, m) in [
        ("white pure", translucent(0.3, 0.4, 0.2, 0.1, 0.0, false)),
        ("coloured pure", coloured(0.0)),
    ] {
        for theta in [10.0f32, 70.0, 160.0] {
            let wl = SampledWavelengths::sample_uniform(0.61);
            for (k, (a, se)) in albedo(&m, dir_deg(theta, 0.0), &wl, n, 5)
                .into_iter()
                .enumerate()
            {
                assert!(
                    (a - 1.0).abs() <= 5.0 * se + 1e-5 && se < 2e-3,
                    "{name} θo={theta} lane {k}: albedo {a} ± {se}, expected 1"
                );
            }
        }
    }
}

#[test]
fn sampling_matches_eval_and_pdf_chi_square() {
    let mut cases = Vec::new();
    for (name, m) in materials() {
        for (t, p) in [
            (0.0f32, 0.0f32),
            (45.0, 120.0),
            (80.0, 300.0),
            (135.0, 30.0),
        ] {
            cases.push((format!("{name} θo={t}"), m.clone(), dir_deg(t, p)));
        }
    }
    let failures = chi2_cases(&cases, 500);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_closed_white_sheet_in_a_uniform_environment_shows_its_luminance() {
    // Furnace: a closed sphere of a sheet with ρd + τd + τs + ρs = 1 (pure, no Fresnel: no
    // loss at any angle) inside a uniform environment of luminance L. The solution is L in
    // every direction inside, whatever the split between the lobes and over wavelengths.
    for material in [
        "Translucent(reflectance: Constant(0.3), transmittance: Constant(0.4), specular_transmittance: Constant(0.2), specular: 0.1)",
        "Translucent(reflectance: Tabulated([(360, 0.1), (830, 0.6)]), transmittance: Tabulated([(360, 0.6), (830, 0.1)]), specular_transmittance: Constant(0.2), specular: 0.1)",
    ] {
        let w = world(&format!(
            r#"(
            camera: (position: (0.2, 0.1, 0), look_at: (0, 0, 1), vfov_deg: 90, resolution: (12, 12)),
            render: (spp: 256),
            materials: {{ "sheet": {material} }},
            objects: [(shape: Sphere(center: (0, 0, 0), radius: 1), material: "sheet")],
            lights: [Environment(spectrum: Named("E"), amount: Luminance(100.0))],
        )"#
        ));
        let film = render(&w, 2);
        let (m, se) = image_mean(&film);
        println!("furnace {material}: Y = {} ± {se} cd/m² (expected 100)", m[1]);
        assert_every_pixel(&film, 100.0, 5.0);
    }
}

/// The meter at the origin (normal +y) under a 20 m × 20 m sheet of `material` at height 1, with
/// `lights` and nothing else (no ground).
fn meter_under(material: &str, lights: &str, samples: u64) -> candela::meter::Estimate {
    let w = world(&format!(
        r#"(
        camera: (position: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 10, resolution: (1, 1)),
        render: (spp: 1),
        materials: {{ "sheet": {material} }},
        objects: [(shape: Quad(origin: (-10, 1, -10), edge_u: (20, 0, 0), edge_v: (0, 0, 20)), material: "sheet")],
        lights: [{lights}],
        meters: [Illuminance(name: "m", position: (0, 0, 0), normal: (0, 1, 0))],
        measure: (samples: {samples}),
    )"#
    ));
    measure_all(&w).meters[0]
}

/// The share of a horizontal meter's cosine-weighted hemisphere (its configuration factor) that
/// a 2a × 2a square centred 1 m above it fills.
fn square_view_factor(a: f64) -> f64 {
    let s = a / (1.0 + a * a).sqrt();
    4.0 / PI * s * s.atan()
}

#[test]
fn a_meter_under_a_diffusing_pane_in_a_uniform_sky() {
    // Uniform sky of luminance L over a black ground. The sheet's top receives πL, so its
    // underside sends τd·L diffusely and τs·L straight from the sky; its underside receives
    // nothing (no ground, no floor). Over the sheet's share F of the meter's hemisphere the
    // meter sees (τd + τs)·L, beyond it the sky: E = πL (F (τd + τs) + 1 − F).
    let l = 1000.0;
    let sky = format!(
        "Sky(model: Uniform, amount: ZenithLuminance({l}), spectrum: Named(\"E\"), ground_reflectance: 0.0)"
    );
    let f = square_view_factor(10.0);
    for (rd, td, ts, rs) in [(0.3, 0.5, 0.0, 0.0), (0.2, 0.35, 0.25, 0.08)] {
        let material = format!(
            "Translucent(reflectance: Constant({rd}), transmittance: Constant({td}), specular_transmittance: Constant({ts}), specular: {rs})"
        );
        let e = meter_under(&material, &sky, 65536);
        let expected = PI * l * (f * (td + ts) + 1.0 - f);
        println!(
            "ρd={rd} τd={td} τs={ts} ρs={rs}: E = {:.3} ± {:.3} lx, expected {expected:.3} lx",
            e.mean, e.stderr
        );
        assert_estimate_near(
            e.mean,
            e.stderr,
            expected,
            0.005,
            "meter under a diffusing pane",
        );
    }
}

#[test]
fn the_sun_passes_a_pure_pane_with_its_straight_transmittance() {
    // A distant sun (80 klx normal) above a pure sheet with Fresnel and no diffuse
    // transmission: shadow rays cross it with τs·(1 − F(cos θ)), Radiance's weight C·ts for a
    // shadow ray through `trans` (its diffuse reflection goes up and is lost). E = E⊥ cos θ τs
    // (1 − F(cos θ)), F(μ) = e^(−5.85μ) − 0.00202943064 (Radiance 6's normal.c).
    let (ts, rs) = (0.6, 0.04);
    let material = format!(
        "Translucent(reflectance: Constant(0.3), specular_transmittance: Constant({ts}), specular: {rs}, fresnel: true)"
    );
    for dir in [
        Vec3::new(0.0, -1.0, 0.0),
        Vec3::new(0.5, -1.0, 0.2),
        Vec3::new(1.0, -0.4, 0.0),
    ] {
        let e = meter_under(
            &material,
            &format!(
                r#"Distant(direction: ({}, {}, {}), spectrum: Named("D65"), amount: Illuminance(80000.0))"#,
                dir.x, dir.y, dir.z
            ),
            64,
        );
        let cos = (-dir.normalize()).y as f64;
        let fresnel = ((-5.85 * cos).exp() - 0.002_029_430_64).clamp(0.0, 1.0);
        let expected = 8e4 * cos * ts * (1.0 - fresnel);
        println!(
            "sun from {dir}: E = {} ± {} lx, expected {expected}",
            e.mean, e.stderr
        );
        assert!(
            (e.mean - expected).abs() <= 5.0 * e.stderr + 1e-4 * expected,
            "sun from {dir}: E = {} ± {}, expected {expected}",
            e.mean,
            e.stderr
        );
    }
}

#[test]
fn scene_errors_name_the_field() {
    let build = |m: &str| {
        let text = format!(
            r#"(camera: (position: (0, 0, -3), look_at: (0, 0, 0), vfov_deg: 40, resolution: (4, 4)),
            materials: {{ "sheet": {m} }},
            objects: [(shape: Sphere(center: (0, 0, 0), radius: 1), material: "sheet")])"#
        );
        let path = std::path::Path::new("t.ron");
        let s = candela::scene::parse(&text, path).unwrap();
        candela::scene::build(&s, path, &Default::default())
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    let e = build("Translucent(reflectance: Constant(0.5), transmittance: Constant(0.4), specular_transmittance: Constant(0.2))");
    assert!(
        e.contains("materials[\"sheet\"].specular_transmittance") && e.contains("exceeds 1"),
        "{e}"
    );
    let e = build("RadianceTrans(colour: Constant(0.8), transmissivity: 1.2)");
    assert!(e.contains("materials[\"sheet\"].transmissivity"), "{e}");
    let e = build(
        "Translucent(reflectance: Constant(0.5), roughness: 0.2, specular: 0.05, fresnel: true)",
    );
    assert!(e.contains("materials[\"sheet\"].fresnel"), "{e}");
}
