//! The parts of `candela spectrum` beyond classic colorimetry: CIE S 026 α-opic quantities,
//! CIE 224:2017 / TM-30-20 colour rendition with its colour vector graphic, NIST CQS 9.0, and
//! the XYZ and
//! luminous efficacy by an explicitly chosen method (`--method`, `--efficacy-rule`). See
//! `docs/colour.md`.

use std::path::{Path, PathBuf};

use anyhow::Context;
use serde_json::{json, Value};

use candela::colour::alpha_opic::{alpha_opic_quantities, AlphaOpic, AlphaOpicQuantities};
use candela::colour::colorimetry::{sd_to_xyz_emissive_with, XyzMethod};
use candela::colour::cqs::{colour_quality_scale, Cqs};
use candela::colour::grid::LEN;
use candela::colour::models::xyz_to_xy;
use candela::colour::sd::Interpolation;
use candela::colour::tables::Observer;
use candela::colour::tm30::{colour_rendition, ColourRendition, Reference, N_BINS};
use candela::output::draw;
use candela::photometry::{luminous_efficacy, luminous_efficiency_trapezoid, K_M};

/// How the luminous efficacy of radiation is integrated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EfficacyRule {
    /// 683·Σ S V / Σ S over 360–830 nm (rectangle sums, candela's default).
    Sum,
    /// colour-science's `luminous_efficacy`: 683·trapz(S V) / trapz(S).
    Trapezoid,
}

/// Options of `candela spectrum` beyond `--observer` and `--json`.
#[derive(Clone, Debug, Default)]
pub struct SpectrumOptions {
    /// `--method`: also print XYZ and xy exactly as colour-science's `sd_to_XYZ` with that
    /// method.
    pub method: Option<XyzMethod>,
    /// `--efficacy-rule`: also print the luminous efficacy by that rule.
    pub efficacy_rule: Option<EfficacyRule>,
    /// `--cvg FILE.png`: write TM-30's colour vector graphic there.
    pub cvg: Option<PathBuf>,
    /// `--interpolation`: how a CSV file is resampled to 1 nm.
    pub interpolation: Interpolation,
}

/// Parses `--method`: "integration" or "astm-e308".
pub fn parse_method(s: &str) -> anyhow::Result<XyzMethod> {
    match s.trim().to_lowercase().replace('_', "-").as_str() {
        "integration" => Ok(XyzMethod::Integration),
        "astm-e308" | "astm" | "e308" => Ok(XyzMethod::AstmE308),
        _ => anyhow::bail!("unknown --method '{s}': use integration or astm-e308"),
    }
}

/// Parses `--efficacy-rule`: "sum" or "trapezoid".
pub fn parse_efficacy_rule(s: &str) -> anyhow::Result<EfficacyRule> {
    match s.trim().to_lowercase().as_str() {
        "sum" => Ok(EfficacyRule::Sum),
        "trapezoid" | "trapz" => Ok(EfficacyRule::Trapezoid),
        _ => anyhow::bail!("unknown --efficacy-rule '{s}': use sum or trapezoid"),
    }
}

fn method_name(m: XyzMethod) -> &'static str {
    match m {
        XyzMethod::Integration => "Integration",
        XyzMethod::AstmE308 => "ASTM E308",
    }
}

fn rule_name(r: EfficacyRule) -> &'static str {
    match r {
        EfficacyRule::Sum => "sum",
        EfficacyRule::Trapezoid => "trapezoid",
    }
}

/// Everything this module adds for one spectrum.
pub struct Extras {
    alpha_opic: Option<AlphaOpicQuantities>,
    rendition: Option<ColourRendition>,
    cqs: Option<Cqs>,
    method: Option<(XyzMethod, [f64; 3], [f64; 2])>,
    efficacy: Option<(EfficacyRule, f64)>,
}

impl Extras {
    /// Whether CIE 224 / TM-30 colour rendition was computed.
    pub fn has_rendition(&self) -> bool {
        self.rendition.is_some()
    }
}

/// Computes the extras for `table` (as given, not rescaled). Lights get α-opic quantities and
/// colour rendition; reflectances neither. Writes the CVG if asked (an error for a reflectance).
pub fn extras(
    table: &[f64; LEN],
    reflectance: bool,
    observer: Observer,
    opts: &SpectrumOptions,
) -> anyhow::Result<Extras> {
    let light = !reflectance;
    let alpha_opic = light
        .then(|| alpha_opic_quantities(table))
        .filter(|q| q.illuminance_lx > 0.0 && q.illuminance_lx.is_finite());
    // Only the shape matters: scale to a peak of 1 so huge or tiny inputs stay finite.
    let peak = table.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let rendition = if light {
        colour_rendition(&table.map(|v| v / peak))
    } else {
        None
    };
    let cqs = light
        .then(|| quality_scale(&table.map(|v| v / peak)))
        .flatten();
    if let Some(path) = &opts.cvg {
        let r = rendition.as_ref().with_context(|| {
            "--cvg: the colour vector graphic needs a light source with power in 380–780 nm"
        })?;
        write_cvg(path, r)?;
    }
    let method = opts.method.map(|m| {
        let xyz = sd_to_xyz_emissive_with(table, observer, m);
        (m, xyz, xyz_to_xy(xyz))
    });
    let efficacy = opts.efficacy_rule.map(|r| {
        let k = match r {
            EfficacyRule::Sum => luminous_efficacy(table),
            EfficacyRule::Trapezoid => K_M * luminous_efficiency_trapezoid(table),
        };
        (r, k)
    });
    Ok(Extras {
        alpha_opic,
        rendition,
        cqs,
        method,
        efficacy,
    })
}

/// NIST CQS 9.0 of a relative SPD, or None when it has no light in 360–780 nm (no CCT).
pub fn quality_scale(table: &[f64; LEN]) -> Option<Cqs> {
    let y = sd_to_xyz_emissive_with(table, Observer::Cie1931_2, XyzMethod::AstmE308)[1];
    (y > 0.0 && y.is_finite())
        .then(|| colour_quality_scale(table))
        .filter(|c| c.q_a.is_finite())
}

fn reference_name(r: Reference) -> String {
    match r {
        Reference::Blackbody => "blackbody".into(),
        Reference::Daylight => "CIE daylight".into(),
        Reference::Mixture { daylight_fraction } => {
            format!(
                "blackbody/daylight mixture ({:.1} % daylight)",
                100.0 * daylight_fraction
            )
        }
    }
}

/// Adds the extras' keys to the JSON report `j`.
pub fn add_json(j: &mut Value, e: &Extras) {
    if let Some(q) = &e.alpha_opic {
        let per = |v: &[f64; 5]| -> Value {
            AlphaOpic::ALL
                .iter()
                .map(|a| (a.key().to_string(), json!(v[*a as usize])))
                .collect::<serde_json::Map<_, _>>()
                .into()
        };
        j["alpha_opic"] = json!({
            "irradiance_w_m2": per(&q.irradiance_w_m2),
            "illuminance_380_780_lx": q.illuminance_lx,
            "elr_w_per_lm": per(&q.elr_w_per_lm),
            "der": per(&q.der),
            "edi_lx": per(&q.edi_lx),
            "equivalent_melanopic_lux": q.equivalent_melanopic_lux,
        });
    }
    if let Some(r) = &e.rendition {
        j["colour_rendition"] = json!({
            "rf": r.rf,
            "rg": r.rg,
            "cct_k": r.cct_k,
            "duv": r.duv,
            "reference": reference_name(r.reference),
            "rf_samples": r.rf_samples.to_vec(),
            "bins": r.bins.iter().map(|b| json!({
                "n_samples": b.n_samples,
                "chroma_shift_percent": b.chroma_shift_percent,
                "hue_shift_rad": b.hue_shift_rad,
                "fidelity": b.fidelity,
            })).collect::<Vec<_>>(),
        });
    }
    if let Some(c) = &e.cqs {
        j["cqs"] = json!({
            "method": "NIST CQS 9.0",
            "qa": c.q_a,
            "qf": c.q_f,
            "qg": c.q_g,
            "cct_k": c.cct_k,
            "reference": if c.reference_is_blackbody { "blackbody" } else { "CIE daylight" },
            "samples": c.samples.iter().map(|s| json!({
                "qa": s.q_a,
                "delta_e_ab": s.delta_e_ab,
                "delta_c_ab": s.delta_c_ab,
                "delta_e_prime_ab": s.delta_e_p_ab,
            })).collect::<Vec<_>>(),
        });
    }
    if let Some((m, xyz, xy)) = &e.method {
        j["xyz_method"] = json!({"method": method_name(*m), "xyz": xyz, "xy": xy});
    }
    if let Some((r, k)) = &e.efficacy {
        j["luminous_efficacy_rule"] = json!({"rule": rule_name(*r), "lm_per_w": k});
    }
}

/// The extras as lines of the text report, through `line(key, value)`.
pub fn add_text(line: &mut dyn FnMut(&str, String), e: &Extras) {
    if let Some((m, xyz, xy)) = &e.method {
        line(
            &format!("XYZ (sd_to_XYZ, {})", method_name(*m)),
            format!(
                "{:.6} {:.6} {:.6} ({})",
                xyz[0],
                xyz[1],
                xyz[2],
                match m {
                    XyzMethod::Integration => "100·Σ S x̄ / Σ ȳ over 360–830 nm",
                    XyzMethod::AstmE308 => "100·Σ S x̄ / Σ ȳ over 360–780 nm",
                }
            ),
        );
        line("  xy", format!("{:.6} {:.6}", xy[0], xy[1]));
    }
    if let Some((r, k)) = &e.efficacy {
        line(
            &format!("luminous efficacy ({} rule)", rule_name(*r)),
            format!(
                "{k:.6} lm/W ({})",
                match r {
                    EfficacyRule::Sum => "683·Σ S V / Σ S, 360–830 nm",
                    EfficacyRule::Trapezoid => "683·trapz(S V) / trapz(S), 360–830 nm",
                }
            ),
        );
    }
    if let Some(q) = &e.alpha_opic {
        line(
            "α-opic (CIE S 026, 380–780 nm)",
            "s-cone m-cone l-cone rhodopic melanopic".into(),
        );
        let fmt = |v: &[f64; 5], scale: f64, prec: usize| {
            v.iter()
                .map(|x| format!("{:.prec$}", x * scale))
                .collect::<Vec<_>>()
                .join(" ")
        };
        line(
            "  E_e,α (W/m²; S in W·m⁻²·nm⁻¹)",
            format!("{:.6e}", q.irradiance_w_m2[0])
                + &q.irradiance_w_m2[1..]
                    .iter()
                    .map(|x| format!(" {x:.6e}"))
                    .collect::<String>(),
        );
        line("  ELR (mW/lm)", fmt(&q.elr_w_per_lm, 1e3, 5));
        line("  D65 efficacy ratio DER", fmt(&q.der, 1.0, 5));
        line(
            "  EDI (lx; cd/m² EDL for radiance)",
            format!("{:.6e}", q.edi_lx[0])
                + &q.edi_lx[1..]
                    .iter()
                    .map(|x| format!(" {x:.6e}"))
                    .collect::<String>(),
        );
        line(
            "  E_v 380–780 nm, EML (WELL)",
            format!(
                "{:.6e} lx, {:.6e} (= m-EDI / 0.9058)",
                q.illuminance_lx, q.equivalent_melanopic_lux
            ),
        );
    }
    if let Some(r) = &e.rendition {
        line(
            "TM-30-20 / CIE 224:2017 Rf, Rg",
            format!(
                "{:.2}, {:.2} (reference: {} at {:.0} K)",
                r.rf,
                r.rg,
                reference_name(r.reference),
                r.cct_k
            ),
        );
        let row = |f: &dyn Fn(usize) -> String| -> String {
            (0..N_BINS).map(f).collect::<Vec<_>>().join(" ")
        };
        line(
            "  Rcs,h1–h16 (%)",
            row(&|j| format!("{:+.1}", r.bins[j].chroma_shift_percent)),
        );
        line(
            "  Rhs,h1–h16",
            row(&|j| format!("{:+.3}", r.bins[j].hue_shift_rad)),
        );
        line(
            "  Rf,h1–h16",
            row(&|j| format!("{:.1}", r.bins[j].fidelity)),
        );
    }
    if let Some(c) = &e.cqs {
        line(
            "CQS (NIST 9.0) Qa, Qf, Qg",
            format!(
                "{:.2}, {:.2}, {:.2} (reference: {} at {:.0} K)",
                c.q_a,
                c.q_f,
                c.q_g,
                if c.reference_is_blackbody {
                    "blackbody"
                } else {
                    "CIE daylight"
                },
                c.cct_k
            ),
        );
        line(
            "  ΔE*ab VS1–VS15",
            c.samples
                .iter()
                .map(|s| format!("{:.2}", s.delta_e_ab))
                .collect::<Vec<_>>()
                .join(" "),
        );
    }
}

/// TM-30's colour vector graphic: the reference as the unit circle, and per hue bin the test
/// source's mean a′b′ relative to the reference's, (Δa′, Δb′)/|ref| + (cos h_ref, sin h_ref),
/// joined into a polygon with an arrow from the circle. 600 × 600 px PNG.
pub fn write_cvg(path: &Path, r: &ColourRendition) -> anyhow::Result<()> {
    const SIZE: u32 = 600;
    let mut img = image::RgbImage::from_pixel(SIZE, SIZE, draw::WHITE);
    let c = SIZE as f64 / 2.0;
    let scale = SIZE as f64 * 0.32; // radius of the reference circle, px
    let px = |p: [f64; 2]| ((c + scale * p[0]) as f32, (c - scale * p[1]) as f32);
    // Grid: circles at 0.8, 1 and 1.2 of the reference chroma, and the bin boundaries.
    for (k, colour) in [
        (0.8, image::Rgb([200, 200, 200])),
        (1.0, draw::BLACK),
        (1.2, image::Rgb([200, 200, 200])),
    ] {
        draw::draw_circle(&mut img, c as i32, c as i32, (k * scale) as i32, colour);
    }
    for j in 0..N_BINS {
        let a = (22.5 * j as f64).to_radians();
        let (x0, y0) = px([0.0, 0.0]);
        let (x1, y1) = px([1.3 * a.cos(), 1.3 * a.sin()]);
        draw::draw_line(&mut img, x0, y0, x1, y1, image::Rgb([225, 225, 225]));
    }
    let pts: Vec<([f64; 2], [f64; 2])> = r
        .bins
        .iter()
        .map(|b| {
            let (ra, ta) = (b.reference_ab, b.test_ab);
            let norm = ra[0].hypot(ra[1]);
            let h = ra[1].atan2(ra[0]);
            let base = [h.cos(), h.sin()];
            (
                base,
                [
                    base[0] + (ta[0] - ra[0]) / norm,
                    base[1] + (ta[1] - ra[1]) / norm,
                ],
            )
        })
        .collect();
    let red = image::Rgb([200, 30, 30]);
    for (j, (base, test)) in pts.iter().enumerate() {
        let (bx, by) = px(*base);
        let (tx, ty) = px(*test);
        draw::draw_line(&mut img, bx, by, tx, ty, image::Rgb([60, 60, 200]));
        let (nx, ny) = px(pts[(j + 1) % pts.len()].1);
        draw::draw_line_aa(&mut img, tx as i32, ty as i32, nx as i32, ny as i32, red);
        draw::fill_rect(&mut img, tx as i32 - 2, ty as i32 - 2, 5, 5, red);
    }
    draw::draw_text(
        &mut img,
        12,
        10,
        20.0,
        &format!("TM-30-20  Rf {:.0}  Rg {:.0}", r.rf, r.rg),
        draw::BLACK,
    );
    for (k, text) in [
        format!(
            "reference (black circle): {} at {:.0} K",
            reference_name(r.reference),
            r.cct_k
        ),
        format!("test source (red), Duv {:+.4}", r.duv),
    ]
    .iter()
    .enumerate()
    {
        let y = SIZE as i32 - 50 + 22 * k as i32;
        draw::draw_text(&mut img, 12, y, 14.0, text, draw::DARK_GREY);
    }
    candela::output::write_rgb_png(path, &img)
        .with_context(|| format!("writing the colour vector graphic {}", path.display()))?;
    Ok(())
}
