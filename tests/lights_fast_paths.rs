//! Next-event estimation's cheaper paths give what the general ones give:
//! - solid-angle sampling without texture coordinates (for untextured lights) returns the same
//!   point, normal and pdf, bit for bit, on every kind of primitive;
//! - a light BVH over at most eight emitters is one node, so each emitter is chosen in
//!   proportion to its own importance; with more, the probabilities still sum to 1.

use candela::geometry::{SceneGeometry, Shape, TriangleMesh};
use candela::light::bounds::{Cone, LightBounds};
use candela::light::bvh::{Emitter, LightBvh};
use glam::{Vec2, Vec3};

fn next(s: &mut u64) -> f32 {
    *s = s
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*s >> 40) as f32) / (1u64 << 24) as f32
}

#[test]
fn solid_angle_sampling_without_texture_coordinates_is_the_same_sample() {
    let mesh = TriangleMesh {
        positions: vec![
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(1.0, 2.2, 0.0),
            Vec3::new(0.0, 2.1, 1.5),
        ],
        indices: vec![[0, 1, 2]],
        ..Default::default()
    };
    let shapes = [
        Shape::Sphere {
            center: Vec3::new(0.5, 2.0, 0.5),
            radius: 0.3,
        },
        Shape::Quad {
            origin: Vec3::new(-1.0, 3.0, -1.0),
            edge_u: Vec3::new(0.6, 0.0, 0.0),
            edge_v: Vec3::new(0.0, 0.1, 0.6),
        },
        Shape::Disk {
            center: Vec3::new(1.0, 2.5, -0.5),
            normal: Vec3::new(0.0, -1.0, 0.2).normalize(),
            radius: 0.4,
        },
        Shape::Mesh(mesh),
    ];
    let mut s = 3u64;
    for shape in shapes {
        let g = SceneGeometry::build(&[(shape, 1)]).unwrap();
        let prim = g.primitives_of_object(1)[0];
        // Receivers far, near and (for the sphere) inside.
        for reference in [
            Vec3::ZERO,
            Vec3::new(0.4, 1.8, 0.6),
            Vec3::new(0.5, 2.1, 0.45),
        ] {
            for _ in 0..2000 {
                let u = Vec2::new(next(&mut s), next(&mut s));
                let full = g.sample_prim_solid_angle(prim, reference, u);
                let bare = g.sample_prim_solid_angle_with(prim, reference, u, false);
                match (full, bare) {
                    (None, None) => {}
                    (Some((a, pa)), Some((b, pb))) => {
                        assert_eq!(
                            a.p.to_array().map(f32::to_bits),
                            b.p.to_array().map(f32::to_bits)
                        );
                        assert_eq!(
                            a.n.to_array().map(f32::to_bits),
                            b.n.to_array().map(f32::to_bits)
                        );
                        assert_eq!(pa.to_bits(), pb.to_bits());
                        assert_eq!(b.tex, Vec2::ZERO);
                    }
                    other => panic!("{other:?} at {reference} u {u}"),
                }
            }
        }
    }
}

fn emitters(n: usize, s: &mut u64) -> Vec<Emitter> {
    (0..n)
        .map(|i| {
            let c = Vec3::new(10.0 * next(s), 3.0, 10.0 * next(s));
            let half = Vec3::new(0.3, 0.0, 0.3);
            Emitter {
                light: i as u32,
                prim: 0,
                bounds: LightBounds {
                    lo: c - half,
                    hi: c + half,
                    phi: 100.0 + 1000.0 * next(s),
                    axes: Cone {
                        w: -Vec3::Y,
                        cos_theta: 1.0,
                    },
                    cos_e: 0.0,
                    two_sided: false,
                },
            }
        })
        .collect()
}

#[test]
fn eight_emitters_or_fewer_are_one_node_chosen_by_their_own_importance() {
    let mut s = 17u64;
    for n in 2..=8 {
        let es = emitters(n, &mut s);
        let bvh = LightBvh::build(es.clone());
        assert_eq!(bvh.stats(), (1, 1), "{n} emitters");
        for _ in 0..50 {
            let p = Vec3::new(10.0 * next(&mut s), 0.0, 10.0 * next(&mut s));
            let normal = Some(Vec3::Y);
            let imp: Vec<f64> = bvh
                .emitters()
                .iter()
                .map(|e| e.bounds.importance(p, normal) as f64)
                .collect();
            let total: f64 = imp.iter().sum();
            for (e, &w) in imp.iter().enumerate() {
                let pmf = bvh.pmf(p, normal, e) as f64;
                assert!(
                    (pmf - w / total).abs() < 1e-6,
                    "{n} emitters, {e}: {pmf} vs {}",
                    w / total
                );
            }
        }
    }
}

#[test]
fn many_emitters_pmf_sums_to_one_and_matches_sample() {
    let mut s = 5u64;
    for n in [9, 30, 200] {
        let bvh = LightBvh::build(emitters(n, &mut s));
        let (nodes, depth) = bvh.stats();
        assert!(
            nodes > 1 && depth >= 2,
            "{n} emitters: {nodes} nodes, depth {depth}"
        );
        for _ in 0..20 {
            let p = Vec3::new(10.0 * next(&mut s), 0.0, 10.0 * next(&mut s));
            let normal = Some(Vec3::Y);
            let total: f64 = (0..n).map(|e| bvh.pmf(p, normal, e) as f64).sum();
            assert!((total - 1.0).abs() < 1e-5, "{n} emitters: Σ pmf = {total}");
            for _ in 0..50 {
                let (e, pr) = bvh.sample(p, normal, next(&mut s)).expect("an emitter");
                assert_eq!(pr, bvh.pmf(p, normal, e));
            }
        }
    }
}
