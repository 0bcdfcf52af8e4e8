//! The BVH over hostile and CAD-ugly meshes: coincident triangles, duplicated faces, fans of
//! thousands of slivers round one vertex, long strips of equal boxes. Each builds quickly with a
//! bounded depth, and closest and any hit agree with brute force on random rays.
//!
//! Build times are printed, never asserted. The big cases are `#[ignore]`d: `cargo test --test
//! geometry_bvh_hostile -- --ignored --nocapture big_hostile_meshes`; `measure` builds any of
//! the meshes at any size (`HOSTILE=fan:100000,coincident:30000`, see its kinds).

#[path = "../src/cli/bench/generate.rs"]
#[allow(dead_code)]
mod generate;
#[path = "../src/cli/bench/rng.rs"]
#[allow(dead_code)]
mod rng;

use candela::geometry::{SceneGeometry, Shape, TriangleMesh};
use glam::Vec3;
use rng::Rng;
use std::time::Instant;

/// `n` copies of one triangle (each with its own three vertices, as a careless exporter writes).
fn coincident(n: usize) -> TriangleMesh {
    let tri = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    TriangleMesh {
        positions: (0..n).flat_map(|_| tri).collect(),
        normals: None,
        indices: (0..n as u32)
            .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect(),
    }
}

/// A disk of radius 1 in the plane z = 0 made of `n` triangles round its centre.
fn fan(n: usize) -> TriangleMesh {
    let mut positions = vec![Vec3::ZERO];
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        positions.push(Vec3::new(a.cos() as f32, a.sin() as f32, 0.0));
    }
    let n = n as u32;
    TriangleMesh {
        positions,
        normals: None,
        indices: (0..n).map(|k| [0, 1 + k, 1 + (k + 1) % n]).collect(),
    }
}

/// A convex polygon of `n` + 2 vertices on the unit circle, triangulated as a fan from its first
/// vertex (as CAD exporters triangulate faces): `n` slivers sharing a rim vertex.
fn polygon_fan(n: usize) -> TriangleMesh {
    let m = n + 2;
    let positions = (0..m)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / m as f64;
            Vec3::new(a.cos() as f32, a.sin() as f32, 0.0)
        })
        .collect();
    TriangleMesh {
        positions,
        normals: None,
        indices: (1..=n as u32).map(|k| [0, k, k + 1]).collect(),
    }
}

/// The side of a cylinder (radius 1, height 1) of `n` segments, two triangles each.
fn cylinder(n: usize) -> TriangleMesh {
    let mut positions = Vec::new();
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        let (x, y) = (a.cos() as f32, a.sin() as f32);
        positions.push(Vec3::new(x, y, 0.0));
        positions.push(Vec3::new(x, y, 1.0));
    }
    let n = n as u32;
    let indices = (0..n)
        .flat_map(|k| {
            let (a, b) = (2 * k, 2 * k + 1);
            let (c, d) = (2 * ((k + 1) % n), 2 * ((k + 1) % n) + 1);
            [[a, c, d], [a, d, b]]
        })
        .collect();
    TriangleMesh {
        positions,
        normals: None,
        indices,
    }
}

/// A row of `n` unit squares (two triangles each) along x at integer coordinates: every pair of
/// neighbouring squares has the same bounds area.
fn strip(n: usize) -> TriangleMesh {
    let mut positions = Vec::new();
    for i in 0..=n {
        positions.push(Vec3::new(i as f32, 0.0, 0.0));
        positions.push(Vec3::new(i as f32, 1.0, 0.0));
    }
    let indices = (0..n as u32)
        .flat_map(|i| {
            let (a, b, c, d) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
            [[a, c, d], [a, d, b]]
        })
        .collect();
    TriangleMesh {
        positions,
        normals: None,
        indices,
    }
}

/// `n` long slivers from one vertex to random points on a sphere of radius 1 (a hedgehog).
fn hedgehog(n: usize, seed: u64) -> TriangleMesh {
    let mut rng = Rng::new(seed);
    let mut positions = vec![Vec3::ZERO];
    for _ in 0..n {
        let d = rng.unit_vector();
        let side = d.any_orthonormal_vector() * 1e-3;
        positions.push(d);
        positions.push(d + side);
    }
    TriangleMesh {
        positions,
        normals: None,
        indices: (0..n as u32).map(|k| [0, 1 + 2 * k, 2 + 2 * k]).collect(),
    }
}

/// A `k`×`k` grid of unit squares in z = 0 whose every face appears `copies` times, alternately
/// with either winding.
fn duplicated_grid(k: u32, copies: usize) -> TriangleMesh {
    let mut positions = Vec::new();
    for j in 0..=k {
        for i in 0..=k {
            positions.push(Vec3::new(i as f32, j as f32, 0.0));
        }
    }
    let mut indices = Vec::new();
    for j in 0..k {
        for i in 0..k {
            let v = |di: u32, dj: u32| (j + dj) * (k + 1) + i + di;
            for c in 0..copies {
                for [a, b, d] in [[v(0, 0), v(1, 0), v(1, 1)], [v(0, 0), v(1, 1), v(0, 1)]] {
                    indices.push(if c % 2 == 0 { [a, b, d] } else { [a, d, b] });
                }
            }
        }
    }
    TriangleMesh {
        positions,
        normals: None,
        indices,
    }
}

/// The vertices of `mesh` moved by up to 4 ulps (of 1 or more) in x and y.
fn jittered(mut mesh: TriangleMesh, seed: u64) -> TriangleMesh {
    let mut rng = Rng::new(seed);
    for p in &mut mesh.positions {
        let mut off = || (rng.next_u64() % 9) as f32 - 4.0;
        let ulps = |v: f32, k: f32| v + k * f32::EPSILON * v.abs().max(1.0);
        *p = Vec3::new(ulps(p.x, off()), ulps(p.y, off()), p.z);
    }
    mesh
}

/// Most node levels a BVH may have (the traversal stack is sized for it).
const MAX_DEPTH: u32 = 63;

/// Builds the mesh, printing the time taken (never asserted: machines differ), and checks the
/// depth bound.
fn build(what: &str, mesh: TriangleMesh) -> SceneGeometry {
    let n = mesh.indices.len();
    let t = Instant::now();
    let g = SceneGeometry::build(&[(Shape::Mesh(mesh), 7)])
        .unwrap_or_else(|e| panic!("{what}: {n} triangles refused: {e}"));
    println!(
        "{what}: {n} triangles built in {:.3} s, depth {}, {} nodes",
        t.elapsed().as_secs_f64(),
        g.bvh_depth(),
        g.node_count()
    );
    assert!(
        g.bvh_depth() <= MAX_DEPTH,
        "{what}: depth {}",
        g.bvh_depth()
    );
    g
}

/// Closest hit and any hit against brute force on `rays` random rays: from around the mesh's
/// bounds towards random points in them, some aimed at `aim` (a vertex many triangles share),
/// some in the mesh's plane z = 0 if it is flat, some shortened. Returns the number of hits.
fn agrees_with_brute_force(
    what: &str,
    g: &SceneGeometry,
    rays: usize,
    aim: Vec3,
    seed: u64,
) -> usize {
    let mut rng = Rng::new(seed);
    let (lo, hi) = g.bounds();
    let pad = (hi - lo).max_element() * 0.5;
    let mut hits = 0;
    for i in 0..rays {
        let mut o = rng.in_box(lo - pad, hi + pad);
        let mut target = rng.in_box(lo, hi);
        match i % 8 {
            0 => target = aim,
            1 if lo.z == hi.z => {
                o.z = lo.z;
                target.z = lo.z;
            }
            _ => {}
        }
        let d = target - o;
        if d == Vec3::ZERO {
            continue;
        }
        let t_max = if i % 3 == 0 { 0.999 } else { f32::INFINITY };
        let a = g.intersect(o, d, t_max);
        let b = g.intersect_brute_force(o, d, t_max);
        match (&a, &b) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                hits += 1;
                // The same distance (another primitive only at a tie: coincident faces). At a
                // vertex the triangles round it give distances an ulp apart, and which of them
                // a query returns depends on the order it tests them in.
                let ulp = if i % 8 == 0 {
                    a.t.max(b.t) * f32::EPSILON
                } else {
                    0.0
                };
                assert!(
                    (a.t - b.t).abs() <= ulp,
                    "{what}: ray {i}: BVH t {} vs brute force {}",
                    a.t,
                    b.t
                );
                assert_eq!(a.object, 7);
            }
            _ => panic!("{what}: ray {i} from {o} along {d}: BVH {a:?} vs brute force {b:?}"),
        }
        assert_eq!(
            g.occluded(o, d, t_max),
            b.is_some(),
            "{what}: ray {i}: any hit differs from brute force"
        );
    }
    println!("{what}: {hits} of {rays} rays hit, as brute force");
    hits
}

#[test]
fn coincident_triangles() {
    let g = build("coincident", coincident(20_000));
    let hits = agrees_with_brute_force("coincident", &g, 600, Vec3::new(0.25, 0.25, 0.0), 1);
    assert!(hits > 100);
    // Nearly coincident: each copy a few ulps off.
    let g = build("nearly coincident", jittered(coincident(20_000), 2));
    agrees_with_brute_force("nearly coincident", &g, 600, Vec3::new(0.25, 0.25, 0.0), 3);
}

/// 2 048 slivers: round the centre of a disk, and a polygon fanned from one rim vertex.
#[test]
fn fans_of_2048() {
    let g = build("centre fan", fan(2048));
    assert!(agrees_with_brute_force("centre fan", &g, 3000, Vec3::ZERO, 4) > 500);
    let g = build("polygon fan", polygon_fan(2048));
    assert!(agrees_with_brute_force("polygon fan", &g, 3000, Vec3::X, 5) > 500);
}

#[test]
fn fans_of_65536() {
    let g = build("centre fan", fan(65_536));
    assert!(agrees_with_brute_force("centre fan", &g, 400, Vec3::ZERO, 6) > 100);
    let g = build("polygon fan", polygon_fan(65_536));
    assert!(agrees_with_brute_force("polygon fan", &g, 400, Vec3::X, 7) > 100);
}

/// Every face repeated: three times over a 64×64 grid, and 1 000 times over a 4×4 one.
#[test]
fn duplicated_faces() {
    let g = build("3 copies", duplicated_grid(64, 3));
    assert!(agrees_with_brute_force("3 copies", &g, 1500, Vec3::new(32.0, 32.0, 0.0), 8) > 300);
    let g = build("1000 copies", duplicated_grid(4, 1000));
    assert!(agrees_with_brute_force("1000 copies", &g, 1500, Vec3::new(2.0, 2.0, 0.0), 9) > 300);
}

/// Long rows of equal boxes, a finely divided cylinder, long slivers from one vertex in every
/// direction.
#[test]
fn strips_cylinders_hedgehogs() {
    let g = build("strip", strip(20_000));
    agrees_with_brute_force("strip", &g, 600, Vec3::new(100.0, 1.0, 0.0), 10);
    let g = build("cylinder", cylinder(20_000));
    agrees_with_brute_force("cylinder", &g, 600, Vec3::X, 11);
    let g = build("hedgehog", hedgehog(20_000, 12));
    assert!(agrees_with_brute_force("hedgehog", &g, 600, Vec3::ZERO, 13) > 50);
}

/// The big cases (for scripts/hostile.sh): 10⁵ coincident triangles, 10⁶ slivers round a centre
/// and fanned from a rim vertex. Prints build times and depths.
#[test]
#[ignore]
fn big_hostile_meshes() {
    let g = build("coincident", coincident(100_000));
    agrees_with_brute_force("coincident", &g, 50, Vec3::new(0.25, 0.25, 0.0), 14);
    drop(g);
    let g = build("centre fan", fan(1_000_000));
    agrees_with_brute_force("centre fan", &g, 50, Vec3::ZERO, 15);
    drop(g);
    let g = build("polygon fan", polygon_fan(1_000_000));
    agrees_with_brute_force("polygon fan", &g, 50, Vec3::X, 16);
}

/// Measurement only: `HOSTILE=kind:n[,kind:n…]` builds each and prints the time and depth.
#[test]
#[ignore]
fn measure() {
    let spec = std::env::var("HOSTILE").unwrap_or_default();
    for item in spec.split(',').filter(|s| !s.is_empty()) {
        let (kind, n) = item.split_once(':').unwrap();
        let n: usize = n.parse().unwrap();
        let mesh = match kind {
            "coincident" => coincident(n),
            "fan" => fan(n),
            "strip" => strip(n),
            "polyfan" => polygon_fan(n),
            "cylinder" => cylinder(n),
            "hedgehog" => hedgehog(n, 1),
            "dup" => duplicated_grid(n as u32, 3),
            // An ordinary mesh for comparison: a bumpy sphere of about n triangles.
            "bumpy" => generate::bumpy_sphere(((n as f64 / 12.0).sqrt().ceil() as u32).max(1)),
            _ => panic!("unknown kind {kind}"),
        };
        let t = Instant::now();
        let n = mesh.indices.len();
        match SceneGeometry::build(&[(Shape::Mesh(mesh), 7)]) {
            Ok(g) => println!(
                "{kind} {n}: {:.3} s, depth {}",
                t.elapsed().as_secs_f64(),
                g.bvh_depth()
            ),
            Err(e) => println!("{kind} {n}: {:.3} s, error {e}", t.elapsed().as_secs_f64()),
        }
    }
}
