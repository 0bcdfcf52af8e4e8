//! Paths that do not hold what they should: `/dev/zero`, a FIFO, a directory or a file larger
//! than its kind allows, given as the scene, a mesh (OBJ, PLY), an OBJ's material library, a
//! spectrum CSV, a luminaire file and an EXR to probe or false-colour. Each must end within
//! seconds with exit code 1 and the file named on stderr: no hang (a FIFO blocks whoever opens
//! it), no abort, no endless read. Also files that start with a UTF-8 byte-order mark, a PLY
//! header that declares more elements than memory holds, and an OBJ face of 10⁶ vertices.
//! (EXR headers that promise more pixels than memory or the file holds: `tests/fuzz_exr.rs`.)

#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Longest any refusal may take.
const TIMEOUT: Duration = Duration::from_secs(20);

/// Address-space limit of the child, so that a regression (an endless read of `/dev/zero`, a
/// decoded bomb) ends in an allocation failure instead of taking the machine's memory.
const CHILD_ADDRESS_SPACE_KB: u64 = 2 << 20;

struct Run {
    code: Option<i32>,
    stderr: String,
    elapsed: Duration,
}

/// Runs `candela ARGS` in `dir`, killing it after [`TIMEOUT`].
fn candela(dir: &Path, args: &[&str]) -> Run {
    let start = Instant::now();
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {CHILD_ADDRESS_SPACE_KB} && exec \"$0\" \"$@\""
        ))
        .arg(env!("CARGO_BIN_EXE_candela"))
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Read stderr on a thread so that a chatty child cannot block on a full pipe.
    let mut pipe = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = Vec::new();
        std::io::Read::read_to_end(&mut pipe, &mut s).ok();
        String::from_utf8_lossy(&s).into_owned()
    });
    let status = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        if start.elapsed() > TIMEOUT {
            child.kill().ok();
            child.wait().ok();
            panic!("candela {args:?} did not finish within {TIMEOUT:?} (hangs)");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    Run {
        code: status.code(),
        stderr: reader.join().unwrap(),
        elapsed: start.elapsed(),
    }
}

fn expect_refused(dir: &Path, args: &[&str], name: &str, why: &str) {
    let r = candela(dir, args);
    assert_eq!(
        r.code,
        Some(1),
        "candela {args:?} ({why}): exit {:?}, stderr:\n{}",
        r.code,
        r.stderr
    );
    assert!(
        r.stderr.contains(name),
        "candela {args:?} ({why}): stderr does not name {name}:\n{}",
        r.stderr
    );
    assert!(!r.stderr.contains("panicked"), "{}", r.stderr);
    assert!(r.elapsed < TIMEOUT);
}

/// The four hostile things a path can be; `limit` is the kind's size limit in bytes.
#[derive(Clone, Copy, Debug)]
enum Hostile {
    DevZero,
    Fifo,
    Directory,
    /// A sparse file one byte over the limit.
    TooLarge(u64),
}

impl Hostile {
    fn make(self, path: &Path) {
        match self {
            Hostile::DevZero => std::os::unix::fs::symlink("/dev/zero", path).unwrap(),
            Hostile::Fifo => {
                let st = Command::new("mkfifo").arg(path).status().unwrap();
                assert!(st.success());
            }
            Hostile::Directory => std::fs::create_dir(path).unwrap(),
            Hostile::TooLarge(limit) => {
                let f = std::fs::File::create(path).unwrap();
                f.set_len(limit + 1).unwrap();
            }
        }
    }
    /// What the message must say beside the name.
    fn reason(self) -> &'static str {
        match self {
            Hostile::DevZero => "device",
            Hostile::Fifo => "FIFO",
            Hostile::Directory => "directory",
            Hostile::TooLarge(_) => "",
        }
    }
}

/// Every hostile kind with the given size limit.
fn all(limit: u64) -> [Hostile; 4] {
    [
        Hostile::DevZero,
        Hostile::Fifo,
        Hostile::Directory,
        Hostile::TooLarge(limit),
    ]
}

const TEXT_LIMIT: u64 = candela::limits::MAX_TEXT_BYTES;
/// Beyond any machine's memory: the mesh and EXR limits are the memory available.
const HUGE: u64 = 1 << 40;

fn scene_with(object: &str, light: &str, reflectance: &str) -> String {
    format!(
        r#"(
    camera: (position: (0, 0, -3), look_at: (0, 0, 0), vfov_deg: 40, resolution: (4, 4)),
    render: (spp: 1, max_depth: 2),
    materials: {{ "m": Diffuse(reflectance: {reflectance}) }},
    objects: [(shape: {object}, material: "m")],
    lights: [{light}],
)"#
    )
}

const QUAD: &str = "Quad(origin: (-1, -1, 0), edge_u: (2, 0, 0), edge_v: (0, 2, 0))";
const POINT: &str = r#"Point(position: (0, 0, -2), spectrum: Named("D65"), amount: Intensity(10))"#;
const GREY: &str = "Constant(0.5)";
const OBJ: &str = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n";

/// Renders `scene` (written as scene.ron in `dir`) and expects a refusal naming `name`.
fn render_refused(dir: &Path, scene: &str, name: &str, why: &str) {
    std::fs::write(dir.join("scene.ron"), scene).unwrap();
    expect_refused(
        dir,
        &["render", "--quiet", "--out", "out", "scene.ron"],
        name,
        why,
    );
}

fn fresh() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

#[test]
fn hostile_scene_files_are_refused() {
    for h in all(TEXT_LIMIT) {
        let dir = fresh();
        h.make(&dir.path().join("bad.ron"));
        expect_refused(
            dir.path(),
            &["render", "--quiet", "bad.ron"],
            "bad.ron",
            &format!("{h:?} scene"),
        );
        let r = candela(dir.path(), &["render", "--quiet", "bad.ron"]);
        assert!(r.stderr.contains(h.reason()), "{h:?}: {}", r.stderr);
    }
}

#[test]
fn hostile_meshes_are_refused() {
    for (shape, file) in [("Obj", "bad.obj"), ("Ply", "bad.ply")] {
        for h in all(HUGE) {
            let dir = fresh();
            h.make(&dir.path().join(file));
            let scene = scene_with(&format!("{shape}({file:?})"), POINT, GREY);
            render_refused(dir.path(), &scene, file, &format!("{h:?} {shape}"));
        }
    }
}

#[test]
fn hostile_material_libraries_are_refused_and_missing_ones_ignored() {
    let scene = scene_with("Obj(\"m.obj\")", POINT, GREY);
    let obj = format!("mtllib lib.mtl\n{OBJ}");
    for h in all(16 << 20) {
        let dir = fresh();
        std::fs::write(dir.path().join("m.obj"), &obj).unwrap();
        h.make(&dir.path().join("lib.mtl"));
        render_refused(dir.path(), &scene, "lib.mtl", &format!("{h:?} mtllib"));
    }
    // A material library that is not there is no reason to refuse: materials come from the
    // scene, so an OBJ exported with its .mtl left behind renders.
    let dir = fresh();
    std::fs::write(dir.path().join("m.obj"), &obj).unwrap();
    std::fs::write(dir.path().join("scene.ron"), &scene).unwrap();
    let r = candela(
        dir.path(),
        &["render", "--quiet", "--out", "out", "scene.ron"],
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
}

#[test]
fn hostile_spectrum_files_are_refused() {
    for h in all(TEXT_LIMIT) {
        let dir = fresh();
        h.make(&dir.path().join("bad.csv"));
        expect_refused(
            dir.path(),
            &["spectrum", "bad.csv"],
            "bad.csv",
            &format!("{h:?} spectrum"),
        );
        let scene = scene_with(QUAD, POINT, "Csv(\"bad.csv\")");
        render_refused(dir.path(), &scene, "bad.csv", &format!("{h:?} Csv"));
    }
}

#[test]
fn hostile_luminaire_files_are_refused() {
    for file in ["bad.ies", "bad.ldt"] {
        for h in all(candela::luminaire::MAX_FILE_BYTES) {
            let dir = fresh();
            h.make(&dir.path().join(file));
            expect_refused(
                dir.path(),
                &["luminaire", file],
                file,
                &format!("{h:?} luminaire"),
            );
            let light = format!(
                "Goniometric(file: {file:?}, position: (0, 0, -2), spectrum: Named(\"D65\"))"
            );
            let scene = scene_with(QUAD, &light, GREY);
            render_refused(dir.path(), &scene, file, &format!("{h:?} Goniometric"));
        }
    }
}

#[test]
fn hostile_exr_files_are_refused() {
    for h in all(HUGE) {
        let dir = fresh();
        h.make(&dir.path().join("bad.exr"));
        expect_refused(
            dir.path(),
            &["probe", "bad.exr", "0", "0"],
            "bad.exr",
            &format!("{h:?} probe"),
        );
        expect_refused(
            dir.path(),
            &["falsecolour", "bad.exr", "-o", "fc.png"],
            "bad.exr",
            &format!("{h:?} falsecolour"),
        );
    }
}

// --- A byte-order mark at the start of a text file -------------------------------------------

fn with_bom(text: &[u8]) -> Vec<u8> {
    let mut v = b"\xEF\xBB\xBF".to_vec();
    v.extend_from_slice(text);
    v
}

#[test]
fn an_obj_with_a_bom_loads_like_one_without() {
    // The first line is a vertex: read with the mark in front, it was taken for an unknown
    // statement and the faces then referred to a vertex that did not exist.
    let dir = fresh();
    let (a, b) = (dir.path().join("a.obj"), dir.path().join("b.obj"));
    std::fs::write(&a, OBJ).unwrap();
    std::fs::write(&b, with_bom(OBJ.as_bytes())).unwrap();
    let plain = candela::geometry::load_obj(&a).unwrap();
    let marked = candela::geometry::load_obj(&b).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(marked.positions.len(), 4);
    assert_eq!(marked.indices.len(), 2);
    assert_eq!(marked.positions, plain.positions);
    assert_eq!(marked.indices, plain.indices);
}

#[test]
fn a_ply_with_a_bom_loads_like_one_without() {
    let ply = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let dir = fresh();
    let (a, b) = (dir.path().join("a.ply"), dir.path().join("b.ply"));
    std::fs::write(&a, ply).unwrap();
    std::fs::write(&b, with_bom(ply)).unwrap();
    let plain = candela::geometry::load_ply(&a).unwrap();
    let marked = candela::geometry::load_ply(&b).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(marked.positions, plain.positions);
    assert_eq!(marked.indices, vec![[0, 1, 2]]);
}

#[test]
fn a_spectrum_csv_with_a_bom_reads_like_one_without() {
    use candela::colour::sd::SpectralDistribution;
    let csv = b"nm,value\n400,0.25\n700,0.75\n";
    let dir = fresh();
    let f = dir.path().join("s.csv");
    std::fs::write(&f, with_bom(csv)).unwrap();
    let sd = SpectralDistribution::from_csv_path(&f).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(sd.wavelengths_nm, vec![400.0, 700.0]);
    assert_eq!(sd.values, vec![0.25, 0.75]);
    // Without a header line the first data line carries the mark.
    std::fs::write(&f, with_bom(b"400,0.25\n700,0.75\n")).unwrap();
    let sd = SpectralDistribution::from_csv_path(&f).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(sd.wavelengths_nm, vec![400.0, 700.0]);
}

#[test]
fn luminaire_files_with_a_bom_read_like_ones_without() {
    for name in ["narrow-spot.ies", "batwing-office.ldt"] {
        let src = PathBuf::from("data/luminaires").join(name);
        let plain = candela::luminaire::load(&src).unwrap();
        let dir = fresh();
        let f = dir.path().join(name);
        std::fs::write(&f, with_bom(&std::fs::read(&src).unwrap())).unwrap();
        let marked = candela::luminaire::load(&f).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(marked.candela, plain.candela, "{name}");
        assert_eq!(marked.header, plain.header, "{name}");
        // The same with Latin-1 text in a descriptive line (so not UTF-8 as a whole): the
        // mark must not be read as the Latin-1 characters "ï»¿".
        let mut latin = with_bom(&std::fs::read(&src).unwrap());
        let descriptive_line = if name.ends_with(".ies") { 1 } else { 0 };
        let at = latin
            .iter()
            .enumerate()
            .filter(|(_, &b)| b == b'\n')
            .nth(descriptive_line)
            .unwrap()
            .0;
        latin.insert(at, 0xE9); // é in Latin-1
        std::fs::write(&f, &latin).unwrap();
        let marked = candela::luminaire::load(&f).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(marked.candela, plain.candela, "{name} (Latin-1)");
        assert!(
            marked.header.iter().any(|(_, v)| v.ends_with('é')),
            "{name}"
        );
        assert!(
            !marked.header.iter().any(|(_, v)| v.contains('ï')),
            "{name}"
        );
    }
}

// --- Meshes whose parse would need more memory than there is -----------------------------------

#[test]
fn a_ply_header_declaring_more_elements_than_memory_holds_is_refused() {
    // An element without properties takes no bytes in a binary payload, so the file cannot
    // bound its count: the parser would build 10¹⁵ empty elements.
    let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement nothing 1000000000000000\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n".to_vec();
    for v in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
        ply.extend(v.to_le_bytes());
    }
    ply.push(3);
    for i in [0i32, 1, 2] {
        ply.extend(i.to_le_bytes());
    }
    let dir = fresh();
    std::fs::write(dir.path().join("m.ply"), &ply).unwrap();
    let scene = scene_with("Ply(\"m.ply\")", POINT, GREY);
    std::fs::write(dir.path().join("scene.ron"), scene).unwrap();
    let r = candela(
        dir.path(),
        &["render", "--quiet", "--out", "out", "scene.ron"],
    );
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    assert!(r.stderr.contains("m.ply"), "{}", r.stderr);
    assert!(
        r.stderr.contains("1000000000000004 elements"),
        "{}",
        r.stderr
    );
    assert!(r.stderr.contains("GiB of memory"), "{}", r.stderr);
}

#[test]
fn an_obj_face_of_a_million_vertices_loads_as_a_fan() {
    // 32 MB of OBJ; it loads in about 2 s with a peak of about 210 MB.
    const N: usize = 1_000_000;
    let mut obj = String::with_capacity(40 * N);
    for k in 0..N {
        let a = std::f64::consts::TAU * k as f64 / N as f64;
        obj.push_str(&format!("v {:.7} {:.7} 0\n", a.cos(), a.sin()));
    }
    obj.push('f');
    for k in 1..=N {
        obj.push_str(&format!(" {k}"));
    }
    obj.push('\n');
    let dir = fresh();
    let f = dir.path().join("disc.obj");
    std::fs::write(&f, obj).unwrap();
    let mesh = candela::geometry::load_obj(&f).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(mesh.positions.len(), N);
    assert_eq!(mesh.indices.len(), N - 2);
    assert!(mesh.indices.iter().all(|t| t[0] == mesh.indices[0][0]));
}
