//! glTF's metallic-roughness material with textures, resolved at each hit by the rule that maps
//! an untextured one (docs/scene-format.md → glTF models): metallic m ≥ 0.5 → a conductor of
//! n = 1 whose normal-incidence reflectance is the base colour ρ; else perceptual roughness
//! r ≥ 0.5 → Lambertian of reflectance ρ; else a Lambertian base ρ under a clear coat. ρ comes
//! from the base-colour texture (its texels already multiplied by `baseColorFactor`) or the
//! factor; m and r are the factors times the metallic-roughness texture's B and G channels,
//! filtered bilinearly and rounded to the texture's 1/255 steps, so that a constant texture
//! gives exactly the untextured material. The coats of the 256 roughness steps are built once.

use super::coated::Coated;
use super::conductor::ConductorAt;
use super::microfacet::Microfacet;
use super::{Material, MaterialFlags};
use crate::description::context::{Context, SceneError};
use crate::description::schema::{DistributionDesc, MaskingDesc};
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths, N_LAMBDA};
use crate::texture::bytes::ByteTexture;
use crate::texture::Texture;
use glam::Vec2;
use std::sync::Arc;

/// Largest normal-incidence reflectance given to a conductor (its k is 2√(R/(1 − R)), finite).
pub const MAX_METAL_REFLECTANCE: f64 = 0.999;

/// Where the base colour comes from.
#[derive(Clone, Debug)]
pub enum BaseColour {
    Spectrum(DenseSpectrum),
    Texture(Arc<Texture>),
}

impl BaseColour {
    #[inline]
    fn at(&self, tex: Vec2, wl: &SampledWavelengths) -> SampledSpectrum {
        match self {
            BaseColour::Spectrum(s) => s.sample(wl),
            BaseColour::Texture(t) => t.reflectance(tex, wl),
        }
    }
}

/// A textured metallic-roughness material (see the module docs).
#[derive(Clone, Debug)]
pub struct MetalRough {
    pub base: BaseColour,
    pub metallic: f64,
    /// Perceptual roughness factor (α = r²).
    pub roughness: f64,
    /// Roughness (G) and metallic (B) channels; `None`: the factors alone.
    pub texture: Option<ByteTexture<2>>,
    /// Per roughness step q (r = roughness · q/255): the microfacet distribution.
    mf: Vec<Microfacet>,
    /// Per roughness step: the coat, for the steps with r < 0.5.
    coats: Vec<Option<Arc<Coated>>>,
    /// [`MaterialFlags::DELTA`] when a hit can resolve to a smooth metal or coat.
    flags: MaterialFlags,
}

impl MetalRough {
    /// The material at `field`: base colour, metallic and roughness factors in [0, 1], the
    /// optional metallic-roughness texture and the coat's index `ior` (≥ 1).
    pub fn build(
        ctx: &Context,
        field: &str,
        base: BaseColour,
        (metallic, roughness): (f64, f64),
        texture: Option<ByteTexture<2>>,
        ior: f64,
    ) -> Result<Self, SceneError> {
        let steps = if texture.is_some() { 256 } else { 1 };
        let mut mf = Vec::with_capacity(steps);
        for q in 0..steps {
            let r = level(roughness, q, steps);
            mf.push(Microfacet::build(
                ctx,
                field,
                DistributionDesc::Ggx,
                MaskingDesc::Smith,
                (r * r) as f32,
                None,
            )?);
        }
        // Coats (a few ms each) only for the steps a hit can reach: between the texture's
        // extreme roughness texels, below r = 0.5, unless the material is metal everywhere.
        let (lo, hi) = match &texture {
            Some(t) => {
                let (lo, hi) = t.channel_range(0);
                let metal_everywhere = metallic * (t.channel_range(1).0 as f64 / 255.0) >= 0.5;
                if metal_everywhere {
                    (1, 0)
                } else {
                    (lo as usize, hi as usize)
                }
            }
            None if metallic < 0.5 => (0, 0),
            None => (1, 0),
        };
        use rayon::prelude::*;
        let coats: Vec<Option<Arc<Coated>>> = (0..steps)
            .into_par_iter()
            .map(|q| {
                let r = level(roughness, q, steps);
                (q >= lo && q <= hi && r < 0.5)
                    .then(|| Arc::new(Coated::new(DenseSpectrum::constant(0.5), ior as f32, mf[q])))
            })
            .collect();
        // Reachable roughness steps: the texture's range of G (all 256 bilinear values between).
        let (r_lo, r_hi) = match &texture {
            Some(t) => {
                let (a, b) = t.channel_range(0);
                (a as usize, b as usize)
            }
            None => (0, 0),
        };
        let flags = if (r_lo..=r_hi).any(|q| mf[q].effectively_smooth()) {
            MaterialFlags::DELTA
        } else {
            MaterialFlags::NONE
        };
        Ok(MetalRough {
            flags,
            base,
            metallic,
            roughness,
            texture,
            mf,
            coats,
        })
    }

    /// What its hits can be: [`MaterialFlags::DELTA`] if any can be a smooth metal or coat.
    pub fn flags(&self) -> MaterialFlags {
        self.flags
    }

    /// Heap memory of the textures' texels and the coats' tables, bytes.
    pub fn memory_bytes(&self) -> usize {
        let base = match &self.base {
            BaseColour::Texture(t) => t.memory_bytes(),
            BaseColour::Spectrum(_) => 0,
        };
        base + self.texture.as_ref().map_or(0, |t| t.memory_bytes())
    }

    /// The material at texture coordinates `tex`, its base colour at the wavelengths of `wl`.
    pub fn at(&self, tex: Vec2, wl: &SampledWavelengths) -> Material {
        let (q, metallic) = match &self.texture {
            Some(t) => {
                let [g, b] = t.lookup_raw(tex);
                let step = |v: f32| v.round().clamp(0.0, 255.0) as usize;
                (step(g), self.metallic * (step(b) as f64 / 255.0))
            }
            None => (0, self.metallic),
        };
        let steps = self.mf.len();
        let rho = self.base.at(tex, wl);
        if metallic >= 0.5 {
            let mut k = SampledSpectrum::ZERO;
            for i in 0..N_LAMBDA {
                k[i] = ConductorAt::k_of_reflectance(rho[i] as f64, MAX_METAL_REFLECTANCE) as f32;
            }
            return Material::ConductorAt(ConductorAt { mf: self.mf[q], k });
        }
        if level(self.roughness, q, steps) >= 0.5 {
            return Material::DiffuseAt(rho);
        }
        match &self.coats[q] {
            Some(coat) => Material::CoatedAt(coat.clone(), rho),
            None => Material::DiffuseAt(rho),
        }
    }
}

/// Perceptual roughness of step `q` of `steps` (256 with a texture, else the factor itself).
#[inline]
fn level(roughness: f64, q: usize, steps: usize) -> f64 {
    if steps == 1 {
        roughness
    } else {
        roughness * (q as f64 / 255.0)
    }
}
