//! Display units of reports: which unit of [`crate::photometry`]'s table a report prints a
//! quantity in for an SI (cd/m², lx, m) or imperial (fL, fc, ft) system, and how numbers are
//! formatted. Every value candela computes is SI; reports convert only when they print or
//! draw, with the unit's own factor.

use crate::photometry::{
    Quantity, Unit, CANDELA, FOOTCANDLE, FOOTLAMBERT, FOOT_M, LUMEN, LUX, NIT, TALBOT,
};

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

    /// The unit this system shows `q` in: cd/m² or fL, lx or fc; lm, cd and lm·s in both.
    pub fn unit(self, q: Quantity) -> &'static Unit {
        match (self, q) {
            (UnitSystem::Si, Quantity::Luminance) => &NIT,
            (UnitSystem::Si, Quantity::Illuminance) => &LUX,
            (UnitSystem::Imperial, Quantity::Luminance) => &FOOTLAMBERT,
            (UnitSystem::Imperial, Quantity::Illuminance) => &FOOTCANDLE,
            (_, Quantity::LuminousFlux) => &LUMEN,
            (_, Quantity::LuminousIntensity) => &CANDELA,
            (_, Quantity::LuminousEnergy) => &TALBOT,
        }
    }

    /// Unit symbol of `q`: `cd/m²`, `lx`, `fL` or `fc` (see [`UnitSystem::unit`]).
    pub fn symbol(self, q: Quantity) -> &'static str {
        self.unit(q).symbol
    }

    /// How many SI units (cd/m² or lx) one display unit of `q` is.
    pub fn si_per_unit(self, q: Quantity) -> f64 {
        self.unit(q).si
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
            UnitSystem::Imperial => m / FOOT_M,
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
        use crate::photometry::{CD_M2_PER_FL, LX_PER_FC};
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
