//! Scenes of a few quads (a lit room: walls, floor, ceiling, panels) tested all at once,
//! without the BVH: the quad test of `intersect_quad` run on [`LANES`] quads side by side
//! (structure-of-arrays, f64, AVX2 on x86-64; elsewhere the scalar test quad by quad). For a
//! dozen quads this is cheaper than the node test, the leaf dispatch and the per-quad scalar
//! tests of a traversal (rendering the 12-quad office of bench/mitsuba/interior.ron took 17%
//! less CPU; a 16-quad room 12% less, while with 32 quads the BVH was the faster).
//!
//! Every lane repeats `intersect_quad`'s operations in the same order (no contraction into
//! FMAs, which Rust never does implicitly), so a lane accepts exactly the hits the scalar test
//! accepts, and the hit's `t` and parameters are taken from the lane bit for bit. Closest hits
//! are the same as the traversal's except among hits at exactly the same `t` (f32), which need
//! a ray through the shared edge of two quads to f64 precision: the traversal keeps the first
//! it tests, this the one with the lowest primitive id.

use crate::geometry::prim::{quad_hit_geom, HitGeom, Prim, PrimT, QuadPre, RayPre};
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

/// A quad as `Prim::Quad` holds it.
#[derive(Clone, Copy, Debug)]
struct Quad {
    origin: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
    pre: QuadPre,
}

/// The quads of a scene made of at most [`MAX_QUADS`] quads and nothing else, in primitive id
/// order; empty for every other scene.
#[derive(Clone, Default, Debug)]
pub(in crate::geometry) struct SmallQuads {
    groups: Vec<QuadGroup>,
    /// Per primitive id, for the scalar test and the hit geometry.
    quads: Vec<Quad>,
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
                Prim::Quad {
                    origin,
                    edge_u,
                    edge_v,
                    pre,
                } => quads.push(Quad {
                    origin,
                    edge_u,
                    edge_v,
                    pre,
                }),
                _ => return Self::default(),
            }
        }
        let mut groups = vec![QuadGroup::default(); quads.len().div_ceil(LANES)];
        for (i, q) in quads.iter().enumerate() {
            let (g, l) = (&mut groups[i / LANES], i % LANES);
            let o = q.origin.as_dvec3();
            for k in 0..3 {
                g.o[k][l] = o[k];
                g.n[k][l] = q.pre.n[k];
                g.du[k][l] = q.pre.du[k];
                g.dv[k][l] = q.pre.dv[k];
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
        let q = &self.quads[id];
        crate::geometry::prim::intersect_quad_f64(od, dd, t_max, q.origin, &q.pre)
    }

    /// The hit geometry (`Prim::hit_geom`) of primitive `id` at parameters (a, b).
    #[inline(always)]
    pub(in crate::geometry) fn hit_geom(&self, id: u32, a: f32, b: f32) -> HitGeom {
        let q = &self.quads[id as usize];
        quad_hit_geom(q.origin, q.edge_u, q.edge_v, &q.pre, a, b)
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
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        let h = simd::closest(&self.groups, o, d, t_max);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        let h = {
            let (od, dd) = (o.as_dvec3(), d.as_dvec3());
            let (mut best, mut t_max) = (None, t_max);
            // Strictly nearer hits only: the lowest id among equally near ones.
            for id in 0..self.quads.len() {
                if let Some((t, a, b)) = self.test(id, od, dd, t_max) {
                    best = Some((id as u32, t, a, b));
                    t_max = t;
                }
            }
            best
        };
        debug_assert!(h.is_none_or(|(id, t, a, b)| {
            self.test(id as usize, o.as_dvec3(), d.as_dvec3(), t_max) == Some((t, a, b))
        }));
        h
    }

    /// True if a quad is hit with `t` in `(0, t_max)` (a valid ray).
    #[inline(always)]
    pub(in crate::geometry) fn occluded(&self, o: Vec3, d: Vec3, t_max: f32) -> bool {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return simd::occluded(&self.groups, o, d, t_max);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        self.any_hit(o, d, t_max, |_, _, _| false)
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
        // The ray's test data, made once and only for a ray that hits something.
        let mut pre = None;
        let mut hit =
            |id: usize, h: PrimT| !pass(id as u32, pre.get_or_insert_with(|| RayPre::new(o, d)), h);
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return simd::any_hit(&self.groups, o, d, t_max, |id, h| {
            debug_assert_eq!(self.test(id, o.as_dvec3(), d.as_dvec3(), t_max), Some(h));
            hit(id, h)
        });
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        {
            let (od, dd) = (o.as_dvec3(), d.as_dvec3());
            (0..self.quads.len()).any(|id| self.test(id, od, dd, t_max).is_some_and(|h| hit(id, h)))
        }
    }

    /// Heap memory in bytes.
    pub(in crate::geometry) fn memory_bytes(&self) -> usize {
        self.groups.capacity() * std::mem::size_of::<QuadGroup>()
            + self.quads.capacity() * std::mem::size_of::<Quad>()
    }
}

/// The group test in AVX2 (the compiler's own vectorisation of a loop over the lanes moved
/// every lane's comparisons to scalar registers). Only exactly rounded IEEE operations, in the
/// scalar test's order and without fusing, so every lane computes the scalar test's values.
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
mod simd {
    use super::{QuadGroup, LANES};
    use crate::geometry::prim::{quad_param, quad_params, PrimT};
    use glam::Vec3;
    use std::arch::x86_64::*;

    const _: () = assert!(LANES == 4 && super::MAX_QUADS <= ID_MASK as usize + 1);

    /// A lane's key is its hit's `t`, rounded to f32 and back to f64, as the bits of that f64,
    /// with the quad's id in the low bits (zero in an f64 made from an f32): positive, so
    /// integer order is the order by `t`, then by id. Lanes without a hit have `t` = +∞.
    const ID_MASK: i64 = (1 << 29) - 1;
    /// The key of `t` = +∞ and id 0.
    const NO_HIT: i64 = f64::INFINITY.to_bits() as i64;

    /// The ray's data in every lane.
    struct Ray {
        o: [__m256d; 3],
        d: [__m256d; 3],
        /// `t_max` with the scalar test's margin for the rounding of `t` to f32.
        t_lim: __m256d,
        t_max: __m256d,
    }

    /// A group's lanes before the division: the scalar test's values and the mask of the lanes
    /// that pass its tests so far.
    struct Partial {
        num: __m256d,
        den: __m256d,
        den_abs: __m256d,
        /// s·|d·n| and t·|d·n|.
        sd: __m256d,
        vd: __m256d,
        candidates: __m256d,
    }

    impl Ray {
        #[inline(always)]
        fn new(o: Vec3, d: Vec3, t_max: f32) -> Self {
            // SAFETY: AVX2 is enabled at compile time.
            unsafe {
                Self {
                    o: [o.x, o.y, o.z].map(|c| _mm256_set1_pd(c as f64)),
                    d: [d.x, d.y, d.z].map(|c| _mm256_set1_pd(c as f64)),
                    t_lim: _mm256_set1_pd(t_max as f64 * (1.0 + 1e-6)),
                    t_max: _mm256_set1_pd(t_max as f64),
                }
            }
        }
    }

    /// `intersect_quad_f64` on the lanes of `g`, up to the division. With `EARLY`, `None` when
    /// no lane's plane is met within `(0, t_max)` (a shadow ray's usual case, which then skips
    /// the parameters' dot products).
    #[inline(always)]
    fn partial<const EARLY: bool>(g: &QuadGroup, r: &Ray) -> Option<Partial> {
        // SAFETY: AVX2 is enabled at compile time; every load reads one [f64; 4] of `g`, which
        // `QuadGroup`'s alignment keeps 32-byte aligned.
        unsafe {
            let ld = |a: &[f64; LANES]| _mm256_load_pd(a.as_ptr());
            let (mul, add, sub, and) = (_mm256_mul_pd, _mm256_add_pd, _mm256_sub_pd, _mm256_and_pd);
            let dot = |a: &[__m256d; 3], b: &[[f64; LANES]; 3]| {
                add(
                    add(mul(a[0], ld(&b[0])), mul(a[1], ld(&b[1]))),
                    mul(a[2], ld(&b[2])),
                )
            };
            let w = [0, 1, 2].map(|k| sub(ld(&g.o[k]), r.o[k]));
            let num = dot(&w, &g.n);
            let den = dot(&r.d, &g.n);
            let zero = _mm256_setzero_pd();
            let sign_bit = _mm256_set1_pd(-0.0);
            let den_abs = _mm256_andnot_pd(sign_bit, den);
            let in_range = and(
                _mm256_cmp_pd::<_CMP_GT_OQ>(mul(num, den), zero),
                _mm256_cmp_pd::<_CMP_LT_OQ>(_mm256_andnot_pd(sign_bit, num), mul(den_abs, r.t_lim)),
            );
            if EARLY && _mm256_movemask_pd(in_range) == 0 {
                return None;
            }
            // The scalar test's ×±1 (the sign of d·n) is a sign flip; d·n = ±0 or NaN fails
            // `in_range`.
            let flip = and(den, sign_bit);
            let sd = _mm256_xor_pd(
                sub(mul(num, dot(&r.d, &g.du)), mul(den, dot(&w, &g.du))),
                flip,
            );
            let vd = _mm256_xor_pd(
                sub(mul(num, dot(&r.d, &g.dv)), mul(den, dot(&w, &g.dv))),
                flip,
            );
            let inside = and(
                and(
                    _mm256_cmp_pd::<_CMP_GE_OQ>(sd, zero),
                    _mm256_cmp_pd::<_CMP_LE_OQ>(sd, den_abs),
                ),
                and(
                    _mm256_cmp_pd::<_CMP_GE_OQ>(vd, zero),
                    _mm256_cmp_pd::<_CMP_LE_OQ>(vd, den_abs),
                ),
            );
            Some(Partial {
                num,
                den,
                den_abs,
                sd,
                vd,
                candidates: and(in_range, inside),
            })
        }
    }

    /// The lanes' keys, the ids `ids` in their low bits.
    #[inline(always)]
    fn keys(p: &Partial, r: &Ray, ids: __m256i) -> __m256i {
        // SAFETY: AVX2 is enabled at compile time.
        unsafe {
            let zero = _mm256_setzero_pd();
            let inf = _mm256_set1_pd(f64::INFINITY);
            let t = _mm256_div_pd(p.num, p.den);
            let ok = _mm256_and_pd(p.candidates, _mm256_cmp_pd::<_CMP_GT_OQ>(t, zero));
            // t as f32 (+∞ in the lanes rejected so far, which the f32 tests then reject as
            // well), back in f64: exact, so the f32 tests can be made in f64.
            let t32 = _mm256_cvtps_pd(_mm256_cvtpd_ps(_mm256_blendv_pd(inf, t, ok)));
            let ok = _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_GT_OQ>(t32, zero),
                _mm256_cmp_pd::<_CMP_LT_OQ>(t32, r.t_max),
            );
            _mm256_or_si256(_mm256_castpd_si256(_mm256_blendv_pd(inf, t32, ok)), ids)
        }
    }

    /// Lane `l` of `v`.
    #[inline(always)]
    fn lane(v: __m256d, l: usize) -> f64 {
        let mut a = [0.0; LANES];
        // SAFETY: AVX2 is enabled at compile time; `a` holds 4 f64.
        unsafe { _mm256_storeu_pd(a.as_mut_ptr(), v) };
        a[l]
    }

    /// The hit of a lane with key `key` (a hit's), whose values are in lane `l` of `p`.
    #[inline(always)]
    fn hit(key: i64, sd: __m256d, vd: __m256d, den_abs: __m256d, l: usize) -> PrimT {
        let t = f64::from_bits((key & !ID_MASK) as u64) as f32;
        let (a, b) = quad_params(lane(sd, l), lane(vd, l), lane(den_abs, l));
        (t, a, b)
    }

    /// [`super::SmallQuads::closest`].
    #[inline(always)]
    pub(super) fn closest(
        groups: &[QuadGroup],
        o: Vec3,
        d: Vec3,
        t_max: f32,
    ) -> Option<(u32, f32, f32, f32)> {
        let r = Ray::new(o, d, t_max);
        // SAFETY: AVX2 is enabled at compile time.
        unsafe {
            // Per lane the least key so far and the values of its hit.
            let mut best = _mm256_set1_epi64x(i64::MAX);
            let (mut sd, mut vd, mut den_abs) = (
                _mm256_setzero_pd(),
                _mm256_setzero_pd(),
                _mm256_setzero_pd(),
            );
            let mut ids = _mm256_setr_epi64x(0, 1, 2, 3);
            for g in groups {
                let Some(p) = partial::<false>(g, &r) else {
                    unreachable!()
                };
                let key = keys(&p, &r, ids);
                let less = _mm256_castsi256_pd(_mm256_cmpgt_epi64(best, key));
                best = _mm256_castpd_si256(_mm256_blendv_pd(
                    _mm256_castsi256_pd(best),
                    _mm256_castsi256_pd(key),
                    less,
                ));
                sd = _mm256_blendv_pd(sd, p.sd, less);
                vd = _mm256_blendv_pd(vd, p.vd, less);
                den_abs = _mm256_blendv_pd(den_abs, p.den_abs, less);
                ids = _mm256_add_epi64(ids, _mm256_set1_epi64x(LANES as i64));
            }
            // The parameters of each lane's hit, the division alongside the reduction below.
            let inv = _mm256_div_pd(_mm256_set1_pd(1.0), den_abs);
            let (mut a, mut b) = (_mm256_mul_pd(sd, inv), _mm256_mul_pd(vd, inv));
            // The least key and its parameters in every lane: halves swapped, then neighbours.
            for step in 0..2 {
                let other = |v: __m256d| {
                    if step == 0 {
                        _mm256_permute4x64_pd::<0b01_00_11_10>(v)
                    } else {
                        _mm256_permute_pd::<0b0101>(v)
                    }
                };
                let other_best = _mm256_castpd_si256(other(_mm256_castsi256_pd(best)));
                let less = _mm256_castsi256_pd(_mm256_cmpgt_epi64(best, other_best));
                best = _mm256_castpd_si256(_mm256_blendv_pd(
                    _mm256_castsi256_pd(best),
                    _mm256_castsi256_pd(other_best),
                    less,
                ));
                a = _mm256_blendv_pd(a, other(a), less);
                b = _mm256_blendv_pd(b, other(b), less);
            }
            let key = _mm256_extract_epi64::<0>(best);
            if key >= NO_HIT {
                return None;
            }
            let t = f64::from_bits((key & !ID_MASK) as u64) as f32;
            let (a, b) = (
                quad_param(_mm256_cvtsd_f64(a)),
                quad_param(_mm256_cvtsd_f64(b)),
            );
            Some(((key & ID_MASK) as u32, t, a, b))
        }
    }

    /// [`super::SmallQuads::occluded`]. The division waits for a lane that passes the tests
    /// before it, which shadow rays in a room rarely have.
    #[inline(always)]
    pub(super) fn occluded(groups: &[QuadGroup], o: Vec3, d: Vec3, t_max: f32) -> bool {
        let r = Ray::new(o, d, t_max);
        // SAFETY: AVX2 is enabled at compile time.
        unsafe {
            let no_hit = _mm256_set1_epi64x(NO_HIT);
            groups.iter().any(|g| {
                let Some(p) = partial::<true>(g, &r) else {
                    return false;
                };
                _mm256_movemask_pd(p.candidates) != 0 && {
                    let key = keys(&p, &r, _mm256_setzero_si256());
                    _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_cmpgt_epi64(no_hit, key))) != 0
                }
            })
        }
    }

    /// [`super::SmallQuads::any_hit`]: `hit(id, (t, a, b))` for each hit in id order until it
    /// returns true; returns whether one did.
    #[inline(always)]
    pub(super) fn any_hit(
        groups: &[QuadGroup],
        o: Vec3,
        d: Vec3,
        t_max: f32,
        mut hit_found: impl FnMut(usize, PrimT) -> bool,
    ) -> bool {
        let r = Ray::new(o, d, t_max);
        // SAFETY: AVX2 is enabled at compile time.
        unsafe {
            let no_hit = _mm256_set1_epi64x(NO_HIT);
            for (gi, g) in groups.iter().enumerate() {
                let Some(p) = partial::<true>(g, &r) else {
                    continue;
                };
                if _mm256_movemask_pd(p.candidates) == 0 {
                    continue;
                }
                let key = keys(&p, &r, _mm256_setzero_si256());
                let mut mask =
                    _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_cmpgt_epi64(no_hit, key)));
                let mut k = [0i64; LANES];
                _mm256_storeu_si256(k.as_mut_ptr() as *mut __m256i, key);
                while mask != 0 {
                    let l = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    if hit_found(gi * LANES + l, hit(k[l], p.sd, p.vd, p.den_abs, l)) {
                        return true;
                    }
                }
            }
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closest and any-hit queries report exactly the scalar test's hits (primitive, `t`
    /// and parameters), for quads of any orientation and rays with zero, tiny and huge
    /// components, from on and near the quads.
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
        let mut hits = 0;
        for round in 0..2000 {
            let scale = [1e-3, 1.0, 1e4][round % 3];
            let n = [7, 12, 16, 1][round % 4];
            let prims: Vec<Prim> = (0..n)
                .map(|_| {
                    let v = |f: &mut dyn FnMut() -> f32| Vec3::new(f(), f(), f()) * scale;
                    Prim::quad(v(&mut f), v(&mut f), v(&mut f))
                })
                .collect();
            let set = SmallQuads::new(&prims);
            assert!(set.active());
            let Prim::Quad { origin, edge_u, .. } = prims[round % n] else {
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
                let scalar: Vec<(u32, PrimT)> = (0..n)
                    .filter_map(|id| set.test(id, od, dd, t_max).map(|h| (id as u32, h)))
                    .collect();
                // The nearest, the first of equally near ones.
                let want = scalar
                    .iter()
                    .fold(None, |b: Option<(u32, PrimT)>, &(id, h)| match b {
                        Some(b) if b.1 .0 <= h.0 => Some(b),
                        _ => Some((id, h)),
                    })
                    .map(|(id, (t, a, b))| (id, t, a, b));
                let got = set.closest(o, d, t_max);
                assert_eq!(got, want, "{o} {d} {t_max}");
                let mut all = Vec::new();
                assert!(!set.any_hit(o, d, t_max, |id, _, h| {
                    all.push((id, h));
                    true
                }));
                assert_eq!(all, scalar, "{o} {d} {t_max}");
                assert_eq!(set.occluded(o, d, t_max), !scalar.is_empty());
                hits += scalar.len();
            }
        }
        assert!(hits > 1000, "{hits}");
    }
}
