//! candela — a spectral path tracer whose output is measured light.
//!
//! Every pixel is a calibrated photometric quantity (luminance in cd/m², illuminance in lux);
//! internally everything is spectral radiometry (W·m⁻²·sr⁻¹·nm⁻¹).
//!
//! Data flow: `scene` (RON) → `world` (spectra resolved, lights in W, one BVH) →
//! `integrator` per sample → `film` (absolute XYZ sums) → `output` (EXR, PNG).

pub mod annual;
pub mod bxdf;
pub mod camera;
pub mod colour;
pub mod daylight;
pub mod description;
pub mod film;
pub mod geometry;
pub mod glare;
pub mod integrator;
pub mod job;
pub mod light;
pub mod limits;
pub mod luminaire;
pub mod meter;
pub mod output;
pub mod photometry;
#[cfg(feature = "python")]
mod python;
pub mod render;
pub mod report;
pub mod sampling;
pub mod scene;
pub mod spectrum;
pub mod state;
pub mod texture;
pub mod world;
