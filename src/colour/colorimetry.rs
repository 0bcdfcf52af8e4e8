//! Spectral → tristimulus integration (CIE XYZ), absolute and relative.
//!
//! All spectra are 1 nm tables over 360–830 nm (`[f64; LEN]`, index `i` ↔ `360 + i` nm),
//! the grid of the colour-matching functions, so integration is the plain sum
//! Σ S(λ) x̄(λ) Δλ with Δλ = 1 nm — exactly colour-science's `sd_to_XYZ_integration`
//! (`k * np.dot(R * S, cmfs) * d_w`) for 1 nm data.
//!
//! **Which colour-science method this matches.** colour-science's `sd_to_XYZ` defaults to
//! `method="ASTM E308"`; for 1 nm data that method *is* `sd_to_XYZ_integration`, but with
//! `use_practice_range=True` it first trims the CMFs to 360–780 nm.  candela's default
//! ([`XyzMethod::Integration`]) integrates the full 360–830 nm tables, i.e. colour-science
//! `sd_to_XYZ(sd, cmfs, illuminant, method="Integration")` (equivalently
//! `use_practice_range=False`), which is also what the spectral renderer integrates.
//! [`XyzMethod::AstmE308`] reproduces colour-science's default (360–780 nm) bit for bit
//! in method; the difference is the 780–830 nm tail (≤ ~1e-4 relative for deep reds).

use crate::colour::tables::{cmfs, Observer};

use crate::colour::grid::LEN;

/// Maximum luminous efficacy for photopic vision, lm/W (CIE; colour-science
/// `CONSTANT_K_M`): absolute Y in cd/m² from a radiance. Re-exported by
/// `photometry`, which builds on this module.
pub const K_M: f64 = 683.0;

/// Integration method, named after colour-science's `sd_to_XYZ(method=...)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum XyzMethod {
    /// Full 360–830 nm sum (colour-science `method="Integration"`). candela's default.
    #[default]
    Integration,
    /// colour-science's default `method="ASTM E308"` for 1 nm data: the same sum, with the
    /// CMFs trimmed to the ASTM E308 practice range 360–780 nm.
    AstmE308,
}

impl XyzMethod {
    /// Number of 1 nm samples (from 360 nm) the method sums over.
    pub fn len(self) -> usize {
        match self {
            XyzMethod::Integration => LEN,
            XyzMethod::AstmE308 => 780 - 360 + 1,
        }
    }

    /// Always false (both methods cover a non-empty range).
    pub fn is_empty(self) -> bool {
        false
    }
}

/// Σ w(λ) · x̄ȳz̄(λ) · Δλ over the method's range (Δλ = 1 nm).
fn weighted_sums(w: impl Fn(usize) -> f64, observer: Observer, method: XyzMethod) -> [f64; 3] {
    let c = cmfs(observer);
    let mut s = [0.0; 3];
    for i in 0..method.len() {
        let wi = w(i);
        s[0] += wi * c.x[i];
        s[1] += wi * c.y[i];
        s[2] += wi * c.z[i];
    }
    s
}

/// Absolute tristimulus values X, Y, Z = K_m Σ S(λ) x̄ȳz̄(λ) Δλ with K_m = 683 lm/W.
///
/// With `spectrum` a spectral radiance in W·m⁻²·sr⁻¹·nm⁻¹, Y is the luminance in cd/m²
/// (for irradiance in W·m⁻²·nm⁻¹, Y is illuminance in lx).  No colorimetric normalisation.
///
/// Reference: CIE 15:2018 §7.1 (k = K_m for photometric Y); colour-science
/// `sd_to_XYZ(sd, cmfs, k=683, method="Integration")` (for 1 nm data; note that
/// colour-science's default ASTM E308 path divides by 100 when `k` is given for intervals
/// other than 1 nm).
pub fn sd_to_xyz_absolute(spectrum: &[f64; LEN], observer: Observer) -> [f64; 3] {
    sd_to_xyz_absolute_with(spectrum, observer, XyzMethod::Integration)
}

/// [`sd_to_xyz_absolute`] with an explicit [`XyzMethod`].
pub fn sd_to_xyz_absolute_with(
    spectrum: &[f64; LEN],
    observer: Observer,
    method: XyzMethod,
) -> [f64; 3] {
    let s = weighted_sums(|i| spectrum[i], observer, method);
    [K_M * s[0], K_M * s[1], K_M * s[2]]
}

/// Relative tristimulus values of an object colour: reflectance (or transmittance)
/// `reflectance` under `illuminant`, normalised so the perfect diffuser has Y = 100:
/// X = k Σ R S x̄ Δλ, k = 100 / Σ S ȳ Δλ.
///
/// Reference: CIE 15:2018 §7.1, eq. 7.1–7.4; colour-science
/// `sd_to_XYZ(sd, cmfs, illuminant, method="Integration")` (`sd_to_XYZ_integration`).
pub fn sd_to_xyz_relative(
    reflectance: &[f64; LEN],
    illuminant: &[f64; LEN],
    observer: Observer,
) -> [f64; 3] {
    sd_to_xyz_relative_with(reflectance, illuminant, observer, XyzMethod::Integration)
}

/// [`sd_to_xyz_relative`] with an explicit [`XyzMethod`].
pub fn sd_to_xyz_relative_with(
    reflectance: &[f64; LEN],
    illuminant: &[f64; LEN],
    observer: Observer,
    method: XyzMethod,
) -> [f64; 3] {
    let c = cmfs(observer);
    let n = method.len();
    let norm: f64 = c.y[..n]
        .iter()
        .zip(&illuminant[..n])
        .map(|(y, s)| y * s)
        .sum();
    let k = 100.0 / norm;
    // colour-science: XYZ = k * np.dot(R * S, cmfs) * d_w
    let s = weighted_sums(|i| reflectance[i] * illuminant[i], observer, method);
    [k * s[0], k * s[1], k * s[2]]
}

/// Relative tristimulus values of a light source, colour-science's default for an
/// emissive spectrum: the spectrum is treated as a "reflectance" under the equal-energy
/// illuminant E, X = 100 Σ S x̄ / Σ ȳ (so S ≡ 1 gives Y = 100).
///
/// Reference: colour-science `sd_to_XYZ(sd, cmfs, method="Integration")` (illuminant
/// defaults to E).
pub fn sd_to_xyz_emissive(spectrum: &[f64; LEN], observer: Observer) -> [f64; 3] {
    sd_to_xyz_emissive_with(spectrum, observer, XyzMethod::Integration)
}

/// [`sd_to_xyz_emissive`] with an explicit [`XyzMethod`].
pub fn sd_to_xyz_emissive_with(
    spectrum: &[f64; LEN],
    observer: Observer,
    method: XyzMethod,
) -> [f64; 3] {
    sd_to_xyz_relative_with(spectrum, &[1.0; LEN], observer, method)
}

/// White point XYZ (Y = 1) of an illuminant table under `observer`.
pub fn whitepoint_xyz(illuminant: &[f64; LEN], observer: Observer) -> [f64; 3] {
    let w = sd_to_xyz_emissive(illuminant, observer);
    [w[0] / w[1], 1.0, w[2] / w[1]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::tables::named_spectrum;

    #[test]
    fn equal_energy_is_white() {
        let e = [1.0; LEN];
        let xyz = sd_to_xyz_emissive(&e, Observer::Cie1931_2);
        assert!((xyz[1] - 100.0).abs() < 1e-12);
        let abs = sd_to_xyz_absolute(&e, Observer::Cie1931_2);
        assert!((abs[1] - 683.0 * 106.856917).abs() < 1e-3);
        let d65 = named_spectrum("D65").unwrap().to_table();
        let wp = sd_to_xyz_relative(&[1.0; LEN], &d65, Observer::Cie1931_2);
        assert!((wp[1] - 100.0).abs() < 1e-12);
        // D65 white point x,y (CIE 15: 0.31272, 0.32903 from 1 nm data).
        let s = wp[0] + wp[1] + wp[2];
        assert!((wp[0] / s - 0.3127).abs() < 2e-4 && (wp[1] / s - 0.3290).abs() < 2e-4);
    }
}
