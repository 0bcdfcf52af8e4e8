//! Property-based fuzzing of the command line: every subcommand with random options drawn from
//! valid and hostile values (NaN, ±inf, huge, negative, empty, malformed ranges, control
//! characters, unknown flags) must end within a time limit with exit code 0, 1 or 2 (the
//! documented convention, docs/guarantees.md), never a panic, a signal or a hang; a non-zero exit
//! has a message; nothing is written outside the case's directory and no input is changed.
//! `PROPTEST_CASES=N` sets the number of cases per subcommand.

mod fuzz_common;

use fuzz_common::config;
use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const SCENE: &str = r#"(
    camera: (position: (0, 0, 0), look_at: (0, 0, 1), vfov_deg: 30, resolution: (6, 4)),
    render: (spp: 2),
    materials: { "grey": Diffuse(reflectance: Constant(0.5)) },
    objects: [(shape: Sphere(center: (0, 0, 3), radius: 1), material: "grey")],
    lights: [Point(position: (0, 2, 0), spectrum: Named("D65"), amount: Intensity(10.0))],
    meters: [Illuminance(name: "m", position: (0, 0, 2), normal: (0, 0, -1))],
    grids: [(name: "desk", origin: (-0.5, -1, 2), edge_u: (1, 0, 0), edge_v: (0, 0, 1), nx: 3, ny: 2, normal: (0, 0, -1))],
    measure: (samples: 64),
)"#;

const IES: &str = "IESNA:LM-63-2002\n[TEST] fuzz\nTILT=NONE\n1 1000 1 3 1 1 2 0.5 0.5 0\n1 1 100\n0 45 90\n0\n100 80 50\n";

/// Hostile and ordinary option values.
const VALUES: &[&str] = &[
    "0",
    "1",
    "2",
    "-1",
    "-0",
    "0.5",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e309",
    "-1e309",
    "1e-320",
    "3.5e38",
    "1e300",
    "4294967296",
    "18446744073709551616",
    "-9223372036854775809",
    "",
    " ",
    "abc",
    "1:",
    ":1",
    ":",
    "::",
    "0:0",
    "1:0",
    "-1:1",
    "1:1.797e308",
    "nan:1",
    "si",
    "imperial",
    "log",
    "linear",
    "turbo",
    "viridis",
    "1931",
    "1964",
    "none",
    "light-trace",
    "a\rb",
    "\u{1b}[31m",
    "é",
];

/// Values small enough that a render with them ends quickly (sample counts, times, depths).
const CHEAP: &[&str] = &[
    "0", "1", "2", "-1", "nan", "inf", "", "abc", "1e309", "0.5", "1e-320",
];

fn candela() -> &'static str {
    env!("CARGO_BIN_EXE_candela")
}

/// One fuzz case's directory: the scene, an IES file, a rendered EXR and a state, made once
/// and copied, so each case starts from the same files.
fn template() -> &'static Path {
    use std::sync::OnceLock;
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("candela-fuzz-cli-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("scene.ron"), SCENE).unwrap();
        std::fs::write(dir.join("lum.ies"), IES).unwrap();
        let st = Command::new(candela())
            .args([
                "render",
                "--quiet",
                "--save-state",
                "--illuminance",
                "--out",
            ])
            .arg(dir.join("img"))
            .arg(dir.join("scene.ron"))
            .status()
            .unwrap();
        assert!(st.success());
        dir
    })
}

/// Every file in `dir` with its bytes.
fn snapshot(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            let bytes = if p.is_file() {
                std::fs::read(&p).unwrap()
            } else {
                Vec::new()
            };
            (name, bytes)
        })
        .collect();
    v.sort();
    v
}

/// Runs `candela ARGS` in a copy of the template directory (as the working directory, so
/// relative outputs land there) and checks the promises common to every command.
fn run_case(args: &[String]) -> Result<(), TestCaseError> {
    let case = tempfile::tempdir().unwrap();
    for (name, bytes) in snapshot(template()) {
        std::fs::write(case.path().join(&name), bytes).unwrap();
    }
    let inputs = ["scene.ron", "lum.ies", "img.exr", "img.state"];
    let before: Vec<_> = inputs
        .iter()
        .map(|n| std::fs::read(case.path().join(n)).unwrap())
        .collect();
    let mut child = Command::new(candela())
        .args(args)
        .current_dir(case.path())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let limit = Duration::from_secs(60);
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return Err(TestCaseError::fail(format!(
                "candela {args:?} did not end within {limit:?}"
            )));
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let code = status.code();
    prop_assert!(
        matches!(code, Some(0..=2)),
        "candela {args:?}: exit {code:?} (0, 1 or 2 expected), stderr:\n{stderr}"
    );
    prop_assert!(
        !stderr.contains("panicked") && !stderr.contains("RUST_BACKTRACE"),
        "candela {args:?} panicked:\n{stderr}"
    );
    if code != Some(0) {
        prop_assert!(
            !stderr.trim().is_empty(),
            "candela {args:?}: exit {code:?} without a message"
        );
    }
    prop_assert!(
        !stderr.contains('\r') && !stderr.contains('\0') && !stderr.contains('\u{1b}'),
        "candela {args:?}: raw control characters in the message:\n{stderr:?}"
    );
    for (n, b) in inputs.iter().zip(&before) {
        let now = std::fs::read(case.path().join(n));
        prop_assert!(
            now.as_ref().ok() == Some(b),
            "candela {args:?} changed or removed its input {n}"
        );
    }
    Ok(())
}

fn value() -> impl Strategy<Value = String> {
    prop::sample::select(VALUES).prop_map(str::to_string)
}

fn cheap() -> impl Strategy<Value = String> {
    prop::sample::select(CHEAP).prop_map(str::to_string)
}

/// A list of options: each a flag with a value drawn by `pick`, or a bare flag.
fn options(
    with_value: &'static [&'static str],
    cheap_flags: &'static [&'static str],
    bare: &'static [&'static str],
) -> impl Strategy<Value = Vec<String>> {
    let one = prop_oneof![
        (prop::sample::select(with_value), value()).prop_map(|(f, v)| vec![f.to_string(), v]),
        (prop::sample::select(cheap_flags), cheap()).prop_map(|(f, v)| vec![f.to_string(), v]),
        prop::sample::select(bare).prop_map(|f| vec![f.to_string()]),
        value().prop_map(|v| vec![v]),
    ];
    prop::collection::vec(one, 0..5).prop_map(|v| v.concat())
}

proptest! {
    #![proptest_config(config(128))]

    #[test]
    fn render_options(opts in options(
        &["--exposure", "--units", "--caustics", "--target-error", "--target-fraction",
          "--target-floor", "--threads", "--seed", "--out"],
        &["--spp", "--max-spp", "--max-time", "--max-depth", "--checkpoint-interval"],
        &["--illuminance", "--resume", "--save-state", "--falsecolour", "--quiet", "--bogus"],
    )) {
        let mut args = vec!["render".to_string(), "--max-time".into(), "3".into()];
        args.extend(opts);
        args.push("scene.ron".into());
        run_case(&args)?;
    }

    #[test]
    fn falsecolour_options(opts in options(
        &["--quantity", "--scale", "--range", "--steps", "--units", "--palette", "-o"],
        &["--steps"],
        &["--contours", "--bogus"],
    )) {
        let mut args = vec!["falsecolour".to_string()];
        args.extend(opts);
        args.push("img.exr".into());
        run_case(&args)?;
    }

    #[test]
    fn probe_options(opts in options(&["--radius", "--units"], &["--radius"], &["--json", "--bogus"]),
                     x in value(), y in value()) {
        let mut args = vec!["probe".to_string(), "img.exr".into(), x, y];
        args.extend(opts);
        run_case(&args)?;
    }

    #[test]
    fn merge_luminaire_spectrum_convert(which in 0..4usize, opts in options(
        &["--exposure", "--out", "-o", "--diagram", "--observer"],
        &["--exposure"],
        &["--json", "--bogus"],
    ), v in value()) {
        let mut args: Vec<String> = match which {
            0 => vec!["merge".into(), "img.state".into(), "img.state".into()],
            1 => vec!["luminaire".into(), "lum.ies".into()],
            2 => vec!["spectrum".into(), v],
            _ => vec!["convert".into(), v],
        };
        args.extend(opts);
        run_case(&args)?;
    }
}
