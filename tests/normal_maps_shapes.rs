//! Normal maps on instanced meshes, spheres and disks. An instance's tangent frame is its
//! mesh's object-space dp/du, dp/dv carried by the instance's linear part, so an instanced
//! normal-mapped mesh gives the derivatives and the render of its world-space copies (rotated,
//! stretched, mirrored); a flat map changes nothing to the bit; and a constant tilted map on a
//! Lambertian disk or sphere under a distant light gives, pixel by pixel, E·ρ·cos/π of the
//! tilted normal, whose frame is the shape's parameterisation: x along increasing u (a disk's
//! radius, a sphere's φ), y along increasing v (a disk's φ, a sphere's θ from +Z).

mod common;
use candela::bxdf::normal_map::NormalMapped;
use candela::bxdf::Material;
use candela::film::Film;
use candela::geometry::{InstanceGroup, SceneGeometry, Shape, Transform, TriangleMesh};
use candela::texture::bytes::ByteTexture;
use candela::world::World;
use glam::{Affine3A, Mat3, Quat, Vec2, Vec3};
use serde_json::{json, Value};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

/// A bumpy 2 m × 2 m tile of `n`×`n` cells in the xy plane (front +Z) with texture coordinates
/// on a rotated, sheared layout (dp/du along no edge).
fn bumpy_tile(n: u32) -> (TriangleMesh, Vec<Vec2>) {
    let (mut mesh, mut uvs) = (TriangleMesh::default(), Vec::new());
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (
                2.0 * i as f32 / n as f32 - 1.0,
                2.0 * j as f32 / n as f32 - 1.0,
            );
            mesh.positions
                .push(Vec3::new(x, y, 0.15 * (2.0 * x).sin() * (3.0 * y).cos()));
            uvs.push(Vec2::new(
                0.4 * x + 0.15 * y + 0.5,
                -0.2 * x + 0.45 * y + 0.5,
            ));
        }
    }
    for j in 0..n {
        for i in 0..n {
            let v = |a: u32, b: u32| (j + b) * (n + 1) + i + a;
            mesh.indices.push([v(0, 0), v(1, 0), v(1, 1)]);
            mesh.indices.push([v(0, 0), v(1, 1), v(0, 1)]);
        }
    }
    (mesh, uvs)
}

/// Placements: translated, rotated, stretched and sheared, mirrored (one axis, then all three),
/// each 10 m from the next.
fn placements() -> Vec<Transform> {
    let rot = Quat::from_axis_angle(Vec3::new(0.3, 1.0, 0.2).normalize(), 0.9);
    let linear = [
        Mat3::IDENTITY,
        Mat3::from_quat(rot),
        Mat3::from_quat(rot)
            * Mat3::from_cols(Vec3::new(1.6, 0.0, 0.0), Vec3::new(0.5, 0.6, 0.0), Vec3::Z),
        Mat3::from_diagonal(Vec3::new(-1.0, 1.0, 1.0)),
        Mat3::from_quat(rot) * Mat3::from_diagonal(Vec3::new(1.3, -0.7, 1.0)),
        Mat3::from_diagonal(Vec3::new(-1.2, -1.0, -0.8)),
    ];
    linear
        .iter()
        .enumerate()
        .map(|(k, &m)| {
            Transform::from_affine(Affine3A::from_mat3_translation(
                m,
                Vec3::new(10.0 * k as f32, 1.0, -2.0),
            ))
        })
        .collect()
}

/// At hits on random rays, an instanced mesh (with texture coordinates, and without: its
/// barycentrics) has the dp/du, dp/dv of its world-space copies, to f32 rounding: tangent to
/// the world-space surface, and with the copies' handedness under mirroring transforms.
#[test]
fn instance_derivatives_are_the_copies() {
    let (tile, uvs) = bumpy_tile(6);
    let shape = Shape::Mesh(tile);
    let tfs = placements();
    // Group 2 is the same tile without texture coordinates, 30 m further along z.
    let tfs2: Vec<Transform> = tfs
        .iter()
        .map(|t| {
            Transform::from_trs(Vec3::new(0.0, 0.0, 30.0), Vec3::ZERO, Vec3::ONE).then_after(t)
        })
        .collect();
    let groups = [
        InstanceGroup {
            parts: vec![(&shape, Some(&uvs[..]))],
            transforms: &tfs,
            first_object: 0,
        },
        InstanceGroup {
            parts: vec![(&shape, None)],
            transforms: &tfs2,
            first_object: 6,
        },
    ];
    let inst = SceneGeometry::build_instanced(&[], &[], &groups).unwrap();
    let mut shapes = Vec::new();
    let mut shape_uvs: Vec<Option<&[Vec2]>> = Vec::new();
    for (k, t) in tfs.iter().chain(&tfs2).enumerate() {
        shapes.push((shape.to_world(t).unwrap(), k as u32));
        shape_uvs.push((k < 6).then_some(&uvs[..]));
    }
    let copies = SceneGeometry::build_with_uvs(&shapes, &shape_uvs).unwrap();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut checked = [0usize; 12];
    for k in 0..3000 {
        let obj = k % 12; // aimed at; `a.object` is the one hit
        let t = if obj < 6 { &tfs[obj] } else { &tfs2[obj - 6] };
        let (x, y) = (1.8 * rnd() - 0.9, 1.8 * rnd() - 0.9);
        let target = t.transform_point(Vec3::new(x, y, 0.15 * (2.0 * x).sin() * (3.0 * y).cos()));
        let w = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize();
        let o = target + 4.0 * w;
        let (Some(a), Some(b)) = (
            inst.intersect(o, target - o, 1.01),
            copies.intersect(o, target - o, 1.01),
        ) else {
            continue;
        };
        if a.object != b.object || (a.p - b.p).length() > 1e-4 || (a.tex - b.tex).length() > 1e-4 {
            continue; // a ray along an edge between two triangles (rounding picks either)
        }
        let obj = a.object as usize;
        let (du, dv) = inst
            .texture_derivatives(&a)
            .unwrap_or_else(|| panic!("no tangent frame at {a:?}"));
        let (cu, cv) = copies.texture_derivatives(&b).unwrap();
        let close = |x: Vec3, y: Vec3| (x - y).length() <= 2e-4 * (1.0 + y.length());
        assert!(
            close(du, cu) && close(dv, cv),
            "object {obj}: instance ({du}, {dv}), copy ({cu}, {cv})"
        );
        // Tangent to the surface, and the copy's handedness (the sign of (dp/du × dp/dv)·ng).
        assert!(
            du.dot(a.ng).abs() <= 1e-4 * du.length() && dv.dot(a.ng).abs() <= 1e-4 * dv.length()
        );
        assert_eq!(
            du.cross(dv).dot(a.ng) > 0.0,
            cu.cross(cv).dot(b.ng) > 0.0,
            "object {obj}"
        );
        checked[obj] += 1;
    }
    eprintln!("hits compared per instance: {checked:?}");
    assert!(checked.iter().all(|&c| c > 150), "{checked:?}");
}

/// A `w` × `h` normal map of texels `t` (top row first) as `dir`/`name`.
fn png(dir: &Path, name: &str, w: u32, h: u32, t: &[[u8; 3]]) {
    let raw: Vec<u8> = t.iter().flatten().copied().collect();
    image::RgbImage::from_raw(w, h, raw)
        .unwrap()
        .save(dir.join(name))
        .unwrap();
}

/// A 2 × 2 map of strong tilts in x and y (each texel about 1 m across on a tile).
const BUMPS: [[u8; 3]; 4] = [
    [200, 90, 230],
    [60, 170, 230],
    [90, 60, 230],
    [170, 200, 230],
];

/// `dir`/`name`: a glTF of the bumpy tile (turned to face +Y) placed by `nodes`: one mesh every
/// node places (instances), or with `instanced` false, one mesh per node (world-space copies),
/// of a grey Lambertian material with, if `map` is given, that normal texture.
fn tiles_gltf(dir: &Path, name: &str, nodes: &[Value], instanced: bool, map: Option<&str>) {
    let (tile, uvs) = bumpy_tile(4);
    let pos: Vec<[f32; 3]> = tile.positions.iter().map(|p| [p.x, p.z, -p.y]).collect();
    let mut bin: Vec<u8> = pos.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    let n_pos = bin.len();
    bin.extend(
        uvs.iter()
            .flat_map(|v| [v.x, v.y])
            .flat_map(|v| v.to_le_bytes()),
    );
    let n_uv = bin.len() - n_pos;
    bin.extend(tile.indices.iter().flatten().flat_map(|v| v.to_le_bytes()));
    let bin_name = format!("{name}.bin");
    std::fs::write(dir.join(&bin_name), &bin).unwrap();
    let (lo, hi) = pos
        .iter()
        .fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), p| {
            (
                std::array::from_fn(|k| lo[k].min(p[k])),
                std::array::from_fn(|k| hi[k].max(p[k])),
            )
        });
    let mut material = json!({"pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1.0],
                               "metallicFactor": 0.0, "roughnessFactor": 1.0}});
    if map.is_some() {
        material["normalTexture"] = json!({"index": 0});
    }
    let mesh = json!({"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
                                      "indices": 2, "material": 0}]});
    let n_meshes = if instanced { 1 } else { nodes.len() };
    let nodes: Vec<Value> = nodes
        .iter()
        .enumerate()
        .map(|(k, n)| {
            let mut n = n.clone();
            n["mesh"] = json!(if instanced { 0 } else { k });
            n
        })
        .collect();
    let doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bin.len(), "uri": bin_name}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": n_pos},
            {"buffer": 0, "byteOffset": n_pos, "byteLength": n_uv},
            {"buffer": 0, "byteOffset": n_pos + n_uv, "byteLength": bin.len() - n_pos - n_uv}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": pos.len(), "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5126, "count": uvs.len(), "type": "VEC2"},
            {"bufferView": 2, "componentType": 5125, "count": 3 * tile.indices.len(), "type": "SCALAR"}
        ],
        "meshes": vec![mesh; n_meshes],
        "nodes": nodes,
        "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "materials": [material],
        "images": map.iter().map(|f| json!({"uri": f})).collect::<Vec<_>>(),
        "textures": map.iter().map(|_| json!({"source": 0})).collect::<Vec<_>>(),
    });
    std::fs::write(dir.join(name), serde_json::to_vec_pretty(&doc).unwrap()).unwrap();
}

/// Three tiles: translated; rotated (50° about a tilted axis) and stretched; mirrored (x → −x,
/// then turned 30° about Y).
fn tile_nodes() -> Vec<Value> {
    let q = Quat::from_axis_angle(Vec3::new(0.3, 1.0, 0.2).normalize(), 50f32.to_radians());
    let (s, c) = 30f32.to_radians().sin_cos();
    vec![
        json!({"translation": [-2.3, 0.0, 0.0]}),
        json!({"rotation": [q.x, q.y, q.z, q.w], "scale": [1.2, 1.0, 0.8]}),
        json!({"matrix": [-c, 0.0, s, 0.0, 0.0, 1.0, 0.0, 0.0, s, 0.0, c, 0.0, 2.3, 0.0, 0.0, 1.0]}),
    ]
}

fn tiles_scene(file: &str) -> String {
    format!(
        r#"(
    camera: (position: (0, 5, 1.5), look_at: (0, 0, 0), vfov_deg: 45, resolution: (48, 32)),
    render: (spp: 16, max_depth: 3, seed: 7),
    materials: {{ "grey": Diffuse(reflectance: Constant(0.5)) }},
    objects: [
        (shape: Model(file: "{file}"), material: "grey"),
        (shape: Quad(origin: (-10, -1.5, -10), edge_u: (0, 0, 20), edge_v: (20, 0, 0)), material: "grey"),
    ],
    lights: [Distant(direction: (1, -0.5, 0.2), spectrum: Named("D65"), amount: Illuminance(10000.0))],
)"#
    )
}

fn render_tiles(dir: &Path, file: &str, instances: usize) -> Film {
    let w = common::world_in(&tiles_scene(file), dir);
    assert_eq!(w.geometry.instance_count(), instances, "{file}");
    common::render(&w, 2)
}

/// A normal-mapped glTF mesh placed by three nodes (instanced) renders as the same mesh placed
/// once per node (world-space copies): same seed, every 8×8 block within 4.5 combined standard
/// errors (an instance rounds its hits differently, so a path can take another turn), and the
/// image means within 4. The map matters: without it some block moves by more than 10.
#[test]
fn instanced_normal_mapped_mesh_renders_as_copies() {
    let dir = tempfile::tempdir().unwrap();
    png(dir.path(), "bumps.png", 2, 2, &BUMPS);
    let nodes = tile_nodes();
    tiles_gltf(dir.path(), "inst.gltf", &nodes, true, Some("bumps.png"));
    tiles_gltf(dir.path(), "copies.gltf", &nodes, false, Some("bumps.png"));
    tiles_gltf(dir.path(), "plain.gltf", &nodes, true, None);
    let a = render_tiles(dir.path(), "inst.gltf", 3);
    let b = render_tiles(dir.path(), "copies.gltf", 0);
    let identical = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| p.mean_xyz() == q.mean_xyz())
        .count();
    let worst = common::assert_blocks_agree(&a, &b, 8, ("instances", "copies"));
    let ((ya, sa), (yb, sb)) = (common::image_mean(&a), common::image_mean(&b));
    let z = (ya[1] - yb[1]) / (sa * sa + sb * sb).sqrt();
    eprintln!(
        "normal-mapped instances vs copies: mean Y {:.3} vs {:.3} cd/m² (z {z:.2}), worst block |z| {worst:.2}, {identical} of {} pixels bit-identical",
        ya[1],
        yb[1],
        a.pixels.len()
    );
    assert!(z.abs() < 4.0);
    let plain = render_tiles(dir.path(), "plain.gltf", 3);
    let moved = common::block_means(&a, 8)
        .iter()
        .zip(common::block_means(&plain, 8))
        .map(|((ma, sa), (mp, sp))| ((ma - mp) / (sa * sa + sp * sp).sqrt()).abs())
        .fold(0.0, f64::max);
    eprintln!("largest block |z| of the map's effect: {moved:.1}");
    assert!(moved > 10.0, "the normal map does not show ({moved})");
}

/// `world` with every object's material under the normal map of `texels` (`w` × `h`).
fn with_map(mut world: World, w: u32, h: u32, texels: Vec<[u8; 3]>) -> World {
    let map = ByteTexture::from_texels(w, h, texels);
    let first = world.materials.len() as u32;
    let mapped: Vec<Material> = world
        .materials
        .iter()
        .map(|m| {
            Material::NormalMapped(std::sync::Arc::new(NormalMapped {
                inner: m.clone(),
                map: map.clone(),
                scale: 1.0,
            }))
        })
        .collect();
    world.materials.extend(mapped);
    for o in &mut world.objects {
        o.material += first;
    }
    world
}

fn assert_bit_identical(a: &Film, b: &Film, what: &str) {
    for (i, (p, q)) in a.pixels.iter().zip(&b.pixels).enumerate() {
        assert_eq!(p.mean_xyz(), q.mean_xyz(), "{what}: pixel {i}");
    }
}

/// A flat map (128, 128, 255) leaves a sphere, a disk and an instanced mesh as they were, to
/// the bit.
#[test]
fn flat_normal_map_changes_nothing_on_shapes_and_instances() {
    let text = r#"(
    camera: (position: (0, 3, 4), look_at: (0, 0, 0), vfov_deg: 50, resolution: (32, 24)),
    render: (spp: 4, max_depth: 3, seed: 3),
    materials: { "white": Diffuse(reflectance: Constant(0.7)) },
    objects: [
        (shape: Sphere(center: (-0.8, 0.6, 0), radius: 0.6), material: "white"),
        (shape: Disk(center: (0.5, 0, 0.3), normal: (0.2, 1, 0.1), radius: 1.5), material: "white"),
    ],
    lights: [
        Distant(direction: (0.4, -1, -0.3), spectrum: Named("D65"), amount: Illuminance(10000.0)),
        Environment(spectrum: Named("D65"), amount: Luminance(1000.0)),
    ],
)"#;
    let plain = common::render(&common::world(text), 1);
    let mapped = common::render(
        &with_map(common::world(text), 2, 2, vec![[128, 128, 255]; 4]),
        1,
    );
    assert_bit_identical(&plain, &mapped, "sphere and disk");
    let dir = tempfile::tempdir().unwrap();
    png(dir.path(), "flat.png", 2, 2, &[[128, 128, 255]; 4]);
    let nodes = tile_nodes();
    tiles_gltf(dir.path(), "flat.gltf", &nodes, true, Some("flat.png"));
    tiles_gltf(dir.path(), "plain.gltf", &nodes, true, None);
    let a = render_tiles(dir.path(), "plain.gltf", 3);
    let b = render_tiles(dir.path(), "flat.gltf", 3);
    assert_bit_identical(&a, &b, "instances");
}

/// The texel (192, 160, 255): m = (64, 32, 127)/127 before normalising, a tilt of 29.4°.
const TILT: [u8; 3] = [192, 160, 255];

fn tilt() -> (f64, f64, f64) {
    let (x, y) = (64.0 / 127.0, 32.0 / 127.0);
    let l = (x * x + y * y + 1.0f64).sqrt();
    (x / l, y / l, 1.0 / l)
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = dot(a, a).sqrt();
    a.map(|v| v / l)
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Luminance (cd/m²) of a Lambertian of reflectance ρ = 0.8 with shading normal `n` (geometric
/// normal `ng`) seen along `wo` (toward the eye), lit by E = 1000 lx from `wi`: E·ρ·cos(wi, n)/π,
/// and nothing where either direction is below `n` while above `ng` (the geometric normal
/// decides sides: such a pair carries nothing) or the light is behind the surface.
fn lambert(n: [f64; 3], ng: [f64; 3], wo: [f64; 3], wi: [f64; 3]) -> f64 {
    if dot(wo, n) <= 0.0 || dot(wi, n) <= 0.0 || dot(wi, ng) <= 0.0 || dot(wo, ng) <= 0.0 {
        return 0.0;
    }
    1000.0 * 0.8 * dot(wi, n) / PI
}

/// Checks each pixel that `keep` selects against its expected value (the box-filter mean over
/// its footprint) within 5 standard errors, and their mean within 4 with a standard error below
/// 1 %; returns how many of them a render of `wrong` (the frame's y reversed) would fail by more
/// than 5 standard errors, and how many pixels were checked.
fn check_tilted(
    film: &Film,
    label: &str,
    keep: impl Fn(usize, usize) -> bool,
    expected: impl Fn(usize, usize) -> f64,
    wrong: impl Fn(usize, usize) -> f64,
) -> (usize, usize) {
    let (mut sum, mut sum_e, mut var, mut n, mut rejects) = (0.0, 0.0, 0.0, 0, 0);
    for y in 0..film.height {
        for x in 0..film.width {
            if !keep(x, y) {
                continue;
            }
            let (v, se) = common::luminance(&film.pixels[y * film.width + x]);
            let e = expected(x, y);
            assert!(
                (v - e).abs() <= 5.0 * se,
                "{label}, pixel ({x}, {y}): {v} ± {se}, expected {e}"
            );
            if (v - wrong(x, y)).abs() > 5.0 * se {
                rejects += 1;
            }
            sum += v;
            sum_e += e;
            var += se * se;
            n += 1;
        }
    }
    let (m, e, se) = (sum / n as f64, sum_e / n as f64, var.sqrt() / n as f64);
    eprintln!("{label}: {n} pixels, mean {m:.3} ± {se:.3} cd/m², expected {e:.3}; the reversed frame fails {rejects}");
    assert!(
        (m - e).abs() <= 4.0 * se && se < 0.01 * e,
        "{label}: mean {m} ± {se}, expected {e}"
    );
    (rejects, n)
}

/// A Lambertian disk (y = 0, facing +Y) under a constant tilted map and an oblique distant
/// light, seen from 1 m above its centre. Its frame is polar: x along increasing r (outward),
/// y along increasing φ (N × e_r), so the tilted normal turns about the centre and each pixel
/// has E·ρ·cos/π of its own. The 2 × 2 pixels at the centre, where the frame turns within a
/// pixel, are left out.
#[test]
fn tilted_map_on_a_disk_follows_the_cosine_law() {
    let text = r#"(
    camera: (position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 90, resolution: (32, 32)),
    render: (spp: 64, max_depth: 1),
    materials: { "white": Diffuse(reflectance: Constant(0.8)) },
    objects: [(shape: Disk(center: (0, 0, 0), normal: (0, 1, 0), radius: 3), material: "white")],
    lights: [Distant(direction: (-0.5, -1, 0.2), spectrum: Named("D65"), amount: Illuminance(1000.0))],
)"#;
    let w = with_map(common::world(text), 1, 1, vec![TILT]);
    let film = common::render(&w, 2);
    let wi = unit([0.5, 1.0, -0.2]);
    let (mx, my, mz) = tilt();
    let value = |p: Vec3, sign: f64| {
        let ng = [0.0, 1.0, 0.0];
        let er = unit([p.x as f64, 0.0, p.z as f64]);
        let ephi = cross(ng, er);
        let n: [f64; 3] = std::array::from_fn(|k| mx * er[k] + sign * my * ephi[k] + mz * ng[k]);
        let wo = unit([-p.x as f64, 1.0, -p.z as f64]);
        lambert(unit(n), ng, wo, wi)
    };
    let (rejects, n) = check_tilted(
        &film,
        "tilted map on a disk",
        |x, y| !((15..17).contains(&x) && (15..17).contains(&y)),
        |x, y| common::floor_footprint_mean(&w, x, y, |p| value(p, 1.0)),
        |x, y| common::floor_footprint_mean(&w, x, y, |p| value(p, -1.0)),
    );
    assert!(
        rejects > n / 4,
        "the test cannot tell the frame's y from its reverse"
    );
}

/// A Lambertian sphere (radius 1 at the origin) under a constant tilted map, seen from +X with
/// a distant light near the eye. Its frame is x along increasing φ (about +Z), y along
/// increasing θ (from +Z, so toward −Z on the equator). Only pixels whose whole footprint sees
/// the sphere within 45° of the view direction are checked (away from the silhouette and the
/// poles, where the light is in front of every shading and geometric normal).
#[test]
fn tilted_map_on_a_sphere_follows_the_cosine_law() {
    let text = r#"(
    camera: (position: (4, 0, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 30, resolution: (32, 32)),
    render: (spp: 64, max_depth: 1),
    materials: { "white": Diffuse(reflectance: Constant(0.8)) },
    objects: [(shape: Sphere(center: (0, 0, 0), radius: 1), material: "white")],
    lights: [Distant(direction: (-1, -0.3, -0.4), spectrum: Named("D65"), amount: Illuminance(1000.0))],
)"#;
    let w = with_map(common::world(text), 1, 1, vec![TILT]);
    let film = common::render(&w, 2);
    let wi = unit([1.0, 0.3, 0.4]);
    let (mx, my, mz) = tilt();
    // The unit normal where the ray (o, d) meets the unit sphere, if it does.
    let hit = |o: Vec3, d: Vec3| -> Option<([f64; 3], [f64; 3])> {
        let (o, d) = (o.as_dvec3(), d.as_dvec3().normalize());
        let b = o.dot(d);
        let disc = b * b - (o.length_squared() - 1.0);
        (disc >= 0.0).then(|| {
            let p = o + d * (-b - disc.sqrt());
            (p.to_array(), (-d).to_array())
        })
    };
    let value = |o: Vec3, d: Vec3, sign: f64| {
        let Some((ng, wo)) = hit(o, d) else {
            return 0.0;
        };
        let ephi = unit([-ng[1], ng[0], 0.0]);
        let etheta = cross(ephi, ng);
        let n: [f64; 3] =
            std::array::from_fn(|k| mx * ephi[k] + sign * my * etheta[k] + mz * ng[k]);
        lambert(unit(n), ng, wo, wi)
    };
    let inner = |x: usize, y: usize| {
        common::pixel_footprint_mean(&w, x, y, |o, d| match hit(o, d) {
            Some((ng, wo)) if dot(ng, wo) > 0.7 => 1.0,
            _ => 0.0,
        }) == 1.0
    };
    let (rejects, n) = check_tilted(
        &film,
        "tilted map on a sphere",
        inner,
        |x, y| common::pixel_footprint_mean(&w, x, y, |o, d| value(o, d, 1.0)),
        |x, y| common::pixel_footprint_mean(&w, x, y, |o, d| value(o, d, -1.0)),
    );
    assert!(n > 250, "{n} pixels checked");
    assert!(
        rejects > n / 4,
        "the test cannot tell the frame's y from its reverse"
    );
}

/// The scene's `NormalMapped(material: …, file: …)` puts a material under a map read from an
/// image: the tilted disk renders to the bit as with the map given in code; a missing image and
/// a map inside a map are errors naming the field.
#[test]
fn scene_normal_mapped_material_is_the_map_from_its_image() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("normal_maps_scene_material");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    png(&dir, "tilt.png", 1, 1, &[TILT]);
    let text = |material: &str| {
        format!(
            r#"(
    camera: (position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 90, resolution: (16, 16)),
    render: (spp: 16, max_depth: 1),
    materials: {{ "white": {material} }},
    objects: [(shape: Disk(center: (0, 0, 0), normal: (0, 1, 0), radius: 3), material: "white")],
    lights: [Distant(direction: (-0.5, -1, 0.2), spectrum: Named("D65"), amount: Illuminance(1000.0))],
)"#
        )
    };
    let plain = "Diffuse(reflectance: Constant(0.8))";
    let by_code = with_map(common::world(&text(plain)), 1, 1, vec![TILT]);
    let by_scene = common::world_in(
        &text(&format!(
            "NormalMapped(material: {plain}, file: \"tilt.png\", scale: 1.0)"
        )),
        &dir,
    );
    let (a, b) = (common::render(&by_code, 1), common::render(&by_scene, 1));
    assert_bit_identical(&a, &b, "scene NormalMapped");
    let unmapped = common::render(&common::world(&text(plain)), 1);
    assert!(a
        .pixels
        .iter()
        .zip(&unmapped.pixels)
        .any(|(p, q)| p.mean_xyz() != q.mean_xyz()));
    let err = |material: &str| {
        std::fs::write(dir.join("bad.ron"), text(material)).unwrap();
        match candela::scene::load_world(&dir.join("bad.ron"), &Default::default()) {
            Ok(_) => panic!("{material} loaded"),
            Err(e) => e.to_string(),
        }
    };
    let e = err(&format!(
        "NormalMapped(material: {plain}, file: \"gone.png\")"
    ));
    assert!(
        e.contains("materials") && e.contains(".file") && e.contains("gone.png"),
        "{e}"
    );
    let e = err(&format!(
        "NormalMapped(material: NormalMapped(material: {plain}, file: \"tilt.png\"), file: \"tilt.png\")"
    ));
    assert!(
        e.contains("cannot wrap another normal-mapped material"),
        "{e}"
    );
}
