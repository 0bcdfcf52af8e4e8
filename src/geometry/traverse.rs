//! The CWBVH node walk shared by the closest-hit and any-hit queries: the node test, the
//! traversal stack and the [`LeafTest`] a query plugs its primitive tests into.
//!
//! obvhs's own `CwBvhNode::intersect_ray` clamps the box entry distance to a hard-coded
//! `1e-4` and ignores `ray.tmin`, which silently culls every node lying entirely closer than
//! 0.1 mm to the ray origin (and every node for rays shorter than 0.1 mm); it also replaces
//! direction components below `f32::EPSILON` by ±1/ε, which can cull valid boxes for nearly
//! axis-parallel rays; and its traversal stack (32 entries) is not bounds-checked in release
//! builds. We therefore keep obvhs as the builder and node layout but traverse its nodes with
//! our own loop ([`traverse`]: a distance-ordered stack sized for the depth the build
//! guarantees) and our own node test ([`node_test`]): entry clamped to 0, exact reciprocal
//! directions, and per-node conservative padding of the slab distances by their
//! floating-point error bound, so no box containing a valid hit is ever culled.

use super::bvh::MAX_DEPTH;
use super::robust::gamma;
use glam::{Vec3, Vec3A};
use obvhs::cwbvh::node::CwBvhNode;
use std::mem::{offset_of, MaybeUninit};

/// Ray data for the node test.
struct NodeRay {
    o: Vec3A,
    inv: Vec3A,
    /// gamma(7)·|inv|: the rounding-error bound of the slab distances per unit of |p−o| + 255e.
    g7_inv_abs: Vec3A,
    /// Byte offsets in a [`CwBvhNode`] of the near and far plane arrays per axis, chosen once
    /// per ray from the direction's signs (near = min plane for a positive direction).
    near: [usize; 3],
    far: [usize; 3],
}

const INV_LIMIT: f32 = 1e30;

impl NodeRay {
    #[inline(always)]
    fn new(o: Vec3, d: Vec3) -> Self {
        // 1/±0 = ±∞ is clamped to ±INV_LIMIT (d is finite and non-zero, so no NaN).
        let inv =
            (Vec3A::ONE / Vec3A::from(d)).clamp(Vec3A::splat(-INV_LIMIT), Vec3A::splat(INV_LIMIT));
        // From the reciprocal, so that −0 (reciprocal −∞ → −INV_LIMIT) counts as negative.
        // The min and max plane arrays of axis a are at MIN_X + 16a and MIN_X + 16a + 8.
        let neg = inv.cmplt(Vec3A::ZERO).bitmask() as usize;
        const MIN_X: usize = offset_of!(CwBvhNode, child_min_x);
        const _: () = assert!(
            offset_of!(CwBvhNode, child_max_x) == MIN_X + 8
                && offset_of!(CwBvhNode, child_min_y) == MIN_X + 16
                && offset_of!(CwBvhNode, child_max_y) == MIN_X + 24
                && offset_of!(CwBvhNode, child_min_z) == MIN_X + 32
                && offset_of!(CwBvhNode, child_max_z) == MIN_X + 40
        );
        let near = |a: usize| MIN_X + 16 * a + 8 * ((neg >> a) & 1);
        let far = |a: usize| near(a) ^ 8;
        Self {
            o: o.into(),
            inv,
            g7_inv_abs: gamma(7) * inv.abs(),
            near: [near(0), near(1), near(2)],
            far: [far(0), far(1), far(2)],
        }
    }
}

// The node test loads p and the e bytes as one 16-byte vector.
const _: () = assert!(offset_of!(CwBvhNode, p) == 0 && offset_of!(CwBvhNode, e) == 12);

/// The 8 plane bytes at byte offset `off` of `node`.
#[inline(always)]
fn planes(node: &CwBvhNode, off: usize) -> &[u8; 8] {
    debug_assert!(off + 8 <= std::mem::size_of::<CwBvhNode>());
    // SAFETY: `off` is the offset of one of the node's six `[u8; 8]` plane arrays.
    unsafe { &*((node as *const CwBvhNode as *const u8).add(off) as *const [u8; 8]) }
}

/// Slab test of the 8 children of `node` against the ray segment [0, t_max]. Returns the
/// mask of hit (non-empty) child slots and every slot's entry distance. The plane distances
/// are computed as `q·(e/d) + (p−o)/d` (q = quantized plane) and widened by a bound on their
/// rounding error, so the test is conservative.
#[inline(always)]
fn node_test(node: &CwBvhNode, r: &NodeRay, t_max: f32, tmin_out: &mut [f32; 8]) -> u32 {
    // AVX2 (all 8 children at once; built with `target-cpu=native` on any recent x86-64).
    // FMA rounds once where mul + add rounded twice, so the padding stays conservative.
    #[cfg(all(
        target_arch = "x86_64",
        target_feature = "avx2",
        target_feature = "fma"
    ))]
    // SAFETY: the target features are enabled at compile time; loads stay within the node.
    unsafe {
        use std::arch::x86_64::*;
        let np = node as *const CwBvhNode as *const u8;
        // p in lanes 0–2 of both 128-bit halves (lane 3 holds the e bytes and imask), the
        // extent 2^(e−127) per axis from the e bytes, and the ray data likewise duplicated:
        // every per-axis value is then one in-lane permute away from a full broadcast.
        let p = _mm256_broadcast_ps(&*(np as *const __m128));
        // The e bytes and imask (bytes 12–15), broadcast from memory, one byte per lane.
        let e4 = _mm256_set1_epi32((np.add(12) as *const i32).read_unaligned());
        let e_bytes = _mm256_setr_epi8(
            0, -128, -128, -128, 1, -128, -128, -128, 2, -128, -128, -128, 3, -128, -128, -128, 0,
            -128, -128, -128, 1, -128, -128, -128, 2, -128, -128, -128, 3, -128, -128, -128,
        );
        let e = _mm256_castsi256_ps(_mm256_slli_epi32::<23>(_mm256_shuffle_epi8(e4, e_bytes)));
        let dup = |v: &Vec3A| _mm256_broadcast_ps(&*(v as *const Vec3A as *const __m128));
        let (o, inv, g7_inv) = (dup(&r.o), dup(&r.inv), dup(&r.g7_inv_abs));
        let rel = _mm256_sub_ps(p, o);
        let base = _mm256_mul_ps(rel, inv);
        let scale = _mm256_mul_ps(e, inv);
        let rel_abs = _mm256_andnot_ps(_mm256_set1_ps(-0.0), rel);
        let pad = _mm256_mul_ps(_mm256_fmadd_ps(e, _mm256_set1_ps(255.0), rel_abs), g7_inv);
        let near = _mm256_sub_ps(base, pad);
        let far = _mm256_add_ps(base, pad);
        let lane = |v: __m256, a: usize| -> __m256 {
            match a {
                0 => _mm256_permute_ps::<0b00_00_00_00>(v),
                1 => _mm256_permute_ps::<0b01_01_01_01>(v),
                _ => _mm256_permute_ps::<0b10_10_10_10>(v),
            }
        };
        let q8 = |off: usize| {
            _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_loadl_epi64(
                planes(node, off).as_ptr() as *const __m128i,
            )))
        };
        let slab = |a: usize| {
            let s = lane(scale, a);
            (
                _mm256_fmadd_ps(q8(r.near[a]), s, lane(near, a)),
                _mm256_fmadd_ps(q8(r.far[a]), s, lane(far, a)),
            )
        };
        let (tnx, tfx) = slab(0);
        let (tny, tfy) = slab(1);
        let (tnz, tfz) = slab(2);
        let tmin = _mm256_max_ps(
            _mm256_max_ps(tnx, tny),
            _mm256_max_ps(tnz, _mm256_setzero_ps()),
        );
        let tmax = _mm256_min_ps(
            _mm256_min_ps(tfx, tfy),
            _mm256_min_ps(tfz, _mm256_set1_ps(t_max)),
        );
        _mm256_storeu_ps(tmin_out.as_mut_ptr(), tmin);
        // Empty slots have inverted boxes (see `SceneGeometry::build`), and should one still
        // pass it decodes as an empty leaf.
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(tmin, tmax)) as u32
    }

    // Portable form of the same test, one child at a time.
    #[cfg(not(all(
        target_arch = "x86_64",
        target_feature = "avx2",
        target_feature = "fma"
    )))]
    {
        let e = node.compute_extent();
        let rel = Vec3A::from(node.p) - r.o;
        let scale = e * r.inv;
        let base = rel * r.inv;
        let pad = (rel.abs() + 255.0 * e) * r.g7_inv_abs;
        let base_near = base - pad;
        let base_far = base + pad;
        let (nx, ny, nz) = (
            planes(node, r.near[0]),
            planes(node, r.near[1]),
            planes(node, r.near[2]),
        );
        let (fx, fy, fz) = (
            planes(node, r.far[0]),
            planes(node, r.far[1]),
            planes(node, r.far[2]),
        );
        let mut hit_mask = 0u32;
        for k in 0..8 {
            let tmin = (nx[k] as f32 * scale.x + base_near.x)
                .max(ny[k] as f32 * scale.y + base_near.y)
                .max(nz[k] as f32 * scale.z + base_near.z)
                .max(0.0);
            let tmax = (fx[k] as f32 * scale.x + base_far.x)
                .min(fy[k] as f32 * scale.y + base_far.y)
                .min(fz[k] as f32 * scale.z + base_far.z)
                .min(t_max);
            tmin_out[k] = tmin;
            if tmin <= tmax && node.child_meta[k] & 0x20 != 0 {
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
/// `first..` (`unary` = their count in unary: 1, 3 or 7, or 0 for none) and returns the new
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

/// CWBVH traversal with a CPU-style stack of inner nodes ([`Key`]s). The leaf children of a
/// node are tested as soon as the node test finds them, before its inner children. With
/// `ORDERED` (closest hit) the inner children that still start before the (possibly reduced)
/// `t_max` are visited nearest first, and stack entries that start beyond the current `t_max`
/// are skipped; without it (any hit) the order is arbitrary.
#[inline(always)]
pub(super) fn traverse<const ORDERED: bool>(
    nodes: &[CwBvhNode],
    origin: Vec3,
    dir: Vec3,
    mut t_max: f32,
    leaves: &mut impl LeafTest,
) {
    if nodes.is_empty() {
        return;
    }
    let r = NodeRay::new(origin, dir);
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
                let meta = node.child_meta[k as usize] as u32;
                let first = node.primitive_base_idx + (meta & 0x1f);
                match leaves.leaf(first, meta >> 5, t_max) {
                    Some(t) => t_max = t,
                    None => return,
                }
                leaf_mask &= leaf_mask - 1;
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
