//! `candela bench scaling`: the generated mesh scene at several triangle counts (BVH build
//! time, bytes per triangle, peak memory, traversal and render throughput) and a
//! pixels × samples linearity check.

use super::generate::bumpy_sphere;
use super::rayfile::RayBatch;
use super::traversal::{bench_camera, generate_batches, trace_batch};
use super::{median, mesh_scene, subdivisions_for};
use anyhow::{Context, Result};
use candela::geometry::{SceneGeometry, Shape};
use candela::render::render;
use candela::scene::{self, Overrides};
use candela::world::World;
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
    /// Worker threads (default: all cores; at most 16 per available core).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Repetitions of every render and traversal timing (medians are reported).
    #[arg(long, default_value_t = 3)]
    pub reps: usize,
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

/// CPU time of the whole process (all threads, user + system) in seconds, from /proc/self/stat
/// (Linux; 10 ms resolution), if known.
pub fn process_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    let rest = &s[s.rfind(')')? + 1..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    // Fields 14 and 15 of proc(5) (utime, stime) in clock ticks of 1/100 s (USER_HZ).
    let ticks = f.get(11)?.parse::<u64>().ok()? + f.get(12)?.parse::<u64>().ok()?;
    Some(ticks as f64 / 100.0)
}

/// One render's cost: wall and CPU nanoseconds per sample, rays per sample, samples.
#[derive(Clone, Copy)]
struct RenderCost {
    wall_ns: f64,
    cpu_ns: f64,
    samples: f64,
    rays_per_sample: f64,
}

/// Renders `world` `reps` times; the medians of the costs.
fn render_cost(world: &World, threads: Option<usize>, reps: usize) -> Result<RenderCost> {
    let (mut wall, mut cpu) = (Vec::new(), Vec::new());
    let mut last = None;
    for _ in 0..reps.max(1) {
        let c0 = process_cpu_seconds();
        let r = render(world, threads, &|_, _| {})?;
        let c1 = process_cpu_seconds();
        let samples = r.film.total_samples() as f64;
        wall.push(r.elapsed.as_secs_f64() * 1e9 / samples);
        cpu.push(match (c0, c1) {
            (Some(a), Some(b)) => (b - a) * 1e9 / samples,
            _ => f64::NAN,
        });
        last = Some((samples, r.stats.total_rays() as f64 / samples));
    }
    let (samples, rays_per_sample) = last.expect("at least one render");
    Ok(RenderCost {
        wall_ns: median(&mut wall),
        cpu_ns: median(&mut cpu),
        samples,
        rays_per_sample,
    })
}

/// Median Mrays per CPU-second of `batch` over `reps` runs on `threads` threads.
fn traversal_rate(geo: &SceneGeometry, batch: &RayBatch, threads: usize, reps: usize) -> f64 {
    median(
        &mut (0..reps.max(1))
            .map(|_| batch.rays.len() as f64 / trace_batch(geo, batch, threads).0.cpu / 1e6)
            .collect::<Vec<_>>(),
    )
}

pub fn run(args: &ScalingArgs) -> Result<()> {
    if let Some(n) = args.threads {
        super::check_threads("--threads", n)?;
    }
    for &n in &args.triangles {
        super::check_triangles("--triangles", n)?;
    }
    super::check_triangles("--linearity-triangles", args.linearity_triangles)?;
    super::check_positive("--spp", args.spp.into())?;
    super::check_resolution(args.resolution)?;
    super::check_positive("--reps", args.reps as u64)?;
    // The sizes run one at a time: the largest decides, with the traversal rays at 512² and
    // the render's film (the linearity check renders up to 512² too).
    let largest = args.triangles.iter().copied().max().unwrap_or(0);
    let images = super::render_bytes(args.resolution.max(512)) + 512 * 512 * super::BYTES_PER_RAY;
    for (flag, n) in [
        ("--triangles", largest),
        ("--linearity-triangles", args.linearity_triangles),
    ] {
        super::check_memory_for(
            &format!(
                "{} with --resolution {} (its renders and 512² traversal rays)",
                super::mesh_what(flag, n),
                args.resolution
            ),
            super::mesh_bytes(n) + images,
        )?;
    }
    let overrides = Overrides {
        spp: Some(args.spp),
        ..Default::default()
    };
    let threads = match args.threads {
        Some(n) if n > 0 => n,
        _ => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    let reps = args.reps.max(1);
    let peak_resets = reset_peak_rss();
    println!(
        "Scaling: bumpy sphere of N triangles on a floor quad, sky + sun, {r}×{r} × {spp} spp, {threads} threads, medians of {reps} runs.\n\
         * BVH build: SceneGeometry::build alone. Peak RSS: VmHWM over scene build and render{}.\n\
         * Traversal: the primary / diffuse closest-hit rays of `bench traversal` at 512², in Mrays per CPU-second (robust to other processes).\n\
         * ns/sample: wall-clock time ÷ samples; CPU ns/sample: CPU time of all threads ÷ samples, i.e. core-nanoseconds per sample (robust to other processes).\n",
        if peak_resets { " (reset before each scene)" } else { " (cannot reset: peak of the whole run so far)" },
        r = args.resolution,
        spp = args.spp,
    );
    println!("| triangles | BVH build s | geometry B/triangle | peak RSS MB | RSS while rendering MB | primary Mrays/CPU-s | diffuse Mrays/CPU-s | ns/sample | CPU ns/sample | M samples/s | M rays/s | rays/sample |");
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
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
        let batches = generate_batches(&geo, 512);
        let primary = traversal_rate(&geo, &batches[0], threads, reps);
        let diffuse = traversal_rate(&geo, &batches[1], threads, reps);
        drop(batches);
        drop(geo);

        reset_peak_rss();
        let scene_file = mesh_scene(mesh, args.spp, args.resolution);
        let world = scene::build(&scene_file, Path::new("<generated>"), &overrides)?;
        drop(scene_file);
        let c = render_cost(&world, args.threads, reps)?;
        let mem = memory_status();
        println!(
            "| {} | {:.3} | {:.1} | {} | {} | {} | {} | {:.0} | {} | {:.3} | {:.3} | {:.2} |",
            n_tris,
            build_s,
            bytes_per_tri,
            mb(mem.map(|m| m.0)),
            mb(mem.map(|m| m.1)),
            super::cell(primary, 2),
            super::cell(diffuse, 2),
            c.wall_ns,
            super::cell(c.cpu_ns, 0),
            1e3 / c.wall_ns,
            1e3 / c.wall_ns * c.rays_per_sample,
            c.rays_per_sample,
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
            "\nLinearity in pixels × samples ({n_tris} triangles, {threads} threads, medians of {reps} runs after a warm-up render): ns/sample should stay constant.\n"
        );
        println!("| image | spp | samples | ns/sample | CPU ns/sample | CPU ns/sample relative to 256² × 16 |");
        println!("|---|---:|---:|---:|---:|---:|");
        world.camera = bench_camera(64, 64);
        world.settings.spp = 16;
        render(&world, args.threads, &|_, _| {})?; // warm-up: threads, page faults, caches
        let configs = [(128u32, 16u32), (256, 16), (512, 16), (256, 8), (256, 32)];
        let mut rows = Vec::new();
        for (res, spp) in configs {
            world.camera = bench_camera(res as usize, res as usize);
            world.settings.spp = spp;
            rows.push((res, spp, render_cost(&world, args.threads, reps)?));
        }
        let base = rows
            .iter()
            .find(|r| (r.0, r.1) == (256, 16))
            .map_or(f64::NAN, |r| r.2.cpu_ns);
        for (res, spp, c) in rows {
            println!(
                "| {res}×{res} | {spp} | {} | {:.0} | {} | {} |",
                c.samples,
                c.wall_ns,
                super::cell(c.cpu_ns, 0),
                super::cell(c.cpu_ns / base, 2)
            );
        }
    }
    Ok(())
}
