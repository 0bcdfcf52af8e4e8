//! Sample streams: Owen-scrambled Sobol points (Burley 2020, via `sobol_burley`), one
//! independent scramble per pixel, addressed by (pixel, sample index, dimension) so that any
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

/// Number of samples `sobol_burley` provides per seed; longer runs move to a fresh scramble.
const BLOCK: u32 = 1 << 16;
/// Dimensions per seed in `sobol_burley`; deeper dimensions reuse them with a fresh scramble.
const DIMS: u32 = 256;

/// The sample stream of one camera sample.
///
/// Values are exactly `sobol_burley::sample(index, dim, seed)` (tested), but computed four
/// dimensions at a time with SIMD (`sobol_burley::parts`), and with the per-sample index
/// shuffle (the same for every dimension) done once: the generator was a quarter of the
/// render time when every dimension paid for its own shuffle.
#[derive(Clone, Debug)]
pub struct Sampler {
    seed: u64,
    block_seed: u32,
    /// Sample index within the block.
    index: u32,
    /// Bit-reversed, Owen-shuffled sample index under `block_seed`.
    shuffled_rev: u32,
    /// Next dimension to hand out.
    dim: u32,
    /// Dimensions `dim & !3 ..= dim | 3`, valid when `dim & 3 != 0`.
    buf: [f32; 4],
}

impl Sampler {
    /// Stream for sample `sample_index` of pixel `pixel` (row-major index) under `seed`.
    pub fn new(seed: u64, pixel: u64, sample_index: u64) -> Self {
        use sobol_burley::parts::{hash, owen_scramble_rev};
        let pixel_seed = mix64(seed ^ mix64(pixel.wrapping_add(0x9e37_79b9_7f4a_7c15)));
        let block = sample_index / BLOCK as u64;
        let block_seed = mix64(pixel_seed ^ block) as u32;
        let index = (sample_index % BLOCK as u64) as u32;
        Self {
            seed: pixel_seed,
            block_seed,
            index,
            shuffled_rev: owen_scramble_rev(index.reverse_bits(), hash(block_seed ^ 0x79c6_8e4a)),
            dim: 0,
            buf: [0.0; 4],
        }
    }

    /// Dimensions `4·set .. 4·set + 4` of the stream (set < DIMS / 4) under scramble `seed`:
    /// `sobol_burley::sample_4d` with the index shuffle precomputed.
    #[inline]
    fn sample_4d(shuffled_rev: u32, set: u32, seed: u32) -> [f32; 4] {
        use sobol_burley::parts::{hash_int4, owen_scramble_int4_rev, sobol_int4_rev, Int4};
        let sobol = sobol_int4_rev(shuffled_rev, set);
        let seed = seed.wrapping_mul(0x9c8f_2d3b);
        let scramble: Int4 = [
            seed ^ set ^ 0x912f_69ba,
            seed ^ set ^ 0x174f_18ab,
            seed ^ set ^ 0x691e_72ca,
            seed ^ set ^ 0xb40c_c1b8,
        ]
        .into();
        owen_scramble_int4_rev(sobol, hash_int4(scramble))
            .reverse_bits()
            .to_f32_norm()
    }

    #[inline]
    fn refill(&mut self) {
        let d = self.dim;
        self.buf = if d < DIMS {
            Self::sample_4d(self.shuffled_rev, d / 4, self.block_seed)
        } else {
            // Deeper dimensions: the same Sobol dimensions under a fresh scramble (which also
            // reshuffles the index).
            let seed = mix64(self.seed ^ ((d / DIMS) as u64) << 40 ^ self.block_seed as u64) as u32;
            sobol_burley::sample_4d(self.index, (d % DIMS) / 4, seed)
        };
    }

    /// Next uniform number in [0, 1).
    #[inline]
    pub fn get1d(&mut self) -> f32 {
        let d = self.dim;
        if d & 3 == 0 {
            self.refill();
        }
        self.dim += 1;
        self.buf[(d & 3) as usize].min(ONE_MINUS_EPSILON)
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
    fn equals_sobol_burley_one_dimension_at_a_time() {
        // The batched generator must hand out exactly `sobol_burley::sample`'s values,
        // including past the 256 dimensions of one scramble and past the 2^16-sample block.
        for (pixel, index) in [(0u64, 0u64), (77, 5), (123, 70_000), (4_000_000, 65_535)] {
            let mut s = Sampler::new(11, pixel, index);
            let pixel_seed = mix64(11 ^ mix64(pixel.wrapping_add(0x9e37_79b9_7f4a_7c15)));
            let block_seed = mix64(pixel_seed ^ (index >> 16)) as u32;
            let i = (index % (1 << 16)) as u32;
            for d in 0..600u32 {
                let want = if d < DIMS {
                    sobol_burley::sample(i, d, block_seed)
                } else {
                    let seed = mix64(pixel_seed ^ ((d / DIMS) as u64) << 40 ^ block_seed as u64);
                    sobol_burley::sample(i, d % DIMS, seed as u32)
                }
                .min(ONE_MINUS_EPSILON);
                assert_eq!(
                    s.get1d(),
                    want,
                    "pixel {pixel}, index {index}, dimension {d}"
                );
            }
        }
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
