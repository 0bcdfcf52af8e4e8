//! 95 % intervals of the glare indices from the per-pixel standard errors of a rendered image.
//!
//! The indices are not smooth functions of the pixels (a pixel that crosses the threshold
//! joins or leaves a source), so the error is propagated by simulation, a parametric
//! bootstrap: K images L + se·N(0, 1) are drawn (fixed seed), each is detected and evaluated
//! again, and the spread of each index over the draws stands for the spread of the index of
//! the rendered image about that of the noise-free image. The interval is the bias-corrected
//! estimate (the value less its second-order bias from the noise, [`super::bias`]) ±
//! t₀.₉₇₅(K − 1)·sd; the draws are corrected alike, so they centre on it. The sources'
//! membership is a step function of the pixels, which no estimate corrects: pixels near the
//! threshold must be converged for UGR and DGI to be calibrated (docs/glare.md), and an index
//! that the pixels in doubt could move by more than its half-width ([`super::membership`]) is
//! not trusted. The draws also say whether the detection itself is stable: how often the
//! number of sources changes, and how much luminous solid angle changes sides of the
//! threshold.
//!
//! Limits: pixels are taken as independent and normal (a path-traced pixel's mean over many
//! samples is, by the central limit theorem, but a firefly pixel's standard error is itself
//! poorly known); the interval holds while the index is close to linear over the noise
//! (see [`UncertainOptions::max_dgp_half_width`] and the stability checks), and it covers
//! the noise of the image only, not the bias of a biased renderer or of the DGP model.

use super::bias::{bias, CORRECTED};
use super::image::{GlareImage, ImageError};
use super::indices::{evaluate_detected, GlareOptions, GlareResult};
use super::membership::{membership, Membership};
use crate::meter::t95;
use crate::sampling::mix64;

/// Settings of the simulation and the limits past which the image is too noisy to trust.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UncertainOptions {
    /// Perturbed images drawn (K).
    pub draws: usize,
    /// Seed of the draws.
    pub seed: u64,
    /// Largest 95 % half-width of DGP for a trustworthy result (default 0.01, a fifth of the
    /// 0.05 steps between the DGP comfort classes).
    pub max_dgp_half_width: f64,
    /// Largest 95 % half-width of UGR for a trustworthy result (default 0.5, a sixth of the
    /// 3-unit steps of the UGR limits).
    pub max_ugr_half_width: f64,
    /// Largest share of the draws whose number of significant sources (see
    /// [`significant_sources`]) differs from the image's own (default 0.05).
    pub max_source_count_changes: f64,
    /// Largest mean share of the glare sources' L·ω that changes sides of the threshold in a
    /// draw (default 0.05).
    pub max_membership_flip: f64,
    /// Largest reach of the threshold's selection of noisy pixels over an index
    /// ([`Membership::reach`], how far the pixels in doubt could move it), as a multiple of
    /// the index's 95 % half-width (default 1).
    pub max_membership_reach: f64,
    /// Smallest share of the sources' solid angle in pixels within 2 standard errors of the
    /// threshold for the reach to decide trust (default 0.10): below it the draws' intervals,
    /// which re-select the sources, already hold the selection's noise.
    pub min_membership_share: f64,
}

impl Default for UncertainOptions {
    fn default() -> Self {
        UncertainOptions {
            draws: 64,
            seed: 0x0067_6c61_7265,
            max_dgp_half_width: 0.01,
            max_ugr_half_width: 0.5,
            max_source_count_changes: 0.05,
            max_membership_flip: 0.05,
            max_membership_reach: 1.0,
            min_membership_share: 0.10,
        }
    }
}

/// An index with its 95 % interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// The index of the image itself, as evalglare computes it from these pixels.
    pub value: f64,
    /// The index of the noise-free image estimated from this one: `value` less its
    /// second-order bias from the pixels' noise (DGP, DGI, UGR, CGI; the same as `value` for
    /// E_v and VCP, and without standard errors). The interval is centred on it.
    pub estimate: f64,
    /// Half-width of the 95 % interval: t₀.₉₇₅(K − 1) × the standard deviation over the draws.
    pub half_width: f64,
    /// 2.5 % and 97.5 % quantiles of the bias-corrected index over the draws (for skewed
    /// cases).
    pub quantiles: (f64, f64),
}

impl UncertainGlare {
    /// Whether index `name` ("DGP", "DGI", "UGR", "CGI", "VCP") is trusted: the image passes
    /// the image-wide checks and the index its own (each index in `untrusted` adds one
    /// warning).
    pub fn trusted(&self, name: &str) -> bool {
        !self.untrusted.contains(&name) && self.warnings.len() == self.untrusted.len()
    }
}

impl Interval {
    pub fn low(&self) -> f64 {
        self.estimate - self.half_width
    }
    pub fn high(&self) -> f64 {
        self.estimate + self.half_width
    }
    pub fn contains(&self, x: f64) -> bool {
        (self.low()..=self.high()).contains(&x)
    }
}

/// The glare result of an image with the 95 % interval of each index and the noise verdict.
#[derive(Clone, Debug, PartialEq)]
pub struct UncertainGlare {
    pub result: GlareResult,
    pub dgp: Interval,
    pub dgi: Interval,
    pub ugr: Interval,
    pub vcp: Interval,
    pub cgi: Interval,
    pub ev_lx: Interval,
    /// Share of the draws whose number of significant sources ([`significant_sources`])
    /// differs from the image's own.
    pub source_count_changes: f64,
    /// Mean over the draws of the L·ω (of the image's own luminances) of the pixels whose
    /// glare membership differs from the image's, over the L·ω of the image's glare pixels.
    pub membership_flip: f64,
    /// The threshold's selection of the image's noisy pixels (none without standard errors).
    pub membership: Membership,
    /// The indices ("DGP", "DGI", "UGR", "CGI") whose reach of the threshold's
    /// selection passes [`UncertainOptions::max_membership_reach`] times their half-width: not
    /// trusted at this noise.
    pub untrusted: Vec<&'static str>,
    /// Whether the result is within every limit of [`UncertainOptions`].
    pub trustworthy: bool,
    /// The limits that were passed, in words.
    pub warnings: Vec<String>,
}

/// Share of Σ L_s² ω_s / P_s² (the sum of UGR, CGI and, by default, DGP) a source must carry
/// to count as significant.
pub const SIGNIFICANT_SHARE: f64 = 0.01;

/// The number of sources that carry at least [`SIGNIFICANT_SHARE`] of Σ L_s² ω_s / P_s².
///
/// A noisy image has pixels just below the threshold (a wall in indirect sunlight, a
/// luminaire's edge) of which a few cross it in each draw, each a source of one pixel whose
/// share of the sum is negligible (10⁻¹¹ beside the sun's disk); counting every source would
/// flag such an image in every draw although its indices do not move.
pub fn significant_sources(r: &GlareResult) -> usize {
    let term = |s: &super::indices::SourceReport| {
        (s.luminance_cd_m2 / s.position_index).powi(2) * s.solid_angle_sr
    };
    let total: f64 = r.sources.iter().map(term).sum();
    r.sources
        .iter()
        .filter(|s| term(s) >= SIGNIFICANT_SHARE * total)
        .count()
}

/// A standard normal deviate from two 64-bit hashes (Box–Muller).
fn normal(seed: u64, draw: u64, pixel: u64) -> f64 {
    let h1 = mix64(seed ^ mix64(draw.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ pixel));
    let h2 = mix64(h1 ^ 0x5851_f42d_4c95_7f2d);
    let u1 = ((h1 >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
    let u2 = (h2 >> 11) as f64 / (1u64 << 53) as f64;
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

fn interval(value: f64, estimate: f64, draws: &mut [f64]) -> Interval {
    let k = draws.len();
    if k < 2 {
        return Interval {
            value,
            estimate,
            half_width: if k == 0 { 0.0 } else { f64::INFINITY },
            quantiles: (estimate, estimate),
        };
    }
    let mean = draws.iter().sum::<f64>() / k as f64;
    let var = draws.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (k - 1) as f64;
    draws.sort_by(|a, b| a.total_cmp(b));
    let q = |p: f64| {
        let x = p * (k - 1) as f64;
        let (i, f) = (x.floor() as usize, x - x.floor());
        draws[i] + f * (draws[(i + 1).min(k - 1)] - draws[i])
    };
    Interval {
        value,
        estimate,
        half_width: t95((k - 1) as u32) * var.sqrt(),
        quantiles: (q(0.025), q(0.975)),
    }
}

/// Evaluate `img` with `opt` and propagate its standard errors (none: zero-width intervals).
pub fn evaluate_uncertain(
    img: &GlareImage,
    opt: &GlareOptions,
    u: &UncertainOptions,
) -> Result<UncertainGlare, ImageError> {
    img.validate()?;
    let (base, base_det) = evaluate_detected(img, &img.luminance_cd_m2, opt);
    // Second-order bias of DGP, DGI, UGR, CGI (in this order) from the pixels' noise.
    let base_bias = match &img.stderr_cd_m2 {
        Some(se) => bias(img, &img.luminance_cd_m2, se, &base_det, &base, opt),
        None => [0.0; CORRECTED],
    };
    let member = match &img.stderr_cd_m2 {
        Some(se) => membership(img, &img.luminance_cd_m2, se, &base_det, &base, opt),
        None => Membership::default(),
    };
    let k = if img.stderr_cd_m2.is_some() {
        u.draws
    } else {
        0
    };
    let draws = Draws::simulate(img, opt, u.seed, &base, k);
    let (changes, flip) = draws.shares(k);
    let [mut a, mut b, mut c, mut e, mut f, mut g] = draws.series;
    let out_dgp = interval(base.dgp, base.dgp - base_bias[0], &mut a);
    let out_ugr = interval(base.ugr, base.ugr - base_bias[2], &mut c);
    let mut warnings = noise_warnings(u, &base, &out_dgp, &out_ugr, changes, flip);
    let out_dgi = interval(base.dgi, base.dgi - base_bias[1], &mut b);
    let out_cgi = interval(base.cgi, base.cgi - base_bias[3], &mut f);
    let out_vcp = interval(base.vcp, base.vcp, &mut e);
    let corrected = [&out_dgp, &out_dgi, &out_ugr, &out_cgi];
    let untrusted = selection_untrusted(u, &member, &base, corrected, &mut warnings);
    Ok(UncertainGlare {
        dgi: out_dgi,
        vcp: out_vcp,
        cgi: out_cgi,
        ev_lx: interval(base.ev_lx, base.ev_lx, &mut g),
        dgp: out_dgp,
        ugr: out_ugr,
        result: base,
        source_count_changes: changes,
        membership_flip: flip,
        membership: member,
        untrusted,
        trustworthy: warnings.is_empty(),
        warnings,
    })
}

/// Pixels of the detected sources of `r` (evaluated from `lum`), recovered from the
/// threshold: sources are exactly the valid pixels above it.
fn glare_pixels(img: &GlareImage, r: &GlareResult, lum: &[f64]) -> Vec<bool> {
    (0..img.len())
        .map(|i| img.valid(i) && lum[i] > r.threshold_cd_m2)
        .collect()
}

/// The perturbed images' indices, bias-corrected, and how their detection differed from the
/// image's own.
struct Draws {
    /// Per draw: DGP, DGI, UGR, VCP, CGI and E_v (lx).
    series: [Vec<f64>; 6],
    /// Draws whose number of significant sources differs from the image's.
    count_changes: usize,
    /// Sum over the draws of the share of the image's glare L·ω that changed sides.
    flip_sum: f64,
}

impl Draws {
    /// `k` images L + se·N(0, 1) drawn from `seed`, each detected and evaluated again.
    fn simulate(
        img: &GlareImage,
        opt: &GlareOptions,
        seed: u64,
        base: &GlareResult,
        k: usize,
    ) -> Draws {
        let base_flag = glare_pixels(img, base, &img.luminance_cd_m2);
        let base_significant = significant_sources(base);
        let lw = |i: usize| img.luminance_cd_m2[i] * img.solid_angle_sr[i];
        let base_lw: f64 = (0..img.len()).filter(|&i| base_flag[i]).map(lw).sum();
        let mut draws = Draws {
            series: Default::default(),
            count_changes: 0,
            flip_sum: 0.0,
        };
        let mut lum = img.luminance_cd_m2.clone();
        for d in 0..k {
            let se = img.stderr_cd_m2.as_ref().expect("draws only with errors");
            for i in 0..img.len() {
                lum[i] = img.luminance_cd_m2[i] + se[i] * normal(seed, d as u64, i as u64);
            }
            let (r, det) = evaluate_detected(img, &lum, opt);
            // A draw adds the image's noise again, so its bias from the noise-free image is
            // twice the image's: less 2b, the draws centre on the image's corrected value.
            let b = bias(img, &lum, se, &det, &r, opt);
            if significant_sources(&r) != base_significant {
                draws.count_changes += 1;
            }
            let flag = glare_pixels(img, &r, &lum);
            let flipped: f64 = (0..img.len())
                .filter(|&i| flag[i] != base_flag[i])
                .map(lw)
                .sum();
            draws.flip_sum += if base_lw > 0.0 {
                flipped / base_lw
            } else if flipped > 0.0 {
                1.0
            } else {
                0.0
            };
            let values = [
                r.dgp - 2.0 * b[0],
                r.dgi - 2.0 * b[1],
                r.ugr - 2.0 * b[2],
                r.vcp,
                r.cgi - 2.0 * b[3],
                r.ev_lx,
            ];
            for (s, v) in draws.series.iter_mut().zip(values) {
                s.push(v);
            }
        }
        draws
    }

    /// Share of the `k` draws whose number of significant sources changed, and the mean
    /// share of the glare L·ω that changed sides (0 and 0 without draws).
    fn shares(&self, k: usize) -> (f64, f64) {
        if k > 0 {
            (
                self.count_changes as f64 / k as f64,
                self.flip_sum / k as f64,
            )
        } else {
            (0.0, 0.0)
        }
    }
}

/// The image-wide limits of `u` that the result passes, in words: the half-widths of DGP and
/// (with sources) UGR, and the draws' changes of the `changes` and `flip` shares.
fn noise_warnings(
    u: &UncertainOptions,
    base: &GlareResult,
    out_dgp: &Interval,
    out_ugr: &Interval,
    changes: f64,
    flip: f64,
) -> Vec<String> {
    let mut warnings = Vec::new();
    if out_dgp.half_width > u.max_dgp_half_width {
        warnings.push(format!(
            "DGP ±{:.4} (95 %) is wider than ±{}",
            out_dgp.half_width, u.max_dgp_half_width
        ));
    }
    if !base.sources.is_empty() && out_ugr.half_width > u.max_ugr_half_width {
        warnings.push(format!(
            "UGR ±{:.2} (95 %) is wider than ±{}",
            out_ugr.half_width, u.max_ugr_half_width
        ));
    }
    if changes > u.max_source_count_changes {
        warnings.push(format!(
            "the number of significant glare sources changes in {:.0} % of the draws",
            100.0 * changes
        ));
    }
    if flip > u.max_membership_flip {
        warnings.push(format!(
            "{:.1} % of the sources' L·ω changes sides of the threshold per draw",
            100.0 * flip
        ));
    }
    warnings
}

/// The indices among DGI, UGR and CGI (`corrected`: the intervals of DGP, DGI, UGR, CGI)
/// that the threshold's selection of noisy pixels could move by more than
/// [`UncertainOptions::max_membership_reach`] times their half-width, when the pixels in
/// doubt hold enough of the sources' solid angle; each adds a warning.
fn selection_untrusted(
    u: &UncertainOptions,
    member: &Membership,
    base: &GlareResult,
    corrected: [&Interval; 4],
    warnings: &mut Vec<String>,
) -> Vec<&'static str> {
    let mut untrusted = Vec::new();
    for (k, (name, i)) in ["DGP", "DGI", "UGR", "CGI"]
        .into_iter()
        .zip(corrected)
        .enumerate()
    {
        let reach = member.reach[k];
        if k > 0
            && reach > u.max_membership_reach * i.half_width
            && member.solid_angle_share_within_2se >= u.min_membership_share
        {
            untrusted.push(name);
            warnings.push(format!(
                "{name}: {} pixel(s) within 2 standard errors of the {:.0} cd/m² glare threshold \
                 ({:.0} % of the sources' solid angle) could move it by {reach:.3}, more than its \
                 95 % half-width {:.3}: not trusted at this noise (more samples needed)",
                member.pixels_within_2se,
                base.threshold_cd_m2,
                100.0 * member.solid_angle_share_within_2se,
                i.half_width
            ));
        }
    }
    untrusted
}
