//! α-opic quantities of CIE S 026/E:2018 ("CIE system for metrology of optical radiation for
//! ipRGC-influenced responses to light"): the irradiance (or radiance) weighted by each of the
//! five photoreceptor action spectra, its efficacy of luminous radiation, its D65 efficacy
//! ratio, the equivalent daylight (D65) illuminance or luminance, and WELL's equivalent
//! melanopic lux.
//!
//! Conventions, as in the CIE S 026 toolbox and luxpy's `spd_to_aopic*`:
//! * Every sum is Σ S(λ) w(λ) Δλ over **380–780 nm at 1 nm** (Δλ = 1 nm), the range S 026
//!   defines its action spectra on; the photopic E_v in the ratios is summed over the same
//!   range. (candela's luminance and illuminance elsewhere sum 360–830 nm; for daylight-like
//!   spectra the two differ by ~2e-6 relative.)
//! * K_m = 683 lm/W, candela's constant everywhere. S 026 quotes 683.002 lm/W (the maximum at
//!   555 nm); that would scale E_v, ELR and EDI by 1 + 2.9e-6 and leave DER unchanged.
//! * The reference D65 is candela's `D65` table (colour-science's CIE 15 table, linearly
//!   interpolated to 1 nm), so D65 itself has DER = 1 and m-EDI = E_v exactly. The CIE's own
//!   1 nm D65 (S 014-2) gives D65 ELRs within 4e-7 relative of these.
//!
//! The same functions serve irradiance and radiance: for a spectral irradiance in
//! W·m⁻²·nm⁻¹ the α-opic quantity is an irradiance in W·m⁻² and the EDI an illuminance in lx;
//! for a spectral radiance in W·m⁻²·sr⁻¹·nm⁻¹ it is a radiance in W·m⁻²·sr⁻¹ and the
//! equivalent daylight luminance (EDL) in cd/m².

use std::sync::LazyLock;

use crate::colour::colorimetry::K_M;
use crate::colour::grid::{LEN, START_NM};
use crate::colour::tables::{alpha_opic_action_spectra, named_spectrum, photopic_v};

/// The five photoreceptor types of CIE S 026, in the order of every `[f64; 5]` here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AlphaOpic {
    /// S-cone (cyanopic), s_sc(λ).
    SCone,
    /// M-cone (chloropic), s_mc(λ).
    MCone,
    /// L-cone (erythropic), s_lc(λ).
    LCone,
    /// Rods (rhodopic), s_rh(λ) = V′(λ).
    Rhodopic,
    /// ipRGC (melanopic), s_mel(λ).
    Melanopic,
}

impl AlphaOpic {
    /// All five, in array order.
    pub const ALL: [AlphaOpic; 5] = [
        AlphaOpic::SCone,
        AlphaOpic::MCone,
        AlphaOpic::LCone,
        AlphaOpic::Rhodopic,
        AlphaOpic::Melanopic,
    ];

    /// S 026's adjective: "cyanopic", "chloropic", "erythropic", "rhodopic", "melanopic".
    pub fn name(self) -> &'static str {
        match self {
            AlphaOpic::SCone => "cyanopic",
            AlphaOpic::MCone => "chloropic",
            AlphaOpic::LCone => "erythropic",
            AlphaOpic::Rhodopic => "rhodopic",
            AlphaOpic::Melanopic => "melanopic",
        }
    }

    /// Key used in JSON output: "s_cone", "m_cone", "l_cone", "rhodopic", "melanopic".
    pub fn key(self) -> &'static str {
        match self {
            AlphaOpic::SCone => "s_cone",
            AlphaOpic::MCone => "m_cone",
            AlphaOpic::LCone => "l_cone",
            AlphaOpic::Rhodopic => "rhodopic",
            AlphaOpic::Melanopic => "melanopic",
        }
    }

    /// The action spectrum s_α(λ) (1 at its peak), 360–830 nm at 1 nm, zero outside
    /// 380–780 nm.
    pub fn action_spectrum(self) -> &'static [f64; LEN] {
        &alpha_opic_action_spectra()[self as usize]
    }
}

/// Table indices of S 026's 380–780 nm range.
const S026: std::ops::RangeInclusive<usize> = (380 - START_NM as usize)..=(780 - START_NM as usize);

/// WELL's equivalent melanopic lux per lux of melanopic EDI: EML = m-EDI / 0.9058 (CIE S 026
/// toolbox user guide and WELL v2 L03; the ratio of the Lucas et al. (2014) melanopic
/// illuminant-E normalisation to S 026's D65 one).
pub const M_EDI_PER_EML: f64 = 0.9058;

/// α-opic irradiances E_e,α = Σ E_e,λ(λ) s_α(λ) Δλ over 380–780 nm, W/m² for a spectral
/// irradiance in W·m⁻²·nm⁻¹ (W·m⁻²·sr⁻¹ for a spectral radiance).
///
/// Reference: CIE S 026/E:2018 eq. (1); luxpy `spd_to_aopicE`.
pub fn alpha_opic_irradiance(spectrum: &[f64; LEN]) -> [f64; 5] {
    AlphaOpic::ALL.map(|a| {
        let s = a.action_spectrum();
        S026.clone().map(|i| spectrum[i] * s[i]).sum()
    })
}

/// Illuminance over S 026's range, E_v = K_m Σ E_e,λ V(λ) Δλ (380–780 nm), lx for a spectral
/// irradiance in W·m⁻²·nm⁻¹ (cd/m² for a spectral radiance).
pub fn illuminance_380_780(spectrum: &[f64; LEN]) -> f64 {
    let v = photopic_v();
    K_M * S026.clone().map(|i| spectrum[i] * v[i]).sum::<f64>()
}

/// α-opic efficacy of luminous radiation K_α,v = E_e,α / E_v, W/lm (scale-free).
///
/// Reference: CIE S 026/E:2018 §3.6 (α-opic ELR); luxpy `spd_to_aopicELR`.
pub fn alpha_opic_elr(spectrum: &[f64; LEN]) -> [f64; 5] {
    let ev = illuminance_380_780(spectrum);
    alpha_opic_irradiance(spectrum).map(|e| e / ev)
}

/// α-opic ELR of CIE standard illuminant D65, W/lm (S 026 Table 3 prints them in mW/lm:
/// 0.8173, 1.4558, 1.6289, 1.4497, 1.3262).
pub fn d65_elr() -> &'static [f64; 5] {
    static D65: LazyLock<[f64; 5]> =
        LazyLock::new(|| alpha_opic_elr(&named_spectrum("D65").expect("D65").to_table()));
    &D65
}

/// α-opic daylight (D65) efficacy ratio γ_α = K_α,v / K_α,v(D65) (dimensionless).
///
/// Reference: CIE S 026/E:2018 §3.8 (α-opic DER); luxpy `spd_to_aopicDER`.
pub fn alpha_opic_der(spectrum: &[f64; LEN]) -> [f64; 5] {
    let elr = alpha_opic_elr(spectrum);
    let d = d65_elr();
    std::array::from_fn(|k| elr[k] / d[k])
}

/// α-opic equivalent daylight (D65) illuminance E_v,α^D65 = E_e,α / K_α,v(D65): lx for a
/// spectral irradiance in W·m⁻²·nm⁻¹; for a spectral radiance it is the equivalent daylight
/// luminance (EDL) in cd/m². Equals DER·E_v.
///
/// Reference: CIE S 026/E:2018 §3.9 (α-opic EDI); luxpy `spd_to_aopicEDI`.
pub fn alpha_opic_edi(spectrum: &[f64; LEN]) -> [f64; 5] {
    let e = alpha_opic_irradiance(spectrum);
    let d = d65_elr();
    std::array::from_fn(|k| e[k] / d[k])
}

/// WELL equivalent melanopic lux (EML, "melanopic lux") from the melanopic EDI in lx:
/// EML = m-EDI / 0.9058 (see [`M_EDI_PER_EML`]).
pub fn equivalent_melanopic_lux(melanopic_edi_lx: f64) -> f64 {
    melanopic_edi_lx / M_EDI_PER_EML
}

/// Every α-opic quantity of one spectrum (index order [`AlphaOpic::ALL`]). Units are for a
/// spectral irradiance in W·m⁻²·nm⁻¹; for a spectral radiance read W·m⁻²·sr⁻¹ for W·m⁻² and
/// cd/m² for lx.
#[derive(Clone, Debug, PartialEq)]
pub struct AlphaOpicQuantities {
    /// α-opic irradiances E_e,α, W/m².
    pub irradiance_w_m2: [f64; 5],
    /// Photopic illuminance over 380–780 nm (K_m = 683 lm/W), lx.
    pub illuminance_lx: f64,
    /// α-opic efficacies of luminous radiation, W/lm.
    pub elr_w_per_lm: [f64; 5],
    /// α-opic D65 efficacy ratios (dimensionless).
    pub der: [f64; 5],
    /// α-opic equivalent daylight (D65) illuminances, lx.
    pub edi_lx: [f64; 5],
    /// WELL equivalent melanopic lux, = m-EDI / 0.9058.
    pub equivalent_melanopic_lux: f64,
}

/// All α-opic quantities of `spectrum` (see the module doc for range, K_m and units).
pub fn alpha_opic_quantities(spectrum: &[f64; LEN]) -> AlphaOpicQuantities {
    let irradiance_w_m2 = alpha_opic_irradiance(spectrum);
    let illuminance_lx = illuminance_380_780(spectrum);
    let d = d65_elr();
    let edi_lx: [f64; 5] = std::array::from_fn(|k| irradiance_w_m2[k] / d[k]);
    AlphaOpicQuantities {
        irradiance_w_m2,
        illuminance_lx,
        elr_w_per_lm: irradiance_w_m2.map(|e| e / illuminance_lx),
        der: std::array::from_fn(|k| irradiance_w_m2[k] / illuminance_lx / d[k]),
        equivalent_melanopic_lux: equivalent_melanopic_lux(edi_lx[4]),
        edi_lx,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn action_spectra_peak_at_one() {
        // Each S 026 action spectrum is normalised to 1 at its peak (S 026 Table 2), at
        // 448 (s), 541 (m), 569 (l), 506 (rh) and 490 nm (mel) on the 1 nm grid, within the
        // table's rounding (its peaks lie between grid points: 0.99994 for the m-cone).
        for (a, peak_nm) in AlphaOpic::ALL.iter().zip([448, 541, 569, 506, 490]) {
            let s = a.action_spectrum();
            let (i, m) = s
                .iter()
                .enumerate()
                .fold((0, 0.0), |b, (i, &v)| if v > b.1 { (i, v) } else { b });
            assert_eq!(i + START_NM as usize, peak_nm, "{a:?}");
            assert!((m - 1.0).abs() < 1e-4, "{a:?}: peak {m}");
        }
    }

    #[test]
    fn d65_is_its_own_reference() {
        let d65 = named_spectrum("D65").unwrap().to_table();
        let q = alpha_opic_quantities(&d65.map(|v| v * 1e-2));
        for k in 0..5 {
            assert!((q.der[k] - 1.0).abs() < 1e-14, "{k}: {}", q.der[k]);
            assert!((q.edi_lx[k] / q.illuminance_lx - 1.0).abs() < 1e-14);
        }
    }
}
