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
#[inline]
fn sample_4d_set0(index: u32, seed: u32) -> [f32; 4] {
    use sobol_burley::parts::{hash, hash_int4, owen_scramble_int4_rev, owen_scramble_rev, Int4};
    debug_assert!(index < BLOCK);
    let shuffled = owen_scramble_rev(index.reverse_bits(), hash(seed ^ 0x79c6_8e4a));
    let t = &**SET0_BYTES;
    let sobol = Int4::from(t[(shuffled >> 24) as usize])
        ^ Int4::from(t[256 + ((shuffled >> 16) & 0xff) as usize]);
    let s = seed.wrapping_mul(0x9c8f_2d3b);
    let scramble = Int4::from([
        s ^ 0x912f_69ba,
        s ^ 0x174f_18ab,
        s ^ 0x691e_72ca,
        s ^ 0xb40c_c1b8,
    ]);
    owen_scramble_int4_rev(sobol, hash_int4(scramble))
        .reverse_bits()
        .to_f32_norm()
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
    /// Sample index within the block.
    index: u32,
    /// Next dimension to hand out.
    dim: u32,
    /// Dimensions `dim & !3 ..= dim | 3`, valid when `dim & 3 != 0`.
    buf: [f32; 4],
}

impl Sampler {
    /// Stream for sample `sample_index` of pixel `pixel` (row-major index) under `seed`.
    pub fn new(seed: u64, pixel: u64, sample_index: u64) -> Self {
        let pixel_seed = mix64(seed ^ mix64(pixel.wrapping_add(0x9e37_79b9_7f4a_7c15)));
        let block = sample_index / BLOCK as u64;
        Self {
            block_seed: mix64(pixel_seed ^ block) as u32,
            index: (sample_index % BLOCK as u64) as u32,
            dim: 0,
            buf: [0.0; 4],
        }
    }

    /// Seed of the dimension set `set` (dimensions 4·set .. 4·set + 4).
    #[inline]
    fn set_seed(&self, set: u32) -> u32 {
        mix64(((set as u64) << 32) ^ self.block_seed as u64) as u32
    }

    /// Dimensions `d .. d + 4` (`d` a multiple of 4), each in [0, 1).
    #[inline]
    fn block(&self, d: u32) -> [f32; 4] {
        sample_4d_set0(self.index, self.set_seed(d / 4)).map(|x| x.min(ONE_MINUS_EPSILON))
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
