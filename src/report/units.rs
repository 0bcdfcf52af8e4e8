//! Units for displaying photometric values: SI (cd/m², lx) or imperial (fL, fc).
//!
//! Every value candela computes is SI; reports convert only when they print or draw. The
//! factors are those of [`crate::photometry`] (international foot, NIST SP 811):
//! 1 fc = 1 lm/ft² = 10.763 910 417 lx and 1 fL = (1/π) cd/ft² = 3.426 259 099 6 cd/m².

use crate::photometry::FOOT_M;

/// Lux per footcandle (1 lm/ft²).
pub const LX_PER_FC: f64 = 1.0 / (FOOT_M * FOOT_M);
/// cd/m² per footlambert ((1/π) cd/ft²).
pub const CD_M2_PER_FL: f64 = 1.0 / (std::f64::consts::PI * FOOT_M * FOOT_M);
/// Metres per foot (international foot).
pub const M_PER_FT: f64 = FOOT_M;

/// The photometric quantity a report shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Quantity {
    /// Luminance (EXR channel `Y`), cd/m² or fL.
    #[default]
    Luminance,
    /// Illuminance (EXR channel `E`, or a calculation grid), lx or fc.
    Illuminance,
}

impl Quantity {
    /// `"luminance"` or `"illuminance"`.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Luminance => "luminance",
            Quantity::Illuminance => "illuminance",
        }
    }

    /// Parses `luminance`/`L`/`Y` or `illuminance`/`E` (case-insensitive).
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "luminance" | "l" | "y" => Some(Quantity::Luminance),
            "illuminance" | "e" => Some(Quantity::Illuminance),
            _ => None,
        }
    }
}

/// SI or imperial display units.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum UnitSystem {
    /// cd/m², lx, m.
    #[default]
    Si,
    /// fL, fc, ft.
    Imperial,
}

impl UnitSystem {
    /// `"si"` or `"imperial"` (the value reports write as `units.system`).
    pub fn name(self) -> &'static str {
        match self {
            UnitSystem::Si => "si",
            UnitSystem::Imperial => "imperial",
        }
    }

    /// Parses `si`/`metric` or `imperial`/`us` (case-insensitive).
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "si" | "metric" => Some(UnitSystem::Si),
            "imperial" | "us" => Some(UnitSystem::Imperial),
            _ => None,
        }
    }

    /// Unit symbol of `q`: `cd/m²`, `lx`, `fL` or `fc`.
    pub fn symbol(self, q: Quantity) -> &'static str {
        match (self, q) {
            (UnitSystem::Si, Quantity::Luminance) => "cd/m²",
            (UnitSystem::Si, Quantity::Illuminance) => "lx",
            (UnitSystem::Imperial, Quantity::Luminance) => "fL",
            (UnitSystem::Imperial, Quantity::Illuminance) => "fc",
        }
    }

    /// How many SI units (cd/m² or lx) one display unit of `q` is.
    pub fn si_per_unit(self, q: Quantity) -> f64 {
        match (self, q) {
            (UnitSystem::Si, _) => 1.0,
            (UnitSystem::Imperial, Quantity::Luminance) => CD_M2_PER_FL,
            (UnitSystem::Imperial, Quantity::Illuminance) => LX_PER_FC,
        }
    }

    /// Converts an SI value (cd/m² or lx) of `q` to this system's unit.
    pub fn from_si(self, q: Quantity, si: f64) -> f64 {
        si / self.si_per_unit(q)
    }

    /// Converts a value in this system's unit of `q` to SI (cd/m² or lx).
    pub fn to_si(self, q: Quantity, value: f64) -> f64 {
        value * self.si_per_unit(q)
    }

    /// Length unit symbol: `m` or `ft`.
    pub fn length_symbol(self) -> &'static str {
        match self {
            UnitSystem::Si => "m",
            UnitSystem::Imperial => "ft",
        }
    }

    /// Converts a length in metres to this system's length unit.
    pub fn length_from_m(self, m: f64) -> f64 {
        match self {
            UnitSystem::Si => m,
            UnitSystem::Imperial => m / M_PER_FT,
        }
    }
}

/// Formats `v` with about `sig` significant digits, without trailing zeros or exponent for
/// everyday magnitudes (1e-3 ≤ |v| < 1e6): `512`, `12.5`, `0.042`, `1.2e-5`.
pub fn format_sig(v: f64, sig: usize) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    if v == 0.0 {
        return "0".to_string();
    }
    let a = v.abs();
    if !(1e-3..1e6).contains(&a) {
        let s = format!("{:.*e}", sig.saturating_sub(1), v);
        // "1.20e-5" -> "1.2e-5"
        if let Some((mant, exp)) = s.split_once('e') {
            return format!("{}e{exp}", trim_zeros(mant));
        }
        return s;
    }
    let digits_before = a.log10().floor() as i32 + 1;
    let decimals = (sig as i32 - digits_before).max(0) as usize;
    let s = format!("{:.*}", decimals, v);
    trim_zeros(&s)
}

fn trim_zeros(s: &str) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_match_the_definitions() {
        assert!((LX_PER_FC - 10.763910417).abs() < 1e-8);
        assert!((CD_M2_PER_FL - 3.4262590996).abs() < 1e-9);
        let fc = crate::photometry::convert(100.0, "lx", "fc").unwrap();
        assert!((UnitSystem::Imperial.from_si(Quantity::Illuminance, 100.0) - fc).abs() < 1e-12);
        let fl = crate::photometry::convert(100.0, "cd/m2", "fL").unwrap();
        assert!((UnitSystem::Imperial.from_si(Quantity::Luminance, 100.0) - fl).abs() < 1e-12);
        assert_eq!(UnitSystem::Si.from_si(Quantity::Luminance, 3.5), 3.5);
    }

    #[test]
    fn significant_digits() {
        assert_eq!(format_sig(512.3, 3), "512");
        assert_eq!(format_sig(12.5, 3), "12.5");
        assert_eq!(format_sig(0.0420, 3), "0.042");
        assert_eq!(format_sig(100.0, 3), "100");
        assert_eq!(format_sig(1234.0, 3), "1234");
        assert_eq!(format_sig(0.0, 3), "0");
        assert_eq!(format_sig(1.2e-5, 3), "1.2e-5");
        assert_eq!(format_sig(-2.5, 3), "-2.5");
    }
}
