//! The legend bar beside a false-colour map or heat map: unit, colour bar, tick values, the
//! "undefined" swatch, and the one-line description of a scale.

use image::{Rgb, RgbImage};

use super::{ColourScale, HATCH_PERIOD, LABEL_PX, UNDEFINED_HATCH};
use crate::output::draw::{self, BLACK, DARK_GREY};
use crate::report::units::format_sig;

const BAR_W: u32 = 26;

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
