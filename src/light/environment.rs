//! Environment light: uniform radiance from every direction at infinity, sampled uniformly
//! over the sphere or, with portals ([`super::portal`]), through the openings it shines
//! through.

use super::portal::{Portal, Portals};
use super::{LightFlags, LightSample};
use crate::description::context::{Context, SceneError};
use crate::description::schema::{Amount, PortalDesc, SpectrumDesc};
use crate::photometry::luminous_integral;
use crate::sampling::{uniform_sphere, UNIFORM_SPHERE_PDF};
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct EnvironmentLight {
    /// Radiance L_e(λ), W·m⁻²·sr⁻¹·nm⁻¹, the same from every direction.
    pub radiance: DenseSpectrum,
    pub portals: Portals,
}

/// The portals of `lights[i]` (`field`), as parallelograms.
pub fn build_portals(
    ctx: &Context,
    field: &str,
    portals: &[PortalDesc],
) -> Result<Portals, SceneError> {
    let mut built = Vec::with_capacity(portals.len());
    for (k, d) in portals.iter().enumerate() {
        let pf = format!("{field}.portals[{k}]");
        let origin = ctx.vec3(&format!("{pf}.origin"), d.origin)?;
        let eu = ctx.vec3(&format!("{pf}.edge_u"), d.edge_u)?;
        let ev = ctx.vec3(&format!("{pf}.edge_v"), d.edge_v)?;
        built.push(Portal::new(origin, eu, ev).ok_or_else(|| {
            ctx.err(
                &pf,
                "the portal has zero area (its edges are zero or parallel)",
            )
        })?);
    }
    Ok(Portals::new(built))
}

impl EnvironmentLight {
    pub const FLAGS: LightFlags = LightFlags::INFINITE;

    /// From `lights[i]`'s fields (`field` is `lights[i]`): amount `Luminance(cd/m²)`, portals
    /// as parallelograms.
    pub fn build(
        ctx: &Context,
        field: &str,
        spectrum: &SpectrumDesc,
        amount: Amount,
        portals: &[PortalDesc],
    ) -> Result<Self, SceneError> {
        let afield = format!("{field}.amount");
        let lum = match amount {
            Amount::Luminance(l) => ctx.nonneg(&afield, l)?,
            a => return Err(super::wrong_amount(ctx, &afield, &a, "Luminance(cd/m²)")),
        };
        Ok(Self {
            radiance: ctx.emission(&format!("{field}.spectrum"), &afield, spectrum, lum)?,
            portals: build_portals(ctx, field, portals)?,
        })
    }

    /// A direction from `p` (uniform on the sphere, or through the portals) with li = L_e.
    pub fn sample_li(
        &self,
        p: Vec3,
        uc: f32,
        u: Vec2,
        wl: &SampledWavelengths,
    ) -> Option<LightSample> {
        let (wi, pdf) = if self.portals.is_empty() {
            (uniform_sphere(u), UNIFORM_SPHERE_PDF)
        } else {
            self.portals.sample(p, uc, u)?
        };
        Some(LightSample {
            wi,
            li: self.radiance.sample(wl),
            pdf,
            dist: f32::INFINITY,
            point: None,
            delta: false,
        })
    }

    /// Density (solid angle) with which [`EnvironmentLight::sample_li`] at `p` picks unit
    /// direction `wi`.
    pub fn pdf_li(&self, p: Vec3, wi: Vec3) -> f32 {
        if self.portals.is_empty() {
            UNIFORM_SPHERE_PDF
        } else {
            self.portals.pdf(p, wi)
        }
    }

    /// Radiance arriving along an escaped ray.
    pub fn escaped(&self, wl: &SampledWavelengths) -> SampledSpectrum {
        self.radiance.sample(wl)
    }

    /// Power proxy (lm): the flux onto the scene's bounding disk, L π² r².
    pub fn power_lm(&self, scene_radius: f32) -> f64 {
        let r2 = (scene_radius as f64).powi(2);
        let pi = std::f64::consts::PI;
        luminous_integral(&self.radiance) * pi * pi * r2
    }
}
