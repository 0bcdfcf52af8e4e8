//! A year of skies from a weather file: for each hourly record, the sun's position at the
//! middle of its hour and the Perez sky over the sky patches ([`SkyVector`]), as `gendaymtx`
//! builds them from the file (through `epw2wea`, which also places each record at the middle
//! of its hour).

use crate::daylight::epw::Weather;
use crate::daylight::patches::{SkyPatches, SkyVector};
use crate::daylight::perez::{eccentricity, DEFAULT_DEW_POINT_C};
use crate::daylight::sun::{sun_position, Atmosphere, CivilTime};

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

/// What the year's skies report beyond the skies.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct YearNotes {
    /// Records whose irradiances are missing (the format's missing-value codes), taken as dark.
    pub missing_records: usize,
}

/// The skies of every record of an hourly weather file (8760 or 8784 records) over `patches`,
/// above a ground of reflectance `ground_reflectance`.
pub fn hourly_skies(
    weather: &Weather,
    patches: &SkyPatches,
    ground_reflectance: f64,
) -> Result<(Vec<HourSky>, YearNotes), String> {
    let n = weather.records.len();
    if n != 8760 && n != 8784 {
        return Err(format!(
            "annual daylight needs a year of hourly records (8760 or 8784), the file has {n}"
        ));
    }
    let site = &weather.site;
    let missing = std::sync::atomic::AtomicUsize::new(0);
    let hour = |(i, r): (usize, &crate::daylight::epw::Record)| -> Result<HourSky, String> {
        let at = |e: &dyn std::fmt::Display| {
            format!(
                "record {} ({:02}-{:02} hour {}): {e}",
                i + 1,
                r.month,
                r.day,
                r.hour
            )
        };
        let t = CivilTime {
            year: r.year.clamp(1, 9999),
            month: r.month,
            day: r.day,
            seconds: (r.hour as f64 - 0.5) * 3600.0,
            offset_s: site.time_zone_h * 3600.0,
        };
        let pos = sun_position(
            site.latitude_deg,
            site.longitude_deg,
            site.elevation_m,
            &t,
            Atmosphere::default(),
            None,
        )
        .map_err(|e| at(&e))?;
        let (alt, az) = (pos.altitude_deg.to_radians(), pos.azimuth_deg.to_radians());
        let to_sun = [alt.cos() * az.sin(), alt.cos() * az.cos(), alt.sin()];
        let (dn, dh) = match (r.direct_normal_w_m2, r.diffuse_horizontal_w_m2) {
            (Some(dn), Some(dh)) => (dn, dh),
            _ => {
                missing.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                (0.0, 0.0)
            }
        };
        let sky = SkyVector::perez(
            patches,
            dh,
            dn,
            to_sun,
            eccentricity(t.day_of_year() as f64),
            r.dew_point_c.unwrap_or(DEFAULT_DEW_POINT_C),
            ground_reflectance,
        )
        .map_err(|e| at(&e))?;
        Ok(HourSky {
            month: r.month,
            day: r.day,
            hour: r.hour,
            sun_altitude_deg: pos.altitude_deg,
            to_sun_enu: to_sun,
            sky,
        })
    };
    use rayon::prelude::*;
    let hours = weather
        .records
        .par_iter()
        .enumerate()
        .map(hour)
        .collect::<Result<Vec<_>, _>>()?;
    let notes = YearNotes {
        missing_records: missing.into_inner(),
    };
    Ok((hours, notes))
}
