//! glTF 2.0 models (`.gltf` with its buffers and images as files relative to it or `data:`
//! URIs, and `.glb`), read with the `gltf` crate's document model and candela's own checks:
//! the file and every buffer are read through [`crate::limits::read_file`], every accessor is
//! checked against the bytes it points into, and the memory the meshes will take is checked
//! before they are read. Malformed input is an error naming the file, never a panic.
//!
//! The result keeps the file's structure: each glTF mesh once (its primitives in the mesh's own
//! space) and the list of node world transforms that place it, so shared meshes need not be
//! copied by whoever builds instances; [`GltfModel::flatten_count`] says how many triangles a
//! world-space copy holds. Materials and lights are kept as the file gives them; how they become
//! candela's is in `scene::gltf` and docs/scene-format.md → models.

mod data;
mod material;

use super::{GeometryError, TriangleMesh};
use crate::limits;
use data::parse_err;
use glam::{Affine3A, Mat4, Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};
use std::path::{Path, PathBuf};

/// Largest `.gltf` / `.glb` file read; below it, the memory available decides.
const MAX_GLTF_FILE_BYTES: u64 = 1 << 40;

/// One triangle primitive of a mesh, in the mesh's own space.
#[derive(Clone, Debug)]
pub struct GltfPrimitive {
    pub mesh: TriangleMesh,
    /// Per-vertex texture coordinates (set 0) with v measured up from the image's bottom row
    /// (candela's convention; glTF's v runs down, so v is stored as 1 − v).
    pub uvs: Option<Vec<Vec2>>,
    /// Index into [`GltfModel::materials`]; `None` for glTF's default material.
    pub material: Option<usize>,
}

/// A glTF mesh: its triangle primitives.
#[derive(Clone, Debug)]
pub struct GltfMesh {
    pub name: Option<String>,
    pub primitives: Vec<GltfPrimitive>,
}

/// A node that places a mesh: the mesh's index and the node's world transform (the product of
/// its ancestors' and its own).
#[derive(Clone, Debug)]
pub struct GltfInstance {
    pub mesh: usize,
    pub node: usize,
    pub world: Affine3A,
}

/// A texture reference, its transform already in candela's texture convention.
#[derive(Clone, Debug)]
pub struct GltfTextureRef {
    pub image: usize,
    /// `KHR_texture_transform` as a map of candela's coordinates
    /// ([`crate::texture::gltf_uv_map`]); the identity without it.
    pub uv: glam::Affine2,
    /// Both wrap modes are CLAMP_TO_EDGE.
    pub clamp: bool,
}

/// A metallic-roughness material as the file gives it (defaults filled in).
#[derive(Clone, Debug)]
pub struct GltfMaterial {
    /// The material's name, or `#index` when it has none.
    pub name: String,
    pub index: usize,
    /// Linear RGBA.
    pub base_colour: [f64; 4],
    pub base_texture: Option<GltfTextureRef>,
    /// Roughness in G, metallic in B (linear), multiplying the factors.
    pub metal_rough_texture: Option<GltfTextureRef>,
    /// A tangent-space normal map and its `scale`.
    pub normal_texture: Option<(GltfTextureRef, f32)>,
    pub metallic: f64,
    /// Perceptual roughness (α = roughness²).
    pub roughness: f64,
    /// `KHR_materials_transmission`'s factor, 0 without it.
    pub transmission: f64,
    /// `KHR_materials_ior`, 1.5 without it.
    pub ior: f64,
    /// Linear RGB emissive factor.
    pub emissive: [f64; 3],
    /// sRGB colour multiplying `emissive` per texel.
    pub emissive_texture: Option<GltfTextureRef>,
    /// `KHR_materials_emissive_strength`, 1 without it.
    pub emissive_strength: f64,
}

/// Where an image's bytes are.
#[derive(Clone, Debug)]
pub enum GltfImage {
    /// A file relative to the model.
    File(PathBuf),
    /// Embedded (a buffer view or a `data:` URI); the label names it in messages.
    Bytes { label: PathBuf, bytes: Vec<u8> },
}

/// A `KHR_lights_punctual` light's kind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GltfLightKind {
    /// Intensity in cd.
    Point,
    /// Intensity in cd on the axis; cone half-angles in radians.
    Spot { inner_rad: f64, outer_rad: f64 },
    /// Illuminance in lx on a surface facing it.
    Directional,
}

/// A punctual light placed by its node.
#[derive(Clone, Debug)]
pub struct GltfLight {
    pub name: String,
    pub kind: GltfLightKind,
    /// Linear RGB.
    pub colour: [f64; 3],
    /// cd (point, spot) or lx (directional).
    pub intensity: f64,
    /// World position, m.
    pub position: Vec3,
    /// World direction the light travels along (the node's −Z), unit.
    pub direction: Vec3,
}

/// A glTF camera's projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GltfProjection {
    /// Full vertical field of view `yfov_rad` (radians) and, if the file gives it, the image's
    /// width / height.
    Perspective {
        yfov_rad: f64,
        aspect_ratio: Option<f64>,
    },
    Orthographic,
}

/// A camera placed by its node: glTF cameras look down the node's −Z with +Y up.
#[derive(Clone, Debug)]
pub struct GltfCamera {
    pub node: usize,
    /// The node's name, if it has one.
    pub node_name: Option<String>,
    /// The camera's name, if it has one.
    pub camera_name: Option<String>,
    pub projection: GltfProjection,
    /// World position, m.
    pub position: Vec3,
    /// World view direction (the node's −Z), unit.
    pub forward: Vec3,
    /// World up (the node's +Y), unit.
    pub up: Vec3,
}

/// A glTF file read (see the module docs).
#[derive(Clone, Debug)]
pub struct GltfModel {
    pub path: PathBuf,
    pub meshes: Vec<GltfMesh>,
    pub instances: Vec<GltfInstance>,
    pub materials: Vec<GltfMaterial>,
    pub images: Vec<GltfImage>,
    pub lights: Vec<GltfLight>,
    /// The camera nodes of the scene, in scene order (parents before children).
    pub cameras: Vec<GltfCamera>,
    /// Primitives left out because they are points or lines.
    pub skipped_primitives: usize,
    /// The files the model names (buffers and images), each checked to lie in its folder.
    pub files: Vec<PathBuf>,
}

impl GltfModel {
    /// Triangles in a world-space copy of every instance.
    pub fn flatten_count(&self) -> u64 {
        self.instances
            .iter()
            .map(|i| {
                (self.meshes[i.mesh].primitives.iter())
                    .map(|p| p.mesh.indices.len() as u64)
                    .sum::<u64>()
            })
            .sum()
    }
}

/// The file read (within its size limit) and parsed; a parser panic on malformed input
/// becomes an error naming the file.
fn parse_file(path: &Path) -> Result<gltf::Gltf, GeometryError> {
    let bytes =
        limits::read_file(path, MAX_GLTF_FILE_BYTES).map_err(|source| GeometryError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    precheck(path, &bytes)?;
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        gltf::Gltf::from_slice(&bytes)
    }))
    .map_err(|_| parse_err(path, "the glTF parser failed on malformed input".into()))?
    .map_err(|e| parse_err(path, e.to_string()))
}

/// Refuses a primitive whose `POSITION` names an accessor the file does not have, which the
/// `gltf` crate's validation would index unchecked (a panic). Anything else malformed is left
/// to the parser, which reports it.
fn precheck(path: &Path, bytes: &[u8]) -> Result<(), GeometryError> {
    let glb;
    let json: &[u8] = if bytes.starts_with(b"glTF") {
        match gltf::Glb::from_slice(bytes) {
            Ok(g) => {
                glb = g;
                &glb.json
            }
            Err(_) => return Ok(()),
        }
    } else {
        bytes
    };
    let Ok(root) = gltf::json::Root::from_slice(json) else {
        return Ok(());
    };
    let n = root.accessors.len();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (k, p) in mesh.primitives.iter().enumerate() {
            for (semantic, a) in &p.attributes {
                if a.value() >= n {
                    return Err(parse_err(
                        path,
                        format!(
                            "mesh {m} primitive {k}: attribute {:?} names accessor {}, but the file has {n}",
                            semantic,
                            a.value()
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Loads a `.gltf` or `.glb` file (see the module docs). The scene is the file's default
/// scene, else its first, else every node without a parent.
pub fn load_gltf(path: &Path) -> Result<GltfModel, GeometryError> {
    let gltf::Gltf { document, blob } = parse_file(path)?;
    for ext in document.extensions_required() {
        if !matches!(
            ext,
            "KHR_lights_punctual"
                | "KHR_materials_transmission"
                | "KHR_materials_ior"
                | "KHR_materials_emissive_strength"
                | "KHR_texture_transform"
        ) {
            return Err(parse_err(
                path,
                format!("it requires the extension {ext}, which candela does not read"),
            ));
        }
    }
    let mut files = Vec::new();
    let buffers = data::buffers(path, &document, blob, &mut files)?;
    let instances = instances(path, &document)?;
    check_mesh_memory(path, &document, &instances)?;
    let mut skipped = 0;
    let mut meshes = Vec::new();
    for m in document.meshes() {
        let mut primitives = Vec::new();
        for p in m.primitives() {
            if p.mode() != gltf::mesh::Mode::Triangles {
                skipped += 1;
                continue;
            }
            primitives.push(primitive(path, &m, &p, &buffers)?);
        }
        meshes.push(GltfMesh {
            name: m.name().map(str::to_string),
            primitives,
        });
    }
    if instances.iter().all(|i| {
        meshes[i.mesh]
            .primitives
            .iter()
            .all(|p| p.mesh.indices.is_empty())
    }) {
        return Err(GeometryError::NoTriangles {
            path: path.to_path_buf(),
            detail: format!(
                "no node of its scene places a mesh with triangles ({} meshes, {} primitives of points or lines skipped)",
                meshes.len(),
                skipped
            ),
        });
    }
    check_world_positions(path, &document, &meshes, &instances)?;
    let materials = document
        .materials()
        .map(|m| material::material(path, &m))
        .collect::<Result<_, _>>()?;
    let images: Vec<GltfImage> = document
        .images()
        .map(|im| material::image(path, &im, &buffers))
        .collect::<Result<_, _>>()?;
    for im in &images {
        if let GltfImage::File(f) = im {
            files.push(f.clone());
        }
    }
    let lights = lights(path, &document)?;
    let cameras = cameras(path, &document)?;
    Ok(GltfModel {
        path: path.to_path_buf(),
        meshes,
        instances,
        materials,
        images,
        lights,
        cameras,
        skipped_primitives: skipped,
        files,
    })
}

/// The camera nodes of a `.gltf` or `.glb` file's scene, without reading its buffers.
pub fn load_cameras(path: &Path) -> Result<Vec<GltfCamera>, GeometryError> {
    cameras(path, &parse_file(path)?.document)
}

fn cameras(path: &Path, doc: &gltf::Document) -> Result<Vec<GltfCamera>, GeometryError> {
    let nodes: Vec<gltf::Node> = doc.nodes().collect();
    let mut out = Vec::new();
    for (i, world) in scene_nodes(path, doc)? {
        let Some(c) = nodes[i].camera() else { continue };
        let projection = match c.projection() {
            gltf::camera::Projection::Perspective(p) => GltfProjection::Perspective {
                yfov_rad: p.yfov() as f64,
                aspect_ratio: p.aspect_ratio().map(|a| a as f64),
            },
            gltf::camera::Projection::Orthographic(_) => GltfProjection::Orthographic,
        };
        let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
        let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
        if forward == Vec3::ZERO || up == Vec3::ZERO || forward.cross(up).length() < 1e-6 {
            return Err(parse_err(
                path,
                format!("node {i}'s transform leaves its camera no view direction or up"),
            ));
        }
        out.push(GltfCamera {
            node: i,
            node_name: nodes[i].name().map(str::to_string),
            camera_name: c.name().map(str::to_string),
            projection,
            position: world.transform_point3(Vec3::ZERO),
            forward,
            up,
        });
    }
    Ok(out)
}

/// The nodes of the scene with their world transforms, parents before children.
fn scene_nodes(path: &Path, doc: &gltf::Document) -> Result<Vec<(usize, Mat4)>, GeometryError> {
    let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(s) => s.nodes().collect(),
        None => {
            let mut child = vec![false; doc.nodes().len()];
            for n in doc.nodes() {
                for c in n.children() {
                    child[c.index()] = true;
                }
            }
            doc.nodes().filter(|n| !child[n.index()]).collect()
        }
    };
    let mut seen = vec![false; doc.nodes().len()];
    let mut out = Vec::new();
    let mut stack: Vec<(gltf::Node, Mat4)> = roots
        .into_iter()
        .rev()
        .map(|n| (n, Mat4::IDENTITY))
        .collect();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut seen[node.index()], true) {
            return Err(parse_err(
                path,
                format!(
                    "node {} is reached twice from the scene (glTF nodes form trees)",
                    node.index()
                ),
            ));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        if !world.is_finite() {
            return Err(parse_err(
                path,
                format!("node {} has a non-finite transform", node.index()),
            ));
        }
        out.push((node.index(), world));
        for c in node.children().collect::<Vec<_>>().into_iter().rev() {
            stack.push((c, world));
        }
    }
    Ok(out)
}

fn instances(path: &Path, doc: &gltf::Document) -> Result<Vec<GltfInstance>, GeometryError> {
    let nodes: Vec<gltf::Node> = doc.nodes().collect();
    Ok(scene_nodes(path, doc)?
        .into_iter()
        .filter_map(|(i, world)| {
            nodes[i].mesh().map(|m| GltfInstance {
                mesh: m.index(),
                node: i,
                world: Affine3A::from_mat4(world),
            })
        })
        .collect())
}

/// Refuses a model whose meshes, and their world-space copies, would not fit in memory; the
/// counts come from the accessors (not yet checked against the buffers, so a file that lies is
/// refused here or by the accessor checks after).
fn check_mesh_memory(
    path: &Path,
    doc: &gltf::Document,
    instances: &[GltfInstance],
) -> Result<(), GeometryError> {
    let mut uses = vec![0u64; doc.meshes().len()];
    for i in instances {
        uses[i.mesh] += 1;
    }
    let mut per_mesh = Vec::new();
    let mut need = 0u64;
    for m in doc.meshes() {
        let mut tris = 0u64;
        for p in m.primitives() {
            let verts = p
                .get(&gltf::Semantic::Positions)
                .map_or(0, |a| a.count() as u64);
            let idx = p.indices().map_or(verts, |a| a.count() as u64);
            // Position, normal (12 B each), uv (8 B), index (4 B): in the file's mesh and once
            // more while it is being built.
            need = need.saturating_add(verts.saturating_mul(2 * 32) + idx.saturating_mul(8));
            // A shared mesh is instanced (stored once); only its emitting primitives are copied.
            if uses[m.index()] < 2 || p.material().emissive_factor() != [0.0; 3] {
                tris = tris.saturating_add(idx / 3);
            }
        }
        per_mesh.push(tris);
    }
    // A world-space copy of each copied primitive: 3 vertices of 32 B and 12 B of indices per
    // triangle.
    for i in instances {
        need = need.saturating_add(per_mesh[i.mesh].saturating_mul(108));
    }
    limits::check_memory(need, "loading this glTF model's meshes").map_err(|message| {
        GeometryError::TooLarge {
            path: path.to_path_buf(),
            message,
        }
    })
}

/// Refuses a vertex that a node's transform puts at a non-finite position or beyond
/// [`super::bvh::MAX_COORDINATE`] (a valid vertex can be scaled out of range), naming the node,
/// mesh, primitive, vertex and accessor. Each primitive's bounding box is transformed first;
/// only when it reaches out are its vertices searched.
fn check_world_positions(
    path: &Path,
    doc: &gltf::Document,
    meshes: &[GltfMesh],
    instances: &[GltfInstance],
) -> Result<(), GeometryError> {
    let max = super::bvh::MAX_COORDINATE;
    let far = |p: Vec3| !p.is_finite() || p.abs().max_element() > max;
    for inst in instances {
        for (k, prim) in meshes[inst.mesh].primitives.iter().enumerate() {
            let ps = &prim.mesh.positions;
            let (lo, hi) = ps
                .iter()
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| {
                    (a.min(*p), b.max(*p))
                });
            if ps.is_empty() {
                continue;
            }
            let corners = (0..8).map(|c| {
                let pick = |bit: u32, l: f32, h: f32| if c & bit == 0 { l } else { h };
                inst.world.transform_point3(Vec3::new(
                    pick(1, lo.x, hi.x),
                    pick(2, lo.y, hi.y),
                    pick(4, lo.z, hi.z),
                ))
            });
            if !corners.into_iter().any(far) {
                continue;
            }
            let Some((v, w)) = (ps.iter().enumerate())
                .map(|(v, p)| (v, inst.world.transform_point3(*p)))
                .find(|(_, w)| far(*w))
            else {
                continue;
            };
            // The k-th triangle primitive kept, by its index in the file.
            let gp = doc.meshes().nth(inst.mesh).and_then(|m| {
                m.primitives()
                    .filter(|p| p.mode() == gltf::mesh::Mode::Triangles)
                    .nth(k)
            });
            let index = gp.as_ref().map_or(k, |p| p.index());
            let accessor = (gp.as_ref())
                .and_then(|p| p.get(&gltf::Semantic::Positions))
                .map_or(String::new(), |a| format!(" (accessor {})", a.index()));
            return Err(parse_err(
                path,
                format!(
                    "node {} places vertex {v} of mesh {} primitive {index}{accessor} at ({}, {}, {}) m; geometry must lie within ±{max:e} m of the origin",
                    inst.node, inst.mesh, w.x, w.y, w.z
                ),
            ));
        }
    }
    Ok(())
}

fn primitive(
    path: &Path,
    mesh: &gltf::Mesh,
    p: &gltf::Primitive,
    buffers: &[Vec<u8>],
) -> Result<GltfPrimitive, GeometryError> {
    let at = |what: &str| format!("mesh {} primitive {} {what}", mesh.index(), p.index());
    let Some(pos) = p.get(&gltf::Semantic::Positions) else {
        return Err(parse_err(path, at("has no POSITION attribute")));
    };
    let pos = data::elements(
        path,
        &pos,
        &at("POSITION"),
        Dimensions::Vec3,
        &[DataType::F32],
        buffers,
    )?;
    let nv = pos.count;
    let mut m = TriangleMesh {
        positions: (0..nv)
            .map(|i| Vec3::new(pos.float(i, 0), pos.float(i, 1), pos.float(i, 2)))
            .collect(),
        ..Default::default()
    };
    if let Some(v) = m.positions.iter().position(|p| !p.is_finite()) {
        return Err(GeometryError::NonFinite {
            path: path.to_path_buf(),
            vertex: v,
            what: "position",
        });
    }
    let same_count = |e: &data::Elements, what: &str| {
        if e.count != nv {
            return Err(parse_err(
                path,
                at(&format!(
                    "{what} has {} elements for {nv} positions",
                    e.count
                )),
            ));
        }
        Ok(())
    };
    if let Some(n) = p.get(&gltf::Semantic::Normals) {
        let n = data::elements(
            path,
            &n,
            &at("NORMAL"),
            Dimensions::Vec3,
            &[DataType::F32],
            buffers,
        )?;
        same_count(&n, "NORMAL")?;
        let ns: Vec<Vec3> = (0..nv)
            .map(|i| Vec3::new(n.float(i, 0), n.float(i, 1), n.float(i, 2)).normalize_or_zero())
            .collect();
        if let Some(v) = ns.iter().position(|n| !n.is_finite()) {
            return Err(GeometryError::NonFinite {
                path: path.to_path_buf(),
                vertex: v,
                what: "normal",
            });
        }
        m.normals = Some(ns);
    }
    let uvs = match p.get(&gltf::Semantic::TexCoords(0)) {
        None => None,
        Some(t) => {
            let t = data::elements(
                path,
                &t,
                &at("TEXCOORD_0"),
                Dimensions::Vec2,
                &[DataType::F32, DataType::U8, DataType::U16],
                buffers,
            )?;
            same_count(&t, "TEXCOORD_0")?;
            let uv: Vec<Vec2> = (0..nv)
                .map(|i| Vec2::new(t.float(i, 0), 1.0 - t.float(i, 1)))
                .collect();
            if let Some(i) = uv.iter().position(|t| !t.is_finite()) {
                return Err(parse_err(
                    path,
                    at(&format!("texture coordinate {i} is not finite")),
                ));
            }
            Some(uv)
        }
    };
    let indices: Vec<u32> = match p.indices() {
        Some(a) => {
            let e = data::elements(
                path,
                &a,
                "indices",
                Dimensions::Scalar,
                &[DataType::U8, DataType::U16, DataType::U32],
                buffers,
            )?;
            (0..e.count).map(|i| e.uint(i)).collect()
        }
        None => (0..nv as u32).collect(),
    };
    if indices.len() % 3 != 0 {
        return Err(parse_err(
            path,
            at(&format!(
                "has {} indices, not a multiple of 3",
                indices.len()
            )),
        ));
    }
    for (f, c) in indices.chunks_exact(3).enumerate() {
        if let Some(&i) = c.iter().find(|&&i| i as usize >= nv) {
            return Err(parse_err(
                path,
                at(&format!(
                    "triangle {f} refers to vertex {i}, but the primitive has {nv} vertices"
                )),
            ));
        }
        m.indices.push([c[0], c[1], c[2]]);
    }
    Ok(GltfPrimitive {
        mesh: m,
        uvs,
        material: p.material().index(),
    })
}

fn lights(path: &Path, doc: &gltf::Document) -> Result<Vec<GltfLight>, GeometryError> {
    let nodes: Vec<gltf::Node> = doc.nodes().collect();
    let mut out = Vec::new();
    for (i, world) in scene_nodes(path, doc)? {
        let Some(l) = nodes[i].light() else { continue };
        use gltf::khr_lights_punctual::Kind;
        let kind = match l.kind() {
            Kind::Point => GltfLightKind::Point,
            Kind::Directional => GltfLightKind::Directional,
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => GltfLightKind::Spot {
                inner_rad: inner_cone_angle as f64,
                outer_rad: outer_cone_angle as f64,
            },
        };
        let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
        if direction == Vec3::ZERO && kind != GltfLightKind::Point {
            return Err(parse_err(
                path,
                format!("node {i}'s transform leaves its light no direction"),
            ));
        }
        out.push(GltfLight {
            name: l
                .name()
                .map_or_else(|| format!("#{}", l.index()), str::to_string),
            kind,
            colour: l.color().map(|v| v as f64),
            intensity: l.intensity() as f64,
            position: world.transform_point3(Vec3::ZERO),
            direction,
        });
    }
    Ok(out)
}

/// Whether a model file is glTF, by its extension (`.gltf`, `.glb`, any case).
pub fn is_gltf(file: &str) -> bool {
    Path::new(file)
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}
