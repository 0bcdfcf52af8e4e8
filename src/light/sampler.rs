//! Choosing one light (and, for an area light, one of its primitives) per shading point for
//! next-event estimation, and the probability of that choice for multiple importance sampling.
//!
//! Two strategies ([`LightSamplerKind`], the scene's `render.light_sampler`):
//! - [`LightSamplerKind::Bvh`] (default): lights at infinity (environment, distant) beside a
//!   [light BVH](super::bvh) over every emitter at a finite position, which prefers the
//!   emitters that can send the most to the shading point. Each light at infinity counts as
//!   one candidate and the whole BVH as one: with n of them, each is chosen with probability
//!   1/(n+1) and the BVH with 1/(n+1). This is robust in a daylit room lit by both the sky and
//!   luminaires: neither part is ever starved (the estimate's variance is at most about twice
//!   that of sampling the better part alone), whereas a share by power would follow the sky's
//!   "power", defined over the whole scene's bounding sphere, which says nothing about how
//!   much sky a point inside the room sees through its windows.
//! - [`LightSamplerKind::Power`]: every light in proportion to its luminous power (lm), the
//!   primitives of an area light in proportion to their area, whatever the shading point.
//!
//! [`LightSampler::pmf`] returns exactly the probability [`LightSampler::sample`] reports.

use super::bounds::{Cone, LightBounds, POINT_SPREAD};
use super::bvh::{Emitter, LightBvh};
use super::{Light, LightFlags};
use crate::geometry::SceneGeometry;
use crate::photometry::luminous_integral;
use crate::sampling::pick_from_cdf;
use glam::Vec3;

/// The largest f32 below 1, for rescaled sample numbers.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Which light selection strategy a render uses (see the module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightSamplerKind {
    #[default]
    Bvh,
    Power,
}

/// A chosen light: index into the world's lights, primitive id (the chosen primitive of an
/// area light; 0 for other lights) and the probability of the choice.
pub type LightChoice = (usize, u32, f32);

#[derive(Clone, Debug)]
pub enum LightSampler {
    Power(PowerSampler),
    Bvh(BvhSampler),
}

impl Default for LightSampler {
    fn default() -> Self {
        LightSampler::Power(PowerSampler::default())
    }
}

impl LightSampler {
    pub fn new(
        kind: LightSamplerKind,
        lights: &[Light],
        geom: &SceneGeometry,
        scene_radius: f32,
    ) -> Self {
        match kind {
            LightSamplerKind::Power => {
                LightSampler::Power(PowerSampler::new(lights, geom, scene_radius))
            }
            LightSamplerKind::Bvh => LightSampler::Bvh(BvhSampler::new(lights, geom)),
        }
    }

    pub fn kind(&self) -> LightSamplerKind {
        match self {
            LightSampler::Power(_) => LightSamplerKind::Power,
            LightSampler::Bvh(_) => LightSamplerKind::Bvh,
        }
    }

    /// Choose a light for a receiver at `p` (m) with unit normal `n` (None for a point without
    /// a surface) from `u` ∈ [0, 1); None if no light can be chosen.
    pub fn sample(&self, p: Vec3, n: Option<Vec3>, u: f32) -> Option<LightChoice> {
        match self {
            LightSampler::Power(s) => s.sample(u),
            LightSampler::Bvh(s) => s.sample(p, n, u),
        }
    }

    /// Probability that [`LightSampler::sample`] at `p`, `n` chooses `light` and, for an area
    /// light, its primitive `prim` (ignored for other lights).
    pub fn pmf(&self, p: Vec3, n: Option<Vec3>, light: usize, prim: u32) -> f32 {
        match self {
            LightSampler::Power(s) => s.pmf(light, prim),
            LightSampler::Bvh(s) => s.pmf(p, n, light, prim),
        }
    }
}

/// (light, primitive id) → an index, for the primitives of area lights.
#[derive(Clone, Debug, Default)]
struct PrimMap(Vec<(u64, u32)>);

fn prim_key(light: usize, prim: u32) -> u64 {
    (light as u64) << 32 | prim as u64
}

impl PrimMap {
    fn new(mut v: Vec<(u64, u32)>) -> Self {
        v.sort_unstable_by_key(|x| x.0);
        Self(v)
    }
    fn get(&self, light: usize, prim: u32) -> Option<u32> {
        let k = prim_key(light, prim);
        self.0
            .binary_search_by_key(&k, |x| x.0)
            .ok()
            .map(|i| self.0[i].1)
    }
}

/// Lights in proportion to their luminous power, an area light's primitives by area.
#[derive(Clone, Debug, Default)]
pub struct PowerSampler {
    cdf: Vec<f32>,
    prob: Vec<f32>,
    /// Per light: an area light's primitive ids and their area cdf.
    prims: Vec<Option<(Vec<u32>, Vec<f32>)>>,
    /// (area light, primitive) → index into its primitive list.
    prim_index: PrimMap,
}

impl PowerSampler {
    pub fn new(lights: &[Light], geom: &SceneGeometry, scene_radius: f32) -> Self {
        let powers: Vec<f64> = lights
            .iter()
            .map(|l| l.power_lm(geom, scene_radius).max(0.0))
            .collect();
        let total: f64 = powers.iter().sum();
        let n = lights.len();
        let weights: Vec<f64> = if total > 0.0 && total.is_finite() {
            powers
        } else {
            vec![1.0; n]
        };
        let cdf = crate::sampling::cdf_from_weights(&weights);
        // The probability of each light as `pick_from_cdf` reports it.
        let prob = (0..n)
            .map(|k| cdf[k] - if k == 0 { 0.0 } else { cdf[k - 1] })
            .collect();
        let mut index = Vec::new();
        let prims = lights
            .iter()
            .enumerate()
            .map(|(i, l)| match l {
                Light::Area(a) => {
                    for (k, &p) in a.prims.iter().enumerate() {
                        index.push((prim_key(i, p), k as u32));
                    }
                    Some((a.prims.clone(), a.cdf.clone()))
                }
                _ => None,
            })
            .collect();
        Self {
            cdf,
            prob,
            prims,
            prim_index: PrimMap::new(index),
        }
    }

    fn sample(&self, u: f32) -> Option<LightChoice> {
        if self.cdf.is_empty() {
            return None;
        }
        let (k, p) = pick_from_cdf(&self.cdf, u);
        if p <= 0.0 {
            return None;
        }
        match &self.prims[k] {
            None => Some((k, 0, p)),
            Some((prims, cdf)) => {
                let lo = if k == 0 { 0.0 } else { self.cdf[k - 1] };
                let u2 = ((u - lo) / p).clamp(0.0, ONE_MINUS_EPSILON);
                let (j, pp) = pick_from_cdf(cdf, u2);
                (pp > 0.0).then_some((k, prims[j], p * pp))
            }
        }
    }

    fn pmf(&self, light: usize, prim: u32) -> f32 {
        let Some(&p) = self.prob.get(light) else {
            return 0.0;
        };
        match &self.prims[light] {
            None => p,
            Some((_, cdf)) => match self.prim_index.get(light, prim) {
                Some(j) => {
                    let j = j as usize;
                    p * (cdf[j] - if j == 0 { 0.0 } else { cdf[j - 1] })
                }
                None => 0.0,
            },
        }
    }
}

/// How the BVH sampler reaches a light.
#[derive(Clone, Copy, Debug)]
enum Slot {
    /// Never chosen (emits nothing).
    Off,
    /// A light at infinity, chosen beside the BVH.
    Infinite,
    /// A point-like light: its emitter index in the BVH.
    Emitter(u32),
    /// An area light: its primitives are emitters (see `prim_emitter`).
    Area,
}

/// Lights at infinity beside a light BVH over the rest (see the module doc).
#[derive(Clone, Debug, Default)]
pub struct BvhSampler {
    bvh: LightBvh,
    infinite: Vec<u32>,
    slots: Vec<Slot>,
    prim_emitter: PrimMap,
}

/// The emitters of `lights` at a finite position, with their bounds ([`super::bounds`]).
pub fn emitters(lights: &[Light], geom: &SceneGeometry) -> Vec<Emitter> {
    let point_cos_e = POINT_SPREAD.cos();
    let point = |light: usize, at: Vec3, axes: Cone, cd: f64| Emitter {
        light: light as u32,
        prim: 0,
        bounds: LightBounds {
            lo: at,
            hi: at,
            phi: (4.0 * std::f64::consts::PI * cd) as f32,
            axes,
            cos_e: point_cos_e,
            two_sided: false,
        },
    };
    let mut out = Vec::new();
    for (i, l) in lights.iter().enumerate() {
        match l {
            Light::Point(pl) => out.push(point(
                i,
                pl.position,
                Cone::SPHERE,
                luminous_integral(&pl.intensity),
            )),
            Light::Spot(s) => out.push(point(
                i,
                s.position,
                Cone {
                    w: s.frame.n,
                    cos_theta: s.cos_outer,
                },
                luminous_integral(&s.intensity),
            )),
            Light::Goniometric(g) => {
                let (w, cos_theta) = g.emission_cone();
                out.push(point(
                    i,
                    g.position,
                    Cone { w, cos_theta },
                    g.peak_candela(),
                ))
            }
            Light::Area(a) => {
                let sides = if a.two_sided { 2.0 } else { 1.0 };
                // A textured light's primitives by their estimated mean luminance, floored at a
                // thousandth of the light's mean so that none that might emit is never chosen.
                let floor = if a.is_textured() {
                    1e-3 * a.mean_luminance(geom)
                } else {
                    0.0
                };
                for (k, &prim) in a.prims.iter().enumerate() {
                    let luminance = a.prim_mean_luminance(k).max(floor);
                    let ((lo, hi), normal) = geom.prim_bounds_normal(prim);
                    let area = geom.prim_area(prim) as f64;
                    let axes = normal.map_or(Cone::SPHERE, |w| Cone { w, cos_theta: 1.0 });
                    out.push(Emitter {
                        light: i as u32,
                        prim,
                        bounds: LightBounds {
                            lo,
                            hi,
                            phi: super::area::flux_lm(luminance, area, sides) as f32,
                            axes,
                            cos_e: 0.0,
                            two_sided: a.two_sided && normal.is_some(),
                        },
                    });
                }
            }
            Light::Distant(_) | Light::Environment(_) | Light::Sky(_) | Light::Sun(_) => {}
        }
    }
    out
}

fn at_infinity(l: &Light) -> bool {
    let f = l.flags();
    f.contains(LightFlags::INFINITE) || f.contains(LightFlags::DELTA_DIRECTION)
}

impl BvhSampler {
    pub fn new(lights: &[Light], geom: &SceneGeometry) -> Self {
        let bvh = LightBvh::build(emitters(lights, geom));
        let mut slots = vec![Slot::Off; lights.len()];
        let mut infinite = Vec::new();
        for (i, l) in lights.iter().enumerate() {
            if at_infinity(l) {
                slots[i] = Slot::Infinite;
                infinite.push(i as u32);
            }
        }
        let mut prim_emitter = Vec::new();
        for (e, em) in bvh.emitters().iter().enumerate() {
            let light = em.light as usize;
            if let Light::Area(_) = lights[light] {
                slots[light] = Slot::Area;
                prim_emitter.push((prim_key(light, em.prim), e as u32));
            } else {
                slots[light] = Slot::Emitter(e as u32);
            }
        }
        Self {
            bvh,
            infinite,
            slots,
            prim_emitter: PrimMap::new(prim_emitter),
        }
    }

    /// The BVH (for statistics and tests).
    pub fn bvh(&self) -> &LightBvh {
        &self.bvh
    }

    /// Number of candidates: each light at infinity, and the BVH if it has emitters.
    fn candidates(&self) -> usize {
        self.infinite.len() + usize::from(!self.bvh.is_empty())
    }

    fn sample(&self, p: Vec3, n: Option<Vec3>, u: f32) -> Option<LightChoice> {
        let nc = self.candidates();
        if nc == 0 {
            return None;
        }
        let x = u * nc as f32;
        let k = (x as usize).min(nc - 1);
        if k < self.infinite.len() {
            return Some((self.infinite[k] as usize, 0, 1.0 / nc as f32));
        }
        let u2 = (x - k as f32).clamp(0.0, ONE_MINUS_EPSILON);
        let (e, pe) = self.bvh.sample(p, n, u2)?;
        let em = &self.bvh.emitters()[e];
        Some((em.light as usize, em.prim, pe / nc as f32))
    }

    fn pmf(&self, p: Vec3, n: Option<Vec3>, light: usize, prim: u32) -> f32 {
        let nc = self.candidates() as f32;
        let e = match self.slots.get(light) {
            None | Some(Slot::Off) => return 0.0,
            Some(Slot::Infinite) => return 1.0 / nc,
            Some(Slot::Emitter(e)) => *e,
            Some(Slot::Area) => match self.prim_emitter.get(light, prim) {
                Some(e) => e,
                None => return 0.0,
            },
        };
        self.bvh.pmf(p, n, e as usize) / nc
    }
}
