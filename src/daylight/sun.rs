//! Where the sun is, from a place and a time, by NREL's Solar Position Algorithm (Reda &
//! Andreas 2004, ±0.0003°; through the `solar-positioning` crate), and the sun's disk.
//!
//! Angles follow the lighting convention: altitude above the horizon, azimuth from north
//! towards east (0° north, 90° east, 180° south). Times are ISO 8601 with their offset from
//! UTC (`2026-06-21T10:00:00+02:00`, `…Z`).

use solar_positioning::{time::JulianDate, Location, RefractionCorrection, SolarPositions};

/// Angular diameter of the sun's disk, degrees (its mean; the sun subtends 0.524°–0.542°
/// over the year).
pub const SUN_DIAMETER_DEG: f64 = 0.533;

/// Solid angle of the sun's disk, sr: 2π(1 − cos(d/2)).
pub fn sun_solid_angle_sr() -> f64 {
    2.0 * std::f64::consts::PI * (1.0 - (0.5 * SUN_DIAMETER_DEG).to_radians().cos())
}

/// A civil time with its offset from UTC.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CivilTime {
    pub year: i32,
    pub month: u32,
    pub day: u32,
    /// Seconds since local midnight.
    pub seconds: f64,
    /// Offset of local time from UTC, seconds (+7200 for UTC+02:00).
    pub offset_s: f64,
}

/// Days from 1970-01-01 to a proleptic Gregorian date (Hinnant's algorithm).
fn days_from_civil(y: i64, m: u32, d: u32) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (m as i64 + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d as i64 - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

fn days_in_month(y: i32, m: u32) -> u32 {
    match m {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        _ if (y % 4 == 0 && y % 100 != 0) || y % 400 == 0 => 29,
        _ => 28,
    }
}

impl CivilTime {
    /// Parse `YYYY-MM-DDThh:mm[:ss[.fff]]` followed by `Z` or `±hh:mm`. The offset is
    /// required: a time without it names no instant.
    pub fn parse(s: &str) -> Result<Self, String> {
        Self::parse_with(s, true)
    }

    /// Parse a local apparent solar time, `YYYY-MM-DDThh:mm[:ss[.fff]]` without an offset
    /// (solar time is fixed by the sun, not by a time zone); `offset_s` is 0.
    pub fn parse_solar(s: &str) -> Result<Self, String> {
        Self::parse_with(s, false)
    }

    fn parse_with(s: &str, with_offset: bool) -> Result<Self, String> {
        let example = if with_offset {
            "2026-06-21T10:00:00+02:00"
        } else {
            "2026-06-21T10:00:00, local apparent solar time without an offset"
        };
        let bad = |why: &str| format!("time {s:?}: {why} (expected e.g. \"{example}\")");
        let (date, rest) = s
            .split_once(['T', ' '])
            .ok_or_else(|| bad("no 'T' between date and time"))?;
        let d: Vec<&str> = date.split('-').collect();
        let [y, mo, da] = d[..] else {
            return Err(bad("the date is not YYYY-MM-DD"));
        };
        let num = |t: &str, what: &str| -> Result<i64, String> {
            if t.is_empty() || !t.bytes().all(|b| b.is_ascii_digit()) || t.len() > 4 {
                return Err(bad(&format!("bad {what}")));
            }
            t.parse::<i64>().map_err(|_| bad(&format!("bad {what}")))
        };
        let (year, month, day) = (num(y, "year")?, num(mo, "month")?, num(da, "day")?);
        if !with_offset && (rest.ends_with('Z') || rest.contains(['+', '-'])) {
            return Err(bad("a solar time has no UTC offset"));
        }
        let (clock, offset_s) = if !with_offset {
            (rest, 0.0)
        } else if let Some(c) = rest.strip_suffix('Z') {
            (c, 0.0)
        } else if let Some(i) = rest.rfind(['+', '-']) {
            let (c, off) = rest.split_at(i);
            let sign = if off.starts_with('-') { -1.0 } else { 1.0 };
            let (oh, om) = off[1..].split_once(':').unwrap_or((&off[1..], "0"));
            let (oh, om) = (num(oh, "offset hours")?, num(om, "offset minutes")?);
            if oh > 14 || om > 59 {
                return Err(bad("offset out of range"));
            }
            (c, sign * (oh * 3600 + om * 60) as f64)
        } else {
            return Err(bad("no UTC offset (add Z or ±hh:mm)"));
        };
        let c: Vec<&str> = clock.split(':').collect();
        let (h, mi, sec) = match c[..] {
            [h, m] => (num(h, "hour")?, num(m, "minute")?, 0.0),
            [h, m, sec] => {
                let v: f64 = sec.parse().map_err(|_| bad("bad second"))?;
                if !(0.0..60.0).contains(&v) {
                    return Err(bad("second out of range"));
                }
                (num(h, "hour")?, num(m, "minute")?, v)
            }
            _ => return Err(bad("the time is not hh:mm[:ss]")),
        };
        if !(1..=12).contains(&month) {
            return Err(bad("month out of range"));
        }
        if day < 1 || day > days_in_month(year as i32, month as u32) as i64 {
            return Err(bad("no such day in that month"));
        }
        if h > 24 || mi > 59 || (h == 24 && (mi > 0 || sec > 0.0)) {
            return Err(bad("time of day out of range"));
        }
        Ok(Self {
            year: year as i32,
            month: month as u32,
            day: day as u32,
            seconds: (h * 3600 + mi * 60) as f64 + sec,
            offset_s,
        })
    }

    /// The same instant in UTC: (year, month, day, seconds since midnight).
    pub fn to_utc(&self) -> (i32, u32, u32, f64) {
        let t = self.seconds - self.offset_s;
        let day_shift = t.div_euclid(86_400.0);
        let secs = t - day_shift * 86_400.0;
        let (y, m, d) = civil_from_days(
            days_from_civil(self.year as i64, self.month, self.day) + day_shift as i64,
        );
        (y as i32, m, d, secs)
    }

    /// Day of the year of the local date (1 = 1 January).
    pub fn day_of_year(&self) -> u32 {
        (days_from_civil(self.year as i64, self.month, self.day)
            - days_from_civil(self.year as i64, 1, 1)) as u32
            + 1
    }
}

/// The sun's apparent position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunPosition {
    /// Above the horizon, degrees (negative below), with atmospheric refraction.
    pub altitude_deg: f64,
    /// From north towards east, degrees in [0, 360).
    pub azimuth_deg: f64,
}

/// Atmosphere for the refraction correction: pressure (hPa) and temperature (°C).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Atmosphere {
    pub pressure_hpa: f64,
    pub temperature_c: f64,
}

impl Default for Atmosphere {
    fn default() -> Self {
        Self {
            pressure_hpa: 1013.25,
            temperature_c: 12.0,
        }
    }
}

/// The UT Julian date of local apparent solar time `t` (its date and clock; `offset_s`
/// ignored) at `longitude_deg`: the sun's upper meridian transit of that day (by SPA) plus the
/// clock's distance from 12:00. The equation of time drifts by under 30 s a day, so the
/// instant is right to a few seconds.
pub fn solar_time_to_julian(
    t: &CivilTime,
    longitude_deg: f64,
    delta_t_s: f64,
) -> Result<f64, String> {
    use solar_positioning::SolarEvents;
    let noon = JulianDate::from_utc(t.year, t.month, t.day, 12, 0, 0.0, delta_t_s)
        .map_err(|e| format!("time: {e}"))?
        .julian_date()
        - longitude_deg / 360.0;
    let transit = SolarEvents::new()
        .next_transit_from_julian(noon - 0.5, noon + 0.5, longitude_deg, delta_t_s)
        .map_err(|e| format!("solar noon: {e}"))?
        .ok_or_else(|| "no solar noon found on that date".to_string())?;
    Ok(transit + (t.seconds - 43_200.0) / 86_400.0)
}

/// The sun's position at `latitude_deg` (north positive), `longitude_deg` (east positive),
/// `elevation_m` above sea level, at `time`; ΔT (TT − UT, s) estimated from the date unless
/// given.
pub fn sun_position(
    latitude_deg: f64,
    longitude_deg: f64,
    elevation_m: f64,
    time: &CivilTime,
    atmosphere: Atmosphere,
    delta_t_s: Option<f64>,
) -> Result<SunPosition, String> {
    sun_position_at(
        latitude_deg,
        longitude_deg,
        elevation_m,
        time,
        false,
        atmosphere,
        delta_t_s,
    )
}

/// [`sun_position`], with `time` read as local apparent solar time when `solar_time` (see
/// [`CivilTime::parse_solar`]).
pub fn sun_position_at(
    latitude_deg: f64,
    longitude_deg: f64,
    elevation_m: f64,
    time: &CivilTime,
    solar_time: bool,
    atmosphere: Atmosphere,
    delta_t_s: Option<f64>,
) -> Result<SunPosition, String> {
    if !(latitude_deg.is_finite() && (-90.0..=90.0).contains(&latitude_deg)) {
        return Err(format!("latitude {latitude_deg}° is not in [−90°, 90°]"));
    }
    if !(longitude_deg.is_finite() && (-180.0..=180.0).contains(&longitude_deg)) {
        return Err(format!(
            "longitude {longitude_deg}° is not in [−180°, 180°]"
        ));
    }
    if !elevation_m.is_finite() {
        return Err("elevation must be finite".into());
    }
    let (y, m, d, s) = time.to_utc();
    let delta_t = match delta_t_s {
        Some(v) => v,
        None => solar_positioning::delta_t::estimate_from_date(y, m)
            .map_err(|e| format!("ΔT for {y}-{m:02}: {e}"))?,
    };
    let jd = if solar_time {
        JulianDate::new(solar_time_to_julian(time, longitude_deg, delta_t)?, delta_t)
            .map_err(|e| format!("time: {e}"))?
    } else {
        let (h, rem) = ((s / 3600.0).floor(), s % 3600.0);
        let (mi, sec) = ((rem / 60.0).floor(), rem % 60.0);
        // 24:00 is the next day's midnight.
        let (y, m, d, h) = if h >= 24.0 {
            let (y2, m2, d2) = civil_from_days(days_from_civil(y as i64, m, d) + 1);
            (y2 as i32, m2, d2, 0.0)
        } else {
            (y, m, d, h)
        };
        JulianDate::from_utc(y, m, d, h as u32, mi as u32, sec, delta_t)
            .map_err(|e| format!("time: {e}"))?
    };
    let refraction = RefractionCorrection::new(atmosphere.pressure_hpa, atmosphere.temperature_c)
        .map_err(|e| format!("atmosphere: {e}"))?;
    let p = SolarPositions::new()
        .at_from_julian(
            jd,
            Location {
                latitude: latitude_deg,
                longitude: longitude_deg,
            },
            elevation_m,
            Some(refraction),
        )
        .map_err(|e| format!("sun position: {e}"))?;
    Ok(SunPosition {
        altitude_deg: 90.0 - p.zenith_angle(),
        azimuth_deg: p.azimuth().rem_euclid(360.0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nrel_test_vector() {
        // Reda & Andreas, Table A4.1: 2003-10-17 12:30:30 at UTC−7, 39.742476 N, 105.1786 W,
        // 1830.14 m, 820 mbar, 11 °C, ΔT 67 s: zenith 50.11162°, azimuth 194.34024°.
        let t = CivilTime::parse("2003-10-17T12:30:30-07:00").unwrap();
        let p = sun_position(
            39.742476,
            -105.1786,
            1830.14,
            &t,
            Atmosphere {
                pressure_hpa: 820.0,
                temperature_c: 11.0,
            },
            Some(67.0),
        )
        .unwrap();
        assert!((90.0 - p.altitude_deg - 50.11162).abs() < 3e-4, "{p:?}");
        assert!((p.azimuth_deg - 194.34024).abs() < 3e-4, "{p:?}");
    }

    #[test]
    fn solstice_noon_and_equinox() {
        // Near the June solstice at true solar noon, altitude ≈ 90° − lat + 23.44°, due south
        // north of the tropic. Lyon (45.76 N, 4.84 E): solar noon ≈ 11:42:20 UTC on 21 June
        // 2026 (longitude −19.4 min, equation of time −1.7 min).
        let t = CivilTime::parse("2026-06-21T13:42:20+02:00").unwrap();
        let p = sun_position(45.76, 4.84, 0.0, &t, Atmosphere::default(), None).unwrap();
        assert!(
            (p.altitude_deg - (90.0 - 45.76 + 23.44)).abs() < 0.1,
            "{p:?}"
        );
        assert!((p.azimuth_deg - 180.0).abs() < 0.5, "{p:?}");
        // Sunrise direction near the March equinox on the equator: due east.
        let t = CivilTime::parse("2026-03-20T06:10:00Z").unwrap();
        let p = sun_position(0.0, 0.0, 0.0, &t, Atmosphere::default(), None).unwrap();
        assert!(
            (p.azimuth_deg - 90.0).abs() < 0.5 && p.altitude_deg.abs() < 3.0,
            "{p:?}"
        );
    }

    #[test]
    fn solar_time() {
        // At 12:00 local apparent solar time the sun is due south (north of the tropics), and
        // 09:00 and 15:00 mirror each other about the meridian.
        let at = |clock: &str| {
            let t = CivilTime::parse_solar(&format!("2026-04-15T{clock}")).unwrap();
            sun_position_at(45.76, 4.84, 0.0, &t, true, Atmosphere::default(), None).unwrap()
        };
        let noon = at("12:00:00");
        assert!((noon.azimuth_deg - 180.0).abs() < 0.01, "{noon:?}");
        let (am, pm) = (at("09:00:00"), at("15:00:00"));
        // The declination moves by about 0.1° in six hours in April.
        assert!(
            (am.altitude_deg - pm.altitude_deg).abs() < 0.1,
            "{am:?} {pm:?}"
        );
        assert!(
            (am.azimuth_deg + pm.azimuth_deg - 360.0).abs() < 0.2,
            "{am:?} {pm:?}"
        );
        // The same instant by the clock: solar noon in Lyon on 15 April 2026 is near
        // 11:40:30 UTC (longitude −19.4 min, equation of time +0.1 min).
        let t = CivilTime::parse("2026-04-15T11:40:30Z").unwrap();
        let clock = sun_position(45.76, 4.84, 0.0, &t, Atmosphere::default(), None).unwrap();
        assert!((clock.azimuth_deg - 180.0).abs() < 0.2, "{clock:?}");
        assert!(CivilTime::parse_solar("2026-04-15T12:00:00+02:00").is_err());
        assert!(CivilTime::parse_solar("2026-04-15T12:00Z").is_err());
    }

    #[test]
    fn times_parse_and_convert() {
        let t = CivilTime::parse("2026-01-01T01:30:00+02:00").unwrap();
        assert_eq!(t.to_utc(), (2025, 12, 31, 23.5 * 3600.0));
        let t = CivilTime::parse("2024-02-28T23:00Z").unwrap();
        assert_eq!(t.day_of_year(), 59);
        let t = CivilTime::parse("2024-02-28T20:00-05:00").unwrap();
        assert_eq!(t.to_utc(), (2024, 2, 29, 3600.0));
        for bad in [
            "2026-06-21 10:00",
            "2026-02-30T10:00Z",
            "2026-13-01T10:00Z",
            "2026-06-21T25:00Z",
            "2026-06-21T10:00+15:00",
            "21/06/2026 10:00Z",
            "",
        ] {
            assert!(CivilTime::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn sun_disk() {
        // Ω = π (d/2)² to first order: 6.7967e-5 sr for 0.533°, so 100 klx of normal
        // illuminance is 1.471e9 cd/m² of disk.
        let omega = sun_solid_angle_sr();
        let small_angle = std::f64::consts::PI * (0.5 * SUN_DIAMETER_DEG).to_radians().powi(2);
        assert!((omega / small_angle - 1.0).abs() < 1e-5, "{omega}");
        assert!((1e5 / omega / 1.471e9 - 1.0).abs() < 1e-3);
    }
}
