//! `candela render` killed mid-way (SIGINT) writes a checkpoint; `--resume` finishes it to the
//! same image as an uninterrupted render; a changed scene is refused; `merge` combines seeds.

mod common;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

const SCENE: &str = r#"(
    camera: (position: (0.1, -0.2, 0.05), look_at: (0, 0, 1), vfov_deg: 120, resolution: (32, 32)),
    render: (spp: 512, max_depth: 64),
    materials: { "wall": Diffuse(reflectance: Constant(0.7)), "glass": Dielectric(ior: Constant(1.5)) },
    objects: [(
        shape: Sphere(center: (0, 0, 0), radius: 1),
        material: "wall",
        emission: (spectrum: Named("E"), amount: Luminance(1.0), two_sided: true),
    ), (
        // Glass: light-traced caustics (their light paths) take part in checkpoints too.
        shape: Sphere(center: (0.3, 0.2, 0.6), radius: 0.15),
        material: "glass",
    )],
)"#;

fn candela(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_candela"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

fn y_channel(path: &Path) -> Vec<f32> {
    candela::output::read_exr(path)
        .unwrap()
        .channel("Y")
        .unwrap()
        .to_vec()
}

#[test]
fn sigint_checkpoint_then_resume_matches_uninterrupted() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.ron"), SCENE).unwrap();
    let whole = candela(
        dir.path(),
        &[
            "render",
            "--quiet",
            "--threads",
            "2",
            "--out",
            "whole",
            "s.ron",
        ],
    );
    assert!(
        whole.status.success(),
        "{}",
        String::from_utf8_lossy(&whole.stderr)
    );

    let mut child = Command::new(env!("CARGO_BIN_EXE_candela"))
        .current_dir(dir.path())
        .args([
            "render",
            "--quiet",
            "--threads",
            "2",
            "--out",
            "part",
            "s.ron",
        ])
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(400));
    let _ = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status();
    let status = child.wait().unwrap();
    if status.code() == Some(130) {
        assert!(dir.path().join("part.state").exists());
    } else {
        // The machine was fast enough to finish first; the resume below is then a no-op.
        assert!(status.success());
    }
    let resumed = candela(
        dir.path(),
        &[
            "render",
            "--quiet",
            "--threads",
            "1",
            "--resume",
            "--out",
            "part",
            "s.ron",
        ],
    );
    assert!(
        resumed.status.success(),
        "{}",
        String::from_utf8_lossy(&resumed.stderr)
    );
    assert_eq!(
        y_channel(&dir.path().join("part.exr")),
        y_channel(&dir.path().join("whole.exr"))
    );

    // A changed scene is refused.
    std::fs::write(dir.path().join("s.ron"), SCENE.replace("0.7", "0.6")).unwrap();
    let refused = candela(
        dir.path(),
        &["render", "--quiet", "--resume", "--out", "part", "s.ron"],
    );
    assert_eq!(refused.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&refused.stderr).contains("changed"));
}

#[test]
fn a_changed_referenced_file_is_refused_on_resume() {
    // The scene text stays the same; the spectrum file it refers to changes.
    let dir = tempfile::tempdir().unwrap();
    let scene = SCENE
        .replace("spp: 512", "spp: 4")
        .replace("Constant(0.7)", "Csv(\"wall.csv\")");
    std::fs::write(dir.path().join("s.ron"), scene).unwrap();
    std::fs::write(dir.path().join("wall.csv"), "nm,value\n360,0.7\n830,0.7\n").unwrap();
    let args = [
        "render",
        "--quiet",
        "--checkpoint-interval",
        "1ms",
        "--out",
        "r",
        "s.ron",
    ];
    let first = candela(dir.path(), &args);
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    assert!(dir.path().join("r.state").exists());
    let resume = [
        "render",
        "--quiet",
        "--resume",
        "--max-spp",
        "8",
        "--out",
        "r",
        "s.ron",
    ];
    // Unchanged: the state is accepted.
    let same = candela(dir.path(), &resume);
    assert!(
        same.status.success(),
        "{}",
        String::from_utf8_lossy(&same.stderr)
    );
    std::fs::write(dir.path().join("wall.csv"), "nm,value\n360,0.6\n830,0.6\n").unwrap();
    let refused = candela(dir.path(), &resume);
    assert_eq!(refused.status.code(), Some(1));
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(
        err.contains("changed") && err.contains("refers to"),
        "{err}"
    );
}

#[test]
fn merge_combines_two_seeds() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("s.ron"),
        SCENE.replace("spp: 512", "spp: 8"),
    )
    .unwrap();
    common::render_states(dir.path(), "s.ron", &[("r1", "1"), ("r2", "2")]);
    let o = candela(dir.path(), &["merge", "r1.state", "r2.state", "-o", "m"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (a, b, m) = (
        y_channel(&dir.path().join("r1.exr")),
        y_channel(&dir.path().join("r2.exr")),
        y_channel(&dir.path().join("m.exr")),
    );
    for i in 0..m.len() {
        assert!((m[i] - 0.5 * (a[i] + b[i])).abs() <= 1e-5 * m[i].abs().max(1.0));
    }
    // The same seed twice is refused, also when one input is itself a merge containing it.
    let o = candela(dir.path(), &["merge", "r1.state", "r1.state", "-o", "m2"]);
    assert_eq!(o.status.code(), Some(1));
    let o = candela(dir.path(), &["merge", "m.state", "r2.state", "-o", "m3"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("repeats seed 2"));
}

#[test]
fn target_error_run_reports_what_was_reached() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("s.ron"),
        SCENE.replace("(32, 32)", "(8, 8)"),
    )
    .unwrap();
    let o = candela(
        dir.path(),
        &[
            "render",
            "--quiet",
            "--target-error",
            "4%",
            "--out",
            "t",
            "s.ron",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("target reached"), "{stdout}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("t.report.json")).unwrap())
            .unwrap();
    let p = &report["progressive"];
    assert_eq!(p["stop_reason"], "TargetReached");
    assert_eq!(p["target_relative_error_95"], 0.04);
    assert!(p["fraction_of_eligible_pixels_at_target"].as_f64().unwrap() >= 1.0);
    // The image mean equals the furnace value L = 1/(1 − 0.7) within 4 of its standard errors
    // (from the EXR's stderr.Y; pixels are independent).
    let layers = candela::output::read_exr(&dir.path().join("t.exr")).unwrap();
    let y = layers.channel("Y").unwrap();
    let se = layers.channel("stderr.Y").unwrap();
    let n = y.len() as f64;
    let mean = y.iter().map(|&v| v as f64).sum::<f64>() / n;
    let se_mean = se.iter().map(|&s| (s as f64).powi(2)).sum::<f64>().sqrt() / n;
    assert!(
        (mean - 1.0 / 0.3).abs() <= 4.0 * se_mean,
        "{mean} ± {se_mean}"
    );
}

/// (seconds, M samples/s) of the closing line of a render.
fn closing_rate(stdout: &str) -> (f64, f64) {
    let line = stdout
        .lines()
        .find(|l| l.starts_with("rendered "))
        .unwrap_or_else(|| panic!("no closing line in {stdout}"));
    let number_before = |marker: &str| -> f64 {
        let head = &line[..line.find(marker).unwrap()];
        head.rsplit(' ').next().unwrap().parse().unwrap()
    };
    (number_before(" s on "), number_before(" M samples/s"))
}

#[test]
fn samples_per_second_counts_only_the_samples_of_this_run() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.ron"), SCENE).unwrap();
    let first = candela(
        dir.path(),
        &["render", "--quiet", "--spp", "32", "--save-state", "s.ron"],
    );
    assert!(first.status.success());
    // Resumed from 32 to 64 spp: this run renders 32 × 32 × 32 samples.
    let resumed = candela(
        dir.path(),
        &["render", "--quiet", "--resume", "--spp", "64", "s.ron"],
    );
    assert!(
        resumed.status.success(),
        "{}",
        String::from_utf8_lossy(&resumed.stderr)
    );
    let (seconds, rate) = closing_rate(&String::from_utf8_lossy(&resumed.stdout));
    let counted = rate * 1e6 * seconds;
    let rendered = 32.0 * 32.0 * 32.0;
    // The printed figures are rounded (seconds to 0.01, rate to 0.001 M/s): a few per cent.
    assert!(
        (counted / rendered - 1.0).abs() < 0.15,
        "{rate} M samples/s × {seconds} s = {counted} samples, rendered {rendered}"
    );
}
