//! 8-bit sRGB PNG previews of absolute-XYZ images, with camera-style exposure.
//!
//! # Exposure convention
//!
//! `EV` is the exposure value at ISO 100 that a reflected-light meter calibrated per
//! ISO 2720 (K = 12.5 cd·s·m⁻²) reads for a uniform surface of luminance `L`:
//!
//! ```text
//! L = K · 2^EV / S        (K = 12.5, S = 100, so L = 0.125 · 2^EV cd/m²)
//! ```
//!
//! and, like a camera set to that meter reading, the image renders such a surface as middle
//! grey: display-linear value 0.18 (sRGB code value 118). So every pixel is scaled by
//!
//! ```text
//! scale = 0.18 · S / (K · 2^EV) = 1.44 · 2^−EV   [display-linear per cd/m²]
//! ```
//!
//! (display-linear 1.0, the clipping point, is `2^EV / 1.44 ≈ 0.694 · 2^EV` cd/m²).
//! Automatic exposure meters the image: the log-average (geometric mean) of the luminance `Y`
//! over pixels with `Y > 0`, after leaving out the brightest 1 % of them, and picks the EV the
//! meter would read for that luminance, so the log-average maps to 0.18.

use std::io::{self, Cursor};
use std::path::Path;

use image::{codecs::png::PngEncoder, ExtendedColorType, ImageEncoder, ImageFormat, RgbImage};

use super::{write_atomic, OutputError};
use crate::colour::rgb::{srgb_encode, xyz_to_linear_srgb};

/// Reflected-light meter calibration constant K of ISO 2720, in cd·s·m⁻².
pub const CALIBRATION_K: f64 = 12.5;
/// The ISO arithmetic speed S at which EV values are quoted.
pub const ISO_SPEED: f64 = 100.0;
/// Display-linear value at which a metered (average) luminance renders: 18 % grey.
pub const MIDDLE_GREY: f64 = 0.18;

/// How to expose the PNG.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PngSettings {
    /// `None`: automatic exposure (meter the image); `Some(ev)`: fixed EV at ISO 100.
    pub exposure_ev: Option<f64>,
}

/// What [`write_srgb_png`] applied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PngInfo {
    /// The exposure value used (ISO 100).
    pub exposure_ev: f64,
    /// Display-linear value per cd/m², `= 0.18 · 100 / (12.5 · 2^EV)`.
    pub scale: f64,
}

/// The scale from luminance (cd/m²) to display-linear value at exposure `ev` (ISO 100):
/// `0.18 · 100 / (12.5 · 2^ev) = 1.44 · 2^−ev`.
pub fn ev_to_scale(ev: f64) -> f64 {
    MIDDLE_GREY * ISO_SPEED / (CALIBRATION_K * ev.exp2())
}

/// The log-average luminance that automatic exposure meters: `exp(mean(ln Y))` over the
/// pixels with finite `Y > 0`, leaving out the brightest 1 % of those (`floor(n / 100)`
/// pixels). `None` if no pixel has a positive luminance.
pub fn log_average_luminance(xyz: &[[f32; 3]]) -> Option<f64> {
    let mut ys: Vec<f64> = xyz
        .iter()
        .map(|p| p[1] as f64)
        .filter(|y| y.is_finite() && *y > 0.0)
        .collect();
    if ys.is_empty() {
        return None;
    }
    ys.sort_unstable_by(f64::total_cmp);
    let keep = ys.len() - ys.len() / 100;
    let sum: f64 = ys[..keep].iter().map(|y| y.ln()).sum();
    Some((sum / keep as f64).exp())
}

/// The EV (ISO 100) that automatic exposure picks for an image:
/// `log2(L_avg · 100 / 12.5)` with `L_avg` = [`log_average_luminance`]. An image without any
/// positive luminance gets EV 0.
pub fn auto_exposure_ev(xyz: &[[f32; 3]]) -> f64 {
    match log_average_luminance(xyz) {
        Some(l) => (l * ISO_SPEED / CALIBRATION_K).log2(),
        None => 0.0,
    }
}

/// Tone-map an absolute-XYZ image (`Y` in cd/m²; row-major, top row first) to an 8-bit sRGB
/// PNG, written atomically.
///
/// Per pixel: `XYZ · scale` (see [`ev_to_scale`]; `settings.exposure_ev = None` meters the
/// image with [`auto_exposure_ev`]) → linear sRGB (IEC 61966-2-1, D65) → each channel clipped
/// to [0, 1] independently → sRGB transfer function → `round(255 · v)`. Per-channel clipping
/// shifts the hue of over-exposed saturated colours towards the primaries/white.
///
/// Errors: sizes that do not match, an empty image, a non-finite fixed EV, or a non-finite
/// pixel ([`OutputError::NonFinite`]).
pub fn write_srgb_png(
    path: &Path,
    width: usize,
    height: usize,
    xyz: &[[f32; 3]],
    settings: &PngSettings,
) -> Result<PngInfo, OutputError> {
    if width == 0 || height == 0 || width > u32::MAX as usize || height > u32::MAX as usize {
        return Err(OutputError::invalid(
            path,
            format!("image size {width}x{height} cannot be written as PNG"),
        ));
    }
    if xyz.len() != width * height {
        return Err(OutputError::invalid(
            path,
            format!(
                "image has {} pixels, expected {width}x{height} = {}",
                xyz.len(),
                width * height
            ),
        ));
    }
    if let Some(i) = xyz.iter().position(|p| p.iter().any(|v| !v.is_finite())) {
        let c = xyz[i].iter().position(|v| !v.is_finite()).unwrap_or(0);
        return Err(OutputError::NonFinite {
            path: path.to_path_buf(),
            channel: ["X", "Y", "Z"][c].to_string(),
            x: i % width,
            y: i / width,
            value: xyz[i][c],
        });
    }
    let exposure_ev = match settings.exposure_ev {
        Some(ev) if ev.is_finite() => ev,
        Some(ev) => {
            return Err(OutputError::invalid(
                path,
                format!("exposure EV must be finite, got {ev}"),
            ))
        }
        None => auto_exposure_ev(xyz),
    };
    let scale = ev_to_scale(exposure_ev);

    let mut rgb8 = Vec::with_capacity(xyz.len() * 3);
    for p in xyz {
        let scaled = [
            p[0] as f64 * scale,
            p[1] as f64 * scale,
            p[2] as f64 * scale,
        ];
        for v in xyz_to_linear_srgb(scaled) {
            let encoded = srgb_encode(v.clamp(0.0, 1.0));
            rgb8.push((encoded * 255.0).round().clamp(0.0, 255.0) as u8);
        }
    }

    write_atomic(path, |w| {
        PngEncoder::new(w)
            .write_image(&rgb8, width as u32, height as u32, ExtendedColorType::Rgb8)
            .map_err(|e| match e {
                image::ImageError::IoError(e) => e,
                other => io::Error::other(other),
            })
    })?;
    Ok(PngInfo { exposure_ev, scale })
}
/// Encodes `img` as PNG and writes it atomically.
pub fn write_rgb_png(path: &Path, img: &RgbImage) -> Result<(), OutputError> {
    let mut bytes = Vec::new();
    img.write_to(&mut Cursor::new(&mut bytes), ImageFormat::Png)
        .map_err(|e| OutputError::Png {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    write_atomic(path, |w| w.write_all(&bytes))
}
