//! Pixel reconstruction filters.

use crate::description::context::{Context, SceneError};
use crate::description::schema::FilterDesc;
use glam::Vec2;

/// Pixel reconstruction filter. Samples are drawn from the filter itself (filter importance
/// sampling), so every sample carries weight 1 and belongs to exactly one pixel; the per-pixel
/// mean and sample variance are then those of independent, identically weighted samples.
#[derive(Clone, Debug, PartialEq)]
pub enum PixelFilter {
    /// Uniform over the pixel square (half-width 0.5 px): the pixel's value is the average
    /// radiance over its footprint.
    Box,
    /// Tent (triangle) of the given radius in pixels.
    Tent { radius: f32 },
    /// Gaussian of standard deviation `sigma` px truncated at `radius` px.
    Gaussian {
        sigma: f32,
        radius: f32,
        table: GaussianTable,
    },
}

/// Inverse CDF of a truncated Gaussian, tabulated.
#[derive(Clone, Debug, PartialEq)]
pub struct GaussianTable {
    inv_cdf: Vec<f32>,
    /// ∫ exp(−x²/2σ²) dx over [−radius, radius] (the 1-D normalisation of the density).
    norm: f32,
}

impl GaussianTable {
    fn new(sigma: f32, radius: f32) -> Self {
        const N: usize = 1024;
        // Tabulate the CDF on a fine grid, then invert at equally spaced probabilities.
        let m = 8192;
        let xs: Vec<f64> = (0..=m)
            .map(|i| -radius as f64 + 2.0 * radius as f64 * i as f64 / m as f64)
            .collect();
        let f = |x: f64| (-(x * x) / (2.0 * (sigma as f64).powi(2))).exp();
        let mut cdf = vec![0.0f64; m + 1];
        for i in 1..=m {
            cdf[i] = cdf[i - 1] + 0.5 * (f(xs[i - 1]) + f(xs[i])) * (xs[i] - xs[i - 1]);
        }
        let total = cdf[m];
        let mut inv_cdf = Vec::with_capacity(N + 1);
        let mut j = 0;
        for k in 0..=N {
            let p = total * k as f64 / N as f64;
            while j < m - 1 && cdf[j + 1] < p {
                j += 1;
            }
            let t = if cdf[j + 1] > cdf[j] {
                ((p - cdf[j]) / (cdf[j + 1] - cdf[j])).clamp(0.0, 1.0)
            } else {
                0.0
            };
            inv_cdf.push((xs[j] + t * (xs[j + 1] - xs[j])) as f32);
        }
        Self {
            inv_cdf,
            norm: total as f32,
        }
    }
    fn sample(&self, u: f32) -> f32 {
        let n = self.inv_cdf.len() - 1;
        let x = u * n as f32;
        let i = (x as usize).min(n - 1);
        let t = x - i as f32;
        self.inv_cdf[i] * (1.0 - t) + self.inv_cdf[i + 1] * t
    }
}

impl PixelFilter {
    /// The filter of `render.filter` from its description (radius and sigma in pixels).
    pub fn build(ctx: &Context, desc: &FilterDesc) -> Result<Self, SceneError> {
        Ok(match *desc {
            FilterDesc::Box => PixelFilter::Box,
            FilterDesc::Tent { radius } => PixelFilter::Tent {
                radius: ctx.positive("render.filter.radius", radius as f64)? as f32,
            },
            FilterDesc::Gaussian { sigma, radius } => PixelFilter::gaussian(
                ctx.positive("render.filter.sigma", sigma as f64)? as f32,
                ctx.positive("render.filter.radius", radius as f64)? as f32,
            ),
        })
    }

    pub fn gaussian(sigma: f32, radius: f32) -> Self {
        PixelFilter::Gaussian {
            sigma,
            radius,
            table: GaussianTable::new(sigma, radius),
        }
    }

    /// Half-width of the filter's support, pixels.
    pub fn radius(&self) -> f32 {
        match self {
            PixelFilter::Box => 0.5,
            PixelFilter::Tent { radius } | PixelFilter::Gaussian { radius, .. } => *radius,
        }
    }

    /// The density (px⁻², integrating to 1) with which [`Self::sample`] draws offset `d` from
    /// the pixel centre: the weight of a film point at `d` in that pixel's value.
    pub fn density(&self, d: Vec2) -> f32 {
        let r = self.radius();
        if d.x.abs() > r || d.y.abs() > r {
            return 0.0;
        }
        match self {
            // The half-open pixel square [−½, ½)², as `sample` produces.
            PixelFilter::Box => {
                if d.x < 0.5 && d.y < 0.5 {
                    1.0
                } else {
                    0.0
                }
            }
            PixelFilter::Tent { radius } => {
                let t = |x: f32| (1.0 - x.abs() / radius) / radius;
                t(d.x) * t(d.y)
            }
            PixelFilter::Gaussian { sigma, table, .. } => {
                let g = |x: f32| (-(x * x) / (2.0 * sigma * sigma)).exp() / table.norm;
                g(d.x) * g(d.y)
            }
        }
    }

    /// Offset from the pixel centre, in pixels, distributed as the filter.
    pub fn sample(&self, u: Vec2) -> Vec2 {
        match self {
            PixelFilter::Box => u - Vec2::splat(0.5),
            PixelFilter::Tent { radius } => {
                let tent = |u: f32| {
                    if u < 0.5 {
                        -radius * (1.0 - (2.0 * u).sqrt())
                    } else {
                        radius * (1.0 - (2.0 - 2.0 * u).sqrt())
                    }
                };
                Vec2::new(tent(u.x), tent(u.y))
            }
            PixelFilter::Gaussian { table, .. } => Vec2::new(table.sample(u.x), table.sample(u.y)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaussian_filter_sample_has_right_spread() {
        let f = PixelFilter::gaussian(0.5, 1.5);
        let n = 20_000;
        let var: f32 = (0..n)
            .map(|i| {
                f.sample(Vec2::new((i as f32 + 0.5) / n as f32, 0.5))
                    .x
                    .powi(2)
            })
            .sum::<f32>()
            / n as f32;
        // Truncation at 3σ reduces the variance by ~2.7 %.
        assert!((var.sqrt() - 0.5).abs() < 0.01, "σ = {}", var.sqrt());
    }

    #[test]
    fn filter_densities_integrate_to_one_and_match_their_samples() {
        for f in [
            PixelFilter::Box,
            PixelFilter::Tent { radius: 1.5 },
            PixelFilter::gaussian(0.5, 1.5),
        ] {
            let r = f.radius();
            let n = 600;
            let h = 2.0 * r / n as f32;
            let mut total = 0.0f64;
            let mut second = 0.0f64;
            for j in 0..n {
                for i in 0..n {
                    let d = Vec2::new(-r + (i as f32 + 0.5) * h, -r + (j as f32 + 0.5) * h);
                    let w = (f.density(d) * h * h) as f64;
                    total += w;
                    second += w * (d.x * d.x) as f64;
                }
            }
            assert!((total - 1.0).abs() < 2e-3, "{f:?}: ∫ = {total}");
            // E[x²] of the samples equals the density's.
            let m = 4000;
            let s: f64 = (0..m)
                .map(|i| (f.sample(Vec2::new((i as f32 + 0.5) / m as f32, 0.5)).x as f64).powi(2))
                .sum::<f64>()
                / m as f64;
            assert!(
                (s - second).abs() < 2e-3 * (1.0 + second),
                "{f:?}: {s} vs {second}"
            );
        }
    }
}
