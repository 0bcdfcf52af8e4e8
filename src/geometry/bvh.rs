//! Building the scene BVH: primitives from the shapes (validated, zero-area triangles
//! dropped), their padded bounds, the obvhs CWBVH (8-wide, compressed nodes) over them with
//! empty child slots made unhittable and its depth checked, and the primitives laid out in
//! leaf order.

use super::prim::Prim;
use super::robust::gamma;
use super::{GeometryError, SceneGeometry, Shape};
use glam::Vec3;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::BvhBuildParams;

/// Largest distance from the origin (m, per axis) of any primitive's bounds: beyond it the
/// BVH builder's f32 surface-area costs overflow (7 astronomical units: room for a sun).
pub const MAX_COORDINATE: f32 = 1e12;

/// Maximum supported BVH depth.
pub(super) const MAX_DEPTH: usize = 64;

/// Depth of a CWBVH (1 for a single root node; 0 if empty).
pub(super) fn cwbvh_depth(bvh: &CwBvh) -> u32 {
    if bvh.nodes.is_empty() {
        return 0;
    }
    let mut max = 0;
    let mut stack = vec![(0u32, 1u32)];
    while let Some((n, d)) = stack.pop() {
        max = max.max(d);
        let node = &bvh.nodes[n as usize];
        for k in 0..node.imask.count_ones() {
            stack.push((node.child_base_idx + k, d + 1));
        }
    }
    max
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
        Self::build_with_params(shapes, BvhBuildParams::medium_build())
    }

    /// [`SceneGeometry::build`] with explicit obvhs build parameters (spatial pre-splits are
    /// always disabled).
    pub fn build_with_params(
        shapes: &[(Shape, u32)],
        mut params: BvhBuildParams,
    ) -> Result<SceneGeometry, GeometryError> {
        params.pre_split = false;
        let mut prims: Vec<Prim> = Vec::new();
        let mut objects: Vec<u32> = Vec::new();
        let mut prim_normals: Vec<[u32; 3]> = Vec::new();
        let mut normals: Vec<Vec3> = Vec::new();
        let any_normals = shapes
            .iter()
            .any(|(s, _)| matches!(s, Shape::Mesh(m) if m.normals.is_some()));
        let no_n = [u32::MAX; 3];
        for (shape, object) in shapes {
            let object = *object;
            match shape {
                Shape::Sphere { center, radius } => {
                    if !(finite3(*center) && radius.is_finite() && *radius > 0.0) {
                        return Err(invalid(
                            shape,
                            object,
                            format!("center {center} and radius {radius} must be finite with radius > 0"),
                        ));
                    }
                    prims.push(Prim::Sphere {
                        center: *center,
                        radius: *radius,
                    });
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
                    prims.push(Prim::Quad {
                        origin: *origin,
                        edge_u: *edge_u,
                        edge_v: *edge_v,
                    });
                }
                Shape::Disk {
                    center,
                    normal,
                    radius,
                } => {
                    let n = normal.as_dvec3().normalize_or_zero();
                    if !(finite3(*center) && radius.is_finite() && *radius > 0.0)
                        || n == glam::DVec3::ZERO
                    {
                        return Err(invalid(
                            shape,
                            object,
                            format!("center {center}, normal {normal} and radius {radius} must be finite with radius > 0 and a non-zero normal"),
                        ));
                    }
                    prims.push(Prim::Disk {
                        center: *center,
                        normal: n.as_vec3(),
                        radius: *radius,
                    });
                }
                Shape::Mesh(m) => {
                    if let Some(i) = m.positions.iter().position(|p| !p.is_finite()) {
                        return Err(invalid(
                            shape,
                            object,
                            format!("vertex {i} has a non-finite position {}", m.positions[i]),
                        ));
                    }
                    let nbase = normals.len() as u32;
                    let has_n = match &m.normals {
                        Some(ns) => {
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
                            normals.extend(ns.iter().map(|n| n.normalize_or_zero()));
                            true
                        }
                        None => false,
                    };
                    let nv = m.positions.len();
                    for (f, tri) in m.indices.iter().enumerate() {
                        if let Some(&bad) = tri.iter().find(|&&i| i as usize >= nv) {
                            return Err(invalid(
                                shape,
                                object,
                                format!("triangle {f} refers to vertex {bad}, but the mesh has only {nv} vertices"),
                            ));
                        }
                        let v = tri.map(|i| m.positions[i as usize]);
                        let (a, b, c) = (v[0].as_dvec3(), v[1].as_dvec3(), v[2].as_dvec3());
                        if (b - a).cross(c - a).length_squared() == 0.0 {
                            continue; // zero area: dropped
                        }
                        prims.push(Prim::Triangle(v));
                        if any_normals {
                            prim_normals.push(if has_n { tri.map(|i| nbase + i) } else { no_n });
                        }
                        objects.push(object);
                    }
                    continue;
                }
            }
            objects.push(object);
            if any_normals {
                prim_normals.push(no_n);
            }
        }
        if prims.len() >= u32::MAX as usize {
            return Err(GeometryError::InvalidShape {
                shape: "scene",
                object: 0,
                message: "too many primitives (at most 2^32 − 1)".into(),
            });
        }

        let mut lo = Vec3::INFINITY;
        let mut hi = Vec3::NEG_INFINITY;
        let mut aabbs: Vec<Aabb> = Vec::with_capacity(prims.len());
        for (p, &object) in prims.iter().zip(&objects) {
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
            // Pad by a few ulps so rounding in bounds/quantization can never exclude the
            // primitive's surface.
            let pad = (a.abs().max(b.abs()) * gamma(4)) + Vec3::splat(f32::MIN_POSITIVE);
            aabbs.push(Aabb::new((a - pad).into(), (b + pad).into()));
        }
        let bounds = if prims.is_empty() {
            (Vec3::ZERO, Vec3::ZERO)
        } else {
            (lo, hi)
        };
        let mut bvh = if prims.is_empty() {
            CwBvh::default()
        } else {
            // Same steps as `obvhs::cwbvh::builder::build_cwbvh`, minus its debug-build
            // validation, which asserts a depth < 32 that degenerate scenes can exceed (we
            // check the depth ourselves below).
            let mut bvh2 = obvhs::ploc::PlocBuilder::with_capacity(aabbs.len()).build(
                params.ploc_search_distance,
                &aabbs,
                (0..aabbs.len() as u32).collect(),
                params.sort_precision,
                params.search_depth_threshold,
            );
            obvhs::bvh2::reinsertion::ReinsertionOptimizer::default().run(
                &mut bvh2,
                params.reinsertion_batch_ratio,
                None,
            );
            obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(
                &bvh2,
                params.max_prims_per_leaf.clamp(1, 3),
                true,
                false,
            )
        };
        bvh.nodes.shrink_to_fit();
        // Empty child slots get inverted boxes (min 255 > max 0) so the node test misses them
        // (it does not check the slot's meta byte).
        for node in &mut bvh.nodes {
            for k in 0..8 {
                if node.child_meta[k] == 0 {
                    node.child_min_x[k] = 255;
                    node.child_min_y[k] = 255;
                    node.child_min_z[k] = 255;
                    node.child_max_x[k] = 0;
                    node.child_max_y[k] = 0;
                    node.child_max_z[k] = 0;
                }
            }
        }
        // Our traversal stack holds MAX_DEPTH entries; refuse a pathological BVH deeper than that.
        let depth = cwbvh_depth(&bvh);
        if depth as usize >= MAX_DEPTH {
            return Err(GeometryError::InvalidShape {
                shape: "scene",
                object: 0,
                message: format!(
                    "the BVH over {} primitives is {depth} levels deep (at most 63 supported); the scene is probably degenerate (e.g. millions of coincident primitives)",
                    prims.len()
                ),
            });
        }
        drop(aabbs);

        // Lay primitives out in leaf order so the traversal indexes them directly.
        let order = &bvh.primitive_indices;
        let mut others = Vec::new();
        let tris: Vec<[Vec3; 3]> = order
            .iter()
            .map(|&i| match prims[i as usize] {
                Prim::Triangle(v) => v,
                p => {
                    others.push(p);
                    let marker = Vec3::new(f32::from_bits((others.len() - 1) as u32), 0.0, 0.0);
                    [Vec3::NAN, marker, Vec3::ZERO]
                }
            })
            .collect();
        drop(prims);
        let prim_object: Vec<u32> = order.iter().map(|&i| objects[i as usize]).collect();
        let prim_normals: Vec<[u32; 3]> = if any_normals {
            order.iter().map(|&i| prim_normals[i as usize]).collect()
        } else {
            Vec::new()
        };
        // Traversal only needs the node array once the primitives are in leaf order.
        bvh.primitive_indices = Vec::new();
        bvh.exact_node_aabbs = None;
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
        Ok(SceneGeometry {
            bvh,
            tris,
            others,
            prim_object,
            prim_normals,
            normals,
            object_prims,
            bounds,
        })
    }
}
