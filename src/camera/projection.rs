//! Projections: how a film position maps to a view direction and back, and each pixel's exact
//! solid angle.
//!
//! The film is described in plane coordinates (sx, sy) = ((px − W/2)·s, (H/2 − py)·s), with
//! `s` the size of one pixel: on the image plane at unit distance for the perspective, as a
//! fraction of the image circle's radius for fisheyes. Every radial projection maps the
//! radius r = √(sx² + sy²) to the angle θ(r) from the view direction, at the azimuth of
//! (sx, sy); the equirectangular panorama maps columns to azimuth and rows to elevation.

use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::OnceLock;

/// Radial mapping of a fisheye lens: the image radius as a function of the angle θ to the
/// view direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FisheyeMapping {
    /// Angular (equidistant): r ∝ θ. Up to 360°.
    Equidistant,
    /// Hemispherical (orthographic): r ∝ sin θ. Up to 180°.
    Orthographic,
    /// Equisolid (equal-area): r ∝ 2 sin(θ/2). Up to 180°.
    Equisolid,
    /// Stereographic (planisphere): r ∝ 2 tan(θ/2). Up to 180°.
    Stereographic,
}

impl FisheyeMapping {
    /// Largest full field of view this mapping accepts, degrees.
    pub fn max_fov_deg(self) -> f64 {
        match self {
            FisheyeMapping::Equidistant => 360.0,
            _ => 180.0,
        }
    }

    /// The name of the scene syntax.
    pub fn name(self) -> &'static str {
        match self {
            FisheyeMapping::Equidistant => "Equidistant",
            FisheyeMapping::Orthographic => "Orthographic",
            FisheyeMapping::Equisolid => "Equisolid",
            FisheyeMapping::Stereographic => "Stereographic",
        }
    }

    /// f(θ), the unnormalised image radius.
    fn radius_of(self, theta: f64) -> f64 {
        match self {
            FisheyeMapping::Equidistant => theta,
            FisheyeMapping::Orthographic => theta.sin(),
            FisheyeMapping::Equisolid => 2.0 * (0.5 * theta).sin(),
            FisheyeMapping::Stereographic => 2.0 * (0.5 * theta).tan(),
        }
    }

    /// f⁻¹(ρ).
    fn angle_of(self, rho: f64) -> f64 {
        match self {
            FisheyeMapping::Equidistant => rho,
            FisheyeMapping::Orthographic => rho.min(1.0).asin(),
            FisheyeMapping::Equisolid => 2.0 * (0.5 * rho).min(1.0).asin(),
            FisheyeMapping::Stereographic => 2.0 * (0.5 * rho).atan(),
        }
    }
}

/// A camera projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Pinhole (or thin-lens) perspective with full vertical field of view `vfov_deg`.
    Perspective { vfov_deg: f64 },
    /// Circular fisheye inscribed in the shorter side of the image, `fov_deg` across the
    /// circle. Pixels wholly outside the circle see nothing.
    Fisheye {
        mapping: FisheyeMapping,
        fov_deg: f64,
    },
    /// 360° (columns, azimuth, view direction at the centre, right to the right) × 180° (rows,
    /// elevation, zenith of `up` at the top) latitude–longitude panorama.
    Equirectangular,
}

/// The map between film positions and directions in the camera's frame: x = right, y = up,
/// z = view direction (unit vectors, f64).
#[derive(Clone, Copy, Debug)]
pub(crate) struct FilmMap {
    pub projection: Projection,
    pub width: usize,
    pub height: usize,
    /// Pixel size in plane coordinates (radial projections).
    scale: f64,
    /// f(θ_max) of a fisheye (its image circle has unit radius in plane coordinates).
    rim: f64,
}

impl FilmMap {
    pub fn new(projection: Projection, width: usize, height: usize) -> Self {
        let (scale, rim) = match projection {
            Projection::Perspective { vfov_deg } => (
                2.0 * (0.5 * vfov_deg.to_radians()).tan() / height as f64,
                0.0,
            ),
            Projection::Fisheye { mapping, fov_deg } => (
                2.0 / width.min(height) as f64,
                mapping.radius_of(0.5 * fov_deg.to_radians()),
            ),
            Projection::Equirectangular => (0.0, 0.0),
        };
        FilmMap {
            projection,
            width,
            height,
            scale,
            rim,
        }
    }

    /// Plane coordinates of film position (px, py) (pixels, 0,0 = top-left corner).
    fn plane(&self, px: f64, py: f64) -> (f64, f64) {
        (
            (px - 0.5 * self.width as f64) * self.scale,
            (0.5 * self.height as f64 - py) * self.scale,
        )
    }

    /// Largest plane radius that sees anything (∞ for the perspective).
    fn r_max(&self) -> f64 {
        match self.projection {
            Projection::Fisheye { .. } => 1.0,
            _ => f64::INFINITY,
        }
    }

    /// θ(r) of a radial projection.
    fn theta(&self, r: f64) -> f64 {
        match self.projection {
            Projection::Perspective { .. } => r.atan(),
            Projection::Fisheye { mapping, .. } => mapping.angle_of(r * self.rim),
            Projection::Equirectangular => unreachable!("not radial"),
        }
    }

    /// Unit direction (camera frame) through film position (px, py), or None outside a
    /// fisheye's image circle.
    pub fn direction(&self, px: f64, py: f64) -> Option<[f64; 3]> {
        match self.projection {
            Projection::Equirectangular => {
                let phi = (px / self.width as f64 - 0.5) * 2.0 * PI;
                let beta = (0.5 - py / self.height as f64) * PI;
                let (sp, cp) = phi.sin_cos();
                let (sb, cb) = beta.sin_cos();
                Some([cb * sp, sb, cb * cp])
            }
            Projection::Perspective { .. } => {
                let (x, y) = self.plane(px, py);
                let n = (x * x + y * y + 1.0).sqrt();
                Some([x / n, y / n, 1.0 / n])
            }
            Projection::Fisheye { .. } => {
                let (x, y) = self.plane(px, py);
                let r = (x * x + y * y).sqrt();
                if r > 1.0 {
                    return None;
                }
                let (st, ct) = self.theta(r).sin_cos();
                if r == 0.0 {
                    return Some([0.0, 0.0, 1.0]);
                }
                Some([st * x / r, st * y / r, ct])
            }
        }
    }

    /// Film position (pixels) of unit direction `d` (camera frame), or None if the
    /// projection does not see it (behind a perspective camera, beyond a fisheye's field).
    pub fn film(&self, d: [f64; 3]) -> Option<(f64, f64)> {
        let [x, y, z] = d;
        match self.projection {
            Projection::Equirectangular => {
                let phi = x.atan2(z);
                let beta = y.clamp(-1.0, 1.0).asin();
                Some((
                    (phi / (2.0 * PI) + 0.5) * self.width as f64,
                    (0.5 - beta / PI) * self.height as f64,
                ))
            }
            Projection::Perspective { .. } => {
                if z <= 0.0 {
                    return None;
                }
                let (sx, sy) = (x / z, y / z);
                Some((
                    0.5 * self.width as f64 + sx / self.scale,
                    0.5 * self.height as f64 - sy / self.scale,
                ))
            }
            Projection::Fisheye { mapping, fov_deg } => {
                let s = (x * x + y * y).sqrt();
                let theta = s.atan2(z);
                if theta > 0.5 * fov_deg.to_radians() {
                    return None;
                }
                let r = mapping.radius_of(theta) / self.rim;
                let (cx, cy) = match (s > 0.0, z > 0.0) {
                    (true, _) => (x / s, y / s),
                    (false, true) => (0.0, 0.0),
                    // Straight behind a 360° fisheye: the whole rim, no single position.
                    (false, false) => return None,
                };
                Some((
                    0.5 * self.width as f64 + r * cx / self.scale,
                    0.5 * self.height as f64 - r * cy / self.scale,
                ))
            }
        }
    }

    /// dω/dA at direction `d` (camera frame): steradians per square pixel of film.
    pub fn solid_angle_density(&self, d: [f64; 3]) -> f64 {
        let [x, y, z] = d;
        let s2 = self.scale * self.scale;
        match self.projection {
            Projection::Equirectangular => {
                let cb = (x * x + z * z).sqrt();
                cb * (2.0 * PI / self.width as f64) * (PI / self.height as f64)
            }
            Projection::Perspective { .. } => z * z * z * s2,
            Projection::Fisheye { mapping, .. } => {
                let c = self.rim;
                let theta = (x * x + y * y).sqrt().atan2(z);
                // sin θ · θ′(r) / r in closed form for each mapping.
                let j = match mapping {
                    FisheyeMapping::Equidistant => {
                        if theta < 1e-8 {
                            c * c
                        } else {
                            c * c * theta.sin() / theta
                        }
                    }
                    FisheyeMapping::Orthographic => c * c / theta.cos(),
                    FisheyeMapping::Equisolid => c * c,
                    FisheyeMapping::Stereographic => c * c * (0.5 * theta).cos().powi(4),
                };
                j * s2
            }
        }
    }

    /// Whether any part of pixel (x, y) sees the scene (false only outside a fisheye's
    /// image circle).
    pub fn pixel_inside(&self, x: usize, y: usize) -> bool {
        match self.projection {
            Projection::Fisheye { .. } => {
                // Nearest point of the pixel square to the centre of the circle.
                let (cx, cy) = (0.5 * self.width as f64, 0.5 * self.height as f64);
                let nx = cx.clamp(x as f64, x as f64 + 1.0) - cx;
                let ny = cy.clamp(y as f64, y as f64 + 1.0) - cy;
                (nx * nx + ny * ny).sqrt() * self.scale < 1.0
            }
            _ => true,
        }
    }

    /// Whether all of pixel (x, y) sees the scene (its farthest corner inside the circle).
    fn pixel_wholly_inside(&self, x: usize, y: usize) -> bool {
        let (cx, cy) = (0.5 * self.width as f64, 0.5 * self.height as f64);
        let fx = (x as f64 - cx).abs().max((x as f64 + 1.0 - cx).abs());
        let fy = (y as f64 - cy).abs().max((y as f64 + 1.0 - cy).abs());
        (fx * fx + fy * fy).sqrt() * self.scale <= 1.0
    }

    /// Solid angle of pixel (x, y), sr: the part of its footprint that sees the scene.
    pub fn pixel_solid_angle(&self, x: usize, y: usize) -> f64 {
        if !self.pixel_inside(x, y) {
            return 0.0;
        }
        match self.projection {
            Projection::Equirectangular => {
                let (p0, p1, b0, b1) = self.lat_long(x, y);
                (p1 - p0) * (b1.sin() - b0.sin())
            }
            _ => self
                .contour(x, y, |m, r| {
                    let t = m.theta(r.min(m.r_max()));
                    let h = (0.5 * t).sin();
                    2.0 * h * h
                })
                .max(0.0),
        }
    }

    /// ∫ max(cos θ, 0) dω over pixel (x, y), sr, with θ the angle to the view direction: the
    /// pixel's weight in the illuminance of a plane facing the view direction at the eye.
    pub fn pixel_projected_solid_angle(&self, x: usize, y: usize) -> f64 {
        if !self.pixel_inside(x, y) {
            return 0.0;
        }
        match self.projection {
            Projection::Equirectangular => {
                let (p0, p1, b0, b1) = self.lat_long(x, y);
                let (q0, q1) = (p0.max(-FRAC_PI_2), p1.min(FRAC_PI_2));
                if q1 <= q0 {
                    return 0.0;
                }
                let g = |b: f64| 0.5 * b + 0.25 * (2.0 * b).sin();
                (q1.sin() - q0.sin()) * (g(b1) - g(b0))
            }
            _ => self
                .contour(x, y, |m, r| {
                    let t = m.theta(r.min(m.r_max())).min(FRAC_PI_2);
                    0.5 * t.sin().powi(2)
                })
                .max(0.0),
        }
    }

    /// Fraction of pixel (x, y)'s area that sees the scene (1 except on a fisheye's rim).
    pub fn pixel_coverage(&self, x: usize, y: usize) -> f64 {
        match self.projection {
            Projection::Fisheye { .. } if !self.pixel_inside(x, y) => 0.0,
            Projection::Fisheye { .. } if self.pixel_wholly_inside(x, y) => 1.0,
            Projection::Fisheye { .. } => {
                let a = self.contour(x, y, |m, r| 0.5 * r.min(m.r_max()).powi(2));
                (a / (self.scale * self.scale)).clamp(0.0, 1.0)
            }
            _ => 1.0,
        }
    }

    /// Azimuth and elevation bounds (radians) of an equirectangular pixel.
    fn lat_long(&self, x: usize, y: usize) -> (f64, f64, f64, f64) {
        let (w, h) = (self.width as f64, self.height as f64);
        let phi = |px: f64| (px / w - 0.5) * 2.0 * PI;
        let beta = |py: f64| (0.5 - py / h) * PI;
        (
            phi(x as f64),
            phi(x as f64 + 1.0),
            beta(y as f64 + 1.0),
            beta(y as f64),
        )
    }

    /// ∫∫ (1/r) dG/dr dA over the pixel, by Green's theorem ∮ G(r) dφ along its edges, for a
    /// radial function G with G(0) = 0. With G = 1 − cos θ(r) this is the solid angle (the
    /// integrand sin θ θ′(r) dr dφ), with G = sin²θ/2 the cosine-weighted solid angle, with
    /// G = r²/2 the area. Each edge is split where r crosses the rim or θ = 90° (kinks of G)
    /// and integrated by Gauss–Legendre after a cosine substitution, which also absorbs the
    /// square-root behaviour of the orthographic mapping at its rim.
    fn contour(&self, x: usize, y: usize, g: impl Fn(&FilmMap, f64) -> f64) -> f64 {
        let (x0, y0) = self.plane(x as f64, y as f64 + 1.0);
        let (x1, y1) = self.plane(x as f64 + 1.0, y as f64);
        // Counter-clockwise in plane coordinates.
        let corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)];
        let mut kinks = vec![self.r_max()];
        if let Projection::Fisheye { mapping, .. } = self.projection {
            if self.rim > mapping.radius_of(FRAC_PI_2) {
                kinks.push(mapping.radius_of(FRAC_PI_2) / self.rim);
            }
        }
        let nodes = gauss_legendre();
        let mut total = 0.0;
        for k in 0..4 {
            let (ax, ay) = corners[k];
            let (bx, by) = corners[(k + 1) % 4];
            let (dx, dy) = (bx - ax, by - ay);
            // x dy − y dx is constant along a straight edge.
            let cross = ax * dy - ay * dx;
            if cross == 0.0 {
                continue;
            }
            // Parameters t ∈ (0, 1) where |a + t d| equals a kink radius.
            let mut cuts = vec![0.0, 1.0];
            let (qa, qb) = (dx * dx + dy * dy, 2.0 * (ax * dx + ay * dy));
            for &rk in &kinks {
                if !rk.is_finite() {
                    continue;
                }
                let qc = ax * ax + ay * ay - rk * rk;
                let disc = qb * qb - 4.0 * qa * qc;
                if disc > 0.0 {
                    let sq = disc.sqrt();
                    for t in [(-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa)] {
                        if t > 0.0 && t < 1.0 {
                            cuts.push(t);
                        }
                    }
                }
            }
            cuts.sort_by(f64::total_cmp);
            for w in cuts.windows(2) {
                let (ta, tb) = (w[0], w[1]);
                let mut piece = 0.0;
                for &(u, wt) in nodes {
                    // t = ta + (tb − ta)(1 − cos πu)/2, u ∈ [0, 1].
                    let (su, cu) = (PI * u).sin_cos();
                    let t = ta + (tb - ta) * 0.5 * (1.0 - cu);
                    let dt = (tb - ta) * 0.5 * PI * su;
                    let (px, py) = (ax + t * dx, ay + t * dy);
                    let r2 = px * px + py * py;
                    piece += wt * g(self, r2.sqrt()) / r2 * dt;
                }
                total += cross * piece;
            }
        }
        total
    }
}

/// Gauss–Legendre nodes and weights on [0, 1].
fn gauss_legendre() -> &'static [(f64, f64)] {
    static NODES: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    NODES.get_or_init(|| {
        const N: usize = 24;
        let mut out = Vec::with_capacity(N);
        for i in 0..N {
            let mut x = (PI * (i as f64 + 0.75) / (N as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                // Legendre P_N and its derivative by the three-term recurrence.
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=N {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = N as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            out.push((0.5 * (1.0 - x), 0.5 * w));
        }
        out
    })
}

/// The Radiance view options (`-vt? -vp … -vd … -vu … -vh … -vv …`) of a camera, or None
/// where Radiance has no such view type (equisolid fisheye, equirectangular panorama) or
/// cannot frame it (a hemispherical fisheye on a non-square image whose width or height
/// would reach past 180°).
pub fn radiance_view(
    projection: Projection,
    (width, height): (usize, usize),
    position: [f64; 3],
    direction: [f64; 3],
    up: [f64; 3],
) -> Option<String> {
    let (w, h) = (width as f64, height as f64);
    let half = |deg: f64| 0.5 * deg.to_radians();
    let (t, vh, vv) = match projection {
        Projection::Perspective { vfov_deg } => {
            let tv = half(vfov_deg).tan();
            ("v", 2.0 * (tv * w / h).atan().to_degrees(), vfov_deg)
        }
        Projection::Fisheye { mapping, fov_deg } => {
            // The circle spans the shorter side; the other side reaches `k` times as far in
            // the mapping's image radius.
            let m = w.min(h);
            let (kw, kh) = (w / m, h / m);
            match mapping {
                FisheyeMapping::Equidistant => ("a", fov_deg * kw, fov_deg * kh),
                FisheyeMapping::Orthographic => {
                    let s = half(fov_deg).sin();
                    if s * kw > 1.0 || s * kh > 1.0 {
                        return None;
                    }
                    (
                        "h",
                        2.0 * (s * kw).asin().to_degrees(),
                        2.0 * (s * kh).asin().to_degrees(),
                    )
                }
                FisheyeMapping::Stereographic => {
                    let q = (0.5 * half(fov_deg)).tan();
                    (
                        "s",
                        4.0 * (q * kw).atan().to_degrees(),
                        4.0 * (q * kh).atan().to_degrees(),
                    )
                }
                FisheyeMapping::Equisolid => return None,
            }
        }
        Projection::Equirectangular => return None,
    };
    let v3 = |v: [f64; 3]| format!("{} {} {}", round6(v[0]), round6(v[1]), round6(v[2]));
    Some(format!(
        "-vt{t} -vp {} -vd {} -vu {} -vh {} -vv {} -vo 0 -va 0 -vs 0 -vl 0",
        v3(position),
        v3(direction),
        v3(up),
        round6(vh),
        round6(vv)
    ))
}

/// Six decimals, without a negative zero.
fn round6(v: f64) -> f64 {
    (v * 1e6).round() / 1e6 + 0.0
}

/// The projection in scene syntax, e.g. `Fisheye(mapping: Equisolid, fov_deg: 180)`.
pub fn describe(projection: Projection) -> String {
    match projection {
        Projection::Perspective { vfov_deg } => format!("Perspective(vfov_deg: {vfov_deg})"),
        Projection::Fisheye { mapping, fov_deg } => {
            format!("Fisheye(mapping: {}, fov_deg: {fov_deg})", mapping.name())
        }
        Projection::Equirectangular => "Equirectangular".to_string(),
    }
}
