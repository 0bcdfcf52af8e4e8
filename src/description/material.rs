//! The materials of the RON scene format: a scene's `materials` entries, an OBJ object's
//! material references, and the indices of refraction and microfacet options they take.
//! Re-exported by [`super::schema`]; documented in `docs/scene-format.md` → materials.

use super::schema::{default_uv_scale, SpectrumDesc};
use serde::Deserialize;

/// A material given by an OBJ object's `materials_from_file`: a material of the scene's
/// `materials` by name, or one defined in place.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MaterialRefDesc {
    Named(String),
    Material(MaterialDesc),
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MaterialDesc {
    /// Lambertian reflection with reflectance in [0, 1].
    Diffuse { reflectance: SpectrumDesc },
    /// Oren–Nayar rough diffuse; `sigma_deg` is the facet slope deviation, degrees.
    OrenNayar {
        reflectance: SpectrumDesc,
        sigma_deg: f32,
    },
    /// Energy-normalised Phong: diffuse + specular ≤ 1 at every wavelength.
    Phong {
        #[serde(default = "zero_spectrum")]
        diffuse: SpectrumDesc,
        specular: SpectrumDesc,
        exponent: f32,
    },
    /// Metal. Either `metal: "Au"` (a table in data/ior) or `n` and `k` spectra.
    /// `roughness` is the microfacet α (0 = mirror); `roughness_v`, if given, makes it
    /// anisotropic (α along the tangent, α along the bitangent).
    Conductor {
        #[serde(default)]
        metal: Option<String>,
        #[serde(default)]
        n: Option<SpectrumDesc>,
        #[serde(default)]
        k: Option<SpectrumDesc>,
        #[serde(default)]
        roughness: f32,
        #[serde(default)]
        roughness_v: Option<f32>,
        #[serde(default)]
        distribution: DistributionDesc,
        #[serde(default)]
        masking: MaskingDesc,
    },
    /// Glass interface (outside = the side the normal points to); smooth when roughness = 0.
    Dielectric {
        ior: IorDesc,
        #[serde(default)]
        roughness: f32,
        #[serde(default)]
        roughness_v: Option<f32>,
        #[serde(default)]
        distribution: DistributionDesc,
    },
    /// Thin slab (window pane): mirror reflection and undeviated transmission.
    ThinDielectric { ior: IorDesc },
    /// Diffuse base under a clear coating of constant index (plastic, varnish); the coat is
    /// smooth when roughness = 0 (default).
    Coated {
        base: SpectrumDesc,
        #[serde(default = "default_coat_ior")]
        ior: f32,
        #[serde(default)]
        roughness: f32,
        #[serde(default)]
        distribution: DistributionDesc,
    },
    /// Lambertian plus a normalised Ward lobe (docs/ward.md): ρd + ρs ≤ 1; roughness α in
    /// [0, 1] (0: a mirror), `roughness_v` makes it anisotropic with α along `orientation`.
    Ward {
        #[serde(default = "zero_spectrum")]
        diffuse: SpectrumDesc,
        specular: SpectrumDesc,
        #[serde(default)]
        roughness: f32,
        #[serde(default)]
        roughness_v: Option<f32>,
        #[serde(default)]
        orientation: Option<[f32; 3]>,
        #[serde(default)]
        fresnel: bool,
    },
    /// Radiance `plastic`: red green blue spec rough, mapped onto `Ward` (docs/ward.md).
    RadiancePlastic {
        colour: SpectrumDesc,
        specular: f32,
        roughness: f32,
    },
    /// Radiance `metal` (specular coloured), mapped onto `Ward`.
    RadianceMetal {
        colour: SpectrumDesc,
        specular: f32,
        roughness: f32,
    },
    /// Radiance `plastic2`: orientation ux uy uz, then red green blue spec urough vrough.
    RadiancePlastic2 {
        orientation: [f32; 3],
        colour: SpectrumDesc,
        specular: f32,
        roughness_u: f32,
        roughness_v: f32,
    },
    /// Radiance `metal2` (specular coloured).
    RadianceMetal2 {
        orientation: [f32; 3],
        colour: SpectrumDesc,
        specular: f32,
        roughness_u: f32,
        roughness_v: f32,
    },
    /// Translucent sheet, two-sided (docs/fenestration.md): diffuse reflectance and
    /// transmittance, specular transmittance (spectra in [0, 1]), uncoloured specular
    /// reflectance, roughness α (0: mirror and straight through) and Radiance's Fresnel
    /// estimate on a pure surface; the four coefficients sum to at most 1 at every wavelength.
    Translucent {
        #[serde(default = "zero_spectrum")]
        reflectance: SpectrumDesc,
        #[serde(default = "zero_spectrum")]
        transmittance: SpectrumDesc,
        #[serde(default = "zero_spectrum")]
        specular_transmittance: SpectrumDesc,
        #[serde(default)]
        specular: f32,
        #[serde(default)]
        roughness: f32,
        #[serde(default)]
        fresnel: bool,
    },
    /// Scattering read from an LBNL WINDOW / Radiance BSDF XML file of Klems matrices
    /// (docs/fenestration.md): `file` relative to the scene; `up` (scene coordinates) orients
    /// the file's azimuths as Radiance's `BSDF` primitive does (the file's X axis is
    /// up × normal). The surface normal points into the room (WINDOW's back).
    BsdfFile { file: String, up: [f32; 3] },
    /// Radiance's `trans` material: `colour` (red green blue), `specular` (spec), `roughness`
    /// (rough), `transmissivity` (trans), `transmitted_specular` (tspec); converted to a
    /// `Translucent` (docs/fenestration.md).
    RadianceTrans {
        colour: SpectrumDesc,
        #[serde(default)]
        specular: f32,
        #[serde(default)]
        roughness: f32,
        transmissivity: f32,
        #[serde(default)]
        transmitted_specular: f32,
    },
    /// Absorbs all light.
    Black,
    /// `material` under a tangent-space normal map (docs/scene-format.md → normal maps).
    NormalMapped {
        material: Box<MaterialDesc>,
        /// PNG or JPEG image, linear 8-bit, relative to the scene file.
        file: String,
        /// Multiplies the map's x and y (default 1).
        #[serde(default = "default_map_scale")]
        scale: f32,
        #[serde(default = "default_uv_scale")]
        uv_scale: [f32; 2],
        #[serde(default)]
        uv_offset: [f32; 2],
        #[serde(default)]
        wrap: crate::texture::Wrap,
    },
}

fn default_map_scale() -> f32 {
    1.0
}

fn zero_spectrum() -> SpectrumDesc {
    SpectrumDesc::Constant(0.0)
}
fn default_coat_ior() -> f32 {
    1.5
}

/// Microfacet normal distribution.
#[derive(Debug, Clone, Copy, Default, Deserialize)]
pub enum DistributionDesc {
    /// GGX / Trowbridge–Reitz.
    #[default]
    Ggx,
    Beckmann,
}

/// Microfacet masking-shadowing.
#[derive(Debug, Clone, Copy, Default, Deserialize)]
pub enum MaskingDesc {
    /// Smith, height-correlated.
    #[default]
    Smith,
    /// V-cavity (Cook–Torrance).
    VCavity,
}

/// A dielectric's refractive index.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum IorDesc {
    /// The same index at every wavelength (no dispersion).
    Constant(f32),
    /// A glass from data/ior/glasses.csv: "BK7", "fused-silica", "SF11", "F2", "BaK4".
    Glass(String),
    /// n = a + b/λ² + c/λ⁴, λ in nm.
    Cauchy {
        a: f64,
        b: f64,
        #[serde(default)]
        c: f64,
    },
    /// n² = 1 + Σ bᵢλ²/(λ² − cᵢ), λ in µm, cᵢ in µm² (three terms).
    Sellmeier { b: [f64; 3], c: [f64; 3] },
}
