//! The probe of one pixel, or of a small disc of pixels, of a rendered EXR: luminance and
//! illuminance with 95 % confidence intervals, XYZ, xy, u′v′, CCT, Duv and sRGB, and their JSON
//! (keys in `docs/reports.md`). `candela probe` prints them as text or as that JSON.
use std::path::Path;

use anyhow::anyhow;
use serde_json::{json, Value};

use super::units::UnitSystem;
use crate::colour::models::{xyz_to_upvp, xyz_to_xy};
use crate::colour::rgb::{srgb_encode, xyz_to_linear_srgb};
use crate::colour::temperature::xyz_to_cct_ohno2013;
use crate::limits::check_memory;
use crate::output::{
    read_image, Layers, CHANNEL_E, CHANNEL_E_MASK, CHANNEL_E_STDERR, CHANNEL_X, CHANNEL_Y,
    CHANNEL_Y_STDERR, CHANNEL_Z, ILLUMINANCE_SENTINEL,
};
use crate::photometry::Quantity;

/// z value of the two-sided 95 % normal confidence interval.
pub const Z95: f64 = 1.96;

/// A mean with its standard error (display units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// Mean value.
    pub mean: f64,
    /// Standard error of the mean; `None` if the image has no error channel.
    pub stderr: Option<f64>,
    /// The multiple of `stderr` that is the 95 % interval's half-width: Student's t₀.₉₇₅ with
    /// the degrees of freedom of the pixels' batch standard errors (Welch–Satterthwaite over
    /// several pixels), or [`Z95`] for an image that does not state its batches.
    pub t95: f64,
}

impl Estimate {
    /// The 95 % confidence interval mean ± t95·SE.
    pub fn ci95(&self) -> Option<(f64, f64)> {
        self.stderr
            .map(|se| (self.mean - self.t95 * se, self.mean + self.t95 * se))
    }

    fn to_json(self) -> Value {
        json!({
            "mean": self.mean,
            "stderr": self.stderr,
            "ci95": self.ci95().map(|(a, b)| [a, b]),
        })
    }
}

/// The illuminance part of a probe.
#[derive(Clone, Debug, PartialEq)]
pub enum IlluminanceProbe {
    /// The image has no `E` channel (rendered without `--illuminance`).
    NoChannel,
    /// No probed pixel sees a surface (sky, emitter, nothing): illuminance is undefined.
    Undefined {
        /// Mean of `mask.E` over all probed pixels (`None` without a mask channel).
        mask_mean: Option<f64>,
    },
    /// Mean over the probed pixels where `E` is defined.
    Defined {
        /// Mean and standard error, display units.
        estimate: Estimate,
        /// How many of the probed pixels have `E` defined.
        pixels: usize,
        /// Mean of `mask.E` over all probed pixels (`None` without a mask channel).
        mask_mean: Option<f64>,
    },
}

/// Everything `candela probe` reports.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeResult {
    /// Column and row of the centre pixel.
    pub x: usize,
    /// Row of the centre pixel.
    pub y: usize,
    /// Disc radius in pixels (`None` = the single pixel).
    pub radius: Option<f64>,
    /// Number of pixels averaged.
    pub pixels: usize,
    /// SI or imperial; luminance, XYZ and illuminance are in its units.
    pub units: UnitSystem,
    /// Luminance (mean of the pixels' means; SE = √(Σ SEᵢ²)/n).
    pub luminance: Estimate,
    /// Illuminance, likewise over the pixels where it is defined.
    pub illuminance: IlluminanceProbe,
    /// Mean absolute XYZ (display luminance units), if the image has X and Z.
    pub xyz: Option<[f64; 3]>,
    /// CIE 1931 chromaticity.
    pub xy: Option<[f64; 2]>,
    /// CIE 1976 UCS chromaticity.
    pub upvp: Option<[f64; 2]>,
    /// Correlated colour temperature (K) and Duv, Ohno (2013); `None` for black.
    pub cct_duv: Option<[f64; 2]>,
    /// Linear sRGB of XYZ / Y (white at Y = 1), not clipped.
    pub srgb_linear: Option<[f64; 3]>,
    /// IEC 61966-2-1 encoded sRGB of `srgb_linear`, not clipped.
    pub srgb_encoded: Option<[f64; 3]>,
}

/// Probes pixel (`x`, `y`) (0, 0 = top-left) of `layers`, or the disc of pixels whose centres
/// lie within `radius` pixels of it. Errors (no `Y` channel, pixel outside the image, bad
/// radius) are messages without the file name.
pub fn probe(
    layers: &Layers,
    x: i64,
    y: i64,
    radius: Option<f64>,
    units: UnitSystem,
) -> Result<ProbeResult, String> {
    let (lum, x, y) = check_request(layers, x, y, radius)?;
    let idx = probed_pixels(layers.width, layers.height, x, y, radius)?;
    let samples = Samples::of(layers);
    let lq = Quantity::Luminance;
    let y_se = layers.channel(CHANNEL_Y_STDERR);
    let luminance = Estimate {
        mean: units.from_si(lq, mean_of(lum, &idx)),
        stderr: y_se
            .filter(|_| !samples.too_few)
            .map(|c| units.from_si(lq, se_of(c, &idx))),
        t95: y_se.map_or(Z95, |c| samples.t95_of(c, &idx)),
    };
    let illuminance = probe_illuminance(layers, &idx, units, &samples);

    let xyz_si = match (layers.channel(CHANNEL_X), layers.channel(CHANNEL_Z)) {
        (Some(cx), Some(cz)) => Some([mean_of(cx, &idx), mean_of(lum, &idx), mean_of(cz, &idx)]),
        _ => None,
    };
    let positive = xyz_si.filter(|v| v[1] > 0.0 && v.iter().all(|c| c.is_finite()));
    let srgb_linear = positive.map(|v| xyz_to_linear_srgb(v.map(|c| c / v[1])));
    let cct_duv = positive
        .map(xyz_to_cct_ohno2013)
        .filter(|c| c.iter().all(|v| v.is_finite()));
    Ok(ProbeResult {
        x,
        y,
        radius,
        pixels: idx.len(),
        units,
        luminance,
        illuminance,
        xyz: xyz_si.map(|v| v.map(|c| units.from_si(lq, c))),
        xy: xyz_si.map(xyz_to_xy),
        upvp: xyz_si.map(xyz_to_upvp),
        cct_duv,
        srgb_linear,
        srgb_encoded: srgb_linear.map(|v| v.map(srgb_encode)),
    })
}

/// Refuses a probe of an inconsistent image, of one without luminance, of a pixel outside it
/// or with a bad radius; returns the luminance channel and the pixel.
fn check_request(
    layers: &Layers,
    x: i64,
    y: i64,
    radius: Option<f64>,
) -> Result<(&[f32], usize, usize), String> {
    let (w, h) = (layers.width, layers.height);
    let channels = || {
        layers
            .channels
            .iter()
            .map(|(n, _)| n.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    if let Some((name, c)) = layers
        .channels
        .iter()
        .find(|(_, c)| Some(c.len()) != w.checked_mul(h))
    {
        return Err(format!(
            "channel '{name}' has {} samples, expected {w}×{h}",
            c.len()
        ));
    }
    let lum = layers.channel(CHANNEL_Y).ok_or_else(|| {
        format!(
            "no '{CHANNEL_Y}' (luminance) channel; the image has: {}",
            channels()
        )
    })?;
    if x < 0 || y < 0 || x as u64 >= w as u64 || y as u64 >= h as u64 {
        return Err(format!(
            "pixel ({x}, {y}) is outside the {w}×{h} image (x from 0 to {}, y from 0 to {}; 0, 0 = top-left)",
            w as i64 - 1,
            h as i64 - 1
        ));
    }
    if let Some(r) = radius {
        if !r.is_finite() || r < 0.0 {
            return Err(format!(
                "--radius must be a finite number of pixels ≥ 0, got {r}"
            ));
        }
    }
    Ok((lum, x as usize, y as usize))
}

/// Indices of the probed pixels of a `w` × `h` image, row by row: a radius beyond the image
/// covers the image (and no more), and the indices must fit in memory.
fn probed_pixels(
    w: usize,
    h: usize,
    x: usize,
    y: usize,
    radius: Option<f64>,
) -> Result<Vec<usize>, String> {
    let mut idx = Vec::new();
    match radius {
        None => idx.push(y * w + x),
        Some(r) => {
            let k = (r.floor() as usize).min(w.max(h));
            let (i0, i1) = (x.saturating_sub(k), (x.saturating_add(k)).min(w - 1));
            let (j0, j1) = (y.saturating_sub(k), (y.saturating_add(k)).min(h - 1));
            let most = (i1 - i0 + 1) as u64 * (j1 - j0 + 1) as u64;
            check_memory(
                most * 16,
                &format!("a probe of radius {r} pixels in the {w}×{h} image"),
            )?;
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let (dx, dy) = (i as f64 - x as f64, j as f64 - y as f64);
                    if dx * dx + dy * dy <= r * r {
                        idx.push(j * w + i);
                    }
                }
            }
        }
    }
    Ok(idx)
}

/// Mean of channel `c` over the pixels `ids`.
fn mean_of(c: &[f32], ids: &[usize]) -> f64 {
    ids.iter().map(|&i| c[i] as f64).sum::<f64>() / ids.len() as f64
}

/// SE of a mean of independent pixel means, from their standard errors `c`: √(Σ SEᵢ²) / n.
fn se_of(c: &[f32], ids: &[usize]) -> f64 {
    ids.iter()
        .map(|&i| (c[i] as f64).powi(2))
        .sum::<f64>()
        .sqrt()
        / ids.len() as f64
}

/// What the image says about the samples behind its standard errors.
struct Samples {
    /// Mean samples per pixel, if the image states it.
    spp: Option<f64>,
    /// Fewer than 2 samples a pixel: standard errors are unknown.
    too_few: bool,
    /// Degrees of freedom of one pixel's standard error, if the image states its batches.
    dof: Option<u32>,
}

impl Samples {
    fn of(layers: &Layers) -> Samples {
        // With fewer than 2 samples per pixel a pixel's sample variance is undefined (the
        // render writes 0 for it): its standard error is unknown, not zero. candela's EXRs
        // carry their mean samples per pixel, and all pixels have the same count until the
        // passes that already give every pixel 2 or more, so the mean decides.
        let spp = layers
            .attribute("spp")
            .and_then(|v| v.trim().parse::<f64>().ok());
        let too_few = spp.is_some_and(|spp| spp < 2.0);
        // A pixel's standard error comes from min(n, batches) independent batches of its n
        // samples (the mean spp stands for n); images that do not state their batches get the
        // normal quantile.
        let batches = layers
            .attribute(crate::film::STDERR_BATCHES_ATTRIBUTE)
            .and_then(|v| v.trim().parse::<u32>().ok());
        let dof =
            batches.map(|k| (spp.unwrap_or(k as f64).floor().clamp(1.0, k as f64) as u32) - 1);
        Samples { spp, too_few, dof }
    }

    /// The 95 % interval's multiple of the standard error of the mean over `ids`, whose
    /// standard errors are `c`.
    fn t95_of(&self, c: &[f32], ids: &[usize]) -> f64 {
        match self.dof {
            None => Z95,
            Some(0) => f64::INFINITY,
            Some(d) => {
                // Welch–Satterthwaite: ν = (Σ seᵢ²)² / Σ (seᵢ⁴ / dᵢ), at least one pixel's dof.
                let (s2, s4) = ids.iter().fold((0.0, 0.0), |(a, b), &i| {
                    let v = (c[i] as f64).powi(2);
                    (a + v, b + v * v)
                });
                let nu = if s4 > 0.0 {
                    (s2 * s2 / s4 * d as f64).min(u32::MAX as f64 / 2.0) as u32
                } else {
                    d
                };
                crate::sampling::t95(nu.max(d))
            }
        }
    }
}

/// Illuminance over the probed pixels `idx` where it is defined.
fn probe_illuminance(
    layers: &Layers,
    idx: &[usize],
    units: UnitSystem,
    samples: &Samples,
) -> IlluminanceProbe {
    let eq = Quantity::Illuminance;
    let Some(e) = layers.channel(CHANNEL_E) else {
        return IlluminanceProbe::NoChannel;
    };
    let mask = layers.channel(CHANNEL_E_MASK);
    let defined: Vec<usize> = idx
        .iter()
        .copied()
        .filter(|&i| {
            let v = e[i];
            v.is_finite()
                && v != ILLUMINANCE_SENTINEL
                && v >= 0.0
                && mask.is_none_or(|m| m[i] > 0.0)
        })
        .collect();
    let mask_mean = mask.map(|m| mean_of(m, idx));
    // A pixel's illuminance samples are its samples that saw a receiving surface,
    // mask.E × spp of them: with fewer than 2 its E has no sample variance either.
    // In an adaptive render pixels stop at different counts, so the mean spp can hide
    // a pixel with 0 or 1 illuminance samples; its stderr.E is then 0 while only some
    // of its samples saw a surface (0 < mask < 1), which a real estimate with a
    // sample variance practically never gives.
    let e_se = layers.channel(CHANNEL_E_STDERR);
    let too_few_e = defined.iter().any(|&i| {
        let m = mask.map_or(1.0, |m| m[i]);
        samples.spp.is_some_and(|spp| m as f64 * spp < 1.5)
            || (e_se.is_some_and(|se| se[i] == 0.0) && m > 0.0 && m < 1.0)
    });
    if defined.is_empty() {
        IlluminanceProbe::Undefined { mask_mean }
    } else {
        IlluminanceProbe::Defined {
            estimate: Estimate {
                mean: units.from_si(eq, mean_of(e, &defined)),
                stderr: e_se
                    .filter(|_| !samples.too_few && !too_few_e)
                    .map(|c| units.from_si(eq, se_of(c, &defined))),
                t95: e_se.map_or(Z95, |c| samples.t95_of(c, &defined)),
            },
            pixels: defined.len(),
            mask_mean,
        }
    }
}

/// Reads `path` and probes it; every error names the file.
pub fn probe_file(
    path: &Path,
    x: i64,
    y: i64,
    radius: Option<f64>,
    units: UnitSystem,
) -> anyhow::Result<ProbeResult> {
    let layers = read_image(path)?;
    super::check_photometric_layers(path, &layers).map_err(|e| anyhow!(e))?;
    probe(&layers, x, y, radius, units).map_err(|e| anyhow!("{}: {e}", path.display()))
}

impl ProbeResult {
    /// JSON with the keys documented in docs/reports.md (`file` is added by the command).
    pub fn to_json(&self) -> Value {
        let u = self.units;
        let illuminance = match &self.illuminance {
            IlluminanceProbe::NoChannel => Value::Null,
            IlluminanceProbe::Undefined { mask_mean } => json!({
                "defined": false,
                "reason": "pixel sees no surface",
                "pixels": 0,
                "mean": null, "stderr": null, "ci95": null,
                "mask_mean": mask_mean,
            }),
            IlluminanceProbe::Defined {
                estimate,
                pixels,
                mask_mean,
            } => {
                let mut v = estimate.to_json();
                v["defined"] = json!(true);
                v["pixels"] = json!(pixels);
                v["mask_mean"] = json!(mask_mean);
                v
            }
        };
        json!({
            "x": self.x,
            "y": self.y,
            "radius_px": self.radius,
            "pixels": self.pixels,
            "units": {
                "system": u.name(),
                "luminance": u.symbol(Quantity::Luminance),
                "illuminance": u.symbol(Quantity::Illuminance),
            },
            "luminance": self.luminance.to_json(),
            "illuminance": illuminance,
            "xyz": self.xyz,
            "xy": self.xy,
            "upvp": self.upvp,
            "cct_k": self.cct_duv.map(|c| c[0]),
            "duv": self.cct_duv.map(|c| c[1]),
            "srgb_linear": self.srgb_linear,
            "srgb_encoded": self.srgb_encoded,
        })
    }
}
