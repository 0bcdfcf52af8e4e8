//! Lambertian diffuse reflection: f = ρ(λ)/π, sampled with the cosine-weighted hemisphere.
//! Two-sided: it reflects on whichever side `wo` is.

use super::{same_hemisphere, BsdfSample, MaterialFlags};
use crate::description::context::{Context, Role, SceneError};
use crate::description::schema::SpectrumDesc;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Debug)]
pub struct Diffuse {
    /// Reflectance ρ(λ) ∈ [0, 1].
    pub reflectance: DenseSpectrum,
}

impl Diffuse {
    pub const FLAGS: MaterialFlags = MaterialFlags::NONE;

    /// The material at `field` from its description.
    pub fn build(
        ctx: &Context,
        field: &str,
        reflectance: &SpectrumDesc,
    ) -> Result<Self, SceneError> {
        Ok(Diffuse {
            reflectance: ctx.spectrum(
                &format!("{field}.reflectance"),
                reflectance,
                Role::Reflectance,
            )?,
        })
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3, wl: &SampledWavelengths) -> SampledSpectrum {
        lambert_eval(self.reflectance.sample(wl), wo, wi)
    }
    pub fn sample(&self, wo: Vec3, u: Vec2, wl: &SampledWavelengths) -> Option<BsdfSample> {
        lambert_sample(self.reflectance.sample(wl), wo, u)
    }
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        Self::pdf_cosine(wo, wi)
    }
    /// Density of the cosine-weighted sample, whatever the reflectance.
    #[inline]
    pub fn pdf_cosine(wo: Vec3, wi: Vec3) -> f32 {
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        crate::sampling::cosine_hemisphere_pdf(wi.z.abs())
    }
}

/// f = ρ/π of reflectance `r` at the path's wavelengths.
#[inline]
pub fn lambert_eval(r: SampledSpectrum, wo: Vec3, wi: Vec3) -> SampledSpectrum {
    if !same_hemisphere(wo, wi) {
        return SampledSpectrum::ZERO;
    }
    r * FRAC_1_PI
}

/// A cosine-weighted direction on `wo`'s side of the surface and its density (None where the
/// density vanishes): the sampling of every diffuse lobe.
#[inline]
pub fn cosine_direction(wo: Vec3, u: Vec2) -> Option<(Vec3, f32)> {
    let mut wi = crate::sampling::cosine_hemisphere(u);
    if wo.z < 0.0 {
        wi.z = -wi.z;
    }
    let pdf = crate::sampling::cosine_hemisphere_pdf(wi.z.abs());
    (pdf > 0.0).then_some((wi, pdf))
}

/// Cosine-weighted sample of the Lambertian of reflectance `r`.
#[inline]
pub fn lambert_sample(r: SampledSpectrum, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
    let (wi, pdf) = cosine_direction(wo, u)?;
    Some(BsdfSample {
        wi,
        f: r * FRAC_1_PI,
        pdf,
        specular: false,
    })
}

/// Lambertian reflection whose reflectance is an image texture ([`crate::texture`]).
#[derive(Clone, Debug)]
pub struct TexturedDiffuse {
    pub texture: std::sync::Arc<crate::texture::Texture>,
}

impl TexturedDiffuse {
    /// Loads the texture at `path`; `uv_scale`, `uv_offset` transform texture coordinates.
    pub fn load(
        path: &std::path::Path,
        uv_scale: [f32; 2],
        uv_offset: [f32; 2],
        wrap: crate::texture::Wrap,
    ) -> Result<Self, String> {
        if !(uv_scale.iter().chain(&uv_offset)).all(|v| v.is_finite()) {
            return Err(format!(
                "uv_scale {uv_scale:?} and uv_offset {uv_offset:?} must be finite"
            ));
        }
        let mut t = crate::texture::Texture::load(path).map_err(|e| e.to_string())?;
        t.uv = crate::texture::scale_offset(uv_scale, uv_offset);
        t.wrap = wrap;
        Ok(TexturedDiffuse {
            texture: std::sync::Arc::new(t),
        })
    }
}
