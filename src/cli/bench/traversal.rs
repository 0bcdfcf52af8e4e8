//! `candela bench traversal`: closest-hit and any-hit throughput of [`SceneGeometry`] on the
//! kinds of rays a path tracer shoots, optionally side by side with Embree (the
//! `bench/embree/embree_trace` program, fed the same mesh and rays through a ray file).

use super::generate::bumpy_sphere;
use super::median;
use super::rayfile::{read_hits, BenchRay, RayBatch, RayFile, RayKind};
use super::rng::Rng;
use anyhow::{bail, Context, Result};
use candela::camera::Camera;
use candela::geometry::{shadow_ray_between, SceneGeometry, Shape, TriangleMesh};
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

mod tables;
use tables::{print_agreement, print_bvh_table, print_full_hit_throughput, print_throughput};

/// Options of `candela bench traversal`.
#[derive(clap::Args, Debug, Clone)]
pub struct TraversalArgs {
    /// Triangles of the generated mesh (a bumpy sphere on a two-triangle floor), approximate.
    #[arg(long, default_value_t = 1_000_000)]
    pub triangles: usize,
    /// Primary rays: one jittered pinhole-camera ray per pixel of a RES×RES image. The diffuse
    /// bounce and shadow batches start where those rays hit.
    #[arg(long, default_value_t = 1024, value_name = "RES")]
    pub resolution: u32,
    /// Write the generated mesh and rays to this ray file (for bench/embree/embree_trace) and exit.
    #[arg(long, value_name = "FILE", conflicts_with = "rays")]
    pub export: Option<PathBuf>,
    /// Trace the mesh and rays of this ray file (from --export) instead of generating them.
    #[arg(long, value_name = "FILE")]
    pub rays: Option<PathBuf>,
    /// Also time Embree: the embree_trace program built by bench/embree/build.sh. Needs --rays.
    #[arg(long, value_name = "PROGRAM", requires = "rays")]
    pub embree: Option<PathBuf>,
    /// Embree configurations to compare against: a build quality (low, medium, high),
    /// optionally with `-robust` (e.g. `medium-robust`: RTC_SCENE_FLAG_ROBUST, Embree's
    /// watertight mode, the guarantee candela's kernel always gives).
    #[arg(long, value_delimiter = ',', default_value = "medium,high")]
    pub embree_quality: Vec<String>,
    /// Thread counts to time (comma separated; each 1 to 16 per available core).
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    pub threads: Vec<usize>,
    /// Timing repetitions; candela and Embree alternate and the medians are reported.
    #[arg(long, default_value_t = 5)]
    pub reps: usize,
    /// Write candela's hit distances to this hit file (the format of embree_trace --hits).
    #[arg(long, value_name = "FILE")]
    pub hits_out: Option<PathBuf>,
    /// BVH builds to time (median reported), for candela and Embree alike.
    #[arg(long, default_value_t = 3)]
    pub build_reps: usize,
    /// What candela's closest-hit rays compute: `basic` (`SceneGeometry::intersect_basic`: t,
    /// u, v, unnormalized Ng, primitive and object id, as Embree's rtcIntersect1), `full`
    /// (`SceneGeometry::intersect`: the renderer's full `Hit`) or `both` (basic in the main
    /// tables, full in an extra table).
    #[arg(long, value_enum, default_value_t = Record::Both)]
    pub record: Record,
}

/// What candela computes per closest-hit ray (see [`TraversalArgs::record`]).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Record {
    Basic,
    Full,
    Both,
}

/// Rays are handed to threads in chunks of this many (embree_trace uses the same).
const CHUNK: usize = 1024;

/// The benchmark mesh: a bumpy sphere of about `triangles` triangles (radius ≈ 1, centred at
/// y = 1) on a 20 m × 20 m floor made of two triangles at y = 0. One mesh, front faces out / up.
pub fn bench_mesh(triangles: usize) -> TriangleMesh {
    let subdivisions = ((triangles as f64 / 12.0).sqrt().ceil() as u32).max(1);
    let mut mesh = bumpy_sphere(subdivisions);
    for p in &mut mesh.positions {
        p.y += 1.0;
    }
    let base = mesh.positions.len() as u32;
    mesh.positions.extend([
        Vec3::new(-10.0, 0.0, -10.0),
        Vec3::new(-10.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, -10.0),
    ]);
    mesh.indices
        .extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    mesh
}

/// The benchmark camera (the same view as the `candela bench` mesh scene).
pub fn bench_camera(width: usize, height: usize) -> Camera {
    Camera::new(
        Vec3::new(0.0, 1.2, -3.2),
        Vec3::new(0.0, 0.9, 0.0),
        Vec3::Y,
        45.0,
        (width, height),
        None,
    )
}

/// The area light the shadow rays aim at: a 3 m × 2 m rectangle 3.5 m above the floor, in
/// front of and above the sphere (corner, edge, edge).
const LIGHT: (Vec3, Vec3, Vec3) = (
    Vec3::new(-1.5, 3.5, -2.5),
    Vec3::new(3.0, 0.0, 0.0),
    Vec3::new(0.0, 0.0, 2.0),
);

fn cosine_direction(n: Vec3, u: Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let phi = std::f32::consts::TAU * u.y;
    let (t, b) = n.any_orthonormal_pair();
    let z = (1.0 - u.x).max(0.0).sqrt();
    (r * phi.cos() * t + r * phi.sin() * b + z * n).normalize()
}

/// The three batches of a path tracer's first bounce, in pixel order: `primary` (one jittered
/// camera ray per pixel), `diffuse` (from each primary hit, a cosine-distributed direction about
/// the normal facing the camera; origins offset with [`candela::geometry::offset_ray_origin`]) and
/// `shadow` (from each primary hit toward a uniformly chosen point of [`LIGHT`], only where the
/// light is above the surface, as next-event estimation would; `t_max` stops short of the
/// light). Deterministic.
pub fn generate_batches(geo: &SceneGeometry, resolution: u32) -> Vec<RayBatch> {
    let res = resolution.max(1) as usize;
    let cam = bench_camera(res, res);
    let primary: Vec<BenchRay> = (0..res * res)
        .into_par_iter()
        .map(|i| {
            let mut rng = Rng::new(i as u64);
            let (x, y) = ((i % res) as f32, (i / res) as f32);
            let r = cam.generate_ray(x + rng.f32(), y + rng.f32(), Vec2::ZERO);
            BenchRay {
                origin: r.origin,
                tnear: 0.0,
                dir: r.dir,
                tfar: f32::INFINITY,
            }
        })
        .collect();
    let secondary: Vec<(Option<BenchRay>, Option<BenchRay>)> = primary
        .par_iter()
        .enumerate()
        .map(|(i, r)| {
            let Some(hit) = geo.intersect(r.origin, r.dir, r.tfar) else {
                return (None, None);
            };
            let mut rng = Rng::new(0x5EED_0000_0000 + i as u64);
            let n = if hit.front_face { hit.ng } else { -hit.ng };
            let wi = cosine_direction(n, rng.vec2());
            let diffuse = BenchRay {
                origin: hit.spawn_origin(wi),
                tnear: 0.0,
                dir: wi,
                tfar: f32::INFINITY,
            };
            let (c, eu, ev) = LIGHT;
            let target = c + rng.f32() * eu + rng.f32() * ev;
            let shadow = ((target - hit.p).dot(n) > 0.0).then(|| {
                let (o, d, t) =
                    shadow_ray_between(hit.p, hit.error, hit.ng, target, Vec3::ZERO, Vec3::ZERO);
                BenchRay {
                    origin: o,
                    tnear: 0.0,
                    dir: d,
                    tfar: t,
                }
            });
            (Some(diffuse), shadow)
        })
        .collect();
    let diffuse = secondary.iter().filter_map(|s| s.0).collect();
    let shadow = secondary.iter().filter_map(|s| s.1).collect();
    vec![
        RayBatch {
            name: "primary".into(),
            kind: RayKind::Closest,
            rays: primary,
        },
        RayBatch {
            name: "diffuse".into(),
            kind: RayKind::Closest,
            rays: diffuse,
        },
        RayBatch {
            name: "shadow".into(),
            kind: RayKind::Occluded,
            rays: shadow,
        },
    ]
}

/// Builds the BVH over `mesh` (one object). Returns it and the build time in seconds.
pub fn build_geometry(mesh: &TriangleMesh) -> Result<(SceneGeometry, f64)> {
    let shapes = [(Shape::Mesh(mesh.clone()), 0u32)];
    let t0 = Instant::now();
    let geo = SceneGeometry::build(&shapes).context("building the benchmark BVH")?;
    Ok((geo, t0.elapsed().as_secs_f64()))
}

/// CPU time this thread has run, in seconds (Linux: /proc/thread-self/schedstat), if known.
fn thread_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    Some(s.split_whitespace().next()?.parse::<u64>().ok()? as f64 * 1e-9)
}

/// Timing of one batch.
#[derive(Clone, Copy, Debug)]
pub struct Timing {
    /// Wall-clock seconds.
    pub wall: f64,
    /// CPU seconds of the tracing threads, summed (NaN if unknown); unlike the wall time it does
    /// not grow when other processes take the cores.
    pub cpu: f64,
}

/// [`trace_batch_record`] with the full `Hit` (what the renderer computes).
pub fn trace_batch(geo: &SceneGeometry, batch: &RayBatch, threads: usize) -> (Timing, Vec<f32>) {
    trace_batch_record(geo, batch, threads, true)
}

/// Traces `batch` on `threads` threads that take chunks of [`CHUNK`] consecutive rays from a
/// shared counter (as embree_trace does). Closest-hit rays build the full `Hit` with `full`,
/// else only what Embree's rtcIntersect1 returns ([`SceneGeometry::intersect_basic`]). Returns
/// the timing and, per ray, the hit `t` (+∞ for a miss; for any-hit rays 0 when occluded, +∞
/// when not).
pub fn trace_batch_record(
    geo: &SceneGeometry,
    batch: &RayBatch,
    threads: usize,
    full: bool,
) -> (Timing, Vec<f32>) {
    let mut out = vec![f32::NAN; batch.rays.len()];
    let chunks: Vec<Mutex<(&[BenchRay], &mut [f32])>> = batch
        .rays
        .chunks(CHUNK)
        .zip(out.chunks_mut(CHUNK))
        .map(Mutex::new)
        .collect();
    let next = AtomicUsize::new(0);
    let t0 = Instant::now();
    let cpu: f64 = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads.max(1))
            .map(|_| {
                scope.spawn(|| {
                    let c0 = thread_cpu_seconds();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(chunk) = chunks.get(i) else { break };
                        let mut guard = chunk.lock().unwrap_or_else(|e| e.into_inner());
                        let (rays, ts) = &mut *guard;
                        match batch.kind {
                            RayKind::Closest if full => {
                                for (r, t) in rays.iter().zip(ts.iter_mut()) {
                                    *t = geo
                                        .intersect(r.origin, r.dir, r.tfar)
                                        .map_or(f32::INFINITY, |h| h.t);
                                }
                            }
                            RayKind::Closest => {
                                for (r, t) in rays.iter().zip(ts.iter_mut()) {
                                    *t = geo
                                        .intersect_basic(r.origin, r.dir, r.tfar)
                                        .map_or(f32::INFINITY, |h| h.t);
                                }
                            }
                            RayKind::Occluded => {
                                for (r, t) in rays.iter().zip(ts.iter_mut()) {
                                    *t = if geo.occluded(r.origin, r.dir, r.tfar) {
                                        0.0
                                    } else {
                                        f32::INFINITY
                                    };
                                }
                            }
                        }
                    }
                    match (c0, thread_cpu_seconds()) {
                        (Some(a), Some(b)) => b - a,
                        _ => f64::NAN,
                    }
                })
            })
            .collect();
        workers
            .into_iter()
            .map(|w| w.join().unwrap_or(f64::NAN))
            .sum()
    });
    let wall = t0.elapsed().as_secs_f64();
    drop(chunks);
    (Timing { wall, cpu }, out)
}

/// A running `embree_trace --serve` process.
struct Embree {
    quality: String,
    child: Child,
    stdin: ChildStdin,
    stdout: BufReader<ChildStdout>,
    build_seconds: f64,
    bytes_total: f64,
    bytes_buffers: f64,
    version: String,
}

fn fields(line: &str) -> BTreeMap<&str, &str> {
    line.split_whitespace()
        .filter_map(|w| w.split_once('='))
        .collect()
}

fn field<T: std::str::FromStr>(line: &str, key: &str) -> Result<T> {
    fields(line)
        .get(key)
        .and_then(|v| v.parse().ok())
        .with_context(|| format!("embree_trace printed {line:?}, without a valid {key}="))
}

impl Embree {
    fn spawn(program: &Path, rays: &Path, quality: &str, build_reps: usize) -> Result<Embree> {
        let (build_quality, robust) = match quality.strip_suffix("-robust") {
            Some(q) => (q, true),
            None => (quality, false),
        };
        let mut child = Command::new(program)
            .arg(rays)
            .args(["--quality", build_quality])
            .args(robust.then_some("--robust"))
            .arg("--build-reps")
            .arg(build_reps.max(1).to_string())
            .arg("--serve")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .with_context(|| {
                format!(
                    "cannot run '{}' (build it with `bash bench/embree/build.sh`)",
                    program.display()
                )
            })?;
        let stdin = child.stdin.take().context("embree_trace stdin")?;
        let stdout = BufReader::new(child.stdout.take().context("embree_trace stdout")?);
        let mut e = Embree {
            quality: quality.to_string(),
            child,
            stdin,
            stdout,
            build_seconds: 0.0,
            bytes_total: 0.0,
            bytes_buffers: 0.0,
            version: String::new(),
        };
        let v = e.expect_line("embree")?;
        e.version = field::<u64>(&v, "version")
            .map(|n| format!("{}.{}.{}", n / 10000, n / 100 % 100, n % 100))
            .unwrap_or_else(|_| "?".into());
        let b = e.expect_line("build")?;
        e.build_seconds = field(&b, "seconds")?;
        e.bytes_total = field(&b, "bytes_total")?;
        e.bytes_buffers = field(&b, "bytes_buffers")?;
        Ok(e)
    }

    fn expect_line(&mut self, keyword: &str) -> Result<String> {
        let mut line = String::new();
        let n = self.stdout.read_line(&mut line)?;
        if n == 0 {
            let status = self.child.wait()?;
            bail!("embree_trace (quality {}) stopped ({status}) before answering; see its error above", self.quality);
        }
        if !line.starts_with(keyword) {
            bail!("embree_trace printed {line:?}; expected a line starting with '{keyword}'");
        }
        Ok(line.trim_end().to_string())
    }

    fn command(&mut self, cmd: &str, answer: &str) -> Result<String> {
        writeln!(self.stdin, "{cmd}")
            .and_then(|_| self.stdin.flush())
            .with_context(|| format!("embree_trace (quality {}) is not running", self.quality))?;
        self.expect_line(answer)
    }

    fn trace(&mut self, batch: &str, threads: usize) -> Result<Timing> {
        let line = self.command(&format!("trace {batch} {threads}"), "trace")?;
        Ok(Timing {
            wall: field(&line, "seconds")?,
            cpu: field(&line, "cpu_seconds").unwrap_or(f64::NAN),
        })
    }

    fn hits(&mut self, path: &Path) -> Result<Vec<Vec<f32>>> {
        let p = path.to_str().context("the hit file path is not UTF-8")?;
        if p.contains(char::is_whitespace) {
            bail!("the hit file path {p:?} must not contain spaces");
        }
        self.command(&format!("hits {p}"), "hits")?;
        read_hits(path)
    }
}

impl Drop for Embree {
    fn drop(&mut self) {
        let _ = writeln!(self.stdin, "quit").and_then(|_| self.stdin.flush());
        let _ = self.child.wait();
    }
}

/// Hit/miss agreement of two `t` arrays of one batch.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Agreement {
    pub rays: usize,
    /// Both hit or both missed (for any-hit rays: both occluded or both not).
    pub agree: usize,
    /// Only the first (candela) reports a hit.
    pub only_a: usize,
    /// Only the second (Embree) reports a hit.
    pub only_b: usize,
    /// Both hit, but |Δt| > 10⁻⁴·max(t, 1) (a different surface).
    pub t_differs: usize,
    /// Largest |Δt| / max(t, 1) among rays that both hit.
    pub max_rel_dt: f64,
}

pub fn agreement(a: &[f32], b: &[f32]) -> Agreement {
    let mut g = Agreement {
        rays: a.len().min(b.len()),
        ..Default::default()
    };
    for (&ta, &tb) in a.iter().zip(b) {
        match (ta.is_finite(), tb.is_finite()) {
            (true, true) => {
                g.agree += 1;
                let rel = (ta as f64 - tb as f64).abs() / (ta.max(tb) as f64).max(1.0);
                g.max_rel_dt = g.max_rel_dt.max(rel);
                if rel > 1e-4 {
                    g.t_differs += 1;
                }
            }
            (false, false) => g.agree += 1,
            (true, false) => g.only_a += 1,
            (false, true) => g.only_b += 1,
        }
    }
    g
}

fn mrays(rays: usize, seconds: f64) -> f64 {
    rays as f64 / seconds / 1e6
}

pub fn run(args: &TraversalArgs) -> Result<()> {
    check_args(args)?;
    let (file, source) = load_rays(args)?;
    if let Some(path) = &args.export {
        return export(path, &file);
    }
    let bvh = CandelaBvh::build(&file.mesh, args.build_reps)?;
    let mut embrees = Vec::new();
    if let (Some(program), Some(rays)) = (&args.embree, &args.rays) {
        for q in &args.embree_quality {
            eprintln!("starting embree_trace (quality {q})…");
            embrees.push(Embree::spawn(program, rays, q, args.build_reps)?);
        }
    }
    let times = time_batches(args, &file, &bvh.geo, &mut embrees)?;
    if let Some(path) = &args.hits_out {
        let bytes = super::rayfile::hits_to_bytes(&times.candela_hits);
        candela::output::write_atomic(path, |w| w.write_all(&bytes))
            .with_context(|| format!("cannot write the hit file '{}'", path.display()))?;
    }
    print_throughput(args, &file, &source, &times, &embrees);
    if args.record == Record::Both {
        print_full_hit_throughput(args, &file, &times, &embrees);
    }
    print_bvh_table(args, &file, &bvh, &embrees);
    if let Some(rays) = &args.rays {
        print_agreement(rays, &file, &times, &mut embrees)?;
    }
    Ok(())
}

/// The options' own checks, and room in memory for what a generated benchmark holds.
fn check_args(args: &TraversalArgs) -> Result<()> {
    if args.threads.is_empty() {
        bail!("--threads needs thread counts of at least 1, e.g. 1,2");
    }
    for &n in &args.threads {
        super::check_threads("--threads", n)?;
    }
    super::check_triangles("--triangles", args.triangles)?;
    super::check_resolution(args.resolution)?;
    super::check_positive("--reps", args.reps as u64)?;
    super::check_positive("--build-reps", args.build_reps as u64)?;
    if args.rays.is_none() {
        let rays = (args.resolution as u64).pow(2) * super::BYTES_PER_RAY;
        super::check_memory_for(
            &format!(
                "{} with --resolution {} ({}² primary rays and their diffuse and shadow rays, about {} bytes each)",
                super::mesh_what("--triangles", args.triangles),
                args.resolution,
                args.resolution,
                super::BYTES_PER_RAY
            ),
            super::mesh_bytes(args.triangles) + rays,
        )?;
    }
    Ok(())
}

/// The mesh and rays: read from --rays, or generated. Returns them and where they came from
/// (for the report's first line).
fn load_rays(args: &TraversalArgs) -> Result<(RayFile, String)> {
    match &args.rays {
        Some(path) => {
            let t0 = Instant::now();
            let f = RayFile::read(path)?;
            super::check_memory_for(
                &format!(
                    "the BVH of the {} triangles of '{}'",
                    f.mesh.indices.len(),
                    path.display()
                ),
                super::mesh_bytes(f.mesh.indices.len()),
            )?;
            eprintln!(
                "read {} in {:.1} s",
                path.display(),
                t0.elapsed().as_secs_f64()
            );
            Ok((f, path.display().to_string()))
        }
        None => {
            let mesh = bench_mesh(args.triangles);
            let (geo, _) = build_geometry(&mesh)?;
            let batches = generate_batches(&geo, args.resolution);
            Ok((
                RayFile { mesh, batches },
                format!(
                    "generated ({} triangles, {}² primary rays)",
                    args.triangles, args.resolution
                ),
            ))
        }
    }
}

/// `--export`: writes the ray file and says what it holds.
fn export(path: &Path, file: &RayFile) -> Result<()> {
    file.write(path)?;
    println!(
        "wrote {}: {} triangles, {}",
        path.display(),
        file.mesh.indices.len(),
        file.batches
            .iter()
            .map(|b| format!("{} {} rays", b.rays.len(), b.name))
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(())
}

/// candela's BVH over the benchmark mesh, with its median build time.
struct CandelaBvh {
    geo: SceneGeometry,
    /// Median of the build times, seconds.
    build_seconds: f64,
    bytes: f64,
}

impl CandelaBvh {
    /// Builds the BVH `build_reps` times (at least once), keeping the last build.
    fn build(mesh: &TriangleMesh, build_reps: usize) -> Result<CandelaBvh> {
        let mut builds = Vec::new();
        let mut geo = None;
        for _ in 0..build_reps.max(1) {
            drop(geo.take()); // free the previous build first
            let (g, s) = build_geometry(mesh)?;
            builds.push(s);
            geo = Some(g);
        }
        let geo = geo.expect("at least one build");
        let build_seconds = median(&mut builds);
        let bytes = geo.memory_bytes() as f64;
        Ok(CandelaBvh {
            geo,
            build_seconds,
            bytes,
        })
    }
}

/// The timings of every repetition, indexed `[batch][threads index]` (and then, for Embree,
/// by process), and candela's hits.
struct Times {
    candela: Vec<Vec<Vec<Timing>>>,
    embree: Vec<Vec<Vec<Vec<Timing>>>>,
    /// With --record both: the full-Hit timings of the closest-hit batches.
    candela_full: Vec<Vec<Vec<Timing>>>,
    /// Per batch, the hit `t` of candela's first repetition.
    candela_hits: Vec<Vec<f32>>,
}

/// Traces every batch at every thread count, `--reps` times, with candela and each Embree
/// process alternating.
fn time_batches(
    args: &TraversalArgs,
    file: &RayFile,
    geo: &SceneGeometry,
    embrees: &mut [Embree],
) -> Result<Times> {
    let reps = args.reps;
    let nb = file.batches.len();
    let nt = args.threads.len();
    let mut t = Times {
        candela: vec![vec![Vec::new(); nt]; nb],
        embree: vec![vec![vec![Vec::new(); embrees.len()]; nt]; nb],
        candela_full: vec![vec![Vec::new(); nt]; nb],
        candela_hits: vec![Vec::new(); nb],
    };
    let main_full = args.record == Record::Full;
    for rep in 0..reps {
        eprintln!("repetition {}/{reps}…", rep + 1);
        for (b, batch) in file.batches.iter().enumerate() {
            for (k, &threads) in args.threads.iter().enumerate() {
                let (s, hits) = trace_batch_record(geo, batch, threads, main_full);
                t.candela[b][k].push(s);
                if t.candela_hits[b].is_empty() {
                    t.candela_hits[b] = hits;
                }
                for (e, emb) in embrees.iter_mut().enumerate() {
                    t.embree[b][k][e].push(emb.trace(&batch.name, threads)?);
                }
                if args.record == Record::Both && batch.kind == RayKind::Closest {
                    let (s, hits) = trace_batch_record(geo, batch, threads, true);
                    t.candela_full[b][k].push(s);
                    if hits != t.candela_hits[b] {
                        bail!(
                            "intersect and intersect_basic disagree on batch {}",
                            batch.name
                        );
                    }
                }
            }
        }
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agreement_counts() {
        let inf = f32::INFINITY;
        let g = agreement(&[1.0, inf, 2.0, inf, 3.0], &[1.0, inf, inf, 4.0, 3.1]);
        assert_eq!(
            (g.rays, g.agree, g.only_a, g.only_b, g.t_differs),
            (5, 3, 1, 1, 1)
        );
    }

    #[test]
    fn generated_batches_are_consistent() {
        let mesh = bench_mesh(2000);
        let (geo, _) = build_geometry(&mesh).unwrap();
        let b = generate_batches(&geo, 32);
        assert_eq!(b[0].rays.len(), 32 * 32);
        assert!(b[1].rays.len() > 500 && b[1].rays.len() <= 1024);
        assert!(!b[2].rays.is_empty() && b[2].rays.len() <= b[1].rays.len());
        let (_, t) = trace_batch_record(&geo, &b[0], 2, false);
        assert_eq!(trace_batch(&geo, &b[0], 1).1, t);
        assert_eq!(t.iter().filter(|t| t.is_finite()).count(), b[1].rays.len());
        // Diffuse rays leave the surface: none may hit at t ≈ 0.
        let (_, t) = trace_batch_record(&geo, &b[1], 2, false);
        assert!(t.iter().all(|&t| t >= 1e-4));
    }
}
