//! From parsed scene to [`World`]: check every value, resolve spectra, convert photometric
//! amounts to radiometric light spectra, build the BVH.

use crate::bxdf::{Material, MaterialFlags};
use crate::camera::{Camera, PixelFilter};
use crate::description::context::{Context, SceneError};
use crate::description::schema::*;
use crate::geometry::{self, SceneGeometry, Shape, Transform};
use crate::light::{AreaLight, Light, LightFlags, LightSampler, LightSamplerKind};
use crate::world::{Object, RenderSettings, World};
use glam::Vec3;
use std::collections::HashMap;
use std::path::Path;

mod instances;
mod obj_model;

use instances::{instance_group, instance_spheres, InstanceParts};
use obj_model::{model_parts, Part};

/// Overrides of the scene's render settings by the job (`candela render`'s options).
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    pub spp: Option<u32>,
    pub seed: Option<u64>,
    pub max_depth: Option<u32>,
    /// Force per-pixel illuminance on.
    pub illuminance: bool,
    /// Override render.caustics.
    pub caustics: Option<crate::world::Caustics>,
    /// Override camera.resolution (width, height), pixels.
    pub resolution: Option<(u32, u32)>,
    /// The camera of a glTF scene file: the index of its camera node (0-based, scene order) or
    /// its node or camera name; `None` the first. Refused for a RON scene, which has one camera.
    pub camera: Option<String>,
}

/// Largest image the renderer accepts (pixels), so a typo cannot exhaust memory.
pub const MAX_PIXELS: u64 = 1 << 28;

/// How the job runs the render, beyond [`Overrides`]: what the memory guard needs to
/// know (see [`bytes_per_pixel`]). The default is a plain render.
#[derive(Clone, Copy, Debug, Default)]
pub struct RunMode {
    /// Adaptive sampling (`--target-error`): a second, decision buffer per pixel.
    pub adaptive: bool,
    /// False-colour maps are written (`--falsecolour`).
    pub falsecolour: bool,
}

const PIXEL_SUMS: u64 = std::mem::size_of::<crate::film::PixelSums>() as u64;
const E_SUMS: u64 = std::mem::size_of::<crate::film::IlluminanceSums>() as u64;

/// Bytes of one pixel of one film buffer: its sums, and its illuminance sums if the render
/// estimates illuminance (208 B, 376 B).
fn sums_bytes(illuminance: bool) -> u64 {
    PIXEL_SUMS + if illuminance { E_SUMS } else { 0 }
}

/// Peak memory of a render's own buffers per pixel in `mode`, without the render state (see
/// [`peak_bytes_per_pixel`] for the whole job). During a pass: the film, the next film buffer
/// that the pass's image sums go to, and the tiles' decision and illuminance sums; at the end,
/// once those are freed, the film and the finished render's copy of it; plus the image, EXR
/// and PNG buffers (48 B) and the pass plan (8 B). How much of the tiles' sums the allocator
/// still holds when the copy is made is measured, not derived: at 2048² the peak held two
/// copies of the pixel sums and three of the illuminance sums of a plain render, and five
/// copies of the pixel sums and four of the illuminance sums with adaptive sampling (two
/// buffers, each in the film and the copy, and the tiles' decision sums), whose per-pass
/// statistics, illuminance channels and false-colour maps are within that but for 32 B.
/// Measured peak RSS: see tests/scene_errors.rs.
pub fn bytes_per_pixel(mode: &RunMode, illuminance: bool) -> u64 {
    let e = if illuminance { E_SUMS } else { 0 };
    if !mode.adaptive {
        return 2 * PIXEL_SUMS + 3 * e + 56;
    }
    let adaptive = 5 * PIXEL_SUMS + 4 * e;
    if illuminance || mode.falsecolour {
        adaptive + 32
    } else {
        adaptive
    }
}

/// Memory of a render besides its per-pixel buffers: the program, the scene, the threads and
/// light tracing's batches of splats (measured: 50 to 130 MB).
pub const RENDER_BASE_BYTES: u64 = 150 << 20;

/// A film buffer's pixel in a render state file (postcard: 24 f64, 16 of them batch sums, and
/// 2 variable-length counts; with illuminance 20 f64 more and a count), with the slack of the
/// growing encoding buffer.
fn state_pixel_bytes(illuminance: bool) -> u64 {
    200 + if illuminance { 166 } else { 0 }
}

/// Peak memory per pixel of a render as `candela render` runs it in `mode` (add
/// [`RENDER_BASE_BYTES`] once). The larger of
/// * the render's own buffers, [`bytes_per_pixel`], and
/// * writing the render state at the end (`--save-state`, `--resume`): the film, the finished
///   render's copy of it and the state's encoding, per film buffer (two with adaptive
///   sampling); a checkpoint during the render holds one copy fewer;
///
/// and, with light-traced caustics, 96 B per film buffer: a pass's light-path sums (48 B) and
/// as much again for what the allocator keeps of light tracing's splat batches (measured:
/// 35 to 65 B in all). Measured peak RSS
/// with a checkpoint after every pass and the state written at the end: see
/// tests/hostile_memory.rs.
pub fn peak_bytes_per_pixel(mode: &RunMode, illuminance: bool, caustics: bool) -> u64 {
    let buffers = if mode.adaptive { 2 } else { 1 };
    let sums = sums_bytes(illuminance);
    let mut state = buffers * (2 * sums + state_pixel_bytes(illuminance));
    if mode.adaptive && (illuminance || mode.falsecolour) {
        state += 32;
    }
    let peak = bytes_per_pixel(mode, illuminance).max(state);
    if caustics {
        peak + buffers * 96
    } else {
        peak
    }
}

/// Refuse a film of `w`×`h` pixels beyond [`MAX_PIXELS`].
fn check_film_size(ctx: &Context, w: u32, h: u32) -> Result<(), SceneError> {
    if w as u64 * h as u64 > MAX_PIXELS {
        return Err(ctx.err(
            "camera.resolution",
            format!(
                "{w}×{h} pixels exceeds the limit of {MAX_PIXELS} pixels (the film would need {:.0} GiB)",
                w as f64 * h as f64 * bytes_per_pixel(&RunMode::default(), false) as f64 / crate::limits::GIB
            ),
        ));
    }
    Ok(())
}

/// Refuse a film of `w`×`h` pixels that a render in `mode` could not hold in the memory
/// available (see [`peak_bytes_per_pixel`]).
fn check_film_memory(
    ctx: &Context,
    (w, h): (u32, u32),
    mode: &RunMode,
    illuminance: bool,
    caustics: bool,
) -> Result<(), SceneError> {
    let need =
        w as u64 * h as u64 * peak_bytes_per_pixel(mode, illuminance, caustics) + RENDER_BASE_BYTES;
    if let Some(avail) = crate::limits::available_memory_bytes() {
        if need > avail {
            let traced = if caustics {
                ", with light-traced caustics"
            } else {
                ""
            };
            return Err(ctx.err(
                "camera.resolution",
                format!(
                    "{w}×{h} pixels need about {:.1} GiB of memory{traced} but only {:.1} GiB is available",
                    need as f64 / crate::limits::GIB,
                    avail as f64 / crate::limits::GIB
                ),
            ));
        }
    }
    Ok(())
}

/// Load and build a scene file, RON or glTF (for a plain render; see [`load_world_for`]).
pub fn load_world(path: &Path, overrides: &Overrides) -> Result<World, SceneError> {
    load_world_for(path, overrides, &RunMode::default())
}

/// Load and build a scene file to be rendered in `mode` (which sizes the memory guard): a RON
/// scene, or a glTF file as a whole scene ([`super::gltf_scene`]).
pub fn load_world_for(
    path: &Path,
    overrides: &Overrides,
    mode: &RunMode,
) -> Result<World, SceneError> {
    let scene = if super::gltf_scene::is_gltf_path(path) {
        super::gltf_scene::scene(path, overrides.camera.as_deref(), overrides.resolution)?
    } else {
        let scene = super::load(path)?;
        if let (Some(c), None) = (&overrides.camera, &scene.camera.from_model) {
            return Err(SceneError::Invalid {
                path: path.to_path_buf(),
                field: "camera".into(),
                message: format!(
                    "--camera {c} chooses among a glTF file's cameras; this RON scene has its one `camera` (a `camera: (from_model: …)` takes --camera)"
                ),
            });
        }
        scene
    };
    build_for(&scene, path, overrides, mode)
}

fn object_field(i: usize, o: &ObjectDesc) -> String {
    match &o.name {
        Some(n) => format!("objects[{i}] {n:?}"),
        None => format!("objects[{i}]"),
    }
}

/// Check one scene and build the world (for a plain render; see [`build_for`]).
pub fn build(scene: &SceneFile, path: &Path, overrides: &Overrides) -> Result<World, SceneError> {
    build_for(scene, path, overrides, &RunMode::default())
}

/// Check one scene and build the world to be rendered in `mode` (which sizes the memory guard).
pub fn build_for(
    scene: &SceneFile,
    path: &Path,
    overrides: &Overrides,
    mode: &RunMode,
) -> Result<World, SceneError> {
    let ctx = Context {
        path,
        dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        sources: Default::default(),
    };

    // Camera, and the film its resolution asks for.
    let illuminance = scene.render.illuminance || overrides.illuminance;
    let mut camera_desc =
        super::gltf_scene::model_camera(&ctx, scene, overrides.camera.as_deref())?;
    if let Some(r) = overrides.resolution {
        camera_desc.resolution = r;
    }
    let camera = Camera::build(&ctx, &camera_desc, |w, h| check_film_size(&ctx, w, h))?;

    // Render settings.
    let r = &scene.render;
    let spp = overrides.spp.unwrap_or(r.spp);
    if spp == 0 {
        return Err(ctx.err("render.spp", "samples per pixel must be at least 1"));
    }
    let max_depth = overrides.max_depth.or(r.max_depth);
    if let Some(max_depth) = max_depth.filter(|&d| d > 10_000) {
        return Err(ctx.err(
            "render.max_depth",
            format!("{max_depth} is unreasonably deep (limit 10000)"),
        ));
    }
    // Without a depth limit, a path that loses no light (a closed box of reflectance 1) only
    // ends once Russian roulette begins, after rr_depth scatterings.
    if r.rr_depth > 10_000 {
        return Err(ctx.err(
            "render.rr_depth",
            format!("{} is unreasonably deep (limit 10000)", r.rr_depth),
        ));
    }
    let filter = PixelFilter::build(&ctx, &r.filter)?;
    if !crate::film::PIXEL_BATCH_CHOICES.contains(&r.pixel_batches) {
        return Err(ctx.err(
            "render.pixel_batches",
            format!(
                "{} is not one of 2, 4, 8 or 16: the independent sample sequences per pixel whose spread gives its standard error",
                r.pixel_batches
            ),
        ));
    }
    let settings = RenderSettings {
        pixel_batches: r.pixel_batches,
        spp,
        max_depth,
        rr_depth: r.rr_depth,
        seed: overrides.seed.unwrap_or(r.seed),
        filter,
        illuminance,
        light_paths_per_sample: {
            let v = r.light_paths_per_sample as f64;
            if !(v > 0.0 && v <= 1024.0) {
                return Err(ctx.err(
                    "render.light_paths_per_sample",
                    format!("{v} must be a number in (0, 1024]: light paths traced per camera sample for caustics"),
                ));
            }
            v as f32
        },
        light_sampler: match r.light_sampler {
            crate::description::schema::LightSamplerDesc::Bvh => LightSamplerKind::Bvh,
            crate::description::schema::LightSamplerDesc::Power => LightSamplerKind::Power,
        },
        caustics: overrides.caustics.unwrap_or(match r.caustics {
            CausticsDesc::LightTracing => crate::world::Caustics::LightTracing,
            CausticsDesc::PathTracing => crate::world::Caustics::PathTracing,
        }),
    };

    // Materials.
    let mut materials = vec![Material::Black];
    let mut material_index: HashMap<&str, u32> = HashMap::new();
    material_index.insert("black", 0);
    for (name, m) in &scene.materials {
        let field = format!("materials[{name:?}]");
        if name == "black" {
            return Err(ctx.err(
                field,
                "\"black\" is predefined (it absorbs all light) and cannot be redefined; give this material another name",
            ));
        }
        let mat = Material::build(&ctx, &field, m)?;
        material_index.insert(name.as_str(), materials.len() as u32);
        materials.push(mat);
    }

    // Objects and their shapes. A `Model` becomes one object per material it uses, so the
    // world's objects are numbered apart from the scene's: `scene_object` maps them back.
    let mut shapes: Vec<(Shape, u32)> = Vec::with_capacity(scene.objects.len());
    let mut shape_uvs: Vec<Option<Vec<glam::Vec2>>> = Vec::new();
    let mut scene_object: Vec<usize> = Vec::with_capacity(scene.objects.len());
    let mut objects = Vec::with_capacity(scene.objects.len());
    let mut pending_area: Vec<(u32, String, EmissionDesc, crate::light::EmissionShape)> =
        Vec::new();
    let mut model_lights: Vec<(String, LightDesc)> = Vec::new();
    let mut groups: Vec<(usize, InstanceParts)> = Vec::new();
    let lookup = |field: &str, name: &str| -> Result<u32, SceneError> {
        material_index.get(name).copied().ok_or_else(|| {
            let mut known: Vec<&str> = material_index.keys().copied().collect();
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
        })
    };
    for (i, o) in scene.objects.iter().enumerate() {
        let field = object_field(i, o);
        let transform = match &o.transform {
            Some(t) => Some(Transform::build(&ctx, &format!("{field}.transform"), t)?),
            None => None,
        };
        let place = |shape: Shape| -> Result<Shape, SceneError> {
            match &transform {
                Some(tf) => shape
                    .to_world(tf)
                    .map_err(|e| ctx.err(format!("{field}.transform"), e.to_string())),
                None => Ok(shape),
            }
        };
        // An `Instances` shape: its mesh's parts, placed at each of its transforms below.
        let (shape_desc, instances) = match &o.shape {
            ShapeDesc::Instances { mesh, transforms } => (
                mesh.as_ref(),
                Some(Transform::build_instances(
                    &ctx,
                    &format!("{field}.shape"),
                    transforms,
                )?),
            ),
            desc => (desc, None),
        };
        let shape_field = match instances {
            Some(_) => format!("{field}.shape.mesh"),
            None => format!("{field}.shape"),
        };
        let parts = match shape_desc {
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
                let at = format!("{field}.shape");
                let (flat, shared, found) = super::gltf::model_parts(
                    &ctx,
                    &at,
                    model,
                    (transform.as_ref(), &o.material, &lookup),
                    &mut materials,
                )?;
                model_lights.extend(found);
                let part = |p: super::gltf::GltfPart| Part {
                    shape: p.shape,
                    uvs: p.uvs,
                    material: p.material,
                    emission: p.emission,
                };
                let mut parts: Vec<Part> = flat.into_iter().map(part).collect();
                for g in shared {
                    if instances.is_some() {
                        // Inside `Instances`, the model is the instanced mesh: one level.
                        parts.extend(g.flatten(&ctx, &at)?.into_iter().map(part));
                        continue;
                    }
                    let gparts = g.parts.into_iter().map(part).collect();
                    match instance_group(&ctx, &at, gparts, g.transforms, transform.as_ref())? {
                        Ok(group) => {
                            add_group(i, group, &mut scene_object, &mut objects, &mut groups)
                        }
                        Err(copies) => parts.extend(copies),
                    }
                }
                parts
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
                &ctx,
                &field,
                (file, materials_from_file, *ke_luminance),
                &o.material,
                &lookup,
                &mut materials,
            )?,
            desc => vec![Part {
                shape: Shape::build(&ctx, &shape_field, desc)?,
                uvs: None,
                material: lookup(&format!("{field}.material"), &o.material)?,
                emission: o.emission.clone(),
            }],
        };
        let parts = match instances {
            Some(tfs) => match instance_group(&ctx, &field, parts, tfs, transform.as_ref())? {
                Ok(group) => {
                    add_group(i, group, &mut scene_object, &mut objects, &mut groups);
                    continue;
                }
                Err(copies) => copies,
            },
            None => parts,
        };
        for part in parts {
            let id = objects.len() as u32;
            shapes.push((place(part.shape)?, id));
            if part.uvs.is_some() {
                shape_uvs.resize(shapes.len(), None);
                shape_uvs[shapes.len() - 1] = part.uvs;
            }
            scene_object.push(i);
            objects.push(Object {
                material: part.material,
                light: None,
            });
            if let Some(e) = part.emission {
                let s = AreaLight::spectrum(&ctx, &field, &e)?;
                pending_area.push((id, field.clone(), e, s));
            }
        }
    }
    // Bounding spheres of the objects that scatter specularly: where light tracing aims.
    let caustic_targets: Vec<(Vec3, f32)> = shapes
        .iter()
        .filter(|(_, o)| {
            materials[objects[*o as usize].material as usize]
                .flags()
                .contains(MaterialFlags::DELTA)
        })
        .filter_map(|(shape, _)| crate::world::caustic_lights::bounding_sphere(shape))
        .chain(
            groups
                .iter()
                .flat_map(|(_, g)| instance_spheres(g, &materials)),
        )
        .collect();
    // The film's memory, before the BVH is built: light tracing (when anything can start and
    // aim its paths) keeps more per pixel.
    let caustics = settings.caustics == crate::world::Caustics::LightTracing
        && crate::world::caustic_lights::may_trace(
            &caustic_targets,
            !pending_area.is_empty(),
            scene.lights.iter().any(|l| {
                !matches!(
                    l,
                    LightDesc::Environment { .. } | LightDesc::Sky { .. } | LightDesc::Sun { .. }
                )
            }),
        );
    check_film_memory(
        &ctx,
        (camera.width as u32, camera.height as u32),
        mode,
        illuminance,
        caustics,
    )?;
    let uvs: Vec<Option<&[glam::Vec2]>> = shape_uvs.iter().map(|u| u.as_deref()).collect();
    let instance_groups: Vec<geometry::InstanceGroup> = groups
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
    let geometry =
        SceneGeometry::build_instanced(&shapes, &uvs, &instance_groups).map_err(|e| {
            let field = match &e {
                geometry::GeometryError::InvalidShape { object, .. } => scene_object
                    .get(*object as usize)
                    .map(|&i| format!("{}.shape", object_field(i, &scene.objects[i]))),
                _ => None,
            };
            ctx.err(field.unwrap_or_else(|| "objects".into()), e.to_string())
        })?;
    let (lo, hi) = geometry.bounds();
    let scene_radius = if lo.is_finite() && hi.is_finite() && hi.cmpge(lo).all() {
        (0.5 * (hi - lo).length()).max(1e-6)
    } else {
        1.0
    };

    // Lights.
    let mut lights: Vec<Light> = Vec::new();
    let mut infinite_lights = Vec::new();
    for (object, field, e, s) in pending_area {
        let light = AreaLight::build(&ctx, &field, object, &e, &s, &geometry)?;
        objects[object as usize].light = Some(lights.len() as u32);
        lights.push(Light::Area(light));
    }
    let frame = site_frame(&ctx, &scene.site)?;
    // Skies come last: their ground reflects the suns.
    let mut sky = None;
    let mut suns_horizontal = crate::spectrum::DenseSpectrum::constant(0.0);
    let mut push = |light: Light, lights: &mut Vec<Light>| {
        if light.flags().contains(LightFlags::INFINITE) {
            infinite_lights.push(lights.len() as u32);
        }
        lights.push(light);
    };
    for (field, l) in &model_lights {
        push(build_light(&ctx, field, l)?, &mut lights);
    }
    for (i, l) in scene.lights.iter().enumerate() {
        let field = format!("lights[{i}]");
        let light = match l {
            LightDesc::Sky { .. } | LightDesc::Weather { .. } => {
                if let Some((j, _)) = sky {
                    return Err(ctx.err(
                        &field,
                        format!("a scene has one sky, and lights[{j}] is one already"),
                    ));
                }
                sky = Some((i, l));
                continue;
            }
            LightDesc::Sun {
                sun,
                amount,
                spectrum,
            } => {
                let (s, _) = crate::light::SunLight::build(
                    &ctx,
                    &field,
                    sun,
                    *amount,
                    spectrum.as_ref(),
                    &frame,
                )?;
                let h = s.horizontal_irradiance(&frame);
                for (a, b) in suns_horizontal.values.iter_mut().zip(h.values.iter()) {
                    *a += *b;
                }
                Light::Sun(s)
            }
            _ => build_light(&ctx, &field, l)?,
        };
        push(light, &mut lights);
    }
    let weather;
    let desc = match sky {
        Some((
            i,
            LightDesc::Sky {
                model,
                sun,
                amount,
                spectrum,
                ground_reflectance,
                portals,
                sun_disk,
            },
        )) => Some((
            i,
            crate::light::sky::SkyDesc {
                model,
                sun: sun.as_ref(),
                amount: *amount,
                spectrum: spectrum.as_ref(),
                ground_reflectance: *ground_reflectance,
                portals,
                sun_disk: *sun_disk,
            },
        )),
        Some((
            i,
            LightDesc::Weather {
                file,
                time,
                spectrum,
                ground_reflectance,
                portals,
                sun_disk,
            },
        )) => {
            weather = crate::light::sky::weather_sky(&ctx, &format!("lights[{i}]"), file, time)?;
            Some((
                i,
                crate::light::sky::SkyDesc {
                    model: &weather.0,
                    sun: Some(&weather.1),
                    amount: None,
                    spectrum: spectrum.as_ref(),
                    ground_reflectance: *ground_reflectance,
                    portals,
                    sun_disk: *sun_disk,
                },
            ))
        }
        _ => None,
    };
    if let Some((i, desc)) = desc {
        let (s, perez_sun) = crate::light::SkyLight::build(
            &ctx,
            &format!("lights[{i}]"),
            &desc,
            &frame,
            &suns_horizontal,
        )?;
        push(Light::Sky(Box::new(s)), &mut lights);
        if let Some(sun) = perez_sun {
            push(Light::Sun(sun), &mut lights);
        }
    }
    let light_sampler = LightSampler::new(settings.light_sampler, &lights, &geometry, scene_radius);
    let (meters, grids, measure) =
        crate::world::measure::build_meters(&ctx, &scene.meters, &scene.grids, &scene.measure)?;
    let caustics = match settings.caustics {
        crate::world::Caustics::LightTracing => {
            crate::world::CausticLights::new(&lights, caustic_targets, &geometry, scene_radius)
        }
        crate::world::Caustics::PathTracing => None,
    };

    let mut see_through: Vec<bool> = objects
        .iter()
        .map(|o| {
            materials[o.material as usize]
                .flags()
                .contains(MaterialFlags::STRAIGHT_THROUGH)
        })
        .collect();
    if !see_through.contains(&true) {
        see_through.clear();
    }
    Ok(World {
        geometry,
        see_through,
        objects,
        materials,
        lights,
        light_sampler,
        infinite_lights,
        camera,
        settings,
        meters,
        grids,
        measure,
        caustics,
        sources: ctx.sources.into_inner(),
    })
}

/// Adds instance group `group` of scene object `i`: a world object per part and instance, in
/// the order [`geometry::InstanceGroup`] numbers them.
fn add_group(
    i: usize,
    group: InstanceParts,
    scene_object: &mut Vec<usize>,
    objects: &mut Vec<Object>,
    groups: &mut Vec<(usize, InstanceParts)>,
) {
    let first = objects.len();
    for _ in &group.transforms {
        for part in &group.parts {
            scene_object.push(i);
            objects.push(Object {
                material: part.material,
                light: None,
            });
        }
    }
    groups.push((first, group));
}

/// The site's frame from `site`.
fn site_frame(
    ctx: &Context,
    site: &crate::description::schema::SiteDesc,
) -> Result<crate::light::SiteFrame, SceneError> {
    let up = ctx.unit("site.up", site.up)?.as_dvec3();
    let north = ctx.unit("site.north", site.north)?.as_dvec3();
    if up.normalize().cross(north.normalize()).length() < 1e-3 {
        return Err(ctx.err("site.north", "north is parallel to up"));
    }
    crate::light::SiteFrame::new(up, north)
        .ok_or_else(|| ctx.err("site.north", "north is parallel to up"))
}

fn build_light(ctx: &Context, field: &str, l: &LightDesc) -> Result<Light, SceneError> {
    use crate::light::*;
    Ok(match l {
        LightDesc::Point {
            position,
            spectrum,
            amount,
        } => Light::Point(PointLight::build(ctx, field, *position, spectrum, *amount)?),
        LightDesc::Spot {
            position,
            look_at,
            inner_deg,
            outer_deg,
            spectrum,
            amount,
        } => Light::Spot(SpotLight::build(
            ctx, field, *position, *look_at, *inner_deg, *outer_deg, spectrum, *amount,
        )?),
        LightDesc::Distant {
            direction,
            spectrum,
            amount,
        } => Light::Distant(DistantLight::build(
            ctx, field, *direction, spectrum, *amount,
        )?),
        LightDesc::Environment {
            spectrum,
            amount,
            portals,
        } => Light::Environment(EnvironmentLight::build(
            ctx, field, spectrum, *amount, portals,
        )?),
        LightDesc::Goniometric {
            file,
            position,
            rotate_deg,
            spectrum,
            lumens,
            multiplier,
        } => Light::Goniometric(Box::new(GoniometricLight::build(
            ctx,
            field,
            &goniometric::GoniometricDesc {
                file,
                position: *position,
                rotate_deg: *rotate_deg,
                spectrum,
                lumens: *lumens,
                multiplier: *multiplier,
            },
        )?)),
        LightDesc::Sky { .. } | LightDesc::Weather { .. } | LightDesc::Sun { .. } => {
            unreachable!("skies and suns are built beside the site's frame")
        }
    })
}
