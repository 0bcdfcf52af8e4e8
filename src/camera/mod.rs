//! The camera: projections (perspective with an optional thin lens, fisheyes, equirectangular
//! panorama) and pixel reconstruction filters.
//!
//! The camera is a radiance meter: each pixel reports the filter-weighted average of the
//! radiance arriving along its rays, so a pixel's Y is luminance in cd/m² (no vignetting or
//! cos⁴ falloff, no exposure). Image rows run top to bottom. A fisheye's film outside its
//! image circle sees nothing: samples there carry zero radiance, and pixels wholly outside
//! ([`Camera::pixel_inside`] false) are not sampled at all.

mod filter;
pub mod projection;

pub use filter::{GaussianTable, PixelFilter};
pub use projection::{describe, radiance_view, FisheyeMapping, Projection};

use crate::description::context::{Context, SceneError};
use crate::description::schema::{CameraDesc, FisheyeMappingDesc, ProjectionDesc};
use glam::{Vec2, Vec3};
use projection::FilmMap;

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

/// A camera: position, orientation, projection and (perspective only) thin lens.
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
    map: FilmMap,
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
        let required = |field: &str, v: Option<[f32; 3]>| {
            v.ok_or_else(|| {
                ctx.err(
                    format!("camera.{field}"),
                    "missing: give `position` and `look_at`, or `from_model` (a camera of a glTF model)",
                )
            })
        };
        let position = ctx.vec3("camera.position", required("position", c.position)?)?;
        let look_at = ctx.vec3("camera.look_at", required("look_at", c.look_at)?)?;
        let up = ctx.vec3("camera.up", c.up.unwrap_or([0.0, 1.0, 0.0]))?;
        let forward = look_at - position;
        if forward.length_squared() == 0.0 {
            return Err(ctx.err("camera.look_at", "look_at equals position"));
        }
        if forward.normalize().cross(up).length_squared() < 1e-12 {
            return Err(ctx.err("camera.up", "up is zero or parallel to the view direction"));
        }
        let projection = build_projection(ctx, c)?;
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
            Some(_) if !matches!(projection, Projection::Perspective { .. }) => {
                return Err(ctx.err(
                    "camera.lens",
                    format!(
                        "a thin lens works only with the perspective projection, not with {}; remove `lens`",
                        describe(projection)
                    ),
                ));
            }
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
        Ok(Camera::with_projection(
            position,
            look_at,
            up,
            projection,
            (w as usize, h as usize),
            lens,
        ))
    }

    /// A perspective camera; `vfov_deg` is the full vertical field of view. `up` need not be
    /// orthogonal to the view direction but must not be parallel to it.
    pub fn new(
        position: Vec3,
        look_at: Vec3,
        up: Vec3,
        vfov_deg: f32,
        resolution: (usize, usize),
        lens: Option<ThinLens>,
    ) -> Self {
        let projection = Projection::Perspective {
            vfov_deg: vfov_deg as f64,
        };
        Self::with_projection(position, look_at, up, projection, resolution, lens)
    }

    /// A camera with any projection (a lens is used only by the perspective).
    pub fn with_projection(
        position: Vec3,
        look_at: Vec3,
        up: Vec3,
        projection: Projection,
        (width, height): (usize, usize),
        lens: Option<ThinLens>,
    ) -> Self {
        let ThinLens {
            radius: lens_radius,
            focus_distance,
        } = lens
            .filter(|_| matches!(projection, Projection::Perspective { .. }))
            .unwrap_or(ThinLens {
                radius: 0.0,
                focus_distance: 1.0,
            });
        let forward = (look_at - position).normalize();
        // With a right-handed world (+y up, camera looking along +z) +x appears on the left.
        let right = forward.cross(up).normalize();
        let up = right.cross(forward);
        let vfov_deg = match projection {
            Projection::Perspective { vfov_deg } => vfov_deg as f32,
            _ => 90.0,
        };
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
            map: FilmMap::new(projection, width, height),
        }
    }

    /// The camera's projection.
    pub fn projection(&self) -> Projection {
        self.map.projection
    }

    /// Unit view direction, right and up vectors of the image (world space).
    pub fn frame(&self) -> (Vec3, Vec3, Vec3) {
        (self.forward, self.right, self.up)
    }

    /// Ray through film position (`px`, `py`) in pixels (0,0 = top-left corner of the image),
    /// with lens sample `u_lens` ∈ [0,1)²; None outside a fisheye's image circle.
    pub fn try_ray(&self, px: f32, py: f32, u_lens: Vec2) -> Option<CameraRay> {
        match self.map.projection {
            Projection::Perspective { .. } => Some(self.perspective_ray(px, py, u_lens)),
            _ => {
                let d = self.map.direction(px as f64, py as f64)?;
                Some(CameraRay {
                    origin: self.position,
                    dir: self.to_world(d),
                })
            }
        }
    }

    /// As [`Self::try_ray`]; outside a fisheye's image circle, the ray of the circle's edge
    /// in the same azimuth.
    pub fn generate_ray(&self, px: f32, py: f32, u_lens: Vec2) -> CameraRay {
        self.try_ray(px, py, u_lens).unwrap_or_else(|| {
            let (cx, cy) = (0.5 * self.width as f64, 0.5 * self.height as f64);
            let (dx, dy) = (px as f64 - cx, py as f64 - cy);
            let k = 0.5 * self.width.min(self.height) as f64 / (dx * dx + dy * dy).sqrt();
            let d = self
                .map
                .direction(cx + dx * k * (1.0 - 1e-9), cy + dy * k * (1.0 - 1e-9))
                .unwrap_or([0.0, 0.0, 1.0]);
            CameraRay {
                origin: self.position,
                dir: self.to_world(d),
            }
        })
    }

    fn perspective_ray(&self, px: f32, py: f32, u_lens: Vec2) -> CameraRay {
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

    /// Camera-frame direction (x right, y up, z forward) to world space.
    fn to_world(&self, d: [f64; 3]) -> Vec3 {
        (d[0] as f32 * self.right + d[1] as f32 * self.up + d[2] as f32 * self.forward).normalize()
    }

    /// World direction to the camera frame (f64).
    fn to_camera(&self, v: Vec3) -> [f64; 3] {
        let v = v.as_dvec3().normalize();
        let f = |a: Vec3| a.as_dvec3().dot(v);
        [f(self.right), f(self.up), f(self.forward)]
    }

    /// Whether pixel (x, y) sees anything (false only wholly outside a fisheye's image
    /// circle; such pixels are black and take no samples).
    pub fn pixel_inside(&self, x: usize, y: usize) -> bool {
        self.map.pixel_inside(x, y)
    }

    /// Number of pixels that see anything.
    pub fn inside_pixels(&self) -> usize {
        (0..self.height)
            .map(|y| (0..self.width).filter(|&x| self.pixel_inside(x, y)).count())
            .sum()
    }

    /// Unit direction (world space) through the centre of pixel (x, y); for a pixel whose
    /// centre lies outside a fisheye's circle, through the nearest point of the circle.
    pub fn pixel_direction(&self, x: usize, y: usize) -> Vec3 {
        self.generate_ray(x as f32 + 0.5, y as f32 + 0.5, Vec2::splat(0.5))
            .dir
    }

    /// Film position (pixels, 0,0 = top-left corner) where the pinhole ray of world
    /// direction `dir` lands, or None if the projection does not see that direction.
    pub fn film_position(&self, dir: Vec3) -> Option<(f64, f64)> {
        self.map.film(self.to_camera(dir))
    }

    /// Whether every ray of the camera starts at its position (no thin lens): then a direction
    /// maps to one film position ([`Self::film_position`]).
    pub fn is_pinhole(&self) -> bool {
        self.lens_radius <= 0.0
    }

    /// dω/dA of the pinhole projection at world direction `dir`: steradians per square pixel of
    /// film, so a direction's share δω of solid angle covers δω / density square pixels.
    pub fn solid_angle_density(&self, dir: Vec3) -> f64 {
        self.map.solid_angle_density(self.to_camera(dir))
    }

    /// Solid angle of pixel (x, y), sr: the exact integral over the part of its footprint
    /// that sees the scene (pinhole; a thin lens's pixels see the same directions on average).
    pub fn pixel_solid_angle_sr(&self, x: usize, y: usize) -> f64 {
        self.map.pixel_solid_angle(x, y)
    }

    /// ∫ max(cos θ, 0) dω over pixel (x, y), sr, θ the angle to the view direction: exact.
    pub fn pixel_projected_solid_angle_sr(&self, x: usize, y: usize) -> f64 {
        self.map.pixel_projected_solid_angle(x, y)
    }

    /// Fraction of pixel (x, y)'s area inside the image (below 1 only on a fisheye's rim).
    pub fn pixel_coverage(&self, x: usize, y: usize) -> f64 {
        self.map.pixel_coverage(x, y)
    }

    /// The Radiance view options of this camera (`-vta -vp … -vd … -vu … -vh … -vv …`), or
    /// None where Radiance has no matching view type (equisolid fisheye, equirectangular).
    pub fn radiance_view(&self) -> Option<String> {
        let v = |a: Vec3| [a.x as f64, a.y as f64, a.z as f64];
        radiance_view(
            self.map.projection,
            (self.width, self.height),
            v(self.position),
            v(self.forward),
            v(self.up),
        )
    }
}

/// Vertical illuminance at the eye, lx, from a luminance image (cd/m², row-major, top row
/// first) taken by `camera`: E_v = Σ L · ∫ max(cos θ, 0) dω over each pixel (θ to the view
/// direction; the integral exact per pixel). A fisheye's rim pixel holds the mean over its
/// whole area with zero outside the circle, so its term is divided by its coverage. Sums in
/// f64. Panics if the image is not `width × height`.
pub fn vertical_illuminance_lx(camera: &Camera, luminance_cd_m2: &[f32]) -> f64 {
    assert_eq!(
        luminance_cd_m2.len(),
        camera.width * camera.height,
        "luminance image size"
    );
    let mut e = 0.0f64;
    for y in 0..camera.height {
        for x in 0..camera.width {
            if !camera.pixel_inside(x, y) {
                continue;
            }
            let cov = camera.pixel_coverage(x, y);
            if cov <= 0.0 {
                continue;
            }
            let l = luminance_cd_m2[y * camera.width + x] as f64;
            e += l * camera.pixel_projected_solid_angle_sr(x, y) / cov;
        }
    }
    e
}

/// The projection the description asks for: `projection`, else perspective with
/// `vfov_deg`; each field's limits checked.
fn build_projection(ctx: &Context, c: &CameraDesc) -> Result<Projection, SceneError> {
    let perspective = |field: &str, v: f32| -> Result<Projection, SceneError> {
        let vfov = ctx.finite(field, v as f64)?;
        if !(vfov > 0.0 && vfov < 180.0) {
            return Err(ctx.err(
                field,
                format!(
                    "the field of view must lie strictly between 0 and 180 degrees, got {vfov}"
                ),
            ));
        }
        Ok(Projection::Perspective { vfov_deg: vfov })
    };
    match (&c.projection, c.vfov_deg) {
        (None, Some(v)) => perspective("camera.vfov_deg", v),
        (None, None) => Err(ctx.err(
            "camera.vfov_deg",
            "missing: give `vfov_deg` (perspective) or a `projection`",
        )),
        (Some(_), Some(_)) => Err(ctx.err(
            "camera.vfov_deg",
            "conflicts with `projection`: give the field of view inside the projection (e.g. `Perspective(vfov_deg: 40)`) and remove `vfov_deg`",
        )),
        (Some(ProjectionDesc::Perspective { vfov_deg }), None) => {
            perspective("camera.projection.vfov_deg", *vfov_deg)
        }
        (Some(ProjectionDesc::Equirectangular), None) => Ok(Projection::Equirectangular),
        (Some(ProjectionDesc::Fisheye { mapping, fov_deg }), None) => {
            let mapping = match mapping {
                FisheyeMappingDesc::Equidistant => FisheyeMapping::Equidistant,
                FisheyeMappingDesc::Orthographic => FisheyeMapping::Orthographic,
                FisheyeMappingDesc::Equisolid => FisheyeMapping::Equisolid,
                FisheyeMappingDesc::Stereographic => FisheyeMapping::Stereographic,
            };
            let field = "camera.projection.fov_deg";
            let fov = ctx.finite(field, *fov_deg as f64)?;
            let max = mapping.max_fov_deg();
            if !(fov > 0.0 && fov <= max) {
                return Err(ctx.err(
                    field,
                    format!(
                        "the {} fisheye's field of view must lie in (0, {max}] degrees, got {fov}",
                        mapping.name().to_lowercase()
                    ),
                ));
            }
            Ok(Projection::Fisheye {
                mapping,
                fov_deg: fov,
            })
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
        if !matches!(self.map.projection, Projection::Perspective { .. }) {
            return self.connect_pinhole(p, margin);
        }
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

impl Camera {
    /// [`Self::connect`] for the projections without a lens: the film position is the
    /// projection's inverse map, and dA_film = dω / (dω/dA_film) with the solid angle density
    /// of the projection in place of A_pix·cos³θ.
    fn connect_pinhole(&self, p: Vec3, margin: f32) -> Option<CameraConnection> {
        let v = p - self.position;
        let dist = v.length();
        if dist == 0.0 || !dist.is_finite() {
            return None;
        }
        let d = self.to_camera(v);
        let (px, py) = self.map.film(d)?;
        let (w, h, m) = (self.width as f64, self.height as f64, margin as f64);
        if !(px >= -m && px < w + m && py >= -m && py < h + m) {
            return None;
        }
        let density = self.map.solid_angle_density(d);
        if density <= 0.0 || !density.is_finite() {
            return None;
        }
        let importance = 1.0 / (density * dist as f64 * dist as f64);
        Some(CameraConnection {
            lens_point: self.position,
            wi: -v / dist,
            dist,
            film: Vec2::new(px as f32, py as f32),
            importance: importance as f32,
        })
    }
}

#[cfg(test)]
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
    fn build_checks_the_film_before_the_lens() {
        use crate::description::schema::LensDesc;
        let path = std::path::Path::new("t.ron");
        let ctx = Context {
            path,
            dir: Default::default(),
            sources: Default::default(),
        };
        let mut desc = CameraDesc {
            position: Some([0.0, 0.0, 0.0]),
            look_at: Some([0.0, 0.0, 1.0]),
            up: None,
            from_model: None,
            vfov_deg: Some(40.0),
            resolution: (8, 6),
            projection: None,
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
