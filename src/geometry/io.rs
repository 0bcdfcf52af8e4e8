//! OBJ loading (tobj), and the reading and checks every mesh loader shares (PLY: `ply`).
//! Every failure is a [`GeometryError`] naming the file; malformed input never panics.
//!
//! Files are read whole through [`crate::limits::read_file`] (so a FIFO, a device or a
//! directory is refused unread). Meshes may be gigabytes and the parsers hold several times
//! the file's size, in a proportion that depends on what the file holds, so before parsing,
//! the memory the parse will need is estimated from the file's contents (OBJ: its statements;
//! PLY: its header) and checked against the memory available.

use super::mtl::MtlMaterial;
use super::{GeometryError, TriangleMesh};
use crate::limits;
use glam::{Vec2, Vec3};
use std::path::Path;

/// Largest mesh file read at all; below it, the memory available decides.
const MAX_MESH_FILE_BYTES: u64 = 1 << 40;

/// Largest material library (`mtllib`) read; real ones are kilobytes.
const MAX_MTL_FILE_BYTES: u64 = 16 << 20;

pub(super) fn read_mesh(path: &Path) -> Result<Vec<u8>, GeometryError> {
    limits::read_file(path, MAX_MESH_FILE_BYTES).map_err(|source| GeometryError::Io {
        path: path.to_path_buf(),
        source,
    })
}

pub(super) fn check_memory(path: &Path, what: &str, need: u64) -> Result<(), GeometryError> {
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

/// Checks indices, finiteness and that there is at least one triangle.
pub(super) fn validate(path: &Path, mesh: &TriangleMesh) -> Result<(), GeometryError> {
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
    let libraries = MtlLibraries::new(path, mtl_mode);
    let models = run_tobj(path, text, &libraries)?;
    check_reach(path, text, &models)?;
    let mtls = libraries.materials.into_inner();
    let read = libraries.read.into_inner();
    if mtl_mode == Mtl::Use {
        check_usemtl(path, text, &mtls)?;
    }
    Ok((models, mtls, read))
}

fn obj_error(path: &Path, message: String) -> GeometryError {
    GeometryError::Parse {
        path: path.to_path_buf(),
        format: "OBJ",
        message,
    }
}

/// The objects tobj parses from `text`, its `mtllib` statements read through `libraries`. The
/// first library error comes before tobj's own.
fn run_tobj(
    path: &Path,
    text: &str,
    libraries: &MtlLibraries,
) -> Result<Vec<tobj::Model>, GeometryError> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // tobj should not panic on malformed input, but a mesh loader must never take the
    // renderer down: convert any panic into an error.
    let loaded = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut text.as_bytes(), &opts, |line| libraries.load(line))
    }))
    .map_err(|_| obj_error(path, "the OBJ parser failed on malformed input".into()))?;
    if let Some(e) = libraries.error.take() {
        return Err(e);
    }
    let (models, _materials) = loaded.map_err(|e| tobj_error(path, text, e))?;
    Ok(models)
}

/// tobj's error `e` on `text` as ours, with the line of a bad face.
fn tobj_error(path: &Path, text: &str, e: tobj::LoadError) -> GeometryError {
    let parse = |message: String| obj_error(path, message);
    match e {
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
    }
}

/// Refuses a vertex that is not finite or lies beyond [`super::bvh::MAX_COORDINATE`],
/// naming its line of `text`.
fn check_reach(path: &Path, text: &str, models: &[tobj::Model]) -> Result<(), GeometryError> {
    let far =
        |p: &[f32]| (p.iter()).any(|c| !c.is_finite() || c.abs() > super::bvh::MAX_COORDINATE);
    if models.iter().any(|m| far(&m.mesh.positions)) {
        return Err(obj_error(
            path,
            far_vertex(text).unwrap_or_else(|| {
                format!(
                    "a vertex lies beyond ±{:e} m from the origin (or is not finite)",
                    super::bvh::MAX_COORDINATE
                )
            }),
        ));
    }
    Ok(())
}

/// Refuses a `usemtl` naming no material of the libraries, which would silently lose its
/// faces' material: says where it is.
fn check_usemtl(path: &Path, text: &str, mtls: &[MtlMaterial]) -> Result<(), GeometryError> {
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
                return Err(obj_error(path, format!(
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
    Ok(())
}

/// The material libraries of the OBJ file `path`, read as tobj meets its `mtllib`
/// statements (through a callback that cannot return our errors, hence the cells).
struct MtlLibraries<'a> {
    path: &'a Path,
    /// The OBJ file's directory, which library names are relative to.
    dir: &'a Path,
    mode: Mtl,
    /// The first error met.
    error: std::cell::RefCell<Option<GeometryError>>,
    /// The materials of the libraries parsed (with [`Mtl::Use`]).
    materials: std::cell::RefCell<Vec<MtlMaterial>>,
    /// Libraries read, each once however often `mtllib` names it.
    read: std::cell::RefCell<Vec<std::path::PathBuf>>,
    /// The libraries met, canonical: the same file by another spelling is the same library.
    seen: std::cell::RefCell<Vec<std::path::PathBuf>>,
}

impl<'a> MtlLibraries<'a> {
    fn new(path: &'a Path, mode: Mtl) -> Self {
        MtlLibraries {
            path,
            dir: path.parent().unwrap_or(Path::new("")),
            mode,
            error: Default::default(),
            materials: Default::default(),
            read: Default::default(),
            seen: Default::default(),
        }
    }

    /// tobj's material loader for the `mtllib` statement `line`: the materials it adds, by
    /// name only (ours are kept in `materials`). On an error, none (the error is kept).
    fn load(&self, line: &Path) -> tobj::MTLLoadResult {
        // tobj's own map type (it is not named in tobj's API).
        let empty: tobj::MTLLoadResult = Ok(Default::default());
        let Ok((mut mats, mut map)) = empty else {
            unreachable!()
        };
        for name in mtllib_names(&line.to_string_lossy()) {
            let added = match self.library(&name) {
                Ok(added) => added,
                Err(e) => {
                    self.error.borrow_mut().get_or_insert(e);
                    return Ok(Default::default());
                }
            };
            for name in added {
                map.insert(name.clone(), mats.len());
                mats.push(tobj::Material {
                    name,
                    ..Default::default()
                });
            }
        }
        Ok((mats, map))
    }

    /// The names of the materials the library `name` adds: none when it is skipped (read
    /// before, or missing while unused) or not used.
    fn library(&self, name: &str) -> Result<Vec<String>, GeometryError> {
        let Some((mtl, bytes)) = self.read_library(name)? else {
            return Ok(Vec::new());
        };
        if self.mode == Mtl::Ignore {
            return Ok(Vec::new());
        }
        let parsed = super::mtl::parse_mtl(&mtl, &bytes)?;
        self.add(parsed)
    }

    /// The path and bytes of the library `name`, or `None` when it is skipped.
    fn read_library(
        &self,
        name: &str,
    ) -> Result<Option<(std::path::PathBuf, Vec<u8>)>, GeometryError> {
        let mtl = match model_file(self.path, self.dir, name, "the material library") {
            Ok(f) => f,
            // An unused library outside the folder is not read; one that is not there is
            // ignored, as missing libraries are.
            Err(_)
                if self.mode == Mtl::Ignore
                    && std::fs::symlink_metadata(self.dir.join(name)).is_err() =>
            {
                return Ok(None)
            }
            Err(e) => return Err(e),
        };
        let key = mtl.canonicalize().unwrap_or_else(|_| mtl.clone());
        if self.seen.borrow().contains(&key) {
            return Ok(None);
        }
        self.seen.borrow_mut().push(key);
        #[cfg(test)]
        MTL_READS.with(|n| n.set(n.get() + 1));
        let bytes = match limits::read_file(&mtl, MAX_MTL_FILE_BYTES) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound && self.mode == Mtl::Ignore => {
                return Ok(None)
            }
            Err(source) => {
                return Err(GeometryError::Material {
                    path: self.path.to_path_buf(),
                    mtl,
                    source,
                })
            }
            Ok(b) => b,
        };
        self.read.borrow_mut().push(mtl.clone());
        Ok(Some((mtl, bytes)))
    }

    /// Adds the materials `parsed` of one library, refusing one defined before; their names.
    fn add(&self, parsed: Vec<MtlMaterial>) -> Result<Vec<String>, GeometryError> {
        let mut all = self.materials.borrow_mut();
        let mut names = Vec::new();
        for m in parsed {
            if let Some(prev) = all.iter().find(|p| p.name == m.name) {
                return Err(GeometryError::MaterialSyntax {
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
            names.push(m.name.clone());
            all.push(m);
        }
        Ok(names)
    }
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
