//! The sun: a disk of 0.533° at infinity, of uniform radiance, given by its direct-normal
//! illuminance E_n (lx) and placed by altitude and azimuth or by place and time
//! ([`crate::daylight::sun`]). Not a delta light: penumbrae have their width, and a camera
//! sees the disk's luminance E_n / Ω (about 1.5·10⁹ cd/m² at 100 klx).
//!
//! Its default spectrum is CIE D50 (`Named("D50")`), a daylight phase of 5003 K close to the
//! direct-normal solar spectrum at air mass 1.5.

use super::{LightFlags, LightSample};
use crate::daylight::sun::{sun_solid_angle_sr, SUN_DIAMETER_DEG};
use crate::photometry::luminous_integral;
use crate::sampling::{uniform_cone, uniform_cone_pdf};
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::{DVec3, Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct SunLight {
    /// Unit direction from the scene toward the sun's centre (world frame).
    pub to_sun: Vec3,
    /// 1 − cos of the disk's angular radius.
    one_minus_cos: f64,
    /// Radiance of the disk L_e(λ), W·m⁻²·sr⁻¹·nm⁻¹.
    pub radiance: DenseSpectrum,
    /// Direct-normal illuminance, lx (what the user gave).
    pub normal_illuminance_lx: f64,
}

impl SunLight {
    pub const FLAGS: LightFlags = LightFlags::INFINITE;

    /// A sun toward `to_sun` (unit, world frame) whose disk has radiance `radiance` (already
    /// scaled to luminance E_n / Ω).
    pub fn new(to_sun: Vec3, radiance: DenseSpectrum, normal_illuminance_lx: f64) -> Self {
        let half = (0.5 * SUN_DIAMETER_DEG).to_radians();
        // 1 − cos θ = 2 sin²(θ/2), without cancellation.
        let one_minus_cos = 2.0 * (0.5 * half).sin().powi(2);
        Self {
            to_sun,
            one_minus_cos,
            radiance,
            normal_illuminance_lx,
        }
    }

    /// The disk's luminance (cd/m²) for a normal illuminance of `lux`.
    pub fn luminance_for(lux: f64) -> f64 {
        lux / sun_solid_angle_sr()
    }

    fn frame(&self) -> (DVec3, DVec3, DVec3) {
        let z = self.to_sun.as_dvec3();
        let a = if z.x.abs() > 0.9 { DVec3::Y } else { DVec3::X };
        let x = a.cross(z).normalize();
        (x, z.cross(x), z)
    }

    /// A direction uniform over the disk, with li = L_e.
    pub fn sample_li(&self, u: Vec2, wl: &SampledWavelengths) -> Option<LightSample> {
        let (cos_t, sin_t, phi) = uniform_cone(u.x as f64, u.y as f64, self.one_minus_cos);
        let (x, y, z) = self.frame();
        let wi = (x * (sin_t * phi.cos()) + y * (sin_t * phi.sin()) + z * cos_t)
            .normalize()
            .as_vec3();
        Some(LightSample {
            wi,
            li: self.radiance.sample(wl),
            pdf: uniform_cone_pdf(self.one_minus_cos) as f32,
            dist: f32::INFINITY,
            point: None,
            delta: false,
        })
    }

    /// The disk's solid angle Ω, sr.
    pub fn solid_angle_sr(&self) -> f64 {
        std::f64::consts::TAU * self.one_minus_cos
    }

    /// `n × n` directions (unit, world frame) over the disk, one at the centre of each cell of
    /// an equal-solid-angle n × n grid, so each stands for Ω / n² of it: a deterministic
    /// quadrature of the disk.
    pub fn disk_directions(&self, n: usize) -> impl Iterator<Item = DVec3> + '_ {
        let (x, y, z) = self.frame();
        (0..n * n).map(move |k| {
            let (i, j) = (k / n, k % n);
            let u = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
            let (cos_t, sin_t, phi) = uniform_cone(u.0, u.1, self.one_minus_cos);
            (x * (sin_t * phi.cos()) + y * (sin_t * phi.sin()) + z * cos_t).normalize()
        })
    }

    fn inside(&self, wi: Vec3) -> bool {
        1.0 - (wi.as_dvec3().dot(self.to_sun.as_dvec3())) <= self.one_minus_cos
    }

    /// Density (solid angle) of [`SunLight::sample_li`] for unit direction `wi`.
    pub fn pdf_li(&self, wi: Vec3) -> f32 {
        if self.inside(wi) {
            uniform_cone_pdf(self.one_minus_cos) as f32
        } else {
            0.0
        }
    }

    /// Radiance along an escaped ray of direction `wi`: the disk's, or nothing.
    pub fn escaped(&self, wi: Vec3, wl: &SampledWavelengths) -> SampledSpectrum {
        if self.inside(wi) {
            self.radiance.sample(wl)
        } else {
            SampledSpectrum::ZERO
        }
    }

    /// Spectral irradiance on a surface facing the sun, W·m⁻²·nm⁻¹: L_e Ω.
    pub fn normal_irradiance(&self) -> DenseSpectrum {
        self.radiance
            .scaled((std::f64::consts::TAU * self.one_minus_cos) as f32)
    }

    /// Spectral irradiance on a horizontal surface of the site (`frame`), W·m⁻²·nm⁻¹: L_e Ω
    /// sin(altitude), 0 with the sun below the horizon.
    pub fn horizontal_irradiance(&self, frame: &super::SiteFrame) -> DenseSpectrum {
        let sin_alt = self.to_sun.as_dvec3().dot(frame.up).max(0.0);
        self.normal_irradiance().scaled(sin_alt as f32)
    }

    /// Power proxy (lm): the flux through the scene's bounding disk, E_n π r².
    pub fn power_lm(&self, scene_radius: f32) -> f64 {
        let r2 = (scene_radius as f64).powi(2);
        luminous_integral(&self.radiance)
            * std::f64::consts::TAU
            * self.one_minus_cos
            * std::f64::consts::PI
            * r2
    }
}

/// Where a sun is, resolved from its description.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunPlacement {
    pub altitude_deg: f64,
    /// From north toward east.
    pub azimuth_deg: f64,
    /// (R₀/R)² of the date, 1 (the mean Earth–Sun distance) when no date is given.
    pub eccentricity: f64,
}

/// Resolve `lights[i].sun` (`field`): altitude and azimuth, or place and time.
pub fn place_sun(
    ctx: &crate::description::context::Context,
    field: &str,
    d: &crate::description::schema::SunDesc,
) -> Result<SunPlacement, crate::description::context::SceneError> {
    use crate::daylight::sun::{sun_position_at, Atmosphere, CivilTime};
    let by_angles = d.altitude_deg.is_some() || d.azimuth_deg.is_some();
    let by_place = d.latitude_deg.is_some()
        || d.longitude_deg.is_some()
        || d.time.is_some()
        || d.elevation_m.is_some();
    match (by_angles, by_place) {
        (true, false) => {
            let (Some(alt), Some(az)) = (d.altitude_deg, d.azimuth_deg) else {
                return Err(ctx.err(field, "give both altitude_deg and azimuth_deg"));
            };
            let alt = ctx.finite(&format!("{field}.altitude_deg"), alt)?;
            let az = ctx.finite(&format!("{field}.azimuth_deg"), az)?;
            if !(-90.0..=90.0).contains(&alt) {
                return Err(ctx.err(
                    format!("{field}.altitude_deg"),
                    format!("{alt}° is not an altitude (−90° to 90°)"),
                ));
            }
            Ok(SunPlacement {
                altitude_deg: alt,
                azimuth_deg: az.rem_euclid(360.0),
                eccentricity: 1.0,
            })
        }
        (false, true) => {
            let (Some(lat), Some(lon), Some(time)) = (d.latitude_deg, d.longitude_deg, &d.time)
            else {
                return Err(ctx.err(
                    field,
                    "give latitude_deg, longitude_deg and time (or altitude_deg and azimuth_deg)",
                ));
            };
            let t = if d.solar_time {
                CivilTime::parse_solar(time)
            } else {
                CivilTime::parse(time)
            }
            .map_err(|m| ctx.err(format!("{field}.time"), m))?;
            let p = sun_position_at(
                lat,
                lon,
                d.elevation_m.unwrap_or(0.0),
                &t,
                d.solar_time,
                Atmosphere::default(),
                None,
            )
            .map_err(|m| ctx.err(field, m))?;
            Ok(SunPlacement {
                altitude_deg: p.altitude_deg,
                azimuth_deg: p.azimuth_deg,
                eccentricity: crate::daylight::perez::eccentricity(t.day_of_year() as f64),
            })
        }
        (true, true) => Err(ctx.err(
            field,
            "give either altitude_deg and azimuth_deg, or latitude_deg, longitude_deg and time, not both",
        )),
        (false, false) => Err(ctx.err(
            field,
            "give altitude_deg and azimuth_deg, or latitude_deg, longitude_deg and time",
        )),
    }
}

impl SunLight {
    /// From `lights[i]` (`field`): position `sun`, amount `NormalIlluminance(lx)`, spectrum
    /// (default CIE D50), in the site's `frame`. The sun may be below the horizon (it then
    /// lights nothing above a ground, but the scene may be open below).
    pub fn build(
        ctx: &crate::description::context::Context,
        field: &str,
        sun: &crate::description::schema::SunDesc,
        amount: crate::description::schema::Amount,
        spectrum: Option<&crate::description::schema::SpectrumDesc>,
        frame: &super::SiteFrame,
    ) -> Result<(Self, SunPlacement), crate::description::context::SceneError> {
        use crate::description::schema::{Amount, SpectrumDesc};
        let afield = format!("{field}.amount");
        let lux = match amount {
            Amount::NormalIlluminance(e) => ctx.nonneg(&afield, e)?,
            a => {
                return Err(super::wrong_amount(
                    ctx,
                    &afield,
                    &a,
                    "NormalIlluminance(lx)",
                ))
            }
        };
        let place = place_sun(ctx, &format!("{field}.sun"), sun)?;
        let d50 = SpectrumDesc::Named("D50".into());
        let radiance = ctx.emission(
            &format!("{field}.spectrum"),
            &afield,
            spectrum.unwrap_or(&d50),
            Self::luminance_for(lux),
        )?;
        let to_sun = frame
            .direction(place.altitude_deg, place.azimuth_deg)
            .as_vec3();
        Ok((Self::new(to_sun, radiance, lux), place))
    }
}
