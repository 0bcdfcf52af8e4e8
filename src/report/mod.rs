//! Photometric reports: the JSON report and grid CSVs, false colour, heat maps, the probe.

pub mod json;
