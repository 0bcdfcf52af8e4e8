//! The 1 nm wavelength grid of every spectral table: 360..=830 nm, index `i` ↔ `360 + i` nm.

/// First tabulated wavelength, nm.
pub const START_NM: u32 = 360;
/// Last tabulated wavelength, nm.
pub const END_NM: u32 = 830;
/// Number of 1 nm samples from [`START_NM`] to [`END_NM`] inclusive.
pub const LEN: usize = 471;
