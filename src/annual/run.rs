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
    view_bytes, view_camera, view_coefficients, view_metrics, HourGlare, ViewResult, ViewSettings,
};
use super::year::{hourly_skies, HourSky};
use crate::daylight::epw::{Site, Weather};
use crate::daylight::patches::SkyPatches;
use crate::description::schema::{
    Amount, LightDesc, SceneFile, SkyModelDesc, SpectrumDesc, SunDesc,
};
use crate::glare::GlareOptions;
use crate::light::Light;
use crate::scene::build::Overrides;
use anyhow::{anyhow, bail, Result};
use glam::Vec3;
use std::path::{Path, PathBuf};

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

/// Runs the annual calculation of the scene at `scene_path`.
pub fn run(
    scene_path: &Path,
    settings: &AnnualSettings,
    progress: &mut dyn FnMut(Stage, usize, usize),
) -> Result<AnnualRun> {
    let mut scene = crate::scene::load(scene_path)?;
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
    let patches = SkyPatches::new(settings.mf).map_err(|e| anyhow!(e))?;
    let year = hourly_skies(&weather, &patches, sky.ground_reflectance)
        .map_err(|e| anyhow!("{}: {e}", weather_path.display()))?;

    // The geometry lit by the unit sky.
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
        seed: settings.seed,
        ..Default::default()
    };
    let world = crate::scene::build::build(&scene, scene_path, &overrides)?;
    let frame = match world.lights.as_slice() {
        [Light::Sky(s)] => s.frame,
        _ => bail!("internal error: the unit-sky world has no sky"),
    };
    let mut grids = Vec::new();
    let mut receivers = Vec::new();
    let mut ranges = Vec::new();
    for g in &world.grids {
        let start = receivers.len();
        let mut points = Vec::with_capacity(g.nx as usize * g.ny as usize);
        for j in 0..g.ny {
            for i in 0..g.nx {
                points.push(g.point(i, j));
                receivers.push((g.point(i, j), g.normal));
            }
        }
        ranges.push(start..receivers.len());
        grids.push(GridLayout {
            name: g.name.clone(),
            nx: g.nx,
            ny: g.ny,
            points,
            normal: g.normal,
            size_m: (g.edge_u.length() as f64, g.edge_v.length() as f64),
        });
    }
    let sunny: Vec<usize> = (0..year.len()).filter(|&h| year[h].has_sun()).collect();
    let daylight_n = year.iter().filter(|h| h.is_daylight()).count();
    let n_p = patches.len() as u64;
    let view_cam = settings
        .view
        .map(|v| view_camera(&world.camera, v.resolution));
    let view_need = match (&view_cam, &settings.view) {
        (Some(c), Some(v)) => {
            if !(8..=1024).contains(&v.resolution) {
                return Err(crate::job::invalid_option(format!(
                    "--view-resolution {} must be 8 to 1024",
                    v.resolution
                )));
            }
            // Nodes are at most one per sunny hour.
            view_bytes(c.width * c.height, patches.len(), sunny.len(), sunny.len())
                + year.len() as u64 * 160
        }
        _ => 0,
    };
    let need = receivers.len() as u64 * n_p * crate::meter::BATCHES as u64 * 8
        + sun_coefficient_bytes(sunny.len(), receivers.len())
        + hourly_bytes(year.len(), daylight_n, receivers.len())
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
                points: receivers.len(),
                hours: year.len(),
                sunny_hours: sunny.len(),
                patches: patches.len(),
                grids: grids.len(),
                glare: settings.view.is_some(),
                coefficients: settings.keep_coefficients,
            },
        )?;
    }

    let t0 = std::time::Instant::now();
    progress(Stage::Sky, 0, 1);
    let sky_c: Coefficients = sky_coefficients(&world, &receivers, &patches, settings.sky_samples)?;
    progress(Stage::Sky, 1, 1);
    let view_t = std::time::Instant::now();
    let view_m = match (&view_cam, &settings.view) {
        (Some(camera), Some(v)) => {
            progress(Stage::View, 0, 1);
            Some(view_coefficients(&world, camera, &patches, v)?)
        }
        _ => None,
    };
    let view_sky_s = view_t.elapsed().as_secs_f64();
    let t1 = view_t;

    let sun_light = {
        let ctx = crate::description::context::Context {
            path: scene_path,
            dir: dir.clone(),
            sources: Default::default(),
        };
        let desc = SunDesc {
            altitude_deg: Some(45.0),
            azimuth_deg: Some(180.0),
            ..Default::default()
        };
        let (s, _) = crate::light::SunLight::build(
            &ctx,
            "annual sun",
            &desc,
            Amount::NormalIlluminance(1.0),
            None,
            &frame,
        )?;
        s
    };
    let mut sun_world = world.relit(vec![Light::Sun(sun_light)]);
    let to_sun: Vec<[f64; 3]> = sunny.iter().map(|&h| year[h].to_sun_enu).collect();
    let n_sunny = to_sun.len();
    progress(Stage::Sun, 0, 1);
    let sun_c: SunCoefficients = sun_coefficients(
        &mut sun_world,
        &receivers,
        &to_sun,
        &frame,
        weather.site.latitude_deg,
        settings.sun_samples,
        settings.direct_samples,
        &mut |d, n| progress(Stage::Sun, d, n),
    )?;
    let t2 = std::time::Instant::now();

    progress(Stage::Metrics, 0, 1);
    let days = year.len() / 24;
    let occupied = Schedule::daily(days, settings.occupied.0, settings.occupied.1);
    let daylight = Schedule {
        hours: (0..year.len())
            .filter(|&h| year[h].sun_altitude_deg > 0.0)
            .collect(),
    };
    let hourly = hourly(&sky_c, &sun_c, &year);
    let seed = settings.seed.unwrap_or(sun_world.settings.seed);
    let results = metrics(
        &hourly,
        &ranges,
        &occupied,
        &daylight,
        &settings.thresholds,
        settings.draws,
        seed,
    );
    progress(Stage::Metrics, 1, 1);
    let t3 = std::time::Instant::now();

    let view = match (&view_cam, &settings.view, view_m) {
        (Some(camera), Some(v), Some(mut vm)) => {
            vm.add_sun(
                &mut sun_world,
                camera,
                &frame,
                &to_sun,
                weather.site.latitude_deg,
                v,
                &mut |d, n| progress(Stage::View, 1 + d, n + 2),
            );
            let t4 = std::time::Instant::now();
            let mut sun_index = vec![usize::MAX; year.len()];
            for (i, &h) in sunny.iter().enumerate() {
                sun_index[h] = i;
            }
            let hours = vm.glare(&year, &occupied.hours, &sun_index, &settings.glare);
            let result = view_metrics(&hours, &occupied, &settings.glare, settings.draws, seed);
            progress(Stage::View, 1, 1);
            Some(ViewRun {
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
            })
        }
        _ => None,
    };

    let mut notes = Vec::new();
    if electric > 0 {
        notes.push(format!(
            "{electric} electric light(s) of the scene are left out: annual results are daylight alone"
        ));
    }
    Ok(AnnualRun {
        scene: scene_path.to_path_buf(),
        weather: weather_path,
        site: weather.site.clone(),
        settings: AnnualSettings {
            sky_samples: sky_c.samples,
            sun_samples: sun_c.samples,
            direct_samples: sun_c.direct_samples,
            ..settings.clone()
        },
        patches: patches.len(),
        grids,
        results,
        hourly,
        occupied_hours: occupied.hours.len(),
        daylight_hours: daylight.hours.len(),
        sunny_hours: n_sunny,
        sun_nodes: sun_c.nodes,
        year,
        seconds: (
            (t1 - t0).as_secs_f64(),
            (t2 - t1).as_secs_f64() - view_sky_s,
            (t3 - t2).as_secs_f64(),
        ),
        view,
        coefficients: settings.keep_coefficients.then_some((sky_c, sun_c)),
        notes,
    })
}
