//! The parts of an OBJ + MTL building model (`Model(file: "x.obj")`): one world object per
//! material its faces use, mapped from the MTL or replaced by `materials_from_file`.

use crate::bxdf::Material;
use crate::description::context::{Context, SceneError};
use crate::description::schema::*;
use crate::geometry::{self, Shape};

/// One world object made from a scene object: its shape (before the object's transform), its
/// texture coordinates, material and emission.
pub(super) struct Part {
    pub(super) shape: Shape,
    pub(super) uvs: Option<Vec<glam::Vec2>>,
    pub(super) material: u32,
    pub(super) emission: Option<EmissionDesc>,
}

/// The parts of a `Model` object at `field`: one per material its OBJ file uses, with the
/// material mapped from the MTL (or given by `materials_from_file`), faces that name none
/// taking `fallback`; materials made here are appended to `materials`.
pub(super) fn model_parts(
    ctx: &Context,
    field: &str,
    (file, overrides, ke_luminance): (
        &str,
        &std::collections::BTreeMap<String, MaterialRefDesc>,
        Option<f64>,
    ),
    fallback: &str,
    lookup: &dyn Fn(&str, &str) -> Result<u32, SceneError>,
    materials: &mut Vec<Material>,
) -> Result<Vec<Part>, SceneError> {
    let shape_field = format!("{field}.shape");
    let obj = ctx.resolve(file);
    let model = geometry::load_obj_model(&obj)
        .map_err(|e| geometry::mesh_err(ctx, &shape_field, file, e))?;
    for lib in &model.libraries {
        record(ctx, lib);
    }
    let names = || {
        let mut n: Vec<&str> = model.materials.iter().map(|m| m.name.as_str()).collect();
        n.sort_unstable();
        n.join(", ")
    };
    for name in overrides.keys() {
        if !model.materials.iter().any(|m| &m.name == name) {
            return Err(ctx.err(
                format!("{shape_field}.materials_from_file[{name:?}]"),
                format!(
                    "{file:?} defines no material {name:?}; its materials: {}",
                    names()
                ),
            ));
        }
    }
    if let Some(l) = ke_luminance {
        if !(l.is_finite() && l >= 0.0) {
            return Err(ctx.err(
                format!("{shape_field}.ke_luminance"),
                format!("{l} must be a luminance ≥ 0, cd/m²"),
            ));
        }
    }
    let mut parts = Vec::with_capacity(model.groups.len());
    let mut emissive_maps: std::collections::HashMap<
        String,
        std::sync::Arc<crate::texture::emission::EmissionTexture>,
    > = std::collections::HashMap::new();
    for g in model.groups {
        let Some(name) = g.material else {
            let material = lookup(&format!("{field}.material"), fallback).map_err(|e| {
                ctx.err(
                    format!("{field}.material"),
                    format!("{file:?} has faces before any `usemtl`; they take the object's `material`: {}", e),
                )
            })?;
            parts.push(Part {
                shape: Shape::Mesh(g.mesh),
                uvs: g.uvs,
                material,
                emission: None,
            });
            continue;
        };
        let mtl = model
            .materials
            .iter()
            .find(|m| m.name == name)
            .expect("the loader checks every usemtl");
        let over = format!("{shape_field}.materials_from_file[{name:?}]");
        let material = match overrides.get(&name) {
            Some(MaterialRefDesc::Named(n)) => lookup(&over, n)?,
            Some(MaterialRefDesc::Material(desc)) => {
                materials.push(Material::build(ctx, &over, desc)?);
                materials.len() as u32 - 1
            }
            None => {
                for (stmt, map) in [("map_Kd", &mtl.map_kd), ("norm", &mtl.norm)] {
                    if let Some(map) = map {
                        map_file(ctx, &shape_field, &obj, mtl, stmt, map)?;
                    }
                }
                materials.push(Material::from_mtl(ctx, &shape_field, mtl)?);
                materials.len() as u32 - 1
            }
        };
        // `map_Ke` multiplies `Ke`, which is white when the material gives only the map.
        let ke = mtl.ke.or(mtl.map_ke.as_ref().map(|_| [1.0; 3]));
        let emission = match (ke_luminance, ke) {
            (Some(l), Some(ke)) if ke.iter().any(|&v| v > 0.0) => {
                if let Some(v) = ke.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
                    return Err(ctx.err(
                        format!(
                            "{shape_field} (`Ke` of material {name:?}, '{}' line {})",
                            mtl.file.display(),
                            mtl.line
                        ),
                        format!("component {v} must be ≥ 0"),
                    ));
                }
                let texture = match &mtl.map_ke {
                    None => None,
                    Some(map) => Some(match emissive_maps.get(&name) {
                        Some(t) => t.clone(),
                        None => {
                            map_file(ctx, &shape_field, &obj, mtl, "map_Ke", map)?;
                            let t =
                                std::sync::Arc::new(emission_map(ctx, &shape_field, mtl, map, ke)?);
                            emissive_maps.insert(name.clone(), t.clone());
                            t
                        }
                    }),
                };
                let peak = ke.iter().copied().fold(0.0, f64::max);
                let y = 0.2126 * ke[0] + 0.7152 * ke[1] + 0.0722 * ke[2];
                Some(match texture {
                    None => EmissionDesc {
                        spectrum: SpectrumDesc::Rgb(ke[0] / peak, ke[1] / peak, ke[2] / peak),
                        amount: Amount::Luminance(l * y),
                        two_sided: false,
                        texture: None,
                    },
                    Some(t) => EmissionDesc {
                        spectrum: SpectrumDesc::Rgb(1.0, 1.0, 1.0),
                        amount: Amount::Luminance(l),
                        two_sided: false,
                        texture: Some(t),
                    },
                })
            }
            _ => None,
        };
        parts.push(Part {
            shape: Shape::Mesh(g.mesh),
            uvs: g.uvs,
            material,
            emission,
        });
    }
    Ok(parts)
}

/// The emission texture of material `mtl`'s `map_Ke` (relative to its MTL file), each texel's
/// linear colour multiplied by `ke`, with the map's `-s`, `-o` and `-clamp`.
fn emission_map(
    ctx: &Context,
    shape_field: &str,
    mtl: &geometry::mtl::MtlMaterial,
    map: &geometry::mtl::MtlMap,
    ke: [f64; 3],
) -> Result<crate::texture::emission::EmissionTexture, SceneError> {
    let at = format!(
        "{shape_field} (`map_Ke` of material {:?}, '{}' line {})",
        mtl.name,
        mtl.file.display(),
        mtl.line
    );
    let uv = crate::texture::scale_offset(map.scale, map.offset);
    if !uv.is_finite() {
        return Err(ctx.err(at, "its -s and -o must be finite"));
    }
    let path = mtl
        .file
        .parent()
        .unwrap_or(std::path::Path::new(""))
        .join(&map.file);
    let mut t = crate::texture::emission::EmissionTexture::load(&path, ke.map(|v| v as f32))
        .map_err(|e| ctx.err(&at, e.to_string()))?;
    t.uv = uv;
    t.wrap = if map.clamp {
        crate::texture::Wrap::Clamp
    } else {
        crate::texture::Wrap::Repeat
    };
    Ok(t)
}

/// Records `file` among the scene's sources: a render refuses to overwrite it and its state's
/// hash covers it.
pub(super) fn record(ctx: &Context, file: &std::path::Path) {
    let mut sources = ctx.sources.borrow_mut();
    if !sources.iter().any(|s| s == file) {
        sources.push(file.to_path_buf());
    }
}

/// The image of material `mtl`'s map `stmt` (relative to its MTL file), checked to lie inside
/// the OBJ file `obj`'s folder and recorded among the scene's sources.
fn map_file(
    ctx: &Context,
    shape_field: &str,
    obj: &std::path::Path,
    mtl: &geometry::mtl::MtlMaterial,
    stmt: &str,
    map: &geometry::mtl::MtlMap,
) -> Result<(), SceneError> {
    let dir = mtl.file.parent().unwrap_or(std::path::Path::new(""));
    let what = format!(
        "the `{stmt}` image of material {:?} ('{}' line {})",
        mtl.name,
        mtl.file.display(),
        mtl.line
    );
    let file = geometry::model_file(obj, dir, &map.file, &what)
        .map_err(|e| ctx.err(shape_field, e.to_string()))?;
    record(ctx, &file);
    Ok(())
}
