//! Property-based fuzzing of the CSV spectrum parser
//! (`SpectralDistribution::from_csv_str` / `from_csv_path`) and of its use as a reflectance and
//! an emission spectrum in a scene: mutated valid files and random text must give `Ok` (with
//! the documented invariants) or an `Err` naming the file — never a panic, and a scene built
//! from an accepted file renders finite pixels. `PROPTEST_CASES=N` sets the number of cases.

mod fuzz_common;

use candela::colour::sd::SpectralDistribution;
use candela::scene::{self, Overrides};
use fuzz_common::{apply, config, plan};
use proptest::prelude::*;

const SEEDS: &[&str] = &[
    "nm,value\n380,0.1\n500,0.5\n780,0.9\n",
    "# lamp, relative\n# second comment\nwavelength;power\n360;0\n400;0.25 # blue\n550;1\n700;0.5\n830;0.1\n",
    "\u{feff}400\t0.2\n450\t0.3\n500\t0.4\n550\t0.6\n600\t0.7\n650\t0.72\n700\t0.75\n",
    "380.5, 1e-3\n381.5, 2.5E-1\n\n\n382.5, 0.5\n",
];

const SCENE: &str = r#"(
    camera: (position: (0, 1, -2), look_at: (0, 0, 0), vfov_deg: 60, resolution: (2, 2)),
    render: (spp: 1, max_depth: 3),
    materials: { "m": Diffuse(reflectance: Csv("s.csv")) },
    objects: [
        (shape: Quad(origin: (-1, 0, -1), edge_u: (0, 0, 2), edge_v: (2, 0, 0)), material: "m"),
        (shape: Sphere(center: (0, 2, 0), radius: 0.2), material: "black",
         emission: (spectrum: Csv("s.csv"), amount: Luminance(1000))),
    ],
    lights: [Point(position: (0, 1, 0), spectrum: Csv("s.csv"), amount: Intensity(10))],
)"#;

fn check(bytes: &[u8]) {
    let text = String::from_utf8_lossy(bytes);
    match SpectralDistribution::from_csv_str(&text, "fuzz.csv") {
        Ok(sd) => {
            let w = &sd.wavelengths_nm;
            assert!(w.len() >= 2 && w.len() == sd.values.len());
            assert!(w.windows(2).all(|p| p[0] < p[1]), "not increasing: {w:?}");
            assert!(w.iter().chain(&sd.values).all(|v| v.is_finite()));
            for nm in [
                f64::NAN,
                -1.0,
                360.0,
                555.5,
                830.0,
                1e300,
                w[0],
                w[w.len() - 1],
            ] {
                let _ = sd.value(nm);
            }
            let _ = sd.to_table();
        }
        Err(e) => {
            let m = e.to_string();
            assert!(m.contains("fuzz.csv"), "error does not name the file: {m}");
        }
    }
    // The same bytes as a file used by a scene (reflectance, area emission, point light).
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.csv"), bytes).unwrap();
    let path = dir.path().join("scene.ron");
    let parsed = scene::parse(SCENE, &path).unwrap();
    match scene::build(&parsed, &path, &Overrides::default()) {
        Ok(world) => {
            let r = candela::render::render(&world, Some(1), &|_, _| {}).unwrap();
            for p in &r.film.pixels {
                assert!(p.mean_xyz().iter().all(|v| v.is_finite()), "{text}");
            }
            assert_eq!(r.stats.non_finite, 0, "{text}");
        }
        Err(e) => {
            let m = e.to_string();
            assert!(m.contains("scene.ron"), "{m}");
        }
    }
}

#[test]
fn seeds_parse() {
    for s in SEEDS {
        SpectralDistribution::from_csv_str(s, "seed.csv").unwrap_or_else(|e| panic!("{e}"));
    }
}

proptest! {
    #![proptest_config(config(1500))]

    #[test]
    fn mutated_csv_never_panics((seed, muts) in plan(SEEDS.len(), 5)) {
        let seeds: Vec<&[u8]> = SEEDS.iter().map(|s| s.as_bytes()).collect();
        check(&apply(seeds[seed], &muts, &seeds));
    }

    #[test]
    fn random_csv_never_panics(
        bytes in proptest::collection::vec(any::<u8>(), 0..200),
        s in "([0-9eE.,;#\t +-]|nan|inf|\n){0,80}",
    ) {
        check(&bytes);
        check(s.as_bytes());
    }
}
