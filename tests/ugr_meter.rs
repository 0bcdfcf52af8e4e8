//! The `Ugr` meter against closed forms: one luminaire of known intensity and luminous area
//! under a uniform environment (CIE 117 UGR by hand), and the background luminance from the
//! light a diffuse floor reflects toward the eye (a quadrature of the exact floor luminance).

mod common;
use candela::meter::measure_all;
use common::world;
use std::f64::consts::PI;

/// An IES file of an isotropic 1000 cd luminaire whose luminous opening is a flat
/// 0.6 m × 0.6 m square facing down.
fn flat_ies(name: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::write(
        &path,
        "IESNA:LM-63-2002\n[TEST] isotropic 1000 cd, 0.6 m square opening\nTILT=NONE\n\
         1 -1 1 3 1 1 2 0.6 0.6 0\n1 1 0\n0 90 180\n0\n1000 1000 1000\n",
    )
    .unwrap();
    path.display().to_string()
}

#[test]
fn one_luminaire_under_a_uniform_sky_by_hand() {
    let file = flat_ies("ugr-flat.ies");
    let w = world(&format!(
        r#"(
        camera: (position: (0, 1.2, 0), look_at: (0, 1.2, -1), vfov_deg: 10, resolution: (1, 1)),
        render: (spp: 1),
        lights: [
            Goniometric(file: {file:?}, position: (0, 2.0, -3.0), spectrum: Named("E")),
            Environment(spectrum: Named("E"), amount: Luminance(50.0)),
        ],
        meters: [Ugr(name: "desk", position: (0, 1.2, 0), direction: (0, 0, -1))],
        measure: (samples: 16384),
    )"#
    ));
    let m = measure_all(&w);
    let u = w.meters[0].ugr(&w, &m.meters[0]).expect("a Ugr meter");
    // Eye to luminaire: (0, 0.8, −3), d² = 9.64, d = 3.10483. The opening's projected area
    // toward the eye: 0.36 · 0.8/d = 0.0927583 m²; L = 1000/A_p = 10780.66 cd/m²;
    // ω = A_p/d² = 0.00962223 sr; σ = atan(0.8/3) = 14.9314° straight above (τ = 0):
    // P = exp(33.98·10⁻³σ + 21·10⁻⁵σ²) = exp(0.507369 + 0.046818) = 1.740320;
    // E_dir = 1000 · (3/d)/d² = 100.233 lx; E_ind = π · 50 (the sky's hemisphere): L_b = 50;
    // UGR = 8 log10(0.25/50 · L² ω / P²), computed below from these.
    let d = (9.64f64).sqrt();
    let ap = 0.36 * 0.8 / d;
    let (l, omega) = (1000.0 / ap, ap / 9.64);
    let sigma = (0.8f64 / 3.0).atan().to_degrees();
    let p = (33.98e-3 * sigma + 21e-5 * sigma * sigma).exp();
    let expected = 8.0 * (0.25 / 50.0 * l * l * omega / (p * p)).log10();
    assert_eq!(u.luminaires.len(), 1);
    let lv = &u.luminaires[0];
    assert!((lv.luminance_cd_m2 / l - 1.0).abs() < 1e-4, "{lv:?}");
    assert!((lv.solid_angle_sr / omega - 1.0).abs() < 1e-4, "{lv:?}");
    assert!((lv.position_index / p - 1.0).abs() < 1e-4, "{lv:?}");
    assert!(
        (u.ev_direct_lx - 1000.0 * 3.0 / d / 9.64).abs() < 1e-3,
        "{u:?}"
    );
    // The measured indirect illuminance is the sky's π·50 within its Monte Carlo error.
    let se = u.ev_stderr_lx;
    assert!(se > 0.0 && se < 0.01 * 50.0 * PI, "{u:?}");
    assert!((u.ev_indirect_lx - 50.0 * PI).abs() <= 4.0 * se, "{u:?}");
    let (lo, hi) = u.ugr_interval;
    assert!(
        lo <= expected && expected <= hi,
        "UGR {expected} outside [{lo}, {hi}]"
    );
    assert!(
        hi - lo < 0.2,
        "UGR interval [{lo}, {hi}] too wide to test anything"
    );
    assert!(
        (u.ugr - expected).abs() < 0.1,
        "UGR {} vs {expected}",
        u.ugr
    );
    println!(
        "UGR {:.3} (95 %: {lo:.3} to {hi:.3}), expected {expected:.3}",
        u.ugr
    );
}

#[test]
fn background_is_the_light_a_diffuse_floor_reflects_to_the_eye() {
    // A black world with one diffuse floor (ρ = 0.5, 400 m square) under the same 1000 cd
    // luminaire at (0, 3, −4); the eye at height 1.2 looks along −z. Only the floor reflects,
    // once: its luminance is L_f = ρ/π · I·3/s³ (s from the luminaire), and the indirect
    // vertical illuminance is ∫ L_f cosθ_eye cosθ_floor / r² dA over the floor in front of
    // the eye, by quadrature (r = e·tan t around the eye's foot, midpoints).
    let file = flat_ies("ugr-floor.ies");
    let rho = 0.5;
    let w = world(&format!(
        r#"(
        camera: (position: (0, 1.2, 0), look_at: (0, 1.2, -1), vfov_deg: 10, resolution: (1, 1)),
        render: (spp: 1, max_depth: 8),
        materials: {{ "floor": Diffuse(reflectance: Constant({rho})) }},
        objects: [(shape: Quad(origin: (-200, 0, -200), edge_u: (0, 0, 400), edge_v: (400, 0, 0)), material: "floor")],
        lights: [Goniometric(file: {file:?}, position: (0, 3.0, -4.0), spectrum: Named("E"))],
        meters: [Ugr(name: "eye", position: (0, 1.2, 0), direction: (0, 0, -1))],
        measure: (samples: 65536),
    )"#
    ));
    let m = measure_all(&w);
    let u = w.meters[0].ugr(&w, &m.meters[0]).unwrap();
    let e = 1.2;
    let (nt, nphi) = (4000, 800);
    let mut expected = 0.0;
    for i in 0..nt {
        let t = (i as f64 + 0.5) / nt as f64 * PI / 2.0;
        let r = e * t.tan();
        let dr = e / t.cos().powi(2) * (PI / 2.0 / nt as f64);
        for j in 0..nphi {
            let phi = -PI / 2.0 + (j as f64 + 0.5) / nphi as f64 * PI;
            let (x, z) = (r * phi.sin(), -r * phi.cos());
            if x.abs() > 200.0 || z.abs() > 200.0 {
                continue;
            }
            let s2 = r * r + e * e;
            let lum = [0.0 - x, 3.0, -4.0 - z];
            let dl = (lum[0] * lum[0] + lum[1] * lum[1] + lum[2] * lum[2]).sqrt();
            let lf = rho / PI * 1000.0 * 3.0 / dl.powi(3);
            let cos_eye = r * phi.cos() / s2.sqrt();
            let cos_floor = e / s2.sqrt();
            expected += lf * cos_eye * cos_floor / s2 * r * dr * (PI / nphi as f64);
        }
    }
    let se = u.ev_stderr_lx;
    println!(
        "E_ind {:.4} ± {se:.4} lx (floor quadrature {expected:.4}), L_b {:.4} cd/m², UGR {:.2}",
        u.ev_indirect_lx, u.background_cd_m2, u.ugr
    );
    assert!(se > 0.0 && se < 0.02 * expected, "{u:?}");
    assert!(
        (u.ev_indirect_lx - expected).abs() <= 4.0 * se,
        "E_ind {} vs {expected} ± 4·{se}",
        u.ev_indirect_lx
    );
    assert!((u.background_cd_m2 - u.ev_indirect_lx / PI).abs() < 1e-12);
    assert_eq!(u.luminaires.len(), 1);
}

#[test]
fn an_area_light_on_the_line_of_sight_by_hand() {
    // A one-sided 0.5 m × 0.5 m emitter of 2000 cd/m² 3 m ahead, centred on the line of
    // sight and facing the eye, under a uniform 20 cd/m² sky. Its solid angle is
    // Ω = 4 asin(ab/√((a² + 4d²)(b² + 4d²))) = 0.0275867 sr, P = 1, and it hides Ω·cos ≈ Ω of
    // the sky's π·20 lx (cos ≥ 0.9966 over it). UGR = 8 log10(0.25/L_b · 2000² Ω).
    let w = world(
        r#"(
        camera: (position: (0, 1.2, 0), look_at: (0, 1.2, -1), vfov_deg: 10, resolution: (1, 1)),
        render: (spp: 1),
        objects: [(shape: Quad(origin: (-0.25, 0.95, -3.0), edge_u: (0.5, 0, 0), edge_v: (0, 0.5, 0)),
                   material: "black", emission: (spectrum: Named("E"), amount: Luminance(2000.0)))],
        lights: [Environment(spectrum: Named("E"), amount: Luminance(20.0))],
        meters: [Ugr(name: "eye", position: (0, 1.2, 0), direction: (0, 0, -1))],
        measure: (samples: 16384),
    )"#,
    );
    let m = measure_all(&w);
    let u = w.meters[0].ugr(&w, &m.meters[0]).unwrap();
    let omega = 4.0 * (0.25f64 / (0.25f64 + 36.0)).asin();
    assert_eq!(u.luminaires.len(), 1, "{u:?}");
    let lv = &u.luminaires[0];
    assert!((lv.luminance_cd_m2 / 2000.0 - 1.0).abs() < 1e-4, "{lv:?}");
    assert!(
        (lv.solid_angle_sr / omega - 1.0).abs() < 1e-3,
        "{lv:?} vs Ω = {omega}"
    );
    assert!((lv.position_index - 1.0).abs() < 1e-3, "{lv:?}");
    assert!(
        (u.ev_direct_lx / (2000.0 * omega) - 1.0).abs() < 4e-3,
        "{u:?}"
    );
    let se = u.ev_stderr_lx;
    let e_ind = 20.0 * (PI - omega);
    assert!(se > 0.0 && (u.ev_indirect_lx - e_ind).abs() <= 4.0 * se + 4e-3 * 20.0 * omega);
    let expected = 8.0 * (0.25 / (e_ind / PI) * 2000.0f64.powi(2) * omega).log10();
    let (lo, hi) = u.ugr_interval;
    println!(
        "area light: UGR {:.3} (95 %: {lo:.3} to {hi:.3}), expected {expected:.3}",
        u.ugr
    );
    assert!((u.ugr - expected).abs() < 0.05 && hi - lo < 0.2, "{u:?}");
}
