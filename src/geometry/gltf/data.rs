//! The bytes behind a glTF document: its buffers (the GLB's BIN chunk, files relative to the
//! model, `data:` URIs) and its accessors, each checked against the bytes it points into before
//! anything is allocated from its count.

use super::super::GeometryError;
use crate::limits;
use gltf::accessor::{DataType, Dimensions};
use std::path::{Path, PathBuf};

/// Largest buffer or image file a model names, bytes.
const MAX_RESOURCE_FILE_BYTES: u64 = 1 << 40;

pub(super) fn parse_err(path: &Path, message: String) -> GeometryError {
    GeometryError::Parse {
        path: path.to_path_buf(),
        format: "glTF",
        message,
    }
}

/// A URI's `%XX` escapes decoded (glTF URIs are RFC 3986 references).
fn percent_decode(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = std::str::from_utf8(&b[i + 1..i + 3]).ok();
            if let Some(v) = hex.and_then(|h| u8::from_str_radix(h, 16).ok()) {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Standard base64 (RFC 4648, padding optional, whitespace refused).
fn base64_decode(s: &str) -> Option<Vec<u8>> {
    let s = s.trim_end_matches('=');
    let mut out = Vec::with_capacity(s.len() / 4 * 3 + 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    for c in s.bytes() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32;
        acc = (acc << 6) | v;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

/// Where a buffer or an image named by `uri` comes from.
pub(super) enum Resource {
    /// A file, relative to the model's directory.
    File(PathBuf),
    /// The decoded payload of a `data:` URI.
    Data(Vec<u8>),
}

/// Resolves `uri` (a `data:` URI or a path relative to the model `path`); `what` names it in
/// messages.
pub(super) fn resource(path: &Path, uri: &str, what: &str) -> Result<Resource, GeometryError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((head, payload)) = rest.split_once(',') else {
            return Err(parse_err(path, format!("{what}'s data: URI has no ','")));
        };
        if !head.ends_with(";base64") {
            return Err(parse_err(
                path,
                format!("{what}'s data: URI is not base64-encoded"),
            ));
        }
        return base64_decode(payload)
            .map(Resource::Data)
            .ok_or_else(|| parse_err(path, format!("{what}'s data: URI is not valid base64")));
    }
    if uri.contains("://") {
        return Err(parse_err(
            path,
            format!(
                "{what} names {uri:?}; only files relative to the model and data: URIs are read"
            ),
        ));
    }
    let dir = path.parent().unwrap_or(Path::new(""));
    super::super::model_file(path, dir, &percent_decode(uri), what)
        .map(Resource::File)
        .map_err(|e| match e {
            // Named as the file writes it.
            GeometryError::Outside {
                path, what, folder, ..
            } => GeometryError::Outside {
                path,
                what,
                name: uri.to_string(),
                folder,
            },
            e => e,
        })
}

/// Reads a file a model names, through [`limits::read_file`].
pub(super) fn read_resource(
    path: &Path,
    file: &Path,
    what: &str,
) -> Result<Vec<u8>, GeometryError> {
    limits::read_file(file, MAX_RESOURCE_FILE_BYTES).map_err(|e| {
        parse_err(
            path,
            format!("cannot read its {what} '{}': {e}", file.display()),
        )
    })
}

/// The data of every buffer of `doc`, each at least as long as the buffer declares; the files
/// read are appended to `files`.
pub(super) fn buffers(
    path: &Path,
    doc: &gltf::Document,
    mut blob: Option<Vec<u8>>,
    files: &mut Vec<PathBuf>,
) -> Result<Vec<Vec<u8>>, GeometryError> {
    let mut out = Vec::new();
    for b in doc.buffers() {
        let what = format!("buffer {}", b.index());
        let data = match b.source() {
            gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                parse_err(
                    path,
                    format!("{what} is the GLB's binary chunk, but the file has none (or it is used twice)"),
                )
            })?,
            gltf::buffer::Source::Uri(uri) => match resource(path, uri, &what)? {
                Resource::Data(d) => d,
                Resource::File(f) => {
                    files.push(f.clone());
                    read_resource(path, &f, &what)?
                }
            },
        };
        if data.len() < b.length() {
            return Err(parse_err(
                path,
                format!(
                    "{what} declares {} bytes but holds only {}",
                    b.length(),
                    data.len()
                ),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// The bytes of a buffer view, checked to lie inside its buffer.
pub(super) fn view_bytes<'b>(
    path: &Path,
    view: &gltf::buffer::View,
    buffers: &'b [Vec<u8>],
) -> Result<&'b [u8], GeometryError> {
    let buf = &buffers[view.buffer().index()];
    let end = view.offset().checked_add(view.length());
    match end {
        Some(end) if end <= buf.len() => Ok(&buf[view.offset()..end]),
        _ => Err(parse_err(
            path,
            format!(
                "buffer view {} (offset {}, length {}) runs past the end of buffer {} ({} bytes)",
                view.index(),
                view.offset(),
                view.length(),
                view.buffer().index(),
                buf.len()
            ),
        )),
    }
}

/// An accessor checked against its buffer view: its elements as byte slices.
pub(super) struct Elements<'b> {
    bytes: &'b [u8],
    offset: usize,
    stride: usize,
    pub count: usize,
    pub data_type: DataType,
}

impl<'b> Elements<'b> {
    /// The `i`-th element's bytes (component `c` of `size` bytes).
    #[inline]
    fn at(&self, i: usize, c: usize, size: usize) -> &'b [u8] {
        let s = self.offset + i * self.stride + c * size;
        &self.bytes[s..s + size]
    }

    /// Component `c` of element `i` as f32 (normalised integers mapped to [0, 1]).
    pub fn float(&self, i: usize, c: usize) -> f32 {
        match self.data_type {
            DataType::F32 => f32::from_le_bytes(self.at(i, c, 4).try_into().unwrap()),
            DataType::U8 => self.at(i, c, 1)[0] as f32 / 255.0,
            DataType::U16 => {
                u16::from_le_bytes(self.at(i, c, 2).try_into().unwrap()) as f32 / 65535.0
            }
            _ => f32::NAN,
        }
    }

    /// Element `i` of a scalar unsigned-integer accessor.
    pub fn uint(&self, i: usize) -> u32 {
        match self.data_type {
            DataType::U8 => self.at(i, 0, 1)[0] as u32,
            DataType::U16 => u16::from_le_bytes(self.at(i, 0, 2).try_into().unwrap()) as u32,
            DataType::U32 => u32::from_le_bytes(self.at(i, 0, 4).try_into().unwrap()),
            _ => u32::MAX,
        }
    }
}

/// Accessor `acc` used as `what`, checked: its shape is one of `dims`, its component type one
/// of `types`, it is not sparse, and every element lies inside its buffer view.
pub(super) fn elements<'b>(
    path: &Path,
    acc: &gltf::Accessor,
    what: &str,
    dims: Dimensions,
    types: &[DataType],
    buffers: &'b [Vec<u8>],
) -> Result<Elements<'b>, GeometryError> {
    let name = format!("accessor {} ({what})", acc.index());
    if acc.sparse().is_some() {
        return Err(parse_err(
            path,
            format!("{name} is sparse, which candela does not read"),
        ));
    }
    if acc.dimensions() != dims || !types.contains(&acc.data_type()) {
        return Err(parse_err(
            path,
            format!(
                "{name} is {:?} of {:?}; expected {dims:?} of {types:?}",
                acc.dimensions(),
                acc.data_type()
            ),
        ));
    }
    if acc.data_type() != DataType::F32 && what != "indices" && !acc.normalized() {
        return Err(parse_err(
            path,
            format!("{name} holds integers that are not normalized"),
        ));
    }
    let Some(view) = acc.view() else {
        return Err(parse_err(path, format!("{name} has no buffer view")));
    };
    let bytes = view_bytes(path, &view, buffers)?;
    let size = acc.size();
    let stride = view.stride().unwrap_or(size).max(size);
    let count = acc.count();
    let need = match count {
        0 => Some(0),
        n => (n - 1)
            .checked_mul(stride)
            .and_then(|v| v.checked_add(size))
            .and_then(|v| v.checked_add(acc.offset())),
    };
    match need {
        Some(n) if n <= bytes.len() => {}
        _ => {
            return Err(parse_err(
                path,
                format!(
                    "{name}: {count} elements of {size} bytes (stride {stride}, offset {}) do not fit in buffer view {} of {} bytes",
                    acc.offset(),
                    view.index(),
                    bytes.len()
                ),
            ))
        }
    }
    Ok(Elements {
        bytes,
        offset: acc.offset(),
        stride,
        count,
        data_type: acc.data_type(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decodes_base64_and_percent_escapes() {
        assert_eq!(base64_decode("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(base64_decode("AAEC").unwrap(), [0, 1, 2]);
        assert!(base64_decode("a b").is_none());
        assert_eq!(percent_decode("my%20file.bin"), "my file.bin");
        assert_eq!(percent_decode("a%2"), "a%2");
    }
}
