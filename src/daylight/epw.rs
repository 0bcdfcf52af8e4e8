//! EnergyPlus weather files (EPW): the site and, per hour, the solar irradiance and
//! illuminance that drive a Perez sky and the sun.
//!
//! An EPW file is CSV: eight header lines (the first, `LOCATION`, gives the place and its
//! standard time zone), then one record per hour with 35 fields. Record hour h covers local
//! standard time (h − 1):00 to h:00. The fields read here (EnergyPlus Auxiliary Programs,
//! "Weather Converter Program"):
//!
//! | field | column | unit | missing |
//! |---|---|---|---|
//! | year, month, day, hour, minute | 1–5 | | |
//! | dew point temperature | 8 | °C | 99.9 |
//! | direct normal irradiance | 15 | W/m² | 9999 |
//! | diffuse horizontal irradiance | 16 | W/m² | 9999 |
//! | direct normal illuminance | 18 | lx | 999999 |
//! | diffuse horizontal illuminance | 19 | lx | 999999 |

use std::path::Path;

/// Largest EPW file read (a year of hourly records is about 1.6 MB; sub-hourly files more).
pub const MAX_EPW_BYTES: u64 = 64 << 20;

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
    pub year: i32,
    pub month: u32,
    pub day: u32,
    /// 1–24: the record covers the hour ending at `hour`:00 local standard time.
    pub hour: u32,
    pub minute: u32,
    /// °C, None where missing.
    pub dew_point_c: Option<f64>,
    /// W/m², None where missing.
    pub direct_normal_w_m2: Option<f64>,
    pub diffuse_horizontal_w_m2: Option<f64>,
    /// lx, None where missing.
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

fn field<'a>(fields: &[&'a str], col: usize, line: usize, name: &str) -> Result<&'a str, EpwError> {
    fields
        .get(col - 1)
        .map(|s| s.trim())
        .ok_or_else(|| EpwError {
            line,
            message: format!(
                "no field {col} ({name}): the line has {} fields",
                fields.len()
            ),
        })
}

fn number(fields: &[&str], col: usize, line: usize, name: &str) -> Result<f64, EpwError> {
    let s = field(fields, col, line, name)?;
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(EpwError {
            line,
            message: format!("field {col} ({name}) is {s:?}, not a number"),
        }),
    }
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
        return Err(EpwError {
            line,
            message: format!("field {col} ({name}) is {v}, negative"),
        });
    }
    Ok(Some(v))
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
        _ => Err(EpwError {
            line,
            message: format!(
                "field {col} ({name}) is {s:?}, not an integer in {}–{}",
                range.0, range.1
            ),
        }),
    }
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

    pub fn parse(text: &str) -> Result<Self, EpwError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
        let (n, first) = lines.next().ok_or(EpwError {
            line: 1,
            message: "empty file, not an EPW weather file".into(),
        })?;
        let f: Vec<&str> = first.split(',').collect();
        if f[0].trim() != "LOCATION" {
            return Err(EpwError {
                line: n,
                message: format!("the first line starts {:?}, not LOCATION", f[0].trim()),
            });
        }
        let latitude_deg = number(&f, 7, n, "latitude")?;
        let longitude_deg = number(&f, 8, n, "longitude")?;
        let time_zone_h = number(&f, 9, n, "time zone")?;
        let elevation_m = number(&f, 10, n, "elevation")?;
        if !(-90.0..=90.0).contains(&latitude_deg) {
            return Err(EpwError {
                line: n,
                message: format!("latitude {latitude_deg} is not in −90…90"),
            });
        }
        if !(-180.0..=180.0).contains(&longitude_deg) {
            return Err(EpwError {
                line: n,
                message: format!("longitude {longitude_deg} is not in −180…180"),
            });
        }
        if !(-12.0..=14.0).contains(&time_zone_h) {
            return Err(EpwError {
                line: n,
                message: format!("time zone {time_zone_h} h is not in −12…+14"),
            });
        }
        let site = Site {
            city: field(&f, 2, n, "city")?.to_string(),
            country: field(&f, 4, n, "country").unwrap_or("").to_string(),
            latitude_deg,
            longitude_deg,
            time_zone_h,
            elevation_m,
        };
        // Seven more header lines, the last DATA PERIODS.
        for _ in 0..7 {
            lines.next().ok_or(EpwError {
                line: n,
                message: "the file ends inside its eight header lines".into(),
            })?;
        }
        let mut records = Vec::new();
        for (n, l) in lines {
            if l.trim().is_empty() {
                continue;
            }
            let f: Vec<&str> = l.split(',').collect();
            if f.len() < 21 {
                return Err(EpwError {
                    line: n,
                    message: format!("{} fields, an EPW record has 35", f.len()),
                });
            }
            let month = integer(&f, 2, n, "month", (1, 12))? as u32;
            let day = integer(&f, 3, n, "day", (1, 31))? as u32;
            records.push(Record {
                year: integer(&f, 1, n, "year", (-9999, 9999))? as i32,
                month,
                day,
                hour: integer(&f, 4, n, "hour", (1, 24))? as u32,
                minute: integer(&f, 5, n, "minute", (0, 60))? as u32,
                dew_point_c: {
                    let v = number(&f, 8, n, "dew point temperature")?;
                    (v < 99.9).then_some(v)
                },
                direct_normal_w_m2: amount(&f, 15, n, "direct normal irradiance", 9999.0)?,
                diffuse_horizontal_w_m2: amount(
                    &f,
                    16,
                    n,
                    "diffuse horizontal irradiance",
                    9999.0,
                )?,
                direct_normal_lx: amount(&f, 18, n, "direct normal illuminance", 999_900.0)?,
                diffuse_horizontal_lx: amount(
                    &f,
                    19,
                    n,
                    "diffuse horizontal illuminance",
                    999_900.0,
                )?,
            });
        }
        if records.is_empty() {
            return Err(EpwError {
                line: text.lines().count(),
                message: "no hourly records after the eight header lines".into(),
            });
        }
        Ok(Self { site, records })
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

    fn rec(h: u32, dni: &str, dhi: &str) -> String {
        format!(
            "1995,6,21,{h},60,A7A7,20.0,11.5,60,98000,1300,1367,350,700,{dni},{dhi},70000,65000,25000,4000,180,3.0,5,3,20.0,77777,9,999999999,0,0.2,0,88,0.0,0.0,0.0\n"
        )
    }

    #[test]
    fn reads_site_and_records() {
        let text = format!("{HEAD}{}{}", rec(11, "600", "120"), rec(12, "9999", "130"));
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
        assert_eq!(r.hour, 11);
        assert_eq!(r.direct_normal_w_m2, Some(600.0));
        assert_eq!(r.diffuse_horizontal_lx, Some(25000.0));
        assert_eq!(r.dew_point_c, Some(11.5));
        assert_eq!(w.at(6, 21, 11, 0).unwrap().direct_normal_w_m2, None);
        assert!(w.at(6, 22, 10, 0).is_none());
    }

    #[test]
    fn errors_name_the_line_and_field() {
        let e = Weather::parse(&format!("{HEAD}{}", rec(11, "abc", "120"))).unwrap_err();
        assert_eq!(e.line, 9);
        assert!(
            e.message.contains("field 15 (direct normal irradiance)"),
            "{e}"
        );
        let e = Weather::parse(&format!("{HEAD}{}", rec(11, "-5", "120"))).unwrap_err();
        assert!(e.message.contains("negative"), "{e}");
        let e = Weather::parse(&format!("{HEAD}{}", rec(25, "5", "120"))).unwrap_err();
        assert!(e.message.contains("hour"), "{e}");
        let e = Weather::parse(&format!("{HEAD}1995,6,21\n")).unwrap_err();
        assert!(e.message.contains("3 fields"), "{e}");
        let e = Weather::parse("DESIGN,1\n").unwrap_err();
        assert_eq!(e.line, 1);
        assert!(Weather::parse(&HEAD.replace("45.73", "95")).is_err());
        assert!(Weather::parse(HEAD)
            .unwrap_err()
            .message
            .contains("no hourly records"));
        assert!(Weather::parse("").is_err());
    }
}
