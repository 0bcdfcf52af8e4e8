//! obvhs's PLOC builder (`PlocBuilder::build` with a search distance of 14, 64-bit Morton codes
//! and a search distance of 1 for the first 3 passes: `BvhBuildParams::medium_build()`), step for
//! step and on obvhs's own types, so that it gives the same BVH2 node for node, with one
//! addition: it gives up once it has done more passes or more work than a reasonable input needs.
//!
//! PLOC merges, in each pass, the pairs of clusters that are each other's nearest neighbour (by
//! the area of their union) among the 14 either side in Morton order. Where the nearest
//! neighbours form long one-way chains (identical boxes, whose ties always point the same way;
//! fans of slivers round a vertex or rim, whose boxes grow steadily along the Morton order), a
//! pass merges only a pair or two per chain, so the passes number O(n), the time O(n²) and the
//! tree is a chain O(n) deep. obvhs runs its passes to the end and cannot be stopped from
//! outside, hence this copy; the unit test below checks it against obvhs itself.

use obvhs::aabb::Aabb;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::bvh2::{Bvh2, DEFAULT_MAX_STACK_DEPTH};
use obvhs::ploc::morton::morton_encode_u64_unorm;
use rayon::prelude::*;

const SEARCH_DISTANCE: usize = 14;
/// Passes below this use a search distance of 1.
const SEARCH_DEPTH_THRESHOLD: usize = 3;

/// Most passes allowed: ordinary inputs need a few dozen (each pass merges a large fraction of
/// the clusters), so this is only reached by inputs with chains of nearest neighbours.
const MAX_PASSES: usize = 192;
/// A pass over this many clusters or more that merges fewer than 1 in [`MIN_MERGE_RATIO`] of
/// them gives up: ordinary inputs merge 1 in 5 to 1 in 9 per pass, chains 1 in 30 or fewer.
const CHECK_MERGES_FROM: usize = 4096;
const MIN_MERGE_RATIO: usize = 32;
/// Most clusters visited over all passes: per primitive (ordinary inputs visit about 3), plus
/// a few thousand so that small inputs with a short chain or two keep PLOC's tree.
const MAX_WORK_PER_PRIM: usize = 8;
const WORK_SLACK: usize = 4096;

/// Same layout as obvhs's 64-bit Morton key, so that the (unstable) sort orders equal codes the
/// same way.
#[derive(Clone, Copy)]
#[repr(C)]
struct Morton64 {
    code: u64,
    index: u64,
}

/// The BVH2 obvhs's `PlocBuilder::build` gives for `aabbs` (primitive indices 0..n), or `None`
/// if a large pass merges too few clusters, or it would take more than [`MAX_PASSES`] passes or
/// visit more than [`MAX_WORK_PER_PRIM`] clusters per primitive in all.
pub(super) fn build(aabbs: &[Aabb]) -> Option<Bvh2> {
    let n = aabbs.len();
    let mut bvh = Bvh2 {
        nodes: vec![Bvh2Node::default(); (2 * n).saturating_sub(1)],
        primitive_indices: (0..n as u32).collect(),
        ..Bvh2::default()
    };
    if n == 0 {
        return Some(bvh);
    }
    let mut current: Vec<Bvh2Node> = aabbs
        .iter()
        .enumerate()
        .map(|(i, a)| Bvh2Node::new(*a, 1, i as u32))
        .collect();
    let mut total = Aabb::empty();
    for a in aabbs {
        total = total.union(a);
    }

    // Sort by the Morton code of the box centres.
    let scale = 1.0 / total.diagonal().as_dvec3();
    let offset = -total.min.as_dvec3() * scale;
    let code = |i: usize, node: &Bvh2Node| Morton64 {
        code: morton_encode_u64_unorm(node.aabb().center().as_dvec3() * scale + offset),
        index: i as u64,
    };
    let mut mortons: Vec<Morton64> = if n > 100_000 {
        current
            .par_iter()
            .enumerate()
            .map(|(i, c)| code(i, c))
            .collect()
    } else {
        current
            .iter()
            .enumerate()
            .map(|(i, c)| code(i, c))
            .collect()
    };
    mortons.par_sort_unstable_by_key(|m| m.code);
    let mut next: Vec<Bvh2Node> = mortons.iter().map(|m| current[m.index as usize]).collect();
    drop(mortons);
    std::mem::swap(&mut current, &mut next);

    let mut merge = vec![0i8; n];
    let mut insert = bvh.nodes.len();
    let mut pass = 0usize;
    let mut count = n;
    let mut work = 0usize;
    let cost = |a: &Bvh2Node, b: &Bvh2Node| a.aabb().union(b.aabb()).half_area();
    while count > 1 {
        work += count;
        if pass >= MAX_PASSES || work > MAX_WORK_PER_PRIM * n + WORK_SLACK {
            return None;
        }
        let nodes = &current[..count];
        let merge = &mut merge[..count];
        if pass < SEARCH_DEPTH_THRESHOLD {
            // Each cluster pairs with the cheaper of its two neighbours (the next one on a tie).
            let pair: Vec<f32> = (0..count - 1)
                .into_par_iter()
                .with_min_len(4096)
                .map(|i| cost(&nodes[i], &nodes[i + 1]))
                .collect();
            let mut last = f32::INFINITY;
            for (m, &c) in merge.iter_mut().zip(&pair) {
                *m = if last < c { -1 } else { 1 };
                last = c;
            }
            merge[count - 1] = -1;
        } else {
            // The cheapest within SEARCH_DISTANCE either side; on a tie the furthest on.
            merge
                .par_iter_mut()
                .with_min_len(1024)
                .enumerate()
                .for_each(|(i, m)| {
                    let lo = i.saturating_sub(SEARCH_DISTANCE);
                    let hi = (i + SEARCH_DISTANCE + 1).min(count);
                    let mut best = i;
                    let mut best_cost = f32::INFINITY;
                    for j in (lo..hi).filter(|&j| j != i) {
                        let c = cost(&nodes[i], &nodes[j]);
                        if c <= best_cost {
                            best = j;
                            best_cost = c;
                        }
                    }
                    *m = (best as i64 - i as i64) as i8;
                });
        }
        // Merge the pairs that chose each other; keep the rest for the next pass.
        let mut kept = 0;
        for i in 0..count {
            let best = (i as i64 + merge[i] as i64) as usize;
            if best as i64 + merge[best] as i64 != i as i64 {
                next[kept] = current[i];
                kept += 1;
                continue;
            }
            if best > i {
                continue;
            }
            let (left, right) = (current[i], current[best]);
            insert -= 2;
            bvh.nodes[insert] = left;
            bvh.nodes[insert + 1] = right;
            next[kept] = Bvh2Node::new(left.aabb().union(right.aabb()), 0, insert as u32);
            kept += 1;
        }
        if count >= CHECK_MERGES_FROM && (count - kept) * MIN_MERGE_RATIO < count {
            return None;
        }
        std::mem::swap(&mut current, &mut next);
        count = kept;
        pass += 1;
    }
    debug_assert_eq!(insert, 1);
    bvh.nodes[0] = current[0];
    bvh.max_depth = DEFAULT_MAX_STACK_DEPTH.max(pass + 1);
    bvh.children_are_ordered_after_parents = true;
    Some(bvh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3A;

    fn same_as_obvhs(aabbs: &[Aabb]) {
        let p = obvhs::BvhBuildParams::medium_build();
        let theirs = obvhs::ploc::PlocBuilder::with_capacity(aabbs.len()).build(
            p.ploc_search_distance,
            aabbs,
            (0..aabbs.len() as u32).collect(),
            p.sort_precision,
            p.search_depth_threshold,
        );
        let ours = build(aabbs).expect("an ordinary input");
        assert_eq!(ours.nodes.len(), theirs.nodes.len());
        for (i, (a, b)) in ours.nodes.iter().zip(&theirs.nodes).enumerate() {
            assert!(
                a.aabb == b.aabb && a.prim_count == b.prim_count && a.first_index == b.first_index,
                "node {i} of {}: {a:?} vs obvhs {b:?}",
                aabbs.len()
            );
        }
        assert_eq!(ours.primitive_indices, theirs.primitive_indices);
        assert_eq!(ours.max_depth, theirs.max_depth);
    }

    /// Boxes of varied sizes round random points, a few of them repeated.
    fn random_boxes(n: usize, seed: u64) -> Vec<Aabb> {
        let mut s = seed;
        let mut r = move || crate::sampling::test_uniform(&mut s);
        let mut v: Vec<Aabb> = (0..n)
            .map(|_| {
                let c = Vec3A::new(r(), r(), r()) * 100.0;
                let h = Vec3A::new(r(), r(), r()) * r().powi(4) * 5.0 + 1e-3;
                Aabb::new(c - h, c + h)
            })
            .collect();
        for i in (0..n).step_by(97) {
            v[i] = v[i / 2];
        }
        v
    }

    /// The node arrays equal obvhs's, in the sizes where obvhs switches to its parallel code
    /// paths (4 000 clusters for the search, 100 000 for the Morton codes, 300 000 for the
    /// first passes).
    #[test]
    fn same_tree_as_obvhs() {
        for (n, seed) in [
            (1, 1),
            (2, 2),
            (3, 3),
            (40, 4),
            (3_000, 5),
            (20_000, 6),
            (310_000, 7),
        ] {
            same_as_obvhs(&random_boxes(n, seed));
        }
    }

    /// Identical boxes make a chain of nearest neighbours: the build gives up.
    #[test]
    fn gives_up_on_chains() {
        let a = Aabb::new(Vec3A::ZERO, Vec3A::ONE);
        assert!(build(&vec![a; 5_000]).is_none());
        assert!(build(&vec![a; 50]).is_some());
        assert!(build(&vec![a; MAX_PASSES + 1]).is_none());
    }
}
