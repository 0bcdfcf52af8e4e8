//! Surfaces that pass light straight through (window panes): the lobe chosen on arrival, so
//! that passing straight through is a null event for camera and light paths alike, and the
//! transmittance of a segment through the panes it crosses (shadow rays, camera connections).

use crate::sampling::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;
use glam::Vec3;

/// Most surfaces a ray passes straight through before it is given up (a guard against
/// pathological stacks of panes).
pub const MAX_STRAIGHT_THROUGH: u32 = 64;

/// The lobe a window pane ([`crate::bxdf::MaterialFlags::STRAIGHT_THROUGH`]) chose for a path.
pub enum PaneLobe {
    /// Straight through: a null event, with this weight f·|cos|/pdf on the throughput.
    Straight(SampledSpectrum),
    /// A real scattering (the mirror lobe), to be handled like any other.
    Scatter(crate::bxdf::BsdfSample),
}

/// At a surface that passes light straight through, choose its lobe before anything else (one
/// set of four sampler dimensions), so that passing through can be a null event; the camera
/// paths and the light paths both do this. None when the surface scatters nothing (the path
/// ends).
pub fn choose_pane_lobe(
    material: &crate::bxdf::Material,
    wo: Vec3,
    sampler: &mut Sampler,
    wl: &mut SampledWavelengths,
) -> Option<PaneLobe> {
    let [ux, uy, uc, _] = sampler.get4();
    let bs = material.sample(wo, uc, glam::Vec2::new(ux, uy), wl)?;
    if bs.pdf.is_nan() || bs.pdf <= 0.0 {
        return None;
    }
    Some(if material.is_straight_through(wo, bs.wi) {
        PaneLobe::Straight(bs.f * (bs.wi.z.abs() / bs.pdf))
    } else {
        PaneLobe::Scatter(bs)
    })
}

/// Spectral transmittance of the segment from `origin` along unit `dir` up to `t_max`: `None`
/// when an opaque surface blocks it, else the product of the straight-through transmittances
/// ([`crate::bxdf::Material::straight_transmittance`]) of the window panes it crosses (one
/// when it crosses none). Without see-through materials in the world this is one any-hit
/// query; with panes, one any-hit query that passes through them.
pub fn transmittance(
    world: &World,
    origin: Vec3,
    dir: Vec3,
    t_max: f32,
    wl: &SampledWavelengths,
) -> Option<SampledSpectrum> {
    transmittance_counted(world, origin, dir, t_max, wl).map(|(tr, _)| tr)
}

/// [`transmittance`], and the number of panes the segment crosses.
pub fn transmittance_counted(
    world: &World,
    origin: Vec3,
    dir: Vec3,
    t_max: f32,
    wl: &SampledWavelengths,
) -> Option<(SampledSpectrum, u32)> {
    if world.see_through.is_empty() {
        return (!world.geometry.occluded(origin, dir, t_max)).then_some((SampledSpectrum::ONE, 0));
    }
    // One any-hit traversal that passes through the panes' primitives: the transmittance is a
    // product, so the order in which they are found does not matter. A ray exactly through the
    // seam of two pieces of a pane (two triangles, two touching quads) hits both at the same
    // point: that is one crossing, recognised by points that agree within their error bounds.
    let mut tr = SampledSpectrum::ONE;
    let mut seen = [(Vec3::ZERO, Vec3::ZERO); MAX_STRAIGHT_THROUGH as usize];
    let mut crossed = 0usize;
    let blocked = world
        .geometry
        .occluded_except(origin, dir, t_max, &world.see_through, |hit| {
            let same =
                |&(p, e): &(Vec3, Vec3)| ((hit.p - p).abs() - (hit.error + e)).max_element() <= 0.0;
            if seen[..crossed].iter().any(same) {
                return true;
            }
            if crossed == seen.len() {
                return false;
            }
            seen[crossed] = (hit.p, hit.error);
            crossed += 1;
            let material = &world.materials[world.objects[hit.object as usize].material as usize];
            match material.straight_transmittance(dir.dot(hit.ns), wl) {
                Some(t) => {
                    tr *= t;
                    !tr.is_black()
                }
                None => false,
            }
        });
    (!blocked).then_some((tr, crossed as u32))
}
