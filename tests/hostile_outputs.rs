//! `candela render` never replaces its own inputs or an earlier render's state, checks its
//! outputs can be written before it renders, and writes every output it can when some fail.

mod common;
use candela::job::{self, Outcome, Progress, RenderJob};
use common::listing;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// A 4×4 scene; `{WALL}` is the wall's reflectance, `{MESH}` extra objects, `{LIGHT}` extra
/// lights, `{GRIDS}` its grids.
const TEMPLATE: &str = r#"(
    camera: (position: (0, 0, 0), look_at: (0, 0, 1), vfov_deg: 30, resolution: (4, 4)),
    render: (spp: 2),
    materials: { "grey": Diffuse(reflectance: {WALL}) },
    objects: [(shape: Sphere(center: (0, 0, 3), radius: 1), material: "grey"){MESH}],
    lights: [Point(position: (0, 2, 0), spectrum: Named("D65"), amount: Intensity(10.0)){LIGHT}],
    grids: [{GRIDS}],
)"#;

fn scene(wall: &str, mesh: &str, light: &str, grids: &str) -> String {
    TEMPLATE
        .replace("{WALL}", wall)
        .replace("{MESH}", mesh)
        .replace("{LIGHT}", light)
        .replace("{GRIDS}", grids)
}

fn plain() -> String {
    scene("Constant(0.5)", "", "", "")
}

/// A grid named `name` on the sphere's side facing the camera.
fn grid(name: &str) -> String {
    format!(
        "(name: {name:?}, origin: (-0.5, -0.5, 1.9), edge_u: (1, 0, 0), edge_v: (0, 1, 0), nx: 2, ny: 2, normal: (0, 0, -1))"
    )
}

/// Exit code 1, one line naming every needle, and the directory exactly as before.
fn assert_refused_untouched(
    dir: &Path,
    args: &[&str],
    needles: &[&str],
    before: &[(String, Vec<u8>)],
) -> String {
    let (code, _, stderr) = common::cli(args, dir);
    assert_eq!(code, 1, "exit code {code}, stderr:\n{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    for n in needles {
        assert!(stderr.contains(n), "message lacks {n:?}:\n{stderr}");
    }
    let after: Vec<(String, Vec<u8>)> = listing(dir)
        .into_iter()
        .filter(|n| !Path::new(&dir.join(n)).is_dir())
        .map(|n| {
            let bytes = std::fs::read(dir.join(&n)).unwrap();
            (n, bytes)
        })
        .collect();
    assert_eq!(
        after.len(),
        before.len(),
        "files changed: {:?}",
        listing(dir)
    );
    for ((a, x), (b, y)) in after.iter().zip(before) {
        assert_eq!(a, b);
        assert!(x == y, "{a} was changed");
    }
    stderr
}

/// The files of `dir` with their contents.
fn snapshot(dir: &Path) -> Vec<(String, Vec<u8>)> {
    listing(dir)
        .into_iter()
        .filter(|n| !Path::new(&dir.join(n)).is_dir())
        .map(|n| {
            let bytes = std::fs::read(dir.join(&n)).unwrap();
            (n, bytes)
        })
        .collect()
}

#[test]
fn a_scene_named_like_an_output_is_not_replaced() {
    for name in ["room.png", "room.exr", "room.state"] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join(name), plain()).unwrap();
        let before = snapshot(dir.path());
        assert_refused_untouched(
            dir.path(),
            &["render", "--quiet", name],
            &["refusing to overwrite the scene file", name],
            &before,
        );
    }
}

#[test]
fn referenced_files_named_like_outputs_are_not_replaced() {
    let ies = std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/luminaires/narrow-spot.ies"),
    )
    .unwrap();
    let obj = b"v -0.2 -0.2 2\nv 0.2 -0.2 2\nv 0 0.2 2\nf 1 2 3\n".to_vec();
    let csv = b"nm,value\n360,0.5\n830,0.5\n".to_vec();
    let light = r#", Goniometric(file: "s.state", position: (0, 2, 1), spectrum: Named("A"))"#;
    let mesh = r#", (shape: Obj("s.report.json"), material: "grey")"#;
    let cases: Vec<(String, &str, Vec<u8>, &[&str])> = vec![
        // A spectrum, a mesh and a luminaire, each named like one of the outputs.
        (
            scene(r#"Csv("s.png")"#, "", "", ""),
            "s.png",
            csv.clone(),
            &[],
        ),
        (
            scene("Constant(0.5)", mesh, "", ""),
            "s.report.json",
            obj,
            &[],
        ),
        (scene("Constant(0.5)", "", light, ""), "s.state", ies, &[]),
        // Only a job that writes the false-colour map or the grid files writes over them.
        (
            scene(r#"Csv("s.luminance.png")"#, "", "", ""),
            "s.luminance.png",
            csv.clone(),
            &["--falsecolour"],
        ),
        (
            scene(r#"Csv("s.grid-desk.csv")"#, "", "", &grid("Desk")),
            "s.grid-desk.csv",
            csv,
            &[],
        ),
    ];
    for (text, file, bytes, options) in cases {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("s.ron"), &text).unwrap();
        std::fs::write(dir.path().join(file), &bytes).unwrap();
        let before = snapshot(dir.path());
        let mut args = vec!["render", "--quiet"];
        args.extend_from_slice(options);
        args.push("s.ron");
        assert_refused_untouched(
            dir.path(),
            &args,
            &["refusing to overwrite the file the scene refers to", file],
            &before,
        );
    }
}

#[test]
fn the_same_file_by_another_name_is_not_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir(d.join("sub")).unwrap();
    std::fs::write(d.join("sub/s.ron"), scene(r#"Csv("../w.png")"#, "", "", "")).unwrap();
    std::fs::write(d.join("w.png"), "nm,value\n360,0.5\n830,0.5\n").unwrap();
    std::os::unix::fs::symlink(d, d.join("sub/up")).unwrap();
    let before = snapshot(d);
    // The spectrum's directory entry reached through `..` and through a symbolic link to its
    // directory.
    for out in ["sub/../w", "sub/up/w", "./w.exr"] {
        assert_refused_untouched(
            d,
            &["render", "--quiet", "--out", out, "sub/s.ron"],
            &[
                "refusing to overwrite the file the scene refers to",
                "w.png",
            ],
            &before,
        );
    }
    // A hard link to the spectrum with an output's name.
    std::fs::hard_link(d.join("w.png"), d.join("h.png")).unwrap();
    let before = snapshot(d);
    assert_refused_untouched(
        d,
        &["render", "--quiet", "--out", "h", "sub/s.ron"],
        &[
            "refusing to overwrite the file the scene refers to",
            "h.png",
        ],
        &before,
    );
    // The scene itself, by a symbolic link named like an output.
    std::os::unix::fs::symlink(d.join("sub/s.ron"), d.join("sub/s.png")).unwrap();
    assert_refused_untouched(
        d,
        &["render", "--quiet", "--out", "sub/", "sub/s.png"],
        &["refusing to overwrite the scene file", "s.png"],
        &before,
    );
}

#[test]
fn an_earlier_state_is_kept_unless_resumed_or_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.ron"), plain()).unwrap();
    let (code, _, stderr) = common::cli(&["render", "--quiet", "--save-state", "s.ron"], d);
    assert_eq!(code, 0, "{stderr}");
    // The first render has 2 spp; a resumed one adds to it.
    let (code, _, stderr) =
        common::cli(&["render", "--quiet", "--resume", "--spp", "6", "s.ron"], d);
    assert_eq!(code, 0, "{stderr}");
    let spp = |d: &Path| {
        candela::state::RenderState::load(&d.join("s.state"))
            .unwrap()
            .film
            .samples_per_pixel()
    };
    assert_eq!(spp(d), 6.0);
    // Again without --resume, with or without --save-state or checkpoints: refused, and the
    // 6-spp state stays.
    let before = snapshot(d);
    for extra in [
        &[][..],
        &["--save-state"],
        &["--checkpoint-interval", "1ms"],
        &["--checkpoint-interval", "0s"],
    ] {
        let mut args = vec!["render", "--quiet"];
        args.extend_from_slice(extra);
        args.push("s.ron");
        assert_refused_untouched(d, &args, &["s.state", "--resume", "--overwrite"], &before);
    }
    // --resume and --overwrite together: a usage error.
    let (code, _, stderr) = common::cli(
        &["render", "--quiet", "--resume", "--overwrite", "s.ron"],
        d,
    );
    assert_eq!(code, 2, "{stderr}");
    assert_eq!(snapshot(d), before);
    // --overwrite starts again and replaces the state with the new render's.
    let (code, _, stderr) = common::cli(&["render", "--quiet", "--overwrite", "s.ron"], d);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(spp(d), 2.0);
}

#[test]
fn a_grid_name_too_long_for_a_file_name_is_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A grid name past the scene format's limit is refused when the scene is read.
    std::fs::write(
        d.join("s.ron"),
        scene("Constant(0.5)", "", "", &grid(&"a".repeat(250))),
    )
    .unwrap();
    let before = snapshot(d);
    assert_refused_untouched(
        d,
        &["render", "--quiet", "s.ron"],
        &["grids[0].name", "more than the limit of 100"],
        &before,
    );
    // Within it, but with an output stem that makes `NAME.grid-<name>.csv` too long for a
    // file name: a million samples per pixel are refused at once, not after the render.
    let long = "a".repeat(100);
    std::fs::write(
        d.join("s.ron"),
        scene("Constant(0.5)", "", "", &grid(&long)),
    )
    .unwrap();
    let stem = "c".repeat(150);
    let t = std::time::Instant::now();
    let before = snapshot(d);
    let stderr = assert_refused_untouched(
        d,
        &[
            "render", "--quiet", "--spp", "1000000", "--out", &stem, "s.ron",
        ],
        &["grid \"aaaa", "bytes", ".grid-aaaa"],
        &before,
    );
    assert!(t.elapsed().as_secs_f64() < 10.0, "{:?}", t.elapsed());
    assert!(stderr.contains("the CSV of grid") || stderr.contains("the heat map of grid"));
    // The same grid with a short stem fits.
    let (code, _, stderr) = common::cli(&["render", "--quiet", "s.ron"], d);
    assert_eq!(code, 0, "{stderr}");
    assert!(d.join(format!("s.grid-{long}.csv")).is_file());
}

#[test]
fn unwritable_outputs_are_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.ron"), plain()).unwrap();
    // An output path that is a directory.
    std::fs::create_dir(d.join("s.png")).unwrap();
    let before = snapshot(d);
    assert_refused_untouched(
        d,
        &["render", "--quiet", "--spp", "1000000", "s.ron"],
        &["the PNG image", "s.png", "not a regular file"],
        &before,
    );
    // A directory that takes no new file (even for root).
    let (code, _, stderr) = common::cli(
        &[
            "render", "--quiet", "--spp", "1000000", "--out", "/proc/", "s.ron",
        ],
        d,
    );
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("cannot write") && stderr.contains("/proc"),
        "{stderr}"
    );
}

/// A [`Progress`] that, once the checks are done, puts directories where the report and the
/// state will go, so that those two writes fail; it records the warnings.
struct Sabotage<'a> {
    dir: &'a Path,
    warnings: Vec<String>,
}

impl Progress for Sabotage<'_> {
    fn start(&mut self, _max_samples: u64) -> anyhow::Result<()> {
        std::fs::create_dir(self.dir.join("s.report.json")).unwrap();
        std::fs::create_dir(self.dir.join("s.state")).unwrap();
        Ok(())
    }
    fn warning(&mut self, message: &str) {
        self.warnings.push(message.to_string());
    }
}

#[test]
fn outputs_that_fail_do_not_stop_the_others() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("s.ron"),
        scene("Constant(0.5)", "", "", &grid("desk")),
    )
    .unwrap();
    let mut job = RenderJob::new(d.join("s.ron"));
    job.out = Some(d.join("s"));
    job.save_state = true;
    job.overrides.spp = Some(64);
    // A checkpoint after every pass: each one fails to write the state, with a warning.
    job.checkpoint_interval = Some(std::time::Duration::from_nanos(1));
    let mut progress = Sabotage {
        dir: d,
        warnings: Vec::new(),
    };
    let e = job::run(&job, &mut progress, &AtomicBool::new(false))
        .err()
        .expect("the state and report cannot be written");
    let msg = format!("{e:#}");
    assert!(msg.starts_with("2 files could not be written"), "{msg}");
    assert!(
        msg.contains("s.report.json") && msg.contains("s.state"),
        "{msg}"
    );
    // Everything else was written, the state last.
    for f in ["s.exr", "s.png", "s.grid-desk.csv", "s.grid-desk.png"] {
        assert!(d.join(f).is_file(), "{f} missing: {msg}");
    }
    assert!(!progress.warnings.is_empty());
    assert!(
        progress
            .warnings
            .iter()
            .all(|w| w.starts_with("checkpoint not written") && w.contains("s.state")),
        "{:?}",
        progress.warnings
    );
    // Nothing was interrupted: the film is complete.
    let layers = candela::output::read_exr(&d.join("s.exr")).unwrap();
    assert_eq!(
        layers
            .attributes
            .iter()
            .find(|(k, _)| k == "spp")
            .unwrap()
            .1,
        "64.00"
    );
}

#[test]
fn a_job_stopped_before_its_first_pass_leaves_a_resumed_state_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.ron"), plain()).unwrap();
    let mut job = RenderJob::new(d.join("s.ron"));
    job.out = Some(d.join("s"));
    job.save_state = true;
    job::run(&job, &mut job::Silent, &AtomicBool::new(false)).unwrap();
    let before = snapshot(d);
    job.resume = true;
    job.overrides.spp = Some(8);
    let out = job::run(&job, &mut job::Silent, &AtomicBool::new(true)).unwrap();
    assert_eq!(out.outcome, Outcome::InterruptedBeforeFirstPass);
    assert_eq!(snapshot(d), before);
}

#[test]
fn merge_never_replaces_an_input_state_by_any_name() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.ron"), plain()).unwrap();
    common::render_states(d, "s.ron", &[("s", "1"), ("t", "2")]);
    // The input state under the output's name: a hard link, a symbolic link, a path through
    // `..`. Each is refused before anything is read or written.
    std::fs::hard_link(d.join("s.state"), d.join("h.state")).unwrap();
    std::os::unix::fs::symlink(d.join("s.state"), d.join("l.state")).unwrap();
    std::fs::create_dir(d.join("sub")).unwrap();
    let before = snapshot(d);
    for out in ["h", "l", "sub/../s"] {
        assert_refused_untouched(
            d,
            &["merge", "s.state", "t.state", "-o", out],
            &["refusing to overwrite the input state file", "s.state"],
            &before,
        );
    }
}

/// The HTML report of `--report-html` (NAME.html) is checked with the other outputs before
/// rendering: a scene file named like it, or a mesh it refers to, is refused and left byte for
/// byte; without `--report-html` the same files render and stay as they were.
#[test]
fn the_html_report_never_replaces_an_input() {
    let obj = b"v -0.2 -0.2 2\nv 0.2 -0.2 2\nv 0 0.2 2\nf 1 2 3\n".to_vec();
    // The scene itself is room.html: its report would be room.html.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("room.html"), plain()).unwrap();
    let before = snapshot(dir.path());
    assert_refused_untouched(
        dir.path(),
        &["render", "--quiet", "--report-html", "room.html"],
        &[
            "refusing to overwrite the scene file",
            "the HTML report",
            "room.html",
        ],
        &before,
    );
    // A mesh m.html and `--out m`.
    let mesh = r#", (shape: Obj("m.html"), material: "grey")"#;
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("s.ron"),
        scene("Constant(0.5)", mesh, "", ""),
    )
    .unwrap();
    std::fs::write(dir.path().join("m.html"), &obj).unwrap();
    let before = snapshot(dir.path());
    assert_refused_untouched(
        dir.path(),
        &["render", "--quiet", "--report-html", "--out", "m", "s.ron"],
        &[
            "refusing to overwrite the file the scene refers to",
            "m.html",
        ],
        &before,
    );
    let (code, _, stderr) = common::cli(&["render", "--quiet", "--out", "m", "s.ron"], dir.path());
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(std::fs::read(dir.path().join("m.html")).unwrap(), obj);
}

/// `candela report` refuses an output that is its image, its report JSON or its glare JSON, by
/// any name (a hard link), and leaves them as they were.
#[test]
fn report_never_replaces_its_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.ron"), plain()).unwrap();
    let (code, _, stderr) = common::cli(&["render", "--quiet", "s.ron"], d);
    assert_eq!(code, 0, "{stderr}");
    let glare = r#"{"dgp": {"value": 0.2}, "sources": []}"#;
    std::fs::write(d.join("g.json"), glare).unwrap();
    std::fs::hard_link(d.join("s.exr"), d.join("link.html")).unwrap();
    let before = snapshot(d);
    for (args, input) in [
        (&["report", "s.exr", "-o", "s.exr"][..], "s.exr"),
        (&["report", "s.exr", "-o", "link.html"], "s.exr"),
        (
            &["report", "s.exr", "s.report.json", "-o", "s.report.json"],
            "s.report.json",
        ),
        (
            &["report", "s.exr", "--glare", "g.json", "-o", "g.json"],
            "g.json",
        ),
    ] {
        let stderr = assert_refused_untouched(
            d,
            args,
            &["refusing to overwrite the input", input],
            &before,
        );
        assert!(stderr.contains("HTML report"), "{stderr}");
    }
}
