//! OBJ (tobj) and PLY (ply-rs-bw) loading. Every failure is a [`GeometryError`] naming the
//! file; malformed input never panics.

use super::{GeometryError, TriangleMesh};
use glam::Vec3;
use std::path::Path;

fn open_check(path: &Path) -> Result<std::fs::File, GeometryError> {
    let f = std::fs::File::open(path).map_err(|source| GeometryError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    match f.metadata() {
        Ok(m) if m.is_dir() => Err(GeometryError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::other("it is a directory, not a file"),
        }),
        _ => Ok(f),
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

/// Checks indices, finiteness and that there is at least one triangle.
fn validate(path: &Path, mesh: &TriangleMesh) -> Result<(), GeometryError> {
    let nv = mesh.positions.len();
    for (f, tri) in mesh.indices.iter().enumerate() {
        if let Some(&i) = tri.iter().find(|&&i| i as usize >= nv) {
            return Err(GeometryError::IndexOutOfRange {
                path: path.to_path_buf(),
                face: f,
                index: i as i64,
                vertex_count: nv,
            });
        }
    }
    if let Some(v) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(GeometryError::NonFinite {
            path: path.to_path_buf(),
            vertex: v,
            what: "position",
        });
    }
    if let Some(ns) = &mesh.normals {
        if let Some(v) = ns.iter().position(|n| !n.is_finite()) {
            return Err(GeometryError::NonFinite {
                path: path.to_path_buf(),
                vertex: v,
                what: "normal",
            });
        }
    }
    if mesh.indices.is_empty() {
        return Err(GeometryError::NoTriangles {
            path: path.to_path_buf(),
            detail: "no faces with 3 or more vertices were found".into(),
        });
    }
    Ok(())
}

/// The first OBJ face whose vertex reference is not a valid position index, described with
/// its line, its face number (from 0, counting `f` lines) and the vertex count: OBJ indices
/// are 1-based, or negative to count back from the last vertex defined so far.
fn locate_bad_face(path: &Path) -> Option<String> {
    let text = std::fs::read(path).ok()?;
    let text = String::from_utf8_lossy(&text);
    let is = |l: &str, tag: &str| {
        l.strip_prefix(tag)
            .is_some_and(|r| r.starts_with([' ', '\t']))
    };
    let total = text.lines().filter(|l| is(l.trim_start(), "v")).count();
    let (mut seen, mut face) = (0usize, 0usize);
    for (n, line) in text.lines().enumerate() {
        let l = line.trim_start();
        if is(l, "v") {
            seen += 1;
        } else if is(l, "f") {
            for tok in l[1..].split_whitespace() {
                let first = tok.split('/').next().unwrap_or("");
                let ok = match first.parse::<i64>() {
                    Ok(i) if i > 0 => i as u64 <= total as u64,
                    Ok(i) if i < 0 => i.unsigned_abs() <= seen as u64,
                    _ => false,
                };
                if !ok {
                    return Some(format!(
                        "line {}: face {face} refers to vertex {first:?}, but the file has {total} vertices ({seen} before this line); OBJ vertex indices run from 1 to {total}, or from -1 back to -{seen}",
                        n + 1
                    ));
                }
            }
            face += 1;
        }
    }
    None
}

/// Loads a Wavefront OBJ file: polygons are triangulated (fan), all objects/groups are merged
/// into one mesh, materials and texture coordinates are ignored. Vertex normals are kept only
/// if every object in the file has them.
pub fn load_obj(path: &Path) -> Result<TriangleMesh, GeometryError> {
    open_check(path)?;
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let parse = |message: String| GeometryError::Parse {
        path: path.to_path_buf(),
        format: "OBJ",
        message,
    };
    // tobj should not panic on malformed input, but a mesh loader must never take the
    // renderer down: convert any panic into an error.
    let loaded = std::panic::catch_unwind(|| tobj::load_obj(path, &opts))
        .map_err(|_| parse("the OBJ parser failed on malformed input".into()))?;
    let (models, _materials) = loaded.map_err(|e| match e {
        tobj::LoadError::FaceVertexOutOfBounds | tobj::LoadError::FaceParseError => {
            // tobj does not say where: find the face ourselves.
            parse(locate_bad_face(path).unwrap_or_else(|| {
                match e {
                    tobj::LoadError::FaceVertexOutOfBounds => {
                        "a face refers to a vertex index that does not exist (index out of range)"
                            .into()
                    }
                    _ => "a face ('f' line) has a non-numeric or zero vertex index".into(),
                }
            }))
        }
        tobj::LoadError::PositionParseError => {
            parse("a vertex position ('v' line) is not three numbers".into())
        }
        e => parse(e.to_string()),
    })?;
    let mut mesh = TriangleMesh::default();
    let all_normals = !models.is_empty()
        && models
            .iter()
            .all(|m| !m.mesh.normals.is_empty() && m.mesh.normals.len() == m.mesh.positions.len());
    let mut normals = Vec::new();
    for m in &models {
        let base = mesh.positions.len() as u64;
        let mm = &m.mesh;
        if mm.positions.len() % 3 != 0 || mm.indices.len() % 3 != 0 {
            return Err(parse(format!(
                "object '{}' has malformed position or index data",
                m.name
            )));
        }
        let nv = mm.positions.len() / 3;
        mesh.positions.extend(
            mm.positions
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2])),
        );
        if all_normals {
            normals.extend(
                mm.normals
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2])),
            );
        }
        for (f, c) in mm.indices.chunks_exact(3).enumerate() {
            if let Some(&i) = c.iter().find(|&&i| i as usize >= nv) {
                return Err(GeometryError::IndexOutOfRange {
                    path: path.to_path_buf(),
                    face: f,
                    index: i as i64,
                    vertex_count: nv,
                });
            }
            let idx = |i: u32| -> Result<u32, GeometryError> {
                u32::try_from(base + i as u64).map_err(|_| parse("more than 2^32 vertices".into()))
            };
            mesh.indices.push([idx(c[0])?, idx(c[1])?, idx(c[2])?]);
        }
    }
    if all_normals {
        mesh.normals = Some(normals);
    }
    validate(path, &mesh)?;
    Ok(mesh)
}

/// Loads a PLY file (ascii, binary little- or big-endian): element `vertex` with float
/// properties `x, y, z` (optionally `nx, ny, nz`), element `face` with a list property
/// `vertex_indices` (or `vertex_index`); polygons are triangulated as fans.
pub fn load_ply(path: &Path) -> Result<TriangleMesh, GeometryError> {
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::{DefaultElement, Property};
    let file = open_check(path)?;
    let parse = |message: String| GeometryError::Parse {
        path: path.to_path_buf(),
        format: "PLY",
        message,
    };
    let mut reader = std::io::BufReader::new(file);
    let parser = Parser::<DefaultElement>::new();
    let ply = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        parser.read_ply(&mut reader)
    }))
    .map_err(|_| parse("the PLY parser failed on malformed input".into()))?
    .map_err(|e| parse(one_paragraph(&e.to_string())))?;

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
    let mut mesh = TriangleMesh::default();
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
        let prop = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
            .ok_or_else(|| {
                parse(format!(
                    "face {f} has no 'vertex_indices' (or 'vertex_index') list property"
                ))
            })?;
        let idx: Vec<i64> = match prop {
            Property::ListChar(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListUChar(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListShort(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListUShort(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListInt(v) => v.iter().map(|&x| x as i64).collect(),
            Property::ListUInt(v) => v.iter().map(|&x| x as i64).collect(),
            _ => {
                return Err(parse(format!(
                    "face {f}: the vertex index property is not a list of integers"
                )))
            }
        };
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
    validate(path, &mesh)?;
    Ok(mesh)
}
