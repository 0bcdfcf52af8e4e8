//! A whole render job through the library (`candela::job`), without the binary: images,
//! meters, grids, reports, resume, cancellation and merge, with the meters and grid checked
//! against the inverse-square and cosine laws (closed-forms.md §2.2).

use candela::job::{self, Outcome, Progress, RenderJob, Silent};
use candela::render::PassStatus;
use std::sync::atomic::AtomicBool;

/// A point light of I = 400 cd 2.5 m above a black floor (so no light is reflected): at floor
/// point (x, 0, z) E = I cos θ / r² with r² = (x−1)² + d² + (z−2)² and cos θ = d / r.
const SCENE: &str = r#"(
    camera: (position: (1, 3, -3), look_at: (1, 0, 2), vfov_deg: 40, resolution: (16, 12)),
    render: (spp: 4, max_depth: 4, seed: 5),
    materials: { "floor": Diffuse(reflectance: Constant(0.0)) },
    objects: [(shape: Quad(origin: (-20, 0, -20), edge_u: (0, 0, 40), edge_v: (40, 0, 0)), material: "floor")],
    lights: [Point(position: (1, 2.5, 2), spectrum: Named("A"), amount: Intensity(400))],
    meters: [Illuminance(name: "foot", position: (1, 0, 2), normal: (0, 1, 0))],
    grids: [(name: "floor grid", origin: (-1, 0, 0), edge_u: (4, 0, 0), edge_v: (0, 0, 4), nx: 3, ny: 2)],
    measure: (samples: 4096),
)"#;

const I_CD: f64 = 400.0;
const D_M: f64 = 2.5;

fn exact_lx(x: f64, z: f64) -> f64 {
    let r2 = (x - 1.0).powi(2) + D_M * D_M + (z - 2.0).powi(2);
    I_CD * (D_M / r2.sqrt()) / r2
}

#[derive(Default)]
struct Count {
    started: u32,
    passes: u32,
    rendered: u32,
}
impl Progress for Count {
    fn start(&mut self, _max_samples: u64) -> anyhow::Result<()> {
        self.started += 1;
        Ok(())
    }
    fn pass(&mut self, _s: &PassStatus) {
        self.passes += 1;
    }
    fn rendered(&mut self, _image: &job::ImageDone) {
        self.rendered += 1;
    }
}

fn job_in(dir: &std::path::Path, name: &str) -> RenderJob {
    let scene = dir.join("room.ron");
    std::fs::write(&scene, SCENE).unwrap();
    let mut job = RenderJob::new(&scene);
    job.out = Some(dir.join(name));
    job.checkpoint_interval = None;
    job
}

#[test]
fn a_whole_job_writes_every_output_and_measures_the_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let job = job_in(dir.path(), "room");
    let mut count = Count::default();
    let out = job::run(&job, &mut count, &AtomicBool::new(false)).expect("job");
    assert_eq!(out.outcome, Outcome::Finished);
    assert_eq!((count.started, count.rendered), (1, 1));
    assert!(count.passes >= 1);
    assert_eq!((out.render.film.width, out.render.film.height), (16, 12));
    assert_eq!(out.render.film.samples_per_pixel(), 4.0);
    for p in [&out.exr_path, &out.png_path, &out.report_path] {
        assert!(p.is_file(), "{} missing", p.display());
    }
    for f in ["room.grid-floor-grid.csv", "room.grid-floor-grid.png"] {
        assert!(dir.path().join(f).is_file(), "{f} missing");
        let listed = dir.path().join(f).display().to_string();
        assert!(
            out.outputs.contains(&listed),
            "{f} not among {:?}",
            out.outputs
        );
    }
    // The meter at the foot: E = I/d², within 5 standard errors, and a standard error below
    // 1 % of it so that the check keeps its power.
    let m = &out.meters[0].estimate;
    let e = I_CD / (D_M * D_M);
    assert!(
        (m.mean - e).abs() <= 5.0 * m.stderr,
        "{} vs {e} ± {}",
        m.mean,
        m.stderr
    );
    assert!(m.stderr < 0.01 * e, "se {}", m.stderr);
    // The report carries the same numbers, and every grid point obeys the cosine law.
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out.report_path).unwrap()).unwrap();
    assert_eq!(report["meters"][0]["value"].as_f64(), Some(m.mean));
    let grid = &report["grids"][0];
    let (values, stderr) = (&grid["values"], &grid["stderr"]);
    let mut points = 0;
    for j in 0..2 {
        for i in 0..3 {
            // Point (i, j) of a grid sits at the centre of its cell.
            let (x, z) = (
                -1.0 + 4.0 * (i as f64 + 0.5) / 3.0,
                4.0 * (j as f64 + 0.5) / 2.0,
            );
            let exact = exact_lx(x, z);
            let (v, se) = (
                values[j][i].as_f64().unwrap(),
                stderr[j][i].as_f64().unwrap(),
            );
            assert!(
                (v - exact).abs() <= 5.0 * se,
                "grid ({i},{j}): {v} vs {exact} ± {se}"
            );
            assert!(se < 0.01 * exact);
            points += 1;
        }
    }
    assert_eq!(points, 6);
    assert_eq!(out.grids[0].nx, 3);
    assert!((out.grids[0].stats.max - report["grids"][0]["E_max"].as_f64().unwrap()).abs() < 1e-9);
}

#[test]
fn resume_continues_and_merge_adds_the_samples() {
    let dir = tempfile::tempdir().unwrap();
    let mut job = job_in(dir.path(), "room");
    job.save_state = true;
    job::run(&job, &mut Silent, &AtomicBool::new(false)).expect("first");
    job.resume = true;
    job.max_spp = Some(8);
    let out = job::run(&job, &mut Silent, &AtomicBool::new(false)).expect("resumed");
    assert_eq!(out.render.film.samples_per_pixel(), 8.0);
    // A second seed, then a merge of the two states.
    let mut other = job_in(dir.path(), "other");
    other.save_state = true;
    other.overrides.seed = Some(6);
    job::run(&other, &mut Silent, &AtomicBool::new(false)).expect("other seed");
    let merged = job::merge(
        &[
            dir.path().join("room.state"),
            dir.path().join("other.state"),
        ],
        &dir.path().join("merged"),
        None,
    )
    .expect("merge");
    assert_eq!(merged.renders, 2);
    assert_eq!(merged.seeds, vec![5, 6]);
    assert_eq!(merged.samples_per_pixel, 12.0);
    assert!(merged.exr_path.is_file() && merged.state_path.is_file());
    // The same seed twice is refused.
    assert!(job::merge(
        &[
            dir.path().join("room.state"),
            dir.path().join("merged.state")
        ],
        &dir.path().join("again"),
        None,
    )
    .is_err());
}

#[test]
fn a_job_stopped_before_its_first_pass_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let job = job_in(dir.path(), "room");
    let out = job::run(&job, &mut Silent, &AtomicBool::new(true)).expect("job");
    assert_eq!(out.outcome, Outcome::InterruptedBeforeFirstPass);
    assert!(!out.exr_path.exists() && !out.png_path.exists() && !out.report_path.exists());
}

#[test]
fn job_settings_are_checked_before_the_scene_is_read() {
    let mut job = RenderJob::new("/nonexistent/scene.ron");
    job.threads = Some(0);
    let e = job::run(&job, &mut Silent, &AtomicBool::new(false))
        .err()
        .unwrap();
    assert!(
        e.to_string().contains("--threads must be at least 1"),
        "{e}"
    );
    job.threads = None;
    job.exposure_ev = Some(f64::NAN);
    assert!(job::run(&job, &mut Silent, &AtomicBool::new(false)).is_err());
    job.exposure_ev = None;
    let e = job::run(&job, &mut Silent, &AtomicBool::new(false))
        .err()
        .unwrap();
    assert!(format!("{e:#}").contains("/nonexistent/scene.ron"), "{e:#}");
}

/// With `render.pixel_batches: 4` a render resumed from its state is the render done at once:
/// sample i of a pixel is sample i / 4 of batch i mod 4 however the samples are split, and the
/// state carries the number of batches.
#[test]
fn resume_with_four_batches_per_pixel_is_the_render_done_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("lit.ron");
    std::fs::write(
        &scene,
        SCENE
            .replace("Constant(0.0)", "Constant(0.5)")
            .replace("seed: 5)", "seed: 5, pixel_batches: 4)"),
    )
    .unwrap();
    let run = |name: &str, spp: u32, resume: bool, save: bool| {
        let mut job = RenderJob::new(&scene);
        job.out = Some(dir.path().join(name));
        job.checkpoint_interval = None;
        job.max_spp = Some(spp);
        job.resume = resume;
        job.save_state = save;
        job::run(&job, &mut Silent, &AtomicBool::new(false)).expect("job")
    };
    let whole = run("whole", 12, false, false);
    run("part", 5, false, true);
    let resumed = run("part", 12, true, true);
    assert_eq!(whole.render.film.pixel_batches, 4);
    assert_eq!(resumed.render.film.pixel_batches, 4);
    let y = |o: &job::RenderOutputs| -> Vec<f64> {
        o.render
            .film
            .pixels
            .iter()
            .flat_map(|p| [p.mean_xyz()[1], p.y_standard_error(4)])
            .collect()
    };
    assert!(y(&whole).iter().any(|&v| v > 0.0));
    assert_eq!(y(&whole), y(&resumed));
}
