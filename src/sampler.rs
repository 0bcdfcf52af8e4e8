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
#[derive(Clone, Debug)]
pub struct Sampler {
    seed: u64,
    index: u32,
    block_seed: u32,
    dim: u32,
}

impl Sampler {
    /// Stream for sample `sample_index` of pixel `pixel` (row-major index) under `seed`.
    pub fn new(seed: u64, pixel: u64, sample_index: u64) -> Self {
        let pixel_seed = mix64(seed ^ mix64(pixel.wrapping_add(0x9e37_79b9_7f4a_7c15)));
        let block = sample_index / BLOCK as u64;
        Self {
            seed: pixel_seed,
            index: (sample_index % BLOCK as u64) as u32,
            block_seed: mix64(pixel_seed ^ block) as u32,
            dim: 0,
        }
    }

    /// Next uniform number in [0, 1).
    #[inline]
    pub fn get1d(&mut self) -> f32 {
        let d = self.dim;
        self.dim += 1;
        let (dim, seed) = if d < DIMS {
            (d, self.block_seed)
        } else {
            (
                d % DIMS,
                mix64(self.seed ^ ((d / DIMS) as u64) << 40 ^ self.block_seed as u64) as u32,
            )
        };
        sobol_burley::sample(self.index, dim, seed).min(ONE_MINUS_EPSILON)
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
