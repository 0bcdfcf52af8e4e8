//! Photometry: luminous quantities from spectral radiometric ones, and photometric units.

/// Maximum luminous efficacy for photopic vision, lm/W (CIE; colour-science
/// `CONSTANT_K_M`).
pub const K_M: f64 = 683.0;
/// Maximum luminous efficacy for scotopic vision, lm/W (CIE 1951; colour-science
/// `CONSTANT_KP_M`).
pub const K_M_SCOTOPIC: f64 = 1700.0;
