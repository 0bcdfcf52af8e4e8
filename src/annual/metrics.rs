//! Climate-based daylight metrics from hourly illuminances on a grid of points.
//!
//! Per point, over the occupied hours: daylight autonomy DA(E) (the fraction of hours with
//! E ≥ the threshold), continuous daylight autonomy cDA (hours below the threshold earn E/E_th),
//! useful daylight illuminance UDI (the fractions below, within and above a useful band), and
//! the hours of direct sunlight above a threshold. Per grid: spatial daylight autonomy
//! sDA_{E,f} (the fraction of points whose DA(E) ≥ f; IES LM-83 sDA300/50%), annual sunlight
//! exposure ASE_{E,h} (the fraction of points with more than h hours of direct sunlight above E;
//! LM-83 ASE1000,250h), and EN 17037's daylight provision (the fraction of hours in which at
//! least a given fraction of the points reach a target).
//!
//! Illuminances are lux. Arrays are hour-major: `e[h * points + p]`.

/// The hours (of a year of 8760) a metric counts: occupied hours for DA/UDI/sDA/ASE, daylight
/// hours for EN 17037.
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    /// Indices of the counted hours.
    pub hours: Vec<usize>,
}

impl Schedule {
    /// Every day of a year of `days` days, the hours starting at `from` … `to` − 1 (local
    /// standard time; LM-83's occupied hours are 8 to 18, 3650 hours a year).
    pub fn daily(days: usize, from: usize, to: usize) -> Self {
        let hours = (0..days)
            .flat_map(|d| (from.min(24)..to.min(24)).map(move |h| d * 24 + h))
            .collect();
        Self { hours }
    }
}

/// Useful daylight illuminance: the fractions of counted hours below `low`, from `low` to
/// `high`, and above `high` (lx; the usual band is 100–3000).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Udi {
    pub below: f64,
    pub useful: f64,
    pub above: f64,
}

/// Per-point metrics.
#[derive(Clone, Debug, PartialEq)]
pub struct PointMetrics {
    /// Daylight autonomy, fraction 0–1.
    pub da: f64,
    /// Continuous daylight autonomy, fraction 0–1.
    pub cda: f64,
    pub udi: Udi,
}

/// The thresholds of the metrics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thresholds {
    /// DA/cDA/sDA threshold, lx (LM-83: 300).
    pub da_lx: f64,
    /// sDA: the fraction of hours a point must reach `da_lx` (LM-83: 0.5).
    pub sda_fraction: f64,
    /// UDI band, lx (100, 3000).
    pub udi_lx: (f64, f64),
    /// ASE: direct-sun illuminance, lx (LM-83: 1000), and hours (250).
    pub ase_lx: f64,
    pub ase_hours: f64,
}

impl Default for Thresholds {
    fn default() -> Self {
        Self {
            da_lx: 300.0,
            sda_fraction: 0.5,
            udi_lx: (100.0, 3000.0),
            ase_lx: 1000.0,
            ase_hours: 250.0,
        }
    }
}

/// DA, cDA and UDI of every point of hourly illuminances `e` (hour-major, `points` per hour)
/// over the schedule's hours.
pub fn point_metrics(
    e: &[f64],
    points: usize,
    schedule: &Schedule,
    t: &Thresholds,
) -> Vec<PointMetrics> {
    let n = schedule.hours.len().max(1) as f64;
    (0..points)
        .map(|p| {
            let (mut da, mut cda, mut below, mut useful, mut above) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for &h in &schedule.hours {
                let v = e[h * points + p];
                if v >= t.da_lx {
                    da += 1.0;
                    cda += 1.0;
                } else {
                    cda += (v / t.da_lx).max(0.0);
                }
                if v < t.udi_lx.0 {
                    below += 1.0;
                } else if v <= t.udi_lx.1 {
                    useful += 1.0;
                } else {
                    above += 1.0;
                }
            }
            PointMetrics {
                da: da / n,
                cda: cda / n,
                udi: Udi {
                    below: below / n,
                    useful: useful / n,
                    above: above / n,
                },
            }
        })
        .collect()
}

/// sDA: the fraction of points whose DA reaches `t.sda_fraction`.
pub fn spatial_daylight_autonomy(points: &[PointMetrics], t: &Thresholds) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    points.iter().filter(|m| m.da >= t.sda_fraction).count() as f64 / points.len() as f64
}

/// Hours of direct sunlight above `t.ase_lx` at each point, from the direct-sun illuminances
/// `sun` (hour-major), over the schedule's hours.
pub fn sun_hours(sun: &[f64], points: usize, schedule: &Schedule, t: &Thresholds) -> Vec<f64> {
    (0..points)
        .map(|p| {
            schedule
                .hours
                .iter()
                .filter(|&&h| sun[h * points + p] > t.ase_lx)
                .count() as f64
        })
        .collect()
}

/// ASE: the fraction of points with more than `t.ase_hours` hours of direct sunlight above
/// `t.ase_lx`.
pub fn annual_sunlight_exposure(sun_hours: &[f64], t: &Thresholds) -> f64 {
    if sun_hours.is_empty() {
        return 0.0;
    }
    sun_hours.iter().filter(|&&h| h > t.ase_hours).count() as f64 / sun_hours.len() as f64
}

/// EN 17037 daylight provision: the fraction of the schedule's hours (its daylight hours) in
/// which at least `plane_fraction` of the points reach `target_lx` (target level: 300 lx over
/// 50 % of the plane; minimum target: 100 lx over 95 %; met when the result is ≥ 0.5).
pub fn daylight_provision(
    e: &[f64],
    points: usize,
    schedule: &Schedule,
    target_lx: f64,
    plane_fraction: f64,
) -> f64 {
    if points == 0 || schedule.hours.is_empty() {
        return 0.0;
    }
    let met = schedule
        .hours
        .iter()
        .filter(|&&h| {
            let lit = e[h * points..(h + 1) * points]
                .iter()
                .filter(|&&v| v >= target_lx)
                .count();
            lit as f64 >= plane_fraction * points as f64
        })
        .count();
    met as f64 / schedule.hours.len() as f64
}

/// A 95 % interval of a metric from its values over replicate years (each computed from one
/// draw of the daylight coefficients within their errors): the 2.5 % and 97.5 % quantiles
/// (linear interpolation between order statistics).
pub fn replicate_interval(values: &mut [f64]) -> Option<(f64, f64)> {
    if values.len() < 2 || values.iter().any(|v| v.is_nan()) {
        return None;
    }
    values.sort_by(|a, b| a.total_cmp(b));
    let q = |p: f64| {
        let x = p * (values.len() - 1) as f64;
        let (i, f) = (x.floor() as usize, x.fract());
        let j = (i + 1).min(values.len() - 1);
        values[i] * (1.0 - f) + values[j] * f
    };
    Some((q(0.025), q(0.975)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn occupied_hours_of_a_year() {
        let s = Schedule::daily(365, 8, 18);
        assert_eq!(s.hours.len(), 3650);
        assert_eq!(s.hours[0], 8);
        assert_eq!(*s.hours.last().unwrap(), 364 * 24 + 17);
    }

    /// Closed forms: a point lit by E = k·100 lx at hour k of each day has, over hours 8–17,
    /// 800 … 1700 lx: DA300 = 1, UDI useful = 1; a point at a tenth of that (80 … 170 lx) has
    /// DA300 = 0, cDA = mean(E)/300 = 125/300, UDI below 100 = 2/10 (80, 90).
    #[test]
    fn point_metrics_closed_forms() {
        let days = 3;
        let points = 2;
        let mut e = vec![0.0; days * 24 * points];
        for h in 0..days * 24 {
            let k = (h % 24) as f64;
            e[h * points] = 100.0 * k;
            e[h * points + 1] = 10.0 * k;
        }
        let s = Schedule::daily(days, 8, 18);
        let t = Thresholds::default();
        let m = point_metrics(&e, points, &s, &t);
        assert_eq!(m[0].da, 1.0);
        assert_eq!(m[0].udi.useful, 1.0);
        assert_eq!(m[1].da, 0.0);
        assert!((m[1].cda - 125.0 / 300.0).abs() < 1e-12);
        assert!((m[1].udi.below - 0.2).abs() < 1e-12);
        assert!((m[1].udi.useful - 0.8).abs() < 1e-12);
        assert_eq!(spatial_daylight_autonomy(&m, &t), 0.5);
        // Hour 10–17 of the bright point exceed 1000 lx (1100 … 1700): 7 hours a day.
        let hours = sun_hours(&e, points, &s, &t);
        assert_eq!(hours, vec![7.0 * days as f64, 0.0]);
        let t2 = Thresholds {
            ase_hours: 20.0,
            ..t
        };
        assert_eq!(annual_sunlight_exposure(&hours, &t2), 0.5);
        // Every hour, one point of two reaches 300 lx: provision over 50 % of the plane is met
        // every hour, over 95 % never.
        assert_eq!(daylight_provision(&e, points, &s, 300.0, 0.5), 1.0);
        assert_eq!(daylight_provision(&e, points, &s, 300.0, 0.95), 0.0);
    }

    #[test]
    fn replicate_quantiles() {
        let mut v: Vec<f64> = (0..=40).map(|i| i as f64).collect();
        let (lo, hi) = replicate_interval(&mut v).unwrap();
        assert!((lo - 1.0).abs() < 1e-12 && (hi - 39.0).abs() < 1e-12);
        assert!(replicate_interval(&mut [1.0]).is_none());
        assert!(replicate_interval(&mut [1.0, f64::NAN]).is_none());
    }
}
