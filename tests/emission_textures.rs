//! Emission textures: a 2 m × 2 m emitter whose left half is one colour and right half another
//! (a 256-texel-wide image, so bilinear filtering blends only a 1 cm strip) lights two meters
//! 2 m below it with E = π Σ L_i F_i, F the point-to-parallel-rectangle configuration factors —
//! the same from a scene `Texture` emission, glTF's `emissiveTexture` × `emissiveFactor` ×
//! `emissive_strength` and OBJ's `map_Ke` × `Ke` × `ke_luminance`; a one-colour texture renders
//! as the untextured `Rgb` emitter of that colour (to rounding, same seed); sampled points carry
//! the texture coordinates a hit there reports; bad input is a clear error.

mod common;
use candela::geometry::{SceneGeometry, Shape, TriangleMesh};
use candela::meter::measure_all;
use glam::{Vec2, Vec3};
use serde_json::json;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

/// Point under a corner of an a × b rectangle parallel to the receiver at height h.
fn f_corner(a: f64, b: f64, h: f64) -> f64 {
    let (x, y) = (a / h, b / h);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
}

fn srgb_decode(v: u8) -> f64 {
    let c = v as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn luma(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

const A: [u8; 3] = [255, 128, 64];
const B: [u8; 3] = [20, 60, 200];

/// The two-colour image, 256 × 4: columns 0–127 `A`, 128–255 `B`.
fn halves_png(dir: &Path, name: &str) {
    let mut img = image::RgbImage::new(256, 4);
    for (x, _, p) in img.enumerate_pixels_mut() {
        p.0 = if x < 128 { A } else { B };
    }
    img.save(dir.join(name)).unwrap();
}

fn dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Scene with the emitter object `emitter` and meters at x = −0.5 (under the `A` half's
/// middle) and x = +0.5, 2 m below the emitter, facing it.
fn meters_scene(emitter: &str) -> String {
    format!(
        r#"(
        camera: (position: (0, -5, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 10, resolution: (1, 1)),
        render: (spp: 1, max_depth: 1),
        objects: [{emitter}],
        meters: [Illuminance(name: "a", position: (-0.5, 0, 0), normal: (0, 1, 0)),
                 Illuminance(name: "b", position: (0.5, 0, 0), normal: (0, 1, 0))],
        measure: (samples: 16384),
    )"#
    )
}

/// Checks both meters against π(L_near F_near + L_far F_far) for halves of luminance `la`, `lb`.
fn check_meters(w: &candela::world::World, la: f64, lb: f64, label: &str) {
    // Under the middle of one half (1 m × 2 m at h = 2): four 0.5 × 1 corner rectangles; the
    // other half spans 0.5 … 1.5 m across.
    let near = 4.0 * f_corner(0.5, 1.0, 2.0);
    let far = 2.0 * (f_corner(1.5, 1.0, 2.0) - f_corner(0.5, 1.0, 2.0));
    let m = measure_all(w);
    for (e, want) in [
        (m.meters[0], PI * (la * near + lb * far)),
        (m.meters[1], PI * (lb * near + la * far)),
    ] {
        assert!(
            (e.mean - want).abs() <= 4.5 * e.stderr && e.stderr < 0.005 * want,
            "{label}: E = {} ± {}, expected {want}",
            e.mean,
            e.stderr
        );
    }
}

#[test]
fn configuration_factor_matches_the_tabulated_case() {
    assert!((f_corner(1.0, 2.0, 3.0) - 0.0522678).abs() < 1e-7);
}

#[test]
fn scene_texture_emission_lights_meters_by_the_configuration_factor() {
    let d = dir("emission_textures_scene");
    halves_png(&d, "halves.png");
    let l = 1500.0;
    let w = common::world_in(
        &meters_scene(
            r#"(shape: Quad(origin: (-1, 2, -1), edge_u: (2, 0, 0), edge_v: (0, 0, 2)), material: "black",
                emission: (spectrum: Texture(file: "halves.png", wrap: Clamp), amount: Luminance(1500.0)))"#,
        ),
        &d,
    );
    let (la, lb) = (l * luma(A.map(srgb_decode)), l * luma(B.map(srgb_decode)));
    check_meters(&w, la, lb, "scene texture");
}

#[test]
fn gltf_emissive_texture_multiplies_factor_and_strength() {
    let d = dir("emission_textures_gltf");
    halves_png(&d, "halves.png");
    // The emitter facing −Y at y = 2; u = (x + 1)/2 (v is uniform in the image).
    let pos = [
        [-1.0, 2.0, -1.0],
        [1.0, 2.0, -1.0],
        [1.0, 2.0, 1.0],
        [-1.0, 2.0, 1.0],
    ];
    let factor = [1.0, 0.8, 0.5];
    let strength = 2000.0;
    let extra = json!({
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "materials": [{
            "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0},
            "emissiveFactor": factor,
            "emissiveTexture": {"index": 0},
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}
        }],
        "images": [{"uri": "halves.png"}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"wrapS": 33071, "wrapT": 33071}],
    });
    common::gltf_quad(&d, "panel.gltf", pos, [0, 1, 2, 0, 2, 3], extra);
    let w = common::world_in(
        &meters_scene(r#"(shape: Model(file: "panel.gltf"), material: "black")"#),
        &d,
    );
    let tinted = |c: [u8; 3]| {
        let c = c.map(srgb_decode);
        strength * luma([c[0] * factor[0], c[1] * factor[1], c[2] * factor[2]])
    };
    check_meters(&w, tinted(A), tinted(B), "glTF emissiveTexture");
}

#[test]
fn obj_map_ke_multiplies_ke_and_ke_luminance() {
    let d = dir("emission_textures_obj");
    halves_png(&d, "halves.png");
    std::fs::write(
        d.join("panel.obj"),
        "mtllib panel.mtl\nv -1 2 -1\nv 1 2 -1\nv 1 2 1\nv -1 2 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
         usemtl sign\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    )
    .unwrap();
    std::fs::write(
        d.join("panel.mtl"),
        "newmtl sign\nKd 0 0 0\nKe 0.5 1 1\nmap_Ke -clamp on halves.png\n",
    )
    .unwrap();
    let l = 3000.0;
    let w = common::world_in(
        &meters_scene(
            r#"(shape: Model(file: "panel.obj", ke_luminance: 3000.0), material: "black")"#,
        ),
        &d,
    );
    let ke = [0.5, 1.0, 1.0];
    let tinted = |c: [u8; 3]| {
        let c = c.map(srgb_decode);
        l * luma([c[0] * ke[0], c[1] * ke[1], c[2] * ke[2]])
    };
    check_meters(&w, tinted(A), tinted(B), "OBJ map_Ke");
}

/// A one-colour texture is the untextured `Rgb` emitter of that colour at the luminance of its
/// texels: seen directly (same seed, same wavelengths per sample), every pixel's X, Y and Z
/// agree to single-precision rounding.
#[test]
fn one_colour_texture_renders_as_the_rgb_emitter() {
    let d = dir("emission_textures_uniform");
    let c = [200u8, 90, 30];
    let mut img = image::RgbImage::new(4, 4);
    for p in img.pixels_mut() {
        p.0 = c;
    }
    img.save(d.join("one.png")).unwrap();
    let lin = c.map(srgb_decode);
    let peak = lin.iter().copied().fold(0.0, f64::max);
    let l = 800.0;
    let scene = |emission: &str| {
        format!(
            r#"(
        camera: (position: (0, 0, 0), look_at: (0, 2, 0), up: (0, 0, 1), vfov_deg: 40, resolution: (8, 8)),
        render: (spp: 16, max_depth: 1),
        objects: [(shape: Quad(origin: (-1, 2, -1), edge_u: (2, 0, 0), edge_v: (0, 0, 2)), material: "black",
                   emission: {emission})],
    )"#
        )
    };
    let textured = common::world_in(
        &scene(&format!(
            "(spectrum: Texture(file: \"one.png\"), amount: Luminance({l}))"
        )),
        &d,
    );
    let plain = common::world_in(
        &scene(&format!(
            "(spectrum: Rgb({}, {}, {}), amount: Luminance({}))",
            lin[0] / peak,
            lin[1] / peak,
            lin[2] / peak,
            l * luma(lin)
        )),
        &d,
    );
    let (a, b) = (common::render(&textured, 1), common::render(&plain, 1));
    let (ma, _) = common::image_mean(&a);
    let (mb, _) = common::image_mean(&b);
    for k in 0..3 {
        assert!(
            (ma[k] - mb[k]).abs() < 2e-5 * mb[k],
            "channel {k}: {} vs {}",
            ma[k],
            mb[k]
        );
    }
    // And the luminance is the texel's: within the noise of the spectral sampling.
    assert!(
        (ma[1] - l * luma(lin)).abs() < 0.05 * l * luma(lin),
        "{} vs {}",
        ma[1],
        l * luma(lin)
    );
}

/// Points sampled on each kind of primitive report the texture coordinates that a ray hitting
/// them there reports.
#[test]
fn sampled_points_carry_the_hits_texture_coordinates() {
    let mesh = TriangleMesh {
        positions: vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.5),
        ],
        normals: None,
        indices: vec![[0, 1, 2]],
    };
    let uvs = [
        Vec2::new(0.1, 0.2),
        Vec2::new(0.9, 0.3),
        Vec2::new(0.4, 0.8),
    ];
    let shapes = vec![
        (Shape::Mesh(mesh.clone()), 0),
        (Shape::Mesh(mesh), 1),
        (
            Shape::Quad {
                origin: Vec3::new(3.0, 0.0, 0.0),
                edge_u: Vec3::new(1.0, 0.0, 0.0),
                edge_v: Vec3::new(0.0, 2.0, 0.0),
            },
            2,
        ),
        (
            Shape::Sphere {
                center: Vec3::new(-3.0, 0.0, 0.0),
                radius: 0.7,
            },
            3,
        ),
        (
            Shape::Disk {
                center: Vec3::new(0.0, 5.0, 0.0),
                normal: Vec3::new(0.3, 0.2, 1.0),
                radius: 0.8,
            },
            4,
        ),
    ];
    // The second triangle is shifted so the two meshes do not overlap.
    let mut shapes = shapes;
    if let Shape::Mesh(m) = &mut shapes[1].0 {
        for p in &mut m.positions {
            *p += Vec3::new(0.0, 0.0, 3.0);
        }
    }
    let g = SceneGeometry::build_with_uvs(&shapes, &[Some(&uvs[..]), None]).unwrap();
    let mut checked = 0;
    for object in 0..5u32 {
        for &prim in g.primitives_of_object(object) {
            for k in 0..64 {
                let u = Vec2::new(
                    ((k * 37 % 64) as f32 + 0.5) / 64.0,
                    ((k * 11 % 64) as f32 + 0.5) / 64.0,
                );
                let sp = g.sample_prim(prim, u);
                let origin = sp.p + sp.n * 0.25;
                let hit = g.intersect(origin, -sp.n, 1.0).expect("the point is hit");
                assert_eq!(hit.object, object);
                assert!(
                    (hit.tex - sp.tex).length() < 2e-4,
                    "object {object}, u {u}: sampled {} vs hit {}",
                    sp.tex,
                    hit.tex
                );
                // The solid-angle sampler reports the same coordinates.
                if let Some((sa, _)) = g.sample_prim_solid_angle(prim, origin + sp.n, u) {
                    if !matches!(shapes[object as usize].0, Shape::Sphere { .. }) {
                        assert_eq!(sa.tex, sp.tex);
                    }
                }
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 5 * 64);
}

#[test]
fn bad_emission_textures_are_clear_errors() {
    let d = dir("emission_textures_bad");
    halves_png(&d, "halves.png");
    let err = |emission: &str| -> String {
        let text = format!(
            r#"(
        camera: (position: (0, 0, 0), look_at: (0, 2, 0), up: (0, 0, 1), vfov_deg: 40, resolution: (8, 8)),
        objects: [(name: "sign", shape: Quad(origin: (-1, 2, -1), edge_u: (2, 0, 0), edge_v: (0, 0, 2)), material: "black",
                   emission: {emission})],
    )"#
        );
        let path = d.join("bad.ron");
        std::fs::write(&path, text).unwrap();
        match candela::scene::load_world(&path, &candela::scene::Overrides::default()) {
            Ok(_) => panic!("{emission} was accepted"),
            Err(e) => e.to_string(),
        }
    };
    let e = err(r#"(spectrum: Texture(file: "missing.png"), amount: Luminance(100.0))"#);
    assert!(
        e.contains("missing.png") && e.contains("emission.spectrum"),
        "{e}"
    );
    let e = err(r#"(spectrum: Texture(file: "halves.png"), amount: Flux(100.0))"#);
    assert!(
        e.contains("emission.amount") && e.contains("Luminance"),
        "{e}"
    );
    let e = err(r#"(spectrum: Texture(file: "halves.png"), amount: Luminance(-1.0))"#);
    assert!(e.contains("emission.amount"), "{e}");
    let e = err(
        r#"(spectrum: Texture(file: "halves.png", uv_scale: (1, inf)), amount: Luminance(1.0))"#,
    );
    assert!(e.contains("uv_scale"), "{e}");
    std::fs::write(d.join("zero.png"), b"").unwrap();
    let e = err(r#"(spectrum: Texture(file: "zero.png"), amount: Luminance(1.0))"#);
    assert!(e.contains("zero.png"), "{e}");
}

/// Light tracing evaluates the texture where its paths start: a two-colour emitter facing a
/// mirror lights the floor beside it only through the mirror (light → mirror → floor → eye),
/// and the light-traced image agrees block by block with the path tracer's, which sees the
/// emitter's texels where its rays hit them.
#[test]
fn light_tracing_starts_paths_with_the_texels_radiance() {
    let d = dir("emission_textures_light_tracing");
    halves_png(&d, "halves.png");
    let text = r#"(
        camera: (position: (1.2, 0.9, 0.0), look_at: (1.2, 0, 0), up: (0, 0, 1), vfov_deg: 60, resolution: (16, 16)),
        render: (spp: 256, max_depth: 2, light_paths_per_sample: 4, caustics: CAUSTICS),
        materials: {
            "floor": Diffuse(reflectance: Constant(0.5)),
            "mirror": Conductor(n: Constant(0.2), k: Constant(3.0)),
        },
        objects: [
            (shape: Quad(origin: (-50, 0, -50), edge_u: (0, 0, 100), edge_v: (100, 0, 0)), material: "floor"),
            (shape: Quad(origin: (-50, 1, -50), edge_u: (100, 0, 0), edge_v: (0, 0, 100)), material: "mirror"),
            (shape: Quad(origin: (-0.5, 0.4, -0.5), edge_u: (0, 0, 1), edge_v: (1, 0, 0)), material: "black",
             emission: (spectrum: Texture(file: "halves.png", wrap: Clamp), amount: Luminance(5000.0))),
        ],
    )"#;
    let lt = common::world_in(&text.replace("CAUSTICS", "LightTracing"), &d);
    let pt = common::world_in(&text.replace("CAUSTICS", "PathTracing"), &d);
    assert!(lt.caustics.is_some() && pt.caustics.is_none());
    let (a, b) = (common::render(&lt, 2), common::render(&pt, 2));
    common::assert_blocks_agree(&a, &b, 4, ("light tracing", "path tracing"));
    // The floor is lit: the comparison is not of two black images. Its brightest block is
    // under the bright half's mirror image (z < 0 is image right).
    let blocks = common::block_means(&a, 8);
    assert!(blocks.iter().all(|(m, se)| *m > 20.0 * se), "{blocks:?}");
}
