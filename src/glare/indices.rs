//! The glare indices of a detected image, as evalglare (Radiance 6, version 3.06) computes
//! them: the Guth position index (with the Iwata–Osterhaus form below the line of sight),
//! vertical illuminance, background luminance, DGP, DGI, UGR, VCP (through DGR) and CGI.

use super::image::{cross, dot, normalize, GlareImage, ImageError};
use super::sources::{detect, DetectOptions, Detection};
use crate::sampling::special::erf;

/// How the background luminance L_b of DGI and UGR is taken (evalglare `-q`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Background {
    /// CIE: L_b = (E_v − E_dir)/π, the indirect part of the vertical illuminance (default).
    #[default]
    Cie,
    /// The mean luminance of the valid pixels outside the glare sources (`-q 1`).
    Mean,
    /// L_b = E_v/π (`-q 2`).
    EvOverPi,
}

/// Which up vector the position index measures the angle τ from.
///
/// A Radiance view's `-vu` need not be perpendicular to `-vd` (`-vu 0 0 1` with a tilted
/// line of sight is the usual way to write it); the image's vertical is `-vu` made
/// perpendicular. evalglare takes τ from `-vu` as given, so in a tilted view its τ never
/// reaches 0° or 180°; above or below the line of sight is decided by the perpendicular up.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PositionIndexUp {
    /// The image's `up` as given (evalglare's convention; the default).
    #[default]
    AsGiven,
    /// `up` made perpendicular to the line of sight: the image's vertical, the direction
    /// Guth's table measures from.
    Perpendicular,
}

/// Coefficients of DGP = c1·E_v^a5 + c2·log10(1 + Σ L^a1 ω^a2 / (E_v^a3 P^a4)) + c3
/// (evalglare `-w a1 a2 a3 a4 a5 c1 c2 c3`; defaults from Wienold & Christoffersen 2006 as
/// evalglare rounds them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DgpCoefficients {
    pub a1: f64,
    pub a2: f64,
    pub a3: f64,
    pub a4: f64,
    pub a5: f64,
    pub c1: f64,
    pub c2: f64,
    pub c3: f64,
}

impl Default for DgpCoefficients {
    fn default() -> Self {
        DgpCoefficients {
            a1: 2.0,
            a2: 1.0,
            a3: 1.87,
            a4: 2.0,
            a5: 1.0,
            c1: 5.87e-5,
            c2: 0.092,
            c3: 0.159,
        }
    }
}

/// Options of a glare evaluation, evalglare's defaults by `Default`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GlareOptions {
    pub detect: DetectOptions,
    pub background: Background,
    pub dgp: DgpCoefficients,
    /// DGP low-light correction (evalglare `-C l+`; off by default since evalglare 2.14):
    /// below 1000 lx DGP is multiplied by e^(0.024 E_v − 4)/(1 + e^(0.024 E_v − 4)).
    pub low_light_correction: bool,
    /// The up vector of the position index (default evalglare's, `up` as given).
    pub position_index_up: PositionIndexUp,
}

/// One glare source as reported.
#[derive(Clone, Debug, PartialEq)]
pub struct SourceReport {
    /// Unit direction (image frame).
    pub direction: [f64; 3],
    /// Solid angle, sr.
    pub solid_angle_sr: f64,
    /// Mean luminance, cd/m².
    pub luminance_cd_m2: f64,
    /// Guth position index (1 on the line of sight, capped at 16).
    pub position_index: f64,
    /// Angle from the line of sight, rad.
    pub angle_from_view_rad: f64,
    /// Contribution to the vertical illuminance, lx.
    pub illuminance_lx: f64,
    /// Pixels in the source.
    pub pixel_count: usize,
}

/// The glare indices of one image.
#[derive(Clone, Debug, PartialEq)]
pub struct GlareResult {
    /// Daylight glare probability (0–1).
    pub dgp: f64,
    /// Daylight glare index (0 without sources, as evalglare).
    pub dgi: f64,
    /// CIE unified glare rating (0 without sources, as evalglare).
    pub ugr: f64,
    /// Visual comfort probability, % (100 without sources).
    pub vcp: f64,
    /// Discomfort glare rating behind VCP (0 without sources).
    pub dgr: f64,
    /// CIE glare index (0 without sources).
    pub cgi: f64,
    /// Vertical illuminance at the eye, Σ L cosθ ω over valid pixels, lx.
    pub ev_lx: f64,
    /// Its direct part, from the glare sources' pixels, lx.
    pub ev_direct_lx: f64,
    /// Background luminance used by DGI and UGR, cd/m².
    pub background_cd_m2: f64,
    /// Mean luminance of the valid pixels, cd/m².
    pub mean_luminance_cd_m2: f64,
    /// Glare-pixel threshold used, cd/m².
    pub threshold_cd_m2: f64,
    pub sources: Vec<SourceReport>,
}

/// Guth position index of direction `dir` for unit line of sight `view` and up vector `up`, as
/// evalglare computes it: above the line of sight the IES handbook's fit of
/// Guth's data,
///   P = exp((35.2 − 0.31889 τ − 1.22 e^(−2τ/9))·10⁻³ σ + (21 + 0.26667 τ − 0.002963 τ²)·10⁻⁵ σ²),
/// below it Iwata & Osterhaus (CIE 2010) in Kikuchi's coordinates,
///   β = atan(tan σ · √(1 + 0.3225 cos²τ)), P = exp(6.49·10⁻³ β + 21·10⁻⁵ β²),
/// σ the angle from the line of sight and τ the angle from `up` of the direction's projection
/// across the line of sight, both in degrees; capped at 16. `up` is used as given (it need not
/// be perpendicular to `view`; see [`PositionIndexUp`]); above or below the line of sight is
/// decided by its component across `view`.
pub fn position_index(dir: [f64; 3], view: [f64; 3], up: [f64; 3]) -> f64 {
    let deg = 180.0 / std::f64::consts::PI;
    let d = normalize(dir).unwrap_or(view);
    let up = normalize(up).unwrap_or([0.0, 1.0, 0.0]);
    let k = dot(up, view);
    let up_across = [
        up[0] - k * view[0],
        up[1] - k * view[1],
        up[2] - k * view[2],
    ];
    let cos_s = dot(view, d).clamp(-1.0, 1.0);
    let sigma_rad = cos_s.acos();
    let sigma = sigma_rad * deg;
    // Angle τ between up and the direction's component across the line of sight (90° when
    // the direction is the line of sight itself, where σ = 0 makes it irrelevant).
    let across = [
        d[0] / cos_s - view[0],
        d[1] / cos_s - view[1],
        d[2] / cos_s - view[2],
    ];
    let tau = normalize(across)
        .map(|h| dot(up, h).clamp(-1.0, 1.0).acos())
        .unwrap_or(std::f64::consts::FRAC_PI_2)
        * deg;
    let above = dot(up_across, d) >= 0.0;
    let p = if above {
        ((35.2 - 0.31889 * tau - 1.22 * (-2.0 * tau / 9.0).exp()) / 1000.0 * sigma
            + (21.0 + 0.26667 * tau - 0.002963 * tau * tau) / 100_000.0 * sigma * sigma)
            .exp()
    } else {
        let c = (tau / deg).cos();
        let beta = (sigma_rad.tan() * (1.0 + 0.3225 * c * c).sqrt()).atan() * deg;
        (6.49 / 1000.0 * beta + 21.0 / 100_000.0 * beta * beta).exp()
    };
    p.min(16.0)
}

/// A source as the formulas need it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SourceTerm {
    pub luminance_cd_m2: f64,
    pub solid_angle_sr: f64,
    pub position_index: f64,
}

/// DGP from vertical illuminance (lx) and sources, capped at 1, with the optional low-light
/// correction.
pub fn dgp(ev_lx: f64, sources: &[SourceTerm], k: &DgpCoefficients, low_light: bool) -> f64 {
    let mut v = k.c1 * ev_lx.powf(k.a5) + k.c3;
    if !sources.is_empty() {
        let s: f64 = sources
            .iter()
            .map(|s| {
                s.luminance_cd_m2.powf(k.a1) * s.solid_angle_sr.powf(k.a2)
                    / s.position_index.powf(k.a4)
            })
            .sum();
        v += k.c2 * (1.0 + s / ev_lx.powf(k.a3)).log10();
    }
    v = v.min(1.0);
    if low_light && ev_lx < 1000.0 {
        let e = (0.024 * ev_lx - 4.0).exp();
        v *= e / (1.0 + e);
    }
    v
}

/// Σ L² ω / P² over the sources (cd²·m⁻⁴·sr).
fn sum_l2w_p2(sources: &[SourceTerm]) -> f64 {
    sources
        .iter()
        .map(|s| (s.luminance_cd_m2 / s.position_index).powi(2) * s.solid_angle_sr)
        .sum()
}

/// CIE 117 UGR = 8 log10(0.25/L_b Σ L² ω / P²); 0 without sources (evalglare's convention),
/// −99 when L_b ≤ 0.
pub fn ugr(background_cd_m2: f64, sources: &[SourceTerm]) -> f64 {
    let s = sum_l2w_p2(sources);
    if background_cd_m2 <= 0.0 {
        -99.0
    } else if s == 0.0 {
        0.0
    } else {
        8.0 * (0.25 / background_cd_m2 * s).log10()
    }
}

/// DGI = 10 log10 Σ 0.478 L^1.6 (ω/P²)^0.8 / (L_b + 0.07 ω^0.5 L) (Hopkinson; evalglare's
/// form, the modified solid angle taken as ω/P²); 0 without sources.
pub fn dgi(background_cd_m2: f64, sources: &[SourceTerm]) -> f64 {
    if sources.is_empty() {
        return 0.0;
    }
    let s: f64 = sources
        .iter()
        .map(|s| {
            let (l, w) = (s.luminance_cd_m2, s.solid_angle_sr);
            let w_mod = w / (s.position_index * s.position_index);
            0.478 * l.powf(1.6) * w_mod.powf(0.8) / (background_cd_m2 + 0.07 * w.sqrt() * l)
        })
        .sum();
    10.0 * s.log10()
}

/// CGI = 8 log10(2 (1 + E_dir/500)/E_v Σ L² ω / P²) (Einhorn); 0 without sources.
pub fn cgi(ev_lx: f64, ev_direct_lx: f64, sources: &[SourceTerm]) -> f64 {
    if sources.is_empty() {
        return 0.0;
    }
    8.0 * ((2.0 * (1.0 + ev_direct_lx / 500.0) / ev_lx) * sum_l2w_p2(sources)).log10()
}

/// Discomfort glare rating DGR = (Σ 0.5 L (20.4 ω + 1.52 ω^0.2 − 0.075) / (P L_a^0.44))^(n^−0.0914)
/// with L_a the mean luminance of the image (cd/m²), n the number of sources; 0 without.
pub fn dgr(mean_luminance_cd_m2: f64, sources: &[SourceTerm]) -> f64 {
    if sources.is_empty() {
        return 0.0;
    }
    let s: f64 = sources
        .iter()
        .map(|s| {
            let w = s.solid_angle_sr;
            0.5 * s.luminance_cd_m2 * (20.4 * w + 1.52 * w.powf(0.2) - 0.075)
                / (s.position_index * mean_luminance_cd_m2.powf(0.44))
        })
        .sum();
    s.powf((sources.len() as f64).powf(-0.0914))
}

/// VCP (%) from DGR: 50 erf((6.374 − 1.3227 ln DGR)/√2) + 50, 100 below DGR 20, 0 above 750.
pub fn vcp(dgr: f64) -> f64 {
    if dgr < 20.0 {
        100.0
    } else if dgr > 750.0 {
        0.0
    } else {
        50.0 * erf((6.374 - 1.3227 * dgr.ln()) / std::f64::consts::SQRT_2) + 50.0
    }
}

/// Vertical illuminance Σ L cosθ ω over the valid pixels (lx), cosθ = direction · view,
/// not clamped (the inside mask excludes what is behind the eye).
pub fn vertical_illuminance(img: &GlareImage, lum: &[f64]) -> f64 {
    let (view, _) = img.frame();
    (0..img.len())
        .filter(|&i| img.valid(i))
        .map(|i| lum[i] * dot(view, img.direction[i]) * img.solid_angle_sr[i])
        .sum()
}

/// Evaluate `img` (its own luminances) with `opt`.
pub fn evaluate(img: &GlareImage, opt: &GlareOptions) -> Result<GlareResult, ImageError> {
    img.validate()?;
    Ok(evaluate_luminance(img, &img.luminance_cd_m2, opt))
}

/// Evaluate the geometry of `img` with luminances `lum` (cd/m², one per pixel); `img` must be
/// valid.
pub fn evaluate_luminance(img: &GlareImage, lum: &[f64], opt: &GlareOptions) -> GlareResult {
    evaluate_detected(img, lum, opt).0
}

/// [`evaluate_luminance`] with the detection it evaluated (the sources' pixels).
pub(crate) fn evaluate_detected(
    img: &GlareImage,
    lum: &[f64],
    opt: &GlareOptions,
) -> (GlareResult, Detection) {
    let (view, _) = img.frame();
    let up = img.position_up(opt.position_index_up);
    let det: Detection = detect(img, lum, &opt.detect);
    let ev = vertical_illuminance(img, lum);
    let ev_direct: f64 = det.sources.iter().map(|s| s.illuminance_lx).sum();
    let reports: Vec<SourceReport> = det
        .sources
        .iter()
        .map(|s| SourceReport {
            direction: s.direction,
            solid_angle_sr: s.solid_angle_sr,
            luminance_cd_m2: s.luminance_cd_m2,
            position_index: position_index(s.direction, view, up),
            angle_from_view_rad: dot(view, s.direction).clamp(-1.0, 1.0).acos(),
            illuminance_lx: s.illuminance_lx,
            pixel_count: s.pixels.len(),
        })
        .collect();
    let terms: Vec<SourceTerm> = reports
        .iter()
        .map(|s| SourceTerm {
            luminance_cd_m2: s.luminance_cd_m2,
            solid_angle_sr: s.solid_angle_sr,
            position_index: s.position_index,
        })
        .collect();
    let background = match opt.background {
        Background::Cie => (ev - ev_direct) / std::f64::consts::PI,
        Background::EvOverPi => ev / std::f64::consts::PI,
        Background::Mean => {
            let sang: f64 = (0..img.len())
                .filter(|&i| img.valid(i))
                .map(|i| img.solid_angle_sr[i])
                .sum();
            let ws: f64 = terms.iter().map(|s| s.solid_angle_sr).sum();
            let ls: f64 = terms
                .iter()
                .map(|s| s.luminance_cd_m2 * s.solid_angle_sr)
                .sum();
            if sang == ws {
                det.mean_luminance_cd_m2
            } else {
                (sang * det.mean_luminance_cd_m2 - ls) / (sang - ws)
            }
        }
    };
    let d = dgr(det.mean_luminance_cd_m2, &terms);
    let result = GlareResult {
        dgp: dgp(ev, &terms, &opt.dgp, opt.low_light_correction),
        dgi: dgi(background, &terms),
        ugr: if terms.is_empty() {
            0.0
        } else {
            ugr(background, &terms)
        },
        vcp: if terms.is_empty() { 100.0 } else { vcp(d) },
        dgr: d,
        cgi: cgi(ev, ev_direct, &terms),
        ev_lx: ev,
        ev_direct_lx: ev_direct,
        background_cd_m2: background,
        mean_luminance_cd_m2: det.mean_luminance_cd_m2,
        threshold_cd_m2: det.threshold_cd_m2,
        sources: reports,
    };
    (result, det)
}

/// The right-handed frame (right, up, view) of a line of sight and an up vector, for callers
/// that build directions in the view frame.
pub fn view_frame(view: [f64; 3], up: [f64; 3]) -> Option<([f64; 3], [f64; 3], [f64; 3])> {
    let v = normalize(view)?;
    let r = normalize(cross(v, up))?;
    Some((r, cross(r, v), v))
}
