//! glTF files as whole scenes (`candela render room.glb`) and glTF meshes shared by several
//! nodes stored once (instances): a shared mesh renders as its copies do, a punctual light of
//! 100 cd 2 m above a Lambertian plane gives it 25·ρ/π cd/m² through the file's camera, the
//! file's camera puts a marked point on the pixel a pinhole model predicts, and a missing,
//! unknown or orthographic camera is a clear error.

mod common;
use candela::scene::{load_world, Overrides};
use glam::{Mat4, Quat, Vec3};
use serde_json::{json, Value};
use std::path::Path;

/// One triangle primitive: positions, indices, material.
struct Prim {
    positions: Vec<[f32; 3]>,
    indices: Vec<u32>,
    material: usize,
}

/// Standard base64 (RFC 4648, padded), for `data:` URIs.
fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                out.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Writes `meshes` (each a list of primitives) and `json` (nodes, scenes, materials, cameras,
/// extensions) as `dir/name`: a `.glb`, or a `.gltf` whose buffer is a base64 `data:` URI.
fn write(meshes: &[Vec<Prim>], json: &Value, dir: &Path, name: &str) {
    let mut bin: Vec<u8> = Vec::new();
    let (mut views, mut accessors, mut out_meshes) = (vec![], vec![], vec![]);
    let mut add = |bin: &mut Vec<u8>, bytes: Vec<u8>, acc: Value| -> usize {
        views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
        bin.extend(bytes);
        let mut acc = acc;
        acc["bufferView"] = json!(views.len() - 1);
        accessors.push(acc);
        accessors.len() - 1
    };
    for m in meshes {
        let mut prims = vec![];
        for p in m {
            let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
            for v in &p.positions {
                for k in 0..3 {
                    lo[k] = lo[k].min(v[k]);
                    hi[k] = hi[k].max(v[k]);
                }
            }
            let pos = add(
                &mut bin,
                p.positions
                    .concat()
                    .iter()
                    .flat_map(|x| x.to_le_bytes())
                    .collect(),
                json!({"componentType": 5126, "count": p.positions.len(), "type": "VEC3", "min": lo, "max": hi}),
            );
            let idx = add(
                &mut bin,
                p.indices.iter().flat_map(|x| x.to_le_bytes()).collect(),
                json!({"componentType": 5125, "count": p.indices.len(), "type": "SCALAR"}),
            );
            prims.push(
                json!({"attributes": {"POSITION": pos}, "indices": idx, "material": p.material}),
            );
        }
        out_meshes.push(json!({ "primitives": prims }));
    }
    let mut j = json.clone();
    j["asset"] = json!({"version": "2.0"});
    j["meshes"] = json!(out_meshes);
    j["bufferViews"] = json!(views);
    j["accessors"] = json!(accessors);
    if name.ends_with(".glb") {
        j["buffers"] = json!([{"byteLength": bin.len()}]);
        std::fs::write(dir.join(name), common::glb(&j, &bin)).unwrap();
    } else {
        let uri = format!("data:application/octet-stream;base64,{}", base64(&bin));
        j["buffers"] = json!([{"byteLength": bin.len(), "uri": uri}]);
        std::fs::write(dir.join(name), serde_json::to_vec_pretty(&j).unwrap()).unwrap();
    }
}

/// A quad of half-size `h` at height `y` centred on (cx, cz), facing +Y (or −Y if `down`).
fn quad(cx: f32, y: f32, cz: f32, h: f32, down: bool, material: usize) -> Prim {
    let positions = vec![
        [cx - h, y, cz - h],
        [cx + h, y, cz - h],
        [cx + h, y, cz + h],
        [cx - h, y, cz + h],
    ];
    let indices = if down {
        vec![0, 1, 2, 0, 2, 3]
    } else {
        vec![0, 2, 1, 0, 3, 2]
    };
    Prim {
        positions,
        indices,
        material,
    }
}

/// A closed box [−0.25, 0.25] × [0, 0.5] × [−0.25, 0.25] (12 triangles, outward), material 1.
fn chair() -> Prim {
    let mut positions = vec![];
    for k in 0..8 {
        positions.push([
            if k & 1 == 0 { -0.25 } else { 0.25 },
            if k & 2 == 0 { 0.0 } else { 0.5 },
            if k & 4 == 0 { -0.25 } else { 0.25 },
        ]);
    }
    let faces: [[u32; 4]; 6] = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let indices = faces
        .iter()
        .flat_map(|f| [f[0], f[1], f[2], f[0], f[2], f[3]])
        .collect();
    Prim {
        positions,
        indices,
        material: 1,
    }
}

/// Quaternion (x, y, z, w) of a rotation by `deg` about the unit `axis`.
fn rot(axis: Vec3, deg: f32) -> [f32; 4] {
    Quat::from_axis_angle(axis, deg.to_radians()).to_array()
}

/// The glTF camera node looking from (0, 4, 6) at the origin, 40° vertical field of view.
fn camera_json() -> (Value, Value) {
    let a = -(4f32).atan2(6.0).to_degrees();
    (
        json!({"name": "view", "translation": [0.0, 4.0, 6.0], "rotation": rot(Vec3::X, a), "camera": 0}),
        json!([{"type": "perspective", "perspective": {"yfov": 40f32.to_radians(), "aspectRatio": 4.0 / 3.0, "znear": 0.01}}]),
    )
}

/// Materials: 0 the floor (grey 0.5, Lambertian), 1 the chairs and housings (0.7), 2 the
/// luminaires' panels (200 cd/m²).
fn materials() -> Value {
    let grey = |v: f32| json!({"pbrMetallicRoughness": {"baseColorFactor": [v, v, v, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}});
    json!([grey(0.5), grey(0.7), {
        "emissiveFactor": [1.0, 1.0, 1.0],
        "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0},
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 200.0}}
    }])
}

/// A room: a floor, a box "chair" placed by 5 nodes (turned, stretched, one mirrored) and a
/// luminaire (a housing and an emitting panel, two primitives) placed by 3, lit by the panels
/// and a point light. `shared`: the nodes share the two meshes; else each node has its own
/// copy of them.
fn room(dir: &Path, name: &str, shared: bool) {
    let mut meshes = vec![vec![quad(0.0, 0.0, 0.0, 20.0, false, 0)]];
    let mut nodes = vec![json!({"mesh": 0})];
    let chairs: [([f32; 3], f32, [f32; 3]); 5] = [
        ([-1.5, 0.0, -1.0], 0.0, [1.0, 1.0, 1.0]),
        ([-0.5, 0.0, 0.8], 30.0, [1.0, 1.0, 1.0]),
        ([0.7, 0.0, -0.4], 45.0, [1.0, 1.6, 0.8]),
        ([1.6, 0.0, 1.2], -20.0, [-1.0, 1.0, 1.0]),
        ([0.2, 0.0, 2.0], 90.0, [0.7, 0.7, 0.7]),
    ];
    let lums: [[f32; 3]; 3] = [[-1.0, 2.5, 0.0], [1.0, 2.5, -1.0], [0.5, 2.5, 1.5]];
    let luminaire = || {
        vec![
            quad(0.0, 0.02, 0.0, 0.3, false, 1),
            quad(0.0, 0.0, 0.0, 0.25, true, 2),
        ]
    };
    let (chair_mesh, lum_mesh) = (meshes.len(), meshes.len() + 1);
    meshes.push(vec![chair()]);
    meshes.push(luminaire());
    for (t, deg, s) in chairs {
        let mesh = if shared {
            chair_mesh
        } else {
            meshes.push(vec![chair()]);
            meshes.len() - 1
        };
        nodes.push(
            json!({"mesh": mesh, "translation": t, "rotation": rot(Vec3::Y, deg), "scale": s}),
        );
    }
    // The luminaires hang from a parent node: their world transforms compose two levels.
    let parent = nodes.len();
    nodes.push(json!({"translation": [0.0, 0.3, 0.0], "children": []}));
    for t in lums {
        let mesh = if shared {
            lum_mesh
        } else {
            meshes.push(luminaire());
            meshes.len() - 1
        };
        let k = nodes.len();
        nodes[parent]["children"]
            .as_array_mut()
            .unwrap()
            .push(json!(k));
        nodes.push(json!({"mesh": mesh, "translation": [t[0], t[1] - 0.3, t[2]]}));
    }
    let (cam, cameras) = camera_json();
    nodes.push(cam);
    nodes.push(json!({"translation": [0.0, 3.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}));
    let roots: Vec<usize> = (0..nodes.len())
        .filter(|&i| i <= parent || i >= parent + 4)
        .collect();
    let json = json!({
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 50.0}]}},
        "scene": 0, "scenes": [{"nodes": roots}],
        "nodes": nodes, "cameras": cameras, "materials": materials(),
    });
    write(&meshes, &json, dir, name);
}

fn small(spp: u32, w: u32, h: u32) -> Overrides {
    Overrides {
        spp: Some(spp),
        resolution: Some((w, h)),
        ..Default::default()
    }
}

/// A mesh placed by several nodes is stored once: the chair's 12 triangles and the luminaire
/// housing's 2 are the instanced triangles stored (66 placed), the luminaires' emitting panels
/// are flattened (3 area lights, as in the copies), and the scene renders as the one with a
/// copy of the meshes per node: every 6×6-pixel block agrees within 4.5 combined standard
/// errors (48 blocks: a false alarm has probability 3·10⁻⁴). The `.gltf` with a base64 buffer
/// holds the same scene as the `.glb`.
#[test]
fn shared_meshes_are_instances_that_render_as_copies() {
    let dir = tempfile::tempdir().unwrap();
    room(dir.path(), "shared.glb", true);
    room(dir.path(), "shared.gltf", true);
    room(dir.path(), "copies.glb", false);
    let o = small(64, 48, 36);
    let a = load_world(&dir.path().join("shared.glb"), &o).unwrap_or_else(|e| panic!("{e}"));
    let b = load_world(&dir.path().join("copies.glb"), &o).unwrap_or_else(|e| panic!("{e}"));
    let (ga, gb) = (&a.geometry, &b.geometry);
    eprintln!(
        "shared: {} flat + {} instanced triangles stored ({} placed by {} instances), {} B; copies: {} triangles, {} B",
        ga.primitive_count(),
        ga.instanced_stored_triangle_count(),
        ga.instanced_triangle_count(),
        ga.instance_count(),
        ga.memory_bytes(),
        gb.primitive_count(),
        gb.memory_bytes()
    );
    assert_eq!(ga.instance_count(), 8);
    assert_eq!(ga.instanced_stored_triangle_count(), 12 + 2);
    assert_eq!(ga.instanced_triangle_count(), 5 * 12 + 3 * 2);
    // The floor and the three panels.
    assert_eq!(ga.primitive_count(), 2 + 3 * 2);
    assert_eq!(gb.instance_count(), 0);
    assert_eq!(gb.primitive_count(), 2 + 5 * 12 + 3 * 4);
    assert_eq!(a.lights.len(), 4);
    assert_eq!(b.lights.len(), 4);
    let c = load_world(&dir.path().join("shared.gltf"), &o).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(c.geometry.instanced_stored_triangle_count(), 14);
    assert_eq!(c.geometry.primitive_count(), 8);
    let (fa, fb) = (common::render(&a, 2), common::render(&b, 2));
    let worst = common::assert_blocks_agree(&fa, &fb, 6, ("instances", "copies"));
    let (ma, sa) = common::image_mean(&fa);
    let (mb, sb) = common::image_mean(&fb);
    eprintln!(
        "image mean: instances {} ± {sa}, copies {} ± {sb} cd/m²; worst block |z| = {worst:.2}",
        ma[1], mb[1]
    );
    assert!((ma[1] - mb[1]).abs() < 4.5 * (sa * sa + sb * sb).sqrt());
    // The render must see the room: the floor, chairs and lit panels, not a black image.
    assert!(ma[1] > 1.0, "{}", ma[1]);
}

/// Reflectance of the test plane.
const RHO: f64 = 0.5;

/// The camera node's world transform for the whole-scene test: at (0.4, 2.2, 2.6), looking at
/// (0.1, 0, −0.2), turned 10° about its view axis.
fn test_camera_world() -> Mat4 {
    let eye = Vec3::new(0.4, 2.2, 2.6);
    let f = (Vec3::new(0.1, 0.0, -0.2) - eye).normalize();
    let right = f.cross(Vec3::Y).normalize();
    let up = right.cross(f);
    let look = Mat4::from_cols(
        right.extend(0.0),
        up.extend(0.0),
        (-f).extend(0.0),
        eye.extend(1.0),
    );
    look * Mat4::from_rotation_z(10f32.to_radians())
}

const YFOV_DEG: f32 = 30.0;
const ASPECT: f32 = 1.5;

/// The pixel coordinates (x right, y down, in pixels) of world point `p` through a pinhole at
/// `world` with vertical field of view [`YFOV_DEG`], on a `w`×`h` image.
fn project(world: Mat4, p: Vec3, w: f32, h: f32) -> (f32, f32) {
    let c = world.inverse().transform_point3(p);
    let t = (YFOV_DEG.to_radians() / 2.0).tan();
    let x = c.x / -c.z / (t * w / h);
    let y = c.y / -c.z / t;
    ((x + 1.0) / 2.0 * w, (1.0 - y) / 2.0 * h)
}

/// The world point on the plane y = 0 seen through image point (px, py).
fn unproject_to_floor(world: Mat4, px: f32, py: f32, w: f32, h: f32) -> Vec3 {
    let t = (YFOV_DEG.to_radians() / 2.0).tan();
    let d = Vec3::new(
        (2.0 * px / w - 1.0) * t * w / h,
        (1.0 - 2.0 * py / h) * t,
        -1.0,
    );
    let o = world.transform_point3(Vec3::ZERO);
    let d = world.transform_vector3(d);
    o + d * (-o.y / d.y)
}

/// The whole-scene file: a 4 m plane of reflectance [`RHO`] at y = 0, a point light of 100 cd
/// 2 m above the origin, a 2 cm marker square of 1000 cd/m² (black, facing up) on the plane at
/// `marker`, and the camera of [`test_camera_world`] as a child of a turned parent node.
/// `camera`: the camera JSON (None: no camera).
fn plane_scene(dir: &Path, name: &str, marker: Vec3, camera: Option<Value>) {
    let meshes = vec![
        vec![quad(0.0, 0.0, 0.0, 2.0, false, 0)],
        vec![quad(marker.x, 0.001, marker.z, 0.01, false, 1)],
    ];
    let parent = Mat4::from_rotation_translation(
        Quat::from_rotation_y(35f32.to_radians()),
        Vec3::new(0.3, 1.0, -0.5),
    );
    let local = parent.inverse() * test_camera_world();
    let (s, r, t) = local.to_scale_rotation_translation();
    let mut nodes = vec![
        json!({"mesh": 0}),
        json!({"mesh": 1}),
        json!({"translation": [0.0, 2.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}),
    ];
    let mut roots = vec![0, 1, 2];
    let mut j = json!({
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 100.0}]}},
        "materials": [
            {"pbrMetallicRoughness": {"baseColorFactor": [RHO, RHO, RHO, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}},
            {"emissiveFactor": [1.0, 1.0, 1.0],
             "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0},
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1000.0}}},
        ],
    });
    if let Some(c) = camera {
        roots.push(nodes.len());
        nodes.push(json!({"name": "rig", "translation": parent.to_scale_rotation_translation().2.to_array(),
            "rotation": Quat::from_rotation_y(35f32.to_radians()).to_array(), "children": [nodes.len() + 1]}));
        nodes.push(json!({"name": "main", "translation": t.to_array(), "rotation": r.to_array(), "scale": s.to_array(), "camera": 0}));
        j["cameras"] = json!([c]);
    }
    j["nodes"] = json!(nodes);
    j["scenes"] = json!([{ "nodes": roots }]);
    j["scene"] = json!(0);
    write(&meshes, &j, dir, name);
}

fn perspective() -> Value {
    json!({"type": "perspective", "name": "persp", "perspective": {"yfov": YFOV_DEG.to_radians(), "aspectRatio": ASPECT, "znear": 0.01}})
}

/// A glTF file rendered as a whole scene: the file's camera (a child of a turned node) puts
/// the marker on the pixel a pinhole model of its node's transform predicts, and the pixel
/// over the point light's foot point has luminance I·h/d³·ρ/π averaged over its footprint
/// (25·ρ/π cd/m² at the foot itself) within 5 standard errors, below 1 %. The default
/// resolution is 1024 pixels wide at the camera's aspect ratio.
#[test]
fn gltf_file_is_a_whole_scene() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (60u32, 40u32);
    // The marker at the floor point seen through the centre of pixel (41, 13).
    let world = test_camera_world();
    let marker = unproject_to_floor(world, 41.5, 13.5, w as f32, h as f32);
    plane_scene(dir.path(), "plane.glb", marker, Some(perspective()));
    let path = dir.path().join("plane.glb");
    let full = load_world(&path, &Overrides::default()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((full.camera.width, full.camera.height), (1024, 683));
    assert_eq!(full.settings.spp, 64);
    let wld = load_world(&path, &small(256, w, h)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(wld.lights.len(), 2, "the point light and the marker");
    let film = common::render(&wld, 2);
    let y = |x: usize, yy: usize| film.pixels[yy * w as usize + x].mean_xyz()[1];
    let brightest = (0..(w * h) as usize)
        .max_by(|&a, &b| film.pixels[a].mean_xyz()[1].total_cmp(&film.pixels[b].mean_xyz()[1]))
        .unwrap();
    assert_eq!(
        (brightest % w as usize, brightest / w as usize),
        (41, 13),
        "the marker at {marker} is not where the file's camera puts it"
    );
    // The foot point's pixel: the prediction is independent of the renderer's camera.
    let (fx, fy) = project(world, Vec3::ZERO, w as f32, h as f32);
    let (px, py) = (fx.floor() as usize, fy.floor() as usize);
    let want = common::floor_footprint_mean(&wld, px, py, |p| {
        let d2 = (p.x * p.x + p.z * p.z) as f64 + 4.0;
        100.0 * 2.0 / d2.powf(1.5) * RHO / std::f64::consts::PI
    });
    let p = &film.pixels[py * w as usize + px];
    let (l, se) = (
        p.mean_xyz()[1],
        p.y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES),
    );
    eprintln!(
        "foot pixel ({px}, {py}) of ({fx:.2}, {fy:.2}): {l} ± {se} cd/m², expected {want} (25ρ/π = {})",
        25.0 * RHO / std::f64::consts::PI
    );
    assert!((want / (25.0 * RHO / std::f64::consts::PI) - 1.0).abs() < 0.01);
    assert!(
        (l - want).abs() <= 5.0 * se && se < 0.01 * want,
        "{l} ± {se} vs {want}"
    );
    assert!(y(px, py) > 0.0);
}

/// Camera choice and its errors: by index or name; an unknown index or name, a file without
/// a camera, an orthographic camera and `--camera` on a RON scene are clear errors naming the
/// file and what it has. The CLI renders a `.gltf` given as the scene.
#[test]
fn gltf_scene_camera_choice_and_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let marker = Vec3::new(0.3, 0.0, 0.2);
    plane_scene(d, "plane.gltf", marker, Some(perspective()));
    let o = |c: &str| Overrides {
        camera: Some(c.into()),
        resolution: Some((8, 6)),
        ..Default::default()
    };
    let path = d.join("plane.gltf");
    let first = load_world(&path, &o("0")).unwrap_or_else(|e| panic!("{e}"));
    for c in ["main", "persp"] {
        let w = load_world(&path, &o(c)).unwrap_or_else(|e| panic!("{e}"));
        let (r0, r1) = (
            first.camera.generate_ray(3.5, 2.5, glam::Vec2::ZERO),
            w.camera.generate_ray(3.5, 2.5, glam::Vec2::ZERO),
        );
        assert!((r0.origin - r1.origin).length() < 1e-6 && (r0.dir - r1.dir).length() < 1e-6);
    }
    let err = |p: &Path, o: &Overrides| match load_world(p, o) {
        Ok(_) => panic!("{} loaded", p.display()),
        Err(e) => e.to_string(),
    };
    let e = err(&path, &o("3"));
    assert!(
        e.contains("plane.gltf") && e.contains("has 1 camera node") && e.contains("\"main\""),
        "{e}"
    );
    let e = err(&path, &o("balcony"));
    assert!(e.contains("no camera node named \"balcony\""), "{e}");
    plane_scene(d, "blind.glb", marker, None);
    let e = err(&d.join("blind.glb"), &Overrides::default());
    assert!(
        e.contains("blind.glb") && e.contains("has no camera node"),
        "{e}"
    );
    plane_scene(
        d,
        "ortho.glb",
        marker,
        Some(
            json!({"type": "orthographic", "orthographic": {"xmag": 1.0, "ymag": 1.0, "znear": 0.01, "zfar": 10.0}}),
        ),
    );
    let e = err(&d.join("ortho.glb"), &Overrides::default());
    assert!(e.contains("orthographic"), "{e}");
    std::fs::write(
        d.join("s.ron"),
        r#"(camera: (position: (0, 1, 2), look_at: (0, 0, 0), vfov_deg: 40, resolution: (4, 4)),
            objects: [(shape: Sphere(center: (0, 0, 0), radius: 0.5), material: "black")])"#,
    )
    .unwrap();
    let e = err(&d.join("s.ron"), &o("0"));
    assert!(
        e.contains("--camera 0 chooses among a glTF file's cameras"),
        "{e}"
    );
    // The CLI: the glTF as the scene, its camera by name, a resolution, and a clear error for
    // a bad camera.
    let (code, _, stderr) = common::cli(
        &[
            "render",
            "--quiet",
            "--spp",
            "2",
            "--resolution",
            "16x12",
            "--camera",
            "main",
            "--out",
            "out",
            "plane.gltf",
        ],
        d,
    );
    assert_eq!(code, 0, "{stderr}");
    assert!(d.join("out.exr").exists() && d.join("out.png").exists());
    let (code, _, stderr) = common::cli(&["render", "--quiet", "--camera", "7", "plane.gltf"], d);
    assert_ne!(code, 0);
    assert!(
        stderr.contains("has 1 camera node") && !stderr.contains("panicked"),
        "{stderr}"
    );
    let (code, _, stderr) = common::cli(
        &["render", "--quiet", "--resolution", "16by12", "plane.gltf"],
        d,
    );
    assert_ne!(code, 0);
    assert!(stderr.contains("WIDTHxHEIGHT"), "{stderr}");
}

/// A RON scene takes its camera from a glTF model it places (`camera: (from_model: …)`): the
/// same rays as the file rendered on its own, moved by the object's transform; `vfov_deg` or a
/// projection replaces only the field of view; `--camera` chooses among the model's cameras;
/// an unknown object, a non-glTF object, an unknown camera and `position` beside `from_model`
/// are clear errors.
#[test]
fn ron_scene_takes_its_camera_from_a_model() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    plane_scene(
        d,
        "plane.gltf",
        Vec3::new(0.3, 0.0, 0.2),
        Some(perspective()),
    );
    let (w, h) = (60u32, 40u32);
    let alone = load_world(
        &d.join("plane.gltf"),
        &Overrides {
            resolution: Some((w, h)),
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let ron = |camera: &str, transform: &str| {
        let text = format!(
            r#"(camera: ({camera}resolution: ({w}, {h})),
                objects: [(name: "box", shape: Sphere(center: (0, -5, 0), radius: 0.5), material: "black"),
                          (name: "plane", shape: Model(file: "plane.gltf", lights: true){transform})])"#
        );
        std::fs::write(d.join("s.ron"), text).unwrap();
        d.join("s.ron")
    };
    let load = |p: &Path, o: &Overrides| load_world(p, o).unwrap_or_else(|e| panic!("{e}"));
    let placed = load(
        &ron("from_model: (object: \"plane\"), ", ""),
        &Overrides::default(),
    );
    let moved = load(
        &ron(
            "from_model: (object: \"plane\", camera: \"main\"), ",
            ", transform: (rotate_deg: (0, 30, 0), translate: (1, 0.5, -2))",
        ),
        &Overrides::default(),
    );
    let t = Mat4::from_translation(Vec3::new(1.0, 0.5, -2.0))
        * Mat4::from_rotation_y(30f32.to_radians());
    for (x, y) in [(0.5, 0.5), (41.5, 13.5), (59.5, 39.5), (30.0, 20.0)] {
        let r0 = alone.camera.generate_ray(x, y, glam::Vec2::ZERO);
        let r1 = placed.camera.generate_ray(x, y, glam::Vec2::ZERO);
        assert!(
            (r0.origin - r1.origin).length() < 1e-5 && (r0.dir - r1.dir).length() < 1e-6,
            "pixel ({x}, {y}): {r0:?} vs {r1:?}"
        );
        let r2 = moved.camera.generate_ray(x, y, glam::Vec2::ZERO);
        let (o, dir) = (
            t.transform_point3(r0.origin),
            t.transform_vector3(r0.dir).normalize(),
        );
        assert!(
            (o - r2.origin).length() < 1e-5 && (dir - r2.dir).length() < 1e-5,
            "moved pixel ({x}, {y}): {o} {dir} vs {r2:?}"
        );
    }
    // A wider field of view from the same point, and a fisheye there.
    let wide = load(
        &ron("from_model: (object: \"plane\"), vfov_deg: 80, ", ""),
        &Overrides::default(),
    );
    let (c0, c1) = (
        alone.camera.generate_ray(30.0, 20.0, glam::Vec2::ZERO),
        wide.camera.generate_ray(30.0, 20.0, glam::Vec2::ZERO),
    );
    assert!((c0.origin - c1.origin).length() < 1e-5 && (c0.dir - c1.dir).length() < 1e-6);
    let (e0, e1) = (
        alone.camera.generate_ray(30.0, 0.0, glam::Vec2::ZERO),
        wide.camera.generate_ray(30.0, 0.0, glam::Vec2::ZERO),
    );
    let half = |r: &candela::camera::CameraRay| r.dir.angle_between(c0.dir).to_degrees();
    assert!((half(&e0) - YFOV_DEG / 2.0).abs() < 0.01 && (half(&e1) - 40.0).abs() < 0.01);
    let fish = load(
        &ron(
            "from_model: (object: \"plane\"), projection: Fisheye(mapping: Equidistant, fov_deg: 180), ",
            "",
        ),
        &Overrides::default(),
    );
    let f = fish.camera.generate_ray(30.0, 20.0, glam::Vec2::ZERO);
    assert!((f.origin - c0.origin).length() < 1e-5 && (f.dir - c0.dir).length() < 1e-3);
    // --camera chooses among the model's cameras.
    let by_flag = load(
        &ron("from_model: (object: \"plane\"), ", ""),
        &Overrides {
            camera: Some("persp".into()),
            ..Default::default()
        },
    );
    let r = by_flag.camera.generate_ray(41.5, 13.5, glam::Vec2::ZERO);
    assert!((r.dir - alone.camera.generate_ray(41.5, 13.5, glam::Vec2::ZERO).dir).length() < 1e-6);
    let err = |camera: &str| match load_world(&ron(camera, ""), &Overrides::default()) {
        Ok(_) => panic!("{camera} loaded"),
        Err(e) => e.to_string(),
    };
    let e = err("from_model: (object: \"room\"), ");
    assert!(
        e.contains("camera.from_model.object") && e.contains("\"room\"") && e.contains("\"plane\""),
        "{e}"
    );
    let e = err("from_model: (object: \"box\"), ");
    assert!(e.contains("not a glTF `Model`"), "{e}");
    let e = err("from_model: (object: \"plane\", camera: \"balcony\"), ");
    assert!(
        e.contains("camera.from_model.camera balcony") && e.contains("\"main\""),
        "{e}"
    );
    let e = err("from_model: (object: \"plane\"), position: (0, 1, 0), ");
    assert!(
        e.contains("camera.position") && e.contains("from_model"),
        "{e}"
    );
    let e = err("vfov_deg: 40, ");
    assert!(
        e.contains("camera.position") && e.contains("missing"),
        "{e}"
    );
}
