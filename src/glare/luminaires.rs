//! CIE 117 UGR at an eye point from a scene's luminaires (the `Ugr` meter): each luminaire's
//! luminance toward the eye, the solid angle of its luminous area, its Guth position index,
//! and the background luminance from the indirect illuminance at the eye.
//!
//! - a goniometric luminaire (IES / EULUMDAT): luminance = its intensity toward the eye over
//!   the projected area of the file's luminous box (length along C0, width, height), solid
//!   angle = projected area / d²;
//! - an area light: its luminance, its solid angle Σ A cosθ / d² over a stratified grid of
//!   points on each primitive (front faces only unless two-sided), direction the
//!   ω-weighted mean;
//! - a point or spot light has no luminous area: it is no glare source, but its direct light
//!   is still taken out of the background.
//!
//! L_b = E_ind/π with E_ind = E_v − E_dir: E_v is the meter's Monte Carlo vertical
//! illuminance (with its standard error), E_dir the luminaires' direct vertical illuminance in
//! closed form (unobstructed). The UGR interval maps E_ind's 95 % interval through the
//! (monotone) formula.

use super::indices::{position_index, ugr, SourceTerm};
use crate::light::Light;
use crate::meter::Estimate;
use crate::photometry::luminous_integral;
use crate::world::World;
use glam::{Vec2, Vec3};

/// Grid points per side on each area-light primitive.
const GRID: u32 = 24;

/// One luminaire as the eye sees it.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct LuminaireView {
    /// Index of the light in the world.
    pub light: usize,
    /// Unit direction from the eye to the luminaire (world).
    pub direction: [f64; 3],
    /// Angle from the line of sight, degrees.
    pub angle_from_view_deg: f64,
    /// Luminance toward the eye, cd/m².
    pub luminance_cd_m2: f64,
    /// Solid angle of the luminous area, sr.
    pub solid_angle_sr: f64,
    /// Guth position index.
    pub position_index: f64,
    /// Direct vertical illuminance at the eye, lx.
    pub illuminance_lx: f64,
}

/// The UGR meter's result.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct UgrResult {
    /// CIE 117 UGR (0 without a visible luminaire, −99 when L_b ≤ 0).
    pub ugr: f64,
    /// UGR at the upper and lower ends of E_ind's 95 % interval (low, high).
    pub ugr_interval: (f64, f64),
    /// Vertical illuminance at the eye (Monte Carlo), lx, and its standard error.
    pub ev_lx: f64,
    pub ev_stderr_lx: f64,
    /// Direct vertical illuminance from the luminaires (closed form), lx.
    pub ev_direct_lx: f64,
    /// Indirect illuminance E_ind = E_v − E_dir, lx.
    pub ev_indirect_lx: f64,
    /// Background luminance L_b = E_ind/π, cd/m².
    pub background_cd_m2: f64,
    /// Luminaires in front of the eye with a luminous area.
    pub luminaires: Vec<LuminaireView>,
}

fn arr(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

/// The luminaires seen from `eye` looking along unit `view` with `up`, and the direct
/// vertical illuminance (lx) of every luminaire, area or not.
pub fn luminaire_views(
    world: &World,
    eye: Vec3,
    view: Vec3,
    up: Vec3,
) -> (Vec<LuminaireView>, f64) {
    let view64 = arr(view);
    let up64 = {
        let u = arr(up - view * view.dot(up));
        let n = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
        u.map(|x| x / n)
    };
    let mut out = Vec::new();
    let mut e_dir = 0.0;
    // A point-like luminaire at `pos` with intensity `cd` toward the eye.
    let point = |pos: Vec3, cd: f64| -> Option<(Vec3, f64, f64)> {
        let d = eye - pos;
        let r2 = d.length_squared() as f64;
        let to_lum = (-d).normalize();
        let cos_eye = to_lum.dot(view) as f64;
        (r2 > 0.0 && cos_eye > 0.0).then_some((to_lum, r2, cd * cos_eye / r2))
    };
    let view_of = |i: usize, dir: [f64; 3], l: f64, w: f64, e: f64| LuminaireView {
        light: i,
        direction: dir,
        angle_from_view_deg: (dir[0] * view64[0] + dir[1] * view64[1] + dir[2] * view64[2])
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees(),
        luminance_cd_m2: l,
        solid_angle_sr: w,
        position_index: position_index(dir, view64, up64),
        illuminance_lx: e,
    };
    for (i, light) in world.lights.iter().enumerate() {
        match light {
            Light::Point(p) => {
                let cd = luminous_integral(&p.intensity);
                if let Some((_, _, e)) = point(p.position, cd) {
                    e_dir += e;
                }
            }
            Light::Spot(s) => {
                let to_eye = (eye - s.position).normalize();
                let f =
                    crate::light::spot::smoothstep(s.cos_outer, s.cos_inner, to_eye.dot(s.frame.n));
                let cd = luminous_integral(&s.intensity) * f.max(0.0) as f64;
                if let Some((_, _, e)) = point(s.position, cd) {
                    e_dir += e;
                }
            }
            Light::Goniometric(g) => {
                let to_eye = (eye - g.position).normalize();
                let cd = g.candela(to_eye);
                let Some((dir, r2, e)) = point(g.position, cd) else {
                    continue;
                };
                e_dir += e;
                // Projected area of the luminous box seen from the eye (luminaire frame:
                // C0 along +x, nadir −y, C90 −z; length along x, width along z, height along y).
                let l = g.rotation.transpose() * to_eye;
                let [len, wid, hgt] = g.luminous_size_m;
                let area = len * wid * (l.y as f64).abs()
                    + wid * hgt * (l.x as f64).abs()
                    + len * hgt * (l.z as f64).abs();
                if area > 0.0 && cd > 0.0 {
                    out.push(view_of(i, arr(dir), cd / area, area / r2, e));
                }
            }
            Light::Area(a) => {
                // A textured emitter's luminance varies: the source's is the mean over its
                // solid angle.
                let (mut w, mut e, mut lw, mut sum) = (0.0, 0.0, 0.0, Vec3::ZERO);
                for &prim in &a.prims {
                    let da = world.geometry.prim_area(prim) as f64 / (GRID * GRID) as f64;
                    for j in 0..GRID {
                        for k in 0..GRID {
                            let u = Vec2::new(
                                (j as f32 + 0.5) / GRID as f32,
                                (k as f32 + 0.5) / GRID as f32,
                            );
                            let sp = world.geometry.sample_prim(prim, u);
                            let d = sp.p - eye;
                            let r2 = d.length_squared() as f64;
                            let dir = d.normalize();
                            let cos_l = -(sp.n.dot(dir)) as f64;
                            let cos_l = if a.two_sided { cos_l.abs() } else { cos_l };
                            let cos_e = dir.dot(view) as f64;
                            if cos_l <= 0.0 || cos_e <= 0.0 || r2 <= 0.0 {
                                continue;
                            }
                            let dw = da * cos_l / r2;
                            let lum = a.luminance_at(sp.tex);
                            w += dw;
                            lw += lum * dw;
                            e += lum * cos_e * dw;
                            sum += dir * dw as f32;
                        }
                    }
                }
                e_dir += e;
                let lum = if w > 0.0 { lw / w } else { 0.0 };
                if w > 0.0 && lum > 0.0 {
                    out.push(view_of(i, arr(sum.normalize()), lum, w, e));
                }
            }
            _ => {}
        }
    }
    (out, e_dir)
}

/// UGR at `eye` from the meter's vertical-illuminance estimate `ev` (lx).
pub fn ugr_from_estimate(
    world: &World,
    eye: Vec3,
    view: Vec3,
    up: Vec3,
    ev: &Estimate,
) -> UgrResult {
    let (luminaires, e_dir) = luminaire_views(world, eye, view, up);
    let terms: Vec<SourceTerm> = luminaires
        .iter()
        .map(|l| SourceTerm {
            luminance_cd_m2: l.luminance_cd_m2,
            solid_angle_sr: l.solid_angle_sr,
            position_index: l.position_index,
        })
        .collect();
    let e_ind = ev.mean - e_dir;
    let at = |e: f64| ugr(e / std::f64::consts::PI, &terms);
    let h = ev.ci95();
    UgrResult {
        ugr: at(e_ind),
        // Below zero indirect illuminance the background vanishes and UGR has no upper bound.
        ugr_interval: (
            at(e_ind + h),
            if e_ind - h > 0.0 {
                at(e_ind - h)
            } else {
                f64::INFINITY
            },
        ),
        ev_lx: ev.mean,
        ev_stderr_lx: ev.stderr,
        ev_direct_lx: e_dir,
        ev_indirect_lx: e_ind,
        background_cd_m2: e_ind / std::f64::consts::PI,
        luminaires,
    }
}

impl crate::world::Meter {
    /// The UGR of a `Ugr` meter from its vertical-illuminance estimate (`None` for other kinds).
    pub fn ugr(&self, world: &World, ev: &Estimate) -> Option<UgrResult> {
        match self.kind {
            crate::world::MeterKind::Ugr {
                position,
                direction,
                up,
            } => Some(ugr_from_estimate(world, position, direction, up, ev)),
            _ => None,
        }
    }
}
