//! The wide BVH against obvhs's CWBVH walked by the `traverse` kernel (the same watertight
//! triangle test behind both): same closest hits and any hits on random rays over a CAD-shaped
//! mesh; the portable node and block tests against the SIMD ones; rays through shared edges
//! and vertices of closed meshes never leak.

use super::*;
use crate::geometry::bvh::{build_cwbvh, padded_aabb};
use crate::geometry::prim::intersect_triangle;
use crate::geometry::traverse::{self, LeafTest};
use crate::geometry::{SceneGeometry, Shape, TriangleMesh};

struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
    fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.f()
    }
    fn unit(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(self.f(), self.f(), self.f()) * 2.0 - 1.0;
            let l = v.length_squared();
            if l > 1e-4 && l <= 1.0 {
                return v / l.sqrt();
            }
        }
    }
}

/// A CAD-like mesh: a fan of slivers round one vertex, a finely tessellated cylinder of long
/// slivers, a grid with a coincident copy of part of it, and a soup of small triangles.
fn cad_mesh(rng: &mut Rng) -> TriangleMesh {
    let mut m = TriangleMesh::default();
    let tri = |m: &mut TriangleMesh, v: [Vec3; 3]| {
        let b = m.positions.len() as u32;
        m.positions.extend(v);
        m.indices.push([b, b + 1, b + 2]);
    };
    // Fan: 2000 slivers round (0, 0, 0) in the plane z = 0.
    let n = 2000;
    for i in 0..n {
        let a0 = i as f32 / n as f32 * std::f32::consts::TAU;
        let a1 = (i + 1) as f32 / n as f32 * std::f32::consts::TAU;
        let p = |a: f32| Vec3::new(a.cos(), a.sin(), 0.0) * 2.0;
        tri(&mut m, [Vec3::ZERO, p(a0), p(a1)]);
    }
    // Cylinder: 1000 facets 3 m long, 2 slivers each.
    let n = 1000;
    for i in 0..n {
        let a0 = i as f32 / n as f32 * std::f32::consts::TAU;
        let a1 = (i + 1) as f32 / n as f32 * std::f32::consts::TAU;
        let p = |a: f32, z: f32| Vec3::new(3.0 + 0.5 * a.cos(), 0.5 * a.sin(), z);
        tri(&mut m, [p(a0, -1.5), p(a1, -1.5), p(a1, 1.5)]);
        tri(&mut m, [p(a0, -1.5), p(a1, 1.5), p(a0, 1.5)]);
    }
    // Grid 40 × 40 at x = −3, and a coincident copy of its first 400 triangles.
    let mut grid = Vec::new();
    for j in 0..40 {
        for i in 0..40 {
            let p = |i: i32, j: i32| Vec3::new(-3.0, i as f32 * 0.1 - 2.0, j as f32 * 0.1 - 2.0);
            grid.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            grid.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    for v in grid.iter().chain(&grid[..400]) {
        tri(&mut m, *v);
    }
    // Soup.
    for _ in 0..4000 {
        let c = Vec3::new(
            rng.range(-4.0, 4.0),
            rng.range(-3.0, 3.0),
            rng.range(-2.0, 2.0),
        );
        let s = rng.range(0.005, 0.2);
        tri(
            &mut m,
            [c + s * rng.unit(), c + s * rng.unit(), c + s * rng.unit()],
        );
    }
    m
}

/// The old kernel: obvhs's CWBVH (leaves of at most 3) walked by `traverse::traverse`, with
/// the scalar triangle test.
struct Reference {
    nodes: Vec<obvhs::cwbvh::node::CwBvhNode>,
    tris: Vec<[Vec3; 3]>,
}

impl Reference {
    fn new(tris: &[[Vec3; 3]]) -> Self {
        let aabbs: Vec<_> = tris
            .iter()
            .map(|t| padded_aabb(t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2])))
            .collect();
        let bvh = build_cwbvh(&aabbs, 3);
        let tris = bvh
            .primitive_indices
            .iter()
            .map(|&i| tris[i as usize])
            .collect();
        Self {
            nodes: bvh.nodes,
            tris,
        }
    }

    /// (triangle, t, b1, b2) of the closest hit, or whether anything is hit (`any`).
    fn trace(&self, o: Vec3, d: Vec3, t_max: f32, any: bool) -> Option<([Vec3; 3], f32, f32, f32)> {
        struct L<'a> {
            r: &'a Reference,
            pre: RayPre,
            any: bool,
            best: Option<([Vec3; 3], f32, f32, f32)>,
        }
        impl LeafTest for L<'_> {
            fn leaf(&mut self, first: u32, unary: u32, mut t_max: f32) -> Option<f32> {
                let (mut id, mut u) = (first, unary);
                while u != 0 {
                    let v = &self.r.tris[id as usize];
                    let h = match self.pre.kz {
                        0 => intersect_triangle::<0>(&self.pre, t_max, v),
                        1 => intersect_triangle::<1>(&self.pre, t_max, v),
                        _ => intersect_triangle::<2>(&self.pre, t_max, v),
                    };
                    if let Some((t, a, b)) = h {
                        self.best = Some((*v, t, a, b));
                        if self.any {
                            return None;
                        }
                        t_max = t;
                    }
                    id += 1;
                    u >>= 1;
                }
                Some(t_max)
            }
            fn prefetch(&self, _: u32) {}
        }
        let mut l = L {
            r: self,
            pre: RayPre::new(o, d),
            any,
            best: None,
        };
        if any {
            traverse::traverse::<false>(&self.nodes, o, d, t_max, &mut l);
        } else {
            traverse::traverse::<true>(&self.nodes, o, d, t_max, &mut l);
        }
        l.best
    }
}

/// Closest hits: t and the barycentrics bit-identical on the same triangle; or, where several
/// triangles meet the ray at one point (shared edges and vertices, the coincident copy),
/// possibly another of them, with the (t, b1, b2) the scalar test gives it and t within 1 ulp.
/// Any hits: the same answer.
#[test]
fn same_hits_as_the_cwbvh_kernel() {
    let mut rng = Rng(7);
    let mesh = cad_mesh(&mut rng);
    let tris: Vec<[Vec3; 3]> = mesh
        .indices
        .iter()
        .map(|t| t.map(|i| mesh.positions[i as usize]))
        .collect();
    let geo = SceneGeometry::build(&[(Shape::Mesh(mesh), 0)]).unwrap();
    assert_eq!(geo.tris.len(), tris.len());
    let reference = Reference::new(&tris);
    let (mut hits, mut ties, mut ulp1, mut occluded) = (0, 0, 0, 0);
    let rays = 120_000;
    for i in 0..rays {
        // Origins round the scene, aimed at points in it (half of them at a fan or grid
        // vertex, where many triangles meet); every 4th ray is short.
        let o = rng.unit() * rng.range(0.5, 8.0);
        let target = match i % 4 {
            0 => Vec3::ZERO,
            1 => Vec3::new(
                -3.0,
                (i % 40) as f32 * 0.1 - 2.0,
                ((i / 40) % 40) as f32 * 0.1 - 2.0,
            ),
            _ => Vec3::new(
                rng.range(-4.0, 4.0),
                rng.range(-3.0, 3.0),
                rng.range(-2.0, 2.0),
            ),
        };
        let d = (target - o) * rng.range(0.2, 3.0);
        let t_max = if i % 4 == 3 {
            rng.range(0.1, 1.2)
        } else {
            f32::INFINITY
        };
        let want = reference.trace(o, d, t_max, false);
        let got = geo.intersect_basic(o, d, t_max);
        match (want, got) {
            (None, None) => {}
            (Some((v, t, a, b)), Some(h)) => {
                hits += 1;
                let gv = geo.tris[h.prim as usize];
                if gv == v {
                    assert_eq!(
                        (h.t.to_bits(), h.u.to_bits(), h.v.to_bits()),
                        (t.to_bits(), a.to_bits(), b.to_bits()),
                        "ray {i}"
                    );
                } else {
                    // Another triangle at the same point (a shared vertex or edge, or the
                    // coincident copy): its own t, which the scalar test also gives, and
                    // within 1 ulp of the reference's (the test rejects by t_scaled against
                    // t_max·det, so which of two hits 1 ulp apart wins depends on the order).
                    ties += 1;
                    ulp1 += (h.t != t) as u32;
                    assert!(
                        h.t.to_bits().abs_diff(t.to_bits()) <= 1,
                        "ray {i}: {} vs {t}",
                        h.t
                    );
                    let pre = RayPre::new(o, d);
                    let again =
                        crate::geometry::prim::Prim::Triangle(gv).intersect_dyn(&pre, t_max);
                    assert_eq!(
                        again.map(|x| (x.0.to_bits(), x.1.to_bits(), x.2.to_bits())),
                        Some((h.t.to_bits(), h.u.to_bits(), h.v.to_bits())),
                        "ray {i}"
                    );
                }
            }
            (w, g) => panic!("ray {i} from {o} along {d}: reference {w:?}, wide {g:?}"),
        }
        let want_any = reference.trace(o, d, t_max, true).is_some();
        assert_eq!(geo.occluded(o, d, t_max), want_any, "ray {i}");
        occluded += want_any as u32;
    }
    // The test means something: most rays hit, many through shared vertices and coincident
    // triangles.
    assert!(
        hits > rays / 2 && occluded > rays / 2,
        "{hits} hits, {occluded} occluded"
    );
    assert!(ties > 100, "{ties} ties");
    eprintln!("{rays} rays: {hits} hits, {ties} on another triangle at the same point ({ulp1} of them 1 ulp apart in t), {occluded} occluded");
}

fn random_node(rng: &mut Rng) -> WideNode {
    let mut n = EMPTY_NODE;
    for k in 0..WIDTH - (rng.f() * 3.0) as usize {
        for a in 0..3 {
            let c = rng.range(-5.0, 5.0);
            let h = rng.range(0.0, 2.0) * rng.f().powi(3);
            n.planes[2 * a][k] = c - h;
            n.planes[2 * a + 1][k] = c + h;
        }
        n.child[k] = k as u32;
    }
    n
}

/// The portable node and block tests give the same masks and distances as the SIMD ones.
#[test]
fn portable_tests_match_simd() {
    let mut rng = Rng(11);
    for i in 0..20_000 {
        let node = random_node(&mut rng);
        let o = rng.unit() * rng.range(0.0, 9.0);
        let mut d = rng.unit();
        if i % 7 == 0 {
            d[i % 3] = 0.0;
        }
        let r = NodeRay::new(o, d);
        let t_max = if i % 2 == 0 {
            f32::INFINITY
        } else {
            rng.range(0.0, 10.0)
        };
        let (mut a, mut b) = ([0.0; WIDTH], [0.0; WIDTH]);
        let ma = node_test(&node, &r, t_max, &mut a);
        let mb = node_test_scalar(&node, &r, t_max, &mut b);
        assert_eq!(ma, mb, "node {i}");
        for k in 0..WIDTH {
            if ma & (1 << k) != 0 {
                assert_eq!(a[k], b[k]);
            }
        }
        // Blocks: triangles near the ray, some through it.
        let mut block = TriBlock {
            v: [[[0.0; LANES]; 3]; 3],
            first: 0,
            mask: (1 << (1 + i % 4)) - 1,
            _pad: [0; 2],
        };
        for l in 0..LANES {
            let c = o + d * rng.range(0.0, 5.0) + rng.unit() * rng.range(0.0, 0.3);
            for k in 0..3 {
                let p = c + rng.unit() * rng.range(0.01, 0.5);
                for ax in 0..3 {
                    block.v[k][ax][l] = p[ax];
                }
            }
        }
        if d == Vec3::ZERO {
            continue;
        }
        let pre = RayPre::new(o, d);
        let (simd, scalar) = match pre.kz {
            0 => (
                block_candidates::<0>(&block, &pre),
                block_candidates_scalar::<0>(&block, &pre),
            ),
            1 => (
                block_candidates::<1>(&block, &pre),
                block_candidates_scalar::<1>(&block, &pre),
            ),
            _ => (
                block_candidates::<2>(&block, &pre),
                block_candidates_scalar::<2>(&block, &pre),
            ),
        };
        assert_eq!(simd, scalar, "block {i}");
    }
}

/// Rays from inside closed meshes (a tessellated sphere, in several sizes and places) aimed
/// exactly at their vertices and edge midpoints always hit them, closest and any hit.
#[test]
fn closed_meshes_do_not_leak() {
    let mut rng = Rng(5);
    for (scale, centre) in [
        (1.0, Vec3::ZERO),
        (1e-3, Vec3::splat(0.2)),
        (300.0, Vec3::new(1e3, -2e3, 5e2)),
    ] {
        let (nu, nv) = (48u32, 24u32);
        let mut m = TriangleMesh::default();
        for j in 0..=nv {
            for i in 0..nu {
                let (th, ph) = (
                    j as f32 / nv as f32 * std::f32::consts::PI,
                    i as f32 / nu as f32 * std::f32::consts::TAU,
                );
                m.positions.push(
                    centre + scale * Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()),
                );
            }
        }
        for j in 0..nv {
            for i in 0..nu {
                let v = |i: u32, j: u32| j * nu + i % nu;
                m.indices.push([v(i, j), v(i, j + 1), v(i + 1, j + 1)]);
                m.indices.push([v(i, j), v(i + 1, j + 1), v(i + 1, j)]);
            }
        }
        let targets: Vec<Vec3> = m
            .indices
            .iter()
            .flat_map(|t| {
                let p = t.map(|i| m.positions[i as usize]);
                [
                    p[0],
                    (p[0] + p[1]) * 0.5,
                    (p[1] + p[2]) * 0.5,
                    (p[0] + p[2]) * 0.5,
                ]
            })
            .collect();
        let geo = SceneGeometry::build(&[(Shape::Mesh(m), 0)]).unwrap();
        for target in targets {
            let o = centre + rng.unit() * scale * rng.range(0.0, 0.5);
            let d = target - o;
            assert!(
                geo.intersect_basic(o, d, f32::INFINITY).is_some(),
                "leak at {target}"
            );
            assert!(geo.occluded(o, d, 2.0), "shadow leak at {target}");
        }
    }
}
