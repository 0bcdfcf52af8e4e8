//! Thin dielectric slab (a window pane, a soap film without interference): light is either
//! mirrored or passes straight through, after infinitely many incoherent internal reflections.
//! Summed per polarisation (closed-forms §2.8): R' = 2R/(1+R), T' = (1−R)/(1+R) for each of
//! s and p, then averaged (pbrt-v4 §9.5.3 `ThinDielectricBxDF` averages before summing, which
//! is exact only at normal incidence). Both lobes are deltas. Transmission keeps the direction,
//! so dispersion changes only the weights (per wavelength) and the path keeps all lanes.

use super::fresnel::fr_dielectric_sp;
use super::ior::Ior;
use super::{BsdfSample, MaterialFlags};
use crate::description::context::{Context, SceneError};
use crate::description::schema::IorDesc;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, N_LAMBDA};
use glam::Vec3;

#[derive(Clone, Debug)]
pub struct ThinDielectric {
    pub ior: Ior,
}

/// Reflectance of the slab (incoherent multiple reflections, per polarisation).
pub fn thin_slab_reflectance(cos: f32, eta: f32) -> f32 {
    let (rs, rp) = fr_dielectric_sp(cos.abs(), eta);
    let slab = |r: f32| if r < 1.0 { 2.0 * r / (1.0 + r) } else { 1.0 };
    0.5 * (slab(rs) + slab(rp))
}

impl ThinDielectric {
    /// Both lobes are deltas, and transmission passes straight through.
    pub const FLAGS: MaterialFlags =
        MaterialFlags::ALL_DELTA.union(MaterialFlags::STRAIGHT_THROUGH);

    /// The material at `field` from its description.
    pub fn build(ctx: &Context, field: &str, ior: &IorDesc) -> Result<Self, SceneError> {
        Ok(ThinDielectric {
            ior: Ior::build(ctx, &format!("{field}.ior"), ior)?,
        })
    }

    /// Straight-through transmittance 1 − R' at |cos θ| = `cos`, per wavelength (zero at
    /// grazing incidence).
    pub fn transmittance(&self, cos: f32, wl: &SampledWavelengths) -> SampledSpectrum {
        let c = cos.abs().min(1.0);
        let mut t = SampledSpectrum::ZERO;
        if c > 0.0 {
            for i in 0..N_LAMBDA {
                t[i] = 1.0 - thin_slab_reflectance(c, self.ior.at(wl.lambda[i]));
            }
        }
        t
    }

    pub fn sample(&self, wo: Vec3, uc: f32, wl: &SampledWavelengths) -> Option<BsdfSample> {
        let c = wo.z.abs();
        if c == 0.0 {
            return None;
        }
        let mut r = SampledSpectrum::ZERO;
        for i in 0..N_LAMBDA {
            r[i] = thin_slab_reflectance(c, self.ior.at(wl.lambda[i]));
        }
        let r0 = r[0];
        if uc < r0 {
            Some(BsdfSample {
                wi: Vec3::new(-wo.x, -wo.y, wo.z),
                f: r / c,
                pdf: r0,
                specular: true,
            })
        } else {
            Some(BsdfSample {
                wi: -wo,
                f: (SampledSpectrum::ONE - r) / c,
                pdf: 1.0 - r0,
                specular: true,
            })
        }
    }
}
