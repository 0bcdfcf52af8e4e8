//! A sky's luminance tabulated over the sphere, for importance sampling: directions are drawn
//! with a density proportional to the tabulated luminance, piecewise constant over cells
//! equal in solid angle.
//!
//! Directions are in the site's frame: z up, y north, x east; the cells are a grid in
//! (cos Z, azimuth), so each covers the same solid angle 4π/(nu·nv) and the density over
//! solid angle is the grid density / 4π.

use crate::sampling::Piecewise2D;
use glam::DVec3;
use std::f64::consts::PI;

#[derive(Clone, Debug, PartialEq)]
pub struct SkyMap {
    dist: Piecewise2D,
}

/// Direction of the cell point (u, v) ∈ [0, 1)²: cos Z = 1 − 2u, azimuth 2πv from north
/// towards east.
fn direction(u: f64, v: f64) -> DVec3 {
    let cos_z = 1.0 - 2.0 * u;
    let sin_z = (1.0 - cos_z * cos_z).max(0.0).sqrt();
    let phi = 2.0 * PI * v;
    DVec3::new(sin_z * phi.sin(), sin_z * phi.cos(), cos_z)
}

impl SkyMap {
    /// Rows in cos Z (over the whole sphere) and sectors in azimuth: cells of 1.2e-4 sr,
    /// 0.7° wide in azimuth; ample for sky distributions, whose features are tens of degrees
    /// wide (the sun's disk is a light of its own).
    pub const ROWS: usize = 256;
    pub const SECTORS: usize = 512;

    /// Tabulate `luminance` (any unit, ≥ 0) at the centre of each cell; None if it is zero
    /// everywhere, or negative or not finite somewhere.
    pub fn new(luminance: impl Fn(DVec3) -> f64) -> Option<Self> {
        let (nu, nv) = (Self::ROWS, Self::SECTORS);
        let mut w = Vec::with_capacity(nu * nv);
        for i in 0..nu {
            for j in 0..nv {
                let d = direction((i as f64 + 0.5) / nu as f64, (j as f64 + 0.5) / nv as f64);
                w.push(luminance(d));
            }
        }
        Some(Self {
            dist: Piecewise2D::new(&w, nu, nv)?,
        })
    }

    /// A unit direction and its density (sr⁻¹).
    pub fn sample(&self, u0: f64, u1: f64) -> (DVec3, f64) {
        let ([u, v], p) = self.dist.sample(u0, u1);
        (direction(u, v), p / (4.0 * PI))
    }

    /// Density (sr⁻¹) with which [`SkyMap::sample`] picks unit direction `d`.
    pub fn pdf(&self, d: DVec3) -> f64 {
        let u = (0.5 * (1.0 - d.z)).clamp(0.0, 1.0);
        let mut v = d.x.atan2(d.y) / (2.0 * PI);
        if v < 0.0 {
            v += 1.0;
        }
        self.dist.pdf(u, v.min(1.0 - f64::EPSILON)) / (4.0 * PI)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::daylight::CieSky;

    #[test]
    fn sampled_pdf_is_the_evaluated_pdf_and_integrates_to_one() {
        let sun = DVec3::new(0.3, -0.6, 0.742).normalize();
        let sky = CieSky::general(13).unwrap();
        let zs = sun.z.acos();
        let lum = |d: DVec3| sky.relative_luminance(d.z, d.dot(sun).clamp(-1.0, 1.0).acos(), zs);
        let map = SkyMap::new(lum).unwrap();
        let mut state = 7u64;
        let mut rnd = || {
            state = crate::sampling::mix64(state.wrapping_add(0x9E37_79B9_7F4A_7C15));
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        // E_h = ∫ L cos Z dω by importance sampling, against the quadrature; and the
        // estimator's relative spread is small because the density follows L.
        let n = 100_000;
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let (d, p) = map.sample(rnd(), rnd());
            assert!(
                (map.pdf(d) / p - 1.0).abs() < 1e-9,
                "pdf {} vs {}",
                map.pdf(d),
                p
            );
            assert!(d.z > 0.0, "the sky has no light below the horizon");
            let f = lum(d) * d.z / p;
            s += f;
            s2 += f * f;
        }
        let mean = s / n as f64;
        let sd = (s2 / n as f64 - mean * mean).sqrt();
        let exact =
            crate::daylight::horizontal_integral(zs, |cz, g| sky.relative_luminance(cz, g, zs));
        let se = sd / (n as f64).sqrt();
        assert!((mean - exact).abs() < 4.0 * se, "{mean} ± {se} vs {exact}");
        // The spread per sample is that of cos Z over the sky, about its mean: far below the
        // 1.0+ of uniform sampling.
        assert!(sd / mean < 0.6, "relative spread {}", sd / mean);
        // The density integrates to 1 over the sphere (midpoint sum over a finer grid).
        let mut total = 0.0;
        let (nu, nv) = (600, 900);
        for i in 0..nu {
            for j in 0..nv {
                total += map.pdf(direction(
                    (i as f64 + 0.5) / nu as f64,
                    (j as f64 + 0.5) / nv as f64,
                ));
            }
        }
        total *= 4.0 * PI / (nu * nv) as f64;
        assert!((total - 1.0).abs() < 2e-3, "{total}");
    }
}
