//! Building the scene BVH: primitives from the shapes (validated, zero-area triangles
//! dropped), their padded bounds, a binary BVH over them (obvhs's PLOC and reinsertion for
//! ordinary inputs; a top-down SAH build of bounded height for the inputs PLOC handles badly),
//! the 8-wide tree with float child boxes collapsed from it (`wide`), and
//! the primitives laid out in leaf order.
//!
//! Any set of valid primitives builds in O(n log n)-ish time into a tree at most
//! [`MAX_DEPTH`] − 1 levels deep: PLOC gives up on inputs that would make it quadratic
//! (`ploc`), and a tree too deep after reinsertion is built top-down instead (`sah`).

mod ploc;
mod sah;
mod small;

pub(super) use small::SmallQuads;

use super::pages::HugeArray;
use super::prim::Prim;
use super::robust::gamma;
use super::wide::WideBvh;
use super::{GeometryError, SceneGeometry, Shape, TriangleMesh};
use glam::{Vec2, Vec3};
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;

/// Largest distance from the origin (m, per axis) of any primitive's bounds: beyond it the
/// BVH builder's f32 surface-area costs overflow (7 astronomical units: room for a sun).
pub const MAX_COORDINATE: f32 = 1e12;

/// Bound on the depth of the wide BVH (node levels), which sizes the traversal stack. The
/// binary tree it is made from is kept below it, and no wide BVH is deeper than its binary tree.
pub(super) const MAX_DEPTH: usize = 64;

/// Most levels of the binary tree.
const MAX_BVH2_HEIGHT: u32 = MAX_DEPTH as u32 - 1;

/// Peak memory of [`SceneGeometry::build`] per primitive, bytes, beyond its input: the
/// primitives, their boxes and ids, the binary and the wide tree (measured: 386 B for 10⁷
/// random triangles, tests/bvh_cad_bench.rs).
pub const BUILD_PEAK_BYTES_PER_PRIM: u64 = 400;

/// obvhs's `BvhBuildParams::medium_build()` value for the reinsertion after PLOC.
const REINSERTION_BATCH_RATIO: f32 = 0.05;
/// Most primitives in a leaf of the scene's BVH.
const MAX_PRIMS_PER_LEAF: u32 = 6;

/// Height of a binary tree (1 for a single leaf), or `None` once it exceeds `limit`.
fn bvh2_height(bvh: &Bvh2, limit: u32) -> Option<u32> {
    let mut max = 0;
    let mut stack = vec![(0u32, 1u32)];
    while let Some((n, d)) = stack.pop() {
        if d > limit {
            return None;
        }
        max = max.max(d);
        let node = &bvh.nodes[n as usize];
        if node.prim_count == 0 {
            stack.push((node.first_index, d + 1));
            stack.push((node.first_index + 1, d + 1));
        }
    }
    Some(max)
}

/// The binary tree over `aabbs` (not empty): obvhs's PLOC and reinsertion where PLOC finishes
/// in reasonable time and the result is not too deep, else the top-down build.
fn build_bvh2(aabbs: &[Aabb]) -> Bvh2 {
    if let Some(mut bvh2) = ploc::build(aabbs) {
        obvhs::bvh2::reinsertion::ReinsertionOptimizer::default().run(
            &mut bvh2,
            REINSERTION_BATCH_RATIO,
            None,
        );
        if bvh2_height(&bvh2, MAX_BVH2_HEIGHT).is_some() {
            return bvh2;
        }
    }
    sah::build(aabbs, MAX_BVH2_HEIGHT)
}

/// The wide BVH over `aabbs` (not empty), leaves of at most `max_leaf` primitives, and the
/// `aabbs` indices in leaf order.
pub(super) fn build_wide(aabbs: &[Aabb], max_leaf: u32) -> (WideBvh, Vec<u32>) {
    WideBvh::from_bvh2(&build_bvh2(aabbs), max_leaf)
}

/// Refuses a BVH too deep for the traversal stack (which the binary tree's height bound
/// already excludes: no level of the wide tree is made of fewer than one binary level).
pub(super) fn check_depth(bvh: &WideBvh, n: usize) -> Result<(), GeometryError> {
    let depth = bvh.depth();
    if depth as usize >= MAX_DEPTH {
        return Err(GeometryError::InvalidShape {
            shape: "scene",
            object: 0,
            message: format!(
                "internal error: the BVH over {n} primitives is {depth} levels deep (at most {} supported)",
                MAX_DEPTH - 1
            ),
        });
    }
    Ok(())
}

/// The padded box of a primitive or instance with bounds `(a, b)`: a few ulps wider, so that
/// rounding in bounds and quantization can never exclude its surface.
pub(super) fn padded_aabb(a: Vec3, b: Vec3) -> Aabb {
    let pad = (a.abs().max(b.abs()) * gamma(4)) + Vec3::splat(f32::MIN_POSITIVE);
    Aabb::new((a - pad).into(), (b + pad).into())
}

fn invalid(shape: &Shape, object: u32, message: impl Into<String>) -> GeometryError {
    GeometryError::InvalidShape {
        shape: shape.name(),
        object,
        message: message.into(),
    }
}

fn finite3(v: Vec3) -> bool {
    v.is_finite()
}

/// "No vertex normal / texture coordinate" in a primitive's index triple.
const NO_INDEX: [u32; 3] = [u32::MAX; 3];

impl SceneGeometry {
    /// Builds the BVH over all primitives of `shapes` (already in world space), each tagged
    /// with the caller's object id.
    ///
    /// Triangles with exactly zero area (collinear or repeated vertices) are dropped: they can
    /// never be hit and cannot be sampled. Invalid shapes (non-finite coordinates,
    /// non-positive radius, degenerate quad edges, zero disk normal, mesh indices out of range,
    /// vertex-normal count different from the vertex count) give an error naming the object.
    /// An empty scene is allowed (every ray misses).
    pub fn build(shapes: &[(Shape, u32)]) -> Result<SceneGeometry, GeometryError> {
        Self::build_with_uvs(shapes, &[])
    }

    /// [`SceneGeometry::build`] with per-vertex texture coordinates for some meshes:
    /// `uvs[k]`, if present, belongs to the mesh `shapes[k]` (one per vertex), and hits on it
    /// interpolate them into [`Hit::tex`](super::Hit::tex).
    pub fn build_with_uvs(
        shapes: &[(Shape, u32)],
        uvs: &[Option<&[Vec2]>],
    ) -> Result<SceneGeometry, GeometryError> {
        check_build_memory(shapes)?;
        let collected = Collected::from_shapes(shapes, uvs)?;
        let (aabbs, bounds) = padded_boxes(&collected.prims, &collected.objects)?;
        let (bvh, order) = if collected.prims.is_empty() {
            (WideBvh::default(), Vec::new())
        } else {
            build_wide(&aabbs, MAX_PRIMS_PER_LEAF)
        };
        // The traversal stack's bound, which the binary tree's height already guarantees.
        check_depth(&bvh, collected.prims.len())?;
        drop(aabbs);
        Ok(collected.in_leaf_order(bvh, &order, bounds))
    }
}

/// Refuses a build whose peak memory (by the count of primitives the shapes hold) exceeds
/// the memory available.
fn check_build_memory(shapes: &[(Shape, u32)]) -> Result<(), GeometryError> {
    let n: u64 = shapes
        .iter()
        .map(|(s, _)| match s {
            Shape::Mesh(m) => m.indices.len() as u64,
            _ => 1,
        })
        .sum();
    crate::limits::check_memory(
        n.saturating_mul(BUILD_PEAK_BYTES_PER_PRIM),
        &format!("the BVH over {n} primitives"),
    )
    .map_err(|message| GeometryError::OutOfMemory { message })
}

/// The validated primitive of a sphere, quad or disk.
fn analytic_prim(shape: &Shape, object: u32) -> Result<Prim, GeometryError> {
    match shape {
        Shape::Sphere { center, radius } => {
            if !(finite3(*center) && radius.is_finite() && *radius > 0.0) {
                return Err(invalid(
                    shape,
                    object,
                    format!("center {center} and radius {radius} must be finite with radius > 0"),
                ));
            }
            Ok(Prim::Sphere {
                center: *center,
                radius: *radius,
            })
        }
        Shape::Quad {
            origin,
            edge_u,
            edge_v,
        } => {
            let area = edge_u.as_dvec3().cross(edge_v.as_dvec3()).length();
            if !(finite3(*origin)
                && finite3(*edge_u)
                && finite3(*edge_v)
                && area > 0.0
                && area.is_finite())
            {
                return Err(invalid(
                    shape,
                    object,
                    format!("origin {origin}, edges {edge_u} and {edge_v} must be finite and not parallel (the quad has zero area)"),
                ));
            }
            Ok(Prim::quad(*origin, *edge_u, *edge_v))
        }
        Shape::Disk {
            center,
            normal,
            radius,
        } => {
            let n = normal.as_dvec3().normalize_or_zero();
            if !(finite3(*center) && radius.is_finite() && *radius > 0.0) || n == glam::DVec3::ZERO
            {
                return Err(invalid(
                    shape,
                    object,
                    format!("center {center}, normal {normal} and radius {radius} must be finite with radius > 0 and a non-zero normal"),
                ));
            }
            Ok(Prim::Disk {
                center: *center,
                normal: n.as_vec3(),
                radius: *radius,
            })
        }
        Shape::Mesh(_) => unreachable!("meshes are collected triangle by triangle"),
    }
}

/// Refuses a mesh with a vertex that is not finite or lies beyond [`MAX_COORDINATE`].
fn check_mesh_positions(shape: &Shape, object: u32, m: &TriangleMesh) -> Result<(), GeometryError> {
    if let Some(i) = m.positions.iter().position(|p| !p.is_finite()) {
        return Err(invalid(
            shape,
            object,
            format!("vertex {i} has a non-finite position {}", m.positions[i]),
        ));
    }
    // Checked per vertex, before small triangles far out collapse in f32 to
    // zero area and would be dropped unseen.
    if let Some(i) = (m.positions.iter()).position(|p| p.abs().max_element() > MAX_COORDINATE) {
        return Err(invalid(
            shape,
            object,
            format!(
                "vertex {i} is at {} m; geometry must lie within ±{MAX_COORDINATE:e} m",
                m.positions[i]
            ),
        ));
    }
    Ok(())
}

/// The primitives of the shapes in input order, each with its object and (where any shape
/// has them) the indices of its vertex normals and texture coordinates.
struct Collected {
    prims: Vec<Prim>,
    objects: Vec<u32>,
    /// Per primitive, indices into `normals` ([`NO_INDEX`] for none); empty unless `any_normals`.
    prim_normals: Vec<[u32; 3]>,
    normals: Vec<Vec3>,
    /// Per primitive, indices into `uvs` ([`NO_INDEX`] for none); empty unless `any_uvs`.
    prim_uvs: Vec<[u32; 3]>,
    uvs: Vec<Vec2>,
    any_normals: bool,
    any_uvs: bool,
}

impl Collected {
    /// Validates every shape and collects its primitives (zero-area triangles dropped).
    fn from_shapes(
        shapes: &[(Shape, u32)],
        uvs: &[Option<&[Vec2]>],
    ) -> Result<Collected, GeometryError> {
        let mut c = Collected {
            prims: Vec::new(),
            objects: Vec::new(),
            prim_normals: Vec::new(),
            normals: Vec::new(),
            prim_uvs: Vec::new(),
            uvs: Vec::new(),
            any_normals: shapes
                .iter()
                .any(|(s, _)| matches!(s, Shape::Mesh(m) if m.normals.is_some())),
            any_uvs: uvs.iter().any(Option::is_some),
        };
        for (k, (shape, object)) in shapes.iter().enumerate() {
            let object = *object;
            match shape {
                Shape::Mesh(m) => c.push_mesh(shape, m, object, uvs.get(k).copied().flatten())?,
                _ => c.push_analytic(analytic_prim(shape, object)?, object),
            }
        }
        if c.prims.len() >= u32::MAX as usize {
            return Err(GeometryError::InvalidShape {
                shape: "scene",
                object: 0,
                message: "too many primitives (at most 2^32 − 1)".into(),
            });
        }
        Ok(c)
    }

    /// A sphere, quad or disk: no vertex normals, no texture coordinates.
    fn push_analytic(&mut self, prim: Prim, object: u32) {
        self.prims.push(prim);
        self.objects.push(object);
        if self.any_normals {
            self.prim_normals.push(NO_INDEX);
        }
        if self.any_uvs {
            self.prim_uvs.push(NO_INDEX);
        }
    }

    /// The triangles of mesh `m` (the shape `shape`) with its normals and texture coordinates
    /// `shape_uvs`.
    fn push_mesh(
        &mut self,
        shape: &Shape,
        m: &TriangleMesh,
        object: u32,
        shape_uvs: Option<&[Vec2]>,
    ) -> Result<(), GeometryError> {
        check_mesh_positions(shape, object, m)?;
        let nbase = self.normals.len() as u32;
        let has_n = self.push_mesh_normals(shape, m, object)?;
        let nv = m.positions.len();
        let tbase = self.uvs.len() as u32;
        if let Some(t) = shape_uvs {
            if t.len() != nv {
                return Err(invalid(
                    shape,
                    object,
                    format!("it has {} texture coordinates for {nv} vertices", t.len()),
                ));
            }
            self.uvs.extend_from_slice(t);
        }
        for (f, tri) in m.indices.iter().enumerate() {
            if let Some(&bad) = tri.iter().find(|&&i| i as usize >= nv) {
                return Err(invalid(
                    shape,
                    object,
                    format!(
                        "triangle {f} refers to vertex {bad}, but the mesh has only {nv} vertices"
                    ),
                ));
            }
            let v = tri.map(|i| m.positions[i as usize]);
            let (a, b, c) = (v[0].as_dvec3(), v[1].as_dvec3(), v[2].as_dvec3());
            if (b - a).cross(c - a).length_squared() == 0.0 {
                continue; // zero area: dropped
            }
            self.prims.push(Prim::Triangle(v));
            if self.any_normals {
                let n = if has_n {
                    tri.map(|i| nbase + i)
                } else {
                    NO_INDEX
                };
                self.prim_normals.push(n);
            }
            if self.any_uvs {
                let has_t = shape_uvs.is_some();
                let t = if has_t {
                    tri.map(|i| tbase + i)
                } else {
                    NO_INDEX
                };
                self.prim_uvs.push(t);
            }
            self.objects.push(object);
        }
        Ok(())
    }

    /// Appends the unit vertex normals of mesh `m`, if it has them (one per vertex).
    fn push_mesh_normals(
        &mut self,
        shape: &Shape,
        m: &TriangleMesh,
        object: u32,
    ) -> Result<bool, GeometryError> {
        let Some(ns) = &m.normals else {
            return Ok(false);
        };
        if ns.len() != m.positions.len() {
            return Err(invalid(
                shape,
                object,
                format!(
                    "it has {} vertex normals for {} vertices",
                    ns.len(),
                    m.positions.len()
                ),
            ));
        }
        self.normals
            .extend(ns.iter().map(|n| n.normalize_or_zero()));
        Ok(true)
    }

    /// The scene with its primitives laid out in the leaf order `order` of `bvh`, so the
    /// traversal indexes them directly.
    fn in_leaf_order(self, bvh: WideBvh, order: &[u32], bounds: (Vec3, Vec3)) -> SceneGeometry {
        let Collected {
            prims,
            objects,
            prim_normals,
            normals,
            prim_uvs,
            uvs,
            any_normals,
            any_uvs,
        } = self;
        let small = if prims.len() <= small::MAX_QUADS {
            SmallQuads::new(&order.iter().map(|&i| prims[i as usize]).collect::<Vec<_>>())
        } else {
            SmallQuads::default()
        };
        let (tris, others) = split_triangles(&prims, order);
        drop(prims);
        let prim_object: Vec<u32> = order.iter().map(|&i| objects[i as usize]).collect();
        let prim_normals = reordered(&prim_normals, order, any_normals);
        let prim_uvs = reordered(&prim_uvs, order, any_uvs);
        let object_prims = prims_by_object(&prim_object);
        SceneGeometry {
            bvh,
            tris,
            others,
            prim_object,
            prim_normals,
            normals,
            prim_uvs,
            uvs,
            object_prims,
            bounds,
            instances: None,
            small,
        }
    }
}

/// The padded box of every primitive and the bounds of them all (zero for none). Refuses a
/// primitive (of the object in `objects`) reaching beyond [`MAX_COORDINATE`].
fn padded_boxes(
    prims: &[Prim],
    objects: &[u32],
) -> Result<(Vec<Aabb>, (Vec3, Vec3)), GeometryError> {
    let mut lo = Vec3::INFINITY;
    let mut hi = Vec3::NEG_INFINITY;
    let mut aabbs: Vec<Aabb> = Vec::with_capacity(prims.len());
    for (p, &object) in prims.iter().zip(objects) {
        let (a, b) = p.bounds();
        // The BVH builder's surface-area costs (f32) overflow to inf and NaN for boxes
        // near f32::MAX, which corrupts the build (an out-of-bounds panic in obvhs).
        let reach = a.abs().max(b.abs()).max_element();
        if reach.is_nan() || reach > MAX_COORDINATE {
            return Err(GeometryError::InvalidShape {
                shape: "primitive",
                object,
                message: format!(
                    "it extends to {reach:e} m from the origin; geometry must lie within ±{MAX_COORDINATE:e} m"
                ),
            });
        }
        lo = lo.min(a);
        hi = hi.max(b);
        aabbs.push(padded_aabb(a, b));
    }
    let bounds = if prims.is_empty() {
        (Vec3::ZERO, Vec3::ZERO)
    } else {
        (lo, hi)
    };
    Ok((aabbs, bounds))
}

/// The triangles in leaf order, and the other primitives: a non-triangle's slot in the
/// triangle array holds a NaN vertex and, in the bits of the next, its index in `others`.
fn split_triangles(prims: &[Prim], order: &[u32]) -> (HugeArray<[Vec3; 3]>, Vec<Prim>) {
    let mut others = Vec::new();
    let tris = HugeArray::collect(
        order.len(),
        order.iter().map(|&i| match prims[i as usize] {
            Prim::Triangle(v) => v,
            p => {
                others.push(p);
                let marker = Vec3::new(f32::from_bits((others.len() - 1) as u32), 0.0, 0.0);
                [Vec3::NAN, marker, Vec3::ZERO]
            }
        }),
    );
    (tris, others)
}

/// Per-primitive index triples in leaf order; empty when not `kept`.
fn reordered(per_prim: &[[u32; 3]], order: &[u32], kept: bool) -> Vec<[u32; 3]> {
    if kept {
        order.iter().map(|&i| per_prim[i as usize]).collect()
    } else {
        Vec::new()
    }
}

/// Each object's primitive ids, ascending, objects in ascending order.
fn prims_by_object(prim_object: &[u32]) -> Vec<(u32, Vec<u32>)> {
    let mut by_obj: Vec<(u32, u32)> = prim_object
        .iter()
        .enumerate()
        .map(|(i, &o)| (o, i as u32))
        .collect();
    by_obj.sort_unstable();
    let mut object_prims: Vec<(u32, Vec<u32>)> = Vec::new();
    for (o, i) in by_obj {
        match object_prims.last_mut() {
            Some((lo, v)) if *lo == o => v.push(i),
            _ => object_prims.push((o, vec![i])),
        }
    }
    object_prims
}
