//! The scene BVH: all primitives in one obvhs CWBVH (8-wide, compressed nodes), laid out in
//! leaf order, with our own traversal node test.
//!
//! obvhs's own `CwBvhNode::intersect_ray` clamps the box entry distance to a hard-coded
//! `1e-4` and ignores `ray.tmin`, which silently culls every node lying entirely closer than
//! 0.1 mm to the ray origin (and every node for rays shorter than 0.1 mm); it also replaces
//! direction components below `f32::EPSILON` by ±1/ε, which can cull valid boxes for nearly
//! axis-parallel rays; and its traversal stack (32 entries) is not bounds-checked in release
//! builds. We therefore keep obvhs as the builder and node layout but traverse its nodes with
//! our own loop ([`traverse`], the same algorithm as `obvhs::traverse!`, with a 64-entry stack
//! whose bound the build checks) and our own node test ([`node_hitmask`]): entry clamped to 0,
//! exact reciprocal directions, and per-node conservative padding of the slab distances by
//! their floating-point error bound, so no box containing a valid hit is ever culled.

use super::prim::{Prim, RayPre};
use super::robust::gamma;
use super::{GeometryError, Hit, Shape, SurfacePoint};
use glam::{UVec2, Vec2, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::cwbvh::CwBvh;
use obvhs::BvhBuildParams;

/// All primitives of the scene in one BVH.
pub struct SceneGeometry {
    bvh: CwBvh,
    /// Primitives in BVH leaf order; the primitive id is the index into this array.
    prims: Vec<Prim>,
    prim_object: Vec<u32>,
    /// Per primitive vertex-normal indices into `normals` (`u32::MAX` = none). Empty when no
    /// primitive has vertex normals.
    prim_normals: Vec<[u32; 3]>,
    normals: Vec<Vec3>,
    /// (object id, primitive ids), sorted by object id.
    object_prims: Vec<(u32, Vec<u32>)>,
    bounds: (Vec3, Vec3),
}

/// Ray data for the node test.
struct NodeRay {
    o: Vec3A,
    inv: Vec3A,
    neg: [bool; 3],
}

const INV_LIMIT: f32 = 1e30;

impl NodeRay {
    #[inline(always)]
    fn new(o: Vec3, d: Vec3) -> Self {
        // 1/±0 = ±∞ is clamped to ±INV_LIMIT (d is finite and non-zero, so no NaN).
        let inv =
            (Vec3A::ONE / Vec3A::from(d)).clamp(Vec3A::splat(-INV_LIMIT), Vec3A::splat(INV_LIMIT));
        Self {
            o: o.into(),
            inv,
            // From the reciprocal, so that −0 (reciprocal −∞ → −INV_LIMIT) counts as negative.
            neg: [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0],
        }
    }
}

/// Slab test of the 8 children of `node` against the ray segment [0, t_max]; returns obvhs's
/// hitmask. The plane distances are computed as `q·(e/d) + (p−o)/d` (q = quantized plane) and
/// widened by a bound on their rounding error, so the test is conservative.
#[inline(always)]
fn node_hitmask(node: &CwBvhNode, r: &NodeRay, oct_inv4: u32, t_max: f32) -> u32 {
    let e = node.compute_extent();
    let rel = Vec3A::from(node.p) - r.o;
    let scale = e * r.inv;
    let base = rel * r.inv;
    let pad = gamma(7) * (rel.abs() + 255.0 * e) * r.inv.abs();
    let base_near = base - pad;
    let base_far = base + pad;
    let (child_bits8, bit_index8) = node.get_child_and_index_bits(oct_inv4);

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
        /// Entry and exit distances of the 8 children's slabs on one axis.
        #[inline(always)]
        fn slabs(
            lo: &[u8; 8],
            hi: &[u8; 8],
            neg: bool,
            s: f32,
            near: f32,
            far: f32,
        ) -> (__m256, __m256) {
            // SAFETY: reads exactly the 8 bytes of each array.
            unsafe {
                let q8 = |v: &[u8; 8]| {
                    _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_loadl_epi64(
                        v.as_ptr() as *const __m128i
                    )))
                };
                let (lo, hi) = (q8(lo), q8(hi));
                let (qn, qf) = if neg { (hi, lo) } else { (lo, hi) };
                let s = _mm256_set1_ps(s);
                (
                    _mm256_fmadd_ps(qn, s, _mm256_set1_ps(near)),
                    _mm256_fmadd_ps(qf, s, _mm256_set1_ps(far)),
                )
            }
        }
        let (tnx, tfx) = slabs(
            &node.child_min_x,
            &node.child_max_x,
            r.neg[0],
            scale.x,
            base_near.x,
            base_far.x,
        );
        let (tny, tfy) = slabs(
            &node.child_min_y,
            &node.child_max_y,
            r.neg[1],
            scale.y,
            base_near.y,
            base_far.y,
        );
        let (tnz, tfz) = slabs(
            &node.child_min_z,
            &node.child_max_z,
            r.neg[2],
            scale.z,
            base_near.z,
            base_far.z,
        );
        let tmin = _mm256_max_ps(
            _mm256_max_ps(tnx, tny),
            _mm256_max_ps(tnz, _mm256_setzero_ps()),
        );
        let tmax = _mm256_min_ps(
            _mm256_min_ps(tfx, tfy),
            _mm256_min_ps(tfz, _mm256_set1_ps(t_max)),
        );
        let hit = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_LE_OQ>(tmin, tmax));
        // hit_mask = OR over hit children k of child_bits[k] << bit_index[k], 8 lanes at once.
        let bits = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(child_bits8 as i64));
        let index = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(bit_index8 as i64));
        let lanes = _mm256_and_si256(_mm256_sllv_epi32(bits, index), hit);
        let x = _mm_or_si128(
            _mm256_castsi256_si128(lanes),
            _mm256_extracti128_si256::<1>(lanes),
        );
        let x = _mm_or_si128(x, _mm_shuffle_epi32::<0b01_00_11_10>(x));
        let x = _mm_or_si128(x, _mm_shuffle_epi32::<0b10_11_00_01>(x));
        _mm_cvtsi128_si32(x) as u32
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
            let q = |lo: u8, hi: u8, neg: bool| {
                if neg {
                    (hi as f32, lo as f32)
                } else {
                    (lo as f32, hi as f32)
                }
            };
            let (nx, fx) = q(node.child_min_x[k], node.child_max_x[k], r.neg[0]);
            let (ny, fy) = q(node.child_min_y[k], node.child_max_y[k], r.neg[1]);
            let (nz, fz) = q(node.child_min_z[k], node.child_max_z[k], r.neg[2]);
            let tmin = (nx * scale.x + base_near.x)
                .max(ny * scale.y + base_near.y)
                .max(nz * scale.z + base_near.z)
                .max(0.0);
            let tmax = (fx * scale.x + base_far.x)
                .min(fy * scale.y + base_far.y)
                .min(fz * scale.z + base_far.z)
                .min(t_max);
            if tmin <= tmax {
                let child_bits = ((child_bits8 >> (k * 8)) as u32) & 0xff;
                let bit_index = ((bit_index8 >> (k * 8)) as u32) & 0xff;
                hit_mask |= child_bits << bit_index;
            }
        }
        hit_mask
    }
}

/// Largest distance from the origin (m, per axis) of any primitive's bounds: beyond it the
/// BVH builder's f32 surface-area costs overflow (7 astronomical units: room for a sun).
pub const MAX_COORDINATE: f32 = 1e12;

/// Maximum supported BVH depth (our traversal stack size).
const MAX_DEPTH: usize = 64;

#[inline(always)]
fn firstbithigh(v: u32) -> u32 {
    31 - v.leading_zeros()
}

#[inline(always)]
fn octant_inv4(d: Vec3) -> u32 {
    (if d.x < 0.0 { 0 } else { 0x04040404 })
        | (if d.y < 0.0 { 0 } else { 0x02020202 })
        | (if d.z < 0.0 { 0 } else { 0x01010101 })
}

/// CWBVH traversal (the loop of `obvhs::traverse!`, Ylitie et al. 2017) with our node test and
/// a 64-entry stack. `prim_fn(id, t_max)` tests primitive `id` and returns the new t_max
/// (smaller on a closer hit) or `None` to stop traversal (any-hit).
#[inline(always)]
fn traverse(
    bvh: &CwBvh,
    origin: Vec3,
    dir: Vec3,
    mut t_max: f32,
    mut prim_fn: impl FnMut(u32, f32) -> Option<f32>,
) {
    if bvh.nodes.is_empty() {
        return;
    }
    let r = NodeRay::new(origin, dir);
    let oct_inv4 = octant_inv4(dir);
    let mut stack = [UVec2::ZERO; MAX_DEPTH];
    let mut sp = 0usize;
    let mut current = UVec2::new(0, 0x8000_0000);
    let mut prims = UVec2::ZERO;
    loop {
        while prims.y != 0 {
            let local = firstbithigh(prims.y);
            prims.y &= !(1u32 << local);
            match prim_fn(prims.x + local, t_max) {
                Some(t) => t_max = t,
                None => return,
            }
        }
        if current.y & 0xff00_0000 != 0 {
            let hits_imask = current.y;
            let child_offset = firstbithigh(hits_imask);
            let child_base = current.x;
            current.y &= !(1u32 << child_offset);
            if current.y & 0xff00_0000 != 0 {
                // SAFETY: the stack holds one entry per level and the build rejects BVHs
                // deeper than MAX_DEPTH.
                unsafe { *stack.get_unchecked_mut(sp) = current };
                sp += 1;
            }
            let slot = (child_offset - 24) ^ (oct_inv4 & 0xff);
            let relative = (hits_imask & !(0xffff_ffffu32 << slot)).count_ones();
            let node = &bvh.nodes[(child_base + relative) as usize];
            let hitmask = node_hitmask(node, &r, oct_inv4, t_max);
            current = UVec2::new(
                node.child_base_idx,
                (hitmask & 0xff00_0000) | node.imask as u32,
            );
            prims = UVec2::new(node.primitive_base_idx, hitmask & 0x00ff_ffff);
        } else {
            current = UVec2::ZERO;
        }
        if prims.y == 0 && current.y & 0xff00_0000 == 0 {
            if sp == 0 {
                return;
            }
            sp -= 1;
            current = stack[sp];
        }
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
        let prims: Vec<Prim> = order.iter().map(|&i| prims[i as usize]).collect();
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
            prims,
            prim_object,
            prim_normals,
            normals,
            object_prims,
            bounds,
        })
    }

    #[inline]
    fn ray_ok(origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        origin.is_finite() && dir.is_finite() && dir != Vec3::ZERO && t_max > 0.0
    }

    /// Closest hit with `t` in `(0, t_max)` (`t_max` may be `f32::INFINITY`). `dir` need not be
    /// normalized (any finite non-zero vector); `t` is in units of `|dir|`. Returns `None` for
    /// a miss or an invalid ray (non-finite, zero direction).
    pub fn intersect(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        if self.prims.is_empty() || !Self::ray_ok(origin, dir, t_max) {
            return None;
        }
        let pre = RayPre::new(origin, dir);
        match pre.kz {
            0 => self.closest::<0>(&pre, t_max),
            1 => self.closest::<1>(&pre, t_max),
            _ => self.closest::<2>(&pre, t_max),
        }
    }

    #[inline(always)]
    fn closest<const KZ: usize>(&self, pre: &RayPre, t_max: f32) -> Option<Hit> {
        let prims = &self.prims[..];
        let mut best = u32::MAX;
        let (mut tbest, mut ba, mut bb) = (t_max, 0.0f32, 0.0f32);
        traverse(&self.bvh, pre.o, pre.d, t_max, |id, tmax| {
            // SAFETY: leaf primitive ids index `prims` (same length as the builder's input).
            let prim = unsafe { prims.get_unchecked(id as usize) };
            if let Some((t, a, b)) = prim.intersect::<KZ>(pre, tmax) {
                best = id;
                (tbest, ba, bb) = (t, a, b);
                return Some(t);
            }
            Some(tmax)
        });
        (best != u32::MAX).then(|| self.make_hit(best, pre, tbest, ba, bb))
    }

    /// The hit record for primitive `prim` at ray parameter `t` (used after traversal and by
    /// brute-force tests).
    fn make_hit(&self, prim: u32, pre: &RayPre, t: f32, a: f32, b: f32) -> Hit {
        let p = &self.prims[prim as usize];
        let g = p.hit_geom(pre, t, a, b);
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
        if self.prims.is_empty() || !Self::ray_ok(origin, dir, t_max) {
            return false;
        }
        let pre = RayPre::new(origin, dir);
        match pre.kz {
            0 => self.any_hit::<0>(&pre, t_max),
            1 => self.any_hit::<1>(&pre, t_max),
            _ => self.any_hit::<2>(&pre, t_max),
        }
    }

    #[inline(always)]
    fn any_hit<const KZ: usize>(&self, pre: &RayPre, t_max: f32) -> bool {
        let prims = &self.prims[..];
        let mut hit = false;
        traverse(&self.bvh, pre.o, pre.d, t_max, |id, tmax| {
            // SAFETY: see `closest`.
            let prim = unsafe { prims.get_unchecked(id as usize) };
            if prim.intersect::<KZ>(pre, tmax).is_some() {
                hit = true;
                return None;
            }
            Some(tmax)
        });
        hit
    }

    /// Brute force closest hit over all primitives (no BVH) — for tests and debugging.
    pub fn intersect_brute_force(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        if !Self::ray_ok(origin, dir, t_max) {
            return None;
        }
        let pre = RayPre::new(origin, dir);
        let mut tmax = t_max;
        let mut best = None;
        for (i, p) in self.prims.iter().enumerate() {
            if let Some((t, a, b)) = p.intersect_dyn(&pre, tmax) {
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
        self.prims[prim as usize].area()
    }

    /// Uniform by area on the primitive: point, unit front-face geometric normal; the pdf
    /// w.r.t. area is `1 / prim_area(prim)`. `u` ∈ [0,1)². The point's error bound is
    /// [`super::point_error_bound`] (it is computed in f64).
    pub fn sample_prim(&self, prim: u32, u: Vec2) -> SurfacePoint {
        let (p, n) = self.prims[prim as usize].sample_area(u);
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
        let pr = &self.prims[prim as usize];
        if let Prim::Sphere { center, radius } = *pr {
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
                let pdf = 1.0 / (std::f64::consts::TAU * one_minus_cos_max);
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
        let pr = &self.prims[prim as usize];
        if let Prim::Sphere { center, radius } = *pr {
            if let Some((_, one_minus_cos_max)) = Self::sphere_cone(center, radius, reference) {
                let pdf = (1.0 / (std::f64::consts::TAU * one_minus_cos_max)) as f32;
                return if pdf.is_finite() { pdf } else { 0.0 };
            }
        }
        Self::area_to_solid_angle(pr.area(), reference, hit.p, hit.ng)
    }

    /// Solid angle (sr) subtended by a sphere primitive from outside, if `prim` is one and the
    /// reference is outside it.
    pub fn sphere_solid_angle(&self, prim: u32, reference: Vec3) -> Option<f32> {
        if let Prim::Sphere { center, radius } = self.prims[prim as usize] {
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
        self.prims.len()
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
            + self.prims.capacity() * std::mem::size_of::<Prim>()
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
