//! BVH benchmark on CAD-shaped and CAD-sized input: build time, depth, node count and memory
//! for 100 000 coincident triangles, a 100 000-triangle fan, 100 000 slivers of aspect 10⁶,
//! 10⁷ random triangles, and 1 000 instances of a 100 000-triangle mesh (with ray throughput
//! of instances against the same triangles written out). A benchmark, not a timed test:
//! `cargo test --release --test bvh_cad_bench -- --ignored --nocapture` (figures in
//! bench/README.md → "CAD-shaped meshes and instances"). `CAD_BENCH_RANDOM=n` changes the
//! random-triangle count.

#[path = "../src/cli/bench/generate.rs"]
#[allow(dead_code)]
mod generate;
#[path = "../src/cli/bench/rng.rs"]
#[allow(dead_code)]
mod rng;

use candela::geometry::{InstanceGroup, SceneGeometry, Shape, Transform, TriangleMesh};
use glam::Vec3;
use rng::Rng;
use std::time::Instant;

/// (VmRSS, VmHWM) of this process in bytes.
fn rss() -> (u64, u64) {
    let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let kb = |key: &str| -> u64 {
        s.lines()
            .find_map(|l| l.strip_prefix(key))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
            .unwrap_or(0)
            * 1024
    };
    (kb("VmRSS:"), kb("VmHWM:"))
}

unsafe extern "C" {
    /// glibc: returns freed heap memory to the system, so that RSS counts live data.
    fn malloc_trim(pad: usize) -> i32;
}

/// Returns freed heap memory to the system (RSS then counts what is live).
fn trim() {
    // SAFETY: malloc_trim only releases free memory of glibc's heap.
    unsafe {
        malloc_trim(0);
    }
}

/// Resets VmHWM to the current RSS.
fn reset_peak() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

fn soup(tris: impl Iterator<Item = [Vec3; 3]>) -> TriangleMesh {
    let mut m = TriangleMesh::default();
    for t in tris {
        let b = m.positions.len() as u32;
        m.positions.extend(t);
        m.indices.push([b, b + 1, b + 2]);
    }
    m
}

fn coincident(n: usize) -> TriangleMesh {
    soup((0..n).map(|_| [Vec3::ZERO, Vec3::X, Vec3::Y]))
}

fn fan(n: usize) -> TriangleMesh {
    let mut positions = vec![Vec3::ZERO];
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        positions.push(Vec3::new(a.cos() as f32, a.sin() as f32, 0.0));
    }
    let n = n as u32;
    TriangleMesh {
        positions,
        normals: None,
        indices: (0..n).map(|k| [0, 1 + k, 1 + (k + 1) % n]).collect(),
    }
}

/// Slivers 1 m long and 1 µm wide (aspect 10⁶), at random positions and orientations in a
/// 10 m box.
fn slivers(n: usize, rng: &mut Rng) -> TriangleMesh {
    soup((0..n).map(|_| {
        let a = rng.in_box(Vec3::splat(-5.0), Vec3::splat(5.0));
        let u = rng.unit_vector();
        let w = u.any_orthonormal_vector() * 1e-6;
        [a, a + u, a + 0.5 * u + w]
    }))
}

/// Random triangles of edge up to 1 % of a 100 m box (a building's clutter).
fn random_tris(n: usize, rng: &mut Rng) -> TriangleMesh {
    soup((0..n).map(|_| {
        let a = rng.in_box(Vec3::splat(-50.0), Vec3::splat(50.0));
        [a, a + rng.unit_vector(), a + rng.unit_vector()]
    }))
}

struct Built {
    geo: SceneGeometry,
    seconds: f64,
    peak_bytes: u64,
    kept_bytes: u64,
}

fn build(shapes: &[(Shape, u32)], groups: &[InstanceGroup]) -> Built {
    trim();
    let before = rss().0;
    reset_peak();
    let t = Instant::now();
    let geo = SceneGeometry::build_instanced(shapes, &[], groups).expect("valid geometry");
    let seconds = t.elapsed().as_secs_f64();
    let peak = rss().1;
    trim();
    let now = rss().0;
    Built {
        geo,
        seconds,
        peak_bytes: peak.saturating_sub(before),
        kept_bytes: now.saturating_sub(before),
    }
}

fn report(what: &str, triangles: u64, b: &Built) {
    let g = &b.geo;
    println!(
        "| {what} | {triangles} | {:.3} s | {} | {} | {:.1} | {:.1} | {:.0} |",
        b.seconds,
        g.bvh_depth().max(g.instance_bvh_depth()),
        g.node_count() + g.instance_node_count(),
        g.memory_bytes() as f64 / triangles as f64,
        b.kept_bytes as f64 / triangles as f64,
        b.peak_bytes as f64 / 1e6,
    );
}

/// Rays per second (one thread) of closest-hit queries from random points around `center`
/// towards random points inside radius `r`.
fn rays_per_second(g: &SceneGeometry, center: Vec3, r: f32, n: usize) -> (f64, f64) {
    let mut rng = Rng::new(3);
    let rays: Vec<(Vec3, Vec3)> = (0..n)
        .map(|_| {
            let o = center + rng.unit_vector() * 1.5 * r;
            let t = center + rng.unit_vector() * r * rng.f32();
            (o, t - o)
        })
        .collect();
    let t = Instant::now();
    let hits = rays
        .iter()
        .filter(|(o, d)| g.intersect(*o, *d, f32::INFINITY).is_some())
        .count();
    (n as f64 / t.elapsed().as_secs_f64(), hits as f64 / n as f64)
}

#[test]
#[ignore]
fn cad_meshes_and_instances() {
    let mut rng = Rng::new(5);
    println!("| input | triangles | build | depth | nodes | geometry B/tri | RSS kept B/tri | build peak MB |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    // 1 000 instances of a 100 000-triangle mesh on a 10 × 10 × 10 grid, each turned and
    // stretched its own way.
    let mesh = Shape::Mesh(generate::bumpy_sphere(92));
    let tris = match &mesh {
        Shape::Mesh(m) => m.indices.len() as u64,
        _ => unreachable!(),
    };
    let transforms: Vec<Transform> = (0..1000)
        .map(|k| {
            Transform::from_trs(
                Vec3::new((k % 10) as f32, ((k / 10) % 10) as f32, (k / 100) as f32) * 3.0,
                rng.unit_vector() * 180.0,
                Vec3::new(1.0, 0.8 + 0.4 * rng.f32(), 1.0),
            )
        })
        .collect();
    let group = |n: usize| {
        [InstanceGroup {
            parts: vec![(&mesh, None)],
            transforms: &transforms[..n],
            first_object: 0,
        }]
    };
    let single = build(&[], &group(1));
    report("1 instance", tris, &single);
    let many = build(&[], &group(1000));
    report("1 000 instances", 1000 * tris, &many);
    let per_instance = (many.geo.memory_bytes() - single.geo.memory_bytes()) as f64 / 999.0;
    let rss_per_instance = many.kept_bytes.saturating_sub(single.kept_bytes) as f64 / 999.0;
    println!(
        "instances: {:.0} B per instance (geometry), {:.0} B per instance (RSS), mesh {:.1} MB once",
        per_instance,
        rss_per_instance,
        single.geo.memory_bytes() as f64 / 1e6
    );
    drop(many);
    drop(single);

    let one = |m: TriangleMesh| vec![(Shape::Mesh(m), 0u32)];
    for (what, mesh) in [
        ("coincident", coincident(100_000)),
        ("fan", fan(100_000)),
        ("slivers 10⁶:1", slivers(100_000, &mut rng)),
        ("bumpy sphere", generate::bumpy_sphere(92)),
    ] {
        let n = mesh.indices.len() as u64;
        let b = build(&one(mesh), &[]);
        report(what, n, &b);
    }
    // Throughput: 27 instances against the same triangles written out (2.7 M triangles).
    let centre = Vec3::splat(3.0);
    let inst = build(&[], &group(27));
    let copies: Vec<(Shape, u32)> = transforms[..27]
        .iter()
        .map(|t| (mesh.to_world(t).unwrap(), 0))
        .collect();
    let flat = build(&copies, &[]);
    drop(copies);
    report("27 instances", 27 * tris, &inst);
    report("27 copies", 27 * tris, &flat);
    let (ri, hi) = rays_per_second(&inst.geo, centre, 6.0, 400_000);
    let (rf, hf) = rays_per_second(&flat.geo, centre, 6.0, 400_000);
    println!(
        "27 × {tris}: instances {:.3} M rays/s, copies {:.3} M rays/s (ratio {:.2}); hit fractions {hi:.3} / {hf:.3}",
        ri * 1e-6,
        rf * 1e-6,
        ri / rf
    );
    assert!((hi - hf).abs() < 1e-3);

    let n_random: usize = std::env::var("CAD_BENCH_RANDOM")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(10_000_000);
    {
        let mesh = random_tris(n_random, &mut rng);
        let b = build(&one(mesh), &[]);
        report("random", n_random as u64, &b);
    }
}
