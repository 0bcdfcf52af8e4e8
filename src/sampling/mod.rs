//! Sampling: the random streams ([`sobol`]), the warps from the unit square to the shapes the
//! renderer samples, each beside its density ([`warp`]), and choosing among weighted items
//! ([`discrete`]), and tabulated densities ([`piecewise`]). Every caller that warps a sample
//! uses these.

pub mod discrete;
pub mod piecewise;
pub mod sobol;
pub mod special;
pub mod student;
pub mod warp;

pub use discrete::{cdf_from_weights, choose_by_weight, pick_from_cdf};
pub use piecewise::{Piecewise1D, Piecewise2D};
pub use sobol::{batch_stream, mix64, Sampler, ONE_MINUS_EPSILON};
pub use student::t95;
pub use warp::*;

/// Next number in [0, 1) of a 64-bit linear congruential stream (Knuth's MMIX constants) whose
/// state is `state`: reproducible random geometry for tests.
#[cfg(test)]
pub(crate) fn test_uniform(state: &mut u64) -> f32 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 40) as f32 / (1u64 << 24) as f32
}
