//! candela's glare evaluation of Radiance pictures against evalglare 3.06 (PyPI `pyradiance`)
//! in views that are not level (tests/glare/evalglare_views.py): a picture written pixel by
//! pixel with bright blocks at known places, seen level, 26.6° down, 45° up and rolled (`-vu`
//! tilted sideways); three rooms rendered by rpict in tilted and rolled views; uniform
//! pictures in every accepted view type. candela reads each `.hdr` itself (its `VIEW=` line
//! gives the geometry and the up vector) and must give each source evalglare's position index,
//! and DGP, UGR, DGI and E_v, to the digits evalglare prints (with a margin for evalglare's
//! single-precision sums, measured below); with the perpendicular-up convention it must
//! differ where the view is tilted.

mod common;
use common::python;

use candela::glare::file::{parse_radiance_view, read_glare_image};
use candela::glare::{evaluate, Background, GlareOptions, PositionIndexUp};
use serde_json::Value;
use std::path::PathBuf;
use std::process::Command;

fn options(args: &[String]) -> GlareOptions {
    let mut o = GlareOptions::default();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut num = || it.next().unwrap().parse::<f64>().unwrap();
        match a.as_str() {
            "-q" => {
                o.background = match num() as i64 {
                    0 => Background::Cie,
                    1 => Background::Mean,
                    2 => Background::EvOverPi,
                    q => panic!("-q {q} not mapped"),
                }
            }
            "-Y" => o.detect.peak_limit_cd_m2 = Some(num()),
            other => panic!("option {other} not mapped"),
        }
    }
    o
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    a.map(|v| v / n)
}

/// The pictures and evalglare's results, made once for all tests of this file.
fn cases() -> &'static (PathBuf, Vec<Value>) {
    static CASES: std::sync::OnceLock<(PathBuf, Vec<Value>)> = std::sync::OnceLock::new();
    CASES.get_or_init(make_cases)
}

fn make_cases() -> (PathBuf, Vec<Value>) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("glare_views");
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/glare/evalglare_views.py");
    let out = Command::new(python())
        .arg(script)
        .arg(&dir)
        .output()
        .expect("run python");
    assert!(
        out.status.success(),
        "evalglare_views.py failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    (dir, serde_json::from_slice(&out.stdout).unwrap())
}

#[test]
fn tilted_and_rolled_views_match_evalglare() {
    let (dir, cases) = cases();
    let dir = dir.as_path();
    let mut compared = 0;
    let mut tilted_differs = 0;
    for c in cases.iter().filter(|c| c["kind"] != "uniform") {
        let pic = c["picture"].as_str().unwrap();
        let img = read_glare_image(&dir.join(pic)).unwrap();
        let args: Vec<String> = c["options"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().to_string())
            .collect();
        let o = options(&args);
        let r = evaluate(&img, &o).unwrap();
        let f = |k: &str| c[k].as_f64().unwrap();
        let label = format!("{pic} {args:?}");
        println!(
            "{label}: DGP {:.6}/{:.6} UGR {:.4}/{:.4} DGI {:.4}/{:.4} Ev {:.3}/{:.3} Lb {:.3}/{:.3}",
            r.dgp,
            f("dgp"),
            r.ugr,
            f("ugr"),
            r.dgi,
            f("dgi"),
            r.ev_lx,
            f("ev"),
            r.background_cd_m2,
            f("lb")
        );
        // The image frame in the world: Radiance's hvec = vd × vu, vvec = hvec × vd.
        let v = parse_radiance_view(c["view"].as_str().unwrap(), img.width, img.height).unwrap();
        let vd = unit(v.vd);
        let hv = unit(cross(vd, v.vu));
        let vv = cross(hv, vd);
        let theirs = c["sources"].as_array().unwrap();
        assert_eq!(r.sources.len(), theirs.len(), "{label}: number of sources");
        for s in &r.sources {
            let d = s.direction;
            let w: [f64; 3] = std::array::from_fn(|k| d[0] * hv[k] + d[1] * vv[k] + d[2] * vd[k]);
            let e = theirs
                .iter()
                .map(|t| {
                    let t: Vec<f64> = t
                        .as_array()
                        .unwrap()
                        .iter()
                        .map(|x| x.as_f64().unwrap())
                        .collect();
                    let dist = (0..3).map(|k| (t[6 + k] - w[k]).powi(2)).sum::<f64>();
                    (dist, t)
                })
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .unwrap();
            println!(
                "  source {:.4} {:.4} {:.4}: P {:.6}/{:.6} L {:.1}/{:.1} ω {:.8}/{:.8}",
                w[0],
                w[1],
                w[2],
                s.position_index,
                e.1[5],
                s.luminance_cd_m2,
                e.1[3],
                s.solid_angle_sr,
                e.1[4]
            );
            // evalglare prints a source's direction at its unrounded centre, candela gives the
            // pixel it takes the position index at: within 1.5 pixels (0.013 rad each).
            assert!(
                e.0.sqrt() < 0.02,
                "{label}: source direction {w:?} not evalglare's"
            );
            assert!(
                (s.position_index - e.1[5]).abs() <= 2e-6 * e.1[5],
                "{label}: position index {} vs {}",
                s.position_index,
                e.1[5]
            );
        }
        assert!((r.dgp - f("dgp")).abs() <= 2e-6, "{label}: DGP");
        assert!((r.ugr - f("ugr")).abs() <= 2e-4, "{label}: UGR");
        assert!((r.dgi - f("dgi")).abs() <= 2e-4, "{label}: DGI");
        assert!((r.ev_lx / f("ev") - 1.0).abs() <= 1e-6, "{label}: Ev");
        assert!(
            (r.background_cd_m2 / f("lb") - 1.0).abs() <= 1e-6,
            "{label}: Lb"
        );
        compared += 1;
        // The perpendicular-up convention agrees where -vu is perpendicular to -vd and not
        // otherwise.
        let perp = evaluate(
            &img,
            &GlareOptions {
                position_index_up: PositionIndexUp::Perpendicular,
                ..o
            },
        )
        .unwrap();
        println!(
            "  perpendicular up: DGP {:.6} UGR {:.4} DGI {:.4}",
            perp.dgp, perp.ugr, perp.dgi
        );
        let along = (0..3).map(|k| unit(v.vu)[k] * vd[k]).sum::<f64>();
        if along.abs() < 1e-9 {
            assert_eq!(perp.ugr, r.ugr, "{label}");
        } else if (perp.ugr - r.ugr).abs() > 0.05 {
            tilted_differs += 1;
        }
    }
    assert_eq!(compared, 14);
    assert!(tilted_differs >= 8, "{tilted_differs}");
}

#[test]
fn uniform_pictures_give_evalglare_illuminance() {
    let (dir, cases) = cases();
    let dir = dir.as_path();
    let mut n = 0;
    let mut bad = Vec::new();
    for c in cases.iter().filter(|c| c["kind"] == "uniform") {
        let pic = c["picture"].as_str().unwrap();
        let view = c["view"].as_str().unwrap();
        let img = read_glare_image(&dir.join(pic)).unwrap();
        let r = evaluate(&img, &GlareOptions::default()).unwrap();
        let l = img.luminance_cd_m2[0];
        let ev = c["ev"].as_f64().unwrap();
        println!(
            "{view} {}×{}: Ev {:.3} evalglare {ev:.3} πL {:.3}",
            img.width,
            img.height,
            r.ev_lx,
            std::f64::consts::PI * l
        );
        if view.starts_with("-vts") {
            // Both stereographic views see behind the eye in their corners: evalglare counts
            // those pixels (cos θ < 0 lowers E_v), candela leaves them out and gets πL.
            if (r.ev_lx / (std::f64::consts::PI * l) - 1.0).abs() > 1e-4 || ev >= r.ev_lx - 5.0 {
                bad.push(format!("{view}: Ev {} vs πL and evalglare {ev}", r.ev_lx));
            }
        } else if view.starts_with("-vth -vh 180") {
            // The rim of a hemispherical fisheye: evalglare's solid angles of the pixels the
            // 180° circle crosses differ from candela's (0 when a corner is outside the view);
            // measured 1.8e-4 of E_v at 200 pixels.
            if (r.ev_lx / ev - 1.0).abs() > 3e-4 {
                bad.push(format!("{view}: Ev {} vs {ev}", r.ev_lx));
            }
        } else if (r.ev_lx / ev - 1.0).abs() > 1e-6 {
            bad.push(format!("{view}: Ev {} vs {ev}", r.ev_lx));
        }
        n += 1;
    }
    assert!(bad.is_empty(), "{bad:#?}");
    assert_eq!(n, 11);
}

/// `candela glare` with `--background`, `--peak-limit` and `--position-index-up` against
/// evalglare with `-q`, `-Y` and its own convention, on the tilted picture.
#[test]
fn cli_options_match_evalglare() {
    let (dir, cases) = cases();
    let find = |opts: &[&str]| {
        cases
            .iter()
            .find(|c| {
                c["picture"] == "sources_down26.hdr" && c["options"] == serde_json::json!(opts)
            })
            .unwrap()
    };
    let run = |args: &[&str]| -> Value {
        let mut a = vec!["glare", "sources_down26.hdr", "--json", "--draws", "0"];
        a.extend_from_slice(args);
        let (code, out, err) = common::cli(&a, dir);
        assert_eq!(code, 0, "{args:?}: {err}");
        serde_json::from_str(&out).unwrap()
    };
    for (ours, theirs) in [
        (vec![], vec![]),
        (vec!["--background", "mean"], vec!["-q", "1"]),
        (vec!["--background", "ev-over-pi"], vec!["-q", "2"]),
        (vec!["--background", "cie"], vec![]),
        (vec!["--peak-limit", "20000"], vec!["-Y", "20000"]),
        (vec!["--peak-limit", "100000"], vec!["-Y", "100000"]),
        (vec!["--position-index-up", "as-given"], vec![]),
    ] {
        let (r, e) = (run(&ours), find(&theirs));
        println!(
            "{ours:?}: DGP {} UGR {} DGI {}",
            r["dgp"]["value"], r["ugr"]["value"], r["dgi"]["value"]
        );
        for (k, tol) in [("dgp", 2e-6), ("ugr", 2e-4), ("dgi", 2e-4)] {
            let (a, b) = (r[k]["value"].as_f64().unwrap(), e[k].as_f64().unwrap());
            assert!((a - b).abs() <= tol, "{ours:?}: {k} {a} vs evalglare {b}");
        }
        assert!(
            (r["background_cd_m2"].as_f64().unwrap() / e["lb"].as_f64().unwrap() - 1.0).abs()
                < 1e-6
        );
        assert_eq!(
            r["sources"].as_array().unwrap().len(),
            e["sources"].as_array().unwrap().len()
        );
    }
    // The perpendicular up changes the position indices of this tilted view.
    let p = run(&["--position-index-up", "perpendicular"]);
    let e = find(&[]);
    let d = (p["ugr"]["value"].as_f64().unwrap() - e["ugr"].as_f64().unwrap()).abs();
    assert!(d > 0.01, "UGR moved by {d}");
    for bad in [
        vec!["--peak-limit", "0"],
        vec!["--peak-limit", "nan"],
        vec!["--peak-limit", "1000", "--no-peaks"],
        vec!["--background", "median"],
        vec!["--position-index-up", "world"],
    ] {
        let mut a = vec!["glare", "sources_down26.hdr"];
        a.extend_from_slice(&bad);
        let (code, _, err) = common::cli(&a, dir);
        assert_eq!(code, 2, "{bad:?}: {err}");
    }
}

/// Views that no projection can have, or that do not fit their picture, are refused with the
/// file and the VIEW option named, not evaluated.
#[test]
fn impossible_views_are_refused() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("glare_views_refused");
    std::fs::create_dir_all(&dir).unwrap();
    for (k, (view, option)) in [
        ("-vth -vh 300 -vv 300", "-vh 300"),
        ("-vtv -vh 400 -vv 400", "-vh 400"),
        ("-vtv -vh 180 -vv 180", "-vh 180"),
        ("-vta -vh 400 -vv 180", "-vh 400"),
        ("-vts -vh 360 -vv 360", "-vh 360"),
        ("-vta -vh 0 -vv 0", "-vh 0"),
        ("-vta -vh -180 -vv -180", "-vh -180"),
        ("-vta -vh nan -vv 180", "-vh"),
        ("-vta -vh 180 -vv 180 -vu 0 1 0", "-vu"),
        ("-vta -vh 180 -vv 90", "-vh 180 -vv 90"),
        ("-vta -vh 180 -vv 180 -vs 0.3", "-vs 0.3"),
        ("-vtc -vh 180 -vv 180", "-vtc"),
    ]
    .iter()
    .enumerate()
    {
        let name = format!("bad{k}.hdr");
        let mut bytes =
            format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nVIEW= {view}\n\n-Y 8 +X 8\n").into_bytes();
        bytes.extend_from_slice(&[128, 128, 128, 136].repeat(64));
        std::fs::write(dir.join(&name), bytes).unwrap();
        let (code, out, err) = common::cli(&["glare", &name], &dir);
        println!("{view}: {}", err.trim());
        assert_eq!(code, 1, "{view}: {out} {err}");
        assert!(
            err.contains(&name) && err.contains("VIEW") && err.contains(option),
            "{view}: {err}"
        );
    }
}

/// A candela EXR's `projection` attribute: what is behind the eye is left out (a uniform
/// luminance L gives E_v = πL also for a 360° fisheye and an equirectangular image, whose
/// rear half would otherwise cancel the front), and projections out of range are refused.
#[test]
fn exr_projection_attribute_views() {
    use candela::output::{write_exr, Layers, ATTRIBUTE_PROJECTION, CHANNEL_Y};
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("glare_views_exr");
    std::fs::create_dir_all(&dir).unwrap();
    let write = |name: &str, projection: &str, w: usize, h: usize| {
        let layers = Layers {
            width: w,
            height: h,
            channels: vec![(CHANNEL_Y.to_string(), vec![100.0; w * h])],
            attributes: vec![(ATTRIBUTE_PROJECTION.to_string(), projection.to_string())],
        };
        let path = dir.join(name);
        write_exr(&path, &layers).unwrap();
        path
    };
    let pi_l = std::f64::consts::PI * 100.0;
    for (projection, w, h, tol) in [
        // Rim pixels hold the mean over their whole area: the sum is exact to rounding.
        (
            "Fisheye(mapping: Equidistant, fov_deg: 180)",
            200,
            200,
            1e-3,
        ),
        (
            "Fisheye(mapping: Equidistant, fov_deg: 360)",
            200,
            200,
            1e-3,
        ),
        // Pixels across the horizon count by their centre's side: half a row's error.
        ("Equirectangular", 400, 200, 1e-2),
    ] {
        let img = read_glare_image(&write("a.exr", projection, w, h)).unwrap();
        let r = evaluate(&img, &GlareOptions::default()).unwrap();
        println!("{projection}: Ev {:.3} πL {pi_l:.3}", r.ev_lx);
        assert!(
            (r.ev_lx / pi_l - 1.0).abs() < tol,
            "{projection}: Ev {}",
            r.ev_lx
        );
    }
    for bad in [
        "Fisheye(mapping: Orthographic, fov_deg: 300)",
        "Fisheye(mapping: Equidistant, fov_deg: 400)",
        "Fisheye(mapping: Stereographic, fov_deg: 0)",
        "Perspective(vfov_deg: 180)",
        "Perspective(vfov_deg: -10)",
    ] {
        let path = write("bad.exr", bad, 16, 16);
        let e = read_glare_image(&path).unwrap_err().to_string();
        assert!(
            e.contains("bad.exr") && e.contains("projection"),
            "{bad}: {e}"
        );
    }
}
