//! Isotropic point light: the same radiant intensity in every direction.

use super::LightFlags;
use crate::description::context::{Context, SceneError};
use crate::description::schema::{Amount, SpectrumDesc, V3};
use crate::photometry::luminous_integral;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::Vec3;

#[derive(Clone, Debug)]
pub struct PointLight {
    /// Position, m.
    pub position: Vec3,
    /// Radiant intensity I_e(λ), W·sr⁻¹·nm⁻¹.
    pub intensity: DenseSpectrum,
}

/// Luminous flux (lm) of an isotropic source of `candela` cd: Φ = 4π I.
pub fn flux_lm(candela: f64) -> f64 {
    4.0 * std::f64::consts::PI * candela
}

impl PointLight {
    pub const FLAGS: LightFlags = LightFlags::DELTA_POSITION;

    /// From `lights[i]`'s fields (`field` is `lights[i]`): amount `Intensity(cd)` or
    /// `Flux(lm)`.
    pub fn build(
        ctx: &Context,
        field: &str,
        position: V3,
        spectrum: &SpectrumDesc,
        amount: Amount,
    ) -> Result<Self, SceneError> {
        let afield = format!("{field}.amount");
        let cd = super::intensity_cd(ctx, &afield, amount, flux_lm(1.0))?;
        Ok(Self {
            position: ctx.vec3(&format!("{field}.position"), position)?,
            intensity: ctx.emission(&format!("{field}.spectrum"), &afield, spectrum, cd)?,
        })
    }

    /// Radiant intensity (W·sr⁻¹·nm⁻¹), the same toward every direction.
    pub fn intensity(&self, wl: &SampledWavelengths) -> SampledSpectrum {
        self.intensity.sample(wl)
    }

    /// Luminous flux, lm.
    pub fn power_lm(&self) -> f64 {
        flux_lm(luminous_integral(&self.intensity))
    }
}
