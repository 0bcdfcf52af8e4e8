//! The colour scale: linear or log mapping of values (display units) to a palette's colours,
//! its automatic range, bands and legend ticks.

use super::FalsecolourSettings;

/// Linear or logarithmic mapping of values to colours.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Scale {
    /// Colour position proportional to the value.
    #[default]
    Linear,
    /// Colour position proportional to log(value); values ≤ 0 take the lowest colour.
    Log,
}

impl Scale {
    /// `"linear"` or `"log"`.
    pub fn name(self) -> &'static str {
        match self {
            Scale::Linear => "linear",
            Scale::Log => "log",
        }
    }

    /// Parses `linear`/`lin` or `log`/`logarithmic`.
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "linear" | "lin" => Some(Scale::Linear),
            "log" | "logarithmic" => Some(Scale::Log),
            _ => None,
        }
    }
}

/// Colour map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Palette {
    /// Google's Turbo: an improved rainbow, dark blue → green → yellow → dark red; the look of
    /// lighting-design software, with monotonic lightness on each half.
    #[default]
    Turbo,
    /// Matplotlib's viridis: perceptually uniform, dark violet → yellow, colour-blind safe.
    Viridis,
}

impl Palette {
    /// `"turbo"` or `"viridis"`.
    pub fn name(self) -> &'static str {
        match self {
            Palette::Turbo => "turbo",
            Palette::Viridis => "viridis",
        }
    }

    /// Parses `turbo` or `viridis`.
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "turbo" => Some(Palette::Turbo),
            "viridis" => Some(Palette::Viridis),
            _ => None,
        }
    }

    /// The colour at position `t` ∈ [0, 1] (clamped).
    pub fn eval(self, t: f64) -> [u8; 3] {
        let g = match self {
            Palette::Turbo => colorous::TURBO,
            Palette::Viridis => colorous::VIRIDIS,
        };
        let c = g.eval_continuous(t.clamp(0.0, 1.0));
        [c.r, c.g, c.b]
    }
}

/// A resolved colour scale: value (display units) → colour.
#[derive(Clone, Debug, PartialEq)]
pub struct ColourScale {
    /// Linear or log.
    pub scale: Scale,
    /// Value at the bottom of the legend (display units); > 0 for a log scale.
    pub min: f64,
    /// Value at the top of the legend (display units); > `min`.
    pub max: f64,
    /// Number of bands, or `None` for a continuous scale.
    pub steps: Option<usize>,
    /// Colour map.
    pub palette: Palette,
    /// Legend tick values, ascending, from `min` to `max` inclusive. For a banded scale these
    /// are exactly the `steps + 1` step boundaries.
    pub ticks: Vec<f64>,
}

impl ColourScale {
    /// Resolves `settings` against the data `values` (display units; the defined pixels or
    /// grid points only).
    ///
    /// Automatic range (documented in docs/reports.md):
    /// * linear: min = 0 (or the 1st percentile rounded down, if that is negative), max = the
    ///   99th percentile rounded up so that the interval per step ((max − min)/N, N = the
    ///   steps, or 10 for a continuous scale) is a "nice" number (1, 1.2, 1.5, 2, 2.5, 3, 4,
    ///   5, 6, 8 × 10ᵏ);
    /// * log: whole decades around the 1st and 99th percentiles of the positive values, at most
    ///   six decades below the top.
    ///
    /// Errors describe the bad setting (min ≥ max, log scale with min ≤ 0, non-finite).
    pub fn resolve(settings: &FalsecolourSettings, values: &[f64]) -> Result<ColourScale, String> {
        for (name, v) in [("minimum", settings.min), ("maximum", settings.max)] {
            if let Some(v) = v {
                if !v.is_finite() {
                    return Err(format!("range {name} {v} is not a finite number"));
                }
            }
        }
        let steps = settings.steps.filter(|&n| n > 0);
        if let Some(n) = steps {
            if n > 1000 {
                return Err(format!("--steps {n} is too many (at most 1000)"));
            }
        }
        let mut finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
        finite.sort_unstable_by(f64::total_cmp);
        let (min, max) = match settings.scale {
            Scale::Linear => {
                let auto_min = || {
                    let p1 = percentile(&finite, 0.01).unwrap_or(0.0);
                    if p1 < 0.0 {
                        -nice_ceil(-p1)
                    } else {
                        0.0
                    }
                };
                let min = settings.min.unwrap_or_else(auto_min);
                let max = settings.max.unwrap_or_else(|| {
                    let p99 = percentile(&finite, 0.99).unwrap_or(1.0);
                    if p99 > min {
                        // A nice interval per step (or per tenth), so that the legend's
                        // values are round numbers.
                        let n = steps.unwrap_or(10) as f64;
                        min + n * nice_ceil((p99 - min) / n)
                    } else {
                        min + 1.0
                    }
                });
                (min, max)
            }
            Scale::Log => {
                let positive: Vec<f64> = finite.iter().copied().filter(|&v| v > 0.0).collect();
                let max = settings.max.unwrap_or_else(|| {
                    let hi = percentile(&positive, 0.99).unwrap_or(1.0);
                    let mut m = 10f64.powf(hi.log10().ceil());
                    if let Some(lo) = settings.min {
                        if m <= lo {
                            m = lo * 10.0;
                        }
                    }
                    m
                });
                let min = settings.min.unwrap_or_else(|| {
                    let lo = percentile(&positive, 0.01).unwrap_or(max / 10.0);
                    let m = 10f64.powf(lo.log10().floor()).max(max * 1e-6);
                    if m >= max {
                        max / 10.0
                    } else {
                        m
                    }
                });
                if min <= 0.0 {
                    return Err(format!(
                        "a logarithmic scale needs a positive minimum, got {min}"
                    ));
                }
                (min, max)
            }
        };
        if min >= max || !(max - min).is_finite() {
            return Err(format!(
                "the range minimum ({min}) must be below the maximum ({max})"
            ));
        }
        let ticks = match steps {
            Some(n) => (0..=n)
                .map(|k| match settings.scale {
                    Scale::Linear => min + (max - min) * k as f64 / n as f64,
                    Scale::Log => min * (max / min).powf(k as f64 / n as f64),
                })
                .map(|v| snap(v, min, max))
                .collect(),
            None => match settings.scale {
                Scale::Linear => (0..=10)
                    .map(|k| snap(min + (max - min) * k as f64 / 10.0, min, max))
                    .collect(),
                Scale::Log => log_ticks(min, max),
            },
        };
        Ok(ColourScale {
            scale: settings.scale,
            min,
            max,
            steps,
            palette: settings.palette,
            ticks,
        })
    }

    /// Position of `v` on the scale, 0 (min) … 1 (max), clamped. NaN and (log) v ≤ 0 give 0.
    pub fn position(&self, v: f64) -> f64 {
        let t = match self.scale {
            Scale::Linear => (v - self.min) / (self.max - self.min),
            Scale::Log => {
                if v > 0.0 {
                    (v / self.min).ln() / (self.max / self.min).ln()
                } else {
                    0.0
                }
            }
        };
        if t.is_nan() {
            0.0
        } else {
            t.clamp(0.0, 1.0)
        }
    }

    /// The band `v` falls in: `k` such that `ticks[k] ≤ v < ticks[k + 1]` (values below the
    /// range give 0, values at or above the top give `steps − 1`). `None` for a continuous
    /// scale.
    pub fn step_of(&self, v: f64) -> Option<usize> {
        let n = self.steps?;
        // Compare with the boundaries themselves so that the legend and the map agree exactly.
        let k = self.ticks[1..n].iter().take_while(|&&b| v >= b).count();
        Some(k)
    }

    /// Colour of band `k` (banded scales): the palette at the band's middle.
    pub fn step_colour(&self, k: usize) -> [u8; 3] {
        let n = self.steps.unwrap_or(1).max(1);
        self.palette.eval((k as f64 + 0.5) / n as f64)
    }

    /// The colour `v` is painted with.
    pub fn colour(&self, v: f64) -> [u8; 3] {
        match self.step_of(v) {
            Some(k) => self.step_colour(k),
            None => self.palette.eval(self.position(v)),
        }
    }

    /// The contour class of `v`: how many interior ticks are ≤ `v`. Contour lines are drawn
    /// between neighbouring pixels of different classes.
    pub fn contour_class(&self, v: f64) -> usize {
        let n = self.ticks.len();
        if n < 3 {
            return 0;
        }
        self.ticks[1..n - 1].iter().take_while(|&&b| v >= b).count()
    }
}

/// Removes floating-point fuzz from computed tick values (e.g. 299.99999999999994 → 300) and
/// pins the ends to exactly `min` and `max`.
fn snap(v: f64, min: f64, max: f64) -> f64 {
    if (v - min).abs() <= 1e-12 * max.abs().max(min.abs()) {
        return min;
    }
    if (v - max).abs() <= 1e-12 * max.abs().max(min.abs()) {
        return max;
    }
    let r: f64 = format!("{v:.12e}").parse().unwrap_or(v);
    r
}

/// Ticks for a continuous log scale: 1-2-5 per decade when the range spans at most three
/// decades, else decades; plus both ends.
fn log_ticks(min: f64, max: f64) -> Vec<f64> {
    let decades = (max / min).log10();
    let mults: &[f64] = if decades <= 3.0 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    let mut ticks = vec![min];
    let mut e = min.log10().floor() as i32;
    // Decades past 10^308 are infinite: the bound ends the loop for a range up to f64::MAX.
    while e <= f64::MAX_10_EXP && 10f64.powi(e) <= max * 1.000001 {
        for m in mults {
            let v: f64 = format!("{:.12e}", m * 10f64.powi(e)).parse().unwrap_or(0.0);
            let last = *ticks.last().unwrap_or(&min);
            if v > min * 1.000001 && v < max / 1.000001 && v > last {
                ticks.push(v);
            }
        }
        e += 1;
    }
    ticks.push(max);
    ticks
}

/// The `q` quantile (0..1) of sorted data, nearest-rank; `None` if empty.
fn percentile(sorted: &[f64], q: f64) -> Option<f64> {
    if sorted.is_empty() {
        return None;
    }
    let i = ((sorted.len() - 1) as f64 * q).round() as usize;
    Some(sorted[i.min(sorted.len() - 1)])
}

/// The smallest "nice" number ≥ `v` (> 0): 1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10ᵏ.
pub fn nice_ceil(v: f64) -> f64 {
    if v.is_nan() || v <= 0.0 || !v.is_finite() {
        return 1.0;
    }
    let e = v.log10().floor();
    let base = 10f64.powf(e);
    for m in [1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0] {
        let c: f64 = format!("{:.12e}", m * base).parse().unwrap_or(m * base);
        if c >= v * (1.0 - 1e-12) {
            return c;
        }
    }
    10.0 * base
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A log range up to the largest f64 ends, with finite increasing ticks and both ends.
    #[test]
    fn log_ticks_of_the_widest_range_end() {
        for (lo, hi) in [
            (1.0, f64::MAX),
            (f64::MIN_POSITIVE, f64::MAX),
            (1e300, 1.797e308),
        ] {
            let t = log_ticks(lo, hi);
            assert_eq!((t[0], *t.last().unwrap()), (lo, hi));
            assert!(
                t.windows(2).all(|w| w[0] < w[1] && w[1].is_finite()),
                "{t:?}"
            );
        }
    }

    #[test]
    fn banded_steps_and_nice_automatic_maximum() {
        let values: Vec<f64> = (0..=100).map(|i| i as f64 * 0.22).collect();
        let s = FalsecolourSettings {
            steps: Some(8),
            ..Default::default()
        };
        let cs = ColourScale::resolve(&s, &values).unwrap();
        // 99th percentile 21.8 → 8 steps of 3.
        assert_eq!(cs.max, 24.0);
        assert_eq!(cs.ticks[1], 3.0);
        assert_eq!(cs.step_of(2.99), Some(0));
        assert_eq!(cs.step_of(3.0), Some(1));
        assert_eq!(cs.step_of(-5.0), Some(0));
        assert_eq!(cs.step_of(1e9), Some(7));
        assert_eq!(cs.colour(1e9), cs.step_colour(7));
    }

    #[test]
    fn nice_numbers() {
        assert_eq!(nice_ceil(437.0), 500.0);
        assert_eq!(nice_ceil(500.0), 500.0);
        assert_eq!(nice_ceil(0.0123), 0.015);
        assert_eq!(nice_ceil(101.0), 120.0);
    }

    #[test]
    fn log_ticks_are_decades_and_125() {
        assert_eq!(
            log_ticks(1.0, 100.0),
            vec![1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0]
        );
        assert_eq!(
            log_ticks(0.01, 1e4),
            vec![0.01, 0.1, 1.0, 10.0, 100.0, 1000.0, 1e4]
        );
    }

    #[test]
    fn automatic_ranges() {
        let values: Vec<f64> = (0..1000).map(|i| i as f64 * 0.437).collect();
        let s = FalsecolourSettings::default();
        let cs = ColourScale::resolve(&s, &values).unwrap();
        assert_eq!((cs.min, cs.max), (0.0, 500.0));
        let s = FalsecolourSettings {
            scale: Scale::Log,
            ..Default::default()
        };
        let cs = ColourScale::resolve(&s, &values).unwrap();
        assert_eq!((cs.min, cs.max), (1.0, 1000.0));
        let bad = FalsecolourSettings {
            scale: Scale::Log,
            min: Some(0.0),
            ..Default::default()
        };
        assert!(ColourScale::resolve(&bad, &values).is_err());
    }
}
