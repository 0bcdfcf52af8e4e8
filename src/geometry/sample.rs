//! Sampling the scene's primitives: uniformly by area, and by solid angle as seen from a
//! reference point (the cone a sphere subtends, area sampling converted for the rest), with
//! the matching densities.

use super::prim::Prim;
use super::{Hit, SceneGeometry, SurfacePoint};
use glam::{Vec2, Vec3};

impl SceneGeometry {
    /// Surface area of a primitive (m²).
    pub fn prim_area(&self, prim: u32) -> f32 {
        self.prim(prim).area()
    }

    /// Bounding box (m) of a primitive and, for a flat one, its unit front-face normal (the
    /// normal [`SceneGeometry::sample_prim`] gives everywhere on it); None for a sphere.
    pub fn prim_bounds_normal(&self, prim: u32) -> ((Vec3, Vec3), Option<Vec3>) {
        let pr = self.prim(prim);
        let n = (!matches!(pr, Prim::Sphere { .. })).then(|| pr.sample_area(Vec2::splat(0.5)).1);
        (pr.bounds(), n)
    }

    /// A quad's origin and edges, or a triangle's vertices (with `true`); None for a sphere or
    /// a disk. With [`SceneGeometry::prim_bounds_normal`]'s normal and
    /// [`SceneGeometry::prim_area`], what a light needs to sample a flat primitive without
    /// looking it up each time (see [`crate::light::area`]).
    pub fn prim_corners(&self, prim: u32) -> Option<([Vec3; 3], bool)> {
        match self.prim(prim) {
            Prim::Triangle(v) => Some((v, true)),
            Prim::Quad {
                origin,
                edge_u,
                edge_v,
                ..
            } => Some(([origin, edge_u, edge_v], false)),
            Prim::Sphere { .. } | Prim::Disk { .. } => None,
        }
    }

    /// Uniform by area on the primitive: point, unit front-face geometric normal; the pdf
    /// w.r.t. area is `1 / prim_area(prim)`. `u` ∈ [0,1)². The point's error bound is
    /// [`super::point_error_bound`] (it is computed in f64).
    pub fn sample_prim(&self, prim: u32, u: Vec2) -> SurfacePoint {
        let pr = self.prim(prim);
        let (p, n) = pr.sample_area(u);
        SurfacePoint {
            p,
            n,
            tex: self.tex_at(prim, &pr, p, n, u),
        }
    }

    /// Texture coordinates of the point `p` (front normal `n`) that [`Prim::sample_area`] made
    /// from `u` on primitive `prim`: those a hit there reports ([`Hit::tex`]), i.e. a mesh's
    /// interpolated `vt` where it has them, else the surface's own parameters.
    fn tex_at(&self, prim: u32, pr: &Prim, p: Vec3, n: Vec3, u: Vec2) -> Vec2 {
        match *pr {
            Prim::Triangle(_) => {
                // The barycentrics sample_area used.
                let (b0, b1, b2) = crate::sampling::uniform_triangle(u.x as f64, u.y as f64);
                match self.prim_uvs.get(prim as usize) {
                    Some(idx) if idx[0] != u32::MAX => {
                        let b = Vec3::new(b0 as f32, b1 as f32, b2 as f32);
                        b.x * self.uvs[idx[0] as usize]
                            + b.y * self.uvs[idx[1] as usize]
                            + b.z * self.uvs[idx[2] as usize]
                    }
                    _ => Vec2::new(b1 as f32, b2 as f32),
                }
            }
            Prim::Quad { .. } => u,
            Prim::Sphere { .. } => super::prim::sphere_uv(n.as_dvec3()),
            Prim::Disk {
                center,
                normal,
                radius,
            } => {
                let nd = normal.as_dvec3().normalize();
                let mut rel = p.as_dvec3() - center.as_dvec3();
                rel -= rel.dot(nd) * nd;
                super::prim::disk_uv(rel, nd, radius)
            }
        }
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
        self.sample_prim_solid_angle_with(prim, reference, u, true)
    }

    /// [`SceneGeometry::sample_prim_solid_angle`] for a caller that may not need texture
    /// coordinates (`tex` false: they are left zero, which saves a sphere's or a mesh's
    /// parametrisation, e.g. for an untextured light). The point and pdf are the same.
    pub fn sample_prim_solid_angle_with(
        &self,
        prim: u32,
        reference: Vec3,
        u: Vec2,
        tex: bool,
    ) -> Option<(SurfacePoint, f32)> {
        let pr = self.prim(prim);
        let tex_at = |p: Vec3, n: Vec3| {
            if tex {
                self.tex_at(prim, &pr, p, n, u)
            } else {
                Vec2::ZERO
            }
        };
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
                let (p, n) = (p.as_vec3(), n.as_vec3());
                let tex = tex_at(p, n);
                return Some((SurfacePoint { p, n, tex }, pdf));
            }
        }
        let (p, n) = pr.sample_area(u);
        let pdf = Self::area_to_solid_angle(pr.area(), reference, p, n);
        (pdf > 0.0 && pdf.is_finite()).then(|| {
            let tex = tex_at(p, n);
            (SurfacePoint { p, n, tex }, pdf)
        })
    }

    /// The density w.r.t. solid angle at `reference` of a point `p` (normal `n`) sampled
    /// uniformly on `area` m² (0 where it would be infinite or NaN).
    #[inline]
    pub fn area_to_solid_angle(area: f32, reference: Vec3, p: Vec3, n: Vec3) -> f32 {
        let w = p.as_dvec3() - reference.as_dvec3();
        let d2 = w.length_squared();
        if d2 == 0.0 {
            return 0.0;
        }
        // d²/(A·cos θ) with cos θ = |n·w|/d: d³/(A·|n·w|), one division (the density is on
        // the light-sampling path of every bounce, where a chain of divisions shows).
        let den = n.as_dvec3().dot(w).abs() * area as f64;
        if den.is_nan() || den <= 0.0 {
            return 0.0;
        }
        let pdf = (d2 * d2.sqrt() / den) as f32;
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
}
