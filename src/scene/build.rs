//! From parsed scene to [`World`]: check every value, resolve spectra, convert photometric
//! amounts to radiometric light spectra, build the BVH.

use crate::bxdf::{Material, MaterialFlags};
use crate::camera::{Camera, PixelFilter};
use crate::description::context::{Context, SceneError};
use crate::description::schema::*;
use crate::geometry::SceneGeometry;
use crate::light::{LightSampler, LightSamplerKind};
use crate::world::{Object, RenderSettings, World};
use std::collections::HashMap;
use std::path::Path;

mod instances;
mod lights;
mod obj_model;
mod objects;

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
    let illuminance = scene.render.illuminance || overrides.illuminance;
    let camera = build_camera(&ctx, scene, overrides)?;
    let settings = render_settings(&ctx, &scene.render, overrides, illuminance)?;
    let (mut materials, index) = build_materials(&ctx, scene)?;
    let mut objects = objects::build_objects(&ctx, scene, &index, &mut materials)?;
    let caustic_targets = objects.caustic_targets(&materials);
    // The film's memory, before the BVH is built: light tracing (when anything can start and
    // aim its paths) keeps more per pixel.
    let caustics = settings.caustics == crate::world::Caustics::LightTracing
        && crate::world::caustic_lights::may_trace(
            &caustic_targets,
            !objects.pending_area.is_empty(),
            scene.lights.iter().any(|l| {
                !matches!(
                    l,
                    LightDesc::Environment { .. } | LightDesc::Sky { .. } | LightDesc::Sun { .. }
                )
            }),
        );
    let size = (camera.width as u32, camera.height as u32);
    check_film_memory(&ctx, size, mode, illuminance, caustics)?;
    let geometry = objects.geometry(&ctx, scene)?;
    let scene_radius = scene_radius(&geometry);
    let lights = lights::build_lights(&ctx, scene, &mut objects, &geometry)?;
    let light_sampler = LightSampler::new(
        settings.light_sampler,
        &lights.lights,
        &geometry,
        scene_radius,
    );
    let (meters, grids, measure) =
        crate::world::measure::build_meters(&ctx, &scene.meters, &scene.grids, &scene.measure)?;
    let caustics = match settings.caustics {
        crate::world::Caustics::LightTracing => crate::world::CausticLights::new(
            &lights.lights,
            caustic_targets,
            &geometry,
            scene_radius,
        ),
        crate::world::Caustics::PathTracing => None,
    };
    let see_through = see_through(&objects.objects, &materials);
    Ok(World {
        geometry,
        see_through,
        objects: objects.objects,
        materials,
        lights: lights.lights,
        light_sampler,
        infinite_lights: lights.infinite,
        camera,
        settings,
        meters,
        grids,
        measure,
        caustics,
        sources: ctx.sources.into_inner(),
    })
}

/// The camera, with the film its resolution asks for checked.
fn build_camera(
    ctx: &Context,
    scene: &SceneFile,
    overrides: &Overrides,
) -> Result<Camera, SceneError> {
    let mut desc = super::gltf_scene::model_camera(ctx, scene, overrides.camera.as_deref())?;
    if let Some(r) = overrides.resolution {
        desc.resolution = r;
    }
    Camera::build(ctx, &desc, |w, h| check_film_size(ctx, w, h))
}

/// The render settings of `r`, overridden by the job's `overrides`.
fn render_settings(
    ctx: &Context,
    r: &RenderDesc,
    overrides: &Overrides,
    illuminance: bool,
) -> Result<RenderSettings, SceneError> {
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
    let filter = PixelFilter::build(ctx, &r.filter)?;
    if !crate::film::PIXEL_BATCH_CHOICES.contains(&r.pixel_batches) {
        return Err(ctx.err(
            "render.pixel_batches",
            format!(
                "{} is not one of 2, 4, 8 or 16: the independent sample sequences per pixel whose spread gives its standard error",
                r.pixel_batches
            ),
        ));
    }
    let light_paths = r.light_paths_per_sample as f64;
    if !(light_paths > 0.0 && light_paths <= 1024.0) {
        return Err(ctx.err(
            "render.light_paths_per_sample",
            format!("{light_paths} must be a number in (0, 1024]: light paths traced per camera sample for caustics"),
        ));
    }
    Ok(RenderSettings {
        pixel_batches: r.pixel_batches,
        spp,
        max_depth,
        rr_depth: r.rr_depth,
        seed: overrides.seed.unwrap_or(r.seed),
        filter,
        illuminance,
        light_paths_per_sample: light_paths as f32,
        light_sampler: match r.light_sampler {
            LightSamplerDesc::Bvh => LightSamplerKind::Bvh,
            LightSamplerDesc::Power => LightSamplerKind::Power,
        },
        caustics: overrides.caustics.unwrap_or(match r.caustics {
            CausticsDesc::LightTracing => crate::world::Caustics::LightTracing,
            CausticsDesc::PathTracing => crate::world::Caustics::PathTracing,
        }),
    })
}

/// The scene's materials after the predefined `black` (index 0), and each one's index by name.
fn build_materials<'a>(
    ctx: &Context,
    scene: &'a SceneFile,
) -> Result<(Vec<Material>, HashMap<&'a str, u32>), SceneError> {
    let mut materials = vec![Material::Black];
    let mut index: HashMap<&str, u32> = HashMap::new();
    index.insert("black", 0);
    for (name, m) in &scene.materials {
        let field = format!("materials[{name:?}]");
        if name == "black" {
            return Err(ctx.err(
                field,
                "\"black\" is predefined (it absorbs all light) and cannot be redefined; give this material another name",
            ));
        }
        let mat = Material::build(ctx, &field, m)?;
        index.insert(name.as_str(), materials.len() as u32);
        materials.push(mat);
    }
    Ok((materials, index))
}

/// Half the diagonal of the geometry's bounds (1 m when it has none).
fn scene_radius(geometry: &SceneGeometry) -> f32 {
    let (lo, hi) = geometry.bounds();
    if lo.is_finite() && hi.is_finite() && hi.cmpge(lo).all() {
        (0.5 * (hi - lo).length()).max(1e-6)
    } else {
        1.0
    }
}

/// Per object, whether shadow rays cross its material straight through (empty when none do).
fn see_through(objects: &[Object], materials: &[Material]) -> Vec<bool> {
    let flags: Vec<bool> = objects
        .iter()
        .map(|o| {
            materials[o.material as usize]
                .flags()
                .contains(MaterialFlags::STRAIGHT_THROUGH)
        })
        .collect();
    if flags.contains(&true) {
        flags
    } else {
        Vec::new()
    }
}
