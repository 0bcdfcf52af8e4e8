//! Perspective camera with an optional thin lens, and pixel reconstruction filters.
//!
//! The camera is a radiance meter: each pixel reports the filter-weighted average of the
//! radiance arriving along its rays, so a pixel's Y is luminance in cd/m² (no vignetting or
//! cos⁴ falloff, no exposure). Image rows run top to bottom.

use crate::description::context::{Context, SceneError};
use crate::description::schema::{CameraDesc, FilterDesc};
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

/// A camera ray (unit direction).
#[derive(Clone, Copy, Debug)]
pub struct CameraRay {
    pub origin: Vec3,
    pub dir: Vec3,
}

/// A thin lens: aperture radius and focus distance, metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    /// Aperture radius, m.
    pub radius: f32,
    /// Distance to the plane in focus, m.
    pub focus_distance: f32,
}

/// Pinhole or thin-lens perspective camera.
#[derive(Clone, Debug)]
pub struct Camera {
    /// Position of the pinhole or lens centre, m.
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
    /// The camera of the scene's `camera` from its description. `check_film` sees the
    /// resolution (width, height in pixels, each ≥ 1) before the lens is read, so that the
    /// film's limits are reported first.
    pub fn build(
        ctx: &Context,
        c: &CameraDesc,
        check_film: impl FnOnce(u32, u32) -> Result<(), SceneError>,
    ) -> Result<Self, SceneError> {
        let position = ctx.vec3("camera.position", c.position)?;
        let look_at = ctx.vec3("camera.look_at", c.look_at)?;
        let up = ctx.vec3("camera.up", c.up)?;
        let forward = look_at - position;
        if forward.length_squared() == 0.0 {
            return Err(ctx.err("camera.look_at", "look_at equals position"));
        }
        if forward.normalize().cross(up).length_squared() < 1e-12 {
            return Err(ctx.err("camera.up", "up is zero or parallel to the view direction"));
        }
        let vfov = ctx.finite("camera.vfov_deg", c.vfov_deg as f64)?;
        if !(vfov > 0.0 && vfov < 180.0) {
            return Err(ctx.err(
                "camera.vfov_deg",
                format!(
                    "the field of view must lie strictly between 0 and 180 degrees, got {vfov}"
                ),
            ));
        }
        let (w, h) = c.resolution;
        if w == 0 || h == 0 {
            return Err(ctx.err(
                "camera.resolution",
                format!("the resolution must be at least 1×1, got {w}×{h}"),
            ));
        }
        check_film(w, h)?;
        let lens = match &c.lens {
            None => None,
            Some(l) => {
                let r = ctx.finite("camera.lens.aperture_radius", l.aperture_radius as f64)?;
                if r < 0.0 {
                    return Err(ctx.err(
                        "camera.lens.aperture_radius",
                        format!("must be ≥ 0, got {r}"),
                    ));
                }
                let f = ctx.positive("camera.lens.focus_distance", l.focus_distance as f64)?;
                Some(ThinLens {
                    radius: r as f32,
                    focus_distance: f as f32,
                })
            }
        };
        Ok(Camera::new(
            position,
            look_at,
            up,
            vfov as f32,
            (w as usize, h as usize),
            lens,
        ))
    }

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
        let origin = self.lens_point(u_lens);
        CameraRay {
            origin,
            dir: (focus - origin).normalize(),
        }
    }
}

/// A connection from a scene point to the camera (light tracing): where it lands on the film
/// and the importance that converts the radiance leaving the point toward the lens into pixel
/// values.
#[derive(Clone, Copy, Debug)]
pub struct CameraConnection {
    /// The point on the lens (the pinhole for a pinhole camera).
    pub lens_point: Vec3,
    /// Unit direction from the scene point toward `lens_point`.
    pub wi: Vec3,
    /// Distance from the scene point to `lens_point`, m.
    pub dist: f32,
    /// Film position in pixels (0,0 = top-left corner), as [`Camera::generate_ray`] takes it.
    pub film: Vec2,
    /// 1 / (A_pix · d² · cos³θ): with A_pix the area of one pixel on the plane at unit distance
    /// and θ the angle of the ray to the view axis. A pixel's value is the filter-weighted mean
    /// of the radiance over its film footprint, and the film position of a ray toward the lens
    /// maps to the scene point's area as dA_film = cos θ_x dA_x / (d² cos³θ); so radiance L
    /// leaving the point toward the lens, carried by a light-path weight with area measure at
    /// the point, adds `L · |cos θ_x| · importance · filter density` to a pixel.
    pub importance: f32,
}

impl Camera {
    /// The point of the lens for lens sample `u_lens` ∈ [0,1)² (the pinhole for a pinhole
    /// camera).
    fn lens_point(&self, u_lens: Vec2) -> Vec3 {
        if self.lens_radius <= 0.0 {
            return self.position;
        }
        let d = crate::sampling::concentric_disk(u_lens) * self.lens_radius;
        self.position + d.x * self.right + d.y * self.up
    }

    /// Connect scene point `p` to the camera through lens point `u_lens` ∈ [0,1)²: None if
    /// the point is behind the camera or outside the film (farther than `margin` pixels from
    /// its edge: the reconstruction filter's radius).
    pub fn connect(&self, p: Vec3, u_lens: Vec2, margin: f32) -> Option<CameraConnection> {
        let lens_point = self.lens_point(u_lens);
        let v = p - lens_point;
        let z = v.dot(self.forward);
        let dist = v.length();
        if z <= 0.0 || dist == 0.0 || !dist.is_finite() {
            return None;
        }
        // Film coordinates of the ray lens → p: the pinhole direction of the point where it
        // crosses the plane in focus (for a pinhole, of p itself).
        let (sx, sy) = if self.lens_radius > 0.0 {
            let focus = lens_point + v * (self.focus_distance / z) - self.position;
            (
                focus.dot(self.right) / self.focus_distance,
                focus.dot(self.up) / self.focus_distance,
            )
        } else {
            (v.dot(self.right) / z, v.dot(self.up) / z)
        };
        let aspect = self.width as f32 / self.height as f32;
        let (w, h) = (self.width as f32, self.height as f32);
        let px = (sx / (aspect * self.tan_half_vfov) + 1.0) * 0.5 * w;
        let py = (1.0 - sy / self.tan_half_vfov) * 0.5 * h;
        if !(px >= -margin && px < w + margin && py >= -margin && py < h + margin) {
            return None;
        }
        let a_pix = (2.0 * aspect * self.tan_half_vfov / w) * (2.0 * self.tan_half_vfov / h);
        let cos = z / dist;
        Some(CameraConnection {
            lens_point,
            wi: -v / dist,
            dist,
            film: Vec2::new(px, py),
            importance: 1.0 / (a_pix * dist * dist * cos * cos * cos),
        })
    }
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

    #[test]
    fn connect_lands_where_the_camera_ray_started() {
        let lenses = [
            None,
            Some(ThinLens {
                radius: 0.05,
                focus_distance: 3.0,
            }),
        ];
        for lens in lenses {
            let c = Camera::new(
                Vec3::new(0.3, 1.0, -2.0),
                Vec3::new(0.0, 0.5, 1.0),
                Vec3::Y,
                50.0,
                (160, 90),
                lens,
            );
            for (px, py, u) in [(10.3, 80.1, (0.2, 0.9)), (150.0, 5.5, (0.7, 0.3))] {
                let u = Vec2::new(u.0, u.1);
                let r = c.generate_ray(px, py, u);
                let p = r.origin + r.dir * 4.2;
                let k = c.connect(p, u, 0.5).expect("in view");
                assert!((k.film - Vec2::new(px, py)).length() < 2e-3, "{:?}", k.film);
                assert!((k.lens_point - r.origin).length() < 1e-5);
                assert!((k.wi + r.dir).length() < 1e-5);
                assert!((k.dist - 4.2).abs() < 1e-4);
            }
            // Behind the camera or outside the film.
            assert!(c
                .connect(Vec3::new(0.3, 1.0, -3.0), Vec2::ZERO, 0.5)
                .is_none());
            assert!(c
                .connect(Vec3::new(40.0, 1.0, 0.0), Vec2::ZERO, 0.5)
                .is_none());
        }
    }

    /// The importance of a pinhole integrates to one pixel over the film: the film positions of
    /// a plane facing the camera cover Σ importance·cos·dA = W·H pixel areas.
    #[test]
    fn connect_importance_integrates_to_the_film() {
        let c = Camera::new(Vec3::ZERO, Vec3::Z, Vec3::Y, 60.0, (64, 48), None);
        // The plane z = 2 over a grid wide enough to cover the view.
        let (n, half) = (1200, 3.0f32);
        let da = (2.0 * half / n as f32).powi(2) as f64;
        let mut sum = 0.0f64;
        for j in 0..n {
            for i in 0..n {
                let p = Vec3::new(
                    -half + (i as f32 + 0.5) * 2.0 * half / n as f32,
                    -half + (j as f32 + 0.5) * 2.0 * half / n as f32,
                    2.0,
                );
                if let Some(k) = c.connect(p, Vec2::ZERO, 0.0) {
                    sum += (k.importance * k.wi.z.abs()) as f64 * da;
                }
            }
        }
        let pixels = 64.0 * 48.0;
        assert!((sum / pixels - 1.0).abs() < 5e-3, "{}", sum / pixels);
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

    #[test]
    fn build_checks_the_film_before_the_lens() {
        use crate::description::schema::LensDesc;
        let path = std::path::Path::new("t.ron");
        let ctx = Context {
            path,
            dir: Default::default(),
            sources: Default::default(),
        };
        let mut desc = CameraDesc {
            position: [0.0, 0.0, 0.0],
            look_at: [0.0, 0.0, 1.0],
            up: [0.0, 1.0, 0.0],
            vfov_deg: 40.0,
            resolution: (8, 6),
            lens: Some(LensDesc {
                aperture_radius: -1.0,
                focus_distance: 1.0,
            }),
        };
        let film_err = |w: u32, h: u32| Err(ctx.err("camera.resolution", format!("{w}×{h}")));
        let e = Camera::build(&ctx, &desc, film_err)
            .unwrap_err()
            .to_string();
        assert!(e.contains("`camera.resolution`: 8×6"), "{e}");
        let e = Camera::build(&ctx, &desc, |_, _| Ok(()))
            .unwrap_err()
            .to_string();
        assert!(e.contains("`camera.lens.aperture_radius`"), "{e}");
        desc.resolution = (0, 6);
        let e = Camera::build(&ctx, &desc, film_err)
            .unwrap_err()
            .to_string();
        assert!(e.contains("at least 1×1, got 0×6"), "{e}");
        desc.resolution = (8, 6);
        desc.lens = None;
        let cam = Camera::build(&ctx, &desc, |_, _| Ok(())).unwrap();
        assert_eq!((cam.width, cam.height), (8, 6));
    }
}
