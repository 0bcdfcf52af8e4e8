//! Distant light: parallel light from one direction (the sun), given by the illuminance on a
//! surface facing it.

use super::{LightFlags, LightSample};
use crate::description::context::{Context, SceneError};
use crate::description::schema::{Amount, SpectrumDesc, V3};
use crate::photometry::luminous_integral;
use crate::spectrum::{DenseSpectrum, SampledWavelengths};
use glam::Vec3;

#[derive(Clone, Debug)]
pub struct DistantLight {
    /// Unit direction toward the source (opposite to the light's travel).
    pub to_light: Vec3,
    /// Irradiance at normal incidence E_e(λ), W·m⁻²·nm⁻¹.
    pub irradiance: DenseSpectrum,
}

impl DistantLight {
    pub const FLAGS: LightFlags = LightFlags::DELTA_DIRECTION;

    /// From `lights[i]`'s fields (`field` is `lights[i]`): `direction` of travel, amount
    /// `Illuminance(lx)`.
    pub fn build(
        ctx: &Context,
        field: &str,
        direction: V3,
        spectrum: &SpectrumDesc,
        amount: Amount,
    ) -> Result<Self, SceneError> {
        let afield = format!("{field}.amount");
        let d = ctx.unit(&format!("{field}.direction"), direction)?;
        let lux = match amount {
            Amount::Illuminance(e) => ctx.nonneg(&afield, e)?,
            a => return Err(super::wrong_amount(ctx, &afield, &a, "Illuminance(lx)")),
        };
        Ok(Self {
            to_light: -d,
            irradiance: ctx.emission(&format!("{field}.spectrum"), &afield, spectrum, lux)?,
        })
    }

    /// The single direction the light arrives from, with li = E_e.
    pub fn sample_li(&self, wl: &SampledWavelengths) -> LightSample {
        LightSample {
            wi: self.to_light,
            li: self.irradiance.sample(wl),
            pdf: 1.0,
            dist: f32::INFINITY,
            point: None,
            delta: true,
        }
    }

    /// Power proxy (lm): the flux through the scene's bounding disk, E π r².
    pub fn power_lm(&self, scene_radius: f32) -> f64 {
        let r2 = (scene_radius as f64).powi(2);
        luminous_integral(&self.irradiance) * std::f64::consts::PI * r2
    }
}
