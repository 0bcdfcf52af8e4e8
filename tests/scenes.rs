//! Every scene shipped in scenes/ loads and builds (they are the files users copy).

use candela::scene::{load_world, Overrides};
use std::path::Path;

#[test]
fn every_shipped_scene_loads() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "ron") {
            let w = load_world(&path, &Overrides::default())
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert!(
                w.camera.width > 0 && !w.lights.is_empty(),
                "{}",
                path.display()
            );
            n += 1;
        }
    }
    assert!(n >= 9, "only {n} scenes");
}

#[test]
fn sunlit_window_scene_traces_the_sun() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sunlit-window.ron");
    let w = load_world(&path, &Overrides::default()).unwrap();
    assert!(w.caustics.is_some());
}
