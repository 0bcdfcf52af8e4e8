//! Self-intersection: rays spawned with `offset_ray_origin` never re-hit their own surface,
//! at scales 1e-6 m, 1e-3 m, 1 m, 1e3 m and 1e6 m (and far from the world origin).

#[path = "../src/cli/bench/generate.rs"]
#[allow(dead_code)]
mod generate;
#[path = "../src/cli/bench/rng.rs"]
#[allow(dead_code)]
mod rng;

use candela::geometry::{
    offset_ray_origin, point_error_bound, shadow_ray, Hit, SceneGeometry, Shape, Transform,
    TriangleMesh,
};
use generate::grid_mesh;
use glam::Vec3;
use rng::Rng;

const SCALES: [f32; 5] = [1e-6, 1e-3, 1.0, 1e3, 1e6];
const RAYS: usize = 20_000;

/// Direction in the hemisphere around `n` (cosine to n at least `min_cos`).
fn dir_around(rng: &mut Rng, n: Vec3, min_cos: f32) -> Vec3 {
    loop {
        let w = rng.unit_vector();
        if w.dot(n) >= min_cos {
            return w;
        }
        if (-w).dot(n) >= min_cos {
            return -w;
        }
    }
}

/// Hits on the geometry from random rays aimed at it from outside `radius` around `center`.
fn surface_hits(g: &SceneGeometry, rng: &mut Rng, center: Vec3, radius: f32, n: usize) -> Vec<Hit> {
    let mut hits = Vec::new();
    let mut tries = 0;
    while hits.len() < n {
        tries += 1;
        assert!(tries < 20 * n, "rays aimed at the object keep missing it");
        let o = center + rng.unit_vector() * radius * 3.0;
        let target = center + rng.unit_vector() * radius * rng.f32();
        if let Some(h) = g.intersect(o, target - o, f32::INFINITY) {
            hits.push(h);
        }
    }
    hits
}

/// A convex, closed, finely subdivided cube (flat faces made of many triangles sharing edges
/// and vertices), outward front faces.
fn subdivided_cube(n: u32) -> TriangleMesh {
    let mut out = TriangleMesh::default();
    let face = grid_mesh(n, n, 2.0, |_, _| 1.0); // z = 1, front +Z
    let rots = [
        Vec3::ZERO,
        Vec3::new(180.0, 0.0, 0.0),
        Vec3::new(90.0, 0.0, 0.0),
        Vec3::new(-90.0, 0.0, 0.0),
        Vec3::new(0.0, 90.0, 0.0),
        Vec3::new(0.0, -90.0, 0.0),
    ];
    for r in rots {
        let t = Transform::from_trs(Vec3::ZERO, r, Vec3::ONE);
        let base = out.positions.len() as u32;
        out.positions
            .extend(face.positions.iter().map(|&p| t.transform_point(p)));
        out.indices
            .extend(face.indices.iter().map(|t| t.map(|i| i + base)));
    }
    out
}

/// Spawns rays from hits: outward ones (away from the closed convex surface) must miss
/// everything; inward ones must hit the surface again at a distance (not themselves).
/// For `flat` (polyhedral) surfaces the inward hit must be on another face (a different
/// plane); for the sphere it must be at a chord distance.
fn check_closed_convex(
    g: &SceneGeometry,
    hits: &[Hit],
    rng: &mut Rng,
    size: f32,
    flat: bool,
    label: &str,
) {
    for (k, h) in hits.iter().enumerate() {
        // Outward: the side of the front face (these are outward-facing closed surfaces).
        let w = dir_around(rng, h.ng, 0.0);
        let o = h.spawn_origin(w);
        if let Some(x) = g.intersect(o, w, f32::INFINITY) {
            panic!(
                "{label}: outward ray {k} from {} re-hit at t = {} (prim {} vs {})",
                h.p, x.t, x.prim, h.prim
            );
        }
        assert!(
            !g.occluded(o, w, f32::INFINITY),
            "{label}: outward shadow ray {k} occluded"
        );
        // Inward: must reach the far side.
        let w = dir_around(rng, -h.ng, 0.05);
        let o = h.spawn_origin(w);
        let x = g
            .intersect(o, w, f32::INFINITY)
            .unwrap_or_else(|| panic!("{label}: inward ray {k} escaped the closed surface"));
        if flat {
            assert!(
                x.ng.dot(h.ng) < 0.999,
                "{label}: inward ray {k} hit its own face plane at t = {}",
                x.t
            );
        } else {
            assert!(
                x.t > 0.01 * size,
                "{label}: inward ray {k} hit itself at t = {} (size {size})",
                x.t
            );
        }
        assert!(
            !x.front_face,
            "{label}: inward ray {k} must hit a back face"
        );
    }
}

#[test]
fn sphere_no_self_intersection() {
    let mut rng = Rng::new(11);
    for s in SCALES {
        for offset in [Vec3::ZERO, Vec3::new(37.0, -11.0, 5.0) * s] {
            let c = offset + Vec3::new(0.3, 0.2, -0.1) * s;
            let g = SceneGeometry::build(&[(
                Shape::Sphere {
                    center: c,
                    radius: s,
                },
                0,
            )])
            .unwrap();
            let hits = surface_hits(&g, &mut rng, c, s, RAYS / 4);
            check_closed_convex(
                &g,
                &hits,
                &mut rng,
                s,
                false,
                &format!("sphere scale {s} offset {offset}"),
            );
            // Also from area samples (points without a hit record).
            for k in 0..RAYS / 4 {
                let sp = g.sample_prim(0, rng.vec2());
                let w = dir_around(&mut rng, sp.n, 0.0);
                let o = offset_ray_origin(sp.p, point_error_bound(sp.p), sp.n, w);
                assert!(
                    g.intersect(o, w, f32::INFINITY).is_none(),
                    "sampled point {k} re-hit"
                );
                let w = dir_around(&mut rng, -sp.n, 0.05);
                let o = offset_ray_origin(sp.p, point_error_bound(sp.p), sp.n, w);
                let x = g
                    .intersect(o, w, f32::INFINITY)
                    .expect("inward ray escaped");
                assert!(x.t > 0.01 * s);
            }
        }
    }
}

#[test]
fn mesh_no_self_intersection() {
    let mut rng = Rng::new(12);
    for s in SCALES {
        for offset in [Vec3::ZERO, Vec3::new(-23.0, 41.0, 7.0) * s] {
            let t = Transform::from_trs(offset, Vec3::new(10.0, 20.0, 30.0), Vec3::splat(s));
            let mesh = Shape::Mesh(subdivided_cube(12)).to_world(&t).unwrap();
            let g = SceneGeometry::build(&[(mesh, 0)]).unwrap();
            let hits = surface_hits(&g, &mut rng, offset, s, RAYS / 2);
            check_closed_convex(
                &g,
                &hits,
                &mut rng,
                s,
                true,
                &format!("mesh scale {s} offset {offset}"),
            );
            // Aim exactly at vertices / shared edges of the subdivided faces, then spawn.
            let m = match Shape::Mesh(subdivided_cube(12)).to_world(&t).unwrap() {
                Shape::Mesh(m) => m,
                _ => unreachable!(),
            };
            let mut n = 0;
            for (k, &p) in m.positions.iter().enumerate().step_by(3) {
                let o = p + (p - offset).normalize() * 2.0 * s + rng.unit_vector() * 0.3 * s;
                if let Some(h) = g.intersect(o, p - o, f32::INFINITY) {
                    n += 1;
                    let w = dir_around(&mut rng, h.ng, 0.0);
                    assert!(
                        g.intersect(h.spawn_origin(w), w, f32::INFINITY).is_none(),
                        "vertex {k} re-hit"
                    );
                }
            }
            assert!(n > 100);
        }
    }
}

#[test]
fn quad_and_disk_no_self_intersection() {
    let mut rng = Rng::new(13);
    for s in SCALES {
        for offset in [Vec3::ZERO, Vec3::new(17.0, 3.0, -29.0) * s] {
            let shapes = vec![
                (
                    Shape::Quad {
                        origin: offset + Vec3::new(-1.0, -1.0, 0.3) * s,
                        edge_u: Vec3::new(2.0, 0.1, 0.3) * s,
                        edge_v: Vec3::new(-0.2, 2.0, 0.1) * s,
                    },
                    0,
                ),
                (
                    Shape::Disk {
                        center: offset + Vec3::new(0.0, 0.0, -2.0) * s,
                        normal: Vec3::new(0.1, 0.2, 1.0),
                        radius: s,
                    },
                    1,
                ),
            ];
            let g = SceneGeometry::build(&shapes).unwrap();
            for obj in [0u32, 1] {
                let prim = g.primitives_of_object(obj)[0];
                for k in 0..RAYS / 4 {
                    // From a hit on this primitive...
                    let sp = g.sample_prim(prim, rng.vec2());
                    let o = sp.p
                        + dir_around(&mut rng, sp.n, 0.2)
                            * 3.0
                            * s
                            * if k % 2 == 0 { 1.0 } else { -1.0 };
                    let Some(h) = g.intersect(o, sp.p - o, f32::INFINITY) else {
                        continue;
                    };
                    if h.prim != prim {
                        continue;
                    }
                    // ...rays to either side must not re-hit this primitive.
                    for side in [1.0, -1.0] {
                        let w = dir_around(&mut rng, side * h.ng, 0.0);
                        if let Some(x) = g.intersect(h.spawn_origin(w), w, f32::INFINITY) {
                            assert_ne!(
                                x.prim, prim,
                                "scale {s}: primitive {prim} re-hit itself at t={}",
                                x.t
                            );
                        }
                    }
                    // Grazing directions, too.
                    let w = (rng.unit_vector().cross(h.ng)).normalize();
                    if let Some(x) = g.intersect(h.spawn_origin(w), w, f32::INFINITY) {
                        assert_ne!(x.prim, prim, "scale {s}: grazing self-hit");
                    }
                }
            }
        }
    }
}

#[test]
fn shadow_rays_between_surfaces_are_unoccluded() {
    // A floor and an area light facing each other: shadow rays between a floor hit and a light
    // sample are never blocked by either end, at any scale.
    let mut rng = Rng::new(14);
    for s in SCALES {
        let shapes = vec![
            (
                Shape::Quad {
                    origin: Vec3::new(-5.0, -5.0, 0.0) * s,
                    edge_u: Vec3::new(10.0, 0.0, 0.0) * s,
                    edge_v: Vec3::new(0.0, 10.0, 0.0) * s,
                },
                0,
            ),
            (
                Shape::Quad {
                    origin: Vec3::new(-0.5, -0.5, 3.0) * s,
                    edge_u: Vec3::new(0.0, 1.0, 0.0) * s,
                    edge_v: Vec3::new(1.0, 0.0, 0.0) * s,
                },
                1,
            ),
            (
                Shape::Sphere {
                    center: Vec3::new(3.0, 3.0, 2.0) * s,
                    radius: 0.3 * s,
                },
                2,
            ),
        ];
        let g = SceneGeometry::build(&shapes).unwrap();
        for &light in &[1u32, 2] {
            let lp = g.primitives_of_object(light)[0];
            for _ in 0..RAYS / 4 {
                let o = Vec3::new(rng.range(-4.0, 4.0), rng.range(-4.0, 4.0), 1.0) * s;
                let h = g.intersect(o, -Vec3::Z, f32::INFINITY).unwrap();
                let ls = match g.sample_prim_solid_angle(lp, h.p, rng.vec2()) {
                    Some((sp, _)) => sp,
                    None => continue,
                };
                let (ro, rd, tmax) = shadow_ray(&h, ls.p, ls.n);
                assert!(
                    !g.occluded(ro, rd, tmax),
                    "scale {s}: shadow ray from {} to {} occluded",
                    h.p,
                    ls.p
                );
            }
        }
        // And a real occluder between them is detected.
        let h = g
            .intersect(Vec3::new(0.0, 0.0, 1.0) * s, -Vec3::Z, f32::INFINITY)
            .unwrap();
        let (ro, rd, tmax) = shadow_ray(&h, Vec3::new(0.0, 0.0, 10.0) * s, -Vec3::Z);
        assert!(g.occluded(ro, rd, tmax));
    }
}
