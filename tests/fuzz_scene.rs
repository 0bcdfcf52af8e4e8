//! Property-based fuzzing of the scene pipeline: `scene::parse` → `scene::build` → a tiny
//! render and the meters, on mutated valid scenes (hostile numbers, byte flips, truncation,
//! splicing) and on random bytes. Every input must give `Ok` with finite pixels and meter
//! values (and no non-finite sample dropped by the renderer) or an `Err` whose message names
//! the scene file — never a panic. `PROPTEST_CASES=N` sets the number of cases (see
//! docs/fuzzing.md).

mod fuzz_common;

use candela::scene::{self, Overrides};
use fuzz_common::{apply, config, plan};
use proptest::prelude::*;
use std::path::{Path, PathBuf};

/// Exercises every construct of the format; refers to the side files written by `fixture`.
const ALL_FEATURES: &str = r#"Scene(
    camera: (position: (0.0, 1.0, -3.0), look_at: (0.0, 0.5, 0.0), up: (0.0, 1.0, 0.0), vfov_deg: 50.0,
             resolution: (4, 3), lens: Some((aperture_radius: 0.01, focus_distance: 3.0))),
    render: (spp: 2, max_depth: 5, rr_depth: 2, seed: 7, illuminance: true, filter: Gaussian(sigma: 0.5, radius: 1.5)),
    materials: {
        "white": Diffuse(reflectance: Constant(0.8)),
        "red": Diffuse(reflectance: Rgb(0.8, 0.1, 0.1)),
        "srgb": Diffuse(reflectance: Srgb(0.2, 0.5, 0.9)),
        "tab": Diffuse(reflectance: Tabulated([(400.0, 0.2), (550.0, 0.9), (700.0, 0.4)])),
        "csv": Diffuse(reflectance: Csv("refl.csv")),
        "named": Diffuse(reflectance: Named("colorchecker:3")),
        "ink": Black,
    },
    objects: [
        (name: "floor", material: "white",
         shape: Quad(origin: (-2.0, 0.0, -2.0), edge_u: (0.0, 0.0, 4.0), edge_v: (4.0, 0.0, 0.0))),
        (name: "ball", material: "red", shape: Sphere(center: (0.5, 0.5, 0.0), radius: 0.5),
         transform: (translate: (0.1, 0.0, 0.0), rotate_deg: (0.0, 30.0, 0.0), scale: (1.0, 1.0, 1.0))),
        (name: "disk", material: "srgb", shape: Disk(center: (-0.7, 0.3, 0.2), normal: (0.0, 1.0, 0.0), radius: 0.3)),
        (name: "tri", material: "tab",
         shape: Triangles(positions: [(0.0, 0.0, 1.0), (1.0, 0.0, 1.0), (0.0, 1.0, 1.0), (1.0, 1.0, 1.0)],
                          indices: [(0, 1, 2), (1, 3, 2)],
                          normals: Some([(0.0, 0.0, -1.0), (0.0, 0.0, -1.0), (0.0, 0.0, -1.0), (0.0, 0.0, -1.0)]))),
        (name: "obj", material: "csv", shape: Obj("tri.obj"), transform: (scale: (0.5, 2.0, 0.5))),
        (name: "ply", material: "named", shape: Ply("tri.ply"), transform: (translate: (-1.0, 0.0, 0.5))),
        (name: "lamp", material: "ink",
         shape: Quad(origin: (-0.25, 2.0, -0.25), edge_u: (0.5, 0.0, 0.0), edge_v: (0.0, 0.0, 0.5)),
         emission: (spectrum: Blackbody(4000.0), amount: Flux(500.0), two_sided: true)),
        (name: "glow", material: "white", shape: Sphere(center: (0.0, 1.5, 1.0), radius: 0.1),
         emission: (spectrum: Named("D65"), amount: Luminance(200.0))),
    ],
    lights: [
        Point(position: (1.0, 2.0, -1.0), spectrum: Named("A"), amount: Intensity(50.0)),
        Point(position: (-1.0, 2.0, -1.0), spectrum: Csv("emit.csv"), amount: Flux(300.0)),
        Spot(position: (0.0, 2.5, 0.0), look_at: (0.0, 0.0, 0.0), inner_deg: 20.0, outer_deg: 35.0,
             spectrum: Blackbody(3000.0), amount: Intensity(1000.0)),
        Spot(position: (0.5, 2.5, 0.0), look_at: (0.5, 0.0, 0.0), inner_deg: 10.0, outer_deg: 10.0,
             spectrum: Rgb(1.0, 0.9, 0.8), amount: Flux(100.0)),
        Distant(direction: (0.3, -1.0, 0.2), spectrum: Named("D65"), amount: Illuminance(1000.0)),
        Environment(spectrum: Srgb(0.5, 0.6, 1.0), amount: Luminance(100.0)),
    ],
    meters: [
        Illuminance(name: "floor", position: (0.0, 0.001, 0.0), normal: (0.0, 1.0, 0.0)),
        Luminance(name: "wall", position: (0.0, 1.0, -2.0), direction: (0.0, 0.0, 1.0), half_angle_deg: 1.0),
    ],
    grids: [
        (name: "plane", origin: (-1.0, 0.8, -1.0), edge_u: (2.0, 0.0, 0.0), edge_v: (0.0, 0.0, 2.0), nx: 2, ny: 2, normal: (0.0, 1.0, 0.0)),
    ],
    measure: (samples: 64, target_relative_error: Some(0.5), max_samples: 128),
)"#;

/// Side files referenced by the seeds, written next to the scene.
fn fixture() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let w = |name: &str, text: &str| std::fs::write(dir.path().join(name), text).unwrap();
    w("refl.csv", "nm,value\n380,0.1\n500,0.5\n780,0.9\n");
    w("emit.csv", "# lamp\n380,1\n550,3\n780,2\n");
    w(
        "tri.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nf 1//1 2//2 3//3\nf 2//2 4//4 3//3\n",
    );
    w(
        "tri.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
    );
    dir
}

fn seeds() -> Vec<Vec<u8>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut v = vec![ALL_FEATURES.as_bytes().to_vec()];
    for s in [
        "cornell-box.ron",
        "room-spot.ron",
        "furnace.ron",
        "sun-patch.ron",
    ] {
        v.push(std::fs::read(root.join("scenes").join(s)).unwrap());
    }
    v
}

/// Largest image the fuzz test renders (bigger valid scenes are only built).
const RENDER_PIXELS: usize = 64;

/// The whole pipeline on one input; panics (= a found bug) on any violated property.
fn check(bytes: &[u8], path: &Path) {
    let text = String::from_utf8_lossy(bytes);
    let parsed = match scene::parse(&text, path) {
        Ok(s) => s,
        Err(e) => {
            let m = e.to_string();
            assert!(
                m.contains("scene.ron"),
                "parse error does not name the file: {m}"
            );
            return;
        }
    };
    let world = match scene::build(&parsed, path, &Overrides::default()) {
        Ok(w) => w,
        Err(e) => {
            let m = e.to_string();
            assert!(
                m.contains("scene.ron"),
                "build error does not name the file: {m}"
            );
            return;
        }
    };
    let mut world = world;
    // Keep the work of one case tiny: at most 1 spp, a few bounces, a few meter samples.
    world.settings.spp = 1;
    world.settings.max_depth = Some(world.settings.max_depth.map_or(6, |d| d.min(6)));
    world.measure.samples = 8;
    world.measure.max_samples = 16;
    if world.camera.width * world.camera.height <= RENDER_PIXELS {
        let r = candela::render::render(&world, Some(1), &|_, _| {}).expect("render");
        for (i, p) in r.film.pixels.iter().enumerate() {
            let xyz = p.mean_xyz();
            assert!(
                xyz.iter().all(|v| v.is_finite())
                    && p.y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES)
                        .is_finite(),
                "pixel {i} is not finite: {xyz:?}\n{text}"
            );
        }
        assert_eq!(
            r.stats.non_finite, 0,
            "the renderer dropped non-finite samples\n{text}"
        );
    }
    let points: u64 = world.grids.iter().map(|g| g.nx as u64 * g.ny as u64).sum();
    if points + world.meters.len() as u64 <= 16 {
        let m = candela::meter::measure_all(&world);
        for e in m.meters.iter().chain(m.grids.iter().flatten()) {
            assert!(
                e.mean.is_finite() && e.stderr.is_finite(),
                "meter value not finite: {e:?}\n{text}"
            );
        }
    }
}

struct Env {
    _dir: tempfile::TempDir,
    path: PathBuf,
    seeds: Vec<Vec<u8>>,
}

fn env() -> Env {
    let dir = fixture();
    let path = dir.path().join("scene.ron");
    Env {
        path,
        _dir: dir,
        seeds: seeds(),
    }
}

#[test]
fn seeds_are_valid_scenes() {
    let e = env();
    for s in &e.seeds {
        let text = std::str::from_utf8(s).unwrap();
        let parsed = scene::parse(text, &e.path).unwrap_or_else(|err| panic!("{err}"));
        scene::build(&parsed, &e.path, &Overrides::default()).unwrap_or_else(|err| panic!("{err}"));
    }
    check(e.seeds[0].as_slice(), &e.path);
}

proptest! {
    #![proptest_config(config(2000))]

    /// Mutated valid scenes.
    #[test]
    fn mutated_scenes_never_panic((seed, muts) in plan(4, 4)) {
        let e = env();
        let refs: Vec<&[u8]> = e.seeds.iter().map(|s| s.as_slice()).collect();
        let bytes = apply(&e.seeds[seed], &muts, &refs);
        check(&bytes, &e.path);
    }

    /// Only hostile numbers (the most productive mutation), several at once.
    #[test]
    fn hostile_numbers_never_panic(
        seed in 0..4usize,
        muts in proptest::collection::vec(
            (any::<usize>(), 0..fuzz_common::HOSTILE_NUMBERS.len())
                .prop_map(|(k, v)| fuzz_common::Mutation::Number { k, v }),
            1..4,
        ),
    ) {
        let e = env();
        let refs: Vec<&[u8]> = e.seeds.iter().map(|s| s.as_slice()).collect();
        let bytes = apply(&e.seeds[seed], &muts, &refs);
        check(&bytes, &e.path);
    }

    /// Arbitrary bytes and arbitrary strings.
    #[test]
    fn random_input_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..400), s in ".{0,200}") {
        let e = env();
        check(&bytes, &e.path);
        check(s.as_bytes(), &e.path);
    }
}
