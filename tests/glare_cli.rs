//! `candela glare` on candela's own fisheye renders: a room with a window under an overcast sky
//! and a bright ceiling luminaire in view, seen through a 180° angular fisheye.
//! - E_v of the image (Σ L ∫cos θ dω) equals an illuminance meter at the eye facing the line
//!   of sight, within their combined standard errors;
//! - the EXR (with its per-pixel standard errors) and the Radiance picture give the same
//!   indices to RGBE precision, and the EXR's indices carry intervals;
//! - evalglare (Radiance 6) on candela's `.hdr` finds the same DGP within 0.01 and UGR/DGI
//!   within 0.5, and the same number of sources.

mod common;
use common::python_json;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

const SCENE: &str = r#"(
    camera: (position: (0, 1.2, 0.5), look_at: (0, 1.2, 2), resolution: (160, 160),
             projection: Fisheye(mapping: Equidistant, fov_deg: 180.0)),
    render: (spp: 64, seed: 3),
    materials: {
        "wall": Diffuse(reflectance: Constant(0.5)),
        "lamp": Diffuse(reflectance: Constant(0.0)),
    },
    objects: [
        (material: "wall", shape: Quad(origin: (-2, 0, -2), edge_u: (0, 0, 4), edge_v: (4, 0, 0))),
        (material: "wall", shape: Quad(origin: (-2, 3, -2), edge_u: (4, 0, 0), edge_v: (0, 0, 4))),
        (material: "wall", shape: Quad(origin: (-2, 0, -2), edge_u: (4, 0, 0), edge_v: (0, 3, 0))),
        (material: "wall", shape: Quad(origin: (-2, 0, -2), edge_u: (0, 3, 0), edge_v: (0, 0, 4))),
        (material: "wall", shape: Quad(origin: (2, 0, -2), edge_u: (0, 0, 4), edge_v: (0, 3, 0))),
        (material: "wall", shape: Quad(origin: (-2, 0, 2), edge_u: (0, 0.9, 0), edge_v: (4, 0, 0))),
        (material: "wall", shape: Quad(origin: (-2, 2.1, 2), edge_u: (0, 0.9, 0), edge_v: (4, 0, 0))),
        (material: "wall", shape: Quad(origin: (-2, 0.9, 2), edge_u: (0, 1.2, 0), edge_v: (1, 0, 0))),
        (material: "wall", shape: Quad(origin: (1, 0.9, 2), edge_u: (0, 1.2, 0), edge_v: (1, 0, 0))),
        (material: "lamp", shape: Quad(origin: (-0.3, 2.98, 1.0), edge_u: (0.6, 0, 0), edge_v: (0, 0, 0.6)),
         emission: (spectrum: Named("D65"), amount: Luminance(20000.0))),
    ],
    lights: [Sky(model: CieOvercast, amount: HorizontalIlluminance(10000.0),
                 portals: [(origin: (-1, 0.9, 2), edge_u: (2, 0, 0), edge_v: (0, 1.2, 0))])],
    meters: [Illuminance(name: "eye", position: (0, 1.2, 0.5), normal: (0, 0, 1))],
    measure: (samples: 65536),
)"#;

fn glare(image: &Path) -> Value {
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .arg("glare")
        .arg(image)
        .arg("--json")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "candela glare {}: {}",
        image.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn glare_of_candela_fisheye_renders() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("glare_cli");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("room.ron");
    std::fs::write(&scene, SCENE).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .current_dir(&dir)
        .args(["render", "room.ron"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "render: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: Value =
        serde_json::from_slice(&std::fs::read(dir.join("room.report.json")).unwrap()).unwrap();
    let meter = &report["meters"][0];
    let (e_meter, se_meter) = (
        meter["value"].as_f64().unwrap(),
        meter["stderr"].as_f64().unwrap(),
    );

    let exr = glare(&dir.join("room.exr"));
    let hdr = glare(&dir.join("room.hdr"));
    let ev = exr["ev_lx"]["value"].as_f64().unwrap();
    let ci = exr["ev_lx"]["ci95"].as_array().unwrap();
    let half = (ci[1].as_f64().unwrap() - ci[0].as_f64().unwrap()) / 2.0;
    // The interval's half-width is t·sd of the draws; as a standard error, about half of it.
    let se_ev = half / 2.0;
    println!(
        "E_v: image {ev:.2} (95 % CI ± {half:.2}) lx, meter {e_meter:.2} ± {se_meter:.2} lx; \
         DGP {:.4} (EXR) {:.4} (HDR); UGR {:.2} / {:.2}; sources {} / {}",
        exr["dgp"]["value"],
        hdr["dgp"]["value"],
        exr["ugr"]["value"],
        hdr["ugr"]["value"],
        exr["sources"].as_array().unwrap().len(),
        hdr["sources"].as_array().unwrap().len()
    );
    assert!(
        (ev - e_meter).abs() <= 5.0 * (se_ev * se_ev + se_meter * se_meter).sqrt(),
        "E_v {ev} vs meter {e_meter}"
    );
    assert!(half > 0.0, "the EXR's indices carry intervals");
    for k in ["dgp", "ev_lx"] {
        let (a, b) = (
            exr[k]["value"].as_f64().unwrap(),
            hdr[k]["value"].as_f64().unwrap(),
        );
        assert!(
            (a - b).abs() <= 0.01 * a.abs().max(1e-9),
            "{k}: EXR {a}, HDR {b}"
        );
    }

    // evalglare on the same picture.
    let hdr_path = dir.join("room.hdr");
    let eg = python_json("glare/evalglare_file.py", &[hdr_path.as_os_str()], None);
    println!("evalglare: {eg}");
    let near = |k: &str, ours: &Value, tol: f64| {
        let (a, b) = (ours["value"].as_f64().unwrap(), eg[k].as_f64().unwrap());
        assert!((a - b).abs() <= tol, "{k}: candela {a}, evalglare {b}");
    };
    near("dgp", &hdr["dgp"], 0.01);
    near("ugr", &hdr["ugr"], 0.5);
    near("dgi", &hdr["dgi"], 0.5);
    assert_eq!(
        hdr["sources"].as_array().unwrap().len() as f64,
        eg["sources"].as_f64().unwrap()
    );
    let ev_eg = eg["ev"].as_f64().unwrap();
    let ev_hdr = hdr["ev_lx"]["value"].as_f64().unwrap();
    assert!(
        (ev_eg / ev_hdr - 1.0).abs() < 0.01,
        "E_v: evalglare {ev_eg}, candela {ev_hdr}"
    );
}

/// Images without a projection, and bad options, are refused with their reason.
#[test]
fn glare_refuses_what_it_cannot_evaluate() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("glare_cli_errors");
    std::fs::create_dir_all(&dir).unwrap();
    let missing = dir.join("missing.exr");
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .args(["glare", missing.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing.exr"));
    // A Radiance picture without a VIEW line.
    let pic = dir.join("noview.hdr");
    let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n".to_vec();
    bytes.extend_from_slice(&[128, 128, 128, 129].repeat(4));
    std::fs::write(&pic, bytes).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .args(["glare", pic.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("noview.hdr") && err.contains("projection"),
        "{err}"
    );
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .args(["glare", pic.to_str().unwrap(), "--threshold", "-3"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}
