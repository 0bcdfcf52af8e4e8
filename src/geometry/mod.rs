//! Geometry: shapes, transforms, mesh loading, the scene BVH (8-wide, float boxes) with closest-hit and
//! shadow queries, robust ray offsets and area / solid-angle sampling of primitives.
//!
//! Units are metres. All queries are designed to be scale-independent: they work for scenes
//! from micrometres to thousands of kilometres (there is no fixed epsilon anywhere; ray
//! self-intersection is avoided with floating-point error bounds, see [`offset_ray_origin`]).
//!
//! Conventions:
//! * Ray directions passed to [`SceneGeometry::intersect`] / [`SceneGeometry::occluded`] need not
//!   be normalized (any finite, non-zero vector). `t` is the ray parameter (`p = origin + t·dir`),
//!   which equals the distance only for unit directions.
//! * Every primitive has a *front face*: quads `edge_u × edge_v`, disks `normal`, spheres
//!   outward, triangles counter-clockwise `(v1−v0)×(v2−v0)`. [`Hit::ng`] is always the front-face
//!   normal, never flipped toward the ray; [`Hit::front_face`] tells which side was hit.
//! * Primitive ids ([`Hit::prim`], [`SceneGeometry::primitives_of_object`]) are indices into the
//!   BVH's leaf-ordered primitive array; they are stable for the lifetime of a
//!   [`SceneGeometry`] but not across rebuilds.
//!
//! Typical integrator usage:
//!
//! ```ignore
//! let geo = SceneGeometry::build(&shapes)?;            // shapes: Vec<(Shape, object_id)>
//! let hit = geo.intersect(cam_o, cam_d, f32::INFINITY)?;
//! // Next bounce: offset the origin to the side of the new direction (no acne at any scale).
//! let o = hit.spawn_origin(wi);                         // = offset_ray_origin(hit.p, hit.error, hit.ng, wi)
//! let next = geo.intersect(o, wi, f32::INFINITY);
//! // Next-event estimation on an emitting primitive `lp` of an area light:
//! if let Some((ls, pdf_w)) = geo.sample_prim_solid_angle(lp, hit.p, u) {
//!     let (so, sd, st) = shadow_ray(&hit, ls.p, ls.n);  // both ends offset
//!     if !geo.occluded(so, sd, st) { /* add Le · f · |cos| / pdf_w */ }
//! }
//! // MIS weight for a BSDF-sampled ray that hit the light primitive `lp` at `lh`:
//! let pdf_light = geo.pdf_prim_solid_angle(lp, hit.p, &lh); // same `reference` as when sampling
//! ```

pub mod blinds;
mod bvh;
mod desc;
pub mod gltf;
mod instance;
mod io;
pub mod mtl;
mod pages;
mod ply;
mod prim;
mod query;
mod robust;
mod sample;
mod scene;
mod tangent;
mod traverse;
mod wide;

pub use blinds::Blinds;
pub use bvh::BUILD_PEAK_BYTES_PER_PRIM;
pub(crate) use desc::mesh_err;
pub use instance::{InstanceGroup, NO_INSTANCE};
pub use io::{load_obj, load_obj_model, model_file, ObjGroup, ObjModel};
pub use ply::load_ply;
pub use prim::flat_point;
pub use query::RayHit;
pub use robust::{
    gamma, next_float_down, next_float_up, offset_ray_origin, point_error_bound, shadow_ray,
    shadow_ray_between, MACHINE_EPSILON, SHADOW_EPSILON,
};
pub use scene::SceneGeometry;

use glam::{Affine3A, Mat3, Quat, Vec2, Vec3};
use std::path::PathBuf;

/// Errors of the geometry module. Every message is one self-contained paragraph that names
/// the file (or scene object) and what is wrong with it.
#[derive(Debug, thiserror::Error)]
pub enum GeometryError {
    /// The mesh file could not be opened or read.
    #[error("cannot read mesh file '{}': {source}. Check that the path is correct (a scene's relative mesh paths are resolved against the scene file's directory) and that the file is readable.", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// Loading the mesh would need more memory than is available.
    #[error("mesh file '{}' is too large to load: {message}.", path.display())]
    TooLarge { path: PathBuf, message: String },
    /// A material library named by an OBJ file's `mtllib` exists but cannot be read (a FIFO, a
    /// device, a directory, too large, not permitted).
    #[error("cannot read material library '{}' named by mesh file '{}': {source}.", mtl.display(), path.display())]
    Material {
        path: PathBuf,
        mtl: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A statement of a material library is malformed.
    #[error("material library '{}' is invalid, line {line}: {message}.", mtl.display())]
    MaterialSyntax {
        mtl: PathBuf,
        line: usize,
        message: String,
    },
    /// The file exists but its contents could not be parsed (corrupt, truncated, non-numeric...).
    #[error("mesh file '{}' is corrupt, truncated or not a valid {format} file: {message}.", path.display())]
    Parse {
        path: PathBuf,
        format: &'static str,
        message: String,
    },
    /// A face refers to a vertex that does not exist.
    #[error("mesh file '{}' is invalid: face {face} refers to vertex index {index}, but the file has only {vertex_count} vertices (valid indices are 0..{vertex_count}).", path.display())]
    IndexOutOfRange {
        path: PathBuf,
        face: usize,
        index: i64,
        vertex_count: usize,
    },
    /// A vertex position or normal is NaN or infinite.
    #[error("mesh file '{}' is invalid: vertex {vertex} has a non-finite (NaN or infinite) {what}.", path.display())]
    NonFinite {
        path: PathBuf,
        vertex: usize,
        what: &'static str,
    },
    /// A model names a file outside its folder (see [`io::model_file`]).
    #[error("model file '{}' names {what} {name:?}, which is outside the model's folder '{}'; a model may read only files beside it or below its folder (after resolving `..` and symbolic links), or data: URIs.", path.display(), folder.display())]
    Outside {
        path: PathBuf,
        what: String,
        name: String,
        folder: PathBuf,
    },
    /// The file parsed fine but contains no usable triangles.
    #[error("mesh file '{}' contains no triangles: {detail}.", path.display())]
    NoTriangles { path: PathBuf, detail: String },
    /// A shape's parameters are invalid (negative radius, NaN coordinates, bad mesh indices...).
    #[error("invalid {shape} for scene object {object}: {message}.")]
    InvalidShape {
        shape: &'static str,
        object: u32,
        message: String,
    },
    /// The BVH over the scene's primitives would need more memory than is available.
    #[error("the scene's geometry is too large to build: {message}.")]
    OutOfMemory { message: String },
    /// A transform cannot be applied to a shape.
    #[error("cannot transform {shape}: {message}.")]
    InvalidTransform {
        shape: &'static str,
        message: String,
    },
}

/// The rotation by Euler angles `rotate_deg` (degrees): about the fixed X axis, then Y, then Z.
pub fn euler_rotation_deg(rotate_deg: Vec3) -> Quat {
    Quat::from_rotation_z(rotate_deg.z.to_radians())
        * Quat::from_rotation_y(rotate_deg.y.to_radians())
        * Quat::from_rotation_x(rotate_deg.x.to_radians())
}

/// Affine object-to-world transform built from scale, then rotation, then translation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub matrix: Affine3A,
}

impl Default for Transform {
    fn default() -> Self {
        Self::identity()
    }
}

impl Transform {
    pub fn identity() -> Self {
        Self {
            matrix: Affine3A::IDENTITY,
        }
    }

    /// `M = T · Rz · Ry · Rx · S`: the object is first scaled per axis by `scale`, then rotated
    /// about the (fixed, world) X axis by `rotate_deg.x` degrees, then about Y by `rotate_deg.y`,
    /// then about Z by `rotate_deg.z` (right-handed, counter-clockwise when looking down the
    /// axis toward the origin), then translated by `translate`.
    pub fn from_trs(translate: Vec3, rotate_deg: Vec3, scale: Vec3) -> Self {
        let r = euler_rotation_deg(rotate_deg);
        Self {
            matrix: Affine3A::from_scale_rotation_translation(scale, r, translate),
        }
    }

    /// Wraps an arbitrary affine matrix.
    pub fn from_affine(matrix: Affine3A) -> Self {
        Self { matrix }
    }

    /// `self ∘ other` (apply `other` first).
    pub fn then_after(&self, other: &Transform) -> Transform {
        Transform {
            matrix: self.matrix * other.matrix,
        }
    }

    fn linear(&self) -> Mat3 {
        Mat3::from(self.matrix.matrix3)
    }

    /// True if the linear part is a similarity (rotation/reflection times one uniform scale),
    /// within a relative tolerance of 1e-5.
    pub fn is_uniform_scale(&self) -> bool {
        self.uniform_scale_factor().is_some()
    }

    /// The uniform scale factor if the linear part is a (non-degenerate) similarity.
    pub fn uniform_scale_factor(&self) -> Option<f32> {
        let m = self.linear();
        let (a, b, c) = (m.x_axis, m.y_axis, m.z_axis);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let s = (la + lb + lc) / 3.0;
        if !(s.is_finite() && s > 0.0) {
            return None;
        }
        let tol = 1e-5;
        let same =
            (la - s).abs() <= tol * s && (lb - s).abs() <= tol * s && (lc - s).abs() <= tol * s;
        let ortho = a.dot(b).abs() <= tol * s * s
            && a.dot(c).abs() <= tol * s * s
            && b.dot(c).abs() <= tol * s * s;
        (same && ortho).then_some(s)
    }

    /// True if the transform is finite and its linear part is invertible (not singular).
    pub fn is_invertible(&self) -> bool {
        let m = self.linear();
        let det = m.determinant();
        let scale = m.x_axis.length() * m.y_axis.length() * m.z_axis.length();
        self.matrix.translation.is_finite()
            && m.is_finite()
            && det.is_finite()
            && scale > 0.0
            && det.abs() > 1e-9 * scale
    }

    pub fn transform_point(&self, p: Vec3) -> Vec3 {
        self.matrix.transform_point3(p)
    }

    pub fn transform_vector(&self, v: Vec3) -> Vec3 {
        self.matrix.transform_vector3(v)
    }

    /// Transforms a normal (inverse transpose), normalized. Requires an invertible transform.
    pub fn transform_normal(&self, n: Vec3) -> Vec3 {
        (self.linear().inverse().transpose() * n).normalize()
    }

    /// True if the transform mirrors (negative determinant).
    pub fn swaps_handedness(&self) -> bool {
        self.linear().determinant() < 0.0
    }
}

/// A shape in its object space; `to_world` applies a [`Transform`].
#[derive(Clone, Debug)]
pub enum Shape {
    Sphere {
        center: Vec3,
        radius: f32,
    },
    /// Parallelogram origin + s·edge_u + t·edge_v, s,t ∈ \[0,1\]; front-face normal = normalize(edge_u × edge_v).
    Quad {
        origin: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
    },
    /// Front face = `normal`.
    Disk {
        center: Vec3,
        normal: Vec3,
        radius: f32,
    },
    Mesh(TriangleMesh),
}

/// An indexed triangle mesh. Front face: counter-clockwise `(v1−v0)×(v2−v0)`.
/// `normals`, if present, are per-vertex (same length as `positions`).
#[derive(Clone, Debug, Default)]
pub struct TriangleMesh {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub indices: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// Approximate heap size in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.positions.capacity() * 12
            + self.normals.as_ref().map_or(0, |n| n.capacity() * 12)
            + self.indices.capacity() * 12
    }

    /// Area-weighted vertex normals from the faces (front faces).
    pub fn compute_vertex_normals(&mut self) {
        let mut n = vec![Vec3::ZERO; self.positions.len()];
        for tri in &self.indices {
            let [a, b, c] = tri.map(|i| self.positions[i as usize]);
            let fnrm = (b - a).cross(c - a);
            for &i in tri {
                n[i as usize] += fnrm;
            }
        }
        for v in &mut n {
            *v = v.normalize_or(Vec3::Z);
        }
        self.normals = Some(n);
    }
}

impl Shape {
    pub fn name(&self) -> &'static str {
        match self {
            Shape::Sphere { .. } => "sphere",
            Shape::Quad { .. } => "quad",
            Shape::Disk { .. } => "disk",
            Shape::Mesh(_) => "triangle mesh",
        }
    }

    /// Applies `t`. Errors for a sphere or disk under non-uniform scale (they would become
    /// ellipsoids / ellipses) and for any shape under a singular or non-finite transform.
    /// Mirroring transforms keep the front face on the same (transformed) side: quad edges and
    /// triangle windings are swapped so that e.g. an outward-facing closed mesh stays outward.
    pub fn to_world(&self, t: &Transform) -> Result<Shape, GeometryError> {
        let name = self.name();
        if !t.is_invertible() {
            return Err(GeometryError::InvalidTransform {
                shape: name,
                message: format!(
                    "the transform {:?} is singular (zero scale on some axis) or not finite",
                    t.matrix
                ),
            });
        }
        let mirror = t.swaps_handedness();
        Ok(match self {
            Shape::Sphere { center, radius } => {
                let s = t.uniform_scale_factor().ok_or_else(|| GeometryError::InvalidTransform {
                    shape: name,
                    message: "a sphere can only be transformed with a uniform scale (non-uniform scale would make an ellipsoid; use a mesh instead)".into(),
                })?;
                Shape::Sphere {
                    center: t.transform_point(*center),
                    radius: radius * s,
                }
            }
            Shape::Disk {
                center,
                normal,
                radius,
            } => {
                let s = t.uniform_scale_factor().ok_or_else(|| GeometryError::InvalidTransform {
                    shape: name,
                    message: "a disk can only be transformed with a uniform scale (non-uniform scale would make an ellipse; use a mesh instead)".into(),
                })?;
                Shape::Disk {
                    center: t.transform_point(*center),
                    normal: t.transform_normal(*normal),
                    radius: radius * s,
                }
            }
            Shape::Quad {
                origin,
                edge_u,
                edge_v,
            } => {
                let (eu, ev) = (t.transform_vector(*edge_u), t.transform_vector(*edge_v));
                let o = t.transform_point(*origin);
                if mirror {
                    Shape::Quad {
                        origin: o,
                        edge_u: ev,
                        edge_v: eu,
                    }
                } else {
                    Shape::Quad {
                        origin: o,
                        edge_u: eu,
                        edge_v: ev,
                    }
                }
            }
            Shape::Mesh(m) => {
                let positions = m.positions.iter().map(|&p| t.transform_point(p)).collect();
                let normals = m
                    .normals
                    .as_ref()
                    .map(|ns| ns.iter().map(|&n| t.transform_normal(n)).collect());
                let indices = if mirror {
                    m.indices.iter().map(|&[a, b, c]| [a, c, b]).collect()
                } else {
                    m.indices.clone()
                };
                Shape::Mesh(TriangleMesh {
                    positions,
                    normals,
                    indices,
                })
            }
        })
    }
}

/// A point on a surface with its unit front-face geometric normal and texture coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    pub p: Vec3,
    pub n: Vec3,
    /// Texture coordinates there, as a hit at the point reports them ([`Hit::tex`]).
    pub tex: Vec2,
}

/// A ray–surface intersection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit (distance if the direction was unit length).
    pub t: f32,
    pub p: Vec3,
    /// Unit geometric normal of the FRONT face (not flipped toward the ray).
    pub ng: Vec3,
    /// Unit shading normal (interpolated vertex normals where present, else `ng`), flipped if
    /// needed so that it lies in the same hemisphere as `ng`.
    pub ns: Vec3,
    /// Surface parameterisation: triangle barycentrics (b1, b2) of v1, v2; quad (s, t);
    /// sphere (φ/2π, θ/π) with θ from +Z; disk (r/R, φ/2π).
    pub uv: Vec2,
    /// Texture coordinates: a mesh's interpolated `vt` where it has them, else `uv`.
    pub tex: Vec2,
    /// Primitive id (see [`SceneGeometry::primitives_of_object`]).
    pub prim: u32,
    /// The caller's id of the scene object the primitive came from.
    pub object: u32,
    /// The instance hit (its index in the caller's order over all instance groups), or
    /// [`NO_INSTANCE`]. On an instance, `prim` is the primitive's id within the instanced mesh,
    /// not an id the primitive lookups (`prim_area`, sampling) take.
    pub instance: u32,
    /// The ray arrived on the side `ng` points to (`dot(dir, ng) < 0`).
    pub front_face: bool,
    /// Conservative per-axis absolute error bound of `p` (for [`offset_ray_origin`]).
    pub error: Vec3,
}

impl Hit {
    /// Robust origin for a ray leaving this hit in direction `w` (see [`offset_ray_origin`]).
    pub fn spawn_origin(&self, w: Vec3) -> Vec3 {
        offset_ray_origin(self.p, self.error, self.ng, w)
    }

    /// The hit as a [`SurfacePoint`] (position and front-face normal).
    pub fn surface_point(&self) -> SurfacePoint {
        SurfacePoint {
            p: self.p,
            n: self.ng,
            tex: self.tex,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trs_order_is_scale_rotate_translate() {
        let t = Transform::from_trs(
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(0.0, 0.0, 90.0),
            Vec3::new(2.0, 1.0, 1.0),
        );
        // (1,0,0) → scale (2,0,0) → Rz90 (0,2,0) → translate (1,4,3).
        let p = t.transform_point(Vec3::X);
        assert!((p - Vec3::new(1.0, 4.0, 3.0)).length() < 1e-6);
        assert!(!t.is_uniform_scale());
        assert!(Transform::identity().is_uniform_scale());
        // X first, then Y: Rx(90) takes Y to Z, then Ry(90) takes Z to X.
        let t = Transform::from_trs(Vec3::ZERO, Vec3::new(90.0, 90.0, 0.0), Vec3::ONE);
        assert!((t.transform_point(Vec3::Y) - Vec3::X).length() < 1e-6);
    }

    #[test]
    fn normals_transform_with_inverse_transpose() {
        let t = Transform::from_trs(Vec3::ZERO, Vec3::ZERO, Vec3::new(1.0, 4.0, 1.0));
        let n = t.transform_normal(Vec3::new(1.0, 1.0, 0.0).normalize());
        // Tangent (1,-1,0) maps to (1,-4,0); the normal must stay perpendicular to it.
        assert!(n.dot(Vec3::new(1.0, -4.0, 0.0)).abs() < 1e-6);
        assert!((n.length() - 1.0).abs() < 1e-6);
    }
}
