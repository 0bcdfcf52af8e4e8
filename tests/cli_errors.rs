//! Bad input ends with one clear message (file, line:column or field), exit code 1 (not a
//! panic's 101), and no output file; a wrong command line ends with exit code 2, as clap's own
//! usage errors do (docs/guarantees.md).

mod common;
use common::listing;
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
    run_with(text, extra_files, &[])
}

/// [`run`] with extra `render` options.
fn run_with(
    text: &str,
    extra_files: &[(&str, &[u8])],
    options: &[&str],
) -> (i32, String, Vec<String>) {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.ron");
    std::fs::write(&scene, text).unwrap();
    for (name, bytes) in extra_files {
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .args(["render", "--quiet"])
        .args(options)
        .arg("--out")
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
    assert_eq!(
        files,
        vec!["scene.exr", "scene.hdr", "scene.png", "scene.report.json"]
    );
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

/// Run `candela ARGS` in `dir`; returns (exit code, stderr).
fn candela_in(dir: &Path, args: &[&str]) -> (i32, String) {
    let (code, _, stderr) = common::cli(args, dir);
    (code, stderr)
}

/// Exit code 1, no panic, and every needle in the message.
fn assert_refused(code: i32, stderr: &str, needles: &[&str]) {
    assert_refused_with(1, code, stderr, needles);
}

/// A wrong command line: exit code 2, one line, every needle in the message.
fn assert_usage(code: i32, stderr: &str, needles: &[&str]) {
    assert_refused_with(2, code, stderr, needles);
}

fn assert_refused_with(expected: i32, code: i32, stderr: &str, needles: &[&str]) {
    assert_eq!(code, expected, "exit code {code}, stderr:\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(
        stderr.trim_end().lines().count(),
        1,
        "not a one-paragraph message:\n{stderr}"
    );
    for n in needles {
        assert!(stderr.contains(n), "message lacks {n:?}:\n{stderr}");
    }
}

#[test]
fn luminaire_diagram_over_the_input_is_refused() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/luminaires");
    for name in ["batwing-office.ldt", "narrow-spot.ies"] {
        let dir = tempfile::tempdir().unwrap();
        let original = std::fs::read(data.join(name)).unwrap();
        std::fs::write(dir.path().join(name), &original).unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        // The same path, and the same file by another path.
        for diagram in [name.to_string(), format!("sub/../{name}")] {
            let (code, stderr) =
                candela_in(dir.path(), &["luminaire", name, "--diagram", &diagram]);
            assert_refused(code, &stderr, &[name, "--diagram", "refusing to overwrite"]);
            assert_eq!(std::fs::read(dir.path().join(name)).unwrap(), original);
            assert_eq!(listing(dir.path()), vec![name.to_string(), "sub".into()]);
        }
    }
}

#[test]
fn absurd_thread_counts_are_refused() {
    let (code, stderr, files) = run_with(GOOD, &[], &["--threads", "100000"]);
    assert_usage(code, &stderr, &["--threads", "100000"]);
    assert!(
        files.is_empty(),
        "output written despite the error: {files:?}"
    );
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["bench", "--threads", "100000"][..],
        &["bench", "scaling", "--threads", "100000"],
        &["bench", "traversal", "--threads", "1,100000"],
    ] {
        let (code, stderr) = candela_in(dir.path(), args);
        assert_usage(code, &stderr, &["--threads", "100000"]);
    }
    assert!(listing(dir.path()).is_empty());
}

#[test]
fn render_exposure_out_of_range_is_refused() {
    for ev in ["-1e308", "1e308", "101", "nan"] {
        let (code, stderr, files) = run_with(GOOD, &[], &["--exposure", ev]);
        assert_usage(code, &stderr, &["--exposure"]);
        assert!(
            files.is_empty(),
            "output written despite the error: {files:?}"
        );
    }
    let (code, stderr, _) = run_with(GOOD, &[], &["--exposure", "-20"]);
    assert_eq!(code, 0, "{stderr}");
}

/// A directory holding `a.state` and `b.state`: renders of [`GOOD`] with seeds 1 and 2.
fn two_states() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.ron"), GOOD).unwrap();
    common::render_states(dir.path(), "scene.ron", &[("a", "1"), ("b", "2")]);
    dir
}

#[test]
fn merge_exposure_is_checked_before_writing() {
    let dir = two_states();
    let before = listing(dir.path());
    for ev in ["nan", "-1e308", "1e308"] {
        let (code, stderr) = candela_in(
            dir.path(),
            &["merge", "a.state", "b.state", "-o", "out", "--exposure", ev],
        );
        assert_usage(code, &stderr, &["--exposure"]);
        assert_eq!(
            listing(dir.path()),
            before,
            "output written despite the error"
        );
    }
}

#[test]
fn merge_output_over_an_input_is_refused() {
    let dir = two_states();
    let before = listing(dir.path());
    let original = std::fs::read(dir.path().join("a.state")).unwrap();
    for out in ["a", "a.state", "./a.exr"] {
        let (code, stderr) = candela_in(dir.path(), &["merge", "a.state", "b.state", "-o", out]);
        assert_refused(code, &stderr, &["a.state", "refusing to overwrite"]);
        assert_eq!(std::fs::read(dir.path().join("a.state")).unwrap(), original);
        assert_eq!(
            listing(dir.path()),
            before,
            "output written despite the error"
        );
    }
}

#[test]
fn merge_into_a_directory_writes_merged_files_there() {
    let dir = two_states();
    std::fs::create_dir(dir.path().join("out")).unwrap();
    let (code, stderr) = candela_in(dir.path(), &["merge", "a.state", "b.state", "-o", "out"]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(
        listing(&dir.path().join("out")),
        vec!["merged.exr", "merged.hdr", "merged.png", "merged.state"]
    );
    let before = listing(dir.path());
    for out in ["missing/", "missing/c", "/nonexistent/c"] {
        let (code, stderr) = candela_in(dir.path(), &["merge", "a.state", "b.state", "-o", out]);
        assert_refused(code, &stderr, &[out, "does not exist"]);
        assert_eq!(
            listing(dir.path()),
            before,
            "output written despite the error"
        );
    }
}

#[test]
fn os_error_text_appears_once() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let missing = dir.path().join("missing.ron");
    let m = missing.to_str().unwrap();
    for args in [
        &["render", "--quiet", d][..],
        &["luminaire", d],
        &["render", "--quiet", m],
        &["luminaire", m],
    ] {
        let (code, stderr) = candela_in(dir.path(), args);
        assert_refused(code, &stderr, &[args[args.len() - 1]]);
        // The cause, the system's or candela's own, is given once.
        let causes =
            stderr.matches("(os error").count() + stderr.matches("not a regular file").count();
        assert_eq!(causes, 1, "repeated cause:\n{stderr}");
    }
    assert!(listing(dir.path()).is_empty());
}

#[test]
fn bench_bad_counts_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["bench", "--triangles", "18446744073709551615"],
            "--triangles",
        ),
        (&["bench", "--spp", "0"], "--spp"),
        (&["bench", "traversal", "--resolution", "0"], "--resolution"),
        (&["bench", "traversal", "--reps", "0"], "--reps"),
        (
            &["bench", "traversal", "--triangles", "1000000000"],
            "--triangles",
        ),
        (
            &["bench", "scaling", "--triangles", "10000,1000000000"],
            "--triangles",
        ),
        (&["bench", "scaling", "--spp", "0"], "--spp"),
        (&["bench", "scaling", "--reps", "0"], "--reps"),
    ];
    for (args, flag) in cases {
        let (code, stderr) = candela_in(dir.path(), args);
        assert_usage(code, &stderr, &[flag]);
        assert!(!stderr.contains("cornell-box.ron"), "{stderr}");
    }
    assert!(listing(dir.path()).is_empty());
}

#[test]
fn exit_code_2_for_the_command_line_1_for_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.ron"), GOOD).unwrap();
    // Parsed by clap: its own message shape (several lines), exit 2.
    for args in [
        &["render", "--bogus", "s.ron"][..],
        &["render", "--spp", "many", "s.ron"],
        &["render", "--resume", "--overwrite", "s.ron"],
        &["probe"],
    ] {
        let (code, _, stderr) = common::cli(args, d);
        assert_eq!(code, 2, "{args:?}: exit code {code}, stderr:\n{stderr}");
    }
    // Values clap accepts and candela refuses: exit 2 too, before any file is read (the files
    // named here do not exist).
    let cases: &[(&[&str], &str)] = &[
        (&["render", "--spp", "0", "s.ron"], "--spp"),
        (&["render", "--max-spp", "0", "s.ron"], "--max-spp"),
        (
            &["render", "--target-fraction", "2", "s.ron"],
            "--target-fraction",
        ),
        (
            &["render", "--target-floor", "-1", "s.ron"],
            "--target-floor",
        ),
        (&["render", "--threads", "0", "missing.ron"], "--threads"),
        (
            &["probe", "missing.exr", "0", "0", "--radius", "-1"],
            "--radius",
        ),
        (
            &["probe", "missing.exr", "0", "0", "--radius", "nan"],
            "--radius",
        ),
        (&["falsecolour", "missing.exr", "--range", "5:1"], "--range"),
        (&["falsecolour", "missing.exr", "--range", "a:b"], "--range"),
        (
            &["falsecolour", "missing.exr", "--steps", "5000"],
            "--steps",
        ),
        (
            &[
                "falsecolour",
                "missing.exr",
                "--scale",
                "log",
                "--range",
                "0:10",
            ],
            "--scale log",
        ),
        (
            &[
                "merge",
                "x.state",
                "y.state",
                "-o",
                "m",
                "--exposure",
                "inf",
            ],
            "--exposure",
        ),
        (&["convert", "1", "lx", "cd"], "lux"),
        (&["convert", "1", "furlong", "lx"], "furlong"),
    ];
    for (args, flag) in cases {
        let (code, _, stderr) = common::cli(args, d);
        assert_usage(code, &stderr, &[flag]);
    }
    // Files that are missing or wrong: exit 1.
    std::fs::write(d.join("bad.exr"), "not an image").unwrap();
    for args in [
        &["render", "--quiet", "missing.ron"][..],
        &["probe", "missing.exr", "0", "0"],
        &["probe", "bad.exr", "0", "0"],
        &["falsecolour", "bad.exr"],
        &["luminaire", "missing.ies"],
        &["merge", "x.state", "y.state", "-o", "m"],
        &["spectrum", "missing.csv"],
    ] {
        let (code, _, stderr) = common::cli(args, d);
        assert_eq!(code, 1, "{args:?}: exit code {code}, stderr:\n{stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    assert_eq!(listing(d), vec!["bad.exr", "s.ron"]);
}

/// No carriage return, NUL or escape byte in `bytes`, and the escape sequence shown escaped.
fn assert_escaped(bytes: &[u8]) {
    let shown = String::from_utf8_lossy(bytes);
    for byte in [b'\r', 0, 0x1b] {
        assert!(!bytes.contains(&byte), "raw byte {byte:#x} in:\n{shown:?}");
    }
    assert!(shown.contains("gr\\u{d}\\u{0}\\u{1b}[31m"), "{shown:?}");
}

#[test]
fn control_characters_from_the_input_are_escaped_in_messages() {
    // A carriage return, a NUL and ANSI escape sequences (red text, clear screen): in a scene
    // field (a spectrum file name), in a value of a CSV spectrum, in a luminaire's header.
    let evil = "gr\r\0\u{1b}[31m\u{1b}[2Jey";
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/luminaires");
    let mut ies = std::fs::read_to_string(data.join("narrow-spot.ies")).unwrap();
    ies.insert_str(ies.find('\n').unwrap() + 1, &format!("[TEST] {evil}\n"));
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let field = GOOD.replace("Constant(0.5)", &format!("Csv(\"{evil}.csv\")"));
    std::fs::write(d.join("field.ron"), field).unwrap();
    std::fs::write(
        d.join("value.ron"),
        GOOD.replace("Constant(0.5)", r#"Csv("w.csv")"#),
    )
    .unwrap();
    std::fs::write(
        d.join("w.csv"),
        format!("nm,value\n360,0.5\n400,{evil}\n830,0.5\n"),
    )
    .unwrap();
    std::fs::write(d.join("evil.ies"), ies).unwrap();
    for scene in ["field.ron", "value.ron"] {
        let out = Command::new(env!("CARGO_BIN_EXE_candela"))
            .current_dir(d)
            .args(["render", "--quiet", scene])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1));
        assert_escaped(&out.stderr);
        let shown = String::from_utf8_lossy(&out.stderr);
        assert_eq!(shown.trim_end().lines().count(), 1, "{shown:?}");
    }
    // Standard output too: the header line is printed, escaped.
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .current_dir(d)
        .args(["luminaire", "evil.ies", "--diagram", "d.png"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert_escaped(&out.stdout);
}

#[test]
fn falsecolour_over_its_input_is_refused_by_any_path() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.ron"), GOOD).unwrap();
    let (code, stderr) = candela_in(d, &["render", "--quiet", "s.ron"]);
    assert_eq!(code, 0, "{stderr}");
    std::fs::create_dir(d.join("sub")).unwrap();
    let original = std::fs::read(d.join("s.exr")).unwrap();
    let before = listing(d);
    for out in ["s.exr", "./s.exr", "sub/../s.exr"] {
        let (code, stderr) = candela_in(d, &["falsecolour", "s.exr", "-o", out]);
        assert_refused(
            code,
            &stderr,
            &["refusing to overwrite the input image", "s.exr"],
        );
        assert_eq!(std::fs::read(d.join("s.exr")).unwrap(), original);
        assert_eq!(listing(d), before);
    }
}
