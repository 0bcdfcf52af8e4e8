//! BSDF XML files (`BsdfFile`): values against Radiance's own library on the files of
//! tests/data/bsdf (made by bsdf2klems and scripts/bsdf_testfiles.py; oracle values from
//! pyradiance's `query`, scripts/bsdf_oracle.py), sampling against evaluation (χ²), meters under
//! a pane of each file in a uniform sky and under the sun against the file's own sums, the
//! sides a file's blocks belong to, and every malformed file refused with its name and element.

mod bxdf_util;
mod common;
use bxdf_util::*;
use candela::bxdf::{BsdfFile, Material};
use candela::meter::measure_all;
use common::*;
use glam::Vec3;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::sync::Arc;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/bsdf")
        .join(name)
}

fn load(name: &str) -> BsdfFile {
    BsdfFile::load(&data(name), Vec3::Y).unwrap_or_else(|e| panic!("{e}"))
}

fn dir(theta_deg: f64, phi_deg: f64) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(
        (t.sin() * p.cos()) as f32,
        (t.sin() * p.sin()) as f32,
        t.cos() as f32,
    )
}

const KLEMS: [&str; 5] = [
    "klems_quarter_diffuse.xml",
    "klems_quarter_sides.xml",
    "klems_half_lobe.xml",
    "klems_full_lobe.xml",
    "klems_full_clear.xml",
];

#[test]
fn values_match_radiance_on_every_klems_file() {
    // Radiance multiplies each value by 1 + 6·10⁻⁴(d − ½) with d a hash of the patch pair
    // (bsdf_m.c mBSDF_color), so exact reads differ by up to 3·10⁻⁴ relative.
    for name in KLEMS {
        let m = load(name);
        let csv = std::fs::read_to_string(data(&format!("{name}.oracle.csv"))).unwrap();
        let mut n = 0;
        for line in csv.lines().skip(1) {
            let v: Vec<f64> = line.split(',').map(|t| t.parse().unwrap()).collect();
            let (wi, wo) = (dir(v[0], v[1]), dir(v[2], v[3]));
            let got = m.value(wo, wi) as f64;
            assert!(
                (got - v[4]).abs() <= 4e-4 * v[4] + 1e-6,
                "{name}: in ({}°, {}°) out ({}°, {}°): candela {got}, Radiance {}",
                v[0],
                v[1],
                v[2],
                v[3],
                v[4]
            );
            n += 1;
        }
        assert_eq!(n, 800, "{name}");
    }
}

#[test]
fn sampling_matches_eval_and_pdf_chi_square() {
    let mut cases = Vec::new();
    for name in [
        "klems_quarter_sides.xml",
        "klems_half_lobe.xml",
        "klems_full_lobe.xml",
    ] {
        let m = Material::BsdfFile(Arc::new(load(name)));
        for (t, p) in [
            (3.0f32, 10.0f32),
            (40.0, 120.0),
            (80.0, 300.0),
            (130.0, 30.0),
        ] {
            cases.push((format!("{name} θo={t}"), m.clone(), dir_deg(t, p)));
        }
    }
    let failures = chi2_cases(&cases, 900);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn sample_weights_are_the_row_sums_and_never_exceed_one() {
    // Each sample weighs f|cos|/pdf = Σ f Λ over the row of its outgoing patch; by reciprocity
    // that is what light arriving from wo's direction scatters in all (for reciprocal files),
    // checkBSDF's directional-hemispherical sum: 0.2 + 0.5 for the diffuse file.
    let m = load("klems_quarter_diffuse.xml");
    let mut rng = Rng::new(3);
    for _ in 0..200 {
        let wo = rng.sphere();
        if wo.z.abs() < 1e-3 {
            continue;
        }
        let (r, t) = m.reflected_transmitted(-wo);
        let s = m.sample(wo, rng.f32(), rng.vec2()).unwrap();
        let w = s.f.0[0] * s.wi.z.abs() / s.pdf;
        assert!((w as f64 - (r + t)).abs() < 1e-4, "{w} vs {r} + {t}");
        assert!((r - 0.2).abs() < 1e-3 && (t - 0.5).abs() < 1e-3, "{r} {t}");
    }
    for name in KLEMS {
        let m = load(name);
        for k in 0..400 {
            let wi = dir(
                89.0 * (k % 20) as f64 / 19.0,
                360.0 * (k / 20) as f64 / 20.0,
            );
            for w in [wi, -wi] {
                let (r, t) = m.reflected_transmitted(w);
                assert!(r + t <= 1.01, "{name} from {w}: ρ {r} + τ {t}");
            }
        }
    }
}

/// The meter at the origin (normal +y) under a 2 km square pane of `material` at height 1 whose
/// normal points down (`flip`: up), with `lights` and nothing else.
fn meter_under(material: &str, flip: bool, lights: &str, samples: u64) -> candela::meter::Estimate {
    let (u, v) = if flip {
        ("(0, 0, 2000)", "(2000, 0, 0)")
    } else {
        ("(2000, 0, 0)", "(0, 0, 2000)")
    };
    let w = world(&format!(
        r#"(
        camera: (position: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 10, resolution: (1, 1)),
        render: (spp: 1),
        materials: {{ "pane": {material} }},
        objects: [(shape: Quad(origin: (-1000, 1, -1000), edge_u: {u}, edge_v: {v}), material: "pane")],
        lights: [{lights}],
        meters: [Illuminance(name: "m", position: (0, 0, 0), normal: (0, 1, 0))],
        measure: (samples: {samples}),
    )"#
    ));
    measure_all(&w).meters[0]
}

fn uniform_sky(l: f64) -> String {
    format!(
        "Sky(model: Uniform, amount: ZenithLuminance({l}), spectrum: Named(\"E\"), ground_reflectance: 0.0)"
    )
}

/// Σ_o Λ_o Σ_i f[o][i] Λ_i of the file's 'Transmission Front' block: the illuminance under an
/// infinite pane of it in a uniform sky of unit luminance.
fn double_sum(name: &str) -> f64 {
    use candela::bxdf::bsdf_file::{klems::KlemsMatrix, xml};
    let parsed = xml::read(&data(name)).unwrap();
    let b = parsed
        .blocks
        .into_iter()
        .find(|b| b.block == xml::Block::TransToPos)
        .unwrap();
    let (inc, out) = b.bases.unwrap();
    let m = KlemsMatrix::new(inc, out, b.values);
    let (ni, no) = (m.inc.len(), m.out.len());
    (0..no)
        .map(|o| {
            m.out.proj_sr(o) as f64
                * (0..ni)
                    .map(|i| m.f[o * ni + i] as f64 * m.inc.proj_sr(i) as f64)
                    .sum::<f64>()
        })
        .sum()
}

/// The share of a horizontal meter's cosine-weighted hemisphere that a 2a × 2a square centred
/// 1 m above it fills.
fn square_view_factor(a: f64) -> f64 {
    let s = a / (1.0 + a * a).sqrt();
    4.0 / PI * s * s.atan()
}

#[test]
fn a_meter_under_a_pane_in_a_uniform_sky_gets_the_files_transmission() {
    // Uniform sky L above, nothing below: the pane sends L·Σ_i f Λ_i toward each outgoing
    // direction, so E = L Σ_o Λ_o Σ_i f Λ_i over the pane's part of the hemisphere plus the sky
    // beyond it. For a Lambertian file that is π L τ (rtrace, with the same file: 1.570798 per
    // unit L for τ = 0.5; this file holds 0.1592 = 0.50014/π).
    let l = 1000.0;
    let f = square_view_factor(1000.0);
    for (name, flip, tau) in [
        ("klems_quarter_diffuse.xml", false, 0.1592 * PI),
        (
            "klems_half_lobe.xml",
            false,
            double_sum("klems_half_lobe.xml") / PI,
        ),
        ("klems_full_clear.xml", false, 1.0),
        // Sky on the file's exterior (−Z) side: Transmission Front, 0.4; turned over (sky on
        // +Z): Transmission Back, 0.2.
        ("klems_quarter_sides.xml", false, 0.4),
        ("klems_quarter_sides.xml", true, 0.2),
    ] {
        let material = format!("BsdfFile(file: \"tests/data/bsdf/{name}\", up: (0, 0, 1))");
        let e = meter_under(&material, flip, &uniform_sky(l), 1 << 18);
        let expected = PI * l * (f * tau + 1.0 - f);
        println!(
            "{name} (flipped: {flip}): E = {:.3} ± {:.3} lx, expected {expected:.3} lx",
            e.mean, e.stderr
        );
        assert_estimate_near(e.mean, e.stderr, expected, 0.01, name);
    }
}

#[test]
fn the_sun_through_a_lobe_file_is_light_sampled_at_its_exact_direction() {
    // A distant sun of normal illuminance E⊥ above the pane: shadow rays do not cross it, the
    // meter gets the sun only through next-event estimation at the pane, which reads the file
    // at the sun's exact direction: E = E⊥ cos θs · τ(sun's patch), τ the file's transmission
    // sum for that incident patch (the pane fills the meter's hemisphere).
    let m = load("klems_half_lobe.xml");
    let pane_normal = Vec3::new(0.0, -1.0, 0.0);
    let frame = m.frame(pane_normal);
    for sun in [
        Vec3::new(0.0, -1.0, 0.0),
        Vec3::new(0.5, -1.0, 0.2),
        Vec3::new(1.0, -0.6, 0.3),
    ] {
        let wi = frame.to_local(-sun.normalize());
        let (_, tau) = m.reflected_transmitted(wi);
        let e = meter_under(
            "BsdfFile(file: \"tests/data/bsdf/klems_half_lobe.xml\", up: (0, 0, 1))",
            false,
            &format!(
                r#"Distant(direction: ({}, {}, {}), spectrum: Named("E"), amount: Illuminance(80000.0))"#,
                sun.x, sun.y, sun.z
            ),
            1 << 14,
        );
        let cos = (-sun.normalize()).y as f64;
        let expected = 8e4 * cos * tau * square_view_factor(1000.0);
        println!(
            "sun from {sun}: E = {:.1} ± {:.1} lx, expected {expected:.1} (τ = {tau:.4})",
            e.mean, e.stderr
        );
        assert_estimate_near(e.mean, e.stderr, expected, 0.02, "sun through a BSDF file");
    }
}

#[test]
fn the_frame_follows_up_as_radiance_orients_a_bsdf() {
    // Radiance: X = up × normal, Y = normal × X.
    let m = BsdfFile::load(&data("klems_quarter_diffuse.xml"), Vec3::Z).unwrap();
    let n = Vec3::new(0.0, -1.0, 0.0);
    let f = m.frame(n);
    assert!((f.t - Vec3::Z.cross(n)).length() < 1e-6, "{:?}", f.t);
    assert!((f.b - n.cross(f.t)).length() < 1e-6);
}

#[test]
fn malformed_files_are_refused_naming_the_file_and_the_element() {
    for (name, want) in [
        ("broken_truncated.xml", "is not valid XML"),
        ("broken_too_few_values.xml", "has 1661 of the 1681 values"),
        ("broken_non_numeric.xml", "value 101 is \"abc\""),
        ("broken_hemi_sum.xml", "more than 100 %"),
        ("broken_unknown_basis.xml", "LBNL/Klems Eighth"),
        ("broken_tree_braces.xml", "tensor tree"),
    ] {
        let e = BsdfFile::load(&data(name), Vec3::Y).unwrap_err();
        println!("{name}: {e}");
        assert!(e.contains(name) && e.contains(want), "{name}: {e}");
    }
    let e = BsdfFile::load(&data("klems_quarter_diffuse.xml"), Vec3::Y)
        .map(|m| m.notes)
        .unwrap();
    assert!(e.is_empty(), "{e:?}");
    let full = load("klems_full_lobe.xml");
    assert!(
        full.notes.iter().any(|n| n.contains("reciprocity")),
        "{:?}",
        full.notes
    );
}

#[test]
fn what_is_not_a_bsdf_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let cases = [
        (write("empty.xml", ""), "not valid XML"),
        (write("other.xml", "<svg></svg>"), "not a WINDOW BSDF file"),
        (
            write(
                "solar.xml",
                "<WindowElement><Optical><Layer><DataDefinition><IncidentDataStructure>Columns</IncidentDataStructure></DataDefinition><WavelengthData><Wavelength unit=\"Integral\">Solar</Wavelength></WavelengthData></Layer></Optical></WindowElement>",
            ),
            "no Visible scattering data (it has Solar)",
        ),
        (
            write(
                "dtd.xml",
                "<!DOCTYPE x [<!ENTITY a \"aaaa\">]><WindowElement/>",
            ),
            "not valid XML",
        ),
        (dir.path().to_path_buf(), "a directory"),
        (dir.path().join("missing.xml"), "cannot read BSDF file"),
    ];
    for (p, want) in cases {
        let e = BsdfFile::load(&p, Vec3::Y).unwrap_err();
        assert!(e.contains(want), "{}: {e}", p.display());
    }
    #[cfg(unix)]
    {
        let fifo = dir.path().join("fifo.xml");
        let ok = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success());
        if ok {
            let e = BsdfFile::load(&fifo, Vec3::Y).unwrap_err();
            assert!(e.contains("FIFO"), "{e}");
        }
    }
}

#[test]
fn scene_errors_name_the_material_field() {
    let build = |m: &str| {
        let text = format!(
            r#"(camera: (position: (0, 0, -3), look_at: (0, 0, 0), vfov_deg: 40, resolution: (4, 4)),
            materials: {{ "blind": {m} }},
            objects: [(shape: Sphere(center: (0, 0, 0), radius: 1), material: "blind")])"#
        );
        let path = Path::new("t.ron");
        let s = candela::scene::parse(&text, path).unwrap();
        candela::scene::build(&s, path, &Default::default())
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    let e = build("BsdfFile(file: \"tests/data/bsdf/nope.xml\", up: (0, 0, 1))");
    assert!(
        e.contains("materials[\"blind\"].file") && e.contains("nope.xml"),
        "{e}"
    );
    let e = build("BsdfFile(file: \"tests/data/bsdf/klems_quarter_diffuse.xml\", up: (0, 0, 0))");
    assert!(e.contains("materials[\"blind\"].up"), "{e}");
}

#[test]
fn the_sun_through_a_window_lights_the_work_plane_as_the_file_tabulates() {
    // A 2 m × 1.2 m window of the lobe file in the plane y = 0 (normal +y into the room, up
    // +z), the sun outside, nothing else: each point of the window sends the sun's light
    // toward a meter as L = f(wo, sun) E⊥ |cos θi|, so E = E⊥ |cos θi| ∫ f cos θw cos θm / r² dA
    // over the window, here by the midpoint rule on 1200 × 720 cells (the file is constant
    // within each pair of patches; the cells that straddle a patch border err by < 0.1 %).
    let m = load("klems_half_lobe.xml");
    let n = Vec3::Y;
    let frame = BsdfFile::load(&data("klems_half_lobe.xml"), Vec3::Z)
        .unwrap()
        .frame(n);
    let sun = Vec3::new(0.3, -0.8, 0.5).normalize();
    let e_n = 80_000.0;
    let wi = frame.to_local(sun);
    let points = [Vec3::new(2.0, 1.0, 0.8), Vec3::new(2.0, 2.0, 0.8)];
    let (nx, nz) = (1200, 720);
    let da = (2.0 / nx as f64) * (1.2 / nz as f64);
    let by_quadrature = |p: &Vec3, jitter: f32| {
        let mut sum = 0.0f64;
        for ix in 0..nx {
            for iz in 0..nz {
                let x = Vec3::new(
                    1.0 + 2.0 * (ix as f32 + 0.5) / nx as f32,
                    0.0,
                    0.9 + 1.2 * (iz as f32 + 0.5) / nz as f32,
                );
                let d = *p - x;
                let r2 = d.length_squared() as f64;
                let wo_world = d.normalize();
                let cos_m = (-wo_world.z) as f64;
                if cos_m <= 0.0 {
                    continue;
                }
                let wo = frame.to_local(wo_world);
                let f = if jitter > 0.0 {
                    // Radiance's direct calculation averages f over view directions
                    // moved by up to ±jitter/2 in x and y (m_bsdf.c bsdf_jitter).
                    let mut acc = 0.0f64;
                    for k in 0..16 {
                        let (a, b) = ((k % 4) as f32 + 0.5, (k / 4) as f32 + 0.5);
                        let v = Vec3::new(
                            wo.x + jitter * (a / 4.0 - 0.5),
                            wo.y + jitter * (b / 4.0 - 0.5),
                            wo.z,
                        )
                        .normalize();
                        acc += m.value(v, wi) as f64 / 16.0;
                    }
                    acc
                } else {
                    m.value(wo, wi) as f64
                };
                sum += f * wo_world.y as f64 * cos_m / r2 * da;
            }
        }
        e_n * wi.z.abs() as f64 * sum
    };
    let expected: Vec<f64> = points.iter().map(|p| by_quadrature(p, 0.0)).collect();
    // √ of the half basis' smallest projected solid angle, 0.0343 sr.
    let blurred: Vec<f64> = points.iter().map(|p| by_quadrature(p, 0.185)).collect();
    let meters: Vec<String> = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            format!(
                "Illuminance(name: \"p{i}\", position: ({}, {}, {}), normal: (0, 0, 1))",
                p.x, p.y, p.z
            )
        })
        .collect();
    let w = world(&format!(
        r#"(
        camera: (position: (2, 3.5, 1.5), look_at: (2, 0, 1.5), up: (0, 0, 1), vfov_deg: 60, resolution: (1, 1)),
        render: (spp: 1),
        materials: {{ "win": BsdfFile(file: "tests/data/bsdf/klems_half_lobe.xml", up: (0, 0, 1)) }},
        objects: [(shape: Quad(origin: (1, 0, 0.9), edge_u: (0, 0, 1.2), edge_v: (2, 0, 0)), material: "win")],
        lights: [Distant(direction: ({}, {}, {}), spectrum: Named("E"), amount: Illuminance({e_n}))],
        meters: [{}],
        measure: (samples: {}),
    )"#,
        -sun.x,
        -sun.y,
        -sun.z,
        meters.join(", "),
        1 << 20
    ));
    let ours = measure_all(&w).meters;
    for (i, (e, want)) in ours.iter().zip(&expected).enumerate() {
        println!(
            "p{i}: E = {:.2} ± {:.2} lx, the file by quadrature {want:.2} lx (with Radiance's \
             jitter of the view direction {:.2} lx, {:+.2} %)",
            e.mean,
            e.stderr,
            blurred[i],
            100.0 * (blurred[i] / want - 1.0)
        );
        assert_estimate_near(e.mean, e.stderr, *want, 0.01, "sun through a window");
    }
}
