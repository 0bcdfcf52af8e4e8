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
        .with_recursion_limit(RECURSION_LIMIT)
        .from_str::<SceneFile>(text)
        .map_err(|e| SceneError::Parse {
            path: path.to_path_buf(),
            line: e.span.start.line,
            col: e.span.start.col,
            message: match e.code {
                // ron's own text names its Rust option, which a scene's author cannot set.
                ron::error::Error::ExceededRecursionLimit => format!(
                    "brackets nested more than {} deep; a scene needs far fewer",
                    RECURSION_LIMIT
                ),
                code => code.to_string(),
            },
        })
}

/// How deep brackets may nest in a scene file (ron's default; named in the message).
const RECURSION_LIMIT: usize = 128;

#[cfg(test)]
mod tests {
    /// Deep nesting is refused with a message a scene's author can act on, naming the place.
    #[test]
    fn deep_nesting_names_the_limit_not_ron_options() {
        let text = format!(
            "(materials: {{\"a\": {}",
            "NormalMapped(material: ".repeat(1000)
        );
        let e = super::parse(&text, std::path::Path::new("deep.ron")).unwrap_err();
        let m = e.to_string();
        assert!(m.contains("nested more than 128 deep"), "{m}");
        assert!(m.contains("deep.ron:1:"), "{m}");
        assert!(!m.contains("recursion_limit"), "{m}");
    }
}
