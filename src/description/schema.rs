//! The RON scene format: serde types, one per construct. Field names carry their units.
//! Every struct rejects unknown fields. The format is documented in `docs/scene-format.md`.

use serde::Deserialize;
use std::collections::BTreeMap;

pub type V3 = [f32; 3];

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, rename = "Scene")]
pub struct SceneFile {
    pub camera: CameraDesc,
    #[serde(default)]
    pub render: RenderDesc,
    /// Materials by name; objects refer to them by name. `"black"` is predefined (and may not
    /// be redefined). A key given twice is an error.
    #[serde(default, deserialize_with = "unique_material_keys")]
    pub materials: BTreeMap<String, MaterialDesc>,
    #[serde(default)]
    pub objects: Vec<ObjectDesc>,
    #[serde(default)]
    pub lights: Vec<LightDesc>,
    /// Point meters (illuminance or luminance), reported in NAME.report.json.
    #[serde(default)]
    pub meters: Vec<MeterDesc>,
    /// Calculation grids of illuminance meters (e.g. a work plane), reported in the JSON report
    /// and one CSV each.
    #[serde(default)]
    pub grids: Vec<GridDesc>,
    /// Sample budget of meters and grids.
    #[serde(default)]
    pub measure: MeasureDesc,
    /// Which way is up and where north is, for skies and the sun (docs/daylight.md).
    #[serde(default)]
    pub site: SiteDesc,
}

/// The site's orientation in scene coordinates: `up` (default +y) and `north` (default −z;
/// made perpendicular to `up`). East is north × up.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SiteDesc {
    #[serde(default = "default_up")]
    pub up: V3,
    #[serde(default = "default_north")]
    pub north: V3,
}

fn default_north() -> V3 {
    [0.0, 0.0, -1.0]
}

impl Default for SiteDesc {
    fn default() -> Self {
        Self {
            up: default_up(),
            north: default_north(),
        }
    }
}

fn unique_material_keys<'de, D>(d: D) -> Result<BTreeMap<String, MaterialDesc>, D::Error>
where
    D: serde::Deserializer<'de>,
{
    unique_keys(d, "materials")
}

/// Deserialize the map `field`, refusing a key given twice (serde's maps keep the last value
/// silently; the error raised here carries the parser's position).
fn unique_keys<'de, D, V>(d: D, field: &'static str) -> Result<BTreeMap<String, V>, D::Error>
where
    D: serde::Deserializer<'de>,
    V: Deserialize<'de>,
{
    struct Visit<V>(&'static str, std::marker::PhantomData<V>);
    impl<'de, V: Deserialize<'de>> serde::de::Visitor<'de> for Visit<V> {
        type Value = BTreeMap<String, V>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a map with string keys")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            mut map: A,
        ) -> Result<Self::Value, A::Error> {
            let mut out = BTreeMap::new();
            while let Some(key) = map.next_key::<String>()? {
                if out.contains_key(&key) {
                    return Err(serde::de::Error::custom(format!(
                        "`{}`: the key {key:?} is given twice; each key may appear only once",
                        self.0
                    )));
                }
                let value = map.next_value()?;
                out.insert(key, value);
            }
            Ok(out)
        }
    }
    d.deserialize_map(Visit(field, std::marker::PhantomData))
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MeterDesc {
    /// Illuminance (lx) on a small receiver at `position` facing `normal`, from the whole
    /// hemisphere around the normal (a cosine-corrected lux meter).
    Illuminance {
        name: String,
        position: V3,
        normal: V3,
    },
    /// Mean luminance (cd/m²) seen from `position` looking along `direction`, within a cone
    /// of half-angle `half_angle_deg` (a spot luminance meter; 0 = a single direction).
    Luminance {
        name: String,
        position: V3,
        direction: V3,
        #[serde(default)]
        half_angle_deg: f32,
    },
    /// CIE 117 unified glare rating for an eye at `position` looking along `direction`, from
    /// the scene's luminaires, with the background luminance from the measured indirect
    /// vertical illuminance (docs/glare.md); `up` (default +y) orients the position index.
    Ugr {
        name: String,
        position: V3,
        direction: V3,
        #[serde(default)]
        up: Option<V3>,
    },
    /// Vertical illuminance E_v (lx) and melanopic EDI (lx, CIE S 026) at an eye at
    /// `position` looking along `direction` (the receiver faces the direction of gaze), with
    /// their ratio, the melanopic DER of the light reaching the eye.
    Melanopic {
        name: String,
        position: V3,
        direction: V3,
    },
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridDesc {
    pub name: String,
    /// Corner of the grid's rectangle, m.
    pub origin: V3,
    /// The rectangle's two sides, m (nx points along edge_u, ny along edge_v).
    pub edge_u: V3,
    pub edge_v: V3,
    pub nx: u32,
    pub ny: u32,
    /// Direction the meters face (default up, (0, 1, 0): a horizontal work plane).
    #[serde(default = "default_up")]
    pub normal: V3,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeasureDesc {
    /// Samples per meter (and per grid point) when no target error is set, or the minimum
    /// before the target is checked.
    #[serde(default = "default_meter_samples")]
    pub samples: u64,
    /// Stop each meter when its standard error is below this fraction of its value
    /// (e.g. 0.005 for 0.5 %), up to `max_samples`.
    #[serde(default)]
    pub target_relative_error: Option<f64>,
    #[serde(default = "default_meter_max_samples")]
    pub max_samples: u64,
}

impl Default for MeasureDesc {
    fn default() -> Self {
        Self {
            samples: default_meter_samples(),
            target_relative_error: None,
            max_samples: default_meter_max_samples(),
        }
    }
}
fn default_meter_samples() -> u64 {
    4096
}
fn default_meter_max_samples() -> u64 {
    1 << 22
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// Eye position, m (required unless `from_model` gives it).
    #[serde(default)]
    pub position: Option<V3>,
    /// Point looked at, m (required unless `from_model` gives the view).
    #[serde(default)]
    pub look_at: Option<V3>,
    /// Up direction; (0, 1, 0) when omitted (a `from_model` camera's own up).
    #[serde(default)]
    pub up: Option<V3>,
    /// The position, view, up and field of view of a camera of a glTF model placed by one of
    /// the scene's objects, instead of `position`, `look_at` and `up`.
    #[serde(default)]
    pub from_model: Option<ModelCameraDesc>,
    /// Full vertical field of view of the perspective projection, degrees (shorthand for
    /// `projection: Perspective(vfov_deg: …)`; not with `projection`).
    #[serde(default)]
    pub vfov_deg: Option<f32>,
    /// Image width and height, pixels.
    pub resolution: (u32, u32),
    /// How directions map to the image; omitted = perspective with `vfov_deg`.
    #[serde(default)]
    pub projection: Option<ProjectionDesc>,
    /// Thin lens (perspective only); omitted = pinhole.
    #[serde(default)]
    pub lens: Option<LensDesc>,
}

/// The camera's projection (docs/scene-format.md).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ProjectionDesc {
    /// Pinhole or thin-lens perspective; full vertical field of view in degrees.
    Perspective { vfov_deg: f32 },
    /// Circular fisheye inscribed in the image's shorter side; `fov_deg` is the full angle
    /// across the circle, degrees.
    Fisheye {
        mapping: FisheyeMappingDesc,
        fov_deg: f32,
    },
    /// 360° × 180° latitude–longitude panorama centred on the view direction.
    Equirectangular,
}

/// Radial mapping of a fisheye: image radius ∝ θ, sin θ, 2 sin(θ/2) or 2 tan(θ/2) for the
/// angle θ to the view direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum FisheyeMappingDesc {
    Equidistant,
    Orthographic,
    Equisolid,
    Stereographic,
}

/// A camera of a glTF model (`camera.from_model`): the object of `objects` (by `name`) whose
/// `Model` shape is the file, and which of its cameras (as `--camera` for a glTF file: an
/// index in scene order or a node's or camera's name; the first when omitted).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelCameraDesc {
    pub object: String,
    #[serde(default)]
    pub camera: Option<String>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LensDesc {
    /// Radius of the lens aperture, m.
    pub aperture_radius: f32,
    /// Distance from the lens to the plane in focus, m.
    pub focus_distance: f32,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderDesc {
    #[serde(default = "default_spp")]
    pub spp: u32,
    /// Most scattering events per path; None (absent) = unlimited, paths end by Russian
    /// roulette only.
    #[serde(default)]
    pub max_depth: Option<u32>,
    /// Scattering events before Russian roulette may end a path.
    #[serde(default = "default_rr_depth")]
    pub rr_depth: u32,
    #[serde(default)]
    pub seed: u64,
    #[serde(default)]
    pub filter: FilterDesc,
    /// Also write per-pixel illuminance (lx) of the surface seen (`--illuminance`).
    #[serde(default)]
    pub illuminance: bool,
    /// How caustics (light → smooth glass or metal → surface seen) are rendered
    /// (`--caustics`).
    #[serde(default)]
    pub caustics: CausticsDesc,
    /// With light-traced caustics: light paths per camera sample.
    #[serde(default = "default_light_paths_per_sample")]
    pub light_paths_per_sample: f32,
    /// How next-event estimation chooses a light (see `light::sampler`).
    #[serde(default)]
    pub light_sampler: LightSamplerDesc,
    /// Independent sample sequences per pixel (2, 4, 8 or 16) behind its standard error.
    #[serde(default = "default_pixel_batches")]
    pub pixel_batches: u32,
}

fn default_pixel_batches() -> u32 {
    crate::film::DEFAULT_PIXEL_BATCHES
}

/// See `light::LightSamplerKind`.
#[derive(Debug, Clone, Copy, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum LightSamplerDesc {
    #[default]
    Bvh,
    Power,
}

/// Light paths per camera sample unless the scene says otherwise: aimed at the specular
/// objects, each light path costs about as much as a camera path, and on the benchmark Cornell
/// box 1/32 already makes the light-traced part's variance negligible beside the camera paths'.
pub const DEFAULT_LIGHT_PATHS_PER_SAMPLE: f32 = 0.0625;

fn default_light_paths_per_sample() -> f32 {
    DEFAULT_LIGHT_PATHS_PER_SAMPLE
}

/// See `world::Caustics`.
#[derive(Debug, Clone, Copy, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum CausticsDesc {
    #[default]
    LightTracing,
    PathTracing,
}

impl Default for RenderDesc {
    fn default() -> Self {
        Self {
            spp: default_spp(),
            max_depth: None,
            rr_depth: default_rr_depth(),
            seed: 0,
            filter: FilterDesc::Box,
            illuminance: false,
            caustics: CausticsDesc::LightTracing,
            light_paths_per_sample: default_light_paths_per_sample(),
            light_sampler: LightSamplerDesc::Bvh,
            pixel_batches: default_pixel_batches(),
        }
    }
}
fn default_spp() -> u32 {
    64
}
fn default_rr_depth() -> u32 {
    3
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum FilterDesc {
    #[default]
    Box,
    Tent {
        radius: f32,
    },
    Gaussian {
        sigma: f32,
        radius: f32,
    },
}

/// A spectral distribution.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum SpectrumDesc {
    /// The same value at every wavelength.
    Constant(f64),
    /// Planck's law at this temperature, K (emission only).
    Blackbody(f64),
    /// CIE daylight (D series) at this correlated colour temperature, 4000–25 000 K (emission
    /// only).
    Daylight(f64),
    /// A spectrum shipped in data/ (CIE illuminants, Cornell box, ColorChecker, TCS).
    Named(String),
    /// (wavelength nm, value) pairs, strictly increasing in wavelength; linear interpolation,
    /// 0 outside.
    Tabulated(Vec<(f64, f64)>),
    /// A two-column CSV file (nm, value), path relative to the scene file, resampled to 1 nm
    /// as CIE 167 recommends (default) or linearly (`Csv("f.csv", Linear)`).
    Csv(String, #[serde(default)] crate::colour::sd::Interpolation),
    /// A linear-sRGB colour (components in [0, 1]) upsampled to a smooth spectrum.
    Rgb(f64, f64, f64),
    /// An sRGB colour as encoded in images and colour pickers (IEC 61966-2-1 transfer function,
    /// components in [0, 1]); decoded to linear sRGB, then as `Rgb`.
    Srgb(f64, f64, f64),
    /// An image texture, only as a `Diffuse` material's reflectance (each texel's colour
    /// upsampled as `Srgb` (PNG, JPEG) or `Rgb` (OpenEXR)) or as an object's emission spectrum
    /// (each texel emitting the amount × its luminance, with its colour's shape);
    /// docs/scene-format.md → textures.
    Texture {
        /// PNG, JPEG (sRGB) or OpenEXR (linear) image, relative to the scene file.
        file: String,
        /// Texture coordinates are multiplied by this (default (1, 1)), then offset.
        #[serde(default = "default_uv_scale")]
        uv_scale: [f32; 2],
        #[serde(default)]
        uv_offset: [f32; 2],
        /// `Repeat` (default) or `Clamp`.
        #[serde(default)]
        wrap: crate::texture::Wrap,
    },
}

pub(super) fn default_uv_scale() -> [f32; 2] {
    [1.0, 1.0]
}

pub use super::material::{DistributionDesc, IorDesc, MaskingDesc, MaterialDesc, MaterialRefDesc};

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectDesc {
    /// Optional name, used in messages.
    #[serde(default)]
    pub name: Option<String>,
    pub shape: ShapeDesc,
    /// Name of an entry of `materials` (or `"black"`). For a `Model` shape, optional: the
    /// material of the faces that name none (docs/scene-format.md → models).
    #[serde(default)]
    pub material: String,
    #[serde(default)]
    pub emission: Option<EmissionDesc>,
    #[serde(default)]
    pub transform: Option<TransformDesc>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ShapeDesc {
    Sphere {
        center: V3,
        radius: f32,
    },
    /// Parallelogram `origin + s·edge_u + t·edge_v`; its front face is edge_u × edge_v.
    Quad {
        origin: V3,
        edge_u: V3,
        edge_v: V3,
    },
    Disk {
        center: V3,
        normal: V3,
        radius: f32,
    },
    /// Inline triangle mesh; front faces wind counter-clockwise.
    Triangles {
        positions: Vec<V3>,
        indices: Vec<[u32; 3]>,
        #[serde(default)]
        normals: Option<Vec<V3>>,
    },
    /// Wavefront OBJ file, relative to the scene file.
    Obj(String),
    /// PLY file (ASCII or binary), relative to the scene file.
    Ply(String),
    /// A building model: an OBJ file whose faces keep the materials of its MTL libraries, or a
    /// glTF 2.0 file (`.gltf`, `.glb`) with its node hierarchy and materials (relative to the
    /// scene file), mapped to candela materials (docs/scene-format.md → models);
    /// `materials_from_file` replaces some of them by name.
    Model {
        file: String,
        #[serde(default, deserialize_with = "unique_override_keys")]
        materials_from_file: BTreeMap<String, MaterialRefDesc>,
        /// Luminance, cd/m², of a material whose MTL `Ke` is (1, 1, 1); with it, materials
        /// with a non-zero `Ke` emit (none do without it).
        #[serde(default)]
        ke_luminance: Option<f64>,
        /// glTF only: add the file's `KHR_lights_punctual` lights (cd, lx) to the scene.
        #[serde(default)]
        lights: bool,
    },
    /// Venetian blinds, expanded to triangles (`geometry::blinds`): Radiance's `genblinds`
    /// with its axes X, Y, Z along `out`, `width_dir`, `up` and its origin at `origin`.
    /// Lengths in metres; give `spacing` or `count`.
    Blinds {
        origin: V3,
        /// Along the slats (genblinds' +Y).
        width_dir: V3,
        /// Up the stack of slats (genblinds' +Z), perpendicular to `width_dir`.
        up: V3,
        /// Normal of the blinds' plane toward which the slats reach from `origin` (genblinds' +X).
        out: V3,
        width: f64,
        height: f64,
        /// Slat depth (chord of a curved slat), m.
        depth: f64,
        /// Distance between slats, m (the count is height / spacing, rounded).
        #[serde(default)]
        spacing: Option<f64>,
        #[serde(default)]
        count: Option<u32>,
        /// Slat tilt, degrees in [-90, 90]: a positive angle lifts the slats' `out` edge.
        angle_deg: f64,
        /// Radius of curvature of the slats' cross-section, m (genblinds' `-r`: positive puts
        /// the centre of curvature on the `up` side); `None` for flat slats.
        #[serde(default)]
        curvature_radius: Option<f64>,
        /// Slat thickness, m: only 0 (slats are two-sided surfaces, as genblinds makes them).
        #[serde(default)]
        thickness: f64,
    },
    /// One mesh (`Obj`, `Ply`, `Triangles` or `Model`) stored once and placed at each of
    /// `transforms` (each applied before the object's own `transform`).
    Instances {
        mesh: Box<ShapeDesc>,
        transforms: Vec<TransformDesc>,
    },
}

fn unique_override_keys<'de, D>(d: D) -> Result<BTreeMap<String, MaterialRefDesc>, D::Error>
where
    D: serde::Deserializer<'de>,
{
    unique_keys(d, "materials_from_file")
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransformDesc {
    #[serde(default)]
    pub translate: Option<V3>,
    /// Euler angles, degrees, applied about X, then Y, then Z.
    #[serde(default)]
    pub rotate_deg: Option<V3>,
    #[serde(default)]
    pub scale: Option<V3>,
}

/// A photometric amount.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Amount {
    /// Luminance, cd/m².
    Luminance(f64),
    /// Luminous flux, lm.
    Flux(f64),
    /// Luminous intensity, cd.
    Intensity(f64),
    /// Illuminance, lx.
    Illuminance(f64),
    /// A sky's horizontal illuminance (unobstructed, the sky alone), lx.
    HorizontalIlluminance(f64),
    /// A sky's zenith luminance, cd/m².
    ZenithLuminance(f64),
    /// The sun's direct-normal illuminance (on a surface facing it), lx.
    NormalIlluminance(f64),
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EmissionDesc {
    /// Spectral shape of the emission; only its shape matters, `amount` sets the level.
    pub spectrum: SpectrumDesc,
    /// `Luminance(cd/m²)` of the surface, or total `Flux(lm)` of the object.
    pub amount: Amount,
    /// Emit from both faces (default: only the front face).
    #[serde(default)]
    pub two_sided: bool,
    /// An emission texture given by a model file (glTF `emissiveTexture`, OBJ `map_Ke`), not
    /// by scene text: each texel emits `amount` × its luminance Y with its colour's shape, and
    /// `spectrum` is unused.
    #[serde(skip)]
    pub texture: Option<std::sync::Arc<crate::texture::emission::EmissionTexture>>,
}

/// A window or skylight opening of an environment light: the parallelogram
/// `origin + s·edge_u + t·edge_v`, s, t ∈ [0, 1].
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PortalDesc {
    pub origin: V3,
    pub edge_u: V3,
    pub edge_v: V3,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum LightDesc {
    /// Isotropic point light; amount `Intensity(cd)` or `Flux(lm)`.
    Point {
        position: V3,
        spectrum: SpectrumDesc,
        amount: Amount,
    },
    /// Spot light aimed at `look_at`; amount `Intensity(cd)` on the axis or `Flux(lm)`.
    Spot {
        position: V3,
        look_at: V3,
        /// Half-angle of full intensity, degrees.
        inner_deg: f32,
        /// Half-angle where the intensity reaches 0, degrees.
        outer_deg: f32,
        spectrum: SpectrumDesc,
        amount: Amount,
    },
    /// Parallel light travelling along `direction`; amount `Illuminance(lx)` on a surface
    /// facing it.
    Distant {
        direction: V3,
        spectrum: SpectrumDesc,
        amount: Amount,
    },
    /// Uniform light from every direction; amount `Luminance(cd/m²)`. `portals`: the
    /// openings (windows, skylights) through which it reaches an interior, as parallelograms;
    /// light sampling then aims through them (see docs/scene-format.md → lights).
    Environment {
        spectrum: SpectrumDesc,
        amount: Amount,
        #[serde(default)]
        portals: Vec<PortalDesc>,
    },
    /// A luminaire from a photometric file (docs/luminaires.md): candela from the file,
    /// colour from `spectrum`.
    Goniometric {
        /// IES LM-63 (.ies) or EULUMDAT (.ldt) file, relative to the scene file.
        file: String,
        position: V3,
        /// Aiming: Euler angles, degrees, about X, then Y, then Z (as in transforms). Without
        /// it, nadir is −Y and C0 is +X.
        #[serde(default)]
        rotate_deg: Option<V3>,
        spectrum: SpectrumDesc,
        /// Scale the table to this total luminous flux, lm.
        #[serde(default)]
        lumens: Option<f64>,
        /// Multiply the candela (after `lumens`), default 1.
        #[serde(default)]
        multiplier: Option<f64>,
    },
    /// A sky over a ground (docs/daylight.md): its luminance distribution `model`, the sun's
    /// position `sun` (for the models that depend on it), amount `HorizontalIlluminance(lx)`
    /// or `ZenithLuminance(cd/m²)`, spectrum (default `Daylight(6504)`), ground reflectance
    /// (default 0.2) and portals as for `Environment`. A Perez sky also brings its sun's
    /// disk unless `sun_disk: false`.
    Sky {
        model: SkyModelDesc,
        #[serde(default)]
        sun: Option<SunDesc>,
        #[serde(default)]
        amount: Option<Amount>,
        #[serde(default)]
        spectrum: Option<SpectrumDesc>,
        #[serde(default)]
        ground_reflectance: Option<f64>,
        #[serde(default)]
        portals: Vec<PortalDesc>,
        #[serde(default)]
        sun_disk: Option<bool>,
    },
    /// The Perez sky and the sun of one hour of an EnergyPlus weather file (docs/daylight.md):
    /// `time` is `"MM-DD hh:mm"` in the file's local standard time; the other fields as for
    /// `Sky`.
    Weather {
        file: String,
        time: String,
        #[serde(default)]
        spectrum: Option<SpectrumDesc>,
        #[serde(default)]
        ground_reflectance: Option<f64>,
        #[serde(default)]
        portals: Vec<PortalDesc>,
        #[serde(default)]
        sun_disk: Option<bool>,
    },
    /// The sun's disk (0.533°): position `sun`, amount `NormalIlluminance(lx)`, spectrum
    /// (default `Named("D50")`).
    Sun {
        sun: SunDesc,
        amount: Amount,
        #[serde(default)]
        spectrum: Option<SpectrumDesc>,
    },
}

/// A sky's luminance distribution (docs/daylight.md).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum SkyModelDesc {
    /// CIE standard general sky 1–15 (ISO 15469:2004).
    CieGeneral(u32),
    /// The traditional CIE overcast sky, L(Z) = L_z (1 + 2 cos Z)/3.
    CieOvercast,
    /// The same luminance everywhere.
    Uniform,
    /// The CIE 1973 clear sky of Radiance's `gensky +s`.
    CieClear,
    /// The Perez all-weather sky from the direct-normal and diffuse-horizontal illuminance
    /// (lx), as `gendaylit -L`; dew point (°C) for the efficacy model (default: 2 cm of
    /// precipitable water).
    Perez {
        direct_normal_lx: f64,
        diffuse_horizontal_lx: f64,
        #[serde(default)]
        dew_point_c: Option<f64>,
    },
    /// The Perez sky from the direct-normal and diffuse-horizontal irradiance (W/m²), as
    /// `gendaylit -W`: the Perez (1990) efficacy model gives the illuminances.
    PerezIrradiance {
        direct_normal_w_m2: f64,
        diffuse_horizontal_w_m2: f64,
        #[serde(default)]
        dew_point_c: Option<f64>,
    },
}

/// Where the sun is: `altitude_deg` and `azimuth_deg` (from north toward east), or
/// `latitude_deg`, `longitude_deg` (east positive), `time` (ISO 8601 with its UTC offset, or
/// local apparent solar time without one when `solar_time: true`) and optionally
/// `elevation_m`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SunDesc {
    #[serde(default)]
    pub altitude_deg: Option<f64>,
    #[serde(default)]
    pub azimuth_deg: Option<f64>,
    #[serde(default)]
    pub latitude_deg: Option<f64>,
    #[serde(default)]
    pub longitude_deg: Option<f64>,
    #[serde(default)]
    pub time: Option<String>,
    #[serde(default)]
    pub elevation_m: Option<f64>,
    /// `time` is local apparent solar time (no UTC offset) instead of clock time.
    #[serde(default)]
    pub solar_time: bool,
}

fn default_up() -> V3 {
    [0.0, 1.0, 0.0]
}
