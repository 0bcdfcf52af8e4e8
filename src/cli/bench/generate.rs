//! Deterministic procedural meshes for the benchmarks and the geometry tests (which include
//! this file with `#[path]`, so it names the library only through `candela::` paths and
//! expects [`Rng`](super::rng::Rng) in a sibling module `rng`).

use super::rng::Rng;
use candela::geometry::{SceneGeometry, Shape, TriangleMesh};
use glam::Vec3;
use rayon::prelude::*;
use std::time::Instant;

/// A regular grid of `nx × ny` cells (2·nx·ny triangles) over [−size/2, size/2]² in the XY
/// plane, displaced along +Z by `height(x, y)`; front faces point toward +Z.
pub fn grid_mesh(nx: u32, ny: u32, size: f32, height: impl Fn(f32, f32) -> f32) -> TriangleMesh {
    let (nx, ny) = (nx.max(1), ny.max(1));
    let mut positions = Vec::with_capacity(((nx + 1) * (ny + 1)) as usize);
    for j in 0..=ny {
        for i in 0..=nx {
            let x = size * (i as f32 / nx as f32 - 0.5);
            let y = size * (j as f32 / ny as f32 - 0.5);
            positions.push(Vec3::new(x, y, height(x, y)));
        }
    }
    let mut indices = Vec::with_capacity((2 * nx * ny) as usize);
    let id = |i: u32, j: u32| j * (nx + 1) + i;
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            indices.push([a, b, c]);
            indices.push([a, c, d]);
        }
    }
    TriangleMesh {
        positions,
        normals: None,
        indices,
    }
}

/// A closed "bumpy" sphere of radius ≈1 (±5 % radial bumps), built from a cube with
/// `subdivisions × subdivisions` cells per face projected to the sphere: `12·subdivisions²`
/// triangles (≥ 1 M for `subdivisions ≥ 289`), outward front faces, no vertex normals.
pub fn bumpy_sphere(subdivisions: u32) -> TriangleMesh {
    cube_sphere(subdivisions, 0.05)
}

/// A closed cube-sphere of radius ≈1 with `12·subdivisions²` triangles and radial bumps of
/// relative amplitude `bump` (0 gives a convex polyhedron inscribed in the unit sphere).
pub fn cube_sphere(subdivisions: u32, bump: f32) -> TriangleMesh {
    let n = subdivisions.max(1);
    let mut positions = Vec::with_capacity(6 * ((n + 1) * (n + 1)) as usize);
    let mut indices = Vec::with_capacity((12 * n * n) as usize);
    // (normal axis, u axis, v axis) with u × v = normal for outward CCW faces.
    let faces = [
        (Vec3::X, Vec3::Y, Vec3::Z),
        (-Vec3::X, Vec3::Z, Vec3::Y),
        (Vec3::Y, Vec3::Z, Vec3::X),
        (-Vec3::Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (-Vec3::Z, Vec3::Y, Vec3::X),
    ];
    for (nrm, u, v) in faces {
        let base = positions.len() as u32;
        for j in 0..=n {
            for i in 0..=n {
                let a = 2.0 * i as f32 / n as f32 - 1.0;
                let b = 2.0 * j as f32 / n as f32 - 1.0;
                let dir = (nrm + a * u + b * v).normalize();
                let r = 1.0
                    + bump * (7.0 * dir.x).sin() * (9.0 * dir.y).sin() * (11.0 * dir.z + 1.0).sin();
                positions.push(dir * r);
            }
        }
        let id = |i: u32, j: u32| base + j * (n + 1) + i;
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                indices.push([a, b, c]);
                indices.push([a, c, d]);
            }
        }
    }
    TriangleMesh {
        positions,
        normals: None,
        indices,
    }
}

/// Result of [`bench_bvh`].
#[derive(Clone, Debug)]
pub struct BvhBench {
    pub triangles: usize,
    pub build_seconds: f64,
    /// Closest-hit rays per second (all rayon threads).
    pub rays_per_second: f64,
    /// Any-hit (shadow) rays per second.
    pub shadow_rays_per_second: f64,
    pub hit_fraction: f64,
    pub memory_bytes: usize,
    pub bytes_per_triangle: f64,
    pub threads: usize,
}

impl std::fmt::Display for BvhBench {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} triangles: BVH build {:.3} s, closest hit {:.2} Mrays/s, shadow {:.2} Mrays/s ({} threads, {:.1} % hit), {:.1} MB ({:.1} B/triangle)",
            self.triangles,
            self.build_seconds,
            self.rays_per_second * 1e-6,
            self.shadow_rays_per_second * 1e-6,
            self.threads,
            self.hit_fraction * 100.0,
            self.memory_bytes as f64 * 1e-6,
            self.bytes_per_triangle
        )
    }
}

/// Builds a [`SceneGeometry`] for `mesh` and traces `rays` incoherent rays (origins on a sphere
/// around the mesh, aimed at random points of its bounding box) with closest-hit and with
/// any-hit queries, in parallel on the current rayon pool. Deterministic ray set.
pub fn bench_bvh(mesh: &TriangleMesh, rays: usize) -> BvhBench {
    let shapes = vec![(Shape::Mesh(mesh.clone()), 0u32)];
    let t0 = Instant::now();
    let geo = SceneGeometry::build(&shapes).expect("benchmark mesh is valid");
    let build_seconds = t0.elapsed().as_secs_f64();
    drop(shapes);
    let (lo, hi) = geo.bounds();
    let c = 0.5 * (lo + hi);
    let radius = 1.5 * (hi - lo).length().max(1e-30);
    let make = |i: usize| {
        let mut rng = Rng::new(i as u64 * 7919 + 1);
        let o = c + radius * rng.unit_vector();
        let target = rng.in_box(lo, hi);
        (o, (target - o).normalize())
    };
    let ray_set: Vec<(Vec3, Vec3)> = (0..rays).into_par_iter().map(make).collect();
    let t1 = Instant::now();
    let hits: usize = ray_set
        .par_chunks(1024)
        .map(|ch| {
            ch.iter()
                .filter(|(o, d)| geo.intersect(*o, *d, f32::INFINITY).is_some())
                .count()
        })
        .sum();
    let closest = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    let occl: usize = ray_set
        .par_chunks(1024)
        .map(|ch| {
            ch.iter()
                .filter(|(o, d)| geo.occluded(*o, *d, f32::INFINITY))
                .count()
        })
        .sum();
    let shadow = t2.elapsed().as_secs_f64();
    assert_eq!(hits, occl, "closest-hit and any-hit disagree");
    let mem = geo.memory_bytes();
    BvhBench {
        triangles: geo.primitive_count(),
        build_seconds,
        rays_per_second: rays as f64 / closest.max(1e-12),
        shadow_rays_per_second: rays as f64 / shadow.max(1e-12),
        hit_fraction: hits as f64 / rays.max(1) as f64,
        memory_bytes: mem,
        bytes_per_triangle: mem as f64 / geo.primitive_count().max(1) as f64,
        threads: rayon::current_num_threads(),
    }
}
