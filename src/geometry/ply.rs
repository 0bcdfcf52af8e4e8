//! PLY loading (ply-rs-bw): ascii, binary little- or big-endian. Every failure is a
//! [`GeometryError`] naming the file; malformed input never panics.
//!
//! The file is read whole ([`super::io`] reads it, refusing a FIFO, a device or a directory
//! unread). ply-rs holds several times the file's size in a proportion that depends on what
//! the file holds (a 5 MB PLY of one-byte elements takes 1.8 GB), so between header and
//! payload, the memory the payload will need is estimated from the header and checked against
//! the memory available.

use super::io::{check_memory, read_mesh, validate};
use super::{GeometryError, TriangleMesh};
use glam::Vec3;
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{DefaultElement, Header, Ply, Property};
use std::path::Path;

/// Loads a PLY file (ascii, binary little- or big-endian): element `vertex` with float
/// properties `x, y, z` (optionally `nx, ny, nz`), element `face` with a list property
/// `vertex_indices` (or `vertex_index`); polygons are triangulated as fans.
pub fn load_ply(path: &Path) -> Result<TriangleMesh, GeometryError> {
    let bytes = read_mesh(path)?;
    let ply = parse_ply(path, &bytes)?;
    let mut mesh = TriangleMesh::default();
    read_vertices(path, &ply, &mut mesh)?;
    read_faces(path, &ply, &mut mesh)?;
    validate(path, &mesh)?;
    Ok(mesh)
}

fn parse_error(path: &Path, message: String) -> GeometryError {
    GeometryError::Parse {
        path: path.to_path_buf(),
        format: "PLY",
        message,
    }
}

/// Joins a multi-line parser message into one line without a trailing period.
fn one_paragraph(msg: &str) -> String {
    let joined = msg
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ");
    joined.trim_end_matches('.').to_string()
}

/// Peak memory of loading a PLY file whose payload is `payload` bytes, in bytes, from its
/// header. ply-rs holds every element as a map from property name to value: about 250 bytes
/// per element and 180 per property (measured peaks are 0.55–0.9 of this estimate: 2·10⁶
/// vertices of 3 floats, 10⁶ of 9, 2·10⁶ faces, 5·10⁶ one-byte elements, ASCII and binary).
/// The count of an element is taken as no more than the payload can hold, so a header that
/// claims more than the file has is not refused for it (ply-rs stops at the end of the data).
fn ply_memory(header: &Header, payload: usize) -> u64 {
    use ply_rs_bw::ply::{Encoding, PropertyType, ScalarType};
    let size = |t: &ScalarType| match t {
        ScalarType::Char | ScalarType::UChar => 1u64,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    };
    let ascii = matches!(header.encoding, Encoding::Ascii);
    let payload = payload as u64;
    let mut need = 6 * payload;
    for (_, element) in header.elements.iter() {
        let props = element.properties.len() as u64;
        // Fewest bytes one element takes in the file: a value and a separator per property in
        // ASCII (an element is a line), its scalars and list lengths in binary.
        let min_bytes = if ascii {
            (2 * props).max(1)
        } else {
            element
                .properties
                .iter()
                .map(|(_, p)| match &p.data_type {
                    PropertyType::Scalar(t) => size(t),
                    PropertyType::List(count, _) => size(count),
                })
                .sum()
        };
        let count = match min_bytes {
            0 => element.count as u64,
            m => (element.count as u64).min(payload / m),
        };
        need = need.saturating_add(count.saturating_mul(250 + 180 * props));
    }
    need
}

/// Header and payload of the PLY file `bytes`, once the memory the payload needs (estimated
/// from the header) has been found available.
fn parse_ply(path: &Path, bytes: &[u8]) -> Result<Ply<DefaultElement>, GeometryError> {
    let parse = |message: String| parse_error(path, message);
    // A byte-order mark before the "ply" magic line (as some editors write) is skipped.
    let mut reader = Reader::new(bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes));
    let parser = Parser::<DefaultElement>::new();
    let failed = |_| parse("the PLY parser failed on malformed input".into());
    let header = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        parser.read_header(&mut reader)
    }))
    .map_err(failed)?
    .map_err(|e| parse(one_paragraph(&e.to_string())))?;
    let payload_bytes = reader.get_ref().len();
    let elements =
        (header.elements.iter()).fold(0u64, |n, (_, e)| n.saturating_add(e.count as u64));
    check_memory(
        path,
        &format!(
            "loading the {elements} elements its header declares (in a file of {} bytes)",
            bytes.len()
        ),
        ply_memory(&header, payload_bytes),
    )?;
    let payload = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        parser.read_payload(&mut reader, &header)
    }))
    .map_err(failed)?
    .map_err(|e| parse(one_paragraph(&e.to_string())))?;
    Ok(Ply::<DefaultElement> { header, payload })
}

/// The positions of the `vertex` elements into `mesh`, and their normals if every vertex
/// has them.
fn read_vertices(
    path: &Path,
    ply: &Ply<DefaultElement>,
    mesh: &mut TriangleMesh,
) -> Result<(), GeometryError> {
    let parse = |message: String| parse_error(path, message);
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or_else(|| parse("there is no 'vertex' element".into()))?;
    let expected_vertices = ply
        .header
        .elements
        .get("vertex")
        .map(|e| e.count)
        .unwrap_or(vertices.len());
    if vertices.len() != expected_vertices {
        return Err(parse(format!(
            "the header declares {expected_vertices} vertices but only {} could be read (truncated file?)",
            vertices.len()
        )));
    }
    let scalar = |el: &DefaultElement, key: &str, i: usize| -> Result<Option<f32>, GeometryError> {
        match el.get(key) {
            None => Ok(None),
            Some(p) => p.to_f32_lossy().map(Some).ok_or_else(|| {
                parse(format!(
                    "vertex {i}: property '{key}' is a list, expected a number"
                ))
            }),
        }
    };
    let mut normals = Vec::with_capacity(vertices.len());
    let mut has_normals = true;
    mesh.positions.reserve(vertices.len());
    for (i, v) in vertices.iter().enumerate() {
        let x = scalar(v, "x", i)?;
        let y = scalar(v, "y", i)?;
        let z = scalar(v, "z", i)?;
        match (x, y, z) {
            (Some(x), Some(y), Some(z)) => mesh.positions.push(Vec3::new(x, y, z)),
            _ => {
                return Err(parse(format!(
                    "vertex {i} lacks one of the properties 'x', 'y', 'z'"
                )))
            }
        }
        if has_normals {
            match (
                scalar(v, "nx", i)?,
                scalar(v, "ny", i)?,
                scalar(v, "nz", i)?,
            ) {
                (Some(x), Some(y), Some(z)) => normals.push(Vec3::new(x, y, z)),
                _ => has_normals = false,
            }
        }
    }
    if has_normals && !normals.is_empty() {
        mesh.normals = Some(normals);
    }
    Ok(())
}

/// The `face` elements into `mesh` as triangle fans.
fn read_faces(
    path: &Path,
    ply: &Ply<DefaultElement>,
    mesh: &mut TriangleMesh,
) -> Result<(), GeometryError> {
    let parse = |message: String| parse_error(path, message);
    let nv = mesh.positions.len();
    let faces: &[DefaultElement] = ply.payload.get("face").map(|v| &v[..]).unwrap_or(&[]);
    if let Some(def) = ply.header.elements.get("face") {
        if faces.len() != def.count {
            return Err(parse(format!(
                "the header declares {} faces but only {} could be read (truncated file?)",
                def.count,
                faces.len()
            )));
        }
    }
    for (f, face) in faces.iter().enumerate() {
        let idx = face_indices(path, f, face)?;
        if let Some(&bad) = idx.iter().find(|&&i| i < 0 || i as usize >= nv) {
            return Err(GeometryError::IndexOutOfRange {
                path: path.to_path_buf(),
                face: f,
                index: bad,
                vertex_count: nv,
            });
        }
        for k in 1..idx.len().saturating_sub(1) {
            mesh.indices
                .push([idx[0] as u32, idx[k] as u32, idx[k + 1] as u32]);
        }
    }
    Ok(())
}

/// The vertex indices of face `f`, from its integer list property `vertex_indices` (or
/// `vertex_index`).
fn face_indices(path: &Path, f: usize, face: &DefaultElement) -> Result<Vec<i64>, GeometryError> {
    let prop = face
        .get("vertex_indices")
        .or_else(|| face.get("vertex_index"))
        .ok_or_else(|| {
            parse_error(
                path,
                format!("face {f} has no 'vertex_indices' (or 'vertex_index') list property"),
            )
        })?;
    Ok(match prop {
        Property::ListChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListInt(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUInt(v) => v.iter().map(|&x| x as i64).collect(),
        _ => {
            return Err(parse_error(
                path,
                format!("face {f}: the vertex index property is not a list of integers"),
            ))
        }
    })
}
