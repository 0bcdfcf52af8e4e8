//! A glTF file rendered as a whole scene (`candela render room.glb`): the scene description a
//! RON file would give, made from the file. Its one object is the model with its lights
//! (`Model(file: …, lights: true)`); the camera is the file's first camera node, or the one
//! chosen by index or name; everything else takes the RON defaults (docs/scene-format.md →
//! glTF files as scenes).

use crate::description::context::{Context, SceneError};
use crate::description::schema::{
    CameraDesc, MaterialDesc, ObjectDesc, RenderDesc, SceneFile, ShapeDesc, SpectrumDesc,
};
use crate::geometry::gltf::{GltfCamera, GltfProjection};
use std::path::Path;

/// Image width, pixels, when the job gives no resolution; the height follows the camera's
/// aspect ratio.
pub const DEFAULT_WIDTH: u32 = 1024;

/// Width / height of a camera without `aspectRatio` (glTF leaves it to the viewer).
pub const DEFAULT_ASPECT: f64 = 4.0 / 3.0;

/// Lambertian reflectance of primitives without a material.
pub const DEFAULT_REFLECTANCE: f64 = 0.5;

/// Name of the material given to primitives without one.
const DEFAULT_MATERIAL: &str = "gltf-default";

/// A short description of camera `c` (the `k`-th camera node) for messages.
fn describe(k: usize, c: &GltfCamera) -> String {
    let mut s = format!("{k}");
    if let Some(n) = &c.node_name {
        s += &format!(" (node {n:?})");
    } else {
        s += &format!(" (node {})", c.node);
    }
    if let Some(n) = &c.camera_name {
        s += &format!(" (camera {n:?})");
    }
    s
}

/// The camera `choice` names among `cameras`: `None` the first; a number the camera node of that
/// index (0-based, scene order); otherwise the camera node whose node or camera name it is.
fn choose<'a>(
    ctx: &Context,
    file: &str,
    cameras: &'a [GltfCamera],
    choice: Option<&str>,
    (field, choice_field): (&str, &str),
) -> Result<&'a GltfCamera, SceneError> {
    if cameras.is_empty() {
        return Err(ctx.err(
            field,
            format!("'{file}' has no camera node in its scene: add a camera in the modelling tool and export it, or render a RON scene that places the model (`Model(file: \"{file}\", lights: true)`) and gives a `camera`"),
        ));
    }
    let list = || {
        (cameras.iter().enumerate())
            .map(|(k, c)| describe(k, c))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let Some(choice) = choice else {
        return Ok(&cameras[0]);
    };
    let field = format!("{choice_field} {choice}");
    if let Ok(k) = choice.trim().parse::<usize>() {
        return cameras.get(k).ok_or_else(|| {
            ctx.err(
                &field,
                format!(
                    "'{file}' has {} camera node(s), numbered from 0: {}",
                    cameras.len(),
                    list()
                ),
            )
        });
    }
    cameras
        .iter()
        .find(|c| {
            c.node_name.as_deref() == Some(choice) || c.camera_name.as_deref() == Some(choice)
        })
        .ok_or_else(|| {
            ctx.err(
                &field,
                format!(
                    "'{file}' has no camera node named {choice:?}; its cameras: {}",
                    list()
                ),
            )
        })
}

/// The camera nodes of glTF file `path`.
fn read_cameras(ctx: &Context, path: &Path) -> Result<Vec<GltfCamera>, SceneError> {
    crate::geometry::gltf::load_cameras(path).map_err(|e| match e {
        crate::geometry::GeometryError::Io { path, source } => SceneError::Io { path, source },
        e => ctx.err("file", e.to_string()),
    })
}

/// The vertical field of view (radians) and aspect ratio of camera `c` of `cameras` (of file
/// `name`); an orthographic camera is an error at `field`.
fn perspective(
    ctx: &Context,
    name: &str,
    cameras: &[GltfCamera],
    c: &GltfCamera,
    field: &str,
) -> Result<(f64, Option<f64>), SceneError> {
    match c.projection {
        GltfProjection::Perspective {
            yfov_rad,
            aspect_ratio,
        } => Ok((yfov_rad, aspect_ratio)),
        GltfProjection::Orthographic => Err(ctx.err(
            field,
            format!(
                "camera {} of '{name}' is orthographic; candela's cameras are perspective, fisheye and equirectangular: export a perspective camera",
                describe(cameras.iter().position(|x| std::ptr::eq(x, c)).unwrap_or(0), c)
            ),
        )),
    }
}

/// The scene's `camera` with its `from_model` resolved (`choice`, from `--camera`, replaces
/// `from_model.camera`): the position, view direction and up of that camera node of the glTF
/// file that object `from_model.object` places, moved by the object's `transform` (directions
/// renormalised), and the camera's vertical field of view unless `vfov_deg` or `projection`
/// gives one. `position`, `look_at` and `up` beside `from_model` are errors.
pub fn model_camera(
    ctx: &Context,
    scene: &SceneFile,
    choice: Option<&str>,
) -> Result<CameraDesc, SceneError> {
    let mut desc = scene.camera.clone();
    let Some(from) = desc.from_model.take() else {
        return Ok(desc);
    };
    for (given, f) in [
        (desc.position.is_some(), "position"),
        (desc.look_at.is_some(), "look_at"),
        (desc.up.is_some(), "up"),
    ] {
        if given {
            return Err(ctx.err(
                format!("camera.{f}"),
                "`from_model` gives the camera's position, view and up; remove `position`, `look_at` and `up`",
            ));
        }
    }
    let ofield = "camera.from_model.object";
    let models = || {
        let names: Vec<String> = (scene.objects.iter())
            .filter(|o| matches!(&o.shape, ShapeDesc::Model { file, .. } if is_gltf(file)))
            .filter_map(|o| o.name.as_ref().map(|n| format!("{n:?}")))
            .collect();
        if names.is_empty() {
            "the scene has no named object whose shape is a glTF `Model`".to_string()
        } else {
            format!("the named glTF `Model` objects: {}", names.join(", "))
        }
    };
    let (i, object) = (scene.objects.iter().enumerate())
        .find(|(_, o)| o.name.as_deref() == Some(from.object.as_str()))
        .ok_or_else(|| {
            ctx.err(
                ofield,
                format!("no object is named {:?}; {}", from.object, models()),
            )
        })?;
    let file = match &object.shape {
        ShapeDesc::Model { file, .. } if is_gltf(file) => file,
        _ => {
            return Err(ctx.err(
                ofield,
                format!(
                    "object {:?} is not a glTF `Model` (a `.gltf` or `.glb` file), so it has no cameras; {}",
                    from.object,
                    models()
                ),
            ))
        }
    };
    let path = ctx.resolve(file);
    let cameras = read_cameras(ctx, &path)?;
    let choice = choice.or(from.camera.as_deref());
    let c = choose(
        ctx,
        file,
        &cameras,
        choice,
        ("camera.from_model", "camera.from_model.camera"),
    )?;
    let (yfov_rad, _) = perspective(ctx, file, &cameras, c, "camera.from_model.camera")?;
    let (mut position, mut forward, mut up) = (c.position, c.forward, c.up);
    if let Some(t) = &object.transform {
        let field = format!("objects[{i}] {:?}.transform", from.object);
        let t = crate::geometry::Transform::build(ctx, &field, t)?;
        position = t.matrix.transform_point3(position);
        forward = t.matrix.transform_vector3(forward).normalize_or_zero();
        up = t.matrix.transform_vector3(up).normalize_or_zero();
    }
    desc.position = Some(position.to_array());
    desc.look_at = Some((position + forward).to_array());
    desc.up = Some(up.to_array());
    if desc.vfov_deg.is_none() && desc.projection.is_none() {
        desc.vfov_deg = Some(yfov_rad.to_degrees() as f32);
    }
    Ok(desc)
}

fn is_gltf(file: &str) -> bool {
    is_gltf_path(Path::new(file))
}

/// Whether a scene path is a glTF file (`.gltf`, `.glb`, any case), rendered as a whole scene.
pub fn is_gltf_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// The scene that renders glTF file `path` on its own, through its camera `camera` (see
/// [`choose`]) at `resolution` (pixels; default [`DEFAULT_WIDTH`] wide at the camera's aspect
/// ratio).
pub fn scene(
    path: &Path,
    camera: Option<&str>,
    resolution: Option<(u32, u32)>,
) -> Result<SceneFile, SceneError> {
    let ctx = Context {
        path,
        dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        sources: Default::default(),
    };
    let name = path.file_name().and_then(|n| n.to_str()).ok_or_else(|| {
        ctx.err(
            "file",
            "the glTF file's name is not valid UTF-8; rename it or place it in a RON scene",
        )
    })?;
    let cameras = read_cameras(&ctx, path)?;
    let c = choose(
        &ctx,
        name,
        &cameras,
        camera,
        ("camera", "camera (--camera)"),
    )?;
    let (yfov_rad, aspect) = perspective(&ctx, name, &cameras, c, "camera")?;
    let resolution = match resolution {
        Some(r) => r,
        None => {
            let a = aspect.unwrap_or(DEFAULT_ASPECT);
            if !(a.is_finite() && a > 0.0) {
                return Err(ctx.err(
                    "camera",
                    format!("the camera's aspectRatio {a} is not a positive number"),
                ));
            }
            let h = (DEFAULT_WIDTH as f64 / a).round().clamp(1.0, 1e6) as u32;
            (DEFAULT_WIDTH, h)
        }
    };
    let look_at = c.position + c.forward;
    let stem = path
        .file_stem()
        .map_or("model".into(), |s| s.to_string_lossy().into_owned());
    Ok(SceneFile {
        camera: CameraDesc {
            position: Some(c.position.to_array()),
            look_at: Some(look_at.to_array()),
            up: Some(c.up.to_array()),
            from_model: None,
            vfov_deg: Some(yfov_rad.to_degrees() as f32),
            resolution,
            projection: None,
            lens: None,
        },
        render: RenderDesc::default(),
        materials: [(
            DEFAULT_MATERIAL.to_string(),
            MaterialDesc::Diffuse {
                reflectance: SpectrumDesc::Constant(DEFAULT_REFLECTANCE),
            },
        )]
        .into_iter()
        .collect(),
        objects: vec![ObjectDesc {
            name: Some(stem),
            shape: ShapeDesc::Model {
                file: name.to_string(),
                materials_from_file: Default::default(),
                ke_luminance: None,
                lights: true,
            },
            material: DEFAULT_MATERIAL.to_string(),
            emission: None,
            transform: None,
        }],
        lights: Vec::new(),
        meters: Vec::new(),
        grids: Vec::new(),
        measure: Default::default(),
        site: Default::default(),
    })
}
