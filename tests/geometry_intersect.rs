//! Ray–shape intersection against analytic answers, BVH vs brute force, transforms.

#[path = "../src/cli/bench/generate.rs"]
#[allow(dead_code)]
mod generate;
#[path = "../src/cli/bench/rng.rs"]
#[allow(dead_code)]
mod rng;

use candela::geometry::{SceneGeometry, Shape, Transform, TriangleMesh};
use generate::grid_mesh;
use glam::{Vec2, Vec3};
use rng::Rng;

fn close(a: f32, b: f32, tol: f32) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}
fn close3(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol * (1.0 + a.abs().max(b.abs()).max_element())
}

fn scene(shapes: Vec<Shape>) -> SceneGeometry {
    let s: Vec<(Shape, u32)> = shapes
        .into_iter()
        .enumerate()
        .map(|(i, s)| (s, 100 + i as u32))
        .collect();
    SceneGeometry::build(&s).unwrap()
}

#[test]
fn sphere_outside_inside() {
    let g = scene(vec![Shape::Sphere {
        center: Vec3::ZERO,
        radius: 2.0,
    }]);
    let h = g
        .intersect(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, f32::INFINITY)
        .unwrap();
    assert!(close(h.t, 3.0, 1e-6));
    assert!(close3(h.p, Vec3::new(0.0, 0.0, -2.0), 1e-6));
    assert!(close3(h.ng, -Vec3::Z, 1e-6));
    assert!(h.front_face);
    assert_eq!(h.object, 100);
    assert_eq!(g.primitives_of_object(100), &[h.prim]);
    // Off-centre.
    let h = g
        .intersect(Vec3::new(1.0, 0.0, -5.0), Vec3::Z, f32::INFINITY)
        .unwrap();
    assert!(close(h.t, 5.0 - 3f32.sqrt(), 1e-6));
    assert!(close3(h.ng, Vec3::new(0.5, 0.0, -3f32.sqrt() / 2.0), 1e-6));
    // From inside: far side, back face.
    let h = g
        .intersect(Vec3::new(0.0, 0.0, 0.0), Vec3::Z, f32::INFINITY)
        .unwrap();
    assert!(close(h.t, 2.0, 1e-6));
    assert!(close3(h.ng, Vec3::Z, 1e-6));
    assert!(!h.front_face);
    // t_max is exclusive; unnormalised directions give parametric t.
    assert!(g
        .intersect(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 3.0)
        .is_none());
    assert!(g
        .intersect(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 3.0001)
        .is_some());
    let h = g
        .intersect(Vec3::new(0.0, 0.0, -5.0), 2.0 * Vec3::Z, f32::INFINITY)
        .unwrap();
    assert!(close(h.t, 1.5, 1e-6));
    // Pointing away / missing.
    assert!(g
        .intersect(Vec3::new(0.0, 0.0, -5.0), -Vec3::Z, f32::INFINITY)
        .is_none());
    assert!(g
        .intersect(Vec3::new(2.01, 0.0, -5.0), Vec3::Z, f32::INFINITY)
        .is_none());
    assert!(g.occluded(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 3.5));
    assert!(!g.occluded(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 2.5));
}

#[test]
fn quad_both_sides() {
    let g = scene(vec![Shape::Quad {
        origin: Vec3::new(-1.0, -1.0, 0.0),
        edge_u: Vec3::new(2.0, 0.0, 0.0),
        edge_v: Vec3::new(0.0, 2.0, 0.0),
    }]);
    let h = g
        .intersect(Vec3::new(0.5, 0.25, 3.0), -Vec3::Z, f32::INFINITY)
        .unwrap();
    assert!(close(h.t, 3.0, 1e-6));
    assert!(close3(h.p, Vec3::new(0.5, 0.25, 0.0), 1e-6));
    assert!(close3(h.ng, Vec3::Z, 1e-6));
    assert!(close(h.uv.x, 0.75, 1e-6) && close(h.uv.y, 0.625, 1e-6));
    assert!(h.front_face);
    let h = g
        .intersect(Vec3::new(0.5, 0.25, -3.0), Vec3::Z, f32::INFINITY)
        .unwrap();
    assert!(close3(h.ng, Vec3::Z, 1e-6));
    assert!(!h.front_face);
    // Oblique.
    let d = Vec3::new(1.0, 0.0, -1.0);
    let h = g
        .intersect(Vec3::new(-0.5, 0.0, 1.0), d, f32::INFINITY)
        .unwrap();
    assert!(close(h.t, 1.0, 1e-6));
    assert!(close3(h.p, Vec3::new(0.5, 0.0, 0.0), 1e-6));
    // Misses outside the parallelogram, parallel rays miss.
    assert!(g
        .intersect(Vec3::new(1.5, 0.0, 3.0), -Vec3::Z, f32::INFINITY)
        .is_none());
    assert!(g
        .intersect(Vec3::new(0.0, 0.0, 1.0), Vec3::X, f32::INFINITY)
        .is_none());
}

#[test]
fn disk() {
    let g = scene(vec![Shape::Disk {
        center: Vec3::new(1.0, 2.0, 3.0),
        normal: Vec3::new(0.0, 2.0, 0.0),
        radius: 0.5,
    }]);
    let h = g
        .intersect(Vec3::new(1.3, 10.0, 3.0), -Vec3::Y, f32::INFINITY)
        .unwrap();
    assert!(close(h.t, 8.0, 1e-6));
    assert!(close3(h.p, Vec3::new(1.3, 2.0, 3.0), 1e-6));
    assert!(close3(h.ng, Vec3::Y, 1e-6));
    assert!(h.front_face);
    assert!(close(h.uv.x, 0.6, 1e-5));
    let h = g
        .intersect(Vec3::new(1.3, -10.0, 3.0), Vec3::Y, f32::INFINITY)
        .unwrap();
    assert!(!h.front_face);
    assert!(g
        .intersect(Vec3::new(1.6, 10.0, 3.0), -Vec3::Y, f32::INFINITY)
        .is_none());
    assert!(g
        .intersect(Vec3::new(1.0, 10.0, 3.51), -Vec3::Y, f32::INFINITY)
        .is_none());
}

#[test]
fn triangle_edges_and_normals() {
    let mesh = TriangleMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)],
        normals: Some(vec![
            Vec3::Z,
            Vec3::new(1.0, 0.0, 1.0).normalize(),
            Vec3::Z,
            -Vec3::Z, // deliberately flipped: ns is brought to ng's hemisphere
        ]),
        indices: vec![[0, 1, 2], [1, 3, 2]],
    };
    let g = scene(vec![Shape::Mesh(mesh)]);
    assert_eq!(g.primitive_count(), 2);
    // Interior hit.
    let h = g
        .intersect(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z, f32::INFINITY)
        .unwrap();
    assert!(close(h.t, 1.0, 1e-6));
    assert!(close3(h.ng, Vec3::Z, 1e-6));
    assert!(h.front_face);
    assert!(close(h.uv.x, 0.25, 1e-6) && close(h.uv.y, 0.25, 1e-6));
    let expect =
        (0.5 * Vec3::Z + 0.25 * Vec3::new(1.0, 0.0, 1.0).normalize() + 0.25 * Vec3::Z).normalize();
    assert!(close3(h.ns, expect, 1e-5));
    assert!(h.ns.dot(h.ng) > 0.0);
    // Back side.
    let h = g
        .intersect(Vec3::new(0.25, 0.25, -1.0), Vec3::Z, f32::INFINITY)
        .unwrap();
    assert!(!h.front_face);
    assert!(close3(h.ng, Vec3::Z, 1e-6));
    // Exactly on the shared edge and on shared vertices: always hit (watertight).
    for p in [
        Vec3::new(0.5, 0.5, 0.0),
        Vec3::new(0.3, 0.7, 0.0),
        Vec3::X,
        Vec3::Y,
        Vec3::ZERO,
        Vec3::new(0.5, 0.0, 0.0),
    ] {
        let o = p + Vec3::new(0.1, -0.2, 1.0);
        let h = g.intersect(o, p - o, f32::INFINITY);
        assert!(h.is_some(), "missed edge/vertex point {p}");
        assert!(close(h.unwrap().t, 1.0, 1e-6));
    }
    // Just outside an edge: miss.
    assert!(g
        .intersect(Vec3::new(1.0001, 0.5, 1.0), -Vec3::Z, f32::INFINITY)
        .is_none());
    // Vertex normal flipped at vertex 3: ns still in ng's hemisphere.
    let h = g
        .intersect(Vec3::new(0.9, 0.9, 1.0), -Vec3::Z, f32::INFINITY)
        .unwrap();
    assert!(h.ns.dot(h.ng) > 0.0);
}

#[test]
fn watertight_grid_edges_and_vertices() {
    // Rays aimed exactly at the vertices and edge midpoints of a grid never fall through.
    let g = scene(vec![Shape::Mesh(grid_mesh(16, 16, 16.0, |_, _| 0.0))]);
    let mut rng = Rng::new(3);
    let mut n = 0;
    for j in 0..=32 {
        for i in 0..=32 {
            let target = Vec3::new(i as f32 * 0.5 - 8.0, j as f32 * 0.5 - 8.0, 0.0);
            if target.x.abs() >= 8.0 || target.y.abs() >= 8.0 {
                continue;
            }
            for _ in 0..4 {
                let mut w = rng.unit_vector();
                w.z = w.z.abs() + 0.05;
                let o = target + w * rng.range(0.1, 30.0);
                assert!(
                    g.intersect(o, target - o, f32::INFINITY).is_some(),
                    "ray through {target} fell through the mesh"
                );
                assert!(g.occluded(o, target - o, 2.0));
                n += 1;
            }
        }
    }
    assert!(n > 3000);
}

fn random_scene(rng: &mut Rng, scale: f32, offset: Vec3) -> Vec<(Shape, u32)> {
    let mut shapes = Vec::new();
    let mut mesh = TriangleMesh::default();
    for _ in 0..3000 {
        let c = rng.in_box(Vec3::splat(-1.0), Vec3::splat(1.0));
        let s = rng.range(0.01, 0.2);
        let base = mesh.positions.len() as u32;
        for _ in 0..3 {
            mesh.positions
                .push((c + s * rng.unit_vector()) * scale + offset);
        }
        mesh.indices.push([base, base + 1, base + 2]);
    }
    shapes.push((Shape::Mesh(mesh), 0));
    for i in 0..60 {
        shapes.push((
            Shape::Sphere {
                center: rng.in_box(Vec3::splat(-1.0), Vec3::splat(1.0)) * scale + offset,
                radius: rng.range(0.01, 0.15) * scale,
            },
            1 + i,
        ));
    }
    for i in 0..30 {
        shapes.push((
            Shape::Quad {
                origin: rng.in_box(Vec3::splat(-1.0), Vec3::splat(1.0)) * scale + offset,
                edge_u: rng.unit_vector() * 0.2 * scale,
                edge_v: rng.unit_vector() * 0.2 * scale,
            },
            100 + i,
        ));
        shapes.push((
            Shape::Disk {
                center: rng.in_box(Vec3::splat(-1.0), Vec3::splat(1.0)) * scale + offset,
                normal: rng.unit_vector(),
                radius: 0.1 * scale,
            },
            200 + i,
        ));
    }
    shapes
}

fn bvh_vs_brute(scale: f32, offset: Vec3, seed: u64) {
    let mut rng = Rng::new(seed);
    let shapes = random_scene(&mut rng, scale, offset);
    let g = SceneGeometry::build(&shapes).unwrap();
    let mut hits = 0;
    let mut tri_hits = 0;
    for i in 0..6000 {
        let o = rng.in_box(Vec3::splat(-1.5), Vec3::splat(1.5)) * scale + offset;
        let mut d = rng.unit_vector();
        // Some axis-aligned and nearly axis-aligned rays.
        match i % 10 {
            0 => d = Vec3::new(d.x.signum(), 0.0, 0.0),
            1 => d = Vec3::new(0.0, 0.0, d.z.signum()),
            2 => d = Vec3::new(1e-9, d.y, d.z).normalize(),
            _ => {}
        }
        let mut t_max = if i % 3 == 0 {
            f32::INFINITY
        } else {
            rng.range(0.0, 2.0) * scale
        };
        // Unnormalised directions (|d| from 1e-3·scale to 1e3·scale): t is parametric.
        if i % 4 == 3 {
            let len = scale * 10f32.powf(rng.range(-3.0, 3.0));
            d *= len;
            t_max /= len;
        }
        let a = g.intersect(o, d, t_max);
        let b = g.intersect_brute_force(o, d, t_max);
        match (a, b) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                hits += 1;
                if a.object == 0 {
                    tri_hits += 1;
                }
                assert_eq!(a.t, b.t, "ray {i}: BVH t {} vs brute force {}", a.t, b.t);
                if a.prim != b.prim {
                    // Only a genuine tie may pick a different primitive.
                    assert_eq!(a.t, b.t);
                }
                assert_eq!(a.object, g.object_of_prim(a.prim));
            }
            (a, b) => panic!("ray {i} (scale {scale}): BVH {a:?} vs brute force {b:?}"),
        }
        assert_eq!(
            g.occluded(o, d, t_max),
            b.is_some(),
            "ray {i}: occluded mismatch"
        );
    }
    assert!(hits > 1000, "too few hits ({hits}) to be a meaningful test");
    assert!(tri_hits > 500, "too few triangle hits ({tri_hits})");
}

#[test]
fn bvh_matches_brute_force_unit_scale() {
    bvh_vs_brute(1.0, Vec3::ZERO, 1);
}

/// The whole scene is 2 µm across: every hit is closer than obvhs's hard-coded 1e-4 node
/// cut-off, so this fails unless the traversal handles near hits itself.
#[test]
fn bvh_matches_brute_force_micrometre_scale() {
    bvh_vs_brute(1e-6, Vec3::new(3e-6, -1e-6, 2e-6), 2);
}

#[test]
fn bvh_matches_brute_force_megametre_scale() {
    bvh_vs_brute(1e6, Vec3::new(3e6, 0.0, -1e6), 3);
}

#[test]
fn short_rays_near_hits() {
    // A hit at t = 1e-7 m must be found (obvhs's own node test would cull it).
    let g = scene(vec![Shape::Quad {
        origin: Vec3::new(-1.0, -1.0, 0.0),
        edge_u: Vec3::new(2.0, 0.0, 0.0),
        edge_v: Vec3::new(0.0, 2.0, 0.0),
    }]);
    let h = g
        .intersect(Vec3::new(0.1, 0.1, 1e-7), -Vec3::Z, 1e-6)
        .unwrap();
    assert!(close(h.t, 1e-7, 1e-5));
    assert!(g.occluded(Vec3::new(0.1, 0.1, 1e-7), -Vec3::Z, 2e-7));
    assert!(!g.occluded(Vec3::new(0.1, 0.1, 1e-7), -Vec3::Z, 0.5e-7));
}

#[test]
fn empty_scene_and_invalid_rays() {
    let g = SceneGeometry::build(&[]).unwrap();
    assert!(g.intersect(Vec3::ZERO, Vec3::Z, f32::INFINITY).is_none());
    assert!(!g.occluded(Vec3::ZERO, Vec3::Z, f32::INFINITY));
    assert_eq!(g.primitive_count(), 0);
    assert!(g.primitives_of_object(0).is_empty());
    let g = scene(vec![Shape::Sphere {
        center: Vec3::ZERO,
        radius: 1.0,
    }]);
    assert!(g
        .intersect(Vec3::new(0.0, 0.0, -3.0), Vec3::ZERO, 10.0)
        .is_none());
    assert!(g
        .intersect(Vec3::new(f32::NAN, 0.0, -3.0), Vec3::Z, 10.0)
        .is_none());
    assert!(g
        .intersect(Vec3::new(0.0, 0.0, -3.0), Vec3::Z, 0.0)
        .is_none());
}

#[test]
fn zero_area_triangles_dropped_and_invalid_shapes_rejected() {
    let mesh = TriangleMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, 2.0 * Vec3::X],
        normals: None,
        indices: vec![[0, 1, 2], [0, 1, 3], [1, 1, 2]],
    };
    let g = scene(vec![Shape::Mesh(mesh)]);
    assert_eq!(g.primitive_count(), 1);
    for bad in [
        Shape::Sphere {
            center: Vec3::ZERO,
            radius: -1.0,
        },
        Shape::Sphere {
            center: Vec3::NAN,
            radius: 1.0,
        },
        Shape::Quad {
            origin: Vec3::ZERO,
            edge_u: Vec3::X,
            edge_v: 2.0 * Vec3::X,
        },
        Shape::Disk {
            center: Vec3::ZERO,
            normal: Vec3::ZERO,
            radius: 1.0,
        },
        Shape::Mesh(TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: None,
            indices: vec![[0, 1, 5]],
        }),
    ] {
        let e = SceneGeometry::build(&[(bad, 7)]).err().expect("must fail");
        assert!(e.to_string().contains("object 7"), "{e}");
    }
}

#[test]
fn transforms() {
    let t = Transform::from_trs(
        Vec3::new(10.0, 0.0, 0.0),
        Vec3::new(90.0, 0.0, 90.0),
        Vec3::ONE,
    );
    // X is untouched by Rx, then Rz maps it to Y; Y goes to Z by Rx, Z is kept by Rz.
    assert!(close3(
        t.transform_point(Vec3::X),
        Vec3::new(10.0, 1.0, 0.0),
        1e-6
    ));
    assert!(close3(
        t.transform_point(Vec3::Y),
        Vec3::new(10.0, 0.0, 1.0),
        1e-6
    ));
    let t2 = Transform::from_trs(Vec3::ZERO, Vec3::ZERO, Vec3::new(2.0, 3.0, 4.0));
    assert!(close3(
        t2.transform_point(Vec3::ONE),
        Vec3::new(2.0, 3.0, 4.0),
        1e-6
    ));
    assert!(!t2.is_uniform_scale());
    assert!(
        Transform::from_trs(Vec3::ONE, Vec3::new(10.0, 20.0, 30.0), Vec3::splat(3.0))
            .is_uniform_scale()
    );
    let sphere = Shape::Sphere {
        center: Vec3::X,
        radius: 1.0,
    };
    assert!(sphere.to_world(&t2).is_err());
    let disk = Shape::Disk {
        center: Vec3::ZERO,
        normal: Vec3::Z,
        radius: 1.0,
    };
    assert!(disk.to_world(&t2).is_err());
    let singular = Transform::from_trs(Vec3::ZERO, Vec3::ZERO, Vec3::new(1.0, 0.0, 1.0));
    let quad = Shape::Quad {
        origin: Vec3::ZERO,
        edge_u: Vec3::X,
        edge_v: Vec3::Y,
    };
    assert!(quad.to_world(&singular).is_err());
    let ts = Transform::from_trs(
        Vec3::new(0.0, 0.0, 5.0),
        Vec3::new(0.0, 90.0, 0.0),
        Vec3::splat(2.0),
    );
    match sphere.to_world(&ts).unwrap() {
        Shape::Sphere { center, radius } => {
            assert!(close3(center, Vec3::new(0.0, 0.0, 3.0), 1e-6));
            assert!(close(radius, 2.0, 1e-6));
        }
        _ => unreachable!(),
    }
    match disk.to_world(&ts).unwrap() {
        Shape::Disk { normal, .. } => assert!(close3(normal, Vec3::X, 1e-6)),
        _ => unreachable!(),
    }
    // A mirror keeps the front face of a quad on the mirrored side.
    let mirror = Transform::from_trs(Vec3::ZERO, Vec3::ZERO, Vec3::new(1.0, 1.0, -1.0));
    match quad.to_world(&mirror).unwrap() {
        Shape::Quad { edge_u, edge_v, .. } => {
            assert!(close3(edge_u.cross(edge_v).normalize(), -Vec3::Z, 1e-6))
        }
        _ => unreachable!(),
    }
    // ...and an outward closed mesh stays outward under a mirror.
    let m = generate::cube_sphere(4, 0.0);
    let mm = match Shape::Mesh(m).to_world(&mirror).unwrap() {
        Shape::Mesh(m) => m,
        _ => unreachable!(),
    };
    for tri in &mm.indices {
        let [a, b, c] = tri.map(|i| mm.positions[i as usize]);
        assert!((b - a).cross(c - a).dot(a + b + c) > 0.0);
    }
    let _ = Vec2::ZERO;
}

#[test]
fn degenerate_scenes_build_and_trace() {
    // 300 coincident copies of a triangle plus a huge and a tiny primitive.
    let mut mesh = TriangleMesh::default();
    for i in 0..300u32 {
        mesh.positions.extend([Vec3::ZERO, Vec3::X, Vec3::Y]);
        mesh.indices.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    let shapes = vec![
        (Shape::Mesh(mesh), 0),
        (
            Shape::Sphere {
                center: Vec3::new(0.0, 0.0, -1e6),
                radius: 5e5,
            },
            1,
        ),
        (
            Shape::Sphere {
                center: Vec3::new(0.2, 0.2, 5.0),
                radius: 1e-6,
            },
            2,
        ),
    ];
    let g = SceneGeometry::build(&shapes).unwrap();
    println!("depth {}", g.bvh_depth());
    assert!(g.bvh_depth() < 64);
    let h = g
        .intersect(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z, f32::INFINITY)
        .unwrap();
    assert_eq!(h.object, 0);
    assert!((h.t - 1.0).abs() < 1e-6);
    let h = g
        .intersect(Vec3::new(0.2, 0.2, 10.0), -Vec3::Z, f32::INFINITY)
        .unwrap();
    assert_eq!(h.object, 2);
    let h = g
        .intersect(Vec3::new(5.0, 5.0, 1.0), -Vec3::Z, f32::INFINITY)
        .unwrap();
    assert_eq!(h.object, 1);
    let _ = Vec2::ZERO;
}

#[test]
fn pathological_scene_is_an_error_not_a_crash() {
    let mut mesh = TriangleMesh::default();
    for i in 0..3000u32 {
        mesh.positions.extend([Vec3::ZERO, Vec3::X, Vec3::Y]);
        mesh.indices.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    match SceneGeometry::build(&[(Shape::Mesh(mesh), 0)]) {
        Ok(g) => {
            assert!(g.bvh_depth() < 64);
            assert!(g
                .intersect(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, 2.0)
                .is_some());
        }
        Err(e) => assert!(e.to_string().contains("degenerate"), "{e}"),
    }
}

#[test]
fn scene_geometry_is_send_and_sync() {
    fn check<T: Send + Sync>() {}
    check::<SceneGeometry>();
    check::<candela::geometry::Hit>();
    check::<candela::geometry::GeometryError>();
}

/// `occluded_except` against a walk of closest hits (each continued from just past the last):
/// the same verdict, and the same crossings of the passing objects (spheres, which are crossed
/// in and out, and quads), on the random scene at three scales.
#[test]
fn occluded_except_matches_a_walk_of_closest_hits() {
    for (scale, offset, seed) in [
        (1.0, Vec3::ZERO, 11),
        (1e-3, Vec3::splat(0.5), 12),
        (1e3, Vec3::new(-2e3, 0.0, 1e3), 13),
    ] {
        let mut rng = Rng::new(seed);
        let shapes = random_scene(&mut rng, scale, offset);
        let g = SceneGeometry::build(&shapes).unwrap();
        // Spheres (objects 1–60) and quads (100–129) pass; the mesh (0) and disks block.
        let passes: Vec<bool> = (0..230)
            .map(|o| (1..=60).contains(&o) || (100..130).contains(&o))
            .collect();
        let (mut crossings, mut sphere_twice) = (0, 0);
        for i in 0..12000 {
            let o = rng.in_box(Vec3::splat(-1.5), Vec3::splat(1.5)) * scale + offset;
            let d = rng.unit_vector();
            let t_max = if i % 3 == 0 {
                f32::INFINITY
            } else {
                rng.range(0.0, 3.0) * scale
            };
            // Reference: walk the closest hits.
            let end = o + d * t_max;
            let (mut p, mut t) = (o, t_max);
            let mut expected = Vec::new();
            let expected_blocked = loop {
                let Some(h) = g.intersect(p, d, t) else {
                    break false;
                };
                if !passes[h.object as usize] {
                    break true;
                }
                expected.push((h.object, h.p));
                p = h.spawn_origin(d);
                if t.is_finite() {
                    t = (end - p).dot(d);
                    if t <= 0.0 {
                        break false;
                    }
                }
            };
            let mut got = Vec::new();
            let blocked = g.occluded_except(o, d, t_max, &passes, |h| {
                got.push((h.object, h.p));
                true
            });
            assert_eq!(
                blocked, expected_blocked,
                "ray {i} (scale {scale}): verdict"
            );
            if !blocked {
                assert_eq!(
                    got.len(),
                    expected.len(),
                    "ray {i} (scale {scale}): {got:?} vs {expected:?}"
                );
                for (obj, q) in &expected {
                    assert!(
                        got.iter()
                            .any(|(o2, q2)| o2 == obj && close3(*q, *q2, 1e-4)),
                        "ray {i} (scale {scale}): crossing of {obj} at {q} missing from {got:?}"
                    );
                }
                crossings += got.len();
                if (1..=60).any(|s| got.iter().filter(|(o, _)| *o == s).count() == 2) {
                    sphere_twice += 1;
                }
            }
            assert_eq!(g.occluded(o, d, t_max), g.intersect(o, d, t_max).is_some());
        }
        assert!(
            crossings > 200 && sphere_twice > 50,
            "{crossings} crossings, {sphere_twice} rays through a whole sphere"
        );
    }
}

/// The leaf tests against brute force on small scenes of 1–60 overlapping primitives
/// (triangles with spheres, quads and disks among them), so that BVH nodes hold every leaf
/// primitive count from 1 to 24. Written for the 8-wide batched leaf test of branch `trav4`
/// (blocks of 8 slots at every offset, next to padding slots; not merged, see
/// bench/embree/README.md) and kept for any leaf-test layout. Checks the closest hit (t,
/// primitive, barycentrics: bit for bit), the occluded flag, and the crossings that
/// `occluded_except` reports (against one-primitive scenes, crossing by crossing).
#[test]
fn leaf_batches_match_brute_force() {
    let mut rng = Rng::new(77);
    let mut checked_crossings = 0;
    for n in 1..=60usize {
        for round in 0..3 {
            let mut shapes = Vec::new();
            for i in 0..n {
                // Mostly triangles; every 5th (shifted by the round) something else.
                let c = rng.in_box(Vec3::splat(-1.0), Vec3::splat(1.0));
                let shape = match (i + round) % 5 {
                    1 if i % 3 == 0 => Shape::Sphere {
                        center: c,
                        radius: rng.range(0.05, 0.4),
                    },
                    1 if i % 3 == 1 => Shape::Quad {
                        origin: c,
                        edge_u: rng.unit_vector() * 0.8,
                        edge_v: rng.unit_vector() * 0.8,
                    },
                    1 => Shape::Disk {
                        center: c,
                        normal: rng.unit_vector(),
                        radius: 0.4,
                    },
                    _ => {
                        let s = rng.range(0.3, 1.5);
                        Shape::Mesh(TriangleMesh {
                            positions: (0..3).map(|_| c + s * rng.unit_vector()).collect(),
                            indices: vec![[0, 1, 2]],
                            ..Default::default()
                        })
                    }
                };
                shapes.push((shape, i as u32));
            }
            let g = SceneGeometry::build(&shapes).unwrap();
            assert_eq!(g.primitive_count(), n);
            let singles: Vec<SceneGeometry> = shapes
                .iter()
                .map(|s| SceneGeometry::build(std::slice::from_ref(s)).unwrap())
                .collect();
            // Even objects pass.
            let passes: Vec<bool> = (0..n).map(|o| o % 2 == 0).collect();
            for i in 0..300 {
                let o = rng.in_box(Vec3::splat(-2.0), Vec3::splat(2.0));
                let d = rng.in_box(Vec3::splat(-0.8), Vec3::splat(0.8)) - o;
                let t_max = if i % 2 == 0 {
                    f32::INFINITY
                } else {
                    rng.range(0.2, 1.5)
                };
                let ctx = format!("{n} primitives, round {round}, ray {i}");
                let a = g.intersect(o, d, t_max);
                let b = g.intersect_brute_force(o, d, t_max);
                match (&a, &b) {
                    (None, None) => {}
                    (Some(a), Some(b)) => {
                        assert_eq!(a.t.to_bits(), b.t.to_bits(), "{ctx}: t");
                        assert_eq!(a.prim, b.prim, "{ctx}: primitive");
                        assert_eq!(a.uv.x.to_bits(), b.uv.x.to_bits(), "{ctx}: u");
                        assert_eq!(a.uv.y.to_bits(), b.uv.y.to_bits(), "{ctx}: v");
                        assert_eq!(a.object, b.object, "{ctx}: object");
                        assert_eq!(g.object_of_prim(a.prim), a.object);
                        assert_eq!(g.primitives_of_object(a.object), &[a.prim]);
                        let basic = g.intersect_basic(o, d, t_max).unwrap();
                        assert_eq!((basic.t, basic.prim), (a.t, a.prim), "{ctx}: basic");
                    }
                    _ => panic!("{ctx}: BVH {a:?} vs brute force {b:?}"),
                }
                assert_eq!(g.occluded(o, d, t_max), b.is_some(), "{ctx}: occluded");
                // Every primitive's own first crossing.
                let first: Vec<Option<f32>> = singles
                    .iter()
                    .map(|s| s.intersect_brute_force(o, d, t_max).map(|h| h.t))
                    .collect();
                let expect_blocked = (0..n).any(|k| !passes[k] && first[k].is_some());
                let mut got: Vec<(u32, f32)> = Vec::new();
                let blocked = g.occluded_except(o, d, t_max, &passes, |h| {
                    got.push((h.object, h.t));
                    true
                });
                assert_eq!(blocked, expect_blocked, "{ctx}: occluded_except");
                // Each reported crossing is a genuine one of a passing primitive; when nothing
                // blocks, every passing primitive's first crossing is reported (spheres may
                // add their way out, on a ray from a new origin).
                for &(obj, _) in &got {
                    assert!(
                        passes[obj as usize] && first[obj as usize].is_some(),
                        "{ctx}"
                    );
                }
                if !blocked {
                    for k in (0..n).filter(|&k| passes[k]) {
                        if let Some(t) = first[k] {
                            assert!(
                                got.iter().any(
                                    |&(obj, t2)| obj == k as u32 && t2.to_bits() == t.to_bits()
                                ),
                                "{ctx}: crossing of {k} at t = {t} missing from {got:?}"
                            );
                            checked_crossings += 1;
                        }
                    }
                }
            }
        }
    }
    assert!(checked_crossings > 5000, "{checked_crossings} crossings");
}
