//! Light-and-health channels of renders against closed forms: a diffuse plane of constant
//! reflectance under a uniform sky (an environment of luminance L_sky) reflects the sky's own
//! spectrum, so its m-EDL is DER·L_v and its m-EDI is DER·E with the source's melanopic DER
//! (1 for D65, by definition of S 026's EDI); E = π L_sky and L_v = ρ L_sky on the plane. An eye
//! looking horizontally receives half the sky and half the ground: E_v = π (L_sky + ρ L_sky)/2.
//! Tolerances come from the batch standard errors; the spectral OpenEXR is read back with
//! colour-science's reader.

mod common;
use candela::colour::alpha_opic::{alpha_opic_der, AlphaOpic};
use candela::film::{batch_standard_error, Film, HealthChannels, HealthFilm, PIXEL_BATCHES};
use candela::meter::{t95, BATCHES};
use candela::render::{render_progressive, Progressive};
use candela::world::World;
use std::f64::consts::PI;
use std::sync::atomic::AtomicBool;

const L_SKY: f64 = 100.0;
const RHO: f64 = 0.5;
const SIZE: usize = 12;

fn sky_over_plane(spectrum: &str, l_sky: f64, spp: u32) -> World {
    common::world(&format!(
        r#"(
        camera: (position: (0.0, 2.0, 0.0), look_at: (0.3, 0.0, 0.2), vfov_deg: 40, resolution: ({SIZE}, {SIZE})),
        render: (spp: {spp}, illuminance: true),
        materials: {{ "plane": Diffuse(reflectance: Constant({RHO})) }},
        objects: [(shape: Quad(origin: (-10000, 0, -10000), edge_u: (0, 0, 20000), edge_v: (20000, 0, 0)), material: "plane")],
        lights: [Environment(spectrum: {spectrum}, amount: Luminance({l_sky}))],
        meters: [Melanopic(name: "eye", position: (0.0, 1.2, 0.0), direction: (1.0, 0.0, 0.0))],
        measure: (samples: 16384),
    )"#
    ))
}

fn render_health(world: &World, channels: HealthChannels) -> Film {
    let (w, h) = (world.camera.width, world.camera.height);
    let mut film = Film::new(w, h);
    film.estimate_illuminance();
    film.health = Some(HealthFilm::new(channels, true, w * h).unwrap());
    let prog = Progressive {
        max_spp: world.settings.spp,
        ..Default::default()
    };
    let never = AtomicBool::new(false);
    render_progressive(
        world,
        &mut film,
        Some(2),
        &prog,
        &never,
        &mut |_| {},
        &mut |_| Ok(()),
    )
    .unwrap()
    .0
    .film
}

const MELANOPIC: HealthChannels = HealthChannels {
    melanopic: true,
    mesopic: false,
    spectral_bands: 0,
};

fn der(table: &[f64; 471]) -> f64 {
    alpha_opic_der(table)[AlphaOpic::Melanopic as usize]
}

/// Per pixel: m-EDL − der·L_v from the same samples, batch by batch, is 0 within 5 of its
/// standard errors; and the fraction of pixels whose 95 % interval of m-EDL (and of m-EDI)
/// covers the closed form is at least 0.85 (a calibrated interval covers 95 %: 144 pixels
/// at 0.95 fall below 0.85 with probability < 1e-5). Returns the image means of
/// m-EDL / (der L_v).
fn check_pixels(film: &Film, der: f64, l_sky: f64) -> f64 {
    let h = film.health.as_ref().unwrap();
    let e = film.e.as_ref().unwrap();
    let t = t95(PIXEL_BATCHES as u32 - 1);
    let (mut covered_l, mut covered_e, mut ratio) = (0, 0, 0.0);
    for (i, p) in film.pixels.iter().enumerate() {
        let mel = h.melanopic_edl_batches(i).unwrap();
        let d: [f64; PIXEL_BATCHES] = std::array::from_fn(|b| mel[b] - der * p.batch_y[b]);
        let mean_d = d.iter().sum::<f64>() / p.count as f64;
        let se_d = batch_standard_error(&d, p.count, candela::film::DEFAULT_PIXEL_BATCHES);
        assert!(
            mean_d.abs() <= 5.0 * se_d,
            "pixel {i}: m-EDL − DER·L_v = {mean_d} ± {se_d}"
        );
        let edl = h.melanopic_edl(i, p, 16).unwrap();
        assert!(edl.stderr < 0.02 * edl.mean, "pixel {i}: {edl:?}");
        covered_l += ((edl.mean - der * RHO * l_sky).abs() <= t * edl.stderr) as usize;
        let edi = h.melanopic_edi(i, p, e[i].count_e, 16).unwrap();
        covered_e += ((edi.mean - der * PI * l_sky).abs() <= t * edi.stderr) as usize;
        ratio += edl.mean / (der * p.mean_xyz()[1]);
    }
    let n = film.pixels.len();
    for (what, c) in [("m-EDL", covered_l), ("m-EDI", covered_e)] {
        assert!(
            c as f64 >= 0.85 * n as f64,
            "the 95 % interval of {what} covers the closed form in {c} of {n} pixels"
        );
    }
    ratio / n as f64
}

/// The melanopic meter: E_v and m-EDI against the closed form, and m-EDI/E_v against `der`,
/// each within 4 standard errors, which must be below 1 % (so the test keeps its power).
fn check_meter(world: &World, der: f64, l_sky: f64) -> (f64, f64) {
    let m = candela::meter::measure_all(world);
    let me = m.melanopic[0].expect("a melanopic meter");
    let ev = PI * (l_sky + RHO * l_sky) / 2.0;
    assert_eq!(
        me.illuminance_lx, m.meters[0],
        "the same samples as the meter's E_v"
    );
    for (what, e, want) in [
        ("E_v", me.illuminance_lx, ev),
        ("m-EDI", me.m_edi_lx, der * ev),
    ] {
        assert!(
            (e.mean - want).abs() <= 4.0 * e.stderr && e.stderr < 0.01 * want,
            "{what} = {} ± {}, expected {want}",
            e.mean,
            e.stderr
        );
    }
    assert!(
        (me.ratio - der).abs() <= 4.0 * me.ratio_stderr && me.ratio_stderr < 0.01 * der,
        "m-EDI/E_v = {} ± {}, DER {der}",
        me.ratio,
        me.ratio_stderr
    );
    assert_eq!(me.m_edi_lx.batches, BATCHES);
    (me.ratio, me.ratio_stderr)
}

#[test]
fn d65_sky_melanopic_equals_photopic() {
    let d65 = candela::colour::tables::named_spectrum("D65")
        .unwrap()
        .to_table();
    let der = der(&d65);
    // S 026's D65 normalisation: DER 1 to rounding.
    assert!((der - 1.0).abs() < 1e-12, "{der}");
    let w = sky_over_plane("Named(\"D65\")", L_SKY, 256);
    let film = render_health(&w, MELANOPIC);
    let r = check_pixels(&film, der, L_SKY);
    let (mr, mse) = check_meter(&w, der, L_SKY);
    println!("D65: image mean m-EDL/L_v = {r:.5}; meter m-EDI/E_v = {mr:.5} ± {mse:.5}");
}

#[test]
fn blackbody_2700k_ratio_is_the_melanopic_der() {
    let bb = candela::colour::planck::blackbody_table(2700.0);
    let der = der(&bb);
    assert!((0.40..0.48).contains(&der), "DER(2700 K) = {der}");
    let w = sky_over_plane("Blackbody(2700.0)", L_SKY, 256);
    let film = render_health(&w, MELANOPIC);
    let r = check_pixels(&film, der, L_SKY);
    let (mr, mse) = check_meter(&w, der, L_SKY);
    println!("2700 K: DER {der:.5}; image mean m-EDL/(DER L_v) = {r:.5}; meter m-EDI/E_v = {mr:.5} ± {mse:.5}");
}

#[test]
fn mesopic_luminance_of_a_dim_plane() {
    // L_v = ρ L_sky = 0.1 cd/m², mid-mesopic; the plane's S/P is the source's.
    let l_sky = 0.2;
    let d65 = candela::colour::tables::named_spectrum("D65")
        .unwrap()
        .to_table();
    let sp = candela::photometry::sp_ratio(&d65);
    let want = candela::colour::mesopic::mesopic_luminance(RHO * l_sky, sp);
    assert!(want.m > 0.1 && want.m < 0.9, "{want:?}");
    let w = sky_over_plane("Named(\"D65\")", l_sky, 256);
    let film = render_health(
        &w,
        HealthChannels {
            melanopic: false,
            mesopic: true,
            spectral_bands: 0,
        },
    );
    let h = film.health.as_ref().unwrap();
    let t = t95(PIXEL_BATCHES as u32 - 1);
    let mut covered = 0;
    for (i, p) in film.pixels.iter().enumerate() {
        let m = h.mesopic(i, p, 16).unwrap();
        assert!(
            (m.mean - want.luminance_cd_m2).abs() <= 5.0 * m.stderr && m.stderr < 0.02 * m.mean,
            "pixel {i}: L_mes = {} ± {}, expected {want:?}",
            m.mean,
            m.stderr
        );
        covered += ((m.mean - want.luminance_cd_m2).abs() <= t * m.stderr) as usize;
    }
    let n = film.pixels.len();
    assert!(covered as f64 >= 0.85 * n as f64, "{covered} of {n}");
}

#[test]
fn spectral_exr_round_trips_through_colour_science() {
    let bands = 32;
    let w = sky_over_plane("Named(\"D65\")", L_SKY, 64);
    let film = render_health(
        &w,
        HealthChannels {
            melanopic: false,
            mesopic: false,
            spectral_bands: bands,
        },
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plane.spectral.exr");
    let layers = candela::film::spectral_layers(&film, "plane").unwrap();
    candela::output::write_exr(&path, &layers).unwrap();
    let r = common::python_json("health/fichet_read.py", &[path.as_os_str()], None);
    assert_eq!(r["is_emissive"], true);
    assert_eq!(r["emissive_units"], "W.m^-2.sr^-1");
    assert_eq!(r["layout_version"], "1.0");
    assert_eq!(
        (r["width"].as_u64(), r["height"].as_u64()),
        (Some(SIZE as u64), Some(SIZE as u64))
    );
    let wl: Vec<f64> = serde_json::from_value(r["wavelengths"].clone()).unwrap();
    let h = film.health.as_ref().unwrap();
    assert_eq!(wl, h.band_centres_nm());
    // The values read are those written (f32).
    let p0: Vec<f64> = serde_json::from_value(r["pixel0"].clone()).unwrap();
    for (a, b) in p0.iter().zip(h.bands(0, &film.pixels[0])) {
        assert_eq!(*a as f32, b as f32);
    }
    // Y from the bands: the banding error of 12.5 nm bands for this spectrum (the midpoint
    // rule over band means, and nothing below 380 or above 780 nm) is a fixed ratio, computed
    // from the 1 nm tables; the rest is Monte Carlo noise of the image mean.
    let d65 = candela::colour::tables::named_spectrum("D65")
        .unwrap()
        .to_table();
    let ybar = candela::colour::tables::photopic_v();
    let width = 400.0 / bands as f64;
    let exact: f64 = (0..471).map(|i| d65[i] * ybar[i]).sum();
    let mut banded = 0.0;
    for (k, c) in wl.iter().enumerate() {
        let lo = (380.0 + k as f64 * width - 360.0) as usize;
        let hi = (380.0 + (k + 1) as f64 * width - 360.0) as usize;
        // Band mean on the 1 nm grid (trapezoid between the band's edges).
        let mean: f64 =
            (lo..hi).map(|i| (d65[i] + d65[i + 1]) / 2.0).sum::<f64>() / (hi - lo) as f64;
        let y = {
            let x = c - 360.0;
            let i = x as usize;
            ybar[i] * (1.0 - (x - i as f64)) + ybar[i + 1] * (x - i as f64)
        };
        banded += mean * y * width;
    }
    let banding = banded / exact;
    let y: Vec<f64> = serde_json::from_value(r["y"].clone()).unwrap();
    let n = film.pixels.len() as f64;
    let (mut sum_bands, mut sum_y, mut var) = (0.0, 0.0, 0.0);
    for (i, p) in film.pixels.iter().enumerate() {
        sum_bands += y[i] / n;
        sum_y += p.mean_xyz()[1] / n;
        var += p
            .y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES)
            .powi(2);
    }
    let se = var.sqrt() / n;
    let rel = sum_bands / (banding * sum_y) - 1.0;
    println!(
        "spectral round trip: banding ratio {banding:.6}, Y(bands)/Y = {:.6}, after banding {rel:+.5} (se of Y {:.5})",
        sum_bands / sum_y,
        se / sum_y
    );
    // The two estimates share their samples; their difference is within the sum of their
    // errors, each about that of Y.
    assert!(rel.abs() * sum_y <= 4.0 * 2.0 * se, "{rel}");
    assert!((banding - 1.0).abs() < 0.01, "{banding}");
}

#[test]
fn the_cli_writes_the_channels_the_meter_and_the_spectral_image() {
    let dir = tempfile::tempdir().unwrap();
    let scene = r#"(
        camera: (position: (0.0, 2.0, 0.0), look_at: (0.3, 0.0, 0.2), vfov_deg: 40, resolution: (8, 6)),
        render: (spp: 16),
        materials: { "plane": Diffuse(reflectance: Constant(0.5)) },
        objects: [(shape: Quad(origin: (-100, 0, -100), edge_u: (0, 0, 200), edge_v: (200, 0, 0)), material: "plane")],
        lights: [Environment(spectrum: Blackbody(2700.0), amount: Luminance(100.0))],
        meters: [Melanopic(name: "eye", position: (0.0, 1.2, 0.0), direction: (1.0, 0.0, 0.0))],
        measure: (samples: 256),
    )"#;
    std::fs::write(dir.path().join("s.ron"), scene).unwrap();
    let (code, out, err) = common::cli(
        &[
            "render",
            "s.ron",
            "--quiet",
            "--illuminance",
            "--alpha-opic",
            "--mesopic",
            "--spectral-bands",
            "16",
        ],
        dir.path(),
    );
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("m-EDI/E_v"), "{out}");
    let exr = candela::output::read_exr(&dir.path().join("s.exr")).unwrap();
    for c in [
        "melanopic.EDL",
        "stderr.melanopic.EDL",
        "melanopic.EDI",
        "stderr.melanopic.EDI",
        "scotopic.L",
        "mesopic.L",
        "stderr.mesopic.L",
        "mesopic.m",
    ] {
        assert!(exr.channel(c).is_some(), "no channel {c}");
    }
    let spectral = candela::output::read_exr(&dir.path().join("s.spectral.exr")).unwrap();
    let (nm, bands) = candela::film::read_spectral_bands(&spectral);
    assert_eq!((nm.len(), bands.len()), (16, 16));
    assert_eq!(spectral.attribute("emissiveUnits"), Some("W.m^-2.sr^-1"));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("s.report.json")).unwrap())
            .unwrap();
    let m = &report["meters"][0];
    assert_eq!(m["kind"], "melanopic");
    let ratio = m["melanopic"]["m_edi_over_illuminance"]["value"]
        .as_f64()
        .unwrap();
    let der = der(&candela::colour::planck::blackbody_table(2700.0));
    let half = m["melanopic"]["m_edi_over_illuminance"]["ci95_half_width"]
        .as_f64()
        .unwrap();
    assert!(
        (ratio - der).abs() <= 2.0 * half && half < 0.05 * der,
        "{m}"
    );
    // The probe reads the spectral image beside the EXR.
    let (code, out, err) = common::cli(&["probe", "s.exr", "3", "2"], dir.path());
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("TM-30 Rf") && out.contains("relative SPD"),
        "{out}"
    );
}

const HEALTH_FLAGS: [&str; 6] = [
    "--illuminance",
    "--alpha-opic",
    "--mesopic",
    "--spectral-bands",
    "8",
    "--quiet",
];

fn cli_ok(dir: &std::path::Path, args: &[&str]) -> String {
    let (code, out, err) = common::cli(args, dir);
    assert_eq!(code, 0, "{args:?}: {err}");
    out
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs()) + 1e-300
}

/// The health sums of two states hold the same samples: equal but for the order of addition
/// (each pixel's batches too, so the merge and the resume keep the batch numbering).
fn same_health(a: &candela::state::RenderState, b: &candela::state::RenderState) {
    let (ha, hb) = (
        a.film.health.as_ref().unwrap(),
        b.film.health.as_ref().unwrap(),
    );
    assert_eq!((ha.channels, ha.illuminance), (hb.channels, hb.illuminance));
    assert_eq!(ha.sums.len(), hb.sums.len());
    assert!(ha.sums.iter().any(|&v| v > 0.0));
    for (k, (x, y)) in ha.sums.iter().zip(&hb.sums).enumerate() {
        assert!(close(*x, *y), "health sum {k}: {x} vs {y}");
    }
    for (p, q) in a.film.pixels.iter().zip(&b.film.pixels) {
        assert_eq!(p.count, q.count);
        assert!(close(p.sum_xyz[1], q.sum_xyz[1]));
    }
}

/// Health renders resume and shard like plain ones: two shards of 8 spp merged, and a render
/// of 8 spp resumed to 16, hold the sums of one render at 16 spp (8 is half the 16 batches, so
/// the second half's batches must be moved on by 8), and the merged EXR and spectral EXR
/// carry the channels. A resume that asks for other channels than the state's is refused.
#[test]
fn health_channels_survive_shards_merge_and_resume() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = r#"(
        camera: (position: (0.0, 2.0, 0.0), look_at: (0.3, 0.0, 0.2), vfov_deg: 40, resolution: (8, 6)),
        render: (spp: 16),
        materials: { "plane": Diffuse(reflectance: Constant(0.5)) },
        objects: [(shape: Quad(origin: (-100, 0, -100), edge_u: (0, 0, 200), edge_v: (200, 0, 0)), material: "plane")],
        lights: [Environment(spectrum: Blackbody(2700.0), amount: Luminance(100.0))],
    )"#;
    std::fs::write(d.join("s.ron"), scene).unwrap();
    let run = |extra: &[&str]| {
        let mut a = vec!["render", "s.ron"];
        a.extend_from_slice(&HEALTH_FLAGS);
        a.extend_from_slice(extra);
        cli_ok(d, &a)
    };
    run(&["--spp", "16", "--save-state", "--out", "single"]);
    for i in ["0/2", "1/2"] {
        run(&["--spp", "8", "--shard", i, "--out", "r"]);
    }
    cli_ok(
        d,
        &[
            "merge",
            "r.shard-1-of-2.state",
            "r.shard-0-of-2.state",
            "-o",
            "m",
        ],
    );
    let load = |n: &str| candela::state::RenderState::load(&d.join(n)).unwrap();
    let single = load("single.state");
    same_health(&load("m.state"), &single);
    for f in ["m.exr", "m.spectral.exr"] {
        assert!(d.join(f).is_file(), "{f}");
    }
    let exr = candela::output::read_exr(&d.join("m.exr")).unwrap();
    let one = candela::output::read_exr(&d.join("single.exr")).unwrap();
    for c in [
        "melanopic.EDL",
        "melanopic.EDI",
        "mesopic.L",
        "stderr.melanopic.EDL",
    ] {
        let (a, b) = (exr.channel(c).unwrap(), one.channel(c).unwrap());
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-5 * y.abs().max(1e-3), "{c}: {x} vs {y}");
        }
    }

    run(&["--spp", "8", "--save-state", "--out", "res"]);
    run(&["--spp", "16", "--resume", "--out", "res"]);
    same_health(&load("res.state"), &single);
    let (code, _, err) = common::cli(
        &[
            "render",
            "s.ron",
            "--quiet",
            "--illuminance",
            "--mesopic",
            "--spp",
            "24",
            "--resume",
            "--out",
            "res",
        ],
        d,
    );
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("light-and-health channels"), "{err}");
}
