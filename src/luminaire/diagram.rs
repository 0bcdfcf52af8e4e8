//! Polar candela diagram like a manufacturer's data sheet: nadir (γ = 0) at the bottom, the
//! C0–C180 plane in solid red (C0 on the right), the C90–C270 plane in dashed blue (C90 on the
//! right), rings at round candela values labelled in cd, spokes every 30° labelled in degrees.
//! Drawn with the image helpers ([`crate::output::draw`]: `imageproc` lines and
//! circles, text in the bundled DejaVu Sans).

use super::{polar_value, Distribution};
use crate::output::draw;
use crate::output::{write_rgb_png, OutputError};
use image::{Rgb, RgbImage};
use std::path::Path;

/// Label text size (em height, pixels).
const FONT_PX: f32 = 18.0;

const SIZE: u32 = 800;
const BG: Rgb<u8> = Rgb([255, 255, 255]);
const GRID: Rgb<u8> = Rgb([200, 200, 200]);
const TEXT: Rgb<u8> = Rgb([60, 60, 60]);
const RED: Rgb<u8> = Rgb([210, 30, 30]);
const BLUE: Rgb<u8> = Rgb([30, 70, 210]);

/// Smallest positive peak intensity (cd) the diagram is drawn for: the scale from candela to
/// pixels (about 300 / peak) must stay finite.
pub const MIN_PEAK_CD: f64 = 1e-300;

/// A "nice" ring spacing: 1, 2 or 5 × 10^k such that about 5 rings fit `max`.
pub fn ring_step(max: f64) -> f64 {
    if max <= 0.0 || !max.is_finite() {
        return 1.0;
    }
    let raw = max / 5.0;
    let p = 10f64.powf(raw.log10().floor());
    for m in [1.0, 2.0, 5.0, 10.0] {
        if m * p >= raw {
            return m * p;
        }
    }
    10.0 * p
}

/// Draws the diagram of `dist` titled `title` and writes it to `path` as a PNG (atomically).
pub fn write_png(path: &Path, dist: &Distribution, title: &str) -> Result<(), OutputError> {
    let img = draw(dist, title).map_err(|reason| OutputError::InvalidImage {
        path: path.to_path_buf(),
        reason,
    })?;
    write_rgb_png(path, &img)
}

/// Render the diagram; refused (with the reason) when the intensity in the two planes is
/// undefined or infinite, or its peak too small to scale rings by (below [`MIN_PEAK_CD`]), as a
/// file's multipliers can make it.
pub fn draw(dist: &Distribution, title: &str) -> Result<RgbImage, String> {
    let mut img = RgbImage::from_pixel(SIZE, SIZE, BG);
    let (cx, cy) = (SIZE as f64 / 2.0, SIZE as f64 / 2.0 + 10.0);
    let radius = SIZE as f64 * 0.40;
    let curves: Vec<Vec<(f64, f64)>> = [0.0, 90.0]
        .iter()
        .map(|&c| {
            (0..=1440)
                .map(|k| {
                    let t = -180.0 + k as f64 * 0.25;
                    (t, polar_value(dist, c, t))
                })
                .collect()
        })
        .collect();
    let vmax = curves.iter().flatten().map(|p| p.1).fold(0.0, f64::max);
    let undefined = curves.iter().flatten().any(|p| p.1.is_nan());
    if undefined {
        return Err("cannot draw the polar diagram: the intensity in the C0-C180 and C90-C270 planes is undefined after the file's multipliers (infinite values)".into());
    }
    if !(vmax == 0.0 || (vmax.is_finite() && vmax >= MIN_PEAK_CD)) {
        return Err(format!(
            "cannot draw the polar diagram: the peak intensity in the C0-C180 and C90-C270 planes is {vmax:e} cd after the file's multipliers; it must be finite and at least {MIN_PEAK_CD:e} cd"
        ));
    }
    let step = ring_step(vmax);
    let nrings = ((vmax / step).ceil() as usize).max(1);
    let full = step * nrings as f64;
    let scale = radius / full;
    // Rings and their labels.
    for r in 1..=nrings {
        let rr = r as f64 * step * scale;
        draw::draw_circle(
            &mut img,
            cx.round() as i32,
            cy.round() as i32,
            rr.round() as i32,
            GRID,
        );
        let label = format_cd(r as f64 * step);
        draw::draw_text(
            &mut img,
            (cx + 4.0) as i32,
            (cy - rr + 2.0) as i32,
            FONT_PX,
            &label,
            TEXT,
        );
    }
    // Spokes every 30°, angle 0 pointing down (nadir).
    for k in 0..12 {
        let t = (k as f64 * 30.0).to_radians();
        let (ex, ey) = (cx + radius * t.sin(), cy + radius * t.cos());
        draw::draw_line(&mut img, cx as f32, cy as f32, ex as f32, ey as f32, GRID);
        let deg = if k <= 6 { k * 30 } else { 360 - k * 30 };
        let label = format!("{deg}°");
        let (lx, ly) = (
            cx + (radius + 22.0) * t.sin(),
            cy + (radius + 22.0) * t.cos(),
        );
        draw::draw_text_centred(&mut img, lx as i32, ly as i32, FONT_PX, &label, TEXT);
    }
    // Curves: t ≥ 0 to the right (C0 / C90 side), t < 0 to the left.
    for (curve, (colour, dash)) in curves.iter().zip([(RED, None), (BLUE, Some(8.0))]) {
        let pts: Vec<(f64, f64)> = curve
            .iter()
            .map(|&(t, v)| {
                let a = t.to_radians();
                (cx + v * scale * a.sin(), cy + v * scale * a.cos())
            })
            .collect();
        let mut travelled = 0.0;
        for w in pts.windows(2) {
            let seg = ((w[1].0 - w[0].0).powi(2) + (w[1].1 - w[0].1).powi(2)).sqrt();
            let on = dash.is_none_or(|d| (travelled / d) as i64 % 2 == 0);
            if on {
                thick_line(&mut img, w[0], w[1], colour);
            }
            travelled += seg;
        }
    }
    // Title and legend.
    draw::draw_text(&mut img, 16, 10, 22.0, title, TEXT);
    let ly = SIZE as i32 - 30;
    thick_line(
        &mut img,
        (16.0, ly as f64 + 7.0),
        (56.0, ly as f64 + 7.0),
        RED,
    );
    let ty = ly + 7 - draw::line_height(FONT_PX) as i32 / 2;
    draw::draw_text(&mut img, 64, ty, FONT_PX, "C0–C180", TEXT);
    for k in 0..3 {
        let x0 = 200.0 + k as f64 * 14.0;
        thick_line(
            &mut img,
            (x0, ly as f64 + 7.0),
            (x0 + 8.0, ly as f64 + 7.0),
            BLUE,
        );
    }
    draw::draw_text(&mut img, 248, ty, FONT_PX, "C90–C270", TEXT);
    draw::draw_text(&mut img, SIZE as i32 - 60, ty, FONT_PX, "cd", TEXT);
    Ok(img)
}

fn format_cd(v: f64) -> String {
    if v >= 1.0 && v.fract() == 0.0 {
        format!("{v:.0}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// A line two pixels wide (anti-aliased segments offset by one pixel).
fn thick_line(img: &mut RgbImage, a: (f64, f64), b: (f64, f64), c: Rgb<u8>) {
    for (dx, dy) in [(0.0, 0.0), (0.5, 0.5)] {
        draw::draw_line_aa(
            img,
            (a.0 + dx).round() as i32,
            (a.1 + dy).round() as i32,
            (b.0 + dx).round() as i32,
            (b.1 + dy).round() as i32,
            c,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::luminaire::Kind;

    /// A rotationally symmetric table of intensity `cd` at every angle.
    fn flat(cd: f64) -> Distribution {
        Distribution::new(Kind::C, vec![0.0], vec![0.0, 90.0, 180.0], vec![cd; 3])
    }

    /// Infinite and subnormal peaks are refused at once (their ring step would be 0, or 1 for
    /// ∞ rings: a loop without end); zero, tiny normal and the largest finite peaks draw.
    #[test]
    fn undrawable_peaks_are_refused_not_looped_over() {
        for cd in [f64::INFINITY, 1e-301, 1e-310, 5e-324] {
            let e = draw(&flat(cd), "t").err().unwrap_or_default();
            assert!(e.contains("cannot draw the polar diagram"), "{cd}: {e:?}");
        }
        for cd in [0.0, MIN_PEAK_CD, 1000.0, f64::MAX / 4.0] {
            assert!(draw(&flat(cd), "t").is_ok(), "{cd}");
        }
    }
}
