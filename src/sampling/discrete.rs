//! Choosing one of several weighted items: a cumulative distribution and the pick from it.

/// The cumulative distribution (last entry exactly 1) of non-negative weights with a positive,
/// finite sum, accumulated in f64.
pub fn cdf_from_weights(weights: &[f64]) -> Vec<f32> {
    let total: f64 = weights.iter().sum();
    let mut acc = 0.0;
    let mut cdf: Vec<f32> = weights
        .iter()
        .map(|w| {
            acc += w / total;
            acc as f32
        })
        .collect();
    if let Some(last) = cdf.last_mut() {
        *last = 1.0;
    }
    cdf
}

/// Choose an index from a cumulative distribution (last entry 1); returns it and its probability.
pub fn pick_from_cdf(cdf: &[f32], u: f32) -> (usize, f32) {
    let k = cdf.partition_point(|&c| c <= u).min(cdf.len() - 1);
    let lo = if k == 0 { 0.0 } else { cdf[k - 1] };
    (k, cdf[k] - lo)
}

/// The item whose share of the summed `weights` contains `x` ∈ [0, Σw), without a stored
/// distribution (for a few items whose weights change per query); the last item if `x`
/// falls beyond the sum by rounding.
pub fn choose_by_weight(weights: impl ExactSizeIterator<Item = f64>, mut x: f64) -> usize {
    let last = weights.len().saturating_sub(1);
    for (k, w) in weights.enumerate() {
        if x < w {
            return k;
        }
        x -= w;
    }
    last
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pick_returns_the_interval_and_its_probability() {
        let cdf = cdf_from_weights(&[1.0, 1.0, 2.0]);
        assert_eq!(cdf, vec![0.25, 0.5, 1.0]);
        assert_eq!(pick_from_cdf(&cdf, 0.1), (0, 0.25));
        assert_eq!(pick_from_cdf(&cdf, 0.3), (1, 0.25));
        assert_eq!(pick_from_cdf(&cdf, 0.99), (2, 0.5));
        assert_eq!(choose_by_weight([1.0, 1.0, 2.0].into_iter(), 1.5), 1);
        assert_eq!(choose_by_weight([1.0, 1.0, 2.0].into_iter(), 4.5), 2);
    }
}
