//! EnergyPlus weather files (EPW): the site and, per hour, the solar irradiance and
//! illuminance that drive a Perez sky and the sun.
//!
//! An EPW file is CSV: eight header lines (the first, `LOCATION`, gives the place and its
//! standard time zone; the eighth, `DATA PERIODS`, the records per hour), then one record per
//! hour with 35 fields. Record hour h covers local standard time (h − 1):00 to h:00. The
//! fields read here (EnergyPlus Auxiliary Programs, "Weather Converter Program"):
//!
//! | field | column | unit | missing |
//! |---|---|---|---|
//! | year, month, day, hour, minute | 1–5 | | |
//! | dew point temperature | 8 | °C | 99.9 |
//! | global horizontal irradiance | 14 | W/m² | 9999 |
//! | direct normal irradiance | 15 | W/m² | 9999 |
//! | diffuse horizontal irradiance | 16 | W/m² | 9999 |
//! | direct normal illuminance | 18 | lx | 999999 |
//! | diffuse horizontal illuminance | 19 | lx | 999999 |
//!
//! A file is refused, with its line and field, unless it is an hourly series of consecutive
//! hours on real dates whose irradiances are all given and physically possible
//! ([`check_irradiance`]): a wrong weather file would otherwise give plausible-looking wrong
//! numbers.

use super::perez::{eccentricity, SOLAR_CONSTANT_W_M2};
use super::sun::{sun_position, Atmosphere, CivilTime};
use std::path::Path;

/// Largest EPW file read (a year of hourly records is about 1.6 MB; sub-hourly files more).
pub const MAX_EPW_BYTES: u64 = 64 << 20;

/// Elevations accepted, metres: the Dead Sea shore to above the highest weather stations.
pub const ELEVATION_RANGE_M: (f64, f64) = (-500.0, 9000.0);

/// Dew points accepted, °C (the extremes measured on Earth lie within −80…+35).
pub const DEW_POINT_RANGE_C: (f64, f64) = (-90.0, 45.0);

/// Direct-normal irradiance tolerated while the sun is below the horizon all through the hour
/// (W/m²): rounding and twilight, never a sunny hour.
pub const NIGHT_DIRECT_TOLERANCE_W_M2: f64 = 5.0;

/// How far below the horizon (degrees, with refraction) the sun must stay through the whole
/// hour before direct light in it is refused: covers a time zone or longitude rounded in the
/// file (4 minutes of time per degree) and the refraction models' spread at the horizon.
pub const NIGHT_SUN_ALTITUDE_DEG: f64 = -1.0;

/// The `LOCATION` line.
#[derive(Clone, Debug, PartialEq)]
pub struct Site {
    pub city: String,
    pub country: String,
    /// Degrees, north positive.
    pub latitude_deg: f64,
    /// Degrees, east positive.
    pub longitude_deg: f64,
    /// Standard time zone, hours from UTC (+1 for Central Europe).
    pub time_zone_h: f64,
    /// Metres above sea level.
    pub elevation_m: f64,
}

/// One hourly record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Record {
    /// 1-based line of the file holding the record.
    pub line: usize,
    pub year: i32,
    pub month: u32,
    pub day: u32,
    /// 1–24: the record covers the hour ending at `hour`:00 local standard time.
    pub hour: u32,
    pub minute: u32,
    /// °C, None where missing.
    pub dew_point_c: Option<f64>,
    /// W/m², None where missing (it is not used, only checked).
    pub global_horizontal_w_m2: Option<f64>,
    /// W/m², always given (a file with a missing value is refused).
    pub direct_normal_w_m2: f64,
    pub diffuse_horizontal_w_m2: f64,
    /// lx, None where missing. Read but not used for the sky: see [`super::weather`].
    pub direct_normal_lx: Option<f64>,
    pub diffuse_horizontal_lx: Option<f64>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Weather {
    pub site: Site,
    pub records: Vec<Record>,
}

/// A parse error, with the 1-based line and, where one is at fault, the field.
#[derive(Clone, Debug, PartialEq)]
pub struct EpwError {
    pub line: usize,
    pub message: String,
}

impl std::fmt::Display for EpwError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

fn err(line: usize, message: String) -> EpwError {
    EpwError { line, message }
}

/// Input text quoted in a message: control characters escaped, at most 40 characters.
fn quoted(s: &str) -> String {
    format!("\"{}\"", crate::limits::printable(s, 40))
}

fn field<'a>(fields: &[&'a str], col: usize, line: usize, name: &str) -> Result<&'a str, EpwError> {
    fields.get(col - 1).map(|s| s.trim()).ok_or_else(|| {
        err(
            line,
            format!(
                "no field {col} ({name}): the line has {} fields",
                fields.len()
            ),
        )
    })
}

fn number(fields: &[&str], col: usize, line: usize, name: &str) -> Result<f64, EpwError> {
    let s = field(fields, col, line, name)?;
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(err(
            line,
            format!("field {col} ({name}) is {}, not a number", quoted(s)),
        )),
    }
}

/// A number within `range` (inclusive), in `unit`.
fn bounded(
    fields: &[&str],
    col: usize,
    line: usize,
    name: &str,
    range: (f64, f64),
    unit: &str,
) -> Result<f64, EpwError> {
    let v = number(fields, col, line, name)?;
    if !(range.0..=range.1).contains(&v) {
        return Err(err(
            line,
            format!(
                "field {col} ({name}) is {v:e} {unit}, outside {} … {} {unit}",
                range.0, range.1
            ),
        ));
    }
    Ok(v)
}

/// A quantity ≥ 0 or the file's "missing" code.
fn amount(
    fields: &[&str],
    col: usize,
    line: usize,
    name: &str,
    missing: f64,
) -> Result<Option<f64>, EpwError> {
    let v = number(fields, col, line, name)?;
    if v >= missing {
        return Ok(None);
    }
    if v < 0.0 {
        return Err(err(line, format!("field {col} ({name}) is {v}, negative")));
    }
    Ok(Some(v))
}

/// An irradiance that must be given (W/m²).
fn irradiance(fields: &[&str], col: usize, line: usize, name: &str) -> Result<f64, EpwError> {
    amount(fields, col, line, name, 9999.0)?.ok_or_else(|| {
        err(
            line,
            format!(
                "field {col} ({name}) is {}, the format's code for a missing value: every hour's irradiances are needed (fill the gap in the file)",
                field(fields, col, line, name).unwrap_or_default()
            ),
        )
    })
}

fn integer(
    fields: &[&str],
    col: usize,
    line: usize,
    name: &str,
    range: (i64, i64),
) -> Result<i64, EpwError> {
    let s = field(fields, col, line, name)?;
    match s.parse::<i64>() {
        Ok(v) if (range.0..=range.1).contains(&v) => Ok(v),
        _ => Err(err(
            line,
            format!(
                "field {col} ({name}) is {}, not an integer in {}–{}",
                quoted(s),
                range.0,
                range.1
            ),
        )),
    }
}

fn is_leap(year: i32) -> bool {
    (year % 4 == 0 && year % 100 != 0) || year % 400 == 0
}

/// Days in `month`, February with 29 when `leap`.
fn month_days(month: u32, leap: bool) -> u32 {
    match month {
        2 if leap => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// The hour after (month, day, hour); 31 December hour 24 is followed by 1 January hour 1.
/// February has 29 days when `leap`.
fn next_hour((month, day, hour): (u32, u32, u32), leap: bool) -> (u32, u32, u32) {
    if hour < 24 {
        (month, day, hour + 1)
    } else if day < month_days(month, leap) {
        (month, day + 1, 1)
    } else {
        (month % 12 + 1, 1, 1)
    }
}

fn when((month, day, hour): (u32, u32, u32)) -> String {
    format!("{month:02}-{day:02} hour {hour}")
}

/// Checks a record's irradiances against the sun at `site` (the BSRN "physically possible"
/// limits of Long & Dutton 2002, with the cosine of the sun's zenith angle at its largest over
/// the hour, and no direct light from a sun below the horizon through the whole hour). The
/// message names the field.
pub fn check_irradiance(site: &Site, r: &Record) -> Result<(), String> {
    // Within the night-time limits (no direct light, 50 W/m² diffuse, 100 W/m² global) the
    // sun need not be found.
    if r.direct_normal_w_m2 <= NIGHT_DIRECT_TOLERANCE_W_M2
        && r.diffuse_horizontal_w_m2 <= 50.0
        && r.global_horizontal_w_m2.is_none_or(|g| g <= 100.0)
    {
        return Ok(());
    }
    let year = r.year.clamp(1, 9999);
    let mut altitudes = [0.0f64; 3];
    for (k, frac) in [0.0, 0.5, 1.0].into_iter().enumerate() {
        let t = CivilTime {
            year,
            month: r.month,
            day: r.day,
            seconds: (r.hour as f64 - 1.0 + frac) * 3600.0,
            offset_s: site.time_zone_h * 3600.0,
        };
        altitudes[k] = sun_position(
            site.latitude_deg,
            site.longitude_deg,
            site.elevation_m,
            &t,
            Atmosphere::default(),
            None,
        )?
        .altitude_deg;
    }
    let day = CivilTime {
        year,
        month: r.month,
        day: r.day,
        seconds: 0.0,
        offset_s: 0.0,
    }
    .day_of_year();
    let s0 = SOLAR_CONSTANT_W_M2 * eccentricity(day as f64);
    let top = altitudes.iter().copied().fold(f64::MIN, f64::max);
    let mu = top.to_radians().sin().max(0.0);
    let limits = [
        (
            15,
            "direct normal irradiance",
            Some(r.direct_normal_w_m2),
            s0,
            "the extraterrestrial irradiance",
        ),
        (
            16,
            "diffuse horizontal irradiance",
            Some(r.diffuse_horizontal_w_m2),
            0.95 * s0 * mu.powf(1.2) + 50.0,
            "0.95 S₀ cos^1.2 Z + 50, the physically possible limit",
        ),
        (
            14,
            "global horizontal irradiance",
            r.global_horizontal_w_m2,
            1.5 * s0 * mu.powf(1.2) + 100.0,
            "1.5 S₀ cos^1.2 Z + 100, the physically possible limit",
        ),
    ];
    if r.direct_normal_w_m2 > NIGHT_DIRECT_TOLERANCE_W_M2
        && altitudes.iter().all(|&a| a < NIGHT_SUN_ALTITUDE_DEG)
    {
        let h = r.hour as f64;
        return Err(format!(
            "field 15 (direct normal irradiance) is {} W/m² while the sun is below the horizon all through the hour ({:.1}° at {:02}:00, {:.1}° at {:02}:30, {:.1}° at {:02}:00 local standard time): are the LOCATION line's longitude ({}°) and time zone ({} h) right, and are the records in local standard time, each ending at its hour?",
            r.direct_normal_w_m2,
            altitudes[0],
            h as u32 - 1,
            altitudes[1],
            h as u32 - 1,
            altitudes[2],
            h as u32,
            site.longitude_deg,
            site.time_zone_h
        ));
    }
    for (col, name, value, limit, what) in limits {
        if let Some(v) = value {
            if v > limit {
                return Err(format!(
                    "field {col} ({name}) is {v} W/m², above {limit:.0} W/m² ({what}, the sun at most {top:.1}° above the horizon in that hour): is this the right file, and are its irradiances in W/m²?"
                ));
            }
        }
    }
    Ok(())
}

impl Weather {
    /// Read and parse `path` (a bounded read: FIFOs, devices and files over
    /// [`MAX_EPW_BYTES`] are refused). The message names the file and line.
    pub fn read(path: &Path) -> Result<Self, String> {
        let bytes = crate::limits::read_file(path, MAX_EPW_BYTES)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let text = String::from_utf8_lossy(&bytes);
        Self::parse(&text).map_err(|e| format!("{}: {e}", path.display()))
    }

    fn parse_site(n: usize, first: &str) -> Result<Site, EpwError> {
        let f: Vec<&str> = first.split(',').collect();
        if f[0].trim() != "LOCATION" {
            return Err(err(
                n,
                format!(
                    "the first line starts {}, not LOCATION",
                    quoted(f[0].trim())
                ),
            ));
        }
        if f.len() != 10 {
            return Err(err(
                n,
                format!(
                    "the LOCATION line has {} fields, not 10 (LOCATION, city, state, country, source, station, latitude, longitude, time zone, elevation): a decimal comma in a number?",
                    f.len()
                ),
            ));
        }
        let latitude_deg = bounded(&f, 7, n, "latitude", (-90.0, 90.0), "°")?;
        let longitude_deg = bounded(&f, 8, n, "longitude", (-180.0, 180.0), "°")?;
        let time_zone_h = bounded(&f, 9, n, "time zone", (-12.0, 14.0), "h")?;
        let elevation_m = bounded(&f, 10, n, "elevation", ELEVATION_RANGE_M, "m")?;
        Ok(Site {
            city: field(&f, 2, n, "city")?.to_string(),
            country: field(&f, 4, n, "country")?.to_string(),
            latitude_deg,
            longitude_deg,
            time_zone_h,
            elevation_m,
        })
    }

    /// One record; `leap`: the header says 29 February occurs.
    fn parse_record(n: usize, l: &str, leap: bool) -> Result<Record, EpwError> {
        let f: Vec<&str> = l.split(',').collect();
        if f.len() < 21 {
            return Err(err(n, format!("{} fields, an EPW record has 35", f.len())));
        }
        let year = integer(&f, 1, n, "year", (-9999, 9999))? as i32;
        let month = integer(&f, 2, n, "month", (1, 12))? as u32;
        let day = integer(&f, 3, n, "day", (1, 31))? as u32;
        if day > month_days(month, leap || is_leap(year)) {
            return Err(err(
                n,
                format!("fields 2–3 (month, day) are {month:02}-{day:02}, not a date of {year}"),
            ));
        }
        let dew = number(&f, 8, n, "dew point temperature")?;
        Ok(Record {
            line: n,
            year,
            month,
            day,
            hour: integer(&f, 4, n, "hour", (1, 24))? as u32,
            minute: integer(&f, 5, n, "minute", (0, 60))? as u32,
            // 99.9 is the missing-value code; anything else is checked.
            dew_point_c: if dew == 99.9 {
                None
            } else {
                Some(bounded(
                    &f,
                    8,
                    n,
                    "dew point temperature",
                    DEW_POINT_RANGE_C,
                    "°C",
                )?)
            },
            global_horizontal_w_m2: amount(&f, 14, n, "global horizontal irradiance", 9999.0)?,
            direct_normal_w_m2: irradiance(&f, 15, n, "direct normal irradiance")?,
            diffuse_horizontal_w_m2: irradiance(&f, 16, n, "diffuse horizontal irradiance")?,
            direct_normal_lx: amount(&f, 18, n, "direct normal illuminance", 999_900.0)?,
            diffuse_horizontal_lx: amount(&f, 19, n, "diffuse horizontal illuminance", 999_900.0)?,
        })
    }

    pub fn parse(text: &str) -> Result<Self, EpwError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
        let (n, first) = lines.next().ok_or(EpwError {
            line: 1,
            message: "empty file, not an EPW weather file".into(),
        })?;
        let site = Self::parse_site(n, first)?;
        // Seven more header lines: HOLIDAYS/DAYLIGHT SAVINGS says whether 29 February may
        // occur, DATA PERIODS how many records an hour has.
        let mut leap = false;
        for k in 2..=8 {
            let (n, l) = lines.next().ok_or(EpwError {
                line: k - 1,
                message: "the file ends inside its eight header lines".into(),
            })?;
            let f: Vec<&str> = l.split(',').map(str::trim).collect();
            if f[0] == "HOLIDAYS/DAYLIGHT SAVINGS" {
                leap = f.get(1).is_some_and(|v| v.eq_ignore_ascii_case("yes"));
            }
            if k == 8 {
                if f[0] != "DATA PERIODS" {
                    return Err(err(
                        n,
                        format!("the eighth line starts {}, not DATA PERIODS", quoted(f[0])),
                    ));
                }
                let per_hour = f.get(2).copied().unwrap_or("");
                if per_hour != "1" {
                    return Err(err(
                        n,
                        format!(
                            "DATA PERIODS field 3 (records per hour) is {}: only hourly weather files (1 record per hour) are read",
                            quoted(per_hour)
                        ),
                    ));
                }
            }
        }
        let mut records: Vec<Record> = Vec::new();
        for (n, l) in lines {
            if l.trim().is_empty() {
                continue;
            }
            let r = Self::parse_record(n, l, leap)?;
            if let Some(p) = records.last() {
                // After 28 February both 29 February (a leap year's, which the date check
                // allows only in one) and 1 March follow: typical years often take February
                // from a leap year without its 29th.
                let prev = (p.month, p.day, p.hour);
                let (expected, leap_next) = (next_hour(prev, false), next_hour(prev, true));
                let this = (r.month, r.day, r.hour);
                if this != expected && this != leap_next {
                    let how = if this == (p.month, p.day, p.hour) {
                        "repeats it"
                    } else if (r.month, r.day) == (p.month, p.day) && r.hour < p.hour
                        || (r.month, r.day) < (p.month, p.day) && !(p.month == 12 && r.month == 1)
                    {
                        "goes back in time (records repeated or out of order)"
                    } else {
                        "skips hours (records missing or out of order)"
                    };
                    return Err(err(
                        n,
                        format!(
                            "fields 2–4 (month, day, hour): record {} follows {} on line {} and {how}; the records must be consecutive hours ({} expected)",
                            when(this),
                            when((p.month, p.day, p.hour)),
                            p.line,
                            when(expected)
                        ),
                    ));
                }
            }
            records.push(r);
        }
        if records.is_empty() {
            return Err(err(
                text.lines().count(),
                "no hourly records after the eight header lines".into(),
            ));
        }
        // Against the sun: a wrong site, time zone or time convention shows as direct light
        // at night.
        use rayon::prelude::*;
        records
            .par_iter()
            .try_for_each(|r| check_irradiance(&site, r).map_err(|m| err(r.line, m)))?;
        Ok(Self { site, records })
    }

    /// Whether the records are one whole calendar year, 1 January hour 1 to 31 December hour
    /// 24 (8760 hours, or 8784 with 29 February), as annual metrics need: the records are
    /// consecutive hours once parsed, so the first, the last and the count tell.
    pub fn is_full_year(&self) -> bool {
        let (first, last) = (&self.records[0], &self.records[self.records.len() - 1]);
        let n = self.records.len();
        (first.month, first.day, first.hour) == (1, 1, 1)
            && (last.month, last.day, last.hour) == (12, 31, 24)
            && (n == 8760 || n == 8784)
    }

    /// The record covering local standard time `month`-`day` `hour`:`minute` (record hour h
    /// covers (h − 1):00 up to h:00), or None if the file has no such hour.
    pub fn at(&self, month: u32, day: u32, hour: u32, minute: u32) -> Option<&Record> {
        let want = hour + 1;
        let _ = minute;
        self.records
            .iter()
            .find(|r| r.month == month && r.day == day && r.hour == want)
    }
}
#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = "LOCATION,Lyon-Satolas,-,FRA,IWEC Data,074810,45.73,5.08,1.0,240.0
DESIGN CONDITIONS,0
TYPICAL/EXTREME PERIODS,0
GROUND TEMPERATURES,0
HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0
COMMENTS 1,test
COMMENTS 2,test
DATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31
";

    fn rec_on(m: u32, d: u32, h: u32, dni: &str, dhi: &str) -> String {
        format!(
            "1995,{m},{d},{h},60,A7A7,20.0,11.5,60,98000,1300,1367,350,700,{dni},{dhi},70000,65000,25000,4000,180,3.0,5,3,20.0,77777,9,999999999,0,0.2,0,88,0.0,0.0,0.0\n"
        )
    }

    fn rec(h: u32, dni: &str, dhi: &str) -> String {
        rec_on(6, 21, h, dni, dhi)
    }

    fn message(text: &str) -> EpwError {
        Weather::parse(text).unwrap_err()
    }

    #[test]
    fn reads_site_and_records() {
        let text = format!("{HEAD}{}{}", rec(11, "600", "120"), rec(12, "650", "130"));
        let w = Weather::parse(&text).unwrap();
        assert_eq!(w.site.city, "Lyon-Satolas");
        assert_eq!(
            (
                w.site.latitude_deg,
                w.site.longitude_deg,
                w.site.time_zone_h
            ),
            (45.73, 5.08, 1.0)
        );
        assert_eq!(w.records.len(), 2);
        let r = w.at(6, 21, 10, 30).unwrap();
        assert_eq!((r.hour, r.line), (11, 9));
        assert_eq!(r.direct_normal_w_m2, 600.0);
        assert_eq!(r.diffuse_horizontal_lx, Some(25000.0));
        assert_eq!(r.dew_point_c, Some(11.5));
        assert_eq!(w.at(6, 21, 11, 0).unwrap().direct_normal_w_m2, 650.0);
        assert!(w.at(6, 22, 10, 0).is_none());
        assert!(!w.is_full_year());
    }

    #[test]
    fn errors_name_the_line_and_field() {
        let e = message(&format!("{HEAD}{}", rec(11, "abc", "120")));
        assert_eq!(e.line, 9);
        assert!(
            e.message.contains("field 15 (direct normal irradiance)"),
            "{e}"
        );
        let e = message(&format!("{HEAD}{}", rec(11, "-5", "120")));
        assert!(e.message.contains("negative"), "{e}");
        let e = message(&format!("{HEAD}{}", rec(25, "5", "120")));
        assert!(e.message.contains("hour"), "{e}");
        let e = message(&format!("{HEAD}1995,6,21\n"));
        assert!(e.message.contains("3 fields"), "{e}");
        let e = message("DESIGN,1\n");
        assert_eq!(e.line, 1);
        assert!(Weather::parse(&HEAD.replace("45.73", "95")).is_err());
        assert!(message(HEAD).message.contains("no hourly records"));
        assert!(Weather::parse("").is_err());
    }

    /// Every refusal of a file that parses but would give wrong numbers: the line and the
    /// field are named.
    #[test]
    fn refuses_impossible_weather() {
        let ok = |h| rec(h, "600", "120");
        let cases: Vec<(String, usize, &str)> = vec![
            // The header's numbers.
            (HEAD.replace("240.0", "1e300"), 1, "field 10 (elevation) is 1e300 m"),
            (HEAD.replace("45.73", "-91"), 1, "field 7 (latitude)"),
            (HEAD.replace("5.08", "181"), 1, "field 8 (longitude)"),
            (HEAD.replace(",1.0,", ",15,"), 1, "field 9 (time zone)"),
            (HEAD.replace(",1.0,", ",5,5,"), 1, "11 fields, not 10"),
            (HEAD.replace("1,Data", "4,Data"), 8, "records per hour"),
            // The records' order and dates.
            (format!("{HEAD}{}{}", ok(11), ok(11)), 10, "repeats it"),
            (format!("{HEAD}{}{}", ok(12), ok(11)), 10, "goes back"),
            (format!("{HEAD}{}{}", ok(11), ok(13)), 10, "skips hours"),
            (
                format!("{HEAD}{}{}", rec_on(6, 21, 24, "0", "0"), rec_on(6, 21, 1, "0", "0")),
                10,
                "goes back",
            ),
            (format!("{HEAD}{}", rec_on(2, 31, 12, "600", "120")), 9, "02-31, not a date"),
            (format!("{HEAD}{}", rec_on(2, 29, 12, "600", "120")), 9, "02-29, not a date of 1995"),
            (format!("{HEAD}{}", rec_on(4, 31, 12, "600", "120")), 9, "04-31"),
            // The irradiances.
            (format!("{HEAD}{}", rec(11, "9999", "120")), 9, "field 15 (direct normal irradiance) is 9999, the format's code for a missing value"),
            (format!("{HEAD}{}", rec(11, "600", "9999")), 9, "field 16 (diffuse horizontal irradiance) is 9999"),
            (format!("{HEAD}{}", rec(11, "600", "-1")), 9, "field 16 (diffuse horizontal irradiance) is -1, negative"),
            (format!("{HEAD}{}", rec(11, "1500", "120")), 9, "field 15 (direct normal irradiance) is 1500 W/m², above"),
            (format!("{HEAD}{}", rec(11, "600", "1200")), 9, "field 16 (diffuse horizontal irradiance) is 1200"),
            (format!("{HEAD}{}", rec(11, "600", "120").replace(",700,", ",2000,")), 9, "field 14 (global horizontal irradiance) is 2000"),
            (format!("{HEAD}{}", rec(11, "600", "120").replace(",11.5,", ",1e300,")), 9, "field 8 (dew point temperature)"),
            // Direct light at night: 01:00–02:00 in Lyon.
            (format!("{HEAD}{}", rec(2, "100", "0")), 9, "field 15 (direct normal irradiance) is 100 W/m² while the sun is below the horizon"),
            // At night the diffuse limit is 50 W/m².
            (format!("{HEAD}{}", rec(2, "0", "80")), 9, "field 16 (diffuse horizontal irradiance) is 80"),
        ];
        for (text, line, what) in cases {
            let e = message(&text);
            assert_eq!(e.line, line, "{what}: {e}");
            assert!(e.message.contains(what), "{what}: {e}");
        }
    }

    /// What real files do at the horizon is accepted: direct light in the hour of sunrise
    /// (05:00–06:00 in Lyon on 21 June, the sun rising at about 04:50 standard time), twilight
    /// diffuse light, a leap day in a leap year, and the turn of the year.
    #[test]
    fn accepts_the_edges() {
        let text = format!(
            "{HEAD}{}{}",
            rec(5, "0", "20").replace(",700,", ",20,"),
            rec(6, "150", "60").replace(",700,", ",100,")
        );
        assert!(Weather::parse(&text).is_ok());
        // The record of 04:00–05:00, with the sun just up at its end: a few W/m² are rounding.
        assert!(Weather::parse(&format!(
            "{HEAD}{}",
            rec(5, "4", "3").replace(",700,", ",3,")
        ))
        .is_ok());
        let leap = format!(
            "{HEAD}{}",
            rec_on(2, 29, 12, "300", "100").replace("1995,", "1996,")
        );
        assert!(Weather::parse(&leap).is_ok());
        let declared = HEAD.replace("SAVINGS,No", "SAVINGS,Yes");
        assert!(Weather::parse(&format!("{declared}{}", rec_on(2, 29, 12, "300", "100"))).is_ok());
        let turn = format!(
            "{HEAD}{}{}",
            rec_on(12, 31, 24, "0", "0"),
            rec_on(1, 1, 1, "0", "0")
        )
        .replace(",700,", ",0,");
        assert!(Weather::parse(&turn).is_ok());
        // A typical year's February taken from a leap year, without its 29th.
        let feb = format!(
            "{HEAD}{}{}",
            rec_on(2, 28, 24, "0", "0").replace("1995,", "1996,"),
            rec_on(3, 1, 1, "0", "0")
        )
        .replace(",700,", ",0,");
        assert!(Weather::parse(&feb).is_ok());
    }
}
