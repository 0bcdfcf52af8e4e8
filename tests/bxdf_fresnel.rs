//! Fresnel equations and refractive-index data against closed forms and catalogue values
//! (reference: closed-forms.md (the project's reference of closed forms) §2.8).

use candela::bxdf::fresnel::{fr_conductor, fr_dielectric, fr_dielectric_sp};
use candela::bxdf::ior;
use candela::bxdf::thin_dielectric::thin_slab_reflectance;

#[test]
fn conductor_normal_incidence_matches_closed_form_and_reference_values() {
    // (metal, n, k, R0) at 550 nm from the refractiveindex.info data (closed-forms §2.8).
    let check = [
        ("Au", 0.4241, 2.4721, 0.7916),
        ("Ag", 0.0596, 3.5974, 0.9831),
        ("Cu", 1.0066, 2.5823, 0.6235),
        ("Al", 1.0152, 6.6273, 0.9154),
    ];
    for (name, n_ref, k_ref, r0_ref) in check {
        let m = ior::named_metal(name).unwrap();
        let (n, k) = (m.n.value(550.0), m.k.value(550.0));
        assert!(
            (n - n_ref).abs() < 5e-5,
            "{name}: n = {n}, reference {n_ref}"
        );
        assert!(
            (k - k_ref).abs() < 5e-5,
            "{name}: k = {k}, reference {k_ref}"
        );
        let closed = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        let r0 = fr_conductor(1.0, n, k);
        assert!(
            (r0 - closed).abs() < 1e-6,
            "{name}: R0 {r0} vs closed form {closed}"
        );
        assert!(
            (r0 - r0_ref).abs() < 5e-5,
            "{name}: R0 {r0} vs reference {r0_ref}"
        );
    }
    // Cr is shipped too; every metal's R0 lies in (0, 1) across 360–830 nm, R → 1 at grazing.
    for name in ior::metal_names() {
        let m = ior::named_metal(name).unwrap();
        for nm in (360..=830).step_by(10) {
            let (n, k) = (m.n.value(nm as f32), m.k.value(nm as f32));
            let r = fr_conductor(1.0, n, k);
            assert!(r > 0.0 && r < 1.0, "{name} {nm}: {r}");
            assert!((fr_conductor(0.0, n, k) - 1.0).abs() < 1e-6);
        }
    }
}

#[test]
fn dielectric_normal_incidence_brewster_and_tir() {
    for eta in [1.33f32, 1.5, 1.7847, 2.4] {
        let r0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
        assert!((fr_dielectric(1.0, eta) - r0).abs() < 1e-6);
        // From inside at normal incidence: the same.
        assert!((fr_dielectric(-1.0, eta) - r0).abs() < 1e-6);
        // Brewster's angle tan θB = η: R_p = 0 (and R_s > 0).
        let tb = eta.atan();
        let (rs, rp) = fr_dielectric_sp(tb.cos(), eta);
        assert!(rp < 1e-10, "η {eta}: R_p at Brewster = {rp}");
        assert!(rs > 0.01);
        // From inside, Brewster's angle is atan(1/η).
        let (_, rp_in) = fr_dielectric_sp(-(1.0 / eta).atan().cos(), eta);
        assert!(rp_in < 1e-10, "inside Brewster: {rp_in}");
        // Total internal reflection past the critical angle sin θc = 1/η.
        let tc = (1.0 / eta).asin();
        for d in [1e-3f32, 0.05, 0.3] {
            let past = (tc + d).min(std::f32::consts::FRAC_PI_2);
            assert_eq!(
                fr_dielectric(-past.cos(), eta),
                1.0,
                "η {eta}, θ = θc + {d}"
            );
            let before = tc - d;
            assert!(fr_dielectric(-before.cos(), eta) < 1.0);
        }
        // Unpolarised R is (R_s + R_p)/2 of the textbook forms at 45°.
        let ci = std::f32::consts::FRAC_PI_4.cos();
        let ct = (1.0 - (0.5 / (eta * eta))).sqrt();
        let rs = ((ci - eta * ct) / (ci + eta * ct)).powi(2);
        let rp = ((eta * ci - ct) / (eta * ci + ct)).powi(2);
        assert!((fr_dielectric(ci, eta) - 0.5 * (rs + rp)).abs() < 1e-6);
    }
}

#[test]
fn thin_slab_sums_reflections_per_polarisation() {
    // T_x = (1 − R_x)/(1 + R_x) per polarisation, then averaged (closed-forms §2.8).
    for deg in [0.0f32, 30.0, 56.3, 75.0, 89.0] {
        let c = deg.to_radians().cos();
        let (rs, rp) = fr_dielectric_sp(c, 1.5);
        let t = 0.5 * ((1.0 - rs) / (1.0 + rs) + (1.0 - rp) / (1.0 + rp));
        let r = thin_slab_reflectance(c, 1.5);
        assert!((r + t - 1.0).abs() < 1e-6, "{deg}: R {r} T {t}");
    }
    // Normal incidence, η = 1.5: R = 2·0.04/1.04.
    assert!((thin_slab_reflectance(1.0, 1.5) - 0.08 / 1.04).abs() < 1e-6);
}

#[test]
fn bk7_matches_catalogue_indices() {
    // SCHOTT N-BK7 catalogue: n_F (486.1327 nm) 1.52238, n_d (587.5618 nm) 1.51680,
    // n_C (656.2725 nm) 1.51432.
    let bk7 = &ior::named_glass("BK7").unwrap().ior;
    for (nm, n_ref) in [
        (486.1327, 1.52238),
        (587.5618, 1.51680),
        (656.2725, 1.51432),
    ] {
        let n = bk7.at_f64(nm);
        assert!((n - n_ref).abs() < 1e-5, "BK7 at {nm} nm: {n} vs {n_ref}");
        assert!((bk7.at(nm as f32) as f64 - n_ref).abs() < 2e-5);
    }
    // Abbe number ν_d = (n_d − 1)/(n_F − n_C) = 64.17 for N-BK7.
    let v = (bk7.at_f64(587.5618) - 1.0) / (bk7.at_f64(486.1327) - bk7.at_f64(656.2725));
    assert!((v - 64.17).abs() < 0.02, "Abbe number {v}");
    // Fused silica (Malitson) n_d = 1.4585, SF11 n_d = 1.78472.
    let fs = &ior::named_glass("fused-silica").unwrap().ior;
    assert!((fs.at_f64(587.5618) - 1.458_46).abs() < 1e-5);
    let sf11 = &ior::named_glass("sf11").unwrap().ior;
    assert!((sf11.at_f64(587.5618) - 1.784_72).abs() < 1e-5);
    // Normal dispersion: n decreases with wavelength over the visible for every glass.
    for name in ior::glass_names() {
        let g = &ior::named_glass(name).unwrap().ior;
        for nm in (380..800).step_by(10) {
            assert!(
                g.at_f64(nm as f64) > g.at_f64(nm as f64 + 10.0),
                "{name} at {nm}"
            );
        }
    }
}
