//! `candela glare`: reads a fisheye luminance image (candela EXR or Radiance HDR), evaluates
//! its glare with [`candela::glare`] and prints the indices with their 95 % intervals.

use std::path::PathBuf;

use candela::glare::file::read_glare_image;
use candela::glare::{
    evaluate_uncertain, Background, GlareOptions, Interval, PositionIndexUp, Task, Threshold,
    UncertainGlare, UncertainOptions,
};

/// Arguments of `candela glare`.
#[derive(clap::Args, Debug, Clone)]
pub struct GlareArgs {
    /// Fisheye image: an EXR written by `candela render` (its `projection` attribute and
    /// per-pixel standard errors are used) or a Radiance picture with a `VIEW=` line.
    pub image: PathBuf,
    /// Glare-pixel threshold as evalglare's `-b`: above 100 a luminance in cd/m², else a
    /// multiple of the image's mean luminance (default: 2000 cd/m²).
    #[arg(long)]
    pub threshold: Option<f64>,
    /// Search angle in radians (evalglare `-r`): glare pixels within half of it merge.
    #[arg(long, default_value_t = 0.2)]
    pub search_angle: f64,
    /// Do not split sources' peaks above 50 000 cd/m² into sources of their own (evalglare `-x`).
    #[arg(long, conflicts_with = "peak_limit")]
    pub no_peaks: bool,
    /// Peak extraction limit in cd/m² (evalglare `-Y`): the pixels of a source at or above it
    /// become sources of their own when any glare pixel exceeds it (default 50 000).
    #[arg(long, value_name = "CD_M2")]
    pub peak_limit: Option<f64>,
    /// Background luminance of UGR and DGI (evalglare `-q`): `cie` (E_v − E_dir)/π (`-q 0`,
    /// default), `mean` the mean luminance outside the sources (`-q 1`), `ev-over-pi` E_v/π
    /// (`-q 2`).
    #[arg(long, default_value = "cie", value_parser = ["cie", "mean", "ev-over-pi"])]
    pub background: String,
    /// The up vector of the position index: `as-given` the view's up (Radiance `-vu`) as
    /// given, as evalglare takes it (default); `perpendicular` made perpendicular to the line
    /// of sight, the image's vertical.
    #[arg(long, default_value = "as-given", value_parser = ["as-given", "perpendicular"])]
    pub position_index_up: String,
    /// Apply DGP's low-light correction below 1000 lx (evalglare `-C l+`).
    #[arg(long)]
    pub low_light: bool,
    /// Task zone as evalglare's `-t`/`-T x y angle`: the pixels within half of ANGLE (rad) of
    /// the direction of pixel (X, Y), X from the left and Y from the bottom row, as evalglare
    /// counts them; the glare-pixel threshold becomes 5 × the zone's mean luminance (or
    /// `--threshold` times it, at most 100).
    #[arg(long, value_name = "X,Y,ANGLE")]
    pub task: Option<String>,
    /// Perturbed images drawn for the intervals.
    #[arg(long, default_value_t = 64)]
    pub draws: usize,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

impl GlareArgs {
    /// The command's defaults for `image` (text output).
    pub fn defaults_for(image: PathBuf) -> Self {
        GlareArgs {
            image,
            threshold: None,
            search_angle: 0.2,
            no_peaks: false,
            peak_limit: None,
            background: "cie".into(),
            position_index_up: "as-given".into(),
            low_light: false,
            task: None,
            draws: 64,
            json: false,
        }
    }
}

/// Runs the command: the text (or JSON) to print.
pub fn run(args: &GlareArgs) -> anyhow::Result<String> {
    let (g, has_errors) = evaluate(args)?;
    Ok(if args.json {
        json(&g)
    } else {
        text(&g, has_errors)
    })
}

/// One evaluation printed both ways: the text and the JSON (for `render --glare
/// --report-html`, which prints the one and embeds the other).
pub fn run_text_and_json(args: &GlareArgs) -> anyhow::Result<(String, String)> {
    let (g, has_errors) = evaluate(args)?;
    Ok((text(&g, has_errors), json(&g)))
}

/// The evaluation `args` asks for, and whether the image has per-pixel standard errors.
fn evaluate(args: &GlareArgs) -> anyhow::Result<(UncertainGlare, bool)> {
    let mut opt = GlareOptions::default();
    if let Some(b) = args.threshold {
        if !(b.is_finite() && b > 0.0) {
            return Err(super::usage(format!(
                "--threshold must be a positive number, got {b}"
            )));
        }
        opt.detect.threshold = Threshold::from_evalglare_b(b);
    }
    if !(args.search_angle.is_finite() && args.search_angle > 0.0) {
        return Err(super::usage(format!(
            "--search-angle must be a positive angle in radians, got {}",
            args.search_angle
        )));
    }
    super::check_draws(args.draws)?;
    opt.detect.search_angle_rad = args.search_angle;
    if args.no_peaks {
        opt.detect.peak_limit_cd_m2 = None;
    }
    if let Some(y) = args.peak_limit {
        if !(y.is_finite() && y > 0.0) {
            return Err(super::usage(format!(
                "--peak-limit must be a positive luminance in cd/m², got {y}"
            )));
        }
        opt.detect.peak_limit_cd_m2 = Some(y);
    }
    opt.background = match args.background.as_str() {
        "mean" => Background::Mean,
        "ev-over-pi" => Background::EvOverPi,
        _ => Background::Cie,
    };
    opt.position_index_up = match args.position_index_up.as_str() {
        "perpendicular" => PositionIndexUp::Perpendicular,
        _ => PositionIndexUp::AsGiven,
    };
    opt.low_light_correction = args.low_light;
    let task = args.task.as_deref().map(parse_task).transpose()?;
    let img = read_glare_image(&args.image)?;
    if let Some((x, y, angle_rad)) = task {
        if x >= img.width || y >= img.height {
            return Err(super::usage(format!(
                "--task: pixel ({x}, {y}) is outside the {}×{} image",
                img.width, img.height
            )));
        }
        opt.detect.task = Some(Task {
            col: x,
            row: img.height - 1 - y,
            angle_rad,
        });
        if args.threshold.is_none() {
            opt.detect.threshold = Threshold::Multiple { factor: 5.0 };
        }
    }
    let u = UncertainOptions {
        draws: args.draws,
        ..Default::default()
    };
    let g = evaluate_uncertain(&img, &opt, &u)
        .map_err(|e| anyhow::anyhow!("{}: {e}", args.image.display()))?;
    Ok((g, img.stderr_cd_m2.is_some()))
}

/// `X,Y,ANGLE`: a pixel (whole numbers) and an opening angle in radians.
fn parse_task(text: &str) -> anyhow::Result<(usize, usize, f64)> {
    let bad = || {
        super::usage(format!(
            "--task must be X,Y,ANGLE (pixel column and row from the bottom, opening angle in rad), got '{text}'"
        ))
    };
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [x, y, a] = parts.as_slice() else {
        return Err(bad());
    };
    let x: usize = x.parse().map_err(|_| bad())?;
    let y: usize = y.parse().map_err(|_| bad())?;
    let a: f64 = a.parse().map_err(|_| bad())?;
    if !(a.is_finite() && a > 0.0 && a <= std::f64::consts::TAU) {
        return Err(bad());
    }
    Ok((x, y, a))
}

fn interval_json(i: &Interval) -> serde_json::Value {
    serde_json::json!({
        "value": i.value,
        "estimate": i.estimate,
        "ci95": [i.low(), i.high()],
        "quantiles95": [i.quantiles.0, i.quantiles.1],
    })
}

/// An index's interval with the threshold selection's figures (`k` its place in
/// [`candela::glare::Membership::shift`]) and its verdict.
fn index_json(g: &UncertainGlare, name: &str, i: &Interval, k: usize) -> serde_json::Value {
    let mut v = interval_json(i);
    v["membership_shift"] = g.membership.shift[k].into();
    v["membership_reach"] = g.membership.reach[k].into();
    v["trusted"] = g.trusted(name).into();
    v
}

fn json(g: &UncertainGlare) -> String {
    let r = &g.result;
    let sources: Vec<_> = r
        .sources
        .iter()
        .map(|s| {
            serde_json::json!({
                "direction": s.direction,
                "solid_angle_sr": s.solid_angle_sr,
                "luminance_cd_m2": s.luminance_cd_m2,
                "position_index": s.position_index,
                "angle_from_view_deg": s.angle_from_view_rad.to_degrees(),
                "illuminance_lx": s.illuminance_lx,
                "pixels": s.pixel_count,
            })
        })
        .collect();
    let v = serde_json::json!({
        "dgp": index_json(g, "DGP", &g.dgp, 0),
        "dgi": index_json(g, "DGI", &g.dgi, 1),
        "ugr": index_json(g, "UGR", &g.ugr, 2),
        "vcp": index_json(g, "VCP", &g.vcp, 4),
        "cgi": index_json(g, "CGI", &g.cgi, 3),
        "ev_lx": interval_json(&g.ev_lx),
        "ev_direct_lx": r.ev_direct_lx,
        "background_cd_m2": r.background_cd_m2,
        "mean_luminance_cd_m2": r.mean_luminance_cd_m2,
        "threshold_cd_m2": r.threshold_cd_m2,
        "sources": sources,
        "membership": {
            "pixels_within_2se": g.membership.pixels_within_2se,
            "solid_angle_share_within_2se": g.membership.solid_angle_share_within_2se,
        },
        "untrusted": g.untrusted,
        "trustworthy": g.trustworthy,
        "warnings": g.warnings,
    });
    serde_json::to_string_pretty(&v).expect("JSON of numbers and strings")
}

fn text(g: &UncertainGlare, has_errors: bool) -> String {
    let r = &g.result;
    let row = |name: &str, i: &Interval, digits: usize| {
        if has_errors {
            format!(
                "{name:<4} {:.digits$}  (noise-free estimate {:.digits$}, 95 % CI {:.digits$} … {:.digits$})\n",
                i.value,
                i.estimate,
                i.low(),
                i.high()
            )
        } else {
            format!("{name:<4} {:.digits$}\n", i.value)
        }
    };
    let mut s = String::new();
    s += &row("DGP", &g.dgp, 3);
    s += &row("UGR", &g.ugr, 1);
    s += &row("DGI", &g.dgi, 1);
    s += &row("VCP", &g.vcp, 1);
    s += &row("CGI", &g.cgi, 1);
    s += &row("Ev", &g.ev_lx, 1);
    s += &format!(
        "threshold {:.0} cd/m², background {:.1} cd/m², {} glare source(s)\n",
        r.threshold_cd_m2,
        r.background_cd_m2,
        r.sources.len()
    );
    for (k, src) in r.sources.iter().enumerate() {
        s += &format!(
            "  source {}: {:.4} sr, {:.0} cd/m², {:.1}° from the line of sight, position index {:.2}, {:.1} lx\n",
            k + 1,
            src.solid_angle_sr,
            src.luminance_cd_m2,
            src.angle_from_view_rad.to_degrees(),
            src.position_index,
            src.illuminance_lx
        );
    }
    if !has_errors {
        s += "no per-pixel standard errors in the image: no intervals\n";
    } else if !g.trustworthy {
        for w in &g.warnings {
            s += &format!("warning: {w}\n");
        }
    }
    s
}
