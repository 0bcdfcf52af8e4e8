//! The glare threshold's selection of noisy pixels (src/glare/membership.rs): a source whose
//! rim straddles the threshold with large standard errors has UGR and DGI intervals that
//! under-cover, and the check flags them; with tiny standard errors the same image is trusted
//! and the check does nothing.

mod common;
use candela::glare::{
    angular_fisheye, evaluate, evaluate_uncertain, GlareImage, GlareOptions, UncertainOptions,
};

/// A 48 × 48 angular fisheye: a 15 000 cd/m² disc of 10° radius about 25° up and 15° right of
/// the line of sight, a rim to 11.5° at 2250 cd/m² and one to 14° at 1750 cd/m² (the
/// 2000 cd/m² threshold between them, more rim pixels below it than above), on 300 cd/m².
/// The rims' standard error is `rim_se` (cd/m²), the other pixels' 0.2 % of their luminance.
fn rimmed_disc(rim_se: f64) -> GlareImage {
    let (w, h) = (48, 48);
    let (direction, solid_angle_sr, inside) = angular_fisheye(w, h, 180.0, 180.0);
    // The corner of four pixels, so that the disc's weighted centre lies mid-pixel.
    let centre = common::pixel_corner_direction(&direction, w, 30, 14);
    let (mut luminance_cd_m2, mut stderr) = (Vec::new(), Vec::new());
    for d in &direction {
        let c = (d[0] * centre[0] + d[1] * centre[1] + d[2] * centre[2]).clamp(-1.0, 1.0);
        let a = c.acos().to_degrees();
        let (l, se) = if a <= 10.0 {
            (15_000.0, 30.0)
        } else if a <= 11.5 {
            (2250.0, rim_se)
        } else if a <= 14.0 {
            (1750.0, rim_se)
        } else {
            (300.0, 0.6)
        };
        luminance_cd_m2.push(l);
        stderr.push(se);
    }
    GlareImage {
        width: w,
        height: h,
        luminance_cd_m2,
        stderr_cd_m2: Some(stderr),
        direction,
        solid_angle_sr,
        inside,
        view_dir: [0.0, 0.0, 1.0],
        up: [0.0, 1.0, 0.0],
    }
}

/// `img`'s luminances moved by their standard errors times standard normal numbers of stream
/// `t`.
fn perturbed(img: &GlareImage, t: u64) -> Vec<f64> {
    let se = img.stderr_cd_m2.as_ref().unwrap();
    img.luminance_cd_m2
        .iter()
        .enumerate()
        .map(|(i, l)| l + se[i] * common::gauss(t, i as u64))
        .collect()
}

#[test]
fn a_rim_straddling_the_threshold_flags_ugr_and_dgi() {
    let opt = GlareOptions::default();
    let truth_img = rimmed_disc(400.0);
    let truth = evaluate(&truth_img, &opt).unwrap();
    assert_eq!(truth.sources.len(), 1);
    // Noisy copies of the noise-free image: their bias-corrected estimates (which correct the
    // sources' luminances, not their membership) are biased and their 95 % intervals cover
    // the noise-free UGR and DGI far less than 190 ± 3 of 200; the check flags most of them.
    let trials = 200;
    let (mut sums, mut hits, mut flagged) = ([[0.0f64; 2]; 2], [0u32; 2], [0u32; 2]);
    for t in 0..trials {
        let mut img = truth_img.clone();
        img.luminance_cd_m2 = perturbed(&truth_img, t);
        let u = UncertainOptions {
            draws: 16,
            seed: 500 + t,
            ..Default::default()
        };
        let g = evaluate_uncertain(&img, &opt, &u).unwrap();
        for (k, (i, tv, name)) in [(&g.ugr, truth.ugr, "UGR"), (&g.dgi, truth.dgi, "DGI")]
            .into_iter()
            .enumerate()
        {
            let e = i.estimate - tv;
            sums[k][0] += e;
            sums[k][1] += e * e;
            hits[k] += i.contains(tv) as u32;
            flagged[k] += !g.trusted(name) as u32;
        }
    }
    let n = trials as f64;
    for (k, (name, s)) in [("UGR", sums[0]), ("DGI", sums[1])].into_iter().enumerate() {
        let (m, se) = (s[0] / n, ((s[1] / n - (s[0] / n).powi(2)) / n).sqrt());
        println!(
            "{name}: estimates' mean error {m:+.4} ± {se:.4}, covered {}/{trials}, flagged \
             {}/{trials}",
            hits[k], flagged[k]
        );
        // A calibrated interval covers 190 ± 3.1 (binomial sd) of 200: these do not.
        assert!(hits[k] < 180, "{name}: covered {}/{trials}", hits[k]);
        // Measured 181 and 183 of 200 (± 4.2 binomial sd).
        assert!(flagged[k] >= 160, "{name}: flagged {}/{trials}", flagged[k]);
    }
    // A noisy copy is flagged, for UGR and DGI, with the reason.
    let u = UncertainOptions::default();
    let mut noisy = truth_img.clone();
    noisy.luminance_cd_m2 = perturbed(&truth_img, 9_999);
    let g = evaluate_uncertain(&noisy, &opt, &u).unwrap();
    println!("{:?}", g.warnings);
    for name in ["UGR", "DGI"] {
        assert!(!g.trusted(name), "{name}: {:?}", g.warnings);
        assert!(
            g.warnings.iter().any(|w| w.starts_with(name)),
            "{:?}",
            g.warnings
        );
    }
    assert!(!g.trustworthy);
    // With standard errors of 0.2 % the rim is 125 standard errors from the threshold: no
    // pixel is in doubt and the image is trusted.
    let mut clean = rimmed_disc(0.0);
    let se: Vec<f64> = clean.luminance_cd_m2.iter().map(|l| 0.002 * l).collect();
    clean.stderr_cd_m2 = Some(se);
    let g = evaluate_uncertain(&clean, &opt, &u).unwrap();
    assert!(g.trustworthy, "{:?}", g.warnings);
    assert!(g.untrusted.is_empty());
    assert_eq!(g.membership.pixels_within_2se, 0);
    assert_eq!(g.membership.shift, [0.0; 5]);
}
