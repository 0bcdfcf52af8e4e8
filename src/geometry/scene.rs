//! The scene's primitives in one BVH: the [`SceneGeometry`] struct, primitive lookup by id,
//! objects and their primitives, bounds and size statistics. Building it is in `bvh`, ray
//! queries in `query` (over the node walk in `traverse`), primitive sampling in `sample`.

use super::bvh::SmallQuads;
use super::instance::InstanceSet;
use super::prim::Prim;
use super::wide::WideBvh;
use glam::Vec3;

/// All primitives of the scene in one BVH.
pub struct SceneGeometry {
    pub(super) bvh: WideBvh,
    /// Primitives in BVH leaf order; the primitive id is the index into this array. Triangles
    /// are stored inline (their vertices); any other primitive as a marker (NaN first
    /// coordinate, then its index into `others` as the bits of the second vertex's x).
    pub(super) tris: super::pages::HugeArray<[Vec3; 3]>,
    /// The non-triangle primitives.
    pub(super) others: Vec<Prim>,
    pub(super) prim_object: Vec<u32>,
    /// Per primitive vertex-normal indices into `normals` (`u32::MAX` = none). Empty when no
    /// primitive has vertex normals.
    pub(super) prim_normals: Vec<[u32; 3]>,
    pub(super) normals: Vec<Vec3>,
    /// Per primitive texture-coordinate indices into `uvs` (`u32::MAX` = none). Empty when no
    /// primitive has texture coordinates.
    pub(super) prim_uvs: Vec<[u32; 3]>,
    pub(super) uvs: Vec<glam::Vec2>,
    /// (object id, primitive ids), sorted by object id.
    pub(super) object_prims: Vec<(u32, Vec<u32>)>,
    pub(super) bounds: (Vec3, Vec3),
    /// Instanced meshes and their top-level BVH; `None` when the scene has none, so that
    /// scenes without instances pay one branch per query for them.
    pub(super) instances: Option<Box<InstanceSet>>,
    /// For a scene of a few quads, their data for testing them all without the BVH (which
    /// the queries then skip); empty otherwise.
    pub(super) small: SmallQuads,
}

impl SceneGeometry {
    /// Primitive `id`.
    #[inline]
    pub(super) fn prim(&self, id: u32) -> Prim {
        let v = &self.tris[id as usize];
        if v[0].x.is_nan() {
            self.others[v[1].x.to_bits() as usize]
        } else {
            Prim::Triangle(*v)
        }
    }

    /// Primitive ids (as used in [`Hit::prim`](super::Hit::prim)) of that object; empty if
    /// unknown.
    pub fn primitives_of_object(&self, object: u32) -> &[u32] {
        match self.object_prims.binary_search_by_key(&object, |(o, _)| *o) {
            Ok(i) => &self.object_prims[i].1,
            Err(_) => &[],
        }
    }

    /// Object ids present in the scene (sorted).
    pub fn objects(&self) -> impl Iterator<Item = u32> + '_ {
        self.object_prims.iter().map(|(o, _)| *o)
    }

    /// The object id of a primitive.
    pub fn object_of_prim(&self, prim: u32) -> u32 {
        self.prim_object[prim as usize]
    }

    /// World-space bounds of all primitives (`(0, 0)` for an empty scene).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    /// Primitives stored outside instances (instanced meshes: see
    /// [`SceneGeometry::instanced_triangle_count`]).
    pub fn primitive_count(&self) -> usize {
        self.tris.len()
    }

    /// Depth of the BVH (number of node levels).
    pub fn bvh_depth(&self) -> u32 {
        self.bvh.depth()
    }

    /// Number of BVH nodes (256 bytes each).
    pub fn node_count(&self) -> usize {
        self.bvh.nodes.len()
    }

    /// Approximate heap memory in bytes (BVH nodes, primitive data, per-primitive ids, normals,
    /// instances and their meshes).
    pub fn memory_bytes(&self) -> usize {
        self.bvh.memory_bytes()
            + self.tris.memory_bytes()
            + self.others.capacity() * std::mem::size_of::<Prim>()
            + self.prim_object.capacity() * 4
            + self.prim_normals.capacity() * 12
            + self.normals.capacity() * 12
            + self.prim_uvs.capacity() * 12
            + self.uvs.capacity() * 8
            + self
                .object_prims
                .iter()
                .map(|(_, v)| v.capacity() * 4 + 32)
                .sum::<usize>()
            + self.instances.as_ref().map_or(0, |s| s.memory_bytes())
            + self.small.memory_bytes()
    }
}
