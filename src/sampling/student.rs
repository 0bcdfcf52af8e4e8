//! Student's t quantiles for the 95 % intervals of estimates whose standard error comes from a
//! few independent batches (meters, grid points, pixels).

/// t₀.₉₇₅ for 1 to 30 degrees of freedom (exact to 10 decimals).
const T95: [f64; 30] = [
    12.706_204_736_2,
    4.302_652_729_7,
    3.182_446_305_3,
    2.776_445_105_2,
    2.570_581_835_6,
    2.446_911_851_1,
    2.364_624_251_6,
    2.306_004_135_2,
    2.262_157_162_8,
    2.228_138_852_0,
    2.200_985_160_1,
    2.178_812_829_7,
    2.160_368_656_5,
    2.144_786_687_9,
    2.131_449_545_6,
    2.119_905_299_2,
    2.109_815_577_8,
    2.100_922_040_2,
    2.093_024_054_4,
    2.085_963_447_3,
    2.079_613_844_7,
    2.073_873_067_9,
    2.068_657_610_4,
    2.063_898_561_6,
    2.059_538_552_8,
    2.055_529_438_6,
    2.051_830_516_5,
    2.048_407_141_8,
    2.045_229_642_1,
    2.042_272_456_3,
];

/// The two-sided 95 % quantile of Student's t with `dof` degrees of freedom (t₀.₉₇₅): the
/// table up to 30, then the Cornish–Fisher expansion about the normal quantile (Abramowitz &
/// Stegun 26.7.5; within 3·10⁻⁸ from 31 on); infinite for 0.
pub fn t95(dof: u32) -> f64 {
    const Z: f64 = 1.959_963_984_540_054;
    match dof {
        0 => f64::INFINITY,
        1..=30 => T95[dof as usize - 1],
        _ => {
            let (z2, n) = (Z * Z, dof as f64);
            let g1 = (z2 + 1.0) * Z / 4.0;
            let g2 = ((5.0 * z2 + 16.0) * z2 + 3.0) * Z / 96.0;
            let g3 = (((3.0 * z2 + 19.0) * z2 + 17.0) * z2 - 15.0) * Z / 384.0;
            let g4 =
                ((((79.0 * z2 + 776.0) * z2 + 1482.0) * z2 - 1920.0) * z2 - 945.0) * Z / 92160.0;
            Z + (g1 + (g2 + (g3 + g4 / n) / n) / n) / n
        }
    }
}
