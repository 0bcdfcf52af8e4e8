//! The sun's disk seen straight from a pinhole camera, deposited into its pixels
//! deterministically.
//!
//! The disk (0.533°, luminance E_n / Ω ≈ 10⁹ cd/m²) covers a few pixels of a wide view at most,
//! so camera rays rarely hit it and a pixel that one does hit jumps by orders of magnitude: the
//! image's vertical illuminance and every glare index would carry that noise. Instead each
//! pixel receives the exact expectation of what its camera rays would see of the disk along the
//! straight line of sight: a fixed quadrature of the disk (directions of equal solid angle
//! δω), each projected to its film position q and spread over the pixels whose filter covers
//! q, with weight filter(q − centre) · δω / (dω/dA at q), times the disk's radiance and the
//! spectral transmittance of the eye→sun ray (through window panes as shadow rays see them;
//! zero where something opaque blocks it), integrated over wavelength into XYZ with the film's
//! colour-matching functions. [`super::path::trace`] leaves the disk out of rays that reach it
//! without scattering (`PathStart::sun_deposited`), so nothing is counted twice; a disk seen in
//! a mirror, through a refracting solid or by any scattered path is still found by the paths.
//!
//! Every camera sample of a pixel adds the same deposit, so every batch's mean moves by the
//! same amount and the pixel's standard error stays that of the rest of its light.

use crate::colour::tables::{cmfs, Observer};
use crate::light::Light;
use crate::photometry::K_M;
use crate::spectrum::{SampledWavelengths, DENSE_LEN, LAMBDA_MIN, N_LAMBDA};
use crate::world::World;
use glam::{DVec3, Vec2};
use std::collections::BTreeMap;

/// Fewest and most quadrature directions along each axis of the disk's grid.
const MIN_GRID: usize = 16;
const MAX_GRID: usize = 64;
/// Quadrature directions per pixel across the disk's diameter (above [`MIN_GRID`]).
const PER_PIXEL: f64 = 8.0;
/// Widest disk deposited, pixels: a wider one (a long lens) is found often enough by the
/// camera rays themselves, which then keep it.
const MAX_DIAMETER_PX: f64 = MAX_GRID as f64 / PER_PIXEL;

/// The deterministic XYZ of the directly seen disk, per pixel.
#[derive(Clone, Debug, Default)]
pub struct SunInView {
    /// (pixel index y·width + x, absolute XYZ: Y in cd/m²), sorted by pixel.
    pixels: Vec<(u64, [f64; 3])>,
}

impl SunInView {
    /// The deposit of every sun of `world` seen by its camera: None when the camera has a thin
    /// lens or a disk spans more than [`MAX_DIAMETER_PX`] pixels (the camera rays then keep
    /// finding the disks themselves), or the world has no sun. A sun outside
    /// the view gives an empty deposit, and its disk is still left to the deposit (a pixel's
    /// filter can reach past the image's edge).
    pub fn new(world: &World) -> Option<Self> {
        let cam = &world.camera;
        if !cam.is_pinhole() {
            return None;
        }
        let suns: Vec<_> = world
            .lights
            .iter()
            .filter_map(|l| match l {
                Light::Sun(s) => Some(s),
                _ => None,
            })
            .collect();
        if suns.is_empty() {
            return None;
        }
        let filter = &world.settings.filter;
        let r = filter.radius() as f64;
        let (w, h) = (cam.width as i64, cam.height as i64);
        let wraps = matches!(cam.projection(), crate::camera::Projection::Equirectangular);
        let mut acc: BTreeMap<u64, [f64; 3]> = BTreeMap::new();
        for sun in suns {
            let omega = sun.solid_angle_sr();
            // Quadrature points in proportion to the disk's diameter in pixels (the density
            // is not positive behind a perspective camera, which sees none of the disk).
            let density = cam.solid_angle_density(sun.to_sun);
            let n = if density > 0.0 {
                let diameter_px = 2.0 * (omega / std::f64::consts::PI / density).sqrt();
                if diameter_px > MAX_DIAMETER_PX {
                    return None;
                }
                ((PER_PIXEL * diameter_px).ceil() as usize).clamp(MIN_GRID, MAX_GRID)
            } else {
                MIN_GRID
            };
            let d_omega = omega / (n * n) as f64;
            for d in sun.disk_directions(n) {
                let dir = d.as_vec3();
                let Some((fx, fy)) = cam.film_position(dir) else {
                    continue;
                };
                let (x0, x1) = ((fx - r - 0.5).floor() as i64, (fx + r - 0.5).ceil() as i64);
                let (y0, y1) = ((fy - r - 0.5).floor() as i64, (fy + r - 0.5).ceil() as i64);
                if y1 < 0 || y0 >= h || (!wraps && (x1 < 0 || x0 >= w)) {
                    continue;
                }
                let xyz = seen_xyz(world, &sun.radiance, d);
                if xyz == [0.0; 3] {
                    continue;
                }
                let k = d_omega / cam.solid_angle_density(dir);
                for py in y0.max(0)..=y1.min(h - 1) {
                    for px in x0..=x1 {
                        let off = Vec2::new(
                            (fx - (px as f64 + 0.5)) as f32,
                            (fy - (py as f64 + 0.5)) as f32,
                        );
                        let wgt = filter.density(off) as f64;
                        if wgt == 0.0 {
                            continue;
                        }
                        let qx = if wraps {
                            px.rem_euclid(w)
                        } else if (0..w).contains(&px) {
                            px
                        } else {
                            continue;
                        };
                        let e = acc.entry((py * w + qx) as u64).or_default();
                        for (e, v) in e.iter_mut().zip(xyz) {
                            *e += wgt * k * v;
                        }
                    }
                }
            }
        }
        Some(Self {
            pixels: acc.into_iter().collect(),
        })
    }

    /// The deposit of pixel `pixel` (y·width + x), absolute XYZ (Y in cd/m²).
    #[inline]
    pub fn at(&self, pixel: u64) -> Option<[f64; 3]> {
        self.pixels
            .binary_search_by_key(&pixel, |&(p, _)| p)
            .ok()
            .map(|i| self.pixels[i].1)
    }

    /// The pixels that receive a deposit, with it (absolute XYZ, Y in cd/m²).
    pub fn pixels(&self) -> &[(u64, [f64; 3])] {
        &self.pixels
    }
}

/// Absolute XYZ radiance (Y in cd/m²) the eye receives straight from the disk along unit `d`:
/// K_m ∫ L_e(λ) T(λ) x̄(λ) dλ with T the transmittance of the ray from the camera (0 when
/// blocked), the product integrated exactly between the 1 nm nodes where both are linear, as
/// the film's estimate of a sample's radiance converges to.
fn seen_xyz(world: &World, radiance: &crate::spectrum::DenseSpectrum, d: DVec3) -> [f64; 3] {
    let origin = world.camera.position;
    let dir = d.as_vec3();
    let t: [f64; DENSE_LEN] = if world.see_through.is_empty() {
        if world.geometry.occluded(origin, dir, f32::INFINITY) {
            return [0.0; 3];
        }
        [1.0; DENSE_LEN]
    } else {
        let mut t = [0.0; DENSE_LEN];
        for first in (0..DENSE_LEN).step_by(N_LAMBDA) {
            let mut wl = SampledWavelengths {
                lambda: [0.0; N_LAMBDA],
                pdf: [1.0; N_LAMBDA],
            };
            for (i, l) in wl.lambda.iter_mut().enumerate() {
                *l = LAMBDA_MIN + (first + i).min(DENSE_LEN - 1) as f32;
            }
            let Some(tr) = super::transmit::transmittance(world, origin, dir, f32::INFINITY, &wl)
            else {
                return [0.0; 3];
            };
            for (i, &v) in tr.0.iter().enumerate() {
                if let Some(x) = t.get_mut(first + i) {
                    *x = v as f64;
                }
            }
        }
        t
    };
    let c = cmfs(Observer::Cie1931_2);
    let v: Vec<f64> = (0..DENSE_LEN)
        .map(|i| radiance.values[i] as f64 * t[i])
        .collect();
    let mut xyz = [0.0; 3];
    for (k, bar) in [&c.x, &c.y, &c.z].into_iter().enumerate() {
        // ∫₀¹ (a₀ + (a₁ − a₀)s)(b₀ + (b₁ − b₀)s) ds per 1 nm interval.
        xyz[k] = K_M
            * (0..DENSE_LEN - 1)
                .map(|i| {
                    let (a0, a1, b0, b1) = (v[i], v[i + 1], bar[i], bar[i + 1]);
                    (2.0 * a0 * b0 + a0 * b1 + a1 * b0 + 2.0 * a1 * b1) / 6.0
                })
                .sum::<f64>();
    }
    xyz
}
