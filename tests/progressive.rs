//! Progressive rendering: adaptive sampling to a target error stays unbiased; an interrupted
//! and resumed render equals an uninterrupted one; independent renders merge exactly.

mod common;
use candela::film::Film;
use candela::render::{render_progressive, Progressive, StopReason, TargetError};
use common::*;
use std::sync::atomic::{AtomicBool, Ordering};

const FURNACE: &str = r#"(
    camera: (position: (0.1, -0.2, 0.05), look_at: (0, 0, 1), vfov_deg: 120, resolution: (10, 10)),
    render: (spp: 64, max_depth: 64),
    materials: { "wall": Diffuse(reflectance: Constant(0.5)) },
    objects: [(
        shape: Sphere(center: (0, 0, 0), radius: 1),
        material: "wall",
        emission: (spectrum: Named("E"), amount: Luminance(1.0), two_sided: true),
    )],
)"#;

fn run(
    w: &candela::world::World,
    film: &mut Film,
    prog: &Progressive,
    stop_after_passes: Option<u32>,
) -> StopReason {
    let stop = AtomicBool::new(false);
    let (_, reason) = render_progressive(
        w,
        film,
        Some(2),
        prog,
        &stop,
        &mut |s| {
            if stop_after_passes.is_some_and(|n| s.passes >= n) {
                stop.store(true, Ordering::Relaxed);
            }
        },
        &mut |_| Ok(()),
    )
    .unwrap();
    reason
}

#[test]
fn adaptive_render_to_target_error_is_unbiased() {
    // Furnace ρ = 0.5: L = 2 exactly. Every pixel to ±3 % (95 %); then the image mean (mean of
    // 100 independent pixel estimates) must equal 2 within 4 of its standard errors.
    let w = world(FURNACE);
    let mut film = Film::new_adaptive(10, 10);
    let prog = Progressive {
        max_spp: 1 << 16,
        target: Some(TargetError {
            relative: 0.03,
            fraction: 1.0,
            floor_cd_m2: None,
        }),
        ..Default::default()
    };
    assert_eq!(run(&w, &mut film, &prog, None), StopReason::TargetReached);
    for p in &film.pixels {
        assert!(p.count >= 8);
    }
    let (m, se) = image_mean(&film);
    assert!((m[1] - 2.0).abs() <= 4.0 * se, "mean {} ± {se}", m[1]);
    // The decision buffer, not the image, met the target.
    let d = film.decision.as_ref().unwrap();
    assert!(d.iter().all(
        |p| 1.96 * p.y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES)
            <= 0.03 * p.mean_xyz()[1]
    ));
}

#[test]
fn running_out_of_samples_is_not_reaching_the_target() {
    // ±0.1 % needs ~10⁵ samples per pixel here; with a cap of 16 every pixel stops at the cap
    // unconverged, and the render must say so: stop reason Done (samples exhausted), not
    // TargetReached, and a converged fraction that counts the capped pixels as failures.
    let w = world(FURNACE);
    let mut film = Film::new_adaptive(10, 10);
    let prog = Progressive {
        max_spp: 16,
        target: Some(TargetError {
            relative: 0.001,
            fraction: 1.0,
            floor_cd_m2: None,
        }),
        ..Default::default()
    };
    let stop = AtomicBool::new(false);
    let mut last = None;
    let (_, reason) = render_progressive(
        &w,
        &mut film,
        Some(2),
        &prog,
        &stop,
        &mut |s| last = s.converged_fraction,
        &mut |_| Ok(()),
    )
    .unwrap();
    assert_eq!(reason, StopReason::Done);
    assert!((0..100).all(|i| film.samples_taken(i) == 16));
    let frac = last.expect("a converged fraction with a target");
    assert!(frac < 0.05, "converged fraction {frac}");
}

#[test]
fn interrupted_and_resumed_equals_uninterrupted() {
    let w = world(FURNACE);
    let prog = Progressive {
        max_spp: 40,
        ..Default::default()
    };
    let mut whole = Film::new(10, 10);
    assert_eq!(run(&w, &mut whole, &prog, None), StopReason::Done);
    let mut part = Film::new(10, 10);
    assert_eq!(run(&w, &mut part, &prog, Some(3)), StopReason::Interrupted);
    assert!(part.total_samples() < whole.total_samples());
    // Through a state file, as `--resume` does.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.state");
    candela::state::RenderState::new(std::path::Path::new("x.ron"), 7, &w, part)
        .save(&path)
        .unwrap();
    let mut resumed = candela::state::RenderState::load(&path).unwrap().film;
    assert_eq!(run(&w, &mut resumed, &prog, None), StopReason::Done);
    assert_eq!(resumed, whole);

    // The same holds in adaptive mode.
    let prog = Progressive {
        max_spp: 200,
        target: Some(TargetError {
            relative: 0.01,
            fraction: 1.0,
            floor_cd_m2: None,
        }),
        ..Default::default()
    };
    let mut whole = Film::new_adaptive(10, 10);
    run(&w, &mut whole, &prog, None);
    let mut part = Film::new_adaptive(10, 10);
    assert_eq!(run(&w, &mut part, &prog, Some(2)), StopReason::Interrupted);
    run(&w, &mut part, &prog, None);
    assert_eq!(part, whole);
}

#[test]
fn merged_renders_are_the_exact_combined_estimate() {
    let a = render(&world(&FURNACE.replace("spp: 64", "spp: 16, seed: 1")), 2);
    let b = render(&world(&FURNACE.replace("spp: 64", "spp: 16, seed: 2")), 2);
    let mut m = a.clone();
    m.merge(&b);
    for i in 0..m.pixels.len() {
        let (pa, pb, pm) = (&a.pixels[i], &b.pixels[i], &m.pixels[i]);
        assert_eq!(pm.count, 32);
        let expected = (pa.sum_xyz[1] + pb.sum_xyz[1]) / 32.0;
        assert!((pm.mean_xyz()[1] - expected).abs() < 1e-12);
    }
    let (mean, se) = image_mean(&m);
    assert!((mean[1] - 2.0).abs() <= 4.0 * se);
}

#[test]
fn corrupt_state_file_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.state");
    std::fs::write(&path, b"not a state").unwrap();
    let e = candela::state::RenderState::load(&path)
        .unwrap_err()
        .to_string();
    assert!(e.contains("bad.state"), "{e}");
}

#[test]
fn state_with_a_corrupt_size_is_refused_by_name() {
    // Width and height whose product wraps to 0, the length of the (empty) pixel arrays, and a
    // zero size: corrupt files, named as such.
    let dir = tempfile::tempdir().unwrap();
    let w = world(FURNACE);
    for (width, height) in [(1usize << 32, 1usize << 32), (0, 4)] {
        let mut film = Film::new(4, 4);
        film.width = width;
        film.height = height;
        film.pixels.clear();
        let path = dir.path().join("sized.state");
        candela::state::RenderState::new(std::path::Path::new("s.ron"), 1, &w, film)
            .save(&path)
            .unwrap();
        let e = candela::state::RenderState::load(&path)
            .unwrap_err()
            .to_string();
        assert!(e.contains("sized.state") && e.contains("corrupt"), "{e}");
    }
}

#[test]
fn state_of_an_older_format_version_is_refused_by_name() {
    // A version-2 file: the current fields minus the merged-seed list, so postcard alone would
    // only report a truncated file.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("old.state");
    let mut st = candela::state::RenderState::new(
        std::path::Path::new("s.ron"),
        7,
        &world(FURNACE),
        Film::new(2, 2),
    );
    st.version = 2;
    let mut bytes = postcard::to_stdvec(&st).unwrap();
    bytes.pop(); // the empty merged-seed list's length byte
    std::fs::write(&path, bytes).unwrap();
    let e = candela::state::RenderState::load(&path)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("old.state") && e.contains("format version 2"),
        "{e}"
    );
}

#[test]
fn state_without_batch_sums_is_refused_by_name() {
    // Version 4 (intact, with its checksum) has no per-pixel batch sums to estimate the pixels'
    // standard errors from.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("v4.state");
    let mut st = candela::state::RenderState::new(
        std::path::Path::new("s.ron"),
        7,
        &world(FURNACE),
        Film::new(2, 2),
    );
    st.version = 4;
    st.save(&path).unwrap();
    let e = candela::state::RenderState::load(&path)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("v4.state") && e.contains("format version 4") && e.contains("batch sums"),
        "{e}"
    );
}

#[test]
fn adaptive_buffers_have_independent_illuminance_samples() {
    // The decision buffer decides when a pixel stops; if its illuminance samples repeated the
    // image's, the stopping time would depend on the image's own estimate (biased). A floor
    // under a sky: every sample's illuminance estimate is random.
    let w = world(
        r#"(
        camera: (position: (0, 1, -1), look_at: (0, 0, 0), vfov_deg: 40, resolution: (6, 6)),
        render: (spp: 16, illuminance: true),
        materials: { "floor": Diffuse(reflectance: Constant(0.5)) },
        objects: [(shape: Quad(origin: (-5, 0, -5), edge_u: (0, 0, 10), edge_v: (10, 0, 0)), material: "floor")],
        lights: [Environment(spectrum: Named("D65"), amount: Luminance(1000.0)),
                 Point(position: (0.3, 0.5, 0.2), spectrum: Named("A"), amount: Intensity(50.0))],
    )"#,
    );
    let mut film = Film::new_adaptive(6, 6);
    let prog = Progressive {
        max_spp: 64,
        target: Some(TargetError {
            relative: 1e-4,
            fraction: 1.0,
            floor_cd_m2: None,
        }),
        ..Default::default()
    };
    run(&w, &mut film, &prog, None);
    let (e, d) = (film.e.as_ref().unwrap(), film.decision_e.as_ref().unwrap());
    let (mut both, mut differ) = (0, 0);
    for (a, b) in e.iter().zip(d) {
        assert_eq!(a.count_e, b.count_e);
        if a.count_e > 0 {
            both += 1;
            differ += (a.sum_e != b.sum_e) as usize;
        }
    }
    assert!(
        both == 36 && differ == both,
        "{differ} of {both} pixels differ"
    );
}

/// A film whose batches per pixel differ from the scene's is refused before a sample is
/// taken: its standard errors would fold the samples into the wrong batches.
#[test]
fn a_film_of_other_batches_is_refused() {
    let w = world(&FURNACE.replace("max_depth: 64)", "max_depth: 64, pixel_batches: 4)"));
    let mut film = Film::new(10, 10);
    let e = render_progressive(
        &w,
        &mut film,
        Some(1),
        &Progressive::default(),
        &AtomicBool::new(false),
        &mut |_| {},
        &mut |_| Ok(()),
    )
    .err()
    .expect("refused")
    .to_string();
    assert!(e.contains("render.pixel_batches"), "{e}");
    assert_eq!(film.total_samples(), 0);
    film.pixel_batches = 4;
    let p = Progressive {
        max_spp: 4,
        ..Default::default()
    };
    run(&w, &mut film, &p, None);
    assert_eq!(film.total_samples(), 400);
}
