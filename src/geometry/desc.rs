//! Shapes and transforms read from the scene description: every value checked, meshes loaded
//! from files relative to the scene, errors naming the file and the field.

use super::{load_ply, GeometryError, Shape, Transform, TriangleMesh};
use crate::description::context::{Context, SceneError};
use crate::description::schema::{ShapeDesc, TransformDesc};
use glam::Vec3;
use std::path::Path;

/// A mesh file's error; an unreadable file's hint says where relative paths are resolved.
pub(crate) fn mesh_err(ctx: &Context, field: &str, rel: &str, e: GeometryError) -> SceneError {
    match e {
        GeometryError::Io { path, source } => ctx.err(
            field,
            format!(
                "cannot read mesh file '{}': {source}. Check that the path is correct{} and that the file is readable.",
                path.display(),
                if !Path::new(rel).is_relative() {
                    String::new()
                } else if ctx.dir.as_os_str().is_empty() {
                    format!(" ({rel:?} is resolved against the scene file's directory)")
                } else {
                    format!(
                        " ({rel:?} is resolved against the scene file's directory, {})",
                        ctx.dir.display()
                    )
                }
            ),
        ),
        e => ctx.err(field, e.to_string()),
    }
}

impl Shape {
    /// The shape `desc` describes at `field` (meshes read from files relative to the scene).
    pub fn build(ctx: &Context, field: &str, desc: &ShapeDesc) -> Result<Shape, SceneError> {
        let f = |s: &str| format!("{field}.{s}");
        Ok(match desc {
            ShapeDesc::Sphere { center, radius } => Shape::Sphere {
                center: ctx.vec3(&f("center"), *center)?,
                radius: ctx.positive(&f("radius"), *radius as f64)? as f32,
            },
            ShapeDesc::Quad {
                origin,
                edge_u,
                edge_v,
            } => {
                let eu = ctx.vec3(&f("edge_u"), *edge_u)?;
                let ev = ctx.vec3(&f("edge_v"), *edge_v)?;
                if eu.cross(ev).length_squared() == 0.0 {
                    return Err(ctx.err(
                        field,
                        "the quad has zero area (edge_u and edge_v are parallel or zero)",
                    ));
                }
                Shape::Quad {
                    origin: ctx.vec3(&f("origin"), *origin)?,
                    edge_u: eu,
                    edge_v: ev,
                }
            }
            ShapeDesc::Disk {
                center,
                normal,
                radius,
            } => {
                let n = ctx.vec3(&f("normal"), *normal)?;
                if n.length_squared() == 0.0 {
                    return Err(ctx.err(f("normal"), "the normal is the zero vector"));
                }
                Shape::Disk {
                    center: ctx.vec3(&f("center"), *center)?,
                    normal: n.normalize(),
                    radius: ctx.positive(&f("radius"), *radius as f64)? as f32,
                }
            }
            ShapeDesc::Triangles {
                positions,
                indices,
                normals,
            } => {
                let mut mesh = TriangleMesh::default();
                for (k, p) in positions.iter().enumerate() {
                    mesh.positions
                        .push(ctx.vec3(&format!("{field}.positions[{k}]"), *p)?);
                }
                for (k, tri) in indices.iter().enumerate() {
                    for &ix in tri {
                        if ix as usize >= positions.len() {
                            return Err(ctx.err(
                                format!("{field}.indices[{k}]"),
                                format!(
                                    "vertex index {ix} is out of range (the mesh has {} positions)",
                                    positions.len()
                                ),
                            ));
                        }
                    }
                    mesh.indices.push(*tri);
                }
                if mesh.indices.is_empty() {
                    return Err(ctx.err(f("indices"), "the mesh has no triangles"));
                }
                if let Some(ns) = normals {
                    if ns.len() != positions.len() {
                        return Err(ctx.err(
                            f("normals"),
                            format!(
                                "{} normals given for {} positions; give one per position",
                                ns.len(),
                                positions.len()
                            ),
                        ));
                    }
                    let mut v = Vec::with_capacity(ns.len());
                    for (k, n) in ns.iter().enumerate() {
                        v.push(
                            ctx.vec3(&format!("{field}.normals[{k}]"), *n)?
                                .normalize_or_zero(),
                        );
                    }
                    mesh.normals = Some(v);
                }
                Shape::Mesh(mesh)
            }
            ShapeDesc::Blinds { .. } => {
                Shape::Mesh(super::Blinds::from_desc(ctx, field, desc)?.mesh())
            }
            ShapeDesc::Obj(rel) => {
                let (mesh, libraries) = super::io::load_obj_and_libraries(&ctx.resolve(rel))
                    .map_err(|e| mesh_err(ctx, field, rel, e))?;
                // Unused, but the model's: outputs must not replace them.
                let mut sources = ctx.sources.borrow_mut();
                for l in libraries {
                    if !sources.contains(&l) {
                        sources.push(l);
                    }
                }
                Shape::Mesh(mesh)
            }
            ShapeDesc::Model { .. } => {
                return Err(ctx.err(field, "a Model is built with its materials by the scene"))
            }
            ShapeDesc::Instances { .. } => {
                return Err(ctx.err(
                    field,
                    "Instances are built by the scene (an Instances shape cannot be nested)",
                ))
            }
            ShapeDesc::Ply(rel) => {
                Shape::Mesh(load_ply(&ctx.resolve(rel)).map_err(|e| mesh_err(ctx, field, rel, e))?)
            }
        })
    }
}

impl Transform {
    /// The transforms of an `Instances` shape at `field` (`field.transforms[k]`): at least one,
    /// each finite and invertible.
    pub fn build_instances(
        ctx: &Context,
        field: &str,
        transforms: &[TransformDesc],
    ) -> Result<Vec<Transform>, SceneError> {
        if transforms.is_empty() {
            return Err(ctx.err(
                format!("{field}.transforms"),
                "the list is empty: give at least one transform (the instance's placement)",
            ));
        }
        let mut out = Vec::with_capacity(transforms.len());
        for (k, t) in transforms.iter().enumerate() {
            let f = format!("{field}.transforms[{k}]");
            let tf = Transform::build(ctx, &f, t)?;
            if !tf.is_invertible() {
                return Err(ctx.err(
                    f,
                    "the transform is singular (a scale too small or too large to invert in single precision)",
                ));
            }
            out.push(tf);
        }
        Ok(out)
    }

    /// The transform `t` describes at `field` (scale factors must be positive).
    pub fn build(ctx: &Context, field: &str, t: &TransformDesc) -> Result<Transform, SceneError> {
        let tr = match t.translate {
            Some(v) => ctx.vec3(&format!("{field}.translate"), v)?,
            None => Vec3::ZERO,
        };
        let rot = match t.rotate_deg {
            Some(v) => ctx.vec3(&format!("{field}.rotate_deg"), v)?,
            None => Vec3::ZERO,
        };
        let sc = match t.scale {
            Some(v) => ctx.vec3(&format!("{field}.scale"), v)?,
            None => Vec3::ONE,
        };
        if sc.min_element() <= 0.0 {
            return Err(ctx.err(
                format!("{field}.scale"),
                format!("scale factors must be greater than 0, got {sc}"),
            ));
        }
        Ok(Transform::from_trs(tr, rot, sc))
    }
}
