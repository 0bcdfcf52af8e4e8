//! Glare evaluation of a luminance image seen from one eye point, as evalglare (Radiance 6,
//! version 3.06) computes it, with 95 % intervals from the pixels' standard errors
//! (docs/glare.md).
//!
//! - [`image`]: the input, plain per-pixel arrays (luminance, standard error, direction,
//!   solid angle, inside mask), and the geometry of Radiance's angular fisheye;
//! - [`sources`]: glare-source detection (threshold, merging, peak extraction);
//! - [`indices`]: position index, vertical illuminance and the indices DGP, DGI, UGR, VCP, CGI;
//! - [`interval`]: the intervals, by simulation, and the verdict on a too-noisy image;
//! - [`membership`]: how far the pixels near the threshold, whose side of it is in doubt,
//!   could move each index.

pub(crate) mod bias;
pub mod file;
pub mod image;
pub mod indices;
pub mod interval;
pub mod luminaires;
pub mod membership;
pub mod sources;

pub use image::{angular_fisheye, GlareImage, ImageError};
pub use indices::{
    evaluate, evaluate_luminance, position_index, Background, DgpCoefficients, GlareOptions,
    GlareResult, PositionIndexUp, SourceReport, SourceTerm,
};
pub use interval::{
    evaluate_uncertain, significant_sources, Interval, UncertainGlare, UncertainOptions,
};
pub use membership::Membership;
pub use sources::{DetectOptions, Task, Threshold};
