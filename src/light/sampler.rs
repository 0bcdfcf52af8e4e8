//! Choosing one light per shading point in proportion to its luminous power.

use super::Light;
use crate::geometry::SceneGeometry;

#[derive(Clone, Debug, Default)]
pub struct LightSampler {
    cdf: Vec<f32>,
    prob: Vec<f32>,
}

impl LightSampler {
    pub fn new(lights: &[Light], geom: &SceneGeometry, scene_radius: f32) -> Self {
        let powers: Vec<f64> = lights
            .iter()
            .map(|l| l.power_lm(geom, scene_radius).max(0.0))
            .collect();
        let total: f64 = powers.iter().sum();
        let n = lights.len();
        let prob: Vec<f32> = if total > 0.0 && total.is_finite() {
            powers.iter().map(|&p| (p / total) as f32).collect()
        } else {
            vec![1.0 / n.max(1) as f32; n]
        };
        let mut cdf = Vec::with_capacity(n);
        let mut acc = 0.0f64;
        for &p in &prob {
            acc += p as f64;
            cdf.push(acc as f32);
        }
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        Self { cdf, prob }
    }

    /// Pick a light: index and its probability; None if there are no lights.
    pub fn sample(&self, u: f32) -> Option<(usize, f32)> {
        if self.cdf.is_empty() {
            return None;
        }
        let (k, p) = crate::sampling::pick_from_cdf(&self.cdf, u);
        if p > 0.0 {
            Some((k, p))
        } else {
            None
        }
    }

    pub fn pmf(&self, light: usize) -> f32 {
        self.prob.get(light).copied().unwrap_or(0.0)
    }
}
