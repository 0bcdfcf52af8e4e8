//! Light transport estimators that read a built [`crate::world::World`]: camera paths
//! ([`path`]: radiance along a ray, irradiance at a point), light paths for caustics
//! ([`light_path`]), and what both share: straight passage through window panes and the
//! transmittance of a segment ([`transmit`]), the sun's disk seen straight from the camera
//! ([`sun_view`]), ray counters ([`stats`]) and the Russian
//! roulette that ends paths ([`survival_probability`]).

pub mod light_path;
pub mod path;
pub mod stats;
pub mod sun_view;
pub mod transmit;

pub use path::{irradiance, trace, PathStart, RayStart};
pub use stats::RayStats;

/// Largest probability with which Russian roulette lets a path continue. Below 1, so that every
/// path ends with probability 1 even where nothing absorbs (a closed box of reflectance 1, a
/// chain of lossless mirrors): its expected length past `rr_depth` is then at most
/// 1 / (1 − 0.99) = 100 scattering events. The estimate's variance stays finite while the
/// albedo ρ of what the path meets satisfies ρ² < 0.99 (ρ < 0.995).
pub const MAX_SURVIVAL: f32 = 0.99;

/// Probability that Russian roulette lets a path continue, from the largest component of its
/// throughput (times the η′² it has gathered by refraction, so that radiance compressed by
/// refraction is not mistaken for absorption): the throughput itself, capped at
/// [`MAX_SURVIVAL`]. A surviving path divides its throughput by this probability, which keeps
/// the estimate unbiased; since the throughput is then about 1 again, a path keeps going with
/// about the albedo of each surface it meets, so its expected length follows the scene's
/// absorption and no depth limit is needed. 0 (end the path) for a throughput that is not a
/// positive number.
#[inline]
pub fn survival_probability(throughput: f32) -> f32 {
    if throughput > 0.0 {
        throughput.min(MAX_SURVIVAL)
    } else {
        0.0
    }
}

/// `hit` with its shading normal perturbed by the normal map `m` (in the tangent frame of the
/// hit primitive's texture coordinates); unchanged where the primitive gives no such frame
/// (a triangle whose texture coordinates have no area).
#[inline]
pub fn normal_mapped(
    world: &crate::world::World,
    m: &crate::bxdf::normal_map::NormalMapped,
    mut hit: crate::geometry::Hit,
) -> crate::geometry::Hit {
    if let Some((dpdu, dpdv)) = world.geometry.texture_derivatives(&hit) {
        hit.ns = m.shading_normal(hit.tex, hit.ns, hit.ng, dpdu, dpdv);
    }
    hit
}
