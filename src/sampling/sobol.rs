//! Sample streams: padded 4-D Owen-scrambled Sobol points (Burley 2020, via `sobol_burley`),
//! one independent scramble per pixel and dimension set, addressed by (pixel, sample index, dimension) so that any
//! sample of any pixel can be regenerated on any thread — the image does not depend on how the
//! work is split.

/// A deterministic hash (the 64-bit finaliser of MurmurHash3 / SplitMix64).
#[inline]
pub fn mix64(mut x: u64) -> u64 {
    x ^= x >> 33;
    x = x.wrapping_mul(0xff51_afd7_ed55_8ccd);
    x ^= x >> 33;
    x = x.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    x ^= x >> 33;
    x
}

/// The stream of batch `batch` of stream `stream`: an independent scramble of the same Sobol
/// sequence. Estimates whose standard error comes from the spread of independent
/// randomisations (randomised quasi-Monte Carlo, `meter`) draw each batch from its own.
pub fn batch_stream(stream: u64, batch: u32) -> u64 {
    mix64(stream ^ mix64(0x6261_7463_6800_0000 | batch as u64))
}

/// Number of samples `sobol_burley` provides per seed; longer runs move to a fresh scramble.
const BLOCK: u32 = 1 << 16;

/// The unscrambled Sobol points of dimensions 0–3 (bit-reversed) for the top byte (entries
/// 0–255) and the next byte (256–511) of a bit-reversed 16-bit index. A Sobol point is the XOR
/// of the direction vectors of its index's set bits, so two lookups give what
/// `sobol_burley::parts::sobol_int4_rev` computes bit by bit.
static SET0_BYTES: std::sync::LazyLock<Box<[[u32; 4]; 512]>> = std::sync::LazyLock::new(|| {
    use sobol_burley::parts::sobol_int4_rev;
    let mut t = Box::new([[0u32; 4]; 512]);
    for b in 0..256u32 {
        t[b as usize] = sobol_int4_rev(b << 24, 0).into();
        t[256 + b as usize] = sobol_int4_rev(b << 16, 0).into();
    }
    t
});

/// `sobol_burley::sample_4d(index, 0, seed)`, bit for bit, with the Sobol sum from
/// [`SET0_BYTES`] (the crate's loop over up to 16 index bits was a third of the path tracer's
/// own time on diffuse scenes).
#[cfg(test)]
fn sample_4d_set0(index: u32, seed: u32) -> [f32; 4] {
    debug_assert!(index < BLOCK);
    set0_rev(index.reverse_bits(), seed)
}

/// The index shuffle and Sobol point (bit-reversed) of dimension set seed `seed` for the
/// bit-reversed sample index `index_rev`: the four Sobol dimensions before their scramble.
#[inline(always)]
fn set0_sobol_rev(index_rev: u32, seed: u32) -> [u32; 4] {
    use sobol_burley::parts::{hash, owen_scramble_rev};
    let shuffled = owen_scramble_rev(index_rev, hash(seed ^ 0x79c6_8e4a));
    let t = &**SET0_BYTES;
    let (hi, lo) = (
        &t[(shuffled >> 24) as usize],
        &t[256 + ((shuffled >> 16) & 0xff) as usize],
    );
    [0, 1, 2, 3].map(|k| hi[k] ^ lo[k])
}

/// Per-dimension scramble seeds of set seed `seed` (before their hash).
#[inline(always)]
fn set0_scramble(seed: u32) -> [u32; 4] {
    let s = seed.wrapping_mul(0x9c8f_2d3b);
    [
        s ^ 0x912f_69ba,
        s ^ 0x174f_18ab,
        s ^ 0x691e_72ca,
        s ^ 0xb40c_c1b8,
    ]
}

/// [`sample_4d_set0`] of the bit-reversed index `index_rev`, each number in [0, 1) (on x86-64
/// with AVX2 the reference of [`set0_rev_pair`]'s tests).
#[cfg_attr(
    all(target_arch = "x86_64", target_feature = "avx2", not(test)),
    allow(dead_code)
)]
#[inline(always)]
fn set0_rev(index_rev: u32, seed: u32) -> [f32; 4] {
    use sobol_burley::parts::{hash_int4, owen_scramble_int4_rev, Int4};
    owen_scramble_int4_rev(
        Int4::from(set0_sobol_rev(index_rev, seed)),
        hash_int4(Int4::from(set0_scramble(seed))),
    )
    .reverse_bits()
    .to_f32_norm()
    .map(|x| x.min(ONE_MINUS_EPSILON))
}

/// [`set0_rev`] of two set seeds at once, bit for bit: the two chains of dependent multiplies
/// side by side in the lanes of one 8-lane vector, in the time of one.
#[inline(always)]
fn set0_rev_pair(index_rev: u32, seeds: [u32; 2]) -> [[f32; 4]; 2] {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    // SAFETY: AVX2 is enabled at compile time; only register operations and an unaligned
    // store to a local array.
    unsafe {
        use std::arch::x86_64::*;
        let v = |a: [u32; 4], b: [u32; 4]| {
            _mm256_setr_epi32(
                a[0] as i32,
                a[1] as i32,
                a[2] as i32,
                a[3] as i32,
                b[0] as i32,
                b[1] as i32,
                b[2] as i32,
                b[3] as i32,
            )
        };
        let c = |x: u32| _mm256_set1_epi32(x as i32);
        let (xor, mul, add) = (_mm256_xor_si256, _mm256_mullo_epi32, _mm256_add_epi32);
        let sobol = v(
            set0_sobol_rev(index_rev, seeds[0]),
            set0_sobol_rev(index_rev, seeds[1]),
        );
        // `hash_int4` of the scramble seeds.
        let mut h = xor(
            v(set0_scramble(seeds[0]), set0_scramble(seeds[1])),
            c(0xe6fe_3beb),
        );
        h = xor(h, _mm256_srli_epi32::<16>(h));
        h = mul(h, c(0x7feb_352d));
        h = xor(h, _mm256_srli_epi32::<15>(h));
        h = mul(h, c(0x846c_a68b));
        h = xor(h, _mm256_srli_epi32::<16>(h));
        // `owen_scramble_int4_rev`.
        let mut n = sobol;
        n = xor(n, mul(n, c(0x3d20_adea)));
        n = add(n, h);
        n = mul(n, _mm256_or_si256(_mm256_srli_epi32::<16>(h), c(1)));
        n = xor(n, mul(n, c(0x0552_6c56)));
        n = xor(n, mul(n, c(0x53a2_2864)));
        let n = avx2::reverse_bits(n);
        // `to_f32_norm`, then below 1.
        let f = _mm256_sub_ps(
            _mm256_castsi256_ps(_mm256_or_si256(_mm256_srli_epi32::<9>(n), c(0x3f80_0000))),
            _mm256_set1_ps(1.0),
        );
        let f = _mm256_min_ps(f, _mm256_set1_ps(ONE_MINUS_EPSILON));
        let mut out = [[0.0f32; 4]; 2];
        _mm256_storeu_ps(out.as_mut_ptr().cast(), f);
        out
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    seeds.map(|s| set0_rev(index_rev, s))
}

/// Lane-wise helpers of [`set0_rev_pair`].
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
mod avx2 {
    use std::arch::x86_64::*;

    /// `u32::reverse_bits` of each lane: the bits of each byte, then the bytes of each lane.
    #[inline(always)]
    pub(super) fn reverse_bits(n: __m256i) -> __m256i {
        // SAFETY: AVX2 is enabled at compile time; register operations only.
        unsafe {
            _mm256_shuffle_epi8(
                reverse_bits_in_bytes(n),
                _mm256_setr_epi8(
                    3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12, 3, 2, 1, 0, 7, 6, 5, 4,
                    11, 10, 9, 8, 15, 14, 13, 12,
                ),
            )
        }
    }

    /// The bits of each byte reversed, by two nibble lookups.
    #[inline(always)]
    pub(super) fn reverse_bits_in_bytes(n: __m256i) -> __m256i {
        // SAFETY: AVX2 is enabled at compile time; register operations only.
        unsafe {
            let rev_nibble = _mm256_setr_epi8(
                0, 8, 4, 12, 2, 10, 6, 14, 1, 9, 5, 13, 3, 11, 7, 15, 0, 8, 4, 12, 2, 10, 6, 14, 1,
                9, 5, 13, 3, 11, 7, 15,
            );
            let low = _mm256_set1_epi8(0x0f);
            let lo = _mm256_shuffle_epi8(rev_nibble, _mm256_and_si256(n, low));
            let hi =
                _mm256_shuffle_epi8(rev_nibble, _mm256_and_si256(_mm256_srli_epi16::<4>(n), low));
            _mm256_or_si256(_mm256_slli_epi16::<4>(lo), hi)
        }
    }
}

/// The sample stream of one camera sample: *padded* 4-D Owen-scrambled Sobol points (Burley
/// 2020, "Practical Hash-based Owen Scrambling", §4). Dimensions come in sets of four; every
/// set uses the first four Sobol dimensions, with its own index shuffle and its own scramble,
/// so the sets are statistically independent of each other while each set is a
/// well-stratified 4-D point set. Sobol's first dimensions have the best low-dimensional
/// projections — (0, 1) is a (0, 2)-sequence — whereas pairs of high Sobol dimensions can be
/// worse than random at low sample counts; callers therefore put their most important 2-D
/// pair first in each set (pixel position; light-sample point; BSDF direction).
///
/// Computed four dimensions per SIMD call (`sobol_burley::sample_4d`); hot loops take their
/// numbers in fours with [`Sampler::get4`].
#[derive(Clone, Debug)]
pub struct Sampler {
    /// Seed of this pixel and block of 2^16 samples.
    block_seed: u32,
    /// Next dimension to hand out.
    dim: u32,
    /// Dimensions `dim & !3 ..= dim | 3`, valid when `dim & 3 != 0`.
    buf: [f32; 4],
    /// `index.reverse_bits()`, which every set's shuffle starts from.
    index_rev: u32,
    /// The numbers of dimension sets 2·`pair_at` and 2·`pair_at` + 1 (a bounce takes one
    /// pair), and of the next pair, computed one pair early: each set's hashes are a chain of
    /// dependent multiplies, computed two sets at once and ahead of the request so that it
    /// runs while the caller traces the ray.
    pair: [[f32; 4]; 2],
    pair_at: u32,
    ahead: [[f32; 4]; 2],
    ahead_at: u32,
}

impl Sampler {
    /// Stream for sample `sample_index` of pixel `pixel` (row-major index) under `seed`.
    pub fn new(seed: u64, pixel: u64, sample_index: u64) -> Self {
        let pixel_seed = mix64(seed ^ mix64(pixel.wrapping_add(0x9e37_79b9_7f4a_7c15)));
        let block = sample_index / BLOCK as u64;
        Self {
            block_seed: mix64(pixel_seed ^ block) as u32,
            dim: 0,
            buf: [0.0; 4],
            index_rev: ((sample_index % BLOCK as u64) as u32).reverse_bits(),
            pair: [[0.0; 4]; 2],
            pair_at: u32::MAX,
            ahead: [[0.0; 4]; 2],
            ahead_at: u32::MAX,
        }
    }

    /// Seed of the dimension set `set` (dimensions 4·set .. 4·set + 4).
    #[inline]
    fn set_seed(&self, set: u32) -> u32 {
        mix64(((set as u64) << 32) ^ self.block_seed as u64) as u32
    }

    /// The numbers of dimension sets 2·`pair` and 2·`pair` + 1.
    #[inline(always)]
    fn compute_pair(&self, pair: u32) -> [[f32; 4]; 2] {
        let set = pair.wrapping_mul(2);
        set0_rev_pair(
            self.index_rev,
            [self.set_seed(set), self.set_seed(set.wrapping_add(1))],
        )
    }

    /// Dimensions `d .. d + 4` (`d` a multiple of 4), each in [0, 1). A new pair of sets
    /// starts the next pair's computation.
    #[inline]
    fn block(&mut self, d: u32) -> [f32; 4] {
        let set = d / 4;
        let pair = set / 2;
        if pair != self.pair_at {
            self.pair = if pair == self.ahead_at {
                self.ahead
            } else {
                self.compute_pair(pair)
            };
            self.pair_at = pair;
            self.ahead = self.compute_pair(pair.wrapping_add(1));
            self.ahead_at = pair.wrapping_add(1);
        }
        self.pair[(set & 1) as usize]
    }

    /// The next four dimensions at once, starting at the next multiple of four (dimensions
    /// skipped to get there are not used). Cheaper than four [`Sampler::get1d`] calls.
    #[inline]
    pub fn get4(&mut self) -> [f32; 4] {
        let d = (self.dim + 3) & !3;
        self.dim = d + 4;
        self.block(d)
    }

    /// Next uniform number in [0, 1).
    #[inline]
    pub fn get1d(&mut self) -> f32 {
        let d = self.dim;
        if d & 3 == 0 {
            self.buf = self.block(d);
        }
        self.dim += 1;
        self.buf[(d & 3) as usize]
    }

    #[inline]
    pub fn get2d(&mut self) -> glam::Vec2 {
        let x = self.get1d();
        let y = self.get1d();
        glam::Vec2::new(x, y)
    }
}

/// The largest f32 below 1.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_sobol_equals_the_crate_bit_for_bit() {
        for seed in [0u32, 1, 0xdead_beef, u32::MAX, 0x1234_5678] {
            for index in 0..BLOCK {
                let a = sample_4d_set0(index, seed);
                let b = sobol_burley::sample_4d(index, 0, seed);
                assert_eq!(
                    a.map(f32::to_bits),
                    b.map(f32::to_bits),
                    "index {index} seed {seed}"
                );
            }
        }
    }

    #[test]
    fn pair_equals_two_sets_bit_for_bit() {
        let mut x = 0x1234_5678_9abc_def0u64;
        for k in 0..200_000u32 {
            x = mix64(x.wrapping_add(k as u64));
            let (index, a, b) = ((x as u32) % BLOCK, (x >> 32) as u32, mix64(x) as u32);
            let index = if k < BLOCK { k } else { index };
            let pair = set0_rev_pair(index.reverse_bits(), [a, b]);
            for (got, seed) in pair.iter().zip([a, b]) {
                assert_eq!(
                    got.map(f32::to_bits),
                    sample_4d_set0(index, seed).map(f32::to_bits),
                    "index {index} seed {seed}"
                );
            }
        }
    }

    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    #[test]
    fn lane_bit_reversals_equal_the_scalar_one() {
        use std::arch::x86_64::*;
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..20_000 {
            let lanes: [u32; 8] = std::array::from_fn(|_| {
                x = mix64(x);
                x as u32
            });
            // SAFETY: AVX2 is enabled at compile time; loads and stores of local arrays.
            let (all, bytes) = unsafe {
                let v = _mm256_loadu_si256(lanes.as_ptr().cast());
                let (mut a, mut b) = ([0u32; 8], [0u32; 8]);
                _mm256_storeu_si256(a.as_mut_ptr().cast(), avx2::reverse_bits(v));
                _mm256_storeu_si256(b.as_mut_ptr().cast(), avx2::reverse_bits_in_bytes(v));
                (a, b)
            };
            for k in 0..8 {
                assert_eq!(all[k], lanes[k].reverse_bits());
                let per_byte = u32::from_le_bytes(lanes[k].to_le_bytes().map(u8::reverse_bits));
                assert_eq!(bytes[k], per_byte);
            }
        }
    }

    #[test]
    fn deterministic_and_in_range() {
        let mut a = Sampler::new(7, 123, 70_000);
        let mut b = Sampler::new(7, 123, 70_000);
        for _ in 0..600 {
            let x = a.get1d();
            assert_eq!(x, b.get1d());
            assert!((0.0..1.0).contains(&x));
        }
    }

    #[test]
    fn each_set_is_a_stratified_sobol_net() {
        // 64 consecutive samples of one pixel: in every dimension set, dimensions (0, 1) form
        // a (0, 6, 2)-net — exactly one point in each of the 64 elementary intervals of every
        // shape 2^a × 2^(6−a) — and every single dimension has one point per 1/64 interval.
        for set in [0u32, 1, 7, 100] {
            let pts: Vec<[f32; 4]> = (0..64)
                .map(|i| {
                    let mut s = Sampler::new(5, 321, i);
                    for _ in 0..set {
                        s.get4();
                    }
                    s.get4()
                })
                .collect();
            for a in 0..=6 {
                let (nx, ny) = (1u32 << a, 1u32 << (6 - a));
                let mut seen = [false; 64];
                for p in &pts {
                    let cell = (p[0] * nx as f32) as u32 * ny + (p[1] * ny as f32) as u32;
                    assert!(
                        !seen[cell as usize],
                        "set {set}, shape {nx}×{ny}: two points in one cell"
                    );
                    seen[cell as usize] = true;
                }
            }
            for k in 0..4 {
                let mut seen = [false; 64];
                for p in &pts {
                    let cell = (p[k] * 64.0) as usize;
                    assert!(!seen[cell], "set {set}, dimension {k} not stratified");
                    seen[cell] = true;
                }
            }
        }
    }

    #[test]
    fn sets_are_independent() {
        // Different sets of one sample must not repeat each other's values.
        let mut s = Sampler::new(1, 2, 3);
        let a = s.get4();
        let b = s.get4();
        assert_ne!(a, b);
    }

    #[test]
    fn get4_is_the_next_aligned_four_dimensions() {
        let mut a = Sampler::new(3, 8, 1234);
        let mut b = Sampler::new(3, 8, 1234);
        let x = a.get1d();
        assert_eq!(x, b.get1d());
        // get4 skips dimensions 1..4 and hands out 4..8.
        let four = a.get4();
        for _ in 1..4 {
            b.get1d();
        }
        for v in four {
            assert_eq!(v, b.get1d());
        }
        assert_eq!(a.get1d(), b.get1d());
        // Deep dimensions too (every set has its own scramble).
        for _ in 0..300 {
            b.get1d();
        }
        let mut c = b.clone();
        let skip = (4 - c.dim % 4) % 4;
        for _ in 0..skip {
            c.get1d();
        }
        let four = b.get4();
        for v in four {
            assert_eq!(v, c.get1d());
        }
    }

    #[test]
    fn batches_are_independent_randomisations() {
        // Over many streams, the first point of batch 0 and of batch 1 are each uniform and
        // uncorrelated (|r| < 4/√n), and within one batch the usual nets hold (its sampler is
        // an ordinary stream).
        let n = 4096;
        let (mut sx, mut sy, mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for stream in 0..n {
            let x = Sampler::new(11, batch_stream(stream, 0), 0).get1d() as f64 - 0.5;
            let y = Sampler::new(11, batch_stream(stream, 1), 0).get1d() as f64 - 0.5;
            (sx, sy, sxy, sxx, syy) = (sx + x, sy + y, sxy + x * y, sxx + x * x, syy + y * y);
        }
        let nf = n as f64;
        let r = (sxy / nf - sx * sy / nf / nf)
            / ((sxx / nf - (sx / nf).powi(2)) * (syy / nf - (sy / nf).powi(2))).sqrt();
        assert!(r.abs() < 4.0 / nf.sqrt(), "correlation {r}");
        // Uniform: mean 1/2 (sd of the mean 0.29/√n).
        assert!(
            (sx / nf).abs() < 4.0 * 0.29 / nf.sqrt() && (sy / nf).abs() < 4.0 * 0.29 / nf.sqrt()
        );
        let streams: std::collections::HashSet<u64> = (0..1000)
            .flat_map(|s| (0..16).map(move |b| batch_stream(s, b)))
            .collect();
        assert_eq!(streams.len(), 16_000, "batch streams must all differ");
    }

    #[test]
    fn mean_is_one_half_per_dimension() {
        // 4096 Sobol points per dimension: mean is 1/2 to within 1e-3 (QMC error ~1/N).
        for dim in [0usize, 5, 300] {
            let n = 4096;
            let m: f64 = (0..n)
                .map(|i| {
                    let mut s = Sampler::new(1, 9, i);
                    for _ in 0..dim {
                        s.get1d();
                    }
                    s.get1d() as f64
                })
                .sum::<f64>()
                / n as f64;
            assert!((m - 0.5).abs() < 1e-3, "dim {dim}: mean {m}");
        }
    }
}
