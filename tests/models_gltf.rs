//! glTF 2.0 models: the Cornell box written as glTF renders as the RON scene, punctual lights
//! give their photometric values (cd, lx) exactly, emissive materials are seen at their
//! luminance, `.gltf` and `.glb` hold the same model, and bad files end in clear errors.

mod common;
use candela::meter::measure_all;
use serde_json::{json, Value};
use std::path::Path;

/// A triangle mesh to write: positions, triangle indices, optional texture coordinates.
struct Mesh {
    positions: Vec<[f32; 3]>,
    indices: Vec<u32>,
    uvs: Option<Vec<[f32; 2]>>,
    material: Option<usize>,
}

/// A glTF document to write: `meshes` become glTF meshes 0.., and `json` holds everything
/// else (nodes, scenes, materials, extensions); buffers, views and accessors are added.
struct Doc {
    meshes: Vec<Mesh>,
    json: Value,
}

/// Writes `doc` as `name` in `dir`: a `.glb` (JSON and BIN chunks) or a `.gltf` with its
/// buffer in `name.bin`.
fn write(doc: &Doc, dir: &Path, name: &str) {
    let mut bin: Vec<u8> = Vec::new();
    let (mut views, mut accessors, mut meshes) = (vec![], vec![], vec![]);
    let mut add = |bin: &mut Vec<u8>, bytes: Vec<u8>, acc: Value| -> usize {
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
        bin.extend(bytes);
        let mut acc = acc;
        acc["bufferView"] = json!(views.len() - 1);
        accessors.push(acc);
        accessors.len() - 1
    };
    for m in &doc.meshes {
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for p in &m.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let f = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        let pos = add(
            &mut bin,
            f(&m.positions.concat()),
            json!({"componentType": 5126, "count": m.positions.len(), "type": "VEC3", "min": lo, "max": hi}),
        );
        let idx = add(
            &mut bin,
            m.indices.iter().flat_map(|x| x.to_le_bytes()).collect(),
            json!({"componentType": 5125, "count": m.indices.len(), "type": "SCALAR"}),
        );
        let mut attrs = json!({"POSITION": pos});
        if let Some(uv) = &m.uvs {
            attrs["TEXCOORD_0"] = json!(add(
                &mut bin,
                f(&uv.concat()),
                json!({"componentType": 5126, "count": uv.len(), "type": "VEC2"}),
            ));
        }
        let mut prim = json!({"attributes": attrs, "indices": idx});
        if let Some(mat) = m.material {
            prim["material"] = json!(mat);
        }
        meshes.push(json!({"primitives": [prim]}));
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let mut j = doc.json.clone();
    j["asset"] = json!({"version": "2.0"});
    j["meshes"] = json!(meshes);
    j["bufferViews"] = json!(views);
    j["accessors"] = json!(accessors);
    if name.ends_with(".glb") {
        j["buffers"] = json!([{"byteLength": bin.len()}]);
        std::fs::write(dir.join(name), common::glb(&j, &bin)).unwrap();
    } else {
        let bin_name = format!("{name}.bin");
        j["buffers"] = json!([{"byteLength": bin.len(), "uri": bin_name}]);
        std::fs::write(dir.join(&bin_name), &bin).unwrap();
        std::fs::write(dir.join(name), serde_json::to_vec_pretty(&j).unwrap()).unwrap();
    }
}

/// The Cornell box scene file with a small film.
fn cornell_text() -> String {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box.ron"),
    )
    .unwrap();
    let small = text
        .replace("resolution: (256, 256)", "resolution: (48, 48)")
        .replace("spp: 64", "spp: 128");
    assert_ne!(small, text);
    small
}

/// Offset of the Cornell glTF's parent node: its meshes are written relative to it, so the
/// box is only in place if the node hierarchy's transforms are composed.
const PARENT: [f32; 3] = [100.0, -20.0, 5.0];

/// The Cornell box's triangle objects as a glTF document: one mesh per object under a parent
/// node translated by [`PARENT`] (each mesh's node is scaled by 2 and its positions halved, so
/// the child transforms matter too), materials named by wall colour, the blocks a fourth.
fn cornell_doc() -> Doc {
    let text = cornell_text();
    let scene = candela::scene::parse(&text, Path::new("cornell.ron")).unwrap();
    let names = ["Wall_White", "Wall_Red", "Wall_Green", "Block"];
    let mut meshes = Vec::new();
    for o in &scene.objects {
        let candela::description::schema::ShapeDesc::Triangles {
            positions, indices, ..
        } = &o.shape
        else {
            continue;
        };
        let name = o.name.as_deref().unwrap();
        let mat = match o.material.as_str() {
            _ if name.contains("block") => 3,
            "white" => 0,
            "red" => 1,
            "green" => 2,
            m => panic!("unexpected material {m}"),
        };
        meshes.push(Mesh {
            positions: positions
                .iter()
                .map(|p| std::array::from_fn(|k| (p[k] - PARENT[k]) / 2.0))
                .collect(),
            indices: indices.iter().flatten().copied().collect(),
            uvs: None,
            material: Some(mat),
        });
    }
    let children: Vec<usize> = (1..=meshes.len()).collect();
    let mut nodes = vec![json!({"translation": PARENT, "children": children})];
    for i in 0..meshes.len() {
        nodes.push(json!({"mesh": i, "scale": [2.0, 2.0, 2.0]}));
    }
    let materials: Vec<Value> = names
        .iter()
        .map(|n| json!({"name": n, "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}))
        .collect();
    Doc {
        meshes,
        json: json!({"scene": 0, "scenes": [{"nodes": [0]}], "nodes": nodes, "materials": materials}),
    }
}

/// The Cornell scene with its triangle objects replaced by the model `file` whose materials
/// are the RON ones, by name.
fn cornell_with_model(file: &str) -> String {
    let text = cornell_text();
    let start = text.find("objects: [").unwrap() + "objects: [".len();
    let end = text.find("// The light:").unwrap();
    format!(
        "{}\n        (name: \"box\", shape: Model(file: \"{file}\", materials_from_file: {{\n            \"Wall_White\": Named(\"white\"), \"Wall_Red\": Named(\"red\"), \"Wall_Green\": Named(\"green\"),\n            \"Block\": Material(Diffuse(reflectance: Named(\"cornell-white\"))),\n        }})),\n        {}",
        &text[..start],
        &text[end..]
    )
}

/// The Cornell box written as a `.glb` (nested node transforms) with the RON spectra given by
/// name renders the same image as the RON scene: every 6×6-pixel block agrees within 4.5
/// combined standard errors (64 blocks: a false alarm has probability 4·10⁻⁴), and so does the
/// image mean. The same model as `.gltf` + `.bin` loads to the same triangles.
#[test]
fn cornell_box_from_gltf_renders_as_the_ron_scene() {
    let dir = tempfile::tempdir().unwrap();
    let doc = cornell_doc();
    write(&doc, dir.path(), "cornell.glb");
    write(&doc, dir.path(), "cornell.gltf");
    let glb = candela::geometry::gltf::load_gltf(&dir.path().join("cornell.glb")).unwrap();
    let gltf = candela::geometry::gltf::load_gltf(&dir.path().join("cornell.gltf")).unwrap();
    assert_eq!(glb.meshes.len(), doc.meshes.len());
    assert_eq!(glb.instances.len(), doc.meshes.len());
    for (a, b) in glb.meshes.iter().zip(&gltf.meshes) {
        assert_eq!(
            a.primitives[0].mesh.positions,
            b.primitives[0].mesh.positions
        );
        assert_eq!(a.primitives[0].mesh.indices, b.primitives[0].mesh.indices);
    }
    let ron = common::world_in(&cornell_text(), dir.path());
    let model = common::world_in(
        &cornell_with_model("cornell.glb").replace("seed: 0", "seed: 7"),
        dir.path(),
    );
    assert_eq!(model.objects.len(), ron.objects.len());
    let (a, b) = (common::render(&ron, 1), common::render(&model, 1));
    let worst = common::assert_blocks_agree(&a, &b, 6, ("RON", "glTF"));
    let ((ya, sa), (yb, sb)) = (common::image_mean(&a), common::image_mean(&b));
    let z = (ya[1] - yb[1]) / (sa.powi(2) + sb.powi(2)).sqrt();
    eprintln!(
        "Cornell glTF vs RON: image mean Y {:.3} vs {:.3} cd/m² (z = {z:.2}), worst block |z| = {worst:.2}",
        ya[1], yb[1]
    );
    assert!(z.abs() < 4.0 && sa < 0.01 * ya[1]);
}

/// A 4 m × 4 m floor quad at y = 0 (normal +Y), material 0.
fn floor() -> Mesh {
    Mesh {
        positions: vec![
            [-2.0, 0.0, -2.0],
            [2.0, 0.0, -2.0],
            [2.0, 0.0, 2.0],
            [-2.0, 0.0, 2.0],
        ],
        indices: vec![0, 2, 1, 0, 3, 2],
        uvs: Some(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
        material: Some(0),
    }
}

/// A quaternion (x, y, z, w) turning the node's −Z (where glTF lights point) to −Y.
const POINT_DOWN: [f32; 4] = [
    -std::f32::consts::FRAC_1_SQRT_2,
    0.0,
    0.0,
    std::f32::consts::FRAC_1_SQRT_2,
];

/// A scene with the glTF model `file` (its lights on) and meters `meters`.
fn light_scene(file: &str, meters: &str) -> String {
    format!(
        r#"(
    camera: (position: (0, 5, 0.01), look_at: (0, 0, 0), vfov_deg: 60, resolution: (4, 4)),
    render: (spp: 1),
    objects: [(shape: Model(file: "{file}", lights: true, materials_from_file: {{ "floor": Material(Black) }}))],
    meters: [{meters}],
    measure: (samples: 64),
)"#
    )
}

/// glTF punctual lights keep their photometric values: a point light of 100 cd 2 m above a
/// meter gives 100/2² = 25 lx, a spot of 100 cd on its axis the same, and a directional light
/// of 40 lx gives 40 lx on a surface facing it (exact: the floor is black and nothing else is
/// there; the estimates' only noise is the wavelength sampling).
#[test]
fn punctual_lights_give_their_photometric_values() {
    let dir = tempfile::tempdir().unwrap();
    let floor_mat = json!([{"name": "floor", "pbrMetallicRoughness": {"metallicFactor": 0.0}}]);
    let cases: [(Value, f64); 4] = [
        (json!({"type": "point", "intensity": 100.0}), 25.0),
        (
            json!({"type": "point", "intensity": 100.0, "color": [1.0, 0.5, 0.25]}),
            25.0 * (0.2126 + 0.7152 * 0.5 + 0.0722 * 0.25),
        ),
        (
            json!({"type": "spot", "intensity": 100.0, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}}),
            25.0,
        ),
        (json!({"type": "directional", "intensity": 40.0}), 40.0),
    ];
    for (k, (light, want)) in cases.iter().enumerate() {
        let doc = Doc {
            meshes: vec![floor()],
            json: json!({
                "extensionsUsed": ["KHR_lights_punctual"],
                "extensions": {"KHR_lights_punctual": {"lights": [light]}},
                "nodes": [{"mesh": 0}, {"translation": [0.5, 2.0, 0.0], "rotation": POINT_DOWN, "extensions": {"KHR_lights_punctual": {"light": 0}}}],
                "scenes": [{"nodes": [0, 1]}],
                "materials": floor_mat,
            }),
        };
        let name = if k % 2 == 0 { "l.glb" } else { "l.gltf" };
        write(&doc, dir.path(), name);
        let w = common::world_in(
            &light_scene(
                name,
                r#"Illuminance(name: "m", position: (0.5, 0.0, 0.0), normal: (0, 1, 0))"#,
            ),
            dir.path(),
        );
        let e = measure_all(&w).meters[0];
        eprintln!("{light}: {} ± {} lx, expected {want}", e.mean, e.stderr);
        assert!(
            (e.mean - want).abs() <= 5.0 * e.stderr.max(1e-9 * want) && e.stderr < 0.01 * want,
            "{light}: {} ± {} lx, expected {want}",
            e.mean,
            e.stderr
        );
    }
    // The object's transform moves the model's lights with it: the point light of the last
    // .gltf moved 1 m along z is √5 m from the meter, 2 m above it: E = I·cos θ/d² = 100·(2/√5)/5.
    write(
        &Doc {
            meshes: vec![floor()],
            json: json!({
                "extensionsUsed": ["KHR_lights_punctual"],
                "extensions": {"KHR_lights_punctual": {"lights": [cases[0].0]}},
                "nodes": [{"mesh": 0}, {"translation": [0.5, 2.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
                "scenes": [{"nodes": [0, 1]}],
                "materials": floor_mat,
            }),
        },
        dir.path(),
        "l.gltf",
    );
    let text = light_scene(
        "l.gltf",
        r#"Illuminance(name: "m", position: (0.5, 0.001, 0.0), normal: (0, 1, 0))"#,
    )
    .replace("}))],", "}), transform: (translate: (0, 0, 1)))],");
    let e = measure_all(&common::world_in(&text, dir.path())).meters[0];
    let want = 100.0 * (2.0 / 5f64.sqrt()) / 5.0;
    eprintln!(
        "moved point light: {} ± {} lx, expected {want}",
        e.mean, e.stderr
    );
    assert!((e.mean - want).abs() <= 5.0 * e.stderr && e.stderr < 0.01 * want);
    // Without `lights: true` the file's lights are left out.
    let text = light_scene(
        "l.gltf",
        r#"Illuminance(name: "m", position: (0.5, 0.0, 0.0), normal: (0, 1, 0))"#,
    )
    .replace("lights: true, ", "");
    let w = common::world_in(&text, dir.path());
    assert!(w.lights.is_empty());
}

/// An emissive material of `emissiveFactor` c and `emissive_strength` s is seen by a camera at
/// luminance s·(0.2126 r + 0.7152 g + 0.0722 b) cd/m² in every pixel (the emitter fills the
/// view; nothing else lights the scene).
#[test]
fn emissive_material_is_seen_at_its_luminance() {
    let dir = tempfile::tempdir().unwrap();
    for (c, s) in [([1.0, 1.0, 1.0], 50.0), ([1.0, 0.5, 0.25], 200.0)] {
        let doc = Doc {
            meshes: vec![floor()],
            json: json!({
                "extensionsUsed": ["KHR_materials_emissive_strength"],
                "nodes": [{"mesh": 0}],
                "materials": [{"name": "panel", "emissiveFactor": c,
                    "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0.0},
                    "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": s}}}],
            }),
        };
        write(&doc, dir.path(), "e.glb");
        let text = r#"(
    camera: (position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 60, resolution: (8, 8)),
    render: (spp: 64),
    objects: [(shape: Model(file: "e.glb"))],
    meters: [Luminance(name: "l", position: (0.3, 1, 0.2), direction: (0, -1, 0), half_angle_deg: 5)],
)"#;
        let w = common::world_in(text, dir.path());
        let want = s * (0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]);
        common::assert_every_pixel(&common::render(&w, 1), want, 5.0);
        let m = measure_all(&w).meters[0];
        eprintln!(
            "emissive {c:?} × {s}: meter {} ± {}, expected {want} cd/m²",
            m.mean, m.stderr
        );
        assert!(
            (m.mean - want).abs() <= 5.0 * m.stderr.max(1e-9 * want) && m.stderr < 0.01 * want,
            "{} ± {} vs {want}",
            m.mean,
            m.stderr
        );
    }
}

/// `candela render` of a one-model scene (`file`) in `dir`: (exit code, stderr).
fn render_cli(dir: &Path, file: &str) -> (i32, String) {
    let scene = format!(
        r#"(
    camera: (position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 90, resolution: (4, 4)),
    render: (spp: 1),
    objects: [(name: "room", shape: Model(file: "{file}"))],
    lights: [Distant(direction: (0, -1, 0), spectrum: Named("D65"), amount: Illuminance(1000.0))],
)"#
    );
    std::fs::write(dir.join("scene.ron"), scene).unwrap();
    let (code, _, stderr) = common::cli(&["render", "--quiet", "--out", "out", "scene.ron"], dir);
    assert!(!stderr.contains("panicked"), "{stderr}");
    (code, stderr)
}

/// A one-floor document with a base-colour texture `uri`.
fn textured(uri: &str) -> Doc {
    Doc {
        meshes: vec![floor()],
        json: json!({
            "nodes": [{"mesh": 0}],
            "materials": [{"name": "floor", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0}}],
            "textures": [{"source": 0}],
            "images": [{"uri": uri}],
        }),
    }
}

/// Bad glTF input: each case ends with exit code 1 and a message naming the file and what is
/// wrong, without a panic or an allocation of the size the file claims.
#[test]
fn bad_gltf_files_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let doc = || Doc {
        meshes: vec![floor()],
        json: json!({"nodes": [{"mesh": 0}], "materials": [{"name": "floor"}]}),
    };
    // Edits the JSON of `name` (a .gltf) in place.
    let edit = |name: &str, f: &dyn Fn(&mut Value)| {
        let mut j: Value = serde_json::from_slice(&std::fs::read(d.join(name)).unwrap()).unwrap();
        f(&mut j);
        std::fs::write(d.join(name), serde_json::to_vec(&j).unwrap()).unwrap();
    };
    type Case<'a> = (&'a str, Box<dyn Fn() -> &'static str + 'a>, Vec<&'a str>);
    let cases: Vec<Case> = vec![
        (
            "missing .bin",
            Box::new(|| {
                write(&doc(), d, "m.gltf");
                std::fs::remove_file(d.join("m.gltf.bin")).unwrap();
                "m.gltf"
            }),
            vec!["m.gltf", "m.gltf.bin", "buffer 0"],
        ),
        (
            "missing texture",
            Box::new(|| {
                write(&textured("nowhere.png"), d, "m.gltf");
                "m.gltf"
            }),
            vec!["m.gltf", "nowhere.png", "floor"],
        ),
        (
            "accessor past its buffer view",
            Box::new(|| {
                write(&doc(), d, "m.gltf");
                edit("m.gltf", &|j| j["accessors"][0]["count"] = json!(5));
                "m.gltf"
            }),
            vec![
                "m.gltf",
                "accessor 0 (mesh 0 primitive 0 POSITION)",
                "do not fit",
            ],
        ),
        (
            "accessor claiming 10⁶ elements",
            Box::new(|| {
                write(&doc(), d, "m.gltf");
                edit("m.gltf", &|j| j["accessors"][1]["count"] = json!(1_000_000));
                "m.gltf"
            }),
            vec!["m.gltf", "accessor 1 (indices)", "do not fit"],
        ),
        (
            // Refused before reading, by the memory check or the accessor check.
            "accessor claiming 10¹² elements",
            Box::new(|| {
                write(&doc(), d, "m.gltf");
                edit("m.gltf", &|j| {
                    j["accessors"][0]["count"] = json!(1_000_000_000_000u64)
                });
                "m.gltf"
            }),
            vec!["m.gltf", "memory"],
        ),
        (
            "index out of range",
            Box::new(|| {
                let mut m = doc();
                m.meshes[0].indices[4] = 7;
                write(&m, d, "m.gltf");
                "m.gltf"
            }),
            vec!["m.gltf", "triangle 1 refers to vertex 7", "4 vertices"],
        ),
        (
            "buffer view past its buffer",
            Box::new(|| {
                write(&doc(), d, "m.gltf");
                edit("m.gltf", &|j| {
                    j["bufferViews"][0]["byteLength"] = json!(4096)
                });
                "m.gltf"
            }),
            vec!["m.gltf", "buffer view 0", "past the end of buffer 0"],
        ),
        (
            "wrong GLB chunk length",
            Box::new(|| {
                write(&doc(), d, "m.glb");
                let mut b = std::fs::read(d.join("m.glb")).unwrap();
                let n = u32::from_le_bytes(b[12..16].try_into().unwrap());
                b[12..16].copy_from_slice(&(n + 400).to_le_bytes());
                std::fs::write(d.join("m.glb"), b).unwrap();
                "m.glb"
            }),
            vec!["m.glb", "not a valid glTF file"],
        ),
        (
            "GLB whose binary chunk is shorter than its buffer",
            Box::new(|| {
                write(&doc(), d, "m.glb");
                let b = std::fs::read(d.join("m.glb")).unwrap();
                let json_len = u32::from_le_bytes(b[12..16].try_into().unwrap()) as usize;
                let mut j: Value = serde_json::from_slice(&b[20..20 + json_len]).unwrap();
                j["buffers"][0]["byteLength"] = json!(1 << 30);
                let mut doc2 = serde_json::to_vec(&j).unwrap();
                while doc2.len() % 4 != 0 {
                    doc2.push(b' ');
                }
                let bin = &b[20 + json_len..];
                let mut out = b"glTF".to_vec();
                out.extend(2u32.to_le_bytes());
                out.extend(((12 + 8 + doc2.len() + bin.len()) as u32).to_le_bytes());
                out.extend((doc2.len() as u32).to_le_bytes());
                out.extend(b"JSON");
                out.extend(doc2);
                out.extend(bin);
                std::fs::write(d.join("m.glb"), out).unwrap();
                "m.glb"
            }),
            vec!["m.glb", "buffer 0 declares 1073741824 bytes"],
        ),
        (
            "/dev/zero as the model",
            Box::new(|| {
                let _ = std::fs::remove_file(d.join("z.glb"));
                std::os::unix::fs::symlink("/dev/zero", d.join("z.glb")).unwrap();
                "z.glb"
            }),
            vec!["z.glb", "not a regular file"],
        ),
        (
            "not JSON",
            Box::new(|| {
                std::fs::write(d.join("m.gltf"), b"solid cube\n").unwrap();
                "m.gltf"
            }),
            vec!["m.gltf", "not a valid glTF file"],
        ),
    ];
    for (what, setup, needles) in cases {
        let file = setup();
        let (code, stderr) = render_cli(d, file);
        assert_eq!(code, 1, "{what}: exit code {code}\n{stderr}");
        for n in needles {
            assert!(stderr.contains(n), "{what}: message lacks {n:?}:\n{stderr}");
        }
    }
    // An override naming no material of the file names the field and the file's materials.
    write(&doc(), d, "m.gltf");
    let path = d.join("scene.ron");
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "Model(file: \"m.gltf\")",
        "Model(file: \"m.gltf\", materials_from_file: { \"flor\": Material(Black) })",
    );
    std::fs::write(&path, text).unwrap();
    let (code, _, stderr) = common::cli(&["render", "--quiet", "--out", "out", "scene.ron"], d);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("materials_from_file[\"flor\"]") && stderr.contains("floor"),
        "{stderr}"
    );
    // `ke_luminance` is OBJ's; a glTF model's emission is already in cd/m².
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "materials_from_file: { \"flor\": Material(Black) }",
        "ke_luminance: 100.0",
    );
    std::fs::write(&path, text).unwrap();
    let (code, _, stderr) = common::cli(&["render", "--quiet", "--out", "out", "scene.ron"], d);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("shape.ke_luminance") && stderr.contains("OBJ"),
        "{stderr}"
    );
    // And the good model renders, as .gltf and .glb.
    for file in ["m.gltf", "m.glb"] {
        write(&doc(), d, file);
        let (code, stderr) = render_cli(d, file);
        assert_eq!(code, 0, "{file}: {stderr}");
    }
}

/// Luminous reflectance of a texel under D65: ∫ρ S ȳ / ∫S ȳ at 1 nm.
fn luminous_reflectance(t: &candela::texture::Texture, x: u32, y: u32) -> f64 {
    use candela::colour::tables::{cmfs, named_spectrum, Observer};
    let (s, c) = (named_spectrum("D65").unwrap(), cmfs(Observer::Cie1931_2));
    let (mut num, mut den) = (0.0, 0.0);
    for nm in 360..=830 {
        let w = s.value(nm as f64) * c.at(nm as f64)[1];
        num += t.texel_reflectance(x, y, nm as f64) * w;
        den += w;
    }
    num / den
}

/// A base-colour texture embedded as a data: URI, tinted by `baseColorFactor`, on a
/// Lambertian floor under a distant light of E = 1000 lx: mean luminance E·ρ̄/π, ρ̄ the mean
/// luminous reflectance of the tinted texels (the camera sees whole periods of the texture).
#[test]
fn textured_gltf_floor_mean_luminance_is_e_rho_over_pi() {
    let dir = tempfile::tempdir().unwrap();
    let mut raw = Vec::new();
    let mut state = 777u32;
    for _ in 0..16 * 3 {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        raw.push((state >> 24) as u8);
    }
    let mut png = Vec::new();
    image::RgbImage::from_raw(4, 4, raw)
        .unwrap()
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let b64 = {
        const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut s = String::new();
        for c in png.chunks(3) {
            let n = (c[0] as u32) << 16
                | (*c.get(1).unwrap_or(&0) as u32) << 8
                | *c.get(2).unwrap_or(&0) as u32;
            for k in 0..=c.len() {
                s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            }
        }
        s
    };
    let tint = [0.9f32, 0.8, 0.7];
    let mut doc = textured(&format!("data:image/png;base64,{b64}"));
    doc.json["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] =
        json!([0.9, 0.8, 0.7, 1.0]);
    // The floor's uv runs 0..1 over 4 m; scaled by 8 the camera's middle 2 m hold 4 periods.
    doc.json["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] =
        json!({"KHR_texture_transform": {"scale": [8.0, 8.0]}});
    write(&doc, dir.path(), "t.glb");
    let tex = candela::texture::Texture::decode(Path::new("t.png"), &png, tint).unwrap();
    let mut rho = 0.0;
    for y in 0..4 {
        for x in 0..4 {
            rho += luminous_reflectance(&tex, x, y) / 16.0;
        }
    }
    let text = r#"(
    camera: (position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 90, resolution: (32, 32)),
    render: (spp: 64, max_depth: 1),
    objects: [(shape: Model(file: "t.glb"))],
    lights: [Distant(direction: (0, -1, 0), spectrum: Named("D65"), amount: Illuminance(1000.0))],
)"#;
    let w = common::world_in(text, dir.path());
    assert!(w
        .materials
        .iter()
        .any(|m| matches!(m, candela::bxdf::Material::TexturedDiffuse(_))));
    let (m, se) = common::image_mean(&common::render(&w, 1));
    let expected = 1000.0 * rho / std::f64::consts::PI;
    eprintln!(
        "glTF texture: mean Y {:.4} ± {se:.4}, E·ρ̄/π = {expected:.4} cd/m²",
        m[1]
    );
    common::assert_estimate_near(m[1], se, expected, 0.01, "glTF texture");
}

/// The documented material rule: transmission → Dielectric, metallic → Conductor whose
/// normal-incidence reflectance is the base colour's spectrum, smooth → Coated, rough →
/// Diffuse of the upsampled base colour.
#[test]
fn gltf_materials_map_by_rule() {
    use candela::bxdf::Material;
    let dir = tempfile::tempdir().unwrap();
    let pbr = |c: [f64; 3], m: f64, r: f64| json!({"baseColorFactor": [c[0], c[1], c[2], 1.0], "metallicFactor": m, "roughnessFactor": r});
    let materials = json!([
        {"name": "glass", "pbrMetallicRoughness": pbr([1.0, 1.0, 1.0], 0.0, 0.0),
         "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0}, "KHR_materials_ior": {"ior": 1.7}}},
        {"name": "gold", "pbrMetallicRoughness": pbr([1.0, 0.766, 0.336], 1.0, 0.3)},
        {"name": "plastic", "pbrMetallicRoughness": pbr([0.2, 0.3, 0.6], 0.0, 0.2)},
        {"name": "paint", "pbrMetallicRoughness": pbr([0.63, 0.065, 0.05], 0.0, 0.9)},
    ]);
    let meshes = (0..4)
        .map(|i| {
            let mut f = floor();
            f.material = Some(i);
            f
        })
        .collect();
    let nodes: Vec<Value> = (0..4)
        .map(|i| json!({"mesh": i, "translation": [0.0, i as f64, 0.0]}))
        .collect();
    let doc = Doc {
        meshes,
        json: json!({"nodes": nodes, "materials": materials,
            "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior"]}),
    };
    write(&doc, dir.path(), "m.glb");
    let text = r#"(
    camera: (position: (0, 9, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 60, resolution: (4, 4)),
    render: (spp: 1),
    objects: [(shape: Model(file: "m.glb"))],
    lights: [Distant(direction: (0, -1, 0), spectrum: Named("D65"), amount: Illuminance(1000.0))],
)"#;
    let w = common::world_in(text, dir.path());
    let mats: Vec<&Material> = w
        .objects
        .iter()
        .map(|o| &w.materials[o.material as usize])
        .collect();
    assert!(matches!(mats[0], Material::Dielectric(_)), "{:?}", mats[0]);
    assert!(matches!(mats[1], Material::Conductor(_)), "{:?}", mats[1]);
    assert!(matches!(mats[2], Material::Coated(_)), "{:?}", mats[2]);
    let Material::Diffuse(d) = mats[3] else {
        panic!("{:?}", mats[3])
    };
    let (fit, _) = candela::spectrum::rgb_upsample::fit_linear_srgb([0.63, 0.065, 0.05]).unwrap();
    for nm in [400.0, 500.0, 600.0, 700.0] {
        assert!((d.reflectance.value(nm) as f64 - fit.value(nm as f64)).abs() < 1e-6);
    }
}

/// The shipped furnished room keeps its shared chair mesh once, placed by four nodes whose
/// world transforms compose the parent's translation with each chair's own, and its floor
/// texture is embedded.
#[test]
fn furnished_room_keeps_shared_meshes_once() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/furnished-room.glb");
    let m = candela::geometry::gltf::load_gltf(&path).unwrap();
    let chair = m
        .meshes
        .iter()
        .position(|x| x.name.as_deref() == Some("chair"))
        .unwrap();
    let placed: Vec<_> = m.instances.iter().filter(|i| i.mesh == chair).collect();
    assert_eq!(placed.len(), 4);
    let first = placed[0].world.transform_point3(glam::Vec3::ZERO);
    assert!(
        (first - glam::Vec3::new(2.2, 0.0, 2.3)).length() < 1e-5,
        "{first}"
    );
    let per_chair: u64 = m.meshes[chair]
        .primitives
        .iter()
        .map(|p| p.mesh.indices.len() as u64)
        .sum();
    assert!(m.flatten_count() > 4 * per_chair);
    assert!(matches!(
        m.images[0],
        candela::geometry::gltf::GltfImage::Bytes { .. }
    ));
}
