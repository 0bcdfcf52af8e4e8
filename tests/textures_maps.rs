//! Roughness, metallic and normal maps: glTF's metallic-roughness texture resolves per texel
//! to the material the untextured rule gives for the same values (exactly, for a constant
//! texture), tangent-space normal maps tilt a Lambertian's shading normal by the texel's angle
//! (luminance E·ρ·cos θ/π under a light at normal incidence), a flat map changes nothing to
//! the bit, a normal-mapped white Lambertian in a white furnace returns (1 + cos θ)/2 (the
//! directions below the geometric surface carry nothing: no gain, no leak), and missing maps
//! are errors naming the file.

mod common;
use candela::film::Film;
use serde_json::{json, Value};
use std::path::Path;

/// A `w × h` RGB PNG of `texels` (top row first) written as `dir`/`name`.
fn png(dir: &Path, name: &str, w: u32, h: u32, texels: &[[u8; 3]]) {
    let raw: Vec<u8> = texels.iter().flatten().copied().collect();
    image::RgbImage::from_raw(w, h, raw)
        .unwrap()
        .save(dir.join(name))
        .unwrap();
}

/// A 4 m × 4 m floor (y = 0, facing +Y; u = (x + 2)/4 along +x, glTF v = (z + 2)/4) as
/// `dir`/`name`, a `.gltf` with its buffer in a file, with material `material` (images by
/// file name, textures 0.. on images 0..).
fn gltf_floor(dir: &Path, name: &str, material: Value, images: &[&str]) {
    let pos = [
        [-2.0, 0.0, -2.0],
        [2.0, 0.0, -2.0],
        [2.0, 0.0, 2.0],
        [-2.0, 0.0, 2.0],
    ];
    let extra = json!({
        "materials": [material],
        "images": images.iter().map(|f| json!({"uri": f})).collect::<Vec<_>>(),
        "textures": (0..images.len()).map(|i| json!({"source": i})).collect::<Vec<_>>(),
        "samplers": [],
    });
    common::gltf_quad(dir, name, pos, [0, 2, 1, 0, 3, 2], extra);
}

/// The floor seen from 1 m above (32 × 32 pixels over its middle 2 m; image right is −x) under
/// `light`, direct light only.
fn floor_scene(file: &str, light: &str, spp: u32) -> String {
    format!(
        r#"(
    camera: (position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 90, resolution: (32, 32)),
    render: (spp: {spp}, max_depth: 1),
    materials: {{ "white": Diffuse(reflectance: Constant(0.5)) }},
    objects: [(shape: Model(file: "{file}"), material: "white")],
    lights: [{light}],
)"#
    )
}

const SUN: &str =
    r#"Distant(direction: (0, -1, 0), spectrum: Named("D65"), amount: Illuminance(1000.0))"#;

fn render_in(dir: &Path, file: &str, light: &str, spp: u32) -> Film {
    common::render(&common::world_in(&floor_scene(file, light, spp), dir), 1)
}

/// Mean Y (cd/m²) and standard error over pixel columns `cols` (every row).
fn columns_mean(film: &Film, cols: std::ops::Range<usize>) -> (f64, f64) {
    let (mut m, mut v, mut n) = (0.0, 0.0, 0.0);
    for y in 0..film.height {
        for x in cols.clone() {
            let p = &film.pixels[y * film.width + x];
            m += p.mean_xyz()[1];
            v += p
                .y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES)
                .powi(2);
            n += 1.0;
        }
    }
    (m / n, v.sqrt() / n)
}

fn pbr(base: [f64; 3], metallic: f64, roughness: f64) -> Value {
    json!({"baseColorFactor": [base[0], base[1], base[2], 1.0],
           "metallicFactor": metallic, "roughnessFactor": roughness})
}

/// A constant metallic-roughness texture (G = B = 255) times the factors is the material of the
/// factors alone: a coat identical to the bit, a metal (whose k the texture path computes per
/// wavelength rather than interpolating a table) within the Monte Carlo error.
#[test]
fn constant_metal_rough_texture_is_the_untextured_material() {
    let dir = tempfile::tempdir().unwrap();
    png(dir.path(), "mr.png", 2, 2, &[[0, 255, 255]; 4]);
    let base = [0.6, 0.45, 0.3];
    for (metallic, exact) in [(0.0, true), (1.0, false)] {
        let plain = pbr(base, metallic, 0.3);
        let mut textured = plain.clone();
        textured["metallicRoughnessTexture"] = json!({"index": 0});
        gltf_floor(
            dir.path(),
            "plain.gltf",
            json!({"pbrMetallicRoughness": plain}),
            &[],
        );
        gltf_floor(
            dir.path(),
            "textured.gltf",
            json!({"pbrMetallicRoughness": textured}),
            &["mr.png"],
        );
        let a = render_in(dir.path(), "plain.gltf", SUN, 16);
        let w = common::world_in(&floor_scene("textured.gltf", SUN, 16), dir.path());
        assert!(w
            .materials
            .iter()
            .any(|m| matches!(m, candela::bxdf::Material::MetalRough(_))));
        let b = common::render(&w, 1);
        if exact {
            for (i, (p, q)) in a.pixels.iter().zip(&b.pixels).enumerate() {
                assert_eq!(p.mean_xyz(), q.mean_xyz(), "pixel {i}");
            }
        } else {
            let z = common::assert_blocks_agree(&a, &b, 8, ("factors", "constant texture"));
            eprintln!("metal: largest block |z| {z:.2}");
        }
    }
}

/// A metallic-roughness texture whose left half (u < ½) is rough dielectric (G = 255, B = 0)
/// and right half a metal of roughness 77/255 (G = 77, B = 255): each half renders as the
/// untextured material of its values, and the rough half at E·ρ/π.
#[test]
fn metal_and_roughness_vary_per_texel() {
    let dir = tempfile::tempdir().unwrap();
    let texels: Vec<[u8; 3]> = (0..16)
        .map(|i| if i < 8 { [0, 255, 0] } else { [0, 77, 255] })
        .collect();
    png(dir.path(), "mr.png", 16, 1, &texels);
    let base = [0.8, 0.8, 0.8];
    let mut textured = pbr(base, 1.0, 1.0);
    textured["metallicRoughnessTexture"] = json!({"index": 0});
    gltf_floor(
        dir.path(),
        "textured.gltf",
        json!({"pbrMetallicRoughness": textured}),
        &["mr.png"],
    );
    gltf_floor(
        dir.path(),
        "rough.gltf",
        json!({"pbrMetallicRoughness": pbr(base, 0.0, 1.0)}),
        &[],
    );
    gltf_floor(
        dir.path(),
        "metal.gltf",
        json!({"pbrMetallicRoughness": pbr(base, 1.0, 77.0 / 255.0)}),
        &[],
    );
    let spp = 64;
    let t = render_in(dir.path(), "textured.gltf", SUN, spp);
    let rough = render_in(dir.path(), "rough.gltf", SUN, spp);
    let metal = render_in(dir.path(), "metal.gltf", SUN, spp);
    // Pixel column c sees x = 1 − (c + ½)/16 m: u < 7.5/16 (texels 0..7 only) right of column
    // 17, u > 8.5/16 left of column 14.
    let halves = [(19..32, &rough, "rough"), (0..13, &metal, "metal")];
    for (cols, reference, name) in halves {
        let (mt, st) = columns_mean(&t, cols.clone());
        let (mr, sr) = columns_mean(reference, cols);
        let z = (mt - mr) / (st * st + sr * sr).sqrt();
        eprintln!(
            "{name} half: textured {mt:.4} ± {st:.4}, untextured {mr:.4} ± {sr:.4} cd/m², z {z:.2}"
        );
        assert!(z.abs() < 4.5, "{name} half: {mt} ± {st} vs {mr} ± {sr}");
        assert!(
            st < 0.01 * mt,
            "{name} half: standard error {st} too large to test"
        );
    }
    // The rough half is Lambertian of the upsampled grey 0.8 (a constant spectrum).
    let (m, se) = columns_mean(&t, 19..32);
    common::assert_estimate_near(
        m,
        se,
        1000.0 * 0.8 / std::f64::consts::PI,
        0.01,
        "rough half",
    );
    // And the metal half is not: a mirror-like lobe toward the camera.
    let (mm, _) = columns_mean(&t, 0..13);
    assert!(
        (mm - m).abs() > 0.1 * m,
        "metal half {mm} vs rough half {m}"
    );
}

/// An OBJ floor (u along +x, v along +z) with MTL material `mtl_body`.
fn obj_floor(dir: &Path, mtl_body: &str) {
    std::fs::write(
        dir.join("floor.obj"),
        "mtllib floor.mtl\nv -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\n\
         vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl floor\nf 1/1 3/3 2/2\nf 1/1 4/4 3/3\n",
    )
    .unwrap();
    std::fs::write(dir.join("floor.mtl"), format!("newmtl floor\n{mtl_body}\n")).unwrap();
}

/// A flat normal map (128, 128, 255) renders to the bit as no map.
#[test]
fn flat_normal_map_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    png(dir.path(), "flat.png", 2, 2, &[[128, 128, 255]; 4]);
    obj_floor(dir.path(), "Kd 0.7 0.6 0.5");
    let a = render_in(dir.path(), "floor.obj", SUN, 4);
    obj_floor(dir.path(), "Kd 0.7 0.6 0.5\nnorm flat.png");
    let w = common::world_in(&floor_scene("floor.obj", SUN, 4), dir.path());
    assert!(w
        .materials
        .iter()
        .any(|m| matches!(m, candela::bxdf::Material::NormalMapped(_))));
    let b = common::render(&w, 1);
    for (i, (p, q)) in a.pixels.iter().zip(&b.pixels).enumerate() {
        assert_eq!(p.mean_xyz(), q.mean_xyz(), "pixel {i}");
    }
}

/// The tilt of texel (192, 128, 255): x = 64/127, z = 1, so cos θ = 1/√(1 + (64/127)²).
fn tilt_cos() -> f64 {
    let x = 64.0 / 127.0;
    1.0 / (1.0f64 + x * x).sqrt()
}

/// A constant tilted normal map on a Lambertian floor under E = 1000 lx at normal incidence:
/// the light meets the shading normal at θ, so the luminance is E·ρ·cos θ/π (0.8 grey is a
/// constant spectrum).
#[test]
fn tilted_normal_map_gives_e_rho_cos_over_pi() {
    let dir = tempfile::tempdir().unwrap();
    png(dir.path(), "tilt.png", 2, 2, &[[192, 128, 255]; 4]);
    obj_floor(dir.path(), "Kd 0.8 0.8 0.8\nnorm tilt.png");
    let film = render_in(dir.path(), "floor.obj", SUN, 16);
    let (m, se) = common::image_mean(&film);
    let expected = 1000.0 * 0.8 * tilt_cos() / std::f64::consts::PI;
    eprintln!(
        "tilted normal map: {:.4} ± {se:.4}, E·ρ·cos θ/π = {expected:.4} cd/m²",
        m[1]
    );
    common::assert_estimate_near(m[1], se, expected, 0.01, "tilted normal map");
    // Not the untilted value (the test can fail).
    assert!((m[1] - expected / tilt_cos()).abs() > 10.0 * se);
}

/// White furnace: a white Lambertian floor with the tilted map under a uniform environment of
/// 1 cd/m². Of the cosine-weighted directions about the tilted normal, the fraction
/// (1 − cos θ)/2 lies below the geometric surface and carries nothing, so the floor returns
/// (1 + cos θ)/2 cd/m²: less than 1 (no gain) and no light from under the floor.
#[test]
fn normal_mapped_white_furnace_has_no_gain() {
    let dir = tempfile::tempdir().unwrap();
    png(dir.path(), "tilt.png", 2, 2, &[[192, 128, 255]; 4]);
    obj_floor(dir.path(), "Kd 1 1 1\nnorm tilt.png");
    let env = r#"Environment(spectrum: Named("E"), amount: Luminance(1.0))"#;
    let film = render_in(dir.path(), "floor.obj", env, 64);
    let (m, se) = common::image_mean(&film);
    let expected = (1.0 + tilt_cos()) / 2.0;
    eprintln!(
        "normal-mapped furnace: {:.5} ± {se:.5}, (1 + cos θ)/2 = {expected:.5}",
        m[1]
    );
    common::assert_estimate_near(m[1], se, expected, 0.01, "normal-mapped furnace");
    assert!(m[1] < 1.0 - 5.0 * se, "gain: {} ± {se}", m[1]);
}

/// A missing metallic-roughness image, a missing OBJ normal map: errors naming the file.
#[test]
fn missing_maps_are_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut p = pbr([0.5; 3], 0.0, 0.5);
    p["metallicRoughnessTexture"] = json!({"index": 0});
    gltf_floor(
        dir.path(),
        "m.gltf",
        json!({"pbrMetallicRoughness": p}),
        &["gone-mr.png"],
    );
    let mut n = json!({"pbrMetallicRoughness": pbr([0.5; 3], 0.0, 1.0)});
    n["normalTexture"] = json!({"index": 0});
    gltf_floor(dir.path(), "n.gltf", n, &["gone-normal.png"]);
    obj_floor(dir.path(), "Kd 0.5 0.5 0.5\nnorm gone-norm.png");
    for (file, name) in [
        ("m.gltf", "gone-mr.png"),
        ("n.gltf", "gone-normal.png"),
        ("floor.obj", "gone-norm.png"),
    ] {
        let path = dir.path().join("scene.ron");
        std::fs::write(&path, floor_scene(file, SUN, 1)).unwrap();
        let e = match candela::scene::load_world(&path, &Default::default()) {
            Ok(_) => panic!("{file}: a missing {name} was accepted"),
            Err(e) => e.to_string(),
        };
        assert!(e.contains(name), "{file}: {e}");
    }
}
