//! Primitive storage, ray–primitive intersection, hit construction and sampling.
//!
//! Triangles use the watertight test of Woop, Benthin & Wald (2013) as in pbrt-v4, with the
//! 2×2 edge determinants evaluated exactly-rounded in f64 and pbrt's conservative `t > δt`
//! check. Spheres, quads and disks are intersected in f64, which makes the side-of-surface
//! decisions essentially exact; together with [`super::offset_ray_origin`] this prevents
//! self-intersection at any scale. Quads carry their plane normal and dual edge vectors,
//! precomputed in f64, so that their test is a handful of dot products and one division.

use super::robust::gamma;
use glam::{DVec3, Vec2, Vec3};

#[derive(Clone, Copy, Debug)]
pub(crate) enum Prim {
    Triangle([Vec3; 3]),
    Sphere {
        center: Vec3,
        radius: f32,
    },
    /// Built with [`Prim::quad`], which fills in `pre`.
    Quad {
        origin: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
        pre: QuadPre,
    },
    /// `normal` is unit length.
    Disk {
        center: Vec3,
        normal: Vec3,
        radius: f32,
    },
}

/// A quad's ray-test data, in f64 from its f32 edges: the (unnormalized) plane normal
/// n = edge_u × edge_v and the dual edge vectors, which give the parameters of a point p of
/// the plane as s = du·(p − origin), t = dv·(p − origin).
#[derive(Clone, Copy, Debug)]
pub(crate) struct QuadPre {
    pub n: DVec3,
    /// n / |n| rounded to f32: the front-face normal.
    pub unit_n: Vec3,
    /// (edge_v × n) / |n|².
    pub du: DVec3,
    /// (n × edge_u) / |n|².
    pub dv: DVec3,
    /// The part of a hit point's error bound that the point's f64 evaluation contributes (see
    /// [`quad_hit_geom`]), which depends on the quad alone.
    pub err: Vec3,
}

impl Prim {
    /// The parallelogram origin + s·edge_u + t·edge_v, s, t ∈ \[0, 1\] (edges not parallel).
    pub fn quad(origin: Vec3, edge_u: Vec3, edge_v: Vec3) -> Prim {
        let (eu, ev) = (edge_u.as_dvec3(), edge_v.as_dvec3());
        let n = eu.cross(ev);
        let nn = n.length_squared();
        Prim::Quad {
            origin,
            edge_u,
            edge_v,
            pre: QuadPre {
                n,
                unit_n: n.normalize().as_vec3(),
                du: ev.cross(n) / nn,
                dv: n.cross(eu) / nn,
                err: f64_error(quad_point_magnitude(origin.as_dvec3(), eu, ev)),
            },
        }
    }
}

/// Per-ray precomputation shared by all primitive tests.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RayPre {
    pub o: Vec3,
    pub d: Vec3,
    pub od: DVec3,
    pub dd: DVec3,
    /// Index of the largest |direction| component (the triangle test's permuted z axis).
    pub kz: usize,
    /// Shear of the triangle test: x' = x + sx·z, y' = y + sy·z (permuted axes), z' = sz·z.
    pub sx: f32,
    pub sy: f32,
    pub sz: f32,
}

impl RayPre {
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        let ad = d.abs();
        // The largest |component| (the first of equal ones, z on ties with z), branch-free.
        let (m, i) = if ad.x > ad.y { (ad.x, 0) } else { (ad.y, 1) };
        let kz = if m > ad.z { i } else { 2 };
        let kx = (kz + 1) % 3;
        let ky = (kx + 1) % 3;
        let sz = 1.0 / d[kz];
        Self {
            o,
            d,
            od: o.as_dvec3(),
            dd: d.as_dvec3(),
            kz,
            sx: -d[kx] * sz,
            sy: -d[ky] * sz,
            sz,
        }
    }
}

/// a·b − c·d, correctly rounded (the f64 products of f32 values are exact), so its sign is exact.
#[inline(always)]
fn diff_of_products(a: f32, b: f32, c: f32, d: f32) -> f32 {
    (a as f64 * b as f64 - c as f64 * d as f64) as f32
}

/// Result of a primitive test: `t` and two parameters (triangle b1,b2; quad s,t; unused else).
pub(crate) type PrimT = (f32, f32, f32);

/// `KZ` must equal `r.kz` (monomorphised so the axis permutation is free).
#[inline(always)]
pub(crate) fn intersect_triangle<const KZ: usize>(
    r: &RayPre,
    t_max: f32,
    p: &[Vec3; 3],
) -> Option<PrimT> {
    debug_assert_eq!(KZ, r.kz);
    let perm = |v: Vec3| {
        let a = v.to_array();
        Vec3::new(a[(KZ + 1) % 3], a[(KZ + 2) % 3], a[KZ])
    };
    let mut p0t = perm(p[0] - r.o);
    let mut p1t = perm(p[1] - r.o);
    let mut p2t = perm(p[2] - r.o);
    p0t.x += r.sx * p0t.z;
    p0t.y += r.sy * p0t.z;
    p1t.x += r.sx * p1t.z;
    p1t.y += r.sy * p1t.z;
    p2t.x += r.sx * p2t.z;
    p2t.y += r.sy * p2t.z;
    let e0 = diff_of_products(p1t.x, p2t.y, p1t.y, p2t.x);
    let e1 = diff_of_products(p2t.x, p0t.y, p2t.y, p0t.x);
    let e2 = diff_of_products(p0t.x, p1t.y, p0t.y, p1t.x);
    if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
        return None;
    }
    triangle_tail(r, t_max, [p0t, p1t, p2t], [e0, e1, e2])
}

/// max(max(a, b), c) of values that are not NaN, without `f32::max`'s NaN handling (one
/// `maxss` each). In [`triangle_tail`] every NaN operand would already have made `t` NaN and
/// the test return `None`, and all operands are absolute values (no signed zeros), so this
/// gives the same results as `f32::max`.
#[inline(always)]
fn max3(a: f32, b: f32, c: f32) -> f32 {
    let m = if a > b { a } else { b };
    if m > c {
        m
    } else {
        c
    }
}

/// The rest of [`intersect_triangle`] once the edge functions `e` have the same sign: `pt`
/// are the vertices translated to the ray origin, permuted (z = dominant axis) and sheared in
/// x and y (not yet scaled in z).
#[inline(always)]
pub(crate) fn triangle_tail(r: &RayPre, t_max: f32, pt: [Vec3; 3], e: [f32; 3]) -> Option<PrimT> {
    let [mut p0t, mut p1t, mut p2t] = pt;
    let [e0, e1, e2] = e;
    let det = e0 + e1 + e2;
    if det == 0.0 {
        return None;
    }
    // Largest |z| before scaling by 1/d_z, in spatial units (pbrt uses the scaled z in δx/δy,
    // which mixes units and rejects valid hits for short, unnormalised directions).
    let max_zs = max3(p0t.z.abs(), p1t.z.abs(), p2t.z.abs());
    p0t.z *= r.sz;
    p1t.z *= r.sz;
    p2t.z *= r.sz;
    let t_scaled = e0 * p0t.z + e1 * p1t.z + e2 * p2t.z;
    if (det < 0.0 && t_scaled >= 0.0) || (det > 0.0 && t_scaled <= 0.0) {
        return None;
    }
    // Only the rounded t is compared with t_max (not t_scaled with t_max·det, which rounds
    // differently): a triangle then replaces the closest hit so far exactly when its t is
    // smaller, so the closest t does not depend on the order the triangles are tested in.
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;
    if t >= t_max || t.is_nan() {
        return None;
    }
    // Conservative check that t is positive despite rounding (pbrt-v4 §6.8.7; δx, δy in
    // spatial units, δz and t in ray-parameter units).
    let max_zt = max3(p0t.z.abs(), p1t.z.abs(), p2t.z.abs());
    let delta_z = gamma(3) * max_zt;
    let max_xt = max3(p0t.x.abs(), p1t.x.abs(), p2t.x.abs());
    let max_yt = max3(p0t.y.abs(), p1t.y.abs(), p2t.y.abs());
    let delta_x = gamma(5) * (max_xt + max_zs);
    let delta_y = gamma(5) * (max_yt + max_zs);
    let delta_e = 2.0 * (gamma(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
    let max_e = max3(e0.abs(), e1.abs(), e2.abs());
    let delta_t =
        3.0 * (gamma(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv_det.abs();
    if t <= delta_t {
        return None;
    }
    Some((t, e1 * inv_det, e2 * inv_det))
}

/// Roots of the ray–sphere quadratic in f64 with the numerically stable discriminant of
/// Ray Tracing Gems ch. 7. Returns the first root in (0, t_max) with a side-aware rule: a ray
/// starting outside the sphere and moving away cannot hit it; one starting inside only hits
/// the far root.
#[inline]
pub(crate) fn intersect_sphere(r: &RayPre, t_max: f32, center: Vec3, radius: f32) -> Option<PrimT> {
    let c = center.as_dvec3();
    let rad = radius as f64;
    let f = r.od - c;
    let a = r.dd.length_squared();
    let b = -f.dot(r.dd);
    let cc = f.length_squared() - rad * rad;
    let l = f + (b / a) * r.dd;
    let disc = a * (rad * rad - l.length_squared());
    if disc < 0.0 {
        return None;
    }
    let t = if cc > 0.0 {
        // Outside: only the near root, and only when moving toward the centre.
        if b <= 0.0 {
            return None;
        }
        let q = b + disc.sqrt();
        cc / q
    } else {
        // Inside (or exactly on the surface): the far root.
        let sq = disc.sqrt();
        if b >= 0.0 {
            (b + sq) / a
        } else {
            cc / (b - sq)
        }
    };
    let t32 = t as f32;
    (t > 0.0 && t32 > 0.0 && t32 < t_max).then_some((t32, 0.0, 0.0))
}

/// Ray–parallelogram test in f64. With w = origin − o, the plane's t is (w·n) / (d·n), and the
/// parameters of the plane point p = o + t·d are s = du·(p − origin) = (t·du·d − du·w) and
/// likewise for dv. Every rejection is decided before dividing, on t·(d·n) and s·(d·n): the
/// division's latency would otherwise hold up each (often mispredicted) branch.
#[inline(always)]
pub(crate) fn intersect_quad(r: &RayPre, t_max: f32, origin: Vec3, q: &QuadPre) -> Option<PrimT> {
    intersect_quad_f64(r.od, r.dd, t_max, origin, q)
}

/// [`intersect_quad`] of the ray with origin `od` and direction `dd` (in f64).
#[inline(always)]
pub(crate) fn intersect_quad_f64(
    od: DVec3,
    dd: DVec3,
    t_max: f32,
    origin: Vec3,
    q: &QuadPre,
) -> Option<PrimT> {
    let w = origin.as_dvec3() - od;
    let num = w.dot(q.n);
    let den = dd.dot(q.n);
    let den_abs = den.abs();
    // t > 0 (which also excludes den = 0) and t < t_max, the latter with a relative margin of
    // 1e-6 that covers the rounding of t to f32: the exact test follows the division.
    if !(num * den > 0.0 && num.abs() < den_abs * (t_max as f64 * (1.0 + 1e-6))) {
        return None;
    }
    // s·|d·n| and t·|d·n| (the parameters' sign follows d·n's; ×±1 is exact).
    let sign = if den < 0.0 { -1.0 } else { 1.0 };
    let sd = sign * (num * dd.dot(q.du) - den * w.dot(q.du));
    let vd = sign * (num * dd.dot(q.dv) - den * w.dot(q.dv));
    if !(sd >= 0.0 && sd <= den_abs && vd >= 0.0 && vd <= den_abs) {
        return None;
    }
    let t = num / den;
    let t32 = t as f32;
    if !(t > 0.0 && t32 > 0.0 && t32 < t_max) {
        return None;
    }
    let (a, b) = quad_params(sd, vd, den_abs);
    Some((t32, a, b))
}

/// A quad hit's parameters (s, t) from s·|d·n|, t·|d·n| and |d·n| (see [`intersect_quad_f64`]).
#[inline(always)]
pub(crate) fn quad_params(sd: f64, vd: f64, den_abs: f64) -> (f32, f32) {
    let inv = 1.0 / den_abs;
    (quad_param(sd * inv), quad_param(vd * inv))
}

/// A quad hit's parameter from its product with |d·n| times 1/|d·n| (see [`quad_params`]).
#[inline(always)]
pub(crate) fn quad_param(x: f64) -> f32 {
    // In [0, 1] up to the division's rounding, which `min` removes.
    (x as f32).min(1.0)
}

#[inline]
pub(crate) fn intersect_disk(
    r: &RayPre,
    t_max: f32,
    center: Vec3,
    normal: Vec3,
    radius: f32,
) -> Option<PrimT> {
    let (c, n) = (center.as_dvec3(), normal.as_dvec3().normalize());
    let den = r.dd.dot(n);
    if den == 0.0 {
        return None;
    }
    let t = (c - r.od).dot(n) / den;
    let t32 = t as f32;
    if !(t > 0.0 && t32 > 0.0 && t32 < t_max) {
        return None;
    }
    let mut rel = r.od + t * r.dd - c;
    rel -= rel.dot(n) * n;
    let rad = radius as f64;
    if rel.length_squared() > rad * rad {
        return None;
    }
    Some((t32, 0.0, 0.0))
}

/// Orthonormal basis (t, b) with t × b = n (Duff et al. 2017).
pub(crate) fn basis(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// Unit normal of the triangle's front face (computed in f64).
#[inline(always)]
fn triangle_normal(v: &[Vec3; 3]) -> Vec3 {
    let (a, b, c) = (v[0].as_dvec3(), v[1].as_dvec3(), v[2].as_dvec3());
    (b - a).cross(c - a).normalize().as_vec3()
}

/// [`Prim::hit_geom`] of a triangle with vertices `v` and barycentrics (b1, b2) = (a, b).
#[inline(always)]
pub(crate) fn triangle_hit_geom(v: &[Vec3; 3], a: f32, b: f32) -> HitGeom {
    let [p0, p1, p2] = *v;
    let b0 = 1.0 - a - b;
    let p = b0 * p0 + a * p1 + b * p2;
    let error = gamma(7) * ((b0 * p0).abs() + (a * p1).abs() + (b * p2).abs());
    HitGeom {
        p,
        ng: triangle_normal(v),
        uv: Vec2::new(a, b),
        error,
        bary: Vec3::new(b0, a, b),
    }
}

/// [`Prim::hit_geom`] of a quad at parameters (s, t) = (a, b).
#[inline(always)]
pub(crate) fn quad_hit_geom(
    origin: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
    q: &QuadPre,
    a: f32,
    b: f32,
) -> HitGeom {
    let (o, eu, ev) = (origin.as_dvec3(), edge_u.as_dvec3(), edge_v.as_dvec3());
    let (s, v) = (a as f64, b as f64);
    let p = (o + s * eu + v * ev).as_vec3();
    HitGeom {
        p,
        ng: q.unit_n,
        uv: Vec2::new(a, b),
        error: rounded_error_with(p, q.err),
        bary: Vec3::ZERO,
    }
}

/// The magnitude of the terms of a quad point's f64 evaluation (see [`quad_hit_geom`]).
fn quad_point_magnitude(o: DVec3, eu: DVec3, ev: DVec3) -> DVec3 {
    o.abs() + eu.abs() + ev.abs()
}

/// Geometric data of a hit, before shading normals and ids are filled in.
pub(crate) struct HitGeom {
    pub p: Vec3,
    pub ng: Vec3,
    pub uv: Vec2,
    pub error: Vec3,
    /// Barycentrics (b0, b1, b2) for triangles.
    pub bary: Vec3,
}

const F64_REL: f64 = 1.0 / (1u64 << 45) as f64;

/// Error bound of an f64-computed point rounded to f32, whose f64 evaluation involved terms of
/// magnitude `mag` per axis.
#[inline]
fn rounded_error(p: Vec3, mag: DVec3) -> Vec3 {
    rounded_error_with(p, f64_error(mag))
}

/// The f64 evaluation's part of [`rounded_error`].
fn f64_error(mag: DVec3) -> Vec3 {
    (mag * F64_REL).as_vec3()
}

/// [`rounded_error`] with its f64 part `f64_err` given.
#[inline(always)]
fn rounded_error_with(p: Vec3, f64_err: Vec3) -> Vec3 {
    p.abs() * gamma(2) + f64_err + Vec3::splat(f32::MIN_POSITIVE)
}

impl Prim {
    /// Ray test; `KZ` must equal `r.kz` (see [`Prim::intersect_dyn`]).
    #[inline(always)]
    pub fn intersect<const KZ: usize>(&self, r: &RayPre, t_max: f32) -> Option<PrimT> {
        match self {
            Prim::Triangle(p) => intersect_triangle::<KZ>(r, t_max, p),
            Prim::Sphere { center, radius } => intersect_sphere(r, t_max, *center, *radius),
            Prim::Quad { origin, pre, .. } => intersect_quad(r, t_max, *origin, pre),
            Prim::Disk {
                center,
                normal,
                radius,
            } => intersect_disk(r, t_max, *center, *normal, *radius),
        }
    }

    /// [`Prim::intersect`] dispatching on the ray's dominant axis at run time.
    pub fn intersect_dyn(&self, r: &RayPre, t_max: f32) -> Option<PrimT> {
        match r.kz {
            0 => self.intersect::<0>(r, t_max),
            1 => self.intersect::<1>(r, t_max),
            _ => self.intersect::<2>(r, t_max),
        }
    }

    pub fn bounds(&self) -> (Vec3, Vec3) {
        match *self {
            Prim::Triangle([a, b, c]) => (a.min(b).min(c), a.max(b).max(c)),
            Prim::Sphere { center, radius } => (center - radius, center + radius),
            Prim::Quad {
                origin,
                edge_u,
                edge_v,
                ..
            } => {
                let pts = [
                    origin,
                    origin + edge_u,
                    origin + edge_v,
                    origin + edge_u + edge_v,
                ];
                let mut lo = pts[0];
                let mut hi = pts[0];
                for q in pts {
                    lo = lo.min(q);
                    hi = hi.max(q);
                }
                (lo, hi)
            }
            Prim::Disk {
                center,
                normal,
                radius,
            } => {
                let n2 = normal * normal;
                let e = (Vec3::ONE - n2).max(Vec3::ZERO).sqrt() * radius;
                (center - e, center + e)
            }
        }
    }

    pub fn area(&self) -> f32 {
        match *self {
            Prim::Triangle([a, b, c]) => {
                let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
                (0.5 * (b - a).cross(c - a).length()) as f32
            }
            Prim::Sphere { radius, .. } => {
                (4.0 * std::f64::consts::PI * radius as f64 * radius as f64) as f32
            }
            Prim::Quad { edge_u, edge_v, .. } => {
                edge_u.as_dvec3().cross(edge_v.as_dvec3()).length() as f32
            }
            Prim::Disk { radius, .. } => {
                (std::f64::consts::PI * radius as f64 * radius as f64) as f32
            }
        }
    }

    /// Unit front-face normal (for flat primitives; spheres: at `p`).
    pub fn normal_at(&self, p: Vec3) -> Vec3 {
        match *self {
            Prim::Triangle(v) => triangle_normal(&v),
            Prim::Sphere { center, .. } => (p.as_dvec3() - center.as_dvec3()).normalize().as_vec3(),
            Prim::Quad { pre, .. } => pre.unit_n,
            Prim::Disk { normal, .. } => normal.as_dvec3().normalize().as_vec3(),
        }
    }

    /// Full hit geometry for a hit found by [`Prim::intersect`].
    pub fn hit_geom(&self, r: &RayPre, t: f32, a: f32, b: f32) -> HitGeom {
        match *self {
            Prim::Triangle(v) => triangle_hit_geom(&v, a, b),
            Prim::Sphere { center, radius } => {
                let c = center.as_dvec3();
                let ph = r.od + t as f64 * r.dd;
                let mut n = (ph - c).normalize();
                if !n.is_finite() {
                    n = DVec3::Z;
                }
                let p = (c + n * radius as f64).as_vec3();
                HitGeom {
                    p,
                    ng: n.as_vec3(),
                    uv: sphere_uv(n),
                    error: rounded_error(p, c.abs() + DVec3::splat(radius as f64)),
                    bary: Vec3::ZERO,
                }
            }
            Prim::Quad {
                origin,
                edge_u,
                edge_v,
                pre,
            } => quad_hit_geom(origin, edge_u, edge_v, &pre, a, b),
            Prim::Disk {
                center,
                normal,
                radius,
            } => {
                let (c, n) = (center.as_dvec3(), normal.as_dvec3().normalize());
                let mut rel = r.od + t as f64 * r.dd - c;
                rel -= rel.dot(n) * n;
                let p = (c + rel).as_vec3();
                HitGeom {
                    p,
                    ng: n.as_vec3(),
                    uv: disk_uv(rel, n, radius),
                    error: rounded_error(p, c.abs() + DVec3::splat(radius as f64)),
                    bary: Vec3::ZERO,
                }
            }
        }
    }

    /// Uniform-by-area sample: (point, unit front-face normal). Computed in f64, so the point
    /// is accurate to f32 rounding (error bound: [`super::point_error_bound`]).
    pub fn sample_area(&self, u: Vec2) -> (Vec3, Vec3) {
        let (u0, u1) = (u.x as f64, u.y as f64);
        match *self {
            Prim::Triangle(v) => {
                let p = flat_point(v, true, u);
                (p, self.normal_at(p))
            }
            Prim::Sphere { center, radius } => {
                let n = crate::sampling::uniform_sphere_f64(u0, u1);
                let p = center.as_dvec3() + n * radius as f64;
                (p.as_vec3(), n.as_vec3())
            }
            Prim::Quad {
                origin,
                edge_u,
                edge_v,
                ..
            } => {
                let p = flat_point([origin, edge_u, edge_v], false, u);
                (p, self.normal_at(p))
            }
            Prim::Disk {
                center,
                normal,
                radius,
            } => {
                let (r, phi) = crate::sampling::concentric_disk_polar(u0, u1);
                let n = normal.as_dvec3().normalize();
                let (tu, tv) = basis(n);
                let rad = radius as f64 * r;
                let p = center.as_dvec3() + rad * (phi.cos() * tu + phi.sin() * tv);
                (p.as_vec3(), n.as_vec3())
            }
        }
    }
}

/// The point uniform by area for `u` ∈ [0, 1)², computed in f64, of a triangle (`corners` its
/// vertices, `triangle` true) or a quad (`corners` its origin and two edges): what
/// [`Prim::sample_area`] samples, also for lights that keep their primitives' corners
/// ([`crate::light::area`]).
#[inline(always)]
pub fn flat_point(corners: [Vec3; 3], triangle: bool, u: Vec2) -> Vec3 {
    let (u0, u1) = (u.x as f64, u.y as f64);
    let [a, b, c] = corners.map(|v| v.as_dvec3());
    if triangle {
        let (b0, b1, b2) = crate::sampling::uniform_triangle(u0, u1);
        (b0 * a + b1 * b + b2 * c).as_vec3()
    } else {
        (a + u0 * b + u1 * c).as_vec3()
    }
}

/// A sphere's surface parameters (φ/2π, θ/π) at unit normal `n`, θ from +Z, φ about +Z
/// from +X in [0, 2π).
pub(super) fn sphere_uv(n: DVec3) -> Vec2 {
    let theta = n.z.clamp(-1.0, 1.0).acos();
    let mut phi = n.y.atan2(n.x);
    if phi < 0.0 {
        phi += std::f64::consts::TAU;
    }
    Vec2::new(
        (phi / std::f64::consts::TAU) as f32,
        (theta / std::f64::consts::PI) as f32,
    )
}

/// A disk's surface parameters (r/R, φ/2π) at the in-plane offset `rel` from its centre, for
/// the disk of unit normal `n` and radius `radius`; φ from the first axis of [`basis`]`(n)`.
pub(super) fn disk_uv(rel: DVec3, n: DVec3, radius: f32) -> Vec2 {
    let (tu, tv) = basis(n);
    let mut phi = rel.dot(tv).atan2(rel.dot(tu));
    if phi < 0.0 {
        phi += std::f64::consts::TAU;
    }
    Vec2::new(
        (rel.length() / radius as f64) as f32,
        (phi / std::f64::consts::TAU) as f32,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: Vec3, d: Vec3) -> RayPre {
        RayPre::new(o, d)
    }

    #[test]
    fn triangle_barycentrics_and_t() {
        let tri = Prim::Triangle([
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ]);
        let r = ray(Vec3::new(0.5, 0.5, 2.0), Vec3::new(0.0, 0.0, -1.0));
        let (t, b1, b2) = tri.intersect_dyn(&r, f32::INFINITY).unwrap();
        assert_eq!(t, 2.0);
        assert!((b1 - 0.25).abs() < 1e-7 && (b2 - 0.25).abs() < 1e-7);
        // Every dominant axis (monomorphised variants) gives the same answer.
        for d in [
            Vec3::new(-0.1, 0.0, -1.0),
            Vec3::new(0.6, 0.5, -0.5),
            Vec3::new(0.3, 0.8, -0.4),
        ] {
            let o = Vec3::new(0.5, 0.5, 0.0) - d * 3.0;
            let (t, ..) = tri.intersect_dyn(&ray(o, d), f32::INFINITY).unwrap();
            assert!((t - 3.0).abs() < 1e-5, "{d}: t = {t}");
        }
        // Behind the origin, beyond t_max: no hit.
        assert!(tri.intersect_dyn(&r, 2.0).is_none());
        let r = ray(Vec3::new(0.5, 0.5, 2.0), Vec3::new(0.0, 0.0, 1.0));
        assert!(tri.intersect_dyn(&r, f32::INFINITY).is_none());
        // Ray in the triangle's plane: no hit.
        let r = ray(Vec3::new(-1.0, 0.5, 0.0), Vec3::X);
        assert!(tri.intersect_dyn(&r, f32::INFINITY).is_none());
    }

    #[test]
    fn triangle_origin_on_surface_is_not_a_hit() {
        // A ray starting exactly on the triangle must not report t ≈ 0 (pbrt's δt check).
        let tri = Prim::Triangle([
            Vec3::new(100.0, 0.0, 0.0),
            Vec3::new(101.0, 0.0, 0.3),
            Vec3::new(100.0, 1.0, 0.7),
        ]);
        let (p, n) = tri.sample_area(Vec2::new(0.3, 0.4));
        for w in [n, -n, (n + Vec3::X).normalize()] {
            if let Some((t, ..)) = tri.intersect_dyn(&ray(p, w), f32::INFINITY) {
                panic!("self hit at t = {t}");
            }
        }
    }

    #[test]
    fn sphere_roots() {
        let s = Prim::Sphere {
            center: Vec3::new(0.0, 0.0, 10.0),
            radius: 1.0,
        };
        let (t, ..) = s
            .intersect_dyn(&ray(Vec3::ZERO, Vec3::Z), f32::INFINITY)
            .unwrap();
        assert_eq!(t, 9.0);
        let (t, ..) = s
            .intersect_dyn(&ray(Vec3::new(0.0, 0.0, 10.5), Vec3::Z), f32::INFINITY)
            .unwrap();
        assert_eq!(t, 0.5);
        let (t, ..) = s
            .intersect_dyn(&ray(Vec3::new(0.0, 0.0, 10.5), -Vec3::Z), f32::INFINITY)
            .unwrap();
        assert_eq!(t, 1.5);
        // Tiny sphere far away: the stable discriminant still finds it.
        let s = Prim::Sphere {
            center: Vec3::new(0.0, 0.0, 1e4),
            radius: 1e-3,
        };
        let (t, ..) = s
            .intersect_dyn(&ray(Vec3::ZERO, Vec3::Z), f32::INFINITY)
            .unwrap();
        assert!((t - (1e4 - 1e-3)).abs() < 1e-3);
    }

    #[test]
    fn disk_bounds_are_tight() {
        let d = Prim::Disk {
            center: Vec3::ZERO,
            normal: Vec3::Z,
            radius: 2.0,
        };
        let (lo, hi) = d.bounds();
        assert_eq!(lo, Vec3::new(-2.0, -2.0, 0.0));
        assert_eq!(hi, Vec3::new(2.0, 2.0, 0.0));
    }
}
