//! Bad scene input is refused at load with a message naming the file, the position or field and
//! the names involved: grid names that collide as file names, duplicate map keys, a redefined
//! `"black"`, spectra entirely outside 360–830 nm; a leading byte-order mark is accepted.

use candela::scene::{self, Overrides, RunMode, SceneError};
use std::path::Path;
use std::process::Command;

const CAMERA: &str =
    "camera: (position: (0, 1, -3), look_at: (0, 0, 0), vfov_deg: 40, resolution: (4, 4))";
const FLOOR: &str =
    "objects: [(name: \"floor\", shape: Quad(origin: (-1, 0, -1), edge_u: (0, 0, 2), edge_v: (2, 0, 0)), material: \"grey\")]";
const LAMP: &str =
    "lights: [Point(position: (0, 2, 0), spectrum: Named(\"D65\"), amount: Intensity(10.0))]";
const GREY: &str = "\"grey\": Diffuse(reflectance: Constant(0.5))";

fn scene_text(materials: &str, rest: &str) -> String {
    format!("(\n    {CAMERA},\n    materials: {{ {materials} }},\n    {FLOOR},\n    {LAMP},\n{rest}\n)\n")
}

/// Parse and build `text` as if it were the file `errors-test.ron`; the error message.
fn error_of(text: &str) -> String {
    error_at(text, Path::new("errors-test.ron"))
}

fn error_at(text: &str, path: &Path) -> String {
    match scene::parse(text, path) {
        Err(e) => e.to_string(),
        Ok(s) => match scene::build(&s, path, &Overrides::default()) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("the scene was accepted:\n{text}"),
        },
    }
}

fn accepted(text: &str) {
    let path = Path::new("errors-test.ron");
    let s = scene::parse(text, path).unwrap_or_else(|e| panic!("{e}"));
    scene::build(&s, path, &Overrides::default()).unwrap_or_else(|e| panic!("{e}"));
}

fn assert_has(msg: &str, parts: &[&str]) {
    for p in parts {
        assert!(msg.contains(p), "{p:?} missing from the message: {msg}");
    }
    assert!(!msg.contains('\n'), "not one paragraph: {msg}");
}

fn grid(name: &str) -> String {
    format!(
        "(name: {name:?}, origin: (0, 0.8, 0), edge_u: (1, 0, 0), edge_v: (0, 0, 1), nx: 2, ny: 2)"
    )
}

#[test]
fn grid_names_that_share_a_file_name_are_refused() {
    let text = scene_text(
        GREY,
        &format!("    grids: [{}, {}],", grid("a/b"), grid("a b")),
    );
    let msg = error_of(&text);
    assert_has(
        &msg,
        &[
            "errors-test.ron",
            "grids[1].name",
            "\"a/b\"",
            "\"a b\"",
            "grid-a-b.csv",
        ],
    );
    // Case and punctuation differences collide too; distinct slugs are fine.
    let text = scene_text(
        GREY,
        &format!("    grids: [{}, {}],", grid("Desk"), grid("desk!")),
    );
    assert_has(
        &error_of(&text),
        &["grids[0] \"Desk\"", "grids[1] \"desk!\""],
    );
    accepted(&scene_text(
        GREY,
        &format!("    grids: [{}, {}],", grid("desk 1"), grid("desk 2")),
    ));
}

#[test]
fn duplicate_material_key_is_refused_with_its_position() {
    let text = scene_text(
        &format!("{GREY},\n        \"grey\": Diffuse(reflectance: Constant(0.9))"),
        "",
    );
    let path = Path::new("errors-test.ron");
    match scene::parse(&text, path) {
        Err(SceneError::Parse { line, message, .. }) => {
            assert_eq!(line, 4, "the line of the second key: {message}");
            assert_has(&message, &["`materials`", "\"grey\"", "twice"]);
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
    assert_has(
        &error_of(&text),
        &["errors-test.ron:4:", "materials", "\"grey\""],
    );
    // Distinct keys still parse.
    accepted(&scene_text(
        &format!("{GREY}, \"white\": Diffuse(reflectance: Constant(0.9))"),
        "",
    ));
}

#[test]
fn redefining_black_is_refused() {
    let text = scene_text(
        &format!("{GREY}, \"black\": Diffuse(reflectance: Constant(0.9))"),
        "",
    );
    assert_has(
        &error_of(&text),
        &["errors-test.ron", "materials[\"black\"]", "predefined"],
    );
    // Using the predefined one is fine.
    accepted(&scene_text(GREY, "").replace("material: \"grey\"", "material: \"black\""));
}

#[test]
fn leading_byte_order_mark_is_accepted() {
    let text = format!("\u{feff}{}", scene_text(GREY, ""));
    accepted(&text);
    // Through the file loader and the binary too.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bom.ron");
    std::fs::write(&path, text.as_bytes()).unwrap();
    scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .args(["render", "--quiet", "--checkpoint-interval", "0s", "--out"])
        .arg(dir.path().join("out"))
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // A BOM anywhere else is still an error, with a position.
    let bad = scene_text(GREY, "").replacen("camera", "\u{feff}camera", 1);
    assert_has(&error_of(&bad), &["errors-test.ron:", "not valid"]);
}

#[test]
fn spectra_entirely_outside_the_visible_range_are_refused() {
    let outside = "Tabulated([(100, 0.5), (200, 0.6)])";
    let cases = [
        (
            scene_text(
                &format!("{GREY}, \"uv\": Diffuse(reflectance: {outside})"),
                "",
            ),
            "materials[\"uv\"].reflectance",
        ),
        (
            scene_text(
                &format!("{GREY}, \"c\": Coated(base: {outside})"),
                "",
            ),
            "materials[\"c\"].base",
        ),
        (
            scene_text(
                &format!("{GREY}, \"p\": Phong(diffuse: Constant(0.2), specular: {outside}, exponent: 10)"),
                "",
            ),
            "materials[\"p\"].specular",
        ),
        (
            scene_text(
                &format!("{GREY}, \"m\": Conductor(n: Constant(0.2), k: {outside})"),
                "",
            ),
            "materials[\"m\"].k",
        ),
        (
            scene_text(GREY, "").replace(
                "material: \"grey\")",
                &format!("material: \"grey\", emission: (spectrum: {outside}, amount: Luminance(100)))"),
            ),
            "objects[0] \"floor\".emission.spectrum",
        ),
        (
            scene_text(GREY, "").replace("Named(\"D65\")", outside),
            "lights[0].spectrum",
        ),
        (
            scene_text(GREY, "")
                .replace("Named(\"D65\")", "Tabulated([(900, 1), (1000, 2)])"),
            "lights[0].spectrum",
        ),
    ];
    for (text, field) in &cases {
        assert_has(
            &error_of(text),
            &["errors-test.ron", field, "entirely outside", "360–830 nm"],
        );
    }
    // The same from a CSV file, named in the message.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ir.csv"), "nm,value\n900,0.5\n1000,0.6\n").unwrap();
    let text = scene_text(
        &format!("{GREY}, \"ir\": Diffuse(reflectance: Csv(\"ir.csv\"))"),
        "",
    );
    assert_has(
        &error_at(&text, &dir.path().join("scene.ron")),
        &[
            "scene.ron",
            "materials[\"ir\"].reflectance",
            "ir.csv",
            "entirely outside",
        ],
    );
    // Partly inside is fine (0 outside its range), also touching an end.
    accepted(&scene_text(
        &format!("{GREY}, \"edge\": Diffuse(reflectance: Tabulated([(300, 0.5), (400, 0.6)]))"),
        "",
    ));
    accepted(&scene_text(
        &format!("{GREY}, \"edge\": Diffuse(reflectance: Tabulated([(830, 0.5), (900, 0.6)]))"),
        "",
    ));
}

#[test]
fn memory_estimate_depends_on_the_mode() {
    use candela::scene::build::bytes_per_pixel;
    let plain = RunMode::default();
    let adaptive = RunMode {
        adaptive: true,
        falsecolour: false,
    };
    let all = RunMode {
        adaptive: true,
        falsecolour: true,
    };
    // Peak RSS (GNU time's %M) of `candela render scenes/cornell-box.ron` at 2048² (4 194 304
    // pixels), release build, `--threads 2 --checkpoint-interval 0s`, `--spp 2` or
    // `--target-error 1% --max-spp 4`, one run each on a 2-core machine shared with other
    // jobs: 1 919 324 kB plain, 4 203 140 kB adaptive, 7 021 352 kB adaptive with
    // --illuminance --falsecolour; the estimate of the render's own buffers is within 10 %.
    let px = 2048.0 * 2048.0;
    for (bpp, measured_kb) in [
        (bytes_per_pixel(&plain, false), 1_919_324.0),
        (bytes_per_pixel(&adaptive, false), 4_203_140.0),
        (bytes_per_pixel(&all, true), 7_021_352.0),
    ] {
        let est = bpp as f64 * px;
        let measured = measured_kb * 1024.0;
        assert!(
            (est / measured - 1.0).abs() < 0.1,
            "estimate {est:e} B vs measured {measured:e} B"
        );
    }
    // Illuminance sums exist only with --illuminance: a plain render's pixel grows by them.
    let e = std::mem::size_of::<candela::film::IlluminanceSums>() as u64;
    assert!(bytes_per_pixel(&plain, true) >= bytes_per_pixel(&plain, false) + 2 * e);
}

#[test]
fn obj_face_with_a_bad_index_is_named() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("bad.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 -4\n",
    )
    .unwrap();
    let text = scene_text(GREY, "").replace(
        "Quad(origin: (-1, 0, -1), edge_u: (0, 0, 2), edge_v: (2, 0, 0))",
        "Obj(\"bad.obj\")",
    );
    assert_has(
        &error_at(&text, &dir.path().join("scene.ron")),
        &[
            "scene.ron",
            "objects[0] \"floor\".shape",
            "bad.obj",
            "line 5",
            "face 1",
            "3 vertices",
        ],
    );
    let text = scene_text(GREY, "").replace(
        "Quad(origin: (-1, 0, -1), edge_u: (0, 0, 2), edge_v: (2, 0, 0))",
        "Obj(\"missing-dir\")",
    );
    std::fs::create_dir(dir.path().join("missing-dir")).unwrap();
    let msg = error_at(&text, &dir.path().join("scene.ron"));
    assert_has(&msg, &["missing-dir", "scene file's directory"]);
    assert!(!msg.contains("working directory"), "{msg}");
}
