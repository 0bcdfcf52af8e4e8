//! `render`: the job of `candela render` ([`crate::job::run`], the same call and settings, so
//! the same files bit for bit) on a worker thread, while the calling thread, holding the
//! interpreter only between waits, calls the progress callback, watches the cancel event and
//! lets Python see Ctrl-C. A stop request ends the pass in progress, as Ctrl-C does for the
//! command line.

use super::{args, error, error_msg, Cancelled};
use crate::job::{self, ImageDone, Outcome, Progress, RenderJob};
use crate::render::{PassStatus, TargetError};
use crate::report::units::UnitSystem;
use crate::scene::Overrides;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Mutex};
use std::time::{Duration, Instant};

/// What the job reports to the calling thread.
enum Event {
    Start(u64),
    Pass(PassStatus),
    Rendered,
    Warning(String),
}

/// A [`Progress`] that forwards to the calling thread.
struct Forward(mpsc::Sender<Event>);

impl Progress for Forward {
    fn start(&mut self, max_samples: u64) -> anyhow::Result<()> {
        let _ = self.0.send(Event::Start(max_samples));
        Ok(())
    }
    fn pass(&mut self, status: &PassStatus) {
        let _ = self.0.send(Event::Pass(*status));
    }
    fn rendered(&mut self, _image: &ImageDone) {
        let _ = self.0.send(Event::Rendered);
    }
    fn warning(&mut self, message: &str) {
        let _ = self.0.send(Event::Warning(message.to_string()));
    }
}

/// How often the calling thread wakes while the job runs (for Ctrl-C and the cancel event).
const POLL: Duration = Duration::from_millis(50);

fn seconds(what: &str, s: Option<f64>) -> PyResult<Option<Duration>> {
    s.map(|s| {
        args::number(what, s, "a duration ≥ 0 in seconds", |s| s >= 0.0)?;
        Duration::try_from_secs_f64(s).map_err(|_| {
            error_msg(format!(
                "{what} must be a duration ≥ 0 in seconds, got {s:e}"
            ))
        })
    })
    .transpose()
}

/// Renders a scene file as `candela render` does; see `candela.render` (python/candela) for
/// the arguments and the result.
#[pyfunction]
#[pyo3(signature = (scene, out, *, spp=None, seed=None, max_depth=None, threads=None,
    illuminance=false, caustics=None, exposure_ev=None, units="si", target_error=None,
    target_fraction=1.0, target_floor_cd_m2=None, max_spp=None, max_time_s=None,
    checkpoint_interval_s=None, resume=false, overwrite=false, save_state=false,
    falsecolour=false, shard=None, alpha_opic=false, mesopic=false, spectral_bands=None,
    progress=None, cancel=None))]
#[allow(clippy::too_many_arguments)]
fn render<'py>(
    py: Python<'py>,
    scene: PathBuf,
    out: PathBuf,
    spp: Option<Bound<'py, PyAny>>,
    seed: Option<Bound<'py, PyAny>>,
    max_depth: Option<Bound<'py, PyAny>>,
    threads: Option<Bound<'py, PyAny>>,
    illuminance: bool,
    caustics: Option<&str>,
    exposure_ev: Option<f64>,
    units: &str,
    target_error: Option<f64>,
    target_fraction: f64,
    target_floor_cd_m2: Option<f64>,
    max_spp: Option<Bound<'py, PyAny>>,
    max_time_s: Option<f64>,
    checkpoint_interval_s: Option<f64>,
    resume: bool,
    overwrite: bool,
    save_state: bool,
    falsecolour: bool,
    shard: Option<&str>,
    alpha_opic: bool,
    mesopic: bool,
    spectral_bands: Option<Bound<'py, PyAny>>,
    progress: Option<Bound<'py, PyAny>>,
    cancel: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    // The command line's checks, with the messages naming the arguments.
    let n = Counts::check(&spp, &seed, &max_depth, &threads, &max_spp, &spectral_bands)?;
    check_exposure(exposure_ev)?;
    check_target_limits(target_fraction, target_floor_cd_m2)?;
    args::callbacks(&progress, &cancel)?;
    let caustics = caustics_of(caustics)?;
    let units = units_of(units)?;
    check_target_error(target_error)?;
    let job = RenderJob {
        scene,
        overrides: Overrides {
            spp: n.spp,
            seed: n.seed,
            max_depth: n.max_depth,
            illuminance,
            caustics,
            ..Default::default()
        },
        out: Some(out),
        threads: n.threads,
        exposure_ev,
        units,
        target: target_error.map(|relative| TargetError {
            relative,
            fraction: target_fraction,
            floor_cd_m2: target_floor_cd_m2,
        }),
        max_spp: n.max_spp,
        max_time: seconds("max_time_s", max_time_s)?,
        checkpoint_interval: seconds("checkpoint_interval_s", checkpoint_interval_s)?
            .filter(|d| !d.is_zero()),
        resume,
        overwrite,
        save_state,
        falsecolour,
        report_html: false,
        shard: shard
            .map(job::shard::parse_from_env)
            .transpose()
            .map_err(error)?,
        health: crate::film::HealthChannels {
            melanopic: alpha_opic,
            mesopic,
            spectral_bands: n.spectral_bands,
        },
    };
    let (outputs, warnings) = run_watched(py, &job, &progress, &cancel)?;
    result_dict(py, &job, &outputs, warnings)
}

/// The integer arguments of `render`, checked in the command line's ranges.
struct Counts {
    spp: Option<u32>,
    seed: Option<u64>,
    max_depth: Option<u32>,
    threads: Option<usize>,
    max_spp: Option<u32>,
    spectral_bands: usize,
}

impl Counts {
    fn check(
        spp: &Option<Bound<'_, PyAny>>,
        seed: &Option<Bound<'_, PyAny>>,
        max_depth: &Option<Bound<'_, PyAny>>,
        threads: &Option<Bound<'_, PyAny>>,
        max_spp: &Option<Bound<'_, PyAny>>,
        spectral_bands: &Option<Bound<'_, PyAny>>,
    ) -> PyResult<Counts> {
        let spp = args::opt_int_in(spp, "spp", 1, u32::MAX as u64)?.map(|n| n as u32);
        let seed = args::opt_int_in(seed, "seed", 0, u64::MAX)?;
        let max_depth =
            args::opt_int_in(max_depth, "max_depth", 0, u32::MAX as u64)?.map(|n| n as u32);
        let threads =
            args::opt_int_in(threads, "threads", 1, job::max_threads() as u64)?.map(|n| n as usize);
        let max_spp = args::opt_int_in(max_spp, "max_spp", 1, u32::MAX as u64)?.map(|n| n as u32);
        let spectral_bands = args::opt_int_in(
            spectral_bands,
            "spectral_bands",
            0,
            crate::film::MAX_SPECTRAL_BANDS as u64,
        )?
        .unwrap_or(0) as usize;
        Ok(Counts {
            spp,
            seed,
            max_depth,
            threads,
            max_spp,
            spectral_bands,
        })
    }
}

/// `target_fraction` in (0, 1] and `target_floor_cd_m2`, when given, ≥ 0.
fn check_target_limits(target_fraction: f64, target_floor_cd_m2: Option<f64>) -> PyResult<()> {
    args::number(
        "target_fraction",
        target_fraction,
        "a fraction in (0, 1]",
        |f| f > 0.0 && f <= 1.0,
    )?;
    if let Some(f) = target_floor_cd_m2 {
        args::number(
            "target_floor_cd_m2",
            f,
            "a luminance ≥ 0 in cd/m²",
            |f| f >= 0.0,
        )?;
    }
    Ok(())
}

/// `target_error`, when given, strictly between 0 and 1.
fn check_target_error(target_error: Option<f64>) -> PyResult<()> {
    if let Some(t) = target_error {
        args::number(
            "target_error",
            t,
            "strictly between 0 and 1 (a fraction: 0.01 = 1 %)",
            |t| t > 0.0 && t < 1.0,
        )?;
    }
    Ok(())
}

/// The `caustics` argument as the scene setting it overrides.
fn caustics_of(caustics: Option<&str>) -> PyResult<Option<crate::world::Caustics>> {
    match caustics {
        None => Ok(None),
        Some("light-tracing") => Ok(Some(crate::world::Caustics::LightTracing)),
        Some("path-tracing") => Ok(Some(crate::world::Caustics::PathTracing)),
        Some(c) => Err(error_msg(format!(
            "caustics must be \"light-tracing\" or \"path-tracing\", got {c:?}"
        ))),
    }
}

/// The `units` argument: "si" or "imperial".
fn units_of(units: &str) -> PyResult<UnitSystem> {
    match units {
        "si" => Ok(UnitSystem::Si),
        "imperial" => Ok(UnitSystem::Imperial),
        u => Err(error_msg(format!(
            "units must be \"si\" or \"imperial\", got {u:?}"
        ))),
    }
}

/// What the calling thread keeps while it watches the job.
struct Watch<'a, 'py> {
    progress: &'a Option<Bound<'py, PyAny>>,
    cancel: &'a Option<Bound<'py, PyAny>>,
    t0: Instant,
    /// The job's most samples, from its start.
    total: u64,
    warnings: Vec<String>,
    /// Why the caller stopped the job: a Python exception to raise (Ctrl-C, a failing
    /// callback) or a cancellation.
    raised: Option<PyErr>,
    cancelled: bool,
}

impl Watch<'_, '_> {
    /// Handles one event (`None`: the wait timed out), then asks the cancel event and Python's
    /// signal handlers whether to stop; a stop request sets `stop`.
    fn step(&mut self, py: Python<'_>, event: Option<Event>, stop: &AtomicBool) {
        let ask_stop = match event {
            Some(Event::Start(n)) => {
                self.total = n;
                call(self.progress, 0, self.total, self.t0)
            }
            Some(Event::Pass(st)) => call(
                self.progress,
                st.samples,
                self.total.max(st.max_samples),
                self.t0,
            ),
            Some(Event::Rendered) => Ok(false),
            Some(Event::Warning(w)) => {
                self.warnings.push(w);
                Ok(false)
            }
            None => Ok(false),
        };
        let ask_stop = ask_stop.and_then(|s| Ok(s || is_set(self.cancel)?));
        let ask_stop = ask_stop.and_then(|s| py.check_signals().map(|()| s));
        match ask_stop {
            Ok(false) => {}
            Ok(true) => {
                self.cancelled = true;
                stop.store(true, Ordering::SeqCst);
            }
            Err(e) => {
                self.raised.get_or_insert(e);
                stop.store(true, Ordering::SeqCst);
            }
        }
    }
}

/// Runs `job` on a worker thread while this thread forwards its progress and watches for a
/// stop request. Returns its outputs and warnings, or why it did not finish.
fn run_watched(
    py: Python<'_>,
    job: &RenderJob,
    progress: &Option<Bound<'_, PyAny>>,
    cancel: &Option<Bound<'_, PyAny>>,
) -> PyResult<(job::RenderOutputs, Vec<String>)> {
    let stop = AtomicBool::new(false);
    let (tx, rx) = mpsc::channel();
    // A Mutex makes the receiver shareable with the interpreter released (it is never contended).
    let rx = Mutex::new(rx);
    let mut watch = Watch {
        progress,
        cancel,
        t0: Instant::now(),
        total: 0,
        warnings: Vec::new(),
        raised: None,
        cancelled: false,
    };
    let result = std::thread::scope(|s| {
        let worker = s.spawn(|| job::run(job, &mut Forward(tx), &stop));
        loop {
            let event = py.detach(|| {
                rx.lock()
                    .expect("only this thread locks it")
                    .recv_timeout(POLL)
            });
            let event = match event {
                Ok(e) => Some(e),
                Err(mpsc::RecvTimeoutError::Timeout) => None,
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
            };
            watch.step(py, event, &stop);
        }
        // The job ends soon after a stop request: at the end of its pass or measurement.
        py.detach(|| worker.join())
    });
    let outputs = match result {
        Ok(r) => r.map_err(error)?,
        // A panic is a bug in candela; Python gets an exception it can catch, not a
        // PanicException (a BaseException).
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            return Err(error_msg(format!(
                "internal error in candela (please report it): the render failed: {what}"
            )));
        }
    };
    if let Some(e) = watch.raised {
        return Err(e);
    }
    check_finished(&outputs, watch.cancelled)?;
    Ok((outputs, watch.warnings))
}

/// A [`Cancelled`] error saying what a stopped job wrote; `Ok` if it finished.
fn check_finished(outputs: &job::RenderOutputs, cancelled: bool) -> PyResult<()> {
    if outputs.outcome == Outcome::Finished {
        return Ok(());
    }
    let what = match outputs.outcome {
        Outcome::InterruptedBeforeFirstPass => {
            "before its first pass ended: nothing was written".to_string()
        }
        Outcome::InterruptedRender => format!(
            "during the render: a checkpoint was written ({}, {})",
            outputs.exr_path.display(),
            outputs.state_path.display()
        ),
        _ => format!(
            "during the meters and grids: the images were written ({}), no report",
            outputs.exr_path.display()
        ),
    };
    let why = if cancelled { "cancelled" } else { "stopped" };
    Err(Cancelled::new_err(format!("render {why} {what}")))
}

/// Calls `progress(samples_done, samples_total, elapsed_s)`; true if it returned False.
fn call(progress: &Option<Bound<'_, PyAny>>, done: u64, total: u64, t0: Instant) -> PyResult<bool> {
    let Some(p) = progress else {
        return Ok(false);
    };
    let r = p.call1((done, total, t0.elapsed().as_secs_f64()))?;
    // Only an explicit False stops: a callback that returns nothing goes on.
    Ok(r.is_instance_of::<pyo3::types::PyBool>() && !r.is_truthy()?)
}

/// Whether the cancel event (anything with `is_set()`, e.g. `threading.Event`) is set.
fn is_set(cancel: &Option<Bound<'_, PyAny>>) -> PyResult<bool> {
    match cancel {
        None => Ok(false),
        Some(c) => c.call_method0("is_set")?.is_truthy(),
    }
}

/// The result: the EXR's channels as (height, width) float32 arrays, the report and paths.
fn result_dict<'py>(
    py: Python<'py>,
    job: &RenderJob,
    outputs: &job::RenderOutputs,
    warnings: Vec<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let film = &outputs.render.film;
    let mut layers =
        job::files::film_layers(&job.scene.display().to_string(), film, film.e.is_some());
    if job.health.melanopic || job.health.mesopic {
        // The light-and-health channels are derived as the EXR is written: take them from it.
        let written = py
            .detach(|| crate::output::read_exr(&outputs.exr_path))
            .map_err(|e| error(e.into()))?;
        let have: std::collections::HashSet<String> =
            layers.channels.iter().map(|(n, _)| n.clone()).collect();
        layers.channels.extend(
            written
                .channels
                .into_iter()
                .filter(|(n, _)| !have.contains(n)),
        );
    }
    let channels = super::files::channel_dict(py, &layers)?;
    let d = PyDict::new(py);
    d.set_item("channels", channels)?;
    let report = read_report(&outputs.report_path)?;
    d.set_item("report_json", report)?;
    d.set_item("exr_path", &outputs.exr_path)?;
    d.set_item("png_path", &outputs.png_path)?;
    d.set_item("report_path", &outputs.report_path)?;
    d.set_item("outputs", &outputs.outputs)?;
    d.set_item("warnings", warnings)?;
    d.set_item("truncation", &outputs.truncation)?;
    d.set_item("samples_per_pixel", film.samples_per_pixel())?;
    d.set_item("elapsed_s", outputs.render.elapsed.as_secs_f64())?;
    d.set_item("samples_per_second", outputs.samples_per_second())?;
    Ok(d)
}

/// The report a job just wrote, read as every input is (a file replaced meanwhile by a FIFO
/// or something huge is refused).
fn read_report(path: &std::path::Path) -> PyResult<String> {
    crate::limits::read_text(path, crate::limits::MAX_TEXT_BYTES).map_err(|e| {
        super::file_error(
            e.raw_os_error(),
            format!("cannot read the report {}: {e}", path.display()),
        )
    })
}

/// Merges render states or shards as `candela merge` does ([`job::merge_with`]); see
/// `candela.merge` (python/candela) for the result.
#[pyfunction]
#[pyo3(signature = (states, out, *, exposure_ev=None, partial=false))]
fn merge<'py>(
    py: Python<'py>,
    states: Vec<PathBuf>,
    out: PathBuf,
    exposure_ev: Option<f64>,
    partial: bool,
) -> PyResult<Bound<'py, PyDict>> {
    check_exposure(exposure_ev)?;
    let options = job::MergeOptions {
        exposure_ev,
        partial,
    };
    let m = py
        .detach(|| job::merge_with(&states, &out, &options))
        .map_err(error)?;
    let layers = py
        .detach(|| crate::output::read_exr(&m.exr_path))
        .map_err(|e| error(e.into()))?;
    let d = PyDict::new(py);
    d.set_item("channels", super::files::channel_dict(py, &layers)?)?;
    d.set_item("exr_path", &m.exr_path)?;
    d.set_item("png_path", &m.png_path)?;
    d.set_item("hdr_path", &m.hdr_path)?;
    d.set_item("state_path", &m.state_path)?;
    d.set_item("report_path", &m.report_path)?;
    d.set_item("renders", m.renders)?;
    d.set_item("seeds", &m.seeds)?;
    d.set_item("samples_per_pixel", m.samples_per_pixel)?;
    let shards = match &m.shards {
        None => None,
        Some(s) => {
            let sd = PyDict::new(py);
            sd.set_item("count", s.count)?;
            sd.set_item("spp_per_shard", s.spp_per_shard)?;
            sd.set_item("merged", &s.merged)?;
            sd.set_item("missing", &s.missing)?;
            sd.set_item("unfinished", &s.unfinished)?;
            sd.set_item("partial", s.partial)?;
            Some(sd)
        }
    };
    d.set_item("shards", shards)?;
    let report = m.report_path.as_deref().map(read_report).transpose()?;
    d.set_item("report_json", report)?;
    Ok(d)
}

pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(merge, m)?)?;
    Ok(())
}

/// `exposure_ev`, when given, within the command line's range for `--exposure`.
fn check_exposure(exposure_ev: Option<f64>) -> PyResult<()> {
    if let Some(ev) = exposure_ev {
        let max = job::MAX_ABS_EXPOSURE_EV;
        args::number(
            "exposure_ev",
            ev,
            &format!("a finite number of EV between -{max} and {max}"),
            |v| v.abs() <= max,
        )?;
    }
    Ok(())
}
