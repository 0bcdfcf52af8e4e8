//! A year of skies from a weather file: for each hourly record, the sun's position at the
//! middle of its hour and the Perez sky over the sky patches ([`SkyVector`]), as `gendaymtx`
//! builds them from the file (through `epw2wea`, which also places each record at the middle
//! of its hour), by the rule a `Weather` light follows too ([`crate::daylight::weather`]).

use crate::daylight::epw::Weather;
use crate::daylight::patches::{SkyPatches, SkyVector};
use crate::daylight::weather::{middle_of_hour, weather_hour};

/// One hour of the year.
#[derive(Clone, Debug)]
pub struct HourSky {
    pub month: u32,
    pub day: u32,
    /// The EPW record hour, 1–24: the hour ending at `hour`:00 local standard time.
    pub hour: u32,
    /// The sun at the middle of the hour: altitude (degrees, with refraction) and unit
    /// direction (east, north, up).
    pub sun_altitude_deg: f64,
    pub to_sun_enu: [f64; 3],
    pub sky: SkyVector,
}

impl HourSky {
    /// Whether the hour has daylight (sky or sun).
    pub fn is_daylight(&self) -> bool {
        self.sky.diffuse_horizontal_lx > 0.0 || self.has_sun()
    }

    /// Whether the sun shines directly in this hour.
    pub fn has_sun(&self) -> bool {
        self.sky.direct_normal_lx > 0.0 && self.sun_altitude_deg > 0.0
    }
}

/// The skies of every record of an hourly weather file over `patches`, above a ground of
/// reflectance `ground_reflectance`. The file must hold one whole calendar year (8760
/// consecutive hours from 1 January hour 1 to 31 December hour 24, or 8784 with 29
/// February): the metrics count hours of a year. Each record is read by the rule of
/// [`crate::daylight::weather`], at the middle of its hour.
pub fn hourly_skies(
    weather: &Weather,
    patches: &SkyPatches,
    ground_reflectance: f64,
) -> Result<Vec<HourSky>, String> {
    let n = weather.records.len();
    if !weather.is_full_year() {
        let (a, b) = (&weather.records[0], &weather.records[n - 1]);
        return Err(format!(
            "annual daylight needs one whole calendar year of hourly records (8760, or 8784 with 29 February, from 01-01 hour 1 to 12-31 hour 24); the file has {n}, from {:02}-{:02} hour {} (line {}) to {:02}-{:02} hour {} (line {})",
            a.month, a.day, a.hour, a.line, b.month, b.day, b.hour, b.line
        ));
    }
    let site = &weather.site;
    let hour = |r: &crate::daylight::epw::Record| -> Result<HourSky, String> {
        let at = |e: &dyn std::fmt::Display| {
            format!(
                "line {} (record {:02}-{:02} hour {}): {e}",
                r.line, r.month, r.day, r.hour
            )
        };
        let wh = weather_hour(site, r, middle_of_hour(r)).map_err(|e| at(&e))?;
        let sky = SkyVector::perez(
            patches,
            wh.diffuse_horizontal_w_m2,
            wh.direct_normal_w_m2,
            wh.to_sun_enu,
            wh.eccentricity,
            wh.dew_point_c,
            ground_reflectance,
        )
        .map_err(|e| at(&e))?;
        Ok(HourSky {
            month: r.month,
            day: r.day,
            hour: r.hour,
            sun_altitude_deg: wh.sun.altitude_deg,
            to_sun_enu: wh.to_sun_enu,
            sky,
        })
    };
    use rayon::prelude::*;
    weather.records.par_iter().map(hour).collect()
}
