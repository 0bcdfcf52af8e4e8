//! Every material's sampling routine against its pdf: a chi-square goodness-of-fit test over
//! a (θ, φ) grid of the sphere (Mitsuba 3 style) for several roughnesses and incident angles,
//! with one extra cell for samples that are specular or rejected (expected count
//! N (1 − ∫ pdf)). Each sample's f and pdf must also equal `eval` and `pdf`.
//! Significance: p = 0.01 overall, Bonferroni-corrected over all cases.

mod bxdf_util;
use bxdf_util::*;
use candela::bxdf::{Distribution::*, Masking::*, Material};
use glam::Vec3;

#[test]
fn chi2_critical_value_sanity() {
    // χ²₁₀ at p = 0.01 is 23.2093; χ²₁ at p = 0.05 is 3.8415.
    assert!((gamma_q(5.0, 23.2093 / 2.0) - 0.01).abs() < 1e-5);
    assert!((gamma_q(0.5, 3.8415 / 2.0) - 0.05).abs() < 1e-5);
    assert!((gamma_q(150.0, 150.0) - 0.4892).abs() < 1e-3);
}

fn cases() -> Vec<(String, Material, Vec3)> {
    let mut v: Vec<(String, Material, Vec3)> = Vec::new();
    let angles = [(10.0f32, 30.0f32), (50.0, 200.0), (80.0, 100.0)];
    // Conductors: GGX and Beckmann, isotropic and anisotropic, Smith and V-cavity.
    let configs = [
        (Ggx, 0.05, 0.05, Smith),
        (Ggx, 0.2, 0.2, Smith),
        (Ggx, 0.7, 0.7, Smith),
        (Beckmann, 0.1, 0.1, Smith),
        (Beckmann, 0.3, 0.3, Smith),
        (Beckmann, 0.8, 0.8, Smith),
        (Ggx, 0.1, 0.5, Smith),
        (Beckmann, 0.6, 0.15, Smith),
        (Ggx, 0.3, 0.3, VCavity),
        (Beckmann, 0.3, 0.3, VCavity),
    ];
    for (d, ax, ay, m) in configs {
        for (t, p) in angles {
            v.push((
                format!("conductor Au {d:?} α=({ax},{ay}) {m:?} θo={t}"),
                conductor("Au", d, ax, ay, m),
                dir_deg(t, p),
            ));
        }
    }
    // Seen from below (two-sided).
    v.push((
        "conductor Cu GGX 0.3 from below".into(),
        conductor("Cu", Ggx, 0.3, 0.3, Smith),
        -dir_deg(40.0, 10.0),
    ));
    // Rough dielectrics, from outside and from inside (TIR region included).
    for (g, d, a) in [
        ("BK7", Ggx, 0.1),
        ("BK7", Ggx, 0.3),
        ("1.5", Ggx, 0.7),
        ("SF11", Beckmann, 0.3),
        ("1.33", Beckmann, 0.6),
    ] {
        for (t, p) in [
            (20.0f32, 0.0f32),
            (70.0, 60.0),
            (160.0, 45.0),
            (130.0, 250.0),
        ] {
            v.push((
                format!("dielectric {g} {d:?} α={a} θo={t}"),
                dielectric(g, d, a),
                dir_deg(t, p),
            ));
        }
    }
    for (t, p) in angles {
        v.push((
            format!("coated ρ=0.8 η=1.5 θo={t}"),
            coated(0.8, 1.5),
            dir_deg(t, p),
        ));
        v.push((
            format!("coated GGX α=0.2 θo={t}"),
            rough_coated(0.5, 1.5, Ggx, 0.2),
            dir_deg(t, p),
        ));
        v.push((
            format!("coated Beckmann α=0.5 θo={t}"),
            rough_coated(0.9, 1.8, Beckmann, 0.5),
            dir_deg(t, p),
        ));
        v.push((
            format!("Oren–Nayar σ=30° θo={t}"),
            oren_nayar(0.7, 30.0),
            dir_deg(t, p),
        ));
        v.push((
            format!("Phong n=30 θo={t}"),
            phong(0.3, 0.6, 30.0),
            dir_deg(t, p),
        ));
        v.push((
            format!("Phong n=300 θo={t}"),
            phong(0.1, 0.9, 300.0),
            dir_deg(t, p),
        ));
    }
    v.push(("diffuse θo=30".into(), diffuse(0.5), dir_deg(30.0, 0.0)));
    v
}

#[test]
fn sampling_matches_pdf_chi_square() {
    let failures = chi2_cases(&cases(), 1000);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
