//! The film: per-pixel accumulation of absolute CIE 1931 2° XYZ.
//!
//! One camera sample with wavelengths λᵢ (densities pᵢ) and radiance L(λᵢ) contributes
//! `X = K_m · (1/N) Σᵢ L(λᵢ) x̄(λᵢ) / pᵢ` (likewise Y, Z), an unbiased estimate of
//! `K_m ∫ L(λ) x̄(λ) dλ`. Y is then luminance in cd/m² because ȳ = V(λ).
//! Sums are kept in f64: f32 sums drift by percents past ~2²⁰ samples per pixel.

use crate::colour::tables::{cmfs, Observer};
use crate::photometry::K_M;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, DENSE_LEN, LAMBDA_MIN, N_LAMBDA};
use std::sync::LazyLock;

mod batches;
mod health;
mod health_output;
mod illuminance;
use batches::default_pixel_batches;
pub use batches::{
    batch_count, batch_standard_error, fold_batches, DEFAULT_PIXEL_BATCHES, PIXEL_BATCHES,
    PIXEL_BATCH_CHOICES, STDERR_BATCHES_ATTRIBUTE,
};
pub use health::{
    melanopic_edi as health_melanopic_edi, HealthChannels, HealthFilm, HealthPixel, PixelValue,
    BANDS_END_NM, BANDS_START_NM, MAX_SPECTRAL_BANDS,
};
pub use health_output::{
    add_health_layers, fichet_channel_name, read_spectral_bands, spectral_layers,
};
pub use illuminance::{IlluminanceSums, PixelE};

/// The CIE 1931 2° colour-matching functions as f32 tables for the hot path (from the colour
/// library's 1 nm data).
pub struct FilmCmfs {
    pub x: [f32; DENSE_LEN],
    pub y: [f32; DENSE_LEN],
    pub z: [f32; DENSE_LEN],
}

static FILM_CMFS: LazyLock<FilmCmfs> = LazyLock::new(|| {
    let c = cmfs(Observer::Cie1931_2);
    let mut t = FilmCmfs {
        x: [0.0; DENSE_LEN],
        y: [0.0; DENSE_LEN],
        z: [0.0; DENSE_LEN],
    };
    for i in 0..DENSE_LEN {
        t.x[i] = c.x[i] as f32;
        t.y[i] = c.y[i] as f32;
        t.z[i] = c.z[i] as f32;
    }
    t
});

#[inline]
fn lerp_table(t: &[f32; DENSE_LEN], lambda: f32) -> f32 {
    let x = lambda - LAMBDA_MIN;
    if !(0.0..=(DENSE_LEN - 1) as f32).contains(&x) {
        return 0.0;
    }
    let i = (x as usize).min(DENSE_LEN - 2);
    let f = x - i as f32;
    t[i] * (1.0 - f) + t[i + 1] * f
}

/// Absolute XYZ (Y in cd/m² when `l` is radiance in W·m⁻²·sr⁻¹·nm⁻¹) estimated from one
/// sample's spectral radiance. Lanes with pdf 0 (terminated secondaries) contribute nothing.
#[inline]
pub fn radiance_to_xyz(l: &SampledSpectrum, wl: &SampledWavelengths) -> [f64; 3] {
    let c = &*FILM_CMFS;
    let mut xyz = [0.0f64; 3];
    for i in 0..N_LAMBDA {
        if wl.pdf[i] == 0.0 || l.0[i] == 0.0 {
            continue;
        }
        let w = l.0[i] as f64 / wl.pdf[i] as f64;
        xyz[0] += w * lerp_table(&c.x, wl.lambda[i]) as f64;
        xyz[1] += w * lerp_table(&c.y, wl.lambda[i]) as f64;
        xyz[2] += w * lerp_table(&c.z, wl.lambda[i]) as f64;
    }
    let k = K_M / N_LAMBDA as f64;
    [xyz[0] * k, xyz[1] * k, xyz[2] * k]
}

/// Running sums for one pixel (its illuminance, when estimated, is kept apart in
/// [`IlluminanceSums`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PixelSums {
    /// Σ of the samples' absolute XYZ (Y in cd/m²).
    pub sum_xyz: [f64; 3],
    /// Σ Y² ((cd/m²)²): the samples' variance, for consistency checks and the iid error
    /// ([`Self::y_standard_error_iid`]).
    pub sum_y2: f64,
    pub count: u64,
    /// Σ Y (cd/m²) of each batch's samples ([`PIXEL_BATCHES`], sample i in batch i mod 16):
    /// the standard error comes from their spread.
    pub batch_y: [f64; PIXEL_BATCHES],
    /// Σ of the caustic light paths' splats on this pixel (XYZ, Y²) and the number of light
    /// paths traced for the buffer (see [`crate::integrator::light_path`]): they add
    /// `splat_xyz / light_paths` to the camera samples' mean.
    #[serde(default)]
    pub splat_xyz: [f64; 3],
    /// Σ of the splats' Y² ((cd/m²)²).
    #[serde(default)]
    pub splat_y2: f64,
    #[serde(default)]
    pub light_paths: u64,
}

impl PixelSums {
    /// Record the next camera sample's absolute XYZ (index `count`, of batch `count` mod 16;
    /// its illuminance goes to [`IlluminanceSums::add`] first).
    #[inline]
    pub fn add(&mut self, xyz: [f64; 3]) {
        let b = (self.count % PIXEL_BATCHES as u64) as usize;
        self.sum_xyz[0] += xyz[0];
        self.sum_xyz[1] += xyz[1];
        self.sum_xyz[2] += xyz[2];
        self.sum_y2 += xyz[1] * xyz[1];
        self.batch_y[b] += xyz[1];
        self.count += 1;
    }
    /// Independent batches behind the camera samples' standard errors in a render of `k`
    /// batches per pixel (min(samples, k)); the 95 % intervals use Student's t with one degree
    /// of freedom fewer ([`Self::y_ci95_half_width`]).
    pub fn batches(&self, k: u32) -> u32 {
        self.count.min(k as u64) as u32
    }
    /// Half-width (cd/m²) of the 95 % interval of the mean luminance in a render of `k` batches
    /// per pixel: t₀.₉₇₅ with [`Self::batches`] − 1 degrees of freedom times
    /// [`Self::y_standard_error`] (infinite below 2 batches).
    pub fn y_ci95_half_width(&self, k: u32) -> f64 {
        crate::sampling::t95(self.batches(k).saturating_sub(1)) * self.y_standard_error(k)
    }
    /// Add the splats of `paths` light paths (see [`crate::integrator::light_path`]): their
    /// Σ X, Σ Y, Σ Z and Σ Y² on this pixel (Σ E and Σ E² go to
    /// [`IlluminanceSums::add_light_paths`]).
    #[inline]
    pub fn add_light_paths(&mut self, sums: &[f64; 4], paths: u64) {
        for (s, v) in self.splat_xyz.iter_mut().zip(sums) {
            *s += v;
        }
        self.splat_y2 += sums[3];
        self.light_paths += paths;
    }
    /// Add the sums of an independent render of this pixel (another seed). Its batch b joins
    /// batch (b + count) mod 16, as if its samples continued this pixel's numbering, so the
    /// batch sizes keep the i mod 16 rule; every batch stream still feeds a single batch, so
    /// the batches stay independent.
    pub fn merge(&mut self, o: &PixelSums) {
        let r = (self.count % PIXEL_BATCHES as u64) as usize;
        for b in 0..PIXEL_BATCHES {
            self.batch_y[(b + r) % PIXEL_BATCHES] += o.batch_y[b];
        }
        for k in 0..3 {
            self.sum_xyz[k] += o.sum_xyz[k];
        }
        self.sum_y2 += o.sum_y2;
        self.count += o.count;
        for k in 0..3 {
            self.splat_xyz[k] += o.splat_xyz[k];
        }
        self.splat_y2 += o.splat_y2;
        self.light_paths += o.light_paths;
    }
    /// Mean absolute XYZ: the camera samples' mean plus, with light tracing, the light paths'.
    pub fn mean_xyz(&self) -> [f64; 3] {
        let mean = |sum: &[f64; 3], n: u64| {
            if n == 0 {
                [0.0; 3]
            } else {
                sum.map(|v| v / n as f64)
            }
        };
        let (c, l) = (
            mean(&self.sum_xyz, self.count),
            mean(&self.splat_xyz, self.light_paths),
        );
        [c[0] + l[0], c[1] + l[1], c[2] + l[2]]
    }
    /// Standard error (cd/m²) of the mean luminance in a render of `k` batches per pixel: that
    /// of the camera samples from the spread of their batches ([`batch_standard_error`]) and,
    /// with light-traced caustics, that of the light paths from their sample variance, added
    /// in quadrature (independent estimates).
    pub fn y_standard_error(&self, k: u32) -> f64 {
        let cam = batch_standard_error(&self.batch_y, self.count, k);
        let light = standard_error(self.splat_xyz[1], self.splat_y2, self.light_paths);
        (cam * cam + light * light).sqrt()
    }
    /// The standard error of the mean luminance that treats the camera samples as independent,
    /// √(s²/n) with the sample variance: an over-estimate for stratified samples, kept for
    /// comparison.
    pub fn y_standard_error_iid(&self) -> f64 {
        let cam = standard_error(self.sum_xyz[1], self.sum_y2, self.count);
        let light = standard_error(self.splat_xyz[1], self.splat_y2, self.light_paths);
        (cam * cam + light * light).sqrt()
    }
}

/// Most samples a film may hold, summed over its pixels and both buffers (and the most light
/// paths per buffer): far beyond any render (2²⁸ pixels × 2³² samples is 2⁶⁰), and small
/// enough that counts, their sums and a merge of two films never overflow a u64.
pub const MAX_SAMPLES: u64 = 1 << 62;

/// Largest X/Y and Z/Y of any sample. Radiance is ≥ 0 and the CIE 1931 x̄, ȳ, z̄ are ≥ 0 with
/// ȳ > 0 over the table, so a sample's X/Y lies between the table's smallest and largest x̄/ȳ
/// (a weighted sum of ratios, and a lerp between two table points stays between theirs); the
/// same holds for sums of samples. Infinite if ȳ were 0 where x̄ or z̄ is not.
static XYZ_OVER_Y: LazyLock<[f64; 2]> = LazyLock::new(|| {
    let c = &*FILM_CMFS;
    let mut r = [0.0f64; 2];
    for i in 0..DENSE_LEN {
        let y = c.y[i] as f64;
        for (k, v) in [c.x[i], c.z[i]].into_iter().enumerate() {
            let ratio = if v == 0.0 { 0.0 } else { v as f64 / y };
            r[k] = r[k].max(ratio);
        }
    }
    r
});

/// Whether Σx and Σx² of n samples that are each ≥ 0 agree: Σx² ≤ (Σx)² (no cross terms are
/// negative) and (Σx)² ≤ n·Σx² (Cauchy–Schwarz), compared through square roots so that nothing
/// overflows. The relative slack covers the rounding of n additions; the absolute one, samples
/// so small (below 1e-150) that their squares underflow.
fn sums_agree(sum: f64, sum2: f64, n: u64) -> bool {
    if n == 0 {
        return sum == 0.0 && sum2 == 0.0;
    }
    let nf = n as f64;
    let rel = 1.0 + 1e-9_f64.max(4.0 * nf * f64::EPSILON);
    let abs = nf * 1e-150;
    sum2.sqrt() <= sum * rel + abs && sum <= (nf * sum2).sqrt() * rel + abs
}

/// Whether the batch sums `batches` of Σ `what` over `count` samples (sample i in batch
/// i mod 16) are finite, ≥ 0, 0 in the batches that hold no sample, and add up to `total`.
fn check_batches(
    what: &str,
    batches: &[f64; PIXEL_BATCHES],
    total: f64,
    count: u64,
) -> Result<(), String> {
    let nonempty = count.min(PIXEL_BATCHES as u64) as usize;
    for (b, &v) in batches.iter().enumerate() {
        if !(v.is_finite() && v >= 0.0) {
            return Err(format!(
                "batch {b} of Σ {what} is {v:e}, but sums of luminance and illuminance are finite and ≥ 0"
            ));
        }
        if b >= nonempty && v != 0.0 {
            return Err(format!(
                "batch {b} of Σ {what} is {v:e}, but with {count} samples that batch holds none"
            ));
        }
    }
    // The same samples summed in another order: equal but for rounding.
    let rel = 1.0 + 1e-9_f64.max(4.0 * count as f64 * f64::EPSILON);
    let abs = count as f64 * 1e-150;
    let sum: f64 = batches.iter().sum();
    if sum > total * rel + abs || total > sum * rel + abs {
        return Err(format!(
            "its batches of Σ {what} add up to {sum:e}, but Σ {what} is {total:e}"
        ));
    }
    Ok(())
}

impl PixelSums {
    /// Whether these sums can come from a render whose buffer traced `light_paths` light
    /// paths; the message names the field at fault.
    fn check(&self, light_paths: u64) -> Result<(), String> {
        let fields = [
            ("Σ X", self.sum_xyz[0]),
            ("Σ Y", self.sum_xyz[1]),
            ("Σ Z", self.sum_xyz[2]),
            ("Σ Y²", self.sum_y2),
            ("light-path Σ X", self.splat_xyz[0]),
            ("light-path Σ Y", self.splat_xyz[1]),
            ("light-path Σ Z", self.splat_xyz[2]),
            ("light-path Σ Y²", self.splat_y2),
        ];
        for (name, v) in fields {
            // XYZ of spectra ≥ 0 under the (non-negative) CIE 1931 functions and squares are
            // all ≥ 0.
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!(
                    "{name} is {v:e}, but sums of XYZ and their squares are finite and ≥ 0"
                ));
            }
        }
        check_batches("Y", &self.batch_y, self.sum_xyz[1], self.count)?;
        if self.light_paths != light_paths {
            return Err(format!(
                "it counts {} light paths, but the film traced {light_paths} for this buffer",
                self.light_paths
            ));
        }
        let ratio = *XYZ_OVER_Y;
        let tol = 1.0 + 1e-5;
        for (what, xyz, n) in [
            ("", &self.sum_xyz, self.count),
            ("light-path ", &self.splat_xyz, self.light_paths),
        ] {
            if n == 0 && xyz.iter().any(|&v| v != 0.0) {
                return Err(format!("{what}Σ XYZ is not 0 over 0 samples"));
            }
            for (k, c) in [(0, 'X'), (2, 'Z')] {
                let bound = ratio[k / 2] * xyz[1] * tol + n as f64 * 1e-150;
                if xyz[k] > bound {
                    return Err(format!(
                        "{what}Σ {c} = {:e} exceeds {:.1} × Σ Y = {:e}, the most any spectrum gives",
                        xyz[k],
                        ratio[k / 2],
                        xyz[1]
                    ));
                }
            }
        }
        for (what, sum, sum2, n, count) in [
            (
                "Σ Y and Σ Y²",
                self.sum_xyz[1],
                self.sum_y2,
                self.count,
                "samples",
            ),
            (
                "light-path Σ Y and Σ Y²",
                self.splat_xyz[1],
                self.splat_y2,
                self.light_paths,
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

/// √(s²/n) from Σx, Σx² and n, with the unbiased sample variance s² (0 for n < 2).
pub fn standard_error(sum: f64, sum2: f64, n: u64) -> f64 {
    if n < 2 {
        return 0.0;
    }
    let nf = n as f64;
    let mean = sum / nf;
    let var = ((sum2 - nf * mean * mean) / (nf - 1.0)).max(0.0);
    (var / nf).sqrt()
}

/// The whole image's sums.
///
/// In adaptive mode (a target error), each pixel takes its samples in pairs: one for `pixels`
/// (the image), one from an independent random stream for `decision`, whose statistics alone
/// decide whether the pixel needs more samples. The number of image samples is then a stopping
/// time independent of the image samples themselves, so the image stays unbiased.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Film {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<PixelSums>,
    pub decision: Option<Vec<PixelSums>>,
    /// Caustic light paths traced so far for `pixels` and for `decision` (the next path
    /// indices of their streams).
    #[serde(default)]
    pub light_paths: [u64; 2],
    /// Illuminance sums of `pixels` and of `decision`, present only when the render estimates
    /// illuminance (see [`Self::estimate_illuminance`]).
    #[serde(default)]
    pub e: Option<Vec<IlluminanceSums>>,
    #[serde(default)]
    pub decision_e: Option<Vec<IlluminanceSums>>,
    /// Light-and-health channels of the image buffer, when asked for (written to render states
    /// after the film's own fields, see `state`).
    #[serde(skip)]
    pub health: Option<HealthFilm>,
    /// Independent sample sequences (batches) per pixel, one of [`PIXEL_BATCH_CHOICES`]: the
    /// standard errors come from the spread of their means (written to render states after
    /// the light-and-health sums, see `state`).
    #[serde(skip, default = "default_pixel_batches")]
    pub pixel_batches: u32,
}

impl Film {
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            pixel_batches: DEFAULT_PIXEL_BATCHES,
            width,
            height,
            pixels: vec![PixelSums::default(); width * height],
            decision: None,
            light_paths: [0; 2],
            e: None,
            decision_e: None,
            health: None,
        }
    }
    /// Allocate the illuminance sums of every buffer that lacks them (zero: for a film that
    /// holds no samples yet).
    pub fn estimate_illuminance(&mut self) {
        let n = self.pixels.len();
        self.e
            .get_or_insert_with(|| vec![IlluminanceSums::default(); n]);
        if self.decision.is_some() {
            self.decision_e
                .get_or_insert_with(|| vec![IlluminanceSums::default(); n]);
        }
    }
    /// Pixel `i` of the image with its illuminance sums, if the film has them.
    pub fn pixel_e(&self, i: usize) -> Option<PixelE<'_>> {
        let e = self.e.as_ref()?;
        Some(PixelE {
            sums: &self.pixels[i],
            e: &e[i],
            batches: self.pixel_batches,
        })
    }
    /// The image's pixels with their illuminance sums (none if the film has none).
    pub fn pixels_e(&self) -> impl Iterator<Item = PixelE<'_>> {
        self.pixels
            .iter()
            .zip(self.e.iter().flatten())
            .map(|(sums, e)| PixelE {
                sums,
                e,
                batches: self.pixel_batches,
            })
    }
    pub fn new_adaptive(width: usize, height: usize) -> Self {
        Self {
            decision: Some(vec![PixelSums::default(); width * height]),
            ..Self::new(width, height)
        }
    }
    /// Samples taken so far for pixel `i` (image and decision buffers), i.e. the index of its
    /// next sample.
    pub fn samples_taken(&self, i: usize) -> u64 {
        self.pixels[i].count + self.decision.as_ref().map_or(0, |d| d[i].count)
    }
    /// Combine another film of the same size (independent samples: a different seed).
    pub fn merge(&mut self, o: &Film) {
        // Health sums first: their batches continue the pixel's numbering before the merge.
        let same = |a: &HealthFilm, b: &HealthFilm| {
            (a.channels, a.illuminance) == (b.channels, b.illuminance)
        };
        match (self.health.as_mut(), o.health.as_ref()) {
            (Some(a), Some(b)) if same(a, b) => {
                let pixels = &self.pixels;
                a.merge(b, |i| pixels[i].count);
            }
            _ => self.health = None,
        }
        self.light_paths[0] += o.light_paths[0];
        self.light_paths[1] += o.light_paths[1];
        // Illuminance first: its batches continue the pixel's numbering before the merge.
        let decision = self.decision.as_deref().unwrap_or(&[]);
        for (e, oe, pixels) in [
            (&mut self.e, &o.e, &self.pixels[..]),
            (&mut self.decision_e, &o.decision_e, decision),
        ] {
            if let (Some(a), Some(b)) = (e.as_mut(), oe.as_ref()) {
                for ((x, y), p) in a.iter_mut().zip(b).zip(pixels) {
                    x.merge(y, p.count);
                }
            }
        }
        for (a, b) in self.pixels.iter_mut().zip(&o.pixels) {
            a.merge(b);
        }
        if let (Some(a), Some(b)) = (self.decision.as_mut(), o.decision.as_ref()) {
            for (x, y) in a.iter_mut().zip(b) {
                x.merge(y);
            }
        }
    }
    /// Whether this film can be the result of a render (with per-pixel illuminance if
    /// `illuminance`), as read from a file: sizes that match, counts that a render produces
    /// (every pixel the same number of samples, or in adaptive mode as many in each buffer; as
    /// many light paths on every pixel as the buffer traced; at most [`MAX_SAMPLES`]), and sums
    /// that are finite, ≥ 0, and agree with their sums of squares and counts, batch sums
    /// likewise, 0 in batches that hold no sample and adding up to their total. The message
    /// names the pixel, the buffer and what is wrong.
    pub fn check(&self, illuminance: bool) -> Result<(), String> {
        let n = self
            .width
            .checked_mul(self.height)
            .filter(|&n| n > 0)
            .ok_or_else(|| {
                format!(
                    "its size {}×{} is empty or too large",
                    self.width, self.height
                )
            })?;
        if self.e.is_some() != illuminance
            || self.decision_e.is_some() != (illuminance && self.decision.is_some())
        {
            return Err(if illuminance {
                "it lacks illuminance sums, but the render estimated illuminance".into()
            } else {
                "it holds illuminance sums, but the render did not estimate illuminance".into()
            });
        }
        let lengths = [
            Some(self.pixels.len()),
            self.decision.as_ref().map(Vec::len),
            self.e.as_ref().map(Vec::len),
            self.decision_e.as_ref().map(Vec::len),
        ];
        let names = [
            "image",
            "decision",
            "image illuminance",
            "decision illuminance",
        ];
        for (buffer, len) in names.iter().zip(lengths) {
            if len.is_some_and(|len| len != n) {
                return Err(format!(
                    "its {buffer} buffer has {} pixels, but the film is {}×{}",
                    len.unwrap_or(0),
                    self.width,
                    self.height
                ));
            }
        }
        if self.decision.is_none() && self.light_paths[1] != 0 {
            return Err("it counts light paths of a decision buffer it does not have".into());
        }
        if let Some(b) = (0..2).find(|&b| self.light_paths[b] > MAX_SAMPLES) {
            return Err(format!(
                "{} light paths for one buffer exceeds the limit of {MAX_SAMPLES}",
                self.light_paths[b]
            ));
        }
        let total: u128 = self
            .pixels
            .iter()
            .chain(self.decision.iter().flatten())
            .map(|p| p.count as u128)
            .sum();
        if total > MAX_SAMPLES as u128 {
            return Err(format!(
                "{total} samples in all exceeds the limit of {MAX_SAMPLES}"
            ));
        }
        let at = |i: usize| (i % self.width, i / self.width);
        // Passes give every pixel the same number of samples, or, in adaptive mode, the same
        // number to each buffer of a pixel; pixels no ray leaves (outside a fisheye's circle)
        // hold none.
        let most = self.pixels.iter().map(|p| p.count).max().unwrap_or(0);
        for (i, p) in self.pixels.iter().enumerate() {
            let ok = match &self.decision {
                Some(d) => p.count == d[i].count,
                None => p.count == most || p.count == 0,
            };
            if !ok {
                let (x, y) = at(i);
                return Err(match &self.decision {
                    Some(d) => format!("pixel ({x}, {y}) has {} image samples but {} decision samples (adaptive passes give both buffers as many)", p.count, d[i].count),
                    None => format!("pixel ({x}, {y}) has {} samples but other pixels have {most} (every pass gives every pixel of the image as many)", p.count),
                });
            }
        }
        let buffers = std::iter::once(("image", &self.pixels, &self.e, self.light_paths[0])).chain(
            self.decision
                .iter()
                .map(|d| ("decision", d, &self.decision_e, self.light_paths[1])),
        );
        for (buffer, pixels, e, light_paths) in buffers {
            for (i, p) in pixels.iter().enumerate() {
                p.check(light_paths)
                    .and_then(|()| e.as_ref().map_or(Ok(()), |e| e[i].check(p)))
                    .map_err(|e| {
                        let (x, y) = at(i);
                        format!("pixel ({x}, {y}) of the {buffer} buffer: {e}")
                    })?;
            }
        }
        Ok(())
    }
    /// Mean XYZ per pixel as f32 (row-major).
    pub fn xyz_image(&self) -> Vec<[f32; 3]> {
        self.pixels
            .iter()
            .map(|p| {
                let m = p.mean_xyz();
                [m[0] as f32, m[1] as f32, m[2] as f32]
            })
            .collect()
    }
    pub fn y_stderr_image(&self) -> Vec<f32> {
        self.pixels
            .iter()
            .map(|p| p.y_standard_error(self.pixel_batches) as f32)
            .collect()
    }
    /// Illuminance channels: (E with the sentinel where undefined, its standard error, coverage).
    /// (All undefined if the film has no illuminance sums.)
    pub fn illuminance_images(&self) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
        let n = self.pixels.len();
        let (mut e, mut se, mut cov) = (
            vec![crate::output::ILLUMINANCE_SENTINEL; n],
            vec![0.0; n],
            vec![0.0; n],
        );
        for (i, p) in self.pixels_e().enumerate() {
            if let Some(v) = p.mean_e() {
                e[i] = v as f32;
            }
            se[i] = p.e_standard_error() as f32;
            cov[i] = p.e_coverage() as f32;
        }
        (e, se, cov)
    }
    pub fn total_samples(&self) -> u64 {
        self.pixels.iter().map(|p| p.count).sum()
    }

    /// Pixels that have samples: all of them but a fisheye's pixels wholly outside its circle,
    /// which see nothing and are never sampled (at least 1, for an empty film).
    fn sampled_pixels(&self) -> usize {
        self.pixels.iter().filter(|p| p.count > 0).count().max(1)
    }

    /// Mean luminance of the image, cd/m²: the pixels' mean Y averaged over the pixels that
    /// have samples.
    pub fn mean_luminance_cd_m2(&self) -> f64 {
        self.pixels.iter().map(|p| p.mean_xyz()[1]).sum::<f64>() / self.sampled_pixels() as f64
    }

    /// Image samples per pixel: all samples over the number of pixels that have samples.
    pub fn samples_per_pixel(&self) -> f64 {
        self.total_samples() as f64 / self.sampled_pixels() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_error_of_known_samples() {
        // Four samples, one per batch: the batch estimate equals the iid one. s² = 5/3,
        // se = √(5/12).
        let mut p = PixelSums::default();
        for y in [1.0, 2.0, 3.0, 4.0] {
            p.add([0.0, y, 0.0]);
        }
        assert!((p.y_standard_error(16) - (5.0f64 / 12.0).sqrt()).abs() < 1e-12);
        assert!((p.y_standard_error_iid() - (5.0f64 / 12.0).sqrt()).abs() < 1e-12);
        assert_eq!(p.mean_xyz()[1], 2.5);
        assert_eq!(p.batches(16), 4);
    }

    #[test]
    fn the_standard_error_is_the_spread_of_the_batch_means() {
        // 64 samples, sample i in batch i mod 16 with value b = i mod 16 (+ i/16 · 0, so
        // nothing varies within a batch): batch means 0 … 15, sd √(340/15), se = sd/4.
        let (mut p, mut e) = (PixelSums::default(), IlluminanceSums::default());
        for i in 0..64u64 {
            e.add(p.count, Some(2.0 * (i % 16) as f64));
            p.add([0.0, (i % 16) as f64, 0.0]);
        }
        let pe = PixelE {
            sums: &p,
            e: &e,
            batches: 16,
        };
        let se = (340.0f64 / 15.0).sqrt() / 4.0;
        assert!(
            (p.y_standard_error(16) - se).abs() < 1e-12,
            "{}",
            p.y_standard_error(16)
        );
        assert!((pe.e_standard_error() - 2.0 * se).abs() < 1e-12);
        assert!((pe.e_ci95_half_width() - 2.131_449_545_6 * 2.0 * se).abs() < 1e-9);
        assert!((p.y_ci95_half_width(16) - 2.131_449_545_6 * se).abs() < 1e-9);
        // Variation only within batches, equal batch means: no spread at all.
        let mut q = PixelSums::default();
        for i in 0..64u64 {
            q.add([0.0, (i / 16) as f64, 0.0]);
        }
        assert_eq!(q.y_standard_error(16), 0.0);
        // The iid estimate sees the within-batch spread: s² = 80/63.
        assert!((q.y_standard_error_iid() - (80.0f64 / 63.0 / 64.0).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn unequal_batches_are_weighted() {
        // 20 samples of 1: batches 0–3 hold 2, the others 1; every sample equal, no error.
        let mut p = PixelSums::default();
        for _ in 0..20 {
            p.add([0.0, 1.0, 0.0]);
        }
        assert_eq!(p.y_standard_error(16), 0.0);
        assert_eq!((batch_count(20, 3, 16), batch_count(20, 4, 16)), (2, 1));
    }

    #[test]
    fn fewer_batches_gather_the_slots() {
        // 64 samples of value i mod 16 in a render of 4 batches: batch b holds the slots
        // b, b + 4, b + 8, b + 12, whose values are b, b + 4, b + 8, b + 12 four times each,
        // so the 4 batch means are b + 6 (sd √(5/3)) and se = sd/2.
        let mut p = PixelSums::default();
        for i in 0..64u64 {
            p.add([0.0, (i % 16) as f64, 0.0]);
        }
        let se = (5.0f64 / 3.0).sqrt() / 2.0;
        assert!((p.y_standard_error(4) - se).abs() < 1e-12);
        assert!((p.y_ci95_half_width(4) - 3.182_446_305_3 * se).abs() < 1e-9);
        assert_eq!((p.batches(4), p.batches(2)), (4, 2));
        // 6 samples in 4 batches: sizes 2, 2, 1, 1; sample i in batch i mod 4.
        assert_eq!(
            (0..4).map(|b| batch_count(6, b, 4)).collect::<Vec<_>>(),
            [2, 2, 1, 1]
        );
        let folded = fold_batches(&p.batch_y, 4);
        assert_eq!(folded[..4], [96.0, 112.0, 128.0, 144.0]);
        assert!(folded[4..].iter().all(|&v| v == 0.0));
    }

    #[test]
    fn merging_continues_the_batch_numbering() {
        // 5 + 7 samples merged hold the batches of 12 samples numbered in a row.
        let (mut a, mut b, mut all) = Default::default();
        let v = |i: u64| [0.0, (i * i % 7) as f64, 0.0];
        for i in 0..5 {
            PixelSums::add(&mut a, v(i));
            PixelSums::add(&mut all, v(i));
        }
        for i in 5..12 {
            PixelSums::add(&mut b, v(i));
            PixelSums::add(&mut all, v(i));
        }
        a.merge(&b);
        assert_eq!(a.batch_y, all.batch_y);
        assert_eq!(a.count, 12);
        assert!(a.check(0).is_ok());
    }

    #[test]
    fn check_names_inconsistent_batches() {
        let (mut p, mut pe) = (PixelSums::default(), IlluminanceSums::default());
        for i in 0..20 {
            pe.add(p.count, Some(1.0));
            p.add([0.0, i as f64, 0.0]);
        }
        assert!(p.check(0).is_ok() && pe.check(&p).is_ok());
        let mut q = p;
        q.batch_y[3] += 1.0;
        let e = q.check(0).unwrap_err();
        assert!(e.contains("batches of Σ Y add up to"), "{e}");
        let mut qe = pe;
        qe.batch_e[2] = -1.0;
        qe.batch_e[5] += 1.0;
        let e = qe.check(&p).unwrap_err();
        assert!(e.contains("batch 2 of Σ E"), "{e}");
        // Illuminance of more samples than the pixel holds.
        let mut r = p;
        r.count = 10;
        r.batch_y = [0.0; PIXEL_BATCHES];
        let e = pe.check(&r).unwrap_err();
        assert!(
            e.contains("holds none") || e.contains("only 10 samples"),
            "{e}"
        );
        let mut q = PixelSums::default();
        for _ in 0..3 {
            q.add([0.0, 1.0, 0.0]);
        }
        q.batch_y[9] = 1.0;
        q.batch_y[0] = 0.0;
        let e = q.check(0).unwrap_err();
        assert!(
            e.contains("batch 9 of Σ Y") && e.contains("holds none"),
            "{e}"
        );
    }
}
