//! The material syntax of the scene format: every documented form builds, bad values give one
//! clear error naming the field.

use candela::bxdf::Material;
use candela::scene::{build, parse, Overrides};
use std::path::Path;

fn scene(materials: &str) -> String {
    format!(
        r#"(
        camera: (position: (0, 0, 0), look_at: (0, 0, 1), vfov_deg: 30, resolution: (4, 4)),
        materials: {{ {materials} }},
        objects: [(shape: Sphere(center: (0, 0, 3), radius: 1), material: "m")],
    )"#
    )
}

fn try_build(materials: &str) -> Result<Vec<Material>, String> {
    let path = Path::new("test.ron");
    let s = parse(&scene(materials), path).map_err(|e| e.to_string())?;
    build(&s, path, &Overrides::default())
        .map(|w| w.materials)
        .map_err(|e| e.to_string())
}

#[test]
fn documented_forms_build() {
    for m in [
        r#""m": Conductor(metal: "Au", roughness: 0.2)"#,
        r#""m": Conductor(metal: "gold")"#,
        r#""m": Conductor(metal: "Al", roughness: 0.05, roughness_v: 0.4, distribution: Beckmann)"#,
        r#""m": Conductor(metal: "Cu", roughness: 0.3, masking: VCavity)"#,
        r#""m": Conductor(metal: "cr")"#,
        r#""m": Conductor(n: Constant(0.2), k: Tabulated([(400, 3.0), (700, 4.0)]), roughness: 0.1)"#,
        r#""m": Dielectric(ior: Glass("BK7"))"#,
        r#""m": Dielectric(ior: Glass("fused-silica"), roughness: 0.2)"#,
        r#""m": Dielectric(ior: Constant(1.5), roughness: 0.3, distribution: Beckmann)"#,
        r#""m": Dielectric(ior: Cauchy(a: 1.5046, b: 4200.0))"#,
        r#""m": Dielectric(ior: Sellmeier(b: (1.03961212, 0.231792344, 1.01046945), c: (0.00600069867, 0.0200179144, 103.560653)))"#,
        r#""m": ThinDielectric(ior: Constant(1.52))"#,
        r#""m": Coated(base: Rgb(0.6, 0.05, 0.05), ior: 1.5)"#,
        r#""m": Coated(base: Constant(0.5))"#,
        r#""m": Coated(base: Constant(0.5), roughness: 0.2, distribution: Beckmann)"#,
        r#""m": OrenNayar(reflectance: Rgb(0.5, 0.3, 0.2), sigma_deg: 20)"#,
        r#""m": Phong(diffuse: Constant(0.4), specular: Constant(0.5), exponent: 50)"#,
        r#""m": Phong(specular: Constant(0.9), exponent: 500)"#,
    ] {
        let mats = try_build(m).unwrap_or_else(|e| panic!("{m}: {e}"));
        assert!(!mats[1].is_black(), "{m}");
    }
    // Roughness 0 is a delta lobe; the Sellmeier form equals the named BK7.
    let mats = try_build(r#""m": Dielectric(ior: Glass("BK7"))"#).unwrap();
    assert!(mats[1].is_specular());
}

#[test]
fn bad_materials_name_the_field() {
    for (m, field, words) in [
        (
            r#""m": Conductor(metal: "Unobtainium")"#,
            r#"materials["m"].metal"#,
            "unknown metal",
        ),
        (
            r#""m": Conductor(metal: "Au", roughness: -0.1)"#,
            r#"materials["m"].roughness"#,
            "≥ 0",
        ),
        (
            r#""m": Conductor(metal: "Au", roughness: 0.1, roughness_v: NaN)"#,
            r#"materials["m"].roughness_v"#,
            "finite",
        ),
        (
            r#""m": Conductor(metal: "Au", n: Constant(1.0), k: Constant(1.0))"#,
            r#"materials["m"]"#,
            "either",
        ),
        (
            r#""m": Conductor(n: Constant(0.0), k: Constant(3.0))"#,
            r#"materials["m"].n"#,
            "greater than 0",
        ),
        (
            r#""m": Conductor(n: Constant(1.0), k: Blackbody(3000))"#,
            r#"materials["m"].k"#,
            "optical constant",
        ),
        (
            r#""m": Dielectric(ior: Constant(0.0))"#,
            r#"materials["m"].ior"#,
            "greater than 0",
        ),
        (
            r#""m": Dielectric(ior: Constant(-1.5))"#,
            r#"materials["m"].ior"#,
            "greater than 0",
        ),
        (
            r#""m": Dielectric(ior: Constant(NaN))"#,
            r#"materials["m"].ior"#,
            "finite",
        ),
        (
            r#""m": Dielectric(ior: Glass("unobtainium"))"#,
            r#"materials["m"].ior"#,
            "unknown glass",
        ),
        (
            r#""m": Dielectric(ior: Cauchy(a: inf, b: 0.0))"#,
            r#"materials["m"].ior"#,
            "finite",
        ),
        (
            r#""m": ThinDielectric(ior: Constant(0.0))"#,
            r#"materials["m"].ior"#,
            "greater than 0",
        ),
        (
            r#""m": Coated(base: Constant(0.5), ior: 0.0)"#,
            r#"materials["m"].ior"#,
            "greater than 0",
        ),
        (
            r#""m": Coated(base: Constant(1.5))"#,
            r#"materials["m"].base"#,
            "above 1",
        ),
        (
            r#""m": OrenNayar(reflectance: Constant(0.5), sigma_deg: -3)"#,
            r#"materials["m"].sigma_deg"#,
            "angle",
        ),
        (
            r#""m": Phong(diffuse: Constant(0.6), specular: Constant(0.6), exponent: 10)"#,
            r#"materials["m"]"#,
            "exceeds 1",
        ),
        (
            r#""m": Phong(specular: Constant(0.6), exponent: -1)"#,
            r#"materials["m"].exponent"#,
            "≥ 0",
        ),
    ] {
        let e = try_build(m)
            .err()
            .unwrap_or_else(|| panic!("{m} should fail"));
        assert!(e.contains(&format!("`{field}`")), "{m}: {e}");
        assert!(e.contains(words), "{m}: {e}");
    }
}
