//! Area light: Lambertian emission from the primitives of one scene object (its `emission`),
//! given by the surface's luminance or the object's flux.

use super::{EmissionPoint, LightFlags, LightSample};
use crate::description::context::{Context, Role, SceneError};
use crate::description::schema::{Amount, EmissionDesc};
use crate::geometry::{Hit, SceneGeometry};
use crate::photometry::luminous_integral;
use crate::sampling::pick_from_cdf;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct AreaLight {
    /// The scene object (index) that emits.
    pub object: u32,
    /// Its primitives.
    pub prims: Vec<u32>,
    /// Cumulative area fractions of `prims`, last = 1.
    pub cdf: Vec<f32>,
    /// Total area of `prims`, m².
    pub total_area: f32,
    /// Radiance L_e(λ), W·m⁻²·sr⁻¹·nm⁻¹, the same at every point and direction.
    pub radiance: DenseSpectrum,
    /// Emits from both faces (otherwise only from the front face).
    pub two_sided: bool,
}

/// Luminous flux (lm) of a Lambertian emitter of `luminance` cd/m² and `area` m² emitting from
/// `sides` faces: Φ = π L A per face.
pub fn flux_lm(luminance: f64, area: f64, sides: f64) -> f64 {
    std::f64::consts::PI * luminance * area * sides
}

fn sides(two_sided: bool) -> f64 {
    if two_sided {
        2.0
    } else {
        1.0
    }
}

impl AreaLight {
    pub const FLAGS: LightFlags = LightFlags::AREA;

    /// The spectral shape of object `field`'s emission (checked while the objects are read,
    /// before the geometry is built).
    pub fn spectrum(
        ctx: &Context,
        field: &str,
        e: &EmissionDesc,
    ) -> Result<DenseSpectrum, SceneError> {
        ctx.spectrum(
            &format!("{field}.emission.spectrum"),
            &e.spectrum,
            Role::Emission,
        )
    }

    /// The light of scene object `object` (`field` names it, e.g. `objects[3] "lamp"`) from its
    /// `emission` and spectral shape `s` ([`AreaLight::spectrum`]), once the geometry is built:
    /// amount `Luminance(cd/m²)` or `Flux(lm)` of the whole object.
    pub fn build(
        ctx: &Context,
        field: &str,
        object: u32,
        e: &EmissionDesc,
        s: &DenseSpectrum,
        geometry: &SceneGeometry,
    ) -> Result<Self, SceneError> {
        let two_sided = e.two_sided;
        let prims = geometry.primitives_of_object(object).to_vec();
        let areas: Vec<f64> = prims
            .iter()
            .map(|&p| geometry.prim_area(p) as f64)
            .collect();
        let total: f64 = areas.iter().sum();
        if total.is_nan() || total <= 0.0 {
            return Err(ctx.err(
                format!("{field}.emission"),
                "the emitting shape has zero area",
            ));
        }
        let afield = format!("{field}.emission.amount");
        let luminance = match e.amount {
            Amount::Luminance(l) => ctx.nonneg(&afield, l)?,
            Amount::Flux(phi) => ctx.nonneg(&afield, phi)? / flux_lm(1.0, total, sides(two_sided)),
            other => {
                return Err(ctx.err(
                    afield,
                    format!("{other:?} is not an amount for surface emission; use Luminance(cd/m²) or Flux(lm)"),
                ))
            }
        };
        let radiance =
            ctx.scaled_emission(&format!("{field}.emission.spectrum"), &afield, s, luminance)?;
        let cdf = crate::sampling::cdf_from_weights(&areas);
        Ok(Self {
            object,
            prims,
            cdf,
            total_area: total as f32,
            radiance,
            two_sided,
        })
    }

    /// A point uniform by area (`uc` chooses the primitive, `u` the point).
    pub fn sample_emission_point(&self, geom: &SceneGeometry, uc: f32, u: Vec2) -> EmissionPoint {
        let (k, _) = pick_from_cdf(&self.cdf, uc);
        let sp = geom.sample_prim(self.prims[k], u);
        EmissionPoint {
            p: sp.p,
            n: Some(sp.n),
            inv_pdf: self.total_area,
        }
    }

    /// Radiance × |cos θ| (W·m⁻²·sr⁻¹·nm⁻¹) leaving `at` toward unit direction `dir`, zero
    /// behind a one-sided emitter.
    pub fn emission_toward(
        &self,
        at: &EmissionPoint,
        dir: Vec3,
        wl: &SampledWavelengths,
    ) -> SampledSpectrum {
        let cos = at.n.map_or(0.0, |n| n.dot(dir));
        if cos > 0.0 || (self.two_sided && cos < 0.0) {
            self.radiance.sample(wl) * cos.abs()
        } else {
            SampledSpectrum::ZERO
        }
    }

    /// A point on the light seen from `p`, by solid angle within the primitive chosen by area.
    pub fn sample_li(
        &self,
        geom: &SceneGeometry,
        p: Vec3,
        uc: f32,
        u: Vec2,
        wl: &SampledWavelengths,
    ) -> Option<LightSample> {
        let (k, p_prim) = pick_from_cdf(&self.cdf, uc);
        let mut ls = self.sample_li_prim(geom, p, self.prims[k], u, wl)?;
        ls.pdf *= p_prim;
        Some(ls)
    }

    /// A point on primitive `prim` (one of `prims`) seen from `p`, by solid angle; `pdf` is
    /// the density within that primitive (its choice is the caller's).
    pub fn sample_li_prim(
        &self,
        geom: &SceneGeometry,
        p: Vec3,
        prim: u32,
        u: Vec2,
        wl: &SampledWavelengths,
    ) -> Option<LightSample> {
        let (sp, pdf_sa) = geom.sample_prim_solid_angle(prim, p, u)?;
        let d = sp.p - p;
        let dist = d.length();
        if dist == 0.0 || pdf_sa.is_nan() || pdf_sa <= 0.0 || !pdf_sa.is_finite() {
            return None;
        }
        let wi = d / dist;
        let facing = sp.n.dot(-wi) > 0.0;
        if !facing && !self.two_sided {
            return None;
        }
        Some(LightSample {
            wi,
            li: self.radiance.sample(wl),
            pdf: pdf_sa,
            dist,
            point: Some((sp.p, sp.n)),
            delta: false,
        })
    }

    /// Density (solid angle) with which [`AreaLight::sample_li`] from `p` would have produced
    /// the ray that hit the light at `hit`.
    pub fn pdf_li_hit(&self, geom: &SceneGeometry, p: Vec3, hit: &Hit) -> f32 {
        let p_prim = geom.prim_area(hit.prim) / self.total_area;
        p_prim * geom.pdf_prim_solid_angle(hit.prim, p, hit)
    }

    /// Radiance leaving the surface toward the viewer, given the hit.
    pub fn emitted(&self, hit: &Hit, wl: &SampledWavelengths) -> SampledSpectrum {
        if hit.front_face || self.two_sided {
            self.radiance.sample(wl)
        } else {
            SampledSpectrum::ZERO
        }
    }

    /// Luminous flux, lm.
    pub fn power_lm(&self, geom: &SceneGeometry) -> f64 {
        let area: f64 = self.prims.iter().map(|&p| geom.prim_area(p) as f64).sum();
        flux_lm(
            luminous_integral(&self.radiance),
            area,
            sides(self.two_sided),
        )
    }
}
