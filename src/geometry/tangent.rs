//! Surface derivatives with respect to texture coordinates at a hit, for tangent frames
//! (normal maps): dp/du and dp/dv of the primitive's texture coordinates.

use super::instance::NO_INSTANCE;
use super::prim::Prim;
use super::{Hit, SceneGeometry};
use glam::Vec3;

impl SceneGeometry {
    /// (dp/du, dp/dv) at `hit`, in world units per unit of texture coordinate: from a
    /// triangle's vertices and texture coordinates (its barycentrics (b1, b2) when it has none),
    /// or a quad's edges. `None` on spheres and disks, on instanced meshes, and where the
    /// texture coordinates are degenerate (a triangle whose uv area is zero).
    pub fn texture_derivatives(&self, hit: &Hit) -> Option<(Vec3, Vec3)> {
        if hit.instance != NO_INSTANCE || hit.prim as usize >= self.tris.len() {
            return None;
        }
        match self.prim(hit.prim) {
            Prim::Triangle([p0, p1, p2]) => {
                let (e1, e2) = (p1 - p0, p2 - p0);
                let idx = self
                    .prim_uvs
                    .get(hit.prim as usize)
                    .filter(|i| i[0] != u32::MAX);
                let Some(idx) = idx else {
                    return Some((e1, e2));
                };
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
            Prim::Quad { edge_u, edge_v, .. } => Some((edge_u, edge_v)),
            Prim::Sphere { .. } | Prim::Disk { .. } => None,
        }
    }
}
