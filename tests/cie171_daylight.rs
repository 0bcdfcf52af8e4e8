//! The daylight cases of CIE 171:2006 (sky component through roof and façade openings, unglazed
//! and glazed, under CIE general skies), each against a reference computed here by quadrature
//! from an implementation of ISO 15469:2004 / CIE S 011 written for this test (its own table of
//! gradation and indicatrix parameters, its own normalisation to the horizontal illuminance),
//! so every one of the 15 general skies is checked independently of `src/daylight`.
//!
//! The set-up follows CIE 171's daylight cases (the room and openings are this file's own
//! dimensions): a black room (so the internally reflected component is zero and the meters read
//! the sky component, plus the ground's externally reflected component through a façade
//! opening) 4 × 4 m and 3 m high, with a 1.2 × 1.2 m opening in the
//! roof or a 2 × 1 m opening in the south wall; glazed openings hold a clear pane of index 1.5.
//! The sun is at altitude 40°, azimuth 200° (south-south-west), which fixes the indicatrix; the
//! sky alone gives E_h = 10 000 lx.
//!
//! Meter tolerances: 5 calibrated standard errors, each below 0.5 % of the reference.

mod common;
use candela::meter::measure_all;
use common::{assert_estimate_near, world};
use std::f64::consts::PI;

const E_H: f64 = 10_000.0;
const SUN_ALT_DEG: f64 = 40.0;
const SUN_AZ_DEG: f64 = 200.0;
const GROUND: f64 = 0.2;
const N_PANE: f64 = 1.5;

/// ISO 15469:2004 Table 1: gradation groups (a, b) I–VI and indicatrix groups (c, d, e) 1–6,
/// and the standard general skies 1–15 as (gradation, indicatrix).
const GRADATION: [(f64, f64); 6] = [
    (4.0, -0.70),
    (1.1, -0.8),
    (0.0, -1.0),
    (-1.0, -0.55),
    (-1.0, -0.32),
    (-1.0, -0.15),
];
const INDICATRIX: [(f64, f64, f64); 6] = [
    (0.0, -1.0, 0.0),
    (2.0, -1.5, 0.15),
    (5.0, -2.5, 0.30),
    (10.0, -3.0, 0.45),
    (16.0, -3.0, 0.30),
    (24.0, -2.8, 0.15),
];
const SKY_TYPES: [(usize, usize); 15] = [
    (1, 1),
    (1, 2),
    (2, 1),
    (2, 2),
    (3, 1),
    (3, 2),
    (3, 3),
    (3, 4),
    (4, 2),
    (4, 3),
    (4, 4),
    (5, 4),
    (5, 5),
    (6, 5),
    (6, 6),
];

/// World direction (+y up, north −z, east +x) of altitude `alt` and azimuth `az` (from north
/// toward east), radians.
fn direction(alt: f64, az: f64) -> [f64; 3] {
    [alt.cos() * az.sin(), alt.sin(), -alt.cos() * az.cos()]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// A CIE general sky, relative luminance up to a constant, and the constant that makes its
/// horizontal illuminance E_H.
struct Sky {
    a: f64,
    b: f64,
    c: f64,
    d: f64,
    e: f64,
    sun: [f64; 3],
    scale: f64,
}

impl Sky {
    fn general(kind: usize) -> Sky {
        let (g, i) = SKY_TYPES[kind - 1];
        let (a, b) = GRADATION[g - 1];
        let (c, d, e) = INDICATRIX[i - 1];
        let sun = direction(SUN_ALT_DEG.to_radians(), SUN_AZ_DEG.to_radians());
        let mut sky = Sky {
            a,
            b,
            c,
            d,
            e,
            sun,
            scale: 1.0,
        };
        // E_h = ∫ L cos Z dω = ∫₀¹ ∫₀^2π L(u, φ) u dφ du, u = cos Z: midpoints in u and φ.
        let (nu, nphi) = (1500, 1500);
        let mut e_h = 0.0;
        for i in 0..nu {
            let u = (i as f64 + 0.5) / nu as f64;
            let alt = u.asin();
            let mut ring = 0.0;
            for j in 0..nphi {
                let phi = 2.0 * PI * (j as f64 + 0.5) / nphi as f64;
                ring += sky.relative(direction(alt, phi));
            }
            e_h += ring * u;
        }
        e_h *= 2.0 * PI / (nu * nphi) as f64;
        sky.scale = E_H / e_h;
        sky
    }

    /// φ(Z) f(χ), χ the angle to the sun; directions below the horizon are not sky.
    fn relative(&self, w: [f64; 3]) -> f64 {
        let cos_z = w[1];
        let gradation = 1.0 + self.a * (self.b / cos_z).exp();
        let chi = dot(w, self.sun).clamp(-1.0, 1.0).acos();
        let indicatrix = 1.0
            + self.c * ((self.d * chi).exp() - (self.d * PI / 2.0).exp())
            + self.e * chi.cos().powi(2);
        gradation * indicatrix
    }

    /// Luminance (cd/m²) seen in direction `w`: the sky above the horizon, the ground of
    /// luminance ρ_g E_h / π below it.
    fn luminance(&self, w: [f64; 3]) -> f64 {
        if w[1] > 0.0 {
            self.scale * self.relative(w)
        } else {
            GROUND * E_H / PI
        }
    }
}

/// Transmittance of a non-absorbing pane of index N_PANE at incidence cos θ: each polarisation
/// passes (1 − R)/(1 + R) after all internal reflections; unpolarised light averages the two.
fn pane_transmittance(cos_i: f64) -> f64 {
    let sin_t = (1.0 - cos_i * cos_i).sqrt() / N_PANE;
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = ((cos_i - N_PANE * cos_t) / (cos_i + N_PANE * cos_t)).powi(2);
    let rp = ((N_PANE * cos_i - cos_t) / (N_PANE * cos_i + cos_t)).powi(2);
    0.5 * ((1.0 - rs) / (1.0 + rs) + (1.0 - rp) / (1.0 + rp))
}

/// A rectangular opening: corner `o` and edges `u`, `v` (m), unit normal `n`.
struct Opening {
    o: [f64; 3],
    u: [f64; 3],
    v: [f64; 3],
    n: [f64; 3],
}

impl Opening {
    /// E (lx) at `x` on a receiver of normal `nr` from what is seen through the opening:
    /// ∫ L(w) T(w) cos θ_r cos θ_o / r² dA, midpoint quadrature on an n × n grid.
    fn illuminance(&self, sky: &Sky, x: [f64; 3], nr: [f64; 3], glazed: bool) -> f64 {
        let n = 500;
        let area = dot(self.u, self.u).sqrt() * dot(self.v, self.v).sqrt();
        let mut e = 0.0;
        for i in 0..n {
            for j in 0..n {
                let (s, t) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                let p: Vec<f64> = (0..3)
                    .map(|k| self.o[k] + s * self.u[k] + t * self.v[k] - x[k])
                    .collect();
                let r2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
                let r = r2.sqrt();
                let w = [p[0] / r, p[1] / r, p[2] / r];
                let cos_r = dot(w, nr);
                if cos_r <= 0.0 {
                    continue;
                }
                let cos_o = dot(w, self.n).abs();
                let t = if glazed {
                    pane_transmittance(cos_o)
                } else {
                    1.0
                };
                e += sky.luminance(w) * t * cos_r * cos_o / r2;
            }
        }
        e * area / (n * n) as f64
    }

    fn ron(&self) -> String {
        let f = |a: [f64; 3]| format!("({}, {}, {})", a[0], a[1], a[2]);
        format!(
            "origin: {}, edge_u: {}, edge_v: {}",
            f(self.o),
            f(self.u),
            f(self.v)
        )
    }
}

fn quad(material: &str, o: [f64; 3], u: [f64; 3], v: [f64; 3]) -> String {
    format!(
        "(material: \"{material}\", shape: Quad(origin: ({}, {}, {}), edge_u: ({}, {}, {}), edge_v: ({}, {}, {}))),",
        o[0], o[1], o[2], u[0], u[1], u[2], v[0], v[1], v[2]
    )
}

/// The black room (x, z in [−2, 2], y in [0, 3]) with a 1.2 m square opening centred in its roof.
fn roof_room() -> (String, Opening) {
    let h = 0.6;
    let mut s = String::new();
    s += &quad("black", [-2.0, 0.0, -2.0], [4.0, 0.0, 0.0], [0.0, 0.0, 4.0]);
    s += &quad("black", [-2.0, 0.0, -2.0], [0.0, 3.0, 0.0], [4.0, 0.0, 0.0]);
    s += &quad("black", [-2.0, 0.0, 2.0], [0.0, 3.0, 0.0], [4.0, 0.0, 0.0]);
    s += &quad("black", [-2.0, 0.0, -2.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0]);
    s += &quad("black", [2.0, 0.0, -2.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0]);
    s += &quad(
        "black",
        [-2.0, 3.0, -2.0],
        [4.0, 0.0, 0.0],
        [0.0, 0.0, 2.0 - h],
    );
    s += &quad(
        "black",
        [-2.0, 3.0, h],
        [4.0, 0.0, 0.0],
        [0.0, 0.0, 2.0 - h],
    );
    s += &quad(
        "black",
        [-2.0, 3.0, -h],
        [2.0 - h, 0.0, 0.0],
        [0.0, 0.0, 2.0 * h],
    );
    s += &quad(
        "black",
        [h, 3.0, -h],
        [2.0 - h, 0.0, 0.0],
        [0.0, 0.0, 2.0 * h],
    );
    let opening = Opening {
        o: [-h, 3.0, -h],
        u: [2.0 * h, 0.0, 0.0],
        v: [0.0, 0.0, 2.0 * h],
        n: [0.0, 1.0, 0.0],
    };
    (s, opening)
}

/// The black room with a 2 m wide, 1 m high opening in its south wall (z = 2), sill at 1 m.
fn facade_room() -> (String, Opening) {
    let mut s = String::new();
    s += &quad("black", [-2.0, 0.0, -2.0], [4.0, 0.0, 0.0], [0.0, 0.0, 4.0]);
    s += &quad("black", [-2.0, 3.0, -2.0], [4.0, 0.0, 0.0], [0.0, 0.0, 4.0]);
    s += &quad("black", [-2.0, 0.0, -2.0], [0.0, 3.0, 0.0], [4.0, 0.0, 0.0]);
    s += &quad("black", [-2.0, 0.0, -2.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0]);
    s += &quad("black", [2.0, 0.0, -2.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0]);
    // South wall around the opening x ∈ [−1, 1], y ∈ [1, 2].
    s += &quad("black", [-2.0, 0.0, 2.0], [4.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    s += &quad("black", [-2.0, 2.0, 2.0], [4.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    s += &quad("black", [-2.0, 1.0, 2.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    s += &quad("black", [1.0, 1.0, 2.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let opening = Opening {
        o: [-1.0, 1.0, 2.0],
        u: [2.0, 0.0, 0.0],
        v: [0.0, 1.0, 0.0],
        n: [0.0, 0.0, 1.0],
    };
    (s, opening)
}

/// Meter readings (mean, stderr) in `room` under `sky` (RON model), the opening as the
/// sky's portal and, when `glazed`, a pane in it.
fn measure(
    room: &(String, Opening),
    model: &str,
    glazed: bool,
    meters: &[([f64; 3], [f64; 3])],
    samples: u64,
) -> Vec<(f64, f64)> {
    let (objects, opening) = room;
    let pane = if glazed {
        format!("(material: \"pane\", shape: Quad({})),", opening.ron())
    } else {
        String::new()
    };
    let meters: Vec<String> = meters
        .iter()
        .enumerate()
        .map(|(i, (p, n))| {
            format!(
                "Illuminance(name: \"m{i}\", position: ({}, {}, {}), normal: ({}, {}, {}))",
                p[0], p[1], p[2], n[0], n[1], n[2]
            )
        })
        .collect();
    let scene = format!(
        "(camera: (position: (0, 1, 0), look_at: (0, 1, 1), vfov_deg: 30, resolution: (1, 1)),
          materials: {{\"pane\": ThinDielectric(ior: Constant({N_PANE}))}},
          objects: [{objects}{pane}],
          lights: [Sky(model: {model}, sun: (altitude_deg: {SUN_ALT_DEG}, azimuth_deg: {SUN_AZ_DEG}),
                       amount: HorizontalIlluminance({E_H}), ground_reflectance: {GROUND},
                       portals: [({})])],
          meters: [{}], measure: (samples: {samples}))",
        opening.ron(),
        meters.join(", ")
    );
    measure_all(&world(&scene))
        .meters
        .iter()
        .map(|e| (e.mean, e.stderr))
        .collect()
}

/// Runs one case: every general sky, each meter against the quadrature.
fn case(label: &str, room: (String, Opening), glazed: bool, meters: &[([f64; 3], [f64; 3])]) {
    let (mut worst, mut worst_rel, mut max_rel_se): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for kind in 1..=15 {
        let sky = Sky::general(kind);
        let r = measure(&room, &format!("CieGeneral({kind})"), glazed, meters, 16384);
        for ((x, n), (mean, se)) in meters.iter().zip(&r) {
            let exact = room.1.illuminance(&sky, *x, *n, glazed);
            worst = worst.max((mean - exact).abs() / se);
            worst_rel = worst_rel.max((mean - exact).abs() / exact);
            max_rel_se = max_rel_se.max(se / exact);
            assert_estimate_near(
                *mean,
                *se,
                exact,
                0.005,
                &format!("{label}, CIE general sky {kind}, meter at {x:?} facing {n:?}"),
            );
        }
    }
    println!(
        "{label}: 15 skies × {} meters, worst |Δ| = {worst:.2} σ = {:.3} %, largest se {:.3} %",
        meters.len(),
        100.0 * worst_rel,
        100.0 * max_rel_se
    );
}

const UP: [f64; 3] = [0.0, 1.0, 0.0];

/// Horizontal meters on the floor below the roof opening: under its centre and off to the
/// north-east and south-west, where the opening shows lower parts of the sky.
const ROOF_METERS: [([f64; 3], [f64; 3]); 3] = [
    ([0.0, 0.0, 0.0], UP),
    ([1.5, 0.0, -1.5], UP),
    ([-1.0, 0.0, 1.5], UP),
];

/// A horizontal work-plane meter 0.8 m high and a vertical meter facing the window at its
/// mid-height, which sees sky above the horizon and ground below it.
const FACADE_METERS: [([f64; 3], [f64; 3]); 3] = [
    ([0.0, 0.8, 0.5], UP),
    ([0.8, 0.8, -1.0], UP),
    ([0.0, 1.5, 1.0], [0.0, 0.0, 1.0]),
];

#[test]
fn roof_unglazed_opening_sky_component() {
    case("roof, unglazed", roof_room(), false, &ROOF_METERS);
}

#[test]
fn roof_glazed_opening_sky_component() {
    case("roof, glazed", roof_room(), true, &ROOF_METERS);
}

#[test]
fn facade_unglazed_opening_sky_and_ground() {
    case("façade, unglazed", facade_room(), false, &FACADE_METERS);
}

#[test]
fn facade_glazed_opening_sky_and_ground() {
    case("façade, glazed", facade_room(), true, &FACADE_METERS);
}

/// The reference itself: the quadrature gives the closed forms it must — the uniform sky's
/// configuration-factor illuminance below the roof opening, and E_h for the whole sky.
#[test]
fn reference_quadrature_meets_closed_forms() {
    let sky = Sky::general(5);
    // Sky 5 is the uniform sky: L = E_h / π everywhere above the horizon.
    let l = sky.luminance([0.0, 1.0, 0.0]);
    assert!((l - E_H / PI).abs() < 1e-6 * l, "uniform sky {l}");
    let corner = |a: f64, b: f64, c: f64| {
        let (x, y) = (a / c, b / c);
        let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
    };
    let (_, opening) = roof_room();
    let e = opening.illuminance(&sky, [0.0, 0.0, 0.0], UP, false);
    let f = 4.0 * corner(0.6, 0.6, 3.0);
    assert!((e - PI * l * f).abs() < 1e-5 * e, "{e} vs {}", PI * l * f);
    // Normal incidence through the pane: 2n/(n²+1) = 0.923 for n = 1.5.
    let t0 = pane_transmittance(1.0);
    assert!((t0 - 2.0 * N_PANE / (N_PANE * N_PANE + 1.0)).abs() < 1e-12);
}
