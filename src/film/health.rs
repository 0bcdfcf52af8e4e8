//! Optional per-pixel light-and-health channels, kept beside the film only when asked for
//! (`--alpha-opic`, `--mesopic`, `--spectral-bands N`), so a plain render's pixels stay as
//! small as they are:
//!
//! * melanopic equivalent daylight (D65) luminance, m-EDL = ∫ L(λ) s_mel(λ) dλ / K_mel,v^D65 in
//!   cd/m² (CIE S 026), and with illuminance also m-EDI in lx on the surface seen;
//! * scotopic luminance L_s = K′_m ∫ L(λ) V′(λ) dλ (K′_m = 1700 lm/W, scotopic cd/m²), from
//!   which the CIE 191 mesopic luminance follows with the pixel's S/P = L_s / L_v;
//! * N spectral bands of equal width over 380–780 nm: the band's mean spectral radiance in
//!   W·m⁻²·sr⁻¹·nm⁻¹.
//!
//! Each is estimated from the same camera samples (the same wavelengths, the same radiance) as
//! the pixel's XYZ, with one-sample weights L(λᵢ) w(λᵢ) / pᵢ averaged over the hero
//! wavelengths; the melanopic and scotopic ones keep the 16 batch sums of the pixel
//! ([`super::PIXEL_BATCHES`]) so that their standard errors come from the same batches as
//! luminance's. All sums are f64.

use super::{batch_standard_error, PixelSums, PIXEL_BATCHES};
use crate::colour::alpha_opic::{d65_elr, AlphaOpic};
use crate::colour::tables::scotopic_v;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, DENSE_LEN, N_LAMBDA};
use std::sync::LazyLock;

/// Spectral bands span this range (nm): that of CIE S 026's action spectra and of the
/// spectral EXR's channels.
pub const BANDS_START_NM: f64 = 380.0;
pub const BANDS_END_NM: f64 = 780.0;
/// Most spectral bands per pixel.
pub const MAX_SPECTRAL_BANDS: usize = 64;
/// Scotopic maximum luminous efficacy K′_m (lm/W), as [`crate::photometry::sp_ratio`] uses.
pub const K_M_SCOTOPIC: f64 = 1700.0;

/// Which health channels a film keeps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HealthChannels {
    /// Melanopic m-EDL per pixel (and m-EDI where the film has illuminance).
    pub melanopic: bool,
    /// Scotopic luminance per pixel, for the CIE 191 mesopic luminance.
    pub mesopic: bool,
    /// Spectral bands over 380–780 nm per pixel (0: none).
    pub spectral_bands: usize,
}

impl HealthChannels {
    /// Whether any channel is kept.
    pub fn any(&self) -> bool {
        self.melanopic || self.mesopic || self.spectral_bands > 0
    }
    /// f64 sums per pixel: 16 batch sums per batched quantity, one per band.
    pub fn floats_per_pixel(&self, illuminance: bool) -> usize {
        let batched = self.melanopic as usize * (1 + illuminance as usize) + self.mesopic as usize;
        batched * PIXEL_BATCHES + self.spectral_bands
    }
    /// Peak bytes per pixel while rendering: the film's sums, a pass's copy of them and the
    /// finished render's copy.
    pub fn peak_bytes_per_pixel(&self, illuminance: bool) -> u64 {
        3 * 8 * self.floats_per_pixel(illuminance) as u64
    }
}

/// Weight tables at 1 nm from 360 nm, as f32 for the hot path: s_mel(λ)/K_mel,v^D65 (lm/W, so
/// that the integral is in cd/m² or lx) and K′_m V′(λ) (lm/W).
struct Weights {
    melanopic: [f32; DENSE_LEN],
    scotopic: [f32; DENSE_LEN],
}

static WEIGHTS: LazyLock<Weights> = LazyLock::new(|| {
    let s = AlphaOpic::Melanopic.action_spectrum();
    let k = d65_elr()[AlphaOpic::Melanopic as usize];
    let v = scotopic_v();
    Weights {
        melanopic: std::array::from_fn(|i| (s[i] / k) as f32),
        scotopic: std::array::from_fn(|i| (K_M_SCOTOPIC * v[i]) as f32),
    }
});

/// Σᵢ L(λᵢ) w(λᵢ) / pᵢ / N over the sample's wavelengths: an unbiased estimate of ∫ L w dλ.
#[inline]
fn weighted(table: &[f32; DENSE_LEN], l: &SampledSpectrum, wl: &SampledWavelengths) -> f64 {
    let mut s = 0.0f64;
    for i in 0..N_LAMBDA {
        if wl.pdf[i] == 0.0 || l.0[i] == 0.0 {
            continue;
        }
        s += l.0[i] as f64 / wl.pdf[i] as f64 * super::lerp_table(table, wl.lambda[i]) as f64;
    }
    s / N_LAMBDA as f64
}

/// Melanopic EDL (cd/m²) of one sample's spectral radiance, or melanopic EDI (lx) of one
/// sample's spectral irradiance.
#[inline]
pub fn melanopic_edi(l: &SampledSpectrum, wl: &SampledWavelengths) -> f64 {
    weighted(&WEIGHTS.melanopic, l, wl)
}

/// Scotopic luminance (scotopic cd/m²) of one sample's spectral radiance.
#[inline]
pub fn scotopic_luminance(l: &SampledSpectrum, wl: &SampledWavelengths) -> f64 {
    weighted(&WEIGHTS.scotopic, l, wl)
}

/// The health sums of every pixel of a film's image buffer (the decision buffer of adaptive
/// sampling has none: it only steers where samples go).
#[derive(Clone, Debug, PartialEq)]
pub struct HealthFilm {
    pub channels: HealthChannels,
    /// Whether the melanopic channel has an m-EDI part (the film estimates illuminance).
    pub illuminance: bool,
    /// [`HealthChannels::floats_per_pixel`] sums per pixel, pixel after pixel.
    pub sums: Vec<f64>,
}

/// Where each quantity's sums lie in a pixel's slice.
#[derive(Clone, Copy, Debug)]
struct Offsets {
    mel_l: Option<usize>,
    mel_e: Option<usize>,
    scotopic: Option<usize>,
    bands: usize,
    stride: usize,
}

fn offsets(c: &HealthChannels, illuminance: bool) -> Offsets {
    let mut at = 0;
    let mut next = |on: bool| {
        on.then(|| {
            at += PIXEL_BATCHES;
            at - PIXEL_BATCHES
        })
    };
    let mel_l = next(c.melanopic);
    let mel_e = next(c.melanopic && illuminance);
    let scotopic = next(c.mesopic);
    Offsets {
        mel_l,
        mel_e,
        scotopic,
        bands: at,
        stride: at + c.spectral_bands,
    }
}

impl HealthFilm {
    /// Zero sums for `pixels` pixels, after checking that the memory they need is available.
    pub fn new(
        channels: HealthChannels,
        illuminance: bool,
        pixels: usize,
    ) -> Result<HealthFilm, String> {
        let need = pixels as u64 * channels.peak_bytes_per_pixel(illuminance);
        crate::limits::check_memory(
            need,
            &format!("the light-and-health channels of {pixels} pixels"),
        )?;
        Ok(HealthFilm {
            channels,
            illuminance,
            sums: vec![0.0; pixels * channels.floats_per_pixel(illuminance)],
        })
    }
    /// f64 sums per pixel.
    pub fn stride(&self) -> usize {
        self.channels.floats_per_pixel(self.illuminance)
    }
    /// Pixel `i`'s sums.
    pub fn pixel(&self, i: usize) -> &[f64] {
        let s = self.stride();
        &self.sums[i * s..(i + 1) * s]
    }
    /// Pixel `i`'s sums, to add samples to.
    pub fn pixel_mut(&mut self, i: usize) -> HealthPixel<'_> {
        let o = offsets(&self.channels, self.illuminance);
        HealthPixel {
            o,
            sums: &mut self.sums[i * o.stride..(i + 1) * o.stride],
        }
    }
    /// Adds the sums of `o` (the same channels; the samples of another seed or shard), pixel
    /// `i` of this film having had `count(i)` samples before: as [`PixelSums::merge`] does,
    /// `o`'s batch b joins batch (b + count) mod 16, so a batched quantity keeps the batches
    /// of its pixel's luminance.
    pub fn merge(&mut self, o: &HealthFilm, count: impl Fn(usize) -> u64) {
        let off = offsets(&self.channels, self.illuminance);
        let stride = off.stride;
        for (i, (a, b)) in self
            .sums
            .chunks_exact_mut(stride)
            .zip(o.sums.chunks_exact(stride))
            .enumerate()
        {
            let r = (count(i) % PIXEL_BATCHES as u64) as usize;
            for at in [off.mel_l, off.mel_e, off.scotopic].into_iter().flatten() {
                for k in 0..PIXEL_BATCHES {
                    a[at + (k + r) % PIXEL_BATCHES] += b[at + k];
                }
            }
            for k in off.bands..stride {
                a[k] += b[k];
            }
        }
    }
    /// A detached pixel's sums (a pass works on copies), to add samples to.
    pub fn view<'a>(&self, sums: &'a mut [f64]) -> HealthPixel<'a> {
        HealthPixel {
            o: offsets(&self.channels, self.illuminance),
            sums,
        }
    }
}

/// One pixel's health sums, to which the render adds each camera sample.
pub struct HealthPixel<'a> {
    o: Offsets,
    sums: &'a mut [f64],
}

impl HealthPixel<'_> {
    /// Whether the channels need the surface's melanopic irradiance (m-EDI).
    pub fn wants_irradiance(&self) -> bool {
        self.o.mel_e.is_some()
    }
    /// Record camera sample `sample` (its index in the pixel, so batch `sample` mod 16): its
    /// spectral radiance `l` at `wl`, finite.
    #[inline]
    pub fn add_radiance(&mut self, sample: u64, l: &SampledSpectrum, wl: &SampledWavelengths) {
        let b = (sample % PIXEL_BATCHES as u64) as usize;
        if let Some(at) = self.o.mel_l {
            self.sums[at + b] += melanopic_edi(l, wl);
        }
        if let Some(at) = self.o.scotopic {
            self.sums[at + b] += scotopic_luminance(l, wl);
        }
        let n = self.o.stride - self.o.bands;
        if n > 0 {
            let width = (BANDS_END_NM - BANDS_START_NM) / n as f64;
            for i in 0..N_LAMBDA {
                let lambda = wl.lambda[i] as f64;
                if wl.pdf[i] == 0.0
                    || l.0[i] == 0.0
                    || !(BANDS_START_NM..BANDS_END_NM).contains(&lambda)
                {
                    continue;
                }
                let k = (((lambda - BANDS_START_NM) / width) as usize).min(n - 1);
                // ∫_band L dλ / width, one lane of N.
                self.sums[self.o.bands + k] +=
                    l.0[i] as f64 / wl.pdf[i] as f64 / (N_LAMBDA as f64 * width);
            }
        }
    }
    /// Record camera sample `sample`'s melanopic EDI (lx) on the surface it sees.
    #[inline]
    pub fn add_edi(&mut self, sample: u64, m_edi_lx: f64) {
        if let Some(at) = self.o.mel_e {
            self.sums[at + (sample % PIXEL_BATCHES as u64) as usize] += m_edi_lx;
        }
    }
}

/// A quantity's per-pixel mean and standard error.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelValue {
    pub mean: f64,
    pub stderr: f64,
}

fn batched(sums: &[f64], at: usize, n: u64, k: u32) -> (PixelValue, [f64; PIXEL_BATCHES]) {
    let b: [f64; PIXEL_BATCHES] = std::array::from_fn(|k| sums[at + k]);
    let mean = if n == 0 {
        0.0
    } else {
        b.iter().sum::<f64>() / n as f64
    };
    (
        PixelValue {
            mean,
            stderr: batch_standard_error(&b, n, k),
        },
        b,
    )
}

/// Pixel estimates of the health channels, given the pixel's own sums.
impl HealthFilm {
    /// m-EDL (cd/m²) of pixel `i` with its standard error (`k` batches per pixel).
    pub fn melanopic_edl(&self, i: usize, p: &PixelSums, k: u32) -> Option<PixelValue> {
        let o = offsets(&self.channels, self.illuminance);
        Some(batched(self.pixel(i), o.mel_l?, p.count, k).0)
    }
    /// The batch sums of m-EDL (cd/m²) of pixel `i`, as [`PixelSums::batch_y`] holds Y's.
    pub fn melanopic_edl_batches(&self, i: usize) -> Option<[f64; PIXEL_BATCHES]> {
        let o = offsets(&self.channels, self.illuminance);
        let at = o.mel_l?;
        Some(std::array::from_fn(|k| self.pixel(i)[at + k]))
    }
    /// m-EDI (lx) of pixel `i` over the samples that saw a receiving surface (`count_e` of
    /// them; None if none did), with its standard error, as [`super::PixelE::mean_e`] does
    /// for illuminance.
    pub fn melanopic_edi(
        &self,
        i: usize,
        p: &PixelSums,
        count_e: u64,
        k: u32,
    ) -> Option<PixelValue> {
        let o = offsets(&self.channels, self.illuminance);
        let at = o.mel_e?;
        if count_e == 0 || p.count == 0 {
            return None;
        }
        let (v, b) = batched(self.pixel(i), at, p.count, k);
        let coverage = count_e as f64 / p.count as f64;
        Some(PixelValue {
            mean: b.iter().sum::<f64>() / count_e as f64,
            stderr: v.stderr / coverage,
        })
    }
    /// Scotopic luminance (scotopic cd/m²) of pixel `i`.
    pub fn scotopic(&self, i: usize, p: &PixelSums, k: u32) -> Option<PixelValue> {
        let o = offsets(&self.channels, self.illuminance);
        Some(batched(self.pixel(i), o.scotopic?, p.count, k).0)
    }
    /// CIE 191 mesopic luminance (cd/m²) of pixel `i` from its L_v and S/P = L_s / L_v, with
    /// the jackknife standard error over the `k` batches: the estimate recomputed with each
    /// batch left out, whose spread gives the error of a smooth function of batch means.
    pub fn mesopic(&self, i: usize, p: &PixelSums, k: u32) -> Option<PixelValue> {
        let o = offsets(&self.channels, self.illuminance);
        let at = o.scotopic?;
        let s = self.pixel(i);
        let n = p.count;
        let f = |lp_sum: f64, ls_sum: f64, n: u64| {
            if n == 0 || lp_sum <= 0.0 {
                return 0.0;
            }
            let (lp, ls) = (lp_sum / n as f64, ls_sum / n as f64);
            crate::colour::mesopic::mesopic_luminance(lp, ls / lp).luminance_cd_m2
        };
        let (lp_sum, ls_sum) = (p.sum_xyz[1], (0..PIXEL_BATCHES).map(|k| s[at + k]).sum());
        let mean = f(lp_sum, ls_sum, n);
        let batches = n.min(k as u64) as usize;
        let stderr = if batches < 2 {
            0.0
        } else {
            let lp_b = super::fold_batches(&p.batch_y, k);
            let ls_b = super::fold_batches(&std::array::from_fn(|b| s[at + b]), k);
            let loo: Vec<f64> = (0..batches)
                .map(|b| {
                    f(
                        lp_sum - lp_b[b],
                        ls_sum - ls_b[b],
                        n - super::batch_count(n, b, k),
                    )
                })
                .collect();
            let m = loo.iter().sum::<f64>() / batches as f64;
            let ss: f64 = loo.iter().map(|v| (v - m).powi(2)).sum();
            (ss * (batches - 1) as f64 / batches as f64).sqrt()
        };
        Some(PixelValue { mean, stderr })
    }
    /// Mean spectral radiance (W·m⁻²·sr⁻¹·nm⁻¹) of each band of pixel `i`.
    pub fn bands(&self, i: usize, p: &PixelSums) -> Vec<f64> {
        let o = offsets(&self.channels, self.illuminance);
        let n = p.count.max(1) as f64;
        self.pixel(i)[o.bands..o.stride]
            .iter()
            .map(|s| s / n)
            .collect()
    }
    /// Centre wavelengths (nm) of the bands.
    pub fn band_centres_nm(&self) -> Vec<f64> {
        let n = self.channels.spectral_bands;
        let w = (BANDS_END_NM - BANDS_START_NM) / n.max(1) as f64;
        (0..n)
            .map(|k| BANDS_START_NM + (k as f64 + 0.5) * w)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_and_sizes() {
        let c = HealthChannels {
            melanopic: true,
            mesopic: true,
            spectral_bands: 32,
        };
        assert_eq!(c.floats_per_pixel(false), 2 * 16 + 32);
        assert_eq!(c.floats_per_pixel(true), 3 * 16 + 32);
        assert_eq!(HealthChannels::default().floats_per_pixel(true), 0);
        let o = offsets(&c, true);
        assert_eq!(
            (o.mel_l, o.mel_e, o.scotopic, o.bands, o.stride),
            (Some(0), Some(16), Some(32), 48, 80)
        );
    }

    #[test]
    fn weights_give_the_d65_normalisation() {
        // Constant spectral radiance 1 at 1 nm spacing (dense sampling of the integral):
        // m-EDL = Σ s_mel / K_mel,D65 and L_s = 1700 Σ V′.
        let s = AlphaOpic::Melanopic.action_spectrum();
        let k = d65_elr()[AlphaOpic::Melanopic as usize];
        let want: f64 = s.iter().sum::<f64>() / k;
        let got: f64 = WEIGHTS.melanopic.iter().map(|&v| v as f64).sum();
        assert!((got / want - 1.0).abs() < 1e-6, "{got} {want}");
    }
}
