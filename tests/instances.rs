//! Instances: a mesh stored once and placed at many transforms (a two-level BVH) gives the
//! hits, shadows and renders of its copies written out as separate objects.

mod common;
#[path = "../src/cli/bench/generate.rs"]
#[allow(dead_code)]
mod generate;
#[path = "../src/cli/bench/rng.rs"]
#[allow(dead_code)]
mod rng;

use candela::geometry::{
    Hit, InstanceGroup, SceneGeometry, Shape, Transform, TriangleMesh, NO_INSTANCE,
};
use glam::{Affine3A, Mat3, Vec2, Vec3};
use rng::Rng;
use std::fmt::Write;
use std::path::Path;

/// A random invertible transform: rotation, non-uniform scale (0.3–2 per axis), a shear, a
/// mirror every third call, translation inside `reach`.
fn random_transform(rng: &mut Rng, k: usize, reach: f32) -> Transform {
    let rot = glam::Quat::from_scaled_axis(rng.unit_vector() * rng.range(0.0, 3.1));
    let scale = Vec3::new(
        rng.range(0.3, 2.0),
        rng.range(0.3, 2.0),
        rng.range(0.3, 2.0),
    );
    let mut m = Mat3::from_quat(rot) * Mat3::from_diagonal(scale);
    m.y_axis += 0.3 * m.x_axis; // shear
    if k % 3 == 0 {
        m.x_axis = -m.x_axis; // mirror
    }
    let t = rng.in_box(Vec3::splat(-reach), Vec3::splat(reach));
    Transform::from_affine(Affine3A::from_mat3_translation(m, t))
}

/// A convex, closed cube of side 2 with flat faces of `n`×`n` cells, outward front faces.
fn subdivided_cube(n: u32) -> TriangleMesh {
    let mut out = TriangleMesh::default();
    let face = generate::grid_mesh(n, n, 2.0, |_, _| 1.0); // z = 1, front +Z
    for r in [
        Vec3::ZERO,
        Vec3::new(180.0, 0.0, 0.0),
        Vec3::new(90.0, 0.0, 0.0),
        Vec3::new(-90.0, 0.0, 0.0),
        Vec3::new(0.0, 90.0, 0.0),
        Vec3::new(0.0, -90.0, 0.0),
    ] {
        let t = Transform::from_trs(Vec3::ZERO, r, Vec3::ONE);
        let base = out.positions.len() as u32;
        out.positions
            .extend(face.positions.iter().map(|&p| t.transform_point(p)));
        out.indices
            .extend(face.indices.iter().map(|t| t.map(|i| i + base)));
    }
    out
}

/// Two instanced meshes (one with vertex normals and texture coordinates, one of two parts)
/// beside a floor quad and a sphere; the same scene with every instance written out as copies.
struct Scenes {
    inst: SceneGeometry,
    copies: SceneGeometry,
    instances: usize,
}

fn scenes(rng: &mut Rng, per_group: usize) -> Scenes {
    let mut sphere_mesh = generate::bumpy_sphere(2);
    sphere_mesh.compute_vertex_normals();
    let sphere_uvs: Vec<Vec2> = sphere_mesh
        .positions
        .iter()
        .map(|p| Vec2::new(p.x, p.y))
        .collect();
    let grid = generate::grid_mesh(6, 6, 1.0, |x, y| 0.2 * (x * y).sin());
    let cube = generate::cube_sphere(2, 0.0);
    let a = Shape::Mesh(sphere_mesh);
    let (b0, b1) = (Shape::Mesh(grid), Shape::Mesh(cube));
    let t1: Vec<Transform> = (0..per_group)
        .map(|k| random_transform(rng, k, 6.0))
        .collect();
    let t2: Vec<Transform> = (0..per_group)
        .map(|k| random_transform(rng, k + 1, 6.0))
        .collect();
    let flat = vec![
        (
            Shape::Quad {
                origin: Vec3::new(-8.0, -7.0, -8.0),
                edge_u: Vec3::new(0.0, 0.0, 16.0),
                edge_v: Vec3::new(16.0, 0.0, 0.0),
            },
            0,
        ),
        (
            Shape::Sphere {
                center: Vec3::new(1.0, 2.0, -1.0),
                radius: 1.5,
            },
            1,
        ),
    ];
    let first2 = 2 + per_group as u32;
    let groups = [
        InstanceGroup {
            parts: vec![(&a, Some(&sphere_uvs[..]))],
            transforms: &t1,
            first_object: 2,
        },
        InstanceGroup {
            parts: vec![(&b0, None), (&b1, None)],
            transforms: &t2,
            first_object: first2,
        },
    ];
    let mut uvs: Vec<Option<&[Vec2]>> = vec![None, None];
    let inst = SceneGeometry::build_instanced(&flat, &uvs, &groups).unwrap();
    let mut shapes = flat.clone();
    for (k, t) in t1.iter().enumerate() {
        shapes.push((a.to_world(t).unwrap(), 2 + k as u32));
        uvs.push(Some(&sphere_uvs));
    }
    for (k, t) in t2.iter().enumerate() {
        shapes.push((b0.to_world(t).unwrap(), first2 + 2 * k as u32));
        shapes.push((b1.to_world(t).unwrap(), first2 + 2 * k as u32 + 1));
        uvs.extend([None, None]);
    }
    let copies = SceneGeometry::build_with_uvs(&shapes, &uvs).unwrap();
    assert_eq!(
        inst.instanced_triangle_count() as usize + inst.primitive_count(),
        copies.primitive_count()
    );
    Scenes {
        inst,
        copies,
        instances: 2 * per_group,
    }
}

fn close3(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol * (1.0 + a.abs().max(b.abs()).max_element())
}

/// Same surface, object, sides and normals (copies are intersected in world space, instances
/// in object space: t and p agree to rounding).
fn same_hit(a: &Hit, b: &Hit) -> bool {
    a.object == b.object
        && (a.t - b.t).abs() <= 1e-4 * (1.0 + a.t.max(b.t))
        && close3(a.p, b.p, 1e-4)
        && a.ng.dot(b.ng) > 0.9999
        && a.ns.dot(b.ns) > 0.999
        && a.front_face == b.front_face
        && close3(a.tex.extend(0.0), b.tex.extend(0.0), 1e-3)
}

/// Closest hits and shadow queries on random rays (through the instances and from inside
/// the cloud of them): the two-level BVH gives exactly the brute-force hit over every
/// triangle of every instance, and the hits of the copies. A copy and its instance round
/// differently, so a ray within a few ulps of an edge between two objects may hit either:
/// at most 0.1 % of rays may disagree with the copies (none did when this was written).
#[test]
fn closest_and_shadow_hits_match_brute_force_and_copies() {
    let mut rng = Rng::new(18);
    let s = scenes(&mut rng, 40);
    assert_eq!(s.inst.instance_count(), s.instances);
    let (mut hits, mut on_instances, mut differ) = (0, 0, 0);
    const RAYS: usize = 4000;
    for k in 0..RAYS {
        let o = rng.in_box(Vec3::splat(-9.0), Vec3::splat(9.0));
        let target = rng.in_box(Vec3::splat(-6.0), Vec3::splat(6.0));
        let d = (target - o) * rng.range(0.2, 3.0);
        let t_max = if k % 4 == 0 {
            rng.range(0.1, 1.5)
        } else {
            f32::INFINITY
        };
        let h = s.inst.intersect(o, d, t_max);
        let b = s.inst.intersect_brute_force(o, d, t_max);
        assert_eq!(h, b, "ray {k}: two-level BVH vs brute force");
        let c = s.copies.intersect(o, d, t_max);
        match (&h, &c) {
            (Some(h), Some(c)) => {
                hits += 1;
                if h.instance != NO_INSTANCE {
                    on_instances += 1;
                    assert!(h.ng.is_normalized() && h.ns.is_normalized());
                }
                if !same_hit(h, c) {
                    eprintln!("ray {k}: instances {h:?}\n   copies {c:?}");
                    differ += 1;
                }
            }
            (None, None) => {}
            _ => differ += 1,
        }
        assert_eq!(s.inst.occluded(o, d, t_max), b.is_some(), "ray {k}: shadow");
        let basic = s.inst.intersect_basic(o, d, t_max);
        assert_eq!(
            basic.map(|x| (x.t, x.object)),
            h.map(|x| (x.t, x.object)),
            "ray {k}: intersect_basic, instance {:?}",
            h.map(|x| x.instance)
        );
        if let (Some(x), Some(h)) = (basic, h) {
            assert!(x.ng.normalize().dot(h.ng) > 0.9999, "ray {k}: basic normal");
            if h.instance != NO_INSTANCE {
                assert_eq!((x.u, x.v), (h.uv.x, h.uv.y), "ray {k}: basic barycentrics");
            }
        }
    }
    eprintln!(
        "{RAYS} rays: {hits} hits, {on_instances} on instances, {differ} differ from the copies"
    );
    assert!(
        on_instances > RAYS / 4,
        "the rays must mostly hit instances"
    );
    assert!(
        differ * 1000 <= RAYS,
        "{differ} of {RAYS} rays differ from the copies"
    );
}

/// Rays spawned from hits on instanced closed convex meshes (rotated, non-uniformly scaled,
/// sheared, mirrored; from millimetres to kilometres) leave without re-hitting their surface
/// outward, and reach the far side inward.
#[test]
fn instances_spawn_rays_without_self_intersection() {
    let mut rng = Rng::new(19);
    let cube = Shape::Mesh(subdivided_cube(6));
    for scale in [1e-3f32, 1.0, 1e3] {
        let tfs: Vec<Transform> = (0..6)
            .map(|k| {
                let t = random_transform(&mut rng, k, 0.0);
                Transform::from_affine(
                    Affine3A::from_translation(Vec3::new(5.0 * k as f32, 0.0, 0.0) * scale)
                        * Affine3A::from_scale(Vec3::splat(scale))
                        * t.matrix,
                )
            })
            .collect();
        let groups = [InstanceGroup {
            parts: vec![(&cube, None)],
            transforms: &tfs,
            first_object: 0,
        }];
        let g = SceneGeometry::build_instanced(&[], &[], &groups).unwrap();
        let mut n = 0;
        for _ in 0..3000 {
            let k = (rng.f32() * 6.0) as usize % 6;
            let c = tfs[k].transform_point(Vec3::ZERO);
            let o = c + rng.unit_vector() * 8.0 * scale;
            let Some(h) = g.intersect(o, c + rng.unit_vector() * 0.3 * scale - o, f32::INFINITY)
            else {
                continue;
            };
            n += 1;
            let mut w = rng.unit_vector();
            if w.dot(h.ng) < 0.0 {
                w = -w;
            }
            let x = g.intersect(h.spawn_origin(w), w, f32::INFINITY);
            assert!(
                x.is_none_or(|x| x.instance != h.instance),
                "scale {scale}: outward ray re-hit its instance at t = {:?}",
                x.map(|x| x.t)
            );
            let w = -w;
            if w.dot(-h.ng) > 0.05 {
                let x = g
                    .intersect(h.spawn_origin(w), w, f32::INFINITY)
                    .expect("an inward ray reaches the far side");
                assert!(
                    x.ng.dot(h.ng) < 0.9999 && !x.front_face,
                    "scale {scale}: inward"
                );
            }
        }
        assert!(n > 1000);
    }
}

/// A box of 12 triangles, 0.4 m wide and 0.6 m tall, standing on y = 0.
const BOX: &str = "Triangles(positions: [(-0.2, 0, -0.2), (0.2, 0, -0.2), (0.2, 0, 0.2), (-0.2, 0, 0.2), (-0.2, 0.6, -0.2), (0.2, 0.6, -0.2), (0.2, 0.6, 0.2), (-0.2, 0.6, 0.2)], indices: [(0, 1, 2), (0, 2, 3), (4, 6, 5), (4, 7, 6), (0, 4, 5), (0, 5, 1), (1, 5, 6), (1, 6, 2), (2, 6, 7), (2, 7, 3), (3, 7, 4), (3, 4, 0)])";

/// The placements of the boxes: a 40 × 25 grid, each turned and stretched its own way.
fn box_transforms() -> Vec<String> {
    (0..1000)
        .map(|k| {
            let (i, j) = ((k % 40) as f32, (k / 40) as f32);
            format!(
                "(translate: ({}, 0, {}), rotate_deg: (0, {}, 0), scale: ({}, {}, 1))",
                -9.75 + 0.5 * i,
                -6.0 + 0.5 * j,
                (k * 37) % 360,
                0.5 + 0.05 * (k % 7) as f32,
                0.6 + 0.1 * (k % 5) as f32
            )
        })
        .collect()
}

fn boxes_scene(objects: &str) -> String {
    format!(
        r#"(
    camera: (position: (0, 6, 10), look_at: (0, 0, 0), vfov_deg: 60, resolution: (48, 32)),
    render: (spp: 16, max_depth: 3, seed: 5),
    materials: {{ "grey": Diffuse(reflectance: Constant(0.6)), "red": Diffuse(reflectance: Rgb(0.7, 0.2, 0.1)) }},
    objects: [
        (shape: Quad(origin: (-12, 0, -12), edge_u: (0, 0, 24), edge_v: (24, 0, 0)), material: "grey"),
        {objects}
    ],
    lights: [
        Distant(direction: (0.3, -1, -0.4), spectrum: Named("D65"), amount: Illuminance(10000.0)),
        Environment(spectrum: Named("D65"), amount: Luminance(1000.0)),
    ],
)"#
    )
}

/// 1 000 instances of a box render as 1 000 copies written as separate objects. Not
/// bit-identical: an instance is intersected in its object space, so hit points differ from
/// the copies' in the last bits and a path can take another turn. With the same seed the two
/// renders share their random numbers; every 8×8-pixel block must agree within 4.5 standard
/// errors of independent renders (24 blocks), and so must the image mean. (When this was
/// written 38 % of the pixels were bit-identical and the means differed by 2·10⁻⁵.)
#[test]
fn thousand_instances_render_as_thousand_copies() {
    let tfs = box_transforms();
    let instanced = boxes_scene(&format!(
        "(shape: Instances(mesh: {BOX}, transforms: [{}]), material: \"red\"),",
        tfs.join(", ")
    ));
    let mut copies = String::new();
    for t in &tfs {
        writeln!(copies, "(shape: {BOX}, material: \"red\", transform: {t}),").unwrap();
    }
    let copies = boxes_scene(&copies);
    let wi = common::world(&instanced);
    let wc = common::world(&copies);
    assert_eq!(wi.geometry.instance_count(), 1000);
    assert_eq!(wi.geometry.instanced_triangle_count(), 12_000);
    assert_eq!(wi.objects.len(), wc.objects.len());
    let (mi, mc) = (wi.geometry.memory_bytes(), wc.geometry.memory_bytes());
    eprintln!("geometry memory: instanced {mi} B, copies {mc} B");
    let (a, b) = (common::render(&wi, 2), common::render(&wc, 2));
    let identical = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| p.mean_xyz() == q.mean_xyz())
        .count();
    let worst = common::assert_blocks_agree(&a, &b, 8, ("instances", "copies"));
    let ((ya, sa), (yb, sb)) = (common::image_mean(&a), common::image_mean(&b));
    eprintln!(
        "instances vs copies: mean Y {:.3} vs {:.3} cd/m², worst block |z| {worst:.3}, {identical} of {} pixels bit-identical",
        ya[1],
        yb[1],
        a.pixels.len()
    );
    assert!(((ya[1] - yb[1]) / (sa * sa + sb * sb).sqrt()).abs() < 4.0);
}

/// An instanced Lambertian tile under illuminance E has luminance E·ρ/π. The tiles' object
/// space is tilted and stretched (the instance transform turns a slanted, non-uniformly scaled
/// mesh into horizontal tiles), so a normal carried by the transform itself instead of its
/// inverse transpose would tilt the shading frame and change the cosine.
#[test]
fn instanced_lambertian_has_luminance_e_rho_over_pi() {
    let m0 = Transform::from_trs(
        Vec3::ZERO,
        Vec3::new(35.0, -20.0, 50.0),
        Vec3::new(0.5, 2.0, 1.3),
    );
    let inv = m0.matrix.inverse();
    // A 2 m × 1 m horizontal tile in world space, front face up (+Y), as an object-space mesh.
    let world = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(2.0, 0.0, 1.0),
        Vec3::new(2.0, 0.0, 0.0),
    ];
    let pos: Vec<String> = world
        .iter()
        .map(|&p| {
            let q = inv.transform_point3(p);
            format!("({:?}, {:?}, {:?})", q.x, q.y, q.z)
        })
        .collect();
    // The object-space normal of the tile (the inverse-transpose image of +Y is +Y).
    let n = Mat3::from(m0.matrix.matrix3).transpose() * Vec3::Y;
    let n = format!("({:?}, {:?}, {:?})", n.x, n.y, n.z);
    let (r, s) = (Vec3::new(35.0, -20.0, 50.0), Vec3::new(0.5, 2.0, 1.3));
    let mut tfs = Vec::new();
    for i in 0..2 {
        for j in 0..4 {
            tfs.push(format!(
                "(translate: ({}, 0, {}), rotate_deg: ({:?}, {:?}, {:?}), scale: ({:?}, {:?}, {:?}))",
                -2.0 + 2.0 * i as f32,
                -2.0 + j as f32,
                r.x,
                r.y,
                r.z,
                s.x,
                s.y,
                s.z
            ));
        }
    }
    // The instance transform is T·M0 but the scene gives T·R·S; they are the same matrix.
    let text = format!(
        r#"(
    camera: (position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 90, resolution: (24, 24)),
    render: (spp: 32, max_depth: 1),
    materials: {{ "tile": Diffuse(reflectance: Constant(0.6)) }},
    objects: [(shape: Instances(mesh: Triangles(positions: [{}], indices: [(0, 1, 2), (0, 2, 3)], normals: [{n}, {n}, {n}, {n}]), transforms: [{}]), material: "tile")],
    lights: [Distant(direction: (0, -1, 0), spectrum: Named("D65"), amount: Illuminance(1000.0))],
)"#,
        pos.join(", "),
        tfs.join(", ")
    );
    let w = common::world(&text);
    let h = w
        .geometry
        .intersect(Vec3::new(0.3, 1.0, 0.2), -Vec3::Y, f32::INFINITY)
        .expect("the tiles are under the camera");
    assert!(h.ng.dot(Vec3::Y) > 0.99999 && h.ns.dot(Vec3::Y) > 0.99999);
    let film = common::render(&w, 2);
    let (m, se) = common::image_mean(&film);
    let expected = 1000.0 * 0.6 / std::f64::consts::PI;
    eprintln!(
        "instanced tile: {:.4} ± {se:.4} cd/m², E·ρ/π = {expected:.4}",
        m[1]
    );
    common::assert_estimate_near(m[1], se, expected, 0.01, "instanced tile");
    common::assert_every_pixel(&film, expected, 5.0);
}

fn scene_error(objects: &str) -> String {
    let text = format!(
        r#"(
    camera: (position: (0, 1, 5), look_at: (0, 0, 0), vfov_deg: 60, resolution: (8, 8)),
    materials: {{ "grey": Diffuse(reflectance: Constant(0.5)) }},
    objects: [{objects}],
    lights: [Distant(direction: (0, -1, 0), spectrum: Named("D65"), amount: Illuminance(1000.0))],
)"#
    );
    let path = Path::new("test-scene.ron");
    let s = match candela::scene::parse(&text, path) {
        Ok(s) => s,
        Err(e) => return e.to_string(),
    };
    match candela::scene::build(&s, path, &candela::scene::Overrides::default()) {
        Ok(_) => panic!("scene with {objects} was accepted"),
        Err(e) => e.to_string(),
    }
}

/// Bad instance lists are refused with the field named.
#[test]
fn bad_instances_are_clear_errors() {
    let tri = "Triangles(positions: [(0, 0, 0), (1, 0, 0), (0, 1, 0)], indices: [(0, 1, 2)])";
    let cases = [
        (
            format!("(shape: Instances(mesh: {tri}, transforms: []), material: \"grey\")"),
            "objects[0].shape.transforms",
            "empty",
        ),
        (
            format!("(shape: Instances(mesh: {tri}, transforms: [(), (scale: (1, 0, 1))]), material: \"grey\")"),
            "objects[0].shape.transforms[1].scale",
            "greater than 0",
        ),
        (
            format!("(shape: Instances(mesh: {tri}, transforms: [(translate: (NaN, 0, 0))]), material: \"grey\")"),
            "objects[0].shape.transforms[0].translate",
            "",
        ),
        (
            format!("(shape: Instances(mesh: {tri}, transforms: [(scale: (1e-30, 1e-30, 1e-30))]), material: \"grey\")"),
            "objects[0].shape.transforms[0]",
            "singular",
        ),
        (
            "(shape: Instances(mesh: Sphere(center: (0, 0, 0), radius: 1), transforms: [()]), material: \"grey\")".to_string(),
            "objects[0].shape",
            "triangle meshes",
        ),
        (
            format!("(shape: Instances(mesh: Instances(mesh: {tri}, transforms: [()]), transforms: [()]), material: \"grey\")"),
            "objects[0].shape",
            "nested",
        ),
    ];
    for (objects, field, words) in cases {
        let e = scene_error(&objects);
        eprintln!("{e}");
        assert!(e.contains(field) && e.contains(words), "{objects}: {e}");
    }
}
