//! The `candela` command line.

use anyhow::{bail, Context, Result};
use candela::colour::tables::Observer;
use candela::output::{self, Layers, PngSettings};
use candela::render::{render, RenderResult};
use candela::scene::{self, Overrides};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

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
    Render {
        /// Scene file (RON).
        scene: PathBuf,
        /// Samples per pixel (overrides the scene's render.spp).
        #[arg(long)]
        spp: Option<u32>,
        /// Output directory, or output file name (NAME, NAME.exr or NAME.png: both files are written). Default: the current directory, named after the scene.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Worker threads (default: all cores). The image does not depend on it.
        #[arg(long)]
        threads: Option<usize>,
        /// Random seed (overrides render.seed).
        #[arg(long)]
        seed: Option<u64>,
        /// Maximum path depth (overrides render.max_depth).
        #[arg(long)]
        max_depth: Option<u32>,
        /// Exposure of the PNG in EV (ISO 100); default: automatic. Does not affect the EXR.
        #[arg(long, allow_hyphen_values = true)]
        exposure: Option<f64>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
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
    /// Benchmark: samples/s and rays/s on the Cornell box and on a generated 1 M-triangle scene.
    Bench {
        /// Worker threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// Samples per pixel for each benchmark scene.
        #[arg(long, default_value_t = 16)]
        spp: u32,
        /// Triangles in the generated mesh scene (approximate).
        #[arg(long, default_value_t = 1_000_000)]
        triangles: usize,
    },
    /// Luminance, illuminance (95 % CI), XYZ, xy, u′v′, CCT, Duv and sRGB of a pixel or disc of an EXR; see docs/reports.md.
    Probe(candela::report::probe::ProbeArgs),
    /// False-colour PNG of luminance or illuminance with a legend; see docs/reports.md.
    Falsecolour(candela::report::falsecolour::FalsecolourArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render {
            scene,
            spp,
            out,
            threads,
            seed,
            max_depth,
            exposure,
            quiet,
        } => cmd_render(
            &scene,
            Overrides {
                spp,
                seed,
                max_depth,
            },
            out.as_deref(),
            threads,
            exposure,
            quiet,
        ),
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
            candela::cli_colour::spectrum_command(&source, obs, json).map(|s| print!("{s}"))
        }
        Command::Convert { value, from, to } => {
            candela::cli_colour::convert_command(value, &from, &to).map(|s| print!("{s}"))
        }
        Command::Bench {
            threads,
            spp,
            triangles,
        } => candela::bench::run(threads, spp, triangles),
        Command::Probe(args) => candela::report::probe::run(&args).map(|s| print!("{s}")),
        Command::Falsecolour(args) => {
            candela::report::falsecolour::run(&args).map(|s| print!("{s}"))
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Where to write: (`stem.exr`, `stem.png`).
fn output_paths(scene: &Path, out: Option<&Path>) -> (PathBuf, PathBuf) {
    let name = scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".into());
    let stem = match out {
        None => PathBuf::from(&name),
        Some(p) if p.is_dir() || p.as_os_str().to_string_lossy().ends_with('/') => p.join(&name),
        Some(p) => match p.extension().and_then(|e| e.to_str()) {
            Some("exr") | Some("png") => p.with_extension(""),
            _ => p.to_path_buf(),
        },
    };
    let mut exr = stem.clone().into_os_string();
    exr.push(".exr");
    let mut png = stem.into_os_string();
    png.push(".png");
    (exr.into(), png.into())
}

fn cmd_render(
    scene_path: &Path,
    overrides: Overrides,
    out: Option<&Path>,
    threads: Option<usize>,
    exposure: Option<f64>,
    quiet: bool,
) -> Result<()> {
    if let Some(0) = threads {
        bail!("--threads must be at least 1");
    }
    if let Some(ev) = exposure {
        if !ev.is_finite() {
            bail!("--exposure must be a finite number of EV, got {ev}");
        }
    }
    let world = scene::load_world(scene_path, &overrides)?;
    let (exr_path, png_path) = output_paths(scene_path, out);
    if let Some(dir) = exr_path.parent() {
        if !dir.as_os_str().is_empty() && !dir.is_dir() {
            bail!("output directory {} does not exist", dir.display());
        }
    }
    let (w, h, spp) = (world.camera.width, world.camera.height, world.settings.spp);
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::new(0);
        b.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {wide_bar} {percent:>3}% ETA {eta}",
            )
            .expect("valid template"),
        );
        b
    };
    let result = render(&world, threads, &|done, total| {
        bar.set_length(total);
        bar.set_position(done);
    })?;
    bar.finish_and_clear();
    write_outputs(scene_path, &result, &exr_path, &png_path, exposure)?;
    let mean_y = result
        .film
        .pixels
        .iter()
        .map(|p| p.mean_xyz()[1])
        .sum::<f64>()
        / (w * h) as f64;
    println!(
        "rendered {w}×{h} at {spp} spp in {:.2} s on {} threads: {:.3} M samples/s, {:.3} M rays/s; mean luminance {:.4} cd/m²; wrote {} and {}",
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

fn write_outputs(
    scene_path: &Path,
    result: &RenderResult,
    exr_path: &Path,
    png_path: &Path,
    exposure: Option<f64>,
) -> Result<()> {
    let film = &result.film;
    let xyz = film.xyz_image();
    let mut layers = Layers::from_xyz(film.width, film.height, &xyz, &film.y_stderr_image());
    layers.attributes.extend([
        (
            "software".to_string(),
            format!("candela {}", env!("CARGO_PKG_VERSION")),
        ),
        ("scene".to_string(), scene_path.display().to_string()),
        (
            "channel_units".to_string(),
            "X,Y,Z: absolute CIE 1931 2° tristimulus values, Y = luminance in cd/m^2; stderr.Y: standard error of Y in cd/m^2".to_string(),
        ),
        (
            "spp".to_string(),
            (film.total_samples() / (film.width * film.height) as u64).to_string(),
        ),
    ]);
    output::write_exr(exr_path, &layers)
        .with_context(|| format!("writing {}", exr_path.display()))?;
    output::write_srgb_png(
        png_path,
        film.width,
        film.height,
        &xyz,
        &PngSettings {
            exposure_ev: exposure,
        },
    )
    .with_context(|| format!("writing {}", png_path.display()))?;
    Ok(())
}
