//! From coefficients and a year of skies to hourly illuminances and metrics with intervals.
//!
//! An hour's illuminance at a receiver is, batch by batch, E_b = Σᵢ C_b,ᵢ L̄ᵢ + E_vn S_b (the sky
//! patches' coefficients times the hour's patch luminances, plus the hour's direct-normal
//! illuminance times the sun coefficient of its own sun position); its estimate is the mean
//! over the [`BATCHES`] batches and its standard error their spread.
//!
//! The metrics threshold these illuminances, so their errors do not propagate linearly. Their
//! intervals come from replicate years drawn from the batches by a Gaussian multiplier
//! bootstrap: a draw is E + c Σ_b g_b (E_b − E) with g_b standard normal, one set of g for the
//! whole year and every receiver (so the correlations between hours and points that the
//! shared coefficients carry are kept), c = t₀.₉₇₅,₁₅ / z₀.₉₇₅ / √(K (K − 1)) — the draws then
//! have the covariance of the mean, widened by the Student factor of the K − 1 = 15 degrees
//! of freedom its estimate has. Each metric's 95 % interval is the 2.5 % and 97.5 % quantile
//! of its values over the draws.

use super::coefficients::Coefficients;
use super::metrics::{
    annual_sunlight_exposure, daylight_provision, point_metrics, replicate_interval,
    spatial_daylight_autonomy, sun_hours, PointMetrics, Schedule, Thresholds,
};
use super::sun::SunCoefficients;
use super::year::HourSky;
use crate::meter::BATCHES;
use rayon::prelude::*;

/// z₀.₉₇₅.
const Z95: f64 = 1.959_963_984_540_054;

/// Hourly illuminances of every receiver: hour-major means (lx) and standard errors for the
/// whole year (0 at night), and the direct sun's (lx).
#[derive(Clone, Debug)]
pub struct Hourly {
    pub hours: usize,
    pub receivers: usize,
    /// `mean[h * receivers + r]`, lx.
    pub mean: Vec<f64>,
    pub stderr: Vec<f64>,
    /// Direct sunlight, lx.
    pub direct: Vec<f64>,
    /// Per daylight hour (index into the year) its batch values (f32 to halve the memory):
    /// `batches[(d * receivers + r) * BATCHES + b]` for the total, and the direct sun's.
    daylight: Vec<usize>,
    batches: Vec<f32>,
    direct_batches: Vec<f32>,
}

/// Bytes [`hourly`] holds for `hours` (of which `daylight` have light) × `receivers`.
pub fn hourly_bytes(hours: usize, daylight: usize, receivers: usize) -> u64 {
    let r = receivers as u64;
    3 * 8 * hours as u64 * r + 2 * 4 * daylight as u64 * r * BATCHES as u64
}

/// Combines sky coefficients, sun coefficients (one per hour with sun, in the order of
/// `year`'s such hours) and the year's skies into hourly illuminances.
pub fn hourly(sky: &Coefficients, sun: &SunCoefficients, year: &[HourSky]) -> Hourly {
    let k = BATCHES as usize;
    let n_r = sky.receivers;
    let n_p = sky.patches.len();
    let daylight: Vec<usize> = (0..year.len()).filter(|&h| year[h].is_daylight()).collect();
    // Index of each hour's sun in `sun`, in the order of the year's sunny hours.
    let mut sun_index = vec![usize::MAX; year.len()];
    for (i, h) in (0..year.len()).filter(|&h| year[h].has_sun()).enumerate() {
        sun_index[h] = i;
    }
    // Per daylight hour: every receiver's batches.
    let rows: Vec<(Vec<f32>, Vec<f32>)> = daylight
        .par_iter()
        .map(|&h| {
            let hs = &year[h];
            let l = &hs.sky.luminance_cd_m2;
            let mut tot = vec![0f32; n_r * k];
            let mut dir = vec![0f32; n_r * k];
            for r in 0..n_r {
                for b in 0..k {
                    let row = &sky.batches[(r * k + b) * n_p..(r * k + b + 1) * n_p];
                    let e: f64 = row.iter().zip(l).map(|(c, l)| c * l).sum();
                    tot[r * k + b] = e as f32;
                }
                if sun_index[h] != usize::MAX {
                    let (t, d) = sun.batches(sun_index[h], r);
                    let evn = hs.sky.direct_normal_lx;
                    for b in 0..k {
                        tot[r * k + b] += (evn * t[b]) as f32;
                        dir[r * k + b] = (evn * d[b]) as f32;
                    }
                }
            }
            (tot, dir)
        })
        .collect();
    let mut out = Hourly {
        hours: year.len(),
        receivers: n_r,
        mean: vec![0.0; year.len() * n_r],
        stderr: vec![0.0; year.len() * n_r],
        direct: vec![0.0; year.len() * n_r],
        daylight,
        batches: Vec::with_capacity(rows.len() * n_r * k),
        direct_batches: Vec::with_capacity(rows.len() * n_r * k),
    };
    for (d, (tot, dir)) in rows.into_iter().enumerate() {
        let h = out.daylight[d];
        for r in 0..n_r {
            let (m, se) = mean_se(&tot[r * k..(r + 1) * k]);
            out.mean[h * n_r + r] = m;
            out.stderr[h * n_r + r] = se;
            out.direct[h * n_r + r] = mean_se(&dir[r * k..(r + 1) * k]).0;
        }
        out.batches.extend(tot);
        out.direct_batches.extend(dir);
    }
    out
}

fn mean_se(b: &[f32]) -> (f64, f64) {
    let k = b.len() as f64;
    let m = b.iter().map(|&v| v as f64).sum::<f64>() / k;
    let var = b.iter().map(|&v| (v as f64 - m).powi(2)).sum::<f64>() / (k - 1.0);
    (m, (var / k).sqrt())
}

impl Hourly {
    /// One replicate year (see the module's description) from the multipliers `g`
    /// ([`BATCHES`] of them), into `e` and `direct` (hour-major, the whole year).
    pub fn draw(&self, g: &[f64], e: &mut [f64], direct: &mut [f64]) {
        let k = BATCHES as usize;
        let c = crate::sampling::t95(BATCHES - 1) / Z95 / ((k * (k - 1)) as f64).sqrt();
        e.fill(0.0);
        direct.fill(0.0);
        let n_r = self.receivers;
        for (d, &h) in self.daylight.iter().enumerate() {
            for r in 0..n_r {
                let i = h * n_r + r;
                let j = (d * n_r + r) * k;
                let (m, md) = (self.mean[i], self.direct[i]);
                let (mut s, mut sd) = (0.0, 0.0);
                for (b, gb) in g.iter().enumerate().take(k) {
                    s += gb * (self.batches[j + b] as f64 - m);
                    sd += gb * (self.direct_batches[j + b] as f64 - md);
                }
                e[i] = m + c * s;
                direct[i] = md + c * sd;
            }
        }
    }
}

/// A value and its 95 % interval (`None` when there are too few draws).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Estimate {
    pub value: f64,
    pub ci95: Option<(f64, f64)>,
}

/// Per point: DA, cDA, UDI (fractions 0–1) and hours of direct sun above the ASE threshold.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct PointResult {
    pub da: Estimate,
    pub cda: Estimate,
    pub udi_below: Estimate,
    pub udi_useful: Estimate,
    pub udi_above: Estimate,
    pub sun_hours: Estimate,
}

/// Per grid: sDA, ASE (fractions of the points) and EN 17037's daylight provision (fractions
/// of the daylight hours in which the target, or the minimum target, is reached over its
/// share of the plane).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct GridResult {
    pub sda: Estimate,
    pub ase: Estimate,
    pub en17037_target: Estimate,
    pub en17037_minimum: Estimate,
    pub points: Vec<PointResult>,
}

/// EN 17037's levels: target 300 lx over 50 % of the plane, minimum target 100 lx over 95 %.
pub const EN17037_TARGET: (f64, f64) = (300.0, 0.5);
pub const EN17037_MINIMUM: (f64, f64) = (100.0, 0.95);

struct Values {
    /// Per point: [da, cda, udi below, useful, above, sun hours].
    points: Vec<[f64; 6]>,
    /// sda, ase, target, minimum.
    grid: [f64; 4],
}

#[allow(clippy::too_many_arguments)]
fn values(
    e: &[f64],
    direct: &[f64],
    range: std::ops::Range<usize>,
    n_r: usize,
    occupied: &Schedule,
    daylight: &Schedule,
    t: &Thresholds,
    scratch: &mut Vec<f64>,
) -> Values {
    // The grid's own columns, hour-major.
    let n = range.len();
    let hours = e.len() / n_r;
    let sub = |src: &[f64], out: &mut Vec<f64>| {
        out.clear();
        for h in 0..hours {
            out.extend_from_slice(&src[h * n_r + range.start..h * n_r + range.end]);
        }
    };
    sub(e, scratch);
    let pm: Vec<PointMetrics> = point_metrics(scratch, n, occupied, t);
    let sda = spatial_daylight_autonomy(&pm, t);
    let target = daylight_provision(scratch, n, daylight, EN17037_TARGET.0, EN17037_TARGET.1);
    let minimum = daylight_provision(scratch, n, daylight, EN17037_MINIMUM.0, EN17037_MINIMUM.1);
    sub(direct, scratch);
    let sh = sun_hours(scratch, n, occupied, t);
    let ase = annual_sunlight_exposure(&sh, t);
    Values {
        points: pm
            .iter()
            .zip(&sh)
            .map(|(m, &s)| [m.da, m.cda, m.udi.below, m.udi.useful, m.udi.above, s])
            .collect(),
        grid: [sda, ase, target, minimum],
    }
}

/// Standard normal multipliers for draw `d`: a fixed hash of (`seed`, d, b) through the
/// inverse error function, so the intervals are reproducible.
pub(super) fn multipliers(seed: u64, d: usize) -> Vec<f64> {
    (0..BATCHES as u64)
        .map(|b| {
            let x = crate::sampling::mix64(seed ^ crate::sampling::mix64(((d as u64) << 8) | b));
            let u = ((x >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
            std::f64::consts::SQRT_2 * crate::sampling::special::erf_inv(2.0 * u - 1.0)
        })
        .collect()
}

/// The metrics of each grid (`grids`: ranges of receivers) from the mean year, with 95 %
/// intervals from `draws` replicate years.
pub fn metrics(
    hourly: &Hourly,
    grids: &[std::ops::Range<usize>],
    occupied: &Schedule,
    daylight: &Schedule,
    t: &Thresholds,
    draws: usize,
    seed: u64,
) -> Vec<GridResult> {
    let n_r = hourly.receivers;
    let mut scratch = Vec::new();
    let mean: Vec<Values> = grids
        .iter()
        .map(|g| {
            values(
                &hourly.mean,
                &hourly.direct,
                g.clone(),
                n_r,
                occupied,
                daylight,
                t,
                &mut scratch,
            )
        })
        .collect();
    let replicates: Vec<Vec<Values>> = (0..draws)
        .into_par_iter()
        .map_init(
            || {
                (
                    vec![0.0; hourly.mean.len()],
                    vec![0.0; hourly.mean.len()],
                    Vec::new(),
                )
            },
            |(e, dir, scratch), d| {
                hourly.draw(&multipliers(seed, d), e, dir);
                grids
                    .iter()
                    .map(|g| values(e, dir, g.clone(), n_r, occupied, daylight, t, scratch))
                    .collect()
            },
        )
        .collect();
    let est = |value: f64, pick: &dyn Fn(&Vec<Values>) -> f64| {
        let mut v: Vec<f64> = replicates.iter().map(pick).collect();
        Estimate {
            value,
            ci95: replicate_interval(&mut v),
        }
    };
    mean.iter()
        .enumerate()
        .map(|(gi, m)| {
            let points = (0..m.points.len())
                .map(|p| {
                    let f = |q: usize| est(m.points[p][q], &|r: &Vec<Values>| r[gi].points[p][q]);
                    PointResult {
                        da: f(0),
                        cda: f(1),
                        udi_below: f(2),
                        udi_useful: f(3),
                        udi_above: f(4),
                        sun_hours: f(5),
                    }
                })
                .collect();
            let f = |q: usize| est(m.grid[q], &|r: &Vec<Values>| r[gi].grid[q]);
            GridResult {
                sda: f(0),
                ase: f(1),
                en17037_target: f(2),
                en17037_minimum: f(3),
                points,
            }
        })
        .collect()
}
