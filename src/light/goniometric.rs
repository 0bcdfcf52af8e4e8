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
//! [`Goniometric::sample_emission`] draws directions proportional to the tabulated flux of each
//! table cell ([`crate::luminaire::Distribution::sample`]); the light sampler chooses between
//! lights by their integrated lumens.

use crate::luminaire::Distribution;
use crate::photometry::luminous_integral;
use crate::spectrum::DenseSpectrum;
use glam::{Mat3, Vec2, Vec3};
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct Goniometric {
    pub position: Vec3,
    /// Luminaire frame → world.
    pub rotation: Mat3,
    pub distribution: Arc<Distribution>,
    /// Radiant intensity per candela of the table, W·sr⁻¹·nm⁻¹ per cd (times the multiplier).
    pub spectrum: DenseSpectrum,
}

impl Goniometric {
    /// Table candela (before the spectrum's multiplier) toward a unit world direction.
    pub fn table_candela(&self, dir_world: Vec3) -> f64 {
        let l = self.rotation.transpose() * dir_world;
        self.distribution.eval([l.x as f64, l.y as f64, l.z as f64])
    }

    /// Luminous intensity (cd) toward a unit world direction, multiplier included.
    pub fn candela(&self, dir_world: Vec3) -> f64 {
        self.table_candela(dir_world) * luminous_integral(&self.spectrum)
    }

    /// Total luminous flux, lm.
    pub fn power_lm(&self) -> f64 {
        self.distribution.lumens() * luminous_integral(&self.spectrum)
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

/// Build the light for the scene loader. Errors are (field suffix, message), e.g.
/// (".file", "…").
pub fn build(
    file: &std::path::Path,
    position: Vec3,
    rotate_deg: Vec3,
    spectrum: DenseSpectrum,
    lumens: Option<f64>,
    multiplier: Option<f64>,
) -> Result<super::Light, (String, String)> {
    let phot = crate::luminaire::load(file).map_err(|e| (".file".to_string(), e.to_string()))?;
    let distribution = phot.distribution();
    let table_lm = distribution.lumens();
    let mut k = multiplier.unwrap_or(1.0);
    if let Some(target) = lumens {
        if table_lm <= 0.0 || !table_lm.is_finite() {
            return Err((
                ".lumens".into(),
                format!("the file's distribution carries no flux ({table_lm} lm), so it cannot be scaled to {target} lm"),
            ));
        }
        k *= target / table_lm;
    }
    let scale = crate::photometry::photometric_scale(&spectrum, k)
        .map_err(|m| (".spectrum".to_string(), m))?;
    let r = rotate_deg;
    let q = glam::Quat::from_rotation_z(r.z.to_radians())
        * glam::Quat::from_rotation_y(r.y.to_radians())
        * glam::Quat::from_rotation_x(r.x.to_radians());
    Ok(super::Light::Goniometric(Box::new(Goniometric {
        position,
        rotation: Mat3::from_quat(q),
        distribution: Arc::new(distribution),
        spectrum: spectrum.scaled(scale),
    })))
}
