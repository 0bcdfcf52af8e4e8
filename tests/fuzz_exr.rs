//! Property-based fuzzing of the EXR reader behind `candela probe` and `candela falsecolour`:
//! small EXRs written by candela (luminance only; with illuminance; one pixel; more rows than
//! one compressed block), mutated, and random bytes. `output::read_exr`, then the checks and
//! computations of both commands (`check_photometric_layers`, `probe_file`,
//! `render_falsecolour`), must give `Ok` or an `Err` naming the file — never a panic, and never
//! an allocation a file of a few kilobytes cannot justify (a counting allocator records the
//! largest request; a mutated header can promise any size). `PROPTEST_CASES=N` sets the
//! number of cases.

mod fuzz_common;

use candela::output::{self, read_exr, write_exr, Layers};
use candela::report::check_photometric_layers;
use candela::report::falsecolour::{render_falsecolour, FalsecolourSettings};
use candela::report::probe::probe_file;
use candela::report::units::UnitSystem;
use fuzz_common::{apply, config, mutation};
use proptest::prelude::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The global allocator, recording the largest single request since the last reset. Requests
/// over 1 GiB fail (an abort) so that a regression cannot take the machine's memory.
struct Counting;

static LARGEST: AtomicUsize = AtomicUsize::new(0);
const REFUSED_ABOVE: usize = 1 << 30;

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        if layout.size() > REFUSED_ABOVE {
            return std::ptr::null_mut();
        }
        System.alloc(layout)
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        if layout.size() > REFUSED_ABOVE {
            return std::ptr::null_mut();
        }
        System.alloc_zeroed(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LARGEST.fetch_max(new_size, Ordering::Relaxed);
        if new_size > REFUSED_ABOVE {
            return std::ptr::null_mut();
        }
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// One measured read at a time, so that the largest allocation is that read's.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Largest allocation one case may make. The seeds are at most 40×40 pixels; what a mutated
/// file of a few kilobytes may decode to is bounded by the reader (2048 bytes of samples per
/// byte of file), and the false-colour PNG adds its legend.
const MAX_ALLOCATION: usize = 64 << 20;

fn seed(w: usize, h: usize, illuminance: bool, attrs: &[(&str, &str)]) -> Vec<u8> {
    let n = w * h;
    let xyz: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            let y = 1.0 + i as f32 * 0.37;
            [0.95 * y, y, 1.09 * y]
        })
        .collect();
    let stderr: Vec<f32> = (0..n).map(|i| 0.01 * (i % 7) as f32).collect();
    let mut layers = Layers::from_xyz(w, h, &xyz, &stderr);
    if illuminance {
        let e: Vec<f32> = (0..n)
            .map(|i| {
                if i == 0 {
                    output::ILLUMINANCE_SENTINEL
                } else {
                    3.0 * i as f32
                }
            })
            .collect();
        let mask: Vec<f32> = (0..n).map(|i| if i == 0 { 0.0 } else { 1.0 }).collect();
        layers.channels.push((output::CHANNEL_E.into(), e.clone()));
        layers
            .channels
            .push((output::CHANNEL_E_STDERR.into(), vec![0.5; n]));
        layers.channels.push((output::CHANNEL_E_MASK.into(), mask));
    }
    for (k, v) in attrs {
        layers.attributes.push((k.to_string(), v.to_string()));
    }
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("seed.exr");
    write_exr(&p, &layers).unwrap();
    std::fs::read(&p).unwrap()
}

fn seeds() -> &'static [Vec<u8>] {
    static SEEDS: std::sync::OnceLock<Vec<Vec<u8>>> = std::sync::OnceLock::new();
    SEEDS.get_or_init(|| {
        vec![
            seed(3, 2, false, &[]),
            seed(
                5,
                4,
                true,
                &[("scene", "fuzz.ron"), ("software", "candela")],
            ),
            seed(1, 1, true, &[]),
            seed(
                7,
                40,
                false,
                &[("comments", "more rows than one ZIP block")],
            ),
        ]
    })
}

fn check(bytes: &[u8]) {
    let _guard = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fuzz.exr");
    std::fs::write(&path, bytes).unwrap();
    LARGEST.store(0, Ordering::Relaxed);
    let names_file =
        |m: String| assert!(m.contains("fuzz.exr"), "error does not name the file: {m}");
    match read_exr(&path) {
        Ok(layers) => {
            assert!(layers.width > 0 && layers.height > 0);
            for (name, values) in &layers.channels {
                assert_eq!(values.len(), layers.width * layers.height, "{name}");
            }
            exercise(&path, &layers);
        }
        Err(e) => names_file(e.to_string()),
    }
    let largest = LARGEST.load(Ordering::Relaxed);
    assert!(
        largest <= MAX_ALLOCATION,
        "an allocation of {largest} bytes for a file of {} bytes",
        bytes.len()
    );
}

/// What `candela probe` and `candela falsecolour` do with an image they have read.
fn exercise(path: &Path, layers: &Layers) {
    if let Err(m) = check_photometric_layers(path, layers) {
        assert!(m.contains("fuzz.exr"), "{m}");
        return;
    }
    let (w, h) = (layers.width as i64, layers.height as i64);
    for (x, y, r) in [
        (0, 0, None),
        (w - 1, h - 1, Some(2.0)),
        (w / 2, h / 2, Some(0.0)),
    ] {
        for units in [UnitSystem::Si, UnitSystem::Imperial] {
            match probe_file(path, x, y, r, units) {
                Ok(p) => {
                    let json = p.to_json().to_string();
                    assert!(!json.is_empty());
                }
                Err(e) => assert!(e.to_string().contains("fuzz.exr"), "{e}"),
            }
        }
    }
    for quantity in [
        candela::photometry::Quantity::Luminance,
        candela::photometry::Quantity::Illuminance,
    ] {
        let settings = FalsecolourSettings {
            quantity,
            ..FalsecolourSettings::default()
        };
        // The command puts the file name before these errors itself.
        if let Ok((img, _)) = render_falsecolour(layers, &settings) {
            assert!(img.width() > 0 && img.height() > 0);
        }
    }
}

// --- Headers that promise more than memory or the file holds ----------------------------------

/// The bytes of a scan-line EXR header: `channels` half-float channels of `w`×`h` pixels, ZIP
/// compression (16 lines per chunk), followed by an offset table whose entries all point past
/// the end (no pixel data: what matters is that the decoder would allocate the image first).
fn bomb_exr(w: u32, h: u32, channels: &[&str]) -> Vec<u8> {
    let mut v = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
    let mut attr = |name: &str, ty: &str, value: &[u8]| {
        v.extend(name.as_bytes());
        v.push(0);
        v.extend(ty.as_bytes());
        v.push(0);
        v.extend((value.len() as u32).to_le_bytes());
        v.extend(value);
    };
    let mut chlist = Vec::new();
    for c in channels {
        chlist.extend(c.as_bytes());
        chlist.push(0);
        chlist.extend(1i32.to_le_bytes()); // HALF
        chlist.extend([0, 0, 0, 0]); // pLinear, reserved
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
    let chunks = h.div_ceil(16) as usize;
    let end = (v.len() + chunks * 8) as u64;
    for _ in 0..chunks {
        v.extend(end.to_le_bytes());
    }
    v
}

/// `read_exr` on `bytes` as `name`: the error message and the largest allocation made.
fn refusal(name: &str, bytes: &[u8]) -> (String, usize) {
    let _guard = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    LARGEST.store(0, Ordering::Relaxed);
    let e = read_exr(&path).expect_err("a header-only file must be refused");
    (e.to_string(), LARGEST.load(Ordering::Relaxed))
}

#[test]
fn an_exr_promising_more_pixels_than_memory_is_refused_before_decoding() {
    // 2²⁰ × 2¹⁶ pixels × 4 half channels: 512 GiB as stored, 1.5 TiB with the f32 copy; the
    // file is 33 kB. The decoder would allocate the image before reading a block.
    let bytes = bomb_exr(1 << 20, 1 << 16, &["X", "Y", "Z", "stderr.Y"]);
    assert!(bytes.len() < 40_000);
    let (m, largest) = refusal("bomb.exr", &bytes);
    assert!(m.contains("bomb.exr"), "{m}");
    assert!(m.contains("1048576×65536 pixels"), "{m}");
    assert!(m.contains("GiB of memory"), "{m}");
    assert!(largest < 1 << 20, "{largest} bytes allocated");
    // The same through the commands that read EXRs.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bomb.exr"), &bytes).unwrap();
    for args in [
        &["probe", "bomb.exr", "0", "0"][..],
        &["falsecolour", "bomb.exr", "-o", "fc.png"][..],
    ] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_candela"))
            .args(args)
            .current_dir(dir.path())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains("bomb.exr"), "{stderr}");
        assert!(stderr.contains("1048576×65536 pixels"), "{stderr}");
    }
}

#[test]
fn an_exr_promising_more_pixels_than_its_file_holds_is_refused_before_decoding() {
    // 8192² pixels × 4 half channels (512 MiB of samples, within the memory of most
    // machines) in a file of 4.5 kB: more than 2048 times its size, which no OpenEXR
    // compression reaches. The decoder would allocate 128 MiB per channel before finding
    // the blocks missing.
    let bytes = bomb_exr(8192, 8192, &["X", "Y", "Z", "stderr.Y"]);
    assert!(bytes.len() < 5000);
    let (m, largest) = refusal("short.exr", &bytes);
    assert!(m.contains("short.exr"), "{m}");
    assert!(m.contains("8192×8192 pixels"), "{m}");
    assert!(m.contains("truncated or corrupt"), "{m}");
    assert!(largest < 1 << 20, "{largest} bytes allocated");
}

// --- Fuzzing ------------------------------------------------------------------------------------

#[test]
fn seeds_read_and_probe() {
    for (k, s) in seeds().iter().enumerate() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("fuzz.exr");
        std::fs::write(&p, s).unwrap();
        let layers = read_exr(&p).unwrap_or_else(|e| panic!("seed {k}: {e}"));
        check_photometric_layers(&p, &layers).unwrap();
        probe_file(&p, 0, 0, None, UnitSystem::Si).unwrap();
        check(s);
    }
}

/// The header of a candela EXR is about 350 bytes: data and display windows, channel list,
/// compression and the text attributes.
const HEADER_BYTES: usize = 400;

/// Offsets of the four integers of every `box2i` attribute value (data and display windows).
fn window_ints(bytes: &[u8]) -> Vec<usize> {
    let tag = b"box2i\0";
    let mut out = Vec::new();
    for i in 0..bytes.len().saturating_sub(tag.len()) {
        // Type name, then the value's size (4 bytes), then the value.
        let value = i + tag.len() + 4;
        if &bytes[i..i + tag.len()] == tag && value + 16 <= bytes.len() {
            out.extend((0..4).map(|k| value + 4 * k));
        }
    }
    out
}

const HOSTILE_INTS: &[i32] = &[
    0,
    1,
    -1,
    15,
    16,
    17,
    255,
    4096,
    65535,
    65536,
    1 << 20,
    1 << 24,
    i32::MAX,
    i32::MIN,
];

proptest! {
    #![proptest_config(config(600))]

    #[test]
    fn mutated_exr_never_panics_or_balloons(
        seed in 0..4usize,
        muts in proptest::option::weighted(0.7, proptest::collection::vec(mutation(4), 1..=4)),
        ints in proptest::collection::vec((any::<usize>(), 0..HOSTILE_INTS.len()), 0..3),
    ) {
        let seeds: Vec<&[u8]> = seeds().iter().map(|s| s.as_slice()).collect();
        let mut bytes = apply(seeds[seed], muts.as_deref().unwrap_or(&[]), &seeds);
        // Integers of the header set to hostile values: mostly the corners of the data and
        // display windows (which size the image), else anywhere in the header.
        for (pos, v) in ints {
            let windows = window_ints(&bytes);
            let header = bytes.len().min(HEADER_BYTES).saturating_sub(3);
            let at = match pos % 3 {
                0 | 1 if !windows.is_empty() => windows[pos / 3 % windows.len()],
                _ if header > 0 => pos % header,
                _ => continue,
            };
            bytes[at..at + 4].copy_from_slice(&HOSTILE_INTS[v].to_le_bytes());
        }
        check(&bytes);
    }

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        check(&bytes);
        // The same after a valid magic number and version, so the header parser runs.
        let mut v = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
        v.extend(&bytes);
        check(&v);
    }
}
