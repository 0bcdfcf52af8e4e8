//! candela's own BVH layout for the scene's primitives, converted from obvhs's binary tree:
//! 8-wide nodes with their children's boxes as plain f32 planes (one 8-lane array per plane),
//! and leaves of up to [`MAX_LEAF_PRIMS`] primitives stored as blocks of 4 triangles in
//! structure-of-arrays form ([`TriBlock`]), so that the node test and the first half of the
//! triangle test (the edge functions) run on all lanes at once.
//!
//! The node test is conservative: every slab distance is `(plane − o)·(1/d)`, three roundings
//! of relative error at most γ(3) each, and the exit distance and `t_max` are widened by a
//! relative margin ([`FAR_SCALE`]) that covers them and the rounding of a primitive's `t`, so
//! no box holding a hit closer than `t_max` is ever culled. The block test only rejects the
//! lanes whose edge functions (computed exactly as the scalar watertight test computes them)
//! differ in sign; each lane it keeps goes through the full scalar test, so every primitive
//! gives the same (t, b1, b2), to the bit, as the scalar test.

use super::bvh::MAX_DEPTH;
use super::prim::RayPre;
use glam::{Vec3, Vec3A};
use obvhs::bvh2::Bvh2;
use std::mem::MaybeUninit;

/// Children per node.
pub(super) const WIDTH: usize = 8;
/// Triangles per block.
pub(super) const LANES: usize = 4;
/// Most primitives in a leaf: a subtree of the binary tree with this many or fewer becomes one
/// leaf.
pub(super) const MAX_LEAF_PRIMS: u32 = 8;

/// Leaf child references: this bit, the leaf's block count − 1 above [`COUNT_SHIFT`], and its
/// first block below it.
const LEAF: u32 = 1 << 31;
const COUNT_SHIFT: u32 = 28;
/// Most blocks in the scene (the first block index has 28 bits).
pub(super) const MAX_BLOCKS: usize = 1 << COUNT_SHIFT;

/// An 8-wide node: its children's boxes and references.
#[repr(C, align(32))]
#[derive(Clone, Copy)]
pub(super) struct WideNode {
    /// Planes min x, max x, min y, max y, min z, max z of the children's boxes, one lane per
    /// child. Empty slots have the box (+∞, −∞), which no ray enters.
    planes: [[f32; WIDTH]; 6],
    /// An inner child's node index, or a leaf ([`LEAF`] set).
    child: [u32; WIDTH],
}

const EMPTY_NODE: WideNode = WideNode {
    planes: [
        [f32::INFINITY; WIDTH],
        [f32::NEG_INFINITY; WIDTH],
        [f32::INFINITY; WIDTH],
        [f32::NEG_INFINITY; WIDTH],
        [f32::INFINITY; WIDTH],
        [f32::NEG_INFINITY; WIDTH],
    ],
    child: [u32::MAX; WIDTH],
};

/// Four primitives in leaf order, vertex coordinates by lane: `v[k][a][l]` is coordinate `a` of
/// vertex `k` of lane `l`'s primitive (the primitive's entry in `SceneGeometry::tris`, which
/// is a NaN marker for non-triangles).
#[repr(C, align(16))]
#[derive(Clone, Copy)]
pub(super) struct TriBlock {
    pub(super) v: [[[f32; LANES]; 3]; 3],
    /// Primitive id of lane 0; lane `l` holds primitive `first + l`.
    pub(super) first: u32,
    /// The lanes in use (bit `l` for lane `l`).
    pub(super) mask: u32,
    _pad: [u32; 2],
}

/// The wide BVH: nodes (the root is node 0; none for an empty scene) and the leaves' blocks.
#[derive(Default)]
pub(super) struct WideBvh {
    pub(super) nodes: Vec<WideNode>,
    pub(super) blocks: Vec<TriBlock>,
}

/// Size of a node and a block, bytes.
pub(super) const NODE_BYTES: usize = std::mem::size_of::<WideNode>();
pub(super) const BLOCK_BYTES: usize = std::mem::size_of::<TriBlock>();

impl WideBvh {
    /// Converts obvhs's binary tree `bvh2` (not empty). Returns the tree without its blocks'
    /// vertices (see [`WideBvh::fill_blocks`]) and the leaf order: primitive id `i` of the new
    /// tree is `bvh2`'s primitive `order[i]` (an index into the builder's input).
    pub(super) fn from_bvh2(bvh2: &Bvh2) -> (WideBvh, Vec<u32>) {
        let n2 = bvh2.nodes.len();
        // Primitives below each node (in post-order: reinsertion leaves nodes in any order).
        let mut count = vec![0u32; n2];
        let mut stack = vec![(0u32, false)];
        while let Some((i, done)) = stack.pop() {
            let node = &bvh2.nodes[i as usize];
            if node.prim_count > 0 {
                // Binary leaves hold one primitive (PLOC and `sah`), so leaves stay small.
                assert!(node.prim_count <= MAX_LEAF_PRIMS);
                count[i as usize] = node.prim_count;
            } else if done {
                let f = node.first_index as usize;
                count[i as usize] = count[f] + count[f + 1];
            } else {
                stack.extend([
                    (i, true),
                    (node.first_index, false),
                    (node.first_index + 1, false),
                ]);
            }
        }
        let mut b = Builder {
            bvh2,
            count,
            out: WideBvh::default(),
            order: Vec::with_capacity(bvh2.primitive_indices.len()),
        };
        b.out.nodes.push(EMPTY_NODE);
        b.node(0, 0);
        let Builder { mut out, order, .. } = b;
        out.nodes.shrink_to_fit();
        out.blocks.shrink_to_fit();
        (out, order)
    }

    /// Writes the blocks' vertices from the primitives in leaf order.
    pub(super) fn fill_blocks(&mut self, tris: &[[Vec3; 3]]) {
        for b in &mut self.blocks {
            for l in 0..LANES {
                if b.mask & (1 << l) != 0 {
                    let t = &tris[(b.first + l as u32) as usize];
                    for k in 0..3 {
                        for a in 0..3 {
                            b.v[k][a][l] = t[k][a];
                        }
                    }
                }
            }
        }
    }

    /// Node levels (1 for a root alone; 0 if empty).
    pub(super) fn depth(&self) -> u32 {
        if self.nodes.is_empty() {
            return 0;
        }
        let mut max = 0;
        let mut stack = vec![(0u32, 1u32)];
        while let Some((n, d)) = stack.pop() {
            max = max.max(d);
            for &c in &self.nodes[n as usize].child {
                if c & LEAF == 0 {
                    stack.push((c, d + 1));
                }
            }
        }
        max
    }
}

struct Builder<'a> {
    bvh2: &'a Bvh2,
    count: Vec<u32>,
    out: WideBvh,
    order: Vec<u32>,
}

impl Builder<'_> {
    /// Fills wide node `at` from the subtree of binary node `n`: the binary nodes below `n`
    /// with the largest surface areas among those too big for a leaf are opened until there
    /// are 8 children (or none is left to open). The inner children's nodes are allocated
    /// together, so that siblings are adjacent in memory.
    fn node(&mut self, at: usize, n: u32) {
        let nodes = &self.bvh2.nodes;
        let mut slots: Vec<u32> = Vec::with_capacity(WIDTH);
        let count = std::mem::take(&mut self.count);
        let big = |i: u32| count[i as usize] > MAX_LEAF_PRIMS;
        if big(n) {
            let f = nodes[n as usize].first_index;
            slots.extend([f, f + 1]);
        } else {
            slots.push(n);
        }
        while slots.len() < WIDTH {
            let open = slots
                .iter()
                .enumerate()
                .filter(|&(_, &s)| big(s))
                .max_by(|a, b| {
                    let area = |i: u32| nodes[i as usize].aabb().half_area();
                    area(*a.1).total_cmp(&area(*b.1))
                })
                .map(|(k, _)| k);
            let Some(k) = open else { break };
            let f = nodes[slots[k] as usize].first_index;
            slots[k] = f;
            slots.push(f + 1);
        }
        let first_inner = self.out.nodes.len();
        let inner = slots.iter().filter(|&&s| big(s)).count();
        self.out
            .nodes
            .extend(std::iter::repeat_n(EMPTY_NODE, inner));
        let mut next = first_inner;
        let mut todo = Vec::with_capacity(inner);
        for (k, &s) in slots.iter().enumerate() {
            let b = nodes[s as usize].aabb();
            let planes = &mut self.out.nodes[at].planes;
            for a in 0..3 {
                planes[2 * a][k] = b.min[a];
                planes[2 * a + 1][k] = b.max[a];
            }
            let child = if big(s) {
                todo.push((next, s));
                next += 1;
                (next - 1) as u32
            } else {
                self.leaf(s)
            };
            self.out.nodes[at].child[k] = child;
        }
        self.count = count;
        for (i, s) in todo {
            self.node(i, s);
        }
    }

    /// The leaf over the primitives below binary node `n`: their ids in leaf order, and the
    /// blocks that hold them (vertices filled in later).
    fn leaf(&mut self, n: u32) -> u32 {
        let start = self.order.len() as u32;
        let mut stack = vec![n];
        while let Some(i) = stack.pop() {
            let node = &self.bvh2.nodes[i as usize];
            if node.prim_count > 0 {
                let f = node.first_index as usize;
                self.order.extend_from_slice(
                    &self.bvh2.primitive_indices[f..f + node.prim_count as usize],
                );
            } else {
                // Right pushed first, so the left subtree comes first in leaf order.
                stack.extend([node.first_index + 1, node.first_index]);
            }
        }
        let m = self.order.len() as u32 - start;
        let first_block = self.out.blocks.len() as u32;
        let nblocks = m.div_ceil(LANES as u32);
        for j in 0..nblocks {
            let lanes = (m - j * LANES as u32).min(LANES as u32);
            self.out.blocks.push(TriBlock {
                v: [[[0.0; LANES]; 3]; 3],
                first: start + j * LANES as u32,
                mask: (1 << lanes) - 1,
                _pad: [0; 2],
            });
        }
        // The caller refuses scenes with more than MAX_BLOCKS blocks before using the tree.
        LEAF | ((nblocks - 1) << COUNT_SHIFT) | (first_block & (MAX_BLOCKS as u32 - 1))
    }
}

/// Ray data for the node test.
struct NodeRay {
    o: [f32; 3],
    inv: [f32; 3],
    /// Plane indices of the near and far plane per axis (near = min for a positive direction).
    near: [usize; 3],
    far: [usize; 3],
}

const INV_LIMIT: f32 = 1e30;

/// Relative widening of the exit distance (and `t_max`) in the node test: covers the γ(3)
/// rounding of each slab distance on either side, and the rounding of a primitive's `t`
/// (which [`traverse`] compares with entry distances), with room to spare.
const FAR_SCALE: f32 = 1.0 + 1.0 / (1 << 20) as f32;

impl NodeRay {
    #[inline(always)]
    fn new(o: Vec3, d: Vec3) -> Self {
        // 1/±0 = ±∞ is clamped to ±INV_LIMIT (d is finite and non-zero, so no NaN).
        let inv =
            (Vec3A::ONE / Vec3A::from(d)).clamp(Vec3A::splat(-INV_LIMIT), Vec3A::splat(INV_LIMIT));
        // From the reciprocal, so that −0 (reciprocal −∞ → −INV_LIMIT) counts as negative.
        let neg = inv.cmplt(Vec3A::ZERO).bitmask() as usize;
        let near = |a: usize| 2 * a + ((neg >> a) & 1);
        Self {
            o: o.to_array(),
            inv: inv.to_array(),
            near: [near(0), near(1), near(2)],
            far: [near(0) ^ 1, near(1) ^ 1, near(2) ^ 1],
        }
    }
}

/// Slab test of the 8 children of `node` against the ray segment [0, t_max]: the mask of the
/// children hit, and every child's entry distance in `tmin_out`.
#[inline(always)]
fn node_test(node: &WideNode, r: &NodeRay, t_max: f32, tmin_out: &mut [f32; WIDTH]) -> u32 {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    // SAFETY: AVX2 is enabled at compile time.
    return unsafe { node_test_avx2(node, r, t_max, tmin_out) };
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    node_test_scalar(node, r, t_max, tmin_out)
}

/// [`node_test`] with AVX: the 8 children at once, the same operations as the scalar form.
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
#[inline(always)]
unsafe fn node_test_avx2(
    node: &WideNode,
    r: &NodeRay,
    t_max: f32,
    tmin_out: &mut [f32; WIDTH],
) -> u32 {
    use std::arch::x86_64::*;
    let p = &node.planes;
    let slab = |a: usize| {
        let o = _mm256_set1_ps(r.o[a]);
        let inv = _mm256_set1_ps(r.inv[a]);
        let near = _mm256_loadu_ps(p[r.near[a]].as_ptr());
        let far = _mm256_loadu_ps(p[r.far[a]].as_ptr());
        (
            _mm256_mul_ps(_mm256_sub_ps(near, o), inv),
            _mm256_mul_ps(_mm256_sub_ps(far, o), inv),
        )
    };
    let (nx, fx) = slab(0);
    let (ny, fy) = slab(1);
    let (nz, fz) = slab(2);
    let tmin = _mm256_max_ps(
        _mm256_max_ps(nx, ny),
        _mm256_max_ps(nz, _mm256_setzero_ps()),
    );
    let tmax = _mm256_mul_ps(
        _mm256_min_ps(
            _mm256_min_ps(fx, fy),
            _mm256_min_ps(fz, _mm256_set1_ps(t_max)),
        ),
        _mm256_set1_ps(FAR_SCALE),
    );
    _mm256_storeu_ps(tmin_out.as_mut_ptr(), tmin);
    _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(tmin, tmax)) as u32
}

/// Portable form of [`node_test`], one child at a time.
#[cfg_attr(
    all(target_arch = "x86_64", target_feature = "avx2", not(test)),
    allow(dead_code)
)]
#[inline(always)]
fn node_test_scalar(node: &WideNode, r: &NodeRay, t_max: f32, tmin_out: &mut [f32; WIDTH]) -> u32 {
    let p = &node.planes;
    let mut mask = 0;
    for k in 0..WIDTH {
        let t = |plane: usize, a: usize| (p[plane][k] - r.o[a]) * r.inv[a];
        let tmin = t(r.near[0], 0)
            .max(t(r.near[1], 1))
            .max(t(r.near[2], 2))
            .max(0.0);
        let tmax = t(r.far[0], 0)
            .min(t(r.far[1], 1))
            .min(t(r.far[2], 2))
            .min(t_max)
            * FAR_SCALE;
        tmin_out[k] = tmin;
        if tmin <= tmax {
            mask |= 1 << k;
        }
    }
    mask
}

/// The lanes of `b` that the watertight triangle test does not reject by the signs of its
/// edge functions (always including lanes holding a non-triangle's marker, whose edge functions
/// are NaN). `KZ` must equal `r.kz`.
#[inline(always)]
pub(super) fn block_candidates<const KZ: usize>(b: &TriBlock, r: &RayPre) -> u32 {
    #[cfg(all(
        target_arch = "x86_64",
        target_feature = "avx2",
        target_feature = "fma"
    ))]
    // SAFETY: AVX2 and FMA are enabled at compile time.
    return unsafe { block_candidates_avx2::<KZ>(b, r) } & b.mask;
    #[cfg(not(all(
        target_arch = "x86_64",
        target_feature = "avx2",
        target_feature = "fma"
    )))]
    block_candidates_scalar::<KZ>(b, r)
}

/// [`block_candidates`] with AVX2: the four lanes' vertices translated, permuted and sheared
/// with the scalar test's f32 operations, and the edge functions `x_i·y_j − y_i·x_j` from exact
/// f64 products with one f64 rounding (the FMA subtracts an exact product) and one to f32, as
/// the scalar test's `diff_of_products`.
#[cfg(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    target_feature = "fma"
))]
#[inline(always)]
unsafe fn block_candidates_avx2<const KZ: usize>(b: &TriBlock, r: &RayPre) -> u32 {
    use std::arch::x86_64::*;
    let (kx, ky) = ((KZ + 1) % 3, (KZ + 2) % 3);
    let o = r.o.to_array();
    let (ox, oy, oz) = (_mm_set1_ps(o[kx]), _mm_set1_ps(o[ky]), _mm_set1_ps(o[KZ]));
    let (sx, sy) = (_mm_set1_ps(r.sx), _mm_set1_ps(r.sy));
    let vert = |k: usize| {
        let z = _mm_sub_ps(_mm_loadu_ps(b.v[k][KZ].as_ptr()), oz);
        let x = _mm_add_ps(
            _mm_sub_ps(_mm_loadu_ps(b.v[k][kx].as_ptr()), ox),
            _mm_mul_ps(sx, z),
        );
        let y = _mm_add_ps(
            _mm_sub_ps(_mm_loadu_ps(b.v[k][ky].as_ptr()), oy),
            _mm_mul_ps(sy, z),
        );
        (_mm256_cvtps_pd(x), _mm256_cvtps_pd(y))
    };
    let (x0, y0) = vert(0);
    let (x1, y1) = vert(1);
    let (x2, y2) = vert(2);
    let edge = |xa, ya, xb, yb| _mm256_cvtpd_ps(_mm256_fmsub_pd(xa, yb, _mm256_mul_pd(ya, xb)));
    let e0 = edge(x1, y1, x2, y2);
    let e1 = edge(x2, y2, x0, y0);
    let e2 = edge(x0, y0, x1, y1);
    let zero = _mm_setzero_ps();
    let neg = _mm_or_ps(
        _mm_or_ps(_mm_cmplt_ps(e0, zero), _mm_cmplt_ps(e1, zero)),
        _mm_cmplt_ps(e2, zero),
    );
    let pos = _mm_or_ps(
        _mm_or_ps(_mm_cmpgt_ps(e0, zero), _mm_cmpgt_ps(e1, zero)),
        _mm_cmpgt_ps(e2, zero),
    );
    !(_mm_movemask_ps(_mm_and_ps(neg, pos)) as u32) & 0xf
}

/// Portable form of [`block_candidates`], one lane at a time, with the scalar test's
/// operations.
#[cfg_attr(
    all(
        target_arch = "x86_64",
        target_feature = "avx2",
        target_feature = "fma",
        not(test)
    ),
    allow(dead_code)
)]
#[inline(always)]
fn block_candidates_scalar<const KZ: usize>(b: &TriBlock, r: &RayPre) -> u32 {
    let (kx, ky) = ((KZ + 1) % 3, (KZ + 2) % 3);
    let o = r.o.to_array();
    let mut mask = 0;
    for l in 0..LANES {
        if b.mask & (1 << l) == 0 {
            continue;
        }
        let p = |k: usize| {
            let z = b.v[k][KZ][l] - o[KZ];
            let x = (b.v[k][kx][l] - o[kx]) + r.sx * z;
            let y = (b.v[k][ky][l] - o[ky]) + r.sy * z;
            (x, y)
        };
        let ((x0, y0), (x1, y1), (x2, y2)) = (p(0), p(1), p(2));
        let dop =
            |a: f32, b: f32, c: f32, d: f32| (a as f64 * b as f64 - c as f64 * d as f64) as f32;
        let e = [
            dop(x1, y2, y1, x2),
            dop(x2, y0, y2, x0),
            dop(x0, y1, y0, x1),
        ];
        let neg = e.iter().any(|&v| v < 0.0);
        let pos = e.iter().any(|&v| v > 0.0);
        if !(neg && pos) {
            mask |= 1 << l;
        }
    }
    mask
}

/// Traversal stack entries: at most 7 pushes per level below the root.
const STACK_SIZE: usize = (WIDTH - 1) * MAX_DEPTH;

/// A traversal stack entry: an inner node, packed into a `u64` as its entry distance's bits
/// (high half) and its node index (low half). Entry distances are non-negative, so their bits
/// order as integers, and entries order by distance with integer compares.
type Key = u64;

/// The key of an inner node entered at distance `dist` (≥ 0). The sign bit is cleared, so that
/// a −0 orders as +0.
#[inline(always)]
fn node_key(dist: f32, idx: u32) -> Key {
    (((dist.to_bits() & 0x7fff_ffff) as u64) << 32) | idx as u64
}

/// The largest key whose entry distance does not exceed `t` widened as in the node test:
/// entries above it cannot hold a hit closer than `t`.
#[inline(always)]
fn cull_key(t: f32) -> Key {
    node_key(t * FAR_SCALE, u32::MAX)
}

/// The slots whose entry distance `tmin` does not exceed `t` widened as in the node test.
#[inline(always)]
fn le_mask(tmin: &[f32; WIDTH], t: f32) -> u32 {
    let t = t * FAR_SCALE;
    #[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
    // SAFETY: AVX is enabled at compile time; the load reads the 8 floats of `tmin`.
    unsafe {
        use std::arch::x86_64::*;
        let v = _mm256_loadu_ps(tmin.as_ptr());
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(v, _mm256_set1_ps(t))) as u32
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
    {
        let mut m = 0;
        for (k, &d) in tmin.iter().enumerate() {
            if d <= t {
                m |= 1 << k;
            }
        }
        m
    }
}

/// The primitive tests of a traversal: `leaf(first, count, t_max)` tests the primitives of
/// blocks `first..first + count` and returns the new t_max (smaller on a closer hit), or
/// `None` to stop the traversal (any hit).
pub(super) trait BlockTest {
    fn leaf(&mut self, first: u32, count: u32, t_max: f32) -> Option<f32>;
}

/// Stack traversal of the wide BVH. The leaf children of a node are tested as soon as the node
/// test finds them, nearest first with `ORDERED`, before its inner children. With `ORDERED`
/// (closest hit) the inner children that still start before the (possibly reduced) `t_max`
/// are visited nearest first, and stack entries that start beyond `t_max` are skipped; without
/// it (any hit) the order is arbitrary.
#[inline(always)]
pub(super) fn traverse<const ORDERED: bool>(
    bvh: &WideBvh,
    origin: Vec3,
    dir: Vec3,
    mut t_max: f32,
    leaves: &mut impl BlockTest,
) {
    let nodes = &bvh.nodes[..];
    if nodes.is_empty() {
        return;
    }
    let r = NodeRay::new(origin, dir);
    let mut stack = [const { MaybeUninit::<Key>::uninit() }; STACK_SIZE];
    let mut sp = 0usize;
    let mut cull = cull_key(t_max);
    let mut cur = 0u32; // the root
    let mut tmin = [0.0f32; WIDTH];
    macro_rules! push {
        ($k:expr) => {{
            debug_assert!(sp < STACK_SIZE);
            // SAFETY: at most 7 entries are pushed per level, and the build makes no tree
            // deeper than MAX_DEPTH − 1 (and checks it).
            unsafe { stack.get_unchecked_mut(sp).write($k) };
            sp += 1;
        }};
    }
    'nodes: loop {
        // SAFETY: inner child references are valid node indices (node 0 exists).
        let node = unsafe { nodes.get_unchecked(cur as usize) };
        let mut mask = node_test(node, &r, t_max, &mut tmin);
        let mut leaf_mask = 0;
        let mut inner_mask = 0;
        while mask != 0 {
            let k = mask.trailing_zeros();
            if node.child[k as usize] & LEAF != 0 {
                leaf_mask |= 1 << k;
            } else {
                inner_mask |= 1 << k;
            }
            mask &= mask - 1;
        }
        if leaf_mask != 0 {
            let t0 = t_max;
            while leaf_mask != 0 {
                let k = if ORDERED && leaf_mask & (leaf_mask - 1) != 0 {
                    nearest(&tmin, leaf_mask)
                } else {
                    leaf_mask.trailing_zeros()
                };
                leaf_mask &= !(1 << k);
                if ORDERED && tmin[k as usize] > t_max * FAR_SCALE {
                    continue;
                }
                let c = node.child[k as usize];
                let (first, count) = (
                    c & (MAX_BLOCKS as u32 - 1),
                    ((c & !LEAF) >> COUNT_SHIFT) + 1,
                );
                match leaves.leaf(first, count, t_max) {
                    Some(t) => t_max = t,
                    None => return,
                }
            }
            if ORDERED && t_max != t0 {
                cull = cull_key(t_max);
                inner_mask &= le_mask(&tmin, t_max);
            }
        }
        let mut mask = inner_mask;
        if mask != 0 {
            let key = |k: u32| node_key(tmin[k as usize], node.child[k as usize]);
            if !ORDERED {
                cur = node.child[mask.trailing_zeros() as usize];
                mask &= mask - 1;
                while mask != 0 {
                    push!(node.child[mask.trailing_zeros() as usize] as Key);
                    mask &= mask - 1;
                }
                continue;
            }
            let c0 = key(mask.trailing_zeros());
            mask &= mask - 1;
            if mask == 0 {
                cur = c0 as u32;
                continue;
            }
            let c1 = key(mask.trailing_zeros());
            mask &= mask - 1;
            let (near, far) = (c0.min(c1), c0.max(c1));
            if mask == 0 {
                push!(far);
                cur = near as u32;
                continue;
            }
            // Three or more: push all, sorted by decreasing key (the nearest on top), and
            // continue with the nearest.
            let first = sp;
            push!(far);
            push!(near);
            while mask != 0 {
                let x = key(mask.trailing_zeros());
                mask &= mask - 1;
                debug_assert!(sp < STACK_SIZE);
                // SAFETY: entries first..sp were just written; j stays in first..=sp, and sp
                // stays below STACK_SIZE (see `push!`).
                unsafe {
                    let mut j = sp;
                    while j > first && stack.get_unchecked(j - 1).assume_init() < x {
                        let v = stack.get_unchecked(j - 1).assume_init();
                        stack.get_unchecked_mut(j).write(v);
                        j -= 1;
                    }
                    stack.get_unchecked_mut(j).write(x);
                }
                sp += 1;
            }
            sp -= 1;
            // SAFETY: sp < STACK_SIZE and the entry was written above.
            cur = unsafe { stack.get_unchecked(sp).assume_init() } as u32;
            continue;
        }
        // Pop the next entry that can still hold a closer hit.
        while sp > 0 {
            sp -= 1;
            // SAFETY: entries below the old sp were written.
            let k = unsafe { stack.get_unchecked(sp).assume_init() };
            if !ORDERED || k <= cull {
                cur = k as u32;
                continue 'nodes;
            }
        }
        return;
    }
}

/// The slot of `mask` (two or more bits) with the smallest entry distance.
#[inline(always)]
fn nearest(tmin: &[f32; WIDTH], mut mask: u32) -> u32 {
    let mut best = mask.trailing_zeros();
    mask &= mask - 1;
    while mask != 0 {
        let k = mask.trailing_zeros();
        if tmin[k as usize] < tmin[best as usize] {
            best = k;
        }
        mask &= mask - 1;
    }
    best
}

#[cfg(test)]
mod tests;
