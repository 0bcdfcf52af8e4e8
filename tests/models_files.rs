//! The files a model reads: glTF buffers and images, OBJ material libraries and their maps are
//! files the scene refers to (a render refuses to overwrite them and its state's hash covers
//! them); only files beside the model or below its folder are read; each material library is
//! read once; vertices placed out of range by a node are refused.

mod common;
use serde_json::json;
use std::path::Path;

/// A 4×4 scene of one `Model(file)` seen from +z, lit by a point light.
fn scene(file: &str) -> String {
    format!(
        r#"(
    camera: (position: (0, 0, 3), look_at: (0, 0, 0), vfov_deg: 40, resolution: (4, 4)),
    render: (spp: 1),
    objects: [(name: "m", shape: Model(file: "{file}"))],
    lights: [Point(position: (0, 0, 2), spectrum: Named("D65"), amount: Intensity(10.0))],
)"#
    )
}

/// The bytes of the buffer of [`quad`]: a unit quad in the z = 0 plane facing +z, its texture
/// coordinates and indices.
fn quad_bin() -> Vec<u8> {
    let p: [[f32; 3]; 4] = [
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ];
    let uv: [[f32; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let mut bin: Vec<u8> = p.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    bin.extend(uv.iter().flatten().flat_map(|v| v.to_le_bytes()));
    bin.extend([0u32, 1, 2, 0, 2, 3].iter().flat_map(|v| v.to_le_bytes()));
    bin
}

/// A glTF document of [`quad_bin`] in buffer `buffer_uri`, textured by image `image_uri` if
/// given, with a camera node at z = 3 looking down −z, the quad's node transformed by `node`.
fn quad(buffer_uri: &str, image_uri: Option<&str>, node: serde_json::Value) -> serde_json::Value {
    let mut doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": 104, "uri": buffer_uri}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 32},
            {"buffer": 0, "byteOffset": 80, "byteLength": 24}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5125, "count": 6, "type": "SCALAR"}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
                                     "indices": 2, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"metallicFactor": 0.0}}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
        "nodes": [node, {"camera": 0, "translation": [0, 0, 3]}],
        "scenes": [{"nodes": [0, 1]}],
        "scene": 0,
    });
    if let Some(uri) = image_uri {
        doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0});
        doc["textures"] = json!([{"source": 0}]);
        doc["images"] = json!([{"uri": uri}]);
    }
    doc
}

/// A 2×2 RGB PNG.
fn png() -> Vec<u8> {
    let img =
        image::RgbImage::from_raw(2, 2, vec![200, 100, 50, 10, 20, 30, 90, 90, 90, 255, 0, 0])
            .unwrap();
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// The files of `dir` with their contents.
fn snapshot(dir: &Path) -> Vec<(String, Vec<u8>)> {
    common::listing(dir)
        .into_iter()
        .filter(|n| !dir.join(n).is_dir())
        .map(|n| {
            let bytes = std::fs::read(dir.join(&n)).unwrap();
            (n, bytes)
        })
        .collect()
}

/// `candela args` in `dir` exits with 1 and one line holding every needle, leaving every file
/// of `dir` as it was.
fn refused_untouched(dir: &Path, args: &[&str], needles: &[&str]) -> String {
    let before = snapshot(dir);
    let (code, _, stderr) = common::cli(args, dir);
    assert_eq!(code, 1, "{args:?}: exit code {code}, stderr:\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    for n in needles {
        assert!(
            stderr.contains(n),
            "{args:?}: message lacks {n:?}:\n{stderr}"
        );
    }
    assert_eq!(snapshot(dir), before, "{args:?} changed files");
    stderr
}

const OVERWRITE: &str = "refusing to overwrite the file the scene refers to";

#[test]
fn gltf_buffers_and_images_named_like_outputs_are_not_replaced() {
    // A glTF rendered on its own (outputs g.*) whose buffer is g.exr.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("g.exr"), quad_bin()).unwrap();
    std::fs::write(
        d.join("g.gltf"),
        quad("g.exr", None, json!({"mesh": 0})).to_string(),
    )
    .unwrap();
    refused_untouched(d, &["render", "--quiet", "g.gltf"], &[OVERWRITE, "g.exr"]);
    // ... and renders once the output is named otherwise, so the refusal was the name's.
    let (code, _, stderr) = common::cli(&["render", "--quiet", "--out", "x", "g.gltf"], d);
    assert_eq!(code, 0, "{stderr}");

    // In a RON scene with --out h: the image h.png, and a buffer h.state.
    for (buffer, image) in [("m.bin", "h.png"), ("h.state", "t.png")] {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join(buffer), quad_bin()).unwrap();
        std::fs::write(d.join(image), png()).unwrap();
        let doc = quad(buffer, Some(image), json!({"mesh": 0}));
        std::fs::write(d.join("m.gltf"), doc.to_string()).unwrap();
        std::fs::write(d.join("s.ron"), scene("m.gltf")).unwrap();
        let named = if buffer == "h.state" { buffer } else { image };
        let args = ["render", "--quiet", "--save-state", "--out", "h", "s.ron"];
        refused_untouched(d, &args, &[OVERWRITE, named]);
    }
}

#[test]
fn obj_libraries_and_maps_named_like_outputs_are_not_replaced() {
    let obj = "mtllib {LIB}\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nusemtl a\nf 1/1 2/2 3/3\n";
    for (lib, map, named) in [("o.exr", "t.png", "o.exr"), ("m.mtl", "o.png", "o.png")] {
        for stmt in ["map_Kd", "norm"] {
            let dir = tempfile::tempdir().unwrap();
            let d = dir.path();
            std::fs::write(d.join("m.obj"), obj.replace("{LIB}", lib)).unwrap();
            std::fs::write(
                d.join(lib),
                format!("newmtl a\nKd 0.5 0.5 0.5\n{stmt} {map}\n"),
            )
            .unwrap();
            std::fs::write(d.join(map), png()).unwrap();
            std::fs::write(d.join("s.ron"), scene("m.obj")).unwrap();
            let args = ["render", "--quiet", "--out", "o", "s.ron"];
            refused_untouched(d, &args, &[OVERWRITE, named]);
        }
    }
}

#[test]
fn an_obj_shapes_library_named_like_an_output_is_not_replaced() {
    // An `Obj` shape does not use its library, but the library is the model's file all the same.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("m.obj"),
        "mtllib o.png\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(d.join("o.png"), "newmtl a\nKd 0.5 0.5 0.5\n").unwrap();
    let text = scene("m.obj")
        .replace("Model(file: \"m.obj\")", "Obj(\"m.obj\"), material: \"g\"")
        .replace(
            "render: (spp: 1),",
            "render: (spp: 1),\n    materials: { \"g\": Diffuse(reflectance: Constant(0.5)) },",
        );
    std::fs::write(d.join("s.ron"), text).unwrap();
    refused_untouched(
        d,
        &["render", "--quiet", "--out", "o", "s.ron"],
        &[OVERWRITE, "o.png"],
    );
    // A library that is not there is no file to protect: the render goes on.
    std::fs::write(
        d.join("m.obj"),
        "mtllib p.png\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let (code, _, stderr) = common::cli(&["render", "--quiet", "--out", "p", "s.ron"], d);
    assert_eq!(code, 0, "{stderr}");
}

#[test]
fn a_changed_model_texture_makes_a_state_not_match() {
    // The texture is part of the state's hash: after it changes, --resume refuses.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("m.bin"), quad_bin()).unwrap();
    std::fs::write(d.join("t.png"), png()).unwrap();
    let doc = quad("m.bin", Some("t.png"), json!({"mesh": 0}));
    std::fs::write(d.join("m.gltf"), doc.to_string()).unwrap();
    std::fs::write(d.join("s.ron"), scene("m.gltf")).unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["render", "--quiet", "--save-state", "--out", "r"];
        args.extend_from_slice(extra);
        args.push("s.ron");
        common::cli(&args, d)
    };
    let (code, _, stderr) = run(&[]);
    assert_eq!(code, 0, "{stderr}");
    let (code, _, stderr) = run(&["--resume", "--spp", "2"]);
    assert_eq!(code, 0, "the unchanged scene resumes: {stderr}");
    let img = image::RgbImage::from_raw(2, 2, vec![1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12]).unwrap();
    img.save(d.join("t.png")).unwrap();
    let (code, _, stderr) = run(&["--resume", "--spp", "3"]);
    assert_eq!(code, 1, "a changed texture must not resume: {stderr}");
}

/// A file outside the test's model folder, holding bytes that must never appear in a message.
const SECRET: &[u8] = b"SECRET-BYTES-4242";

/// Runs `scene.ron` (a `Model(file)`) in `dir` and expects a refusal naming the model file and
/// `uri`, without the secret's bytes.
fn outside_refused(dir: &Path, file: &str, uri: &str) {
    std::fs::write(dir.join("scene.ron"), scene(file)).unwrap();
    let (code, _, stderr) = common::cli(&["render", "--quiet", "--out", "out", "scene.ron"], dir);
    assert_eq!(code, 1, "{file} naming {uri:?}: exit code {code}\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for n in [file, uri, "outside the model's folder"] {
        assert!(
            stderr.contains(n),
            "{file} naming {uri:?}: message lacks {n:?}:\n{stderr}"
        );
    }
    assert!(!stderr.contains("SECRET"), "{stderr}");
}

/// A temporary tree: `top/secret.bin` and `top/secret.png` (outside) and the model folder
/// `top/model`, holding symbolic links `link.bin` and `link.png` to the secrets and a folder
/// `sub` whose `..` is the model folder.
fn tree() -> (tempfile::TempDir, std::path::PathBuf) {
    let top = tempfile::tempdir().unwrap();
    let d = top.path().join("model");
    std::fs::create_dir_all(d.join("sub")).unwrap();
    std::fs::write(top.path().join("secret.bin"), SECRET).unwrap();
    std::fs::write(top.path().join("secret.png"), SECRET).unwrap();
    std::os::unix::fs::symlink(top.path().join("secret.bin"), d.join("link.bin")).unwrap();
    std::os::unix::fs::symlink(top.path().join("secret.png"), d.join("link.png")).unwrap();
    (top, d)
}

#[test]
fn gltf_files_outside_the_model_folder_are_refused() {
    let (top, d) = tree();
    let secret = top.path().join("secret.bin");
    let abs = secret.to_str().unwrap();
    std::fs::write(d.join("m.bin"), quad_bin()).unwrap();
    for uri in [
        abs,
        "../secret.bin",
        "sub/../../secret.bin",
        "link.bin",
        "%2E%2E/secret.bin",
    ] {
        std::fs::write(
            d.join("m.gltf"),
            quad(uri, None, json!({"mesh": 0})).to_string(),
        )
        .unwrap();
        outside_refused(&d, "m.gltf", uri);
    }
    let png_abs = top.path().join("secret.png");
    for uri in [png_abs.to_str().unwrap(), "../secret.png", "link.png"] {
        let doc = quad("m.bin", Some(uri), json!({"mesh": 0}));
        std::fs::write(d.join("m.gltf"), doc.to_string()).unwrap();
        outside_refused(&d, "m.gltf", uri);
    }
    // The same in a .glb, whose images may name files too.
    let mut doc = quad("m.bin", Some("../secret.png"), json!({"mesh": 0}));
    doc["buffers"] = json!([{"byteLength": 104}]);
    std::fs::write(d.join("m.glb"), common::glb(&doc, &quad_bin())).unwrap();
    outside_refused(&d, "m.glb", "../secret.png");
    // Inside the folder, through `sub/..`, and as a data: URI, a model still reads its files.
    std::fs::write(d.join("t.png"), png()).unwrap();
    let data = format!(
        "data:application/octet-stream;base64,{}",
        base64(&quad_bin())
    );
    for (buffer, image) in [("sub/../m.bin", "t.png"), (data.as_str(), "sub/../t.png")] {
        let doc = quad(buffer, Some(image), json!({"mesh": 0}));
        std::fs::write(d.join("m.gltf"), doc.to_string()).unwrap();
        std::fs::write(d.join("scene.ron"), scene("m.gltf")).unwrap();
        let (code, _, stderr) =
            common::cli(&["render", "--quiet", "--out", "out", "scene.ron"], &d);
        assert_eq!(code, 0, "{buffer} {image}: {stderr}");
    }
}

#[test]
fn obj_files_outside_the_model_folder_are_refused() {
    let (top, d) = tree();
    std::fs::write(top.path().join("lib.mtl"), "newmtl a\nKd 0.5 0.5 0.5\n").unwrap();
    std::os::unix::fs::symlink(top.path().join("lib.mtl"), d.join("link.mtl")).unwrap();
    let obj = |lib: &str| {
        format!("mtllib {lib}\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nusemtl a\nf 1/1 2/2 3/3\n")
    };
    let abs_lib = top.path().join("lib.mtl");
    for lib in [
        abs_lib.to_str().unwrap(),
        "../lib.mtl",
        "link.mtl",
        "sub/../../lib.mtl",
    ] {
        std::fs::write(d.join("m.obj"), obj(lib)).unwrap();
        outside_refused(&d, "m.obj", lib);
    }
    // A library inside whose maps point out, for each kind of map.
    let abs_png = top.path().join("secret.png");
    std::fs::write(d.join("m.obj"), obj("m.mtl")).unwrap();
    for stmt in ["map_Kd", "norm"] {
        for map in [abs_png.to_str().unwrap(), "../secret.png", "link.png"] {
            std::fs::write(d.join("m.mtl"), format!("newmtl a\n{stmt} {map}\n")).unwrap();
            outside_refused(&d, "m.obj", map);
        }
    }
    // A library in a subfolder may name a map beside the model with `..`.
    std::fs::write(d.join("t.png"), png()).unwrap();
    std::fs::write(d.join("sub/m.mtl"), "newmtl a\nmap_Kd ../t.png\n").unwrap();
    std::fs::write(d.join("m.obj"), obj("sub/m.mtl")).unwrap();
    std::fs::write(d.join("scene.ron"), scene("m.obj")).unwrap();
    let (code, _, stderr) = common::cli(&["render", "--quiet", "--out", "out", "scene.ron"], &d);
    assert_eq!(code, 0, "{stderr}");
    // An `Obj` shape does not use its libraries: one outside is refused unread (the secret's
    // bytes are not in the message), one outside that is not there is ignored.
    std::fs::write(d.join("m.obj"), obj("../lib.mtl")).unwrap();
    let obj_scene = scene("m.obj")
        .replace("Model(file: \"m.obj\")", "Obj(\"m.obj\"), material: \"g\"")
        .replace(
            "render: (spp: 1),",
            "render: (spp: 1),\n    materials: { \"g\": Diffuse(reflectance: Constant(0.5)) },",
        );
    std::fs::write(d.join("scene.ron"), &obj_scene).unwrap();
    let (code, _, stderr) = common::cli(&["render", "--quiet", "--out", "out", "scene.ron"], &d);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("../lib.mtl") && stderr.contains("outside"),
        "{stderr}"
    );
    std::fs::write(d.join("m.obj"), obj("../nowhere.mtl")).unwrap();
    let (code, _, stderr) = common::cli(&["render", "--quiet", "--out", "out", "scene.ron"], &d);
    assert_eq!(code, 0, "{stderr}");
}

/// Standard base64 with padding.
fn base64(bytes: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

#[test]
fn many_mtllib_lines_and_several_names_on_one() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // 5000 `mtllib` lines naming one library of 1 MiB (read each time, that is 5 GB).
    let mut lib = String::from("newmtl a\nKd 0.5 0.5 0.5\n");
    while lib.len() < 1 << 20 {
        lib.push_str("# padding padding padding padding padding padding padding padding\n");
    }
    std::fs::write(d.join("a.mtl"), &lib).unwrap();
    std::fs::write(d.join("b c.mtl"), "newmtl b\nKd 0.25 0.25 0.25\n").unwrap();
    let mut obj = "mtllib a.mtl\n".repeat(5000);
    // Two libraries on one line, the second with a space in its name.
    obj.push_str("mtllib a.mtl b c.mtl\n");
    obj.push_str("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nusemtl a\nf 1 2 3\nusemtl b\nf 1 3 4\n");
    std::fs::write(d.join("m.obj"), obj).unwrap();
    let model = candela::geometry::load_obj_model(&d.join("m.obj")).unwrap();
    let names: Vec<&str> = model.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["a", "b"]);
    assert_eq!(model.libraries, [d.join("a.mtl"), d.join("b c.mtl")]);
    assert_eq!(model.groups.len(), 2);
}

#[test]
fn vertices_out_of_range_are_refused_after_transforms() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // OBJ: a small triangle 1e18 m out (it would collapse to zero area in f32 and vanish).
    for far in ["1e18", "1e13", "inf"] {
        let obj = format!(
            "v {far} 0 0\nv {far} 1 0\nv {far} 0 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 4 5 6\nf 1 2 3\n"
        );
        std::fs::write(d.join("m.obj"), obj).unwrap();
        let e = candela::geometry::load_obj_model(&d.join("m.obj"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("m.obj") && e.contains("line 1") && e.contains("vertex 1"),
            "{far}: {e}"
        );
    }
    // A weight w = 1e-20 puts a vertex written at 1 m out at 1e20 m.
    std::fs::write(
        d.join("m.obj"),
        "v 0 0 0\nv 1 0 0 1e-20\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let e = candela::geometry::load_obj(&d.join("m.obj"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 2") && e.contains("vertex 2"), "{e}");
    // glTF: a valid unit quad scaled out of range by its node, directly and through a parent.
    std::fs::write(d.join("m.bin"), quad_bin()).unwrap();
    for nodes in [
        json!([{"mesh": 0, "scale": [1e13, 1e13, 1e13]}, {"camera": 0, "translation": [0, 0, 3]}]),
        json!([{"mesh": 0, "translation": [0, 0, 1e18]}, {"camera": 0, "translation": [0, 0, 3]}]),
        json!([{"children": [2], "matrix": [1e7,0,0,0, 0,1e7,0,0, 0,0,1e7,0, 0,0,0,1]},
               {"camera": 0, "translation": [0, 0, 3]},
               {"mesh": 0, "scale": [1e6, 1, 1]}]),
    ] {
        let mut doc = quad("m.bin", None, json!({}));
        doc["nodes"] = nodes.clone();
        std::fs::write(d.join("m.gltf"), doc.to_string()).unwrap();
        let e = candela::geometry::gltf::load_gltf(&d.join("m.gltf"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("m.gltf") && e.contains("accessor 0") && e.contains("±1e12"),
            "{nodes}: {e}"
        );
    }
    // A scene transform that takes an OBJ out of range is refused with the vertex, too.
    std::fs::write(d.join("m.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let text = r#"(
    camera: (position: (0, 0, 3), look_at: (0, 0, 0), vfov_deg: 40, resolution: (4, 4)),
    materials: { "g": Diffuse(reflectance: Constant(0.5)) },
    objects: [(shape: Obj("m.obj"), material: "g", transform: (translate: (1e18, 0, 0))),
              (shape: Sphere(center: (0, 0, 0), radius: 1), material: "g")],
    lights: [Point(position: (0, 0, 2), spectrum: Named("D65"), amount: Intensity(10.0))],
)"#;
    std::fs::write(d.join("s.ron"), text).unwrap();
    let (code, _, stderr) = common::cli(&["render", "--quiet", "--out", "o", "s.ron"], d);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("vertex 0") && stderr.contains("±1e12"),
        "{stderr}"
    );
}

/// A PNG signature and IHDR chunk claiming `w`×`h` 8-bit RGB pixels, and no image data.
fn png_header(w: u32, h: u32) -> Vec<u8> {
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in bytes {
            c ^= b as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend(w.to_be_bytes());
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 2, 0, 0, 0]);
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    out.extend(13u32.to_be_bytes());
    out.extend(&ihdr);
    out.extend(crc32(&ihdr).to_be_bytes());
    out.extend(0u32.to_be_bytes());
    out.extend(b"IDAT");
    out.extend(crc32(b"IDAT").to_be_bytes());
    out
}

/// A real 8×8 JPEG whose frame header (SOF0) is changed to claim 65535×65535 pixels
/// (4.3·10⁹).
fn jpeg_header() -> Vec<u8> {
    let img = image::RgbImage::from_pixel(8, 8, image::Rgb([100, 150, 200]));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Jpeg).unwrap();
    let mut b = out.into_inner();
    let sof = b.windows(2).position(|w| w == [0xFF, 0xC0]).unwrap();
    b[sof + 5..sof + 9].copy_from_slice(&[0xFF; 4]);
    b
}

#[test]
fn every_kind_of_model_texture_is_checked_from_its_header() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("m.bin"), quad_bin()).unwrap();
    std::fs::write(d.join("big.png"), png_header(1 << 20, 1 << 20)).unwrap();
    std::fs::write(d.join("big.jpg"), jpeg_header()).unwrap();
    let load = |file: &str| {
        std::fs::write(
            d.join("s.ron"),
            scene(file).replace("Model(file", "Model(ke_luminance: 100, file"),
        )
        .unwrap();
        let text = std::fs::read_to_string(d.join("s.ron")).unwrap();
        let text = if file.ends_with(".gltf") {
            text.replace("ke_luminance: 100, ", "")
        } else {
            text
        };
        std::fs::write(d.join("s.ron"), text).unwrap();
        let t = std::time::Instant::now();
        let e = match candela::scene::load_world(&d.join("s.ron"), &Default::default()) {
            Ok(_) => panic!("{file}: loaded"),
            Err(e) => e.to_string(),
        };
        (e, t.elapsed())
    };
    for image in ["big.png", "big.jpg"] {
        let slots = [
            ("baseColorTexture", true),
            ("metallicRoughnessTexture", true),
            ("normalTexture", false),
            ("emissiveTexture", false),
        ];
        for (slot, pbr) in slots {
            let mut doc = quad("m.bin", None, json!({"mesh": 0}));
            doc["textures"] = json!([{"source": 0}]);
            doc["images"] = json!([{"uri": image}]);
            if pbr {
                doc["materials"][0]["pbrMetallicRoughness"][slot] = json!({"index": 0});
            } else {
                doc["materials"][0][slot] = json!({"index": 0});
                doc["materials"][0]["emissiveFactor"] = json!([1, 1, 1]);
            }
            std::fs::write(d.join("m.gltf"), doc.to_string()).unwrap();
            let (e, took) = load("m.gltf");
            assert!(
                e.contains(image) && e.contains("texels"),
                "{slot} {image}: {e}"
            );
            assert!(took.as_secs() < 5, "{slot} {image}: {took:?}");
        }
        for stmt in ["map_Kd", "norm", "map_Ke"] {
            let obj = "mtllib m.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nusemtl a\nf 1/1 2/2 3/3\n";
            std::fs::write(d.join("m.obj"), obj).unwrap();
            std::fs::write(
                d.join("m.mtl"),
                format!("newmtl a\nKe 1 1 1\n{stmt} {image}\n"),
            )
            .unwrap();
            let (e, took) = load("m.obj");
            assert!(
                e.contains(image) && e.contains("texels"),
                "{stmt} {image}: {e}"
            );
            assert!(took.as_secs() < 5, "{stmt} {image}: {took:?}");
        }
    }
}
