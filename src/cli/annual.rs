//! `candela annual`: a year of daylight on the scene's grids from a weather file
//! ([`candela::annual::run`]), with a progress bar; writes NAME.annual.json and
//! NAME.annual.csv and prints the summary.

use anyhow::{Context as _, Result};
use candela::annual::metrics::Thresholds;
use candela::annual::run::{AnnualSettings, Stage};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;

/// Arguments of `candela annual`.
#[derive(clap::Args, Debug, Clone)]
pub struct AnnualArgs {
    /// Scene file (RON) with at least one grid.
    pub scene: PathBuf,
    /// EnergyPlus weather file (EPW) of a year of hourly records (default: the file of the
    /// scene's `Weather` light).
    #[arg(long)]
    pub weather: Option<PathBuf>,
    /// Output name: writes OUT.annual.json and OUT.annual.csv (default: the scene's name in the
    /// current directory); an existing directory writes DIR/NAME.annual.*.
    #[arg(short, long)]
    pub out: Option<PathBuf>,
    /// Reinhart sky subdivision MF, 1–8 (1: Tregenza's 145 patches; 2: 577).
    #[arg(long, default_value_t = 2)]
    pub mf: u32,
    /// Paths per grid point for the sky coefficients.
    #[arg(long, default_value_t = 4096)]
    pub sky_samples: u64,
    /// Paths per grid point and sun-position node for the sun's inter-reflected light.
    #[arg(long, default_value_t = 4096)]
    pub sun_samples: u64,
    /// Shadow rays per grid point and sunny hour for the direct sun (ASE).
    #[arg(long, default_value_t = 64)]
    pub direct_samples: u64,
    /// Occupied hours, local standard time, as FROM-TO (e.g. 8-18: 8:00 to 18:00).
    #[arg(long, default_value = "8-18")]
    pub occupied: String,
    /// Daylight autonomy threshold, lx (sDA's too).
    #[arg(long, default_value_t = 300.0)]
    pub da: f64,
    /// sDA: the fraction of occupied hours a point must reach --da, 0–1.
    #[arg(long, default_value_t = 0.5)]
    pub sda_fraction: f64,
    /// UDI band, lx, as LOW-HIGH.
    #[arg(long, default_value = "100-3000")]
    pub udi: String,
    /// ASE: direct-sun illuminance threshold, lx.
    #[arg(long, default_value_t = 1000.0)]
    pub ase_lx: f64,
    /// ASE: hours above --ase-lx a point may have.
    #[arg(long, default_value_t = 250.0)]
    pub ase_hours: f64,
    /// Replicate years drawn for the 95 % intervals (0: none; else 2 … 100 000).
    #[arg(long, default_value_t = 200)]
    pub draws: usize,
    /// Also compute the annual glare (DGP every occupied hour) of the scene's camera view,
    /// meant for a 180° fisheye at eye height; writes OUT.annual-glare.csv.
    #[arg(long)]
    pub view: bool,
    /// Pixels along the view's longer side for --view, 8–1024.
    #[arg(long, default_value_t = 64)]
    pub view_resolution: usize,
    /// Camera paths per pixel for the view's sky coefficients.
    #[arg(long, default_value_t = 256)]
    pub view_sky_samples: u64,
    /// Camera paths per pixel and sun-position node for the sun on the view's surfaces.
    #[arg(long, default_value_t = 16)]
    pub view_sun_samples: u64,
    /// Also write the grid points' daylight coefficients: OUT.annual-sky-dc.csv (per point
    /// and sky patch, lx per cd/m²) and OUT.annual-sun-dc.csv (per sunny hour and point, lx
    /// per lx of direct-normal illuminance), each with its standard error.
    #[arg(long)]
    pub coefficients: bool,
    /// Seed (default: the scene's).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

fn range(flag: &str, s: &str) -> Result<(f64, f64)> {
    let bad = || {
        super::usage(format!(
            "{flag} must be LOW-HIGH with LOW < HIGH, got {s:?}"
        ))
    };
    let (a, b) = s.split_once('-').ok_or_else(bad)?;
    let (a, b): (f64, f64) = (
        a.trim().parse().map_err(|_| bad())?,
        b.trim().parse().map_err(|_| bad())?,
    );
    if !(a.is_finite() && b.is_finite() && a >= 0.0 && a < b) {
        return Err(bad());
    }
    Ok((a, b))
}

fn positive(flag: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(super::usage(format!(
            "{flag} must be a positive number, got {v}"
        )))
    }
}

/// The library settings of the arguments (usage errors for values no input makes valid).
pub fn settings(a: &AnnualArgs) -> Result<AnnualSettings> {
    let (from, to) = range("--occupied", &a.occupied)?;
    if from.fract() != 0.0 || to.fract() != 0.0 || to > 24.0 {
        return Err(super::usage(format!(
            "--occupied must be whole hours within 0-24, got {:?}",
            a.occupied
        )));
    }
    let udi = range("--udi", &a.udi)?;
    if !(a.sda_fraction.is_finite() && (0.0..=1.0).contains(&a.sda_fraction)) {
        return Err(super::usage(format!(
            "--sda-fraction must be within 0-1, got {}",
            a.sda_fraction
        )));
    }
    if !(a.ase_hours.is_finite() && a.ase_hours >= 0.0) {
        return Err(super::usage(format!(
            "--ase-hours must be 0 or more, got {}",
            a.ase_hours
        )));
    }
    super::check_draws(a.draws)?;
    for (flag, v) in [
        ("--sky-samples", a.sky_samples),
        ("--sun-samples", a.sun_samples),
        ("--direct-samples", a.direct_samples),
        ("--view-sky-samples", a.view_sky_samples),
        ("--view-sun-samples", a.view_sun_samples),
    ] {
        if v == 0 || v > 1 << 32 {
            return Err(super::usage(format!("{flag} must be 1 … 2^32, got {v}")));
        }
    }
    if !(8..=1024).contains(&a.view_resolution) {
        return Err(super::usage(format!(
            "--view-resolution must be 8 to 1024, got {}",
            a.view_resolution
        )));
    }
    if !(1..=8).contains(&a.mf) {
        return Err(super::usage(format!("--mf must be 1 to 8, got {}", a.mf)));
    }
    Ok(AnnualSettings {
        weather: a.weather.clone(),
        mf: a.mf,
        sky_samples: a.sky_samples,
        sun_samples: a.sun_samples,
        direct_samples: a.direct_samples,
        occupied: (from as usize, to as usize),
        thresholds: Thresholds {
            da_lx: positive("--da", a.da)?,
            sda_fraction: a.sda_fraction,
            udi_lx: udi,
            ase_lx: positive("--ase-lx", a.ase_lx)?,
            ase_hours: a.ase_hours,
        },
        draws: a.draws,
        seed: a.seed,
        view: a.view.then_some(candela::annual::view::ViewSettings {
            resolution: a.view_resolution,
            sky_samples: a.view_sky_samples,
            sun_samples: a.view_sun_samples,
        }),
        glare: Default::default(),
        keep_coefficients: a.coefficients,
        out: None,
    })
}

/// Runs the command: the summary to print.
pub fn run(a: &AnnualArgs) -> Result<String> {
    let mut s = settings(a)?;
    if let Some(n) = a.threads {
        candela::job::check_threads("--threads", n)?;
    }
    let (stem, json, csv) =
        candela::annual::output::output_paths(a.out.as_deref(), &a.scene, a.weather.as_deref())?;
    s.out = Some(stem.clone());
    let bar = if a.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(1)
    };
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {msg} {wide_bar} {pos}/{len} ETA {eta}",
        )
        .expect("valid template"),
    );
    let mut progress = |stage: Stage, done: usize, total: usize| {
        let msg = match stage {
            Stage::Sky => "sky coefficients",
            Stage::Sun => "sunny hours",
            Stage::Metrics => "hourly illuminance and metrics",
            Stage::View => "view: coefficients and hourly glare",
        };
        if done == 0 {
            bar.reset();
            bar.set_message(msg);
        }
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads.unwrap_or(0))
        .build()
        .context("starting the worker threads")?;
    let out = pool.install(|| candela::annual::run::run(&a.scene, &s, &mut progress));
    bar.finish_and_clear();
    let out = out?;
    let written = candela::annual::output::write_all(&stem, &out)?;
    let glare_csv = PathBuf::from(format!("{}.annual-glare.csv", stem.display()));
    let dc = [
        PathBuf::from(format!("{}.annual-sky-dc.csv", stem.display())),
        PathBuf::from(format!("{}.annual-sun-dc.csv", stem.display())),
    ];
    let maps = written.iter().filter(|w| w.ends_with(".png")).count();
    let view = match &out.view {
        Some(v) => format!(
            "wrote {} ({:.1} s view coefficients, {:.1} s hourly glare)\n",
            glare_csv.display(),
            v.seconds.0,
            v.seconds.1
        ),
        None => String::new(),
    } + &if out.coefficients.is_some() {
        format!("wrote {} and {}\n", dc[0].display(), dc[1].display())
    } else {
        String::new()
    };
    Ok(format!(
        "{}wrote {}, {} and {} heat maps ({:.1} s sky, {:.1} s sun, {:.1} s metrics)\n{view}",
        candela::annual::output::summary(&out),
        json.display(),
        csv.display(),
        maps,
        out.seconds.0,
        out.seconds.1,
        out.seconds.2
    ))
}
