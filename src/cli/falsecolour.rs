//! `candela falsecolour`: reads its arguments, chooses the output path, writes the map with
//! [`candela::report::falsecolour`] and says what it wrote.

use std::path::PathBuf;

use candela::output::read_image_with;
use candela::photometry::Quantity;
use candela::report::check_photometric_layers;
use candela::report::falsecolour::{
    bytes_per_pixel, describe_scale, render_falsecolour, FalsecolourSettings, Palette, Scale,
};
use candela::report::units::UnitSystem;

/// Arguments of `candela falsecolour`.
#[derive(clap::Args, Debug, Clone)]
pub struct FalsecolourArgs {
    /// EXR (or Radiance HDR) image written by `candela render`.
    pub exr: PathBuf,
    /// luminance (channel Y) or illuminance (channel E, needs a render with --illuminance).
    #[arg(long, default_value = "luminance", value_parser = parse_quantity)]
    pub quantity: Quantity,
    /// linear or log.
    #[arg(long, default_value = "linear", value_parser = parse_scale)]
    pub scale: Scale,
    /// MIN:MAX in display units (either side may be left empty for automatic), e.g. 0:500.
    #[arg(long, allow_hyphen_values = true)]
    pub range: Option<String>,
    /// Number of discrete colour steps; 0 or absent = continuous.
    #[arg(long)]
    pub steps: Option<usize>,
    /// Draw contour lines at the step boundaries (continuous scale: at the legend ticks).
    #[arg(long)]
    pub contours: bool,
    /// si (cd/m², lx) or imperial (fL, fc).
    #[arg(long, default_value = "si", value_parser = super::probe::parse_units)]
    pub units: UnitSystem,
    /// turbo or viridis.
    #[arg(long, default_value = "turbo", value_parser = parse_palette)]
    pub palette: Palette,
    /// Output PNG (default: NAME.luminance.png or NAME.illuminance.png beside the EXR).
    #[arg(short = 'o', long = "out")]
    pub out: Option<PathBuf>,
}

fn parse_quantity(s: &str) -> Result<Quantity, String> {
    match s.trim().to_ascii_lowercase().as_str() {
        "luminance" | "l" | "y" => Ok(Quantity::Luminance),
        "illuminance" | "e" => Ok(Quantity::Illuminance),
        _ => Err(format!(
            "unknown quantity '{s}' (use luminance or illuminance)"
        )),
    }
}

fn parse_scale(s: &str) -> Result<Scale, String> {
    Scale::parse(s).ok_or_else(|| format!("unknown scale '{s}' (use linear or log)"))
}

fn parse_palette(s: &str) -> Result<Palette, String> {
    Palette::parse(s).ok_or_else(|| format!("unknown palette '{s}' (use turbo or viridis)"))
}

/// Parses `MIN:MAX` (either side may be empty = automatic).
pub fn parse_range(s: &str) -> Result<(Option<f64>, Option<f64>), String> {
    let (a, b) = s
        .split_once(':')
        .ok_or_else(|| format!("--range '{s}' must be MIN:MAX, e.g. 0:500 or 10:"))?;
    let num = |t: &str| -> Result<Option<f64>, String> {
        let t = t.trim();
        if t.is_empty() {
            return Ok(None);
        }
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Some(v)),
            _ => Err(format!("--range '{s}': '{t}' is not a finite number")),
        }
    };
    Ok((num(a)?, num(b)?))
}

/// What the command line alone can tell is wrong with the scale: an empty range, a log scale
/// from 0 or below, too many steps (the checks [`candela::report::falsecolour`] makes again).
fn check_settings(
    scale: Scale,
    min: Option<f64>,
    max: Option<f64>,
    steps: Option<usize>,
) -> Result<(), String> {
    if let (Some(a), Some(b)) = (min, max) {
        if a >= b {
            return Err(format!("--range {a}:{b} is empty: MIN must be below MAX"));
        }
    }
    match (scale, min) {
        (Scale::Log, Some(m)) if m <= 0.0 => {
            return Err(format!(
                "--scale log needs a positive minimum, got --range {m}:…"
            ))
        }
        _ => {}
    }
    if let Some(n) = steps.filter(|&n| n > 1000) {
        return Err(format!("--steps {n} is too many (at most 1000)"));
    }
    Ok(())
}

/// `candela falsecolour`: writes the PNG and returns the line to print.
pub fn run(args: &FalsecolourArgs) -> anyhow::Result<String> {
    let (min, max) = match &args.range {
        Some(r) => parse_range(r).map_err(super::usage)?,
        None => (None, None),
    };
    check_settings(args.scale, min, max, args.steps).map_err(super::usage)?;
    let out = args.out.clone().unwrap_or_else(|| {
        candela::output::with_suffix(
            &args.exr.with_extension(""),
            &format!(".{}.png", args.quantity.name()),
        )
    });
    if candela::job::would_replace(&out, &args.exr) {
        anyhow::bail!(
            "-o {}: refusing to overwrite the input image {} with the PNG map; choose another -o",
            out.display(),
            args.exr.display()
        );
    }
    let file_name = args
        .exr
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    let q = args.quantity.name();
    let settings = FalsecolourSettings {
        quantity: args.quantity,
        scale: args.scale,
        min,
        max,
        steps: args.steps,
        contours: args.contours,
        units: args.units,
        palette: args.palette,
        title: Some(format!(
            "{}{} — {file_name}",
            q[..1].to_uppercase(),
            &q[1..]
        )),
    };
    // The map's buffers are part of the memory checked before the image is decoded.
    let layers = read_image_with(&args.exr, &|_| bytes_per_pixel(&settings))
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    check_photometric_layers(&args.exr, &layers).map_err(|e| anyhow::anyhow!(e))?;
    let (img, info) = render_falsecolour(&layers, &settings)
        .map_err(|e| anyhow::anyhow!("{}: {e}", args.exr.display()))?;
    candela::output::write_rgb_png(&out, &img).map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(format!(
        "wrote {}: {} {}\n",
        out.display(),
        q,
        describe_scale(&info.scale, &info.unit)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse() {
        assert_eq!(parse_range("0:500"), Ok((Some(0.0), Some(500.0))));
        assert_eq!(parse_range(":500"), Ok((None, Some(500.0))));
        assert_eq!(parse_range("1e-2:"), Ok((Some(0.01), None)));
        assert!(parse_range("500").is_err());
        assert!(parse_range("a:b").is_err());
        assert!(parse_range("0:inf").is_err());
    }
}
