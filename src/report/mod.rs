//! Photometric reports (issue 5): the JSON report and grid CSVs, false-colour maps, grid heat
//! maps and the pixel probe. See `docs/report-json.md` and `docs/reports.md`.

pub mod draw;
pub mod falsecolour;
pub mod heatmap;
pub mod json;
pub mod probe;
pub mod units;
