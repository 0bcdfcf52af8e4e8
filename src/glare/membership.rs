//! The glare threshold's selection of noisy pixels.
//!
//! A pixel is a glare pixel when its luminance is above the threshold, a step function of the
//! pixel that no smooth propagation of the standard errors follows: a pixel within a few
//! standard errors of the threshold may be on the wrong side of it, and where more such pixels
//! lie below the threshold than above (a window's frame, a sky's gradient, a luminaire's edge)
//! the noisy image's sources hold too many of them on average. UGR and DGI feel it most: a
//! pixel that joins a source raises Σ L² ω / P² and lowers L_b = (E_v − E_dir)/π.
//!
//! For each valid pixel within [`BAND`] standard errors of the threshold this module takes
//! the probability q = Φ(−|L − T|/se) that noise of its standard error puts it on the other
//! side, and the change Δ of each index if it were there: out of its source, or into the
//! source whose glare pixel is nearest within half the search angle (else a source of its
//! own), the other pixels, E_v and the sources' position indices held fixed. From them:
//! - the expected shift Σ q Δ, the change of the index's expectation when each such pixel
//!   takes its side with the probability its standard error gives (what the draws of
//!   [`super::interval`] add on average, without their noise);
//! - the reach Σ q |Δ|, how far those pixels could move the index if their errors went the
//!   same way.
//!
//! The shift is no estimate of the bias: the bias comes from the true luminances' density
//! about the threshold, which the noisy pixels do not show (measured in docs/glare.md). The
//! reach is the scale of what the pixels in doubt can do to the index, and an index whose
//! reach passes its 95 % half-width is not trusted ([`super::interval`]). A pixel with no standard error has q = 0 and takes no
//! part: a converged image is not affected.

use super::image::{dot, GlareImage};
use super::indices::{
    cgi, dgi, dgp, dgr, position_index, ugr, vcp, Background, GlareOptions, GlareResult, SourceTerm,
};
use super::sources::Detection;
use crate::sampling::special::erfc;
use std::collections::HashMap;

/// Pixels farther than this many standard errors from the threshold are taken as certain
/// (q < 0.0014).
pub const BAND: f64 = 3.0;

/// The indices of [`Membership::shift`] and [`Membership::reach`], in this order: DGP, DGI,
/// UGR, CGI, VCP.
pub(crate) const INDICES: usize = 5;

/// The threshold's selection of noisy pixels, for one image.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Membership {
    /// Valid pixels whose luminance is within 2 standard errors of the threshold.
    pub pixels_within_2se: usize,
    /// Their solid angle (in the sources or not) over the sources' (0 without sources).
    pub solid_angle_share_within_2se: f64,
    /// Per index (DGP, DGI, UGR, CGI, VCP): the expected shift Σ q Δ.
    pub shift: [f64; INDICES],
    /// Per index: the reach Σ q |Δ|.
    pub reach: [f64; INDICES],
}

/// One source as the indices need it: solid angle (sr), Σ L ω (cd/m²·sr), Σ L cosθ ω (lx),
/// position index.
#[derive(Clone, Copy, Debug)]
struct Agg {
    w: f64,
    lw: f64,
    e: f64,
    p: f64,
}

/// The image-wide quantities membership does not change.
struct Fixed {
    ev: f64,
    mean: f64,
    solid_angle: f64,
}

/// DGP, DGI, UGR, CGI, VCP of the sources `aggs` (sources with no solid angle left dropped).
fn indices(aggs: &[Agg], f: &Fixed, opt: &GlareOptions) -> [f64; INDICES] {
    let terms: Vec<SourceTerm> = aggs
        .iter()
        .filter(|a| a.w > 0.0)
        .map(|a| SourceTerm {
            luminance_cd_m2: a.lw / a.w,
            solid_angle_sr: a.w,
            position_index: a.p,
        })
        .collect();
    let kept = aggs.iter().filter(|a| a.w > 0.0);
    let e_dir: f64 = kept.clone().map(|a| a.e).sum();
    let (w, lw): (f64, f64) = kept.fold((0.0, 0.0), |(w, lw), a| (w + a.w, lw + a.lw));
    let background = match opt.background {
        Background::Cie => (f.ev - e_dir) / std::f64::consts::PI,
        Background::EvOverPi => f.ev / std::f64::consts::PI,
        Background::Mean => {
            if f.solid_angle == w {
                f.mean
            } else {
                (f.solid_angle * f.mean - lw) / (f.solid_angle - w)
            }
        }
    };
    let empty = terms.is_empty();
    [
        dgp(f.ev, &terms, &opt.dgp, opt.low_light_correction),
        dgi(background, &terms),
        if empty { 0.0 } else { ugr(background, &terms) },
        cgi(f.ev, e_dir, &terms),
        if empty {
            100.0
        } else {
            vcp(dgr(f.mean, &terms))
        },
    ]
}

/// The membership analysis of the image with luminances `lum` and standard errors `se`
/// (cd/m²), its detection `det` and result `r`.
pub(crate) fn membership(
    img: &GlareImage,
    lum: &[f64],
    se: &[f64],
    det: &Detection,
    r: &GlareResult,
    opt: &GlareOptions,
) -> Membership {
    let t = det.threshold_cd_m2;
    let (view, _) = img.frame();
    let up = img.position_up(opt.position_index_up);
    let near: Vec<usize> = (0..img.len())
        .filter(|&i| img.valid(i) && se[i] > 0.0 && (lum[i] - t).abs() < BAND * se[i])
        .collect();
    let mut out = Membership::default();
    if near.is_empty() {
        return out;
    }
    let mut source_of = vec![usize::MAX; img.len()];
    let mut aggs: Vec<Agg> = Vec::with_capacity(det.sources.len());
    for ((k, s), rep) in det.sources.iter().enumerate().zip(&r.sources) {
        for &i in &s.pixels {
            source_of[i] = k;
        }
        aggs.push(Agg {
            w: s.solid_angle_sr,
            lw: s.luminance_cd_m2 * s.solid_angle_sr,
            e: s.illuminance_lx,
            p: rep.position_index,
        });
    }
    let fixed = Fixed {
        ev: r.ev_lx,
        mean: r.mean_luminance_cd_m2,
        solid_angle: (0..img.len())
            .filter(|&i| img.valid(i))
            .map(|i| img.solid_angle_sr[i])
            .sum(),
    };
    let f0 = indices(&aggs, &fixed, opt);
    // The sources' pixels in a grid of cubes of side the chord of half the search angle: a
    // pixel's neighbours within that angle are in its cube's 27.
    let half = 0.5 * opt.detect.search_angle_rad;
    let (cos_half, side) = (half.cos(), 2.0 * (0.5 * half).sin());
    let key = |d: [f64; 3]| d.map(|v| (v / side).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for s in &det.sources {
        for &i in &s.pixels {
            grid.entry(key(img.direction[i])).or_default().push(i);
        }
    }
    let nearest_source = |i: usize| -> Option<usize> {
        let c = key(img.direction[i]);
        let mut best: Option<(f64, usize)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(cell) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                        continue;
                    };
                    for &j in cell {
                        let d = dot(img.direction[i], img.direction[j]);
                        if d >= cos_half && best.is_none_or(|(b, _)| d > b) {
                            best = Some((d, source_of[j]));
                        }
                    }
                }
            }
        }
        best.map(|(_, s)| s)
    };
    let total_w: f64 = aggs.iter().map(|a| a.w).sum();
    let mut trial = aggs.clone();
    for &i in &near {
        let (w, l) = (img.solid_angle_sr[i], lum[i]);
        let pixel = Agg {
            w,
            lw: l * w,
            e: l * dot(view, img.direction[i]) * w,
            p: 0.0,
        };
        let z = (lum[i] - t).abs() / se[i];
        let q = 0.5 * erfc(z / std::f64::consts::SQRT_2);
        let inside = source_of[i] != usize::MAX;
        if z < 2.0 {
            out.pixels_within_2se += 1;
            if total_w > 0.0 {
                out.solid_angle_share_within_2se += w / total_w;
            }
        }
        let f = if inside {
            let k = source_of[i];
            let a = &mut trial[k];
            a.w -= pixel.w;
            a.lw -= pixel.lw;
            a.e -= pixel.e;
            // A source losing its last pixel (rounding leaves a trace) is gone.
            if a.w <= 1e-12 * w {
                a.w = 0.0;
            }
            let f = indices(&trial, &fixed, opt);
            trial[k] = aggs[k];
            f
        } else if let Some(k) = nearest_source(i) {
            let a = &mut trial[k];
            a.w += pixel.w;
            a.lw += pixel.lw;
            a.e += pixel.e;
            let f = indices(&trial, &fixed, opt);
            trial[k] = aggs[k];
            f
        } else {
            trial.push(Agg {
                p: position_index(img.direction[i], view, up),
                ..pixel
            });
            let f = indices(&trial, &fixed, opt);
            trial.pop();
            f
        };
        for k in 0..INDICES {
            let d = f[k] - f0[k];
            if d.is_finite() {
                out.shift[k] += q * d;
                out.reach[k] += q * d.abs();
            }
        }
    }
    out
}
