//! A bounding volume hierarchy over the lights at a finite position, for choosing one light per
//! shading point in proportion to an estimate of what it sends there (many-light sampling of
//! Conty Estevez & Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree
//! Splitting", without the splitting; the same scheme as pbrt-v4's BVH light sampler).
//!
//! Leaves are single emitters: a point, spot or goniometric light, or ONE primitive of an area
//! light (so a luminous ceiling made of one object with many primitives is sampled by where
//! its primitives are, not as a whole). Each node stores [`LightBounds`]: a box (m), a power φ
//! (lm: π L A × sides for an area primitive of luminance L (cd/m²) and area A (m²), 4π × peak
//! intensity (cd) for point-like sources) and the cones of its emitters' axes and spread.
//!
//! Sampling walks from the root: at each node both children's importance for the receiver at
//! p with normal n ([`LightBounds::importance`], φ × bounded emitter cosine × bounded receiver
//! |cos| / clamped squared distance) is computed, a child is chosen in proportion, and the
//! sample number is rescaled for the next level. The probability of a leaf is the product of
//! the choices; [`LightBvh::pmf`] recomputes it by following the leaf's bit trail from the
//! root (0 = first child, 1 = second), with the same arithmetic as [`LightBvh::sample`], so it
//! is exactly the probability the sample reported. The bounds are conservative, so a light that
//! can send light to p never has probability zero.
//!
//! The tree is built top-down, splitting each node in two by the surface area–orientation
//! heuristic over 12 buckets of the centroids along each axis; below depth [`MEDIAN_DEPTH`] it
//! splits at the median instead, which keeps every trail within 64 bits.

use super::bounds::{LightBounds, NodeBounds};
use glam::Vec3;

/// Depth below which nodes are split at the median (count), so the tree is at most
/// `MEDIAN_DEPTH` + 32 levels deep for up to 2³² leaves.
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

#[derive(Clone, Debug)]
struct Node {
    bounds: NodeBounds,
    /// Interior: index of the second child (the first follows the node). Leaf: emitter index.
    index: u32,
    leaf: bool,
}

/// Where an emitter sits in the tree.
#[derive(Clone, Copy, Debug, Default)]
pub struct Trail {
    /// Bit k: the branch taken at depth k (0 = first child).
    pub bits: u64,
    pub depth: u32,
}

#[derive(Clone, Debug, Default)]
pub struct LightBvh {
    nodes: Vec<Node>,
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
            nodes: Vec::with_capacity(2 * emitters.len()),
            trails: vec![Trail::default(); emitters.len()],
            emitters,
        };
        if !bvh.emitters.is_empty() {
            let mut items: Vec<u32> = (0..bvh.emitters.len() as u32).collect();
            bvh.build_node(&mut items, Trail::default());
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

    /// Number of nodes and the deepest leaf's depth.
    pub fn stats(&self) -> (usize, u32) {
        let depth = self.trails.iter().map(|t| t.depth).max().unwrap_or(0);
        (self.nodes.len(), depth)
    }

    fn build_node(&mut self, items: &mut [u32], trail: Trail) -> u32 {
        let at = self.nodes.len() as u32;
        if items.len() == 1 {
            let e = items[0];
            self.trails[e as usize] = trail;
            self.nodes.push(Node {
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
        self.nodes.push(Node {
            bounds: NodeBounds::from(&bounds),
            index: 0,
            leaf: false,
        });
        let mid = self.split(items, &bounds, trail.depth);
        let (left, right) = items.split_at_mut(mid);
        self.build_node(
            left,
            Trail {
                bits: trail.bits,
                depth: trail.depth + 1,
            },
        );
        let second = self.build_node(
            right,
            Trail {
                bits: trail.bits | 1u64 << trail.depth,
                depth: trail.depth + 1,
            },
        );
        self.nodes[at as usize].index = second;
        at
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

    /// Probability of the first child at interior node `at` for a receiver at `p` with normal
    /// `n`. The node's own bounds are looser than its children's, so it may light p while
    /// neither child can: the choice then goes by power, so the probabilities still sum to 1
    /// (the leaves so chosen send nothing to p).
    #[inline]
    fn first_probability(&self, at: usize, p: Vec3, n: Option<Vec3>) -> Option<f32> {
        let (a, b) = (
            &self.nodes[at + 1],
            &self.nodes[self.nodes[at].index as usize],
        );
        let (mut i0, mut i1) = (a.bounds.importance(p, n), b.bounds.importance(p, n));
        if i0 + i1 == 0.0 {
            (i0, i1) = (a.bounds.phi, b.bounds.phi);
        }
        let sum = i0 + i1;
        (sum > 0.0 && sum.is_finite()).then(|| i0 / sum)
    }

    fn root_lights(&self, p: Vec3, n: Option<Vec3>) -> bool {
        self.nodes
            .first()
            .is_some_and(|r| r.bounds.importance(p, n) > 0.0)
    }

    /// Choose an emitter for a receiver at `p` (m) with unit normal `n` from `u` ∈ [0, 1):
    /// its index into [`LightBvh::emitters`] and its probability; None if no emitter can light
    /// p.
    pub fn sample(&self, p: Vec3, n: Option<Vec3>, mut u: f32) -> Option<(usize, f32)> {
        if !self.root_lights(p, n) {
            return None;
        }
        let mut at = 0usize;
        let mut pmf = 1.0f32;
        loop {
            let node = &self.nodes[at];
            if node.leaf {
                return (pmf > 0.0).then_some((node.index as usize, pmf));
            }
            let p0 = self.first_probability(at, p, n)?;
            if u < p0 {
                pmf *= p0;
                u = (u / p0).min(ONE_MINUS_EPSILON);
                at += 1;
            } else {
                let p1 = 1.0 - p0;
                pmf *= p1;
                u = ((u - p0) / p1).min(ONE_MINUS_EPSILON);
                at = node.index as usize;
            }
        }
    }

    /// Probability with which [`LightBvh::sample`] at `p`, `n` chooses emitter `e`.
    pub fn pmf(&self, p: Vec3, n: Option<Vec3>, e: usize) -> f32 {
        let Some(trail) = self.trails.get(e) else {
            return 0.0;
        };
        if !self.root_lights(p, n) {
            return 0.0;
        }
        let mut at = 0usize;
        let mut pmf = 1.0f32;
        for k in 0..trail.depth {
            let Some(p0) = self.first_probability(at, p, n) else {
                return 0.0;
            };
            if trail.bits >> k & 1 == 0 {
                pmf *= p0;
                at += 1;
            } else {
                pmf *= 1.0 - p0;
                at = self.nodes[at].index as usize;
            }
        }
        debug_assert!(self.nodes[at].leaf && self.nodes[at].index as usize == e);
        pmf
    }
}
