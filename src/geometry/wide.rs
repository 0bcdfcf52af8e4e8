//! The BVH's nodes as the traversal reads them: 8 children per node with float child boxes,
//! collapsed from the binary tree the builders make.
//!
//! The collapse chooses, by a surface-area cost, which binary subtrees become a node's 8
//! child slots and which of those are leaves of up to `max_leaf` primitives (Ylitie et al.
//! 2017, "Efficient incoherent ray traversal on GPUs through compressed wide BVHs", §3.1: a
//! dynamic programme over slot counts). Float planes let the slab test be one FMA per plane
//! with the per-ray offsets held in registers.

use super::pages::HugeArray;
use glam::Vec3;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;

/// One node: its 8 child boxes, plane arrays in the order min x, max x, min y, max y, min z,
/// max z (metres, world or object space), then the children's addresses. Empty child slots
/// have inverted boxes (min +∞, max −∞), which every slab test misses.
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug)]
pub(super) struct WideNode {
    pub planes: [[f32; 8]; 6],
    /// Index of the first inner child; the others follow in slot order.
    pub child_base_idx: u32,
    /// Index of the first primitive of the node's leaf children (in leaf order).
    pub primitive_base_idx: u32,
    /// Per leaf slot: its first primitive, from `primitive_base_idx`.
    pub leaf_offset: [u8; 8],
    /// Per leaf slot: its primitive count (0 for inner and empty slots).
    pub leaf_count: [u8; 8],
    /// Bit k set: slot k is an inner node.
    pub imask: u8,
}

impl WideNode {
    /// A node whose 8 slots are all empty.
    pub const EMPTY: WideNode = WideNode {
        planes: [
            [f32::INFINITY; 8],
            [f32::NEG_INFINITY; 8],
            [f32::INFINITY; 8],
            [f32::NEG_INFINITY; 8],
            [f32::INFINITY; 8],
            [f32::NEG_INFINITY; 8],
        ],
        child_base_idx: 0,
        primitive_base_idx: 0,
        leaf_offset: [0; 8],
        leaf_count: [0; 8],
        imask: 0,
    };
}

/// A BVH of [`WideNode`]s (node 0 the root; empty for an empty scene).
#[derive(Default)]
pub(super) struct WideBvh {
    pub nodes: HugeArray<WideNode>,
    /// Per axis, the largest |plane| of any child box (m): bounds the rounding error of the
    /// slab distances (see `traverse::NodeRay`).
    pub plane_bound: Vec3,
}

/// Most primitives in one leaf slot (the offsets of a node's 8 leaves fit a byte).
pub(super) const MAX_LEAF: u32 = 31;

/// Surface-area cost of testing one primitive, against 1 for visiting a node. Lower than
/// obvhs's 0.3 (whose trees this collapse reproduces at leaves of at most 3): node visits are
/// the traversal's dependent memory reads, while a leaf's triangles are contiguous.
const PRIM_COST: f32 = 0.2;

fn half_area(b: &Aabb) -> f32 {
    let d = b.max - b.min;
    d.x * d.y + d.y * d.z + d.z * d.x
}

/// The collapse's per-binary-node choices (10 bytes per binary node; the costs live only on
/// a stack while the subtree above them is open, so the build's peak memory grows little).
struct Plan<'a> {
    bvh2: &'a Bvh2,
    /// For i + 1 slots: 0 = one slot (the node itself), k = k slots to the left child.
    split: Vec<[u8; 8]>,
    /// As a slot of its own: a leaf (else an inner node).
    leaf: Vec<bool>,
    /// As an inner node: the slots given to the left child (of 8).
    inner_split: Vec<u8>,
}

/// A finished subtree: its cost as at most i + 1 slots, and its primitive count (saturated:
/// only compared with a leaf limit of at most [`MAX_LEAF`]).
type Costs = ([f32; 8], u32);

impl<'a> Plan<'a> {
    fn new(bvh2: &'a Bvh2, max_leaf: u32) -> Self {
        let n = bvh2.nodes.len();
        let mut p = Plan {
            bvh2,
            split: vec![[0; 8]; n],
            leaf: vec![false; n],
            inner_split: vec![0; n],
        };
        // Children before their parent, without recursion. The right child is pushed last,
        // so it finishes first: at its parent, the left child's costs are on top.
        let mut stack = vec![(0u32, false)];
        let mut done: Vec<Costs> = Vec::new();
        while let Some((i, expanded)) = stack.pop() {
            let node = &bvh2.nodes[i as usize];
            if node.prim_count == 0 && !expanded {
                stack.push((i, true));
                stack.push((node.first_index, false));
                stack.push((node.first_index + 1, false));
                continue;
            }
            let c = if node.prim_count == 0 {
                let l = done.pop().expect("left child finished");
                let r = done.pop().expect("right child finished");
                p.fill(i as usize, &l, &r, max_leaf)
            } else {
                let area = half_area(node.aabb());
                p.leaf[i as usize] = true;
                (
                    [area * node.prim_count as f32 * PRIM_COST; 8],
                    node.prim_count,
                )
            };
            done.push(c);
        }
        p
    }

    /// The choices of inner binary node `i` from its children's costs; its own costs.
    fn fill(&mut self, i: usize, l: &Costs, r: &Costs, max_leaf: u32) -> Costs {
        let area = half_area(self.bvh2.nodes[i].aabb());
        let prims = l.1.saturating_add(r.1);
        // dist[j]: the best cost of both children in j + 1 slots together (j ≥ 1).
        let mut dist = [(f32::INFINITY, 0u8); 8];
        for (j, d) in dist.iter_mut().enumerate().skip(1) {
            for k in 1..=j {
                let c = l.0[k - 1] + r.0[j - k];
                if c < d.0 {
                    *d = (c, k as u8);
                }
            }
        }
        let inner = area + dist[7].0;
        let as_leaf = if prims <= max_leaf {
            area * prims as f32 * PRIM_COST
        } else {
            f32::INFINITY
        };
        self.leaf[i] = as_leaf <= inner;
        self.inner_split[i] = dist[7].1;
        let one = as_leaf.min(inner);
        let mut cost = [one; 8];
        for (j, &d) in dist.iter().enumerate().skip(1) {
            (cost[j], self.split[i][j]) = if d.0 < one { d } else { (one, 0) };
        }
        (cost, prims)
    }

    /// The slot roots of the wide node standing for binary node `b`.
    fn roots(&self, b: u32, out: &mut Vec<u32>) {
        out.clear();
        let node = &self.bvh2.nodes[b as usize];
        if node.prim_count != 0 {
            out.push(b);
        } else {
            let k = self.inner_split[b as usize] as usize;
            self.slots(node.first_index, k, out);
            self.slots(node.first_index + 1, 8 - k, out);
        }
    }

    /// The number of wide nodes the collapse makes (sizes their array before it is filled).
    fn node_count(&self) -> usize {
        let (mut count, mut work, mut roots) = (0, vec![0u32], Vec::with_capacity(8));
        while let Some(b) = work.pop() {
            count += 1;
            self.roots(b, &mut roots);
            work.extend(roots.iter().filter(|&&m| !self.leaf[m as usize]));
        }
        count
    }

    /// The slot roots of binary node `i` given `slots` slots.
    fn slots(&self, i: u32, slots: usize, out: &mut Vec<u32>) {
        let k = self.split[i as usize][slots - 1] as usize;
        if k == 0 {
            out.push(i);
        } else {
            let l = self.bvh2.nodes[i as usize].first_index;
            self.slots(l, k, out);
            self.slots(l + 1, slots - k, out);
        }
    }

    /// The primitives under binary node `i`, in order.
    fn leaf_prims(&self, i: u32, out: &mut Vec<u32>) {
        let node = &self.bvh2.nodes[i as usize];
        if node.prim_count != 0 {
            let f = node.first_index as usize;
            out.extend_from_slice(&self.bvh2.primitive_indices[f..f + node.prim_count as usize]);
        } else {
            self.leaf_prims(node.first_index, out);
            self.leaf_prims(node.first_index + 1, out);
        }
    }
}

impl WideBvh {
    /// The wide tree of `bvh2` (not empty) with leaves of at most `max_leaf` primitives
    /// (≤ [`MAX_LEAF`]; a binary leaf is never split), and the input primitive indices in leaf
    /// order (leaf primitive ids index it). Every child box is its binary node's box, which
    /// holds the node's primitives.
    pub fn from_bvh2(bvh2: &Bvh2, max_leaf: u32) -> (Self, Vec<u32>) {
        let max_leaf = max_leaf.clamp(1, MAX_LEAF);
        let plan = Plan::new(bvh2, max_leaf);
        let empty = WideNode::EMPTY;
        let count = plan.node_count();
        let mut nodes = HugeArray::collect(count, std::iter::repeat_n(empty, count));
        let mut next = 1;
        let mut order = Vec::with_capacity(bvh2.primitive_indices.len());
        let mut bound = Vec3::ZERO;
        // (wide node to fill, binary node it stands for)
        let mut work = vec![(0usize, 0u32)];
        let mut roots = Vec::with_capacity(8);
        while let Some((w, b)) = work.pop() {
            plan.roots(b, &mut roots);
            let mut out = empty;
            out.child_base_idx = next as u32;
            out.primitive_base_idx = order.len() as u32;
            for (k, &m) in roots.iter().enumerate() {
                let bb = bvh2.nodes[m as usize].aabb();
                for a in 0..3 {
                    out.planes[2 * a][k] = bb.min[a];
                    out.planes[2 * a + 1][k] = bb.max[a];
                }
                bound = bound
                    .max(Vec3::from(bb.min).abs())
                    .max(Vec3::from(bb.max).abs());
                if plan.leaf[m as usize] {
                    let first = order.len();
                    plan.leaf_prims(m, &mut order);
                    out.leaf_offset[k] = (first - out.primitive_base_idx as usize) as u8;
                    out.leaf_count[k] = (order.len() - first) as u8;
                } else {
                    out.imask |= 1 << k;
                }
            }
            for (k, &m) in roots.iter().enumerate() {
                if out.imask & (1 << k) != 0 {
                    work.push((next, m));
                    next += 1;
                }
            }
            nodes[w] = out;
        }
        debug_assert_eq!(next, nodes.len());
        (
            WideBvh {
                nodes,
                plane_bound: bound,
            },
            order,
        )
    }

    /// Number of node levels (1 for a single root node; 0 if empty).
    pub fn depth(&self) -> u32 {
        if self.nodes.is_empty() {
            return 0;
        }
        let mut max = 0;
        let mut stack = vec![(0u32, 1u32)];
        while let Some((n, d)) = stack.pop() {
            max = max.max(d);
            let node = &self.nodes[n as usize];
            for k in 0..node.imask.count_ones() {
                stack.push((node.child_base_idx + k, d + 1));
            }
        }
        max
    }

    /// Heap bytes of the nodes.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.memory_bytes()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_is_four_cache_lines() {
        assert_eq!(std::mem::size_of::<WideNode>(), 256);
        assert_eq!(std::mem::align_of::<WideNode>(), 64);
    }

    /// Boxes of varied sizes round random points, some far from the origin.
    fn boxes(n: usize) -> Vec<Aabb> {
        let mut s = 1u64;
        let mut rnd = || crate::sampling::test_uniform(&mut s);
        (0..n)
            .map(|i| {
                let off = if i % 3 == 0 { 1e5 } else { 0.0 };
                let c = Vec3::new(rnd(), rnd(), rnd()) * 50.0 + Vec3::splat(off);
                let h = Vec3::new(rnd(), rnd(), rnd()) * 0.3 * rnd();
                Aabb::new((c - h).into(), (c + h).into())
            })
            .collect()
    }

    /// The primitive ids (leaf order) below slot `k` of node `n`.
    fn below(bvh: &WideBvh, n: usize, k: usize, out: &mut Vec<u32>) {
        let node = &bvh.nodes[n];
        if node.imask & (1 << k) != 0 {
            let child = node.child_base_idx + (node.imask as u32 & ((1 << k) - 1)).count_ones();
            for j in 0..8 {
                below(bvh, child as usize, j, out);
            }
        } else {
            let first = node.primitive_base_idx + node.leaf_offset[k] as u32;
            out.extend(first..first + node.leaf_count[k] as u32);
        }
    }

    #[test]
    fn every_primitive_is_in_one_leaf_inside_every_box_above_it() {
        for (n, max_leaf) in [
            (1, 6),
            (2, 1),
            (9, 3),
            (3000, 1),
            (3000, 4),
            (3000, 6),
            (20_000, 8),
        ] {
            let aabbs = boxes(n);
            let (bvh, order) = super::super::bvh::build_wide(&aabbs, max_leaf);
            // `order` is a permutation of the input.
            let mut seen = vec![false; n];
            for &i in &order {
                assert!(!std::mem::replace(&mut seen[i as usize], true));
            }
            assert!(seen.iter().all(|&s| s), "n {n}");
            let mut leaves = 0;
            for i in 0..bvh.nodes.len() {
                let node = &bvh.nodes[i];
                for k in 0..8 {
                    let p = &node.planes;
                    let inner = node.imask & (1 << k) != 0;
                    if !inner && node.leaf_count[k] == 0 {
                        // Empty slot: inverted box.
                        assert!(p[0][k] == f32::INFINITY && p[1][k] == f32::NEG_INFINITY);
                        continue;
                    }
                    if !inner {
                        assert!(node.leaf_count[k] as u32 <= max_leaf);
                        leaves += node.leaf_count[k] as usize;
                    }
                    let mut prims = Vec::new();
                    below(&bvh, i, k, &mut prims);
                    assert!(!prims.is_empty());
                    for id in prims {
                        let b = &aabbs[order[id as usize] as usize];
                        for a in 0..3 {
                            assert!(p[2 * a][k] <= b.min[a] && p[2 * a + 1][k] >= b.max[a]);
                            assert!(p[2 * a][k].abs() <= bvh.plane_bound[a]);
                            assert!(p[2 * a + 1][k].abs() <= bvh.plane_bound[a]);
                        }
                    }
                }
            }
            assert_eq!(leaves, n, "each primitive in exactly one leaf");
            assert!(bvh.depth() >= 1 && (bvh.depth() as usize) < super::super::bvh::MAX_DEPTH);
        }
    }

    #[test]
    fn bigger_leaves_make_fewer_nodes() {
        // The cost model trades node visits for primitive tests: allowing bigger leaves never
        // adds nodes, and on many small boxes it removes some.
        let aabbs = boxes(20_000);
        let counts: Vec<usize> = [1, 3, 6]
            .iter()
            .map(|&l| super::super::bvh::build_wide(&aabbs, l).0.nodes.len())
            .collect();
        assert!(
            counts[0] >= counts[1] && counts[1] > counts[2],
            "{counts:?}"
        );
    }
}
