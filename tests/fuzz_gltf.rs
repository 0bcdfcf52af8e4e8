//! Property-based fuzzing of the glTF loader (`geometry::gltf::load_gltf`) on temporary files:
//! valid `.gltf` (buffer in a file or a `data:` URI) and `.glb` models, edited field by field
//! (huge counts, offsets, strides and lengths, accessors overlapping or pointing at other views,
//! hostile URIs) and then mutated byte by byte (truncation, flips, splices), must load or give
//! an `Err` naming the file — never a panic (a panic hook counts any, caught or not), never the
//! bytes of a file outside the model's folder. A model that loads is checked (indices in range,
//! finite positions within the coordinate limit) and rendered in a tiny scene, which must give
//! finite pixels or be refused naming the scene. `PROPTEST_CASES=N` sets the number of cases.

mod common;
mod fuzz_common;

use candela::geometry::gltf::load_gltf;
use candela::scene::{self, Overrides};
use fuzz_common::{apply, config, mutation, Mutation};
use proptest::prelude::*;
use serde_json::{json, Value};
use std::cell::Cell;

/// Bytes of the file outside the model's folder; they must never appear in a message.
const SECRET: &[u8] = b"SECRET-OUTSIDE-7319";

/// A quad (two triangles) with normals, texture coordinates and u16 indices.
fn bin() -> Vec<u8> {
    let f = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let mut b = f(&[0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.]);
    b.extend(f(&[0., 0., 1., 0., 0., 1., 0., 0., 1., 0., 0., 1.]));
    b.extend(f(&[0., 0., 1., 0., 1., 1., 0., 1.]));
    b.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|x| x.to_le_bytes()));
    b
}

/// The document of [`bin`] in buffer `uri` (`None`: the GLB's chunk), with a textured
/// material whose image is `image_uri`, a light and a node hierarchy.
fn doc(uri: Option<&str>, image_uri: &str) -> Value {
    let mut buffer = json!({"byteLength": 140});
    if let Some(u) = uri {
        buffer["uri"] = json!(u);
    }
    json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 5}]}},
        "buffers": [buffer],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 96, "byteStride": 12},
            {"buffer": 0, "byteOffset": 96, "byteLength": 32},
            {"buffer": 0, "byteOffset": 128, "byteLength": 12}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 0, "byteOffset": 48, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                                     "indices": 3, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                                  "metallicFactor": 0.0},
                       "emissiveFactor": [0.1, 0.1, 0.1]}],
        "textures": [{"source": 0}],
        "images": [{"uri": image_uri}],
        "nodes": [{"children": [1, 2], "translation": [0, 0, 1]},
                  {"mesh": 0, "scale": [2, 2, 2]},
                  {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0, 0, 2]},
                  {"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 3,0,0,1]}],
        "scenes": [{"nodes": [0, 3]}],
        "scene": 0
    })
}

/// A 1×1 PNG.
fn png() -> Vec<u8> {
    let img = image::RgbImage::from_raw(1, 1, vec![120, 60, 30]).unwrap();
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

fn base64(bytes: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            s.push(if k <= c.len() {
                A[(n >> (18 - 6 * k) & 63) as usize] as char
            } else {
                '='
            });
        }
    }
    s
}

/// The three seeds: (is GLB, document).
fn seeds() -> Vec<(bool, Value)> {
    let data = format!("data:application/octet-stream;base64,{}", base64(&bin()));
    vec![
        (false, doc(Some("m.bin"), "t.png")),
        (false, doc(Some(&data), "t.png")),
        (true, doc(None, "t.png")),
    ]
}

/// Hostile values for a numeric field.
const HOSTILE: &[f64] = &[
    0.0,
    1.0,
    3.0,
    7.0,
    255.0,
    65535.0,
    2147483647.0,
    4294967295.0,
    4294967296.0,
    9007199254740991.0,
    1e30,
    -1.0,
    5120.0,
    5125.0,
    5126.0,
];

/// Hostile URIs.
const URIS: &[&str] = &[
    "/etc/passwd",
    "../secret.bin",
    "../../../../../../etc/passwd",
    "sub/../../secret.bin",
    "link.bin",
    "%2e%2e/secret.bin",
    "data:,",
    "data:application/octet-stream;base64,!!!",
    "data:image/png;base64,AAAA",
    "http://example.com/x.bin",
    "m.bin\u{0}x",
    "",
    ".",
    "sub",
    "t.png",
    "m.bin",
];

/// One edit of the document.
#[derive(Clone, Debug)]
enum Edit {
    /// Set `field` of element `index` of array `array` to a hostile number.
    Number {
        array: usize,
        index: usize,
        field: usize,
        value: usize,
    },
    /// Set a buffer's or image's URI.
    Uri { image: bool, uri: usize },
    /// Point an attribute of the primitive at another accessor.
    Attribute { attr: usize, accessor: usize },
}

const ARRAYS: &[&str] = &["accessors", "bufferViews", "buffers", "nodes"];
const FIELDS: &[&str] = &[
    "count",
    "byteOffset",
    "byteLength",
    "byteStride",
    "componentType",
    "bufferView",
    "buffer",
    "mesh",
];
const ATTRS: &[&str] = &["POSITION", "NORMAL", "TEXCOORD_0", "indices"];

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        3 => (0..ARRAYS.len(), 0..5usize, 0..FIELDS.len(), 0..HOSTILE.len())
            .prop_map(|(array, index, field, value)| Edit::Number { array, index, field, value }),
        2 => (any::<bool>(), 0..URIS.len()).prop_map(|(image, uri)| Edit::Uri { image, uri }),
        1 => (0..ATTRS.len(), 0..6usize).prop_map(|(attr, accessor)| Edit::Attribute { attr, accessor }),
    ]
}

fn edited(mut j: Value, edits: &[Edit]) -> Value {
    for e in edits {
        match *e {
            Edit::Number {
                array,
                index,
                field,
                value,
            } => {
                if let Some(el) = j[ARRAYS[array]].get_mut(index) {
                    let v = HOSTILE[value];
                    el[FIELDS[field]] = if v.fract() == 0.0 && v.abs() < 1e19 {
                        json!(v as i64)
                    } else {
                        json!(v)
                    };
                }
            }
            Edit::Uri { image, uri } => {
                let at = if image { "images" } else { "buffers" };
                j[at][0]["uri"] = json!(URIS[uri]);
            }
            Edit::Attribute { attr, accessor } => {
                let p = &mut j["meshes"][0]["primitives"][0];
                if ATTRS[attr] == "indices" {
                    p["indices"] = json!(accessor);
                } else {
                    p["attributes"][ATTRS[attr]] = json!(accessor);
                }
            }
        }
    }
    j
}

thread_local! {
    /// Panics on this thread, including those caught by the loader's `catch_unwind`.
    static PANICS: Cell<usize> = const { Cell::new(0) };
}

fn install_hook() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let prev = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            PANICS.with(|c| c.set(c.get() + 1));
            prev(info);
        }));
    });
}

const SCENE: &str = r#"(
    camera: (position: (1, 1, 6), look_at: (1, 1, 0), vfov_deg: 60, resolution: (2, 2)),
    render: (spp: 1, max_depth: 3),
    materials: { "m": Diffuse(reflectance: Constant(0.5)) },
    objects: [(shape: Model(file: "FILE"), material: "m")],
    lights: [Point(position: (0, 1, 4), spectrum: Named("D65"), amount: Intensity(10))],
)"#;

/// Loads `bytes` as model `m.gltf` / `m.glb` in a folder holding `m.bin`, `t.png`, a folder
/// `sub` and a link `link.bin` to a secret file beside the folder; checks as the module says.
fn check(bytes: &[u8], is_glb: bool) {
    install_hook();
    let before = PANICS.with(Cell::get);
    let top = tempfile::tempdir().unwrap();
    let dir = top.path().join("model");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::fs::write(top.path().join("secret.bin"), SECRET).unwrap();
    std::os::unix::fs::symlink(top.path().join("secret.bin"), dir.join("link.bin")).unwrap();
    std::fs::write(dir.join("m.bin"), bin()).unwrap();
    std::fs::write(dir.join("t.png"), png()).unwrap();
    let name = if is_glb { "m.glb" } else { "m.gltf" };
    let file = dir.join(name);
    std::fs::write(&file, bytes).unwrap();
    let r = load_gltf(&file);
    let shown = String::from_utf8_lossy(&bytes[..bytes.len().min(4000)]).into_owned();
    assert_eq!(
        PANICS.with(Cell::get),
        before,
        "the loader panicked (caught) on:\n{shown}"
    );
    let model = match r {
        Err(e) => {
            let m = e.to_string();
            assert!(m.contains(name), "error does not name the file: {m}");
            assert!(!m.contains("SECRET"), "error shows an outside file: {m}");
            return;
        }
        Ok(m) => m,
    };
    for f in &model.files {
        let inside = f
            .canonicalize()
            .map_or(true, |c| c.starts_with(dir.canonicalize().unwrap()));
        assert!(
            inside,
            "{} read from outside the folder:\n{shown}",
            f.display()
        );
    }
    for mesh in &model.meshes {
        for p in &mesh.primitives {
            let n = p.mesh.positions.len();
            assert!(p.mesh.indices.iter().flatten().all(|&i| (i as usize) < n));
            assert!(p.mesh.positions.iter().all(|v| v.is_finite()));
        }
    }
    let text = SCENE.replace("FILE", name);
    let path = dir.join("scene.ron");
    let parsed = scene::parse(&text, &path).unwrap();
    match scene::build(&parsed, &path, &Overrides::default()) {
        Ok(world) => {
            let r = candela::render::render(&world, Some(1), &|_, _| {}).unwrap();
            for p in &r.film.pixels {
                assert!(p.mean_xyz().iter().all(|v| v.is_finite()), "{shown}");
            }
            assert_eq!(r.stats.non_finite, 0, "non-finite samples on:\n{shown}");
        }
        Err(e) => {
            let m = e.to_string();
            assert!(m.contains("scene.ron"), "{m}");
            assert!(!m.contains("SECRET"), "error shows an outside file: {m}");
        }
    }
    assert_eq!(
        PANICS.with(Cell::get),
        before,
        "a panic while building:\n{shown}"
    );
}

/// The bytes of seed `k` after `edits`, as the file holds them.
fn encode(k: usize, edits: &[Edit]) -> (bool, Vec<u8>) {
    let (is_glb, j) = seeds().swap_remove(k);
    let j = edited(j, edits);
    if is_glb {
        (true, common::glb(&j, &bin()))
    } else {
        (false, serde_json::to_vec(&j).unwrap())
    }
}

#[test]
fn seeds_load_and_render() {
    for k in 0..3 {
        let (is_glb, bytes) = encode(k, &[]);
        check(&bytes, is_glb);
        // And they do load: the checks above passed on a model, not on an error.
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("m.bin"), bin()).unwrap();
        std::fs::write(dir.path().join("t.png"), png()).unwrap();
        let f = dir.path().join(if is_glb { "m.glb" } else { "m.gltf" });
        std::fs::write(&f, &bytes).unwrap();
        let m = load_gltf(&f).unwrap_or_else(|e| panic!("seed {k}: {e}"));
        assert_eq!(m.instances.len(), 2, "seed {k}");
    }
}

#[test]
fn each_hostile_uri_is_refused_or_read_inside() {
    for k in 0..3 {
        for uri in 0..URIS.len() {
            for image in [false, true] {
                let (is_glb, bytes) = encode(k, &[Edit::Uri { image, uri }]);
                check(&bytes, is_glb);
            }
        }
    }
}

fn mutations() -> impl Strategy<Value = Vec<Mutation>> {
    proptest::collection::vec(mutation(1), 0..=3)
}

proptest! {
    #![proptest_config(config(1000))]

    #[test]
    fn edited_models_never_panic(
        k in 0..3usize,
        edits in proptest::collection::vec(edit(), 1..=4),
    ) {
        let (is_glb, bytes) = encode(k, &edits);
        check(&bytes, is_glb);
    }

    #[test]
    fn mutated_models_never_panic(
        k in 0..3usize,
        edits in proptest::collection::vec(edit(), 0..=2),
        muts in mutations(),
    ) {
        let (is_glb, bytes) = encode(k, &edits);
        let seed_bytes = bytes.clone();
        check(&apply(&bytes, &muts, &[&seed_bytes]), is_glb);
    }

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
        check(&bytes, false);
        let mut g = b"glTF\x02\0\0\0".to_vec();
        g.extend(&bytes);
        check(&g, true);
    }
}
