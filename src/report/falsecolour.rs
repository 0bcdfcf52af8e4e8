//! False-colour maps of luminance (`Y`) or illuminance (`E`) with a legend bar.
//!
//! [`write_falsecolour`] turns a [`Layers`] image into an 8-bit sRGB PNG: the map (pixels
//! coloured by value, optionally banded into steps and outlined by contour lines), a legend bar
//! with tick values and the unit, a title, and a footer with the image's min / mean / max.
//! Where illuminance is undefined (the pixel sees no surface: `mask.E` = 0 or `E` = the
//! sentinel) the map is hatched in neutral grey and the legend says so.
//!
//! The colour scale ([`ColourScale`]) is shared with the grid heat maps
//! ([`super::heatmap`]). See `docs/reports.md`.

use std::io::Cursor;
use std::path::Path;

use image::{ImageFormat, Rgb, RgbImage};

use super::draw::{self, Colour, BLACK, DARK_GREY, WHITE};
use super::units::{format_sig, UnitSystem};
use crate::output::{
    write_atomic, Layers, OutputError, CHANNEL_E, CHANNEL_E_MASK, CHANNEL_Y, ILLUMINANCE_SENTINEL,
};
use crate::photometry::Quantity;

/// Linear or logarithmic mapping of values to colours.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Scale {
    /// Colour position proportional to the value.
    #[default]
    Linear,
    /// Colour position proportional to log(value); values ≤ 0 take the lowest colour.
    Log,
}

impl Scale {
    /// `"linear"` or `"log"`.
    pub fn name(self) -> &'static str {
        match self {
            Scale::Linear => "linear",
            Scale::Log => "log",
        }
    }

    /// Parses `linear`/`lin` or `log`/`logarithmic`.
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "linear" | "lin" => Some(Scale::Linear),
            "log" | "logarithmic" => Some(Scale::Log),
            _ => None,
        }
    }
}

/// Colour map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Palette {
    /// Google's Turbo: an improved rainbow, dark blue → green → yellow → dark red; the look of
    /// lighting-design software, with monotonic lightness on each half.
    #[default]
    Turbo,
    /// Matplotlib's viridis: perceptually uniform, dark violet → yellow, colour-blind safe.
    Viridis,
}

impl Palette {
    /// `"turbo"` or `"viridis"`.
    pub fn name(self) -> &'static str {
        match self {
            Palette::Turbo => "turbo",
            Palette::Viridis => "viridis",
        }
    }

    /// Parses `turbo` or `viridis`.
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "turbo" => Some(Palette::Turbo),
            "viridis" => Some(Palette::Viridis),
            _ => None,
        }
    }

    /// The colour at position `t` ∈ [0, 1] (clamped).
    pub fn eval(self, t: f64) -> [u8; 3] {
        let g = match self {
            Palette::Turbo => colorous::TURBO,
            Palette::Viridis => colorous::VIRIDIS,
        };
        let c = g.eval_continuous(t.clamp(0.0, 1.0));
        [c.r, c.g, c.b]
    }
}

/// How to draw a false-colour map or heat map. Values (`range`) are in the display units
/// chosen by `units` (cd/m² or lx for SI, fL or fc for imperial).
#[derive(Clone, Debug, PartialEq)]
pub struct FalsecolourSettings {
    /// Luminance (channel `Y`) or illuminance (channel `E`). Grid heat maps always show
    /// illuminance and ignore this.
    pub quantity: Quantity,
    /// Linear or logarithmic.
    pub scale: Scale,
    /// Lower end of the scale in display units; `None` = automatic (see [`ColourScale::resolve`]).
    pub min: Option<f64>,
    /// Upper end of the scale in display units; `None` = automatic.
    pub max: Option<f64>,
    /// Number of discrete colour steps (bands); `None` or `Some(0)` = continuous.
    pub steps: Option<usize>,
    /// Draw contour lines at the step boundaries (continuous: at the legend ticks).
    pub contours: bool,
    /// SI (cd/m², lx) or imperial (fL, fc).
    pub units: UnitSystem,
    /// Colour map.
    pub palette: Palette,
    /// Title line; `None` = the quantity's name.
    pub title: Option<String>,
}

impl Default for FalsecolourSettings {
    fn default() -> Self {
        FalsecolourSettings {
            quantity: Quantity::Luminance,
            scale: Scale::Linear,
            min: None,
            max: None,
            steps: None,
            contours: false,
            units: UnitSystem::Si,
            palette: Palette::Turbo,
            title: None,
        }
    }
}

/// A resolved colour scale: value (display units) → colour.
#[derive(Clone, Debug, PartialEq)]
pub struct ColourScale {
    /// Linear or log.
    pub scale: Scale,
    /// Value at the bottom of the legend (display units); > 0 for a log scale.
    pub min: f64,
    /// Value at the top of the legend (display units); > `min`.
    pub max: f64,
    /// Number of bands, or `None` for a continuous scale.
    pub steps: Option<usize>,
    /// Colour map.
    pub palette: Palette,
    /// Legend tick values, ascending, from `min` to `max` inclusive. For a banded scale these
    /// are exactly the `steps + 1` step boundaries.
    pub ticks: Vec<f64>,
}

impl ColourScale {
    /// Resolves `settings` against the data `values` (display units; the defined pixels or
    /// grid points only).
    ///
    /// Automatic range (documented in docs/reports.md):
    /// * linear: min = 0 (or the 1st percentile rounded down, if that is negative), max = the
    ///   99th percentile rounded up so that the interval per step ((max − min)/N, N = the
    ///   steps, or 10 for a continuous scale) is a "nice" number (1, 1.2, 1.5, 2, 2.5, 3, 4,
    ///   5, 6, 8 × 10ᵏ);
    /// * log: whole decades around the 1st and 99th percentiles of the positive values, at most
    ///   six decades below the top.
    ///
    /// Errors describe the bad setting (min ≥ max, log scale with min ≤ 0, non-finite).
    pub fn resolve(settings: &FalsecolourSettings, values: &[f64]) -> Result<ColourScale, String> {
        for (name, v) in [("minimum", settings.min), ("maximum", settings.max)] {
            if let Some(v) = v {
                if !v.is_finite() {
                    return Err(format!("range {name} {v} is not a finite number"));
                }
            }
        }
        let steps = settings.steps.filter(|&n| n > 0);
        if let Some(n) = steps {
            if n > 1000 {
                return Err(format!("--steps {n} is too many (at most 1000)"));
            }
        }
        let mut finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
        finite.sort_unstable_by(f64::total_cmp);
        let (min, max) = match settings.scale {
            Scale::Linear => {
                let auto_min = || {
                    let p1 = percentile(&finite, 0.01).unwrap_or(0.0);
                    if p1 < 0.0 {
                        -nice_ceil(-p1)
                    } else {
                        0.0
                    }
                };
                let min = settings.min.unwrap_or_else(auto_min);
                let max = settings.max.unwrap_or_else(|| {
                    let p99 = percentile(&finite, 0.99).unwrap_or(1.0);
                    if p99 > min {
                        // A nice interval per step (or per tenth), so that the legend's
                        // values are round numbers.
                        let n = steps.unwrap_or(10) as f64;
                        min + n * nice_ceil((p99 - min) / n)
                    } else {
                        min + 1.0
                    }
                });
                (min, max)
            }
            Scale::Log => {
                let positive: Vec<f64> = finite.iter().copied().filter(|&v| v > 0.0).collect();
                let max = settings.max.unwrap_or_else(|| {
                    let hi = percentile(&positive, 0.99).unwrap_or(1.0);
                    let mut m = 10f64.powf(hi.log10().ceil());
                    if let Some(lo) = settings.min {
                        if m <= lo {
                            m = lo * 10.0;
                        }
                    }
                    m
                });
                let min = settings.min.unwrap_or_else(|| {
                    let lo = percentile(&positive, 0.01).unwrap_or(max / 10.0);
                    let m = 10f64.powf(lo.log10().floor()).max(max * 1e-6);
                    if m >= max {
                        max / 10.0
                    } else {
                        m
                    }
                });
                if min <= 0.0 {
                    return Err(format!(
                        "a logarithmic scale needs a positive minimum, got {min}"
                    ));
                }
                (min, max)
            }
        };
        if min >= max || !(max - min).is_finite() {
            return Err(format!(
                "the range minimum ({min}) must be below the maximum ({max})"
            ));
        }
        let ticks = match steps {
            Some(n) => (0..=n)
                .map(|k| match settings.scale {
                    Scale::Linear => min + (max - min) * k as f64 / n as f64,
                    Scale::Log => min * (max / min).powf(k as f64 / n as f64),
                })
                .map(|v| snap(v, min, max))
                .collect(),
            None => match settings.scale {
                Scale::Linear => (0..=10)
                    .map(|k| snap(min + (max - min) * k as f64 / 10.0, min, max))
                    .collect(),
                Scale::Log => log_ticks(min, max),
            },
        };
        Ok(ColourScale {
            scale: settings.scale,
            min,
            max,
            steps,
            palette: settings.palette,
            ticks,
        })
    }

    /// Position of `v` on the scale, 0 (min) … 1 (max), clamped. NaN and (log) v ≤ 0 give 0.
    pub fn position(&self, v: f64) -> f64 {
        let t = match self.scale {
            Scale::Linear => (v - self.min) / (self.max - self.min),
            Scale::Log => {
                if v > 0.0 {
                    (v / self.min).ln() / (self.max / self.min).ln()
                } else {
                    0.0
                }
            }
        };
        if t.is_nan() {
            0.0
        } else {
            t.clamp(0.0, 1.0)
        }
    }

    /// The band `v` falls in: `k` such that `ticks[k] ≤ v < ticks[k + 1]` (values below the
    /// range give 0, values at or above the top give `steps − 1`). `None` for a continuous
    /// scale.
    pub fn step_of(&self, v: f64) -> Option<usize> {
        let n = self.steps?;
        // Compare with the boundaries themselves so that the legend and the map agree exactly.
        let k = self.ticks[1..n].iter().take_while(|&&b| v >= b).count();
        Some(k)
    }

    /// Colour of band `k` (banded scales): the palette at the band's middle.
    pub fn step_colour(&self, k: usize) -> [u8; 3] {
        let n = self.steps.unwrap_or(1).max(1);
        self.palette.eval((k as f64 + 0.5) / n as f64)
    }

    /// The colour `v` is painted with.
    pub fn colour(&self, v: f64) -> [u8; 3] {
        match self.step_of(v) {
            Some(k) => self.step_colour(k),
            None => self.palette.eval(self.position(v)),
        }
    }

    /// The contour class of `v`: how many interior ticks are ≤ `v`. Contour lines are drawn
    /// between neighbouring pixels of different classes.
    pub fn contour_class(&self, v: f64) -> usize {
        let n = self.ticks.len();
        if n < 3 {
            return 0;
        }
        self.ticks[1..n - 1].iter().take_while(|&&b| v >= b).count()
    }
}

/// Removes floating-point fuzz from computed tick values (e.g. 299.99999999999994 → 300) and
/// pins the ends to exactly `min` and `max`.
fn snap(v: f64, min: f64, max: f64) -> f64 {
    if (v - min).abs() <= 1e-12 * max.abs().max(min.abs()) {
        return min;
    }
    if (v - max).abs() <= 1e-12 * max.abs().max(min.abs()) {
        return max;
    }
    let r: f64 = format!("{v:.12e}").parse().unwrap_or(v);
    r
}

/// Ticks for a continuous log scale: 1-2-5 per decade when the range spans at most three
/// decades, else decades; plus both ends.
fn log_ticks(min: f64, max: f64) -> Vec<f64> {
    let decades = (max / min).log10();
    let mults: &[f64] = if decades <= 3.0 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    let mut ticks = vec![min];
    let mut e = min.log10().floor() as i32;
    while 10f64.powi(e) <= max * 1.000001 {
        for m in mults {
            let v: f64 = format!("{:.12e}", m * 10f64.powi(e)).parse().unwrap_or(0.0);
            let last = *ticks.last().unwrap_or(&min);
            if v > min * 1.000001 && v < max / 1.000001 && v > last {
                ticks.push(v);
            }
        }
        e += 1;
    }
    ticks.push(max);
    ticks
}

/// The `q` quantile (0..1) of sorted data, nearest-rank; `None` if empty.
fn percentile(sorted: &[f64], q: f64) -> Option<f64> {
    if sorted.is_empty() {
        return None;
    }
    let i = ((sorted.len() - 1) as f64 * q).round() as usize;
    Some(sorted[i.min(sorted.len() - 1)])
}

/// The smallest "nice" number ≥ `v` (> 0): 1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10ᵏ.
pub fn nice_ceil(v: f64) -> f64 {
    if v.is_nan() || v <= 0.0 || !v.is_finite() {
        return 1.0;
    }
    let e = v.log10().floor();
    let base = 10f64.powf(e);
    for m in [1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0] {
        let c: f64 = format!("{:.12e}", m * base).parse().unwrap_or(m * base);
        if c >= v * (1.0 - 1e-12) {
            return c;
        }
    }
    10.0 * base
}

/// What a false-colour image shows, returned by [`write_falsecolour`] so that callers and
/// tests can relate the PNG to the data.
#[derive(Clone, Debug, PartialEq)]
pub struct LegendInfo {
    /// The quantity shown.
    pub quantity: Quantity,
    /// SI or imperial.
    pub units: UnitSystem,
    /// Unit symbol printed on the legend (`cd/m²`, `lx`, `fL`, `fc`).
    pub unit: String,
    /// The resolved colour scale; its `ticks` are the legend's values (display units).
    pub scale: ColourScale,
    /// Colour of each band, bottom to top (empty for a continuous scale).
    pub step_colours: Vec<[u8; 3]>,
    /// Pixels where the quantity is undefined (drawn hatched grey).
    pub undefined_pixels: usize,
    /// Defined pixels below the range's minimum (painted with the lowest colour; the legend's
    /// bottom label then reads "< min").
    pub below_range: usize,
    /// Defined pixels above the range's maximum (painted with the highest colour; the legend's
    /// top label then reads "> max").
    pub above_range: usize,
    /// Smallest, mean and largest defined value (display units); `None` if nothing is defined.
    pub stats: Option<(f64, f64, f64)>,
    /// Top-left corner of the map inside the PNG.
    pub map_origin: (u32, u32),
    /// Each image pixel is drawn as `zoom` × `zoom` PNG pixels.
    pub zoom: u32,
    /// Size of the PNG, pixels.
    pub image_size: (u32, u32),
}

/// Neutral greys of the "undefined" hatching.
pub const UNDEFINED_HATCH: (Colour, Colour) = (Rgb([140, 140, 140]), Rgb([200, 200, 200]));
const HATCH_PERIOD: u32 = 8;
const PAD: u32 = 16;
const TITLE_PX: f32 = 20.0;
const LABEL_PX: f32 = 14.0;
const BAR_W: u32 = 26;

/// The values to map (display units) and whether each pixel is defined.
fn extract(
    layers: &Layers,
    settings: &FalsecolourSettings,
) -> Result<(Vec<f64>, Vec<bool>), String> {
    let units = settings.units;
    let q = settings.quantity;
    match q {
        Quantity::Luminance => {
            let y = layers
                .channel(CHANNEL_Y)
                .ok_or_else(|| format!("image has no '{CHANNEL_Y}' (luminance) channel"))?;
            let v = y.iter().map(|&v| units.from_si(q, v as f64)).collect();
            let defined = y.iter().map(|v| v.is_finite()).collect();
            Ok((v, defined))
        }
        Quantity::Illuminance => {
            let e = layers.channel(CHANNEL_E).ok_or_else(|| {
                format!(
                    "image has no '{CHANNEL_E}' (illuminance) channel; render with --illuminance"
                )
            })?;
            let mask = layers.channel(CHANNEL_E_MASK);
            let defined: Vec<bool> = e
                .iter()
                .enumerate()
                .map(|(i, &v)| {
                    v.is_finite()
                        && v != ILLUMINANCE_SENTINEL
                        && v >= 0.0
                        && mask.is_none_or(|m| m[i] > 0.0)
                })
                .collect();
            let v = e.iter().map(|&v| units.from_si(q, v as f64)).collect();
            Ok((v, defined))
        }
        other => Err(format!(
            "a false-colour map shows luminance or illuminance, not {}",
            other.name()
        )),
    }
}

/// Renders the false-colour image in memory (see [`write_falsecolour`]).
pub fn render_falsecolour(
    layers: &Layers,
    settings: &FalsecolourSettings,
) -> Result<(RgbImage, LegendInfo), String> {
    let (w, h) = (layers.width, layers.height);
    if w == 0 || h == 0 {
        return Err("image is empty".into());
    }
    let (values, defined) = extract(layers, settings)?;
    if values.len() != w * h {
        return Err(format!(
            "channel has {} samples, expected {w}×{h}",
            values.len()
        ));
    }
    let data: Vec<f64> = values
        .iter()
        .zip(&defined)
        .filter(|(_, &d)| d)
        .map(|(&v, _)| v)
        .collect();
    let cs = ColourScale::resolve(settings, &data)?;
    let undefined = defined.iter().filter(|&&d| !d).count();
    let stats = if data.is_empty() {
        None
    } else {
        let lo = data.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = data.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Some((lo, data.iter().sum::<f64>() / data.len() as f64, hi))
    };
    let unit = settings.units.symbol(settings.quantity);

    // Zoom small images so the map is at least ~420 px tall, within 2400 px of width.
    let zoom = 420_usize.div_ceil(h).clamp(1, 16).min((2400 / w).max(1)) as u32;
    let (mw, mh) = (w as u32 * zoom, h as u32 * zoom);

    let title = settings.title.clone().unwrap_or_else(|| {
        let name = settings.quantity.name();
        let mut c = name.chars();
        c.next()
            .map(|f| f.to_uppercase().collect::<String>() + c.as_str())
            .unwrap_or_default()
    });
    let subtitle = describe_scale(&cs, unit);
    let footer = match stats {
        Some((lo, mean, hi)) => {
            let mut s = format!(
                "min {}   mean {}   max {} {unit}",
                format_sig(lo, 4),
                format_sig(mean, 4),
                format_sig(hi, 4)
            );
            if undefined > 0 {
                s += &format!("   (over {} of {} pixels)", data.len(), w * h);
            }
            s
        }
        None => format!("no pixel has a defined {}", settings.quantity.name()),
    };
    let undefined_label = (undefined > 0).then(|| {
        let what = match settings.quantity {
            Quantity::Illuminance => "no surface: E undefined",
            _ => "undefined",
        };
        format!(
            "{what} ({} %)",
            format_sig(100.0 * undefined as f64 / (w * h) as f64, 3)
        )
    });

    let below_range = data.iter().filter(|&&v| v < cs.min).count();
    let above_range = data.iter().filter(|&&v| v > cs.max).count();
    let legend = Legend::new(
        &cs,
        unit,
        undefined_label.as_deref(),
        (below_range > 0, above_range > 0),
        mh.max(260),
    );
    let header_h = PAD + draw::line_height(TITLE_PX) + 4 + draw::line_height(LABEL_PX) + 10;
    let footer_h = 8 + draw::line_height(LABEL_PX) + PAD;
    let body_h = mh.max(legend.height);
    let width = (PAD + mw + 24 + legend.width + PAD)
        .max(PAD * 2 + draw::text_width(TITLE_PX, &title))
        .max(PAD * 2 + draw::text_width(LABEL_PX, &subtitle))
        .max(PAD * 2 + draw::text_width(LABEL_PX, &footer));
    let height = header_h + body_h + footer_h;
    let mut img = RgbImage::from_pixel(width, height, WHITE);

    draw::draw_text(&mut img, PAD as i32, PAD as i32, TITLE_PX, &title, BLACK);
    let sub_y = PAD + draw::line_height(TITLE_PX) + 4;
    draw::draw_text(
        &mut img,
        PAD as i32,
        sub_y as i32,
        LABEL_PX,
        &subtitle,
        DARK_GREY,
    );

    // The map.
    let (ox, oy) = (PAD, header_h);
    let classes: Vec<usize> = values.iter().map(|&v| cs.contour_class(v)).collect();
    for j in 0..h {
        for i in 0..w {
            let k = j * w + i;
            let (x0, y0) = (ox + i as u32 * zoom, oy + j as u32 * zoom);
            if defined[k] {
                let c = Rgb(cs.colour(values[k]));
                for dy in 0..zoom {
                    for dx in 0..zoom {
                        img.put_pixel(x0 + dx, y0 + dy, c);
                    }
                }
            } else {
                for dy in 0..zoom {
                    for dx in 0..zoom {
                        let (px, py) = (x0 + dx, y0 + dy);
                        let (a, b) = UNDEFINED_HATCH;
                        let c = draw::hatch_colour(px as i32, py as i32, a, b, HATCH_PERIOD);
                        img.put_pixel(px, py, c);
                    }
                }
            }
        }
    }
    if settings.contours {
        let line = Rgb([0, 0, 0]);
        for j in 0..h {
            for i in 0..w {
                let k = j * w + i;
                if !defined[k] {
                    continue;
                }
                let (x0, y0) = (ox + i as u32 * zoom, oy + j as u32 * zoom);
                if i + 1 < w && defined[k + 1] && classes[k + 1] != classes[k] {
                    for dy in 0..zoom {
                        img.put_pixel(x0 + zoom - 1, y0 + dy, line);
                    }
                }
                if j + 1 < h && defined[k + w] && classes[k + w] != classes[k] {
                    for dx in 0..zoom {
                        img.put_pixel(x0 + dx, y0 + zoom - 1, line);
                    }
                }
            }
        }
    }
    draw::stroke_rect(
        &mut img,
        ox as i32 - 1,
        oy as i32 - 1,
        mw + 2,
        mh + 2,
        DARK_GREY,
    );

    legend.draw(&mut img, (ox + mw + 24) as i32, oy as i32);
    draw::draw_text(
        &mut img,
        PAD as i32,
        (header_h + body_h + 8) as i32,
        LABEL_PX,
        &footer,
        BLACK,
    );

    let info = LegendInfo {
        quantity: settings.quantity,
        units: settings.units,
        unit: unit.to_string(),
        step_colours: (0..cs.steps.unwrap_or(0))
            .map(|k| cs.step_colour(k))
            .collect(),
        scale: cs,
        undefined_pixels: undefined,
        below_range,
        above_range,
        stats,
        map_origin: (ox, oy),
        zoom,
        image_size: (width, height),
    };
    Ok((img, info))
}

/// The legend's label of tick `i`: its value, with "< " / "> " on the end ticks when some
/// values lie outside the range (and take the end colours).
fn tick_label(cs: &ColourScale, i: usize, (below, above): (bool, bool)) -> String {
    let v = format_sig(cs.ticks[i], 3);
    if i == 0 && below {
        format!("< {v}")
    } else if i + 1 == cs.ticks.len() && above {
        format!("> {v}")
    } else {
        v
    }
}

/// "linear scale, 10 steps, 0 – 500 cd/m²".
pub fn describe_scale(cs: &ColourScale, unit: &str) -> String {
    let steps = match cs.steps {
        Some(n) => format!("{n} steps"),
        None => "continuous".to_string(),
    };
    format!(
        "{} scale, {steps}, {} – {} {unit}, {}",
        cs.scale.name(),
        format_sig(cs.min, 4),
        format_sig(cs.max, 4),
        cs.palette.name()
    )
}

/// Writes the false-colour PNG of `layers` to `path` atomically and returns what the legend
/// shows. Errors (missing channel, bad range, I/O) name `path`.
pub fn write_falsecolour(
    path: &Path,
    layers: &Layers,
    settings: &FalsecolourSettings,
) -> Result<LegendInfo, OutputError> {
    let (img, info) =
        render_falsecolour(layers, settings).map_err(|e| OutputError::invalid(path, e))?;
    write_png(path, &img)?;
    Ok(info)
}

/// Encodes `img` as PNG and writes it atomically.
pub fn write_png(path: &Path, img: &RgbImage) -> Result<(), OutputError> {
    let mut bytes = Vec::new();
    img.write_to(&mut Cursor::new(&mut bytes), ImageFormat::Png)
        .map_err(|e| OutputError::Png {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    write_atomic(path, |w| w.write_all(&bytes))
}

/// The legend bar: unit above, bar with ticks and values, optional "undefined" swatch below.
pub(crate) struct Legend<'a> {
    cs: &'a ColourScale,
    unit: &'a str,
    undefined: Option<&'a str>,
    /// Some values lie below `min` / above `max` (labelled "< min" / "> max").
    clipped: (bool, bool),
    bar_h: u32,
    /// Total size, pixels.
    pub width: u32,
    pub height: u32,
}

impl<'a> Legend<'a> {
    const UNIT_GAP: u32 = 8;

    /// A legend whose bar is about `height` pixels tall overall.
    pub fn new(
        cs: &'a ColourScale,
        unit: &'a str,
        undefined: Option<&'a str>,
        clipped: (bool, bool),
        height: u32,
    ) -> Self {
        let lh = draw::line_height(LABEL_PX);
        let n = cs.ticks.len();
        let labels_w = (0..n)
            .map(|i| draw::text_width(LABEL_PX, &tick_label(cs, i, clipped)))
            .max()
            .unwrap_or(0);
        let unit_w = draw::text_width(LABEL_PX, unit);
        let undef_h = if undefined.is_some() { lh + 14 } else { 0 };
        let undef_w = undefined
            .map(|s| 22 + 8 + draw::text_width(LABEL_PX, s))
            .unwrap_or(0);
        let top = lh + Self::UNIT_GAP + lh / 2;
        let bar_h = height.saturating_sub(top + lh / 2 + undef_h).max(120);
        Legend {
            cs,
            unit,
            undefined,
            clipped,
            bar_h,
            width: (BAR_W + 6 + labels_w).max(unit_w).max(undef_w),
            height: top + bar_h + lh / 2 + undef_h,
        }
    }

    /// Draws the legend with its top-left corner at (`x`, `y`).
    pub fn draw(&self, img: &mut RgbImage, x: i32, y: i32) {
        let lh = draw::line_height(LABEL_PX) as i32;
        draw::draw_text(img, x, y, LABEL_PX, self.unit, BLACK);
        let bar_top = y + lh + Self::UNIT_GAP as i32 + lh / 2;
        let bar_h = self.bar_h as i32;
        let cs = self.cs;
        // Bar: row r (0 = top) shows the colour of the position at its centre.
        for r in 0..bar_h {
            let t = 1.0 - (r as f64 + 0.5) / bar_h as f64;
            let c = match cs.steps {
                Some(n) => cs.step_colour(((t * n as f64).floor() as usize).min(n - 1)),
                None => cs.palette.eval(t),
            };
            draw::fill_rect(img, x, bar_top + r, BAR_W, 1, Rgb(c));
        }
        draw::stroke_rect(
            img,
            x - 1,
            bar_top - 1,
            BAR_W + 2,
            self.bar_h + 2,
            DARK_GREY,
        );
        // Ticks: every one drawn, labels thinned so that they do not overlap.
        let tick_y = |v: f64| bar_top + bar_h - (cs.position(v) * bar_h as f64).round() as i32;
        let mut last_label_y = i32::MAX;
        let n = cs.ticks.len();
        for (i, &v) in cs.ticks.iter().enumerate() {
            let ty = tick_y(v);
            draw::draw_line(
                img,
                (x + BAR_W as i32) as f32,
                ty as f32,
                (x + BAR_W as i32 + 4) as f32,
                ty as f32,
                BLACK,
            );
            // Always label both ends; label inner ticks where there is room.
            let room = (last_label_y - ty) >= lh;
            let room_for_top = i + 1 == n || (ty - tick_y(cs.ticks[n - 1])) >= lh;
            if i == 0 || i + 1 == n || (room && room_for_top) {
                let label = tick_label(cs, i, self.clipped);
                let f = draw::line_height(LABEL_PX) as i32;
                draw::draw_text(
                    img,
                    x + BAR_W as i32 + 7,
                    ty - f / 2,
                    LABEL_PX,
                    &label,
                    BLACK,
                );
                last_label_y = ty;
            }
        }
        if let Some(text) = self.undefined {
            let sy = bar_top + bar_h + lh / 2 + 12;
            let (a, b) = UNDEFINED_HATCH;
            draw::hatch_rect(img, x, sy, 22, lh as u32 - 2, a, b, HATCH_PERIOD);
            draw::stroke_rect(img, x - 1, sy - 1, 24, lh as u32, DARK_GREY);
            draw::draw_text(img, x + 30, sy - 2, LABEL_PX, text, BLACK);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn banded_steps_and_nice_automatic_maximum() {
        let values: Vec<f64> = (0..=100).map(|i| i as f64 * 0.22).collect();
        let s = FalsecolourSettings {
            steps: Some(8),
            ..Default::default()
        };
        let cs = ColourScale::resolve(&s, &values).unwrap();
        // 99th percentile 21.8 → 8 steps of 3.
        assert_eq!(cs.max, 24.0);
        assert_eq!(cs.ticks[1], 3.0);
        assert_eq!(cs.step_of(2.99), Some(0));
        assert_eq!(cs.step_of(3.0), Some(1));
        assert_eq!(cs.step_of(-5.0), Some(0));
        assert_eq!(cs.step_of(1e9), Some(7));
        assert_eq!(cs.colour(1e9), cs.step_colour(7));
    }

    #[test]
    fn nice_numbers() {
        assert_eq!(nice_ceil(437.0), 500.0);
        assert_eq!(nice_ceil(500.0), 500.0);
        assert_eq!(nice_ceil(0.0123), 0.015);
        assert_eq!(nice_ceil(101.0), 120.0);
    }

    #[test]
    fn log_ticks_are_decades_and_125() {
        assert_eq!(
            log_ticks(1.0, 100.0),
            vec![1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0]
        );
        assert_eq!(
            log_ticks(0.01, 1e4),
            vec![0.01, 0.1, 1.0, 10.0, 100.0, 1000.0, 1e4]
        );
    }

    #[test]
    fn automatic_ranges() {
        let values: Vec<f64> = (0..1000).map(|i| i as f64 * 0.437).collect();
        let s = FalsecolourSettings::default();
        let cs = ColourScale::resolve(&s, &values).unwrap();
        assert_eq!((cs.min, cs.max), (0.0, 500.0));
        let s = FalsecolourSettings {
            scale: Scale::Log,
            ..Default::default()
        };
        let cs = ColourScale::resolve(&s, &values).unwrap();
        assert_eq!((cs.min, cs.max), (1.0, 1000.0));
        let bad = FalsecolourSettings {
            scale: Scale::Log,
            min: Some(0.0),
            ..Default::default()
        };
        assert!(ColourScale::resolve(&bad, &values).is_err());
    }
}
