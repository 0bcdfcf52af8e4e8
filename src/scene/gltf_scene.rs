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
) -> Result<&'a GltfCamera, SceneError> {
    if cameras.is_empty() {
        return Err(ctx.err(
            "camera",
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
    let field = format!("camera (--camera {choice})");
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
    let cameras = crate::geometry::gltf::load_cameras(path).map_err(|e| match e {
        crate::geometry::GeometryError::Io { path, source } => SceneError::Io { path, source },
        e => ctx.err("file", e.to_string()),
    })?;
    let c = choose(&ctx, name, &cameras, camera)?;
    let (yfov_rad, aspect) = match c.projection {
        GltfProjection::Perspective {
            yfov_rad,
            aspect_ratio,
        } => (yfov_rad, aspect_ratio),
        GltfProjection::Orthographic => {
            return Err(ctx.err(
                "camera",
                format!(
                    "camera {} of '{name}' is orthographic; candela's cameras are perspective, fisheye and equirectangular: export a perspective camera",
                    describe(cameras.iter().position(|x| std::ptr::eq(x, c)).unwrap_or(0), c)
                ),
            ));
        }
    };
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
            position: c.position.to_array(),
            look_at: look_at.to_array(),
            up: c.up.to_array(),
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
