//! Light transport estimators that read a built [`crate::world::World`]: camera paths
//! ([`path`]: radiance along a ray, irradiance at a point), light paths for caustics
//! ([`light_path`]), and what both share: straight passage through window panes and the
//! transmittance of a segment ([`transmit`]), and ray counters ([`stats`]).

pub mod light_path;
pub mod path;
pub mod stats;
pub mod transmit;

pub use path::{irradiance, trace, PathStart, RayStart};
pub use stats::RayStats;
