//! Surface derivatives with respect to texture coordinates at a hit, for tangent frames
//! (normal maps): dp/du and dp/dv of the primitive's texture coordinates, in world space.

use super::prim::{basis, Prim};
use super::{Hit, SceneGeometry, NO_INSTANCE};
use glam::{DVec3, Vec2, Vec3};
use std::f64::consts::{PI, TAU};

impl SceneGeometry {
    /// (dp/du, dp/dv) at `hit`, in world units per unit of texture coordinate: from a
    /// triangle's vertices and texture coordinates (its barycentrics (b1, b2) when it has none),
    /// a quad's edges, a sphere's or a disk's parameterisation ([`Hit::uv`]); on an instanced
    /// mesh, the object-space derivatives carried to world space by the instance's linear part.
    /// `None` where the texture coordinates are degenerate (a triangle whose uv area is zero).
    pub fn texture_derivatives(&self, hit: &Hit) -> Option<(Vec3, Vec3)> {
        if hit.instance != NO_INSTANCE {
            return self.instances.as_ref()?.texture_derivatives(hit);
        }
        if hit.prim as usize >= self.tris.len() {
            return None;
        }
        match self.prim(hit.prim) {
            Prim::Triangle(_) => self.triangle_derivatives(hit.prim),
            Prim::Quad { edge_u, edge_v, .. } => Some((edge_u, edge_v)),
            Prim::Sphere { radius, .. } => sphere_derivatives(radius, hit.uv),
            Prim::Disk { normal, radius, .. } => disk_derivatives(normal, radius, hit.uv),
        }
    }

    /// (dp/du, dp/dv) of triangle `prim` in this geometry's own space; (e1, e2), the
    /// derivatives with respect to its barycentrics (b1, b2), when it has no texture
    /// coordinates (see [`SceneGeometry::has_texture_coordinates`]).
    pub(super) fn triangle_derivatives(&self, prim: u32) -> Option<(Vec3, Vec3)> {
        let [p0, p1, p2] = *self.tris.get(prim as usize)?;
        if p0.x.is_nan() {
            return None;
        }
        let (e1, e2) = (p1 - p0, p2 - p0);
        if !self.has_texture_coordinates(prim) {
            return Some((e1, e2));
        }
        let idx = self.prim_uvs[prim as usize];
        let uv = |k: usize| self.uvs[idx[k] as usize];
        let (d1, d2) = (uv(1) - uv(0), uv(2) - uv(0));
        // [e1 e2] = [dp/du dp/dv]·[d1 d2]; invert the 2×2 uv matrix.
        let det = d1.x * d2.y - d1.y * d2.x;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let r = 1.0 / det;
        let dpdu = (e1 * d2.y - e2 * d1.y) * r;
        let dpdv = (e2 * d1.x - e1 * d2.x) * r;
        (dpdu.is_finite() && dpdv.is_finite()).then_some((dpdu, dpdv))
    }

    /// Whether triangle `prim` has texture coordinates of its own (else its [`Hit::tex`] is its
    /// barycentrics).
    pub(super) fn has_texture_coordinates(&self, prim: u32) -> bool {
        self.prim_uvs
            .get(prim as usize)
            .is_some_and(|i| i[0] != u32::MAX)
    }
}

/// A sphere of radius `radius` m at `uv` = (φ/2π, θ/π), θ from +Z:
/// p = c + R (sin θ cos φ, sin θ sin φ, cos θ), so dp/du = 2π ∂p/∂φ and dp/dv = π ∂p/∂θ.
/// dp/du vanishes at the poles (no tangent there: the map is not applied).
fn sphere_derivatives(radius: f32, uv: Vec2) -> Option<(Vec3, Vec3)> {
    let (phi, theta) = (TAU * uv.x as f64, PI * uv.y as f64);
    let (sp, cp) = phi.sin_cos();
    let (st, ct) = theta.sin_cos();
    let r = radius as f64;
    let dpdu = DVec3::new(-st * sp, st * cp, 0.0) * (TAU * r);
    let dpdv = DVec3::new(ct * cp, ct * sp, -st) * (PI * r);
    Some((dpdu.as_vec3(), dpdv.as_vec3()))
}

/// A disk of radius `radius` m about the unit `normal` at `uv` = (r/R, φ/2π), φ measured in
/// the disk's basis (t, b) ([`basis`], as its hits are): p = c + r (cos φ t + sin φ b), so
/// dp/du = R ∂p/∂r (radial) and dp/dv = 2π ∂p/∂φ (along the circle, zero at the centre).
fn disk_derivatives(normal: Vec3, radius: f32, uv: Vec2) -> Option<(Vec3, Vec3)> {
    let (t, b) = basis(normal.as_dvec3().normalize());
    let phi = TAU * uv.y as f64;
    let (sp, cp) = phi.sin_cos();
    let big_r = radius as f64;
    let r = uv.x as f64 * big_r;
    let dpdu = (t * cp + b * sp) * big_r;
    let dpdv = (b * cp - t * sp) * (TAU * r);
    Some((dpdu.as_vec3(), dpdv.as_vec3()))
}
