//! `Instances` objects: their parts and transforms for the two-level BVH, or their copies when
//! they emit (light sampling needs each emitter's triangles in world space).

use super::obj_model::Part;
use crate::bxdf::{Material, MaterialFlags};
use crate::description::context::{Context, SceneError};
use crate::geometry::{self, Shape, Transform};
use glam::Vec3;

/// An `Instances` object's mesh parts (object space) and its instances' transforms (the
/// object's own transform applied after each).
pub(super) struct InstanceParts {
    pub(super) parts: Vec<Part>,
    pub(super) transforms: Vec<Transform>,
}

/// The instances of `parts` at `tfs` (then `object_tf`), or, when a part emits, their copies
/// in the object's space, each an area light of its own.
pub(super) fn instance_group(
    ctx: &Context,
    field: &str,
    parts: Vec<Part>,
    tfs: Vec<Transform>,
    object_tf: Option<&Transform>,
) -> Result<Result<InstanceParts, Vec<Part>>, SceneError> {
    if parts.iter().all(|p| p.emission.is_none()) {
        let transforms = tfs
            .iter()
            .map(|t| object_tf.map_or(*t, |o| o.then_after(t)))
            .collect();
        return Ok(Ok(InstanceParts { parts, transforms }));
    }
    let tris: u64 = parts
        .iter()
        .map(|p| match &p.shape {
            Shape::Mesh(m) => m.indices.len() as u64,
            _ => 1,
        })
        .sum();
    let n = tris.saturating_mul(tfs.len() as u64);
    // Each copy's vertices and indices, then its share of the BVH build.
    crate::limits::check_memory(
        n.saturating_mul(48 + geometry::BUILD_PEAK_BYTES_PER_PRIM),
        &format!(
            "writing out the {} emitting instances ({n} triangles)",
            tfs.len()
        ),
    )
    .map_err(|m| ctx.err(format!("{field}.shape.transforms"), m))?;
    let mut copies = Vec::with_capacity(parts.len() * tfs.len());
    for (k, t) in tfs.iter().enumerate() {
        for p in &parts {
            copies.push(Part {
                shape: p.shape.to_world(t).map_err(|e| {
                    ctx.err(format!("{field}.shape.transforms[{k}]"), e.to_string())
                })?,
                uvs: p.uvs.clone(),
                material: p.material,
                emission: p.emission.clone(),
            });
        }
    }
    Ok(Err(copies))
}

/// Bounding spheres of an instance group's parts that scatter specularly, one per instance.
pub(super) fn instance_spheres(g: &InstanceParts, materials: &[Material]) -> Vec<(Vec3, f32)> {
    let mut out = Vec::new();
    for p in &g.parts {
        if !materials[p.material as usize]
            .flags()
            .contains(MaterialFlags::DELTA)
        {
            continue;
        }
        let Some((c, r)) = crate::world::caustic_lights::bounding_sphere(&p.shape) else {
            continue;
        };
        for t in &g.transforms {
            let m = t.matrix.matrix3;
            let stretch = m
                .x_axis
                .length()
                .max(m.y_axis.length())
                .max(m.z_axis.length());
            // The image of a ball of radius r has semi-axes at most r·‖M‖_F ≤ r·√3·(longest column).
            let s = stretch * 3f32.sqrt();
            out.push((t.transform_point(c), r * s * (1.0 + 1e-4)));
        }
    }
    out
}
