//! A top-down BVH2 builder for the inputs PLOC handles badly: SAH splits (binned, 32 or 8 bins
//! per axis; a full sweep for 16 primitives or fewer) where they keep the tree within its height
//! budget, and otherwise (or where all centres coincide) a split of the range in two halves: by
//! centre along the widest axis (ties by index), or as it stands where the centres coincide.
//! Any n primitives thus give a tree within the height asked for (if it is at least
//! 1 + ⌈log₂ n⌉), in O(n log n) time for ordinary splits and O(n · height) at worst. Primitives
//! are moved with their boxes, so each pass over a range reads memory in order; large ranges
//! are binned, and their halves built, in parallel. The nodes are laid out as obvhs's BVH2
//! expects: root first, siblings in pairs starting at odd indices.

use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::bvh2::Bvh2;
use rayon::prelude::*;

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

const EMPTY_BIN: Bin = Bin {
    bounds: Aabb {
        min: Vec3A::splat(f32::MAX),
        max: Vec3A::splat(f32::MIN),
    },
    count: 0,
};

/// A primitive's box and index.
#[derive(Clone, Copy)]
struct Rec {
    aabb: Aabb,
    index: u32,
}

impl Rec {
    /// Twice the box centre (the factor cancels in the binning).
    #[inline(always)]
    fn centre2(&self) -> Vec3A {
        self.aabb.min + self.aabb.max
    }
}

/// A BVH2 over `aabbs` (one primitive per leaf, primitive indices into `aabbs`) at most
/// `max_height` levels tall; `max_height` must be at least [`balanced_height`]`(aabbs.len())`.
pub(super) fn build(aabbs: &[Aabb], max_height: u32) -> Bvh2 {
    let n = aabbs.len();
    assert!(max_height >= balanced_height(n));
    let mut recs: Vec<Rec> = aabbs
        .iter()
        .enumerate()
        .map(|(i, a)| Rec {
            aabb: *a,
            index: i as u32,
        })
        .collect();
    let mut nodes = vec![Bvh2Node::default(); (2 * n).saturating_sub(1)];
    if n > 0 {
        let (root, below) = nodes.split_at_mut(1);
        root[0] = subtree(&mut recs, 0, below, 1, max_height);
    }
    Bvh2 {
        nodes,
        primitive_indices: recs.iter().map(|r| r.index).collect(),
        max_depth: obvhs::bvh2::DEFAULT_MAX_STACK_DEPTH.max(max_height as usize + 1),
        ..Bvh2::default()
    }
}

/// Ranges at least this large build their two halves in parallel.
const PARALLEL_MIN: usize = 8192;
/// Ranges at least this large are binned in parallel.
const PARALLEL_BINNING_MIN: usize = 65536;

/// Builds the subtree over `range` (primitives `first`.. of the final order) within `height`
/// levels and returns its root. Its other 2m − 2 nodes go to `below`, which starts at node
/// index `base`: the root's two children first (a sibling pair), then the left child's
/// subtree, then the right child's.
fn subtree(
    range: &mut [Rec],
    first: usize,
    below: &mut [Bvh2Node],
    base: usize,
    height: u32,
) -> Bvh2Node {
    let m = range.len();
    debug_assert_eq!(below.len(), 2 * m - 2);
    if m == 1 {
        return Bvh2Node::new(range[0].aabb, 1, first as u32);
    }
    let k = split(range, height);
    let (left, right) = range.split_at_mut(k);
    let (pair, rest) = below.split_at_mut(2);
    let (below_left, below_right) = rest.split_at_mut(2 * k - 2);
    let (base_left, base_right) = (base + 2, base + 2 + 2 * k - 2);
    let h = height - 1;
    let (l, r) = if m >= PARALLEL_MIN {
        rayon::join(
            || subtree(left, first, below_left, base_left, h),
            || subtree(right, first + k, below_right, base_right, h),
        )
    } else {
        (
            subtree(left, first, below_left, base_left, h),
            subtree(right, first + k, below_right, base_right, h),
        )
    };
    pair[0] = l;
    pair[1] = r;
    Bvh2Node::new(l.aabb().union(r.aabb()), 0, base as u32)
}

/// Bounds of (twice) the centres of `range`.
fn centre_bounds(range: &[Rec]) -> Aabb {
    let fold = |c: &[Rec]| {
        let mut b = Aabb::empty();
        for r in c {
            b.extend(r.centre2());
        }
        b
    };
    if range.len() >= PARALLEL_BINNING_MIN {
        range
            .par_chunks(PARALLEL_BINNING_MIN / 4)
            .map(fold)
            .reduce(Aabb::empty, |a, b| a.union(&b))
    } else {
        fold(range)
    }
}

/// Reorders `range` (≥ 2 primitives) and returns the size of its first part: the best binned
/// SAH split if both parts fit in `height` − 1 levels, else the two halves.
fn split(range: &mut [Rec], height: u32) -> usize {
    let m = range.len();
    let fits = |k: usize| balanced_height(k.max(m - k)) < height;
    if m == 2 {
        return 1;
    }
    if m <= SMALL {
        if let Some(k) = split_small(range, fits) {
            return k;
        }
    }
    let cbounds = centre_bounds(range);
    let binned = if m <= 256 {
        split_binned::<8>(range, &cbounds, fits)
    } else {
        split_binned::<BINS>(range, &cbounds, fits)
    };
    if let Some(k) = binned {
        return k;
    }
    let extent = cbounds.diagonal();
    // Halves: by centre along the widest axis (ties by index), or as they stand.
    let axis = cbounds.largest_axis();
    let half = m / 2;
    if extent[axis] > 0.0 {
        range.select_nth_unstable_by(half, |a, b| {
            let (ca, cb) = (a.centre2()[axis], b.centre2()[axis]);
            ca.total_cmp(&cb).then(a.index.cmp(&b.index))
        });
    }
    half
}

/// The best SAH split of `range` over `B` bins per axis (of its centres' bounds `cbounds`) among
/// those that `fits`, or `None` if there is none.
fn split_binned<const B: usize>(
    range: &mut [Rec],
    cbounds: &Aabb,
    fits: impl Fn(usize) -> bool,
) -> Option<usize> {
    let m = range.len();
    let extent = cbounds.diagonal();
    // Bins per axis along the centres' extent (none on an axis where they all coincide).
    let scale: [f32; 3] = std::array::from_fn(|axis| {
        let s = B as f32 / extent[axis];
        if extent[axis] > 0.0 && s.is_finite() {
            s
        } else {
            0.0
        }
    });
    let (min, scale_v) = (cbounds.min, Vec3A::from_array(scale));
    let bins_of = |r: &Rec| {
        let b = ((r.centre2() - min) * scale_v).to_array();
        b.map(|b| (b as usize).min(B - 1))
    };
    let fill = |c: &[Rec]| {
        let mut bins = [[EMPTY_BIN; B]; 3];
        for r in c {
            for (axis, b) in bins_of(r).into_iter().enumerate() {
                let bin = &mut bins[axis][b];
                bin.bounds = bin.bounds.union(&r.aabb);
                bin.count += 1;
            }
        }
        bins
    };
    let bins = if m >= PARALLEL_BINNING_MIN {
        range.par_chunks(PARALLEL_BINNING_MIN / 4).map(fill).reduce(
            || [[EMPTY_BIN; B]; 3],
            |mut a, b| {
                for (a, b) in a.iter_mut().flatten().zip(b.iter().flatten()) {
                    a.bounds = a.bounds.union(&b.bounds);
                    a.count += b.count;
                }
                a
            },
        )
    } else {
        fill(range)
    };
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, last bin of the first part)
    for (axis, bins) in bins.iter().enumerate() {
        if scale[axis] == 0.0 {
            continue;
        }
        // Areas and counts of the parts right of each plane, then a sweep from the left.
        let mut right = [(0.0f32, 0usize); B];
        let mut acc = Aabb::empty();
        let mut count = 0;
        for b in (1..B).rev() {
            acc = acc.union(&bins[b].bounds);
            count += bins[b].count;
            right[b] = (acc.half_area(), count);
        }
        let mut acc = Aabb::empty();
        let mut count = 0;
        for b in 0..B - 1 {
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
    let (_, axis, last) = best?;
    Some(partition(range, |r| bins_of(r)[axis] <= last))
}

/// Ranges this small are split by a full SAH sweep instead of bins (whose setup would cost more
/// than the range).
const SMALL: usize = 16;

/// The SAH split of a small `range` over the planes between its centres sorted along each axis
/// (ties by index), among the splits that `fits`; `None` if all centres coincide on every axis.
fn split_small(range: &mut [Rec], fits: impl Fn(usize) -> bool) -> Option<usize> {
    let m = range.len();
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, size of the first part)
    let mut right = [0.0f32; SMALL];
    for axis in 0..3 {
        sort_small(range, axis);
        if range[0].centre2()[axis] == range[m - 1].centre2()[axis] {
            continue;
        }
        let mut acc = Aabb::empty();
        for k in (1..m).rev() {
            acc = acc.union(&range[k].aabb);
            right[k] = acc.half_area();
        }
        let mut acc = Aabb::empty();
        for k in 1..m {
            acc = acc.union(&range[k - 1].aabb);
            if !fits(k) {
                continue;
            }
            let cost = acc.half_area() * k as f32 + right[k] * (m - k) as f32;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, k));
            }
        }
    }
    let (_, axis, k) = best?;
    sort_small(range, axis);
    Some(k)
}

/// Sorts a small range by centre along `axis`, ties by index.
fn sort_small(range: &mut [Rec], axis: usize) {
    range.sort_unstable_by(|a, b| {
        let (ca, cb) = (a.centre2()[axis], b.centre2()[axis]);
        ca.total_cmp(&cb).then(a.index.cmp(&b.index))
    });
}

/// Moves the elements for which `first` holds to the front; returns their number.
fn partition(range: &mut [Rec], first: impl Fn(&Rec) -> bool) -> usize {
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

    /// Random boxes, enough for the parallel binning and subtrees.
    #[test]
    fn random_boxes() {
        let mut s = 1u64;
        let mut r = move || crate::sampling::test_uniform(&mut s);
        let aabbs: Vec<Aabb> = (0..200_000)
            .map(|_| {
                let c = Vec3A::new(r(), r(), r()) * 100.0;
                let h = Vec3A::new(r(), r(), r()) * r().powi(4) * 5.0;
                Aabb::new(c - h, c + h)
            })
            .collect();
        check(&aabbs, 63);
        check(&aabbs, balanced_height(aabbs.len()));
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
