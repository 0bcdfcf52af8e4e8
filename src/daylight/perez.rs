//! The Perez all-weather sky (Perez, Seals & Michalsky 1993) and the Perez luminous efficacy
//! model (Perez, Ineichen, Seals, Michalsky & Stewart 1990), as Radiance's `gendaylit` uses
//! them.
//!
//! The sky's condition is given by its clearness ε and brightness Δ, computed from the
//! diffuse-horizontal irradiance E_d and direct-normal irradiance E_n (W/m²) and the sun's
//! zenith angle Z (radians):
//!
//! ε = ((E_d + E_n)/E_d + 1.041 Z³) / (1 + 1.041 Z³),  Δ = m E_d / E_0,
//!
//! with m the relative optical air mass (Kasten 1966) and E_0 the extraterrestrial irradiance
//! (1367 W/m² times the eccentricity correction of the day). ε selects one of eight bins; in
//! each, the five coefficients a…e of the luminance distribution are linear in Z and Δ
//! ([`COEFFICIENTS`], Perez 1993 Table 1; in the first bin c and d have their own forms), and
//!
//! L(Z, γ) ∝ (1 + a·exp(b / cos Z)) (1 + c·exp(d·γ) + e·cos²γ).
//!
//! When the sky is given by illuminances (lx), the irradiances are found as `gendaylit` finds
//! them: by iterating the efficacy model, which itself depends on ε and Δ, to its fixed point.

/// Perez 1993, Table 1: for each ε bin, for each of a, b, c, d, e, the coefficients
/// (x₁, x₂, x₃, x₄) of x = x₁ + x₂ Z + Δ (x₃ + x₄ Z).
pub const COEFFICIENTS: [[[f64; 4]; 5]; 8] = [
    [
        [1.3525, -0.2576, -0.269, -1.4366],
        [-0.767, 0.0007, 1.2734, -0.1233],
        [2.8, 0.6004, 1.2375, 1.0],
        [1.8734, 0.6297, 0.9738, 0.2809],
        [0.0356, -0.1246, -0.5718, 0.9938],
    ],
    [
        [-1.2219, -0.773, 1.4148, 1.1016],
        [-0.2054, 0.0367, -3.9128, 0.9156],
        [6.975, 0.1774, 6.4477, -0.1239],
        [-1.5798, -0.5081, -1.7812, 0.108],
        [0.2624, 0.0672, -0.219, -0.4285],
    ],
    [
        [-1.1, -0.2515, 0.8952, 0.0156],
        [0.2782, -0.1812, -4.5, 1.1766],
        [24.7219, -13.0812, -37.7, 34.8438],
        [-5.0, 1.5218, 3.9229, -2.6204],
        [-0.0156, 0.1597, 0.4199, -0.5562],
    ],
    [
        [-0.5484, -0.6654, -0.2672, 0.7117],
        [0.7234, -0.6219, -5.6812, 2.6297],
        [33.3389, -18.3, -62.25, 52.0781],
        [-3.5, 0.0016, 1.1477, 0.1062],
        [0.4659, -0.3296, -0.0876, -0.0329],
    ],
    [
        [-0.6, -0.3566, -2.5, 2.325],
        [0.2937, 0.0496, -5.6812, 1.8415],
        [21.0, -4.7656, -21.5906, 7.2492],
        [-3.5, -0.1554, 1.4062, 0.3988],
        [0.0032, 0.0766, -0.0656, -0.1294],
    ],
    [
        [-1.0156, -0.367, 1.0078, 1.4051],
        [0.2875, -0.5328, -3.85, 3.375],
        [14.0, -0.9999, -7.1406, 7.5469],
        [-3.4, -0.1078, -1.075, 1.5702],
        [-0.0672, 0.4016, 0.3017, -0.4844],
    ],
    [
        [-1.0, 0.0211, 0.5025, -0.5119],
        [-0.3, 0.1922, 0.7023, -1.6317],
        [19.0, -5.0, 1.2438, -1.9094],
        [-4.0, 0.025, 0.3844, 0.2656],
        [1.0468, -0.3788, -2.4517, 1.4656],
    ],
    [
        [-1.05, 0.0289, 0.426, 0.359],
        [-0.325, 0.1156, 0.7781, 0.0025],
        [31.0625, -14.5, -46.1148, 55.375],
        [-7.2312, 0.405, 13.35, 0.6234],
        [1.5, -0.6426, 1.8564, 0.5636],
    ],
];

/// Lower bounds of the eight clearness bins (the last ends at [`CLEARNESS_MAX`]).
pub const CLEARNESS_BINS: [f64; 8] = [1.0, 1.065, 1.23, 1.5, 1.95, 2.8, 4.5, 6.2];
/// The range of ε and Δ the models were fitted over; values outside are clamped to it.
pub const CLEARNESS_MAX: f64 = 12.01;
pub const BRIGHTNESS_RANGE: (f64, f64) = (0.01, 0.6);

/// Solar constant, W/m² (the value the Perez models were fitted with).
pub const SOLAR_CONSTANT_W_M2: f64 = 1367.0;

/// Perez 1990, Table 4: luminous efficacy (lm/W) of the diffuse-horizontal (`DIFFUSE`) and
/// direct-normal (`DIRECT`) irradiance per clearness bin, as (a, b, c, d) of
/// K = a + b W + c cos Z + d ln Δ (diffuse) and K = a + b W + c exp(5.73 Z − 5) + d Δ (direct),
/// W the atmospheric precipitable water (cm).
pub const DIFFUSE_EFFICACY: [[f64; 4]; 8] = [
    [97.24, -0.46, 12.00, -8.91],
    [107.22, 1.15, 0.59, -3.95],
    [104.97, 2.96, -5.53, -8.77],
    [102.39, 5.59, -13.95, -13.90],
    [100.71, 5.94, -22.75, -23.74],
    [106.42, 3.83, -36.15, -28.83],
    [141.88, 1.90, -53.24, -14.03],
    [152.23, 0.35, -45.27, -7.98],
];
pub const DIRECT_EFFICACY: [[f64; 4]; 8] = [
    [57.20, -4.55, -2.98, 117.12],
    [98.99, -3.46, -1.21, 12.38],
    [109.83, -4.90, -1.71, -8.81],
    [110.34, -5.84, -1.99, -4.56],
    [106.36, -3.97, -1.75, -6.16],
    [107.19, -1.25, -1.51, -26.73],
    [105.75, 0.77, -1.26, -34.44],
    [101.18, 1.58, -1.10, -8.29],
];

/// Eccentricity correction (R₀/R)² of day `day` of the year (1 = 1 January; Spencer 1971).
pub fn eccentricity(day: f64) -> f64 {
    let g = 2.0 * std::f64::consts::PI * (day - 1.0) / 365.0;
    1.00011
        + 0.034221 * g.cos()
        + 0.00128 * g.sin()
        + 0.000719 * (2.0 * g).cos()
        + 0.000077 * (2.0 * g).sin()
}

/// Relative optical air mass at solar zenith angle `zenith` (radians; Kasten 1966, as the
/// Perez models were fitted with), capped at the horizon.
pub fn air_mass(zenith: f64) -> f64 {
    let zd = zenith.to_degrees().min(90.0);
    1.0 / (zd.to_radians().cos() + 0.15 * (93.885 - zd).powf(-1.253))
}

/// Atmospheric precipitable water (cm) from the surface dew point (°C) (Perez 1990, after
/// Wright et al.).
pub fn precipitable_water(dew_point_c: f64) -> f64 {
    (0.07 * dew_point_c - 0.075).exp()
}

/// The default dew point, °C: gives 2 cm of precipitable water (gendaylit's default).
pub const DEFAULT_DEW_POINT_C: f64 = 10.973_531_15;

/// The sky's condition: clearness ε, brightness Δ, and the sun's zenith angle (radians).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyCondition {
    pub clearness: f64,
    pub brightness: f64,
    pub sun_zenith: f64,
}

/// What went wrong building a Perez sky.
#[derive(Clone, Debug, PartialEq)]
pub enum PerezError {
    /// An amount is NaN, infinite or negative.
    Invalid(&'static str),
    /// The sun is at or below the horizon while there is direct light.
    SunBelowHorizon,
    /// Neither direct nor diffuse light.
    Dark,
}

impl std::fmt::Display for PerezError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Invalid(what) => write!(f, "{what} must be a finite number ≥ 0"),
            Self::SunBelowHorizon => {
                write!(f, "direct light with the sun at or below the horizon")
            }
            Self::Dark => write!(f, "neither direct nor diffuse light: no Perez sky"),
        }
    }
}

fn bin(clearness: f64) -> usize {
    CLEARNESS_BINS
        .iter()
        .rposition(|&lo| clearness >= lo)
        .unwrap_or(0)
}

impl SkyCondition {
    /// From the diffuse-horizontal and direct-normal irradiance (W/m²), the sun at zenith
    /// angle `sun_zenith` (radians), the Earth–Sun distance correction `eccentricity`
    /// ((R₀/R)², [`eccentricity`] of the day, 1 at the mean distance); ε and Δ clamped to the
    /// models' range.
    pub fn from_irradiance(
        diffuse_horizontal_w_m2: f64,
        direct_normal_w_m2: f64,
        sun_zenith: f64,
        eccentricity: f64,
    ) -> Result<Self, PerezError> {
        let (ed, en) = (diffuse_horizontal_w_m2, direct_normal_w_m2);
        if !(ed.is_finite() && ed >= 0.0) {
            return Err(PerezError::Invalid("diffuse-horizontal irradiance"));
        }
        if !(en.is_finite() && en >= 0.0) {
            return Err(PerezError::Invalid("direct-normal irradiance"));
        }
        if !(sun_zenith.is_finite() && sun_zenith >= 0.0) {
            return Err(PerezError::Invalid("sun zenith angle"));
        }
        if ed + en == 0.0 {
            return Err(PerezError::Dark);
        }
        if en > 0.0 && sun_zenith >= std::f64::consts::FRAC_PI_2 {
            return Err(PerezError::SunBelowHorizon);
        }
        let z3 = 1.041 * sun_zenith.powi(3);
        let clearness = if ed > 0.0 {
            ((ed + en) / ed + z3) / (1.0 + z3)
        } else {
            CLEARNESS_MAX
        };
        let brightness = ed * air_mass(sun_zenith) / (SOLAR_CONSTANT_W_M2 * eccentricity);
        Ok(Self {
            clearness,
            brightness,
            sun_zenith,
        }
        .clamped())
    }

    /// From the diffuse-horizontal and direct-normal illuminance (lx): the irradiances are
    /// the fixed point of E = illuminance / K(ε(E), Δ(E)) under the efficacy model.
    /// Returns the condition and the irradiances (diffuse, direct), W/m².
    pub fn from_illuminance(
        diffuse_horizontal_lx: f64,
        direct_normal_lx: f64,
        sun_zenith: f64,
        eccentricity: f64,
        dew_point_c: f64,
    ) -> Result<(Self, [f64; 2]), PerezError> {
        let (vd, vn) = (diffuse_horizontal_lx, direct_normal_lx);
        if !(vd.is_finite() && vd >= 0.0) {
            return Err(PerezError::Invalid("diffuse-horizontal illuminance"));
        }
        if !(vn.is_finite() && vn >= 0.0) {
            return Err(PerezError::Invalid("direct-normal illuminance"));
        }
        if !dew_point_c.is_finite() {
            return Err(PerezError::Invalid("dew point"));
        }
        let w = precipitable_water(dew_point_c);
        // Start from the solar constant's own efficacy, 127 500 lx / 1367 W/m² (93.3 lm/W).
        let k0 = 127_500.0 / SOLAR_CONSTANT_W_M2;
        let (mut ed, mut en) = (vd / k0, vn / k0);
        let mut cond = Self::from_irradiance(ed, en, sun_zenith, eccentricity)?;
        for _ in 0..100 {
            let (kd, kn) = (cond.diffuse_efficacy(w), cond.direct_efficacy(w));
            let ed2 = if kd > 0.0 { vd / kd } else { 0.0 };
            let en2 = if kn >= 0.1 { vn / kn } else { 0.0 };
            let done =
                (ed2 - ed).abs() <= 1e-9 * ed.max(1.0) && (en2 - en).abs() <= 1e-9 * en.max(1.0);
            (ed, en) = (ed2, en2);
            cond = Self::from_irradiance(ed, en, sun_zenith, eccentricity)?;
            if done {
                break;
            }
        }
        Ok((cond, [ed, en]))
    }

    /// The sky's condition from irradiances (W/m², as [`SkyCondition::from_irradiance`] takes
    /// them), with the direct-normal and diffuse-horizontal illuminance (lx) the Perez
    /// efficacy model gives them at that condition and the dew point (°C): (condition, E_vn,
    /// E_vd).
    pub fn illuminance_from_irradiance(
        diffuse_horizontal_w_m2: f64,
        direct_normal_w_m2: f64,
        sun_zenith: f64,
        eccentricity: f64,
        dew_point_c: f64,
    ) -> Result<(Self, f64, f64), PerezError> {
        if !dew_point_c.is_finite() {
            return Err(PerezError::Invalid("dew point"));
        }
        let c = Self::from_irradiance(
            diffuse_horizontal_w_m2,
            direct_normal_w_m2,
            sun_zenith,
            eccentricity,
        )?;
        let water = precipitable_water(dew_point_c);
        Ok((
            c,
            direct_normal_w_m2 * c.direct_efficacy(water),
            diffuse_horizontal_w_m2 * c.diffuse_efficacy(water),
        ))
    }

    fn clamped(mut self) -> Self {
        self.clearness = self
            .clearness
            .clamp(CLEARNESS_BINS[0], CLEARNESS_MAX - 0.001);
        self.brightness = self
            .brightness
            .clamp(BRIGHTNESS_RANGE.0, BRIGHTNESS_RANGE.1);
        self
    }

    /// Luminous efficacy of the diffuse-horizontal irradiance (lm/W), W the precipitable
    /// water (cm).
    pub fn diffuse_efficacy(&self, water_cm: f64) -> f64 {
        let [a, b, c, d] = DIFFUSE_EFFICACY[bin(self.clearness)];
        a + b * water_cm + c * self.sun_zenith.cos() + d * self.brightness.ln()
    }

    /// Luminous efficacy of the direct-normal irradiance (lm/W), never negative.
    pub fn direct_efficacy(&self, water_cm: f64) -> f64 {
        let [a, b, c, d] = DIRECT_EFFICACY[bin(self.clearness)];
        (a + b * water_cm + c * (5.73 * self.sun_zenith - 5.0).exp() + d * self.brightness).max(0.0)
    }

    /// The five coefficients a…e of the luminance distribution.
    pub fn coefficients(&self) -> [f64; 5] {
        let z = self.sun_zenith;
        let k = bin(self.clearness);
        // Perez et al. advise Δ ≥ 0.2 in the intermediate bins, where smaller Δ extrapolates
        // the fit to negative luminances.
        let delta = if self.clearness > 1.065 && self.clearness < 2.8 {
            self.brightness.max(0.2)
        } else {
            self.brightness
        };
        let x = &COEFFICIENTS[k];
        let lin = |i: usize| x[i][0] + x[i][1] * z + delta * (x[i][2] + x[i][3] * z);
        if k == 0 {
            [
                lin(0),
                lin(1),
                (delta * (x[2][0] + x[2][1] * z)).powf(x[2][2]).exp() - x[2][3],
                -(delta * (x[3][0] + x[3][1] * z)).exp() + x[3][2] + delta * x[3][3],
                lin(4),
            ]
        } else {
            [lin(0), lin(1), lin(2), lin(3), lin(4)]
        }
    }
}

/// The Perez sky's luminance distribution, up to a scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PerezSky {
    pub condition: SkyCondition,
    pub coefficients: [f64; 5],
}

impl PerezSky {
    pub fn new(condition: SkyCondition) -> Self {
        Self {
            condition,
            coefficients: condition.coefficients(),
        }
    }

    /// Relative luminance (1 + a e^{b/cos Z})(1 + c e^{dγ} + e cos²γ) of a direction above
    /// the horizon with cos Z = `cos_z`, at angle `gamma` (radians) from the sun; 0 at or below
    /// the horizon, and never negative (the fit can dip below 0 outside its data).
    pub fn relative_luminance(&self, cos_z: f64, gamma: f64) -> f64 {
        if cos_z.is_nan() || cos_z <= 0.0 {
            return 0.0;
        }
        let [a, b, c, d, e] = self.coefficients;
        ((1.0 + a * (b / cos_z).exp()) * (1.0 + c * (d * gamma).exp() + e * gamma.cos().powi(2)))
            .max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clearness_and_brightness_round_trip() {
        // An overcast sky (no direct light) has ε = 1; a clear one a large ε.
        let c = SkyCondition::from_irradiance(100.0, 0.0, 0.6, eccentricity(172.0)).unwrap();
        assert_eq!(c.clearness, 1.0);
        let c = SkyCondition::from_irradiance(80.0, 800.0, 0.6, eccentricity(172.0)).unwrap();
        let z3 = 1.041 * 0.6f64.powi(3);
        assert!((c.clearness - (880.0 / 80.0 + z3) / (1.0 + z3)).abs() < 1e-12);
        assert!(c.clearness > 6.2 && bin(c.clearness) == 7);
        // Illuminance input reproduces itself through the efficacies.
        let (c, [ed, en]) =
            SkyCondition::from_illuminance(20_000.0, 70_000.0, 0.6, eccentricity(172.0), 11.0)
                .unwrap();
        let w = precipitable_water(11.0);
        assert!((ed * c.diffuse_efficacy(w) / 20_000.0 - 1.0).abs() < 1e-6);
        assert!((en * c.direct_efficacy(w) / 70_000.0 - 1.0).abs() < 1e-6);
    }

    #[test]
    fn bad_amounts_are_refused() {
        assert!(SkyCondition::from_irradiance(f64::NAN, 1.0, 0.5, 1.0).is_err());
        assert!(SkyCondition::from_irradiance(1.0, -1.0, 0.5, 1.0).is_err());
        assert_eq!(
            SkyCondition::from_irradiance(0.0, 0.0, 0.5, 1.0),
            Err(PerezError::Dark)
        );
        assert_eq!(
            SkyCondition::from_irradiance(10.0, 100.0, 1.6, 1.0),
            Err(PerezError::SunBelowHorizon)
        );
    }

    #[test]
    fn eccentricity_extremes() {
        // Earth is nearest the sun in early January (+3.4 %), farthest in early July (−3.3 %).
        assert!((eccentricity(3.0) - 1.0342).abs() < 1e-3);
        assert!((eccentricity(185.0) - 0.9669).abs() < 1e-3);
    }
}
