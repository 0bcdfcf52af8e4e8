//! `candela render --shard I/N` and `candela merge` of shards: the merge is the same bit for bit
//! whatever the order of its inputs; N shards hold exactly the samples of one render at N× the
//! samples (equal sums but for the rounding of their order of addition); missing and unfinished
//! shards are named, `--partial` merges what is present; shards of different renders are
//! refused; the shard comes from Slurm, AWS Batch or Kubernetes variables; meters and grids
//! merge too, to the furnace's closed form.

mod common;
use std::path::Path;

/// A furnace: inside a sphere that emits 1 cd/m² and reflects ρ = 0.7, the luminance is
/// 1/(1 − ρ) cd/m² everywhere and the illuminance π/(1 − ρ) lx at every point and orientation.
const FURNACE: &str = r#"(
    camera: (position: (0.1, -0.2, 0.05), look_at: (0, 0, 1), vfov_deg: 90, resolution: (20, 16)),
    render: (spp: 8),
    materials: { "wall": Diffuse(reflectance: Constant(REFLECTANCE)) },
    objects: [(
        shape: Sphere(center: (0, 0, 0), radius: 1),
        material: "wall",
        emission: (spectrum: Named("E"), amount: Luminance(1.0), two_sided: true),
    )],
    meters: [Illuminance(name: "centre", position: (0, 0, 0), normal: (0, 0, 1))],
    grids: [(name: "plane", origin: (-0.3, -0.2, -0.3), edge_u: (0.6, 0, 0), edge_v: (0, 0, 0.6), nx: 3, ny: 2)],
    measure: (samples: 1024),
)"#;

const RHO: f64 = 0.7;

/// The array-job variables a test must not inherit (the tests may run inside a Slurm job).
const VARS: [&str; 6] = [
    "SLURM_ARRAY_TASK_ID",
    "SLURM_ARRAY_TASK_MIN",
    "SLURM_ARRAY_TASK_MAX",
    "SLURM_ARRAY_TASK_COUNT",
    "AWS_BATCH_JOB_ARRAY_INDEX",
    "JOB_COMPLETION_INDEX",
];

/// `candela ARGS` in `dir` with the array-job variables `env` only: (exit code, stdout, stderr).
fn run_env(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> (i32, String, String) {
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_candela"));
    c.current_dir(dir).args(args);
    for v in VARS {
        c.env_remove(v);
    }
    for (k, v) in env {
        c.env(k, v);
    }
    let out = c.output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn scene(dir: &Path, name: &str, rho: f64) {
    let text = FURNACE.replace("REFLECTANCE", &rho.to_string());
    std::fs::write(dir.join(name), text).unwrap();
}

/// Renders shard `i` of `n` of `scene` at `spp` per shard into OUT.shard-i-of-n.*.
fn shard(dir: &Path, scene: &str, out: &str, i: u32, n: u32, spp: u32) {
    let spec = format!("{i}/{n}");
    let spp = spp.to_string();
    let (code, _, err) = run_env(
        dir,
        &[
            "render",
            scene,
            "--quiet",
            "--threads",
            "2",
            "--shard",
            &spec,
            "--spp",
            &spp,
            "--out",
            out,
        ],
        &[],
    );
    assert_eq!(code, 0, "shard {spec}: {err}");
}

fn shard_state(out: &str, i: u32, n: u32) -> String {
    format!("{out}.shard-{i}-of-{n}.state")
}

fn merge(dir: &Path, states: &[String], out: &str, extra: &[&str]) -> (i32, String, String) {
    let mut args: Vec<&str> = vec!["merge"];
    args.extend(states.iter().map(String::as_str));
    args.extend(["-o", out]);
    args.extend(extra);
    run_env(dir, &args, &[])
}

fn report(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// An EXR's channels as bits and its attributes sorted: the exr crate writes the attributes in
/// the order of a hash map, which changes from one process to the next.
type ExrContent = (Vec<(String, Vec<u32>)>, Vec<(String, String)>);
fn exr_content(path: &Path) -> ExrContent {
    let l = candela::output::read_exr(path).unwrap();
    let channels = l
        .channels
        .iter()
        .map(|(n, v)| (n.clone(), v.iter().map(|x| x.to_bits()).collect()))
        .collect();
    let mut attributes = l.attributes.clone();
    attributes.sort();
    (channels, attributes)
}

fn rel_close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs()) + 1e-300
}

#[test]
fn shards_merge_bit_identically_in_any_order_and_equal_one_render() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path();
    scene(dir, "s.ron", RHO);
    // 8 spp per shard, not a multiple of the 16 pixel batches: shard I's batches start at
    // batch 8·I mod 16, which the merge must keep.
    let n = 4;
    for i in [2, 0, 3, 1] {
        shard(dir, "s.ron", "r", i, n, 8);
    }
    let orders: [[u32; 4]; 3] = [[0, 1, 2, 3], [3, 1, 0, 2], [2, 3, 1, 0]];
    let mut outputs = Vec::new();
    for (k, order) in orders.iter().enumerate() {
        let states: Vec<String> = order.iter().map(|&i| shard_state("r", i, n)).collect();
        let out = format!("m{k}");
        let (code, stdout, err) = merge(dir, &states, &out, &[]);
        assert_eq!(code, 0, "{err}");
        assert!(
            stdout.contains("merged shards [0, 1, 2, 3] of 4"),
            "{stdout}"
        );
        assert!(!stdout.contains("PARTIAL"), "{stdout}");
        let bytes = |ext: &str| std::fs::read(dir.join(format!("{out}.{ext}"))).unwrap();
        outputs.push((
            exr_content(&dir.join(format!("{out}.exr"))),
            [bytes("png"), bytes("state"), bytes("report.json")],
        ));
    }
    for o in &outputs[1..] {
        assert!(o.0 == outputs[0].0, "EXR differs between merge orders");
        assert!(
            o.1[0] == outputs[0].1[0],
            "PNG differs between merge orders"
        );
        assert!(
            o.1[1] == outputs[0].1[1],
            "state differs between merge orders"
        );
        assert!(
            o.1[2] == outputs[0].1[2],
            "report differs between merge orders"
        );
    }

    // One render at 4 × 8 = 32 spp takes exactly the same samples: the same counts, and sums
    // (XYZ, Y², every pixel batch) equal but for the order of their addition.
    let (code, _, err) = run_env(
        dir,
        &[
            "render",
            "s.ron",
            "--quiet",
            "--threads",
            "2",
            "--spp",
            "32",
            "--save-state",
            "--out",
            "single",
        ],
        &[],
    );
    assert_eq!(code, 0, "{err}");
    let merged = candela::state::RenderState::load(&dir.join("m0.state")).unwrap();
    let single = candela::state::RenderState::load(&dir.join("single.state")).unwrap();
    assert_eq!(merged.film.pixels.len(), single.film.pixels.len());
    let mut max_rel = 0.0f64;
    for (a, b) in merged.film.pixels.iter().zip(&single.film.pixels) {
        assert_eq!(a.count, 32);
        assert_eq!(a.count, b.count);
        let pairs = a
            .sum_xyz
            .iter()
            .zip(&b.sum_xyz)
            .chain(a.batch_y.iter().zip(&b.batch_y))
            .chain([(&a.sum_y2, &b.sum_y2)]);
        for (x, y) in pairs {
            assert!(rel_close(*x, *y), "merged {x} vs single {y}");
            max_rel = max_rel.max((x - y).abs() / y.abs().max(1e-300));
        }
        // Not identical pixel by pixel would still pass the above; the standard errors agree
        // too, so the batches hold the same samples.
        assert!(rel_close(
            a.y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES),
            b.y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES)
        ));
    }
    println!("largest relative difference of a merged sum from the single render's: {max_rel:e}");

    // Meters and grid points: 4 shards of 16 samples per batch are the single render's 64.
    let m = report(&dir.join("m0.report.json"));
    let s = report(&dir.join("single.report.json"));
    let e_exact = std::f64::consts::PI / (1.0 - RHO);
    let meter = &m["meters"][0];
    assert_eq!(meter["name"], "centre");
    assert_eq!(meter["unit"], "lx");
    assert_eq!(meter["samples"], 1024);
    let (mean, se) = (
        meter["mean"].as_f64().unwrap(),
        meter["stderr"].as_f64().unwrap(),
    );
    common::assert_estimate_near(mean, se, e_exact, 0.05, "merged meter");
    // The single render's report: the same samples, summed in another order.
    let single_meter = s["meters"][0]["value"].as_f64().unwrap();
    assert!(
        rel_close(mean, single_meter),
        "merged meter {mean} vs single {single_meter}"
    );
    let single_points: Vec<f64> = s["grids"][0]["values"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|row| row.as_array().unwrap().iter().map(|v| v.as_f64().unwrap()))
        .collect();
    let points = m["grids"][0]["points_lx"].as_array().unwrap();
    let errors = m["grids"][0]["points_stderr_lx"].as_array().unwrap();
    assert_eq!(points.len(), 6);
    for (p, q) in points.iter().zip(&single_points) {
        let p = p.as_f64().unwrap();
        assert!(rel_close(p, *q), "merged grid point {p} vs single {q}");
    }
    for (p, e) in points.iter().zip(errors) {
        common::assert_estimate_near(
            p.as_f64().unwrap(),
            e.as_f64().unwrap(),
            e_exact,
            0.05,
            "merged grid point",
        );
    }
}

#[test]
fn missing_and_unfinished_shards_are_named_and_partial_merges_what_is_present() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path();
    scene(dir, "s.ron", RHO);
    let n = 4;
    for i in [0, 1, 3] {
        shard(dir, "s.ron", "r", i, n, 16);
    }
    let states: Vec<String> = [3, 0, 1].iter().map(|&i| shard_state("r", i, n)).collect();
    let (code, _, err) = merge(dir, &states, "m", &[]);
    assert_ne!(code, 0);
    assert!(
        err.contains("1 of the 4 shards is missing: 2") && err.contains("--partial"),
        "{err}"
    );
    assert!(!dir.join("m.exr").exists());
    let (code, stdout, err) = merge(dir, &states, "m", &["--partial"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        stdout.contains("PARTIAL estimate: 3 of 4 shards merged (0, 1, 3); missing: [2]"),
        "{stdout}"
    );
    let r = report(&dir.join("m.report.json"));
    assert_eq!(r["shards"]["partial"], true);
    assert_eq!(r["shards"]["missing"], serde_json::json!([2]));
    assert_eq!(r["shards"]["merged"], serde_json::json!([0, 1, 3]));
    assert_eq!(r["image"]["samples_per_pixel"], 48.0);
    // No state: resumed, it would continue past samples of the shards it lacks.
    assert!(!dir.join("m.state").exists());
    // The partial image estimates the furnace's luminance all the same: the mean of 320 pixels
    // of 48 samples, each within a few per cent.
    let exr = candela::output::read_exr(&dir.join("m.exr")).unwrap();
    let y = exr.channel("Y").unwrap();
    let mean = y.iter().map(|&v| v as f64).sum::<f64>() / y.len() as f64;
    let l_exact = 1.0 / (1.0 - RHO);
    let mean_l = r["image"]["mean_luminance_cd_m2"].as_f64().unwrap();
    assert!(rel_close(mean, mean_l) || (mean - mean_l).abs() < 1e-6 * mean_l);
    // Independent pixels: the mean's standard error from the pixels' own.
    let se = exr.channel("stderr.Y").unwrap();
    let se_mean = se.iter().map(|&v| (v as f64).powi(2)).sum::<f64>().sqrt() / y.len() as f64;
    common::assert_estimate_near(mean, se_mean, l_exact, 0.05, "partial image mean");

    // A shard stopped early (here before its first pass) is unfinished: named, and rerunning
    // its command finishes it.
    let (code, _, err) = run_env(
        dir,
        &[
            "render",
            "s.ron",
            "--quiet",
            "--shard",
            "2/4",
            "--spp",
            "16",
            "--out",
            "r",
            "--max-time",
            "0s",
        ],
        &[],
    );
    assert_eq!(code, 0, "{err}");
    let all: Vec<String> = (0..n).map(|i| shard_state("r", i, n)).collect();
    let (code, _, err) = merge(dir, &all, "m2", &[]);
    assert_ne!(code, 0);
    assert!(
        err.contains("shard 2 (r.shard-2-of-4.state) is unfinished: 0 of its 16 samples per pixel"),
        "{err}"
    );
    shard(dir, "s.ron", "r", 2, n, 16);
    let (code, stdout, err) = merge(dir, &all, "m2", &[]);
    assert_eq!(code, 0, "{err}");
    assert!(!stdout.contains("PARTIAL"), "{stdout}");

    // With 8 spp per shard, shards 0, 2, 3 cannot be merged without shard 1: shard 2's pixel
    // batches start at batch 0 but would continue the 8 samples of shard 0.
    for i in [0, 2, 3] {
        shard(dir, "s.ron", "h", i, n, 8);
    }
    let states: Vec<String> = [0, 2, 3].iter().map(|&i| shard_state("h", i, n)).collect();
    let (code, _, err) = merge(dir, &states, "m3", &["--partial"]);
    assert_ne!(code, 0);
    assert!(err.contains("pixel batches would mix"), "{err}");
}

#[test]
fn a_requeued_shard_continues_its_state_to_the_same_result() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path();
    scene(dir, "s.ron", RHO);
    shard(dir, "s.ron", "whole", 1, 3, 64);
    // Stopped by a time limit after its first pass or so, then the same command again.
    let args = [
        "render",
        "s.ron",
        "--quiet",
        "--threads",
        "1",
        "--shard",
        "1/3",
        "--spp",
        "64",
        "--out",
        "part",
        "--max-time",
        "1ms",
    ];
    let (code, _, err) = run_env(dir, &args, &[]);
    assert_eq!(code, 0, "{err}");
    let before = candela::state::RenderState::load(&dir.join(shard_state("part", 1, 3))).unwrap();
    assert!(before.film.pixels[0].count < 64);
    shard(dir, "s.ron", "part", 1, 3, 64);
    let a = std::fs::read(dir.join(shard_state("whole", 1, 3))).unwrap();
    let b = std::fs::read(dir.join(shard_state("part", 1, 3))).unwrap();
    assert!(
        a == b,
        "the continued shard's state differs from the uninterrupted one"
    );
    // A rerun with other settings is refused, naming both.
    let (code, _, err) = run_env(
        dir,
        &[
            "render", "s.ron", "--quiet", "--shard", "1/3", "--spp", "32", "--out", "part",
        ],
        &[],
    );
    assert_ne!(code, 0);
    assert!(
        err.contains("holds shard 1 of 3 at 64 samples per pixel")
            && err.contains("asks for shard 1 of 3 at 32"),
        "{err}"
    );
}

#[test]
fn shards_of_different_renders_are_refused() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path();
    scene(dir, "a.ron", RHO);
    scene(dir, "b.ron", 0.5);
    shard(dir, "a.ron", "a", 0, 2, 8);
    shard(dir, "b.ron", "b", 1, 2, 8);
    shard(dir, "a.ron", "c", 1, 3, 8);
    shard(dir, "a.ron", "d", 1, 2, 16);
    shard(dir, "a.ron", "e", 1, 2, 8);
    let cases = [
        ("b", 1, 2, "renders of different scenes or settings"),
        ("c", 1, 3, "split in 2 and 3 shards"),
        ("d", 1, 2, "shards of 8 and 16 samples per pixel"),
    ];
    for (out, i, n, expected) in cases {
        let states = vec![shard_state("a", 0, 2), shard_state(out, i, n)];
        let (code, _, err) = merge(dir, &states, "m", &[]);
        assert_ne!(code, 0, "{out}");
        assert!(
            err.contains("cannot be merged") && err.contains(expected),
            "{out}: {err}"
        );
    }
    // The same shard twice, and a shard with a whole render.
    let states = vec![shard_state("a", 0, 2), shard_state("a", 0, 2)];
    let (_, _, err) = merge(dir, &states, "m", &[]);
    assert!(err.contains("shard 0 of 2 is given twice"), "{err}");
    let (code, _, err) = run_env(
        dir,
        &[
            "render",
            "a.ron",
            "--quiet",
            "--save-state",
            "--out",
            "whole",
        ],
        &[],
    );
    assert_eq!(code, 0, "{err}");
    let states = vec![shard_state("a", 0, 2), "whole.state".to_string()];
    let (_, _, err) = merge(dir, &states, "m", &[]);
    assert!(
        err.contains("is a shard of a render") && err.contains("is not"),
        "{err}"
    );
    // The matching shard merges.
    let states = vec![shard_state("e", 1, 2), shard_state("a", 0, 2)];
    let (code, _, err) = merge(dir, &states, "m", &[]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn the_shard_comes_from_slurm_aws_batch_or_kubernetes() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path();
    scene(dir, "s.ron", RHO);
    let render = |spec: &str, env: &[(&str, &str)]| {
        run_env(
            dir,
            &[
                "render", "s.ron", "--quiet", "--spp", "1", "--out", "r", "--shard", spec,
            ],
            env,
        )
    };
    // A Slurm array --array=1-4: task 3 is shard 2 of 4.
    let slurm = [
        ("SLURM_ARRAY_TASK_ID", "3"),
        ("SLURM_ARRAY_TASK_MIN", "1"),
        ("SLURM_ARRAY_TASK_MAX", "4"),
        ("SLURM_ARRAY_TASK_COUNT", "4"),
    ];
    let (code, _, err) = render("auto", &slurm);
    assert_eq!(code, 0, "{err}");
    assert!(dir.join("r.shard-2-of-4.state").exists());
    let (code, _, err) = render("auto/5", &[("AWS_BATCH_JOB_ARRAY_INDEX", "4")]);
    assert_eq!(code, 0, "{err}");
    assert!(dir.join("r.shard-4-of-5.state").exists());
    let (code, _, err) = render("auto/3", &[("JOB_COMPLETION_INDEX", "0")]);
    assert_eq!(code, 0, "{err}");
    assert!(dir.join("r.shard-0-of-3.state").exists());
    // Garbage and out-of-range values: usage errors (exit code 2) naming the flag or variable.
    type Case<'a> = (&'a str, &'a [(&'a str, &'a str)], &'a str);
    let cases: [Case; 7] = [
        (
            "auto",
            &[
                ("SLURM_ARRAY_TASK_ID", "x1"),
                ("SLURM_ARRAY_TASK_COUNT", "4"),
            ],
            "SLURM_ARRAY_TASK_ID must be a whole number",
        ),
        (
            "auto",
            &[
                ("SLURM_ARRAY_TASK_ID", "4"),
                ("SLURM_ARRAY_TASK_COUNT", "4"),
            ],
            "only 4 shards",
        ),
        (
            "auto",
            &[],
            "--shard auto takes the shard and the shard count from a Slurm array",
        ),
        (
            "auto/4",
            &[("JOB_COMPLETION_INDEX", "-1")],
            "JOB_COMPLETION_INDEX must be a whole number",
        ),
        ("4/4", &[], "--shard 4/4: shards are numbered from 0 to 3"),
        ("1/0", &[], "is 0: a render needs at least 1 shard"),
        (
            "one/4",
            &[],
            "the shard index I of --shard I/N must be a whole number",
        ),
    ];
    for (spec, env, expected) in cases {
        let (code, _, err) = render(spec, env);
        assert_eq!(code, 2, "{spec} {env:?}: {err}");
        assert!(err.contains(expected), "{spec} {env:?}: {err}");
    }
    let (code, _, err) = run_env(
        dir,
        &[
            "render",
            "s.ron",
            "--quiet",
            "--shard",
            "0/2",
            "--target-error",
            "5%",
        ],
        &[],
    );
    assert_eq!(code, 2);
    assert!(
        err.contains("--shard splits a fixed number of samples"),
        "{err}"
    );
}

#[test]
fn a_shard_stopped_by_sigterm_continues_to_the_uninterrupted_state() {
    // What Slurm sends a pre-empted or cancelled task: the shard checkpoints at the end of its
    // pass, and the requeued task (the same command) continues it.
    let t = tempfile::tempdir().unwrap();
    let dir = t.path();
    scene(dir, "s.ron", RHO);
    let args = [
        "render",
        "s.ron",
        "--quiet",
        "--threads",
        "1",
        "--shard",
        "1/2",
        "--spp",
        "2048",
        "--out",
    ];
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_candela"))
        .current_dir(dir)
        .args(args)
        .arg("part")
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(150));
    let _ = std::process::Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status();
    let status = child.wait().unwrap();
    let state = dir.join(shard_state("part", 1, 2));
    if status.code() == Some(130) && state.exists() {
        let st = candela::state::RenderState::load(&state).unwrap();
        assert!(st.film.pixels[0].count < 512);
        println!("stopped at {} of 512 spp", st.film.pixels[0].count);
    } else {
        println!("not stopped mid-way ({status:?}): the rerun starts or continues it");
    }
    let mut args: Vec<&str> = args.to_vec();
    args.push("part");
    let (code, _, err) = run_env(dir, &args, &[]);
    assert_eq!(code, 0, "{err}");
    args.pop();
    args.push("whole");
    let (code, _, err) = run_env(dir, &args, &[]);
    assert_eq!(code, 0, "{err}");
    let a = std::fs::read(dir.join(shard_state("whole", 1, 2))).unwrap();
    let b = std::fs::read(&state).unwrap();
    assert!(
        a == b,
        "the requeued shard's state differs from the uninterrupted one"
    );
}

#[test]
fn fisheye_shards_merge_and_resume_with_the_pixels_outside_the_circle_unsampled() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path();
    let text = FURNACE.replace("REFLECTANCE", &RHO.to_string()).replace(
        "vfov_deg: 90, resolution: (20, 16)",
        "projection: Fisheye(mapping: Equidistant, fov_deg: 180.0), resolution: (16, 16)",
    );
    std::fs::write(dir.join("f.ron"), text).unwrap();
    for i in [1, 0] {
        shard(dir, "f.ron", "r", i, 2, 4);
    }
    let states = [shard_state("r", 0, 2), shard_state("r", 1, 2)];
    let (code, stdout, err) = merge(dir, &states, "m", &[]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("merged shards [0, 1] of 2"), "{stdout}");
    let (code, _, err) = run_env(
        dir,
        &[
            "render",
            "f.ron",
            "--quiet",
            "--threads",
            "2",
            "--spp",
            "8",
            "--save-state",
            "--out",
            "one",
        ],
        &[],
    );
    assert_eq!(code, 0, "{err}");
    let merged = candela::state::RenderState::load(&dir.join("m.state")).unwrap();
    let one = candela::state::RenderState::load(&dir.join("one.state")).unwrap();
    let (mut outside, mut inside, mut means) = (0, 0, Vec::new());
    for (i, (a, b)) in merged.film.pixels.iter().zip(&one.film.pixels).enumerate() {
        assert_eq!(a.count, b.count);
        assert!(
            rel_close(a.sum_xyz[1], b.sum_xyz[1]),
            "{} vs {}",
            a.sum_xyz[1],
            b.sum_xyz[1]
        );
        match a.count {
            0 => outside += 1,
            8 => inside += 1,
            c => panic!("a pixel holds {c} samples: neither none nor all 8"),
        }
        // Pixels wholly inside the circle (those it cuts average in the black outside).
        let (x, y) = ((i % 16) as f64, (i / 16) as f64);
        let far = |c: f64| (c - 8.0).abs().max((c - 7.0).abs());
        if far(x).powi(2) + far(y).powi(2) < 64.0 {
            means.push(a.sum_xyz[1] / 8.0);
        }
    }
    // The pixels whose square meets the 180° fisheye's circle (radius 8 pixels) are sampled,
    // the others, in the corners, hold none.
    let meets = (0..256)
        .filter(|i| {
            let (x, y) = ((i % 16) as f64, (i / 16) as f64);
            let (nx, ny) = (8f64.clamp(x, x + 1.0), 8f64.clamp(y, y + 1.0));
            (nx - 8.0).powi(2) + (ny - 8.0).powi(2) < 64.0
        })
        .count();
    assert_eq!((inside, outside), (meets, 256 - meets));
    // Every direction of the furnace sees 1/(1 − ρ) cd/m² (the pixels are independent: the
    // mean within 4 standard errors from their spread).
    let k = means.len() as f64;
    let mean = means.iter().sum::<f64>() / k;
    let var = means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (k - 1.0);
    let exact = 1.0 / (1.0 - RHO);
    assert!(
        (mean - exact).abs() < 4.0 * (var / k).sqrt(),
        "mean {mean}, exact {exact}"
    );
    // The fisheye render continues from its state to more samples.
    let (code, _, err) = run_env(
        dir,
        &[
            "render",
            "f.ron",
            "--quiet",
            "--threads",
            "2",
            "--spp",
            "12",
            "--resume",
            "--out",
            "one",
        ],
        &[],
    );
    assert_eq!(code, 0, "{err}");
}

/// `merge` attempts every output when one fails: with OUT.exr taken by a directory, the PNG,
/// the report and the merged state are still written, and the error names the EXR (exit 1).
#[test]
fn merge_attempts_every_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    scene(d, "f.ron", 0.5);
    for i in 0..2 {
        shard(d, "f.ron", "f", i, 2, 4);
    }
    let states: Vec<String> = (0..2).map(|i| shard_state("f", i, 2)).collect();
    std::fs::create_dir(d.join("m.exr")).unwrap();
    let (code, _, err) = merge(d, &states, "m", &[]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("m.exr"), "{err}");
    for f in ["m.png", "m.report.json", "m.state"] {
        assert!(d.join(f).is_file(), "{f} missing: {err}");
    }
    assert!(d.join("m.exr").is_dir());
}
