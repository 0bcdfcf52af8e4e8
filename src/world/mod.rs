//! The built, render-ready scene: geometry in one BVH, materials, lights in radiometric units,
//! the camera, the render settings, the meters and grids ([`measure`]) and where light tracing
//! starts and aims ([`caustic_lights`]). Read-only data, produced by `scene::build`; the
//! integrators, the renderer and the meters read it and are not imported by it.

pub mod caustic_lights;
pub mod measure;

pub use caustic_lights::CausticLights;
pub use measure::{Grid, MeasureSettings, Meter, MeterKind};

use crate::bxdf::Material;
use crate::camera::{Camera, PixelFilter};
use crate::geometry::SceneGeometry;
use crate::light::{Light, LightSampler, LightSamplerKind};

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
    /// Maximum number of scattering events along a path (0 = only directly visible emission);
    /// None = unlimited (paths end by Russian roulette only, and the estimate is unbiased).
    pub max_depth: Option<u32>,
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
    /// How next-event estimation chooses a light ([`crate::light::sampler`]).
    pub light_sampler: LightSamplerKind,
    /// Independent sample sequences (batches) per pixel, one of
    /// [`crate::film::PIXEL_BATCH_CHOICES`] (see [`crate::render::pixel_batch`]).
    pub pixel_batches: u32,
}

/// Estimator of the caustic paths light → specular surfaces → non-specular surface → camera.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Caustics {
    /// Traced from the lights and connected to the camera (`integrator::light_path`); used
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
            max_depth: None,
            rr_depth: 3,
            seed: 0,
            filter: PixelFilter::Box,
            illuminance: false,
            caustics: Caustics::LightTracing,
            light_paths_per_sample: crate::description::schema::DEFAULT_LIGHT_PATHS_PER_SAMPLE,
            light_sampler: LightSamplerKind::Bvh,
            pixel_batches: crate::film::DEFAULT_PIXEL_BATCHES,
        }
    }
}

pub struct World {
    pub geometry: SceneGeometry,
    /// Per object: whether its material passes light straight through (a window pane, see
    /// [`crate::bxdf::MaterialFlags::STRAIGHT_THROUGH`]). Empty when no object does. Shadow rays
    /// pass through those objects with their transmittance (`integrator::transmit`).
    pub see_through: Vec<bool>,
    pub objects: Vec<Object>,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    /// Chooses the light for next-event estimation at a shading point.
    pub light_sampler: LightSampler,
    /// Indices of lights at infinity (environment), evaluated on escaped rays.
    pub infinite_lights: Vec<u32>,
    pub camera: Camera,
    pub settings: RenderSettings,
    pub meters: Vec<Meter>,
    pub grids: Vec<Grid>,
    pub measure: MeasureSettings,
    /// Light tracing of caustics, when on and useful (`integrator::light_path`).
    pub caustics: Option<CausticLights>,
    /// The files the scene refers to (meshes, spectra, luminaire data, …), as resolved when it
    /// was built; a render state's scene hash covers their contents.
    pub sources: Vec<std::path::PathBuf>,
}

impl World {
    /// What reading the scene's data files noted for the user (data a file holds that is not
    /// used, a direction made by reciprocity), each naming its file.
    pub fn load_notes(&self) -> Vec<String> {
        self.materials
            .iter()
            .filter_map(|m| match m {
                crate::bxdf::Material::BsdfFile(f) => Some(f),
                _ => None,
            })
            .flat_map(|f| {
                f.notes
                    .iter()
                    .map(|n| format!("BSDF file '{}': {n}", f.path.display()))
            })
            .collect()
    }

    /// The same world lit by `lights` instead (lights at infinity: skies, suns, environments;
    /// objects emit nothing afterwards). Daylight coefficients use it to light one geometry by
    /// a unit sky, then by each hour's sun, without building it again. Light-traced caustics
    /// are dropped: the irradiance estimators these worlds serve do not use them.
    pub fn relit(mut self, lights: Vec<Light>) -> World {
        for o in &mut self.objects {
            o.light = None;
        }
        self.infinite_lights = lights
            .iter()
            .enumerate()
            .filter(|(_, l)| l.flags().contains(crate::light::LightFlags::INFINITE))
            .map(|(i, _)| i as u32)
            .collect();
        let (lo, hi) = self.geometry.bounds();
        let scene_radius = if lo.is_finite() && hi.is_finite() && hi.cmpge(lo).all() {
            (0.5 * (hi - lo).length()).max(1e-6)
        } else {
            1.0
        };
        self.light_sampler = LightSampler::new(
            self.settings.light_sampler,
            &lights,
            &self.geometry,
            scene_radius,
        );
        self.lights = lights;
        self.caustics = None;
        self
    }
}
