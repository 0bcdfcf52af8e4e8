//! Second-order bias correction of the glare indices of a noisy image.
//!
//! The indices are non-linear in the sources' mean luminances: UGR and CGI grow with
//! Σ L_s² ω_s / P², DGI with Σ L_s^1.6 …/(L_b + 0.07 ω^0.5 L_s), DGP with Σ L_s² …, and each
//! takes a logarithm of its sum. With L̂_s = L_s + ε (variance v_s), E[L̂_s²] = L_s² + v_s and
//! E[log Ŝ] ≈ log S − var(Ŝ)/(2S²), so an index F of a noisy image is biased by
//! b ≈ ½ Σ_jk ∂²F/∂x_j∂x_k · cov(x_j, x_k) over its noisy inputs x. The inputs, for the
//! detected sources held fixed, are each source's mean luminance L_s = Σ L ω / Σ ω (variance
//! Σ ω² se² / ω_s², independent between sources), the vertical illuminance of the other
//! pixels E_rest = Σ L cosθ ω and their mean luminance (for the `Mean` background), which
//! share pixels and so covary. A source's direct illuminance moves with its luminance
//! (E_dir,s = κ_s L_s). The position indices and the membership of the sources are held
//! fixed: they are discontinuous in the pixels and have no such correction.
//!
//! The second derivatives are taken by central differences with the step one standard
//! deviation of the input (at most half its value): b_j = ½ (F(x + σ_j) + F(x − σ_j)) − F(x),
//! exact for a quadratic and ½ F_jj σ_j² as σ → 0, so the correction vanishes with the noise.

use super::image::{dot, GlareImage};
use super::indices::{cgi, dgi, dgp, ugr, Background, GlareOptions, GlareResult, SourceTerm};
use super::sources::Detection;

/// The noisy inputs of the indices of one detected image.
struct Inputs {
    /// Per source: luminance (cd/m²), solid angle (sr), position index, κ = E_dir,s / L_s (sr).
    sources: Vec<(f64, f64, f64, f64)>,
    /// Σ L cosθ ω over the valid pixels outside the sources, lx.
    e_rest: f64,
    /// Mean luminance of those pixels, cd/m², and their solid angle, sr.
    l_rest: f64,
    w_rest: f64,
    /// Variances: of each source's luminance, of E_rest, of l_rest, and their covariance.
    var_sources: Vec<f64>,
    var_e: f64,
    var_l: f64,
    cov_el: f64,
}

/// The indices the correction applies to, in this order.
pub(crate) const CORRECTED: usize = 4;

/// DGP, DGI, UGR and CGI of the inputs `x` (source luminances, then E_rest, then l_rest).
fn indices(inp: &Inputs, x: &[f64], opt: &GlareOptions) -> [f64; CORRECTED] {
    let n = inp.sources.len();
    let terms: Vec<SourceTerm> = inp
        .sources
        .iter()
        .zip(x)
        .map(|(&(_, w, p, _), &l)| SourceTerm {
            luminance_cd_m2: l,
            solid_angle_sr: w,
            position_index: p,
        })
        .collect();
    let e_dir: f64 = inp.sources.iter().zip(x).map(|(s, &l)| s.3 * l).sum();
    let (e_rest, l_rest) = (x[n], x[n + 1]);
    let ev = e_rest + e_dir;
    let background = match opt.background {
        Background::Cie => e_rest / std::f64::consts::PI,
        Background::EvOverPi => ev / std::f64::consts::PI,
        Background::Mean => {
            if inp.w_rest > 0.0 {
                l_rest
            } else {
                let w: f64 = inp.sources.iter().map(|s| s.1).sum();
                terms
                    .iter()
                    .map(|t| t.luminance_cd_m2 * t.solid_angle_sr)
                    .sum::<f64>()
                    / w
            }
        }
    };
    let u = if terms.is_empty() {
        0.0
    } else {
        ugr(background, &terms)
    };
    [
        dgp(ev, &terms, &opt.dgp, opt.low_light_correction),
        dgi(background, &terms),
        u,
        cgi(ev, e_dir, &terms),
    ]
}

fn inputs(img: &GlareImage, lum: &[f64], se: &[f64], det: &Detection) -> Inputs {
    let (view, _) = img.frame();
    let mut in_source = vec![false; img.len()];
    let mut sources = Vec::with_capacity(det.sources.len());
    let mut var_sources = Vec::with_capacity(det.sources.len());
    for s in &det.sources {
        let mut v = 0.0;
        for &i in &s.pixels {
            in_source[i] = true;
            v += (img.solid_angle_sr[i] * se[i]).powi(2);
        }
        let w = s.solid_angle_sr;
        let l = s.luminance_cd_m2;
        let kappa = if l > 0.0 { s.illuminance_lx / l } else { 0.0 };
        sources.push((l, w, 0.0, kappa));
        var_sources.push(if w > 0.0 { v / (w * w) } else { 0.0 });
    }
    let (mut e_rest, mut lw, mut w_rest) = (0.0, 0.0, 0.0);
    let (mut var_e, mut var_lw, mut cov) = (0.0, 0.0, 0.0);
    for i in (0..img.len()).filter(|&i| img.valid(i) && !in_source[i]) {
        let (w, c) = (img.solid_angle_sr[i], dot(view, img.direction[i]));
        e_rest += lum[i] * c * w;
        lw += lum[i] * w;
        w_rest += w;
        let s2 = (w * se[i]).powi(2);
        var_e += c * c * s2;
        var_lw += s2;
        cov += c * s2;
    }
    let (l_rest, var_l, cov_el) = if w_rest > 0.0 {
        (lw / w_rest, var_lw / (w_rest * w_rest), cov / w_rest)
    } else {
        (0.0, 0.0, 0.0)
    };
    Inputs {
        sources,
        e_rest,
        l_rest,
        w_rest,
        var_sources,
        var_e,
        var_l,
        cov_el,
    }
}

/// The second-order bias b of DGP, DGI, UGR and CGI of the image with luminances `lum`
/// (cd/m²) and per-pixel standard errors `se` (cd/m²), whose detection is `det` and result
/// `r`: the index less b is unbiased to second order in the noise. Zero without sources.
pub(crate) fn bias(
    img: &GlareImage,
    lum: &[f64],
    se: &[f64],
    det: &Detection,
    r: &GlareResult,
    opt: &GlareOptions,
) -> [f64; CORRECTED] {
    if det.sources.is_empty() {
        return [0.0; CORRECTED];
    }
    let mut inp = inputs(img, lum, se, det);
    for (s, rep) in inp.sources.iter_mut().zip(&r.sources) {
        s.2 = rep.position_index;
    }
    let n = inp.sources.len();
    let mut x: Vec<f64> = inp.sources.iter().map(|s| s.0).collect();
    x.push(inp.e_rest);
    x.push(inp.l_rest);
    let f0 = indices(&inp, &x, opt);
    let mut b = [0.0; CORRECTED];
    // Step along input j: one standard deviation, at most half the input's value (the
    // formulas take logarithms and powers of positive luminances).
    let step = |x: f64, var: f64| var.sqrt().min(0.5 * x.abs());
    let mut second = |x: &mut Vec<f64>, j: usize, h: f64, var: f64| {
        if h.is_nan() || h <= 0.0 {
            return;
        }
        let x0 = x[j];
        x[j] = x0 + h;
        let fp = indices(&inp, x, opt);
        x[j] = x0 - h;
        let fm = indices(&inp, x, opt);
        x[j] = x0;
        for k in 0..CORRECTED {
            b[k] += 0.5 * (fp[k] - 2.0 * f0[k] + fm[k]) / (h * h) * var;
        }
    };
    for j in 0..n {
        let v = inp.var_sources[j];
        let h = step(x[j], v);
        second(&mut x, j, h, v);
    }
    let (he, hl) = (step(inp.e_rest, inp.var_e), step(inp.l_rest, inp.var_l));
    second(&mut x, n, he, inp.var_e);
    second(&mut x, n + 1, hl, inp.var_l);
    // The cross term of E_rest and the rest's mean luminance (only the `Mean` background
    // depends on both).
    if he > 0.0 && hl > 0.0 && inp.cov_el != 0.0 {
        let at = |x: &mut Vec<f64>, de: f64, dl: f64| {
            let (e0, l0) = (x[n], x[n + 1]);
            x[n] = e0 + de;
            x[n + 1] = l0 + dl;
            let f = indices(&inp, x, opt);
            x[n] = e0;
            x[n + 1] = l0;
            f
        };
        let (pp, pm, mp, mm) = (
            at(&mut x, he, hl),
            at(&mut x, he, -hl),
            at(&mut x, -he, hl),
            at(&mut x, -he, -hl),
        );
        for k in 0..CORRECTED {
            b[k] += (pp[k] - pm[k] - mp[k] + mm[k]) / (4.0 * he * hl) * inp.cov_el;
        }
    }
    // An index at a cap or a convention (DGP capped at 1, UGR −99 without background) gives
    // non-finite or meaningless differences: no correction there.
    for (k, v) in b.iter_mut().enumerate() {
        if !v.is_finite() || !f0[k].is_finite() {
            *v = 0.0;
        }
    }
    b
}
