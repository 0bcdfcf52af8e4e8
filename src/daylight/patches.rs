//! The sky divided into patches for daylight coefficients: Tregenza's 145 patches and
//! Reinhart's subdivision of them (multiplication factor MF: each patch below the zenith cap
//! split into MF × MF, 144·MF² + 1 patches), numbered as Radiance's `gendaymtx` and
//! `reinhart.cal` number them — 0 the ground, 1 the patch on the horizon due north, then on
//! round that row toward the east, row after row up to the zenith cap, the last.
//!
//! A sky vector gives each patch the mean luminance (cd/m²) of one sky over the patch, so that
//! an illuminance is Σ coefficient × luminance when each coefficient is the illuminance from
//! its patch glowing at 1 cd/m².

use super::perez::{PerezError, PerezSky, SkyCondition};
use std::f64::consts::{FRAC_PI_2, PI};

/// Patches per row of Tregenza's subdivision, from the horizon up (the zenith cap apart).
const TREGENZA_ROWS: [usize; 7] = [30, 30, 24, 24, 18, 12, 6];

/// The largest multiplication factor accepted: MF 8 already gives 9217 patches.
pub const MAX_MF: u32 = 8;

/// One sky patch: altitude band and azimuth span (radians; azimuth from north toward east),
/// and its solid angle (sr).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Patch {
    pub altitude: (f64, f64),
    /// Centre and half-width of the azimuth span; the zenith cap spans the whole circle.
    pub azimuth: (f64, f64),
    pub solid_angle_sr: f64,
}

impl Patch {
    /// Unit direction of the patch's centre (east, north, up).
    pub fn centre(&self) -> [f64; 3] {
        let alt = if self.altitude.1 >= FRAC_PI_2 {
            FRAC_PI_2
        } else {
            0.5 * (self.altitude.0 + self.altitude.1)
        };
        let az = self.azimuth.0;
        [alt.cos() * az.sin(), alt.cos() * az.cos(), alt.sin()]
    }
}

/// Reinhart's subdivision at one multiplication factor.
#[derive(Clone, Debug)]
pub struct SkyPatches {
    mf: u32,
    /// Patches per row from the horizon up, the zenith cap excluded.
    rows: Vec<usize>,
    /// Angular height of a row (radians); the zenith cap's radius is half of it.
    row_height: f64,
}

impl SkyPatches {
    /// The subdivision with multiplication factor `mf` (1 = Tregenza's 145 patches).
    pub fn new(mf: u32) -> Result<Self, String> {
        if !(1..=MAX_MF).contains(&mf) {
            return Err(format!(
                "the sky subdivision's multiplication factor must be 1 … {MAX_MF}, got {mf}"
            ));
        }
        let m = mf as usize;
        let rows = (0..7 * m).map(|i| TREGENZA_ROWS[i / m] * m).collect();
        Ok(Self {
            mf,
            rows,
            row_height: FRAC_PI_2 / (7.0 * mf as f64 + 0.5),
        })
    }

    pub fn mf(&self) -> u32 {
        self.mf
    }

    /// Number of patches, the ground (patch 0) included: 144·MF² + 2.
    pub fn len(&self) -> usize {
        self.rows.iter().sum::<usize>() + 2
    }

    /// Never empty; for clippy's `len_without_is_empty`.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Sky patch `i` (1 … len − 1); `None` for the ground (0) or past the end.
    pub fn patch(&self, i: usize) -> Option<Patch> {
        if i == 0 || i >= self.len() {
            return None;
        }
        let h = self.row_height;
        if i == self.len() - 1 {
            return Some(Patch {
                altitude: (FRAC_PI_2 - 0.5 * h, FRAC_PI_2),
                azimuth: (0.0, PI),
                solid_angle_sr: 2.0 * PI * (1.0 - (0.5 * h).cos()),
            });
        }
        let mut first = 1;
        for (r, &n) in self.rows.iter().enumerate() {
            if i < first + n {
                let j = i - first;
                let (lo, hi) = (r as f64 * h, (r + 1) as f64 * h);
                return Some(Patch {
                    altitude: (lo, hi),
                    azimuth: (2.0 * PI * j as f64 / n as f64, PI / n as f64),
                    solid_angle_sr: 2.0 * PI * (hi.sin() - lo.sin()) / n as f64,
                });
            }
            first += n;
        }
        None
    }

    /// The patch a unit direction (east, north, up) falls in: 0 at or below the horizon.
    pub fn index(&self, d: [f64; 3]) -> usize {
        if d[2].is_nan() || d[2] <= 0.0 {
            return 0;
        }
        let alt = d[2].min(1.0).asin();
        let row = (alt / self.row_height) as usize;
        if row >= self.rows.len() {
            return self.len() - 1;
        }
        let n = self.rows[row];
        let az = d[0].atan2(d[1]).rem_euclid(2.0 * PI);
        let j = ((az / (2.0 * PI) * n as f64 + 0.5) as usize) % n;
        1 + self.rows[..row].iter().sum::<usize>() + j
    }

    /// ∫ f(direction) dω over sky patch `i` (midpoint rule on a k × k grid in sin(altitude)
    /// and azimuth; on the zenith cap, in cos of the angle from the zenith and azimuth).
    pub fn integrate(&self, i: usize, k: usize, f: impl Fn([f64; 3]) -> f64) -> f64 {
        let Some(p) = self.patch(i) else {
            return 0.0;
        };
        let (s0, s1) = (p.altitude.0.sin(), p.altitude.1.sin());
        let (az0, daz) = (p.azimuth.0 - p.azimuth.1, 2.0 * p.azimuth.1);
        let mut sum = 0.0;
        for a in 0..k {
            let s = s0 + (s1 - s0) * (a as f64 + 0.5) / k as f64;
            let c = (1.0 - s * s).max(0.0).sqrt();
            for b in 0..k {
                let az = az0 + daz * (b as f64 + 0.5) / k as f64;
                sum += f([c * az.sin(), c * az.cos(), s]);
            }
        }
        sum * (s1 - s0) * daz / (k * k) as f64
    }
}

/// One hour's Perez sky over the patches: for each patch its mean luminance (cd/m²) — patch 0
/// the ground's, ρ_g (E_vd + E_vn sin(altitude)) / π — without the sun's disk, which a
/// daylight-coefficient calculation traces on its own.
#[derive(Clone, Debug, PartialEq)]
pub struct SkyVector {
    pub luminance_cd_m2: Vec<f64>,
    /// The sky's diffuse-horizontal and the sun's direct-normal illuminance (lx).
    pub diffuse_horizontal_lx: f64,
    pub direct_normal_lx: f64,
}

/// Sub-samples per side of a patch's quadrature: 8 × 8 for Tregenza's 12° patches, fewer as
/// the patches shrink.
fn quadrature_side(mf: u32) -> usize {
    (8 / mf as usize).max(2)
}

impl SkyVector {
    /// The Perez sky (Perez, Seals & Michalsky 1993; luminous efficacies of Perez et al. 1990
    /// at the dew point `dew_point_c`, °C) of diffuse-horizontal and direct-normal irradiance
    /// (W/m²) with the sun at unit direction `sun` (east, north, up), the Earth–Sun distance
    /// correction `eccentricity` ([`super::perez::eccentricity`] of the day), over `patches`, above a ground of reflectance `ground_reflectance`. A sun at or below
    /// the horizon counts as on it for the sky's shape, as gendaymtx does, and its direct light
    /// is then dropped.
    pub fn perez(
        patches: &SkyPatches,
        diffuse_horizontal_w_m2: f64,
        direct_normal_w_m2: f64,
        sun: [f64; 3],
        eccentricity: f64,
        dew_point_c: f64,
        ground_reflectance: f64,
    ) -> Result<Self, PerezError> {
        let n = patches.len();
        if !(direct_normal_w_m2.is_finite() && direct_normal_w_m2 >= 0.0) {
            return Err(PerezError::Invalid("direct-normal irradiance"));
        }
        let sin_alt = sun[2].clamp(-1.0, 1.0);
        let direct = if sin_alt > 0.0 {
            direct_normal_w_m2
        } else {
            0.0
        };
        if diffuse_horizontal_w_m2 == 0.0 && direct == 0.0 {
            // Night, or only direct light with the sun down: a dark sky.
            return Ok(Self {
                luminance_cd_m2: vec![0.0; n],
                diffuse_horizontal_lx: 0.0,
                direct_normal_lx: 0.0,
            });
        }
        // The model's sun never sits below the horizon (nor, as in gendaymtx, within 3° of
        // the zenith, where the circumsolar term would fold onto it).
        let zenith = sin_alt
            .max(0.0)
            .acos()
            .clamp(3f64.to_radians(), FRAC_PI_2 - 1e-9);
        let (cond, e_vn, e_vd) = SkyCondition::illuminance_from_irradiance(
            diffuse_horizontal_w_m2,
            direct,
            zenith,
            eccentricity,
            dew_point_c,
        )?;
        let sky = PerezSky::new(cond);
        let h = sun[0].hypot(sun[1]);
        let (sx, sy) = if h > 1e-12 {
            (sun[0] / h, sun[1] / h)
        } else {
            (0.0, 1.0)
        };
        let s = [zenith.sin() * sx, zenith.sin() * sy, zenith.cos()];
        let rel = |d: [f64; 3]| {
            let cos_gamma = (d[0] * s[0] + d[1] * s[1] + d[2] * s[2]).clamp(-1.0, 1.0);
            sky.relative_luminance(d[2], cos_gamma.acos())
        };
        // A year is 4000-odd such skies: 128 × 256 cells keep the normalisation within 10⁻⁴.
        let norm =
            super::horizontal_integral_with(zenith, 128, 256, |u, g| sky.relative_luminance(u, g));
        let scale = if norm > 0.0 { e_vd / norm } else { 0.0 };
        let k = quadrature_side(patches.mf());
        let mut luminance = vec![0.0; n];
        luminance[0] = ground_reflectance * (e_vd + e_vn * sin_alt.max(0.0)) / PI;
        for (i, l) in luminance.iter_mut().enumerate().skip(1) {
            let p = patches.patch(i).expect("patch in range");
            *l = scale * patches.integrate(i, k, rel) / p.solid_angle_sr;
        }
        Ok(Self {
            luminance_cd_m2: luminance,
            diffuse_horizontal_lx: e_vd,
            direct_normal_lx: e_vn,
        })
    }

    /// The horizontal illuminance (lx) the sky patches give an unobstructed point:
    /// Σ L̄ᵢ ∫ᵢ cos Z dω, which equals the diffuse-horizontal illuminance.
    pub fn horizontal_illuminance(&self, patches: &SkyPatches) -> f64 {
        (1..patches.len())
            .map(|i| self.luminance_cd_m2[i] * patches.integrate(i, 4, |d| d[2]))
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patch_counts_and_solid_angles() {
        for mf in 1..=4 {
            let p = SkyPatches::new(mf).unwrap();
            assert_eq!(p.len(), 144 * (mf * mf) as usize + 2);
            let total: f64 = (1..p.len())
                .map(|i| p.patch(i).unwrap().solid_angle_sr)
                .sum();
            assert!((total - 2.0 * PI).abs() < 1e-12, "MF {mf}: Σω = {total}");
        }
        assert!(SkyPatches::new(0).is_err() && SkyPatches::new(MAX_MF + 1).is_err());
    }

    #[test]
    fn index_finds_each_patch_centre() {
        for mf in [1, 2, 4] {
            let p = SkyPatches::new(mf).unwrap();
            for i in 1..p.len() {
                assert_eq!(p.index(p.patch(i).unwrap().centre()), i, "MF {mf}");
            }
            assert_eq!(p.index([0.0, 1.0, -0.1]), 0);
        }
        // Patch 1 is on the horizon due north, patch 2 east of it.
        let p = SkyPatches::new(1).unwrap();
        assert_eq!(p.index([0.0, 1.0, 0.01]), 1);
        assert_eq!(p.index([0.2, 1.0, 0.01]), 2);
        assert_eq!(p.index([0.0, 0.0, 1.0]), 145);
    }

    /// The patches' mean luminances times their cos-weighted solid angles give back the
    /// diffuse-horizontal illuminance, to within the patch's resolution (the luminance and
    /// cos Z vary together across a patch), better as the patches shrink.
    #[test]
    fn sky_vector_keeps_the_diffuse_illuminance() {
        let alt = 35f64.to_radians();
        let sun = [alt.cos() * 0.5, -alt.cos() * 0.75f64.sqrt(), alt.sin()];
        let mut errors = vec![];
        for (mf, tolerance) in [(1, 6e-3), (2, 2e-3), (4, 5e-4)] {
            let p = SkyPatches::new(mf).unwrap();
            let v = SkyVector::perez(&p, 120.0, 600.0, sun, 1.0, 11.0, 0.2).unwrap();
            let e = v.horizontal_illuminance(&p) / v.diffuse_horizontal_lx - 1.0;
            errors.push(e);
            assert!(e.abs() < tolerance, "MF {mf}: {e}");
        }
        println!("Σ L̄ cos ω / E_vd − 1 at MF 1, 2, 4: {errors:?}");
        let p = SkyPatches::new(1).unwrap();
        let night = SkyVector::perez(&p, 0.0, 0.0, sun, 1.0, 11.0, 0.2).unwrap();
        assert!(night.luminance_cd_m2.iter().all(|&l| l == 0.0));
        assert!(SkyVector::perez(&p, 100.0, f64::NAN, sun, 1.0, 11.0, 0.2).is_err());
        assert!(SkyVector::perez(&p, -1.0, 0.0, sun, 1.0, 11.0, 0.2).is_err());
    }
}
