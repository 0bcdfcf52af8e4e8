//! From parsed scene to [`World`]: check every value, resolve spectra, convert photometric
//! amounts to radiometric light spectra, build the BVH.

use super::context::{Context, Role, SceneError};
use super::schema::*;
use crate::bxdf::{Diffuse, Frame, Material};
use crate::camera::{Camera, PixelFilter, ThinLens};
use crate::geometry::{self, SceneGeometry, Shape, Transform, TriangleMesh};
use crate::light::{Light, LightSampler};
use crate::spectrum::DenseSpectrum;
use crate::world::{Object, RenderSettings, World};
use glam::Vec3;
use std::collections::HashMap;
use std::path::Path;

/// Command-line overrides of the scene's render settings.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    pub spp: Option<u32>,
    pub seed: Option<u64>,
    pub max_depth: Option<u32>,
    /// Force per-pixel illuminance on.
    pub illuminance: bool,
    /// Override render.caustics.
    pub caustics: Option<crate::world::Caustics>,
}

/// Largest image the renderer accepts (pixels), so a typo cannot exhaust memory.
pub const MAX_PIXELS: u64 = 1 << 28;

/// How the command line runs the render, beyond [`Overrides`]: what the memory guard needs to
/// know (see [`bytes_per_pixel`]). The default is a plain render.
#[derive(Clone, Copy, Debug, Default)]
pub struct RunMode {
    /// Adaptive sampling (`--target-error`): a second, decision buffer per pixel.
    pub adaptive: bool,
    /// False-colour maps are written (`--falsecolour`).
    pub falsecolour: bool,
}

const PIXEL_SUMS: u64 = std::mem::size_of::<crate::film::PixelSums>() as u64;

/// Peak memory of a plain render per pixel: the tiles' pixel sums and the film (both alive while
/// the film is assembled), a pass's light-path sums (48 B for each of up to two buffers), plus
/// the image, EXR and PNG buffers (48 B). Measured peak RSS at 2048²: 1.58 GB (this: 1.61 GB).
const BYTES_PER_PIXEL: u64 = 2 * PIXEL_SUMS + 2 * 48 + 48;

/// Peak memory of a render per pixel in `mode`. Adaptive sampling adds the decision buffer (one
/// [`crate::film::PixelSums`] per pixel) and its per-pass statistics (16 B); its peak is then
/// while the outputs are written, so the illuminance channels and false-colour maps add 32 B.
/// Measured peak RSS at 2048² (GB): adaptive 2.20 (this: 2.18), adaptive with --illuminance
/// and/or --falsecolour 2.23–2.31 (this: 2.32). Without adaptive sampling the output buffers
/// are smaller than the film and do not raise the peak.
pub fn bytes_per_pixel(mode: &RunMode, illuminance: bool) -> u64 {
    if !mode.adaptive {
        return BYTES_PER_PIXEL;
    }
    let adaptive = BYTES_PER_PIXEL + PIXEL_SUMS + 16;
    if illuminance || mode.falsecolour {
        adaptive + 32
    } else {
        adaptive
    }
}

/// Memory this process may still allocate (Linux: MemAvailable and the cgroup limit), if known.
fn available_memory() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let kb: u64 = meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    let mut avail = kb * 1024;
    let cg = |f: &str| -> Option<u64> { std::fs::read_to_string(f).ok()?.trim().parse().ok() };
    if let (Some(max), Some(cur)) = (
        cg("/sys/fs/cgroup/memory.max"),
        cg("/sys/fs/cgroup/memory.current"),
    ) {
        avail = avail.min(max.saturating_sub(cur));
    }
    Some(avail)
}

/// Load and build a scene file (for a plain render; see [`load_world_for`]).
pub fn load_world(path: &Path, overrides: &Overrides) -> Result<World, SceneError> {
    load_world_for(path, overrides, &RunMode::default())
}

/// Load and build a scene file to be rendered in `mode` (which sizes the memory guard).
pub fn load_world_for(
    path: &Path,
    overrides: &Overrides,
    mode: &RunMode,
) -> Result<World, SceneError> {
    let scene = super::load(path)?;
    build_for(&scene, path, overrides, mode)
}

fn object_field(i: usize, o: &ObjectDesc) -> String {
    match &o.name {
        Some(n) => format!("objects[{i}] {n:?}"),
        None => format!("objects[{i}]"),
    }
}

/// A mesh file's error; an unreadable file's hint says where relative paths are resolved.
fn mesh_err(ctx: &Context, field: &str, rel: &str, e: geometry::GeometryError) -> SceneError {
    match e {
        geometry::GeometryError::Io { path, source } => ctx.err(
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

fn build_shape(ctx: &Context, field: &str, desc: &ShapeDesc) -> Result<Shape, SceneError> {
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
        ShapeDesc::Obj(rel) => Shape::Mesh(
            geometry::load_obj(&ctx.resolve(rel)).map_err(|e| mesh_err(ctx, field, rel, e))?,
        ),
        ShapeDesc::Ply(rel) => Shape::Mesh(
            geometry::load_ply(&ctx.resolve(rel)).map_err(|e| mesh_err(ctx, field, rel, e))?,
        ),
    })
}

fn build_transform(ctx: &Context, field: &str, t: &TransformDesc) -> Result<Transform, SceneError> {
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

    // Camera.
    let c = &scene.camera;
    let position = ctx.vec3("camera.position", c.position)?;
    let look_at = ctx.vec3("camera.look_at", c.look_at)?;
    let up = ctx.vec3("camera.up", c.up)?;
    let forward = look_at - position;
    if forward.length_squared() == 0.0 {
        return Err(ctx.err("camera.look_at", "look_at equals position"));
    }
    if forward.normalize().cross(up).length_squared() < 1e-12 {
        return Err(ctx.err("camera.up", "up is zero or parallel to the view direction"));
    }
    let vfov = ctx.finite("camera.vfov_deg", c.vfov_deg as f64)?;
    if !(vfov > 0.0 && vfov < 180.0) {
        return Err(ctx.err(
            "camera.vfov_deg",
            format!("the field of view must lie strictly between 0 and 180 degrees, got {vfov}"),
        ));
    }
    let (w, h) = c.resolution;
    if w == 0 || h == 0 {
        return Err(ctx.err(
            "camera.resolution",
            format!("the resolution must be at least 1×1, got {w}×{h}"),
        ));
    }
    if w as u64 * h as u64 > MAX_PIXELS {
        return Err(ctx.err(
            "camera.resolution",
            format!(
                "{w}×{h} pixels exceeds the limit of {MAX_PIXELS} pixels (the film would need {:.0} GiB)",
                w as f64 * h as f64 * BYTES_PER_PIXEL as f64 / (1u64 << 30) as f64
            ),
        ));
    }
    let illuminance = scene.render.illuminance || overrides.illuminance;
    let need = w as u64 * h as u64 * bytes_per_pixel(mode, illuminance);
    if let Some(avail) = available_memory() {
        if need > avail {
            return Err(ctx.err(
                "camera.resolution",
                format!(
                    "{w}×{h} pixels need about {:.1} GiB of memory but only {:.1} GiB is available",
                    need as f64 / (1u64 << 30) as f64,
                    avail as f64 / (1u64 << 30) as f64
                ),
            ));
        }
    }
    let lens = match &c.lens {
        None => None,
        Some(l) => {
            let r = ctx.finite("camera.lens.aperture_radius", l.aperture_radius as f64)?;
            if r < 0.0 {
                return Err(ctx.err(
                    "camera.lens.aperture_radius",
                    format!("must be ≥ 0, got {r}"),
                ));
            }
            let f = ctx.positive("camera.lens.focus_distance", l.focus_distance as f64)?;
            Some(ThinLens {
                radius: r as f32,
                focus_distance: f as f32,
            })
        }
    };
    let camera = Camera::new(
        position,
        look_at,
        up,
        vfov as f32,
        (w as usize, h as usize),
        lens,
    );

    // Render settings.
    let r = &scene.render;
    let spp = overrides.spp.unwrap_or(r.spp);
    if spp == 0 {
        return Err(ctx.err("render.spp", "samples per pixel must be at least 1"));
    }
    let max_depth = overrides.max_depth.unwrap_or(r.max_depth);
    if max_depth > 10_000 {
        return Err(ctx.err(
            "render.max_depth",
            format!("{max_depth} is unreasonably deep (limit 10000)"),
        ));
    }
    let filter = match r.filter {
        FilterDesc::Box => PixelFilter::Box,
        FilterDesc::Tent { radius } => PixelFilter::Tent {
            radius: ctx.positive("render.filter.radius", radius as f64)? as f32,
        },
        FilterDesc::Gaussian { sigma, radius } => PixelFilter::gaussian(
            ctx.positive("render.filter.sigma", sigma as f64)? as f32,
            ctx.positive("render.filter.radius", radius as f64)? as f32,
        ),
    };
    let settings = RenderSettings {
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
        let mat = match m {
            MaterialDesc::Diffuse { reflectance } => Material::Diffuse(Diffuse {
                reflectance: ctx.spectrum(
                    &format!("{field}.reflectance"),
                    reflectance,
                    Role::Reflectance,
                )?,
            }),
            MaterialDesc::Black => Material::Black,
            other => build_material(&ctx, &field, other)?,
        };
        material_index.insert(name.as_str(), materials.len() as u32);
        materials.push(mat);
    }

    // Objects and their shapes.
    let mut shapes: Vec<(Shape, u32)> = Vec::with_capacity(scene.objects.len());
    let mut objects = Vec::with_capacity(scene.objects.len());
    let mut pending_area: Vec<(u32, String, DenseSpectrum, Amount, bool)> = Vec::new();
    for (i, o) in scene.objects.iter().enumerate() {
        let field = object_field(i, o);
        let mat = *material_index.get(o.material.as_str()).ok_or_else(|| {
            let mut known: Vec<&str> = material_index.keys().copied().collect();
            known.sort();
            ctx.err(
                format!("{field}.material"),
                format!(
                    "unknown material {:?}; defined materials: {}",
                    o.material,
                    known.join(", ")
                ),
            )
        })?;
        let mut shape = build_shape(&ctx, &format!("{field}.shape"), &o.shape)?;
        if let Some(t) = &o.transform {
            let tf = build_transform(&ctx, &format!("{field}.transform"), t)?;
            shape = shape
                .to_world(&tf)
                .map_err(|e| ctx.err(format!("{field}.transform"), e.to_string()))?;
        }
        shapes.push((shape, i as u32));
        objects.push(Object {
            material: mat,
            light: None,
        });
        if let Some(e) = &o.emission {
            let s = ctx.spectrum(
                &format!("{field}.emission.spectrum"),
                &e.spectrum,
                Role::Emission,
            )?;
            pending_area.push((i as u32, field.clone(), s, e.amount, e.two_sided));
        }
    }
    // Bounding spheres of the objects that scatter specularly: where light tracing aims.
    let caustic_targets: Vec<(Vec3, f32)> = shapes
        .iter()
        .filter(|(_, o)| materials[objects[*o as usize].material as usize].has_delta_lobe())
        .filter_map(|(shape, _)| crate::world::caustic_lights::bounding_sphere(shape))
        .collect();
    let geometry = SceneGeometry::build(&shapes).map_err(|e| {
        let field = match &e {
            geometry::GeometryError::InvalidShape { object, .. } => scene
                .objects
                .get(*object as usize)
                .map(|o| format!("{}.shape", object_field(*object as usize, o))),
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
    for (object, field, s, amount, two_sided) in pending_area {
        let prims = geometry.primitives_of_object(object).to_vec();
        let areas: Vec<f64> = prims
            .iter()
            .map(|&p| geometry.prim_area(p) as f64)
            .collect();
        let total: f64 = areas.iter().sum();
        if total.is_nan() || total <= 0.0 {
            return Err(ctx.err(
                format!("{field}.emission"),
                "the emitting shape has zero area",
            ));
        }
        let afield = format!("{field}.emission.amount");
        let luminance = match amount {
            Amount::Luminance(l) => ctx.nonneg(&afield, l)?,
            Amount::Flux(phi) => {
                // Lambertian: Φ = π L A per emitting face.
                let sides = if two_sided { 2.0 } else { 1.0 };
                ctx.nonneg(&afield, phi)? / (std::f64::consts::PI * total * sides)
            }
            other => {
                return Err(ctx.err(
                    afield,
                    format!("{other:?} is not an amount for surface emission; use Luminance(cd/m²) or Flux(lm)"),
                ))
            }
        };
        let radiance = ctx.scaled_emission(
            &format!("{field}.emission.spectrum"),
            &afield,
            &s,
            luminance,
        )?;
        let cdf = crate::sampling::cdf_from_weights(&areas);
        objects[object as usize].light = Some(lights.len() as u32);
        lights.push(Light::Area {
            object,
            prims,
            cdf,
            total_area: total as f32,
            radiance,
            two_sided,
        });
    }
    for (i, l) in scene.lights.iter().enumerate() {
        let field = format!("lights[{i}]");
        let light = build_light(&ctx, &field, l)?;
        if matches!(light, Light::Environment { .. }) {
            infinite_lights.push(lights.len() as u32);
        }
        lights.push(light);
    }
    let light_sampler = LightSampler::new(&lights, &geometry, scene_radius);
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
        .map(|o| materials[o.material as usize].passes_straight())
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

fn build_light(ctx: &Context, field: &str, l: &LightDesc) -> Result<Light, SceneError> {
    let afield = format!("{field}.amount");
    let sfield = format!("{field}.spectrum");
    let scaled = |spec: &SpectrumDesc, amount: f64| ctx.emission(&sfield, &afield, spec, amount);
    let wrong = |a: &Amount, allowed: &str| {
        ctx.err(
            &afield,
            format!("{a:?} is not an amount for this light; use {allowed}"),
        )
    };
    Ok(match l {
        LightDesc::Point {
            position,
            spectrum,
            amount,
        } => {
            let cd = match amount {
                Amount::Intensity(i) => ctx.nonneg(&afield, *i)?,
                Amount::Flux(phi) => ctx.nonneg(&afield, *phi)? / (4.0 * std::f64::consts::PI),
                a => return Err(wrong(a, "Intensity(cd) or Flux(lm)")),
            };
            Light::Point {
                position: ctx.vec3(&format!("{field}.position"), *position)?,
                intensity: scaled(spectrum, cd)?,
            }
        }
        LightDesc::Spot {
            position,
            look_at,
            inner_deg,
            outer_deg,
            spectrum,
            amount,
        } => {
            let p = ctx.vec3(&format!("{field}.position"), *position)?;
            let t = ctx.vec3(&format!("{field}.look_at"), *look_at)?;
            if (t - p).length_squared() == 0.0 {
                return Err(ctx.err(format!("{field}.look_at"), "look_at equals position"));
            }
            let inner = ctx.finite(&format!("{field}.inner_deg"), *inner_deg as f64)?;
            let outer = ctx.finite(&format!("{field}.outer_deg"), *outer_deg as f64)?;
            let valid =
                (0.0..=180.0).contains(&inner) && outer > 0.0 && outer <= 180.0 && inner <= outer;
            if !valid {
                return Err(ctx.err(
                    format!("{field}.outer_deg"),
                    format!("cone half-angles must satisfy 0 ≤ inner ≤ outer ≤ 180 and outer > 0, got inner {inner}, outer {outer}"),
                ));
            }
            let (ci, co) = (inner.to_radians().cos(), outer.to_radians().cos());
            let cd = match amount {
                Amount::Intensity(i) => ctx.nonneg(&afield, *i)?,
                // Φ = ∫ I dω = 2π I [(1 − cos θi) + (cos θi − cos θo)/2] for the smoothstep falloff.
                Amount::Flux(phi) => {
                    ctx.nonneg(&afield, *phi)?
                        / (2.0 * std::f64::consts::PI * (1.0 - 0.5 * (ci + co)))
                }
                a => return Err(wrong(a, "Intensity(cd) or Flux(lm)")),
            };
            Light::Spot {
                position: p,
                frame: Frame::from_normal((t - p).normalize()),
                cos_inner: ci as f32,
                cos_outer: co as f32,
                intensity: scaled(spectrum, cd)?,
            }
        }
        LightDesc::Distant {
            direction,
            spectrum,
            amount,
        } => {
            let d = ctx.vec3(&format!("{field}.direction"), *direction)?;
            if d.length_squared() == 0.0 {
                return Err(ctx.err(
                    format!("{field}.direction"),
                    "the direction is the zero vector",
                ));
            }
            let lux = match amount {
                Amount::Illuminance(e) => ctx.nonneg(&afield, *e)?,
                a => return Err(wrong(a, "Illuminance(lx)")),
            };
            Light::Distant {
                to_light: -d.normalize(),
                irradiance: scaled(spectrum, lux)?,
            }
        }
        LightDesc::Environment {
            spectrum,
            amount,
            portals,
        } => {
            let lum = match amount {
                Amount::Luminance(l) => ctx.nonneg(&afield, *l)?,
                a => return Err(wrong(a, "Luminance(cd/m²)")),
            };
            let mut built = Vec::with_capacity(portals.len());
            for (k, d) in portals.iter().enumerate() {
                let pf = format!("{field}.portals[{k}]");
                let origin = ctx.vec3(&format!("{pf}.origin"), d.origin)?;
                let eu = ctx.vec3(&format!("{pf}.edge_u"), d.edge_u)?;
                let ev = ctx.vec3(&format!("{pf}.edge_v"), d.edge_v)?;
                built.push(crate::light::Portal::new(origin, eu, ev).ok_or_else(|| {
                    ctx.err(
                        &pf,
                        "the portal has zero area (its edges are zero or parallel)",
                    )
                })?);
            }
            Light::Environment {
                radiance: scaled(spectrum, lum)?,
                portals: crate::light::Portals::new(built),
            }
        }
        LightDesc::Goniometric {
            file,
            position,
            rotate_deg,
            spectrum,
            lumens,
            multiplier,
        } => crate::light::goniometric::build(
            &ctx.resolve(file),
            ctx.vec3(&format!("{field}.position"), *position)?,
            match rotate_deg {
                Some(r) => ctx.vec3(&format!("{field}.rotate_deg"), *r)?,
                None => Vec3::ZERO,
            },
            ctx.spectrum(&sfield, spectrum, Role::Emission)?,
            lumens
                .map(|v| ctx.nonneg(&format!("{field}.lumens"), v))
                .transpose()?,
            multiplier
                .map(|v| ctx.nonneg(&format!("{field}.multiplier"), v))
                .transpose()?,
        )
        .map_err(|(sub, m)| ctx.err(format!("{field}{sub}"), m))?,
    })
}

/// The scattering materials other than `Diffuse`/`Black` (the BSDF library, src/bxdf).
fn build_material(ctx: &Context, field: &str, m: &MaterialDesc) -> Result<Material, SceneError> {
    use crate::bxdf::{self, ior};
    let refl = |name: &str, d: &SpectrumDesc| {
        ctx.spectrum(&format!("{field}.{name}"), d, Role::Reflectance)
    };
    let microfacet = |dist: DistributionDesc,
                      masking: MaskingDesc,
                      r: f32,
                      rv: Option<f32>|
     -> Result<bxdf::Microfacet, SceneError> {
        let check = |name: &str, v: f32| {
            if !v.is_finite() || v < 0.0 {
                Err(ctx.err(
                    format!("{field}.{name}"),
                    format!("roughness must be a finite number ≥ 0, got {v}"),
                ))
            } else {
                Ok(v)
            }
        };
        let ax = check("roughness", r)?;
        let ay = match rv {
            Some(v) => check("roughness_v", v)?,
            None => ax,
        };
        let dist = match dist {
            DistributionDesc::Ggx => bxdf::Distribution::Ggx,
            DistributionDesc::Beckmann => bxdf::Distribution::Beckmann,
        };
        let masking = match masking {
            MaskingDesc::Smith => bxdf::Masking::Smith,
            MaskingDesc::VCavity => bxdf::Masking::VCavity,
        };
        // Below 1e-3 the lobe is a delta; keep both axes consistent.
        let (ax, ay) = if ax.max(ay) < 1e-3 {
            (0.0, 0.0)
        } else {
            (ax.max(1e-3), ay.max(1e-3))
        };
        Ok(bxdf::Microfacet::new(dist, ax, ay, masking))
    };
    let dielectric_ior = |d: &IorDesc| -> Result<bxdf::Ior, SceneError> {
        let f = format!("{field}.ior");
        let ior = match d {
            IorDesc::Constant(n) => bxdf::Ior::Constant(*n),
            IorDesc::Glass(name) => ior::named_glass(name)
                .ok_or_else(|| {
                    ctx.err(
                        &f,
                        format!(
                            "unknown glass {name:?}; known glasses: {}",
                            ior::glass_names().join(", ")
                        ),
                    )
                })?
                .ior
                .clone(),
            IorDesc::Cauchy { a, b, c } => {
                for v in [a, b, c] {
                    ctx.finite(&f, *v)?;
                }
                bxdf::Ior::Cauchy {
                    a: *a,
                    b: *b,
                    c: *c,
                }
            }
            IorDesc::Sellmeier { b, c } => {
                for v in b.iter().chain(c) {
                    ctx.finite(&f, *v)?;
                }
                bxdf::Ior::Sellmeier { b: *b, c: *c }
            }
        };
        let (lo, hi) = ior.range();
        if !(lo.is_finite() && hi.is_finite()) || lo <= 0.0 {
            return Err(ctx.err(
                &f,
                format!(
                    "the refractive index must be finite and greater than 0 over 360–830 nm (range {lo} to {hi})"
                ),
            ));
        }
        Ok(ior)
    };
    Ok(match m {
        MaterialDesc::OrenNayar {
            reflectance,
            sigma_deg,
        } => {
            let s = *sigma_deg;
            if !s.is_finite() || !(0.0..=90.0).contains(&s) {
                return Err(ctx.err(
                    format!("{field}.sigma_deg"),
                    format!("must be an angle in [0, 90] degrees, got {s}"),
                ));
            }
            Material::OrenNayar(bxdf::OrenNayar::new(
                refl("reflectance", reflectance)?,
                s.to_radians(),
            ))
        }
        MaterialDesc::Phong {
            diffuse,
            specular,
            exponent,
        } => {
            let kd = refl("diffuse", diffuse)?;
            let ks = refl("specular", specular)?;
            if !exponent.is_finite() || *exponent < 0.0 {
                return Err(ctx.err(
                    format!("{field}.exponent"),
                    format!("must be a finite number ≥ 0, got {exponent}"),
                ));
            }
            if let Some(i) = (0..kd.values.len()).find(|&i| kd.values[i] + ks.values[i] > 1.0) {
                return Err(ctx.err(
                    field,
                    format!(
                        "diffuse + specular = {} at {} nm exceeds 1; the surface would create energy",
                        kd.values[i] + ks.values[i],
                        360 + i
                    ),
                ));
            }
            Material::Phong(bxdf::Phong::new(kd, ks, *exponent))
        }
        MaterialDesc::Conductor {
            metal,
            n,
            k,
            roughness,
            roughness_v,
            distribution,
            masking,
        } => {
            let ior = match (metal, n, k) {
                (Some(name), None, None) => ior::named_metal(name)
                    .ok_or_else(|| {
                        ctx.err(
                            format!("{field}.metal"),
                            format!(
                                "unknown metal {name:?}; known metals: {}",
                                ior::metal_names().join(", ")
                            ),
                        )
                    })?
                    .clone(),
                (None, Some(n), Some(k)) => {
                    for (name, d) in [("n", n), ("k", k)] {
                        if matches!(d, SpectrumDesc::Blackbody(_) | SpectrumDesc::Rgb(..)) {
                            return Err(ctx.err(
                                format!("{field}.{name}"),
                                "an optical constant must be Constant, Tabulated, Csv or Named",
                            ));
                        }
                    }
                    let n = ctx.spectrum(&format!("{field}.n"), n, Role::Emission)?;
                    let k = ctx.spectrum(&format!("{field}.k"), k, Role::Emission)?;
                    if n.min_value() <= 0.0 {
                        return Err(ctx.err(
                            format!("{field}.n"),
                            "the refractive index n must be greater than 0",
                        ));
                    }
                    bxdf::ConductorIor { n, k }
                }
                _ => {
                    return Err(ctx.err(
                        field,
                        "give either `metal` (a name) or both `n` and `k` (spectra)",
                    ))
                }
            };
            Material::Conductor(bxdf::Conductor {
                ior,
                mf: microfacet(*distribution, *masking, *roughness, *roughness_v)?,
            })
        }
        MaterialDesc::Dielectric {
            ior,
            roughness,
            roughness_v,
            distribution,
        } => Material::Dielectric(bxdf::Dielectric {
            ior: dielectric_ior(ior)?,
            mf: microfacet(*distribution, MaskingDesc::Smith, *roughness, *roughness_v)?,
        }),
        MaterialDesc::ThinDielectric { ior } => Material::ThinDielectric(bxdf::ThinDielectric {
            ior: dielectric_ior(ior)?,
        }),
        MaterialDesc::Coated {
            base,
            ior,
            roughness,
            distribution,
        } => {
            if !ior.is_finite() || *ior <= 0.0 {
                return Err(ctx.err(
                    format!("{field}.ior"),
                    format!("the refractive index must be finite and greater than 0, got {ior}"),
                ));
            }
            Material::Coated(bxdf::Coated::new(
                refl("base", base)?,
                *ior,
                microfacet(*distribution, MaskingDesc::Smith, *roughness, None)?,
            ))
        }
        MaterialDesc::Diffuse { .. } | MaterialDesc::Black => unreachable!("handled by build"),
    })
}
