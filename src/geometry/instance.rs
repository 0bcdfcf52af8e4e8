//! Instances: a mesh stored once and placed many times. Each distinct mesh is a bottom-level
//! BVH (a [`SceneGeometry`] of its own, in object space); a top-level BVH over the instances'
//! world bounds (one instance per leaf) leads to them, and rays are carried into an instance's
//! object space (in f64, rounded once) for its bottom level. Ray parameters are the same in
//! both spaces (the direction is transformed, not normalized), so `t` needs no conversion.
//! Hits come back in world space: points through the instance transform with an error bound
//! that covers its rounding, normals through its inverse transpose.
//!
//! Memory: [`Instance`] is 144 bytes and its index 4, plus one top-level node (256 bytes) per
//! about 4–8 instances; the mesh costs what it costs once.

use super::bvh::{build_wide, check_depth, padded_aabb};
use super::prim::{PrimT, RayPre};
use super::robust::gamma;
use super::traverse::{prefetch, traverse, LeafTest};
use super::wide::WideBvh;
use super::{GeometryError, Hit, SceneGeometry, Shape, Transform};
use glam::{Affine3A, DVec3, Vec2, Vec3, Vec3A};

/// [`Hit::instance`] of a hit on a primitive that is not instanced.
pub const NO_INSTANCE: u32 = u32::MAX;

/// A mesh placed at many transforms, as given to [`SceneGeometry::build_instanced`]. Part `k`
/// of instance `j` is scene object `first_object + j·parts.len() + k`.
pub struct InstanceGroup<'a> {
    /// The mesh in object space: triangle meshes (one per material), each with its per-vertex
    /// texture coordinates if it has them.
    pub parts: Vec<(&'a Shape, Option<&'a [Vec2]>)>,
    /// Object-to-world transform of each instance (invertible, finite).
    pub transforms: &'a [Transform],
    pub first_object: u32,
}

/// One placed mesh.
pub(super) struct Instance {
    to_world: Affine3A,
    to_object: Affine3A,
    /// Index into [`InstanceSet::meshes`].
    mesh: u32,
    /// Object id of the mesh's part 0 in this instance.
    object_base: u32,
    /// The instance's index in the caller's order ([`Hit::instance`]).
    index: u32,
    /// The transform mirrors: the mesh's windings are reversed as [`Shape::to_world`] does.
    mirror: bool,
}

/// The instanced part of a scene: the top level and the meshes.
pub(super) struct InstanceSet {
    tlas: WideBvh,
    /// In top-level leaf order.
    insts: Vec<Instance>,
    /// The leaf of each instance, in the caller's order ([`Hit::instance`] → `insts`).
    leaf_of: Vec<u32>,
    meshes: Vec<SceneGeometry>,
    /// Instanced triangles (every instance counted).
    triangles: u64,
    bounds: (Vec3, Vec3),
}

/// `m·p` in f64 (the f32 matrix entries are exact in f64).
#[inline(always)]
fn apply_f64(m: &Affine3A, p: DVec3) -> DVec3 {
    let c = |v: Vec3A| DVec3::new(v.x as f64, v.y as f64, v.z as f64);
    c(m.matrix3.x_axis) * p.x
        + c(m.matrix3.y_axis) * p.y
        + c(m.matrix3.z_axis) * p.z
        + c(m.translation)
}

/// `m·v` (no translation) in f64.
#[inline(always)]
fn apply_vec_f64(m: &Affine3A, v: DVec3) -> DVec3 {
    let c = |v: Vec3A| DVec3::new(v.x as f64, v.y as f64, v.z as f64);
    c(m.matrix3.x_axis) * v.x + c(m.matrix3.y_axis) * v.y + c(m.matrix3.z_axis) * v.z
}

impl Instance {
    /// The ray in object space.
    #[inline(always)]
    fn object_ray(&self, origin: Vec3, dir: Vec3) -> RayPre {
        let o = apply_f64(&self.to_object, origin.as_dvec3()).as_vec3();
        let d = apply_vec_f64(&self.to_object, dir.as_dvec3()).as_vec3();
        RayPre::new(o, d)
    }

    /// A normal in world space: the inverse transpose of the object-to-world transform.
    #[inline]
    fn normal_to_world(&self, n: Vec3) -> Vec3 {
        let m = glam::Mat3::from(self.to_object.matrix3).transpose();
        (m.as_dmat3() * n.as_dvec3()).normalize_or_zero().as_vec3()
    }

    /// The world-space hit on primitive `prim` of `mesh` (this instance's) at the object-space
    /// ray `pre`'s parameter `t`, for the world ray direction `dir`.
    fn world_hit(
        &self,
        mesh: &SceneGeometry,
        prim: u32,
        pre: &RayPre,
        (t, a, b): PrimT,
        dir: Vec3,
    ) -> Hit {
        let h = mesh.make_hit(prim, pre, t, a, b);
        let has_tex = mesh.has_texture_coordinates(prim);
        let mut h = self.hit_to_world(h, dir, has_tex);
        // Vertex normals: each carried to world space, then interpolated, as in a copy (the
        // interpolation does not commute with normalising after a non-uniform scale).
        if let Some(idx) = mesh.prim_normals.get(prim as usize) {
            if idx[0] != u32::MAX {
                let w = |k: usize| self.normal_to_world(mesh.normals[idx[k] as usize]);
                let n = ((1.0 - a - b) * w(0) + a * w(1) + b * w(2)).normalize_or_zero();
                if n != Vec3::ZERO {
                    h.ns = if n.dot(h.ng) < 0.0 { -n } else { n };
                }
            }
        }
        h
    }

    /// The object-space hit `h` of the ray `dir` (world) in world space; `has_tex`: its
    /// texture coordinates are the mesh's (else they are its surface parameters).
    fn hit_to_world(&self, mut h: Hit, dir: Vec3, has_tex: bool) -> Hit {
        let p = apply_f64(&self.to_world, h.p.as_dvec3());
        let pw = p.as_vec3();
        // |M|·error (grown by its own rounding) plus the rounding of M·p in f64 and to f32.
        let l = self.to_world.matrix3;
        let abs_l = [l.x_axis.abs(), l.y_axis.abs(), l.z_axis.abs()];
        let through =
            |v: Vec3| -> Vec3 { Vec3::from(abs_l[0] * v.x + abs_l[1] * v.y + abs_l[2] * v.z) };
        let mag = through(h.p.abs()) + Vec3::from(self.to_world.translation.abs());
        h.error = through(h.error) * (1.0 + gamma(4)) + mag * gamma(4) + pw.abs() * gamma(1);
        h.p = pw;
        h.ng = self.normal_to_world(h.ng);
        let ns = self.normal_to_world(h.ns);
        h.ns = if ns == Vec3::ZERO {
            h.ng
        } else if ns.dot(h.ng) < 0.0 {
            -ns
        } else {
            ns
        };
        if self.mirror {
            // A mirrored copy has its windings reversed: v1 and v2 swap.
            h.uv = Vec2::new(h.uv.y, h.uv.x);
            if !has_tex {
                h.tex = h.uv;
            }
        }
        h.front_face = dir.dot(h.ng) < 0.0;
        h.object += self.object_base;
        h.instance = self.index;
        h
    }
}

impl InstanceSet {
    /// Builds the meshes and the top level; errors name the group's first object.
    pub(super) fn build(groups: &[InstanceGroup]) -> Result<Option<InstanceSet>, GeometryError> {
        let mut meshes = Vec::new();
        let mut insts = Vec::new();
        let mut aabbs = Vec::new();
        let mut triangles = 0u64;
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for g in groups {
            let bad = |message: String| GeometryError::InvalidShape {
                shape: "instances",
                object: g.first_object,
                message,
            };
            if g.transforms.is_empty() {
                return Err(bad("it has no transforms".into()));
            }
            let mut shapes = Vec::with_capacity(g.parts.len());
            let mut uvs = Vec::with_capacity(g.parts.len());
            for (k, (shape, uv)) in g.parts.iter().enumerate() {
                if !matches!(shape, Shape::Mesh(_)) {
                    return Err(bad(format!(
                        "only triangle meshes can be instanced, not a {}",
                        shape.name()
                    )));
                }
                shapes.push(((*shape).clone(), k as u32));
                uvs.push(*uv);
            }
            let mesh = SceneGeometry::build_with_uvs(&shapes, &uvs)?;
            drop(shapes);
            if mesh.tris.is_empty() {
                return Err(bad("its mesh has no triangles of non-zero area".into()));
            }
            let (mlo, mhi) = mesh.bounds;
            let n_parts = g.parts.len() as u64;
            for (j, t) in g.transforms.iter().enumerate() {
                if !t.is_invertible() {
                    return Err(bad(format!(
                        "transform {j} is singular (zero scale on some axis) or not finite: {:?}",
                        t.matrix
                    )));
                }
                let object_base = g.first_object as u64 + j as u64 * n_parts;
                if object_base + n_parts > u32::MAX as u64 {
                    return Err(bad("too many objects (at most 2^32 − 1)".into()));
                }
                // World bounds: the box of the mesh's transformed bounding-box corners.
                let (mut a, mut b) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
                for c in 0..8 {
                    let pick = |bit: u32, l: f32, h: f32| if c & bit == 0 { l } else { h };
                    let corner = DVec3::new(
                        pick(1, mlo.x, mhi.x) as f64,
                        pick(2, mlo.y, mhi.y) as f64,
                        pick(4, mlo.z, mhi.z) as f64,
                    );
                    let w = apply_f64(&t.matrix, corner);
                    a = a.min(w);
                    b = b.max(w);
                }
                let (a, b) = (a.as_vec3(), b.as_vec3());
                let reach = a.abs().max(b.abs()).max_element();
                if reach.is_nan() || reach > super::bvh::MAX_COORDINATE {
                    return Err(bad(format!(
                        "instance {j} extends to {reach:e} m from the origin; geometry must lie within ±{:e} m",
                        super::bvh::MAX_COORDINATE
                    )));
                }
                lo = lo.min(a);
                hi = hi.max(b);
                aabbs.push(padded_aabb(a, b));
                let inv = t.matrix.as_daffine3().inverse();
                insts.push(Instance {
                    to_world: t.matrix,
                    to_object: Affine3A {
                        matrix3: inv.matrix3.as_mat3().into(),
                        translation: inv.translation.as_vec3().into(),
                    },
                    mesh: meshes.len() as u32,
                    object_base: object_base as u32,
                    index: 0,
                    mirror: t.swaps_handedness(),
                });
                triangles += mesh.tris.len() as u64;
            }
            meshes.push(mesh);
        }
        if insts.is_empty() {
            return Ok(None);
        }
        if insts.len() >= u32::MAX as usize {
            return Err(GeometryError::InvalidShape {
                shape: "instances",
                object: 0,
                message: "too many instances (at most 2^32 − 1)".into(),
            });
        }
        let (tlas, order) = build_wide(&aabbs, 1);
        check_depth(&tlas, insts.len())?;
        drop(aabbs);
        for (i, inst) in insts.iter_mut().enumerate() {
            inst.index = i as u32;
        }
        let mut leaf_of = vec![0u32; insts.len()];
        for (leaf, &i) in order.iter().enumerate() {
            leaf_of[i as usize] = leaf as u32;
        }
        let mut by_leaf: Vec<Option<Instance>> = insts.into_iter().map(Some).collect();
        let insts: Vec<Instance> = order
            .iter()
            .map(|&i| {
                by_leaf[i as usize]
                    .take()
                    .expect("each instance is one leaf")
            })
            .collect();
        Ok(Some(InstanceSet {
            tlas,
            insts,
            leaf_of,
            meshes,
            triangles,
            bounds: (lo, hi),
        }))
    }

    pub(super) fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    pub(super) fn instance_count(&self) -> usize {
        self.insts.len()
    }

    pub(super) fn triangle_count(&self) -> u64 {
        self.triangles
    }

    /// Stored triangles (each mesh once).
    pub(super) fn stored_triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.tris.len()).sum()
    }

    pub(super) fn memory_bytes(&self) -> usize {
        self.tlas.memory_bytes()
            + self.insts.capacity() * std::mem::size_of::<Instance>()
            + self.leaf_of.capacity() * std::mem::size_of::<u32>()
            + self
                .meshes
                .iter()
                .map(SceneGeometry::memory_bytes)
                .sum::<usize>()
    }

    pub(super) fn tlas_depth(&self) -> u32 {
        self.tlas.depth()
    }

    /// Closest hit in `(0, t_max)`: (instance in leaf order, object-space ray, primitive, t, a, b).
    pub(super) fn closest(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
    ) -> Option<(u32, RayPre, u32, PrimT)> {
        struct Closest<'a> {
            set: &'a InstanceSet,
            origin: Vec3,
            dir: Vec3,
            best: Option<(u32, RayPre, u32, PrimT)>,
        }
        impl LeafTest for Closest<'_> {
            #[inline(always)]
            fn leaf(&mut self, first: u32, unary: u32, t_max: f32) -> Option<f32> {
                if unary == 0 {
                    return Some(t_max);
                }
                let inst = &self.set.insts[first as usize];
                let pre = inst.object_ray(self.origin, self.dir);
                let mesh = &self.set.meshes[inst.mesh as usize];
                match mesh.closest_dyn(&pre, t_max) {
                    Some((prim, t, a, b)) => {
                        self.best = Some((first, pre, prim, (t, a, b)));
                        Some(t)
                    }
                    None => Some(t_max),
                }
            }
            #[inline(always)]
            fn prefetch(&self, first: u32) {
                prefetch(self.set.insts.as_ptr().wrapping_add(first as usize) as *const u8);
            }
        }
        let mut c = Closest {
            set: self,
            origin,
            dir,
            best: None,
        };
        traverse::<true>(&self.tlas, origin, dir, t_max, &mut c);
        c.best
    }

    /// The world-space hit of [`InstanceSet::closest`]'s result.
    pub(super) fn make_hit(
        &self,
        (leaf, pre, prim, (t, a, b)): (u32, RayPre, u32, PrimT),
        dir: Vec3,
    ) -> Hit {
        let inst = &self.insts[leaf as usize];
        inst.world_hit(&self.meshes[inst.mesh as usize], prim, &pre, (t, a, b), dir)
    }

    /// (dp/du, dp/dv) in world space at `hit` on an instance (see
    /// [`SceneGeometry::texture_derivatives`]): the mesh's object-space derivatives through
    /// the instance's linear part L. Tangent vectors are differences of points, so they map by
    /// L (not by the inverse transpose, as normals do): the result is the derivatives of a
    /// world-space copy of the mesh, orthogonal to the hit's world normal, and a mirroring L
    /// carries the frame's handedness with it.
    pub(super) fn texture_derivatives(&self, hit: &Hit) -> Option<(Vec3, Vec3)> {
        let inst = &self.insts[*self.leaf_of.get(hit.instance as usize)? as usize];
        let mesh = &self.meshes[inst.mesh as usize];
        let (mut du, mut dv) = mesh.triangle_derivatives(hit.prim)?;
        if inst.mirror && !mesh.has_texture_coordinates(hit.prim) {
            // `tex` is the barycentrics of the mirrored winding ([`Instance::hit_to_world`]):
            // (b2, b1) of the object-space triangle.
            std::mem::swap(&mut du, &mut dv);
        }
        let l = glam::Mat3::from(inst.to_world.matrix3);
        let (du, dv) = (l * du, l * dv);
        (du.is_finite() && dv.is_finite()).then_some((du, dv))
    }

    /// True if the instance of a closest hit mirrors.
    pub(super) fn mirrored(&self, (leaf, ..): &(u32, RayPre, u32, PrimT)) -> bool {
        self.insts[*leaf as usize].mirror
    }

    /// The unnormalized world-space front-face normal and the object id of a closest hit.
    pub(super) fn basic(&self, (leaf, _, prim, _): &(u32, RayPre, u32, PrimT)) -> (Vec3, u32) {
        let inst = &self.insts[*leaf as usize];
        let mesh = &self.meshes[inst.mesh as usize];
        let v = &mesh.tris[*prim as usize];
        let n = (v[1] - v[0]).cross(v[2] - v[0]);
        let m = glam::Mat3::from(inst.to_object.matrix3).transpose();
        (m * n, inst.object_base + mesh.prim_object[*prim as usize])
    }

    /// Any-hit query: true if a hit in `(0, t_max)` that `pass` does not let through is found.
    /// `pass(object, hit)` gets the world-space hit of a primitive of `object`.
    pub(super) fn any_hit(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        pass: &mut dyn FnMut(u32, &dyn Fn() -> Hit) -> bool,
    ) -> bool {
        struct AnyHit<'a, 'b> {
            set: &'a InstanceSet,
            origin: Vec3,
            dir: Vec3,
            pass: &'b mut dyn FnMut(u32, &dyn Fn() -> Hit) -> bool,
            hit: bool,
        }
        impl LeafTest for AnyHit<'_, '_> {
            #[inline(always)]
            fn leaf(&mut self, first: u32, unary: u32, t_max: f32) -> Option<f32> {
                if unary == 0 {
                    return Some(t_max);
                }
                let inst = &self.set.insts[first as usize];
                let pre = inst.object_ray(self.origin, self.dir);
                let mesh = &self.set.meshes[inst.mesh as usize];
                let dir = self.dir;
                let pass = &mut *self.pass;
                let f = |prim: u32, pre: &RayPre, (t, a, b): PrimT| {
                    let object = inst.object_base + mesh.prim_object[prim as usize];
                    pass(object, &|| inst.world_hit(mesh, prim, pre, (t, a, b), dir))
                };
                let blocked = match pre.kz {
                    0 => mesh.any_hit::<0>(&pre, t_max, f),
                    1 => mesh.any_hit::<1>(&pre, t_max, f),
                    _ => mesh.any_hit::<2>(&pre, t_max, f),
                };
                if blocked {
                    self.hit = true;
                    return None;
                }
                Some(t_max)
            }
            #[inline(always)]
            fn prefetch(&self, first: u32) {
                prefetch(self.set.insts.as_ptr().wrapping_add(first as usize) as *const u8);
            }
        }
        let mut a = AnyHit {
            set: self,
            origin,
            dir,
            pass,
            hit: false,
        };
        traverse::<false>(&self.tlas, origin, dir, t_max, &mut a);
        a.hit
    }

    /// Brute force closest hit over every triangle of every instance (no BVH at either level).
    pub(super) fn brute_force(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        let mut best: Option<(u32, RayPre, u32, PrimT)> = None;
        let mut tmax = t_max;
        for (leaf, inst) in self.insts.iter().enumerate() {
            let pre = inst.object_ray(origin, dir);
            let mesh = &self.meshes[inst.mesh as usize];
            for i in 0..mesh.tris.len() as u32 {
                if let Some((t, a, b)) = mesh.prim(i).intersect_dyn(&pre, tmax) {
                    tmax = t;
                    best = Some((leaf as u32, pre, i, (t, a, b)));
                }
            }
        }
        best.map(|b| self.make_hit(b, dir))
    }
}

impl SceneGeometry {
    /// [`SceneGeometry::build_with_uvs`] plus instanced meshes: `groups` are stored once per
    /// group and placed at each of their transforms (a two-level BVH). Scenes without groups
    /// are exactly what `build_with_uvs` makes.
    pub fn build_instanced(
        shapes: &[(Shape, u32)],
        uvs: &[Option<&[Vec2]>],
        groups: &[InstanceGroup],
    ) -> Result<SceneGeometry, GeometryError> {
        let mut geo = Self::build_with_uvs(shapes, uvs)?;
        geo.instances = InstanceSet::build(groups)?.map(Box::new);
        if let Some(set) = &geo.instances {
            let (a, b) = set.bounds();
            geo.bounds = if geo.tris.is_empty() {
                (a, b)
            } else {
                (geo.bounds.0.min(a), geo.bounds.1.max(b))
            };
        }
        Ok(geo)
    }

    /// Number of instances (0 without instanced meshes).
    pub fn instance_count(&self) -> usize {
        self.instances.as_ref().map_or(0, |s| s.instance_count())
    }

    /// Triangles the instances place in the scene, every instance counted.
    pub fn instanced_triangle_count(&self) -> u64 {
        self.instances.as_ref().map_or(0, |s| s.triangle_count())
    }

    /// Triangles stored for the instances (each instanced mesh once).
    pub fn instanced_stored_triangle_count(&self) -> usize {
        self.instances
            .as_ref()
            .map_or(0, |s| s.stored_triangle_count())
    }

    /// BVH nodes of the instances: the top level and each instanced mesh's (256 bytes each).
    pub fn instance_node_count(&self) -> usize {
        self.instances.as_ref().map_or(0, |s| {
            s.tlas.nodes.len() + s.meshes.iter().map(|m| m.bvh.nodes.len()).sum::<usize>()
        })
    }

    /// Depth of the top-level BVH over the instances (0 without instances).
    pub fn instance_bvh_depth(&self) -> u32 {
        self.instances.as_ref().map_or(0, |s| s.tlas_depth())
    }
}
