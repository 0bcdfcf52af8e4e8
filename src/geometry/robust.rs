//! Floating-point error bounds and robust ray spawning (pbrt-v4 §6.8 style).

use super::Hit;
use glam::Vec3;

/// Unit roundoff of f32 (half an ulp of 1).
pub const MACHINE_EPSILON: f32 = f32::EPSILON * 0.5;

/// Fraction by which [`shadow_ray`] shortens the segment toward the target (relative, pbrt's
/// `ShadowEpsilon`), on top of offsetting both ends.
pub const SHADOW_EPSILON: f32 = 1e-4;

/// γ(n) = nε / (1 − nε), the classic bound on the relative error of n rounded operations.
#[inline]
pub fn gamma(n: i32) -> f32 {
    let ne = n as f32 * MACHINE_EPSILON;
    ne / (1.0 - ne)
}

/// Smallest float strictly greater than `v` (for finite `v`; +∞ stays +∞).
#[inline]
pub fn next_float_up(v: f32) -> f32 {
    if v.is_infinite() && v > 0.0 {
        return v;
    }
    let v = if v == -0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v >= 0.0 { bits + 1 } else { bits - 1 };
    f32::from_bits(bits)
}

/// Largest float strictly smaller than `v`.
#[inline]
pub fn next_float_down(v: f32) -> f32 {
    if v.is_infinite() && v < 0.0 {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v > 0.0 { bits - 1 } else { bits + 1 };
    f32::from_bits(bits)
}

/// A conservative per-axis error bound for a point that was computed to (near) full f32
/// precision from f64 arithmetic, e.g. the points returned by `SceneGeometry::sample_prim`,
/// or a point given by the caller without a known error. Scale-independent (relative).
#[inline]
pub fn point_error_bound(p: Vec3) -> Vec3 {
    p.abs() * gamma(8) + Vec3::splat(f32::MIN_POSITIVE)
}

/// Robust origin for a ray leaving surface point `p` (with per-axis absolute error bound
/// `error`, e.g. [`Hit::error`]) whose geometric normal is `ng` (unit, either orientation), in
/// direction `w`.
///
/// The point is pushed along ±`ng` (to the side `w` points to) just far enough to leave the
/// box of uncertainty around `p`, then rounded away from `p`, so that a ray from the returned
/// origin cannot re-intersect the surface it starts on (no acne) — at any scene scale, since
/// the offset is proportional to the floating-point error of `p` (Ray Tracing Gems ch. 6 /
/// pbrt-v4 `OffsetRayOrigin`). The offset is tiny (≈ 1e-6 relative to |p|), so contact
/// shadows are preserved. A ray into the surface (`dot(w, ng) < 0`) starts just below it.
#[inline(always)]
pub fn offset_ray_origin(p: Vec3, error: Vec3, ng: Vec3, w: Vec3) -> Vec3 {
    let d = ng.abs().dot(error);
    let d = if w.dot(ng) < 0.0 { -d } else { d };
    let offset = ng * d;
    step_toward3(p + offset, offset)
}

/// [`step_toward`] of each component. Both neighbours are computed and one selected: the sign
/// of the offset is data-dependent, and branching on it mispredicted often enough to show in
/// profiles. On x86-64 the three components are stepped side by side in SSE lanes, with the
/// same integer operations as [`step_toward`].
#[inline(always)]
fn step_toward3(v: Vec3, dir: Vec3) -> Vec3 {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE2 is part of x86-64; only register operations.
    unsafe {
        use std::arch::x86_64::*;
        let vf = _mm_setr_ps(v.x, v.y, v.z, 0.0);
        let df = _mm_setr_ps(dir.x, dir.y, dir.z, 0.0);
        let (vb, db) = (_mm_castps_si128(vf), _mm_castps_si128(df));
        let sign = _mm_set1_epi32(i32::MIN);
        let one = _mm_set1_epi32(1);
        // All ones where v and dir differ in sign (a step toward zero), else 0.
        let toward = _mm_srai_epi32::<31>(_mm_xor_si128(vb, db));
        // v + 1 away from zero, v − 1 toward it.
        let stepped = _mm_add_epi32(vb, _mm_or_si128(toward, one));
        // ±0 steps to the smallest subnormal of dir's sign.
        let from_zero = _mm_or_si128(_mm_and_si128(db, sign), one);
        let is_zero = _mm_cmpeq_epi32(_mm_slli_epi32::<1>(vb), _mm_setzero_si128());
        let select = |m: __m128i, a: __m128i, b: __m128i| {
            _mm_or_si128(_mm_and_si128(m, a), _mm_andnot_si128(m, b))
        };
        let bits = select(is_zero, from_zero, stepped);
        // v unchanged for dir = ±0, a NaN v, and an infinite v moving out.
        let dir_zero = _mm_castps_si128(_mm_cmpeq_ps(df, _mm_setzero_ps()));
        let v_nan = _mm_castps_si128(_mm_cmpunord_ps(vf, vf));
        let v_inf = _mm_cmpeq_epi32(_mm_andnot_si128(sign, vb), _mm_set1_epi32(0x7f80_0000));
        let keep = _mm_or_si128(
            _mm_or_si128(dir_zero, v_nan),
            _mm_andnot_si128(toward, v_inf),
        );
        let mut out = [0.0f32; 4];
        _mm_storeu_ps(out.as_mut_ptr(), _mm_castsi128_ps(select(keep, vb, bits)));
        Vec3::new(out[0], out[1], out[2])
    }
    #[cfg(not(target_arch = "x86_64"))]
    Vec3::new(
        step_toward(v.x, dir.x),
        step_toward(v.y, dir.y),
        step_toward(v.z, dir.z),
    )
}

/// `v` moved one ulp toward the sign of `dir` (unchanged for `dir` = 0, NaN, and ±∞ moving out):
/// the same as [`next_float_up`] / [`next_float_down`], on the bit pattern without branches
/// (the sign of the offset is data-dependent, and the branchy version showed in profiles).
/// (On x86-64 only the reference of [`step_toward3`]'s tests.)
#[cfg_attr(target_arch = "x86_64", allow(dead_code))]
#[inline(always)]
fn step_toward(v: f32, dir: f32) -> f32 {
    let (vb, db) = (v.to_bits(), dir.to_bits());
    // Away from zero when v and dir have the same sign, toward zero otherwise.
    let away = (vb ^ db) >> 31 == 0;
    let stepped = if away {
        vb.wrapping_add(1)
    } else {
        vb.wrapping_sub(1)
    };
    // ±0 steps to the smallest subnormal of dir's sign.
    let from_zero = (db & 0x8000_0000) | 1;
    let bits = if vb << 1 == 0 { from_zero } else { stepped };
    if dir == 0.0 || v.is_nan() || (away && v.is_infinite()) {
        v
    } else {
        f32::from_bits(bits)
    }
}

/// A shadow ray from a hit to a target surface point (`to_point` with unit normal `to_normal`,
/// e.g. a light sample from `SceneGeometry::sample_prim`). Both ends are offset (the target
/// with [`point_error_bound`]) and the segment is additionally shortened by
/// [`SHADOW_EPSILON`] (relative), so neither surface occludes the ray.
///
/// Returns `(origin, unit direction, t_max)` for `SceneGeometry::occluded`. If the two points
/// coincide, `t_max` is 0 (never occluded).
pub fn shadow_ray(from: &Hit, to_point: Vec3, to_normal: Vec3) -> (Vec3, Vec3, f32) {
    shadow_ray_between(
        from.p,
        from.error,
        from.ng,
        to_point,
        point_error_bound(to_point),
        to_normal,
    )
}

/// General form of [`shadow_ray`] with explicit error bounds at both ends. A zero normal at
/// either end means "a point not on a surface" (no offset at that end).
#[inline]
pub fn shadow_ray_between(
    from_p: Vec3,
    from_error: Vec3,
    from_n: Vec3,
    to_p: Vec3,
    to_error: Vec3,
    to_n: Vec3,
) -> (Vec3, Vec3, f32) {
    let o = offset_ray_origin(from_p, from_error, from_n, to_p - from_p);
    let pt = offset_ray_origin(to_p, to_error, to_n, o - to_p);
    let d = pt - o;
    let len = d.length();
    if !(len > 0.0 && len.is_finite()) {
        return (o, Vec3::Z, 0.0);
    }
    (o, d / len, len * (1.0 - SHADOW_EPSILON))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_toward_is_next_float_up_or_down() {
        let values = [
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            3.5e-39,
            -3.5e-39,
            f32::MIN_POSITIVE,
            123.456,
            -7.0e20,
            f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        for v in values {
            for d in [1.0f32, -2.0, 0.0, -0.0] {
                let got = step_toward(v, d);
                let want = if d > 0.0 {
                    next_float_up(v)
                } else if d < 0.0 {
                    next_float_down(v)
                } else {
                    v
                };
                assert!(
                    got.to_bits() == want.to_bits() || (got == 0.0 && want == 0.0),
                    "step_toward({v:e}, {d}) = {got:e}, want {want:e}"
                );
            }
        }
    }

    #[test]
    fn step_toward3_is_step_toward_per_component() {
        let values = [
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            3.5e-39,
            -3.5e-39,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            123.456,
            -7.0e20,
            f32::MAX,
            -f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        for (i, &a) in values.iter().enumerate() {
            for (j, &b) in values.iter().enumerate() {
                let c = values[(i + j) % values.len()];
                let (v, d) = (Vec3::new(a, b, c), Vec3::new(b, c, a));
                let got = step_toward3(v, d);
                for k in 0..3 {
                    let want = step_toward(v[k], d[k]);
                    assert!(
                        got[k].to_bits() == want.to_bits(),
                        "step_toward3 component {k}: ({:e}, {:e}) gave {:e}, want {want:e}",
                        v[k],
                        d[k],
                        got[k]
                    );
                }
            }
        }
    }

    #[test]
    fn next_float() {
        assert!(next_float_up(1.0) > 1.0);
        assert!(next_float_down(1.0) < 1.0);
        assert!(next_float_up(0.0) > 0.0);
        assert!(next_float_up(-0.0) > 0.0);
        assert!(next_float_down(0.0) < 0.0);
        assert!(next_float_up(-1.0) > -1.0);
        assert!(next_float_down(-1.0) < -1.0);
        assert_eq!(next_float_up(f32::INFINITY), f32::INFINITY);
    }

    #[test]
    fn offset_side() {
        let p = Vec3::new(1e3, 2e3, 0.0);
        let e = point_error_bound(p);
        let o = offset_ray_origin(p, e, Vec3::Z, Vec3::new(0.3, 0.0, 1.0));
        assert!(o.z > 0.0);
        let o = offset_ray_origin(p, e, Vec3::Z, Vec3::new(0.3, 0.0, -1.0));
        assert!(o.z < 0.0);
    }
}
