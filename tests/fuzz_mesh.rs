//! Property-based fuzzing of the mesh loaders (`geometry::load_obj`, `geometry::load_ply`) on
//! temporary files: mutated valid OBJ, ASCII PLY and binary PLY files and random bytes must
//! give a valid mesh or an `Err` naming the file — never a panic (the loaders' own
//! `catch_unwind` is not counted: a panic hook records any panic, caught or not). An accepted
//! mesh is then used as an object and as an emitter in a tiny scene that must render finite
//! pixels or be refused. `PROPTEST_CASES=N` sets the number of cases.

mod fuzz_common;

use candela::geometry::{load_obj, load_ply};
use candela::scene::{self, Overrides};
use fuzz_common::{apply, config, plan};
use proptest::prelude::*;
use std::cell::Cell;
use std::path::Path;

const OBJ_SEEDS: &[&str] = &[
    "# cube corner\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\nf 1/1/1 2/2/2 3/3/3\nf 2/2/2 4/4/4 3/3/3\n",
    "o a\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\no b\ng g1\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf -3 -2 -1\nusemtl x\nl 1 2\np 1\n",
    "v 0 0 0 1\nv 2.5e0 0 0\nv 0 1e1 0\nf 1// 2// 3//\ns off\n",
];

fn ply_ascii() -> Vec<u8> {
    b"ply\nformat ascii 1.0\ncomment fuzz seed\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n4 0 1 2 3\n".to_vec()
}

fn ply_binary(big_endian: bool) -> Vec<u8> {
    let fmt = if big_endian {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let mut v = format!("ply\nformat {fmt} 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n").into_bytes();
    let f = |x: f32| {
        if big_endian {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        }
    };
    let u = |x: u32| {
        if big_endian {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        }
    };
    for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in p {
            v.extend(f(c));
        }
    }
    v.push(3);
    for i in [0u32, 1, 2] {
        v.extend(u(i));
    }
    v
}

fn ply_seeds() -> Vec<Vec<u8>> {
    vec![ply_ascii(), ply_binary(false), ply_binary(true)]
}

thread_local! {
    /// Panics on this thread, including those caught by the loaders' `catch_unwind`.
    static PANICS: Cell<usize> = const { Cell::new(0) };
}

fn install_hook() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let prev = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            PANICS.with(|c| c.set(c.get() + 1));
            prev(info);
        }));
    });
}

const SCENE: &str = r#"(
    camera: (position: (0.3, 0.3, -2), look_at: (0.3, 0.3, 0), vfov_deg: 60, resolution: (2, 2)),
    render: (spp: 1, max_depth: 3),
    materials: { "m": Diffuse(reflectance: Constant(0.5)) },
    objects: [
        (shape: MESH, material: "m"),
        (shape: MESH, material: "black", transform: (translate: (0, 0, 0.5)),
         emission: (spectrum: Named("D65"), amount: Flux(100))),
    ],
    lights: [Point(position: (0, 1, -1), spectrum: Named("D65"), amount: Intensity(10))],
)"#;

fn check(bytes: &[u8], ply: bool) {
    install_hook();
    let before = PANICS.with(Cell::get);
    let dir = tempfile::tempdir().unwrap();
    let name = if ply { "m.ply" } else { "m.obj" };
    let file = dir.path().join(name);
    std::fs::write(&file, bytes).unwrap();
    let r = if ply {
        load_ply(&file)
    } else {
        load_obj(&file)
    };
    let shown = String::from_utf8_lossy(bytes);
    assert_eq!(
        PANICS.with(Cell::get),
        before,
        "the loader panicked (caught) on:\n{shown}"
    );
    match r {
        Ok(mesh) => {
            assert!(!mesh.indices.is_empty());
            let n = mesh.positions.len();
            assert!(mesh.indices.iter().flatten().all(|&i| (i as usize) < n));
            assert!(mesh.positions.iter().all(|p| p.is_finite()));
            if let Some(ns) = &mesh.normals {
                assert_eq!(ns.len(), n);
            }
        }
        Err(e) => {
            let m = e.to_string();
            assert!(m.contains(name), "error does not name the file: {m}");
            return;
        }
    }
    let text = SCENE.replace(
        "MESH",
        &format!("{}({name:?})", if ply { "Ply" } else { "Obj" }),
    );
    let path = dir.path().join("scene.ron");
    let parsed = scene::parse(&text, &path).unwrap();
    match scene::build(&parsed, &path, &Overrides::default()) {
        Ok(world) => {
            let r = candela::render::render(&world, Some(1), &|_, _| {}).unwrap();
            for p in &r.film.pixels {
                assert!(p.mean_xyz().iter().all(|v| v.is_finite()), "{shown}");
            }
            assert_eq!(r.stats.non_finite, 0, "non-finite samples on:\n{shown}");
        }
        Err(e) => {
            let m = e.to_string();
            assert!(m.contains("scene.ron"), "{m}");
        }
    }
}

#[test]
fn seeds_load() {
    let dir = tempfile::tempdir().unwrap();
    for (k, s) in OBJ_SEEDS.iter().enumerate() {
        let p = dir.path().join(format!("{k}.obj"));
        std::fs::write(&p, s).unwrap();
        load_obj(&p).unwrap_or_else(|e| panic!("{e}"));
    }
    for (k, s) in ply_seeds().iter().enumerate() {
        let p = dir.path().join(format!("{k}.ply"));
        std::fs::write(&p, s).unwrap();
        load_ply(&p).unwrap_or_else(|e| panic!("{e}"));
    }
}

#[test]
fn directories_and_missing_files_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    assert!(load_obj(dir.path()).is_err());
    assert!(load_ply(dir.path()).is_err());
    assert!(load_obj(&dir.path().join("none.obj")).is_err());
    assert!(load_ply(Path::new("")).is_err());
}

proptest! {
    #![proptest_config(config(700))]

    #[test]
    fn mutated_obj_never_panics((seed, muts) in plan(OBJ_SEEDS.len(), 5)) {
        let seeds: Vec<&[u8]> = OBJ_SEEDS.iter().map(|s| s.as_bytes()).collect();
        check(&apply(seeds[seed], &muts, &seeds), false);
    }

    #[test]
    fn mutated_ply_never_panics((seed, muts) in plan(3, 5)) {
        let owned = ply_seeds();
        let seeds: Vec<&[u8]> = owned.iter().map(|s| s.as_slice()).collect();
        check(&apply(seeds[seed], &muts, &seeds), true);
    }

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
        check(&bytes, false);
        let mut ply = b"ply\nformat ascii 1.0\n".to_vec();
        ply.extend(&bytes);
        check(&ply, true);
        check(&bytes, true);
    }
}
