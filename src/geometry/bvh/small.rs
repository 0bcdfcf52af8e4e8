//! Scenes of a few quads (a lit room: walls, floor, ceiling, panels) tested all at once,
//! without the BVH: the quad test of `intersect_quad` run on [`LANES`] quads side by side
//! (structure-of-arrays, f64; AVX2 on x86-64, else a loop over the lanes). For a dozen quads
//! this is cheaper than the node test, the leaf dispatch and the per-quad scalar tests of a
//! traversal (rendering the 12-quad office of bench/mitsuba/interior.ron took 17% less CPU; a
//! 16-quad room 12% less, while with 32 quads the BVH was the faster).
//!
//! Every lane repeats `intersect_quad`'s operations in the same order (no contraction into
//! FMAs, which Rust never does implicitly), so a lane accepts exactly the hits the scalar test
//! accepts; the hit that is reported is then recomputed by `intersect_quad` itself. Closest
//! hits are the same as the traversal's except among hits at exactly the same `t` (f32), which
//! need a ray through the shared edge of two quads to f64 precision: the traversal keeps the
//! first it tests, this the one with the lowest primitive id.

use crate::geometry::prim::{intersect_quad_f64, Prim, PrimT, QuadPre, RayPre};
use glam::{DVec3, Vec3};

/// Quads tested side by side.
const LANES: usize = 4;

/// Most quads for which a scene skips the BVH.
pub(in crate::geometry) const MAX_QUADS: usize = 16;

/// [`LANES`] quads' test data ([`QuadPre`] and the origin, in f64), one array per coordinate.
/// Unused lanes are all zero: their plane normal is zero, which no ray hits.
#[derive(Clone, Copy, Default, Debug)]
#[repr(C, align(32))]
struct QuadGroup {
    o: [[f64; LANES]; 3],
    n: [[f64; LANES]; 3],
    du: [[f64; LANES]; 3],
    dv: [[f64; LANES]; 3],
}

/// The quads of a scene made of at most [`MAX_QUADS`] quads and nothing else, in primitive id
/// order; empty for every other scene.
#[derive(Clone, Default, Debug)]
pub(in crate::geometry) struct SmallQuads {
    groups: Vec<QuadGroup>,
    /// Per primitive id: the quad's origin and test data, for the scalar test.
    quads: Vec<(Vec3, QuadPre)>,
}

/// Per-lane `a·b` as `DVec3::dot` evaluates it: `(x·x' + y·y') + z·z'`.
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
#[inline(always)]
fn dot(a: [f64; 3], b: &[[f64; LANES]; 3], l: usize) -> f64 {
    a[0] * b[0][l] + a[1] * b[1][l] + a[2] * b[2][l]
}

impl SmallQuads {
    /// The set for primitives `prims` (in primitive id order), or an empty one when they are
    /// not all quads or more than [`MAX_QUADS`].
    pub(in crate::geometry) fn new(prims: &[Prim]) -> Self {
        if prims.len() > MAX_QUADS {
            return Self::default();
        }
        let mut quads = Vec::with_capacity(prims.len());
        for p in prims {
            match *p {
                Prim::Quad { origin, pre, .. } => quads.push((origin, pre)),
                _ => return Self::default(),
            }
        }
        let mut groups = vec![QuadGroup::default(); quads.len().div_ceil(LANES)];
        for (i, (origin, q)) in quads.iter().enumerate() {
            let (g, l) = (&mut groups[i / LANES], i % LANES);
            let o = origin.as_dvec3();
            for k in 0..3 {
                g.o[k][l] = o[k];
                g.n[k][l] = q.n[k];
                g.du[k][l] = q.du[k];
                g.dv[k][l] = q.dv[k];
            }
        }
        Self { groups, quads }
    }

    /// True when the scene's queries use this set instead of the BVH.
    #[inline(always)]
    pub(in crate::geometry) fn active(&self) -> bool {
        !self.groups.is_empty()
    }

    /// `intersect_quad` of primitive `id`.
    #[inline(always)]
    fn test(&self, id: usize, od: DVec3, dd: DVec3, t_max: f32) -> Option<PrimT> {
        let (origin, q) = &self.quads[id];
        intersect_quad_f64(od, dd, t_max, *origin, q)
    }

    /// The ray parameter (f32) of the hit of each quad of group `g` with `t` in `(0, t_max)`,
    /// +∞ where there is none, and the mask of the lanes with a hit: `intersect_quad`'s
    /// acceptance, lane by lane.
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    #[inline(always)]
    fn group_t(g: &QuadGroup, od: DVec3, dd: DVec3, t_max: f32) -> ([f32; LANES], u32) {
        let (od, dd) = (od.to_array(), dd.to_array());
        let t_lim = t_max as f64 * (1.0 + 1e-6);
        let mut out = [0.0f32; LANES];
        let mut mask = 0;
        for (l, out) in out.iter_mut().enumerate() {
            let w = [g.o[0][l] - od[0], g.o[1][l] - od[1], g.o[2][l] - od[2]];
            let num = dot(w, &g.n, l);
            let den = dot(dd, &g.n, l);
            let den_abs = den.abs();
            let in_range = (num * den > 0.0) & (num.abs() < den_abs * t_lim);
            let sign = if den < 0.0 { -1.0 } else { 1.0 };
            let sd = sign * (num * dot(dd, &g.du, l) - den * dot(w, &g.du, l));
            let vd = sign * (num * dot(dd, &g.dv, l) - den * dot(w, &g.dv, l));
            let inside = (sd >= 0.0) & (sd <= den_abs) & (vd >= 0.0) & (vd <= den_abs);
            let t = num / den;
            let t32 = t as f32;
            let ok = in_range & inside & (t > 0.0) & (t32 > 0.0) & (t32 < t_max);
            *out = if ok { t32 } else { f32::INFINITY };
            mask |= (ok as u32) << l;
        }
        (out, mask)
    }

    /// The portable `group_t` in AVX2 (the compiler's own vectorisation of it moved every
    /// lane's comparisons to scalar registers). Only exactly rounded IEEE operations, in the
    /// same order and without fusing, so every lane computes the same values.
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    #[inline(always)]
    fn group_t(g: &QuadGroup, od: DVec3, dd: DVec3, t_max: f32) -> ([f32; LANES], u32) {
        use std::arch::x86_64::*;
        const _: () = assert!(LANES == 4);
        let t_lim = t_max as f64 * (1.0 + 1e-6);
        // SAFETY: AVX2 is enabled at compile time; every load reads one [f64; 4] of `g`, which
        // `QuadGroup`'s alignment keeps 32-byte aligned.
        unsafe {
            let ld = |a: &[f64; LANES]| _mm256_load_pd(a.as_ptr());
            let (mul, add, sub) = (_mm256_mul_pd, _mm256_add_pd, _mm256_sub_pd);
            let dot = |a: &[__m256d; 3], b: &[[f64; LANES]; 3]| {
                add(
                    add(mul(a[0], ld(&b[0])), mul(a[1], ld(&b[1]))),
                    mul(a[2], ld(&b[2])),
                )
            };
            let w = [0, 1, 2].map(|k| sub(ld(&g.o[k]), _mm256_set1_pd(od[k])));
            let d = [0, 1, 2].map(|k| _mm256_set1_pd(dd[k]));
            let num = dot(&w, &g.n);
            let den = dot(&d, &g.n);
            let zero = _mm256_setzero_pd();
            let abs_mask = _mm256_set1_pd(-0.0);
            let den_abs = _mm256_andnot_pd(abs_mask, den);
            let in_range = _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_GT_OQ>(mul(num, den), zero),
                _mm256_cmp_pd::<_CMP_LT_OQ>(
                    _mm256_andnot_pd(abs_mask, num),
                    mul(den_abs, _mm256_set1_pd(t_lim)),
                ),
            );
            let sign = _mm256_blendv_pd(
                _mm256_set1_pd(1.0),
                _mm256_set1_pd(-1.0),
                _mm256_cmp_pd::<_CMP_LT_OQ>(den, zero),
            );
            let sd = mul(
                sign,
                sub(mul(num, dot(&d, &g.du)), mul(den, dot(&w, &g.du))),
            );
            let vd = mul(
                sign,
                sub(mul(num, dot(&d, &g.dv)), mul(den, dot(&w, &g.dv))),
            );
            let inside = _mm256_and_pd(
                _mm256_and_pd(
                    _mm256_cmp_pd::<_CMP_GE_OQ>(sd, zero),
                    _mm256_cmp_pd::<_CMP_LE_OQ>(sd, den_abs),
                ),
                _mm256_and_pd(
                    _mm256_cmp_pd::<_CMP_GE_OQ>(vd, zero),
                    _mm256_cmp_pd::<_CMP_LE_OQ>(vd, den_abs),
                ),
            );
            let t = _mm256_div_pd(num, den);
            let ok64 = _mm256_and_pd(
                _mm256_and_pd(in_range, inside),
                _mm256_cmp_pd::<_CMP_GT_OQ>(t, zero),
            );
            // +∞ in the lanes rejected so far, which the f32 tests then reject as well.
            let t32 = _mm256_cvtpd_ps(_mm256_blendv_pd(_mm256_set1_pd(f64::INFINITY), t, ok64));
            let ok = _mm_and_ps(
                _mm_cmp_ps::<_CMP_GT_OQ>(t32, _mm_setzero_ps()),
                _mm_cmp_ps::<_CMP_LT_OQ>(t32, _mm_set1_ps(t_max)),
            );
            let mut out = [0.0f32; LANES];
            _mm_storeu_ps(
                out.as_mut_ptr(),
                _mm_blendv_ps(_mm_set1_ps(f32::INFINITY), t32, ok),
            );
            let mask = _mm_movemask_ps(ok) as u32;
            (out, mask)
        }
    }

    /// Closest hit of the ray `o + t·d` (a valid ray): (primitive, t, a, b), as the scene's
    /// traversal reports it.
    #[inline(always)]
    pub(in crate::geometry) fn closest(
        &self,
        o: Vec3,
        d: Vec3,
        t_max: f32,
    ) -> Option<(u32, f32, f32, f32)> {
        let (od, dd) = (o.as_dvec3(), d.as_dvec3());
        // Per lane the nearest hit and its group (the first on ties).
        let mut best_t = [f32::INFINITY; LANES];
        let mut best_g = [0u32; LANES];
        for (gi, g) in self.groups.iter().enumerate() {
            let (t, _) = Self::group_t(g, od, dd, t_max);
            for l in 0..LANES {
                let nearer = t[l] < best_t[l];
                best_t[l] = if nearer { t[l] } else { best_t[l] };
                best_g[l] = if nearer { gi as u32 } else { best_g[l] };
            }
        }
        let t = best_t.iter().fold(f32::INFINITY, |m, &t| m.min(t));
        if t == f32::INFINITY {
            return None;
        }
        // The lowest id among the lanes at that t.
        let mut id = u32::MAX;
        for l in 0..LANES {
            let lane_id = if best_t[l] == t {
                best_g[l] * LANES as u32 + l as u32
            } else {
                u32::MAX
            };
            id = id.min(lane_id);
        }
        let h = self.test(id as usize, od, dd, t_max);
        debug_assert!(h.is_some_and(|h| h.0 == t));
        h.map(|(t, a, b)| (id, t, a, b))
    }

    /// Any-hit query: every quad hit with `t` in `(0, t_max)` is handed to `pass` (by id order,
    /// with the ray's [`RayPre`]) until it returns false; returns whether one did.
    #[inline(always)]
    pub(in crate::geometry) fn any_hit(
        &self,
        o: Vec3,
        d: Vec3,
        t_max: f32,
        mut pass: impl FnMut(u32, &RayPre, PrimT) -> bool,
    ) -> bool {
        let (od, dd) = (o.as_dvec3(), d.as_dvec3());
        // The ray's test data, made once and only for a ray that hits something.
        let mut pre = None;
        for (gi, g) in self.groups.iter().enumerate() {
            let (_, mut mask) = Self::group_t(g, od, dd, t_max);
            while mask != 0 {
                let id = gi * LANES + mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if let Some(h) = self.test(id, od, dd, t_max) {
                    if !pass(id as u32, pre.get_or_insert_with(|| RayPre::new(o, d)), h) {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// Heap memory in bytes.
    pub(in crate::geometry) fn memory_bytes(&self) -> usize {
        self.groups.capacity() * std::mem::size_of::<QuadGroup>()
            + self.quads.capacity() * std::mem::size_of::<(Vec3, QuadPre)>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every lane accepts exactly the hits of the scalar test, at the same `t`, for quads of
    /// any orientation and rays with zero, tiny and huge components, from on and near the quads.
    #[test]
    fn lanes_are_the_scalar_test() {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut f = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let special = [0.0, -0.0, 1e-30, -1e-30, 1e20, 1.0, -1.0, f32::MIN_POSITIVE];
        for round in 0..2000 {
            let scale = [1e-3, 1.0, 1e4][round % 3];
            let prims: Vec<Prim> = (0..7)
                .map(|_| {
                    let v = |f: &mut dyn FnMut() -> f32| Vec3::new(f(), f(), f()) * scale;
                    Prim::quad(v(&mut f), v(&mut f), v(&mut f))
                })
                .collect();
            let set = SmallQuads::new(&prims);
            assert!(set.active());
            let Prim::Quad { origin, edge_u, .. } = prims[round % 7] else {
                unreachable!()
            };
            for k in 0..16 {
                // From a point of a quad (on its plane), or anywhere near the quads.
                let o = if k % 2 == 0 {
                    origin + edge_u * f().abs()
                } else {
                    Vec3::new(f(), f(), f()) * scale * 2.0
                };
                let mut d = Vec3::new(f(), f(), f());
                if k % 4 == 1 {
                    d[k % 3] = special[(round + k) % special.len()];
                }
                if d == Vec3::ZERO {
                    continue;
                }
                let t_max = [f32::INFINITY, 1.0, 1e-3, scale * f().abs()][k % 4];
                let (od, dd) = (o.as_dvec3(), d.as_dvec3());
                for (gi, g) in set.groups.iter().enumerate() {
                    let (t, mask) = SmallQuads::group_t(g, od, dd, t_max);
                    for (l, &t) in t.iter().enumerate() {
                        let id = gi * LANES + l;
                        let want = (id < prims.len())
                            .then(|| set.test(id, od, dd, t_max))
                            .flatten();
                        assert_eq!(mask >> l & 1 == 1, want.is_some(), "{o} {d} {t_max} {id}");
                        assert_eq!(t, want.map_or(f32::INFINITY, |h| h.0));
                    }
                }
            }
        }
    }
}
