//! Ray queries on the scene BVH: closest hit (full [`Hit`] or Embree-style [`RayHit`]),
//! any hit for shadow rays (optionally letting some objects' primitives through), the
//! per-primitive leaf tests they run, and a brute-force reference. A scene of a few quads is
//! queried without its BVH (`bvh::small`).

use super::instance::InstanceSet;
use super::prim::{Prim, PrimT, RayPre};
use super::traverse::{prefetch, traverse, LeafTest};
use super::{Hit, SceneGeometry};
use glam::{Vec3, Vec3A};

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

/// [`super::prim::intersect_triangle`] with the vertex transform and the edge functions in SIMD (the
/// three vertices in three lanes); every operation and its rounding is the same as in the
/// scalar test, so the results are bit-identical.
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

/// A closest hit: on a primitive stored flat ((primitive, t, a, b)), or in an instance.
enum Found<'a> {
    Flat((u32, f32, f32, f32)),
    Instanced(&'a InstanceSet, (u32, RayPre, u32, PrimT)),
}

impl SceneGeometry {
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
    #[inline(always)]
    pub fn intersect(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        // A scene of a few quads and nothing else: the query in the caller (whose use of the
        // hit then needs no copy of it through memory), the hit record from the quads' data.
        if self.small.active() && self.instances.is_none() {
            if !Self::ray_ok(origin, dir, t_max) {
                return None;
            }
            let (prim, t, a, b) = self.small.closest(origin, dir, t_max)?;
            return Some(self.small_hit(prim, dir, t, a, b));
        }
        self.intersect_any(origin, dir, t_max)
    }

    /// [`SceneGeometry::intersect`] in any scene.
    #[inline(never)]
    fn intersect_any(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        Some(match self.closest_any(origin, dir, t_max)? {
            Found::Flat((prim, t, a, b)) => self.hit_record(prim, origin, dir, t, a, b),
            Found::Instanced(set, h) => set.make_hit(h, dir),
        })
    }

    /// The closest hit as Embree's `rtcIntersect1` reports it: `t`, the surface parameters,
    /// the unnormalized geometric normal, and the primitive and object ids. Same hits and
    /// conventions as [`SceneGeometry::intersect`], without building the full [`Hit`].
    pub fn intersect_basic(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<RayHit> {
        Some(match self.closest_any(origin, dir, t_max)? {
            Found::Flat((prim, t, u, v)) => {
                let tri = &self.tris[prim as usize];
                let ng = if tri[0].x.is_nan() {
                    self.prim(prim).normal_at(origin + t * dir)
                } else {
                    (tri[1] - tri[0]).cross(tri[2] - tri[0])
                };
                RayHit {
                    t,
                    u,
                    v,
                    ng,
                    prim,
                    object: self.prim_object[prim as usize],
                }
            }
            Found::Instanced(set, h) => {
                let (ng, object) = set.basic(&h);
                let (_, _, prim, (t, mut u, mut v)) = h;
                if set.mirrored(&h) {
                    std::mem::swap(&mut u, &mut v);
                }
                RayHit {
                    t,
                    u,
                    v,
                    ng,
                    prim,
                    object,
                }
            }
        })
    }

    /// The closest hit among the primitives stored flat and the instances (an instance's only
    /// when nearer than the flat one).
    #[inline(always)]
    fn closest_any(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Found<'_>> {
        if !Self::ray_ok(origin, dir, t_max) {
            return None;
        }
        // A scene of a few quads needs none of the triangle test's ray data.
        let flat = if self.small.active() {
            self.small.closest(origin, dir, t_max)
        } else if self.tris.is_empty() {
            None
        } else {
            self.closest_dyn(&RayPre::new(origin, dir), t_max)
        };
        if let Some(set) = &self.instances {
            let t = flat.map_or(t_max, |f| f.1);
            if let Some(h) = set.closest(origin, dir, t) {
                return Some(Found::Instanced(set, h));
            }
        }
        flat.map(Found::Flat)
    }

    /// Closest-hit traversal: (primitive, t, a, b) of the closest hit.
    #[inline(always)]
    pub(super) fn closest_dyn(&self, pre: &RayPre, t_max: f32) -> Option<(u32, f32, f32, f32)> {
        if self.small.active() {
            return self.small.closest(pre.o, pre.d, t_max);
        }
        match pre.kz {
            0 => self.closest::<0>(pre, t_max),
            1 => self.closest::<1>(pre, t_max),
            _ => self.closest::<2>(pre, t_max),
        }
    }

    #[inline(always)]
    fn closest<const KZ: usize>(&self, pre: &RayPre, t_max: f32) -> Option<(u32, f32, f32, f32)> {
        if self.others.is_empty() {
            self.closest_in::<KZ, false>(pre, t_max)
        } else {
            self.closest_in::<KZ, true>(pre, t_max)
        }
    }

    /// [`SceneGeometry::closest`] for a scene with (`ANALYTIC`) or without non-triangle
    /// primitives.
    #[inline(always)]
    fn closest_in<const KZ: usize, const ANALYTIC: bool>(
        &self,
        pre: &RayPre,
        t_max: f32,
    ) -> Option<(u32, f32, f32, f32)> {
        struct Closest<'a, const KZ: usize, const ANALYTIC: bool> {
            geo: &'a SceneGeometry,
            pre: &'a RayPre,
            best: (u32, f32, f32, f32),
        }
        impl<const KZ: usize, const ANALYTIC: bool> LeafTest for Closest<'_, KZ, ANALYTIC> {
            #[inline(always)]
            fn leaf(&mut self, first: u32, unary: u32, mut t_max: f32) -> Option<f32> {
                let (mut id, mut u) = (first, unary);
                while u != 0 {
                    if let Some((t, a, b)) =
                        self.geo.prim_intersect::<KZ, ANALYTIC>(id, self.pre, t_max)
                    {
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
        let mut c = Closest::<KZ, ANALYTIC> {
            geo: self,
            pre,
            best: (u32::MAX, t_max, 0.0, 0.0),
        };
        traverse::<true>(&self.bvh, pre.o, pre.d, t_max, &mut c);
        (c.best.0 != u32::MAX).then_some(c.best)
    }

    /// Ray test of primitive `id` (a leaf primitive id from the traversal). With `ANALYTIC` (the
    /// scene has non-triangle primitives) the marker of one (NaN first vertex, see
    /// `SceneGeometry::tris`) is checked first, so that analytic primitives skip the triangle
    /// test; without, there are no markers and triangles pay nothing for the check.
    #[inline(always)]
    fn prim_intersect<const KZ: usize, const ANALYTIC: bool>(
        &self,
        id: u32,
        pre: &RayPre,
        t_max: f32,
    ) -> Option<PrimT> {
        debug_assert!((id as usize) < self.tris.len());
        // SAFETY: leaf primitive ids index `tris` (same length as the builder's input).
        let v = unsafe { self.tris.get_unchecked(id as usize) };
        debug_assert!(ANALYTIC || !v[0].x.is_nan());
        if ANALYTIC && v[0].x.is_nan() {
            return self.others[v[1].x.to_bits() as usize].intersect::<KZ>(pre, t_max);
        }
        #[cfg(all(
            target_arch = "x86_64",
            target_feature = "avx2",
            target_feature = "fma"
        ))]
        return intersect_triangle_simd::<KZ>(pre, t_max, v);
        #[cfg(not(all(
            target_arch = "x86_64",
            target_feature = "avx2",
            target_feature = "fma"
        )))]
        super::prim::intersect_triangle::<KZ>(pre, t_max, v)
    }

    /// The hit record for primitive `prim` at ray parameter `t` (used after traversal and by
    /// brute-force tests).
    pub(super) fn make_hit(&self, prim: u32, pre: &RayPre, t: f32, a: f32, b: f32) -> Hit {
        self.hit_record(prim, pre.o, pre.d, t, a, b)
    }

    /// [`SceneGeometry::make_hit`] for the ray from `origin` along `dir`, inlined into
    /// [`SceneGeometry::intersect`] (the call and its ray data showed in profiles of small
    /// scenes).
    #[inline(always)]
    fn hit_record(&self, prim: u32, origin: Vec3, dir: Vec3, t: f32, a: f32, b: f32) -> Hit {
        let v = &self.tris[prim as usize];
        let g = if v[0].x.is_nan() {
            // Quads (the common analytic primitive) skip the ray data that only spheres and
            // disks need.
            match self.others[v[1].x.to_bits() as usize] {
                Prim::Quad {
                    origin: corner,
                    edge_u,
                    edge_v,
                    ref pre,
                } => super::prim::quad_hit_geom(corner, edge_u, edge_v, pre, a, b),
                ref p => p.hit_geom(&RayPre::new(origin, dir), t, a, b),
            }
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
        let mut tex = g.uv;
        if let Some(idx) = self.prim_uvs.get(prim as usize) {
            if idx[0] != u32::MAX {
                tex = g.bary.x * self.uvs[idx[0] as usize]
                    + g.bary.y * self.uvs[idx[1] as usize]
                    + g.bary.z * self.uvs[idx[2] as usize];
            }
        }
        Hit {
            t,
            p: g.p,
            ng: g.ng,
            ns,
            uv: g.uv,
            tex,
            prim,
            object: self.prim_object[prim as usize],
            instance: super::NO_INSTANCE,
            front_face: dir.dot(g.ng) < 0.0,
            error: g.error,
        }
    }

    /// [`SceneGeometry::hit_record`] in a scene of a few quads, which have neither vertex
    /// normals nor texture coordinates.
    #[inline(always)]
    fn small_hit(&self, prim: u32, dir: Vec3, t: f32, a: f32, b: f32) -> Hit {
        let g = self.small.hit_geom(prim, a, b);
        Hit {
            t,
            p: g.p,
            ng: g.ng,
            ns: g.ng,
            uv: g.uv,
            tex: g.uv,
            prim,
            object: self.prim_object[prim as usize],
            instance: super::NO_INSTANCE,
            front_face: dir.dot(g.ng) < 0.0,
            error: g.error,
        }
    }

    /// True if anything is hit with `t` in `(0, t_max)` (any-hit traversal, for shadow rays).
    /// Same ray conventions as [`SceneGeometry::intersect`].
    #[inline(always)]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        // A scene of a few quads and nothing else: the query in the caller.
        if self.small.active() && self.instances.is_none() {
            return Self::ray_ok(origin, dir, t_max) && self.small.occluded(origin, dir, t_max);
        }
        self.occluded_any(origin, dir, t_max)
    }

    /// [`SceneGeometry::occluded`] in any scene.
    #[inline(never)]
    fn occluded_any(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        if !Self::ray_ok(origin, dir, t_max) {
            return false;
        }
        if self.small.active() {
            if self.small.occluded(origin, dir, t_max) {
                return true;
            }
        } else if !self.tris.is_empty() {
            let pre = RayPre::new(origin, dir);
            let block = |_: u32, _: &RayPre, _: PrimT| false;
            let hit = match pre.kz {
                0 => self.any_hit::<0>(&pre, t_max, block),
                1 => self.any_hit::<1>(&pre, t_max, block),
                _ => self.any_hit::<2>(&pre, t_max, block),
            };
            if hit {
                return true;
            }
        }
        match &self.instances {
            Some(set) => set.any_hit(origin, dir, t_max, &mut |_, _| false),
            None => false,
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
        if !Self::ray_ok(origin, dir, t_max) {
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
        let blocked = !self.tris.is_empty()
            && match pre.kz {
                0 => self.any_hit::<0>(&pre, t_max, &mut pass),
                1 => self.any_hit::<1>(&pre, t_max, &mut pass),
                _ => self.any_hit::<2>(&pre, t_max, &mut pass),
            };
        if blocked {
            return true;
        }
        match &self.instances {
            // Instanced meshes are triangles: each crossing is one hit.
            Some(set) => set.any_hit(origin, dir, t_max, &mut |object, hit| {
                passes.get(object as usize).copied().unwrap_or(false) && crossed(&hit())
            }),
            None => false,
        }
    }

    /// Any-hit traversal; a hit primitive for which `pass(prim, ray, (t, a, b))` is true does
    /// not end it.
    #[inline(always)]
    pub(super) fn any_hit<const KZ: usize>(
        &self,
        pre: &RayPre,
        t_max: f32,
        pass: impl FnMut(u32, &RayPre, PrimT) -> bool,
    ) -> bool {
        if self.small.active() {
            return self.small.any_hit(pre.o, pre.d, t_max, pass);
        }
        if self.others.is_empty() {
            self.any_hit_in::<KZ, false>(pre, t_max, pass)
        } else {
            self.any_hit_in::<KZ, true>(pre, t_max, pass)
        }
    }

    /// [`SceneGeometry::any_hit`] for a scene with (`ANALYTIC`) or without non-triangle
    /// primitives.
    #[inline(always)]
    fn any_hit_in<const KZ: usize, const ANALYTIC: bool>(
        &self,
        pre: &RayPre,
        t_max: f32,
        pass: impl FnMut(u32, &RayPre, PrimT) -> bool,
    ) -> bool {
        struct AnyHit<'a, F, const KZ: usize, const ANALYTIC: bool> {
            geo: &'a SceneGeometry,
            pre: &'a RayPre,
            pass: F,
            hit: bool,
        }
        impl<F: FnMut(u32, &RayPre, PrimT) -> bool, const KZ: usize, const ANALYTIC: bool> LeafTest
            for AnyHit<'_, F, KZ, ANALYTIC>
        {
            #[inline(always)]
            fn leaf(&mut self, first: u32, unary: u32, t_max: f32) -> Option<f32> {
                let (mut id, mut u) = (first, unary);
                while u != 0 {
                    if let Some(h) = self.geo.prim_intersect::<KZ, ANALYTIC>(id, self.pre, t_max) {
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
        let mut a = AnyHit::<_, KZ, ANALYTIC> {
            geo: self,
            pre,
            pass,
            hit: false,
        };
        traverse::<false>(&self.bvh, pre.o, pre.d, t_max, &mut a);
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
        let flat = best.map(|(i, a, b)| self.make_hit(i, &pre, tmax, a, b));
        match &self.instances {
            Some(set) => set.brute_force(origin, dir, tmax).or(flat),
            None => flat,
        }
    }
}
