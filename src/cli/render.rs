//! `candela render` and `candela merge`: their options, the progress bar, Ctrl-C, and the
//! closing summary; the work is [`candela::job::run`] and [`candela::job::merge`].

use anyhow::{Context, Result};
use candela::job::{
    self, GridResult, ImageDone, MeterResult, Outcome, Progress, RenderJob, RenderOutputs,
};
use candela::photometry::Quantity;
use candela::render::{StopReason, TargetError};
use candela::report::units::UnitSystem;
use candela::scene::Overrides;
use candela::world::MeterKind;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// Options of `candela render`.
#[derive(clap::Args)]
pub struct RenderOpts {
    /// Scene file: RON, or a glTF file (.gltf, .glb) rendered as a whole scene with its camera, lights and materials (docs/scene-format.md → glTF files as scenes).
    scene: PathBuf,
    /// The camera to render through: for a glTF scene, or a RON scene whose camera is `from_model`, the index of the model's camera node (0-based, in scene order) or its node or camera name (default: the first camera node, or `from_model.camera`).
    #[arg(long)]
    camera: Option<String>,
    /// Image size WIDTHxHEIGHT in pixels, e.g. 1280x720 (overrides camera.resolution; a glTF scene's default is 1024 pixels wide at its camera's aspect ratio).
    #[arg(long, value_parser = parse_resolution)]
    resolution: Option<Resolution>,
    /// Samples per pixel (overrides the scene's render.spp).
    #[arg(long)]
    spp: Option<u32>,
    /// Output directory, or output file name (NAME, NAME.exr or NAME.png: both files are written). Default: the current directory, named after the scene.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Worker threads (default: all cores; at most 16 per available core). The image does not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// Random seed (overrides render.seed).
    #[arg(long)]
    seed: Option<u64>,
    /// Most scattering events per path, at most 10000 (overrides render.max_depth; default: unlimited, paths end by Russian roulette).
    #[arg(long)]
    max_depth: Option<u32>,
    /// Exposure of the PNG in EV (ISO 100), between -100 and 100; default: automatic. Does not affect the EXR.
    #[arg(long, allow_hyphen_values = true)]
    exposure: Option<f64>,
    /// Also estimate the illuminance (lx) on the surface seen through each pixel (EXR channels E, stderr.E, mask.E).
    #[arg(long)]
    illuminance: bool,
    /// How caustics (light → smooth glass/metal → surface seen) are rendered: light-tracing (traced from the lights and connected to the camera; the default) or path-tracing (camera paths only). Overrides render.caustics.
    #[arg(long, value_parser = ["light-tracing", "path-tracing"])]
    caustics: Option<String>,
    /// Units of the report: si (lx, cd/m²) or imperial (fc, fL).
    #[arg(long, default_value = "si", value_parser = ["si", "imperial"])]
    units: String,
    /// Render until every pixel's luminance (and illuminance, with --illuminance) is known to this relative error at 95 % confidence, e.g. `1%` or `0.01`; samples go where the error is still large.
    #[arg(long, value_parser = parse_fraction)]
    target_error: Option<f64>,
    /// With --target-error: fraction of the eligible pixels that must meet it (default 1).
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    target_fraction: f64,
    /// With --target-error: pixels darker than this luminance (cd/m²) need not meet it (default: 0.1 % of the image's mean luminance).
    #[arg(long, allow_hyphen_values = true)]
    target_floor: Option<f64>,
    /// Upper bound of samples per pixel (default: --spp if given, else the scene's spp, or 65536 with --target-error; with --target-error it counts the decision buffer's samples too).
    #[arg(long)]
    max_spp: Option<u32>,
    /// Stop after this long (e.g. `90s`, `10m`, `2h`), at the end of the pass in progress.
    #[arg(long, value_parser = humantime::parse_duration)]
    max_time: Option<std::time::Duration>,
    /// Write a checkpoint (NAME.state, NAME.exr and NAME.png) this often (e.g. `60s`; `0s` disables).
    #[arg(long, value_parser = humantime::parse_duration, default_value = "60s")]
    checkpoint_interval: std::time::Duration,
    /// Continue from NAME.state (refused if the scene or its settings changed).
    #[arg(long, conflicts_with = "overwrite")]
    resume: bool,
    /// Start afresh even if NAME.state exists, replacing it (without this or --resume an existing NAME.state is never replaced: the render is refused).
    #[arg(long)]
    overwrite: bool,
    /// Also write NAME.state at the end (for --resume to more samples, or `candela merge`).
    #[arg(long)]
    save_state: bool,
    /// Also write false-colour maps NAME.luminance.png (and NAME.illuminance.png with --illuminance), automatic range; `candela falsecolour` offers every option.
    #[arg(long)]
    falsecolour: bool,
    /// After the render, evaluate the glare of the image as `candela glare NAME.exr` does with its defaults (DGP, UGR, DGI, VCP, CGI, E_v with 95 % intervals; meant for a fisheye camera) and print it.
    #[arg(long)]
    glare: bool,
    /// Render shard I of N (0-based): samples I·spp … (I+1)·spp − 1 of every pixel, so N shards at --spp S merge (`candela merge`) into the render at N·S spp. Writes NAME.shard-I-of-N.state (always) and images; rerunning the same command continues its state. `auto` takes I and N from a Slurm array (SLURM_ARRAY_TASK_ID − SLURM_ARRAY_TASK_MIN, SLURM_ARRAY_TASK_COUNT); `auto/N` takes I from SLURM_ARRAY_TASK_ID, AWS_BATCH_JOB_ARRAY_INDEX or JOB_COMPLETION_INDEX (Kubernetes). See docs/cluster.md.
    #[arg(long, value_name = "I/N|auto|auto/N")]
    shard: Option<String>,
    /// Also keep the melanopic equivalent daylight luminance per pixel (EXR channels melanopic.EDL, stderr.melanopic.EDL, cd/m²; CIE S 026) and, with --illuminance, the melanopic EDI (melanopic.EDI, stderr.melanopic.EDI, lx). Not with light-traced caustics.
    #[arg(long)]
    alpha_opic: bool,
    /// Also keep the scotopic luminance per pixel and write the CIE 191 mesopic luminance (EXR channels scotopic.L, mesopic.L, stderr.mesopic.L, mesopic.m). Not with light-traced caustics.
    #[arg(long)]
    mesopic: bool,
    /// Also keep N spectral bands (1 to 64) of equal width over 380–780 nm per pixel and write NAME.spectral.exr (spectral radiance, Fichet et al. 2021 layout). Not with light-traced caustics.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u16).range(0..=64))]
    spectral_bands: u16,
    /// Also write NAME.html, the self-contained HTML report (image with pixel probe, false colour, grids, meters, and the glare evaluation with --glare), as `candela report` does; see docs/report-html.md.
    #[arg(long)]
    report_html: bool,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

/// Options of `candela merge`.
#[derive(clap::Args)]
pub struct MergeOpts {
    /// State files written with --save-state (or checkpoints), or the shards of a render (NAME.shard-I-of-N.state, any order).
    #[arg(required = true, num_args = 1..)]
    states: Vec<PathBuf>,
    /// Output name: writes OUT.exr, OUT.png and OUT.state (and OUT.report.json for shards); an existing directory (or a path ending in `/`) writes DIR/merged.*. Refused if an output would replace an input.
    #[arg(short, long)]
    out: PathBuf,
    /// Exposure of the PNG in EV, between -100 and 100 (default: automatic).
    #[arg(long, allow_hyphen_values = true)]
    exposure: Option<f64>,
    /// Shards: merge those present even if some are missing or unfinished, giving the estimate of the samples they hold (said in OUT.report.json and on the output); without it such a merge is refused.
    #[arg(long)]
    partial: bool,
}

/// Width and height of the image, pixels.
#[derive(Clone, Copy)]
struct Resolution(u32, u32);

/// `1280x720` (or `1280×720`) → 1280 × 720 pixels.
fn parse_resolution(s: &str) -> Result<Resolution, String> {
    let bad = || format!("{s:?} is not WIDTHxHEIGHT in pixels (e.g. 1280x720)");
    let (w, h) = s.trim().split_once(['x', 'X', '×']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if w == 0 || h == 0 {
        return Err(format!("{s:?}: width and height must be at least 1 pixel"));
    }
    Ok(Resolution(w, h))
}

/// `1%`, `0.5 %` or `0.01` → 0.01.
fn parse_fraction(s: &str) -> Result<f64, String> {
    let t = s.trim();
    let (num, scale) = match t.strip_suffix('%') {
        Some(n) => (n.trim(), 0.01),
        None => (t, 1.0),
    };
    let v: f64 = num
        .parse()
        .map_err(|_| format!("{s:?} is not a number or a percentage"))?;
    let v = v * scale;
    if v.is_finite() && v > 0.0 && v < 1.0 {
        Ok(v)
    } else {
        Err(format!("{s:?} must lie strictly between 0 and 100 %"))
    }
}

/// Set by the first Ctrl-C: the job ends at the end of its pass with a checkpoint.
static STOP: AtomicBool = AtomicBool::new(false);

impl RenderOpts {
    fn job(&self) -> Result<RenderJob> {
        Ok(RenderJob {
            scene: self.scene.clone(),
            overrides: Overrides {
                spp: self.spp,
                seed: self.seed,
                max_depth: self.max_depth,
                illuminance: self.illuminance,
                caustics: self.caustics.as_deref().map(|c| match c {
                    "path-tracing" => candela::world::Caustics::PathTracing,
                    _ => candela::world::Caustics::LightTracing,
                }),
                resolution: self.resolution.map(|Resolution(w, h)| (w, h)),
                camera: self.camera.clone(),
            },
            out: self.out.clone(),
            threads: self.threads,
            exposure_ev: self.exposure,
            units: if self.units == "imperial" {
                UnitSystem::Imperial
            } else {
                UnitSystem::Si
            },
            target: self.target_error.map(|relative| TargetError {
                relative,
                fraction: self.target_fraction,
                floor_cd_m2: self.target_floor,
            }),
            max_spp: self.max_spp,
            max_time: self.max_time,
            checkpoint_interval: (!self.checkpoint_interval.is_zero())
                .then_some(self.checkpoint_interval),
            resume: self.resume,
            overwrite: self.overwrite,
            save_state: self.save_state,
            falsecolour: self.falsecolour,
            report_html: self.report_html,
            shard: self
                .shard
                .as_deref()
                .map(job::shard::parse_from_env)
                .transpose()?,
            health: candela::film::HealthChannels {
                melanopic: self.alpha_opic,
                mesopic: self.mesopic,
                spectral_bands: self.spectral_bands as usize,
            },
        })
    }
}

/// The progress bar, and the target message printed as soon as the image is done.
struct Bar {
    bar: ProgressBar,
    quiet: bool,
}

impl Progress for Bar {
    fn start(&mut self, max_samples: u64) -> Result<()> {
        // Ctrl-C ends the render with a checkpoint from here on; before, it ends the process.
        ctrlc::set_handler(|| {
            if STOP.swap(true, Ordering::SeqCst) {
                eprintln!("\ninterrupted twice: exiting without a checkpoint");
                candela::output::remove_temporary_files();
                std::process::exit(130);
            }
            eprintln!(
                "\ninterrupted: finishing with a checkpoint (press Ctrl-C again to quit at once)"
            );
        })
        .context("installing the Ctrl-C handler")?;
        if self.quiet {
            return Ok(());
        }
        self.bar = ProgressBar::new(max_samples);
        self.bar.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {wide_bar} {percent:>3}% ETA {eta} {msg}",
            )
            .expect("valid template"),
        );
        Ok(())
    }

    fn pass(&mut self, s: &candela::render::PassStatus) {
        self.bar.set_position(s.samples);
        if let Some(f) = s.converged_fraction {
            self.bar
                .set_message(format!("{:.1} % of pixels at target", 100.0 * f));
        }
    }

    fn warning(&mut self, message: &str) {
        let text = super::printable_lines(message);
        self.bar.suspend(|| eprintln!("warning: {text}"));
    }

    fn rendered(&mut self, done: &ImageDone) {
        self.bar.finish_and_clear();
        let (reason, last) = (done.reason, done.last);
        match (reason, &done.target) {
            (StopReason::TargetReached, Some(t)) => say!(
                "target reached: {:.1} % of eligible pixels have a 95 % interval within ±{} % ",
                100.0 * last.converged_fraction.unwrap_or(1.0),
                100.0 * t.relative
            ),
            (_, Some(t)) => say!(
                "target not reached ({}): {:.1} % of eligible pixels within ±{} % (goal {:.1} %)",
                if reason == StopReason::MaxTime {
                    "stopped at --max-time"
                } else {
                    "the pixels that miss it have --max-spp samples"
                },
                100.0 * last.converged_fraction.unwrap_or(0.0),
                100.0 * t.relative,
                100.0 * t.fraction
            ),
            (StopReason::MaxTime, None) => {
                say!("stopped at --max-time before every pixel had its samples")
            }
            _ => {}
        }
    }
}

/// `candela render`: exit code 130 when interrupted.
pub fn render(a: &RenderOpts) -> Result<()> {
    let job = a.job()?;
    // The options' own checks, whether or not the option is in effect (the job checks those
    // that are again).
    if let Some(n) = job.threads {
        job::check_threads("--threads", n)?;
    }
    job::check_exposure(job.exposure_ev)?;
    job::check_target(a.target_fraction, a.target_floor)?;
    let mut bar = Bar {
        bar: ProgressBar::hidden(),
        quiet: a.quiet,
    };
    let out = job::run(&job, &mut bar, &STOP);
    // Cleared before any message, error or not.
    bar.bar.finish_and_clear();
    let out = out?;
    exit_if_interrupted(&out);
    print_meters(&out.meters, job.units);
    print_grids(&out.grids, job.units);
    print_summary(&out);
    // One glare evaluation (its draws are the costly part) serves the printout and the page.
    let glare_json = if a.glare {
        Some(print_glare(&out)?)
    } else {
        None
    };
    if a.report_html {
        write_report_html(&out, glare_json.as_deref())?;
    }
    Ok(())
}

/// An output path as printed: control characters escaped.
fn shown(p: &Path) -> String {
    super::printable_lines(&p.display().to_string())
}

/// Says what an interrupted job wrote and exits with code 130; returns if the job finished.
fn exit_if_interrupted(out: &RenderOutputs) {
    let elapsed = out.render.elapsed.as_secs_f64();
    match out.outcome {
        Outcome::Finished => {}
        Outcome::InterruptedBeforeFirstPass => {
            eprintln!(
                "interrupted after {elapsed:.1} s, before the first pass finished: nothing written"
            );
            std::process::exit(130);
        }
        Outcome::InterruptedRender => {
            eprintln!(
                "interrupted after {elapsed:.1} s: wrote {} and {}; continue with --resume",
                shown(&out.exr_path),
                shown(&out.state_path)
            );
            std::process::exit(130);
        }
        Outcome::InterruptedMeasuring => {
            eprintln!(
                "interrupted during the meter and grid measurements: wrote {} and {} (the render had finished); no meter, grid or report output",
                shown(&out.exr_path),
                shown(&out.png_path)
            );
            std::process::exit(130);
        }
    }
}

/// Each meter's estimate (with its UGR and melanopic values), in `units`.
fn print_meters(meters: &[MeterResult], units: UnitSystem) {
    for m in meters {
        let q = match m.kind {
            MeterKind::Illuminance { .. } | MeterKind::Ugr { .. } | MeterKind::Melanopic { .. } => {
                Quantity::Illuminance
            }
            MeterKind::Luminance { .. } => Quantity::Luminance,
        };
        let (k, unit) = (units.from_si(q, 1.0), units.symbol(q));
        let e = &m.estimate;
        say!(
            "meter {:?}: {:.4} ± {:.4} {unit} (95 %, {} samples)",
            m.name,
            e.mean * k,
            e.ci95() * k,
            e.samples
        );
        if let Some(u) = &m.ugr {
            say!(
                "meter {:?}: UGR {:.1} (95 %: {:.1} to {:.1}), L_b {:.3} cd/m², {} luminaires",
                m.name,
                u.ugr,
                u.ugr_interval.0,
                u.ugr_interval.1,
                u.background_cd_m2,
                u.luminaires.len()
            );
        }
        if let Some(me) = &m.melanopic {
            say!(
                "meter {:?}: m-EDI {:.4} ± {:.4} {unit}, E_v {:.4} ± {:.4} {unit}, m-EDI/E_v {:.4} ± {:.4} (95 %)",
                m.name,
                me.m_edi_lx.mean * k,
                me.m_edi_lx.ci95() * k,
                me.illuminance_lx.mean * k,
                me.illuminance_lx.ci95() * k,
                me.ratio,
                candela::meter::t95(candela::meter::BATCHES - 1) * me.ratio_stderr
            );
        }
        if e.non_finite > 0 {
            eprintln!(
                "warning: meter {:?}: {} of {} samples were not finite and were counted as 0; its value is not reliable",
                m.name, e.non_finite, e.samples
            );
        }
    }
}

/// Each grid's illuminance statistics, in `units`.
fn print_grids(grids: &[GridResult], units: UnitSystem) {
    for g in grids {
        let s = &g.stats;
        let (k, u) = (
            units.from_si(Quantity::Illuminance, 1.0),
            units.symbol(Quantity::Illuminance),
        );
        say!(
            "grid {:?} ({}×{}): E_min {:.2} {u}, E_avg {:.2} {u}, E_max {:.2} {u}, U0 {:.3}",
            g.name,
            g.nx,
            g.ny,
            s.min * k,
            s.avg * k,
            s.max * k,
            s.u0.unwrap_or(0.0)
        );
        if g.non_finite > 0 {
            eprintln!(
                "warning: grid {:?}: {} samples were not finite and were counted as 0; its values are not reliable",
                g.name, g.non_finite
            );
        }
    }
}

/// The render's size, speed and files, and its warnings.
fn print_summary(out: &RenderOutputs) {
    let r = &out.render;
    say!(
        "rendered {}×{} at {:.1} spp (image samples) in {:.2} s on {} threads: {:.3} M samples/s, {:.3} M rays/s; mean luminance {:.4} cd/m²; wrote {} and {}",
        r.film.width,
        r.film.height,
        r.film.samples_per_pixel(),
        r.elapsed.as_secs_f64(),
        r.threads,
        out.samples_per_second() / 1e6,
        r.rays_per_second() / 1e6,
        r.film.mean_luminance_cd_m2(),
        out.exr_path.display(),
        out.png_path.display()
    );
    if r.stats.non_finite > 0 {
        eprintln!(
            "warning: {} samples gave a non-finite value and were counted as 0",
            r.stats.non_finite
        );
    }
    if let Some(w) = &out.truncation {
        eprintln!("warning: {w}");
    }
}

/// `--glare`: evaluates the image as `candela glare` does with its defaults and prints the
/// report; returns the evaluation as JSON.
fn print_glare(out: &RenderOutputs) -> Result<String> {
    let args = super::glare::GlareArgs::defaults_for(out.exr_path.clone());
    let (report, json) = super::glare::run_text_and_json(&args)?;
    say!("glare of {}:\n{}", shown(&out.exr_path), report.trim_end());
    Ok(json)
}

/// `--report-html`: writes NAME.html, with the glare evaluation if there is one.
fn write_report_html(out: &RenderOutputs, glare_json: Option<&str>) -> Result<()> {
    let glare = match glare_json {
        Some(j) => Some(serde_json::from_str(j)?),
        None => None,
    };
    let html = out.exr_path.with_extension("html");
    let r = candela::report::html::write_html_report(
        &out.exr_path,
        // A shard's render writes no report: its page has the image only.
        Some(out.report_path.as_path()).filter(|p| p.is_file()),
        glare.as_ref(),
        &html,
    )?;
    say!("wrote {} ({:.2} MB)", shown(&r.path), r.bytes as f64 / 1e6);
    Ok(())
}

/// `candela merge`.
pub fn merge(a: &MergeOpts) -> Result<()> {
    let options = job::MergeOptions {
        exposure_ev: a.exposure,
        partial: a.partial,
    };
    let m = job::merge_with(&a.states, &a.out, &options)?;
    let Some(s) = &m.shards else {
        say!(
            "merged {} renders (seeds {:?}): {:.1} image samples per pixel; wrote {}",
            m.renders,
            m.seeds,
            m.samples_per_pixel,
            m.exr_path.display()
        );
        return Ok(());
    };
    let list = |v: &[u32]| {
        v.iter()
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    if s.partial {
        say!(
            "PARTIAL estimate: {} of {} shards merged ({}); missing: [{}]; unfinished: [{}]",
            s.merged.len(),
            s.count,
            list(&s.merged),
            list(&s.missing),
            list(&s.unfinished)
        );
    }
    for meter in m.meters.iter().filter(|x| x.grid.is_none()) {
        let e = meter.estimate();
        let unit = if meter.luminance { "cd/m²" } else { "lx" };
        say!(
            "meter {:?}: {:.4} ± {:.4} {unit} (95 %, {} samples)",
            meter.name,
            e.mean,
            e.ci95(),
            e.samples
        );
    }
    say!(
        "merged shards [{}] of {} ({} spp each): {:.1} image samples per pixel; wrote {}, {}",
        list(&s.merged),
        s.count,
        s.spp_per_shard,
        m.samples_per_pixel,
        m.exr_path.display(),
        m.report_path
            .as_ref()
            .map_or(String::new(), |p| p.display().to_string())
    );
    Ok(())
}
