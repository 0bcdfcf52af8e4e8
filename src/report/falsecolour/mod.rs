//! False-colour maps of luminance (`Y`) or illuminance (`E`) with a legend bar.
//!
//! [`write_falsecolour`] turns a [`Layers`](crate::output::Layers) image into an 8-bit sRGB
//! PNG: the map (pixels coloured by value, optionally banded into steps and outlined by contour
//! lines), a legend bar with tick values and the unit, a title, and a footer with the image's
//! min / mean / max. Where illuminance is undefined (the pixel sees no surface: `mask.E` = 0 or
//! `E` = the sentinel) the map is hatched in neutral grey and the legend says so.
//!
//! This module holds the settings and what a map shows; `scale` maps values to colours
//! ([`ColourScale`], shared with the grid heat maps of [`super::heatmap`]), `map` draws the
//! image and `legend` the legend bar. See `docs/reports.md`.

mod legend;
mod map;
mod scale;

use image::Rgb;

use super::units::UnitSystem;
use crate::output::draw::Colour;
use crate::photometry::Quantity;

pub use legend::describe_scale;
pub(crate) use legend::Legend;
pub use map::{bytes_per_pixel, render_falsecolour, write_falsecolour};
pub use scale::{nice_ceil, ColourScale, Palette, Scale};

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
const LABEL_PX: f32 = 14.0;
