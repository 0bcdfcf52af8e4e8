//! The scene's objects as the world numbers them: a `Model` becomes one object per material it
//! uses and an `Instances` object one per part and placement, so the world's objects are
//! numbered apart from the scene's (`scene_object` maps them back). Also what the objects
//! imply before the lights are built: the area emitters, the lights models bring, where light
//! tracing aims, and the BVH over all shapes.

use super::instances::{instance_group, instance_spheres, InstanceParts};
use super::obj_model::{model_parts, Part};
use crate::bxdf::{Material, MaterialFlags};
use crate::description::context::{Context, SceneError};
use crate::description::schema::*;
use crate::geometry::{self, SceneGeometry, Shape, Transform};
use crate::light::{AreaLight, EmissionShape};
use crate::world::Object;
use glam::Vec3;
use std::collections::HashMap;

/// Resolves a material name of the scene to its index in the world's materials.
pub(super) type Lookup<'a> = dyn Fn(&str, &str) -> Result<u32, SceneError> + 'a;

/// An emitting world object waiting for the BVH: its id, field, emission and spectrum.
pub(super) type PendingArea = (u32, String, EmissionDesc, EmissionShape);

/// The world's objects and what they hold, before the BVH is built.
#[derive(Default)]
pub(super) struct Objects {
    /// Shapes placed in the world, each with its world object id.
    pub(super) shapes: Vec<(Shape, u32)>,
    /// Texture coordinates per entry of `shapes` (shorter when the last shapes have none).
    pub(super) shape_uvs: Vec<Option<Vec<glam::Vec2>>>,
    /// The scene object (index in `objects[]` of the scene file) of each world object.
    pub(super) scene_object: Vec<usize>,
    pub(super) objects: Vec<Object>,
    /// Emitting world objects, made area lights once the BVH exists.
    pub(super) pending_area: Vec<PendingArea>,
    /// Punctual lights found in glTF models, with their field.
    pub(super) model_lights: Vec<(String, LightDesc)>,
    /// Instance groups and the id of their first world object.
    pub(super) groups: Vec<(usize, InstanceParts)>,
}

/// The field path of scene object `i`, by name when it has one.
pub(super) fn object_field(i: usize, o: &ObjectDesc) -> String {
    match &o.name {
        Some(n) => format!("objects[{i}] {n:?}"),
        None => format!("objects[{i}]"),
    }
}

/// The message for a material name that `index` does not hold, listing the names it does.
fn unknown_material(
    ctx: &Context,
    index: &HashMap<&str, u32>,
    field: &str,
    name: &str,
) -> SceneError {
    let mut known: Vec<&str> = index.keys().copied().collect();
    known.sort();
    if name.is_empty() {
        return ctx.err(
            field,
            format!(
                "missing: name the object's material; defined materials: {}",
                known.join(", ")
            ),
        );
    }
    ctx.err(
        field,
        format!(
            "unknown material {name:?}; defined materials: {}",
            known.join(", ")
        ),
    )
}

/// Every object of the scene, with the materials of `index`; materials that models define
/// are appended to `materials`.
pub(super) fn build_objects(
    ctx: &Context,
    scene: &SceneFile,
    index: &HashMap<&str, u32>,
    materials: &mut Vec<Material>,
) -> Result<Objects, SceneError> {
    let lookup = |field: &str, name: &str| -> Result<u32, SceneError> {
        index
            .get(name)
            .copied()
            .ok_or_else(|| unknown_material(ctx, index, field, name))
    };
    let mut out = Objects {
        shapes: Vec::with_capacity(scene.objects.len()),
        scene_object: Vec::with_capacity(scene.objects.len()),
        objects: Vec::with_capacity(scene.objects.len()),
        ..Default::default()
    };
    for (i, o) in scene.objects.iter().enumerate() {
        out.add_object(ctx, i, o, &lookup, materials)?;
    }
    Ok(out)
}

impl Objects {
    /// Scene object `i`: its parts, placed once or at each of its instances' transforms.
    fn add_object(
        &mut self,
        ctx: &Context,
        i: usize,
        o: &ObjectDesc,
        lookup: &Lookup,
        materials: &mut Vec<Material>,
    ) -> Result<(), SceneError> {
        let field = object_field(i, o);
        let transform = match &o.transform {
            Some(t) => Some(Transform::build(ctx, &format!("{field}.transform"), t)?),
            None => None,
        };
        // An `Instances` shape: its mesh's parts, placed at each of its transforms below.
        let (shape_desc, instances) = match &o.shape {
            ShapeDesc::Instances { mesh, transforms } => (
                mesh.as_ref(),
                Some(Transform::build_instances(
                    ctx,
                    &format!("{field}.shape"),
                    transforms,
                )?),
            ),
            desc => (desc, None),
        };
        let whole = (i, o, field.as_str(), transform.as_ref());
        let parts = self.object_parts(
            ctx,
            whole,
            shape_desc,
            instances.is_some(),
            lookup,
            materials,
        )?;
        let parts = match instances {
            Some(tfs) => match instance_group(ctx, &field, parts, tfs, transform.as_ref())? {
                Ok(group) => {
                    self.add_group(i, group);
                    return Ok(());
                }
                Err(copies) => copies,
            },
            None => parts,
        };
        self.add_parts(ctx, i, &field, parts, transform.as_ref())
    }

    /// The parts of scene object `i` (at `field`, with its `transform`) whose shape is `desc`
    /// (the instanced mesh when `instanced`), before the object's transform.
    fn object_parts(
        &mut self,
        ctx: &Context,
        (i, o, field, transform): (usize, &ObjectDesc, &str, Option<&Transform>),
        desc: &ShapeDesc,
        instanced: bool,
        lookup: &Lookup,
        materials: &mut Vec<Material>,
    ) -> Result<Vec<Part>, SceneError> {
        Ok(match desc {
            ShapeDesc::Model { .. } if o.emission.is_some() => {
                return Err(ctx.err(
                    format!("{field}.emission"),
                    "a Model's materials emit through their MTL `Ke` and the shape's `ke_luminance`; give other emitters as objects of their own",
                ));
            }
            ShapeDesc::Model {
                file,
                materials_from_file,
                ke_luminance,
                lights,
            } if geometry::gltf::is_gltf(file) => {
                let model = (file.as_str(), materials_from_file, *ke_luminance, *lights);
                let at = (i, field, transform, o.material.as_str());
                self.gltf_parts(ctx, at, model, instanced, lookup, materials)?
            }
            ShapeDesc::Model { lights: true, .. } => {
                return Err(ctx.err(
                    format!("{field}.shape.lights"),
                    "only a glTF model (.gltf, .glb) has lights",
                ));
            }
            ShapeDesc::Model {
                file,
                materials_from_file,
                ke_luminance,
                ..
            } => model_parts(
                ctx,
                field,
                (file, materials_from_file, *ke_luminance),
                &o.material,
                lookup,
                materials,
            )?,
            desc => {
                let shape_field = match instanced {
                    true => format!("{field}.shape.mesh"),
                    false => format!("{field}.shape"),
                };
                vec![Part {
                    shape: Shape::build(ctx, &shape_field, desc)?,
                    uvs: None,
                    material: lookup(&format!("{field}.material"), &o.material)?,
                    emission: o.emission.clone(),
                }]
            }
        })
    }

    /// A glTF model's parts: its unshared meshes as parts, its shared meshes as instance
    /// groups (or as parts, inside `Instances`, or when they emit); its lights are kept.
    fn gltf_parts(
        &mut self,
        ctx: &Context,
        (i, field, transform, fallback): (usize, &str, Option<&Transform>, &str),
        model: (
            &str,
            &std::collections::BTreeMap<String, MaterialRefDesc>,
            Option<f64>,
            bool,
        ),
        instanced: bool,
        lookup: &Lookup,
        materials: &mut Vec<Material>,
    ) -> Result<Vec<Part>, SceneError> {
        let at = format!("{field}.shape");
        let (flat, shared, found) = crate::scene::gltf::model_parts(
            ctx,
            &at,
            model,
            (transform, fallback, lookup),
            materials,
        )?;
        self.model_lights.extend(found);
        let part = |p: crate::scene::gltf::GltfPart| Part {
            shape: p.shape,
            uvs: p.uvs,
            material: p.material,
            emission: p.emission,
        };
        let mut parts: Vec<Part> = flat.into_iter().map(part).collect();
        for g in shared {
            if instanced {
                // Inside `Instances`, the model is the instanced mesh: one level.
                parts.extend(g.flatten(ctx, &at)?.into_iter().map(part));
                continue;
            }
            let gparts = g.parts.into_iter().map(part).collect();
            match instance_group(ctx, &at, gparts, g.transforms, transform)? {
                Ok(group) => self.add_group(i, group),
                Err(copies) => parts.extend(copies),
            }
        }
        Ok(parts)
    }

    /// `parts` of scene object `i`, placed by its `transform`: a world object each, an area
    /// emitter pending for those that emit.
    fn add_parts(
        &mut self,
        ctx: &Context,
        i: usize,
        field: &str,
        parts: Vec<Part>,
        transform: Option<&Transform>,
    ) -> Result<(), SceneError> {
        for part in parts {
            let id = self.objects.len() as u32;
            let shape = match transform {
                Some(tf) => part
                    .shape
                    .to_world(tf)
                    .map_err(|e| ctx.err(format!("{field}.transform"), e.to_string()))?,
                None => part.shape,
            };
            self.shapes.push((shape, id));
            if part.uvs.is_some() {
                self.shape_uvs.resize(self.shapes.len(), None);
                self.shape_uvs[self.shapes.len() - 1] = part.uvs;
            }
            self.scene_object.push(i);
            self.objects.push(Object {
                material: part.material,
                light: None,
            });
            if let Some(e) = part.emission {
                let s = AreaLight::spectrum(ctx, field, &e)?;
                self.pending_area.push((id, field.to_string(), e, s));
            }
        }
        Ok(())
    }

    /// Adds instance group `group` of scene object `i`: a world object per part and instance,
    /// in the order [`geometry::InstanceGroup`] numbers them.
    fn add_group(&mut self, i: usize, group: InstanceParts) {
        let first = self.objects.len();
        for _ in &group.transforms {
            for part in &group.parts {
                self.scene_object.push(i);
                self.objects.push(Object {
                    material: part.material,
                    light: None,
                });
            }
        }
        self.groups.push((first, group));
    }

    /// Bounding spheres of the objects that scatter specularly: where light tracing aims.
    pub(super) fn caustic_targets(&self, materials: &[Material]) -> Vec<(Vec3, f32)> {
        self.shapes
            .iter()
            .filter(|(_, o)| {
                materials[self.objects[*o as usize].material as usize]
                    .flags()
                    .contains(MaterialFlags::DELTA)
            })
            .filter_map(|(shape, _)| crate::world::caustic_lights::bounding_sphere(shape))
            .chain(
                self.groups
                    .iter()
                    .flat_map(|(_, g)| instance_spheres(g, materials)),
            )
            .collect()
    }

    /// The BVH over every shape and instance group; an invalid shape is named by its scene
    /// object's field.
    pub(super) fn geometry(
        &self,
        ctx: &Context,
        scene: &SceneFile,
    ) -> Result<SceneGeometry, SceneError> {
        let uvs: Vec<Option<&[glam::Vec2]>> = self.shape_uvs.iter().map(|u| u.as_deref()).collect();
        let instance_groups: Vec<geometry::InstanceGroup> = self
            .groups
            .iter()
            .map(|(first, g)| geometry::InstanceGroup {
                parts: g
                    .parts
                    .iter()
                    .map(|p| (&p.shape, p.uvs.as_deref()))
                    .collect(),
                transforms: &g.transforms,
                first_object: *first as u32,
            })
            .collect();
        SceneGeometry::build_instanced(&self.shapes, &uvs, &instance_groups).map_err(|e| {
            let field = match &e {
                geometry::GeometryError::InvalidShape { object, .. } => self
                    .scene_object
                    .get(*object as usize)
                    .map(|&i| format!("{}.shape", object_field(i, &scene.objects[i]))),
                _ => None,
            };
            ctx.err(field.unwrap_or_else(|| "objects".into()), e.to_string())
        })
    }
}
