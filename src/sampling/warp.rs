//! Warps from [0,1)² to disks, hemispheres, spheres, cones and triangles, each next to its
//! density. The f64 forms serve the geometry, which samples points in double precision.

use glam::{DVec3, Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

/// Shirley–Chiu concentric map from [0,1)² to the unit disk (uniform by area, density 1/π).
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    // The angle is π/4·q (|q| ≤ 1) from the x axis, or that from the y axis: a cosine and a
    // sine on [−π/4, π/4], where short Taylor polynomials are exact to f32 rounding (no range
    // reduction, unlike the library's sincos, which was 2 % of a diffuse render).
    if o.x.abs() > o.y.abs() {
        let (c, s) = cos_sin_quarter(std::f32::consts::FRAC_PI_4 * (o.y / o.x));
        o.x * Vec2::new(c, s)
    } else {
        let (c, s) = cos_sin_quarter(std::f32::consts::FRAC_PI_4 * (o.x / o.y));
        o.y * Vec2::new(s, c)
    }
}

/// (cos x, sin x) for |x| ≤ π/4: Taylor polynomials to x⁸ and x⁹, whose truncation errors
/// (below 3·10⁻⁸ and 2·10⁻⁹) are under half an f32 ulp of the results.
#[inline(always)]
fn cos_sin_quarter(x: f32) -> (f32, f32) {
    let x2 = x * x;
    let c =
        1.0 + x2 * (-1.0 / 2.0 + x2 * (1.0 / 24.0 + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40320.0))));
    let s = x
        * (1.0
            + x2 * (-1.0 / 6.0
                + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362880.0)))));
    (c, s)
}

/// The concentric map in f64, as polar coordinates (r, φ) of the unit disk; r may be negative
/// (the point is r·(cos φ, sin φ)).
pub fn concentric_disk_polar(u0: f64, u1: f64) -> (f64, f64) {
    let (a, b) = (2.0 * u0 - 1.0, 2.0 * u1 - 1.0);
    if a == 0.0 && b == 0.0 {
        (0.0, 0.0)
    } else if a.abs() > b.abs() {
        (a, std::f64::consts::FRAC_PI_4 * (b / a))
    } else {
        (
            b,
            std::f64::consts::FRAC_PI_2 - std::f64::consts::FRAC_PI_4 * (a / b),
        )
    }
}

/// Uniform by area on the unit disk by the polar map: (radius, angle φ in radians); density
/// 1/π per unit area.
pub fn uniform_disk_polar(u: Vec2) -> (f32, f32) {
    (u.x.sqrt(), 2.0 * PI * u.y)
}

/// Cosine-weighted direction on the +z hemisphere (Malley's method); density
/// [`cosine_hemisphere_pdf`].
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// Density (per steradian) of [`cosine_hemisphere`] at a direction with cos θ = `cos_theta`.
#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta * FRAC_1_PI
}

/// Density (per steradian) of [`uniform_sphere`].
pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

/// Uniform direction on the unit sphere; density [`UNIFORM_SPHERE_PDF`].
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// [`uniform_sphere`] in f64.
pub fn uniform_sphere_f64(u0: f64, u1: f64) -> DVec3 {
    let z = 1.0 - 2.0 * u0;
    let rr = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * u1;
    DVec3::new(rr * phi.cos(), rr * phi.sin(), z)
}

/// Uniform direction in the cone of half-angle θmax about +z, given `one_minus_cos_max` =
/// 1 − cos θmax (kept without cancellation by the caller): (cos θ, sin θ, φ). Density
/// [`uniform_cone_pdf`].
pub fn uniform_cone(u0: f64, u1: f64, one_minus_cos_max: f64) -> (f64, f64, f64) {
    let omc_t = u0 * one_minus_cos_max;
    let cos_t = 1.0 - omc_t;
    let sin_t = (omc_t * (2.0 - omc_t)).max(0.0).sqrt();
    (cos_t, sin_t, 2.0 * std::f64::consts::PI * u1)
}

/// Density (per steradian) of [`uniform_cone`]: 1 / (2π (1 − cos θmax)).
pub fn uniform_cone_pdf(one_minus_cos_max: f64) -> f64 {
    1.0 / (std::f64::consts::TAU * one_minus_cos_max)
}

/// Uniform by area on a triangle: barycentric coordinates (b0, b1, b2) of the vertices, by
/// Heitz 2019, "A Low-Distortion Map Between Triangle and Square". Density 1/area.
pub fn uniform_triangle(u0: f64, u1: f64) -> (f64, f64, f64) {
    let (b0, b1) = if u0 < u1 {
        let b0 = u0 / 2.0;
        (b0, u1 - b0)
    } else {
        let b1 = u1 / 2.0;
        (u0 - b1, b1)
    };
    (b0, b1, 1.0 - b0 - b1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each warp lands in its domain, and the mean of a test function over a stratified grid
    /// of samples, weighted by 1/pdf, reproduces the domain's measure.
    #[test]
    fn warps_cover_their_domains_with_their_densities() {
        let n = 256;
        let (mut disk, mut hemi, mut sphere, mut cone, mut tri) = (0.0, 0.0, 0.0, 0.0, 0.0);
        let omc = 0.3f64;
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let d = concentric_disk(u);
                assert!(d.length() <= 1.0 + 1e-6);
                disk += d.length_squared() as f64; // E[r²] = 1/2 on the unit disk
                let w = cosine_hemisphere(u);
                assert!(w.z >= 0.0 && (w.length() - 1.0).abs() < 1e-5);
                let c = w.z as f64;
                hemi += c * c / cosine_hemisphere_pdf(w.z) as f64;
                let s = uniform_sphere(u);
                assert!((s.length() - 1.0).abs() < 1e-5);
                sphere += s.z as f64;
                let (c, st, _) = uniform_cone(u.x as f64, u.y as f64, omc);
                assert!(c >= 1.0 - omc - 1e-12 && (c * c + st * st - 1.0).abs() < 1e-12);
                cone += 1.0 / uniform_cone_pdf(omc);
                let (b0, b1, b2) = uniform_triangle(u.x as f64, u.y as f64);
                assert!(b0 >= 0.0 && b1 >= 0.0 && b2 >= -1e-15);
                tri += b0;
            }
        }
        let m = (n * n) as f64;
        assert!((disk / m - 0.5).abs() < 1e-3, "E[r²] {}", disk / m);
        // ∫ cos²θ dω over the hemisphere = 2π/3, estimated as mean(cos²θ / pdf).
        assert!(
            (hemi / m / (2.0 * std::f64::consts::PI / 3.0) - 1.0).abs() < 1e-3,
            "{}",
            hemi / m
        );
        assert!((sphere / m).abs() < 1e-3, "E[z] {}", sphere / m);
        assert!(
            (cone / m - std::f64::consts::TAU * omc).abs() < 1e-9,
            "{}",
            cone / m
        );
        assert!((tri / m - 1.0 / 3.0).abs() < 1e-3, "{}", tri / m);
        let (r, phi) = concentric_disk_polar(0.75, 0.5);
        let d = concentric_disk(Vec2::new(0.75, 0.5));
        assert!(
            (r * phi.cos() - d.x as f64).abs() < 1e-6 && (r * phi.sin() - d.y as f64).abs() < 1e-6
        );
        // The polynomial cosine and sine are the library's to f32 rounding, and the map is the
        // f64 polar map's.
        for k in 0..=20_000 {
            let x = std::f32::consts::FRAC_PI_4 * (k as f32 / 10_000.0 - 1.0);
            let (c, s) = cos_sin_quarter(x);
            let xd = x as f64;
            assert!((c as f64 - xd.cos()).abs() < 1.2e-7, "cos {x}");
            assert!((s as f64 - xd.sin()).abs() < 6e-8, "sin {x}");
        }
        for i in 0..=200 {
            for j in 0..=200 {
                let (u0, u1) = (i as f32 / 200.0, j as f32 / 200.0);
                let (r, phi) = concentric_disk_polar(u0 as f64, u1 as f64);
                let d = concentric_disk(Vec2::new(u0, u1));
                assert!((r * phi.cos() - d.x as f64).abs() < 2e-7, "{u0} {u1}");
                assert!((r * phi.sin() - d.y as f64).abs() < 2e-7, "{u0} {u1}");
            }
        }
        let v = uniform_sphere_f64(0.2, 0.7);
        let w = uniform_sphere(Vec2::new(0.2, 0.7));
        assert!((v.as_vec3() - w).length() < 1e-6);
    }
}
