//! `candela probe`: reads its arguments, probes the EXR (or Radiance HDR) with
//! [`candela::report::probe::probe_file`] and formats the result for the terminal (text, or
//! the JSON that docs/reports.md documents).

use std::path::PathBuf;

use anyhow::anyhow;
use candela::photometry::Quantity;
use candela::report::probe::{probe_file, Estimate, IlluminanceProbe, ProbeResult};
use candela::report::units::{format_sig, UnitSystem};
use serde_json::json;

/// Arguments of `candela probe`.
#[derive(clap::Args, Debug, Clone)]
pub struct ProbeArgs {
    /// EXR image written by `candela render` (channels X, Y, Z, stderr.Y; E, stderr.E, mask.E
    /// with --illuminance), or a Radiance HDR picture (luminance and colour, no error).
    pub exr: PathBuf,
    /// Column of the pixel, 0 = left.
    #[arg(allow_hyphen_values = true)]
    pub x: i64,
    /// Row of the pixel, 0 = top.
    #[arg(allow_hyphen_values = true)]
    pub y: i64,
    /// Average over every pixel whose centre is within R pixels of (X, Y).
    #[arg(long, allow_hyphen_values = true)]
    pub radius: Option<f64>,
    /// Print JSON (keys documented in docs/reports.md) instead of text.
    #[arg(long)]
    pub json: bool,
    /// si (cd/m², lx) or imperial (fL, fc).
    #[arg(long, default_value = "si", value_parser = parse_units)]
    pub units: UnitSystem,
}

/// clap value parser for `--units`.
pub fn parse_units(s: &str) -> Result<UnitSystem, String> {
    UnitSystem::parse(s).ok_or_else(|| format!("unknown unit system '{s}' (use si or imperial)"))
}

/// `candela probe`: returns the text (or JSON) to print.
pub fn run(args: &ProbeArgs) -> anyhow::Result<String> {
    if let Some(r) = args.radius {
        if !(r.is_finite() && r >= 0.0) {
            return Err(super::usage(format!(
                "--radius must be a finite number of pixels ≥ 0, got {r}"
            )));
        }
    }
    // Flatten to one line: the messages already name the file and their cause.
    let r = probe_file(&args.exr, args.x, args.y, args.radius, args.units)
        .map_err(|e| anyhow!("{e}"))?;
    let spectrum = spectral_rendition(&args.exr, r.x, r.y)?;
    if args.json {
        let mut v = r.to_json();
        v["file"] = json!(args.exr.display().to_string());
        if let Some(sp) = &spectrum {
            v["spectrum"] = sp.to_json();
        }
        Ok(serde_json::to_string_pretty(&v)? + "\n")
    } else {
        let mut t = text(&r, &args.exr.display().to_string());
        if let Some(sp) = &spectrum {
            t += &sp.text();
        }
        Ok(t)
    }
}

/// Colour rendition of one pixel's spectrum from the spectral image beside the EXR.
struct SpectrumProbe {
    file: String,
    bands: usize,
    rendition: Option<candela::colour::tm30::ColourRendition>,
    ra: f64,
    cqs_qa: Option<f64>,
}

impl SpectrumProbe {
    fn text(&self) -> String {
        let tm30 = match &self.rendition {
            Some(c) => format!("TM-30 Rf {:.1}, Rg {:.1}", c.rf, c.rg),
            None => "TM-30 undefined (black or outside the CCT range)".to_string(),
        };
        let cqs = match self.cqs_qa {
            Some(q) => format!("; CQS Qa {q:.1}"),
            None => String::new(),
        };
        format!(
            "  {:<13} {tm30}; CIE Ra {:.1}{cqs}   (the pixel's spectrum as a relative SPD, {} bands of {})\n",
            "rendition", self.ra, self.bands, self.file
        )
    }
    fn to_json(&self) -> serde_json::Value {
        json!({
            "file": self.file,
            "bands": self.bands,
            "relative_spd": true,
            "tm30_rf": self.rendition.as_ref().map(|c| c.rf),
            "tm30_rg": self.rendition.as_ref().map(|c| c.rg),
            "cri_ra": self.ra,
            "cqs_qa": self.cqs_qa,
        })
    }
}

/// With `NAME.spectral.exr` beside `NAME.exr` (`candela render --spectral-bands`), TM-30 and
/// CRI of pixel (x, y)'s spectrum, taken as a relative SPD: band values linearly
/// interpolated between the band centres onto 1 nm, held at the end bands' values out to
/// 380 and 780 nm, 0 outside.
fn spectral_rendition(
    exr: &std::path::Path,
    x: usize,
    y: usize,
) -> anyhow::Result<Option<SpectrumProbe>> {
    let name = exr.file_name().and_then(|n| n.to_str()).unwrap_or("");
    let Some(stem) = name.strip_suffix(".exr") else {
        return Ok(None);
    };
    let path = exr.with_file_name(format!("{stem}.spectral.exr"));
    if stem.ends_with(".spectral") || !path.is_file() {
        return Ok(None);
    }
    let layers = candela::output::read_exr(&path).map_err(|e| anyhow!("{e}"))?;
    let (nm, values) = candela::film::read_spectral_bands(&layers);
    if nm.len() < 2 || x >= layers.width || y >= layers.height {
        return Ok(None);
    }
    let i = y * layers.width + x;
    let v: Vec<f64> = values.iter().map(|b| b[i].max(0.0) as f64).collect();
    let mut table = [0.0f64; candela::colour::grid::LEN];
    for (k, t) in table.iter_mut().enumerate() {
        let l = 360.0 + k as f64;
        if !(candela::film::BANDS_START_NM..=candela::film::BANDS_END_NM).contains(&l) {
            continue;
        }
        let j = nm.partition_point(|&c| c <= l);
        *t = if j == 0 {
            v[0]
        } else if j == nm.len() {
            v[nm.len() - 1]
        } else {
            let f = (l - nm[j - 1]) / (nm[j] - nm[j - 1]);
            v[j - 1] * (1.0 - f) + v[j] * f
        };
    }
    if table.iter().all(|&t| t == 0.0) {
        return Ok(None);
    }
    Ok(Some(SpectrumProbe {
        file: path.display().to_string(),
        bands: nm.len(),
        rendition: candela::colour::tm30::colour_rendition(&table),
        ra: candela::colour::cri::colour_rendering_index(&table).ra,
        cqs_qa: Some(candela::colour::cqs::colour_quality_scale(&table).q_a)
            .filter(|q| q.is_finite()),
    }))
}

fn fmt3(v: [f64; 3], digits: usize) -> String {
    format!(
        "{:.*} {:.*} {:.*}",
        digits, v[0], digits, v[1], digits, v[2]
    )
}

fn estimate_text(e: &Estimate, unit: &str) -> String {
    match (e.stderr, e.ci95()) {
        (Some(se), Some((lo, hi))) => format!(
            "{} ± {} {unit}   (95 % CI {} … {}; standard error {})",
            format_sig(e.mean, 5),
            format_sig(e.t95 * se, 3),
            format_sig(lo, 5),
            format_sig(hi, 5),
            format_sig(se, 3)
        ),
        _ => format!(
            "{} {unit}   (confidence interval unknown: no standard error channel, or fewer than 2 samples per pixel)",
            format_sig(e.mean, 5)
        ),
    }
}

/// The human-readable report of `r`; `file` names the image in the first line.
fn text(r: &ProbeResult, file: &str) -> String {
    let u = r.units;
    let lu = u.symbol(Quantity::Luminance);
    let eu = u.symbol(Quantity::Illuminance);
    let mut s = match r.radius {
        None => format!("{file}: pixel ({}, {})\n", r.x, r.y),
        Some(radius) => format!(
            "{file}: disc of radius {} px around pixel ({}, {}): {} pixel{}\n",
            format_sig(radius, 4),
            r.x,
            r.y,
            r.pixels,
            if r.pixels == 1 { "" } else { "s" }
        ),
    };
    let row = |s: &mut String, k: &str, v: String| s.push_str(&format!("  {k:<13} {v}\n"));
    row(&mut s, "luminance", estimate_text(&r.luminance, lu));
    let e = match &r.illuminance {
        IlluminanceProbe::NoChannel => {
            "no E channel in this image (render with --illuminance)".to_string()
        }
        IlluminanceProbe::Undefined { .. } => "undefined: pixel sees no surface".to_string(),
        IlluminanceProbe::Defined {
            estimate,
            pixels,
            mask_mean,
        } => {
            let mut t = estimate_text(estimate, eu);
            if *pixels < r.pixels {
                t += &format!(
                    "; over the {pixels} of {} pixels that see a surface",
                    r.pixels
                );
            }
            if let Some(m) = mask_mean {
                if *m < 1.0 {
                    t += &format!("; coverage {}", format_sig(*m, 3));
                }
            }
            t
        }
    };
    row(&mut s, "illuminance", e);
    match r.xyz {
        None => row(&mut s, "XYZ", "no X/Z channels".to_string()),
        Some(v) => {
            row(
                &mut s,
                "XYZ",
                format!(
                    "{} {} {} {lu}",
                    format_sig(v[0], 5),
                    format_sig(v[1], 5),
                    format_sig(v[2], 5)
                ),
            );
        }
    }
    if let Some(v) = r.xy {
        row(&mut s, "xy", format!("{:.4} {:.4}", v[0], v[1]));
    }
    if let Some(v) = r.upvp {
        row(&mut s, "u′v′", format!("{:.4} {:.4}", v[0], v[1]));
    }
    match r.cct_duv {
        Some([t, duv]) => {
            let mut line = format!("{t:.0} K   Duv {duv:+.4}");
            if duv.abs() > 0.05 {
                line += "  (|Duv| > 0.05: CCT is not meaningful)";
            }
            row(&mut s, "CCT", line);
        }
        None if r.xyz.is_some() => row(&mut s, "CCT", "undefined (black)".into()),
        None => {}
    }
    if let (Some(l), Some(e)) = (r.srgb_linear, r.srgb_encoded) {
        let gamut = if l.iter().any(|&c| !(-1e-9..=1.0 + 1e-9).contains(&c)) {
            "  (outside 0…1: out of gamut or brighter than white)"
        } else {
            ""
        };
        row(
            &mut s,
            "sRGB linear",
            format!("{}   (Y = 1){gamut}", fmt3(l, 4)),
        );
        let hex: Vec<String> = e
            .iter()
            .map(|c| format!("{:02X}", (c.clamp(0.0, 1.0) * 255.0).round() as u8))
            .collect();
        row(
            &mut s,
            "sRGB encoded",
            format!("{}   #{}", fmt3(e, 4), hex.concat()),
        );
    }
    s
}
