//! A top-down BVH2 builder for the inputs PLOC handles badly: binned SAH splits where they keep
//! the tree within its height budget, and otherwise (or where all centres coincide) a split of
//! the range in two halves: by centre along the widest axis (ties by index), or as it stands
//! where the centres coincide.
//! Any n primitives thus give a tree within the height asked for (if it is at least
//! 1 + ⌈log₂ n⌉), in O(n log n) time for ordinary splits and O(n · height) at worst. The nodes
//! are laid out as obvhs's BVH2 expects: root first, siblings in pairs starting at odd indices.

use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::bvh2::Bvh2;

const BINS: usize = 32;

/// ⌈log₂ m⌉ for m ≥ 1.
fn ceil_log2(m: usize) -> u32 {
    usize::BITS - (m - 1).leading_zeros()
}

/// Levels a range of `m` primitives needs when halved at every level.
pub(super) fn balanced_height(m: usize) -> u32 {
    1 + ceil_log2(m.max(1))
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: Aabb,
    count: usize,
}

/// A BVH2 over `aabbs` (one primitive per leaf, primitive indices into `aabbs`) at most
/// `max_height` levels tall; `max_height` must be at least [`balanced_height`]`(aabbs.len())`.
pub(super) fn build(aabbs: &[Aabb], max_height: u32) -> Bvh2 {
    let n = aabbs.len();
    assert!(max_height >= balanced_height(n));
    let mut idx: Vec<u32> = (0..n as u32).collect();
    let centres: Vec<Vec3A> = aabbs.iter().map(|a| a.center()).collect();
    let mut nodes = vec![Bvh2Node::default(); (2 * n).saturating_sub(1)];
    if n > 0 {
        let input = Input {
            aabbs,
            centres: &centres,
        };
        let (root, below) = nodes.split_at_mut(1);
        root[0] = input.subtree(&mut idx, 0, below, 1, max_height);
    }
    Bvh2 {
        nodes,
        primitive_indices: idx,
        max_depth: obvhs::bvh2::DEFAULT_MAX_STACK_DEPTH.max(max_height as usize + 1),
        ..Bvh2::default()
    }
}

struct Input<'a> {
    aabbs: &'a [Aabb],
    centres: &'a [Vec3A],
}

/// Ranges at least this large build their two halves in parallel.
const PARALLEL_MIN: usize = 8192;

impl Input<'_> {
    /// Builds the subtree over `range` (primitives `first`.. of the final order) within `height`
    /// levels and returns its root. Its other 2m − 2 nodes go to `below`, which starts at node
    /// index `base`: the root's two children first (a sibling pair), then the left child's
    /// subtree, then the right child's.
    fn subtree(
        &self,
        range: &mut [u32],
        first: usize,
        below: &mut [Bvh2Node],
        base: usize,
        height: u32,
    ) -> Bvh2Node {
        let m = range.len();
        debug_assert_eq!(below.len(), 2 * m - 2);
        if m == 1 {
            return Bvh2Node::new(self.aabbs[range[0] as usize], 1, first as u32);
        }
        let mut cbounds = Aabb::empty();
        for &i in range.iter() {
            cbounds.extend(self.centres[i as usize]);
        }
        let k = split(range, self.aabbs, self.centres, &cbounds, height);
        let (left, right) = range.split_at_mut(k);
        let (pair, rest) = below.split_at_mut(2);
        let (below_left, below_right) = rest.split_at_mut(2 * k - 2);
        let (base_left, base_right) = (base + 2, base + 2 + 2 * k - 2);
        let h = height - 1;
        let (l, r) = if m >= PARALLEL_MIN {
            rayon::join(
                || self.subtree(left, first, below_left, base_left, h),
                || self.subtree(right, first + k, below_right, base_right, h),
            )
        } else {
            (
                self.subtree(left, first, below_left, base_left, h),
                self.subtree(right, first + k, below_right, base_right, h),
            )
        };
        pair[0] = l;
        pair[1] = r;
        Bvh2Node::new(l.aabb().union(r.aabb()), 0, base as u32)
    }
}

/// Reorders `range` (≥ 2 primitives) and returns the size of its first part: the best binned
/// SAH split if both parts fit in `height` − 1 levels, else the two halves.
fn split(
    range: &mut [u32],
    aabbs: &[Aabb],
    centres: &[Vec3A],
    cbounds: &Aabb,
    height: u32,
) -> usize {
    let m = range.len();
    let fits = |k: usize| balanced_height(k.max(m - k)) < height;
    let extent = cbounds.diagonal();
    // Bins per axis along the centres' extent (none on an axis where they all coincide).
    let scale: [f32; 3] = std::array::from_fn(|axis| {
        let s = BINS as f32 / extent[axis];
        if extent[axis] > 0.0 && s.is_finite() {
            s
        } else {
            0.0
        }
    });
    let bin_of = |i: u32, axis: usize| {
        let b = (centres[i as usize][axis] - cbounds.min[axis]) * scale[axis];
        (b as usize).min(BINS - 1)
    };
    let empty = Bin {
        bounds: Aabb::empty(),
        count: 0,
    };
    let mut bins = [[empty; BINS]; 3];
    for &i in range.iter() {
        for (axis, axis_bins) in bins.iter_mut().enumerate() {
            let b = &mut axis_bins[bin_of(i, axis)];
            b.bounds = b.bounds.union(&aabbs[i as usize]);
            b.count += 1;
        }
    }
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, last bin of the first part)
    for (axis, bins) in bins.iter().enumerate() {
        if scale[axis] == 0.0 {
            continue;
        }
        // Areas and counts of the parts right of each plane, then a sweep from the left.
        let mut right = [(0.0f32, 0usize); BINS];
        let mut acc = Aabb::empty();
        let mut count = 0;
        for b in (1..BINS).rev() {
            acc = acc.union(&bins[b].bounds);
            count += bins[b].count;
            right[b] = (acc.half_area(), count);
        }
        let mut acc = Aabb::empty();
        let mut count = 0;
        for b in 0..BINS - 1 {
            acc = acc.union(&bins[b].bounds);
            count += bins[b].count;
            let (right_area, right_count) = right[b + 1];
            if count == 0 || right_count == 0 || !fits(count) {
                continue;
            }
            let cost = acc.half_area() * count as f32 + right_area * right_count as f32;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    if let Some((_, axis, last)) = best {
        return partition(range, |&i| bin_of(i, axis) <= last);
    }
    // Halves: by centre along the widest axis (ties by index), or as it stands.
    let axis = cbounds.largest_axis();
    let half = m / 2;
    if extent[axis] > 0.0 {
        range.select_nth_unstable_by(half, |&a, &b| {
            let (ca, cb) = (centres[a as usize][axis], centres[b as usize][axis]);
            ca.total_cmp(&cb).then(a.cmp(&b))
        });
    }
    half
}

/// Moves the elements for which `first` holds to the front; returns their number.
fn partition(range: &mut [u32], first: impl Fn(&u32) -> bool) -> usize {
    let mut k = 0;
    for j in 0..range.len() {
        if first(&range[j]) {
            range.swap(k, j);
            k += 1;
        }
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;

    fn height(b: &Bvh2) -> u32 {
        let mut max = 0;
        let mut stack = vec![(0usize, 1u32)];
        while let Some((i, d)) = stack.pop() {
            max = max.max(d);
            let node = &b.nodes[i];
            if node.prim_count == 0 {
                stack.push((node.first_index as usize, d + 1));
                stack.push((node.first_index as usize + 1, d + 1));
            }
        }
        max
    }

    /// Each primitive is in exactly one leaf, every node's box holds its children's, and the
    /// height stays within the budget.
    fn check(aabbs: &[Aabb], max_height: u32) {
        let b = build(aabbs, max_height);
        assert_eq!(b.nodes.len(), 2 * aabbs.len() - 1);
        let mut seen = vec![false; aabbs.len()];
        for (i, node) in b.nodes.iter().enumerate() {
            if node.prim_count == 1 {
                let p = b.primitive_indices[node.first_index as usize] as usize;
                assert!(!seen[p]);
                seen[p] = true;
                assert_eq!(node.aabb, aabbs[p]);
            } else {
                let f = node.first_index as usize;
                assert!(f % 2 == 1 && f > i);
                let u = b.nodes[f].aabb.union(&b.nodes[f + 1].aabb);
                assert_eq!(node.aabb, u);
            }
        }
        assert!(seen.iter().all(|&s| s));
        let h = height(&b);
        assert!(h <= max_height, "height {h} > {max_height}");
    }

    #[test]
    fn coincident_boxes_halve_by_index() {
        let a = Aabb::new(Vec3A::ZERO, Vec3A::ONE);
        check(&vec![a; 1000], balanced_height(1000));
    }

    /// Exponentially growing boxes along a line: SAH would peel one at a time; the budget
    /// forces halves once the tree would grow too tall.
    #[test]
    fn height_budget_holds() {
        let aabbs: Vec<Aabb> = (0..3000)
            .map(|i| {
                let s = 1.01f32.powi(i);
                Aabb::new(Vec3A::splat(s), Vec3A::splat(2.0 * s))
            })
            .collect();
        for h in [balanced_height(3000), 15, 20, 64] {
            check(&aabbs, h);
        }
        assert_eq!(balanced_height(1), 1);
        assert_eq!(balanced_height(2), 2);
        assert_eq!(balanced_height(3), 3);
        assert_eq!(balanced_height(4), 3);
        assert_eq!(balanced_height(5), 4);
    }
}
