//! Spectra as the renderer carries them.
//!
//! * [`SampledWavelengths`] — the few wavelengths (nm) one camera sample carries, with their
//!   sampling densities (hero-wavelength sampling, Wilkie et al. 2014; pbrt-v4 §4.5.4).
//! * [`SampledSpectrum`] — the value of a spectral quantity at those wavelengths (one f32 lane
//!   per wavelength). Radiance is carried in W·m⁻²·sr⁻¹·nm⁻¹.
//! * [`DenseSpectrum`] — a scene spectrum baked at 1 nm over 360–830 nm, evaluated by linear
//!   interpolation. Every scene spectrum (tabulated, named, blackbody, RGB) is resolved into one
//!   of these when the world is built, so the hot path is a table lookup.

pub mod rgb_upsample;

use std::ops::{Add, AddAssign, Div, Index, IndexMut, Mul, MulAssign, Sub};

/// Number of wavelengths carried by one camera sample.
pub const N_LAMBDA: usize = 4;
/// Shortest wavelength the renderer samples, nm.
pub const LAMBDA_MIN: f32 = 360.0;
/// Longest wavelength the renderer samples, nm.
pub const LAMBDA_MAX: f32 = 830.0;
/// Number of 1 nm samples in a [`DenseSpectrum`] (360..=830).
pub const DENSE_LEN: usize = 471;

/// Values of a spectral quantity at the [`SampledWavelengths`] of one path.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct SampledSpectrum(pub [f32; N_LAMBDA]);

impl SampledSpectrum {
    pub const ZERO: Self = Self([0.0; N_LAMBDA]);
    pub const ONE: Self = Self([1.0; N_LAMBDA]);

    pub fn splat(v: f32) -> Self {
        Self([v; N_LAMBDA])
    }
    pub fn is_black(&self) -> bool {
        self.0.iter().all(|&v| v == 0.0)
    }
    pub fn max_component(&self) -> f32 {
        self.0.iter().copied().fold(f32::MIN, f32::max)
    }
    pub fn average(&self) -> f32 {
        self.0.iter().sum::<f32>() / N_LAMBDA as f32
    }
    /// Component-wise division that yields 0 where the divisor is 0.
    pub fn safe_div(self, d: Self) -> Self {
        let mut r = self;
        for i in 0..N_LAMBDA {
            r.0[i] = if d.0[i] != 0.0 {
                self.0[i] / d.0[i]
            } else {
                0.0
            };
        }
        r
    }
    /// True if every lane is finite.
    pub fn is_finite(&self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }
}

macro_rules! lanewise {
    ($tr:ident, $f:ident, $op:tt, $opa:tt, $tra:ident, $fa:ident) => {
        impl $tr for SampledSpectrum {
            type Output = Self;
            #[inline]
            fn $f(self, o: Self) -> Self {
                let mut r = self;
                for i in 0..N_LAMBDA {
                    r.0[i] = self.0[i] $op o.0[i];
                }
                r
            }
        }
        impl $tr<f32> for SampledSpectrum {
            type Output = Self;
            #[inline]
            fn $f(self, o: f32) -> Self {
                let mut r = self;
                for v in r.0.iter_mut() {
                    *v $opa o;
                }
                r
            }
        }
        impl $tra for SampledSpectrum {
            #[inline]
            fn $fa(&mut self, o: Self) {
                *self = *self $op o;
            }
        }
    };
}
lanewise!(Add, add, +, +=, AddAssign, add_assign);
lanewise!(Mul, mul, *, *=, MulAssign, mul_assign);

impl Sub for SampledSpectrum {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        let mut r = self;
        for i in 0..N_LAMBDA {
            r.0[i] -= o.0[i];
        }
        r
    }
}
impl Div<f32> for SampledSpectrum {
    type Output = Self;
    #[inline]
    fn div(self, o: f32) -> Self {
        self * (1.0 / o)
    }
}
impl Mul<SampledSpectrum> for f32 {
    type Output = SampledSpectrum;
    #[inline]
    fn mul(self, o: SampledSpectrum) -> SampledSpectrum {
        o * self
    }
}
impl Index<usize> for SampledSpectrum {
    type Output = f32;
    fn index(&self, i: usize) -> &f32 {
        &self.0[i]
    }
}
impl IndexMut<usize> for SampledSpectrum {
    fn index_mut(&mut self, i: usize) -> &mut f32 {
        &mut self.0[i]
    }
}

/// The wavelengths (nm) carried by one camera sample and the density each was drawn with.
///
/// The first wavelength (the hero) is importance-sampled over 360–830 nm with the density
/// [`visible_wavelength_pdf`]; the others use the same warp on stratified offsets `u + i/N`
/// (mod 1), so each lane is marginally distributed with that density and the lanes together
/// stratify the spectrum. Each lane's estimate `f(λᵢ)/p(λᵢ)` is unbiased; the film averages them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledWavelengths {
    pub lambda: [f32; N_LAMBDA],
    pub pdf: [f32; N_LAMBDA],
}

impl SampledWavelengths {
    /// Hero-wavelength sampling from one uniform number `u` ∈ [0, 1).
    pub fn sample_visible(u: f32) -> Self {
        let mut lambda = [0.0; N_LAMBDA];
        let mut pdf = [0.0; N_LAMBDA];
        for i in 0..N_LAMBDA {
            let mut up = u + i as f32 / N_LAMBDA as f32;
            if up >= 1.0 {
                up -= 1.0;
            }
            // a(λ − 538) = atanh(t), so sech² of it is 1 − t²: the density without an
            // exponential.
            let t = visible_tanh(up);
            lambda[i] = wavelength_of_tanh(t);
            pdf[i] = VIS_NORM as f32 * (1.0 - t * t);
        }
        Self { lambda, pdf }
    }

    /// Uniform sampling over 360–830 nm (pdf 1/470 per nm), mainly for tests.
    pub fn sample_uniform(u: f32) -> Self {
        let mut lambda = [0.0; N_LAMBDA];
        let range = LAMBDA_MAX - LAMBDA_MIN;
        for (i, l) in lambda.iter_mut().enumerate() {
            let mut up = u + i as f32 / N_LAMBDA as f32;
            if up >= 1.0 {
                up -= 1.0;
            }
            *l = LAMBDA_MIN + up * range;
        }
        Self {
            lambda,
            pdf: [1.0 / range; N_LAMBDA],
        }
    }

    /// Keep only the hero wavelength (used when a path disperses, e.g. refraction with a
    /// wavelength-dependent index): the other lanes get pdf 0 and the hero's pdf is divided by
    /// N so that the film's average over lanes stays unbiased.
    pub fn terminate_secondary(&mut self) {
        if self.secondary_terminated() {
            return;
        }
        for i in 1..N_LAMBDA {
            self.pdf[i] = 0.0;
        }
        self.pdf[0] /= N_LAMBDA as f32;
    }

    pub fn secondary_terminated(&self) -> bool {
        self.pdf[1..].iter().all(|&p| p == 0.0)
    }

    /// The density of each lane as a spectrum (0 for terminated lanes).
    pub fn pdf_spectrum(&self) -> SampledSpectrum {
        SampledSpectrum(self.pdf)
    }
}

/// Density (per nm) of [`sample_visible_wavelength`] on 360–830 nm: p(λ) ∝ sech²(0.0072 (λ − 538)),
/// a fit to the luminance response (pbrt-v4, `VisibleWavelengthsPDF`), normalised here exactly
/// over [`LAMBDA_MIN`, `LAMBDA_MAX`].
pub fn visible_wavelength_pdf(lambda: f32) -> f32 {
    if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda) {
        return 0.0;
    }
    // sech²(x) = 4e^{2x} / (e^{2x} + 1)²: one exponential (f32: this runs 4× per camera
    // sample).
    let e = (2.0 * VIS_A as f32 * (lambda - VIS_CENTER as f32)).exp();
    let d = e + 1.0;
    VIS_NORM as f32 * 4.0 * e / (d * d)
}

const VIS_A: f64 = 0.0072;
const VIS_CENTER: f64 = 538.0;
/// tanh(a(360 − 538)) and tanh(a(830 − 538)): the CDF's ends.
const VIS_TANH_MIN: f64 = -0.856910625469828;
const VIS_TANH_MAX: f64 = 0.9705913469402698;
/// 1 / ∫_{360}^{830} sech²(a(λ−538)) dλ = a / (tanh(a·292) + tanh(a·178)).
const VIS_NORM: f64 = VIS_A / (VIS_TANH_MAX - VIS_TANH_MIN);

/// Inverse-CDF warp for [`visible_wavelength_pdf`]: λ = 538 + atanh(t)/a with
/// t = lerp(u, tanh(a(360−538)), tanh(a(830−538))).
pub fn sample_visible_wavelength(u: f32) -> f32 {
    wavelength_of_tanh(visible_tanh(u))
}

/// tanh(a(λ − 538)) of the wavelength that [`sample_visible_wavelength`] gives for `u`.
#[inline]
fn visible_tanh(u: f32) -> f32 {
    let (t0, t1) = (VIS_TANH_MIN as f32, VIS_TANH_MAX as f32);
    t0 + u * (t1 - t0)
}

/// λ = 538 + atanh(t)/a, nm.
#[inline]
fn wavelength_of_tanh(t: f32) -> f32 {
    // atanh(t) = ½ ln((1 + t)/(1 − t)), in f32 (t stays ≥ 0.03 away from ±1).
    let l = VIS_CENTER as f32 + ((1.0 + t) / (1.0 - t)).ln() * (0.5 / VIS_A as f32);
    l.clamp(LAMBDA_MIN, LAMBDA_MAX)
}

/// A spectrum baked at 1 nm steps over 360–830 nm (index i ↔ 360 + i nm).
#[derive(Clone, Debug, PartialEq)]
pub struct DenseSpectrum {
    pub values: Box<[f32; DENSE_LEN]>,
}

impl DenseSpectrum {
    pub fn constant(v: f32) -> Self {
        Self {
            values: Box::new([v; DENSE_LEN]),
        }
    }
    /// Bake any function of wavelength (nm) at 360, 361, …, 830 nm.
    pub fn from_fn(mut f: impl FnMut(f64) -> f64) -> Self {
        let mut values = Box::new([0.0f32; DENSE_LEN]);
        for (i, v) in values.iter_mut().enumerate() {
            *v = f(LAMBDA_MIN as f64 + i as f64) as f32;
        }
        Self { values }
    }
    /// Linear interpolation between the 1 nm samples; 0 outside 360–830 nm.
    #[inline]
    pub fn value(&self, lambda: f32) -> f32 {
        let x = lambda - LAMBDA_MIN;
        if !(0.0..=(DENSE_LEN - 1) as f32).contains(&x) {
            return 0.0;
        }
        let i = (x as usize).min(DENSE_LEN - 2);
        let t = x - i as f32;
        self.values[i] * (1.0 - t) + self.values[i + 1] * t
    }
    #[inline]
    pub fn sample(&self, wl: &SampledWavelengths) -> SampledSpectrum {
        let mut s = SampledSpectrum::ZERO;
        for i in 0..N_LAMBDA {
            s.0[i] = self.value(wl.lambda[i]);
        }
        s
    }
    pub fn max_value(&self) -> f32 {
        self.values.iter().copied().fold(f32::MIN, f32::max)
    }
    pub fn min_value(&self) -> f32 {
        self.values.iter().copied().fold(f32::MAX, f32::min)
    }
    pub fn scaled(&self, k: f32) -> Self {
        let mut s = self.clone();
        for v in s.values.iter_mut() {
            *v *= k;
        }
        s
    }
    /// The 1 nm samples as f64, the colour library's table layout (index i ↔ 360 + i nm).
    pub fn to_f64_array(&self) -> [f64; DENSE_LEN] {
        self.values.map(|v| v as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visible_pdf_normalised_and_matches_sampler() {
        // ∫ p dλ = 1 by the midpoint rule.
        let n = 47_000;
        let h = (LAMBDA_MAX - LAMBDA_MIN) as f64 / n as f64;
        let integral: f64 = (0..n)
            .map(|i| visible_wavelength_pdf(LAMBDA_MIN + ((i as f64 + 0.5) * h) as f32) as f64 * h)
            .sum();
        assert!((integral - 1.0).abs() < 1e-4, "∫p = {integral}");
        // The warp's derivative equals 1/p.
        for &u in &[0.05f32, 0.3, 0.5, 0.77, 0.95] {
            let du = 1e-3f32;
            let dl = sample_visible_wavelength(u + du) - sample_visible_wavelength(u - du);
            let p_num = 2.0 * du / dl;
            let p = visible_wavelength_pdf(sample_visible_wavelength(u));
            assert!((p_num - p).abs() / p < 2e-3, "u={u}: {p_num} vs {p}");
        }
        assert_eq!(sample_visible_wavelength(0.0), LAMBDA_MIN);
        assert!((sample_visible_wavelength(0.999_999) - LAMBDA_MAX).abs() < 0.1);
    }

    #[test]
    fn hero_lanes_are_stratified() {
        let wl = SampledWavelengths::sample_visible(0.1);
        for i in 1..N_LAMBDA {
            assert!(wl.lambda[i] != wl.lambda[0]);
            assert!(wl.pdf[i] > 0.0);
        }
        // The sampler's densities are the density function's at its wavelengths.
        for u in (0..1000).map(|k| k as f32 / 1000.0) {
            let wl = SampledWavelengths::sample_visible(u);
            for i in 0..N_LAMBDA {
                let want = visible_wavelength_pdf(wl.lambda[i]);
                assert!((wl.pdf[i] - want).abs() <= 2e-6 * want, "{u} {i}");
            }
        }
        let mut t = wl;
        t.terminate_secondary();
        assert!(t.secondary_terminated());
        assert_eq!(t.pdf[0], wl.pdf[0] / N_LAMBDA as f32);
    }

    #[test]
    fn dense_interpolates_linearly() {
        let s = DenseSpectrum::from_fn(|nm| nm / 100.0);
        assert!((s.value(500.25) - 5.0025).abs() < 1e-5);
        assert_eq!(s.value(359.0), 0.0);
        assert_eq!(s.value(831.0), 0.0);
        assert!((s.value(830.0) - 8.3).abs() < 1e-5);
    }
}
