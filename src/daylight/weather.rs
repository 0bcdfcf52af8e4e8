//! One hour of a weather file as daylight: the single rule by which `candela annual` and a
//! scene's `Weather` light read a record, so that both see the same sky.
//!
//! - The sky comes from the record's irradiances (fields 15 and 16, W/m²), turned into
//!   illuminances by the Perez et al. (1990) luminous efficacy model at the record's dew point
//!   ([`SkyCondition::illuminance_from_irradiance`]), as Radiance's `gendaymtx` and
//!   `gendaylit -W` do. The file's illuminance fields are not used: many files leave them
//!   missing or zero, and most fill them from the irradiances with this same model.
//! - The sun is where it is at the instant asked for: `annual` asks for the middle of each
//!   record's hour ([`middle_of_hour`]), a `Weather` light for the time it is given.
//! - Direct light counts only while the sun is above the horizon at that instant; in the hour
//!   of sunrise or sunset the record's direct light is dropped when the instant falls with the
//!   sun below it.
//! - A missing dew point (99.9) is taken as [`DEFAULT_DEW_POINT_C`] (2 cm of precipitable
//!   water, gendaylit's default).

use super::epw::{Record, Site};
use super::perez::{eccentricity, PerezError, SkyCondition, DEFAULT_DEW_POINT_C};
use super::sun::{sun_position, Atmosphere, CivilTime, SunPosition};

/// The instant, seconds after local midnight, at the middle of record `r`'s hour.
pub fn middle_of_hour(r: &Record) -> f64 {
    (r.hour as f64 - 0.5) * 3600.0
}

/// What one record gives the sky and the sun at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WeatherHour {
    /// Local standard time of the instant.
    pub time: CivilTime,
    /// The sun at that instant (with refraction).
    pub sun: SunPosition,
    /// Unit vector toward the sun (east, north, up).
    pub to_sun_enu: [f64; 3],
    /// The Earth–Sun distance correction of the day.
    pub eccentricity: f64,
    /// W/m²: the record's diffuse-horizontal irradiance.
    pub diffuse_horizontal_w_m2: f64,
    /// W/m²: the record's direct-normal irradiance, 0 when the sun is at or below the horizon.
    pub direct_normal_w_m2: f64,
    /// °C, the default where the record lacks it.
    pub dew_point_c: f64,
}

impl WeatherHour {
    /// Whether the instant has daylight.
    pub fn is_dark(&self) -> bool {
        self.diffuse_horizontal_w_m2 == 0.0 && self.direct_normal_w_m2 == 0.0
    }

    /// The Perez sky's condition and the direct-normal and diffuse-horizontal illuminances
    /// (lx) for the sun at zenith angle `model_zenith` (radians; the model's sun, which a
    /// caller may keep off the horizon or the zenith): (condition, E_vn, E_vd).
    pub fn illuminance(&self, model_zenith: f64) -> Result<(SkyCondition, f64, f64), PerezError> {
        SkyCondition::illuminance_from_irradiance(
            self.diffuse_horizontal_w_m2,
            self.direct_normal_w_m2,
            model_zenith,
            self.eccentricity,
            self.dew_point_c,
        )
    }
}

/// Record `r` of a file for `site`, at `seconds` after local midnight of its day (standard
/// time), by the rule above.
pub fn weather_hour(site: &Site, r: &Record, seconds: f64) -> Result<WeatherHour, String> {
    let time = CivilTime {
        year: r.year.clamp(1, 9999),
        month: r.month,
        day: r.day,
        seconds,
        offset_s: site.time_zone_h * 3600.0,
    };
    let sun = sun_position(
        site.latitude_deg,
        site.longitude_deg,
        site.elevation_m,
        &time,
        Atmosphere::default(),
        None,
    )?;
    let (alt, az) = (sun.altitude_deg.to_radians(), sun.azimuth_deg.to_radians());
    Ok(WeatherHour {
        time,
        sun,
        to_sun_enu: [alt.cos() * az.sin(), alt.cos() * az.cos(), alt.sin()],
        eccentricity: eccentricity(time.day_of_year() as f64),
        diffuse_horizontal_w_m2: r.diffuse_horizontal_w_m2,
        direct_normal_w_m2: if sun.altitude_deg > 0.0 {
            r.direct_normal_w_m2
        } else {
            0.0
        },
        dew_point_c: r.dew_point_c.unwrap_or(DEFAULT_DEW_POINT_C),
    })
}
