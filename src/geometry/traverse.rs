//! The BVH node walk shared by the closest-hit and any-hit queries: the node test, the
//! traversal stack and the [`LeafTest`] a query plugs its primitive tests into.
//!
//! The loop ([`traverse`]) keeps a distance-ordered stack sized for the depth the build
//! guarantees; the node test ([`node_test`]) clamps the entry to 0, uses exact reciprocal
//! directions and widens the slab distances by a bound on their floating-point error, so no
//! box containing a valid hit is ever culled (obvhs's own CWBVH walk clamps the entry to
//! `1e-4` and replaces tiny direction components, which can cull valid boxes).

use super::bvh::MAX_DEPTH;
use super::wide::{WideBvh, WideNode};
use glam::Vec3;
use std::mem::MaybeUninit;

/// Ray data for the node test.
struct NodeRay {
    inv: [f32; 3],
    /// Per axis, o·(1/d) plus (near) or minus (far) the bound on the slab distances' rounding
    /// error: a slab distance is `plane·inv − off`, one FMA.
    near_off: [f32; 3],
    far_off: [f32; 3],
    /// Index in [`WideNode::planes`] of the near and far plane array per axis, chosen once per
    /// ray from the direction's signs (near = min plane for a positive direction).
    near: [usize; 3],
    far: [usize; 3],
}

/// Bound on |1/d| per axis. With every plane and origin within `MAX_COORDINATE` (10¹²) of the
/// origin, no slab distance or offset overflows f32; a clamped axis (|d| < 10⁻²⁶) only
/// shortens that axis' slab for hits beyond 10¹² m.
const INV_LIMIT: f32 = 1e26;

impl NodeRay {
    /// `bound`: per axis, the largest |plane| of the BVH's child boxes.
    #[inline(always)]
    fn new(o: Vec3, d: Vec3, bound: Vec3) -> Self {
        // 1/±0 = ±∞ is clamped to ±INV_LIMIT (d is finite and non-zero, so no NaN).
        let inv = (Vec3::ONE / d).clamp(Vec3::splat(-INV_LIMIT), Vec3::splat(INV_LIMIT));
        // The computed distance fl(P·inv − fl32(o·inv ± pad)), against the exact (P − o)/d,
        // is off by at most (2|P| + 3|o|)·|inv|·u/(1 − 2u) + 2u·pad (the error of inv, of the
        // FMA and of rounding the offset to f32; o·inv is exact in f64). pad below exceeds
        // it, so near distances are never too large nor far ones too small.
        let g = super::robust::gamma(4) as f64;
        let mut near_off = [0.0; 3];
        let mut far_off = [0.0; 3];
        let mut near = [0; 3];
        let mut far = [0; 3];
        for a in 0..3 {
            let (o, inv_a) = (o[a] as f64, inv[a] as f64);
            let oi = o * inv_a;
            let pad = (2.0 * bound[a] as f64 + 3.0 * o.abs()) * inv_a.abs() * g;
            let m = f32::MAX as f64;
            near_off[a] = (oi + pad).clamp(-m, m) as f32;
            far_off[a] = (oi - pad).clamp(-m, m) as f32;
            // From the reciprocal, so that −0 (reciprocal −∞ → −INV_LIMIT) counts as negative.
            let neg = usize::from(inv[a] < 0.0);
            near[a] = 2 * a + neg;
            far[a] = 2 * a + 1 - neg;
        }
        Self {
            inv: inv.to_array(),
            near_off,
            far_off,
            near,
            far,
        }
    }
}

/// Slab test of the 8 children of `node` against the ray segment [0, t_max]. Returns the
/// mask of hit (non-empty) child slots and every slot's entry distance.
#[inline(always)]
fn node_test(node: &WideNode, r: &NodeRay, t_max: f32, tmin_out: &mut [f32; 8]) -> u32 {
    // AVX2 (all 8 children at once; built with `target-cpu=native` on any recent x86-64).
    #[cfg(all(
        target_arch = "x86_64",
        target_feature = "avx2",
        target_feature = "fma"
    ))]
    // SAFETY: the target features are enabled at compile time; the plane indices are below 6.
    unsafe {
        use std::arch::x86_64::*;
        let slab = |plane: usize, a: usize, off: &[f32; 3]| {
            _mm256_fmsub_ps(
                _mm256_loadu_ps(node.planes.get_unchecked(plane).as_ptr()),
                _mm256_set1_ps(*r.inv.get_unchecked(a)),
                _mm256_set1_ps(*off.get_unchecked(a)),
            )
        };
        let near = |a: usize| slab(*r.near.get_unchecked(a), a, &r.near_off);
        let far = |a: usize| slab(*r.far.get_unchecked(a), a, &r.far_off);
        let tmin = _mm256_max_ps(
            _mm256_max_ps(near(0), near(1)),
            _mm256_max_ps(near(2), _mm256_setzero_ps()),
        );
        let tmax = _mm256_min_ps(
            _mm256_min_ps(far(0), far(1)),
            _mm256_min_ps(far(2), _mm256_set1_ps(t_max)),
        );
        _mm256_storeu_ps(tmin_out.as_mut_ptr(), tmin);
        // Empty slots have inverted boxes: +∞ entry, −∞ exit.
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(tmin, tmax)) as u32
    }

    // Portable form of the same test, one child at a time.
    #[cfg(not(all(
        target_arch = "x86_64",
        target_feature = "avx2",
        target_feature = "fma"
    )))]
    {
        let mut hit_mask = 0u32;
        for k in 0..8 {
            let d =
                |p: usize, a: usize, off: &[f32; 3]| node.planes[p][k].mul_add(r.inv[a], -off[a]);
            let tmin = d(r.near[0], 0, &r.near_off)
                .max(d(r.near[1], 1, &r.near_off))
                .max(d(r.near[2], 2, &r.near_off))
                .max(0.0);
            let tmax = d(r.far[0], 0, &r.far_off)
                .min(d(r.far[1], 1, &r.far_off))
                .min(d(r.far[2], 2, &r.far_off))
                .min(t_max);
            tmin_out[k] = tmin;
            if tmin <= tmax {
                hit_mask |= 1 << k;
            }
        }
        hit_mask
    }
}

/// Traversal stack entries: at most 7 pushes per level below the root.
const STACK_SIZE: usize = 7 * MAX_DEPTH;

/// A traversal stack entry: an inner node, packed into a `u64` as its entry distance's bits
/// (high half) and its node index (low half). Entry distances are non-negative, so their bits
/// order as integers, and entries order by distance with integer compares.
type Key = u64;

/// The key of an inner node entered at distance `dist` (≥ 0). The sign bit is cleared, so that
/// a −0 (which `f32::max(−0, 0)` may return) orders as +0.
#[inline(always)]
fn node_key(dist: f32, idx: u32) -> Key {
    (((dist.to_bits() & 0x7fff_ffff) as u64) << 32) | idx as u64
}

/// The largest key whose entry distance does not exceed `t` (> 0): entries above it cannot
/// hold a hit closer than `t`.
#[inline(always)]
fn cull_key(t: f32) -> Key {
    node_key(t, u32::MAX)
}

/// The slots whose entry distance `tmin` does not exceed `t` (a mask as from [`node_test`]).
#[inline(always)]
fn le_mask(tmin: &[f32; 8], t: f32) -> u32 {
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

/// The primitive tests of a traversal: `leaf(first, unary, t_max)` tests the leaf's primitives
/// `first..` (`unary` = their count n in unary, 2ⁿ − 1, at most 31 bits) and returns the new
/// t_max (smaller on a closer hit), or `None` to stop the traversal (any hit).
pub(super) trait LeafTest {
    fn leaf(&mut self, first: u32, unary: u32, t_max: f32) -> Option<f32>;
    /// Prefetches the data of primitive `first` (any value; nothing is read).
    fn prefetch(&self, first: u32);
}

/// Prefetches the two cache lines at `p` (any address: prefetching never faults).
#[inline(always)]
pub(super) fn prefetch(p: *const u8) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: prefetching has no effect on memory and never faults.
    unsafe {
        use std::arch::x86_64::*;
        _mm_prefetch::<_MM_HINT_T0>(p as *const i8);
        _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64) as *const i8);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

/// BVH traversal with a CPU-style stack of inner nodes ([`Key`]s). The leaf children of a
/// node are tested as soon as the node test finds them, before its inner children. With
/// `ORDERED` (closest hit) the inner children that still start before the (possibly reduced)
/// `t_max` are visited nearest first, and stack entries that start beyond the current `t_max`
/// are skipped; without it (any hit) the order is arbitrary.
#[inline(always)]
pub(super) fn traverse<const ORDERED: bool>(
    bvh: &WideBvh,
    origin: Vec3,
    dir: Vec3,
    mut t_max: f32,
    leaves: &mut impl LeafTest,
) {
    let nodes = &bvh.nodes[..];
    if nodes.is_empty() {
        return;
    }
    let r = NodeRay::new(origin, dir, bvh.plane_bound);
    let mut stack = [const { MaybeUninit::<Key>::uninit() }; STACK_SIZE];
    let mut sp = 0usize;
    let mut cull = cull_key(t_max);
    let mut cur = 0u32; // the root
    let mut tmin = [0.0f32; 8];
    macro_rules! push {
        ($k:expr) => {{
            debug_assert!(sp < STACK_SIZE);
            // SAFETY: at most 7 entries are pushed per level, and the build makes no BVH
            // deeper than MAX_DEPTH − 1 (and checks it).
            unsafe { stack.get_unchecked_mut(sp).write($k) };
            sp += 1;
        }};
    }
    'nodes: loop {
        // SAFETY: inner child indices are valid node indices (node 0 exists).
        let node = unsafe { nodes.get_unchecked(cur as usize) };
        prefetch(nodes.as_ptr().wrapping_add(node.child_base_idx as usize) as *const u8);
        leaves.prefetch(node.primitive_base_idx);
        let mut mask = node_test(node, &r, t_max, &mut tmin);
        let imask = node.imask as u32;
        // The leaf children (an empty slot would decode as a leaf without primitives).
        let mut leaf_mask = mask & !imask;
        if leaf_mask != 0 {
            let t0 = t_max;
            while leaf_mask != 0 {
                let k = leaf_mask.trailing_zeros();
                leaf_mask &= leaf_mask - 1;
                // A leaf that starts beyond a hit found in this node's other leaves.
                if ORDERED && tmin[k as usize] > t_max {
                    continue;
                }
                let first = node.primitive_base_idx + node.leaf_offset[k as usize] as u32;
                let unary = (1u32 << node.leaf_count[k as usize]) - 1;
                match leaves.leaf(first, unary, t_max) {
                    Some(t) => t_max = t,
                    None => return,
                }
            }
            if ORDERED && t_max != t0 {
                cull = cull_key(t_max);
                mask &= le_mask(&tmin, t_max);
            }
        }
        // The inner children, stored in slot order from child_base_idx.
        let mut mask = mask & imask;
        if mask != 0 {
            let idx = |k: u32| node.child_base_idx + (imask & ((1u32 << k) - 1)).count_ones();
            let key = |k: u32| node_key(tmin[k as usize], idx(k));
            if !ORDERED {
                cur = idx(mask.trailing_zeros());
                mask &= mask - 1;
                while mask != 0 {
                    push!(idx(mask.trailing_zeros()) as Key);
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
                // is below STACK_SIZE as in `push!`.
                unsafe {
                    let mut j = sp;
                    while j > first && stack.get_unchecked(j - 1).assume_init() < x {
                        let y = stack.get_unchecked(j - 1).assume_init();
                        stack.get_unchecked_mut(j).write(y);
                        j -= 1;
                    }
                    stack.get_unchecked_mut(j).write(x);
                }
                sp += 1;
            }
            sp -= 1;
            // SAFETY: entry sp was written.
            cur = unsafe { stack.get_unchecked(sp).assume_init() } as u32;
            continue;
        }
        // Pop the nearest entry that can still hold a hit.
        while sp != 0 {
            sp -= 1;
            // SAFETY: entries below sp were written.
            let k = unsafe { stack.get_unchecked(sp).assume_init() };
            if !ORDERED || k <= cull {
                cur = k as u32;
                continue 'nodes;
            }
        }
        return;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether the segment [0, t_max] of the ray meets the box, in f64 (exact enough: its
    /// rounding is 10⁹ times below the node test's padding).
    fn meets(o: Vec3, d: Vec3, t_max: f32, lo: [f32; 3], hi: [f32; 3]) -> bool {
        let (mut t0, mut t1) = (0.0f64, t_max as f64);
        for a in 0..3 {
            let (o, d) = (o[a] as f64, d[a] as f64);
            if d == 0.0 {
                if o < lo[a] as f64 || o > hi[a] as f64 {
                    return false;
                }
                continue;
            }
            let (n, f) = ((lo[a] as f64 - o) / d, (hi[a] as f64 - o) / d);
            t0 = t0.max(n.min(f));
            t1 = t1.min(n.max(f));
        }
        t0 <= t1
    }

    #[test]
    fn node_test_never_culls_a_box_the_ray_meets() {
        // Rays aimed at box corners, edges and faces (so many graze them), from near and far,
        // with scenes near the origin and far from it; every box the exact test finds is hit.
        let mut s = 7u64;
        let mut rnd = || crate::sampling::test_uniform(&mut s);
        let (mut exact_hits, mut misses) = (0, 0);
        for case in 0..20_000 {
            let scale = [1.0f32, 1e3, 1e6][case % 3];
            let centre = Vec3::splat([0.0f32, 5e4, -3e7][case % 5 % 3]);
            let mut node = WideNode {
                leaf_count: [1; 8],
                ..WideNode::EMPTY
            };
            let mut bound = Vec3::ZERO;
            for k in 0..8 {
                let c = centre + (Vec3::new(rnd(), rnd(), rnd()) - 0.5) * scale;
                let h = Vec3::new(rnd(), rnd(), rnd()) * scale * 0.1 * rnd();
                let (lo, hi) = (c - h, c + h);
                for a in 0..3 {
                    node.planes[2 * a][k] = lo[a];
                    node.planes[2 * a + 1][k] = hi[a];
                }
                bound = bound.max(lo.abs()).max(hi.abs());
            }
            // Aim at a corner, edge point or face point of box 0 .. 7.
            let k = case % 8;
            let mut corner = |a: usize| node.planes[2 * a + (rnd() < 0.5) as usize][k];
            let mut target = Vec3::new(corner(0), corner(1), corner(2));
            let free = case % 4; // 3: a corner; else move along one axis within the box
            if free < 3 {
                let (lo, hi) = (node.planes[2 * free][k], node.planes[2 * free + 1][k]);
                target[free] = lo + (hi - lo) * rnd();
            }
            let o =
                target + (Vec3::new(rnd(), rnd(), rnd()) - 0.5) * scale * [0.01f32, 3.0][case % 2];
            let mut d = target - o;
            if case % 7 == 0 {
                d[case % 3] *= 1e-30; // nearly axis-parallel
            }
            if d == Vec3::ZERO || !d.is_finite() {
                continue;
            }
            let t_max = [f32::INFINITY, 1.0, 0.5][case % 3];
            let r = NodeRay::new(o, d, bound);
            let mut tmin = [0.0f32; 8];
            let mask = node_test(&node, &r, t_max, &mut tmin);
            for j in 0..8 {
                let lo = [node.planes[0][j], node.planes[2][j], node.planes[4][j]];
                let hi = [node.planes[1][j], node.planes[3][j], node.planes[5][j]];
                if meets(o, d, t_max, lo, hi) {
                    exact_hits += 1;
                    assert!(
                        mask & (1 << j) != 0,
                        "case {case}: box {j} {lo:?}..{hi:?} culled for o {o} d {d} t_max {t_max}"
                    );
                } else {
                    misses += 1;
                }
            }
        }
        assert!(
            exact_hits > 10_000 && misses > 10_000,
            "{exact_hits} {misses}"
        );
    }

    #[test]
    fn empty_slots_are_never_hit() {
        let node = WideNode::EMPTY;
        for d in [
            Vec3::X,
            -Vec3::ONE,
            Vec3::new(1e-30, -1.0, 0.0),
            Vec3::new(0.0, 0.0, -3.0),
        ] {
            let r = NodeRay::new(Vec3::new(1.0, -2.0, 3.0), d, Vec3::splat(10.0));
            assert_eq!(node_test(&node, &r, f32::INFINITY, &mut [0.0; 8]), 0, "{d}");
        }
    }
}
