//! Allocations sized by input are checked before they are made: a grid whose heat map could not
//! be drawn is refused before the render, heat maps stay bounded, `bench` refuses what it
//! could not hold, false-colour maps and probes check the memory an image asks for, and the
//! film's memory guard covers what light tracing and checkpoints add.

use candela::output::Layers;
use candela::report::falsecolour::{render_falsecolour, FalsecolourSettings};
use candela::report::heatmap::{render_grid_heatmap, GridValues, MAX_HEATMAP_PIXELS};
use candela::report::probe::probe;
use candela::report::units::UnitSystem;
use std::process::Command;
use std::time::{Duration, Instant};

fn candela(args: &[&str], dir: &std::path::Path) -> (i32, String, Duration) {
    let t0 = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
        t0.elapsed(),
    )
}

fn scene_with_grid(name: &str, nx: u32, ny: u32) -> String {
    format!(
        r#"(
    camera: (position: (0, 1, -3), look_at: (0, 0, 0), vfov_deg: 40, resolution: (8, 8)),
    render: (spp: 1),
    materials: {{ "grey": Diffuse(reflectance: Constant(0.5)) }},
    objects: [(shape: Quad(origin: (-1, 0, -1), edge_u: (0, 0, 2), edge_v: (2, 0, 0)), material: "grey")],
    lights: [Point(position: (0, 2, 0), spectrum: Named("D65"), amount: Intensity(10.0))],
    grids: [(name: "{name}", origin: (-1, 0.01, -1), edge_u: (2, 0, 0), edge_v: (0, 0, 2), nx: {nx}, ny: {ny})],
    measure: (samples: 1),
)"#
    )
}

/// A 10⁶ × 1 grid asked for a 28 000 000-pixel-wide heat map (36 GB) after the render; it is
/// refused when the scene is read, naming the grid, its field and the limit.
#[test]
fn a_grid_too_long_for_its_heat_map_is_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("s.ron"),
        scene_with_grid("corridor", 1_000_000, 1),
    )
    .unwrap();
    let (code, stderr, took) = candela(&["render", "--quiet", "s.ron"], dir.path());
    assert_eq!(code, 1, "{stderr}");
    for needle in ["s.ron", "grids[0].nx", "\"corridor\"", "1000000", "4096"] {
        assert!(
            stderr.contains(needle),
            "{needle:?} missing from:\n{stderr}"
        );
    }
    assert!(took < Duration::from_secs(10), "took {took:?}");
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(left.len(), 1, "files written: {left:?}");

    // The longest edge the heat map draws is accepted (the scene builds).
    let path = dir.path().join("ok.ron");
    std::fs::write(&path, scene_with_grid("line", 4096, 2)).unwrap();
    let world = candela::scene::load_world(&path, &Default::default()).unwrap();
    assert_eq!((world.grids[0].nx, world.grids[0].ny), (4096, 2));
}

/// A grid name becomes part of two file names: one longer than the limit is refused when the
/// scene is read, not when the files are written after the render.
#[test]
fn a_grid_name_too_long_for_a_file_name_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.ron");
    std::fs::write(&path, scene_with_grid(&"g".repeat(300), 2, 2)).unwrap();
    let e = candela::scene::load_world(&path, &Default::default())
        .err()
        .expect("refused")
        .to_string();
    for needle in ["grids[0].name", "300 characters", "limit of 100"] {
        assert!(e.contains(needle), "{needle:?} missing from: {e}");
    }
    assert!(e.len() < 600, "the message repeats the whole name: {e}");
}

fn ramp_grid(nx: usize, ny: usize) -> GridValues {
    let n = nx * ny;
    GridValues {
        name: "wide".into(),
        nx,
        ny,
        values: (0..n).map(|k| 100.0 * k as f64 / (n - 1) as f64).collect(),
        stderr: Vec::new(),
        size_m: (nx as f64 * 0.1, ny as f64 * 0.1),
    }
}

/// Large grids are drawn with smaller cells: the image stays within its bound, and each
/// cell still shows its value's colour.
#[test]
fn heat_maps_of_large_grids_are_bounded() {
    for (nx, ny) in [(4000, 3), (300, 300), (3, 2000)] {
        let grid = ramp_grid(nx, ny);
        let settings = FalsecolourSettings {
            min: Some(0.0),
            max: Some(100.0),
            ..Default::default()
        };
        let (img, info) = render_grid_heatmap(&grid, &settings).unwrap();
        let (w, h) = img.dimensions();
        assert!(
            w as u64 * h as u64 <= MAX_HEATMAP_PIXELS && w <= 4096 + 1600 && h <= 4096 + 600,
            "{nx}×{ny}: {w}×{h} pixels, cells of {} px",
            info.cell_px
        );
        assert!(info.cell_px >= 1 && (nx.max(ny) as u32) * info.cell_px <= 4096);
        for (i, j) in [(0, 0), (nx - 1, ny - 1), (nx / 2, ny / 3)] {
            let (x, y) = info.cell_centre(i, j, ny);
            let want = info.scale.colour(grid.values[j * nx + i]);
            assert_eq!(img.get_pixel(x, y).0, want, "{nx}×{ny}: cell ({i}, {j})");
        }
    }
}

/// `candela bench` refuses counts above its maxima at once, naming the option and the limit.
#[test]
fn bench_maxima_are_refused_before_anything_is_generated() {
    let dir = tempfile::tempdir().unwrap();
    for (args, needles) in [
        (
            &["bench", "--triangles", "100000000"][..],
            &["--triangles 100000000", "at most 50000000"][..],
        ),
        (
            &[
                "bench",
                "scaling",
                "--triangles",
                "1000",
                "--linearity-triangles",
                "60000000",
            ],
            &["--linearity-triangles 60000000", "at most 50000000"],
        ),
        (
            &["bench", "traversal", "--resolution", "8193"],
            &["--resolution 8193", "at most 8192"],
        ),
    ] {
        let (code, stderr, took) = candela(args, dir.path());
        assert_ne!(code, 0, "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        for n in needles {
            assert!(
                stderr.contains(n),
                "{args:?}: {n:?} missing from:\n{stderr}"
            );
        }
        assert!(took < Duration::from_secs(10), "{args:?} took {took:?}");
    }
}

/// The largest accepted `bench traversal` (50 M triangles, 8192² rays) needs about 31 GiB; where
/// that is not available it is refused before the mesh is generated, naming the options and
/// both sizes.
#[test]
fn bench_traversal_beyond_the_memory_available_is_refused() {
    let need = 50_000_000u64 * 360 + 8192 * 8192 * 200;
    match candela::limits::available_memory_bytes() {
        Some(avail) if avail < need => {}
        other => {
            eprintln!("skipped: {other:?} bytes available, the maximal benchmark fits");
            return;
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let (code, stderr, took) = candela(
        &[
            "bench",
            "traversal",
            "--triangles",
            "50000000",
            "--resolution",
            "8192",
            "--reps",
            "1",
        ],
        dir.path(),
    );
    assert_ne!(code, 0, "{stderr}");
    for n in [
        "--triangles 50000000",
        "--resolution 8192",
        "needs about",
        "is available",
    ] {
        assert!(stderr.contains(n), "{n:?} missing from:\n{stderr}");
    }
    assert!(took < Duration::from_secs(10), "took {took:?}");
}

/// A false-colour map needs about 25 bytes a pixel beside the image: an image that asks for
/// more than the memory available is refused before those buffers are allocated. (The channel
/// here is zero-filled memory the system has not yet provided, so it costs nothing.)
#[test]
fn falsecolour_refuses_an_image_beyond_the_memory_available() {
    let Some(avail) = candela::limits::available_memory_bytes() else {
        eprintln!("skipped: the system does not say how much memory is available");
        return;
    };
    let pixels = (avail / 8) as usize;
    let (w, h) = (1 << 16, pixels >> 16);
    let mut layers = Layers::new(w, h);
    layers.channels.push(("Y".into(), vec![0.0f32; w * h]));
    let t0 = Instant::now();
    let Err(e) = render_falsecolour(&layers, &FalsecolourSettings::default()) else {
        panic!("a {w}×{h} false-colour map was drawn");
    };
    for n in [&format!("{w}×{h} image"), "needs about", "is available"] {
        assert!(e.contains(n), "{n:?} missing from: {e}");
    }
    assert!(t0.elapsed() < Duration::from_secs(5));
}

fn small_layers() -> Layers {
    let (w, h) = (5, 4);
    let mut layers = Layers::new(w, h);
    layers
        .channels
        .push(("Y".into(), (0..w * h).map(|i| i as f32).collect()));
    layers
}

/// A radius beyond the image covers the whole image (it once overflowed the pixel range).
#[test]
fn probe_with_a_huge_radius_averages_the_whole_image() {
    let layers = small_layers();
    for r in [1e9, 1e300, f64::MAX] {
        let p = probe(&layers, 3, 2, Some(r), UnitSystem::Si).unwrap();
        assert_eq!(p.pixels, 20, "radius {r}");
        assert!((p.luminance.mean - 9.5).abs() < 1e-9, "radius {r}: {p:?}");
    }
}

/// Channels shorter than the image are an error, not an out-of-bounds panic.
#[test]
fn a_channel_shorter_than_the_image_is_an_error() {
    let mut layers = small_layers();
    layers.channels[0].1.truncate(7);
    let e = probe(&layers, 4, 3, None, UnitSystem::Si).unwrap_err();
    assert!(e.contains("'Y' has 7 samples, expected 5×4"), "{e}");
    let e = render_falsecolour(&layers, &FalsecolourSettings::default()).unwrap_err();
    assert!(e.contains("'Y' has 7 samples, expected 5×4"), "{e}");
}

/// The film's memory guard covers what light-traced caustics and the render state add: its
/// estimate is at least the peak RSS measured for `candela render` with a checkpoint after
/// every pass and the state written at the end (`--checkpoint-interval 1s --save-state`), and
/// at most 1.35 times it (at 2048²: 1.25 times).
#[test]
fn memory_guard_covers_caustics_and_checkpoints() {
    use candela::scene::build::{peak_bytes_per_pixel, RENDER_BASE_BYTES};
    use candela::scene::RunMode;
    let plain = RunMode::default();
    let adaptive = RunMode {
        adaptive: true,
        falsecolour: false,
    };
    let adaptive_fc = RunMode {
        adaptive: true,
        falsecolour: true,
    };
    // (scene, side, mode, --illuminance, light-traced caustics, peak RSS in kB): GNU time's %M
    // of the release build rendering scenes/NAME.ron at side² with `--threads 2
    // --checkpoint-interval 1s --save-state` and `--spp 2` or `--target-error 1% --max-spp 4`
    // (adaptive; with --falsecolour for adaptive_fc), one run each on a 2-core machine shared
    // with other jobs.
    let measured = [
        ("cornell-box", 2048, plain, false, false, 2_572_412u64),
        ("cornell-box", 2048, adaptive, false, false, 5_155_612),
        ("cornell-glass", 2048, plain, false, true, 2_587_852),
        ("cornell-glass", 2048, plain, true, true, 4_705_780),
        ("cornell-glass", 2048, adaptive_fc, true, true, 9_173_140),
        ("cornell-glass", 2048, adaptive, false, true, 5_108_080),
        ("bench-cornell", 2048, plain, false, true, 2_588_528),
        ("cornell-box", 1024, plain, false, false, 672_360),
        ("cornell-glass", 1024, plain, false, true, 675_144),
        ("cornell-box", 1024, adaptive, false, false, 1_296_448),
    ];
    for (scene, side, mode, illuminance, caustics, kb) in measured {
        let px = side as u64 * side as u64;
        let est = RENDER_BASE_BYTES + px * peak_bytes_per_pixel(&mode, illuminance, caustics);
        let ratio = est as f64 / (kb * 1024) as f64;
        let most = if side == 2048 { 1.25 } else { 1.35 };
        assert!(
            (1.0..=most).contains(&ratio),
            "{scene} {side}² {mode:?} illuminance {illuminance}: estimate {est} B is {ratio:.3} × the measured peak"
        );
    }
}

/// A resolution whose film fits the memory available for camera paths alone, but not with
/// light tracing's buffers, is refused for a glass scene and accepted without light tracing.
#[test]
fn memory_guard_counts_light_tracing_when_the_scene_has_caustics() {
    use candela::scene::build::{peak_bytes_per_pixel, RENDER_BASE_BYTES};
    use candela::world::Caustics;
    let Some(avail) = candela::limits::available_memory_bytes() else {
        eprintln!("skipped: the system does not say how much memory is available");
        return;
    };
    let mode = candela::scene::RunMode::default();
    let (without, with) = (
        peak_bytes_per_pixel(&mode, false, false),
        peak_bytes_per_pixel(&mode, false, true),
    );
    // Halfway between the two estimates: about 20 % either side of the memory available.
    let px = avail.saturating_sub(RENDER_BASE_BYTES) * 2 / (without + with);
    let side = (px as f64).sqrt() as u64;
    let scene = format!(
        r#"(
    camera: (position: (0, 1, -3), look_at: (0, 0, 0), vfov_deg: 40, resolution: ({side}, {side})),
    materials: {{ "grey": Diffuse(reflectance: Constant(0.5)), "glass": Dielectric(ior: Glass("BK7")) }},
    objects: [
        (shape: Quad(origin: (-1, 0, -1), edge_u: (0, 0, 2), edge_v: (2, 0, 0)), material: "grey"),
        (shape: Sphere(center: (0, 0.5, 0), radius: 0.3), material: "glass"),
    ],
    lights: [Point(position: (0, 2, 0), spectrum: Named("D65"), amount: Intensity(10.0))],
)"#
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("glass.ron");
    std::fs::write(&path, scene).unwrap();
    let e = candela::scene::load_world(&path, &Default::default())
        .err()
        .expect("refused with light tracing")
        .to_string();
    for n in [
        "camera.resolution",
        &format!("{side}×{side} pixels"),
        "light-traced caustics",
        "is available",
    ] {
        assert!(e.contains(n), "{n:?} missing from: {e}");
    }
    let overrides = candela::scene::Overrides {
        caustics: Some(Caustics::PathTracing),
        ..Default::default()
    };
    let world = candela::scene::load_world(&path, &overrides).unwrap();
    assert!(world.caustics.is_none());
}

// --- Under an address-space limit (`ulimit -v`) ------------------------------------------------

/// 4 GiB of address space, as scripts/hostile.sh runs its cases.
const ULIMIT_KB: u64 = 4 << 20;

/// `candela ARGS` in `dir` under `ulimit -v ULIMIT_KB`: exit code and standard error.
fn candela_under_ulimit(args: &[&str], dir: &std::path::Path) -> (i32, String) {
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {ULIMIT_KB} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_candela"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A constant Radiance picture of `w`×`h` in the fewest bytes a scanline can take (one pixel,
/// then old-style runs of it): 16384² in 197 kB.
fn dense_hdr(w: usize, h: usize, view: bool) -> Vec<u8> {
    let mut b = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n".to_vec();
    if view {
        b.extend(b"VIEW= -vta -vh 180 -vv 180\n");
    }
    b.extend(format!("\n-Y {h} +X {w}\n").bytes());
    let mut line = vec![128, 128, 128, 129];
    let mut rest = w - 1;
    while rest > 0 {
        line.extend([1, 1, 1, (rest & 255) as u8]);
        rest >>= 8;
    }
    for _ in 0..h {
        b.extend(&line);
    }
    b
}

/// A scan-line EXR of `w`×`h` f32 pixels in `channels`, ZIP-compressed zeros (16 lines a
/// block, each ~1000 times smaller than its pixels): 16384² × 7 channels in 7 MB.
fn zip_exr(w: u32, h: u32, channels: &[&str]) -> Vec<u8> {
    let mut v = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
    let mut attr = |name: &str, ty: &str, value: &[u8]| {
        v.extend(name.as_bytes());
        v.push(0);
        v.extend(ty.as_bytes());
        v.push(0);
        v.extend((value.len() as u32).to_le_bytes());
        v.extend(value);
    };
    let mut names = channels.to_vec();
    names.sort();
    let mut chlist = Vec::new();
    for c in &names {
        chlist.extend(c.as_bytes());
        chlist.push(0);
        chlist.extend(2i32.to_le_bytes()); // FLOAT
        chlist.extend([0, 0, 0, 0]);
        chlist.extend(1i32.to_le_bytes());
        chlist.extend(1i32.to_le_bytes());
    }
    chlist.push(0);
    attr("channels", "chlist", &chlist);
    attr("compression", "compression", &[3]);
    let window: Vec<u8> = [0i32, 0, w as i32 - 1, h as i32 - 1]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    attr("dataWindow", "box2i", &window);
    attr("displayWindow", "box2i", &window);
    attr("lineOrder", "lineOrder", &[0]);
    attr("pixelAspectRatio", "float", &1f32.to_le_bytes());
    attr("screenWindowCenter", "v2f", &[0; 8]);
    attr("screenWindowWidth", "float", &1f32.to_le_bytes());
    v.push(0);
    let block = miniz_oxide::deflate::compress_to_vec_zlib(
        &vec![0u8; w as usize * 4 * channels.len() * 16],
        9,
    );
    let chunks = h.div_ceil(16) as u64;
    let first = v.len() as u64 + chunks * 8;
    for i in 0..chunks {
        v.extend((first + i * (8 + block.len() as u64)).to_le_bytes());
    }
    for i in 0..chunks {
        v.extend((i as i32 * 16).to_le_bytes());
        v.extend((block.len() as i32).to_le_bytes());
        v.extend(&block);
    }
    v
}

/// Under `ulimit -v` 4 GiB, every command that reads an image refuses one that needs more
/// than the address space left, before decoding it and naming the file and the limit, where
/// each used to abort (exit 134, "memory allocation of … failed") after seconds of decoding:
/// a 197 kB picture of 16384² (report, falsecolour, glare hold 36 to 57 bytes a pixel beside
/// its 12), a 7-channel EXR of 16384² (probe: 7.5 GB of samples), the HTML report of it, and
/// `bench traversal --resolution 8192` (13 GB of rays). The 16384² picture's probe needs
/// 3.1 GB (measured peak RSS) and is not refused for want of memory.
#[test]
fn under_an_address_space_limit_images_are_refused_not_aborted() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("big.hdr"), dense_hdr(16384, 16384, true)).unwrap();
    let seven = ["X", "Y", "Z", "stderr.Y", "E", "stderr.E", "mask.E"];
    std::fs::write(d.join("seven.exr"), zip_exr(16384, 16384, &seven)).unwrap();
    for (args, file) in [
        (&["report", "big.hdr", "-o", "big.html"][..], "big.hdr"),
        (&["falsecolour", "big.hdr", "-o", "big.png"], "big.hdr"),
        (&["glare", "big.hdr"], "big.hdr"),
        (&["probe", "seven.exr", "0", "0"], "seven.exr"),
        (&["report", "seven.exr", "-o", "seven.html"], "seven.exr"),
        (
            &["falsecolour", "seven.exr", "-o", "seven.png"],
            "seven.exr",
        ),
        (&["glare", "seven.exr"], "seven.exr"),
        (
            &[
                "bench",
                "traversal",
                "--resolution",
                "8192",
                "--triangles",
                "1000",
            ],
            "--resolution 8192",
        ),
    ] {
        let t0 = Instant::now();
        let (code, stderr) = candela_under_ulimit(args, d);
        assert_eq!(code, 1, "{args:?}: {stderr}");
        for n in [
            file,
            "needs about",
            "under the address-space limit (ulimit -v)",
        ] {
            assert!(
                stderr.contains(n),
                "{args:?}: {n:?} missing from:\n{stderr}"
            );
        }
        assert!(
            t0.elapsed() < Duration::from_secs(10),
            "{args:?}: {:?}",
            t0.elapsed()
        );
    }
    let left: Vec<_> = std::fs::read_dir(d).unwrap().collect();
    assert_eq!(left.len(), 2, "files written: {left:?}");
}

/// A picture whose resolution line declares more scanlines than the file could hold at the
/// densest encoding (30000 lines of 30000 pixels take 360 kB; the file has 200 kB) is refused
/// from its header by every command, with or without an address-space limit, naming the file
/// and both sizes: it used to be decoded up to the 16662nd scanline (1.9 GB) first.
#[test]
fn a_picture_shorter_than_its_declared_size_is_refused_from_its_header() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut bytes = dense_hdr(30000, 30000, true);
    bytes.truncate(200_000);
    std::fs::write(d.join("short.hdr"), bytes).unwrap();
    for args in [
        &["probe", "short.hdr", "0", "0"][..],
        &["report", "short.hdr", "-o", "s.html"],
        &["falsecolour", "short.hdr", "-o", "s.png"],
        &["glare", "short.hdr"],
    ] {
        let t0 = Instant::now();
        let (code, stderr, _) = candela(args, d);
        assert_eq!(code, 1, "{args:?}: {stderr}");
        for n in ["short.hdr", "30000×30000", "at least 360000 bytes"] {
            assert!(
                stderr.contains(n),
                "{args:?}: {n:?} missing from:\n{stderr}"
            );
        }
        assert!(
            t0.elapsed() < Duration::from_secs(2),
            "{args:?}: {:?}",
            t0.elapsed()
        );
        let (code, stderr) = candela_under_ulimit(args, d);
        assert_eq!(code, 1, "{args:?} under ulimit: {stderr}");
    }
}

/// Under `ulimit -v` 4 GiB a normal render works (with its HTML report and false colour), and
/// a film that needs more than the address space left (4096², about 10 GB) is refused naming
/// the scene's resolution and the limit, where the machine's free memory alone would let it
/// start and abort.
#[test]
fn renders_under_an_address_space_limit() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.ron"), scene_with_grid("desk", 4, 4)).unwrap();
    let (code, stderr) = candela_under_ulimit(
        &[
            "render",
            "--quiet",
            "s.ron",
            "--resolution",
            "512x512",
            "--illuminance",
            "--falsecolour",
            "--report-html",
        ],
        d,
    );
    assert_eq!(code, 0, "{stderr}");
    assert!(d.join("s.html").is_file() && d.join("s.luminance.png").is_file());
    let (code, stderr) = candela_under_ulimit(
        &[
            "render",
            "--quiet",
            "s.ron",
            "--resolution",
            "4096x4096",
            "--out",
            "big",
        ],
        d,
    );
    assert_eq!(code, 1, "{stderr}");
    for n in ["s.ron", "4096×4096", "is available"] {
        assert!(stderr.contains(n), "{n:?} missing from:\n{stderr}");
    }
    assert!(!d.join("big.exr").exists());
}
