//! Bounds of a set of lights for the light BVH ([`super::bvh`]): where they are (a box, m),
//! how much they emit (a power φ, lm) and toward which directions (two cones), and the
//! importance a node of lights has for a shading point: an upper bound, up to a constant, of
//! the illuminance the lights can send there (Conty Estevez & Kulla 2018).
//!
//! Directions: every emitter in the set has its emission axis within `cos_o` (θ_o) of `w`, and
//! emits only within θ_e (`cos_e`) of its own axis. So no light in the set sends anything
//! along a direction more than θ_o + θ_e from `w`:
//! - a one-sided flat primitive: its front normal, θ_o = 0, θ_e = π/2;
//! - a two-sided flat primitive: `two_sided` (directions are folded onto the axis' side);
//! - a sphere primitive, an isotropic point light: the whole sphere, θ_o = π;
//! - a spot: its axis, θ_o = the outer half-angle; a goniometric luminaire: the cone of its
//!   table's non-zero directions ([`super::goniometric::GoniometricLight::emission_cone`]).
//!   Point-like sources have no cosine falloff, so they get a tiny θ_e ([`POINT_SPREAD`]):
//!   zero importance outside their support, ≈ 1 inside.

use glam::Vec3;
use std::f32::consts::{FRAC_PI_2, PI};

/// θ_e (rad) of point-like sources: a margin that absorbs rounding in the angle tests, so a
/// direction on the edge of a cone never gets zero importance.
pub const POINT_SPREAD: f32 = 0.01;

/// Smallest clamped squared distance, m², so a shading point on a point light stays finite.
const MIN_DIST2: f32 = 1e-12;

/// Floor of the bound on the receiver's |cos θ_i|: a light exactly in the tangent plane sends
/// nothing, but the caller's own cosine may round to a tiny positive value there, which must
/// not meet a zero probability.
const MIN_COS_I: f32 = 1e-4;

/// A cone of unit directions: axis `w` and cosine of the half-angle (`cos_theta` = −1: the
/// whole sphere).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    pub w: Vec3,
    pub cos_theta: f32,
}

impl Cone {
    pub const SPHERE: Cone = Cone {
        w: Vec3::Z,
        cos_theta: -1.0,
    };

    /// The smallest cone (up to a safety margin) containing `a` and `b`.
    pub fn union(a: Cone, b: Cone) -> Cone {
        let ta = a.cos_theta.clamp(-1.0, 1.0).acos();
        let tb = b.cos_theta.clamp(-1.0, 1.0).acos();
        let td = angle_between(a.w, b.w);
        if (td + tb).min(PI) <= ta {
            return a;
        }
        if (td + ta).min(PI) <= tb {
            return b;
        }
        // The new cone spans from a's far edge to b's far edge along the great circle through
        // both axes; a small margin covers the rounding of the rotation below.
        let t = 0.5 * (ta + td + tb) + 1e-4;
        if t >= PI {
            return Cone::SPHERE;
        }
        let axis = a.w.cross(b.w);
        let len = axis.length();
        if len < 1e-6 {
            return Cone::SPHERE;
        }
        // Rotate a.w toward b.w by t − ta about their common normal (Rodrigues, axis ⟂ a.w).
        let k = axis / len;
        let r = t - ta;
        let w = (a.w * r.cos() + k.cross(a.w) * r.sin()).normalize();
        Cone {
            w,
            cos_theta: t.cos(),
        }
    }
}

/// Angle (rad) between unit vectors, accurate near 0 and π.
fn angle_between(a: Vec3, b: Vec3) -> f32 {
    if a.dot(b) < 0.0 {
        PI - 2.0 * ((a + b).length() * 0.5).clamp(-1.0, 1.0).asin()
    } else {
        2.0 * ((b - a).length() * 0.5).clamp(-1.0, 1.0).asin()
    }
}

#[inline]
fn sin_of(cos: f32) -> f32 {
    (1.0 - cos * cos).max(0.0).sqrt()
}

/// Bounds of one light (a leaf) or of a node's lights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightBounds {
    /// Box containing every emitting point, m.
    pub lo: Vec3,
    pub hi: Vec3,
    /// Power, lm: π L A × sides for area primitives, 4π × peak intensity for point-like
    /// sources (the flux an isotropic source of that intensity would emit).
    pub phi: f32,
    /// Cone containing every emitter's axis (θ_o).
    pub axes: Cone,
    /// Cosine of the spread θ_e ≤ π/2 of emission around each emitter's axis.
    pub cos_e: f32,
    /// Some emitter emits on both sides of its axis: directions are compared to ±w.
    pub two_sided: bool,
}

impl LightBounds {
    pub fn centroid(&self) -> Vec3 {
        0.5 * (self.lo + self.hi)
    }

    /// The bounds of the lights of `a` and of `b` together.
    pub fn union(a: &LightBounds, b: &LightBounds) -> LightBounds {
        if a.phi <= 0.0 {
            return *b;
        }
        if b.phi <= 0.0 {
            return *a;
        }
        LightBounds {
            lo: a.lo.min(b.lo),
            hi: a.hi.max(b.hi),
            phi: a.phi + b.phi,
            axes: Cone::union(a.axes, b.axes),
            cos_e: a.cos_e.min(b.cos_e),
            two_sided: a.two_sided || b.two_sided,
        }
    }

    /// Solid-angle measure of the emitted directions (M_Ω of Conty Estevez & Kulla), sr.
    fn orientation_measure(&self) -> f32 {
        let theta_o = self.axes.cos_theta.clamp(-1.0, 1.0).acos();
        let theta_e = self.cos_e.clamp(-1.0, 1.0).acos();
        let theta_w = (theta_o + theta_e).min(PI);
        let (sin_o, cos_o) = theta_o.sin_cos();
        2.0 * PI * (1.0 - cos_o)
            + FRAC_PI_2
                * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o
                    + cos_o)
    }

    /// Cost of a node with these bounds for the build (surface area–orientation heuristic):
    /// φ × M_Ω × box area, with `kr` the regularisation for thin boxes.
    pub fn cost(&self, kr: f32) -> f32 {
        let d = (self.hi - self.lo).max(Vec3::ZERO);
        let area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
        self.phi * self.orientation_measure() * area.max(1e-12) * kr
    }

    /// Importance for a receiver at `p` (m) with unit normal `n`; see
    /// [`NodeBounds::importance`].
    pub fn importance(&self, p: Vec3, n: Option<Vec3>) -> f32 {
        NodeBounds::from(self).importance(p, n)
    }
}

/// [`LightBounds`] as the light BVH's nodes keep them for sampling: what the importance of
/// every shading point needs, with the bounding sphere and sin θ_o computed once.
#[derive(Clone, Copy, Debug)]
pub struct NodeBounds {
    /// Centre of the box, and radius and squared radius of its bounding sphere, m and m².
    centre: Vec3,
    r: f32,
    r2: f32,
    /// Power, lm.
    pub phi: f32,
    w: Vec3,
    cos_o: f32,
    sin_o: f32,
    cos_e: f32,
    two_sided: bool,
}

impl From<&LightBounds> for NodeBounds {
    fn from(b: &LightBounds) -> Self {
        let r2 = 0.25 * (b.hi - b.lo).length_squared();
        NodeBounds {
            centre: b.centroid(),
            r: r2.sqrt(),
            r2,
            phi: b.phi,
            w: b.axes.w,
            cos_o: b.axes.cos_theta,
            sin_o: sin_of(b.axes.cos_theta),
            cos_e: b.cos_e,
            two_sided: b.two_sided,
        }
    }
}

impl NodeBounds {
    /// Importance for a receiver at `p` (m) with unit normal `n` (None: a point without a
    /// surface, e.g. inside a medium): φ × bounded cos at the emitter × bounded |cos| at the
    /// receiver / clamped squared distance, lm·m⁻². It is zero only where no light of the
    /// bounds can send anything to `p` (or every light lies exactly in the tangent plane).
    #[inline]
    pub fn importance(&self, p: Vec3, n: Option<Vec3>) -> f32 {
        let (n, has_n) = match n {
            Some(n) => (n, true),
            None => (Vec3::ZERO, false),
        };
        self.importance_of_lane(p, n, has_n)
    }

    /// [`NodeBounds::importance`] (`has_n` false: no normal), with every branch a select so
    /// that [`Bounds8`] computes eight lanes side by side in SIMD. The direction to p is never
    /// normalised: with d = |p − c|, the cosines and sines of the angles at p are kept as d
    /// times their value (d² for the final one), which leaves one division (1/d²) and no
    /// chain of square root then division.
    #[inline(always)]
    fn importance_of_lane(&self, p: Vec3, n: Vec3, has_n: bool) -> f32 {
        let (r, r2, phi) = (self.r, self.r2, self.phi);
        let (vx, vy, vz) = (
            p.x - self.centre.x,
            p.y - self.centre.y,
            p.z - self.centre.z,
        );
        let dist2 = vx * vx + vy * vy + vz * vz;
        let inside = dist2 <= r2 || dist2 == 0.0 || !dist2.is_finite();
        // Inside the bounding sphere: every direction is possible.
        let inside_value = if dist2.is_nan() {
            0.0
        } else {
            phi / r2.max(MIN_DIST2)
        };
        let d = dist2.sqrt();
        let inv_dist2 = 1.0 / dist2;
        // d cos θ_b, d sin θ_b: the half-angle θ_b of the cone from p holding the sphere.
        let cb = (dist2 - r2).max(0.0).sqrt();
        let sb = r;
        // d cos θ_w, d sin θ_w: the angle between the axis w and the direction c → p.
        let a0 = self.w.x * vx + self.w.y * vy + self.w.z * vz;
        let a = if self.two_sided { a0.abs() } else { a0 };
        let s = (dist2 - a * a).max(0.0).sqrt();
        let (cos_o, sin_o) = (self.cos_o, self.sin_o);
        // d cos θ_x, d sin θ_x, θ_x = max(0, θ_w − θ_o).
        let within_o = a > cos_o * d;
        let x = if within_o { d } else { a * cos_o + s * sin_o };
        let y = if within_o { 0.0 } else { s * cos_o - a * sin_o };
        // θ' = max(0, θ_x − θ_b): the smallest angle between an emitter's axis and the
        // direction from one of its points to p; cos θ' from d² cos θ'.
        let cos_p = if x > cb { dist2 } else { x * cb + y * sb } * inv_dist2;
        // 1 / max(d², MIN_DIST2) (outside the sphere d² > r²).
        let mut imp = phi * cos_p * inv_dist2.min(1.0 / MIN_DIST2);
        // d |cos θ_i|, d sin θ_i at the receiver; its bound is cos max(0, θ_i − θ_b).
        let ci = (n.x * vx + n.y * vy + n.z * vz).abs().min(d);
        let si = (dist2 - ci * ci).max(0.0).sqrt();
        let f_i = if ci > cb {
            1.0
        } else {
            (ci * cb + si * sb) * inv_dist2
        }
        .max(MIN_COS_I);
        if has_n {
            imp *= f_i;
        }
        let outside_value = if cos_p <= self.cos_e {
            0.0
        } else {
            imp.max(0.0)
        };
        let v = if inside { inside_value } else { outside_value };
        if phi <= 0.0 {
            0.0
        } else {
            v
        }
    }
}

/// Up to [`WIDTH`] [`NodeBounds`] side by side (one per lane), the children of a node of the
/// light BVH: their importances for one shading point are computed together, each lane with
/// the arithmetic of [`NodeBounds::importance`] (so it equals it bit for bit), in a form the
/// compiler turns into SIMD. An empty lane has φ = 0 and importance 0.
#[derive(Clone, Copy, Debug, Default)]
pub struct Bounds8 {
    cx: [f32; WIDTH],
    cy: [f32; WIDTH],
    cz: [f32; WIDTH],
    r: [f32; WIDTH],
    r2: [f32; WIDTH],
    /// Power of each lane, lm.
    pub phi: [f32; WIDTH],
    wx: [f32; WIDTH],
    wy: [f32; WIDTH],
    wz: [f32; WIDTH],
    cos_o: [f32; WIDTH],
    sin_o: [f32; WIDTH],
    cos_e: [f32; WIDTH],
    /// 1 where the lane's emitters are two-sided, else 0.
    two_sided: [f32; WIDTH],
}

/// Lanes of [`Bounds8`]: eight f32 fill one AVX register.
pub const WIDTH: usize = 8;

impl Bounds8 {
    /// Put `b` into lane `i` (< [`WIDTH`]).
    pub fn set(&mut self, i: usize, b: &NodeBounds) {
        self.cx[i] = b.centre.x;
        self.cy[i] = b.centre.y;
        self.cz[i] = b.centre.z;
        self.r[i] = b.r;
        self.r2[i] = b.r2;
        self.phi[i] = b.phi;
        self.wx[i] = b.w.x;
        self.wy[i] = b.w.y;
        self.wz[i] = b.w.z;
        self.cos_o[i] = b.cos_o;
        self.sin_o[i] = b.sin_o;
        self.cos_e[i] = b.cos_e;
        self.two_sided[i] = if b.two_sided { 1.0 } else { 0.0 };
    }

    /// The lanes' importances for a receiver at `p` with unit normal `n` (see
    /// [`NodeBounds::importance`]), lm·m⁻².
    #[inline]
    pub fn importance(&self, p: Vec3, n: Option<Vec3>) -> [f32; WIDTH] {
        let (n, has_n) = match n {
            Some(n) => (n, true),
            None => (Vec3::ZERO, false),
        };
        let mut out = [0.0f32; WIDTH];
        for (i, out) in out.iter_mut().enumerate() {
            *out = NodeBounds {
                centre: Vec3::new(self.cx[i], self.cy[i], self.cz[i]),
                r: self.r[i],
                r2: self.r2[i],
                phi: self.phi[i],
                w: Vec3::new(self.wx[i], self.wy[i], self.wz[i]),
                cos_o: self.cos_o[i],
                sin_o: self.sin_o[i],
                cos_e: self.cos_e[i],
                two_sided: self.two_sided[i] != 0.0,
            }
            .importance_of_lane(p, n, has_n);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rand_dir(s: &mut u64) -> Vec3 {
        let mut next = || crate::sampling::test_uniform(s);
        let z = 1.0 - 2.0 * next();
        let phi = 2.0 * PI * next();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    #[test]
    fn lanes_equal_the_scalar_importance_bit_for_bit() {
        let mut s = 11u64;
        let next = |s: &mut u64| rand_dir(s).x;
        for trial in 0..4000 {
            let mut b8 = Bounds8::default();
            let mut scalar = Vec::new();
            let lanes = 1 + trial % WIDTH;
            for i in 0..lanes {
                let c = 3.0 * rand_dir(&mut s);
                let half = 0.5 * rand_dir(&mut s).abs() * if trial % 7 == 0 { 0.0 } else { 1.0 };
                let b = LightBounds {
                    lo: c - half,
                    hi: c + half,
                    phi: if trial % 13 == 0 {
                        0.0
                    } else {
                        10.0 * next(&mut s).abs()
                    },
                    axes: Cone {
                        w: rand_dir(&mut s),
                        cos_theta: rand_dir(&mut s).z,
                    },
                    cos_e: if i % 2 == 0 { 0.0 } else { POINT_SPREAD.cos() },
                    two_sided: trial % 3 == 0,
                };
                let nb = NodeBounds::from(&b);
                b8.set(i, &nb);
                scalar.push(nb);
            }
            // Receivers far, near, inside a bounding sphere, on a centre; with and without n.
            let p = match trial % 4 {
                0 => 5.0 * rand_dir(&mut s),
                1 => 0.5 * rand_dir(&mut s),
                2 => scalar[0].centre,
                _ => 3.0 * rand_dir(&mut s),
            };
            let n = (trial % 5 != 0).then(|| rand_dir(&mut s));
            let got = b8.importance(p, n);
            for (i, got) in got.iter().enumerate() {
                let want = scalar.get(i).map_or(0.0, |b| b.importance(p, n));
                assert_eq!(
                    got.to_bits(),
                    want.to_bits(),
                    "trial {trial} lane {i}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn cone_union_contains_both_cones() {
        let mut s = 7u64;
        for _ in 0..2000 {
            let a = Cone {
                w: rand_dir(&mut s),
                cos_theta: rand_dir(&mut s).z,
            };
            let b = Cone {
                w: rand_dir(&mut s),
                cos_theta: rand_dir(&mut s).z,
            };
            let u = Cone::union(a, b);
            let tu = u.cos_theta.clamp(-1.0, 1.0).acos();
            for c in [a, b] {
                let tc = c.cos_theta.clamp(-1.0, 1.0).acos();
                let d = angle_between(u.w, c.w);
                assert!(
                    d + tc <= tu + 1e-4 || tu >= PI - 1e-6,
                    "{a:?} ∪ {b:?} = {u:?} misses {c:?}"
                );
            }
        }
    }

    #[test]
    fn one_sided_primitive_is_dark_behind_and_bright_in_front() {
        let b = LightBounds {
            lo: Vec3::new(-0.5, 2.0, -0.5),
            hi: Vec3::new(0.5, 2.0, 0.5),
            phi: 100.0,
            axes: Cone {
                w: -Vec3::Y,
                cos_theta: 1.0,
            },
            cos_e: 0.0,
            two_sided: false,
        };
        assert!(b.importance(Vec3::new(0.0, 0.0, 0.0), Some(Vec3::Y)) > 0.0);
        assert_eq!(b.importance(Vec3::new(0.0, 3.0, 0.0), None), 0.0);
        // A grazing point just below the plane, off to the side, still sees the emitter.
        assert!(b.importance(Vec3::new(3.0, 1.99, 0.0), None) > 0.0);
        assert_eq!(b.importance(Vec3::new(3.0, 3.0, 0.0), None), 0.0);
        // Two-sided: bright on both sides.
        let t = LightBounds {
            two_sided: true,
            ..b
        };
        assert!(t.importance(Vec3::new(0.0, 3.0, 0.0), None) > 0.0);
    }
}
