//! Mesopic photometry by CIE 191:2010 ("Recommended system for mesopic photometry based on
//! visual performance", the MES2 model): the mesopic luminance of a field of photopic
//! luminance L_p and scotopic luminance L_s = (S/P)·L_p, found by CIE 191's iteration for the
//! adaptation coefficient m, and the mesopic luminous efficiency function V_mes(λ) for that m.
//!
//! The S/P ratio is the one candela prints (`photometry::sp_ratio`: K′_m ΣSV′ / K_m ΣSV with
//! K′_m = 1700 lm/W, K_m = 683 lm/W), i.e. L_s in scotopic cd/m².

use crate::colour::grid::{LEN, START_NM};
use crate::colour::tables::{photopic_v, scotopic_v};

/// V′(λ₀) at λ₀ = 555 nm as CIE 191 writes it: 683/1699.
pub const V_PRIME_555: f64 = 683.0 / 1699.0;
/// CIE 191 adaptation coefficients: m = a + b·log10(L_mes / (cd/m²)).
pub const A: f64 = 0.7670;
/// See [`A`].
pub const B: f64 = 0.3334;
/// Upper limit of the mesopic range: at or above this L_mes (cd/m²) m = 1 (photopic).
pub const PHOTOPIC_LIMIT_CD_M2: f64 = 5.0;
/// Lower limit: at or below this L_mes (cd/m²) m = 0 (scotopic).
pub const SCOTOPIC_LIMIT_CD_M2: f64 = 0.005;

/// CIE 191 mesopic luminance for a given adaptation coefficient `m` (0–1):
/// L_mes = (m·L_p + (1 − m)·L_s·V′(λ₀)) / (m + (1 − m)·V′(λ₀)), cd/m² (L_p in cd/m², L_s in
/// scotopic cd/m²).
pub fn mesopic_luminance_for(m: f64, l_p_cd_m2: f64, l_s_cd_m2: f64) -> f64 {
    (m * l_p_cd_m2 + (1.0 - m) * l_s_cd_m2 * V_PRIME_555) / (m + (1.0 - m) * V_PRIME_555)
}

/// Result of [`mesopic_luminance`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mesopic {
    /// Mesopic luminance L_mes, cd/m².
    pub luminance_cd_m2: f64,
    /// Adaptation coefficient m (0 scotopic … 1 photopic).
    pub m: f64,
    /// Iterations until m changed by less than 1e-12.
    pub iterations: usize,
}

/// CIE 191:2010 mesopic luminance of a field of photopic luminance `l_p_cd_m2` (cd/m²) and
/// S/P ratio `sp_ratio` (L_s = S/P·L_p).
///
/// CIE 191 §3.2: start with m₀ = 0.5, then repeat L_mes,n = (m_{n−1}L_p + (1 − m_{n−1})L_s
/// V′(λ₀)) / (m_{n−1} + (1 − m_{n−1})V′(λ₀)) and m_n = 0.767 + 0.3334·log10(L_mes,n),
/// limited to 0 ≤ m ≤ 1 (m = 1 from L_mes ≥ 5 cd/m², 0 at L_mes ≤ 0.005 cd/m²), until m
/// converges (here: to 1e-12). The result is L_mes for the converged m. A zero luminance is
/// scotopic (m = 0, L_mes = 0). Peers: luxpy `get_cie_mesopic_adaptation` (see
/// `tests/colour_health.rs`).
pub fn mesopic_luminance(l_p_cd_m2: f64, sp_ratio: f64) -> Mesopic {
    let l_s = sp_ratio * l_p_cd_m2;
    let step = |m: f64| {
        let l = mesopic_luminance_for(m, l_p_cd_m2, l_s);
        if l > 0.0 {
            (A + B * l.log10()).clamp(0.0, 1.0)
        } else {
            0.0
        }
    };
    let mut m = 0.5;
    let mut iterations = 0;
    // The map is a contraction on the mesopic range (its slope is B/ln 10 times the relative
    // slope of L_mes in m, well below 1), so this converges in a few tens of steps.
    while iterations < 1000 {
        iterations += 1;
        let next = step(m);
        let done = (next - m).abs() < 1e-12;
        m = next;
        if done {
            break;
        }
    }
    Mesopic {
        luminance_cd_m2: mesopic_luminance_for(m, l_p_cd_m2, l_s),
        m,
        iterations,
    }
}

/// CIE 191 mesopic luminous efficiency function V_mes(λ) = (m V(λ) + (1 − m) V′(λ)) / M(m),
/// normalised to a peak of 1, 360–830 nm at 1 nm, and its efficacy at 555 nm
/// K_mes = 683 / V_mes(555 nm) in lm/W.
pub fn mesopic_luminous_efficiency(m: f64) -> ([f64; LEN], f64) {
    let (v, vp) = (photopic_v(), scotopic_v());
    let raw: [f64; LEN] = std::array::from_fn(|i| m * v[i] + (1.0 - m) * vp[i]);
    let peak = raw.iter().copied().fold(0.0, f64::max);
    let table = raw.map(|x| x / peak);
    let k = 683.0 / table[555 - START_NM as usize];
    (table, k)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_and_fixed_point() {
        // S/P = 1: L_s = L_p, so L_mes = L_p whatever m (the formula's weights sum to one).
        let r = mesopic_luminance(0.3, 1.0);
        assert!((r.luminance_cd_m2 - 0.3).abs() < 1e-15, "{r:?}");
        assert!((r.m - (A + B * 0.3f64.log10())).abs() < 1e-12);
        // Photopic and scotopic ends.
        assert_eq!(mesopic_luminance(10.0, 2.0).m, 1.0);
        assert_eq!(mesopic_luminance(10.0, 2.0).luminance_cd_m2, 10.0);
        assert_eq!(mesopic_luminance(1e-4, 1.0).m, 0.0);
        assert_eq!(mesopic_luminance(0.0, 1.5).luminance_cd_m2, 0.0);
        // A converged m satisfies its own equation.
        let r = mesopic_luminance(0.1, 2.0);
        let l = mesopic_luminance_for(r.m, 0.1, 0.2);
        assert!((A + B * l.log10() - r.m).abs() < 1e-12, "{r:?}");
        // V_mes for m = 1 is V(λ) (peak 1 at 555 nm): K_mes = 683 lm/W.
        let (v, k) = mesopic_luminous_efficiency(1.0);
        assert!((k - 683.0).abs() < 1e-9 && (v[555 - 360] - 1.0).abs() < 1e-12);
    }
}
