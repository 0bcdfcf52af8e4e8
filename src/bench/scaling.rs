//! `candela bench scaling`: the generated mesh scene at several triangle counts (BVH build
//! time, bytes per triangle, peak memory, traversal and render throughput) and a
//! pixels × samples linearity check.

use super::traversal::{bench_camera, generate_batches, trace_batch};
use super::{mesh_scene, subdivisions_for};
use crate::geometry::generate::bumpy_sphere;
use crate::geometry::{SceneGeometry, Shape};
use crate::render::render;
use crate::scene::{self, Overrides};
use anyhow::{Context, Result};
use glam::Vec3;
use std::path::Path;
use std::time::Instant;

/// Options of `candela bench scaling`.
#[derive(clap::Args, Debug, Clone)]
pub struct ScalingArgs {
    /// Triangle counts of the generated mesh scene (comma separated, approximate).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "10000,100000,1000000,5000000"
    )]
    pub triangles: Vec<usize>,
    /// Image size of the renders (RES×RES).
    #[arg(long, default_value_t = 256, value_name = "RES")]
    pub resolution: u32,
    /// Samples per pixel of the renders.
    #[arg(long, default_value_t = 16)]
    pub spp: u32,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Triangles of the scene rendered for the pixels × spp linearity check (0 skips it).
    #[arg(long, default_value_t = 1_000_000)]
    pub linearity_triangles: usize,
}

/// (VmHWM, VmRSS) of this process in bytes, from /proc/self/status (Linux).
pub fn memory_status() -> Option<(u64, u64)> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let kb = |key: &str| -> Option<u64> {
        s.lines()
            .find_map(|l| l.strip_prefix(key))?
            .split_whitespace()
            .next()?
            .parse::<u64>()
            .ok()
            .map(|k| k * 1024)
    };
    Some((kb("VmHWM:")?, kb("VmRSS:")?))
}

/// Resets the peak RSS (VmHWM) to the current RSS (Linux ≥ 4.0); false if not possible.
pub fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

fn mb(bytes: Option<u64>) -> String {
    bytes.map_or("n/a".into(), |b| format!("{:.0}", b as f64 / 1e6))
}

pub fn run(args: &ScalingArgs) -> Result<()> {
    let overrides = Overrides {
        spp: Some(args.spp),
        ..Default::default()
    };
    let threads = match args.threads {
        Some(n) if n > 0 => n,
        _ => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    let peak_resets = reset_peak_rss();
    println!(
        "Scaling: bumpy sphere of N triangles on a floor quad, sky + sun, {r}×{r} × {spp} spp, {threads} threads. \
         BVH build = SceneGeometry::build alone; traversal = closest-hit rays of `bench traversal` at 256² (all threads); \
         peak RSS = VmHWM over scene build + render{}.\n",
        if peak_resets { " (reset before each scene)" } else { " (cannot reset: peak of the whole run so far)" },
        r = args.resolution,
        spp = args.spp,
    );
    println!("| triangles | BVH build s | geometry B/triangle | peak RSS MB | RSS while rendering MB | primary Mrays/s | diffuse Mrays/s | ns/sample | M samples/s | M rays/s | rays/sample |");
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for &n in &args.triangles {
        let mesh = bumpy_sphere(subdivisions_for(n));
        let n_tris = mesh.indices.len();
        // The BVH alone, as the render scene has it (mesh translated + floor quad).
        let mut moved = mesh.clone();
        moved.positions.iter_mut().for_each(|p| p.y += 1.0);
        let shapes = vec![
            (Shape::Mesh(moved), 0u32),
            (
                Shape::Quad {
                    origin: Vec3::new(-10.0, 0.0, -10.0),
                    edge_u: Vec3::new(0.0, 0.0, 20.0),
                    edge_v: Vec3::new(20.0, 0.0, 0.0),
                },
                1,
            ),
        ];
        let t0 = Instant::now();
        let geo = SceneGeometry::build(&shapes).context("building the benchmark BVH")?;
        let build_s = t0.elapsed().as_secs_f64();
        drop(shapes);
        let bytes_per_tri = geo.memory_bytes() as f64 / geo.primitive_count() as f64;
        let batches = generate_batches(&geo, 256);
        let (tp, _) = trace_batch(&geo, &batches[0], threads);
        let (td, _) = trace_batch(&geo, &batches[1], threads);
        let primary = batches[0].rays.len() as f64 / tp.wall / 1e6;
        let diffuse = batches[1].rays.len() as f64 / td.wall / 1e6;
        drop(batches);
        drop(geo);

        reset_peak_rss();
        let scene_file = mesh_scene(mesh, args.spp, args.resolution);
        let world = scene::build(&scene_file, Path::new("<generated>"), &overrides)?;
        drop(scene_file);
        let r = render(&world, args.threads, &|_, _| {})?;
        let mem = memory_status();
        let samples = r.film.total_samples() as f64;
        let secs = r.elapsed.as_secs_f64();
        println!(
            "| {} | {:.3} | {:.1} | {} | {} | {:.2} | {:.2} | {:.0} | {:.3} | {:.3} | {:.2} |",
            n_tris,
            build_s,
            bytes_per_tri,
            mb(mem.map(|m| m.0)),
            mb(mem.map(|m| m.1)),
            primary,
            diffuse,
            secs * 1e9 / samples,
            samples / secs / 1e6,
            r.rays_per_second() / 1e6,
            r.stats.total_rays() as f64 / samples,
        );
        drop(world);
    }

    if args.linearity_triangles > 0 {
        let mesh = bumpy_sphere(subdivisions_for(args.linearity_triangles));
        let n_tris = mesh.indices.len();
        let scene_file = mesh_scene(mesh, args.spp, args.resolution);
        let mut world = scene::build(&scene_file, Path::new("<generated>"), &overrides)?;
        drop(scene_file);
        println!(
            "\nLinearity in pixels × samples ({n_tris} triangles, {threads} threads): ns/sample should stay constant.\n"
        );
        println!("| image | spp | samples | seconds | ns/sample | relative to 256² × 16 |");
        println!("|---|---:|---:|---:|---:|---:|");
        let configs = [(128, 16), (256, 16), (512, 16), (256, 8), (256, 32)];
        let mut base = None;
        let mut rows = Vec::new();
        for (res, spp) in configs {
            world.camera = bench_camera(res as usize, res as usize);
            world.settings.spp = spp;
            let r = render(&world, args.threads, &|_, _| {})?;
            let samples = r.film.total_samples() as f64;
            let ns = r.elapsed.as_secs_f64() * 1e9 / samples;
            if (res, spp) == (256, 16) {
                base = Some(ns);
            }
            rows.push((res, spp, samples, r.elapsed.as_secs_f64(), ns));
        }
        for (res, spp, samples, secs, ns) in rows {
            println!(
                "| {res}×{res} | {spp} | {samples} | {secs:.2} | {ns:.0} | {:.2} |",
                ns / base.unwrap_or(ns)
            );
        }
    }
    Ok(())
}
