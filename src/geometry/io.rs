//! OBJ (tobj) and PLY (ply-rs-bw) loading. Every failure is a [`GeometryError`] naming the
//! file; malformed input never panics.
//!
//! Files are read whole through [`crate::limits::read_file`] (so a FIFO, a device or a
//! directory is refused unread). Meshes may be gigabytes and the parsers hold several times
//! the file's size, in a proportion that depends on what the file holds (a 5 MB PLY of
//! one-byte elements takes 1.8 GB in ply-rs), so before parsing, the memory the parse will need
//! is estimated from the file's contents (OBJ: its statements; PLY: its header) and checked
//! against the memory available.

use super::mtl::MtlMaterial;
use super::{GeometryError, TriangleMesh};
use crate::limits;
use glam::{Vec2, Vec3};
use std::path::Path;

/// Largest mesh file read at all; below it, the memory available decides.
const MAX_MESH_FILE_BYTES: u64 = 1 << 40;

/// Largest material library (`mtllib`) read; real ones are kilobytes.
const MAX_MTL_FILE_BYTES: u64 = 16 << 20;

fn read_mesh(path: &Path) -> Result<Vec<u8>, GeometryError> {
    limits::read_file(path, MAX_MESH_FILE_BYTES).map_err(|source| GeometryError::Io {
        path: path.to_path_buf(),
        source,
    })
}

fn check_memory(path: &Path, what: &str, need: u64) -> Result<(), GeometryError> {
    limits::check_memory(need, what).map_err(|message| GeometryError::TooLarge {
        path: path.to_path_buf(),
        message,
    })
}

/// Peak memory of loading OBJ text, in bytes, from a scan of its statements. The costs per
/// statement are tobj's (faces are held as 104-byte records before triangulation; each distinct
/// position/texture/normal index triple enters a hash map) and ours, with room for vector
/// growth; measured peaks are 0.6–0.95 of this estimate (10⁷ one-triangle faces, 1.6·10⁷ quads,
/// a 10⁶-vertex polygon, 3·10⁶ groups, 10⁷ vertices, a 10⁶-vertex grid).
fn obj_memory(bytes: &[u8]) -> u64 {
    let (mut v, mut vt, mut vn, mut faces, mut corners, mut extra, mut groups) =
        (0u64, 0u64, 0u64, 0u64, 0u64, 0u64, 0u64);
    for line in bytes.split(|&b| b == b'\n') {
        let mut words = line
            .split(|b| b.is_ascii_whitespace())
            .filter(|w| !w.is_empty());
        match words.next() {
            Some(b"v") => v += 1,
            Some(b"vt") => vt += 1,
            Some(b"vn") => vn += 1,
            Some(b"f") => {
                let n = words.count() as u64;
                faces += 1;
                corners += n;
                extra += n.saturating_sub(3);
            }
            Some(b"o") | Some(b"g") => groups += 1,
            _ => {}
        }
    }
    // Distinct index triples: at most one per face corner, and at most every combination.
    let triples = corners.min(v.saturating_mul(vt.max(1)).saturating_mul(vn.max(1)));
    let utf8_copy = if std::str::from_utf8(bytes).is_ok() {
        0
    } else {
        3 * bytes.len() as u64
    };
    (bytes.len() as u64 + utf8_copy)
        .saturating_add(24 * v + 16 * vt + 24 * vn)
        .saturating_add(130 * faces + 40 * extra)
        .saturating_add(160 * triples + 350 * groups)
}

/// Peak memory of loading a PLY file whose payload is `payload` bytes, in bytes, from its
/// header. ply-rs holds every element as a map from property name to value: about 250 bytes
/// per element and 180 per property (measured peaks are 0.55–0.9 of this estimate: 2·10⁶
/// vertices of 3 floats, 10⁶ of 9, 2·10⁶ faces, 5·10⁶ one-byte elements, ASCII and binary).
/// The count of an element is taken as no more than the payload can hold, so a header that
/// claims more than the file has is not refused for it (ply-rs stops at the end of the data).
fn ply_memory(header: &ply_rs_bw::ply::Header, payload: usize) -> u64 {
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
fn locate_bad_face(text: &str) -> Option<String> {
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

/// The first `v` line whose position (divided by its optional weight w, as tobj does) is not
/// finite or lies beyond [`super::bvh::MAX_COORDINATE`], described with its line and number.
fn far_vertex(text: &str) -> Option<String> {
    let mut k = 0usize;
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("v") {
            continue;
        }
        k += 1;
        let x: Vec<f32> = words.map_while(|w| w.parse().ok()).collect();
        if x.len() < 3 {
            continue;
        }
        // A fourth value alone is the weight; six are a position and a colour.
        let w = if x.len() == 4 { x[3] } else { 1.0 };
        let p = [x[0] / w, x[1] / w, x[2] / w];
        if p.iter()
            .any(|c| !c.is_finite() || c.abs() > super::bvh::MAX_COORDINATE)
        {
            return Some(format!(
                "line {}: vertex {k} is at ({}, {}, {}) m, {}; geometry must lie within ±{:e} m",
                n + 1,
                p[0],
                p[1],
                p[2],
                if p.iter().all(|c| c.is_finite()) {
                    "too far from the origin"
                } else {
                    "not a finite position"
                },
                super::bvh::MAX_COORDINATE
            ));
        }
    }
    None
}

/// How an OBJ file's material libraries are read.
#[derive(Clone, Copy, PartialEq)]
enum Mtl {
    /// Not used: one that does not exist is ignored, one that is not a plain file is refused.
    Ignore,
    /// Parsed; one that is missing or malformed is an error.
    Use,
}

/// The objects, the materials and the material libraries read.
type Models = (Vec<tobj::Model>, Vec<MtlMaterial>, Vec<std::path::PathBuf>);

#[cfg(test)]
thread_local! {
    /// Material libraries read on this thread (tests count them).
    static MTL_READS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// The file names of one `mtllib` statement (`rest` follows the keyword): OBJ allows several,
/// separated by spaces, and exporters write names with spaces. As Blender's importer does, the
/// text is cut after each `.mtl` (any case) that ends a word, so `a.mtl b c.mtl` names `a.mtl`
/// and `b c.mtl`; text after the last `.mtl` is one more name.
fn mtllib_names(rest: &str) -> Vec<String> {
    let lower = rest.to_ascii_lowercase();
    let b = lower.as_bytes();
    let mut names = Vec::new();
    let mut start = 0;
    let mut i = 0;
    while let Some(k) = lower[i..].find(".mtl") {
        let end = i + k + 4;
        if end == b.len() || b[end].is_ascii_whitespace() {
            names.push(rest[start..end].trim().to_string());
            start = end;
        }
        i = end;
    }
    names.push(rest[start..].trim().to_string());
    names.retain(|n| !n.is_empty());
    names
}

/// Lexically normalised absolute form of `p` (`.` dropped, `..` taking off the component
/// before it), without asking the file system.
fn lexical(p: &Path) -> std::path::PathBuf {
    use std::path::Component;
    let abs = if p.is_absolute() {
        p.to_path_buf()
    } else {
        std::env::current_dir().unwrap_or_default().join(p)
    };
    let mut out = std::path::PathBuf::new();
    for c in abs.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            c => out.push(c),
        }
    }
    out
}

/// The file a model file `model` names as `name` (`what` in messages), relative to `base`
/// (the model's directory, or a material library's inside it): it must lie beside the model
/// or below its folder, both as written (`..` resolved) and, when it exists, once symbolic
/// links are resolved, so a model cannot make candela read (or show bytes of) files elsewhere.
/// The file is not opened here.
pub fn model_file(
    model: &Path,
    base: &Path,
    name: &str,
    what: &str,
) -> Result<std::path::PathBuf, GeometryError> {
    let folder = match model.parent() {
        Some(f) if !f.as_os_str().is_empty() => f,
        _ => Path::new("."),
    };
    let file = base.join(name);
    let outside = || GeometryError::Outside {
        path: model.to_path_buf(),
        what: what.to_string(),
        name: name.to_string(),
        folder: folder.to_path_buf(),
    };
    if !lexical(&file).starts_with(lexical(folder)) {
        return Err(outside());
    }
    if let (Ok(f), Ok(root)) = (file.canonicalize(), folder.canonicalize()) {
        if !f.starts_with(root) {
            return Err(outside());
        }
    }
    Ok(file)
}

/// Reads and parses an OBJ file (and, with [`Mtl::Use`], its material libraries).
fn parse_obj(path: &Path, mtl_mode: Mtl) -> Result<Models, GeometryError> {
    let bytes = read_mesh(path)?;
    check_memory(
        path,
        &format!("loading this OBJ file of {} bytes", bytes.len()),
        obj_memory(&bytes),
    )?;
    let text = String::from_utf8_lossy(&bytes);
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
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
    let mtl_error = std::cell::RefCell::new(None);
    let mtls = std::cell::RefCell::new(Vec::<MtlMaterial>::new());
    // Libraries already read: each is read once however often `mtllib` names it.
    let read = std::cell::RefCell::new(Vec::<std::path::PathBuf>::new());
    let seen = std::cell::RefCell::new(Vec::<std::path::PathBuf>::new());
    let dir = path.parent().unwrap_or(Path::new(""));
    let load_mtl = |line: &Path| -> tobj::MTLLoadResult {
        let fail = |e: GeometryError| {
            mtl_error.borrow_mut().get_or_insert(e);
            Ok(Default::default())
        };
        // tobj's own map type (it is not named in tobj's API).
        let empty: tobj::MTLLoadResult = Ok(Default::default());
        let Ok((mut mats, mut map)) = empty else {
            unreachable!()
        };
        for name in mtllib_names(&line.to_string_lossy()) {
            let mtl = match model_file(path, dir, &name, "the material library") {
                Ok(f) => f,
                // An unused library outside the folder is not read; one that is not there is
                // ignored, as missing libraries are.
                Err(_)
                    if mtl_mode == Mtl::Ignore
                        && std::fs::symlink_metadata(dir.join(&name)).is_err() =>
                {
                    continue
                }
                Err(e) => return fail(e),
            };
            // The same file by another spelling (`./a.mtl`, `sub/../a.mtl`) is the same library.
            let key = mtl.canonicalize().unwrap_or_else(|_| mtl.clone());
            if seen.borrow().contains(&key) {
                continue;
            }
            seen.borrow_mut().push(key);
            #[cfg(test)]
            MTL_READS.with(|n| n.set(n.get() + 1));
            let bytes = match limits::read_file(&mtl, MAX_MTL_FILE_BYTES) {
                Err(e) if e.kind() == std::io::ErrorKind::NotFound && mtl_mode == Mtl::Ignore => {
                    continue
                }
                Err(source) => {
                    return fail(GeometryError::Material {
                        path: path.to_path_buf(),
                        mtl,
                        source,
                    })
                }
                Ok(b) => b,
            };
            read.borrow_mut().push(mtl.clone());
            if mtl_mode == Mtl::Ignore {
                continue;
            }
            let parsed = match super::mtl::parse_mtl(&mtl, &bytes) {
                Ok(p) => p,
                Err(e) => return fail(e),
            };
            let mut all = mtls.borrow_mut();
            for m in parsed {
                if let Some(prev) = all.iter().find(|p| p.name == m.name) {
                    return fail(GeometryError::MaterialSyntax {
                        mtl: m.file.clone(),
                        line: m.line,
                        message: format!(
                            "material {:?} is defined again (first in '{}', line {})",
                            m.name,
                            prev.file.display(),
                            prev.line
                        ),
                    });
                }
                map.insert(m.name.clone(), mats.len());
                mats.push(tobj::Material {
                    name: m.name.clone(),
                    ..Default::default()
                });
                all.push(m);
            }
        }
        Ok((mats, map))
    };
    // tobj should not panic on malformed input, but a mesh loader must never take the
    // renderer down: convert any panic into an error.
    let loaded = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut text.as_bytes(), &opts, load_mtl)
    }))
    .map_err(|_| parse("the OBJ parser failed on malformed input".into()))?;
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let (models, _materials) = loaded.map_err(|e| match e {
        tobj::LoadError::FaceVertexOutOfBounds | tobj::LoadError::FaceParseError => {
            // tobj does not say where: find the face ourselves.
            parse(locate_bad_face(text).unwrap_or_else(|| {
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
        tobj::LoadError::MaterialParseError => {
            parse("a 'usemtl' statement names no material".into())
        }
        e => parse(e.to_string()),
    })?;
    let far =
        |p: &[f32]| (p.iter()).any(|c| !c.is_finite() || c.abs() > super::bvh::MAX_COORDINATE);
    if models.iter().any(|m| far(&m.mesh.positions)) {
        return Err(parse(far_vertex(text).unwrap_or_else(|| {
            format!(
                "a vertex lies beyond ±{:e} m from the origin (or is not finite)",
                super::bvh::MAX_COORDINATE
            )
        })));
    }
    let mtls = mtls.into_inner();
    let libraries = read.into_inner();
    if mtl_mode == Mtl::Use {
        // A `usemtl` naming no material of the libraries would silently lose its faces'
        // material: say where it is.
        for (n, line) in text.lines().enumerate() {
            let l = line.trim_start();
            if let Some(name) = l
                .strip_prefix("usemtl")
                .filter(|r| r.starts_with([' ', '\t']))
            {
                let name = name.trim();
                if !mtls.iter().any(|m| m.name == name) {
                    let mut known: Vec<&str> = mtls.iter().map(|m| m.name.as_str()).collect();
                    known.sort_unstable();
                    return Err(parse(format!(
                        "line {}: `usemtl {name}` names a material that no material library (`mtllib`) of the file defines{}",
                        n + 1,
                        if known.is_empty() {
                            " (it has none)".to_string()
                        } else {
                            format!("; defined: {}", known.join(", "))
                        }
                    )));
                }
            }
        }
    }
    Ok((models, mtls, libraries))
}

/// Appends the triangles of `models` to `mesh` (and their normals to `normals` when
/// `with_normals`, texture coordinates to `uvs` when given).
fn append_models(
    path: &Path,
    models: &[&tobj::Model],
    mesh: &mut TriangleMesh,
    normals: Option<&mut Vec<Vec3>>,
    mut uvs: Option<&mut Vec<Vec2>>,
) -> Result<(), GeometryError> {
    let parse = |message: String| GeometryError::Parse {
        path: path.to_path_buf(),
        format: "OBJ",
        message,
    };
    let mut normals = normals;
    for m in models {
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
        if let Some(normals) = normals.as_deref_mut() {
            normals.extend(
                mm.normals
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2])),
            );
        }
        if let Some(uvs) = uvs.as_deref_mut() {
            if mm.texcoords.len() == 2 * nv {
                uvs.extend(mm.texcoords.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])));
            } else {
                uvs.resize(uvs.len() + nv, Vec2::ZERO);
            }
            if let Some(i) = uvs.iter().position(|t| !t.is_finite()) {
                return Err(parse(format!("texture coordinate {i} is not finite")));
            }
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
    Ok(())
}

fn all_have_normals(models: &[&tobj::Model]) -> bool {
    !models.is_empty()
        && models
            .iter()
            .all(|m| !m.mesh.normals.is_empty() && m.mesh.normals.len() == m.mesh.positions.len())
}

/// Loads a Wavefront OBJ file: polygons are triangulated (fan), all objects/groups are merged
/// into one mesh, materials and texture coordinates are ignored (see [`load_obj_model`]).
/// Vertex normals are kept only if every object in the file has them. A UTF-8 byte-order mark
/// is skipped; bytes that are not UTF-8 (only names and comments can hold them) are replaced.
///
/// Material libraries (`mtllib`) are not used, so one that does not exist is ignored; one that
/// is a FIFO, a device, a directory or over 16 MiB is refused, naming it.
pub fn load_obj(path: &Path) -> Result<TriangleMesh, GeometryError> {
    load_obj_and_libraries(path).map(|(mesh, _)| mesh)
}

/// [`load_obj`], with the material libraries it read (to check them, not to use them).
pub fn load_obj_and_libraries(
    path: &Path,
) -> Result<(TriangleMesh, Vec<std::path::PathBuf>), GeometryError> {
    let (models, _, libraries) = parse_obj(path, Mtl::Ignore)?;
    let models: Vec<&tobj::Model> = models.iter().collect();
    let mut mesh = TriangleMesh::default();
    let with_normals = all_have_normals(&models);
    let mut normals = Vec::new();
    append_models(
        path,
        &models,
        &mut mesh,
        with_normals.then_some(&mut normals),
        None,
    )?;
    if with_normals {
        mesh.normals = Some(normals);
    }
    validate(path, &mesh)?;
    Ok((mesh, libraries))
}

/// The faces of an OBJ file that share one material.
#[derive(Clone, Debug)]
pub struct ObjGroup {
    /// The material their `usemtl` names; `None` for faces before any `usemtl`.
    pub material: Option<String>,
    pub mesh: TriangleMesh,
    /// Per-vertex texture coordinates (as many as `mesh.positions`; (0, 0) at vertices whose
    /// faces give none), present when any face of the group has `vt` references.
    pub uvs: Option<Vec<Vec2>>,
}

/// An OBJ file with its materials: one [`ObjGroup`] per material used, in order of first use,
/// and the materials of its libraries.
#[derive(Clone, Debug)]
pub struct ObjModel {
    pub groups: Vec<ObjGroup>,
    pub materials: Vec<MtlMaterial>,
    /// The material libraries read, each once.
    pub libraries: Vec<std::path::PathBuf>,
}

/// Loads an OBJ file keeping its materials: the faces are grouped by the material their
/// `usemtl` names (each group one mesh, with its texture coordinates and, if every part of the
/// group has them, vertex normals), and the material libraries (`mtllib`, relative to the OBJ
/// file) are parsed. A library that is missing, not a plain file, over 16 MiB or malformed, a
/// material defined twice, and a `usemtl` naming no material of the libraries are errors
/// naming the file and line. Groups with no triangles are left out; a file with none at all is
/// an error.
pub fn load_obj_model(path: &Path) -> Result<ObjModel, GeometryError> {
    let (models, materials, libraries) = parse_obj(path, Mtl::Use)?;
    let mut ids: Vec<Option<usize>> = Vec::new();
    for m in &models {
        if !ids.contains(&m.mesh.material_id) {
            ids.push(m.mesh.material_id);
        }
    }
    let mut groups = Vec::with_capacity(ids.len());
    for id in ids {
        let part: Vec<&tobj::Model> = models
            .iter()
            .filter(|m| m.mesh.material_id == id && !m.mesh.indices.is_empty())
            .collect();
        if part.is_empty() {
            continue;
        }
        let with_normals = all_have_normals(&part);
        let with_uvs = part.iter().any(|m| !m.mesh.texcoords.is_empty());
        let (mut mesh, mut normals, mut uvs) = (TriangleMesh::default(), Vec::new(), Vec::new());
        append_models(
            path,
            &part,
            &mut mesh,
            with_normals.then_some(&mut normals),
            with_uvs.then_some(&mut uvs),
        )?;
        if with_normals {
            mesh.normals = Some(normals);
        }
        validate(path, &mesh)?;
        groups.push(ObjGroup {
            material: id.and_then(|i| materials.get(i)).map(|m| m.name.clone()),
            mesh,
            uvs: with_uvs.then_some(uvs),
        });
    }
    if groups.is_empty() {
        return Err(GeometryError::NoTriangles {
            path: path.to_path_buf(),
            detail: "no faces with 3 or more vertices were found".into(),
        });
    }
    Ok(ObjModel {
        groups,
        materials,
        libraries,
    })
}

/// Loads a PLY file (ascii, binary little- or big-endian): element `vertex` with float
/// properties `x, y, z` (optionally `nx, ny, nz`), element `face` with a list property
/// `vertex_indices` (or `vertex_index`); polygons are triangulated as fans.
pub fn load_ply(path: &Path) -> Result<TriangleMesh, GeometryError> {
    use ply_rs_bw::parser::{Parser, Reader};
    use ply_rs_bw::ply::{DefaultElement, Property};
    let bytes = read_mesh(path)?;
    let parse = |message: String| GeometryError::Parse {
        path: path.to_path_buf(),
        format: "PLY",
        message,
    };
    // A byte-order mark before the "ply" magic line (as some editors write) is skipped.
    let mut reader = Reader::new(bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes));
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
    let ply = ply_rs_bw::ply::Ply::<DefaultElement> { header, payload };

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mtllib_names_split_after_each_mtl() {
        assert_eq!(mtllib_names("a.mtl"), ["a.mtl"]);
        assert_eq!(mtllib_names(" a.mtl  b.MTL "), ["a.mtl", "b.MTL"]);
        assert_eq!(mtllib_names("my lib.mtl b.mtl"), ["my lib.mtl", "b.mtl"]);
        assert_eq!(mtllib_names("a.mtlx.mtl c"), ["a.mtlx.mtl", "c"]);
        assert_eq!(mtllib_names("materials"), ["materials"]);
        assert!(mtllib_names("  ").is_empty());
    }

    #[test]
    fn each_library_is_read_once() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("a.mtl"), "newmtl a\nKd 0.5 0.5 0.5\n").unwrap();
        std::fs::write(d.join("b.mtl"), "newmtl b\nKd 0.5 0.5 0.5\n").unwrap();
        std::fs::create_dir(d.join("x")).unwrap();
        let mut obj = "mtllib a.mtl\nmtllib ./a.mtl b.mtl\nmtllib x/../a.mtl\n".repeat(5000);
        obj.push_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\nusemtl b\nf 1 3 2\n");
        std::fs::write(d.join("m.obj"), obj).unwrap();
        for use_them in [true, false] {
            MTL_READS.with(|n| n.set(0));
            if use_them {
                let m = load_obj_model(&d.join("m.obj")).unwrap();
                assert_eq!(m.materials.len(), 2);
            } else {
                load_obj(&d.join("m.obj")).unwrap();
            }
            // `./a.mtl` and `x/../a.mtl` are the same file by other spellings: read again, it
            // would define material a twice.
            assert_eq!(MTL_READS.with(|n| n.get()), 2, "use {use_them}");
        }
    }
}
