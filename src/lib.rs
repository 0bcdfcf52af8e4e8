//! candela — a spectral path tracer whose output is measured light.
//!
//! Every pixel is a calibrated photometric quantity (luminance in cd/m², illuminance in lux);
//! internally everything is spectral radiometry (W·m⁻²·sr⁻¹·nm⁻¹).

pub mod cli_colour;
pub mod colour;
pub mod photometry;
