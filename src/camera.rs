//! Perspective camera with an optional thin lens, and pixel reconstruction filters.
//!
//! The camera is a radiance meter: each pixel reports the filter-weighted average of the
//! radiance arriving along its rays, so a pixel's Y is luminance in cd/m² (no vignetting or
//! cos⁴ falloff, no exposure). Image rows run top to bottom.

use glam::{Vec2, Vec3};

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
        Self { inv_cdf }
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
    pub fn gaussian(sigma: f32, radius: f32) -> Self {
        PixelFilter::Gaussian {
            sigma,
            radius,
            table: GaussianTable::new(sigma, radius),
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

/// A camera ray (unit direction).
#[derive(Clone, Copy, Debug)]
pub struct CameraRay {
    pub origin: Vec3,
    pub dir: Vec3,
}

/// A thin lens: aperture radius and focus distance, metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    pub radius: f32,
    pub focus_distance: f32,
}

/// Pinhole or thin-lens perspective camera.
#[derive(Clone, Debug)]
pub struct Camera {
    pub position: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    tan_half_vfov: f32,
    pub width: usize,
    pub height: usize,
    /// Lens radius in metres (0 = pinhole).
    lens_radius: f32,
    /// Distance to the plane in focus, metres, along the view direction.
    focus_distance: f32,
}

impl Camera {
    /// `vfov_deg` is the full vertical field of view. `up` need not be orthogonal to the view
    /// direction but must not be parallel to it.
    pub fn new(
        position: Vec3,
        look_at: Vec3,
        up: Vec3,
        vfov_deg: f32,
        (width, height): (usize, usize),
        lens: Option<ThinLens>,
    ) -> Self {
        let ThinLens {
            radius: lens_radius,
            focus_distance,
        } = lens.unwrap_or(ThinLens {
            radius: 0.0,
            focus_distance: 1.0,
        });
        let forward = (look_at - position).normalize();
        // With a right-handed world (+y up, camera looking along +z) +x appears on the left.
        let right = forward.cross(up).normalize();
        let up = right.cross(forward);
        Self {
            position,
            forward,
            right,
            up,
            tan_half_vfov: (vfov_deg.to_radians() * 0.5).tan(),
            width,
            height,
            lens_radius,
            focus_distance,
        }
    }

    /// Ray through film position (`px`, `py`) in pixels (0,0 = top-left corner of the image),
    /// with lens sample `u_lens` ∈ [0,1)².
    pub fn generate_ray(&self, px: f32, py: f32, u_lens: Vec2) -> CameraRay {
        let aspect = self.width as f32 / self.height as f32;
        let sx = (2.0 * px / self.width as f32 - 1.0) * aspect * self.tan_half_vfov;
        let sy = (1.0 - 2.0 * py / self.height as f32) * self.tan_half_vfov;
        let dir = (self.forward + sx * self.right + sy * self.up).normalize();
        if self.lens_radius <= 0.0 {
            return CameraRay {
                origin: self.position,
                dir,
            };
        }
        let focus = self.position + dir * (self.focus_distance / dir.dot(self.forward));
        let d = concentric_disk(u_lens) * self.lens_radius;
        let origin = self.position + d.x * self.right + d.y * self.up;
        CameraRay {
            origin,
            dir: (focus - origin).normalize(),
        }
    }
}

/// Shirley–Chiu concentric map from [0,1)² to the unit disk.
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, std::f32::consts::FRAC_PI_4 * (o.y / o.x))
    } else {
        (
            o.y,
            std::f32::consts::FRAC_PI_2 - std::f32::consts::FRAC_PI_4 * (o.x / o.y),
        )
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_forward_and_plus_x_is_left() {
        let c = Camera::new(
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::ZERO,
            Vec3::Y,
            40.0,
            (100, 100),
            None,
        );
        let r = c.generate_ray(50.0, 50.0, Vec2::ZERO);
        assert!((r.dir - Vec3::Z).length() < 1e-6);
        let left = c.generate_ray(0.0, 50.0, Vec2::ZERO);
        assert!(left.dir.x > 0.0);
        let top = c.generate_ray(50.0, 0.0, Vec2::ZERO);
        assert!(top.dir.y > 0.0);
        // The top edge ray makes half the vertical field of view with the axis.
        assert!((top.dir.y.atan2(top.dir.z).to_degrees() - 20.0).abs() < 1e-4);
    }

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
}
