//! Shared helpers for the BSDF tests: a small RNG, the materials under test, direction
//! helpers and the chi-square machinery (in the manner of Mitsuba 3's `chi2` module: a
//! (θ, φ) histogram of sampled directions against the pdf integrated over each cell by
//! Gauss–Legendre quadrature, cells with expected count < 5 pooled, p-value from the
//! regularised incomplete gamma function).
#![allow(dead_code)]

use candela::bxdf::{
    ior, Coated, Conductor, Dielectric, Diffuse, Distribution, Ior, Masking, Material, Microfacet,
    OrenNayar, Phong, ThinDielectric,
};
use candela::spectrum::{DenseSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};
use std::f64::consts::PI;

/// PCG32 (O'Neill 2014).
pub struct Rng(u64);
impl Rng {
    pub fn new(seed: u64) -> Self {
        let mut r = Rng(seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407));
        r.next_u32();
        r
    }
    pub fn next_u32(&mut self) -> u32 {
        let old = self.0;
        self.0 = old
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }
    /// Uniform in [0, 1).
    pub fn f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }
    pub fn vec2(&mut self) -> Vec2 {
        Vec2::new(self.f32(), self.f32())
    }
    /// Uniform direction on the sphere.
    pub fn sphere(&mut self) -> Vec3 {
        let z = 1.0 - 2.0 * self.f32();
        let r = (1.0 - z * z).max(0.0).sqrt();
        let p = 2.0 * std::f32::consts::PI * self.f32();
        Vec3::new(r * p.cos(), r * p.sin(), z)
    }
}

/// Direction from polar angle θ and azimuth φ (degrees).
pub fn dir_deg(theta: f32, phi: f32) -> Vec3 {
    let (t, p) = (theta.to_radians(), phi.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

pub fn wavelengths() -> SampledWavelengths {
    SampledWavelengths::sample_uniform(0.37)
}

pub fn conductor(metal: &str, dist: Distribution, ax: f32, ay: f32, masking: Masking) -> Material {
    Material::Conductor(Conductor {
        ior: ior::named_metal(metal).unwrap().clone(),
        mf: Microfacet::new(dist, ax, ay, masking),
    })
}

pub fn dielectric(glass: &str, dist: Distribution, alpha: f32) -> Material {
    let ior = if let Ok(n) = glass.parse::<f32>() {
        Ior::Constant(n)
    } else {
        ior::named_glass(glass).unwrap().ior.clone()
    };
    Material::Dielectric(Dielectric {
        ior,
        mf: Microfacet::isotropic(dist, alpha),
    })
}

pub fn thin(n: f32) -> Material {
    Material::ThinDielectric(ThinDielectric {
        ior: Ior::Constant(n),
    })
}

pub fn coated(rho: f32, eta: f32) -> Material {
    rough_coated(rho, eta, Distribution::Ggx, 0.0)
}

pub fn rough_coated(rho: f32, eta: f32, dist: Distribution, alpha: f32) -> Material {
    Material::Coated(Coated::new(
        DenseSpectrum::constant(rho),
        eta,
        Microfacet::isotropic(dist, alpha),
    ))
}

pub fn diffuse(rho: f32) -> Material {
    Material::Diffuse(Diffuse {
        reflectance: DenseSpectrum::constant(rho),
    })
}

pub fn oren_nayar(rho: f32, sigma_deg: f32) -> Material {
    Material::OrenNayar(OrenNayar::new(
        DenseSpectrum::constant(rho),
        sigma_deg.to_radians(),
    ))
}

pub fn phong(kd: f32, ks: f32, n: f32) -> Material {
    Material::Phong(Phong::new(
        DenseSpectrum::constant(kd),
        DenseSpectrum::constant(ks),
        n,
    ))
}

// ---------------------------------------------------------------------------------------
// Chi-square goodness of fit.

const GL_X: [f64; 4] = [
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
const GL_W: [f64; 4] = [
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

/// Nodes and weights of 8-point Gauss–Legendre on [a, b].
fn gl8(a: f64, b: f64) -> [(f64, f64); 8] {
    let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
    let mut out = [(0.0, 0.0); 8];
    for j in 0..4 {
        out[2 * j] = (m - h * GL_X[j], h * GL_W[j]);
        out[2 * j + 1] = (m + h * GL_X[j], h * GL_W[j]);
    }
    out
}

pub struct Chi2Result {
    pub stat: f64,
    pub dof: usize,
    pub p_value: f64,
    /// ∫ pdf over the sphere (the continuous part's total probability).
    pub pdf_integral: f64,
    pub message: Option<String>,
}

/// Histogram `n` samples of `material.sample(wo, …)` on an n_theta × 2·n_theta (θ, φ) grid
/// plus one cell for samples that failed or were specular, and compare with the pdf.
pub fn chi2_test(material: &Material, wo: Vec3, n: usize, n_theta: usize, seed: u64) -> Chi2Result {
    let n_phi = 2 * n_theta;
    let wl0 = wavelengths();
    let cell = |w: Vec3| -> usize {
        let theta = (w.z as f64).clamp(-1.0, 1.0).acos();
        let mut phi = (w.y as f64).atan2(w.x as f64);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let i = ((theta / PI * n_theta as f64) as usize).min(n_theta - 1);
        let j = ((phi / (2.0 * PI) * n_phi as f64) as usize).min(n_phi - 1);
        i * n_phi + j
    };
    let mut obs = vec![0f64; n_theta * n_phi + 1];
    let other = n_theta * n_phi;
    let mut rng = Rng::new(seed);
    let mut mismatch = None;
    for _ in 0..n {
        let mut wl = wl0;
        let uc = rng.f32();
        let u = rng.vec2();
        match material.sample(wo, uc, u, &mut wl) {
            Some(bs) if !bs.specular && bs.pdf > 0.0 => {
                obs[cell(bs.wi)] += 1.0;
                // The sample's f and pdf must be what eval and pdf return.
                if mismatch.is_none() {
                    let p = material.pdf(wo, bs.wi, &wl);
                    let f = material.eval(wo, bs.wi, &wl);
                    let rel = |a: f32, b: f32| (a - b).abs() / a.abs().max(b.abs()).max(1e-20);
                    if rel(p, bs.pdf) > 2e-3 || rel(f[0], bs.f[0]) > 2e-3 {
                        mismatch = Some(format!(
                            "sample/eval mismatch at wi {:?}: pdf {} vs {}, f {} vs {}",
                            bs.wi, bs.pdf, p, bs.f[0], f[0]
                        ));
                    }
                }
            }
            _ => obs[other] += 1.0,
        }
    }
    // Expected counts: N ∫_cell pdf dω, dω = sin θ dθ dφ, by Gauss–Legendre (8 nodes on each
    // of `sub` sub-intervals per axis). Cells where 2 and 4 sub-intervals disagree (a kink or a
    // jump of the pdf inside, e.g. where a rough dielectric's half vector becomes horizontal)
    // are refined to 16.
    let mut exp = vec![0f64; n_theta * n_phi + 1];
    let mut total = 0.0;
    let dt = PI / n_theta as f64;
    let dp = 2.0 * PI / n_phi as f64;
    let integrate = |i: usize, j: usize, sub: usize| -> f64 {
        let mut s = 0.0;
        for ht in 0..sub {
            let a = i as f64 * dt + ht as f64 * dt / sub as f64;
            for (t, wt) in gl8(a, a + dt / sub as f64) {
                let st = t.sin();
                for hp in 0..sub {
                    let b = j as f64 * dp + hp as f64 * dp / sub as f64;
                    for (p, wp) in gl8(b, b + dp / sub as f64) {
                        let w =
                            Vec3::new((st * p.cos()) as f32, (st * p.sin()) as f32, t.cos() as f32);
                        s += wt * wp * st * material.pdf(wo, w, &wl0) as f64;
                    }
                }
            }
        }
        s
    };
    for i in 0..n_theta {
        for j in 0..n_phi {
            let coarse = integrate(i, j, 2);
            let mut s = integrate(i, j, 4);
            if (s - coarse).abs() > 1e-3 / n as f64 + 1e-4 * s {
                s = integrate(i, j, 16);
            }
            exp[i * n_phi + j] = s * n as f64;
            total += s;
        }
    }
    exp[other] = ((1.0 - total) * n as f64).max(0.0);
    let (stat, dof, message) = chi2_statistic(&obs, &exp);
    let p_value = if dof == 0 {
        1.0
    } else {
        gamma_q(dof as f64 / 2.0, stat / 2.0)
    };
    Chi2Result {
        stat,
        dof,
        p_value,
        pdf_integral: total,
        message: mismatch.or(message),
    }
}

/// Pearson's statistic with Mitsuba's pooling: cells whose expected count is below 5 are
/// merged (in increasing order of expectation) into one cell. A sample in a cell of zero
/// expectation is reported.
fn chi2_statistic(obs: &[f64], exp: &[f64]) -> (f64, usize, Option<String>) {
    let mut idx: Vec<usize> = (0..obs.len()).collect();
    idx.sort_by(|&a, &b| exp[a].partial_cmp(&exp[b]).unwrap());
    let mut message = None;
    let (mut pool_o, mut pool_e) = (0.0, 0.0);
    let mut stat = 0.0;
    let mut cells = 0usize;
    for &k in &idx {
        if exp[k] == 0.0 && obs[k] > 0.0 && message.is_none() {
            message = Some(format!(
                "{} samples in cell {k} of zero probability",
                obs[k]
            ));
        }
        if exp[k] < 5.0 {
            pool_o += obs[k];
            pool_e += exp[k];
        } else {
            stat += (obs[k] - exp[k]).powi(2) / exp[k];
            cells += 1;
        }
    }
    if pool_e > 0.0 {
        stat += (pool_o - pool_e).powi(2) / pool_e;
        cells += 1;
    } else if pool_o > 0.0 && message.is_none() {
        message = Some(format!("{pool_o} samples where the pdf integrates to 0"));
    }
    (stat, cells.saturating_sub(1), message)
}

fn ln_gamma(x: f64) -> f64 {
    // Lanczos (g = 7, n = 9).
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularised upper incomplete gamma Q(a, x) (Numerical Recipes §6.2: series / continued
/// fraction).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let gln = ln_gamma(a);
    if x < a + 1.0 {
        let (mut ap, mut sum) = (a, 1.0 / a);
        let mut del = sum;
        for _ in 0..10_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * (-x + a * x.ln() - gln).exp()
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        (-x + a * x.ln() - gln).exp() * h
    }
}

/// Debug helper: the (θ-cell, φ-cell, observed, expected) with the largest contributions.
pub fn chi2_worst_cells(material: &Material, wo: Vec3, n: usize, n_theta: usize, seed: u64) {
    let n_phi = 2 * n_theta;
    let wl0 = wavelengths();
    let mut obs = vec![0f64; n_theta * n_phi];
    let mut rng = Rng::new(seed);
    for _ in 0..n {
        let mut wl = wl0;
        let uc = rng.f32();
        let u = rng.vec2();
        if let Some(bs) = material.sample(wo, uc, u, &mut wl) {
            if bs.specular {
                continue;
            }
            let w = bs.wi;
            let theta = (w.z as f64).clamp(-1.0, 1.0).acos();
            let mut phi = (w.y as f64).atan2(w.x as f64);
            if phi < 0.0 {
                phi += 2.0 * PI;
            }
            let i = ((theta / PI * n_theta as f64) as usize).min(n_theta - 1);
            let j = ((phi / (2.0 * PI) * n_phi as f64) as usize).min(n_phi - 1);
            obs[i * n_phi + j] += 1.0;
        }
    }
    let dt = PI / n_theta as f64;
    let dp = 2.0 * PI / n_phi as f64;
    let mut rows = Vec::new();
    for i in 0..n_theta {
        for j in 0..n_phi {
            let mut s = 0.0;
            for (t, wt) in gl8(i as f64 * dt, (i + 1) as f64 * dt) {
                for (p, wp) in gl8(j as f64 * dp, (j + 1) as f64 * dp) {
                    let w = Vec3::new(
                        (t.sin() * p.cos()) as f32,
                        (t.sin() * p.sin()) as f32,
                        t.cos() as f32,
                    );
                    s += wt * wp * t.sin() * material.pdf(wo, w, &wl0) as f64;
                }
            }
            let e = s * n as f64;
            let o = obs[i * n_phi + j];
            if e > 5.0 {
                rows.push(((o - e).powi(2) / e, i, j, o, e));
            }
        }
    }
    rows.sort_by(|a, b| b.0.partial_cmp(&a.0).unwrap());
    for r in rows.iter().take(12) {
        println!(
            "cell θ{} φ{}: obs {} exp {:.1} contrib {:.1}",
            r.1, r.2, r.3, r.4, r.0
        );
    }
}

/// Gauss–Legendre nodes and weights on [0, 1] (Newton iteration on Pₙ, f64). An N-point rule
/// integrates polynomials of degree ≤ 2N − 1 exactly.
pub fn gauss_legendre_01(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        // Map [−1, 1] → [0, 1].
        out.push((0.5 * (x + 1.0), 1.0 / ((1.0 - x * x) * dp * dp)));
    }
    out
}

/// [`chi2_test`] of every (name, material, wo) case, 100 000 samples on an 18 × 36 grid with
/// seed `seed0 + k` for case k, on two threads (the tests' machine has 2 cores). Prints each
/// result and the smallest p, and returns the failures: a bad sample, p below 0.01
/// Bonferroni-corrected over the cases, or a pdf integrating above 1.
pub fn chi2_cases(cases: &[(String, Material, Vec3)], seed0: u64) -> Vec<String> {
    let alpha = 0.01 / cases.len() as f64;
    let results: Vec<Chi2Result> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..2)
            .map(|t| {
                s.spawn(move || {
                    (0..cases.len())
                        .filter(|k| k % 2 == t)
                        .map(|k| {
                            let seed = seed0 + k as u64;
                            (k, chi2_test(&cases[k].1, cases[k].2, 100_000, 18, seed))
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        let mut all: Vec<(usize, Chi2Result)> = handles
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect();
        all.sort_by_key(|r| r.0);
        all.into_iter().map(|r| r.1).collect()
    });
    let mut failures = Vec::new();
    let mut worst = (1.0f64, String::new());
    for ((name, _, _), r) in cases.iter().zip(results) {
        println!(
            "{name:55} χ² = {:8.2}  dof = {:4}  p = {:.4}  ∫pdf = {:.5}",
            r.stat, r.dof, r.p_value, r.pdf_integral
        );
        if r.p_value < worst.0 {
            worst = (r.p_value, name.clone());
        }
        if let Some(msg) = r.message {
            failures.push(format!("{name}: {msg}"));
        } else if r.p_value < alpha {
            failures.push(format!(
                "{name}: χ² = {} (dof {}), p = {} < {alpha}",
                r.stat, r.dof, r.p_value
            ));
        }
        if r.pdf_integral > 1.0 + 1e-3 {
            failures.push(format!("{name}: pdf integrates to {}", r.pdf_integral));
        }
    }
    println!(
        "{} cases, smallest p = {:.4} ({})",
        cases.len(),
        worst.0,
        worst.1
    );
    failures
}
