//! The false-colour image: the values of the chosen channel, the coloured (banded, contoured,
//! hatched where undefined) map, title, subtitle and footer, and the PNG file.

use std::path::Path;

use image::{Rgb, RgbImage};

use super::{
    describe_scale, ColourScale, FalsecolourSettings, Legend, LegendInfo, HATCH_PERIOD, LABEL_PX,
    UNDEFINED_HATCH,
};
use crate::limits::{check_memory, printable};
use crate::output::draw::{self, BLACK, DARK_GREY, WHITE};
use crate::output::{
    Layers, OutputError, CHANNEL_E, CHANNEL_E_MASK, CHANNEL_Y, ILLUMINANCE_SENTINEL,
};
use crate::photometry::Quantity;
use crate::report::units::format_sig;

const PAD: u32 = 16;
const TITLE_PX: f32 = 20.0;

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

/// Bytes per image pixel a false-colour map holds beside the image's channels: its value, whether
/// it is defined, the defined values, the range's sorted copy of them, and their positive part
/// (log scale) or contour classes; then the PNG's 3 (the measured peak of `candela
/// falsecolour` is the image's channels and 25 bytes a pixel, linear scale).
pub fn bytes_per_pixel(settings: &FalsecolourSettings) -> u64 {
    let log_or_contours = settings.scale == super::Scale::Log || settings.contours;
    8 + 1 + 8 + 8 + if log_or_contours { 8 } else { 0 } + 3
}

/// Renders the false-colour image in memory (see [`write_falsecolour`]).
pub fn render_falsecolour(
    layers: &Layers,
    settings: &FalsecolourSettings,
) -> Result<(RgbImage, LegendInfo), String> {
    let pixels = check_image(layers, settings)?;
    let (w, h) = (layers.width, layers.height);
    let (values, defined) = extract(layers, settings)?;
    let data: Vec<f64> = values
        .iter()
        .zip(&defined)
        .filter(|(_, &d)| d)
        .map(|(&v, _)| v)
        .collect();
    let cs = ColourScale::resolve(settings, &data)?;
    let undefined = defined.iter().filter(|&&d| !d).count();
    let stats = min_mean_max(&data);
    let unit = settings.units.symbol(settings.quantity);

    // Zoom small images so the map is at least ~420 px tall, within 2400 px of width.
    let zoom = 420_usize.div_ceil(h).clamp(1, 16).min((2400 / w).max(1)) as u32;
    let (mw, mh) = (w as u32 * zoom, h as u32 * zoom);

    let title = title(settings);
    let subtitle = describe_scale(&cs, unit);
    let footer = footer(settings, stats, unit, undefined, data.len(), w * h);
    let undefined_label = undefined_label(settings, undefined, w * h);

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
    // The PNG's pixels, beside the values, flags, defined values and contour classes.
    let kept = 8 + 1 + 8 + if settings.contours { 8 } else { 0 };
    check_memory(
        width as u64 * height as u64 * 3 + pixels as u64 * kept,
        &format!("the false-colour PNG ({width}×{height} pixels) of the {w}×{h} image"),
    )?;
    let mut img = RgbImage::from_pixel(width, height, WHITE);

    draw_header(&mut img, &title, &subtitle);
    let (ox, oy) = (PAD, header_h);
    let place = Placement {
        w,
        h,
        zoom,
        origin: (ox, oy),
    };
    draw_map(&mut img, place, &values, &defined, &cs, settings.contours);

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

/// Refuses an image a map cannot be drawn of (empty, too large a side, channels of the wrong
/// length, or past the memory available); returns its number of pixels.
fn check_image(layers: &Layers, settings: &FalsecolourSettings) -> Result<usize, String> {
    let (w, h) = (layers.width, layers.height);
    if w == 0 || h == 0 {
        return Err("image is empty".into());
    }
    // Pixel coordinates of the PNG are drawn as i32 and u32.
    const MAX_SIDE: usize = 1 << 28;
    if w.max(h) > MAX_SIDE {
        return Err(format!(
            "the {w}×{h} image is too large for a false-colour map (at most {MAX_SIDE} pixels a side)"
        ));
    }
    let pixels = w.checked_mul(h).ok_or("the image size overflows")?;
    if let Some((name, c)) = layers.channels.iter().find(|(_, c)| c.len() != pixels) {
        return Err(format!(
            "channel '{name}' has {} samples, expected {w}×{h}",
            c.len()
        ));
    }
    check_memory(
        pixels as u64 * bytes_per_pixel(settings),
        &format!("the false-colour map of the {w}×{h} image"),
    )?;
    Ok(pixels)
}

/// Minimum, mean and maximum of the defined values, or `None` if there are none.
fn min_mean_max(data: &[f64]) -> Option<(f64, f64, f64)> {
    if data.is_empty() {
        None
    } else {
        let lo = data.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = data.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Some((lo, data.iter().sum::<f64>() / data.len() as f64, hi))
    }
}

/// The title: the one given, or the quantity's name capitalised.
fn title(settings: &FalsecolourSettings) -> String {
    settings
        .title
        .as_deref()
        .map(|t| printable(t, 200))
        .unwrap_or_else(|| {
            let name = settings.quantity.name();
            let mut c = name.chars();
            c.next()
                .map(|f| f.to_uppercase().collect::<String>() + c.as_str())
                .unwrap_or_default()
        })
}

/// The footer: min, mean and max over the `defined` of `total` pixels.
fn footer(
    settings: &FalsecolourSettings,
    stats: Option<(f64, f64, f64)>,
    unit: &str,
    undefined: usize,
    defined: usize,
    total: usize,
) -> String {
    match stats {
        Some((lo, mean, hi)) => {
            let mut s = format!(
                "min {}   mean {}   max {} {unit}",
                format_sig(lo, 4),
                format_sig(mean, 4),
                format_sig(hi, 4)
            );
            if undefined > 0 {
                s += &format!("   (over {defined} of {total} pixels)");
            }
            s
        }
        None => format!("no pixel has a defined {}", settings.quantity.name()),
    }
}

/// The legend's entry for the hatched pixels, with their share of all `total`, if any.
fn undefined_label(
    settings: &FalsecolourSettings,
    undefined: usize,
    total: usize,
) -> Option<String> {
    (undefined > 0).then(|| {
        let what = match settings.quantity {
            Quantity::Illuminance => "no surface: E undefined",
            _ => "undefined",
        };
        format!(
            "{what} ({} %)",
            format_sig(100.0 * undefined as f64 / total as f64, 3)
        )
    })
}

/// Where the image's `w` × `h` pixels go in the PNG: each a `zoom` × `zoom` square, pixel
/// (0, 0) at `origin`.
#[derive(Clone, Copy)]
struct Placement {
    w: usize,
    h: usize,
    zoom: u32,
    origin: (u32, u32),
}

/// The title, and below it the colour scale's description in grey.
fn draw_header(img: &mut RgbImage, title: &str, subtitle: &str) {
    draw::draw_text(img, PAD as i32, PAD as i32, TITLE_PX, title, BLACK);
    let sub_y = PAD + draw::line_height(TITLE_PX) + 4;
    draw::draw_text(img, PAD as i32, sub_y as i32, LABEL_PX, subtitle, DARK_GREY);
}

/// The map, its contour lines if asked for, and a frame around it.
fn draw_map(
    img: &mut RgbImage,
    place: Placement,
    values: &[f64],
    defined: &[bool],
    cs: &ColourScale,
    contours: bool,
) {
    draw_pixels(img, place, values, defined, cs);
    if contours {
        draw_contours(img, place, values, defined, cs);
    }
    let (ox, oy) = place.origin;
    let (mw, mh) = (place.w as u32 * place.zoom, place.h as u32 * place.zoom);
    draw::stroke_rect(img, ox as i32 - 1, oy as i32 - 1, mw + 2, mh + 2, DARK_GREY);
}

/// Each defined pixel in its colour, each undefined one hatched.
fn draw_pixels(
    img: &mut RgbImage,
    place: Placement,
    values: &[f64],
    defined: &[bool],
    cs: &ColourScale,
) {
    let Placement {
        w,
        h,
        zoom,
        origin: (ox, oy),
    } = place;
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
}

/// Contour lines: on the right or bottom edge of a defined pixel whose neighbour there is
/// defined and in another contour class.
fn draw_contours(
    img: &mut RgbImage,
    place: Placement,
    values: &[f64],
    defined: &[bool],
    cs: &ColourScale,
) {
    let Placement {
        w,
        h,
        zoom,
        origin: (ox, oy),
    } = place;
    let classes: Vec<usize> = values.iter().map(|&v| cs.contour_class(v)).collect();
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

/// Writes the false-colour PNG of `layers` to `path` atomically and returns what the legend
/// shows. Errors (missing channel, bad range, I/O) name `path`.
pub fn write_falsecolour(
    path: &Path,
    layers: &Layers,
    settings: &FalsecolourSettings,
) -> Result<LegendInfo, OutputError> {
    let (img, info) =
        render_falsecolour(layers, settings).map_err(|e| OutputError::invalid(path, e))?;
    crate::output::write_rgb_png(path, &img)?;
    Ok(info)
}
