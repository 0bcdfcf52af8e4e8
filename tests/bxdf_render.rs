//! The BSDF library inside the renderer: white furnaces (a lossless object in a uniform
//! environment is invisible), and the prism scene's dispersion.

mod bxdf_util;
mod common;
use bxdf_util::gauss_legendre_01;
use candela::bxdf::{Frame, Material};
use candela::scene::{load_world, Overrides};
use candela::spectrum::SampledWavelengths;
use common::{
    assert_every_pixel, check_pixels, fresnel_unpolarised, image_mean, luminance,
    pixel_footprint_mean, render, world,
};
use glam::{Vec2, Vec3};
use std::path::Path;

fn furnace_scene(material: &str) -> String {
    format!(
        r#"(
        camera: (position: (0.3, 0.2, -3.0), look_at: (0, 0, 0), vfov_deg: 30, resolution: (10, 10)),
        render: (spp: 256, max_depth: 64),
        materials: {{ "m": {material} }},
        objects: [(shape: Sphere(center: (0, 0, 0), radius: 1), material: "m")],
        lights: [Environment(spectrum: Named("E"), amount: Luminance(1.0))],
    )"#
    )
}

#[test]
fn white_furnace_lossless_objects_are_invisible() {
    // A closed object made of a lossless material, inside a uniform environment of luminance
    // 1 cd/m², shows exactly 1 cd/m² everywhere: smooth glass (constant index, and dispersive
    // BK7, whose paths keep one wavelength), a thin slab, and a white base under a clear coat.
    for m in [
        "Dielectric(ior: Constant(1.5))",
        "Dielectric(ior: Glass(\"BK7\"))",
        "Dielectric(ior: Glass(\"SF11\"))",
        "ThinDielectric(ior: Constant(1.5))",
        "Coated(base: Constant(1.0), ior: 1.5)",
        "Coated(base: Constant(1.0), ior: 1.5, roughness: 0.3)",
    ] {
        let film = render(&world(&furnace_scene(m)), 2);
        let (mean, se) = image_mean(&film);
        println!("{m:45} mean Y = {:.5} ± {:.5}", mean[1], se);
        assert_every_pixel(&film, 1.0, 5.0);
    }
}

/// The luminance-weighted directional albedo of an isotropic opaque material at incidence
/// cosine `mu_o`: A = ∫ ȳ(λ) ∫ f(ωo, ωi, λ) cos θi dωi dλ / ∫ ȳ(λ) dλ, by quadrature of the
/// material's own `eval` (Gauss–Legendre in cos θi with `n_mu` nodes on each of 7 pieces × Gauss–Legendre in φ
/// with `n_phi` nodes on each of 5 pieces of [0, π], doubled by the mirror symmetry φ → −φ; wavelengths every
/// `dl` nm over 360–830 nm by the trapezoid rule, ȳ from the colour library's table as the
/// film uses it).
fn luminance_albedo(m: &Material, mu_o: f64, n_mu: usize, n_phi: usize, dl: usize) -> f64 {
    use candela::colour::tables::{cmfs, Observer};
    let ybar = &cmfs(Observer::Cie1931_2).y;
    let wo = Vec3::new((1.0 - mu_o * mu_o).max(0.0).sqrt() as f32, 0.0, mu_o as f32);
    // Composite rule in cos θi, graded toward grazing: near grazing incidence the lobe
    // concentrates at grazing ωi.
    // An n-point Gauss–Legendre rule on each interval between consecutive edges.
    let composite = |edges: &[f64], n: usize| -> Vec<(f64, f64)> {
        let gl = gauss_legendre_01(n);
        edges
            .windows(2)
            .flat_map(|e| {
                gl.iter()
                    .map(|&(x, w)| (e[0] + (e[1] - e[0]) * x, (e[1] - e[0]) * w))
            })
            .collect()
    };
    let gl = composite(&[0.0, 0.005, 0.02, 0.06, 0.15, 0.35, 0.65, 1.0], n_mu);
    // In φ (the reflection lobe lies around φ = π, narrowing toward grazing), likewise.
    let pi = std::f64::consts::PI;
    let gphi = composite(
        &[0.0, 0.5 * pi, 0.75 * pi, 0.875 * pi, 0.95 * pi, pi],
        n_phi,
    );
    let dirs: Vec<(Vec3, f64)> = gl
        .iter()
        .flat_map(|&(mu, w)| {
            let s = (1.0 - mu * mu).max(0.0).sqrt();
            gphi.iter().map(move |&(phi, wp)| {
                let wi = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, mu as f32);
                (wi, w * mu * 2.0 * wp)
            })
        })
        .collect();
    let lambdas: Vec<(usize, f64)> = (0..=470)
        .step_by(dl)
        .map(|i| (i, if i == 0 || i == 470 { 0.5 } else { 1.0 }))
        .collect();
    assert_eq!(470 % dl, 0);
    let (mut num, mut den) = (0.0, 0.0);
    for chunk in lambdas.chunks(4) {
        let mut wl = SampledWavelengths::sample_uniform(0.0);
        for (k, &(i, _)) in chunk.iter().enumerate() {
            wl.lambda[k] = 360.0 + i as f32;
        }
        let mut a = [0.0f64; 4];
        for &(wi, w) in &dirs {
            let f = m.eval(wo, wi, &wl);
            for (k, ak) in a.iter_mut().enumerate().take(chunk.len()) {
                *ak += f[k] as f64 * w;
            }
        }
        for (k, &(i, tw)) in chunk.iter().enumerate() {
            num += tw * ybar[i] * a[k];
            den += tw * ybar[i];
        }
    }
    num / den
}

#[test]
fn white_furnace_rough_conductor_shows_its_directional_albedo() {
    // A convex opaque object in a uniform environment of luminance 1 cd/m² sees only the
    // environment, so a camera ray meeting it at incidence cosine μ shows exactly the
    // luminance-weighted directional albedo A(μ) = ∫ f cos θi dωi (weighted by ȳ over
    // wavelength) of its BxDF, and 1 where it misses. A(μ) comes from quadrature of the
    // material's own `eval` on a 1° grid in θo (cubic interpolation between nodes), each
    // pixel's expectation from a 16×16 quadrature over its footprint. This checks the
    // integrator against the BxDF: an integrator that lost energy (or gained it) at any
    // bounce would show here; the BxDF's own energy is checked in tests/bxdf_energy.rs.
    let m = "Conductor(metal: \"Ag\", roughness: 0.4)";
    let w = world(&furnace_scene(m));
    let mat = &w.materials[w.objects[0].material as usize];
    assert!(matches!(mat, Material::Conductor(_)));
    let (n_mu, n_phi, dl) = (12, 12, 5);
    // A(θo) at θo = 0°, 1°, …, 90°, plus one node past each end for the cubic.
    let table: Vec<f64> = (0..=90)
        .map(|d| luminance_albedo(mat, (d as f64).to_radians().cos(), n_mu, n_phi, dl))
        .collect();
    let interp = |theta_deg: f64| -> f64 {
        let t = theta_deg.clamp(0.0, 90.0);
        let i = (t.floor() as usize).min(89);
        let f = t - i as f64;
        let at = |k: isize| -> f64 {
            // A(θ) is even about θ = 0; past 90° extrapolate linearly.
            if k < 0 {
                table[(-k) as usize]
            } else if k > 90 {
                2.0 * table[90] - table[89]
            } else {
                table[k as usize]
            }
        };
        let (p0, p1, p2, p3) = (
            at(i as isize - 1),
            at(i as isize),
            at(i as isize + 1),
            at(i as isize + 2),
        );
        // Catmull–Rom.
        p1 + 0.5
            * f
            * (p2 - p0
                + f * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + f * (3.0 * (p1 - p2) + p3 - p0)))
    };
    // The quadrature's own error: a finer rule (2× in every direction, 1 nm) and direct
    // evaluation between grid nodes agree with the table to well below the test's noise.
    for theta in [0.5f64, 45.5, 84.5, 88.5] {
        let fine = luminance_albedo(mat, theta.to_radians().cos(), 2 * n_mu, 2 * n_phi, 1);
        let tab = interp(theta);
        println!("θo = {theta:4}°: A = {fine:.6} (fine), {tab:.6} (table)");
        assert!(
            (fine - tab).abs() < 5e-4,
            "θo = {theta}°: quadrature {fine} vs table {tab}"
        );
    }
    let film = render(&w, 2);
    let expected_ray = |o: Vec3, d: Vec3| -> f64 {
        unit_sphere_cos(o, d).map_or(1.0, |c| interp(c.acos().to_degrees()))
    };
    let (mean, se) = image_mean(&film);
    let e_mean = (0..film.height)
        .flat_map(|y| (0..film.width).map(move |x| (x, y)))
        .map(|(x, y)| pixel_footprint_mean(&w, x, y, expected_ray))
        .sum::<f64>()
        / film.pixels.len() as f64;
    println!(
        "{m}: image mean Y = {:.5} ± {se:.5}, expected {e_mean:.5} (se/mean = {:.2} %)",
        mean[1],
        100.0 * se / mean[1]
    );
    check_pixels(&film, m, luminance, |x, y| {
        pixel_footprint_mean(&w, x, y, expected_ray)
    });
}

#[test]
fn white_furnace_rough_dielectrics_gain_nothing() {
    // Rough glass loses energy (single scattering: the microfacet model omits light that
    // scatters more than once between facets) but never gains. Its furnace value has no
    // per-pixel reference here (light enters the sphere and leaves after any number of internal
    // paths), so this is an upper bound only; the lower bound is a plausibility check.
    for m in [
        "Dielectric(ior: Constant(1.5), roughness: 0.3)",
        "Dielectric(ior: Glass(\"BK7\"), roughness: 0.5, distribution: Beckmann)",
    ] {
        let film = render(&world(&furnace_scene(m)), 2);
        let (mean, se) = image_mean(&film);
        println!("{m:70} mean Y = {:.5} ± {:.5}", mean[1], se);
        assert!(
            mean[1] <= 1.0 + 4.0 * se,
            "{m}: {} ± {se} gains energy",
            mean[1]
        );
        assert!(se < 0.01, "{m}: standard error {se}");
        assert!(mean[1] > 0.5, "{m}: {} implausibly dark", mean[1]);
    }
}

#[test]
fn glass_sphere_truncated_furnace() {
    // A smooth glass sphere (η = 1.5) in a uniform environment of luminance 1 cd/m², with the
    // path length capped. A ray meeting a sphere at incidence θ meets it at the same internal
    // angle at every later crossing, and R(θ) inside equals R(θ) outside, so after at most N
    // scattering events the camera sees exactly L_N = R + T² Σ_{j=0}^{N−2} Rʲ (T = 1 − R).
    // This checks the Fresnel weights of every bounce; the untruncated furnace cannot (any R
    // sums to R + T²/(1 − R) = 1). Each pixel's expectation is a 16×16 quadrature over its box
    // footprint. The check is on the sum over all pixels: near the silhouette the samples that
    // end inside the sphere are rare (probability T·R² ≈ 0.5 % at depth 3), and a pixel that
    // drew none of them reports a standard error that does not cover them.
    let res = 24;
    for depth in [1u32, 2, 3, 6] {
        let w = world(&format!(
            r#"(
            camera: (position: (0.3, 0.2, -3.0), look_at: (0, 0, 0), vfov_deg: 45, resolution: ({res}, {res})),
            render: (spp: 256, max_depth: {depth}, rr_depth: 1000),
            materials: {{ "glass": Dielectric(ior: Constant(1.5)) }},
            objects: [(shape: Sphere(center: (0, 0, 0), radius: 1), material: "glass")],
            lights: [Environment(spectrum: Named("E"), amount: Luminance(1.0))],
        )"#
        ));
        let film = render(&w, 2);
        let expected_ray = |o: Vec3, d: Vec3| -> f64 {
            let Some(cos) = unit_sphere_cos(o, d) else {
                return 1.0;
            };
            let r = fresnel_unpolarised(cos, 1.5);
            let t = 1.0 - r;
            r + (0..depth as i32 - 1)
                .map(|j| t * t * r.powi(j))
                .sum::<f64>()
        };
        let (mut sum_d, mut var_d, mut sum_e) = (0.0, 0.0, 0.0);
        for y in 0..res {
            for x in 0..res {
                let e = pixel_footprint_mean(&w, x, y, expected_ray);
                let p = &film.pixels[y * res + x];
                let (v, se) = (
                    p.mean_xyz()[1],
                    p.y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES),
                );
                sum_d += v - e;
                var_d += se * se;
                sum_e += e;
            }
        }
        let n = (res * res) as f64;
        let z = sum_d / var_d.sqrt();
        println!(
            "depth {depth}: image mean {:.5} ± {:.5}, expected {:.5} (z = {z:.2})",
            (sum_e + sum_d) / n,
            var_d.sqrt() / n,
            sum_e / n
        );
        assert!(
            z.abs() < 4.0,
            "depth {depth}: image mean {} ± {}, expected {}",
            (sum_e + sum_d) / n,
            var_d.sqrt() / n,
            sum_e / n
        );
    }
}

/// Follow a ray through the prism scene at one wavelength, always refracting.
fn deviation_deg(lambda: f32) -> f32 {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/prism.ron");
    let w = load_world(&path, &Overrides::default()).expect("prism scene");
    // The beam: from the slit centre toward the entry point (−0.1, 0, 0).
    let slit = Vec3::new(-1.767283 + 0.001107, 0.0, -1.104613 - 0.001666);
    let d_in = (Vec3::new(-0.1, 0.0, 0.0) - slit).normalize();
    let (mut o, mut d) = (slit, d_in);
    let mut crossings = 0;
    while let Some(hit) = w.geometry.intersect(o, d, f32::INFINITY) {
        let m = &w.materials[w.objects[hit.object as usize].material as usize];
        if !matches!(m, Material::Dielectric(_)) {
            break;
        }
        let frame = Frame::from_normal(hit.ns);
        let mut wl = SampledWavelengths::sample_uniform(0.0);
        wl.lambda[0] = lambda;
        // uc close to 1: take the refracted branch (R < 1 away from total internal reflection).
        let bs = m
            .sample(frame.to_local(-d), 0.9999, Vec2::new(0.5, 0.5), &mut wl)
            .expect("refraction");
        d = frame.to_world(bs.wi).normalize();
        o = hit.spawn_origin(d);
        crossings += 1;
    }
    assert_eq!(crossings, 2, "the beam should cross two faces");
    d_in.angle_between(d).to_degrees()
}

#[test]
fn prism_deviates_shorter_wavelengths_more() {
    let d450 = deviation_deg(450.0);
    let d550 = deviation_deg(550.0);
    let d650 = deviation_deg(650.0);
    println!("deviation: 450 nm {d450:.3}°, 550 nm {d550:.3}°, 650 nm {d650:.3}°");
    assert!(d450 > d550 && d550 > d650);
    // The scene is set at minimum deviation for 550 nm: δ = 2 asin(n sin 30°) − 60°.
    let n = candela::bxdf::ior::named_glass("SF11")
        .unwrap()
        .ior
        .at_f64(550.0);
    let expected = (2.0 * (n * 0.5).asin().to_degrees() - 60.0) as f32;
    assert!(
        (d550 - expected).abs() < 0.01,
        "δ(550) = {d550}, expected {expected}"
    );
}

/// Luminance of a point on a rough plane lit by a quad light, rendered (light sampling and
/// BSDF sampling combined by MIS) and by direct quadrature of f cos θ over the light.
#[test]
fn rough_materials_under_an_area_light_match_quadrature() {
    let le = 1000.0f64;
    let cam_dir = Vec3::new(40f32.to_radians().sin(), 40f32.to_radians().cos(), 0.0);
    let cam = cam_dir * 2.0;
    for m in [
        r#"Conductor(n: Constant(0.3), k: Constant(3.0), roughness: 0.3)"#,
        r#"Conductor(n: Constant(1.2), k: Constant(2.0), roughness: 0.15, roughness_v: 0.5, distribution: Beckmann)"#,
        r#"Conductor(n: Constant(0.3), k: Constant(3.0), roughness: 0.3, masking: VCavity)"#,
        r#"Dielectric(ior: Constant(1.5), roughness: 0.2)"#,
        r#"Phong(diffuse: Constant(0.3), specular: Constant(0.6), exponent: 40)"#,
        r#"OrenNayar(reflectance: Constant(0.8), sigma_deg: 30)"#,
    ] {
        let text = format!(
            r#"(
            camera: (position: ({}, {}, {}), look_at: (0, 0, 0), vfov_deg: 0.01, resolution: (1, 1)),
            render: (spp: 40000, max_depth: 1),
            materials: {{ "m": {m} }},
            objects: [
                (shape: Disk(center: (0, 0, 0), normal: (0, 1, 0), radius: 1), material: "m"),
                (shape: Quad(origin: (-1.51, 1.5, -0.25), edge_u: (0.5, 0, 0), edge_v: (0, 0, 0.5)),
                 material: "black", emission: (spectrum: Named("E"), amount: Luminance({le}))),
            ],
        )"#,
            cam.x, cam.y, cam.z
        );
        let w = world(&text);
        let film = render(&w, 2);
        let (y, se) = image_mean(&film);
        // Quadrature over the light (f is the same at every wavelength here).
        let mat = &w.materials[1];
        let frame = Frame::from_normal(Vec3::Y);
        let wo = frame.to_local(cam_dir);
        let wl = SampledWavelengths::sample_uniform(0.5);
        let n = 400;
        let mut sum = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let q = Vec3::new(
                    -1.51 + 0.5 * (i as f32 + 0.5) / n as f32,
                    1.5,
                    -0.25 + 0.5 * (j as f32 + 0.5) / n as f32,
                );
                let r2 = q.length_squared();
                let wi_w = q / r2.sqrt();
                let cos_l = wi_w.y; // light faces −y
                let da = 0.25 / (n * n) as f32;
                let wi = frame.to_local(wi_w);
                sum += (mat.eval(wo, wi, &wl)[0] * wi.z * cos_l / r2 * da) as f64;
            }
        }
        let expected = le * sum;
        println!(
            "{m:100} rendered {:.4} ± {:.4}, quadrature {expected:.4}",
            y[1], se
        );
        assert!(
            // Allowance of 1e-3 relative for the error of the 400 × 400 midpoint rule over the
            // light (observed agreement: < 1e-4).
            (y[1] - expected).abs() <= 5.0 * se + 1e-3 * expected,
            "{m}: rendered {} ± {se}, quadrature {expected}",
            y[1]
        );
        assert!(se < 0.02 * expected);
    }
}

/// The cosine of incidence where the ray (o, d) enters the unit sphere at the origin, or `None`
/// if it misses it (it then sees the environment).
fn unit_sphere_cos(o: Vec3, d: Vec3) -> Option<f64> {
    let (o, d) = (o.as_dvec3(), d.as_dvec3().normalize());
    let b2 = o.cross(d).length_squared();
    (o.dot(d) < 0.0 && b2 < 1.0).then(|| (1.0 - b2).sqrt())
}
