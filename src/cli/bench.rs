//! `candela bench`: throughput on the Cornell box and on a generated mesh of about a million
//! triangles (samples/s and rays/s), plus two sub-benchmarks:
//! * `candela bench traversal` — closest-hit / any-hit rays per second of the BVH on primary,
//!   diffuse-bounce and shadow rays, optionally against Embree (see `bench/embree/README.md`);
//! * `candela bench scaling` — the mesh scene at 10 k … 5 M triangles (build time, bytes per
//!   triangle, peak memory, ns per sample) and a pixels × samples linearity check.
//!
//! Nothing here is asserted by tests (timings depend on the machine).

// Shared with the geometry tests, which use the items the benchmarks do not.
#[allow(dead_code)]
pub mod generate;
pub mod rayfile;
#[allow(dead_code)]
pub mod rng;
pub mod scaling;
pub mod traversal;

use candela::description::schema::*;
use candela::render::render;
use candela::scene::{self, Overrides};
use std::path::Path;
use std::time::Instant;

const CORNELL: &str = include_str!("../../scenes/cornell-box.ron");

/// Image size of the default benchmark's mesh scene.
const MESH_SCENE_RESOLUTION: u32 = 256;

/// Options of `candela bench`.
#[derive(clap::Args, Debug, Clone)]
#[command(args_conflicts_with_subcommands = true)]
pub struct BenchArgs {
    #[command(subcommand)]
    pub mode: Option<BenchMode>,
    /// Worker threads (default: all cores; at most 16 per available core).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Samples per pixel for each benchmark scene.
    #[arg(long, default_value_t = 16)]
    pub spp: u32,
    /// Triangles in the generated mesh scene (approximate).
    #[arg(long, default_value_t = 1_000_000)]
    pub triangles: usize,
}

/// The sub-benchmarks of `candela bench` (without one: Cornell box and the 1 M-triangle scene).
#[derive(clap::Subcommand, Debug, Clone)]
pub enum BenchMode {
    /// BVH closest-hit / any-hit Mrays/s on primary, diffuse-bounce and shadow rays (1 and 2 threads); --export writes mesh + rays for bench/embree, --embree compares against Embree. See bench/embree/README.md.
    Traversal(traversal::TraversalArgs),
    /// The mesh scene at 10 k, 100 k, 1 M and 5 M triangles: BVH build time, bytes/triangle, peak RSS, ns/sample, samples/s, rays/s; plus a pixels × spp linearity check.
    Scaling(scaling::ScalingArgs),
}

pub use candela::job::check_threads;

/// Largest triangle count of a generated benchmark mesh: its peak memory,
/// [`BYTES_PER_TRIANGLE`] a triangle, is then about 21 GiB.
pub const MAX_TRIANGLES: usize = 50_000_000;

/// Peak memory per triangle while a generated benchmark mesh and its BVH are built (the BVH
/// builder's working memory; the finished geometry keeps about 69 bytes a triangle). Measured
/// peak RSS of `bench traversal`: 424–429 bytes a triangle at 1 M and 4 M triangles.
pub const BYTES_PER_TRIANGLE: u64 = 460;

/// Peak memory per primary ray of `bench traversal` (RES² of them): the primary, diffuse and
/// shadow batches while they are generated, or the batches and their bytes while they are
/// exported. Measured peak RSS: 148 bytes a ray at 4096², 1 M triangles.
pub const BYTES_PER_RAY: u64 = 200;

/// Memory of a benchmark beyond its mesh, BVH and rays (measured: about 50 MB).
const BASE_BYTES: u64 = 64 << 20;

/// Refuses a benchmark that would need more than the memory available: `bytes` (its mesh,
/// BVH, rays and images) for `what`, which names the options that asked for it.
pub fn check_memory_for(what: &str, bytes: u64) -> anyhow::Result<()> {
    candela::limits::check_memory(bytes.saturating_add(BASE_BYTES), what)
        .map_err(anyhow::Error::msg)
}

/// Peak memory of generating `triangles` triangles and building their BVH.
pub fn mesh_bytes(triangles: usize) -> u64 {
    (triangles as u64).saturating_mul(BYTES_PER_TRIANGLE)
}

/// What `flag N` asks for, for [`check_memory_for`]'s message.
pub fn mesh_what(flag: &str, triangles: usize) -> String {
    format!(
        "{flag} {triangles} (the generated mesh and its BVH, about {BYTES_PER_TRIANGLE} bytes a triangle)"
    )
}

/// Peak memory of a render of `resolution`² pixels (the film and its pass buffers).
pub fn render_bytes(resolution: u32) -> u64 {
    let per_pixel =
        candela::scene::build::bytes_per_pixel(&candela::scene::RunMode::default(), false);
    (resolution as u64).pow(2) * per_pixel
}

/// Refuses a triangle count (of option `flag`) above [`MAX_TRIANGLES`].
pub fn check_triangles(flag: &str, n: usize) -> anyhow::Result<()> {
    if n > MAX_TRIANGLES {
        return Err(super::usage(format!(
            "{flag} {n} is too many: at most {MAX_TRIANGLES} triangles are generated (building them needs about {BYTES_PER_TRIANGLE} bytes a triangle)"
        )));
    }
    Ok(())
}

/// Largest `--resolution` of the generated benchmarks (`bench traversal` holds RES² rays per
/// batch, [`BYTES_PER_RAY`] a primary ray: about 12.5 GiB at the largest).
pub const MAX_RESOLUTION: u32 = 8192;

/// Refuses a `--resolution` of 0 or above [`MAX_RESOLUTION`].
pub fn check_resolution(res: u32) -> anyhow::Result<()> {
    check_positive("--resolution", res.into())?;
    if res > MAX_RESOLUTION {
        return Err(super::usage(format!(
            "--resolution {res} is too large: at most {MAX_RESOLUTION} ({MAX_RESOLUTION}² primary rays per batch)"
        )));
    }
    Ok(())
}

/// A figure for the benchmark tables with `decimals` decimals, or "n/a" where a run was too
/// short for the clock (0 s or 0 ns, so the figure is 0 or infinite).
pub fn cell(x: f64, decimals: usize) -> String {
    if x.is_finite() && x > 0.0 {
        format!("{x:.decimals$}")
    } else {
        "n/a".into()
    }
}

/// Refuses 0 for a count option (`flag`) that needs at least 1.
pub fn check_positive(flag: &str, n: u64) -> anyhow::Result<()> {
    if n == 0 {
        return Err(super::usage(format!("{flag} must be at least 1, got 0")));
    }
    Ok(())
}

/// Entry point of `candela bench`.
pub fn main(args: &BenchArgs) -> anyhow::Result<()> {
    if args.mode.is_none() {
        if let Some(n) = args.threads {
            check_threads("--threads", n)?;
        }
        check_positive("--spp", args.spp.into())?;
        check_triangles("--triangles", args.triangles)?;
        check_memory_for(
            &mesh_what("--triangles", args.triangles),
            mesh_bytes(args.triangles) + render_bytes(MESH_SCENE_RESOLUTION),
        )?;
    }
    match &args.mode {
        None => run(args.threads, args.spp, args.triangles),
        Some(BenchMode::Traversal(a)) => traversal::run(a),
        Some(BenchMode::Scaling(a)) => scaling::run(a),
    }
}

fn report(name: &str, r: &candela::render::RenderResult) {
    println!(
        "{name:<28} {:>4}×{:<4} {:>4} spp  {:>7.2} s  {:>8.3} M samples/s  {:>8.3} M rays/s  ({} threads)",
        r.film.width,
        r.film.height,
        r.film.total_samples() / (r.film.width * r.film.height) as u64,
        r.elapsed.as_secs_f64(),
        r.samples_per_second() / 1e6,
        r.rays_per_second() / 1e6,
        r.threads
    );
}

/// Cube-sphere subdivisions for about `triangles` triangles (`12·s²`).
/// Median of `v` (the upper one of an even count; NaN if empty). Sorts `v`.
pub fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

pub fn subdivisions_for(triangles: usize) -> u32 {
    ((triangles as f64 / 12.0).sqrt().ceil() as u32).max(1)
}

/// The mesh benchmark scene: `mesh` (the bumpy sphere, lifted by 1 m) on a 20 m floor quad,
/// grey diffuse, under a D65 sky and a D50 sun, seen by [`traversal::bench_camera`]'s view.
pub fn mesh_scene(mesh: candela::geometry::TriangleMesh, spp: u32, resolution: u32) -> SceneFile {
    SceneFile {
        camera: CameraDesc {
            position: Some([0.0, 1.2, -3.2]),
            look_at: Some([0.0, 0.9, 0.0]),
            up: None,
            from_model: None,
            vfov_deg: Some(45.0),
            resolution: (resolution, resolution),
            projection: None,
            lens: None,
        },
        render: RenderDesc {
            spp,
            ..Default::default()
        },
        materials: [(
            "grey".to_string(),
            MaterialDesc::Diffuse {
                reflectance: SpectrumDesc::Constant(0.6),
            },
        )]
        .into_iter()
        .collect(),
        objects: vec![
            ObjectDesc {
                name: Some("mesh".into()),
                shape: ShapeDesc::Triangles {
                    positions: mesh.positions.iter().map(|p| p.to_array()).collect(),
                    indices: mesh.indices,
                    normals: None,
                },
                material: "grey".into(),
                emission: None,
                transform: Some(TransformDesc {
                    translate: Some([0.0, 1.0, 0.0]),
                    rotate_deg: None,
                    scale: None,
                }),
            },
            ObjectDesc {
                name: Some("floor".into()),
                shape: ShapeDesc::Quad {
                    origin: [-10.0, 0.0, -10.0],
                    edge_u: [0.0, 0.0, 20.0],
                    edge_v: [20.0, 0.0, 0.0],
                },
                material: "grey".into(),
                emission: None,
                transform: None,
            },
        ],
        lights: vec![
            LightDesc::Environment {
                spectrum: SpectrumDesc::Named("D65".into()),
                amount: Amount::Luminance(5000.0),
                portals: Vec::new(),
            },
            LightDesc::Distant {
                direction: [0.3, -1.0, 0.5],
                spectrum: SpectrumDesc::Named("D50".into()),
                amount: Amount::Illuminance(50_000.0),
            },
        ],
        meters: Vec::new(),
        grids: Vec::new(),
        measure: MeasureDesc::default(),
        site: Default::default(),
    }
}

/// The default benchmark: the Cornell box, then the mesh scene with about `triangles` triangles.
pub fn run(threads: Option<usize>, spp: u32, triangles: usize) -> anyhow::Result<()> {
    let overrides = Overrides {
        spp: Some(spp),
        ..Default::default()
    };
    let path = Path::new("scenes/cornell-box.ron");
    let world = scene::build(&scene::parse(CORNELL, path)?, path, &overrides)?;
    let r = render(&world, threads, &|_, _| {})?;
    report("cornell-box", &r);

    // A displaced sphere of ~`triangles` triangles on a floor, under a sky and a sun.
    let t0 = Instant::now();
    let mesh = generate::bumpy_sphere(subdivisions_for(triangles));
    let n_tris = mesh.indices.len();
    let scene = mesh_scene(mesh, spp, MESH_SCENE_RESOLUTION);
    let world = scene::build(&scene, Path::new("<generated>"), &overrides)?;
    drop(scene);
    println!(
        "generated mesh: {n_tris} triangles, scene built (incl. BVH) in {:.2} s, geometry ≈ {:.1} bytes/triangle",
        t0.elapsed().as_secs_f64(),
        world.geometry.memory_bytes() as f64 / n_tris as f64
    );
    let r = render(&world, threads, &|_, _| {})?;
    report(&format!("mesh {}k triangles", n_tris / 1000), &r);
    Ok(())
}
