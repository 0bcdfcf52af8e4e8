//! What the end of a job writes, each output attempted whether or not an earlier one failed:
//! the grids' CSVs and heat maps and the false-colour maps, and [`Writes`], the account of
//! what was written and what could not be.

use crate::output::with_suffix;
use crate::photometry::Quantity;
use crate::report::json::{grid_csv, write_text};
use crate::report::units::UnitSystem;
use crate::world::measure::grid_csv_path;
use crate::world::World;
use anyhow::{bail, Result};
use std::path::Path;

/// The error and its causes joined by ": ", like `{:#}`, but a cause whose text an outer
/// message already contains (e.g. "cannot read scene file X: {source}" whose source is also
/// the next cause in the chain) is not repeated.
pub fn error_text(e: &anyhow::Error) -> String {
    let mut msg = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if msg.is_empty() {
            msg = text;
        } else if !text.is_empty() && !msg.contains(&text) {
            msg.push_str(": ");
            msg.push_str(&text);
        }
    }
    msg
}

/// The outputs of the end of a job, each attempted whether or not an earlier one failed
/// (also used by `annual` and `merge`).
#[derive(Default)]
pub struct Writes {
    /// Files written, in order.
    pub written: Vec<String>,
    /// One line per file that could not be written, naming it.
    pub failed: Vec<String>,
}

impl Writes {
    pub fn attempt(&mut self, path: &Path, write: impl FnOnce() -> Result<()>) {
        let shown = path.display().to_string();
        match write() {
            Ok(()) => self.written.push(shown),
            Err(e) => {
                let e = error_text(&e);
                self.failed.push(if e.contains(&shown) {
                    e
                } else {
                    format!("{shown}: {e}")
                });
            }
        }
    }

    /// One error listing every file that could not be written, if any.
    pub fn finish(self) -> Result<()> {
        match self.failed.len() {
            0 => Ok(()),
            1 => bail!("{}", self.failed[0]),
            n => bail!(
                "{n} files could not be written (the other outputs were):\n  {}",
                self.failed.join("\n  ")
            ),
        }
    }
}

/// Each grid's CSV and heat map, named after the grid.
pub(super) fn write_grids(
    world: &World,
    measurements: &crate::meter::Measurements,
    stem: &Path,
    units: UnitSystem,
    writes: &mut Writes,
) {
    for (k, (g, est)) in world.grids.iter().zip(&measurements.grids).enumerate() {
        let path = grid_csv_path(stem, &g.name);
        writes.attempt(&path, || {
            write_text(&path, &grid_csv(world, k, est, units))?;
            Ok(())
        });
        let png = path.with_extension("png");
        let values = crate::report::heatmap::GridValues {
            name: g.name.clone(),
            nx: g.nx as usize,
            ny: g.ny as usize,
            values: est.iter().map(|e| e.mean).collect(),
            stderr: est.iter().map(|e| e.stderr).collect(),
            size_m: (g.edge_u.length() as f64, g.edge_v.length() as f64),
        };
        let settings = crate::report::falsecolour::FalsecolourSettings {
            quantity: Quantity::Illuminance,
            units,
            ..Default::default()
        };
        writes.attempt(&png, || {
            crate::report::heatmap::write_grid_heatmap(&png, &values, &settings)?;
            Ok(())
        });
    }
}

/// False-colour maps of the image (the EXR's channels): luminance, and illuminance when it was
/// estimated.
pub(super) fn write_falsecolour(
    world: &World,
    layers: &crate::output::Layers,
    stem: &Path,
    units: UnitSystem,
    writes: &mut Writes,
) {
    let mut quantities = vec![(Quantity::Luminance, ".luminance.png")];
    if world.settings.illuminance {
        quantities.push((Quantity::Illuminance, ".illuminance.png"));
    }
    for (q, suffix) in quantities {
        let path = with_suffix(stem, suffix);
        let settings = crate::report::falsecolour::FalsecolourSettings {
            quantity: q,
            units,
            ..Default::default()
        };
        writes.attempt(&path, || {
            crate::report::falsecolour::write_falsecolour(&path, layers, &settings)?;
            Ok(())
        });
    }
}
