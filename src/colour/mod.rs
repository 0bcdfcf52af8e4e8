//! Colour science for candela: spectral tables, spectral distributions, colorimetry, colour
//! models, chromatic adaptation, RGB colourspaces, correlated colour temperature and colour
//! rendering, α-opic (non-visual) quantities, colour rendition (TM-30, CIE 2017, NIST CQS) and mesopic
//! photometry.
//!
//! Everything here is `f64` and deterministic, and every conversion is validated against
//! the Python reference library colour-science 0.4.7 (see `tests/colour_science.rs` and
//! `docs/colour.md`).

pub mod adaptation;
pub mod alpha_opic;
pub mod colorimetry;
pub mod cqs;
pub mod cri;
pub mod grid;
pub mod illuminants;
pub mod matrix;
pub mod mesopic;
pub mod models;
pub mod planck;
pub mod rgb;
pub mod sd;
pub mod tables;
pub mod temperature;
pub mod tm30;
