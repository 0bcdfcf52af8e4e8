//! Small drawing helpers for report images: text, lines and rectangles on an 8-bit RGB image.
//!
//! Text is rasterised by `ab_glyph` (via `imageproc`) from DejaVu Sans, which is compiled
//! into the binary (`data/fonts/DejaVuSans.ttf`, Bitstream Vera licence, see
//! `data/fonts/LICENSE-DejaVu.txt`), so nothing depends on the system's fonts. Coordinates are
//! pixels, (0, 0) = top-left; anything outside the image is clipped.

use std::sync::OnceLock;

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};
use image::{Rgb, RgbImage};
use imageproc::drawing::{
    draw_antialiased_line_segment_mut, draw_filled_rect_mut, draw_hollow_circle_mut,
    draw_line_segment_mut, draw_text_mut,
};
use imageproc::pixelops::interpolate;
use imageproc::rect::Rect;

/// An sRGB colour.
pub type Colour = Rgb<u8>;

/// Black.
pub const BLACK: Colour = Rgb([0, 0, 0]);
/// White.
pub const WHITE: Colour = Rgb([255, 255, 255]);
/// Dark grey for secondary text and frames.
pub const DARK_GREY: Colour = Rgb([64, 64, 64]);

static FONT_BYTES: &[u8] = include_bytes!("../../data/fonts/DejaVuSans.ttf");

/// The built-in font (DejaVu Sans).
pub fn font() -> &'static FontRef<'static> {
    static FONT: OnceLock<FontRef<'static>> = OnceLock::new();
    FONT.get_or_init(|| FontRef::try_from_slice(FONT_BYTES).expect("bundled DejaVu Sans parses"))
}

/// Draws `text` (one line) with its top-left corner at (`x`, `y`); `px_size` is the font's
/// em height in pixels (the line is [`line_height`] tall). Anti-aliased over the background.
pub fn draw_text(img: &mut RgbImage, x: i32, y: i32, px_size: f32, text: &str, colour: Colour) {
    draw_text_mut(img, colour, x, y, PxScale::from(px_size), font(), text);
}

/// Width in pixels that [`draw_text`] advances for `text` at `px_size`.
pub fn text_width(px_size: f32, text: &str) -> u32 {
    let f = font().as_scaled(PxScale::from(px_size));
    let mut w = 0.0f32;
    let mut last = None;
    for c in text.chars() {
        let id = f.glyph_id(c);
        if let Some(prev) = last {
            w += f.kern(prev, id);
        }
        w += f.h_advance(id);
        last = Some(id);
    }
    w.ceil() as u32
}

/// Height of one line of text at `px_size` (ascent − descent), pixels.
pub fn line_height(px_size: f32) -> u32 {
    let f = font().as_scaled(PxScale::from(px_size));
    (f.ascent() - f.descent()).ceil() as u32
}

/// Draws `text` so that its horizontal centre is `cx` and its vertical centre `cy`.
pub fn draw_text_centred(
    img: &mut RgbImage,
    cx: i32,
    cy: i32,
    px_size: f32,
    text: &str,
    colour: Colour,
) {
    let w = text_width(px_size, text) as i32;
    let f = font().as_scaled(PxScale::from(px_size));
    // Centre the cap height (approximately 0.73 em for DejaVu Sans) rather than the full line.
    let top = cy as f32 - f.ascent() + 0.365 * px_size;
    draw_text(img, cx - w / 2, top.round() as i32, px_size, text, colour);
}

/// Draws a one-pixel line from (`x0`, `y0`) to (`x1`, `y1`) (Bresenham, not anti-aliased).
pub fn draw_line(img: &mut RgbImage, x0: f32, y0: f32, x1: f32, y1: f32, colour: Colour) {
    draw_line_segment_mut(img, (x0, y0), (x1, y1), colour);
}

/// Draws an anti-aliased one-pixel line between integer pixel positions (Xiaolin Wu), e.g. for
/// diagrams with slanted lines.
pub fn draw_line_aa(img: &mut RgbImage, x0: i32, y0: i32, x1: i32, y1: i32, colour: Colour) {
    draw_antialiased_line_segment_mut(img, (x0, y0), (x1, y1), colour, interpolate);
}

/// Draws the outline of a circle of `radius` pixels centred on (`cx`, `cy`).
pub fn draw_circle(img: &mut RgbImage, cx: i32, cy: i32, radius: i32, colour: Colour) {
    draw_hollow_circle_mut(img, (cx, cy), radius, colour);
}

/// Fills the rectangle with top-left (`x`, `y`), `w` × `h` pixels. Empty sizes draw nothing.
pub fn fill_rect(img: &mut RgbImage, x: i32, y: i32, w: u32, h: u32, colour: Colour) {
    if w > 0 && h > 0 {
        draw_filled_rect_mut(img, Rect::at(x, y).of_size(w, h), colour);
    }
}

/// Outlines the rectangle with top-left (`x`, `y`), `w` × `h` pixels, one pixel wide, inside.
pub fn stroke_rect(img: &mut RgbImage, x: i32, y: i32, w: u32, h: u32, colour: Colour) {
    if w > 0 && h > 0 {
        imageproc::drawing::draw_hollow_rect_mut(img, Rect::at(x, y).of_size(w, h), colour);
    }
}

/// Fills a rectangle with diagonal hatching (stripes of `a` and `b`, `period` pixels), the
/// convention report images use for "no value here".
#[allow(clippy::too_many_arguments)]
pub fn hatch_rect(
    img: &mut RgbImage,
    x: i32,
    y: i32,
    w: u32,
    h: u32,
    a: Colour,
    b: Colour,
    period: u32,
) {
    for py in y.max(0)..(y + h as i32).min(img.height() as i32) {
        for px in x.max(0)..(x + w as i32).min(img.width() as i32) {
            img.put_pixel(px as u32, py as u32, hatch_colour(px, py, a, b, period));
        }
    }
}

/// The colour of the hatch pattern of [`hatch_rect`] at image pixel (`px`, `py`).
pub fn hatch_colour(px: i32, py: i32, a: Colour, b: Colour, period: u32) -> Colour {
    let p = period.max(2) as i32;
    if (px + py).rem_euclid(p) < p / 2 {
        a
    } else {
        b
    }
}

/// Black or white, whichever reads better on `background` (by its sRGB luma).
pub fn contrasting_text(background: Colour) -> Colour {
    let [r, g, b] = background.0;
    let luma = 0.2126 * r as f32 + 0.7152 * g as f32 + 0.0722 * b as f32;
    if luma > 140.0 {
        BLACK
    } else {
        WHITE
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_drawn_inside_its_measured_box() {
        let mut img = RgbImage::from_pixel(200, 40, WHITE);
        draw_text(&mut img, 10, 5, 20.0, "512 lx", BLACK);
        let w = text_width(20.0, "512 lx");
        assert!(w > 40 && w < 80, "width {w}");
        let dark: Vec<(u32, u32)> = img
            .enumerate_pixels()
            .filter(|(_, _, p)| p.0[0] < 128)
            .map(|(x, y, _)| (x, y))
            .collect();
        assert!(!dark.is_empty());
        assert!(dark
            .iter()
            .all(|&(x, y)| (10..=10 + w).contains(&x) && (5..5 + 26).contains(&y)));
    }
}
