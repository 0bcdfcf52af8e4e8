//! candela's glare evaluation against evalglare 3.06 (Radiance 6, PyPI `pyradiance`) on
//! fisheye images that Radiance renders itself (tests/glare/evalglare_cases.py): a room with a
//! low winter sun in view, the same room seen away from the sun (a sun patch on the floor),
//! an overcast window, an office with four ceiling luminaires; each with evalglare's defaults
//! and other options (-x, -b factor, -t task, -r). The pixels are read back with pvalue and
//! evaluated with the -vta geometry; DGP must agree within 0.01, UGR and DGI within 0.5, the
//! vertical illuminance within 1 %, and the number of sources exactly.

mod common;
use common::python;

use candela::glare::{
    angular_fisheye, evaluate, DetectOptions, GlareImage, GlareOptions, Task, Threshold,
};
use serde_json::Value;
use std::path::PathBuf;
use std::process::Command;

fn options(args: &[String], width: usize, height: usize) -> GlareOptions {
    let mut o = GlareOptions::default();
    let mut d = DetectOptions::default();
    let mut b = None;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut num = || it.next().unwrap().parse::<f64>().unwrap();
        match a.as_str() {
            "-x" => d.peak_limit_cd_m2 = None,
            "-r" => d.search_angle_rad = num(),
            "-b" => b = Some(num()),
            "-t" => {
                // evalglare's pixel y counts from the bottom row.
                let (x, y, angle) = (num() as usize, num() as usize, num());
                d = DetectOptions {
                    task: Some(Task {
                        col: x,
                        row: height - 1 - y,
                        angle_rad: angle,
                    }),
                    threshold: Threshold::Multiple { factor: 5.0 },
                    ..d
                };
            }
            other => panic!("option {other} not mapped"),
        }
    }
    if let Some(b) = b {
        d.threshold = Threshold::from_evalglare_b(b);
    }
    assert!(width > 0);
    o.detect = d;
    o
}

#[test]
fn indices_match_evalglare_on_radiance_fisheye_images() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("glare_evalglare");
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/glare/evalglare_cases.py");
    let out = Command::new(python())
        .arg(script)
        .arg(&dir)
        .output()
        .expect("run python");
    assert!(
        out.status.success(),
        "evalglare_cases.py failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let cases: Vec<Value> = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(cases.len(), 9);
    let mut images = std::collections::HashMap::new();
    for c in &cases {
        let name = c["image"].as_str().unwrap().to_string();
        let (w, h) = (
            c["width"].as_u64().unwrap() as usize,
            c["height"].as_u64().unwrap() as usize,
        );
        let img = images.entry(name.clone()).or_insert_with(|| {
            let bytes = std::fs::read(dir.join(format!("{name}.f64"))).unwrap();
            let lum: Vec<f64> = bytes
                .chunks_exact(8)
                .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
                .collect();
            assert_eq!(lum.len(), w * h);
            let (direction, solid_angle_sr, inside) = angular_fisheye(w, h, 180.0, 180.0);
            GlareImage {
                width: w,
                height: h,
                luminance_cd_m2: lum,
                stderr_cd_m2: None,
                direction,
                solid_angle_sr,
                inside,
                view_dir: [0.0, 0.0, 1.0],
                up: [0.0, 1.0, 0.0],
            }
        });
        let args: Vec<String> = c["options"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().to_string())
            .collect();
        let r = evaluate(img, &options(&args, w, h)).unwrap();
        let f = |k: &str| c[k].as_f64().unwrap();
        let label = format!("{name} {args:?}");
        println!(
            "{label}: DGP {:.4}/{:.4} UGR {:.2}/{:.2} DGI {:.2}/{:.2} Ev {:.1}/{:.1} sources {}/{}",
            r.dgp,
            f("dgp"),
            r.ugr,
            f("ugr"),
            r.dgi,
            f("dgi"),
            r.ev_lx,
            f("ev"),
            r.sources.len(),
            c["sources"].as_array().unwrap().len()
        );
        // Every case has glare sources, so that the indices are tested, not their defaults.
        assert!(!c["sources"].as_array().unwrap().is_empty(), "{label}");
        assert!((r.ev_lx / f("ev") - 1.0).abs() < 0.01, "{label}: Ev");
        assert_eq!(
            r.sources.len(),
            c["sources"].as_array().unwrap().len(),
            "{label}: number of sources"
        );
        assert!((r.dgp - f("dgp")).abs() <= 0.01, "{label}: DGP");
        assert!((r.ugr - f("ugr")).abs() <= 0.5, "{label}: UGR");
        assert!((r.dgi - f("dgi")).abs() <= 0.5, "{label}: DGI");
        assert!((r.cgi - f("cgi")).abs() <= 0.5, "{label}: CGI");
        assert!((r.vcp - f("vcp")).abs() <= 1.0, "{label}: VCP");
        assert!(
            (r.background_cd_m2 / f("lb") - 1.0).abs() < 0.01,
            "{label}: background luminance"
        );
    }
}
