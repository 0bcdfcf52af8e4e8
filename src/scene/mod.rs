//! Scene files: RON in (parsed into [`crate::description::schema`]), a render-ready
//! [`crate::world::World`] out ([`build`]).
//!
//! Every problem is reported as a [`SceneError`] naming the file, the position (line:column)
//! where the parser knows it, and the field path (e.g. `objects[3] "floor".emission.amount`).

pub mod build;
pub mod gltf;
pub mod gltf_scene;

use std::path::Path;

pub use crate::description::context::SceneError;
pub use crate::description::schema::SceneFile;
pub use build::{build, build_for, load_world, load_world_for, Overrides, RunMode};

/// Parse a scene file (syntax, types and unknown fields; values are checked by [`build`]). The
/// file is read through [`crate::limits::read_text`]: at most [`crate::limits::MAX_TEXT_BYTES`]
/// of UTF-8, and never a FIFO, device or directory.
pub fn load(path: &Path) -> Result<SceneFile, SceneError> {
    let text = crate::limits::read_text(path, crate::limits::MAX_TEXT_BYTES).map_err(|source| {
        SceneError::Io {
            path: path.to_path_buf(),
            source,
        }
    })?;
    parse(&text, path)
}

/// Parse scene text; `path` is only used in messages. A leading UTF-8 byte-order mark (as some
/// Windows editors write) is ignored.
pub fn parse(text: &str, path: &Path) -> Result<SceneFile, SceneError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    ron::Options::default()
        .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
        .from_str::<SceneFile>(text)
        .map_err(|e| SceneError::Parse {
            path: path.to_path_buf(),
            line: e.span.start.line,
            col: e.span.start.col,
            message: e.code.to_string(),
        })
}
