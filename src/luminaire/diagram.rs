//! Polar candela diagram like a manufacturer's data sheet: nadir (γ = 0) at the bottom, the
//! C0–C180 plane in solid red (C0 on the right), the C90–C270 plane in dashed blue (C90 on the
//! right), rings at round candela values labelled in cd, spokes every 30° labelled in degrees.
//! Drawn with the `image` crate and a small embedded 5×7 bitmap font (our own).

use super::{polar_value, Distribution};
use image::{Rgb, RgbImage};

const SIZE: u32 = 800;
const BG: Rgb<u8> = Rgb([255, 255, 255]);
const GRID: Rgb<u8> = Rgb([200, 200, 200]);
const TEXT: Rgb<u8> = Rgb([60, 60, 60]);
const RED: Rgb<u8> = Rgb([210, 30, 30]);
const BLUE: Rgb<u8> = Rgb([30, 70, 210]);

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

/// Render the diagram.
pub fn draw(dist: &Distribution, title: &str) -> RgbImage {
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
    let step = ring_step(vmax);
    let nrings = ((vmax / step).ceil() as usize).max(1);
    let full = step * nrings as f64;
    let scale = radius / full;
    // Rings and their labels.
    for r in 1..=nrings {
        let rr = r as f64 * step * scale;
        circle(&mut img, cx, cy, rr, GRID);
        let label = format_cd(r as f64 * step);
        text(
            &mut img,
            (cx + 4.0) as i32,
            (cy - rr - 10.0) as i32,
            &label,
            TEXT,
            2,
        );
    }
    // Spokes every 30°, angle 0 pointing down (nadir).
    for k in 0..12 {
        let t = (k as f64 * 30.0).to_radians();
        let (ex, ey) = (cx + radius * t.sin(), cy + radius * t.cos());
        line(&mut img, cx, cy, ex, ey, GRID, None);
        let deg = if k <= 6 { k * 30 } else { 360 - k * 30 };
        let label = format!("{deg}°");
        let (lx, ly) = (
            cx + (radius + 22.0) * t.sin(),
            cy + (radius + 22.0) * t.cos(),
        );
        let wpx = label.chars().count() as i32 * 12;
        text(
            &mut img,
            lx as i32 - wpx / 2,
            ly as i32 - 7,
            &label,
            TEXT,
            2,
        );
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
    text(&mut img, 16, 14, title, TEXT, 2);
    let ly = SIZE as i32 - 30;
    thick_line(
        &mut img,
        (16.0, ly as f64 + 7.0),
        (56.0, ly as f64 + 7.0),
        RED,
    );
    text(&mut img, 64, ly, "C0-C180", TEXT, 2);
    for k in 0..3 {
        let x0 = 200.0 + k as f64 * 14.0;
        thick_line(
            &mut img,
            (x0, ly as f64 + 7.0),
            (x0 + 8.0, ly as f64 + 7.0),
            BLUE,
        );
    }
    text(&mut img, 248, ly, "C90-C270", TEXT, 2);
    text(&mut img, SIZE as i32 - 90, ly, "cd", TEXT, 2);
    img
}

fn format_cd(v: f64) -> String {
    if v >= 1.0 && v.fract() == 0.0 {
        format!("{v:.0}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

fn put(img: &mut RgbImage, x: i64, y: i64, c: Rgb<u8>) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, c);
    }
}

fn circle(img: &mut RgbImage, cx: f64, cy: f64, r: f64, c: Rgb<u8>) {
    let n = (r * 8.0).max(16.0) as usize;
    for k in 0..n {
        let a = k as f64 / n as f64 * std::f64::consts::TAU;
        put(
            img,
            (cx + r * a.cos()).round() as i64,
            (cy + r * a.sin()).round() as i64,
            c,
        );
    }
}

fn line(img: &mut RgbImage, x0: f64, y0: f64, x1: f64, y1: f64, c: Rgb<u8>, _dash: Option<f64>) {
    let n = ((x1 - x0).abs().max((y1 - y0).abs()).ceil() as usize).max(1);
    for k in 0..=n {
        let t = k as f64 / n as f64;
        put(
            img,
            (x0 + t * (x1 - x0)).round() as i64,
            (y0 + t * (y1 - y0)).round() as i64,
            c,
        );
    }
}

fn thick_line(img: &mut RgbImage, a: (f64, f64), b: (f64, f64), c: Rgb<u8>) {
    for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)] {
        line(img, a.0 + dx, a.1 + dy, b.0 + dx, b.1 + dy, c, None);
    }
}

/// 5×7 glyphs: each row is 5 bits, most significant on the left.
fn glyph(ch: char) -> [u8; 7] {
    match ch {
        '0' => [14, 17, 19, 21, 25, 17, 14],
        '1' => [4, 12, 4, 4, 4, 4, 14],
        '2' => [14, 17, 1, 2, 4, 8, 31],
        '3' => [31, 2, 4, 2, 1, 17, 14],
        '4' => [2, 6, 10, 18, 31, 2, 2],
        '5' => [31, 16, 30, 1, 1, 17, 14],
        '6' => [6, 8, 16, 30, 17, 17, 14],
        '7' => [31, 1, 2, 4, 8, 8, 8],
        '8' => [14, 17, 17, 14, 17, 17, 14],
        '9' => [14, 17, 17, 15, 1, 2, 12],
        '.' => [0, 0, 0, 0, 0, 12, 12],
        '-' => [0, 0, 0, 31, 0, 0, 0],
        '_' => [0, 0, 0, 0, 0, 0, 31],
        '/' => [1, 1, 2, 4, 8, 16, 16],
        ':' => [0, 12, 12, 0, 12, 12, 0],
        '°' => [12, 18, 18, 12, 0, 0, 0],
        '(' => [2, 4, 8, 8, 8, 4, 2],
        ')' => [8, 4, 2, 2, 2, 4, 8],
        ' ' => [0; 7],
        'a' => [0, 0, 14, 1, 15, 17, 15],
        'b' => [16, 16, 22, 25, 17, 17, 30],
        'c' => [0, 0, 14, 16, 16, 17, 14],
        'd' => [1, 1, 13, 19, 17, 17, 15],
        'e' => [0, 0, 14, 17, 31, 16, 14],
        'f' => [6, 9, 8, 28, 8, 8, 8],
        'g' => [0, 15, 17, 17, 15, 1, 14],
        'h' => [16, 16, 22, 25, 17, 17, 17],
        'i' => [4, 0, 12, 4, 4, 4, 14],
        'k' => [16, 16, 18, 20, 24, 20, 18],
        'l' => [12, 4, 4, 4, 4, 4, 14],
        'm' => [0, 0, 26, 21, 21, 17, 17],
        'n' => [0, 0, 22, 25, 17, 17, 17],
        'o' => [0, 0, 14, 17, 17, 17, 14],
        'p' => [0, 0, 30, 17, 30, 16, 16],
        'r' => [0, 0, 22, 25, 16, 16, 16],
        's' => [0, 0, 14, 16, 14, 1, 30],
        't' => [8, 8, 28, 8, 8, 9, 6],
        'u' => [0, 0, 17, 17, 17, 19, 13],
        'w' => [0, 0, 17, 17, 21, 21, 10],
        'x' => [0, 0, 17, 10, 4, 10, 17],
        'y' => [0, 0, 17, 17, 15, 1, 14],
        'z' => [0, 0, 31, 2, 4, 8, 31],
        c if c.is_ascii_uppercase() => upper(c),
        _ => [31, 17, 17, 17, 17, 17, 31],
    }
}

fn upper(c: char) -> [u8; 7] {
    match c {
        'A' => [14, 17, 17, 31, 17, 17, 17],
        'B' => [30, 17, 17, 30, 17, 17, 30],
        'C' => [14, 17, 16, 16, 16, 17, 14],
        'D' => [28, 18, 17, 17, 17, 18, 28],
        'E' => [31, 16, 16, 30, 16, 16, 31],
        'F' => [31, 16, 16, 30, 16, 16, 16],
        'G' => [14, 17, 16, 23, 17, 17, 15],
        'H' => [17, 17, 17, 31, 17, 17, 17],
        'I' => [14, 4, 4, 4, 4, 4, 14],
        'L' => [16, 16, 16, 16, 16, 16, 31],
        'M' => [17, 27, 21, 21, 17, 17, 17],
        'N' => [17, 17, 25, 21, 19, 17, 17],
        'O' => [14, 17, 17, 17, 17, 17, 14],
        'P' => [30, 17, 17, 30, 16, 16, 16],
        'R' => [30, 17, 17, 30, 20, 18, 17],
        'S' => [15, 16, 16, 14, 1, 1, 30],
        'T' => [31, 4, 4, 4, 4, 4, 4],
        'U' => [17, 17, 17, 17, 17, 17, 14],
        'W' => [17, 17, 17, 21, 21, 21, 10],
        'X' => [17, 17, 10, 4, 10, 17, 17],
        'Y' => [17, 17, 10, 4, 4, 4, 4],
        _ => [31, 17, 17, 17, 17, 17, 31],
    }
}

/// Draw text with its top-left corner at (x, y), each font pixel `s`×`s`.
pub fn text(img: &mut RgbImage, x: i32, y: i32, s: &str, c: Rgb<u8>, scale: i32) {
    for (k, ch) in s.chars().enumerate() {
        let g = glyph(ch);
        let ox = x + k as i32 * 6 * scale;
        for (row, bits) in g.iter().enumerate() {
            for col in 0..5 {
                if bits & (16 >> col) != 0 {
                    for dy in 0..scale {
                        for dx in 0..scale {
                            put(
                                img,
                                (ox + col * scale + dx) as i64,
                                (y + row as i32 * scale + dy) as i64,
                                c,
                            );
                        }
                    }
                }
            }
        }
    }
}
