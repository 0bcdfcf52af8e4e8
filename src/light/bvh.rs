//! A bounding volume hierarchy over the lights at a finite position, for choosing one light per
//! shading point in proportion to an estimate of what it sends there (many-light sampling of
//! Conty Estevez & Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree
//! Splitting", without the splitting; the scheme of pbrt-v4's BVH light sampler, with up to
//! eight children per node).
//!
//! Leaves are single emitters: a point, spot or goniometric light, or ONE primitive of an area
//! light (so a luminous ceiling made of one object with many primitives is sampled by where
//! its primitives are, not as a whole). Each node keeps the [`LightBounds`] of its children: a
//! box (m), a power φ (lm: π L A × sides for an area primitive of luminance L (cd/m²) and area
//! A (m²), 4π × peak intensity (cd) for point-like sources) and the cones of their emitters'
//! axes and spread.
//!
//! Sampling walks from the root: at each node its (up to eight) children's importances for the
//! receiver at p with normal n ([`LightBounds::importance`], φ × bounded emitter cosine ×
//! bounded receiver |cos| / clamped squared distance) are computed together
//! ([`Bounds8::importance`]), a child is chosen in proportion, and the sample number is
//! rescaled for the next level. The probability of a leaf is the product of the choices;
//! [`LightBvh::pmf`] recomputes it by following the leaf's trail from the root (three bits per
//! level: the child taken), with the same arithmetic as [`LightBvh::sample`], so it is exactly
//! the probability the sample reported. The bounds are conservative, so a light that can send
//! light to p never has probability zero.
//!
//! The tree is built top-down as a binary tree, splitting each node in two by the surface
//! area–orientation heuristic over 12 buckets of the centroids along each axis (below depth
//! [`MEDIAN_DEPTH`] at the median instead), then collapsed to up to eight children per node: a
//! node's children are its binary descendants some levels down, as many levels as keep them
//! at most eight (three for a full subtree; a leaf is kept as it is). Eight importances cost
//! about as much as one when computed side by side, and the walk is a third as deep (a scene
//! with at most eight emitters has one node: each emitter is chosen by its own importance).

use super::bounds::{Bounds8, LightBounds, NodeBounds, WIDTH};
use glam::Vec3;

/// Depth below which nodes are split at the median (count), so the binary tree is at most
/// `MEDIAN_DEPTH` + 32 levels deep for up to 2³² leaves, and the 8-wide one at most a third of
/// that (each of its levels spans at least three binary ones): its trails (3 bits per level)
/// fit in 64 bits.
const MEDIAN_DEPTH: u32 = 30;
const BUCKETS: usize = 12;
/// The largest f32 below 1, for rescaled sample numbers.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// One emitter: light index, primitive id (area lights; 0 for others) and its bounds.
#[derive(Clone, Copy, Debug)]
pub struct Emitter {
    pub light: u32,
    pub prim: u32,
    pub bounds: LightBounds,
}

/// A node of the binary tree the build makes before collapsing it.
#[derive(Clone, Debug)]
struct Node {
    bounds: NodeBounds,
    /// Interior: index of the second child (the first follows the node). Leaf: emitter index.
    index: u32,
    leaf: bool,
}

/// A node of the 8-wide tree: its children's bounds side by side and what each child is.
#[derive(Clone, Debug)]
struct Node8 {
    bounds: Bounds8,
    /// Per child: the index of a node (interior child) or of an emitter (leaf child).
    child: [u32; WIDTH],
    /// Bit i: child i is a leaf.
    leaves: u8,
    /// Children in use (lanes 0..count).
    count: u8,
}

/// Where an emitter sits in the tree.
#[derive(Clone, Copy, Debug, Default)]
pub struct Trail {
    /// Bits 3k to 3k + 2: the child (0–7) taken at depth k.
    pub bits: u64,
    pub depth: u32,
}

#[derive(Clone, Debug, Default)]
pub struct LightBvh {
    /// The 8-wide tree, root first; empty when there are fewer than two emitters.
    nodes: Vec<Node8>,
    /// With exactly one emitter: its bounds (the tree is empty).
    single: Option<NodeBounds>,
    emitters: Vec<Emitter>,
    trails: Vec<Trail>,
}

impl LightBvh {
    /// The tree over `emitters` (those with φ ≤ 0 or non-finite bounds are left out).
    pub fn build(emitters: Vec<Emitter>) -> Self {
        let emitters: Vec<Emitter> = emitters
            .into_iter()
            .filter(|e| {
                let b = &e.bounds;
                b.phi > 0.0 && b.phi.is_finite() && b.lo.is_finite() && b.hi.is_finite()
            })
            .collect();
        let mut bvh = LightBvh {
            nodes: Vec::new(),
            single: None,
            trails: vec![Trail::default(); emitters.len()],
            emitters,
        };
        match bvh.emitters.len() {
            0 => {}
            1 => bvh.single = Some(NodeBounds::from(&bvh.emitters[0].bounds)),
            n => {
                let mut binary = Vec::with_capacity(2 * n);
                let mut items: Vec<u32> = (0..n as u32).collect();
                bvh.build_node(&mut binary, &mut items, 0);
                bvh.nodes.reserve(n);
                bvh.collapse(&binary, 0, Trail::default());
            }
        }
        bvh
    }

    pub fn is_empty(&self) -> bool {
        self.emitters.is_empty()
    }

    /// The emitters, in the order [`LightBvh::sample`] and [`LightBvh::pmf`] index them.
    pub fn emitters(&self) -> &[Emitter] {
        &self.emitters
    }

    /// Number of (8-wide) nodes and the deepest leaf's depth in them.
    pub fn stats(&self) -> (usize, u32) {
        let depth = self.trails.iter().map(|t| t.depth).max().unwrap_or(0);
        (self.nodes.len(), depth)
    }

    /// The binary tree over `items`, appended to `out`; returns its root's index.
    fn build_node(&self, out: &mut Vec<Node>, items: &mut [u32], depth: u32) -> u32 {
        let at = out.len() as u32;
        if items.len() == 1 {
            let e = items[0];
            out.push(Node {
                bounds: NodeBounds::from(&self.emitters[e as usize].bounds),
                index: e,
                leaf: true,
            });
            return at;
        }
        let bounds = items
            .iter()
            .map(|&e| self.emitters[e as usize].bounds)
            .reduce(|a, b| LightBounds::union(&a, &b))
            .expect("a node has emitters");
        out.push(Node {
            bounds: NodeBounds::from(&bounds),
            index: 0,
            leaf: false,
        });
        let mid = self.split(items, &bounds, depth);
        let (left, right) = items.split_at_mut(mid);
        self.build_node(out, left, depth + 1);
        let second = self.build_node(out, right, depth + 1);
        out[at as usize].index = second;
        at
    }

    /// The 8-wide node for the binary interior node `b`, appended with all its descendants;
    /// returns its index. Its children: `b`'s, each interior one replaced by its own two as
    /// long as that makes at most [`WIDTH`] (all of a level at once, so at least three levels).
    fn collapse(&mut self, binary: &[Node], b: usize, trail: Trail) -> u32 {
        let at = self.nodes.len();
        self.nodes.push(Node8 {
            bounds: Bounds8::default(),
            child: [0; WIDTH],
            leaves: 0,
            count: 0,
        });
        let mut kids: Vec<usize> = vec![b];
        loop {
            let interior = kids.iter().filter(|&&k| !binary[k].leaf).count();
            if interior == 0 || kids.len() + interior > WIDTH {
                break;
            }
            kids = kids
                .iter()
                .flat_map(|&k| {
                    if binary[k].leaf {
                        [Some(k), None]
                    } else {
                        [Some(k + 1), Some(binary[k].index as usize)]
                    }
                })
                .flatten()
                .collect();
        }
        let mut bounds = Bounds8::default();
        let (mut child, mut leaves) = ([0u32; WIDTH], 0u8);
        for (i, &k) in kids.iter().enumerate() {
            bounds.set(i, &binary[k].bounds);
            let t = Trail {
                bits: trail.bits | (i as u64) << (3 * trail.depth),
                depth: trail.depth + 1,
            };
            if binary[k].leaf {
                leaves |= 1 << i;
                child[i] = binary[k].index;
                self.trails[binary[k].index as usize] = t;
            } else {
                child[i] = self.collapse(binary, k, t);
            }
        }
        self.nodes[at] = Node8 {
            bounds,
            child,
            leaves,
            count: kids.len() as u8,
        };
        at as u32
    }

    /// Reorder `items` into two non-empty groups; returns the size of the first.
    fn split(&self, items: &mut [u32], bounds: &LightBounds, depth: u32) -> usize {
        let centroid = |e: u32| self.emitters[e as usize].bounds.centroid();
        let (mut clo, mut chi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for &e in items.iter() {
            clo = clo.min(centroid(e));
            chi = chi.max(centroid(e));
        }
        let extent = chi - clo;
        let median = |items: &mut [u32]| {
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let mid = items.len() / 2;
            items.select_nth_unstable_by(mid, |&a, &b| {
                centroid(a)[axis].total_cmp(&centroid(b)[axis])
            });
            mid
        };
        if depth >= MEDIAN_DEPTH {
            return median(items);
        }
        let diag = (bounds.hi - bounds.lo).max(Vec3::ZERO);
        let max_len = diag.max_element();
        // (axis, first bucket of the second group, cost)
        let mut best: Option<(usize, usize, f32)> = None;
        for axis in 0..3 {
            if extent[axis] <= 0.0 || !extent[axis].is_finite() {
                continue;
            }
            let bucket = |e: u32| {
                let t = (centroid(e)[axis] - clo[axis]) / extent[axis];
                ((t * BUCKETS as f32) as usize).min(BUCKETS - 1)
            };
            let mut bb: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
            for &e in items.iter() {
                let b = &self.emitters[e as usize].bounds;
                let k = bucket(e);
                bb[k] = Some(bb[k].map_or(*b, |x| LightBounds::union(&x, b)));
            }
            let kr = if diag[axis] > 0.0 {
                max_len / diag[axis]
            } else {
                1.0
            };
            let merge = |r: &[Option<LightBounds>]| {
                r.iter()
                    .flatten()
                    .copied()
                    .reduce(|a, b| LightBounds::union(&a, &b))
            };
            for k in 1..BUCKETS {
                let (Some(l), Some(r)) = (merge(&bb[..k]), merge(&bb[k..])) else {
                    continue;
                };
                let cost = l.cost(kr) + r.cost(kr);
                if cost.is_finite() && best.is_none_or(|(_, _, c)| cost < c) {
                    best = Some((axis, k, cost));
                }
            }
        }
        let Some((axis, k, _)) = best else {
            return median(items);
        };
        let side = |e: u32| {
            let t = (centroid(e)[axis] - clo[axis]) / extent[axis];
            ((t * BUCKETS as f32) as usize).min(BUCKETS - 1) < k
        };
        let mut mid = 0;
        for i in 0..items.len() {
            if side(items[i]) {
                items.swap(i, mid);
                mid += 1;
            }
        }
        if mid == 0 || mid == items.len() {
            return median(items);
        }
        mid
    }

    /// The importances of node `at`'s children for a receiver at `p` with normal `n`, and
    /// their sum; where every child's is zero (the node's bounds are looser than its
    /// children's, so it may light p while none of them can) the choice goes by power, so
    /// the probabilities still sum to 1 (the leaves so chosen send nothing to p). None at the
    /// root when no child can light p, or for a non-finite sum.
    #[inline(always)]
    fn weights(&self, at: usize, p: Vec3, n: Option<Vec3>) -> Option<([f32; WIDTH], f32)> {
        let node = &self.nodes[at];
        let total =
            |w: &[f32; WIDTH]| ((w[0] + w[1]) + (w[2] + w[3])) + ((w[4] + w[5]) + (w[6] + w[7]));
        let mut w = node.bounds.importance(p, n);
        let mut sum = total(&w);
        if sum == 0.0 {
            if at == 0 {
                return None;
            }
            w = node.bounds.phi;
            sum = total(&w);
        }
        (sum > 0.0 && sum.is_finite()).then_some((w, sum))
    }

    /// Choose an emitter for a receiver at `p` (m) with unit normal `n` from `u` ∈ [0, 1):
    /// its index into [`LightBvh::emitters`] and its probability; None if no emitter can light
    /// p.
    pub fn sample(&self, p: Vec3, n: Option<Vec3>, u: f32) -> Option<(usize, f32)> {
        if let Some(b) = &self.single {
            return (b.importance(p, n) > 0.0).then_some((0, 1.0));
        }
        if self.nodes.is_empty() {
            return None;
        }
        let mut at = 0usize;
        let mut pmf = 1.0f32;
        let mut u = u;
        loop {
            let (w, sum) = self.weights(at, p, n)?;
            let node = &self.nodes[at];
            // The child whose share of [0, sum) holds u·sum; the last child with a weight
            // takes what rounding leaves beyond the cumulative sum.
            let target = u * sum;
            let mut acc = 0.0f32;
            let mut k = usize::MAX;
            for (i, &wi) in w.iter().enumerate().take(node.count as usize) {
                if wi > 0.0 {
                    k = i;
                    if target < acc + wi {
                        break;
                    }
                    acc += wi;
                }
            }
            if k == usize::MAX {
                return None;
            }
            let wk = w[k];
            pmf *= wk / sum;
            if node.leaves >> k & 1 == 1 {
                return (pmf > 0.0).then_some((node.child[k] as usize, pmf));
            }
            // Only a further level needs the rescaled sample number.
            u = ((target - acc) / wk).clamp(0.0, ONE_MINUS_EPSILON);
            at = node.child[k] as usize;
        }
    }

    /// Probability with which [`LightBvh::sample`] at `p`, `n` chooses emitter `e`.
    pub fn pmf(&self, p: Vec3, n: Option<Vec3>, e: usize) -> f32 {
        let Some(trail) = self.trails.get(e) else {
            return 0.0;
        };
        if let Some(b) = &self.single {
            return if b.importance(p, n) > 0.0 { 1.0 } else { 0.0 };
        }
        let mut at = 0usize;
        let mut pmf = 1.0f32;
        for level in 0..trail.depth {
            let Some((w, sum)) = self.weights(at, p, n) else {
                return 0.0;
            };
            let k = (trail.bits >> (3 * level) & 7) as usize;
            pmf *= w[k] / sum;
            at = self.nodes[at].child[k] as usize;
        }
        debug_assert!(trail.depth > 0);
        pmf
    }
}
