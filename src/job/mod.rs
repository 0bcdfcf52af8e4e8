//! The whole render job as one library call: load and check the scene, render progressively
//! (resume, checkpoints, target error, time limit, cancellation), write the image files, run
//! the meters and grids, and write grid CSVs, heat maps, false-colour maps and the report.
//! The command line, tests and other front ends call [`run`] and [`merge()`]; what they show
//! while it runs comes through [`Progress`].

mod checks;
pub(crate) mod files;
mod merge;
mod resume;
pub mod shard;
mod writes;

use crate::output::with_suffix;
use checks::check_job;
pub use checks::{check_target, check_threads, invalid_option, max_threads, InvalidOption};
pub use files::would_replace;
pub use files::{check_exposure, MAX_ABS_EXPOSURE_EV};
use files::{
    check_output_dir, check_outputs, output_stem, state_bytes_at_least, write_exr, write_hdr,
    write_png, Planned,
};
pub use merge::{merge, merge_with, MergeOptions, MergeOutputs};
use resume::start_film;
pub use shard::Shard;
pub use shard::ShardSummary;
pub use writes::{error_text, Writes};
use writes::{write_falsecolour, write_grids};

use crate::film::Film;
use crate::meter::{Estimate, GridStats, Measurements, MeterSums};
use crate::render::{PassStatus, Progressive, RenderResult, StopReason, TargetError};
use crate::report::json::{report_json, write_text, ReportInput};
use crate::report::units::UnitSystem;
use crate::scene::{self, Overrides};
use crate::state::RenderState;
use crate::world::measure::grid_csv_path;
use crate::world::MeterKind;
use crate::world::World;
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Duration;

/// Everything `candela render` is asked to do ([`RenderJob::new`] gives the defaults).
#[derive(Clone, Debug)]
pub struct RenderJob {
    /// The scene file (RON).
    pub scene: PathBuf,
    /// Overrides of the scene's render settings (spp, seed, max depth, illuminance, caustics).
    pub overrides: Overrides,
    /// Output directory or name (see [`output_stem`]); None: named after the scene in the
    /// current directory.
    pub out: Option<PathBuf>,
    /// Worker threads (None: all cores); the image does not depend on it.
    pub threads: Option<usize>,
    /// Exposure of the PNG in EV (None: automatic); the EXR is absolute.
    pub exposure_ev: Option<f64>,
    /// Units of the report, grid CSVs and maps.
    pub units: UnitSystem,
    /// Render until every pixel is known to this error (adaptive sampling).
    pub target: Option<TargetError>,
    /// Most samples per pixel (None: the override's or the scene's spp; 65536 with a target).
    pub max_spp: Option<u32>,
    /// Stop after this long, at the end of the pass in progress.
    pub max_time: Option<Duration>,
    /// Write NAME.state, NAME.exr and NAME.png this often (None: never).
    pub checkpoint_interval: Option<Duration>,
    /// Continue from NAME.state.
    pub resume: bool,
    /// Start afresh even if NAME.state exists, replacing it (without this or `resume`, an
    /// existing state is never replaced: the job is refused).
    pub overwrite: bool,
    /// Also write NAME.state at the end.
    pub save_state: bool,
    /// Also write false-colour maps of luminance (and illuminance).
    pub falsecolour: bool,
    /// NAME.html, the HTML report, is written after the job (by its caller, as `candela
    /// render --report-html` does): it is checked with the job's own outputs before rendering.
    pub report_html: bool,
    /// Render only this shard of the render (see [`shard`]): samples I·spp … (I+1)·spp − 1 of
    /// every pixel, outputs named NAME.shard-I-of-N.*, the state always written, and an existing
    /// state of the shard continued (a requeued job picks up where it stopped).
    pub shard: Option<Shard>,
    /// Light-and-health channels to keep per pixel (m-EDL/m-EDI, mesopic, spectral bands);
    /// not carried by render states, so refused with `resume` and `shard`.
    pub health: crate::film::HealthChannels,
}

impl RenderJob {
    /// A job that renders `scene` as its file says: outputs named after it in the current
    /// directory, SI units, checkpoints every 60 s.
    pub fn new(scene: impl Into<PathBuf>) -> Self {
        Self {
            scene: scene.into(),
            overrides: Overrides::default(),
            out: None,
            threads: None,
            exposure_ev: None,
            units: UnitSystem::Si,
            target: None,
            max_spp: None,
            max_time: None,
            checkpoint_interval: Some(Duration::from_secs(60)),
            resume: false,
            overwrite: false,
            save_state: false,
            falsecolour: false,
            report_html: false,
            shard: None,
            health: Default::default(),
        }
    }
}

/// What a front end shows while a job runs. Every method has an empty default.
pub trait Progress {
    /// The render starts, with at most `max_samples` samples over all pixels (the scene is
    /// loaded and checked by then). An error ends the job before anything is rendered.
    fn start(&mut self, _max_samples: u64) -> Result<()> {
        Ok(())
    }
    /// A pass of the progressive render ended.
    fn pass(&mut self, _status: &PassStatus) {}
    /// The image is finished (before the meters and grids are measured).
    fn rendered(&mut self, _image: &ImageDone) {}
    /// Something went wrong and the job goes on (a checkpoint that could not be written).
    fn warning(&mut self, _message: &str) {}
}

/// A [`Progress`] that shows nothing.
pub struct Silent;
impl Progress for Silent {}

/// How the image's render ended.
#[derive(Clone, Copy, Debug)]
pub struct ImageDone {
    pub reason: StopReason,
    /// The last pass's status (passes, samples, fraction of pixels at the target).
    pub last: PassStatus,
    pub target: Option<TargetError>,
}

/// One meter's result, in SI units (lx or cd/m²).
#[derive(Clone, Debug)]
pub struct MeterResult {
    pub name: String,
    pub kind: MeterKind,
    pub estimate: Estimate,
    /// The UGR of a `Ugr` meter (whose estimate is the vertical illuminance at the eye).
    pub ugr: Option<crate::glare::luminaires::UgrResult>,
    /// E_v, m-EDI and their ratio of a `Melanopic` meter.
    pub melanopic: Option<crate::meter::MelanopicEstimate>,
}

/// One grid's result: its size and statistics in SI units (lx).
#[derive(Clone, Debug)]
pub struct GridResult {
    pub name: String,
    pub nx: u32,
    pub ny: u32,
    pub stats: GridStats,
    /// Samples of its points that were not finite (counted as 0).
    pub non_finite: u64,
}

/// How a job ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Everything was written.
    Finished,
    /// Stopped before the first pass ended: nothing was written.
    InterruptedBeforeFirstPass,
    /// Stopped during the render: a checkpoint (state, EXR, PNG) was written.
    InterruptedRender,
    /// Stopped during the meters and grids: the images were written, no report.
    InterruptedMeasuring,
}

/// What a job wrote and measured. The image's size, samples per pixel and mean luminance are
/// those of `render.film`.
pub struct RenderOutputs {
    pub outcome: Outcome,
    pub exr_path: PathBuf,
    pub png_path: PathBuf,
    pub state_path: PathBuf,
    /// The report (written when the outcome is [`Outcome::Finished`]).
    pub report_path: PathBuf,
    /// Every file written at the end (images, grid CSVs and heat maps, false-colour maps).
    pub outputs: Vec<String>,
    /// Image samples the film held from NAME.state before this run (0 unless resumed).
    pub resumed_samples: u64,
    pub render: RenderResult,
    pub meters: Vec<MeterResult>,
    pub grids: Vec<GridResult>,
    /// Paths of the image, meters and grids cut short at a finite `max_depth`, as a warning.
    pub truncation: Option<String>,
}

impl RenderOutputs {
    /// Image samples rendered by this run per second of its render (resumed samples excluded).
    pub fn samples_per_second(&self) -> f64 {
        let new = self.render.film.total_samples() - self.resumed_samples;
        new as f64 / self.render.elapsed.as_secs_f64().max(1e-9)
    }
}

/// Every file the job may write, with what it is (for messages): images, state, report, each
/// grid's CSV and heat map, and the false-colour maps.
fn planned_outputs(job: &RenderJob, world: &World, stem: &Path) -> Vec<Planned> {
    let plan = |suffix: &str, what: &str| Planned {
        path: with_suffix(stem, suffix),
        what: what.to_string(),
    };
    let mut planned = vec![
        plan(".exr", "the EXR image"),
        plan(".png", "the PNG image"),
        plan(".hdr", "the Radiance HDR image"),
        plan(".report.json", "the report"),
        plan(".state", "the render state"),
    ];
    for g in &world.grids {
        let csv = grid_csv_path(stem, &g.name);
        let name = crate::limits::printable(&g.name, 60);
        planned.push(Planned {
            path: csv.with_extension("png"),
            what: format!("the heat map of grid {name:?}"),
        });
        planned.push(Planned {
            path: csv,
            what: format!("the CSV of grid {name:?}"),
        });
    }
    if job.falsecolour {
        planned.push(plan(".luminance.png", "the luminance false-colour map"));
        if world.settings.illuminance {
            planned.push(plan(".illuminance.png", "the illuminance false-colour map"));
        }
    }
    if job.health.spectral_bands > 0 {
        planned.push(plan(".spectral.exr", "the spectral EXR image"));
    }
    if job.report_html {
        planned.push(plan(".html", "the HTML report"));
    }
    planned
}

/// Runs a whole render job. `stop` ends it early (at the end of the pass in progress; during
/// the meters, at once): the outcome then says what was written.
///
/// Before anything is rendered it refuses outputs that would replace the scene file, a file
/// the scene refers to or each other, names the file system would refuse, a directory that
/// takes no new file, too little free space for the state, and an existing NAME.state unless
/// the job resumes it or may overwrite it. Checkpoints that cannot be written are reported
/// through [`Progress::warning`] and the render goes on; at the end every output is attempted
/// (the small ones first, the state last) and the job fails if any could not be written.
pub fn run(
    job: &RenderJob,
    progress: &mut dyn Progress,
    stop: &AtomicBool,
) -> Result<RenderOutputs> {
    check_job(job)?;
    let (world, hash) = load_scene(job)?;
    for note in world.load_notes() {
        progress.warning(&note);
    }
    let paths = JobPaths::new(job)?;
    let plan = StatePlan::checked(job, &world, &paths)?;
    let prog = progressive(job, &world);
    let shard_info = job.shard.map(|s| s.info(prog.max_spp));
    let mut film = start_film(job, &world, hash, shard_info, plan.resuming, &paths.state)?;
    let resumed_samples = film.total_samples();
    let files = JobFiles {
        job,
        world: &world,
        hash,
        shard_info,
        paths: &paths,
    };
    progress.start(prog.max_spp as u64 * world.camera.inside_pixels() as u64)?;
    let (result, done) = render(&files, &mut film, &prog, stop, progress)?;
    let spp = result.film.samples_per_pixel();
    let outputs = RenderOutputs::unmeasured(&paths, resumed_samples, result);
    if done.reason == StopReason::Interrupted {
        return interrupted_render(outputs, &files);
    }
    progress.rendered(&done);
    let mut writes = Writes::default();
    files.write_images(&outputs.render.film, &mut writes);
    let (measured, measure_seconds) = measure(job, &world, stop);
    let Some((measurements, meter_sums)) = measured else {
        return interrupted_measuring(outputs, &files, plan.save_state, writes);
    };
    files.write_maps(&outputs.render.film, &measurements, &mut writes);
    let written = writes.written.clone();
    let report = report_json(&ReportInput {
        scene_path: job.scene.as_path(),
        world: &world,
        render: &outputs.render,
        measurements: &measurements,
        measure_seconds,
        units: job.units,
        outputs: written.clone(),
        progressive: progressive_json(job, &prog, &done, spp),
    });
    files.write_report(&report, &mut writes);
    if plan.save_state {
        files.write_state(&outputs.render.film, &meter_sums, &mut writes);
    }
    writes.finish()?;
    Ok(outputs.measured(&world, &measurements, written))
}

/// The scene's world and the hash its render states carry (of the scene file, the files it
/// refers to and its settings).
fn load_scene(job: &RenderJob) -> Result<(World, u64)> {
    let scene_path = job.scene.as_path();
    let world = scene::load_world_for(
        scene_path,
        &job.overrides,
        &scene::RunMode {
            adaptive: job.target.is_some(),
            falsecolour: job.falsecolour,
        },
    )?;
    let mut scene_bytes = std::fs::read(scene_path)
        .with_context(|| format!("cannot read scene file {}", scene_path.display()))?;
    // A glTF scene's chosen camera is part of what a render state holds.
    if let Some(c) = &job.overrides.camera {
        scene_bytes.extend(format!("\0--camera {c}").bytes());
    }
    let hash = crate::state::scene_hash(&scene_bytes, &world);
    Ok((world, hash))
}

/// The files of a job, named after its output stem (a shard's carrying its suffix).
struct JobPaths {
    stem: PathBuf,
    exr: PathBuf,
    png: PathBuf,
    hdr: PathBuf,
    spectral: PathBuf,
    state: PathBuf,
    report: PathBuf,
}

impl JobPaths {
    /// The job's file names; refuses an output directory that does not exist.
    fn new(job: &RenderJob) -> Result<Self> {
        let name = job
            .scene
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "render".into());
        let mut stem = output_stem(job.out.as_deref(), &name, &["exr", "png", "hdr"]);
        if let Some(s) = &job.shard {
            stem = with_suffix(&stem, &s.suffix());
        }
        check_output_dir(&stem)?;
        Ok(JobPaths {
            exr: with_suffix(&stem, ".exr"),
            png: with_suffix(&stem, ".png"),
            hdr: with_suffix(&stem, ".hdr"),
            spectral: with_suffix(&stem, ".spectral.exr"),
            state: with_suffix(&stem, ".state"),
            report: with_suffix(&stem, ".report.json"),
            stem,
        })
    }
}

/// What the job does with NAME.state: continue it, and write it at the end.
struct StatePlan {
    resuming: bool,
    save_state: bool,
}

impl StatePlan {
    /// The plan, once the outputs are checked (see [`run`]) and an existing state that the
    /// job would neither continue nor be allowed to replace is refused.
    fn checked(job: &RenderJob, world: &World, paths: &JobPaths) -> Result<Self> {
        let (w, h) = (world.camera.width, world.camera.height);
        let state_existed = paths.state.exists();
        // A shard continues its own state: the same command, requeued, picks up where it
        // stopped.
        let resuming = job.resume || (job.shard.is_some() && state_existed && !job.overwrite);
        let save_state = job.save_state || resuming || state_existed || job.shard.is_some();
        let mut inputs = vec![(job.scene.clone(), "the scene file".to_string())];
        inputs.extend(
            world
                .sources
                .iter()
                .map(|p| (p.clone(), "the file the scene refers to".to_string())),
        );
        let need_bytes = if save_state {
            state_bytes_at_least(w, h, job.target.is_some())
        } else {
            0
        };
        check_outputs(
            &planned_outputs(job, world, &paths.stem),
            &inputs,
            need_bytes,
        )?;
        if state_existed && !resuming && !job.overwrite {
            bail!(
                "{} holds the samples of an earlier render: continue it with --resume, or start again and replace it with --overwrite (or choose another --out)",
                crate::limits::printable(&paths.state.display().to_string(), 300)
            );
        }
        Ok(StatePlan {
            resuming,
            save_state,
        })
    }
}

/// The progressive render's settings: the samples per pixel, the stopping rules, and a
/// shard's first sample and light path.
fn progressive(job: &RenderJob, world: &World) -> Progressive {
    let mut prog = Progressive {
        max_spp: job
            .max_spp
            .or(job.overrides.spp)
            .unwrap_or(if job.target.is_some() {
                65536
            } else {
                world.settings.spp
            }),
        target: job.target,
        max_time: job.max_time,
        checkpoint_interval: job.checkpoint_interval,
        first_sample: 0,
        first_light_path: 0,
    };
    if let Some(s) = &job.shard {
        prog.first_sample = s.index as u64 * prog.max_spp as u64;
        prog.first_light_path = s.index as u64 * shard::LIGHT_PATHS_PER_SHARD;
    }
    prog
}

/// What the job writes of a film (images, state) and of its measurements (grids, maps,
/// report).
struct JobFiles<'a> {
    job: &'a RenderJob,
    world: &'a World,
    hash: u64,
    shard_info: Option<crate::state::ShardInfo>,
    paths: &'a JobPaths,
}

impl JobFiles<'_> {
    /// The images of `film`. They come before the state: on a nearly full disk the small
    /// files still get written.
    fn write_images(&self, film: &Film, writes: &mut Writes) {
        let (scene_path, world, p) = (self.job.scene.as_path(), self.world, self.paths);
        let illuminance = world.settings.illuminance;
        writes.attempt(&p.exr, || {
            write_exr(scene_path, film, illuminance, &world.camera, &p.exr)
        });
        writes.attempt(&p.hdr, || write_hdr(film, &world.camera, &p.hdr));
        // The PNG too, so that the image pair on disk is always of the same estimate.
        writes.attempt(&p.png, || write_png(film, &p.png, self.job.exposure_ev));
        if let Some(layers) = crate::film::spectral_layers(film, &scene_path.display().to_string())
        {
            writes.attempt(&p.spectral, || {
                Ok(crate::output::write_exr(&p.spectral, &layers)?)
            });
        }
    }

    /// NAME.state: `film` and a shard's meter sums.
    fn write_state(&self, film: &Film, meters: &[crate::meter::MeterSums], writes: &mut Writes) {
        writes.attempt(&self.paths.state, || {
            RenderState::save_film(
                &self.job.scene,
                self.hash,
                self.world,
                film,
                self.shard_info,
                meters,
                &self.paths.state,
            )
        });
    }

    /// Each grid's CSV and heat map, and the false-colour maps of `film` when asked for.
    fn write_maps(
        &self,
        film: &Film,
        measurements: &crate::meter::Measurements,
        writes: &mut Writes,
    ) {
        let (job, stem) = (self.job, &self.paths.stem);
        write_grids(self.world, measurements, stem, job.units, writes);
        if job.falsecolour {
            let scene = job.scene.display().to_string();
            let layers = files::film_layers(&scene, film, self.world.settings.illuminance);
            write_falsecolour(self.world, &layers, stem, job.units, writes);
        }
    }

    /// NAME.report.json.
    fn write_report(&self, report: &serde_json::Value, writes: &mut Writes) {
        let path = &self.paths.report;
        writes.attempt(path, || {
            write_text(path, &serde_json::to_string_pretty(report)?)?;
            Ok(())
        });
    }
}

/// The progressive render into `film`, its passes shown through `progress` and its
/// checkpoints written (one that cannot be written is a warning: the render goes on).
fn render(
    files: &JobFiles,
    film: &mut Film,
    prog: &Progressive,
    stop: &AtomicBool,
    progress: &mut dyn Progress,
) -> Result<(RenderResult, ImageDone)> {
    let progress = std::cell::RefCell::new(progress);
    let mut last = PassStatus::default();
    let (result, reason) = crate::render::render_progressive(
        files.world,
        film,
        files.job.threads,
        prog,
        stop,
        &mut |s| {
            last = *s;
            progress.borrow_mut().pass(s);
        },
        &mut |f| {
            let mut writes = Writes::default();
            files.write_images(f, &mut writes);
            files.write_state(f, &[], &mut writes);
            for e in &writes.failed {
                progress
                    .borrow_mut()
                    .warning(&format!("checkpoint not written, the render goes on: {e}"));
            }
            Ok(())
        },
    )?;
    let done = ImageDone {
        reason,
        last,
        target: files.job.target,
    };
    Ok((result, done))
}

/// The render was stopped: a checkpoint of its image and state, unless no pass finished (an
/// image of nothing new would replace the files of an earlier render, or the same state
/// again).
fn interrupted_render(mut outputs: RenderOutputs, files: &JobFiles) -> Result<RenderOutputs> {
    let mut writes = Writes::default();
    let film = &outputs.render.film;
    outputs.outcome = if film.total_samples() == outputs.resumed_samples {
        Outcome::InterruptedBeforeFirstPass
    } else {
        files.write_images(film, &mut writes);
        files.write_state(film, &[], &mut writes);
        Outcome::InterruptedRender
    };
    writes.finish()?;
    Ok(outputs)
}

/// Every meter and grid point, and the seconds it took; None if `stop` was raised meanwhile.
/// A shard measures its share of every meter's samples and keeps their sums for the merge.
fn measure(
    job: &RenderJob,
    world: &World,
    stop: &AtomicBool,
) -> (Option<(Measurements, Vec<MeterSums>)>, f64) {
    let t_measure = std::time::Instant::now();
    let measurements = match job.shard {
        Some(s) => crate::meter::measure_shard_until(world, s.index, s.count, stop),
        None => crate::meter::measure_all_until(world, stop).map(|m| (m, Vec::new())),
    };
    (measurements, t_measure.elapsed().as_secs_f64())
}

/// The meters were stopped: the images are written (in `writes`), and the state when the job
/// keeps one; no report.
fn interrupted_measuring(
    mut outputs: RenderOutputs,
    files: &JobFiles,
    save_state: bool,
    mut writes: Writes,
) -> Result<RenderOutputs> {
    if save_state {
        files.write_state(&outputs.render.film, &[], &mut writes);
    }
    outputs.outcome = Outcome::InterruptedMeasuring;
    writes.finish()?;
    Ok(outputs)
}

/// The report's account of the progressive render: why it stopped, its passes and samples,
/// the target and a shard's place.
fn progressive_json(
    job: &RenderJob,
    prog: &Progressive,
    done: &ImageDone,
    spp: f64,
) -> serde_json::Value {
    serde_json::json!({
        "stop_reason": format!("{:?}", done.reason),
        "passes": done.last.passes,
        "max_spp": prog.max_spp,
        "image_samples_per_pixel": spp,
        "target_relative_error_95": job.target.map(|t| t.relative),
        "target_fraction": job.target.map(|t| t.fraction),
        "target_floor_cd_m2": job.target.and_then(|t| t.floor_cd_m2),
        "fraction_of_eligible_pixels_at_target": done.last.converged_fraction,
        "max_time_s": job.max_time.map(|d| d.as_secs_f64()),
        "shard": job.shard.map(|s| serde_json::json!({
            "index": s.index,
            "count": s.count,
            "first_sample": prog.first_sample,
        })),
    })
}

impl RenderOutputs {
    /// The outputs of a job whose render ended with `render` (finished until its meters say
    /// otherwise), before anything is measured.
    fn unmeasured(paths: &JobPaths, resumed_samples: u64, render: RenderResult) -> Self {
        RenderOutputs {
            outcome: Outcome::Finished,
            exr_path: paths.exr.clone(),
            png_path: paths.png.clone(),
            state_path: paths.state.clone(),
            report_path: paths.report.clone(),
            outputs: Vec::new(),
            resumed_samples,
            render,
            meters: Vec::new(),
            grids: Vec::new(),
            truncation: None,
        }
    }

    /// The finished job's outputs: the files `written`, the truncation warning, and each
    /// meter's and grid's result.
    fn measured(
        mut self,
        world: &World,
        measurements: &Measurements,
        written: Vec<String>,
    ) -> Self {
        self.outputs = written;
        self.truncation = crate::report::json::truncation_warning(
            world,
            self.render.stats.truncated_paths + measurements.stats.truncated_paths,
        );
        self.meters = world
            .meters
            .iter()
            .zip(&measurements.meters)
            .enumerate()
            .map(|(k, (m, e))| MeterResult {
                name: m.name.clone(),
                kind: m.kind.clone(),
                estimate: *e,
                ugr: m.ugr(world, e),
                melanopic: measurements.melanopic.get(k).copied().flatten(),
            })
            .collect();
        self.grids = world
            .grids
            .iter()
            .zip(&measurements.grids)
            .map(|(g, est)| GridResult {
                name: g.name.clone(),
                nx: g.nx,
                ny: g.ny,
                stats: crate::meter::grid_stats(est),
                non_finite: crate::meter::grid_non_finite(est),
            })
            .collect();
        self
    }
}
