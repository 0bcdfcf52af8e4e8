//! A goniometric light: a point source whose intensity follows a photometric file
//! ([`crate::luminaire`]), aimed by a rotation, with a spectrum whose luminous content sets
//! the radiometric scale.
//!
//! Radiant intensity toward world direction ω: `I_e(λ, ω) = S(λ) · I_v(R⁻¹ ω)` where `I_v` is
//! the file's candela (interpolated) and `S` is scaled so that `K_m ∫ S V dλ` equals the
//! candela multiplier (1 unless the scene asks for lumen scaling or a multiplier): rendered
//! illuminance is then `I_v cos θ / d²` lux.
//!
//! Sampling: next-event estimation from a shading point toward a point light has a single
//! direction, so the distribution matters only for emission (photons, light paths):
//! [`GoniometricLight::sample_emission`] draws directions proportional to the tabulated flux of each
//! table cell ([`crate::luminaire::Distribution::sample`]); the light sampler chooses between
//! lights by their integrated lumens.

use super::LightFlags;
use crate::description::context::{
    Context, Role, SceneError, MAX_SPECTRAL_VALUE, MIN_SPECTRAL_VALUE,
};
use crate::description::schema::{SpectrumDesc, V3};
use crate::luminaire::Distribution;
use crate::photometry::luminous_integral;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::{Mat3, Vec2, Vec3};
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct GoniometricLight {
    /// Position, m.
    pub position: Vec3,
    /// Luminaire frame → world.
    pub rotation: Mat3,
    /// World → luminaire frame: `rotation` transposed once, not at every lookup.
    to_local: Mat3,
    /// The file's luminous intensity distribution, cd.
    pub distribution: Arc<Distribution>,
    /// Radiant intensity per candela of the table, W·sr⁻¹·nm⁻¹ per cd (times the multiplier).
    pub spectrum: DenseSpectrum,
    /// The file's luminous opening, m: length (along C0), width, height (zero if not given).
    pub luminous_size_m: [f64; 3],
}

/// The scene's fields of a goniometric light (see `LightDesc::Goniometric`).
pub struct GoniometricDesc<'a> {
    /// Photometric file, relative to the scene file.
    pub file: &'a str,
    pub position: V3,
    /// Euler angles, degrees, about X, then Y, then Z.
    pub rotate_deg: Option<V3>,
    pub spectrum: &'a SpectrumDesc,
    /// Total luminous flux to scale the table to, lm.
    pub lumens: Option<f64>,
    /// Factor on the candela (after `lumens`).
    pub multiplier: Option<f64>,
}

impl GoniometricLight {
    pub const FLAGS: LightFlags = LightFlags::DELTA_POSITION;

    /// From `lights[i]`'s fields (`field` is `lights[i]`): the file's candela scaled to
    /// `lumens` and by `multiplier`, aimed by `rotate_deg`.
    pub fn build(ctx: &Context, field: &str, d: &GoniometricDesc) -> Result<Self, SceneError> {
        let file = ctx.resolve(d.file);
        let position = ctx.vec3(&format!("{field}.position"), d.position)?;
        let rotate_deg = match d.rotate_deg {
            Some(r) => ctx.vec3(&format!("{field}.rotate_deg"), r)?,
            None => Vec3::ZERO,
        };
        let spectrum = ctx.spectrum(&format!("{field}.spectrum"), d.spectrum, Role::Emission)?;
        let lumens = d
            .lumens
            .map(|v| ctx.nonneg(&format!("{field}.lumens"), v))
            .transpose()?;
        let multiplier = d
            .multiplier
            .map(|v| ctx.nonneg(&format!("{field}.multiplier"), v))
            .transpose()?;
        let phot = crate::luminaire::load(&file)
            .map_err(|e| ctx.err(format!("{field}.file"), e.to_string()))?;
        let distribution = phot.distribution();
        let table_lm = distribution.lumens();
        let mut k = multiplier.unwrap_or(1.0);
        if let Some(target) = lumens {
            if table_lm <= 0.0 || !table_lm.is_finite() {
                return Err(ctx.err(
                    format!("{field}.lumens"),
                    format!("the file's distribution carries no flux ({table_lm} lm), so it cannot be scaled to {target} lm"),
                ));
            }
            k *= target / table_lm;
        }
        let scale = crate::photometry::photometric_scale(&spectrum, k)
            .map_err(|m| ctx.err(format!("{field}.spectrum"), m))?;
        // The brightest direction's spectral intensity, in f64 (the f32 scale may already be
        // infinite), against the limits every light is held to.
        let peak_cd = distribution.values.iter().copied().fold(0.0, f64::max);
        let peak = peak_cd * k / luminous_integral(&spectrum) * spectrum.max_value() as f64;
        let culprit = match (d.multiplier, d.lumens) {
            (Some(_), _) => "multiplier",
            (None, Some(_)) => "lumens",
            (None, None) => "file",
        };
        let scaled = if k == 1.0 {
            String::new()
        } else {
            format!(" × {k:e} (`lumens`, `multiplier`)")
        };
        let amount = format!(
            "the file's peak intensity of {peak_cd:e} cd{scaled} makes a spectral intensity of {peak:.3e} W/(sr·nm)"
        );
        if peak.is_nan() || peak > MAX_SPECTRAL_VALUE {
            return Err(ctx.err(
                format!("{field}.{culprit}"),
                format!("the light is too bright: {amount}, more than {MAX_SPECTRAL_VALUE:e}, beyond any physical source"),
            ));
        }
        if peak_cd * k > 0.0 && peak < MIN_SPECTRAL_VALUE {
            return Err(ctx.err(
                format!("{field}.{culprit}"),
                format!("the light is too dim: {amount}, less than {MIN_SPECTRAL_VALUE:e}, which single precision rounds to 0; use a multiplier of 0 for a light that is off"),
            ));
        }
        let rotation = Mat3::from_quat(crate::geometry::euler_rotation_deg(rotate_deg));
        Ok(Self {
            position,
            rotation,
            to_local: rotation.transpose(),
            distribution: Arc::new(distribution),
            spectrum: spectrum.scaled(scale),
            luminous_size_m: phot.size_m,
        })
    }

    /// Radiant intensity (W·sr⁻¹·nm⁻¹) toward unit world direction `dir`.
    pub fn intensity_toward(&self, dir: Vec3, wl: &SampledWavelengths) -> SampledSpectrum {
        let cd = self.table_candela(dir) as f32;
        if cd > 0.0 && cd.is_finite() {
            self.spectrum.sample(wl) * cd
        } else {
            SampledSpectrum::ZERO
        }
    }

    /// Table candela (before the spectrum's multiplier) toward a unit world direction.
    pub fn table_candela(&self, dir_world: Vec3) -> f64 {
        let l = self.to_local * dir_world;
        self.distribution.eval_f32(l.to_array())
    }

    /// Luminous intensity (cd) toward a unit world direction, multiplier included.
    pub fn candela(&self, dir_world: Vec3) -> f64 {
        self.table_candela(dir_world) * luminous_integral(&self.spectrum)
    }

    /// Total luminous flux, lm.
    pub fn power_lm(&self) -> f64 {
        self.distribution.lumens() * luminous_integral(&self.spectrum)
    }

    /// Peak table candela times the spectrum's luminous content: the largest luminous
    /// intensity (cd) toward any direction (interpolation never exceeds the table's values).
    pub fn peak_candela(&self) -> f64 {
        let peak = self.distribution.values.iter().copied().fold(0.0, f64::max);
        peak * luminous_integral(&self.spectrum)
    }

    /// A cone (unit world axis, cosine of its half-angle) containing every direction of
    /// non-zero intensity, for the light BVH's bounds. Interpolation spreads a table value over
    /// the cells around it, so the support is the cells touching a non-zero value, widened by
    /// 0.01° for rounding. Type C: around the nadir (γ = 0) or the zenith, whichever is narrower (a
    /// downlight lighting only the lower hemisphere gets the nadir with cos = 0). Types A and
    /// B: around their polar axis if the support lies within 90° of it, else the sphere.
    pub fn emission_cone(&self) -> (Vec3, f32) {
        use crate::luminaire::Kind;
        const MARGIN_DEG: f64 = 0.01;
        let d = &*self.distribution;
        let (np, na) = (d.planes.len(), d.angles.len());
        let sphere = (self.rotation * -Vec3::Y, -1.0);
        if np == 0 || na == 0 || d.values.len() != np * na {
            return sphere;
        }
        let lit = |i: usize, j: usize| d.values[i * na + j] > 0.0;
        // Index ranges of non-zero vertices, widened by one cell each way.
        let lit_angles: Vec<usize> = (0..na).filter(|&j| (0..np).any(|i| lit(i, j))).collect();
        let lit_planes: Vec<usize> = (0..np).filter(|&i| (0..na).any(|j| lit(i, j))).collect();
        let (Some(&j0), Some(&j1)) = (lit_angles.first(), lit_angles.last()) else {
            return sphere;
        };
        let a_lo = d.angles[j0.saturating_sub(1)] - MARGIN_DEG;
        let a_hi = d.angles[(j1 + 1).min(na - 1)] + MARGIN_DEG;
        let cone = match d.kind {
            Kind::C => {
                let down = a_hi.clamp(0.0, 180.0);
                let up = (180.0 - a_lo).clamp(0.0, 180.0);
                if down <= up {
                    (-Vec3::Y, down)
                } else {
                    (Vec3::Y, up)
                }
            }
            Kind::A | Kind::B => {
                // cos(angle to the polar axis −y) = cos(plane) · cos(angle).
                let i0 = lit_planes[0];
                let i1 = lit_planes[lit_planes.len() - 1];
                let p_lo = d.planes[i0.saturating_sub(1)] - MARGIN_DEG;
                let p_hi = d.planes[(i1 + 1).min(np - 1)] + MARGIN_DEG;
                let pmax = p_lo.abs().max(p_hi.abs());
                let amax = a_lo.abs().max(a_hi.abs());
                if pmax >= 90.0 || amax >= 90.0 {
                    return sphere;
                }
                let c = pmax.to_radians().cos() * amax.to_radians().cos();
                (-Vec3::Y, c.clamp(-1.0, 1.0).acos().to_degrees())
            }
        };
        let (axis, half_deg) = cone;
        let cos = if half_deg >= 180.0 {
            -1.0
        } else {
            half_deg.to_radians().cos() as f32
        };
        ((self.rotation * axis).normalize(), cos)
    }

    /// Emission direction (world) sampled by the intensity distribution, its density per
    /// steradian, and the table candela in that direction.
    pub fn sample_emission(&self, u0: f32, u: Vec2) -> Option<(Vec3, f32, f64)> {
        let (d, pdf) = self
            .distribution
            .sample(u0 as f64, u.x as f64, u.y as f64)?;
        let local = Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
        let cd = self.distribution.eval(d);
        Some(((self.rotation * local).normalize(), pdf as f32, cd))
    }
}
