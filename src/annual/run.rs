//! The annual calculation of a scene, as one library call: `candela annual` parses its options
//! into [`AnnualSettings`], calls [`run`] and writes what it returns ([`super::output`]).
//!
//! The scene's geometry and materials are kept; its lights are not. Daylight comes from the
//! weather file, through the scene's sky (`Sky` or `Weather`) for its spectrum, ground
//! reflectance and portals (its own amounts are ignored); electric lights are left out and
//! counted in the notes. The receivers are the points of the scene's grids.

use super::coefficients::{sky_coefficients, Coefficients};
use super::metrics::{Schedule, Thresholds};
use super::results::{hourly, hourly_bytes, metrics, GridResult, Hourly};
use super::sun::{sun_coefficient_bytes, sun_coefficients, SunCoefficients};
use super::view::{
    view_bytes, view_camera, view_coefficients, view_metrics, HourGlare, ViewMatrix, ViewResult,
    ViewSettings,
};
use super::year::{hourly_skies, HourSky};
use crate::camera::Camera;
use crate::daylight::epw::{Site, Weather};
use crate::daylight::patches::SkyPatches;
use crate::description::schema::{
    Amount, LightDesc, SceneFile, SkyModelDesc, SpectrumDesc, SunDesc,
};
use crate::glare::GlareOptions;
use crate::light::sky::SiteFrame;
use crate::light::Light;
use crate::scene::build::Overrides;
use crate::world::World;
use anyhow::{anyhow, bail, Result};
use glam::Vec3;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What [`run`] computes and how finely.
#[derive(Clone, Debug)]
pub struct AnnualSettings {
    /// The weather file (EPW); `None`: the file of the scene's `Weather` light.
    pub weather: Option<PathBuf>,
    /// Reinhart sky subdivision (1 = Tregenza's 145 patches; 2 = 577).
    pub mf: u32,
    /// Paths per receiver for the sky coefficients.
    pub sky_samples: u64,
    /// Paths per receiver and sun-grid node for the sun's inter-reflected light.
    pub sun_samples: u64,
    /// Shadow rays per receiver and sunny hour for the direct sun.
    pub direct_samples: u64,
    /// Occupied hours each day, local standard time: from `occupied.0`:00 to `occupied.1`:00.
    pub occupied: (usize, usize),
    pub thresholds: Thresholds,
    /// Replicate years drawn for the metrics' intervals (0: no intervals).
    pub draws: usize,
    /// Overrides the scene's seed.
    pub seed: Option<u64>,
    /// Annual glare of the scene's camera view, and how finely (None: no view).
    pub view: Option<ViewSettings>,
    /// Glare evaluation of the view's hourly images.
    pub glare: GlareOptions,
    /// Keep the grid points' sky and sun coefficients in [`AnnualRun::coefficients`].
    pub keep_coefficients: bool,
    /// The output stem the caller will write to (NAME of NAME.annual.json): when given, its
    /// directory is checked to take the files and to have room for them before the
    /// computation ([`super::room::check_room`]).
    pub out: Option<PathBuf>,
}

impl Default for AnnualSettings {
    fn default() -> Self {
        Self {
            weather: None,
            mf: 2,
            sky_samples: 4096,
            sun_samples: 4096,
            direct_samples: 64,
            occupied: (8, 18),
            thresholds: Thresholds::default(),
            draws: 200,
            seed: None,
            view: None,
            glare: GlareOptions::default(),
            keep_coefficients: false,
            out: None,
        }
    }
}

/// Which part of the calculation a progress report is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Sky coefficients: one pass (reported as 0 of 1, then 1 of 1).
    Sky,
    /// The sun: its grid's nodes, then hour by hour (steps done, of all).
    Sun,
    /// Hourly illuminances and the metrics with their replicate years.
    Metrics,
    /// The view: sky coefficients, the sun's nodes, then the hourly images' glare.
    View,
}

/// A grid's layout, as the scene gives it.
#[derive(Clone, Debug)]
pub struct GridLayout {
    pub name: String,
    pub nx: u32,
    pub ny: u32,
    /// Cell centres (m), `j * nx + i`.
    pub points: Vec<Vec3>,
    pub normal: Vec3,
    /// Lengths of the grid's two edges, m.
    pub size_m: (f64, f64),
}

/// The annual glare of the scene's camera view.
#[derive(Clone, Debug)]
pub struct ViewRun {
    /// Image size (pixels) and projection of the view's hourly images.
    pub width: usize,
    pub height: usize,
    pub projection: String,
    /// Camera paths per pixel for the sky, and per pixel and sun node for the sun.
    pub sky_samples: u64,
    pub sun_samples: u64,
    /// Occupied hours with daylight, each with its DGP and E_v.
    pub hours: Vec<HourGlare>,
    pub result: ViewResult,
    /// Seconds for the coefficients and for the hourly glare and its metrics.
    pub seconds: (f64, f64),
}

/// Everything an annual calculation found.
#[derive(Clone, Debug)]
pub struct AnnualRun {
    pub scene: PathBuf,
    pub weather: PathBuf,
    pub site: Site,
    pub settings: AnnualSettings,
    /// Sky patches used.
    pub patches: usize,
    pub grids: Vec<GridLayout>,
    pub results: Vec<GridResult>,
    pub hourly: Hourly,
    pub year: Vec<HourSky>,
    /// Occupied hours counted, daylight hours (sun above the horizon) counted by EN 17037.
    pub occupied_hours: usize,
    pub daylight_hours: usize,
    pub sunny_hours: usize,
    /// Sun positions traced for the sun's inter-reflected light.
    pub sun_nodes: usize,
    /// Sky and sun passes, seconds.
    pub seconds: (f64, f64, f64),
    pub view: Option<ViewRun>,
    /// The grid points' sky and sun coefficients (with `keep_coefficients`); the sun's are
    /// those of the year's sunny hours, in order.
    pub coefficients: Option<(Coefficients, SunCoefficients)>,
    pub notes: Vec<String>,
}

/// The sky of a scene as the annual calculation uses it: its spectrum, ground reflectance,
/// portals, and the weather file of a `Weather` light.
struct SceneSky {
    spectrum: Option<SpectrumDesc>,
    ground_reflectance: f64,
    portals: Vec<crate::description::schema::PortalDesc>,
    weather: Option<String>,
}

fn scene_sky(scene: &SceneFile) -> (SceneSky, usize) {
    let mut sky = SceneSky {
        spectrum: None,
        ground_reflectance: 0.2,
        portals: Vec::new(),
        weather: None,
    };
    let mut electric = 0;
    for l in &scene.lights {
        match l {
            LightDesc::Sky {
                spectrum,
                ground_reflectance,
                portals,
                ..
            }
            | LightDesc::Weather {
                spectrum,
                ground_reflectance,
                portals,
                ..
            } => {
                sky.spectrum = spectrum.clone();
                sky.ground_reflectance = ground_reflectance.unwrap_or(0.2);
                sky.portals = portals.clone();
                if let LightDesc::Weather { file, .. } = l {
                    sky.weather = Some(file.clone());
                }
            }
            LightDesc::Sun { .. } => {}
            _ => electric += 1,
        }
    }
    (sky, electric)
}

/// The scene, its weather and the year's skies, read and checked for an annual run.
struct Input {
    scene: SceneFile,
    sky: SceneSky,
    /// Electric lights of the scene (left out).
    electric: usize,
    /// The scene file's directory.
    dir: PathBuf,
    weather_path: PathBuf,
    weather: Weather,
    patches: SkyPatches,
    year: Vec<HourSky>,
    /// The year's hours with sun.
    sunny: Vec<usize>,
}

/// The grid points as one list of receivers (point, normal), each grid's range in it, and
/// each grid's layout.
struct Receivers {
    grids: Vec<GridLayout>,
    points: Vec<(Vec3, Vec3)>,
    ranges: Vec<Range<usize>>,
}

/// The view's camera and settings, with its sky coefficients.
struct ViewSky {
    camera: Camera,
    settings: ViewSettings,
    matrix: ViewMatrix,
}

/// The world lit by one sun of 1 lx alone (moved to each sun in turn), and the year's suns.
struct SunHours {
    world: World,
    frame: SiteFrame,
    latitude_deg: f64,
    /// The direction (east, north, up) to the sun of each of the year's hours with sun.
    to_sun: Vec<[f64; 3]>,
}

/// The hourly illuminances of the grid points and the metrics drawn from them.
struct YearMetrics {
    occupied: Schedule,
    /// Hours with the sun above the horizon (EN 17037's daylight hours).
    daylight: Schedule,
    hourly: Hourly,
    results: Vec<GridResult>,
    /// Seed of the replicate years.
    seed: u64,
}

/// Runs the annual calculation of the scene at `scene_path`.
pub fn run(
    scene_path: &Path,
    settings: &AnnualSettings,
    progress: &mut dyn FnMut(Stage, usize, usize),
) -> Result<AnnualRun> {
    let mut input = read_input(scene_path, settings)?;
    let (world, frame) = unit_sky_world(&mut input.scene, &input.sky, scene_path, settings.seed)?;
    let receivers = receivers(&world);
    let view = view_camera_of(&world, settings)?;
    check_resources(scene_path, settings, &input, &receivers, view.as_ref())?;

    let t0 = Instant::now();
    let sky_c = grid_sky(&world, &receivers, &input.patches, settings, progress)?;
    let t1 = Instant::now();
    let view = view_sky(&world, view, &input.patches, progress)?;
    let view_sky_s = t1.elapsed().as_secs_f64();

    let mut sun = sun_hours(world, frame, scene_path, &input)?;
    let sun_c = grid_sun(&mut sun, &receivers, settings, progress)?;
    let t2 = Instant::now();

    let seed = settings.seed.unwrap_or(sun.world.settings.seed);
    let m = year_metrics(&sky_c, &sun_c, &input, &receivers, settings, seed, progress);
    let t3 = Instant::now();

    let view = view.map(|v| {
        let since = (view_sky_s, t3);
        view_glare(v, &mut sun, &input, &m, settings, since, progress)
    });

    Ok(AnnualRun {
        scene: scene_path.to_path_buf(),
        weather: input.weather_path,
        site: input.weather.site.clone(),
        settings: AnnualSettings {
            sky_samples: sky_c.samples,
            sun_samples: sun_c.samples,
            direct_samples: sun_c.direct_samples,
            ..settings.clone()
        },
        patches: input.patches.len(),
        grids: receivers.grids,
        results: m.results,
        hourly: m.hourly,
        occupied_hours: m.occupied.hours.len(),
        daylight_hours: m.daylight.hours.len(),
        sunny_hours: sun.to_sun.len(),
        sun_nodes: sun_c.nodes,
        year: input.year,
        seconds: (
            (t1 - t0).as_secs_f64(),
            (t2 - t1).as_secs_f64() - view_sky_s,
            (t3 - t2).as_secs_f64(),
        ),
        view,
        coefficients: settings.keep_coefficients.then_some((sky_c, sun_c)),
        notes: notes(input.electric),
    })
}

/// Reads the scene and its weather file, checks the settings, and derives the year's skies.
fn read_input(scene_path: &Path, settings: &AnnualSettings) -> Result<Input> {
    let scene = crate::scene::load(scene_path)?;
    let (sky, electric) = scene_sky(&scene);
    let dir = scene_path.parent().unwrap_or(Path::new("")).to_path_buf();
    let weather_path = match (&settings.weather, &sky.weather) {
        (Some(w), _) => w.clone(),
        (None, Some(w)) => dir.join(w),
        (None, None) => bail!(
            "{}: no weather file: give --weather FILE.epw, or a Weather light in the scene",
            scene_path.display()
        ),
    };
    let weather = Weather::read(&weather_path).map_err(|e| anyhow!(e))?;
    if scene.grids.is_empty() {
        bail!(
            "{}: annual daylight is computed on the scene's grids, and it has none",
            scene_path.display()
        );
    }
    check_settings(settings)?;
    let patches = SkyPatches::new(settings.mf).map_err(|e| anyhow!(e))?;
    let year = hourly_skies(&weather, &patches, sky.ground_reflectance)
        .map_err(|e| anyhow!("{}: {e}", weather_path.display()))?;
    let sunny = (0..year.len()).filter(|&h| year[h].has_sun()).collect();
    Ok(Input {
        scene,
        sky,
        electric,
        dir,
        weather_path,
        weather,
        patches,
        year,
        sunny,
    })
}

/// The sky subdivision and the occupied hours, checked.
fn check_settings(settings: &AnnualSettings) -> Result<()> {
    if !(1..=8).contains(&settings.mf) {
        return Err(crate::job::invalid_option(format!(
            "--mf {} must be 1 to 8",
            settings.mf
        )));
    }
    if settings.occupied.0 >= settings.occupied.1 || settings.occupied.1 > 24 {
        return Err(crate::job::invalid_option(format!(
            "occupied hours {}–{} must be a range within 0–24",
            settings.occupied.0, settings.occupied.1
        )));
    }
    Ok(())
}

/// The scene's geometry lit by the unit sky alone (with the scene's sky spectrum and
/// portals), and the sky's site frame.
fn unit_sky_world(
    scene: &mut SceneFile,
    sky: &SceneSky,
    scene_path: &Path,
    seed: Option<u64>,
) -> Result<(World, SiteFrame)> {
    scene.lights = vec![LightDesc::Sky {
        model: SkyModelDesc::Uniform,
        sun: None,
        amount: Some(Amount::ZenithLuminance(1.0)),
        spectrum: sky.spectrum.clone(),
        ground_reflectance: Some(1.0),
        portals: sky.portals.clone(),
        sun_disk: None,
    }];
    scene.meters.clear();
    let overrides = Overrides {
        seed,
        ..Default::default()
    };
    let world = crate::scene::build::build(scene, scene_path, &overrides)?;
    let frame = match world.lights.as_slice() {
        [Light::Sky(s)] => s.frame,
        _ => bail!("internal error: the unit-sky world has no sky"),
    };
    Ok((world, frame))
}

/// The points of the world's grids, grid after grid, each grid's row after row.
fn receivers(world: &World) -> Receivers {
    let mut grids = Vec::new();
    let mut points = Vec::new();
    let mut ranges = Vec::new();
    for g in &world.grids {
        let start = points.len();
        let mut layout = Vec::with_capacity(g.nx as usize * g.ny as usize);
        for j in 0..g.ny {
            for i in 0..g.nx {
                layout.push(g.point(i, j));
                points.push((g.point(i, j), g.normal));
            }
        }
        ranges.push(start..points.len());
        grids.push(GridLayout {
            name: g.name.clone(),
            nx: g.nx,
            ny: g.ny,
            points: layout,
            normal: g.normal,
            size_m: (g.edge_u.length() as f64, g.edge_v.length() as f64),
        });
    }
    Receivers {
        grids,
        points,
        ranges,
    }
}

/// The camera of the view's hourly images, with the view's settings (checked), when a view
/// is asked for.
fn view_camera_of(
    world: &World,
    settings: &AnnualSettings,
) -> Result<Option<(Camera, ViewSettings)>> {
    let Some(v) = settings.view else {
        return Ok(None);
    };
    // Checked before the camera is sized from it (a huge value would overflow its pixel count).
    if !(8..=1024).contains(&v.resolution) {
        return Err(crate::job::invalid_option(format!(
            "--view-resolution {} must be 8 to 1024",
            v.resolution
        )));
    }
    Ok(Some((view_camera(&world.camera, v.resolution), v)))
}

/// Checks, before the computation, that its coefficients and hourly values fit in memory
/// and that the output's directory has room for the files.
fn check_resources(
    scene_path: &Path,
    settings: &AnnualSettings,
    input: &Input,
    receivers: &Receivers,
    view: Option<&(Camera, ViewSettings)>,
) -> Result<()> {
    let (patches, year, sunny) = (&input.patches, &input.year, &input.sunny);
    let daylight_n = year.iter().filter(|h| h.is_daylight()).count();
    let n_p = patches.len() as u64;
    let n_r = receivers.points.len();
    let view_need = match view {
        // Nodes are at most one per sunny hour.
        Some((c, _)) => {
            view_bytes(c.width * c.height, patches.len(), sunny.len(), sunny.len())
                + year.len() as u64 * 160
        }
        None => 0,
    };
    let need = n_r as u64 * n_p * crate::meter::BATCHES as u64 * 8
        + sun_coefficient_bytes(sunny.len(), n_r)
        + hourly_bytes(year.len(), daylight_n, n_r)
        + view_need;
    crate::limits::check_memory(
        need,
        "the annual calculation's coefficients and hourly illuminances",
    )
    .map_err(|m| anyhow!("{}: {m}", scene_path.display()))?;
    if let Some(stem) = &settings.out {
        super::room::check_room(
            stem,
            &super::room::Planned {
                points: n_r,
                hours: year.len(),
                sunny_hours: sunny.len(),
                patches: patches.len(),
                grids: receivers.grids.len(),
                glare: settings.view.is_some(),
                coefficients: settings.keep_coefficients,
            },
        )?;
    }
    Ok(())
}

/// The grid points' sky coefficients.
fn grid_sky(
    world: &World,
    receivers: &Receivers,
    patches: &SkyPatches,
    settings: &AnnualSettings,
    progress: &mut dyn FnMut(Stage, usize, usize),
) -> Result<Coefficients> {
    progress(Stage::Sky, 0, 1);
    let sky_c = sky_coefficients(world, &receivers.points, patches, settings.sky_samples)?;
    progress(Stage::Sky, 1, 1);
    Ok(sky_c)
}

/// The view's sky coefficients, when there is a view.
fn view_sky(
    world: &World,
    view: Option<(Camera, ViewSettings)>,
    patches: &SkyPatches,
    progress: &mut dyn FnMut(Stage, usize, usize),
) -> Result<Option<ViewSky>> {
    let Some((camera, settings)) = view else {
        return Ok(None);
    };
    progress(Stage::View, 0, 1);
    let matrix = view_coefficients(world, &camera, patches, &settings)?;
    Ok(Some(ViewSky {
        camera,
        settings,
        matrix,
    }))
}

/// The unit-sky world relit by a sun of 1 lx normal illuminance, and the year's suns.
fn sun_hours(world: World, frame: SiteFrame, scene_path: &Path, input: &Input) -> Result<SunHours> {
    let ctx = crate::description::context::Context {
        path: scene_path,
        dir: input.dir.clone(),
        sources: Default::default(),
    };
    let desc = SunDesc {
        altitude_deg: Some(45.0),
        azimuth_deg: Some(180.0),
        ..Default::default()
    };
    let (sun_light, _) = crate::light::SunLight::build(
        &ctx,
        "annual sun",
        &desc,
        Amount::NormalIlluminance(1.0),
        None,
        &frame,
    )?;
    let world = world.relit(vec![Light::Sun(sun_light)]);
    let to_sun = input
        .sunny
        .iter()
        .map(|&h| input.year[h].to_sun_enu)
        .collect();
    Ok(SunHours {
        world,
        frame,
        latitude_deg: input.weather.site.latitude_deg,
        to_sun,
    })
}

/// The grid points' sun coefficients: inter-reflected at the sun grid's nodes, direct for
/// each sunny hour.
fn grid_sun(
    sun: &mut SunHours,
    receivers: &Receivers,
    settings: &AnnualSettings,
    progress: &mut dyn FnMut(Stage, usize, usize),
) -> Result<SunCoefficients> {
    progress(Stage::Sun, 0, 1);
    let sun_c = sun_coefficients(
        &mut sun.world,
        &receivers.points,
        &sun.to_sun,
        &sun.frame,
        sun.latitude_deg,
        settings.sun_samples,
        settings.direct_samples,
        &mut |d, n| progress(Stage::Sun, d, n),
    )?;
    Ok(sun_c)
}

/// The year's hourly illuminances and each grid's metrics, with their replicate years.
fn year_metrics(
    sky_c: &Coefficients,
    sun_c: &SunCoefficients,
    input: &Input,
    receivers: &Receivers,
    settings: &AnnualSettings,
    seed: u64,
    progress: &mut dyn FnMut(Stage, usize, usize),
) -> YearMetrics {
    progress(Stage::Metrics, 0, 1);
    let year = &input.year;
    let days = year.len() / 24;
    let occupied = Schedule::daily(days, settings.occupied.0, settings.occupied.1);
    let daylight = Schedule {
        hours: (0..year.len())
            .filter(|&h| year[h].sun_altitude_deg > 0.0)
            .collect(),
    };
    let hourly = hourly(sky_c, sun_c, year);
    let results = metrics(
        &hourly,
        &receivers.ranges,
        &occupied,
        &daylight,
        &settings.thresholds,
        settings.draws,
        seed,
    );
    progress(Stage::Metrics, 1, 1);
    YearMetrics {
        occupied,
        daylight,
        hourly,
        results,
        seed,
    }
}

/// The view's sun coefficients, then the glare of its occupied daylight hours and the glare
/// metrics. `since`: the seconds of the view's sky coefficients, and when this step starts.
fn view_glare(
    view: ViewSky,
    sun: &mut SunHours,
    input: &Input,
    m: &YearMetrics,
    settings: &AnnualSettings,
    since: (f64, Instant),
    progress: &mut dyn FnMut(Stage, usize, usize),
) -> ViewRun {
    let (view_sky_s, t3) = since;
    let ViewSky {
        camera,
        settings: v,
        matrix: mut vm,
    } = view;
    vm.add_sun(
        &mut sun.world,
        &camera,
        &sun.frame,
        &sun.to_sun,
        sun.latitude_deg,
        &v,
        &mut |d, n| progress(Stage::View, 1 + d, n + 2),
    );
    let t4 = Instant::now();
    let year = &input.year;
    let mut sun_index = vec![usize::MAX; year.len()];
    for (i, &h) in input.sunny.iter().enumerate() {
        sun_index[h] = i;
    }
    let hours = vm.glare(year, &m.occupied.hours, &sun_index, &settings.glare);
    let result = view_metrics(&hours, &m.occupied, &settings.glare, settings.draws, m.seed);
    progress(Stage::View, 1, 1);
    ViewRun {
        width: camera.width,
        height: camera.height,
        projection: crate::camera::describe(camera.projection()),
        sky_samples: vm.sky_samples,
        sun_samples: vm.sun_samples,
        hours,
        result,
        seconds: (
            view_sky_s + (t4 - t3).as_secs_f64(),
            t4.elapsed().as_secs_f64(),
        ),
    }
}

/// Notes on what the annual results leave out.
fn notes(electric: usize) -> Vec<String> {
    let mut notes = Vec::new();
    if electric > 0 {
        notes.push(format!(
            "{electric} electric light(s) of the scene are left out: annual results are daylight alone"
        ));
    }
    notes
}
