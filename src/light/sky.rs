//! The sky: light from every direction above the horizon with a CIE or Perez luminance
//! distribution ([`crate::daylight`]), and below it a ground of reflectance ρ_g whose
//! luminance is ρ_g E_h / π, E_h the horizontal illuminance from the sky and the sun (the CIE
//! 171 assumption). Scene geometry in the way hides the ground, as it hides the sky.
//!
//! The site's frame places it: `up` and `north` (east = north × up). The luminance is
//! L(ω) = k · r(ω) with r the distribution's relative luminance and k set by the amount:
//! `HorizontalIlluminance(lx)` of the unobstructed sky, k = E_h / ∫ r cos Z dω, or
//! `ZenithLuminance(cd/m²)`, k = L_z / r(zenith). Its spectrum is the same in every
//! direction. Light sampling draws directions in proportion to the tabulated luminance
//! ([`SkyMap`]), or through the scene's portals when it has them.

use super::portal::Portals;
use super::sun::{SunLight, SunPlacement};
use super::{LightFlags, LightSample};
use crate::daylight::perez::{SkyCondition, DEFAULT_DEW_POINT_C};
use crate::daylight::{horizontal_integral, CieSky, PerezSky, SkyMap};
use crate::description::context::{Context, SceneError};
use crate::description::schema::{Amount, SkyModelDesc, SpectrumDesc};
use crate::photometry::luminous_integral;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::{DVec3, Vec2, Vec3};

/// The site's frame: which way is up and where north is, in scene coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SiteFrame {
    pub up: DVec3,
    pub north: DVec3,
    pub east: DVec3,
}

impl SiteFrame {
    /// From unit `up` and a `north` not parallel to it (made perpendicular to `up`); None if
    /// they are parallel.
    pub fn new(up: DVec3, north: DVec3) -> Option<Self> {
        let up = up.try_normalize()?;
        let north = (north - up * north.dot(up)).try_normalize()?;
        Some(Self {
            up,
            north,
            east: north.cross(up),
        })
    }

    /// Scene direction → site frame (x east, y north, z up).
    pub fn to_local(&self, d: DVec3) -> DVec3 {
        DVec3::new(d.dot(self.east), d.dot(self.north), d.dot(self.up))
    }

    pub fn to_world(&self, l: DVec3) -> DVec3 {
        self.east * l.x + self.north * l.y + self.up * l.z
    }

    /// Unit scene direction toward altitude `alt_deg`, azimuth `az_deg` (from north toward
    /// east).
    pub fn direction(&self, alt_deg: f64, az_deg: f64) -> DVec3 {
        let (alt, az) = (alt_deg.to_radians(), az_deg.to_radians());
        self.to_world(DVec3::new(
            alt.cos() * az.sin(),
            alt.cos() * az.cos(),
            alt.sin(),
        ))
    }
}

impl Default for SiteFrame {
    /// +y up, north −z, so east is +x.
    fn default() -> Self {
        Self::new(DVec3::Y, DVec3::NEG_Z).expect("the default frame is valid")
    }
}

/// A sky's relative luminance distribution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SkyDistribution {
    Cie(CieSky),
    Perez(PerezSky),
}

impl SkyDistribution {
    /// Relative luminance of site-frame direction `d` (unit), the sun toward `sun` (unit,
    /// site frame); 0 at and below the horizon.
    pub fn relative(&self, d: DVec3, sun: DVec3) -> f64 {
        let gamma = d.dot(sun).clamp(-1.0, 1.0).acos();
        let sun_zenith = sun.z.clamp(-1.0, 1.0).acos();
        match self {
            Self::Cie(s) => s.relative_luminance(d.z, gamma, sun_zenith),
            Self::Perez(s) => s.relative_luminance(d.z, gamma),
        }
    }

    /// ∫ r cos Z dω over the sky: horizontal illuminance per unit of k.
    pub fn horizontal_integral(&self, sun: DVec3) -> f64 {
        let zs = sun.z.clamp(-1.0, 1.0).acos();
        match self {
            Self::Cie(s) => horizontal_integral(zs, |cz, g| s.relative_luminance(cz, g, zs)),
            Self::Perez(s) => horizontal_integral(zs, |cz, g| s.relative_luminance(cz, g)),
        }
    }
}

#[derive(Clone, Debug)]
pub struct SkyLight {
    pub frame: SiteFrame,
    pub distribution: SkyDistribution,
    /// Toward the sun, site frame (the distribution's reference; no disk is drawn here).
    pub sun: DVec3,
    /// Radiance per unit of relative luminance, W·m⁻²·sr⁻¹·nm⁻¹ (its luminance is k, cd/m²).
    pub radiance: DenseSpectrum,
    /// Radiance of the ground below the horizon, W·m⁻²·sr⁻¹·nm⁻¹.
    pub ground: DenseSpectrum,
    /// Horizontal illuminance of the unobstructed sky alone, lx.
    pub horizontal_illuminance_lx: f64,
    pub ground_reflectance: f64,
    /// None when the sky and ground are black.
    map: Option<SkyMap>,
    pub portals: Portals,
    /// The model as the scene names it (e.g. `CieOvercast`), for reports.
    pub model: String,
}

/// What daylight factors are relative to: the horizontal illuminance of an unobstructed
/// overcast sky.
#[derive(Clone, Debug, PartialEq)]
pub struct DaylightReference {
    /// The sky's model as the scene names it.
    pub sky: String,
    /// Its unobstructed horizontal illuminance, lx.
    pub horizontal_illuminance_lx: f64,
}

/// The daylight-factor reference of a scene lit by an overcast sky alone: its sky is
/// `CieOvercast`, `Uniform` or a general sky that does not depend on the sun (1, 3, 5), and it
/// has no sun and no other light. None otherwise (a daylight factor is defined
/// only under such a sky).
pub fn daylight_reference(lights: &[super::Light]) -> Option<DaylightReference> {
    let [super::Light::Sky(sky)] = lights else {
        return None;
    };
    let overcast = match sky.distribution {
        SkyDistribution::Cie(c) => !c.needs_sun(),
        SkyDistribution::Perez(_) => false,
    };
    (overcast && sky.horizontal_illuminance_lx > 0.0).then(|| DaylightReference {
        sky: sky.model.clone(),
        horizontal_illuminance_lx: sky.horizontal_illuminance_lx,
    })
}

impl SkyLight {
    pub const FLAGS: LightFlags = LightFlags::INFINITE;

    /// A sky of `distribution` scaled so that its relative luminance 1 has radiance
    /// `radiance` (luminance k = `horizontal_illuminance_lx` / ∫ r cos Z dω), over a ground
    /// of radiance `ground`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        frame: SiteFrame,
        distribution: SkyDistribution,
        sun: DVec3,
        radiance: DenseSpectrum,
        ground: DenseSpectrum,
        horizontal_illuminance_lx: f64,
        ground_reflectance: f64,
        portals: Portals,
    ) -> Self {
        let k = luminous_integral(&radiance);
        let g = luminous_integral(&ground);
        let map = SkyMap::new(|d| {
            if d.z > 0.0 {
                k * distribution.relative(d, sun)
            } else {
                g
            }
        });
        Self {
            frame,
            distribution,
            sun,
            radiance,
            ground,
            horizontal_illuminance_lx,
            ground_reflectance,
            map,
            portals,
            model: String::new(),
        }
    }

    /// Whether every direction, sky and ground, has a luminance of 1 cd/m² (the sky of
    /// daylight coefficients, [`crate::annual::coefficients`]).
    pub fn is_unit(&self) -> bool {
        let near_one = |x: f64| (x - 1.0).abs() < 1e-6;
        self.distribution == SkyDistribution::Cie(CieSky::Uniform)
            && near_one(luminous_integral(&self.radiance))
            && near_one(luminous_integral(&self.ground))
    }

    /// Radiance arriving along unit scene direction `wi` (sky above the horizon, ground below).
    pub fn escaped(&self, wi: Vec3, wl: &SampledWavelengths) -> SampledSpectrum {
        let d = self.frame.to_local(wi.as_dvec3());
        if d.z > 0.0 {
            let r = self.distribution.relative(d, self.sun);
            self.radiance.sample(wl) * r as f32
        } else {
            self.ground.sample(wl)
        }
    }

    /// A direction from `p`: in proportion to the tabulated luminance, or through the
    /// portals.
    pub fn sample_li(
        &self,
        p: Vec3,
        uc: f32,
        u: Vec2,
        wl: &SampledWavelengths,
    ) -> Option<LightSample> {
        let (wi, pdf) = if self.portals.is_empty() {
            let (d, pdf) = self.map.as_ref()?.sample(u.x as f64, u.y as f64);
            (self.frame.to_world(d).normalize().as_vec3(), pdf as f32)
        } else {
            self.portals.sample(p, uc, u)?
        };
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        Some(LightSample {
            wi,
            li: self.escaped(wi, wl),
            pdf,
            dist: f32::INFINITY,
            point: None,
            delta: false,
        })
    }

    /// Density (solid angle) with which [`SkyLight::sample_li`] at `p` picks `wi`.
    pub fn pdf_li(&self, p: Vec3, wi: Vec3) -> f32 {
        if self.portals.is_empty() {
            self.map
                .as_ref()
                .map_or(0.0, |m| m.pdf(self.frame.to_local(wi.as_dvec3())) as f32)
        } else {
            self.portals.pdf(p, wi)
        }
    }

    /// Spectral horizontal irradiance of the unobstructed sky, W·m⁻²·nm⁻¹.
    pub fn horizontal_irradiance(&self) -> DenseSpectrum {
        let i = self.distribution.horizontal_integral(self.sun);
        self.radiance.scaled(i as f32)
    }

    /// Power proxy (lm): the flux of sky and ground through the scene's bounding disk,
    /// (E_h + π L_ground) π r².
    pub fn power_lm(&self, scene_radius: f32) -> f64 {
        let r2 = (scene_radius as f64).powi(2);
        let pi = std::f64::consts::PI;
        (self.horizontal_illuminance_lx + pi * luminous_integral(&self.ground)) * pi * r2
    }
}

/// The sky's fields (see `LightDesc::Sky`).
pub struct SkyDesc<'a> {
    pub model: &'a crate::description::schema::SkyModelDesc,
    pub sun: Option<&'a crate::description::schema::SunDesc>,
    pub amount: Option<crate::description::schema::Amount>,
    pub spectrum: Option<&'a crate::description::schema::SpectrumDesc>,
    pub ground_reflectance: Option<f64>,
    pub portals: &'a [crate::description::schema::PortalDesc],
    pub sun_disk: Option<bool>,
}

/// The default ground reflectance (CIE 171's and Radiance's).
pub const DEFAULT_GROUND_REFLECTANCE: f64 = 0.2;
/// The default sky spectrum: CIE daylight at 6504 K (D65).
pub const DEFAULT_SKY_CCT_K: f64 = 6504.0;

impl SkyLight {
    /// From `lights[i]` (`field`) in the site's `frame`; `suns_horizontal` is the spectral
    /// horizontal irradiance (W·m⁻²·nm⁻¹) of the scene's `Sun` lights, which the ground
    /// reflects. A Perez sky also returns its sun's disk (unless `sun_disk: false`).
    pub fn build(
        ctx: &Context,
        field: &str,
        d: &SkyDesc,
        frame: &SiteFrame,
        suns_horizontal: &DenseSpectrum,
    ) -> Result<(Self, Option<SunLight>), SceneError> {
        let afield = format!("{field}.amount");
        let sun_place = match d.sun {
            Some(s) => Some(locate_sun(ctx, &format!("{field}.sun"), s)?),
            None => None,
        };
        let (distribution, sky_lx, perez_sun) = match d.model {
            SkyModelDesc::Perez {
                direct_normal_lx: direct,
                diffuse_horizontal_lx: diffuse,
                dew_point_c,
            }
            | SkyModelDesc::PerezIrradiance {
                direct_normal_w_m2: direct,
                diffuse_horizontal_w_m2: diffuse,
                dew_point_c,
            } => {
                let given = (*direct, *diffuse, *dew_point_c);
                perez_sky(ctx, field, d, frame, sun_place, given)?
            }
            m => (cie_sky(ctx, field, m, sun_place)?, None, None),
        };
        let sun = reference_sun(sun_place.map(|p| p.1), &distribution);
        let integral = distribution.horizontal_integral(sun);
        let k = luminance_scale(ctx, &afield, d.amount, sky_lx, &distribution, sun, integral)?;
        let sfield = format!("{field}.spectrum");
        let daylight = SpectrumDesc::Daylight(DEFAULT_SKY_CCT_K);
        let radiance = ctx.emission(&sfield, &afield, d.spectrum.unwrap_or(&daylight), k)?;
        let rho = ground_reflectance(ctx, field, d.ground_reflectance)?;
        let lit_by = (suns_horizontal, perez_sun.as_ref());
        let ground = ground_radiance(&radiance, integral, lit_by, frame, rho);
        let portals = super::environment::build_portals(ctx, field, d.portals)?;
        let mut sky = Self::new(
            *frame,
            distribution,
            sun,
            radiance,
            ground,
            k * integral,
            rho,
            portals,
        );
        sky.model = model_name(d.model);
        Ok((sky, perez_sun))
    }
}

/// The sun's placement and its direction (site frame), when the sky has a sun.
type SunPlace = Option<(SunPlacement, DVec3)>;

/// Where the sun of `SkyDesc::sun` (`field.sun`) is: its placement and its direction in the
/// site frame.
fn locate_sun(
    ctx: &Context,
    sun_field: &str,
    s: &crate::description::schema::SunDesc,
) -> Result<(SunPlacement, DVec3), SceneError> {
    let p = super::sun::place_sun(ctx, sun_field, s)?;
    let (alt, az) = (p.altitude_deg.to_radians(), p.azimuth_deg.to_radians());
    let local = DVec3::new(alt.cos() * az.sin(), alt.cos() * az.cos(), alt.sin());
    Ok((p, local))
}

/// The error of a sky (`what`) that depends on the sun given without one.
fn need_sun(ctx: &Context, field: &str, what: &str) -> SceneError {
    ctx.err(
        format!("{field}.sun"),
        format!("{what} depends on where the sun is: give `sun: (altitude_deg: …, azimuth_deg: …)` or a place and time"),
    )
}

/// A Perez sky from its direct-normal and diffuse-horizontal amounts and dew point
/// (`given`, by illuminance in lx as `gendaylit -L`, or by irradiance in W/m² as
/// `gendaylit -W`): its distribution, its diffuse horizontal illuminance (lx) and its sun's
/// disk (with direct light, unless `sun_disk: false`).
fn perez_sky(
    ctx: &Context,
    field: &str,
    d: &SkyDesc,
    frame: &SiteFrame,
    sun_place: SunPlace,
    given: (f64, f64, Option<f64>),
) -> Result<(SkyDistribution, Option<f64>, Option<SunLight>), SceneError> {
    let mfield = format!("{field}.model");
    let afield = format!("{field}.amount");
    let (direct, diffuse, dew_point_c) = given;
    let by_irradiance = matches!(d.model, SkyModelDesc::PerezIrradiance { .. });
    let (dfield, hfield) = if by_irradiance {
        ("direct_normal_w_m2", "diffuse_horizontal_w_m2")
    } else {
        ("direct_normal_lx", "diffuse_horizontal_lx")
    };
    let direct = ctx.nonneg(&format!("{mfield}.{dfield}"), direct)?;
    let diffuse = ctx.nonneg(&format!("{mfield}.{hfield}"), diffuse)?;
    let dew = match dew_point_c {
        Some(t) => ctx.finite(&format!("{mfield}.dew_point_c"), t)?,
        None => DEFAULT_DEW_POINT_C,
    };
    let Some((p, s)) = sun_place else {
        return Err(need_sun(ctx, field, "the Perez sky"));
    };
    if d.amount.is_some() {
        return Err(ctx.err(
            &afield,
            format!("a Perez sky's amount is its {hfield}; remove `amount`"),
        ));
    }
    // A sun below the horizon (its direct light then absent) shapes the sky from the
    // horizon, as in gendaymtx and `candela annual`.
    let zenith = s.z.clamp(-1.0, 1.0).acos().min(std::f64::consts::FRAC_PI_2);
    let (cond, dn, dh) = if by_irradiance {
        SkyCondition::illuminance_from_irradiance(diffuse, direct, zenith, p.eccentricity, dew)
    } else {
        SkyCondition::from_illuminance(diffuse, direct, zenith, p.eccentricity, dew)
            .map(|(cond, _)| (cond, direct, diffuse))
    }
    .map_err(|e| ctx.err(&mfield, e.to_string()))?;

    let mut perez_sun = None;
    if dn > 0.0 && d.sun_disk.unwrap_or(true) {
        let d50 = SpectrumDesc::Named("D50".into());
        let radiance = ctx.emission(
            &format!("{field}.sun"),
            &format!("{mfield}.{dfield}"),
            &d50,
            SunLight::luminance_for(dn),
        )?;
        perez_sun = Some(SunLight::new(frame.to_world(s).as_vec3(), radiance, dn));
    }
    Ok((
        SkyDistribution::Perez(PerezSky::new(cond)),
        Some(dh),
        perez_sun,
    ))
}

/// The CIE distribution of `model` (not a Perez sky), checked to have the sun above the
/// horizon when it depends on it.
fn cie_sky(
    ctx: &Context,
    field: &str,
    model: &SkyModelDesc,
    sun_place: SunPlace,
) -> Result<SkyDistribution, SceneError> {
    let mfield = format!("{field}.model");
    let cie = match model {
        SkyModelDesc::CieGeneral(k) => CieSky::general(*k).ok_or_else(|| {
            ctx.err(
                &mfield,
                format!("CIE general sky {k}: the standard defines types 1 to 15"),
            )
        })?,
        SkyModelDesc::CieOvercast => CieSky::Overcast,
        SkyModelDesc::Uniform => CieSky::Uniform,
        SkyModelDesc::CieClear => CieSky::Clear,
        SkyModelDesc::Perez { .. } | SkyModelDesc::PerezIrradiance { .. } => {
            unreachable!("handled by perez_sky")
        }
    };
    if cie.needs_sun() {
        match sun_place {
            None => return Err(need_sun(ctx, field, "this sky")),
            Some((p, _)) if p.altitude_deg < 0.0 => {
                return Err(ctx.err(
                    format!("{field}.sun"),
                    format!(
                        "the sun is {:.2}° below the horizon: the CIE skies that depend on it are defined for a sun above it",
                        -p.altitude_deg
                    ),
                ))
            }
            _ => {}
        }
    }
    Ok(SkyDistribution::Cie(cie))
}

/// The direction toward the sun (site frame) the distribution is drawn for. It only shapes
/// sun-dependent skies; any will do for the others.
fn reference_sun(sun_local: Option<DVec3>, distribution: &SkyDistribution) -> DVec3 {
    match (sun_local, distribution) {
        (Some(s), SkyDistribution::Perez(_)) if s.z < 0.0 => DVec3::new(s.x, s.y, 0.0)
            .try_normalize()
            .unwrap_or(DVec3::X),
        (Some(s), _) => s,
        (None, _) => DVec3::Z,
    }
}

/// k, the luminance (cd/m²) of relative luminance 1: from the sky's own horizontal
/// illuminance `sky_lx` (a Perez sky) or from its `amount` (`afield`); `integral` is
/// ∫ r cos Z dω of `distribution` with the sun toward `sun`.
fn luminance_scale(
    ctx: &Context,
    afield: &str,
    amount: Option<Amount>,
    sky_lx: Option<f64>,
    distribution: &SkyDistribution,
    sun: DVec3,
    integral: f64,
) -> Result<f64, SceneError> {
    Ok(match (amount, sky_lx) {
        (None, Some(lx)) => lx / integral,
        (Some(Amount::HorizontalIlluminance(e)), None) => ctx.nonneg(afield, e)? / integral,
        (Some(Amount::ZenithLuminance(l)), None) => {
            ctx.nonneg(afield, l)? / distribution.relative(DVec3::Z, sun)
        }
        (Some(a), _) => {
            return Err(super::wrong_amount(
                ctx,
                afield,
                &a,
                "HorizontalIlluminance(lx) or ZenithLuminance(cd/m²)",
            ))
        }
        (None, None) => {
            return Err(ctx.err(
                afield,
                "missing: give HorizontalIlluminance(lx) or ZenithLuminance(cd/m²)",
            ))
        }
    })
}

/// The ground's reflectance (`field.ground_reflectance`), checked to be within 0–1.
fn ground_reflectance(ctx: &Context, field: &str, given: Option<f64>) -> Result<f64, SceneError> {
    match given {
        Some(r) => {
            let gfield = format!("{field}.ground_reflectance");
            let r = ctx.nonneg(&gfield, r)?;
            if r > 1.0 {
                return Err(ctx.err(gfield, format!("{r} is more than 1")));
            }
            Ok(r)
        }
        None => Ok(DEFAULT_GROUND_REFLECTANCE),
    }
}

/// The ground's radiance (W·m⁻²·sr⁻¹·nm⁻¹): it reflects the sky's horizontal irradiance
/// (`radiance` × `integral`) and the suns' (`lit_by`: the scene's `Sun` lights' and the
/// Perez sky's disk), L = ρ E_h / π.
fn ground_radiance(
    radiance: &DenseSpectrum,
    integral: f64,
    lit_by: (&DenseSpectrum, Option<&SunLight>),
    frame: &SiteFrame,
    rho: f64,
) -> DenseSpectrum {
    let (suns_horizontal, perez_sun) = lit_by;
    let mut e_h = radiance.scaled(integral as f32);
    let mut add = |s: &DenseSpectrum| {
        for (a, b) in e_h.values.iter_mut().zip(s.values.iter()) {
            *a += *b;
        }
    };
    add(suns_horizontal);
    if let Some(s) = perez_sun {
        add(&s.horizontal_irradiance(frame));
    }
    e_h.scaled((rho / std::f64::consts::PI) as f32)
}

/// The model as the scene names it, for reports.
fn model_name(model: &SkyModelDesc) -> String {
    match model {
        SkyModelDesc::CieGeneral(k) => format!("CieGeneral({k})"),
        SkyModelDesc::CieOvercast => "CieOvercast".into(),
        SkyModelDesc::Uniform => "Uniform".into(),
        SkyModelDesc::CieClear => "CieClear".into(),
        SkyModelDesc::Perez { .. } | SkyModelDesc::PerezIrradiance { .. } => "Perez".into(),
    }
}

/// The sky model and sun of `Weather(file, time)` (`field` is `lights[i]`): the record of
/// `file` covering `time` ("MM-DD hh:mm", the file's local standard time; record hour h covers
/// (h − 1):00 to h:00), read by the rule `candela annual` follows too
/// ([`crate::daylight::weather`]): a Perez sky from the record's irradiances and dew point, the
/// sun placed by the file's site at `time`.
pub fn weather_sky(
    ctx: &crate::description::context::Context,
    field: &str,
    file: &str,
    time: &str,
) -> Result<
    (
        crate::description::schema::SkyModelDesc,
        crate::description::schema::SunDesc,
    ),
    crate::description::context::SceneError,
> {
    use crate::daylight::epw::Weather;
    use crate::daylight::weather::weather_hour;
    use crate::description::schema::{SkyModelDesc, SunDesc};
    let tfield = format!("{field}.time");
    let bad_time = || {
        ctx.err(
            &tfield,
            format!("{time:?} is not \"MM-DD hh:mm\" (e.g. \"06-21 10:30\")"),
        )
    };
    let (date, clock) = time.trim().split_once(' ').ok_or_else(bad_time)?;
    let (mo, da) = date.split_once('-').ok_or_else(bad_time)?;
    let (hh, mm) = clock.split_once(':').ok_or_else(bad_time)?;
    let num = |t: &str, max: u32| -> Result<u32, crate::description::context::SceneError> {
        t.parse::<u32>()
            .ok()
            .filter(|v| *v <= max && t.len() <= 2)
            .ok_or_else(bad_time)
    };
    let (month, day, hour, minute) = (num(mo, 12)?, num(da, 31)?, num(hh, 23)?, num(mm, 59)?);
    let path = ctx.resolve(file);
    let w = Weather::read(&path).map_err(|m| ctx.err(format!("{field}.file"), m))?;
    let r = w.at(month, day, hour, minute).ok_or_else(|| {
        ctx.err(
            &tfield,
            format!("{} has no record for {time}", path.display()),
        )
    })?;
    let line = format!(
        "{}: line {} (record {month:02}-{day:02} hour {})",
        path.display(),
        r.line,
        r.hour
    );
    // The offset is written to the minute in the sun's time, so the hour is read with that
    // same offset.
    let offset_min = (w.site.time_zone_h * 60.0).round() as i64;
    let site = crate::daylight::epw::Site {
        time_zone_h: offset_min as f64 / 60.0,
        ..w.site.clone()
    };
    let wh = weather_hour(&site, r, (hour * 3600 + minute * 60) as f64)
        .map_err(|e| ctx.err(&tfield, format!("{line}: {e}")))?;
    if wh.is_dark() {
        return Err(ctx.err(
            &tfield,
            format!("{line}: no daylight at that time (no diffuse light, and no direct light with the sun up)"),
        ));
    }
    let sign = if offset_min < 0 { '-' } else { '+' };
    let iso = format!(
        "{:04}-{month:02}-{day:02}T{hour:02}:{minute:02}:00{sign}{:02}:{:02}",
        wh.time.year,
        offset_min.abs() / 60,
        offset_min.abs() % 60
    );
    let sun = SunDesc {
        latitude_deg: Some(site.latitude_deg),
        longitude_deg: Some(site.longitude_deg),
        elevation_m: Some(site.elevation_m),
        time: Some(iso),
        ..Default::default()
    };
    Ok((
        SkyModelDesc::PerezIrradiance {
            direct_normal_w_m2: wh.direct_normal_w_m2,
            diffuse_horizontal_w_m2: wh.diffuse_horizontal_w_m2,
            dew_point_c: Some(wh.dew_point_c),
        },
        sun,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::daylight::perez::SkyCondition;

    /// χ² of the directions `sample_li` draws against its `pdf_li` integrated over 24 × 48
    /// cells of the sphere (equal in cos Z and azimuth of the scene frame), for a clear CIE
    /// sky and a Perez sky in a tilted site frame, ground included.
    #[test]
    fn sampling_matches_pdf_chi2() {
        let frame = SiteFrame::new(DVec3::new(0.2, 0.9, 0.3), DVec3::new(0.0, 0.1, -1.0)).unwrap();
        let sun = DVec3::new(0.4, -0.5, 0.77).normalize();
        let perez = SkyCondition::from_irradiance(120.0, 600.0, sun.z.acos(), 1.0).unwrap();
        for dist in [
            SkyDistribution::Cie(CieSky::general(13).unwrap()),
            SkyDistribution::Perez(PerezSky::new(perez)),
        ] {
            let sky = SkyLight::new(
                frame,
                dist,
                sun,
                DenseSpectrum::constant(1.0),
                DenseSpectrum::constant(0.05),
                1.0,
                0.2,
                Portals::new(Vec::new()),
            );
            let wl = SampledWavelengths::sample_uniform(0.5);
            let (nz, nphi) = (24usize, 48usize);
            let cell = |w: Vec3| {
                let w = w.as_dvec3();
                let u = ((1.0 - w.y) * 0.5 * nz as f64).min(nz as f64 - 1.0) as usize;
                let mut phi = w.z.atan2(w.x) / std::f64::consts::TAU;
                if phi < 0.0 {
                    phi += 1.0;
                }
                u * nphi + ((phi * nphi as f64) as usize).min(nphi - 1)
            };
            let n = 200_000usize;
            let mut counts = vec![0f64; nz * nphi];
            let mut state = 99u64;
            let mut rnd = || {
                state = crate::sampling::mix64(state.wrapping_add(0x9E37_79B9_7F4A_7C15));
                ((state >> 40) as f32) / (1u32 << 24) as f32
            };
            for _ in 0..n {
                let ls = sky
                    .sample_li(Vec3::ZERO, rnd(), Vec2::new(rnd(), rnd()), &wl)
                    .unwrap();
                let p = sky.pdf_li(Vec3::ZERO, ls.wi);
                assert!((p / ls.pdf - 1.0).abs() < 1e-3, "pdf {p} vs {}", ls.pdf);
                counts[cell(ls.wi)] += 1.0;
            }
            // Expected: the pdf integrated over each cell by a 12 × 12 midpoint rule.
            let k = 12;
            let mut chi2 = 0.0;
            let mut dof = 0;
            let mut pooled = (0.0, 0.0);
            for (c, &count) in counts.iter().enumerate() {
                let (iu, ip) = (c / nphi, c % nphi);
                let mut p = 0.0;
                for a in 0..k {
                    for b in 0..k {
                        let y = 1.0 - 2.0 * (iu as f64 + (a as f64 + 0.5) / k as f64) / nz as f64;
                        let phi = std::f64::consts::TAU * (ip as f64 + (b as f64 + 0.5) / k as f64)
                            / nphi as f64;
                        let s = (1.0 - y * y).max(0.0).sqrt();
                        let w = Vec3::new((s * phi.cos()) as f32, y as f32, (s * phi.sin()) as f32);
                        p += sky.pdf_li(Vec3::ZERO, w) as f64;
                    }
                }
                let expected =
                    p / (k * k) as f64 * 4.0 * std::f64::consts::PI / (nz * nphi) as f64 * n as f64;
                if expected < 5.0 {
                    pooled.0 += expected;
                    pooled.1 += count;
                    continue;
                }
                chi2 += (count - expected).powi(2) / expected;
                dof += 1;
            }
            if pooled.0 > 0.0 {
                chi2 += (pooled.1 - pooled.0).powi(2) / pooled.0;
                dof += 1;
            }
            // Wilson–Hilferty: χ² with ν dof beyond ν + 4.3 √(2ν) has p < 1e-5.
            let limit = dof as f64 + 4.3 * (2.0 * dof as f64).sqrt();
            assert!(
                chi2 < limit,
                "χ² = {chi2:.1} over {dof} cells (limit {limit:.1})"
            );
        }
    }
}
