//! Piecewise-constant densities on [0, 1) and [0, 1)² from tabulated non-negative weights,
//! sampled by inverting their cumulative distributions: the tool for importance-sampling a
//! tabulated function such as a sky's luminance.

/// A piecewise-constant density on [0, 1) with `n` equal cells, proportional to the weights.
#[derive(Clone, Debug, PartialEq)]
pub struct Piecewise1D {
    /// Cumulative sums of the weights, normalised: cdf[0] = 0, cdf[n] = 1.
    cdf: Vec<f64>,
    /// Density on each cell (its weight × n / Σ weights).
    density: Vec<f64>,
    /// Σ weights / n: the integral of the step function over [0, 1).
    integral: f64,
}

impl Piecewise1D {
    /// From `weights` (each ≥ 0 and finite); None if there are none or they sum to 0.
    pub fn new(weights: &[f64]) -> Option<Self> {
        let n = weights.len();
        if n == 0 || weights.iter().any(|w| !(w.is_finite() && *w >= 0.0)) {
            return None;
        }
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0);
        let mut acc = 0.0f64;
        for &w in weights {
            acc += w;
            cdf.push(acc);
        }
        if !(acc > 0.0 && acc.is_finite()) {
            return None;
        }
        for c in &mut cdf {
            *c /= acc;
        }
        cdf[n] = 1.0;
        let density = weights.iter().map(|w| w * n as f64 / acc).collect();
        Some(Self {
            cdf,
            density,
            integral: acc / n as f64,
        })
    }

    pub fn len(&self) -> usize {
        self.density.len()
    }

    pub fn is_empty(&self) -> bool {
        self.density.is_empty()
    }

    /// ∫₀¹ of the step function the weights define.
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// A point x in [0, 1) with density `pdf(x)`, and its cell. Cells of zero weight are
    /// never returned.
    pub fn sample(&self, u: f64) -> (f64, f64, usize) {
        let n = self.len();
        // The last cdf entry ≤ u among those with a following cell of positive weight.
        let mut k = self
            .cdf
            .partition_point(|&c| c <= u)
            .saturating_sub(1)
            .min(n - 1);
        while self.density[k] == 0.0 && k > 0 {
            k -= 1;
        }
        while self.density[k] == 0.0 && k + 1 < n {
            k += 1;
        }
        let width = self.cdf[k + 1] - self.cdf[k];
        let t = if width > 0.0 {
            ((u - self.cdf[k]) / width).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let x = ((k as f64 + t) / n as f64).min(1.0 - f64::EPSILON);
        (x, self.density[k], k)
    }

    /// Density at x ∈ [0, 1).
    pub fn pdf(&self, x: f64) -> f64 {
        let n = self.len();
        let k = ((x * n as f64) as usize).min(n - 1);
        self.density[k]
    }
}

/// A piecewise-constant density on [0, 1)² over an nu × nv grid: u by the marginal of the
/// rows, then v by the chosen row's conditional.
#[derive(Clone, Debug, PartialEq)]
pub struct Piecewise2D {
    marginal: Piecewise1D,
    /// One conditional per row of positive weight (None for rows that are all zero).
    conditional: Vec<Option<Piecewise1D>>,
}

impl Piecewise2D {
    /// From weights in row-major order: `weights[i * nv + j]` for u-cell i, v-cell j.
    pub fn new(weights: &[f64], nu: usize, nv: usize) -> Option<Self> {
        if nu == 0 || nv == 0 || weights.len() != nu.checked_mul(nv)? {
            return None;
        }
        let conditional: Vec<Option<Piecewise1D>> =
            weights.chunks(nv).map(Piecewise1D::new).collect();
        let row_integrals: Vec<f64> = conditional
            .iter()
            .map(|c| c.as_ref().map_or(0.0, |c| c.integral()))
            .collect();
        let marginal = Piecewise1D::new(&row_integrals)?;
        Some(Self {
            marginal,
            conditional,
        })
    }

    /// A point (u, v) and its density.
    pub fn sample(&self, u0: f64, u1: f64) -> ([f64; 2], f64) {
        let (u, pu, i) = self.marginal.sample(u0);
        let cond = self.conditional[i]
            .as_ref()
            .expect("the marginal never picks a row of zero weight");
        let (v, pv, _) = cond.sample(u1);
        ([u, v], pu * pv)
    }

    /// Density at (u, v) ∈ [0, 1)².
    pub fn pdf(&self, u: f64, v: f64) -> f64 {
        let n = self.marginal.len();
        let i = ((u * n as f64) as usize).min(n - 1);
        match &self.conditional[i] {
            Some(c) => self.marginal.pdf(u) * c.pdf(v),
            None => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_d_matches_its_weights() {
        let d = Piecewise1D::new(&[1.0, 0.0, 3.0, 4.0]).unwrap();
        assert_eq!(d.integral(), 2.0);
        // Densities: w · n / Σw = 0.5, 0, 1.5, 2.
        assert_eq!(d.pdf(0.1), 0.5);
        assert_eq!(d.pdf(0.3), 0.0);
        assert_eq!(d.pdf(0.99), 2.0);
        // u at a cell boundary of the zero cell lands in a positive cell.
        let (x, p, k) = d.sample(0.125);
        assert!(k != 1 && p > 0.0 && d.pdf(x) == p, "{x} {p} {k}");
        // Inversion: u = 0.5 is inside cell 2 (cdf 0.125 … 0.5) at its end.
        let (x, _, k) = d.sample(0.3125);
        assert_eq!(k, 2);
        assert!((x - 0.625).abs() < 1e-12);
        assert!(Piecewise1D::new(&[]).is_none());
        assert!(Piecewise1D::new(&[0.0, 0.0]).is_none());
        assert!(Piecewise1D::new(&[1.0, f64::NAN]).is_none());
        assert!(Piecewise1D::new(&[1.0, -1.0]).is_none());
    }

    #[test]
    fn two_d_histogram_matches_pdf() {
        // χ² of 200 000 samples against the cell probabilities of a 6 × 5 table with zeros.
        let (nu, nv) = (6, 5);
        let w: Vec<f64> = (0..nu * nv)
            .map(|k| {
                if k % 7 == 3 {
                    0.0
                } else {
                    1.0 + ((k * 37) % 11) as f64
                }
            })
            .collect();
        let d = Piecewise2D::new(&w, nu, nv).unwrap();
        let total: f64 = w.iter().sum();
        let n = 200_000usize;
        let mut counts = vec![0usize; nu * nv];
        let mut state = 0x1234_5678_9abc_def0u64;
        let mut rnd = || {
            state = crate::sampling::mix64(state.wrapping_add(0x9E37_79B9_7F4A_7C15));
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..n {
            let ([u, v], p) = d.sample(rnd(), rnd());
            let (i, j) = ((u * nu as f64) as usize, (v * nv as f64) as usize);
            assert!((d.pdf(u, v) - p).abs() <= 1e-12 * p, "pdf mismatch");
            counts[i * nv + j] += 1;
        }
        let mut chi2 = 0.0;
        let mut dof = 0;
        for k in 0..nu * nv {
            let expected = n as f64 * w[k] / total;
            if w[k] == 0.0 {
                assert_eq!(counts[k], 0, "a zero cell was sampled");
                continue;
            }
            // The density integrates to the cell's probability: p · cell area.
            let p_cell = d.pdf(
                (k / nv) as f64 / nu as f64 + 1e-9,
                (k % nv) as f64 / nv as f64 + 1e-9,
            ) / (nu * nv) as f64;
            assert!((p_cell - w[k] / total).abs() < 1e-12);
            chi2 += (counts[k] as f64 - expected).powi(2) / expected;
            dof += 1;
        }
        // 25 degrees of freedom: P(χ² > 60) ≈ 1e-4.
        assert!(chi2 < 60.0, "χ² = {chi2} over {dof} cells");
    }
}
