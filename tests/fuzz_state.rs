//! Render state files (`candela::state`) against damage and crafted values. Real small states
//! (a plain render with illuminance and light-traced caustics, and an adaptive one) are
//! rendered once; then:
//! - every single-bit flip of each file is decoded (all must be refused) and, with the checksum
//!   recomputed, again, to count what the value checks alone catch;
//! - random byte-level damage (flips, overwrites, insertions, deletions, truncations,
//!   extensions) goes through `RenderState::load`, `job::run` with `resume` and `job::merge`;
//! - crafted values (negative, non-finite, huge or inconsistent sums, counts, sizes, versions),
//!   saved with a valid checksum, go through `load`, resume and merge.
//!
//! Every case must end in an `Err` naming the file (or, for damage that leaves the bytes as
//! they were, in the undamaged result): never a panic, never an `Ok` with other numbers.
//! `PROPTEST_CASES=N` sets the number of cases.

mod fuzz_common;

use candela::film::{IlluminanceSums, PixelSums};
use candela::job::{self, RenderJob, Silent};
use candela::render::TargetError;
use candela::state::{self, RenderState};
use fuzz_common::{apply, config, Mutation};
use proptest::prelude::*;
use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::OnceLock;

/// A glass sphere on a floor under a point light, 4×3 pixels: per-pixel illuminance and caustic
/// light paths, so every field of a pixel's sums is in use.
const SCENE: &str = r#"(
    camera: (position: (0, 1.2, -3), look_at: (0, 0.3, 0), vfov_deg: 40, resolution: (4, 3)),
    render: (spp: 4, max_depth: 5, seed: 5, illuminance: true, light_paths_per_sample: 8),
    materials: { "floor": Diffuse(reflectance: Constant(0.5)), "glass": Dielectric(ior: Constant(1.5)) },
    objects: [
        (shape: Quad(origin: (-5, 0, -5), edge_u: (0, 0, 10), edge_v: (10, 0, 0)), material: "floor"),
        (shape: Sphere(center: (0, 0.5, 0), radius: 0.5), material: "glass"),
    ],
    lights: [Point(position: (0.3, 3, 0), spectrum: Named("A"), amount: Intensity(400))],
)"#;

/// The states and what resuming and merging them give.
struct Fixture {
    /// Seed 5, plain.
    plain: Vec<u8>,
    /// Seed 5, adaptive (`--target-error`).
    adaptive: Vec<u8>,
    /// Seed 6, plain and adaptive: the other input of a merge.
    other: Vec<u8>,
    other_adaptive: Vec<u8>,
    /// The films of `plain` resumed to 8 spp, and of `plain` merged with `other` (and the
    /// adaptive ones).
    resumed: [candela::film::Film; 2],
    merged: [candela::film::Film; 2],
}

fn write_scene(dir: &Path) -> PathBuf {
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, SCENE).unwrap();
    scene
}

fn target() -> TargetError {
    TargetError {
        relative: 0.05,
        fraction: 1.0,
        floor_cd_m2: None,
    }
}

/// A job that renders (or, with `resume`, continues) `dir/NAME.state`.
fn job_for(dir: &Path, name: &str, adaptive: bool, resume: bool) -> RenderJob {
    let mut job = RenderJob::new(write_scene(dir));
    job.out = Some(dir.join(name));
    job.checkpoint_interval = None;
    job.threads = Some(1);
    job.save_state = true;
    if adaptive {
        job.target = Some(target());
        job.max_spp = Some(if resume { 16 } else { 8 });
    } else if resume {
        job.max_spp = Some(8);
    }
    job.resume = resume;
    job
}

fn render_state(dir: &Path, name: &str, seed: u64, adaptive: bool) -> Vec<u8> {
    let mut job = job_for(dir, name, adaptive, false);
    job.overrides.seed = Some(seed);
    job::run(&job, &mut Silent, &AtomicBool::new(false)).expect("render");
    std::fs::read(dir.join(format!("{name}.state"))).unwrap()
}

/// Resumes `state` (as `a.state` in a new directory): the film, or the error.
fn resume(state: &[u8], adaptive: bool) -> Result<candela::film::Film, String> {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a.state"), state).unwrap();
    job::run(
        &job_for(dir.path(), "a", adaptive, true),
        &mut Silent,
        &AtomicBool::new(false),
    )
    .map(|o| o.render.film)
    .map_err(|e| format!("{e:#}"))
}

/// Merges `state` (as `a.state`) with `other`: the merged film, or the error.
fn merge(state: &[u8], other: &[u8]) -> Result<candela::film::Film, String> {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.state"), dir.path().join("b.state"));
    std::fs::write(&a, state).unwrap();
    std::fs::write(&b, other).unwrap();
    let out = job::merge(&[a, b], &dir.path().join("m"), None).map_err(|e| format!("{e:#}"))?;
    Ok(RenderState::load(&out.state_path).unwrap().film)
}

fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let plain = render_state(dir.path(), "p", 5, false);
        let adaptive = render_state(dir.path(), "ad", 5, true);
        let other = render_state(dir.path(), "o", 6, false);
        let other_adaptive = render_state(dir.path(), "oad", 6, true);
        let f = Fixture {
            resumed: [
                resume(&plain, false).unwrap(),
                resume(&adaptive, true).unwrap(),
            ],
            merged: [
                merge(&plain, &other).unwrap(),
                merge(&adaptive, &other_adaptive).unwrap(),
            ],
            plain,
            adaptive,
            other,
            other_adaptive,
        };
        // The fixture must exercise every field: illuminance, light-path splats, two buffers.
        let s = decode(&f.plain).unwrap();
        assert!(s.film.pixels.iter().all(|p| p.count == 4));
        assert!(s.film.pixels.iter().any(|p| p.sum_xyz[1] > 0.0));
        let e = s.film.e.as_ref().expect("illuminance sums");
        assert!(e.iter().any(|p| p.count_e > 0 && p.sum_e > 0.0));
        assert!(s
            .film
            .pixels
            .iter()
            .zip(e)
            .any(|(p, e)| p.splat_xyz[1] > 0.0 && e.splat_e > 0.0));
        assert!(decode(&f.adaptive).unwrap().film.decision.is_some());
        f
    })
}

fn decode(bytes: &[u8]) -> anyhow::Result<RenderState> {
    RenderState::decode(bytes, Path::new("dir/x.state"))
}

/// `bytes` with its checksum recomputed: what a crafted file, or damage before the checksum was
/// computed, looks like.
fn resealed(bytes: &[u8]) -> Vec<u8> {
    let mut b = bytes[..bytes.len() - 8].to_vec();
    let sum = state::checksum(&b);
    b.extend_from_slice(&sum.to_le_bytes());
    b
}

thread_local! {
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

/// Every single-bit flip of both states is refused; the figures are printed (`--nocapture`).
/// With the checksum recomputed after the flip, the value checks alone are measured: how many
/// flips they refuse, and how many decode to other numbers (the checksum's job).
#[test]
fn every_single_bit_flip_is_refused() {
    let f = fixture();
    for (what, bytes) in [("plain", &f.plain), ("adaptive", &f.adaptive)] {
        let original = decode(bytes).unwrap();
        let (mut accepted, mut values_refused, mut values_changed) = (0, 0, 0);
        let bits = bytes.len() * 8;
        for bit in 0..bits {
            let mut b = bytes.clone();
            b[bit / 8] ^= 1 << (bit % 8);
            if decode(&b).is_ok() {
                accepted += 1;
            }
            if bit < bits - 64 {
                match decode(&resealed(&b)) {
                    Err(_) => values_refused += 1,
                    Ok(s) if s != original => values_changed += 1,
                    Ok(_) => {}
                }
            }
        }
        eprintln!(
            "{what} state, {} bytes: {bits} single-bit flips, {accepted} accepted; with the checksum recomputed, the value checks refuse {values_refused} of {} and {values_changed} decode to other numbers",
            bytes.len(),
            bits - 64
        );
        assert_eq!(accepted, 0, "{what}: flipped bits accepted");
    }
}

/// One step of damage to a file.
#[derive(Clone, Debug)]
enum Damage {
    /// A mutation of the other fuzz tests (positions modulo the length).
    Mutate(Mutation),
    /// Bytes appended at the end.
    Extend(Vec<u8>),
}

/// Applies a damage plan, loads, resumes and merges: each refuses the damaged file by name
/// unless the bytes are unchanged.
fn check_damaged(adaptive: bool, plan: &[Damage]) {
    install_hook();
    let f = fixture();
    let (bytes, other, k) = if adaptive {
        (&f.adaptive, &f.other_adaptive, 1)
    } else {
        (&f.plain, &f.other, 0)
    };
    let mut damaged = bytes.clone();
    for d in plan {
        match d {
            Damage::Mutate(m) => {
                damaged = apply(&damaged, std::slice::from_ref(m), &[bytes, other])
            }
            Damage::Extend(tail) => damaged.extend_from_slice(tail),
        }
    }
    let before = PANICS.with(Cell::get);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("damaged.state");
    std::fs::write(&path, &damaged).unwrap();
    let loaded = RenderState::load(&path);
    let resumed = resume(&damaged, adaptive);
    let merged = merge(&damaged, other);
    assert_eq!(PANICS.with(Cell::get), before, "panic on plan {plan:?}");
    if damaged == *bytes {
        assert_eq!(loaded.unwrap(), decode(bytes).unwrap());
        assert_eq!(resumed.unwrap(), f.resumed[k]);
        assert_eq!(merged.unwrap(), f.merged[k]);
        return;
    }
    let e = loaded.expect_err("damaged state accepted").to_string();
    assert!(e.contains("damaged.state"), "{e}");
    let e = resumed.expect_err("damaged state resumed");
    assert!(e.contains("a.state"), "{e}");
    let e = merged.expect_err("damaged state merged");
    assert!(e.contains("a.state"), "{e}");
}

/// Byte-level damage: the mutations of the other fuzz tests that make sense for a binary file,
/// and extensions.
fn damage() -> impl Strategy<Value = Damage> {
    let m = |m: Mutation| Damage::Mutate(m);
    prop_oneof![
        3 => (any::<usize>(), 0..8u32).prop_map(move |(pos, bit)| m(Mutation::FlipByte { pos, mask: 1 << bit })),
        1 => (any::<usize>(), 1..=255u8).prop_map(move |(pos, mask)| m(Mutation::FlipByte { pos, mask })),
        1 => (any::<usize>(), any::<u8>()).prop_map(move |(pos, byte)| m(Mutation::SetByte { pos, byte })),
        1 => (any::<usize>(), proptest::collection::vec(any::<u8>(), 1..16))
            .prop_map(move |(pos, bytes)| m(Mutation::Insert { pos, bytes })),
        1 => proptest::collection::vec(any::<u8>(), 1..16).prop_map(Damage::Extend),
        1 => (any::<usize>(), 1..40usize).prop_map(move |(pos, len)| m(Mutation::Delete { pos, len })),
        1 => (any::<usize>(), 1..200usize, any::<usize>())
            .prop_map(move |(from, len, to)| m(Mutation::Duplicate { from, len, to })),
        1 => any::<usize>().prop_map(move |pos| m(Mutation::Truncate { pos })),
        1 => (0..2usize, any::<usize>(), 1..300usize, any::<usize>())
            .prop_map(move |(seed, from, len, to)| m(Mutation::Splice { seed, from, len, to })),
    ]
}

proptest! {
    #![proptest_config(config(150))]

    #[test]
    fn damaged_states_are_refused(
        adaptive in any::<bool>(),
        plan in proptest::collection::vec(damage(), 1..=3),
    ) {
        check_damaged(adaptive, &plan);
    }
}

/// A crafted change of a valid state, which is saved again with a valid checksum.
#[derive(Clone, Debug)]
enum Craft {
    /// Field `field` (see [`float_field`]) of pixel `pixel` of buffer `buffer` set to a value
    /// no render gives there.
    Float {
        buffer: usize,
        pixel: usize,
        field: usize,
        value: usize,
    },
    /// A count of one pixel changed (`field`: 0 samples, 1 illuminance samples, 2 light paths;
    /// see [`apply_craft`]).
    Count {
        buffer: usize,
        pixel: usize,
        field: usize,
        value: usize,
    },
    /// Σ Y² or Σ E² out of line with Σ Y, Σ E: 0 or scaled by 10⁶; or X, Z 100 × Y.
    Inconsistent {
        buffer: usize,
        pixel: usize,
        kind: usize,
    },
    /// The film's size, lengths, light-path totals, the version, the signature, the seeds or
    /// the illuminance flag.
    Film { kind: usize },
}

const HOSTILE_FLOATS: &[f64] = &[
    -1.0,
    -5.0,
    -1e-300,
    -f64::MIN_POSITIVE,
    -1e300,
    f64::NAN,
    -f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    1e300,
    f64::MAX,
    f64::MIN,
];

/// Float `field` of a pixel: 0–23 of its [`PixelSums`], 24–43 of its [`IlluminanceSums`].
fn float_field(s: &mut RenderState, buffer: usize, pixel: usize, field: usize) -> Option<&mut f64> {
    if field < 24 {
        let p = &mut buffer_mut(s, buffer)?[pixel];
        return Some(match field {
            0..=2 => &mut p.sum_xyz[field],
            3 => &mut p.sum_y2,
            4..=6 => &mut p.splat_xyz[field - 4],
            7 => &mut p.splat_y2,
            _ => &mut p.batch_y[field - 8],
        });
    }
    let p = &mut e_buffer_mut(s, buffer)?[pixel];
    Some(match field {
        24 => &mut p.sum_e,
        25 => &mut p.sum_e2,
        26 => &mut p.splat_e,
        27 => &mut p.splat_e2,
        _ => &mut p.batch_e[field - 28],
    })
}

fn craft() -> impl Strategy<Value = Craft> {
    prop_oneof![
        4 => (0..2usize, any::<usize>(), 0..44usize, 0..HOSTILE_FLOATS.len())
            .prop_map(|(buffer, pixel, field, value)| Craft::Float { buffer, pixel, field, value }),
        2 => (0..2usize, any::<usize>(), 0..3usize, 0..4usize)
            .prop_map(|(buffer, pixel, field, value)| Craft::Count { buffer, pixel, field, value }),
        2 => (0..2usize, any::<usize>(), 0..6usize)
            .prop_map(|(buffer, pixel, kind)| Craft::Inconsistent { buffer, pixel, kind }),
        2 => (0..FILM_CRAFTS).prop_map(|kind| Craft::Film { kind }),
    ]
}

fn buffer_mut(s: &mut RenderState, b: usize) -> Option<&mut Vec<PixelSums>> {
    if b == 0 {
        Some(&mut s.film.pixels)
    } else {
        s.film.decision.as_mut()
    }
}

fn e_buffer_mut(s: &mut RenderState, b: usize) -> Option<&mut Vec<IlluminanceSums>> {
    if b == 0 {
        s.film.e.as_mut()
    } else {
        s.film.decision_e.as_mut()
    }
}

/// Kinds of [`Craft::Film`].
const FILM_CRAFTS: usize = 19;

/// Applies `c` to `s` with a value no render writes there; false if it does not apply (a
/// decision buffer of a plain state, a ratio of a black pixel).
fn apply_craft(s: &mut RenderState, c: &Craft) -> bool {
    let n = s.film.pixels.len();
    match *c {
        Craft::Float {
            buffer,
            pixel,
            field,
            value,
        } => {
            let Some(v) = float_field(s, buffer, pixel % n, field) else {
                return false;
            };
            *v = HOSTILE_FLOATS[value];
        }
        Craft::Count {
            buffer,
            pixel,
            field,
            value,
        } => {
            let huge = [u64::MAX, 1 << 62];
            if field == 1 {
                // More illuminance samples than samples.
                let count = buffer_mut(s, buffer).map_or(0, |b| b[pixel % n].count);
                let Some(e) = e_buffer_mut(s, buffer) else {
                    return false;
                };
                let e = &mut e[pixel % n];
                match value {
                    0 => e.count_e = count + 1,
                    1 => e.count_e = count + 100,
                    v => e.count_e = huge[v - 2],
                }
                return true;
            }
            let Some(buf) = buffer_mut(s, buffer) else {
                return false;
            };
            let p = &mut buf[pixel % n];
            match (field, value) {
                // One pixel's samples differ from the others' (or its decision buffer's).
                (0, 0) => p.count += 1,
                (0, 1) => p.count = p.count.wrapping_sub(1),
                (0, v) => p.count = huge[v - 2],
                // Other light paths than the film traced.
                (_, 0) => p.light_paths += 1,
                (_, 1) => p.light_paths = p.light_paths.wrapping_sub(1),
                (_, v) => p.light_paths = huge[v - 2],
            }
        }
        Craft::Inconsistent {
            buffer,
            pixel,
            kind,
        } => {
            if let (2 | 3, Some(e)) = (kind, e_buffer_mut(s, buffer)) {
                let p = &mut e[pixel % n];
                match kind {
                    2 if p.sum_e > 0.0 => p.sum_e2 = 0.0,
                    3 if p.sum_e2 > 0.0 => p.sum_e2 *= 1e6,
                    _ => return false,
                }
                return true;
            }
            let Some(buf) = buffer_mut(s, buffer) else {
                return false;
            };
            let p = &mut buf[pixel % n];
            match kind {
                0 if p.sum_xyz[1] > 0.0 => p.sum_y2 = 0.0,
                1 if p.sum_y2 > 0.0 => p.sum_y2 *= 1e6,
                4 if p.sum_xyz[1] > 0.0 => p.sum_xyz[0] = 100.0 * p.sum_xyz[1],
                5 if p.sum_xyz[1] > 0.0 => p.sum_xyz[2] = 200.0 * p.sum_xyz[1],
                _ => return false,
            }
        }
        Craft::Film { kind } => match kind {
            0 => s.film.width += 1,
            1 => s.film.height -= 1,
            2 => s.film.width = 0,
            3 => s.film.width = 1 << 32,
            4 => s.film.width = usize::MAX,
            5 => drop(s.film.pixels.pop()),
            6 => s.film.pixels.push(s.film.pixels[0]),
            7 => s.film.light_paths[0] += 1,
            8 if s.film.decision.is_none() => s.film.light_paths[1] = 1,
            8 => s.film.light_paths[1] = 0,
            9 => s.version = 3,
            10 => s.version = candela::state::VERSION + 1,
            11 => s.magic = "candela-render-statf".into(),
            12 => s.merged_seeds = vec![s.seed],
            13 => s.merged_seeds = vec![7, 7],
            14 => s.illuminance = false,
            // Illuminance sums missing, or one pixel short.
            15 => s.film.e = None,
            16 if s.film.decision_e.is_some() => s.film.decision_e = None,
            16 => s.film.decision_e = s.film.e.clone(),
            17 => drop(s.film.e.as_mut().map(Vec::pop)),
            _ => s.film.pixels[n - 1].count += 2,
        },
    }
    true
}

fn check_crafted(adaptive: bool, c: &Craft) {
    install_hook();
    let f = fixture();
    let (bytes, other) = if adaptive {
        (&f.adaptive, &f.other_adaptive)
    } else {
        (&f.plain, &f.other)
    };
    let mut s = decode(bytes).unwrap();
    if !apply_craft(&mut s, c) {
        return;
    }
    let before = PANICS.with(Cell::get);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("crafted.state");
    s.save(&path).unwrap();
    let crafted = std::fs::read(&path).unwrap();
    let loaded = RenderState::load(&path);
    let merged = merge(&crafted, other);
    assert_eq!(PANICS.with(Cell::get), before, "panic on {c:?}");
    let e = loaded.expect_err("crafted state accepted").to_string();
    assert!(e.contains("crafted.state"), "{e}");
    let e = merged.expect_err("crafted state merged");
    assert!(e.contains("a.state"), "{e}");
}

proptest! {
    #![proptest_config(config(300))]

    #[test]
    fn crafted_values_are_refused(adaptive in any::<bool>(), c in craft()) {
        check_crafted(adaptive, &c);
    }
}

#[test]
fn every_crafted_film_change_is_refused() {
    for adaptive in [false, true] {
        for kind in 0..FILM_CRAFTS {
            check_crafted(adaptive, &Craft::Film { kind });
        }
    }
}

/// The state's bytes with the lowest exponent bit of pixel (0, 0)'s Σ Y flipped: a pixel twice
/// or half as bright in a file that still decodes.
fn flip_sum_y(bytes: &[u8]) -> Vec<u8> {
    let film = decode(bytes).unwrap().film;
    let y = film.pixels[0].sum_xyz[1].to_le_bytes();
    let at = bytes.windows(8).position(|w| w == y).unwrap();
    let mut b = bytes.to_vec();
    b[at + 6] ^= 0x10;
    b
}

#[test]
fn one_flipped_bit_is_refused_by_load_resume_and_merge() {
    let f = fixture();
    let b = flip_sum_y(&f.plain);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flipped.state");
    std::fs::write(&path, &b).unwrap();
    let e = RenderState::load(&path).unwrap_err().to_string();
    assert!(e.contains("flipped.state") && e.contains("checksum"), "{e}");
    let e = resume(&b, false).unwrap_err();
    assert!(e.contains("a.state") && e.contains("corrupt"), "{e}");
    let e = merge(&b, &f.other).unwrap_err();
    assert!(e.contains("a.state") && e.contains("corrupt"), "{e}");
}

#[test]
fn a_negative_sum_is_refused_and_nothing_is_written() {
    let f = fixture();
    let mut s = decode(&f.plain).unwrap();
    s.film.pixels[5].sum_xyz[1] = -5.0;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("negative.state");
    s.save(&path).unwrap();
    let e = RenderState::load(&path).unwrap_err().to_string();
    assert!(
        e.contains("negative.state") && e.contains("pixel (1, 1)") && e.contains("Σ Y is -5"),
        "{e}"
    );
    let b = std::fs::read(&path).unwrap();
    let (a, other) = (dir.path().join("a.state"), dir.path().join("b.state"));
    std::fs::write(&a, &b).unwrap();
    std::fs::write(&other, &f.other).unwrap();
    let out = dir.path().join("m");
    assert!(job::merge(&[a, other], &out, None).is_err());
    assert!(!dir.path().join("m.exr").exists() && !dir.path().join("m.state").exists());
}

#[test]
fn a_truncated_or_extended_file_is_refused() {
    let f = fixture();
    let n = f.plain.len();
    let mut cases: Vec<Vec<u8>> = [1, 8, 9, n / 2, n - 30, n - 1]
        .iter()
        .map(|&cut| f.plain[..n - cut].to_vec())
        .collect();
    for tail in [&[0u8][..], &[0; 8], b"garbage\n"] {
        let mut b = f.plain.clone();
        b.extend_from_slice(tail);
        cases.push(b);
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cut.state");
    for b in cases {
        std::fs::write(&path, &b).unwrap();
        let e = RenderState::load(&path)
            .expect_err("a truncated or extended file was accepted")
            .to_string();
        assert!(
            e.contains("cut.state") && e.contains("corrupt or truncated"),
            "{e}"
        );
    }
}

// Bytes allocated by this thread, to show that a claimed size allocates nothing.
thread_local! {
    static ALLOCATED: Cell<u64> = const { Cell::new(0) };
}

struct Counting;

// SAFETY: forwards to the system allocator; the counter is a const-initialised thread-local
// without a destructor, which allocates nothing.
unsafe impl std::alloc::GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        let _ = ALLOCATED.try_with(|a| a.set(a.get() + layout.size() as u64));
        unsafe { std::alloc::System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        unsafe { std::alloc::System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: std::alloc::Layout, new: usize) -> *mut u8 {
        let _ = ALLOCATED.try_with(|a| a.set(a.get() + new as u64));
        unsafe { std::alloc::System.realloc(ptr, layout, new) }
    }
}

#[global_allocator]
static COUNTING: Counting = Counting;

/// The postcard varint of `v`.
fn varint(mut v: u64) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let b = (v & 0x7f) as u8;
        v >>= 7;
        if v == 0 {
            out.push(b);
            return out;
        }
        out.push(b | 0x80);
    }
}

#[test]
fn huge_claimed_sizes_are_refused_without_allocating() {
    let f = fixture();
    let s = decode(&f.plain).unwrap();
    // The state's fields up to the film's size, then the claims.
    let head = |w: u64, h: u64| {
        let mut b = postcard::to_stdvec(&(
            &s.magic,
            s.version,
            s.scene_hash,
            &s.scene,
            s.seed,
            s.max_depth,
            s.illuminance,
        ))
        .unwrap();
        b.extend(varint(w));
        b.extend(varint(h));
        b
    };
    let sealed = |mut b: Vec<u8>| {
        b.extend(vec![0u8; 200]);
        let sum = state::checksum(&b);
        b.extend_from_slice(&sum.to_le_bytes());
        b
    };
    let mut pixels_2_28 = head(1 << 14, 1 << 14);
    pixels_2_28.extend(varint(1 << 28));
    let mut pixels_2_60 = head(4, 3);
    pixels_2_60.extend(varint(1 << 60));
    let mut film_2_64 = head(u64::MAX, u64::MAX);
    film_2_64.extend(varint(u64::MAX));
    let mut seeds_2_60 = postcard::to_stdvec(&RenderState {
        merged_seeds: vec![],
        ..s.clone()
    })
    .unwrap();
    seeds_2_60.pop();
    seeds_2_60.extend(varint(1 << 60));
    let cases = [
        (pixels_2_28, "needs at least 52076478464 bytes"),
        (pixels_2_60, "claims 1152921504606846976 pixels"),
        (film_2_64, "more than the limit of 268435456"),
        (seeds_2_60, "claims 1152921504606846976 seeds"),
    ];
    for (b, expected) in cases {
        let b = sealed(b);
        let before = ALLOCATED.with(Cell::get);
        let e = decode(&b).unwrap_err().to_string();
        let allocated = ALLOCATED.with(Cell::get) - before;
        assert!(e.contains("x.state") && e.contains(expected), "{e}");
        assert!(allocated < 1 << 16, "{allocated} bytes allocated for: {e}");
    }
}

#[test]
fn a_fifo_or_an_oversized_file_is_refused_without_reading() {
    // The limit is the state of the largest film (2²⁸ pixels, two buffers of up to 382 bytes
    // each: sums and illuminance sums, and 896 bytes of light-and-health sums: 3 × 16 batch
    // sums and 64 bands) and of a shard's meter sums (256 bytes each): one byte more, as a
    // sparse file, is refused before a byte is read.
    let largest = 2 * (1u64 << 28) * 382 + (1u64 << 28) * 896 + state::MAX_METERS * 256;
    assert!((largest..largest + (32 << 20)).contains(&state::MAX_STATE_BYTES));
    let dir = tempfile::tempdir().unwrap();
    let big = dir.path().join("big.state");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(state::MAX_STATE_BYTES + 1)
        .unwrap();
    let e = RenderState::load(&big).unwrap_err().to_string();
    assert!(
        e.contains("big.state") && e.contains("more than the limit"),
        "{e}"
    );
    #[cfg(unix)]
    {
        let fifo = dir.path().join("pipe.state");
        let st = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(st.success());
        let e = RenderState::load(&fifo).unwrap_err().to_string();
        assert!(e.contains("pipe.state") && e.contains("FIFO"), "{e}");
    }
}
