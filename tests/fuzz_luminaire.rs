//! Property-based fuzzing of the photometric file readers (`luminaire::load`: IES LM-63 and
//! EULUMDAT) on temporary files: the example luminaires in `data/luminaires/`, mutated (hostile
//! numbers in counts, angles and candela, byte flips, insertions, deletions, splices,
//! truncation), and random bytes. Each must give a photometry whose table is well formed, or
//! an `Err` naming the file — never a panic. An accepted file then gets the data-sheet
//! summary and the polar diagram `candela luminaire` draws, and is used as a goniometric light
//! in a tiny scene that must render finite pixels or be refused naming the scene.
//! `PROPTEST_CASES=N` sets the number of cases.

mod fuzz_common;

use candela::luminaire::{self, diagram, summary};
use candela::scene::{self, Overrides};
use fuzz_common::{apply, config, plan};
use proptest::prelude::*;
use std::path::Path;

/// The seeds and the extension each is read with.
fn seeds() -> &'static [(Vec<u8>, &'static str)] {
    static SEEDS: std::sync::OnceLock<Vec<(Vec<u8>, &'static str)>> = std::sync::OnceLock::new();
    SEEDS.get_or_init(|| {
        [
            "narrow-spot.ies",
            "batwing-office.ies",
            "wall-washer.ies",
            "batwing-office.ldt",
        ]
        .iter()
        .map(|f| {
            let bytes = std::fs::read(Path::new("data/luminaires").join(f)).unwrap();
            (bytes, if f.ends_with(".ldt") { "ldt" } else { "ies" })
        })
        .collect()
    })
}

const SCENE: &str = r#"(
    camera: (position: (0.2, 1.5, -2.5), look_at: (0, 0, 0), vfov_deg: 70, resolution: (4, 3)),
    render: (spp: 1, max_depth: 3),
    materials: { "grey": Diffuse(reflectance: Constant(0.5)) },
    objects: [
        (shape: Quad(origin: (-3, 0, -3), edge_u: (0, 0, 6), edge_v: (6, 0, 0)), material: "grey"),
        (shape: Sphere(center: (0.5, 0.3, 0.2), radius: 0.3), material: "grey"),
    ],
    lights: [Goniometric(file: FILE, position: (0, 1.2, 0), rotate_deg: (10, 20, 0),
                         spectrum: Blackbody(3000) AMOUNT)],
)"#;

fn check(bytes: &[u8], ext: &str) {
    let dir = tempfile::tempdir().unwrap();
    let name = format!("lum.{ext}");
    let file = dir.path().join(&name);
    std::fs::write(&file, bytes).unwrap();
    let shown = String::from_utf8_lossy(bytes);
    let p = match luminaire::load(&file) {
        Ok(p) => p,
        Err(e) => {
            let m = e.to_string();
            assert!(m.contains(&name), "error does not name the file: {m}");
            return;
        }
    };
    let increasing =
        |v: &[f64]| v.iter().all(|a| a.is_finite()) && v.windows(2).all(|w| w[0] < w[1]);
    assert!(!p.planes.is_empty() && increasing(&p.planes), "{shown}");
    assert!(!p.angles.is_empty() && increasing(&p.angles), "{shown}");
    assert_eq!(p.candela.len(), p.planes.len(), "{shown}");
    for row in &p.candela {
        assert_eq!(row.len(), p.angles.len(), "{shown}");
        assert!(row.iter().all(|c| c.is_finite() && *c >= 0.0), "{shown}");
    }
    let s = summary::summarise(&p);
    assert!(s.integrated_lumens >= 0.0, "{shown}");
    assert!(!s.max_cd.is_nan(), "{shown}");
    let _ = diagram::draw(&p.distribution(), "fuzz");

    for amount in ["", ", lumens: Some(1000)", ", multiplier: Some(1e-3)"] {
        let text = SCENE
            .replace("FILE", &format!("{name:?}"))
            .replace("AMOUNT", amount);
        let path = dir.path().join("scene.ron");
        let parsed = scene::parse(&text, &path).unwrap();
        match scene::build(&parsed, &path, &Overrides::default()) {
            Ok(world) => {
                let r = candela::render::render(&world, Some(1), &|_, _| {}).unwrap();
                for px in &r.film.pixels {
                    assert!(px.mean_xyz().iter().all(|v| v.is_finite()), "{shown}");
                }
                assert_eq!(
                    r.stats.non_finite, 0,
                    "non-finite samples ({amount}) on:\n{shown}"
                );
            }
            Err(e) => {
                let m = e.to_string();
                assert!(m.contains("scene.ron"), "{m}");
            }
        }
    }
}

#[test]
fn seeds_load_and_render() {
    for (bytes, ext) in seeds() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join(format!("seed.{ext}"));
        std::fs::write(&f, bytes).unwrap();
        luminaire::load(&f).unwrap_or_else(|e| panic!("{e}"));
        check(bytes, ext);
    }
}

proptest! {
    #![proptest_config(config(500))]

    #[test]
    fn mutated_luminaire_files_never_panic((seed, muts) in plan(4, 5)) {
        let all = seeds();
        let others: Vec<&[u8]> = all.iter().map(|(b, _)| b.as_slice()).collect();
        let (bytes, ext) = &all[seed];
        check(&apply(bytes, &muts, &others), ext);
    }

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        check(&bytes, "ies");
        check(&bytes, "ldt");
        let mut ies = b"IESNA:LM-63-2002\nTILT=NONE\n".to_vec();
        ies.extend(&bytes);
        check(&ies, "ies");
    }
}
