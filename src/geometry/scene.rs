//! The scene BVH: all primitives in one obvhs CWBVH (8-wide, compressed nodes), laid out in
//! leaf order, with our own traversal node test.
//!
//! obvhs's own `CwBvhNode::intersect_ray` clamps the box entry distance to a hard-coded
//! `1e-4` and ignores `ray.tmin`, which silently culls every node lying entirely closer than
//! 0.1 mm to the ray origin (and every node for rays shorter than 0.1 mm); it also replaces
//! direction components below `f32::EPSILON` by ±1/ε, which can cull valid boxes for nearly
//! axis-parallel rays; and its traversal stack (32 entries) is not bounds-checked in release
//! builds. We therefore keep obvhs as the builder and node layout but traverse its nodes with
//! our own loop ([`traverse`]: a distance-ordered stack whose size the build's depth check
//! bounds) and our own node test ([`node_test`]): entry clamped to 0, exact reciprocal
//! directions, and per-node conservative padding of the slab distances by their
//! floating-point error bound, so no box containing a valid hit is ever culled.

use super::prim::{Prim, PrimT, RayPre};
use super::robust::gamma;
use super::{GeometryError, Hit, Shape, SurfacePoint};
use glam::{Vec2, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::cwbvh::CwBvh;
use obvhs::BvhBuildParams;
use std::mem::{offset_of, MaybeUninit};

/// All primitives of the scene in one BVH.
pub struct SceneGeometry {
    bvh: CwBvh,
    /// Primitives in BVH leaf order; the primitive id is the index into this array. Triangles
    /// are stored inline (their vertices); any other primitive as a marker (NaN first
    /// coordinate, then its index into `others` as the bits of the second vertex's x).
    tris: Vec<[Vec3; 3]>,
    /// The non-triangle primitives.
    others: Vec<Prim>,
    prim_object: Vec<u32>,
    /// Per primitive vertex-normal indices into `normals` (`u32::MAX` = none). Empty when no
    /// primitive has vertex normals.
    prim_normals: Vec<[u32; 3]>,
    normals: Vec<Vec3>,
    /// (object id, primitive ids), sorted by object id.
    object_prims: Vec<(u32, Vec<u32>)>,
    bounds: (Vec3, Vec3),
}

/// A closest hit as [`SceneGeometry::intersect_basic`] returns it: what Embree's
/// `rtcIntersect1` returns (t, u, v, Ng, primID, geomID).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Surface parameters, as [`Hit::uv`] (triangles: barycentrics b1, b2).
    pub u: f32,
    pub v: f32,
    /// Geometric normal of the front face, not normalized (triangles: (v1 − v0) × (v2 − v0)).
    pub ng: Vec3,
    /// Primitive id, as [`Hit::prim`].
    pub prim: u32,
    /// Object id, as [`Hit::object`].
    pub object: u32,
}

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
        // Empty slots have inverted boxes (see `SceneGeometry::build_with_params`), and should
        // one still pass it decodes as an empty leaf.
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

/// Largest distance from the origin (m, per axis) of any primitive's bounds: beyond it the
/// BVH builder's f32 surface-area costs overflow (7 astronomical units: room for a sun).
pub const MAX_COORDINATE: f32 = 1e12;

/// Maximum supported BVH depth.
const MAX_DEPTH: usize = 64;

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
trait LeafTest {
    fn leaf(&mut self, first: u32, unary: u32, t_max: f32) -> Option<f32>;
    /// Prefetches the data of primitive `first` (any value; nothing is read).
    fn prefetch(&self, first: u32);
}

/// Prefetches the two cache lines at `p` (any address: prefetching never faults).
#[inline(always)]
fn prefetch(p: *const u8) {
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
fn traverse<const ORDERED: bool>(
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
            // SAFETY: at most 7 entries are pushed per level and the build rejects BVHs
            // deeper than MAX_DEPTH.
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

/// [`super::prim::intersect_triangle`] with the vertex transform and the edge functions in SIMD (the
/// three vertices in three lanes); every operation and its rounding is the same as in the
/// scalar test, so the results are bit-identical. `v` may also be the marker of a non-triangle
/// primitive (NaN first vertex), which is then tested from `others`.
#[cfg(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    target_feature = "fma"
))]
#[inline(always)]
fn intersect_triangle_simd<const KZ: usize>(
    r: &RayPre,
    t_max: f32,
    v: &[Vec3; 3],
    others: &[Prim],
) -> Option<PrimT> {
    use std::arch::x86_64::*;
    let kx = (KZ + 1) % 3;
    let ky = (KZ + 2) % 3;
    // SAFETY: AVX2 and FMA are enabled at compile time; both 8-float loads stay within the 9
    // floats of `v`.
    unsafe {
        let ptr = v.as_ptr() as *const f32;
        let lo = _mm256_loadu_ps(ptr);
        let hi = _mm256_loadu_ps(ptr.add(1));
        // Coordinate c of the three vertices (floats c, c + 3, c + 6) in lanes 0..3.
        let coord = |c: usize| {
            let (src, b) = if c == 0 { (lo, 0) } else { (hi, c as i32 - 1) };
            _mm256_castps256_ps128(_mm256_permutevar8x32_ps(
                src,
                _mm256_setr_epi32(b, b + 3, b + 6, b + 6, 0, 0, 0, 0),
            ))
        };
        let o = r.o.to_array();
        let z = _mm_sub_ps(coord(KZ), _mm_set1_ps(o[KZ]));
        let x = _mm_add_ps(
            _mm_sub_ps(coord(kx), _mm_set1_ps(o[kx])),
            _mm_mul_ps(_mm_set1_ps(r.sx), z),
        );
        let y = _mm_add_ps(
            _mm_sub_ps(coord(ky), _mm_set1_ps(o[ky])),
            _mm_mul_ps(_mm_set1_ps(r.sy), z),
        );
        // e_i = x_{i+1}·y_{i+2} − y_{i+1}·x_{i+2}: exact f64 products, one rounding in f64
        // (the FMA subtracts an exact product) and one to f32, as `diff_of_products`.
        let xd = _mm256_cvtps_pd(x);
        let yd = _mm256_cvtps_pd(y);
        const NEXT: i32 = 0b11_00_10_01;
        const NEXT2: i32 = 0b11_01_00_10;
        let e = _mm256_cvtpd_ps(_mm256_fmsub_pd(
            _mm256_permute4x64_pd::<NEXT>(xd),
            _mm256_permute4x64_pd::<NEXT2>(yd),
            _mm256_mul_pd(
                _mm256_permute4x64_pd::<NEXT>(yd),
                _mm256_permute4x64_pd::<NEXT2>(xd),
            ),
        ));
        let zero = _mm_setzero_ps();
        let neg = _mm_movemask_ps(_mm_cmplt_ps(e, zero)) & 7;
        let pos = _mm_movemask_ps(_mm_cmpgt_ps(e, zero)) & 7;
        if neg != 0 && pos != 0 {
            return None;
        }
        // A marker for a non-triangle primitive (see `SceneGeometry::tris`) gets here: its first
        // vertex is NaN, so two of its edge functions are NaN and the sign test cannot reject it.
        if v[0].x.is_nan() {
            return others[v[1].x.to_bits() as usize].intersect::<KZ>(r, t_max);
        }
        let mut xa = [0.0f32; 4];
        let mut ya = [0.0f32; 4];
        let mut za = [0.0f32; 4];
        let mut ea = [0.0f32; 4];
        _mm_storeu_ps(xa.as_mut_ptr(), x);
        _mm_storeu_ps(ya.as_mut_ptr(), y);
        _mm_storeu_ps(za.as_mut_ptr(), z);
        _mm_storeu_ps(ea.as_mut_ptr(), e);
        let pt = [0, 1, 2].map(|i| Vec3::new(xa[i], ya[i], za[i]));
        super::prim::triangle_tail(r, t_max, pt, [ea[0], ea[1], ea[2]])
    }
}

/// Depth of a CWBVH (1 for a single root node; 0 if empty).
fn cwbvh_depth(bvh: &CwBvh) -> u32 {
    if bvh.nodes.is_empty() {
        return 0;
    }
    let mut max = 0;
    let mut stack = vec![(0u32, 1u32)];
    while let Some((n, d)) = stack.pop() {
        max = max.max(d);
        let node = &bvh.nodes[n as usize];
        for k in 0..node.imask.count_ones() {
            stack.push((node.child_base_idx + k, d + 1));
        }
    }
    max
}

fn invalid(shape: &Shape, object: u32, message: impl Into<String>) -> GeometryError {
    GeometryError::InvalidShape {
        shape: shape.name(),
        object,
        message: message.into(),
    }
}

fn finite3(v: Vec3) -> bool {
    v.is_finite()
}

impl SceneGeometry {
    /// Builds the BVH over all primitives of `shapes` (already in world space), each tagged
    /// with the caller's object id.
    ///
    /// Triangles with exactly zero area (collinear or repeated vertices) are dropped: they can
    /// never be hit and cannot be sampled. Invalid shapes (non-finite coordinates,
    /// non-positive radius, degenerate quad edges, zero disk normal, mesh indices out of range,
    /// vertex-normal count different from the vertex count) give an error naming the object.
    /// An empty scene is allowed (every ray misses).
    pub fn build(shapes: &[(Shape, u32)]) -> Result<SceneGeometry, GeometryError> {
        Self::build_with_params(shapes, BvhBuildParams::medium_build())
    }

    /// [`SceneGeometry::build`] with explicit obvhs build parameters (spatial pre-splits are
    /// always disabled).
    pub fn build_with_params(
        shapes: &[(Shape, u32)],
        mut params: BvhBuildParams,
    ) -> Result<SceneGeometry, GeometryError> {
        params.pre_split = false;
        let mut prims: Vec<Prim> = Vec::new();
        let mut objects: Vec<u32> = Vec::new();
        let mut prim_normals: Vec<[u32; 3]> = Vec::new();
        let mut normals: Vec<Vec3> = Vec::new();
        let any_normals = shapes
            .iter()
            .any(|(s, _)| matches!(s, Shape::Mesh(m) if m.normals.is_some()));
        let no_n = [u32::MAX; 3];
        for (shape, object) in shapes {
            let object = *object;
            match shape {
                Shape::Sphere { center, radius } => {
                    if !(finite3(*center) && radius.is_finite() && *radius > 0.0) {
                        return Err(invalid(
                            shape,
                            object,
                            format!("center {center} and radius {radius} must be finite with radius > 0"),
                        ));
                    }
                    prims.push(Prim::Sphere {
                        center: *center,
                        radius: *radius,
                    });
                }
                Shape::Quad {
                    origin,
                    edge_u,
                    edge_v,
                } => {
                    let area = edge_u.as_dvec3().cross(edge_v.as_dvec3()).length();
                    if !(finite3(*origin)
                        && finite3(*edge_u)
                        && finite3(*edge_v)
                        && area > 0.0
                        && area.is_finite())
                    {
                        return Err(invalid(
                            shape,
                            object,
                            format!("origin {origin}, edges {edge_u} and {edge_v} must be finite and not parallel (the quad has zero area)"),
                        ));
                    }
                    prims.push(Prim::Quad {
                        origin: *origin,
                        edge_u: *edge_u,
                        edge_v: *edge_v,
                    });
                }
                Shape::Disk {
                    center,
                    normal,
                    radius,
                } => {
                    let n = normal.as_dvec3().normalize_or_zero();
                    if !(finite3(*center) && radius.is_finite() && *radius > 0.0)
                        || n == glam::DVec3::ZERO
                    {
                        return Err(invalid(
                            shape,
                            object,
                            format!("center {center}, normal {normal} and radius {radius} must be finite with radius > 0 and a non-zero normal"),
                        ));
                    }
                    prims.push(Prim::Disk {
                        center: *center,
                        normal: n.as_vec3(),
                        radius: *radius,
                    });
                }
                Shape::Mesh(m) => {
                    if let Some(i) = m.positions.iter().position(|p| !p.is_finite()) {
                        return Err(invalid(
                            shape,
                            object,
                            format!("vertex {i} has a non-finite position {}", m.positions[i]),
                        ));
                    }
                    let nbase = normals.len() as u32;
                    let has_n = match &m.normals {
                        Some(ns) => {
                            if ns.len() != m.positions.len() {
                                return Err(invalid(
                                    shape,
                                    object,
                                    format!(
                                        "it has {} vertex normals for {} vertices",
                                        ns.len(),
                                        m.positions.len()
                                    ),
                                ));
                            }
                            normals.extend(ns.iter().map(|n| n.normalize_or_zero()));
                            true
                        }
                        None => false,
                    };
                    let nv = m.positions.len();
                    for (f, tri) in m.indices.iter().enumerate() {
                        if let Some(&bad) = tri.iter().find(|&&i| i as usize >= nv) {
                            return Err(invalid(
                                shape,
                                object,
                                format!("triangle {f} refers to vertex {bad}, but the mesh has only {nv} vertices"),
                            ));
                        }
                        let v = tri.map(|i| m.positions[i as usize]);
                        let (a, b, c) = (v[0].as_dvec3(), v[1].as_dvec3(), v[2].as_dvec3());
                        if (b - a).cross(c - a).length_squared() == 0.0 {
                            continue; // zero area: dropped
                        }
                        prims.push(Prim::Triangle(v));
                        if any_normals {
                            prim_normals.push(if has_n { tri.map(|i| nbase + i) } else { no_n });
                        }
                        objects.push(object);
                    }
                    continue;
                }
            }
            objects.push(object);
            if any_normals {
                prim_normals.push(no_n);
            }
        }
        if prims.len() >= u32::MAX as usize {
            return Err(GeometryError::InvalidShape {
                shape: "scene",
                object: 0,
                message: "too many primitives (at most 2^32 − 1)".into(),
            });
        }

        let mut lo = Vec3::INFINITY;
        let mut hi = Vec3::NEG_INFINITY;
        let mut aabbs: Vec<Aabb> = Vec::with_capacity(prims.len());
        for (p, &object) in prims.iter().zip(&objects) {
            let (a, b) = p.bounds();
            // The BVH builder's surface-area costs (f32) overflow to inf and NaN for boxes
            // near f32::MAX, which corrupts the build (an out-of-bounds panic in obvhs).
            let reach = a.abs().max(b.abs()).max_element();
            if reach.is_nan() || reach > MAX_COORDINATE {
                return Err(GeometryError::InvalidShape {
                    shape: "primitive",
                    object,
                    message: format!(
                        "it extends to {reach:e} m from the origin; geometry must lie within ±{MAX_COORDINATE:e} m"
                    ),
                });
            }
            lo = lo.min(a);
            hi = hi.max(b);
            // Pad by a few ulps so rounding in bounds/quantization can never exclude the
            // primitive's surface.
            let pad = (a.abs().max(b.abs()) * gamma(4)) + Vec3::splat(f32::MIN_POSITIVE);
            aabbs.push(Aabb::new((a - pad).into(), (b + pad).into()));
        }
        let bounds = if prims.is_empty() {
            (Vec3::ZERO, Vec3::ZERO)
        } else {
            (lo, hi)
        };
        let mut bvh = if prims.is_empty() {
            CwBvh::default()
        } else {
            // Same steps as `obvhs::cwbvh::builder::build_cwbvh`, minus its debug-build
            // validation, which asserts a depth < 32 that degenerate scenes can exceed (we
            // check the depth ourselves below).
            let mut bvh2 = obvhs::ploc::PlocBuilder::with_capacity(aabbs.len()).build(
                params.ploc_search_distance,
                &aabbs,
                (0..aabbs.len() as u32).collect(),
                params.sort_precision,
                params.search_depth_threshold,
            );
            obvhs::bvh2::reinsertion::ReinsertionOptimizer::default().run(
                &mut bvh2,
                params.reinsertion_batch_ratio,
                None,
            );
            obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(
                &bvh2,
                params.max_prims_per_leaf.clamp(1, 3),
                true,
                false,
            )
        };
        bvh.nodes.shrink_to_fit();
        // Empty child slots get inverted boxes (min 255 > max 0) so the node test misses them
        // (it does not check the slot's meta byte).
        for node in &mut bvh.nodes {
            for k in 0..8 {
                if node.child_meta[k] == 0 {
                    node.child_min_x[k] = 255;
                    node.child_min_y[k] = 255;
                    node.child_min_z[k] = 255;
                    node.child_max_x[k] = 0;
                    node.child_max_y[k] = 0;
                    node.child_max_z[k] = 0;
                }
            }
        }
        // Our traversal stack holds MAX_DEPTH entries; refuse a pathological BVH deeper than that.
        let depth = cwbvh_depth(&bvh);
        if depth as usize >= MAX_DEPTH {
            return Err(GeometryError::InvalidShape {
                shape: "scene",
                object: 0,
                message: format!(
                    "the BVH over {} primitives is {depth} levels deep (at most 63 supported); the scene is probably degenerate (e.g. millions of coincident primitives)",
                    prims.len()
                ),
            });
        }
        drop(aabbs);

        // Lay primitives out in leaf order so the traversal indexes them directly.
        let order = &bvh.primitive_indices;
        let mut others = Vec::new();
        let tris: Vec<[Vec3; 3]> = order
            .iter()
            .map(|&i| match prims[i as usize] {
                Prim::Triangle(v) => v,
                p => {
                    others.push(p);
                    let marker = Vec3::new(f32::from_bits((others.len() - 1) as u32), 0.0, 0.0);
                    [Vec3::NAN, marker, Vec3::ZERO]
                }
            })
            .collect();
        drop(prims);
        let prim_object: Vec<u32> = order.iter().map(|&i| objects[i as usize]).collect();
        let prim_normals: Vec<[u32; 3]> = if any_normals {
            order.iter().map(|&i| prim_normals[i as usize]).collect()
        } else {
            Vec::new()
        };
        // Traversal only needs the node array once the primitives are in leaf order.
        bvh.primitive_indices = Vec::new();
        bvh.exact_node_aabbs = None;
        let mut by_obj: Vec<(u32, u32)> = prim_object
            .iter()
            .enumerate()
            .map(|(i, &o)| (o, i as u32))
            .collect();
        by_obj.sort_unstable();
        let mut object_prims: Vec<(u32, Vec<u32>)> = Vec::new();
        for (o, i) in by_obj {
            match object_prims.last_mut() {
                Some((lo, v)) if *lo == o => v.push(i),
                _ => object_prims.push((o, vec![i])),
            }
        }
        Ok(SceneGeometry {
            bvh,
            tris,
            others,
            prim_object,
            prim_normals,
            normals,
            object_prims,
            bounds,
        })
    }

    #[inline(always)]
    fn ray_ok(origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        let (o, d) = (Vec3A::from(origin), Vec3A::from(dir));
        let inf = Vec3A::splat(f32::INFINITY);
        // NaN compares false, so this also rejects NaN components.
        (o.abs().cmplt(inf) & d.abs().cmplt(inf)).all() && d.cmpne(Vec3A::ZERO).any() && t_max > 0.0
    }

    /// Closest hit with `t` in `(0, t_max)` (`t_max` may be `f32::INFINITY`). `dir` need not be
    /// normalized (any finite non-zero vector); `t` is in units of `|dir|`. Returns `None` for
    /// a miss or an invalid ray (non-finite, zero direction).
    ///
    /// This is [`SceneGeometry::intersect_basic`]'s traversal followed by the full hit record
    /// (point, unit normals, shading normal, error bounds).
    pub fn intersect(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        if self.tris.is_empty() || !Self::ray_ok(origin, dir, t_max) {
            return None;
        }
        let pre = RayPre::new(origin, dir);
        let (prim, t, a, b) = self.closest_dyn(&pre, t_max)?;
        Some(self.make_hit(prim, &pre, t, a, b))
    }

    /// The closest hit as Embree's `rtcIntersect1` reports it: `t`, the surface parameters,
    /// the unnormalized geometric normal, and the primitive and object ids. Same hits and
    /// conventions as [`SceneGeometry::intersect`], without building the full [`Hit`].
    pub fn intersect_basic(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<RayHit> {
        if self.tris.is_empty() || !Self::ray_ok(origin, dir, t_max) {
            return None;
        }
        let pre = RayPre::new(origin, dir);
        let (prim, t, u, v) = self.closest_dyn(&pre, t_max)?;
        let tri = &self.tris[prim as usize];
        let ng = if tri[0].x.is_nan() {
            self.prim(prim).normal_at(origin + t * dir)
        } else {
            (tri[1] - tri[0]).cross(tri[2] - tri[0])
        };
        Some(RayHit {
            t,
            u,
            v,
            ng,
            prim,
            object: self.prim_object[prim as usize],
        })
    }

    /// Closest-hit traversal: (primitive, t, a, b) of the closest hit.
    #[inline(always)]
    fn closest_dyn(&self, pre: &RayPre, t_max: f32) -> Option<(u32, f32, f32, f32)> {
        match pre.kz {
            0 => self.closest::<0>(pre, t_max),
            1 => self.closest::<1>(pre, t_max),
            _ => self.closest::<2>(pre, t_max),
        }
    }

    #[inline(always)]
    fn closest<const KZ: usize>(&self, pre: &RayPre, t_max: f32) -> Option<(u32, f32, f32, f32)> {
        struct Closest<'a, const KZ: usize> {
            geo: &'a SceneGeometry,
            pre: &'a RayPre,
            best: (u32, f32, f32, f32),
        }
        impl<const KZ: usize> LeafTest for Closest<'_, KZ> {
            #[inline(always)]
            fn leaf(&mut self, first: u32, unary: u32, mut t_max: f32) -> Option<f32> {
                let (mut id, mut u) = (first, unary);
                while u != 0 {
                    if let Some((t, a, b)) = self.geo.prim_intersect::<KZ>(id, self.pre, t_max) {
                        self.best = (id, t, a, b);
                        t_max = t;
                    }
                    id += 1;
                    u >>= 1;
                }
                Some(t_max)
            }
            #[inline(always)]
            fn prefetch(&self, first: u32) {
                prefetch(self.geo.tris.as_ptr().wrapping_add(first as usize) as *const u8);
            }
        }
        let mut c = Closest::<KZ> {
            geo: self,
            pre,
            best: (u32::MAX, t_max, 0.0, 0.0),
        };
        traverse::<true>(&self.bvh.nodes, pre.o, pre.d, t_max, &mut c);
        (c.best.0 != u32::MAX).then_some(c.best)
    }

    /// Ray test of primitive `id` (a leaf primitive id from the traversal).
    #[inline(always)]
    fn prim_intersect<const KZ: usize>(&self, id: u32, pre: &RayPre, t_max: f32) -> Option<PrimT> {
        debug_assert!((id as usize) < self.tris.len());
        // SAFETY: leaf primitive ids index `tris` (same length as the builder's input).
        let v = unsafe { self.tris.get_unchecked(id as usize) };
        #[cfg(all(
            target_arch = "x86_64",
            target_feature = "avx2",
            target_feature = "fma"
        ))]
        return intersect_triangle_simd::<KZ>(pre, t_max, v, &self.others);
        #[cfg(not(all(
            target_arch = "x86_64",
            target_feature = "avx2",
            target_feature = "fma"
        )))]
        if v[0].x.is_nan() {
            self.others[v[1].x.to_bits() as usize].intersect::<KZ>(pre, t_max)
        } else {
            super::prim::intersect_triangle::<KZ>(pre, t_max, v)
        }
    }

    /// Primitive `id`.
    #[inline]
    fn prim(&self, id: u32) -> Prim {
        let v = &self.tris[id as usize];
        if v[0].x.is_nan() {
            self.others[v[1].x.to_bits() as usize]
        } else {
            Prim::Triangle(*v)
        }
    }

    /// The hit record for primitive `prim` at ray parameter `t` (used after traversal and by
    /// brute-force tests).
    fn make_hit(&self, prim: u32, pre: &RayPre, t: f32, a: f32, b: f32) -> Hit {
        let v = &self.tris[prim as usize];
        let g = if v[0].x.is_nan() {
            self.others[v[1].x.to_bits() as usize].hit_geom(pre, t, a, b)
        } else {
            super::prim::triangle_hit_geom(v, a, b)
        };
        let mut ns = g.ng;
        if let Some(idx) = self.prim_normals.get(prim as usize) {
            if idx[0] != u32::MAX {
                let n = g.bary.x * self.normals[idx[0] as usize]
                    + g.bary.y * self.normals[idx[1] as usize]
                    + g.bary.z * self.normals[idx[2] as usize];
                let n = n.normalize_or_zero();
                if n != Vec3::ZERO {
                    ns = if n.dot(g.ng) < 0.0 { -n } else { n };
                }
            }
        }
        Hit {
            t,
            p: g.p,
            ng: g.ng,
            ns,
            uv: g.uv,
            prim,
            object: self.prim_object[prim as usize],
            front_face: pre.d.dot(g.ng) < 0.0,
            error: g.error,
        }
    }

    /// True if anything is hit with `t` in `(0, t_max)` (any-hit traversal, for shadow rays).
    /// Same ray conventions as [`SceneGeometry::intersect`].
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        if self.tris.is_empty() || !Self::ray_ok(origin, dir, t_max) {
            return false;
        }
        let pre = RayPre::new(origin, dir);
        let block = |_: u32, _: &RayPre, _: PrimT| false;
        match pre.kz {
            0 => self.any_hit::<0>(&pre, t_max, block),
            1 => self.any_hit::<1>(&pre, t_max, block),
            _ => self.any_hit::<2>(&pre, t_max, block),
        }
    }

    /// Any-hit query that lets some objects through: true if a primitive of an object whose
    /// `passes[object]` is false (or out of range) is hit with `t` in `(0, t_max)`. Every
    /// crossing of a primitive of a passing object (a window pane) is handed to `crossed` as a
    /// full [`Hit`], in no particular order, and the traversal goes on; `crossed` returns false
    /// to stop it (the query then reports the ray as blocked). A sphere the ray enters is
    /// crossed twice (in and out, when both are within `t_max`). Same ray conventions as
    /// [`SceneGeometry::occluded`], and as cheap when nothing passing is hit.
    pub fn occluded_except(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        passes: &[bool],
        mut crossed: impl FnMut(&Hit) -> bool,
    ) -> bool {
        if self.tris.is_empty() || !Self::ray_ok(origin, dir, t_max) {
            return false;
        }
        let pre = RayPre::new(origin, dir);
        let mut pass = |prim: u32, pre: &RayPre, (t, a, b): PrimT| {
            let object = self.prim_object[prim as usize] as usize;
            if !passes.get(object).copied().unwrap_or(false) {
                return false;
            }
            let hit = self.make_hit(prim, pre, t, a, b);
            if !crossed(&hit) {
                return false;
            }
            // Entering a sphere (its near root): the way out is a second crossing.
            if let (Prim::Sphere { center, radius }, true) = (self.prim(prim), hit.front_face) {
                let o = hit.spawn_origin(dir);
                let pre = RayPre::new(o, dir);
                let t_left = t_max - (o - origin).dot(dir) / dir.length_squared();
                if let Some((t, _, _)) = super::prim::intersect_sphere(&pre, t_left, center, radius)
                {
                    return crossed(&self.make_hit(prim, &pre, t, 0.0, 0.0));
                }
            }
            true
        };
        match pre.kz {
            0 => self.any_hit::<0>(&pre, t_max, &mut pass),
            1 => self.any_hit::<1>(&pre, t_max, &mut pass),
            _ => self.any_hit::<2>(&pre, t_max, &mut pass),
        }
    }

    /// Any-hit traversal; a hit primitive for which `pass(prim, ray, (t, a, b))` is true does
    /// not end it.
    #[inline(always)]
    fn any_hit<const KZ: usize>(
        &self,
        pre: &RayPre,
        t_max: f32,
        pass: impl FnMut(u32, &RayPre, PrimT) -> bool,
    ) -> bool {
        struct AnyHit<'a, F, const KZ: usize> {
            geo: &'a SceneGeometry,
            pre: &'a RayPre,
            pass: F,
            hit: bool,
        }
        impl<F: FnMut(u32, &RayPre, PrimT) -> bool, const KZ: usize> LeafTest for AnyHit<'_, F, KZ> {
            #[inline(always)]
            fn leaf(&mut self, first: u32, unary: u32, t_max: f32) -> Option<f32> {
                let (mut id, mut u) = (first, unary);
                while u != 0 {
                    if let Some(h) = self.geo.prim_intersect::<KZ>(id, self.pre, t_max) {
                        if !(self.pass)(id, self.pre, h) {
                            self.hit = true;
                            return None;
                        }
                    }
                    id += 1;
                    u >>= 1;
                }
                Some(t_max)
            }
            #[inline(always)]
            fn prefetch(&self, first: u32) {
                prefetch(self.geo.tris.as_ptr().wrapping_add(first as usize) as *const u8);
            }
        }
        let mut a = AnyHit::<_, KZ> {
            geo: self,
            pre,
            pass,
            hit: false,
        };
        traverse::<false>(&self.bvh.nodes, pre.o, pre.d, t_max, &mut a);
        a.hit
    }

    /// Brute force closest hit over all primitives (no BVH) — for tests and debugging.
    pub fn intersect_brute_force(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        if !Self::ray_ok(origin, dir, t_max) {
            return None;
        }
        let pre = RayPre::new(origin, dir);
        let mut tmax = t_max;
        let mut best = None;
        for i in 0..self.tris.len() {
            if let Some((t, a, b)) = self.prim(i as u32).intersect_dyn(&pre, tmax) {
                tmax = t;
                best = Some((i as u32, a, b));
            }
        }
        best.map(|(i, a, b)| self.make_hit(i, &pre, tmax, a, b))
    }

    /// Primitive ids (as used in [`Hit::prim`]) of that object; empty if unknown.
    pub fn primitives_of_object(&self, object: u32) -> &[u32] {
        match self.object_prims.binary_search_by_key(&object, |(o, _)| *o) {
            Ok(i) => &self.object_prims[i].1,
            Err(_) => &[],
        }
    }

    /// Object ids present in the scene (sorted).
    pub fn objects(&self) -> impl Iterator<Item = u32> + '_ {
        self.object_prims.iter().map(|(o, _)| *o)
    }

    /// The object id of a primitive.
    pub fn object_of_prim(&self, prim: u32) -> u32 {
        self.prim_object[prim as usize]
    }

    /// Surface area of a primitive (m²).
    pub fn prim_area(&self, prim: u32) -> f32 {
        self.prim(prim).area()
    }

    /// Uniform by area on the primitive: point, unit front-face geometric normal; the pdf
    /// w.r.t. area is `1 / prim_area(prim)`. `u` ∈ [0,1)². The point's error bound is
    /// [`super::point_error_bound`] (it is computed in f64).
    pub fn sample_prim(&self, prim: u32, u: Vec2) -> SurfacePoint {
        let (p, n) = self.prim(prim).sample_area(u);
        SurfacePoint { p, n }
    }

    /// For a sphere seen from outside: (sinθmax², 1 − cosθmax) of the cone it subtends.
    fn sphere_cone(center: Vec3, radius: f32, reference: Vec3) -> Option<(f64, f64)> {
        let dc2 = (reference.as_dvec3() - center.as_dvec3()).length_squared();
        let r2 = radius as f64 * radius as f64;
        // Inside or (numerically) on the sphere: use area sampling instead.
        if dc2 <= r2 * (1.0 + 1e-6) {
            return None;
        }
        let sin2 = r2 / dc2;
        let one_minus_cos = if sin2 < 0.00068523 {
            // Taylor expansion for small angles (pbrt-v4).
            sin2 / 2.0 + sin2 * sin2 / 8.0
        } else {
            1.0 - (1.0 - sin2).max(0.0).sqrt()
        };
        Some((sin2, one_minus_cos))
    }

    /// Solid-angle sampling as seen from `reference`: spheres seen from outside sample the
    /// subtended cone uniformly; everything else (and a sphere seen from inside) samples area
    /// uniformly and converts the density. Returns the point (with front-face normal) and its
    /// pdf w.r.t. solid angle at `reference`, or `None` if that pdf would be 0 / infinite /
    /// NaN (point at the reference, or seen exactly edge-on). Flat primitives are treated as
    /// two-sided here (|cos|); emission sidedness is the caller's business.
    pub fn sample_prim_solid_angle(
        &self,
        prim: u32,
        reference: Vec3,
        u: Vec2,
    ) -> Option<(SurfacePoint, f32)> {
        let pr = self.prim(prim);
        if let Prim::Sphere { center, radius } = pr {
            if let Some((sin2_max, one_minus_cos_max)) =
                Self::sphere_cone(center, radius, reference)
            {
                // pbrt-v4 Sphere::Sample(ctx, u), in f64.
                let (u0, u1) = (u.x as f64, u.y as f64);
                let sin_max = sin2_max.sqrt();
                let (sin2, cos) = if sin2_max < 0.00068523 {
                    let s2 = sin2_max * u0;
                    (s2, (1.0 - s2).sqrt())
                } else {
                    let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
                    let c = (cos_max - 1.0) * u0 + 1.0;
                    ((1.0 - c * c).max(0.0), c)
                };
                let cos_alpha = sin2 / sin_max + cos * (1.0 - sin2 / sin2_max).max(0.0).sqrt();
                let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
                let phi = u1 * std::f64::consts::TAU;
                let c = center.as_dvec3();
                let wz = (c - reference.as_dvec3()).normalize();
                let (tx, ty) = super::prim::basis(wz);
                // Normal at the sampled point, pointing back toward the reference side.
                let n = -(sin_alpha * phi.cos() * tx + sin_alpha * phi.sin() * ty + cos_alpha * wz);
                let n = n.normalize();
                let p = c + n * radius as f64;
                let pdf = crate::sampling::uniform_cone_pdf(one_minus_cos_max);
                let pdf = pdf as f32;
                if !(pdf.is_finite() && pdf > 0.0) {
                    return None;
                }
                return Some((
                    SurfacePoint {
                        p: p.as_vec3(),
                        n: n.as_vec3(),
                    },
                    pdf,
                ));
            }
        }
        let (p, n) = pr.sample_area(u);
        let pdf = Self::area_to_solid_angle(pr.area(), reference, p, n);
        (pdf > 0.0 && pdf.is_finite()).then_some((SurfacePoint { p, n }, pdf))
    }

    fn area_to_solid_angle(area: f32, reference: Vec3, p: Vec3, n: Vec3) -> f32 {
        let w = p.as_dvec3() - reference.as_dvec3();
        let d2 = w.length_squared();
        if d2 == 0.0 {
            return 0.0;
        }
        let cos = (n.as_dvec3().dot(w) / d2.sqrt()).abs();
        if cos == 0.0 || area <= 0.0 {
            return 0.0;
        }
        let pdf = (d2 / (cos * area as f64)) as f32;
        if pdf.is_finite() {
            pdf
        } else {
            0.0
        }
    }

    /// The pdf (solid angle at `reference`) that [`SceneGeometry::sample_prim_solid_angle`]
    /// would have given for the direction that hit `prim` at `hit` (0 when it returns `None`).
    pub fn pdf_prim_solid_angle(&self, prim: u32, reference: Vec3, hit: &Hit) -> f32 {
        let pr = self.prim(prim);
        if let Prim::Sphere { center, radius } = pr {
            if let Some((_, one_minus_cos_max)) = Self::sphere_cone(center, radius, reference) {
                let pdf = crate::sampling::uniform_cone_pdf(one_minus_cos_max) as f32;
                return if pdf.is_finite() { pdf } else { 0.0 };
            }
        }
        Self::area_to_solid_angle(pr.area(), reference, hit.p, hit.ng)
    }

    /// Solid angle (sr) subtended by a sphere primitive from outside, if `prim` is one and the
    /// reference is outside it.
    pub fn sphere_solid_angle(&self, prim: u32, reference: Vec3) -> Option<f32> {
        if let Prim::Sphere { center, radius } = self.prim(prim) {
            let (_, omc) = Self::sphere_cone(center, radius, reference)?;
            return Some((std::f64::consts::TAU * omc) as f32);
        }
        None
    }

    /// World-space bounds of all primitives (`(0, 0)` for an empty scene).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    pub fn primitive_count(&self) -> usize {
        self.tris.len()
    }

    /// Depth of the BVH (number of node levels).
    pub fn bvh_depth(&self) -> u32 {
        cwbvh_depth(&self.bvh)
    }

    /// Number of CWBVH nodes (80 bytes each).
    pub fn node_count(&self) -> usize {
        self.bvh.nodes.len()
    }

    /// Approximate heap memory in bytes (BVH nodes, primitive data, per-primitive ids, normals).
    pub fn memory_bytes(&self) -> usize {
        self.bvh.nodes.capacity() * std::mem::size_of::<CwBvhNode>()
            + self.bvh.primitive_indices.capacity() * 4
            + self.tris.capacity() * std::mem::size_of::<[Vec3; 3]>()
            + self.others.capacity() * std::mem::size_of::<Prim>()
            + self.prim_object.capacity() * 4
            + self.prim_normals.capacity() * 12
            + self.normals.capacity() * 12
            + self
                .object_prims
                .iter()
                .map(|(_, v)| v.capacity() * 4 + 32)
                .sum::<usize>()
    }
}
