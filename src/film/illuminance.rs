//! Per-pixel illuminance sums, kept beside the film's [`PixelSums`] only when the render
//! estimates illuminance (`--illuminance`): their 16 batch sums would otherwise nearly double
//! every pixel.

use super::{batch_standard_error, standard_error, sums_agree, PixelSums, PIXEL_BATCHES};

/// Running illuminance sums for one pixel; the counts of its camera samples and light paths
/// are those of the pixel's [`PixelSums`] (see [`PixelE`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct IlluminanceSums {
    /// Σ E (lx) of each batch's samples (sample i in batch i mod 16), a sample that sees no
    /// receiving surface counting 0: the standard error comes from their spread.
    pub batch_e: [f64; PIXEL_BATCHES],
    /// Σ E (lx) over the samples whose camera ray found a receiving surface.
    pub sum_e: f64,
    /// Σ E² (lx²) over the same samples.
    pub sum_e2: f64,
    /// Samples whose camera ray found a receiving surface.
    pub count_e: u64,
    /// Σ and Σ² of the light paths' illuminance splats (lx, lx²) on the surface this pixel
    /// sees.
    pub splat_e: f64,
    pub splat_e2: f64,
}

impl IlluminanceSums {
    /// Record the illuminance (lx) of camera sample `sample` of the pixel (its index, so its
    /// batch is `sample` mod 16), if it sees a receiving surface.
    #[inline]
    pub fn add(&mut self, sample: u64, e: Option<f64>) {
        if let Some(e) = e {
            self.sum_e += e;
            self.sum_e2 += e * e;
            self.count_e += 1;
            self.batch_e[(sample % PIXEL_BATCHES as u64) as usize] += e;
        }
    }
    /// Add the light paths' Σ E and Σ E² (lx, lx²) on this pixel.
    #[inline]
    pub fn add_light_paths(&mut self, sum_e: f64, sum_e2: f64) {
        self.splat_e += sum_e;
        self.splat_e2 += sum_e2;
    }
    /// Add the sums of an independent render of this pixel, whose samples continue a pixel
    /// that held `count` samples (see [`PixelSums::merge`]).
    pub fn merge(&mut self, o: &IlluminanceSums, count: u64) {
        let r = (count % PIXEL_BATCHES as u64) as usize;
        for b in 0..PIXEL_BATCHES {
            self.batch_e[(b + r) % PIXEL_BATCHES] += o.batch_e[b];
        }
        self.sum_e += o.sum_e;
        self.sum_e2 += o.sum_e2;
        self.count_e += o.count_e;
        self.splat_e += o.splat_e;
        self.splat_e2 += o.splat_e2;
    }
    /// Whether these sums can belong to the pixel `p` of a render; the message names the
    /// field at fault.
    pub(super) fn check(&self, p: &PixelSums) -> Result<(), String> {
        for (name, v) in [
            ("Σ E", self.sum_e),
            ("Σ E²", self.sum_e2),
            ("light-path Σ E", self.splat_e),
            ("light-path Σ E²", self.splat_e2),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!(
                    "{name} is {v:e}, but sums of illuminance and their squares are finite and ≥ 0"
                ));
            }
        }
        super::check_batches("E", &self.batch_e, self.sum_e, p.count)?;
        if self.count_e > p.count {
            return Err(format!(
                "{} illuminance samples but only {} samples",
                self.count_e, p.count
            ));
        }
        for (what, sum, sum2, n, count) in [
            (
                "Σ E and Σ E²",
                self.sum_e,
                self.sum_e2,
                self.count_e,
                "illuminance samples",
            ),
            (
                "light-path Σ E and Σ E²",
                self.splat_e,
                self.splat_e2,
                p.light_paths,
                "light paths",
            ),
        ] {
            if !sums_agree(sum, sum2, n) {
                return Err(format!(
                    "{what} ({sum:e}, {sum2:e}) cannot both come from {n} {count} (Σx² ≤ (Σx)² ≤ n·Σx² for x ≥ 0)"
                ));
            }
        }
        Ok(())
    }
}

/// One pixel's luminance and illuminance sums together: the illuminance estimates need the
/// pixel's counts of camera samples and light paths.
#[derive(Clone, Copy, Debug)]
pub struct PixelE<'a> {
    pub sums: &'a PixelSums,
    pub e: &'a IlluminanceSums,
    /// Independent batches per pixel of the render ([`super::Film::pixel_batches`]).
    pub batches: u32,
}

/// The pixel's luminance estimates ([`PixelSums::mean_xyz`], …) through the view.
impl std::ops::Deref for PixelE<'_> {
    type Target = PixelSums;
    fn deref(&self) -> &PixelSums {
        self.sums
    }
}

impl PixelE<'_> {
    /// Whether light paths added illuminance to this pixel.
    fn has_e_splats(&self) -> bool {
        self.sums.light_paths > 0 && (self.e.splat_e != 0.0 || self.e.splat_e2 != 0.0)
    }
    /// Mean illuminance (lx) over the samples that saw a receiving surface.
    ///
    /// With light-traced caustics, the light paths' splats estimate the pixel's mean of E over
    /// *all* its footprint (0 where no receiver is seen), so they are added to the camera
    /// samples' mean over all samples and the sum divided by the coverage.
    pub fn mean_e(&self) -> Option<f64> {
        let (s, e) = (self.sums, self.e);
        if e.count_e == 0 {
            return None;
        }
        if !self.has_e_splats() {
            return Some(e.sum_e / e.count_e as f64);
        }
        let all = e.sum_e / s.count as f64 + e.splat_e / s.light_paths as f64;
        Some(all / self.e_coverage())
    }
    /// Standard error (lx) of [`Self::mean_e`] (the coverage taken as exact): that of the
    /// camera samples' mean of E over all samples (0 where no receiver is seen) from the
    /// spread of the batches, and with light-traced caustics that of the light paths' mean
    /// from their sample variance (independent estimates, added in quadrature), over the
    /// coverage.
    pub fn e_standard_error(&self) -> f64 {
        if self.e.count_e == 0 {
            return 0.0;
        }
        let cam = batch_standard_error(&self.e.batch_e, self.sums.count, self.batches);
        let light = if self.has_e_splats() {
            standard_error(self.e.splat_e, self.e.splat_e2, self.sums.light_paths)
        } else {
            0.0
        };
        (cam * cam + light * light).sqrt() / self.e_coverage()
    }
    /// Half-width (lx) of the 95 % interval of [`Self::mean_e`], as for luminance
    /// ([`PixelSums::y_ci95_half_width`]).
    pub fn e_ci95_half_width(&self) -> f64 {
        crate::sampling::t95(self.sums.batches(self.batches).saturating_sub(1))
            * self.e_standard_error()
    }
    /// The standard error (lx) of [`Self::mean_e`] that treats the camera samples as
    /// independent (√(s²/n) with the sample variance): an over-estimate for stratified
    /// samples, kept for comparison.
    pub fn e_standard_error_iid(&self) -> f64 {
        let (s, e) = (self.sums, self.e);
        if !self.has_e_splats() || e.count_e == 0 {
            return standard_error(e.sum_e, e.sum_e2, e.count_e);
        }
        let cam = standard_error(e.sum_e, e.sum_e2, s.count);
        let light = standard_error(e.splat_e, e.splat_e2, s.light_paths);
        (cam * cam + light * light).sqrt() / self.e_coverage()
    }
    /// Fraction of the pixel's samples whose illuminance is defined.
    pub fn e_coverage(&self) -> f64 {
        if self.sums.count == 0 {
            0.0
        } else {
            self.e.count_e as f64 / self.sums.count as f64
        }
    }
}
