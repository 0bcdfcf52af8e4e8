//! Scenes of a few quads skip the BVH and test all quads at once: the hits, shadow-ray answers
//! and hit records must be exactly those of the scalar quad test (brute force) and of the same
//! quads in a scene large enough to use the BVH.

use candela::geometry::{
    InstanceGroup, SceneGeometry, Shape, Transform, TriangleMesh, SHADOW_EPSILON,
};
use glam::Vec3;

/// xorshift64*: reproducible rays without a dependency.
struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32) / (1u64 << 24) as f32
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f()
    }
    fn dir(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            if v.length_squared() > 1e-4 && v.length_squared() <= 1.0 {
                return v;
            }
        }
    }
}

fn quad(o: [f32; 3], u: [f32; 3], v: [f32; 3]) -> Shape {
    Shape::Quad {
        origin: Vec3::from(o),
        edge_u: Vec3::from(u),
        edge_v: Vec3::from(v),
    }
}

/// The 8 × 3 × 6 m office of bench/mitsuba/interior.ron: six room quads and six ceiling panels.
fn room() -> Vec<Shape> {
    let mut s = vec![
        quad([0.0, 0.0, 0.0], [0.0, 0.0, 6.0], [8.0, 0.0, 0.0]),
        quad([0.0, 3.0, 0.0], [8.0, 0.0, 0.0], [0.0, 0.0, 6.0]),
        quad([0.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 6.0]),
        quad([8.0, 0.0, 0.0], [0.0, 0.0, 6.0], [0.0, 3.0, 0.0]),
        quad([0.0, 0.0, 0.0], [8.0, 0.0, 0.0], [0.0, 3.0, 0.0]),
        quad([0.0, 0.0, 6.0], [0.0, 3.0, 0.0], [8.0, 0.0, 0.0]),
    ];
    for (x, z) in [1.03333, 3.7, 6.36667]
        .into_iter()
        .flat_map(|x| [(x, 1.2), (x, 4.2)])
    {
        s.push(quad([x, 2.999, z], [0.6, 0.0, 0.0], [0.0, 0.0, 0.6]));
    }
    s
}

fn build(shapes: &[Shape]) -> SceneGeometry {
    let s: Vec<(Shape, u32)> = shapes
        .iter()
        .enumerate()
        .map(|(i, s)| (s.clone(), i as u32))
        .collect();
    SceneGeometry::build(&s).unwrap()
}

/// Rays of many kinds for a room: from inside, from surface points (spawned), from outside,
/// axis-parallel, aimed exactly at corners and edges (flagged), with finite and infinite
/// `t_max`.
fn rays(seed: u64, n: usize) -> Vec<(Vec3, Vec3, f32, bool)> {
    let mut r = Rng(seed);
    let corners: Vec<Vec3> = (0..8)
        .map(|k| {
            Vec3::new(
                if k & 1 != 0 { 8.0 } else { 0.0 },
                if k & 2 != 0 { 3.0 } else { 0.0 },
                if k & 4 != 0 { 6.0 } else { 0.0 },
            )
        })
        .collect();
    let mut out = Vec::new();
    for i in 0..n {
        let o = match i % 4 {
            0 | 1 => Vec3::new(r.range(0.0, 8.0), r.range(0.0, 3.0), r.range(0.0, 6.0)),
            2 => Vec3::new(
                r.range(-20.0, 28.0),
                r.range(-20.0, 23.0),
                r.range(-20.0, 26.0),
            ),
            _ => Vec3::new(r.range(1.0, 7.0), 2.9995, r.range(1.0, 5.0)),
        };
        let d = match i % 7 {
            0 => corners[i % 8] - o,
            1 => {
                // A point on an edge of the room or of a panel.
                let c = corners[i % 8];
                let e = [Vec3::X * 8.0, Vec3::Y * 3.0, Vec3::Z * 6.0][i % 3];
                c - e * (c.dot(e) / e.length_squared()) + e * r.f() - o
            }
            2 => [Vec3::X, -Vec3::Y, Vec3::Z, Vec3::new(0.0, 1.0, 1e-30)][i % 4],
            _ => r.dir() * r.range(0.01, 10.0),
        };
        let t_max = match i % 5 {
            0 => r.range(0.0, 2.0),
            1 => 1.0,
            _ => f32::INFINITY,
        };
        out.push((o, d, t_max, i % 7 < 2));
    }
    out
}

#[test]
fn few_quads_match_the_scalar_test_exactly() {
    let geo = build(&room());
    let mut hits = 0;
    for (o, d, t_max, _) in rays(1, 60_000) {
        let h = geo.intersect(o, d, t_max);
        let b = geo.intersect_brute_force(o, d, t_max);
        assert_eq!(format!("{h:?}"), format!("{b:?}"), "ray {o} {d} {t_max}");
        assert_eq!(
            geo.occluded(o, d, t_max),
            b.is_some(),
            "ray {o} {d} {t_max}"
        );
        let basic = geo.intersect_basic(o, d, t_max);
        assert_eq!(basic.map(|h| (h.t, h.prim)), h.map(|h| (h.t, h.prim)));
        hits += h.is_some() as usize;
    }
    assert!(hits > 30_000, "{hits} hits");
}

#[test]
fn few_quads_match_the_bvh() {
    let small = room();
    // The same room and five quads far outside it: too many quads to skip the BVH.
    let mut big = small.clone();
    for k in 0..5 {
        big.push(quad(
            [100.0 + k as f32, 0.0, 0.0],
            [0.5, 0.0, 0.0],
            [0.0, 0.5, 0.0],
        ));
    }
    let (gs, gb) = (build(&small), build(&big));
    let mut ties = 0;
    for (o, d, t_max, aimed) in rays(2, 60_000) {
        if o.max_element() > 8.0 || o.min_element() < 0.0 {
            continue; // outside rays could reach the far quads
        }
        let (hs, hb) = (gs.intersect(o, d, t_max), gb.intersect(o, d, t_max));
        let key = |h: Option<candela::geometry::Hit>| {
            h.map(|h| {
                format!(
                    "{:?}",
                    (h.t, h.p, h.ng, h.ns, h.uv, h.object, h.front_face, h.error)
                )
            })
        };
        if key(hs) != key(hb) {
            // A tie: the ray meets the shared edge of two quads (to f64 precision), and the
            // traversal kept another of the equally near hits than the lowest id.
            let (s, b) = (hs.unwrap(), hb.unwrap());
            let on_edge =
                |h: &candela::geometry::Hit| h.uv.min_element() == 0.0 || h.uv.max_element() == 1.0;
            assert!(
                aimed && s.t == b.t && s.object != b.object && on_edge(&s) && on_edge(&b),
                "ray {o} {d} {t_max}: {s:?} vs {b:?}"
            );
            ties += 1;
        }
        assert_eq!(gs.occluded(o, d, t_max), gb.occluded(o, d, t_max));
    }
    assert!(ties > 0, "the test aims no ray at an edge");
}

#[test]
fn shadow_rays_between_surfaces_of_a_few_quads() {
    // Shadow rays from hits on the room to points on the panels: never blocked by either end,
    // and the same answer as the brute-force closest hit within the segment.
    let geo = build(&room());
    let mut r = Rng(3);
    let mut tested = 0;
    for (o, d, ..) in rays(4, 20_000) {
        let Some(h) = geo.intersect(o, d, f32::INFINITY) else {
            continue;
        };
        let target = Vec3::new(r.range(1.04, 1.6), 2.999, r.range(1.21, 1.79));
        let (so, sd, st) = candela::geometry::shadow_ray(&h, target, -Vec3::Y);
        assert!(st < (target - h.p).length() * (1.0 - SHADOW_EPSILON * 0.5));
        let blocked = geo.occluded(so, sd, st);
        assert_eq!(
            blocked,
            geo.intersect_brute_force(so, sd, st).is_some(),
            "from {} to {target}",
            h.p
        );
        tested += 1;
    }
    assert!(tested > 10_000);
}

#[test]
fn few_quads_with_instances_still_see_the_instances() {
    // A small room plus an instanced triangle inside it: the quads' fast path must not hide the
    // instances.
    let tri = Shape::Mesh(TriangleMesh {
        positions: vec![
            Vec3::new(-0.5, 0.0, 0.0),
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ],
        indices: vec![[0, 1, 2]],
        ..Default::default()
    });
    let transforms = [
        Transform::from_trs(Vec3::new(4.0, 1.0, 3.0), Vec3::ZERO, Vec3::ONE),
        Transform::from_trs(
            Vec3::new(2.0, 0.5, 5.0),
            Vec3::new(0.0, 90.0, 0.0),
            Vec3::ONE,
        ),
    ];
    let groups = [InstanceGroup {
        parts: vec![(&tri, None)],
        transforms: &transforms,
        first_object: 100,
    }];
    let shapes: Vec<(Shape, u32)> = room()
        .into_iter()
        .enumerate()
        .map(|(i, s)| (s, i as u32))
        .collect();
    let geo = SceneGeometry::build_instanced(&shapes, &[], &groups).unwrap();
    let mut on_instance = 0;
    for (o, d, t_max, _) in rays(5, 40_000) {
        let h = geo.intersect(o, d, t_max);
        let b = geo.intersect_brute_force(o, d, t_max);
        assert_eq!(format!("{h:?}"), format!("{b:?}"), "ray {o} {d} {t_max}");
        assert_eq!(geo.occluded(o, d, t_max), b.is_some());
        on_instance += h.is_some_and(|h| h.object >= 100) as usize;
    }
    // Aimed at the instances' centres.
    for c in [Vec3::new(4.0, 1.3, 3.0), Vec3::new(2.0, 0.8, 5.0)] {
        let o = Vec3::new(4.5, 2.0, 0.5);
        let h = geo.intersect(o, c - o, f32::INFINITY).unwrap();
        assert!(h.object >= 100, "{h:?}");
        assert!(geo.occluded(o, c - o, 1.5));
        on_instance += 1;
    }
    assert!(on_instance > 100, "{on_instance}");
}
