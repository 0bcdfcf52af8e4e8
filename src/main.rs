//! The `candela` command line.

mod cli;

use anyhow::{bail, Context, Result};
use candela::colour::tables::Observer;
use candela::output::{self, Layers, PngSettings};
use candela::report::json::{grid_csv, report_json, write_text, ReportInput, Units};
use candela::report::units::Quantity;
use candela::scene::{self, Overrides};
use candela::world::measure::grid_csv_path;
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

/// `println!` / `print!` that ignore a closed standard output (e.g. `candela … | head -1`): the
/// outputs are files, and a reader that stopped early must not make the command fail or panic.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}
macro_rules! say_raw {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = write!(std::io::stdout(), $($arg)*);
    }};
}

#[derive(Parser)]
#[command(
    name = "candela",
    version,
    about = "A spectral path tracer whose output is measured light (cd/m², lux)."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to NAME.exr (absolute XYZ, Y = luminance in cd/m², plus its standard error) and NAME.png (sRGB).
    Render(Box<RenderOpts>),
    /// Combine independent renders of the same scene (different seeds) from their state files into one estimate.
    Merge {
        /// State files written with --save-state (or checkpoints).
        #[arg(required = true, num_args = 2..)]
        states: Vec<PathBuf>,
        /// Output name: writes OUT.exr, OUT.png and OUT.state; an existing directory (or a path ending in `/`) writes DIR/merged.exr, .png and .state. Refused if an output would replace an input.
        #[arg(short, long)]
        out: PathBuf,
        /// Exposure of the PNG in EV, between -100 and 100 (default: automatic).
        #[arg(long, allow_hyphen_values = true)]
        exposure: Option<f64>,
    },
    /// Colorimetry of a spectrum: XYZ, xy, u′v′, CCT, Duv, efficacy, S/P, sRGB, CRI.
    Spectrum {
        /// A CSV file (nm,value), a named spectrum (D65, FL2, LED-B3, …) or blackbody:3000K.
        source: String,
        /// Standard observer.
        #[arg(long, default_value = "1931", value_parser = ["1931", "1964"])]
        observer: String,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Convert a photometric value between units, e.g. `candela convert 100 lx fc`.
    Convert {
        #[arg(allow_hyphen_values = true)]
        value: f64,
        from: String,
        to: String,
    },
    /// Summary of an IES/EULUMDAT photometric file (flux, peak, beam and field angles) and a polar candela diagram (PNG).
    Luminaire {
        /// Photometric file: IES LM-63 (.ies) or EULUMDAT (.ldt).
        file: PathBuf,
        /// Where to write the polar diagram (default: FILE-STEM-polar.png in the current directory); refused if it is FILE itself.
        #[arg(long)]
        diagram: Option<PathBuf>,
    },
    /// Benchmark: samples/s and rays/s on the Cornell box and on a generated 1 M-triangle scene; `bench traversal` (BVH vs Embree) and `bench scaling` (10 k … 5 M triangles).
    Bench(candela::bench::BenchArgs),
    /// Luminance, illuminance (95 % CI), XYZ, xy, u′v′, CCT, Duv and sRGB of a pixel or disc of an EXR; see docs/reports.md.
    Probe(candela::report::probe::ProbeArgs),
    /// False-colour PNG of luminance or illuminance with a legend; see docs/reports.md.
    Falsecolour(candela::report::falsecolour::FalsecolourArgs),
}

/// Options of `candela render`.
#[derive(clap::Args)]
struct RenderOpts {
    /// Scene file (RON).
    scene: PathBuf,
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
    /// Maximum path depth (overrides render.max_depth).
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
    #[arg(long, default_value_t = 1.0)]
    target_fraction: f64,
    /// With --target-error: pixels darker than this luminance (cd/m²) need not meet it (default: 0.1 % of the image's mean luminance).
    #[arg(long)]
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
    #[arg(long)]
    resume: bool,
    /// Also write NAME.state at the end (for --resume to more samples, or `candela merge`).
    #[arg(long)]
    save_state: bool,
    /// Also write false-colour maps NAME.luminance.png (and NAME.illuminance.png with --illuminance), automatic range; `candela falsecolour` offers every option.
    #[arg(long)]
    falsecolour: bool,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(opts) => cmd_render(&opts),
        Command::Merge {
            states,
            out,
            exposure,
        } => cmd_merge(&states, &out, exposure),
        Command::Spectrum {
            source,
            observer,
            json,
        } => {
            let obs = if observer == "1964" {
                Observer::Cie1964_10
            } else {
                Observer::Cie1931_2
            };
            candela::cli_colour::spectrum_command(&source, obs, json).map(|s| say_raw!("{s}"))
        }
        Command::Convert { value, from, to } => {
            candela::cli_colour::convert_command(value, &from, &to).map(|s| say_raw!("{s}"))
        }
        Command::Luminaire { file, diagram } => {
            candela::luminaire::cli::run(&file, diagram.as_deref()).map(|s| say_raw!("{s}"))
        }
        Command::Bench(args) => candela::bench::main(&args),
        Command::Probe(args) => candela::report::probe::run(&args).map(|s| say_raw!("{s}")),
        Command::Falsecolour(args) => {
            candela::report::falsecolour::run(&args).map(|s| say_raw!("{s}"))
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", error_message(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes joined by ": ", like `{:#}`, but a cause whose text an outer
/// message already contains (e.g. "cannot read scene file X: {source}" whose source is also
/// the next cause in the chain) is not repeated.
fn error_message(e: &anyhow::Error) -> String {
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

/// Largest |EV| accepted by `--exposure`: ±100 EV is already 2^100 away from any real scene.
const MAX_ABS_EXPOSURE_EV: f64 = 100.0;

/// Refuses a non-finite `--exposure` or one beyond ±[`MAX_ABS_EXPOSURE_EV`].
fn check_exposure(exposure: Option<f64>) -> Result<()> {
    if let Some(ev) = exposure {
        if !(ev.is_finite() && ev.abs() <= MAX_ABS_EXPOSURE_EV) {
            // Large values in exponent form (-1e308 rather than 309 digits).
            let got = if ev.abs() >= 1e6 {
                format!("{ev:e}")
            } else {
                format!("{ev}")
            };
            bail!(
                "--exposure must be a finite number of EV between -{MAX_ABS_EXPOSURE_EV} and {MAX_ABS_EXPOSURE_EV}, got {got}"
            );
        }
    }
    Ok(())
}

/// Where to write: (`stem`, `stem.exr`, `stem.png`), the stem named after the scene.
fn output_paths(scene: &Path, out: Option<&Path>) -> (PathBuf, PathBuf, PathBuf) {
    let name = scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".into());
    let stem = output_stem(out, &name, &["exr", "png"]);
    let (exr, png) = (with_suffix(&stem, ".exr"), with_suffix(&stem, ".png"));
    (stem, exr, png)
}

/// The output stem of `--out` / `-o`: `name` if none is given; `DIR/name` for an existing
/// directory (or a path ending in `/`); otherwise the path, with one of `extensions` removed.
fn output_stem(out: Option<&Path>, name: &str, extensions: &[&str]) -> PathBuf {
    match out {
        None => PathBuf::from(name),
        Some(p) if p.is_dir() || p.as_os_str().to_string_lossy().ends_with('/') => p.join(name),
        Some(p) => match p.extension().and_then(|e| e.to_str()) {
            Some(e) if extensions.contains(&e) => p.with_extension(""),
            _ => p.to_path_buf(),
        },
    }
}

/// Refuses outputs at `stem` whose directory does not exist.
fn check_output_dir(stem: &Path) -> Result<()> {
    if let Some(dir) = stem.parent() {
        if !dir.as_os_str().is_empty() && !dir.is_dir() {
            bail!("output directory {} does not exist", dir.display());
        }
    }
    Ok(())
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

static STOP: AtomicBool = AtomicBool::new(false);

fn with_suffix(stem: &Path, suffix: &str) -> PathBuf {
    let mut p = stem.as_os_str().to_owned();
    p.push(suffix);
    PathBuf::from(p)
}

fn cmd_render(a: &RenderOpts) -> Result<()> {
    let scene_path = a.scene.as_path();
    let overrides = Overrides {
        spp: a.spp,
        seed: a.seed,
        max_depth: a.max_depth,
        illuminance: a.illuminance,
        caustics: a.caustics.as_deref().map(|c| match c {
            "path-tracing" => candela::world::Caustics::PathTracing,
            _ => candela::world::Caustics::LightTracing,
        }),
    };
    let (out, threads, exposure, quiet) = (a.out.as_deref(), a.threads, a.exposure, a.quiet);
    let units = if a.units == "imperial" {
        Units::Imperial
    } else {
        Units::Si
    };
    if let Some(n) = threads {
        candela::bench::check_threads("--threads", n)?;
    }
    check_exposure(exposure)?;
    if !(a.target_fraction > 0.0 && a.target_fraction <= 1.0) {
        bail!(
            "--target-fraction must lie in (0, 1], got {}",
            a.target_fraction
        );
    }
    if let Some(f) = a.target_floor {
        if !(f.is_finite() && f >= 0.0) {
            bail!("--target-floor must be a luminance ≥ 0 in cd/m², got {f}");
        }
    }
    if a.max_spp == Some(0) {
        bail!("--max-spp must be at least 1");
    }
    let world = scene::load_world_for(
        scene_path,
        &overrides,
        &scene::RunMode {
            adaptive: a.target_error.is_some(),
            falsecolour: a.falsecolour,
        },
    )?;
    let scene_bytes = std::fs::read(scene_path)
        .with_context(|| format!("cannot read scene file {}", scene_path.display()))?;
    let hash = candela::state::scene_hash(&scene_bytes, &world);
    let (stem, exr_path, png_path) = output_paths(scene_path, out);
    check_output_dir(&stem)?;
    let state_path = with_suffix(&stem, ".state");
    let (w, h) = (world.camera.width, world.camera.height);
    let target = a.target_error.map(|relative| candela::render::TargetError {
        relative,
        fraction: a.target_fraction,
        floor_cd_m2: a.target_floor,
    });
    let prog = candela::render::Progressive {
        max_spp: a.max_spp.or(overrides.spp).unwrap_or(if target.is_some() {
            65536
        } else {
            world.settings.spp
        }),
        target,
        max_time: a.max_time,
        checkpoint_interval: (!a.checkpoint_interval.is_zero()).then_some(a.checkpoint_interval),
    };
    let mut film = if a.resume {
        let st = candela::state::RenderState::load(&state_path)?;
        if st.scene_hash != hash || st.seed != world.settings.seed {
            bail!(
                "cannot resume from {}: the scene file {}, a file it refers to (mesh, spectrum, luminaire data) or its settings (seed, max depth, resolution, illuminance, caustics) changed since the state was written",
                state_path.display(),
                scene_path.display()
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
        if st.film.decision.is_some() != target.is_some() {
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
        st.film
    } else if target.is_some() {
        candela::film::Film::new_adaptive(w, h)
    } else {
        candela::film::Film::new(w, h)
    };
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
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::new(prog.max_spp as u64 * (w * h) as u64);
        b.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {wide_bar} {percent:>3}% ETA {eta} {msg}",
            )
            .expect("valid template"),
        );
        b
    };
    let mut last = candela::render::PassStatus::default();
    let write_checkpoint = |film: &candela::film::Film| -> Result<()> {
        candela::state::RenderState::new(scene_path, hash, &world, film.clone())
            .save(&state_path)?;
        write_exr(scene_path, &world, film, &exr_path)?;
        // The PNG too, so that the image pair on disk is always of the same estimate.
        write_png(film, &png_path, exposure)?;
        Ok(())
    };
    let (result, reason) = candela::render::render_progressive(
        &world,
        &mut film,
        threads,
        &prog,
        &STOP,
        &mut |s| {
            last = *s;
            bar.set_position(s.samples);
            if let Some(f) = s.converged_fraction {
                bar.set_message(format!("{:.1} % of pixels at target", 100.0 * f));
            }
        },
        &mut |f| write_checkpoint(f),
    )?;
    bar.finish_and_clear();
    if reason == candela::render::StopReason::Interrupted {
        if result.film.total_samples() == 0 {
            // No pass finished: an all-zero image would replace the files of an earlier render.
            eprintln!(
                "interrupted after {:.1} s, before the first pass finished: nothing written",
                result.elapsed.as_secs_f64()
            );
            std::process::exit(130);
        }
        write_checkpoint(&result.film)?;
        eprintln!(
            "interrupted after {:.1} s: wrote {} and {}; continue with --resume",
            result.elapsed.as_secs_f64(),
            exr_path.display(),
            state_path.display()
        );
        std::process::exit(130);
    }
    if a.save_state || a.resume || state_path.exists() {
        candela::state::RenderState::new(scene_path, hash, &world, result.film.clone())
            .save(&state_path)?;
    }
    match (reason, &target) {
        (candela::render::StopReason::TargetReached, Some(t)) => say!(
            "target reached: {:.1} % of eligible pixels have a 95 % interval within ±{} % ",
            100.0 * last.converged_fraction.unwrap_or(1.0),
            100.0 * t.relative
        ),
        (_, Some(t)) => say!(
            "target not reached ({}): {:.1} % of eligible pixels within ±{} % (goal {:.1} %)",
            if reason == candela::render::StopReason::MaxTime {
                "stopped at --max-time"
            } else {
                "the pixels that miss it have --max-spp samples"
            },
            100.0 * last.converged_fraction.unwrap_or(0.0),
            100.0 * t.relative,
            100.0 * t.fraction
        ),
        (candela::render::StopReason::MaxTime, None) => {
            say!("stopped at --max-time before every pixel had its samples")
        }
        _ => {}
    }
    let spp = result.film.total_samples() as f64 / (w * h) as f64;
    let t_measure = std::time::Instant::now();
    let measurements = candela::meter::measure_all_until(&world, &STOP);
    let measure_seconds = t_measure.elapsed().as_secs_f64();
    write_exr(scene_path, &world, &result.film, &exr_path)?;
    write_png(&result.film, &png_path, exposure)?;
    let Some(measurements) = measurements else {
        eprintln!(
            "interrupted during the meter and grid measurements: wrote {} and {} (the render had finished); no meter, grid or report output",
            exr_path.display(),
            png_path.display()
        );
        std::process::exit(130);
    };
    let mut outputs = vec![
        exr_path.display().to_string(),
        png_path.display().to_string(),
    ];
    for (k, (g, est)) in world.grids.iter().zip(&measurements.grids).enumerate() {
        let path = grid_csv_path(&stem, &g.name);
        write_text(&path, &grid_csv(&world, k, est, units))?;
        outputs.push(path.display().to_string());
        let png = path.with_extension("png");
        let values = candela::report::heatmap::GridValues {
            name: g.name.clone(),
            nx: g.nx as usize,
            ny: g.ny as usize,
            values: est.iter().map(|e| e.mean).collect(),
            stderr: est.iter().map(|e| e.stderr).collect(),
            size_m: (g.edge_u.length() as f64, g.edge_v.length() as f64),
        };
        let settings = candela::report::falsecolour::FalsecolourSettings {
            quantity: Quantity::Illuminance,
            units,
            ..Default::default()
        };
        candela::report::heatmap::write_grid_heatmap(&png, &values, &settings)?;
        outputs.push(png.display().to_string());
    }
    if a.falsecolour {
        let layers = output::read_exr(&exr_path)?;
        let mut quantities = vec![(Quantity::Luminance, ".luminance.png")];
        if world.settings.illuminance {
            quantities.push((Quantity::Illuminance, ".illuminance.png"));
        }
        for (q, suffix) in quantities {
            let path = with_suffix(&stem, suffix);
            let settings = candela::report::falsecolour::FalsecolourSettings {
                quantity: q,
                units,
                ..Default::default()
            };
            candela::report::falsecolour::write_falsecolour(&path, &layers, &settings)?;
            outputs.push(path.display().to_string());
        }
    }
    let report_path = {
        let mut p = stem.clone().into_os_string();
        p.push(".report.json");
        PathBuf::from(p)
    };
    let report = report_json(&ReportInput {
        scene_path,
        world: &world,
        render: &result,
        measurements: &measurements,
        measure_seconds,
        units,
        outputs,
        progressive: serde_json::json!({
            "stop_reason": format!("{reason:?}"),
            "passes": last.passes,
            "max_spp": prog.max_spp,
            "image_samples_per_pixel": spp,
            "target_relative_error_95": target.map(|t| t.relative),
            "target_fraction": target.map(|t| t.fraction),
            "target_floor_cd_m2": target.and_then(|t| t.floor_cd_m2),
            "fraction_of_eligible_pixels_at_target": last.converged_fraction,
            "max_time_s": a.max_time.map(|d| d.as_secs_f64()),
        }),
    });
    write_text(&report_path, &serde_json::to_string_pretty(&report)?)?;
    for (m, e) in world.meters.iter().zip(&measurements.meters) {
        let (k, unit) = match m.kind {
            candela::world::MeterKind::Illuminance { .. } => (
                units.from_si(Quantity::Illuminance, 1.0),
                units.symbol(Quantity::Illuminance),
            ),
            candela::world::MeterKind::Luminance { .. } => (
                units.from_si(Quantity::Luminance, 1.0),
                units.symbol(Quantity::Luminance),
            ),
        };
        say!(
            "meter {:?}: {:.4} ± {:.4} {unit} (95 %, {} samples)",
            m.name,
            e.mean * k,
            e.ci95() * k,
            e.samples
        );
    }
    for (g, est) in world.grids.iter().zip(&measurements.grids) {
        let s = candela::meter::grid_stats(est);
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
    }
    let mean_y = result
        .film
        .pixels
        .iter()
        .map(|p| p.mean_xyz()[1])
        .sum::<f64>()
        / (w * h) as f64;
    say!(
        "rendered {w}×{h} at {spp:.1} spp (image samples) in {:.2} s on {} threads: {:.3} M samples/s, {:.3} M rays/s; mean luminance {:.4} cd/m²; wrote {} and {}",
        result.elapsed.as_secs_f64(),
        result.threads,
        result.samples_per_second() / 1e6,
        result.rays_per_second() / 1e6,
        mean_y,
        exr_path.display(),
        png_path.display()
    );
    if result.stats.non_finite > 0 {
        eprintln!(
            "warning: {} samples gave a non-finite value and were counted as 0",
            result.stats.non_finite
        );
    }
    Ok(())
}

fn write_exr(
    scene_path: &Path,
    world: &candela::world::World,
    film: &candela::film::Film,
    exr_path: &Path,
) -> Result<()> {
    let layers = film_layers(
        &scene_path.display().to_string(),
        film,
        world.settings.illuminance,
    );
    output::write_exr(exr_path, &layers).context("cannot write the EXR")?;
    Ok(())
}

/// The EXR channels and attributes of a film (renders and merges alike).
fn film_layers(scene: &str, film: &candela::film::Film, illuminance: bool) -> Layers {
    let xyz = film.xyz_image();
    let mut layers = Layers::from_xyz(film.width, film.height, &xyz, &film.y_stderr_image());
    layers.attributes.extend([
        (
            "software".to_string(),
            format!("candela {}", env!("CARGO_PKG_VERSION")),
        ),
        ("scene".to_string(), scene.to_string()),
        (
            "channel_units".to_string(),
            "X,Y,Z: absolute CIE 1931 2° tristimulus values, Y = luminance in cd/m^2; stderr.Y: standard error of Y in cd/m^2".to_string(),
        ),
        (
            "spp".to_string(),
            format!("{:.2}", film.total_samples() as f64 / (film.width * film.height) as f64),
        ),
    ]);
    if illuminance {
        let (e, se, mask) = film.illuminance_images();
        layers.channels.extend([
            (output::CHANNEL_E.to_string(), e),
            (output::CHANNEL_E_STDERR.to_string(), se),
            (output::CHANNEL_E_MASK.to_string(), mask),
        ]);
        layers.attributes.push((
            "illuminance".to_string(),
            format!(
                "E: illuminance in lx on the surface seen through the pixel (hemisphere facing the camera), {} where the pixel sees no receiving surface; stderr.E: its standard error; mask.E: fraction of samples that saw a receiving surface",
                output::ILLUMINANCE_SENTINEL
            ),
        ));
    }
    layers
}

fn write_png(film: &candela::film::Film, png_path: &Path, exposure: Option<f64>) -> Result<()> {
    output::write_srgb_png(
        png_path,
        film.width,
        film.height,
        &film.xyz_image(),
        &PngSettings {
            exposure_ev: exposure,
        },
    )
    .context("cannot write the PNG")?;
    Ok(())
}

fn cmd_merge(states: &[PathBuf], out: &Path, exposure: Option<f64>) -> Result<()> {
    check_exposure(exposure)?;
    // Like `render --out`, a directory gets files named `merged.*`.
    let stem = output_stem(Some(out), "merged", &["exr", "png", "state"]);
    let exr_path = with_suffix(&stem, ".exr");
    let png_path = with_suffix(&stem, ".png");
    let state_path = with_suffix(&stem, ".state");
    check_output_dir(&stem).with_context(|| format!("-o {}", out.display()))?;
    for output in [&exr_path, &png_path, &state_path] {
        if let Some(input) = states.iter().find(|s| output::same_file(output, s)) {
            bail!(
                "-o {}: refusing to overwrite the input state file {} with the merged {}; choose another output name",
                out.display(),
                input.display(),
                output.display()
            );
        }
    }
    let mut loaded = Vec::new();
    for p in states {
        loaded.push((p, candela::state::RenderState::load(p)?));
    }
    let (p0, first) = &loaded[0];
    let mut film = first.film.clone();
    let mut seeds = first.seeds();
    for (p, s) in &loaded[1..] {
        if s.scene_hash != first.scene_hash
            || s.film.width != film.width
            || s.film.height != film.height
            || s.film.decision.is_some() != film.decision.is_some()
        {
            bail!(
                "{} and {} are renders of different scenes or settings and cannot be merged",
                p0.display(),
                p.display()
            );
        }
        if let Some(seed) = s.seeds().into_iter().find(|x| seeds.contains(x)) {
            bail!(
                "{} repeats seed {seed} of another input (directly or inside a merged state): renders with the same seed take the same samples, so merging them would count those samples twice; render with different --seed values",
                p.display()
            );
        }
        seeds.extend(s.seeds());
        film.merge(&s.film);
    }
    let mut layers = film_layers(&first.scene, &film, first.illuminance);
    layers
        .attributes
        .push(("merged_seeds".to_string(), format!("{seeds:?}")));
    output::write_exr(&exr_path, &layers).context("cannot write the EXR")?;
    write_png(&film, &png_path, exposure)?;
    let merged = candela::state::RenderState {
        seed: seeds[0],
        merged_seeds: seeds[1..].to_vec(),
        film,
        ..first.clone()
    };
    merged
        .save(&state_path)
        .context("cannot write the merged state")?;
    say!(
        "merged {} renders (seeds {seeds:?}): {:.1} image samples per pixel; wrote {}",
        loaded.len(),
        merged.film.total_samples() as f64 / (merged.film.width * merged.film.height) as f64,
        exr_path.display()
    );
    Ok(())
}
