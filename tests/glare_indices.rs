//! The glare formulas against hand computations, the Guth position index against its
//! published table, and the calibration of the 95 % intervals propagated from pixel noise.

mod common;
use candela::glare::{
    angular_fisheye, evaluate, evaluate_uncertain, position_index, GlareImage, GlareOptions,
    GlareResult, UncertainOptions,
};

/// An image of two "pixels": a background pixel on the line of sight whose solid angle is π
/// (so that it gives the vertical illuminance of a uniform hemisphere of its luminance) and
/// a source pixel 30° straight above the line of sight.
fn one_source(background: f64, source: f64, omega: f64) -> GlareImage {
    let s = 30f64.to_radians();
    GlareImage {
        width: 2,
        height: 1,
        luminance_cd_m2: vec![background, source],
        stderr_cd_m2: None,
        direction: vec![[0.0, 0.0, 1.0], [0.0, s.sin(), s.cos()]],
        solid_angle_sr: vec![std::f64::consts::PI, omega],
        inside: vec![true, true],
        view_dir: [0.0, 0.0, 1.0],
        up: [0.0, 1.0, 0.0],
    }
}

#[test]
fn one_source_on_a_uniform_background_by_hand() {
    // L_b = 100 cd/m² over ω = π, source L = 20 000 cd/m², ω = 0.01 sr at σ = 30°, τ = 0:
    // E_v = 100π + 20 000·cos 30°·0.01 = 314.159 + 173.205 = 487.364 lx, E_dir = 173.205 lx,
    // L_b = (E_v − E_dir)/π = 100 cd/m²;
    // P = exp((35.2 − 1.22)·0.030 + 21·10⁻⁵·900) = exp(1.2084) = 3.34812;
    // DGP = 5.87·10⁻⁵·487.364 + 0.092·log10(1 + 20 000²·0.01/(487.364^1.87·3.34812²)) + 0.159
    //     = 0.246429;
    // UGR = 8 log10(0.25/100 · 20 000²·0.01/3.34812²) = 23.6032;
    // DGI = 10 log10(0.478·20 000^1.6·(0.01/P²)^0.8/(100 + 0.07·√0.01·20 000)) = 17.4118;
    // CGI = 8 log10(2(1 + 173.205/500)/487.364 · 20 000²·0.01/P²) = 26.3585;
    // L_a = (100π + 200)/(π + 0.01) = 163.143, DGR = 0.5·20 000·(0.204 + 1.52·0.01^0.2
    //     − 0.075)/(P·L_a^0.44) = 233.044, VCP = 50 erf((6.374 − 1.3227 ln DGR)/√2) + 50
    //     = 20.148.
    let r = evaluate(&one_source(100.0, 20_000.0, 0.01), &GlareOptions::default()).unwrap();
    assert_eq!(r.sources.len(), 1);
    let close = |a: f64, b: f64, tol: f64, what: &str| {
        assert!((a - b).abs() <= tol, "{what}: {a} vs {b}");
    };
    close(r.ev_lx, 487.364_346, 1e-5, "Ev");
    close(r.ev_direct_lx, 173.205_081, 1e-5, "Edir");
    close(r.background_cd_m2, 100.0, 1e-9, "Lb");
    close(r.sources[0].position_index, 3.348_123, 1e-5, "P");
    close(r.dgp, 0.246_429_08, 1e-7, "DGP");
    close(r.ugr, 23.603_177, 1e-5, "UGR");
    close(r.dgi, 17.411_823, 1e-5, "DGI");
    close(r.cgi, 26.358_486, 1e-5, "CGI");
    close(r.dgr, 233.043_815, 1e-4, "DGR");
    close(r.vcp, 20.148_26, 1e-3, "VCP");
    // Below the threshold the source is background: no sources, evalglare's conventions.
    let r = evaluate(&one_source(100.0, 1500.0, 0.01), &GlareOptions::default()).unwrap();
    assert!(r.sources.is_empty());
    assert_eq!((r.ugr, r.dgi, r.cgi, r.vcp), (0.0, 0.0, 0.0, 100.0));
    close(
        r.dgp,
        5.87e-5 * r.ev_lx + 0.159,
        1e-12,
        "DGP without sources",
    );
}

#[test]
fn low_light_correction_below_1000_lx() {
    let img = one_source(100.0, 20_000.0, 0.01);
    let plain = evaluate(&img, &GlareOptions::default()).unwrap();
    let o = GlareOptions {
        low_light_correction: true,
        ..Default::default()
    };
    let corrected = evaluate(&img, &o).unwrap();
    // e^(0.024·487.364 − 4)/(1 + e^(…)) = e^7.6967/(1 + e^7.6967) = 0.999546.
    let f = corrected.dgp / plain.dgp;
    assert!((f - 0.999_546).abs() < 1e-6, "{f}");
}

#[test]
fn guth_position_index_against_its_table() {
    // The Luckiesh–Guth table (CIE 117, IES handbook) for a source straight above the line of
    // sight (T/R = 0) at H/R = 0.1 … 1.0; the handbook's formula is a fit to it, within 3 %.
    let table = [1.26, 1.53, 1.90, 2.35, 2.86, 3.50, 4.20, 5.00, 6.00, 7.00];
    let (view, up) = ([0.0, 0.0, 1.0], [0.0, 1.0, 0.0]);
    for (k, &p) in table.iter().enumerate() {
        let hr = (k + 1) as f64 / 10.0;
        let d = [0.0, hr, 1.0];
        let got = position_index(d, view, up);
        assert!((got / p - 1.0).abs() < 0.035, "H/R {hr}: {got} vs {p}");
    }
    // On the line of sight P = 1; far off it is capped at 16.
    assert!((position_index(view, view, up) - 1.0).abs() < 1e-12);
    assert_eq!(position_index([0.0, 1.0, 0.05], view, up), 16.0);
    // Lateral, σ = 30°, τ = 90°: exp((35.2 − 28.70 − 1.22e⁻²⁰)·0.030 + (21 + 24.00 − 24.00)
    // ·10⁻⁵·900) = 1.46814.
    let s = 30f64.to_radians();
    let lateral = position_index([s.sin(), 0.0, s.cos()], view, up);
    assert!((lateral - 1.468_141).abs() < 1e-5, "{lateral}");
    // Below the line of sight (Iwata & Osterhaus), σ = 30° straight down (τ = 180°):
    // β = atan(tan 30°·√1.3225) = 33.5823°, P = exp(6.49·10⁻³β + 21·10⁻⁵β²) = 1.57583.
    let below = position_index([0.0, -s.sin(), s.cos()], view, up);
    assert!((below - 1.575_828).abs() < 1e-5, "{below}");
}

/// A 48 × 48 angular fisheye with a uniform background and a bright disc.
fn disc_image(background: f64, source: f64, rel_se: f64) -> GlareImage {
    let (w, h) = (48, 48);
    let (direction, solid_angle_sr, inside) = angular_fisheye(w, h, 180.0, 180.0);
    // Up and to the right of the line of sight (about 25° up, 15° right), at the corner of
    // four pixels, so that the disc's L·ω-weighted centre lies mid-pixel and noise does not
    // move it across a pixel edge (the position index is taken at the truncated centre, as
    // evalglare does; a centre on an edge makes it jump, see docs/glare.md).
    let centre = common::pixel_corner_direction(&direction, w, 30, 14);
    let cos_r = 12f64.to_radians().cos();
    let luminance_cd_m2: Vec<f64> = direction
        .iter()
        .map(|d| {
            let c = d[0] * centre[0] + d[1] * centre[1] + d[2] * centre[2];
            if c >= cos_r {
                source
            } else {
                background
            }
        })
        .collect();
    let stderr_cd_m2 = Some(luminance_cd_m2.iter().map(|l| rel_se * l).collect());
    GlareImage {
        width: w,
        height: h,
        luminance_cd_m2,
        stderr_cd_m2,
        direction,
        solid_angle_sr,
        inside,
        view_dir: [0.0, 0.0, 1.0],
        up: [0.0, 1.0, 0.0],
    }
}

/// A standard normal deviate (Box–Muller on a 64-bit hash), independent of the library's.
/// `img` with each pixel moved by its standard error times a standard normal number of
/// stream `t`.
fn perturbed(img: &GlareImage, t: u64) -> GlareImage {
    let mut out = img.clone();
    let se = img.stderr_cd_m2.as_ref().unwrap();
    for (i, l) in out.luminance_cd_m2.iter_mut().enumerate() {
        *l += se[i] * common::gauss(t, i as u64);
    }
    out
}

#[test]
fn dgp_interval_covers_the_truth_95_percent_of_the_time() {
    // Truth: the noise-free image. Each trial adds Gaussian noise of the stated standard error
    // (15 % of each pixel) and asks for the DGP interval from 24 draws; over 1000 trials a
    // calibrated 95 % interval covers the truth 950 ± 7 times (binomial sd), 930–970 allowed.
    let truth_img = disc_image(300.0, 15_000.0, 0.15);
    let opt = GlareOptions::default();
    let truth = evaluate(&truth_img, &opt).unwrap();
    assert_eq!(truth.sources.len(), 1);
    let trials = 1000;
    let (mut dgp_hits, mut ugr_hits, mut width) = (0, 0, 0.0);
    for t in 0..trials {
        let img = perturbed(&truth_img, t);
        let u = UncertainOptions {
            draws: 24,
            seed: 1000 + t,
            ..Default::default()
        };
        let r = evaluate_uncertain(&img, &opt, &u).unwrap();
        dgp_hits += r.dgp.contains(truth.dgp) as u32;
        ugr_hits += r.ugr.contains(truth.ugr) as u32;
        width += r.dgp.half_width / trials as f64;
    }
    println!(
        "DGP {:.4}: covered {dgp_hits}/{trials}, mean half-width {width:.5}; UGR {:.3}: covered \
         {ugr_hits}/{trials}",
        truth.dgp, truth.ugr
    );
    assert!(
        (930..=970).contains(&dgp_hits),
        "DGP coverage {dgp_hits}/{trials}"
    );
    assert!(
        (930..=970).contains(&ugr_hits),
        "UGR coverage {ugr_hits}/{trials}"
    );
    assert!(width > 0.0);
}

#[test]
fn a_noisy_background_near_the_threshold_is_flagged() {
    let opt = GlareOptions::default();
    let u = UncertainOptions::default();
    // Background 1800 cd/m² ± 15 %: pixels cross the 2000 cd/m² threshold from draw to draw.
    let noisy = evaluate_uncertain(&disc_image(1800.0, 15_000.0, 0.15), &opt, &u).unwrap();
    assert!(!noisy.trustworthy, "{:?}", noisy.warnings);
    assert!(noisy.membership_flip > u.max_membership_flip);
    // The same scene with 0.2 % noise is trusted, with a narrow interval.
    let clean = evaluate_uncertain(&disc_image(300.0, 15_000.0, 0.002), &opt, &u).unwrap();
    assert!(clean.trustworthy, "{:?}", clean.warnings);
    assert!(clean.dgp.half_width < 1e-3 && clean.dgp.half_width > 0.0);
    // Without standard errors the intervals have no width.
    let mut exact = disc_image(300.0, 15_000.0, 0.0);
    exact.stderr_cd_m2 = None;
    let e = evaluate_uncertain(&exact, &opt, &u).unwrap();
    assert_eq!(e.dgp.half_width, 0.0);
    assert!(e.trustworthy);
}

/// A 48 × 48 fisheye with a 30 cd/m² background (0.5 % noise) and one source pixel of
/// 40 000 cd/m² whose standard error is the share `r` of it (a pixel hit by few samples),
/// threshold 100 cd/m²
/// and no peak split, so that no pixel crosses the threshold between trials and only the
/// source's luminance is noisy.
fn noisy_source_image(r: f64) -> (GlareImage, GlareOptions) {
    let (w, h) = (48, 48);
    let (direction, solid_angle_sr, inside) = angular_fisheye(w, h, 180.0, 180.0);
    let source = 14 * w + 30;
    let luminance_cd_m2: Vec<f64> = (0..w * h)
        .map(|i| if i == source { 40_000.0 } else { 30.0 })
        .collect();
    let stderr_cd_m2 = Some(
        luminance_cd_m2
            .iter()
            .map(|&l| if l > 100.0 { r * l } else { 0.005 * l })
            .collect(),
    );
    let opt = GlareOptions {
        detect: candela::glare::DetectOptions {
            threshold: candela::glare::Threshold::Fixed {
                luminance_cd_m2: 100.0,
            },
            peak_limit_cd_m2: None,
            ..Default::default()
        },
        ..Default::default()
    };
    let img = GlareImage {
        width: w,
        height: h,
        luminance_cd_m2,
        stderr_cd_m2,
        direction,
        solid_angle_sr,
        inside,
        view_dir: [0.0, 0.0, 1.0],
        up: [0.0, 1.0, 0.0],
    };
    (img, opt)
}

/// Per index (UGR, DGI): Σ and Σ² of the plain value's error and of the estimate's, and the
/// number of intervals covering the noise-free value, over `trials` noisy copies of the image
/// of [`noisy_source_image`] with relative error `r`.
fn noisy_source_trials(r: f64, trials: u64) -> ([[f64; 4]; 2], [u32; 2], GlareResult) {
    let (truth_img, opt) = noisy_source_image(r);
    let truth = evaluate(&truth_img, &opt).unwrap();
    assert_eq!(truth.sources.len(), 1);
    let (mut sums, mut hits) = ([[0.0f64; 4]; 2], [0u32; 2]);
    for t in 0..trials {
        let img = perturbed(&truth_img, 7_000 + t);
        let u = UncertainOptions {
            draws: 8,
            seed: 5000 + t,
            ..Default::default()
        };
        let g = evaluate_uncertain(&img, &opt, &u).unwrap();
        assert_eq!(g.result.sources.len(), 1);
        for (k, (i, tv)) in [(&g.ugr, truth.ugr), (&g.dgi, truth.dgi)]
            .into_iter()
            .enumerate()
        {
            let (e, c) = (i.value - tv, i.estimate - tv);
            let s = &mut sums[k];
            s[0] += e;
            s[1] += e * e;
            s[2] += c;
            s[3] += c * c;
            hits[k] += i.contains(tv) as u32;
        }
    }
    (sums, hits, truth)
}

/// UGR = 8 log10(0.25/L_b · L² ω/P²) of one source is 16 log10 L + const, and with
/// L̂ = L(1 + r ε), E[ln L̂] = ln L − r²/2 − 3r⁴/4 − …: the plain UGR of a source pixel with
/// 20 % noise is low by 16/ln 10 · (r²/2 + 3r⁴/4) = 0.147 (DGI, concave in L too, by 0.076
/// from the same second-order expansion), a tenth of its standard deviation. Over 2000 trials
/// (8 draws each) the plain value's mean error must show that bias (to ±3 standard errors of
/// the mean) and the bias-corrected estimate's must be zero within 3 standard errors. At 20 %
/// the index is skewed enough (a logarithm of L̂) that a symmetric interval covers about 92 %;
/// at 5 % the intervals must cover the noise-free UGR and DGI in 930–970 of 1000 trials.
#[test]
fn the_estimate_removes_the_bias_of_noisy_source_pixels() {
    let (r, trials) = (0.2f64, 2000u64);
    let (sums, hits, truth) = noisy_source_trials(r, trials);
    // E[ln(1 + rε)] = −r²/2 − 3r⁴/4 − … for a standard normal ε.
    let predicted_ugr = -16.0 / std::f64::consts::LN_10 * (r * r / 2.0 + 0.75 * r.powi(4));
    // DGI of one source, 10 log10 g(L) with g = 0.478 L^1.6 Ω^0.8/(L_b + 0.07 ω^0.5 L): its
    // second-order bias ½ (d²/dL² 10 log10 g) r² L², by central differences.
    let s = &truth.sources[0];
    let dgi_of = |l: f64| {
        let wm = s.solid_angle_sr / (s.position_index * s.position_index);
        10.0 * (0.478 * l.powf(1.6) * wm.powf(0.8)
            / (truth.background_cd_m2 + 0.07 * s.solid_angle_sr.sqrt() * l))
            .log10()
    };
    let (l0, dl) = (s.luminance_cd_m2, 1.0);
    let d2 = (dgi_of(l0 + dl) - 2.0 * dgi_of(l0) + dgi_of(l0 - dl)) / (dl * dl);
    let predicted_dgi = 0.5 * d2 * (r * l0).powi(2);
    let n = trials as f64;
    let mean_se = |s: f64, s2: f64| (s / n, ((s2 / n - (s / n).powi(2)) / n).sqrt());
    for (k, (name, predicted)) in [("UGR", predicted_ugr), ("DGI", predicted_dgi)]
        .into_iter()
        .enumerate()
    {
        let (m, se) = mean_se(sums[k][0], sums[k][1]);
        let (mc, sec) = mean_se(sums[k][2], sums[k][3]);
        println!(
            "{name}: plain error {m:+.4} ± {se:.4} (predicted {predicted:+.4}), estimate \
             {mc:+.4} ± {sec:.4}, covered {}/{trials}",
            hits[k]
        );
        assert!(
            (m - predicted).abs() <= 3.0 * se,
            "{name}: plain error {m} ± {se}, predicted {predicted}"
        );
        assert!(
            mc.abs() <= 3.0 * sec,
            "{name}: estimate's error {mc} ± {sec}"
        );
    }
    // 950 ± 6.9 (binomial sd) for a calibrated interval.
    let (_, hits, _) = noisy_source_trials(0.05, 1000);
    println!("at 5 %: UGR covered {}/1000, DGI {}/1000", hits[0], hits[1]);
    assert!((930..=970).contains(&hits[0]), "UGR {}/1000", hits[0]);
    assert!((930..=970).contains(&hits[1]), "DGI {}/1000", hits[1]);
}

/// A converged source with a few isolated background pixels just below the threshold (a wall
/// in indirect sunlight at 1900 ± 200 cd/m²): in most draws one or more of them crosses it and
/// becomes a source of one pixel whose share of Σ L² ω / P² is negligible. The image is
/// trustworthy: the count of significant sources does not change, and its DGP and UGR
/// intervals are narrow. (Counting every source flagged it in most draws.)
#[test]
fn isolated_pixels_crossing_the_threshold_do_not_flag_the_image() {
    let mut img = disc_image(300.0, 15_000.0, 0.002);
    let w = img.width;
    let se = img.stderr_cd_m2.as_mut().unwrap();
    for (c, r) in [(8, 30), (10, 40), (20, 38), (36, 40), (40, 30), (6, 20)] {
        img.luminance_cd_m2[r * w + c] = 1900.0;
        se[r * w + c] = 200.0;
    }
    let opt = GlareOptions::default();
    let g = evaluate_uncertain(&img, &opt, &UncertainOptions::default()).unwrap();
    assert_eq!(g.result.sources.len(), 1);
    // Draws with stray one-pixel sources happen (the plain count changes)...
    let u = UncertainOptions::default();
    let mut plain_changes = 0;
    for d in 0..u.draws as u64 {
        let mut lum = img.luminance_cd_m2.clone();
        let se = img.stderr_cd_m2.as_ref().unwrap();
        for (i, l) in lum.iter_mut().enumerate() {
            *l += se[i] * common::gauss(90_000 + d, i as u64);
        }
        let r = candela::glare::evaluate_luminance(&img, &lum, &opt);
        plain_changes += (r.sources.len() != 1) as u32;
    }
    assert!(
        plain_changes as f64 > 0.5 * u.draws as f64,
        "{plain_changes}"
    );
    // ...but the significant sources are the same and the image is trusted.
    assert_eq!(g.source_count_changes, 0.0);
    assert!(g.trustworthy, "{:?}", g.warnings);
}
