//! The whole render job as one library call: load and check the scene, render progressively
//! (resume, checkpoints, target error, time limit, cancellation), write the image files, run
//! the meters and grids, and write grid CSVs, heat maps, false-colour maps and the report.
//! The command line, tests and other front ends call [`run`] and [`merge()`]; what they show
//! while it runs comes through [`Progress`].

pub(crate) mod files;
mod merge;
pub mod shard;

use crate::output::with_suffix;
pub use files::would_replace;
pub use files::{check_exposure, MAX_ABS_EXPOSURE_EV};
use files::{
    check_output_dir, check_outputs, output_stem, state_bytes_at_least, write_exr, write_hdr,
    write_png, Planned,
};
pub use merge::{merge, merge_with, MergeOptions, MergeOutputs};
pub use shard::Shard;
pub use shard::ShardSummary;

use crate::film::Film;
use crate::meter::{Estimate, GridStats};
use crate::photometry::Quantity;
use crate::render::{PassStatus, Progressive, RenderResult, StopReason, TargetError};
use crate::report::json::{grid_csv, report_json, write_text, ReportInput};
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

/// An option of a job with a value that no input can make valid (a thread count of 0, an
/// exposure of NaN, …). The command line exits with code 2 for it, as for its other usage
/// errors; the message names the command-line option.
#[derive(Debug)]
pub struct InvalidOption(pub String);

impl std::fmt::Display for InvalidOption {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for InvalidOption {}

/// An [`InvalidOption`] error.
pub fn invalid_option(message: impl Into<String>) -> anyhow::Error {
    InvalidOption(message.into()).into()
}

/// The error and its causes joined by ": ", like `{:#}`, but a cause whose text an outer
/// message already contains (e.g. "cannot read scene file X: {source}" whose source is also
/// the next cause in the chain) is not repeated.
pub fn error_text(e: &anyhow::Error) -> String {
    let mut msg = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if msg.is_empty() {
            msg = text;
        } else if !text.is_empty() && !msg.contains(&text) {
            msg.push_str(": ");
            msg.push_str(&text);
        }
    }
    msg
}

/// Largest worker-thread count accepted: 16 per available core
/// ([`std::thread::available_parallelism`]). More only adds contention and memory, and tens of
/// thousands of threads make the process unresponsive.
pub fn max_threads() -> usize {
    16 * std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Refuses a thread count (named `flag` in the message) of 0 or above [`max_threads`].
pub fn check_threads(flag: &str, n: usize) -> Result<()> {
    if n == 0 {
        return Err(invalid_option(format!("{flag} must be at least 1, got 0")));
    }
    let max = max_threads();
    if n > max {
        return Err(invalid_option(format!(
            "{flag} {n} is too many: at most {max} threads are accepted (16 per available core, {} cores here)",
            max / 16
        )));
    }
    Ok(())
}

/// Refuses a target fraction outside (0, 1] or a luminance floor (cd/m²) that is negative or
/// not finite; the messages name the command-line options.
pub fn check_target(fraction: f64, floor_cd_m2: Option<f64>) -> Result<()> {
    if !(fraction > 0.0 && fraction <= 1.0) {
        return Err(invalid_option(format!(
            "--target-fraction must lie in (0, 1], got {fraction}"
        )));
    }
    if let Some(f) = floor_cd_m2 {
        if !(f.is_finite() && f >= 0.0) {
            return Err(invalid_option(format!(
                "--target-floor must be a luminance ≥ 0 in cd/m², got {f}"
            )));
        }
    }
    Ok(())
}

/// Checks the job's own settings (before the scene is read).
fn check_job(job: &RenderJob) -> Result<()> {
    if let Some(n) = job.threads {
        check_threads("--threads", n)?;
    }
    check_exposure(job.exposure_ev)?;
    if let Some(t) = &job.target {
        check_target(t.fraction, t.floor_cd_m2)?;
    }
    if job.max_spp == Some(0) {
        return Err(invalid_option("--max-spp must be at least 1"));
    }
    if job.overrides.spp == Some(0) {
        return Err(invalid_option("--spp must be at least 1"));
    }
    if job.shard.is_some() && job.target.is_some() {
        return Err(invalid_option(
            "--shard splits a fixed number of samples per pixel among the shards; --target-error decides it pixel by pixel as the render goes, which separate shards cannot share: give --shard with --spp",
        ));
    }
    if job.health.spectral_bands > crate::film::MAX_SPECTRAL_BANDS {
        return Err(invalid_option(format!(
            "--spectral-bands must be at most {}",
            crate::film::MAX_SPECTRAL_BANDS
        )));
    }
    if job.resume && job.overwrite {
        return Err(invalid_option(
            "--resume continues NAME.state and --overwrite replaces it: give one of them",
        ));
    }
    Ok(())
}

/// The film to continue: from NAME.state with `resume` (refused if the scene, its settings or
/// the adaptive mode changed), else a new one.
fn initial_film(
    job: &RenderJob,
    world: &World,
    hash: u64,
    shard: Option<crate::state::ShardInfo>,
    state_path: &Path,
) -> Result<Film> {
    let (w, h) = (world.camera.width, world.camera.height);
    if !job.resume {
        let mut film = if job.target.is_some() {
            Film::new_adaptive(w, h)
        } else {
            Film::new(w, h)
        };
        film.pixel_batches = world.settings.pixel_batches;
        return Ok(film);
    }
    let st = RenderState::load(state_path)?;

    if st.scene_hash != hash || st.seed != world.settings.seed {
        bail!(
            "cannot resume from {}: the scene file {}, a file it refers to (mesh, spectrum, luminaire data) or its settings (seed, max depth, resolution, illuminance, caustics) changed since the state was written",
            state_path.display(),
            job.scene.display()
        );
    }
    if st.shard != shard {
        let what = |s: Option<crate::state::ShardInfo>| match s {
            Some(s) => format!(
                "shard {} of {} at {} samples per pixel",
                s.index, s.count, s.spp
            ),
            None => "a whole render (no --shard)".to_string(),
        };
        bail!(
            "cannot resume from {}: it holds {}, but this run asks for {}; rerun it as it was started, or start it again with --overwrite",
            state_path.display(),
            what(st.shard),
            what(shard)
        );
    }
    if (st.film.width, st.film.height) != (w, h) {
        bail!(
            "{} is corrupt: its film is {}×{} but the scene it was rendered from (whose hash it carries) renders {w}×{h}",
            state_path.display(),
            st.film.width,
            st.film.height
        );
    }
    if st.film.decision.is_some() != job.target.is_some() {
        bail!(
            "cannot resume from {}: it was {} a --target-error; resume it the same way",
            state_path.display(),
            if st.film.decision.is_some() {
                "rendered with"
            } else {
                "rendered without"
            }
        );
    }
    let kept = st
        .film
        .health
        .as_ref()
        .map(|h| h.channels)
        .unwrap_or_default();
    if kept != job.health {
        bail!(
            "cannot resume from {}: it keeps the light-and-health channels {kept:?}, but this run asks for {:?}; resume it with the same --alpha-opic, --mesopic and --spectral-bands",
            state_path.display(),
            job.health
        );
    }
    Ok(st.film)
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
    let name = scene_path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".into());
    let mut stem = output_stem(job.out.as_deref(), &name, &["exr", "png", "hdr"]);
    if let Some(s) = &job.shard {
        stem = with_suffix(&stem, &s.suffix());
    }
    let (exr_path, png_path) = (with_suffix(&stem, ".exr"), with_suffix(&stem, ".png"));
    let hdr_path = with_suffix(&stem, ".hdr");
    check_output_dir(&stem)?;
    let state_path = with_suffix(&stem, ".state");
    let report_path = with_suffix(&stem, ".report.json");
    let (w, h) = (world.camera.width, world.camera.height);
    let state_existed = state_path.exists();
    // A shard continues its own state: the same command, requeued, picks up where it stopped.
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
    check_outputs(&planned_outputs(job, &world, &stem), &inputs, need_bytes)?;
    if state_existed && !resuming && !job.overwrite {
        bail!(
            "{} holds the samples of an earlier render: continue it with --resume, or start again and replace it with --overwrite (or choose another --out)",
            crate::limits::printable(&state_path.display().to_string(), 300)
        );
    }
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
    let shard_info = job.shard.map(|s| s.info(prog.max_spp));
    if let Some(s) = &job.shard {
        prog.first_sample = s.index as u64 * prog.max_spp as u64;
        prog.first_light_path = s.index as u64 * shard::LIGHT_PATHS_PER_SHARD;
    }
    let resume_job = RenderJob {
        resume: resuming,
        ..job.clone()
    };
    let mut film = initial_film(&resume_job, &world, hash, shard_info, &state_path)?;
    let resumed_samples = film.total_samples();
    let illuminance = world.settings.illuminance;
    if job.health.any() && film.health.is_none() {
        let h = crate::film::HealthFilm::new(job.health, illuminance, w * h)
            .map_err(anyhow::Error::msg)?;
        film.health = Some(h);
    }
    let spectral_path = with_suffix(&stem, ".spectral.exr");
    // The images before the state: on a nearly full disk the small files still get written.
    let write_images = |film: &Film, writes: &mut Writes| {
        writes.attempt(&exr_path, || {
            write_exr(scene_path, film, illuminance, &world.camera, &exr_path)
        });
        writes.attempt(&hdr_path, || write_hdr(film, &world.camera, &hdr_path));
        // The PNG too, so that the image pair on disk is always of the same estimate.
        writes.attempt(&png_path, || write_png(film, &png_path, job.exposure_ev));
        if let Some(layers) = crate::film::spectral_layers(film, &scene_path.display().to_string())
        {
            writes.attempt(&spectral_path, || {
                Ok(crate::output::write_exr(&spectral_path, &layers)?)
            });
        }
    };
    let write_state = |film: &Film, meters: &[crate::meter::MeterSums], writes: &mut Writes| {
        writes.attempt(&state_path, || {
            RenderState::save_film(
                scene_path,
                hash,
                &world,
                film,
                shard_info,
                meters,
                &state_path,
            )
        });
    };
    progress.start(prog.max_spp as u64 * world.camera.inside_pixels() as u64)?;
    let progress = std::cell::RefCell::new(progress);
    let mut last = PassStatus::default();
    let (result, reason) = crate::render::render_progressive(
        &world,
        &mut film,
        job.threads,
        &prog,
        stop,
        &mut |s| {
            last = *s;
            progress.borrow_mut().pass(s);
        },
        &mut |f| {
            let mut writes = Writes::default();
            write_images(f, &mut writes);
            write_state(f, &[], &mut writes);
            for e in &writes.failed {
                progress
                    .borrow_mut()
                    .warning(&format!("checkpoint not written, the render goes on: {e}"));
            }
            Ok(())
        },
    )?;
    let progress = progress.into_inner();
    let spp = result.film.samples_per_pixel();
    let mut outputs = RenderOutputs {
        outcome: Outcome::Finished,
        exr_path: exr_path.clone(),
        png_path: png_path.clone(),
        state_path: state_path.clone(),
        report_path: report_path.clone(),
        outputs: Vec::new(),
        resumed_samples,
        render: result,
        meters: Vec::new(),
        grids: Vec::new(),
        truncation: None,
    };
    let result = &outputs.render;
    let mut writes = Writes::default();
    if reason == StopReason::Interrupted {
        outputs.outcome = if result.film.total_samples() == resumed_samples {
            // No pass finished: an image of nothing new would replace the files of an earlier
            // render (or the same state again).
            Outcome::InterruptedBeforeFirstPass
        } else {
            write_images(&result.film, &mut writes);
            write_state(&result.film, &[], &mut writes);
            Outcome::InterruptedRender
        };
        writes.finish()?;
        return Ok(outputs);
    }
    progress.rendered(&ImageDone {
        reason,
        last,
        target: job.target,
    });
    write_images(&result.film, &mut writes);
    let t_measure = std::time::Instant::now();
    // A shard measures its share of every meter's samples and keeps their sums for the merge.
    let measurements = match job.shard {
        Some(s) => crate::meter::measure_shard_until(&world, s.index, s.count, stop),
        None => crate::meter::measure_all_until(&world, stop).map(|m| (m, Vec::new())),
    };
    let measure_seconds = t_measure.elapsed().as_secs_f64();
    let Some((measurements, meter_sums)) = measurements else {
        if save_state {
            write_state(&result.film, &[], &mut writes);
        }
        outputs.outcome = Outcome::InterruptedMeasuring;
        writes.finish()?;
        return Ok(outputs);
    };
    write_grids(&world, &measurements, &stem, job.units, &mut writes);
    if job.falsecolour {
        let layers =
            files::film_layers(&scene_path.display().to_string(), &result.film, illuminance);
        write_falsecolour(&world, &layers, &stem, job.units, &mut writes);
    }
    let written = writes.written.clone();
    let report = report_json(&ReportInput {
        scene_path,
        world: &world,
        render: result,
        measurements: &measurements,
        measure_seconds,
        units: job.units,
        outputs: written.clone(),
        progressive: serde_json::json!({
            "stop_reason": format!("{reason:?}"),
            "passes": last.passes,
            "max_spp": prog.max_spp,
            "image_samples_per_pixel": spp,
            "target_relative_error_95": job.target.map(|t| t.relative),
            "target_fraction": job.target.map(|t| t.fraction),
            "target_floor_cd_m2": job.target.and_then(|t| t.floor_cd_m2),
            "fraction_of_eligible_pixels_at_target": last.converged_fraction,
            "max_time_s": job.max_time.map(|d| d.as_secs_f64()),
            "shard": job.shard.map(|s| serde_json::json!({
                "index": s.index,
                "count": s.count,
                "first_sample": prog.first_sample,
            })),
        }),
    });
    writes.attempt(&report_path, || {
        write_text(&report_path, &serde_json::to_string_pretty(&report)?)?;
        Ok(())
    });
    if save_state {
        write_state(&result.film, &meter_sums, &mut writes);
    }
    writes.finish()?;
    outputs.outputs = written;
    outputs.truncation = crate::report::json::truncation_warning(
        &world,
        outputs.render.stats.truncated_paths + measurements.stats.truncated_paths,
    );
    outputs.meters = world
        .meters
        .iter()
        .zip(&measurements.meters)
        .enumerate()
        .map(|(k, (m, e))| MeterResult {
            name: m.name.clone(),
            kind: m.kind.clone(),
            estimate: *e,
            ugr: m.ugr(&world, e),
            melanopic: measurements.melanopic.get(k).copied().flatten(),
        })
        .collect();
    outputs.grids = world
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
    Ok(outputs)
}

/// The outputs of the end of a job, each attempted whether or not an earlier one failed
/// (also used by `annual` and `merge`).
#[derive(Default)]
pub struct Writes {
    /// Files written, in order.
    pub written: Vec<String>,
    /// One line per file that could not be written, naming it.
    pub failed: Vec<String>,
}

impl Writes {
    pub fn attempt(&mut self, path: &Path, write: impl FnOnce() -> Result<()>) {
        let shown = path.display().to_string();
        match write() {
            Ok(()) => self.written.push(shown),
            Err(e) => {
                let e = error_text(&e);
                self.failed.push(if e.contains(&shown) {
                    e
                } else {
                    format!("{shown}: {e}")
                });
            }
        }
    }

    /// One error listing every file that could not be written, if any.
    pub fn finish(self) -> Result<()> {
        match self.failed.len() {
            0 => Ok(()),
            1 => bail!("{}", self.failed[0]),
            n => bail!(
                "{n} files could not be written (the other outputs were):\n  {}",
                self.failed.join("\n  ")
            ),
        }
    }
}

/// Each grid's CSV and heat map, named after the grid.
fn write_grids(
    world: &World,
    measurements: &crate::meter::Measurements,
    stem: &Path,
    units: UnitSystem,
    writes: &mut Writes,
) {
    for (k, (g, est)) in world.grids.iter().zip(&measurements.grids).enumerate() {
        let path = grid_csv_path(stem, &g.name);
        writes.attempt(&path, || {
            write_text(&path, &grid_csv(world, k, est, units))?;
            Ok(())
        });
        let png = path.with_extension("png");
        let values = crate::report::heatmap::GridValues {
            name: g.name.clone(),
            nx: g.nx as usize,
            ny: g.ny as usize,
            values: est.iter().map(|e| e.mean).collect(),
            stderr: est.iter().map(|e| e.stderr).collect(),
            size_m: (g.edge_u.length() as f64, g.edge_v.length() as f64),
        };
        let settings = crate::report::falsecolour::FalsecolourSettings {
            quantity: Quantity::Illuminance,
            units,
            ..Default::default()
        };
        writes.attempt(&png, || {
            crate::report::heatmap::write_grid_heatmap(&png, &values, &settings)?;
            Ok(())
        });
    }
}

/// False-colour maps of the image (the EXR's channels): luminance, and illuminance when it was
/// estimated.
fn write_falsecolour(
    world: &World,
    layers: &crate::output::Layers,
    stem: &Path,
    units: UnitSystem,
    writes: &mut Writes,
) {
    let mut quantities = vec![(Quantity::Luminance, ".luminance.png")];
    if world.settings.illuminance {
        quantities.push((Quantity::Illuminance, ".illuminance.png"));
    }
    for (q, suffix) in quantities {
        let path = with_suffix(stem, suffix);
        let settings = crate::report::falsecolour::FalsecolourSettings {
            quantity: q,
            units,
            ..Default::default()
        };
        writes.attempt(&path, || {
            crate::report::falsecolour::write_falsecolour(&path, layers, &settings)?;
            Ok(())
        });
    }
}
