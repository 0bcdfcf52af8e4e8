//! Bad input ends with one clear message (file, line:column or field), exit code 1 (not a
//! panic's 101), and no output file.

use std::path::Path;
use std::process::Command;

const GOOD: &str = r#"(
    camera: (position: (0, 0, 0), look_at: (0, 0, 1), vfov_deg: 30, resolution: (4, 4)),
    render: (spp: 2),
    materials: { "grey": Diffuse(reflectance: Constant(0.5)) },
    objects: [(shape: Sphere(center: (0, 0, 3), radius: 1), material: "grey")],
    lights: [Point(position: (0, 2, 0), spectrum: Named("D65"), amount: Intensity(10.0))],
)"#;

/// Run `candela render` on `text` in a fresh directory; returns (exit code, stderr, files left).
fn run(text: &str, extra_files: &[(&str, &[u8])]) -> (i32, String, Vec<String>) {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.ron");
    std::fs::write(&scene, text).unwrap();
    for (name, bytes) in extra_files {
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .args(["render", "--quiet", "--out"])
        .arg(dir.path())
        .arg(&scene)
        .output()
        .unwrap();
    let mut files: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "scene.ron" && !extra_files.iter().any(|(f, _)| f == n))
        .collect();
    files.sort();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
        files,
    )
}

fn expect_error(text: &str, extra: &[(&str, &[u8])], needles: &[&str]) {
    let (code, stderr, files) = run(text, extra);
    assert_eq!(code, 1, "exit code {code}, stderr:\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        files.is_empty(),
        "output written despite the error: {files:?}"
    );
    assert!(
        stderr.contains("scene.ron"),
        "message does not name the file:\n{stderr}"
    );
    for n in needles {
        assert!(stderr.contains(n), "message lacks {n:?}:\n{stderr}");
    }
}

#[test]
fn good_scene_renders_all_outputs() {
    let (code, stderr, files) = run(GOOD, &[]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(files, vec!["scene.exr", "scene.png", "scene.report.json"]);
}

#[test]
fn syntax_error_names_line_and_column() {
    let text = GOOD.replace("vfov_deg: 30,", "vfov_deg: 30,,");
    expect_error(&text, &[], &["scene.ron:2:"]);
}

#[test]
fn unknown_field() {
    let text = GOOD.replace("vfov_deg: 30", "vfov_deg: 30, fov: 3");
    expect_error(&text, &[], &["fov"]);
}

#[test]
fn negative_amount() {
    let text = GOOD.replace("Intensity(10.0)", "Intensity(-10.0)");
    expect_error(&text, &[], &["lights[0].amount", "negative"]);
}

#[test]
fn nan_amount() {
    let text = GOOD.replace("Intensity(10.0)", "Intensity(NaN)");
    expect_error(&text, &[], &["lights[0].amount", "finite"]);
}

#[test]
fn zero_resolution() {
    let text = GOOD.replace("resolution: (4, 4)", "resolution: (0, 4)");
    expect_error(&text, &[], &["camera.resolution"]);
}

#[test]
fn huge_resolution_is_refused_not_allocated() {
    let text = GOOD.replace("resolution: (4, 4)", "resolution: (4000000, 4000000)");
    expect_error(&text, &[], &["camera.resolution", "exceeds"]);
}

#[test]
fn reflectance_above_one() {
    let text = GOOD.replace("Constant(0.5)", "Constant(1.2)");
    expect_error(&text, &[], &["materials[\"grey\"].reflectance", "above 1"]);
}

#[test]
fn unknown_spectrum_name() {
    let text = GOOD.replace("Named(\"D65\")", "Named(\"D66\")");
    expect_error(&text, &[], &["lights[0].spectrum", "D66"]);
}

#[test]
fn unknown_material() {
    let text = GOOD.replace("material: \"grey\"", "material: \"gray\"");
    expect_error(&text, &[], &["objects[0].material", "gray"]);
}

#[test]
fn missing_mesh_file() {
    let text = GOOD.replace(
        "Sphere(center: (0, 0, 3), radius: 1)",
        "Obj(\"nowhere.obj\")",
    );
    expect_error(&text, &[], &["objects[0].shape", "nowhere.obj"]);
}

#[test]
fn corrupt_ply_file() {
    let text = GOOD.replace("Sphere(center: (0, 0, 3), radius: 1)", "Ply(\"bad.ply\")");
    let ply = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0";
    expect_error(&text, &[("bad.ply", ply)], &["bad.ply"]);
}

#[test]
fn malformed_csv_spectrum() {
    let text = GOOD.replace("Constant(0.5)", "Csv(\"refl.csv\")");
    expect_error(
        &text,
        &[("refl.csv", b"nm,value\n400,0.5\n500,abc\n")],
        &["refl.csv"],
    );
}

#[test]
fn missing_scene_file() {
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .args(["render", "--quiet", "/nonexistent/scene.ron"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("/nonexistent/scene.ron"), "{stderr}");
}

#[test]
fn out_file_name_is_respected() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.ron");
    std::fs::write(&scene, GOOD).unwrap();
    let target = dir.path().join("named.exr");
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .args(["render", "--quiet", "--out"])
        .arg(&target)
        .arg(&scene)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(Path::new(&dir.path().join("named.exr")).exists());
    assert!(Path::new(&dir.path().join("named.png")).exists());
}
