//! Where a job's files go and how a film becomes them: the output stem of `--out`/`-o`, the
//! EXR channels and attributes of a film, and its sRGB preview.

use crate::film::Film;
use crate::output::{self, Layers, PngSettings};
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};

/// The output stem of `--out` / `-o`: `name` if none is given; `DIR/name` for an existing
/// directory (or a path ending in `/`); otherwise the path, with one of `extensions` removed.
pub fn output_stem(out: Option<&Path>, name: &str, extensions: &[&str]) -> PathBuf {
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
pub fn check_output_dir(stem: &Path) -> Result<()> {
    if let Some(dir) = stem.parent() {
        if !dir.as_os_str().is_empty() && !dir.is_dir() {
            bail!("output directory {} does not exist", dir.display());
        }
    }
    Ok(())
}

/// Largest |EV| accepted for a PNG's exposure: ±100 EV is already 2^100 away from any real
/// scene.
pub const MAX_ABS_EXPOSURE_EV: f64 = 100.0;

/// Refuses a non-finite exposure (EV) or one beyond ±[`MAX_ABS_EXPOSURE_EV`]; the message
/// names the command-line option.
pub fn check_exposure(exposure_ev: Option<f64>) -> Result<()> {
    if let Some(ev) = exposure_ev {
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

/// The EXR channels and attributes of a film (renders and merges alike): absolute XYZ (Y in
/// cd/m²), the standard error of Y and, with `illuminance`, E in lx with its error and mask.
pub fn film_layers(scene: &str, film: &Film, illuminance: bool) -> Layers {
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
            format!("{:.2}", film.samples_per_pixel()),
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

/// Writes the film's EXR (see [`film_layers`]).
pub fn write_exr(scene_path: &Path, film: &Film, illuminance: bool, exr_path: &Path) -> Result<()> {
    let layers = film_layers(&scene_path.display().to_string(), film, illuminance);
    output::write_exr(exr_path, &layers).context("cannot write the EXR")?;
    Ok(())
}

/// Writes the film's sRGB PNG at `exposure_ev` (None: automatic).
pub fn write_png(film: &Film, png_path: &Path, exposure_ev: Option<f64>) -> Result<()> {
    output::write_srgb_png(
        png_path,
        film.width,
        film.height,
        &film.xyz_image(),
        &PngSettings { exposure_ev },
    )
    .context("cannot write the PNG")?;
    Ok(())
}
