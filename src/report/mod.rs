//! Photometric reports (issue 5): false-colour maps, grid heat maps and the pixel probe.
//! See `docs/reports.md`.

pub mod draw;
pub mod falsecolour;
pub mod heatmap;
pub mod probe;
pub mod units;
