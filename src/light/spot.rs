//! Spot light: a point source whose intensity is full inside an inner cone and falls off
//! smoothly (smoothstep in cos θ) to zero at an outer cone.

use super::LightFlags;
use crate::bxdf::Frame;
use crate::description::context::{Context, SceneError};
use crate::description::schema::{Amount, SpectrumDesc, V3};
use crate::photometry::luminous_integral;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::Vec3;

#[derive(Clone, Debug)]
pub struct SpotLight {
    /// Position, m.
    pub position: Vec3,
    /// `frame.n` is the unit axis of the cone.
    pub frame: Frame,
    /// Cosine of the inner (full intensity) half-angle.
    pub cos_inner: f32,
    /// Cosine of the outer (zero intensity) half-angle.
    pub cos_outer: f32,
    /// Radiant intensity on the axis I_e(λ), W·sr⁻¹·nm⁻¹.
    pub intensity: DenseSpectrum,
}

/// Luminous flux (lm) of a spot of `candela` cd on the axis with the smoothstep falloff:
/// Φ = ∫ I dω = 2π I [(1 − cos θi) + (cos θi − cos θo)/2].
pub fn flux_lm(candela: f64, cos_inner: f64, cos_outer: f64) -> f64 {
    2.0 * std::f64::consts::PI * candela * (1.0 - 0.5 * (cos_inner + cos_outer))
}

impl SpotLight {
    pub const FLAGS: LightFlags = LightFlags::DELTA_POSITION;

    /// From `lights[i]`'s fields (`field` is `lights[i]`): cone half-angles in degrees, amount
    /// `Intensity(cd)` on the axis or `Flux(lm)`.
    #[allow(clippy::too_many_arguments)]
    pub fn build(
        ctx: &Context,
        field: &str,
        position: V3,
        look_at: V3,
        inner_deg: f32,
        outer_deg: f32,
        spectrum: &SpectrumDesc,
        amount: Amount,
    ) -> Result<Self, SceneError> {
        let afield = format!("{field}.amount");
        let p = ctx.vec3(&format!("{field}.position"), position)?;
        let t = ctx.vec3(&format!("{field}.look_at"), look_at)?;
        if (t - p).length_squared() == 0.0 {
            return Err(ctx.err(format!("{field}.look_at"), "look_at equals position"));
        }
        let inner = ctx.finite(&format!("{field}.inner_deg"), inner_deg as f64)?;
        let outer = ctx.finite(&format!("{field}.outer_deg"), outer_deg as f64)?;
        let valid =
            (0.0..=180.0).contains(&inner) && outer > 0.0 && outer <= 180.0 && inner <= outer;
        if !valid {
            return Err(ctx.err(
                format!("{field}.outer_deg"),
                format!("cone half-angles must satisfy 0 ≤ inner ≤ outer ≤ 180 and outer > 0, got inner {inner}, outer {outer}"),
            ));
        }
        let (ci, co) = (inner.to_radians().cos(), outer.to_radians().cos());
        let cd = super::intensity_cd(ctx, &afield, amount, flux_lm(1.0, ci, co))?;
        Ok(Self {
            position: p,
            frame: Frame::from_normal((t - p).normalize()),
            cos_inner: ci as f32,
            cos_outer: co as f32,
            intensity: ctx.emission(&format!("{field}.spectrum"), &afield, spectrum, cd)?,
        })
    }

    /// Radiant intensity (W·sr⁻¹·nm⁻¹) toward unit direction `dir`.
    pub fn intensity_toward(&self, dir: Vec3, wl: &SampledWavelengths) -> SampledSpectrum {
        let falloff = smoothstep(self.cos_outer, self.cos_inner, dir.dot(self.frame.n));
        if falloff <= 0.0 {
            return SampledSpectrum::ZERO;
        }
        self.intensity.sample(wl) * falloff
    }

    /// Luminous flux, lm.
    pub fn power_lm(&self) -> f64 {
        flux_lm(
            luminous_integral(&self.intensity),
            self.cos_inner as f64,
            self.cos_outer as f64,
        )
    }
}

pub fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    if a == b {
        return if x < a { 0.0 } else { 1.0 };
    }
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}
