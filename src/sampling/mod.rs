//! Sampling: the random streams ([`sobol`]), the warps from the unit square to the shapes the
//! renderer samples, each beside its density ([`warp`]), and choosing among weighted items
//! ([`discrete`]). Every caller that warps a sample uses these.

pub mod discrete;
pub mod sobol;
pub mod warp;

pub use discrete::{cdf_from_weights, choose_by_weight, pick_from_cdf};
pub use sobol::{batch_stream, mix64, Sampler, ONE_MINUS_EPSILON};
pub use warp::*;
