//! A pixel's independent sample batches: how its samples are numbered into batches, and the
//! standard error from the spread of the batch means ([uncertainty](../../docs/uncertainty.md)).

/// Slots of a pixel's batch sums: sample i is added to slot i mod `PIXEL_BATCHES`. A render
/// draws its camera samples from K independently scrambled Sobol sequences per pixel, K =
/// [`super::Film::pixel_batches`] (2, 4, 8 or 16, a divisor of 16): sample i is sample i / K of
/// sequence i mod K (see [`crate::render::render_pixel`]), so slot b holds samples of sequence
/// b mod K, and the K batches are the slots taken together by that remainder
/// ([`batch_standard_error`]).
pub const PIXEL_BATCHES: usize = 16;

/// Independent sample sequences (batches) per pixel unless the scene says otherwise
/// (`render.pixel_batches`): the most, for the narrowest 95 % intervals (Student's t with 15
/// degrees of freedom).
pub const DEFAULT_PIXEL_BATCHES: u32 = 16;

pub(super) fn default_pixel_batches() -> u32 {
    DEFAULT_PIXEL_BATCHES
}

/// The numbers of batches per pixel a render may use: the divisors of [`PIXEL_BATCHES`] that
/// leave at least two batches for a standard error.
pub const PIXEL_BATCH_CHOICES: [u32; 4] = [2, 4, 8, 16];

/// The batch sums of `k` batches from the slot sums (slot b in batch b mod k), in the first
/// `k` entries.
#[inline]
pub fn fold_batches(slots: &[f64; PIXEL_BATCHES], k: u32) -> [f64; PIXEL_BATCHES] {
    let k = (k as usize).clamp(1, PIXEL_BATCHES);
    let mut out = [0.0; PIXEL_BATCHES];
    for (b, v) in slots.iter().enumerate() {
        out[b % k] += v;
    }
    out
}

/// EXR attribute giving the number of independent sample batches per pixel behind `stderr.Y`
/// and `stderr.E`: a pixel with n samples has min(n, batches) of them, and its 95 % interval
/// uses Student's t with one degree of freedom fewer.
pub const STDERR_BATCHES_ATTRIBUTE: &str = "stderr_batches";

/// Samples of batch `b` of `k` among the first `n` samples of a pixel (sample i in batch
/// i mod k).
#[inline]
pub fn batch_count(n: u64, b: usize, k: u32) -> u64 {
    let k = k as u64;
    n / k + ((b as u64) < n % k) as u64
}

/// Standard error of Σ / n from the slot sums `slots` of `n` samples drawn from `k`
/// independent batches ([`fold_batches`]; batch sizes by [`batch_count`]): the ratio
/// estimator's √(K/(K−1) · Σᵦ (Sᵦ − x̄ nᵦ)²) / n over the K = min(n, k) non-empty batches,
/// which is the spread of the batch means over √K when the batches are equal. 0 below 2
/// batches.
pub fn batch_standard_error(slots: &[f64; PIXEL_BATCHES], n: u64, k: u32) -> f64 {
    let sums = fold_batches(slots, k);
    let kk = n.min(k as u64) as usize;
    if kk < 2 {
        return 0.0;
    }
    let nf = n as f64;
    let mean = sums.iter().sum::<f64>() / nf;
    let ss: f64 = (0..kk)
        .map(|b| (sums[b] - mean * batch_count(n, b, k) as f64).powi(2))
        .sum();
    (ss * kk as f64 / (kk - 1) as f64).sqrt() / nf
}
