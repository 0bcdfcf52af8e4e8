//! Photometric reports: what a run's images and calculation grids show, in forms a reader checks
//! — the JSON report and grid CSVs, false-colour maps, grid heat maps, the pixel probe and the
//! self-contained HTML report. See `docs/report-json.md`, `docs/reports.md` and
//! `docs/report-html.md`.

pub mod falsecolour;
pub mod heatmap;
pub mod html;
pub mod json;
pub mod probe;
pub mod spectrum;
pub mod units;

use std::path::Path;

use crate::output::{
    Layers, CHANNEL_E, CHANNEL_E_MASK, CHANNEL_E_STDERR, CHANNEL_X, CHANNEL_Y, CHANNEL_Y_STDERR,
    CHANNEL_Z, ILLUMINANCE_SENTINEL,
};

/// Checks that the photometric channels of an image read from `path` hold values candela can
/// have written: finite everywhere; X, Y, Z and the standard errors ≥ 0; `mask.E` in [0, 1];
/// `E` ≥ 0 or the "no receiving surface" sentinel. A NaN, infinite or negative value means a
/// corrupt or edited file, and a probe or false-colour map of it would be meaningless, so it
/// is refused with the file, channel and pixel named. Other channels are not looked at.
pub fn check_photometric_layers(path: &Path, layers: &Layers) -> Result<(), String> {
    for (name, values) in &layers.channels {
        let ok: fn(f32) -> bool = match name.as_str() {
            CHANNEL_X | CHANNEL_Y | CHANNEL_Z | CHANNEL_Y_STDERR | CHANNEL_E_STDERR => {
                |v| v.is_finite() && v >= 0.0
            }
            CHANNEL_E => |v| v.is_finite() && (v >= 0.0 || v == ILLUMINANCE_SENTINEL),
            CHANNEL_E_MASK => |v| (0.0..=1.0).contains(&v),
            _ => continue,
        };
        if let Some(i) = values.iter().position(|&v| !ok(v)) {
            let w = layers.width.max(1);
            return Err(format!(
                "{}: channel {name} holds {} at pixel ({}, {}) (x, y from the top-left), which candela never writes: the file is corrupt or was edited",
                path.display(),
                values[i],
                i % w,
                i / w
            ));
        }
    }
    Ok(())
}
