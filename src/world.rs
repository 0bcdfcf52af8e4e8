//! The built, render-ready scene: geometry in one BVH, materials, lights in radiometric units,
//! the camera and the render settings. Produced by [`crate::scene::build`]; read-only while
//! rendering.

use crate::bxdf::Material;
use crate::camera::{Camera, PixelFilter};
use crate::geometry::SceneGeometry;
use crate::light::{Light, LightSampler};

/// What a primitive's `object` id refers to.
#[derive(Clone, Copy, Debug)]
pub struct Object {
    pub material: u32,
    /// Index into [`World::lights`] if the object emits.
    pub light: Option<u32>,
}

/// Settings of one render.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    /// Camera samples per pixel.
    pub spp: u32,
    /// Maximum number of scattering events along a path (0 = only directly visible emission).
    pub max_depth: u32,
    /// Number of scattering events before Russian roulette may end a path.
    pub rr_depth: u32,
    pub seed: u64,
    pub filter: PixelFilter,
    /// Also estimate the illuminance (lx) on the surface seen through each pixel.
    pub illuminance: bool,
    /// How caustic paths (light → specular chain → surface seen) are estimated.
    pub caustics: Caustics,
    /// Light paths traced per camera sample when caustics are light-traced.
    pub light_paths_per_sample: f32,
}

/// Light paths per camera sample unless the scene says otherwise: aimed at the specular
/// objects, each light path costs about as much as a camera path, and on the benchmark Cornell
/// box 1/32 already makes the light-traced part's variance negligible beside the camera paths'.
pub const DEFAULT_LIGHT_PATHS_PER_SAMPLE: f32 = 0.0625;

/// Estimator of the caustic paths light → specular surfaces → non-specular surface → camera.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Caustics {
    /// Traced from the lights and connected to the camera (see [`crate::caustics`]); used
    /// when the scene has a delta-lobe material and a light other than an environment.
    #[default]
    LightTracing,
    /// Left to the camera paths' BSDF sampling (misses point-light caustics entirely).
    PathTracing,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            spp: 64,
            max_depth: 16,
            rr_depth: 3,
            seed: 0,
            filter: PixelFilter::Box,
            illuminance: false,
            caustics: Caustics::LightTracing,
            light_paths_per_sample: DEFAULT_LIGHT_PATHS_PER_SAMPLE,
        }
    }
}

pub struct World {
    pub geometry: SceneGeometry,
    /// Per object: whether its material passes light straight through (a window pane, see
    /// [`crate::bxdf::MaterialFlags::STRAIGHT_THROUGH`]). Empty when no object does. Shadow rays
    /// pass through those objects with their transmittance
    /// ([`crate::integrator::transmittance`]).
    pub see_through: Vec<bool>,
    pub objects: Vec<Object>,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    pub light_sampler: LightSampler,
    /// Indices of lights at infinity (environment), evaluated on escaped rays.
    pub infinite_lights: Vec<u32>,
    pub camera: Camera,
    pub settings: RenderSettings,
    pub meters: Vec<crate::meter::Meter>,
    pub grids: Vec<crate::meter::Grid>,
    pub measure: crate::meter::MeasureSettings,
    /// Light tracing of caustics, when on and useful (see [`crate::caustics`]).
    pub caustics: Option<crate::caustics::CausticLights>,
    /// The files the scene refers to (meshes, spectra, luminaire data, …), as resolved when it
    /// was built; a render state's scene hash covers their contents.
    pub sources: Vec<std::path::PathBuf>,
}
