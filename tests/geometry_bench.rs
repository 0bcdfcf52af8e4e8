//! BVH benchmark on a ≥ 1 M triangle mesh. Ignored by default; run with
//! `cargo test --release --test geometry_bench -- --ignored --nocapture`
//! (`RAYON_NUM_THREADS` selects the thread count).

#[path = "../src/cli/bench/generate.rs"]
#[allow(dead_code)]
mod generate;
#[path = "../src/cli/bench/rng.rs"]
#[allow(dead_code)]
mod rng;

use generate::{bench_bvh, bumpy_sphere};

#[test]
#[ignore]
fn bvh_benchmark_1m_triangles() {
    let mesh = bumpy_sphere(300); // 12·300² = 1.08 M triangles
    assert!(mesh.indices.len() >= 1_000_000);
    let r = bench_bvh(&mesh, 2_000_000);
    println!("{r}");
    assert!(r.hit_fraction > 0.3);
}

#[test]
fn bvh_benchmark_smoke() {
    let r = bench_bvh(&bumpy_sphere(20), 20_000);
    assert_eq!(r.triangles, 12 * 20 * 20);
    assert!(r.hit_fraction > 0.3 && r.rays_per_second > 0.0);
}
