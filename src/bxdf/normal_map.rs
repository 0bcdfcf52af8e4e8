//! Tangent-space normal maps. An 8-bit texel (r, g, b) is the normal (x, y, z) =
//! ((r − 128)/127, (g − 128)/127, (b − 128)/127) (each clamped to [−1, 1]; so 128 is exactly 0
//! and (128, 128, 255) the unperturbed normal), x and y multiplied by the map's `scale`, then
//! normalised, in the frame whose x is
//! the direction of increasing u on the surface, y that of increasing v (up the image, glTF's
//! and OpenGL's convention), z the shading normal. The tangent comes from the primitive's
//! texture-coordinate derivatives dp/du, dp/dv at the hit
//! ([`crate::geometry::SceneGeometry::texture_derivatives`], after the map's UV transform),
//! orthonormalised against the shading normal; mirrored texture coordinates flip y.

use super::Material;
use crate::texture::bytes::ByteTexture;
use glam::{Vec2, Vec3};

/// A material under a normal map.
#[derive(Clone, Debug)]
pub struct NormalMapped {
    pub inner: Material,
    /// The normal map, 3 bytes per texel.
    pub map: ByteTexture<3>,
    /// glTF's `normalTexture.scale`: multiplies x and y (1 leaves the map as it is).
    pub scale: f32,
}

impl NormalMapped {
    /// The perturbed shading normal at texture coordinates `tex` of a surface with shading
    /// normal `ns` and geometric normal `ng` (both unit), whose surface derivatives with
    /// respect to the texture coordinates are `dpdu`, `dpdv`. It is returned on `ng`'s side
    /// as `ns` is; `ns` itself where the frame is degenerate (no derivatives, or a map normal
    /// that would lie in or below the surface).
    pub fn shading_normal(&self, tex: Vec2, ns: Vec3, ng: Vec3, dpdu: Vec3, dpdv: Vec3) -> Vec3 {
        let c = self.map.lookup_raw(tex);
        let d = |v: f32| ((v - 128.0) * (1.0 / 127.0)).clamp(-1.0, 1.0);
        let m = Vec3::new(d(c[0]) * self.scale, d(c[1]) * self.scale, d(c[2]));
        // The unperturbed normal, kept to the bit.
        if m.x == 0.0 && m.y == 0.0 && m.z > 0.0 {
            return ns;
        }
        // The derivatives with respect to the map's coordinates t = A·uv + b:
        // [dp/dt₁ dp/dt₂] = [dp/du dp/dv]·A⁻¹.
        let a = self.map.uv.matrix2;
        let det = a.determinant();
        if det == 0.0 || !det.is_finite() || m.z <= 0.0 {
            return ns;
        }
        let inv = a.inverse();
        let du = dpdu * inv.x_axis.x + dpdv * inv.x_axis.y;
        let dv = dpdu * inv.y_axis.x + dpdv * inv.y_axis.y;
        let t = (du - ns * ns.dot(du)).normalize_or_zero();
        if t == Vec3::ZERO {
            return ns;
        }
        let mut b = ns.cross(t);
        if b.dot(dv) < 0.0 {
            b = -b;
        }
        let n = (t * m.x + b * m.y + ns * m.z).normalize_or_zero();
        if n == Vec3::ZERO || !n.is_finite() || n.dot(ng) * ns.dot(ng) <= 0.0 {
            return ns;
        }
        n
    }
}

/// Whether scattering `wo` → `wi` (world, both leaving the surface) is a reflection by the
/// geometric normal `ng` but a transmission by the shading normal `ns`, or the reverse: with
/// a perturbed shading normal this would let light through an opaque surface or stop it at a
/// transparent one, so such pairs carry nothing.
#[inline]
pub fn leaks(wo: Vec3, wi: Vec3, ns: Vec3, ng: Vec3) -> bool {
    let by_ng = wo.dot(ng) * wi.dot(ng) > 0.0;
    let by_ns = wo.dot(ns) * wi.dot(ns) > 0.0;
    by_ng != by_ns
}
