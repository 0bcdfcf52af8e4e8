//! Helpers shared by the render tests: build a world from RON text, render, summarise.
#![allow(dead_code)]

pub mod radiance_room;
pub mod weather;

use candela::film::Film;
use candela::scene::{self, Overrides};
use candela::world::World;
use std::path::Path;

pub fn world(text: &str) -> World {
    let path = Path::new("test-scene.ron");
    let s = scene::parse(text, path).unwrap_or_else(|e| panic!("{e}"));
    scene::build(&s, path, &Overrides::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// [`world`] with the caustics mode overridden (as `--caustics` does).
pub fn world_with(text: &str, caustics: candela::world::Caustics) -> World {
    let path = Path::new("test-scene.ron");
    let s = scene::parse(text, path).unwrap_or_else(|e| panic!("{e}"));
    let o = Overrides {
        caustics: Some(caustics),
        ..Default::default()
    };
    scene::build(&s, path, &o).unwrap_or_else(|e| panic!("{e}"))
}

pub fn render(world: &World, threads: usize) -> Film {
    candela::render::render(world, Some(threads), &|_, _| {})
        .expect("render")
        .film
}

/// Mean over all pixels of the per-pixel mean XYZ, and the standard error of the image-mean Y
/// (pixels are independent: √(Σ se²)/n).
pub fn image_mean(film: &Film) -> ([f64; 3], f64) {
    let n = film.pixels.len() as f64;
    let mut m = [0.0; 3];
    let mut var = 0.0;
    for p in &film.pixels {
        let x = p.mean_xyz();
        for k in 0..3 {
            m[k] += x[k] / n;
        }
        var += p
            .y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES)
            .powi(2);
    }
    (m, var.sqrt() / n)
}

/// Assert that every pixel's Y is within `k` standard errors of `expected`, and the image mean
/// within 4 standard errors, which must be below 1 % of `expected` (so that the test keeps its
/// power: a change that made the render much noisier would otherwise widen its own tolerance).
pub fn assert_every_pixel(film: &Film, expected: f64, k: f64) {
    for (i, p) in film.pixels.iter().enumerate() {
        let y = p.mean_xyz()[1];
        let se = p.y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES);
        assert!(
            (y - expected).abs() <= k * se,
            "pixel {i}: Y = {y} cd/m², expected {expected} ± {k}·{se}"
        );
    }
    assert_image_mean(film, expected);
}

/// Assert that at least `min_coverage` of the pixels' 95 % intervals (Student t with their
/// batches − 1 degrees of freedom) hold `expected`, and the image mean is within 4 standard
/// errors of it, below 1 % of `expected`: for images whose per-sample values are skewed (a
/// furnace: deterministic first bounces and a geometric tail of Russian roulette), where single
/// pixels' t statistics from 16 batches have heavier tails than a per-pixel bound assumes
/// (docs/uncertainty.md, "Few samples per batch").
pub fn assert_pixel_coverage(film: &Film, expected: f64, min_coverage: f64) {
    let held = film
        .pixels
        .iter()
        .filter(|p| {
            (p.mean_xyz()[1] - expected).abs()
                <= p.y_ci95_half_width(candela::film::DEFAULT_PIXEL_BATCHES)
        })
        .count();
    let coverage = held as f64 / film.pixels.len() as f64;
    assert!(
        coverage >= min_coverage,
        "{held} of {} pixels' 95 % intervals hold {expected} ({:.1} %, at least {:.1} % expected)",
        film.pixels.len(),
        100.0 * coverage,
        100.0 * min_coverage
    );
    assert_image_mean(film, expected);
}

/// Assert that the image mean is within 4 standard errors of `expected`, which must be below
/// 1 % of `expected` (so that a change making the render much noisier cannot widen its own
/// tolerance).
fn assert_image_mean(film: &Film, expected: f64) {
    let (m, se) = image_mean(film);
    assert!(
        (m[1] - expected).abs() <= 4.0 * se,
        "image mean Y = {} cd/m², expected {expected} ± 4·{se}",
        m[1]
    );
    assert!(
        se <= 0.01 * expected.abs(),
        "image mean Y: standard error {se} cd/m² is above 1 % of {expected}"
    );
}

/// The box-filter mean of `f(origin, direction)` over the camera rays of pixel (x, y): a 16×16
/// midpoint quadrature over the pixel square.
pub fn pixel_footprint_mean(
    w: &World,
    x: usize,
    y: usize,
    f: impl Fn(glam::Vec3, glam::Vec3) -> f64,
) -> f64 {
    let n = 16;
    let mut sum = 0.0;
    for j in 0..n {
        for i in 0..n {
            let r = w.camera.generate_ray(
                x as f32 + (i as f32 + 0.5) / n as f32,
                y as f32 + (j as f32 + 0.5) / n as f32,
                glam::Vec2::ZERO,
            );
            sum += f(r.origin, r.dir);
        }
    }
    sum / (n * n) as f64
}

/// The box-filter mean of `f` over pixel (x, y)'s footprint on the plane y = 0: the points
/// where the pixel's camera rays meet the plane (see [`pixel_footprint_mean`]).
pub fn floor_footprint_mean(w: &World, x: usize, y: usize, f: impl Fn(glam::Vec3) -> f64) -> f64 {
    pixel_footprint_mean(w, x, y, |o, d| f(o + d * (-o.y / d.y)))
}

/// Unpolarised Fresnel reflectance of a smooth dielectric (relative index `eta`) at incidence
/// cosine `cos_i` (from outside), written out here independently of the renderer's.
pub fn fresnel_unpolarised(cos_i: f64, eta: f64) -> f64 {
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Every pixel's value (mean, standard error) within 5σ of `expected(x, y)`, and the image
/// mean within 4σ with a standard error below 1 %.
pub fn check_pixels(
    film: &Film,
    label: &str,
    value: impl Fn(&candela::film::PixelSums) -> (f64, f64),
    expected: impl Fn(usize, usize) -> f64,
) {
    check_values(film, label, |i| value(&film.pixels[i]), expected);
}

/// [`check_pixels`] of a value that needs the pixels' illuminance sums.
pub fn check_pixels_e(
    film: &Film,
    label: &str,
    value: impl Fn(candela::film::PixelE) -> (f64, f64),
    expected: impl Fn(usize, usize) -> f64,
) {
    let pixel = |i| film.pixel_e(i).expect("the film has illuminance sums");
    check_values(film, label, |i| value(pixel(i)), expected);
}

fn check_values(
    film: &Film,
    label: &str,
    value: impl Fn(usize) -> (f64, f64),
    expected: impl Fn(usize, usize) -> f64,
) {
    let (mut sum, mut sum_exp, mut var) = (0.0, 0.0, 0.0);
    for y in 0..film.height {
        for x in 0..film.width {
            let (v, se) = value(y * film.width + x);
            let e = expected(x, y);
            assert!(
                (v - e).abs() <= 5.0 * se,
                "{label}, pixel ({x}, {y}): {v} ± {se}, expected {e}"
            );
            sum += v;
            sum_exp += e;
            var += se * se;
        }
    }
    let n = film.pixels.len() as f64;
    let (m, e, se) = (sum / n, sum_exp / n, var.sqrt() / n);
    assert!(
        (m - e).abs() <= 4.0 * se && se < 0.01 * e,
        "{label}: mean {m} ± {se}, expected {e}"
    );
}

pub fn luminance(p: &candela::film::PixelSums) -> (f64, f64) {
    (
        p.mean_xyz()[1],
        p.y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES),
    )
}

/// Straight-through transmittance of a thin non-absorbing slab (relative index `eta`) at
/// incidence cosine `cos_i`: T = (1 − R)/(1 + R) for each polarisation (both faces and all
/// their incoherent inter-reflections), then averaged over s and p; written out here
/// independently of the renderer's.
pub fn thin_slab_transmittance(cos_i: f64, eta: f64) -> f64 {
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let rs = ((cos_i - eta * cos_t) / (cos_i + eta * cos_t)).powi(2);
    let rp = ((eta * cos_i - cos_t) / (eta * cos_i + cos_t)).powi(2);
    0.5 * ((1.0 - rs) / (1.0 + rs) + (1.0 - rp) / (1.0 + rp))
}

/// Reflectance of a conductor of complex index n + ik (`n_re`, `k`) at incidence angle θ (cos θ = `c`),
/// unpolarised: the average of |r_s|² and |r_p|² (Born & Wolf §14.2).
pub fn conductor_reflectance(c: f64, n_re: f64, k: f64) -> f64 {
    let s2 = 1.0 - c * c;
    // n̂² − sin²θ = a + ib; its square root u + iv.
    let (a, b) = (n_re * n_re - k * k - s2, 2.0 * n_re * k);
    let m = (a * a + b * b).sqrt();
    let (u, v) = (((m + a) / 2.0).sqrt(), ((m - a) / 2.0).sqrt());
    let rs = ((c - u).powi(2) + v * v) / ((c + u).powi(2) + v * v);
    // r_p = (n̂² cos θ − w) / (n̂² cos θ + w), w = u + iv.
    let (pr, pi) = (a + s2, b); // n̂² = (n² − k²) + i·2nk
    let (xr, xi) = (pr * c, pi * c);
    let rp = ((xr - u).powi(2) + (xi - v).powi(2)) / ((xr + u).powi(2) + (xi + v).powi(2));
    0.5 * (rs + rp)
}

/// An estimate (mean ± standard error) within 5 standard errors of `expected`, with a standard
/// error below `max_rel_se` of it (so that the check has power). Below 10⁻⁵ of `expected` the
/// renderer is not a Monte Carlo estimate of the closed form alone: emission is scaled by a
/// 1 nm sum of the spectrum against V(λ) while paths integrate its interpolant, in single
/// precision (a D65 sky reads 1.6·10⁻⁶ low), so that much is allowed beside the 5 standard
/// errors (stratified meters reach standard errors of 10⁻⁸).
pub fn assert_estimate_near(mean: f64, stderr: f64, expected: f64, max_rel_se: f64, label: &str) {
    assert!(
        (mean - expected).abs() <= 5.0 * stderr + 1e-5 * expected.abs()
            && stderr < max_rel_se * expected,
        "{label}: {mean} ± {stderr}, expected {expected}"
    );
}

/// Runs the `candela` binary with `args` in `dir`: (exit code, stdout, stderr); the exit code is
/// −1 if it was killed by a signal.
pub fn cli(args: &[&str], dir: &Path) -> (i32, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_candela"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Renders the scene file `scene` (in `dir`) once per (name, seed) with `--save-state`, writing
/// NAME.exr, NAME.png and NAME.state there; panics if a render fails.
pub fn render_states(dir: &Path, scene: &str, runs: &[(&str, &str)]) {
    for (name, seed) in runs {
        let args = [
            "render",
            "--quiet",
            "--save-state",
            "--seed",
            seed,
            "--out",
            name,
            scene,
        ];
        let (code, _, stderr) = cli(&args, dir);
        assert_eq!(code, 0, "{stderr}");
    }
}

/// The sorted names of the files in `dir`.
pub fn listing(dir: &Path) -> Vec<String> {
    let mut files: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    files
}

/// The Python interpreter of the reference tests (colour-science, pyradiance, ladybug-core):
/// `$CANDELA_PYTHON` if set, else `<repo>/target/venv/bin/python` (scripts/setup_python.sh).
pub fn python() -> std::path::PathBuf {
    if let Some(p) = std::env::var_os("CANDELA_PYTHON") {
        let p = std::path::PathBuf::from(p);
        assert!(
            p.exists(),
            "CANDELA_PYTHON={} does not exist; unset it or run scripts/setup_python.sh",
            p.display()
        );
        return p;
    }
    let p = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/venv/bin/python");
    assert!(
        p.exists(),
        "no Python for the reference tests: {} is missing and CANDELA_PYTHON is not set.\n\
         Run scripts/setup_python.sh (creates target/venv with colour-science 0.4.7, pyradiance \
         and ladybug-core) or set CANDELA_PYTHON to an interpreter that has them.",
        p.display()
    );
    p
}

/// Directory of pyradiance's package in [`python`]'s environment: its `bin` holds Radiance's
/// tools, its `lib` their RAYPATH.
pub fn pyradiance_dir() -> std::path::PathBuf {
    let out = std::process::Command::new(python())
        .args([
            "-c",
            "import os, pyradiance; print(os.path.dirname(pyradiance.__file__))",
        ])
        .output()
        .expect("run python");
    assert!(
        out.status.success(),
        "import pyradiance: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::path::PathBuf::from(String::from_utf8(out.stdout).unwrap().trim())
}

/// Runs the reference script `tests/<script>` under [`python`] with `args`, writing `input`
/// (JSON) to its standard input when given, and returns the JSON it prints.
pub fn python_json(
    script: &str,
    args: &[&std::ffi::OsStr],
    input: Option<&serde_json::Value>,
) -> serde_json::Value {
    use std::process::{Command, Stdio};
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join(script);
    let mut child = Command::new(python())
        .arg(&path)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run python");
    let stdin = child.stdin.take().unwrap();
    if let Some(v) = input {
        serde_json::to_writer(stdin, v).unwrap();
    } else {
        drop(stdin);
    }
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{script} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The walls, floor and ceiling of the side-lit room of the annual-daylight tests (RON
/// objects of material "grey", without the brackets): 4 × 4 m, 3 m high, with a 2 × 1.2 m
/// window x ∈ [−1, 1], y ∈ [0.9, 2.1] in its south wall z = 2 (+z is south in the default
/// site frame).
#[macro_export]
macro_rules! side_lit_room_walls {
    () => {
        r#"
        (material: "grey", shape: Quad(origin: (-2, 0, -2), edge_u: (0, 0, 4), edge_v: (4, 0, 0))),
        (material: "grey", shape: Quad(origin: (-2, 3, -2), edge_u: (4, 0, 0), edge_v: (0, 0, 4))),
        (material: "grey", shape: Quad(origin: (-2, 0, -2), edge_u: (4, 0, 0), edge_v: (0, 3, 0))),
        (material: "grey", shape: Quad(origin: (-2, 0, -2), edge_u: (0, 3, 0), edge_v: (0, 0, 4))),
        (material: "grey", shape: Quad(origin: (2, 0, -2), edge_u: (0, 0, 4), edge_v: (0, 3, 0))),
        (material: "grey", shape: Quad(origin: (-2, 0, 2), edge_u: (0, 0.9, 0), edge_v: (4, 0, 0))),
        (material: "grey", shape: Quad(origin: (-2, 2.1, 2), edge_u: (0, 0.9, 0), edge_v: (4, 0, 0))),
        (material: "grey", shape: Quad(origin: (-2, 0.9, 2), edge_u: (0, 1.2, 0), edge_v: (1, 0, 0))),
        (material: "grey", shape: Quad(origin: (1, 0.9, 2), edge_u: (0, 1.2, 0), edge_v: (1, 0, 0))),
"#
    };
}

/// The side-lit room's window as a sky portal (RON `portals` field).
pub const SIDE_LIT_PORTAL: &str =
    "portals: [(origin: (-1, 0.9, 2), edge_u: (2, 0, 0), edge_v: (0, 1.2, 0))]";
/// A one-pixel camera inside the side-lit room.
pub const SIDE_LIT_CAMERA: &str =
    "camera: (position: (0, 1, 0), look_at: (0, 1, 1), vfov_deg: 30, resolution: (1, 1))";

/// The default site frame of a scene: up +y, north −z, east +x.
pub fn default_site() -> candela::light::sky::SiteFrame {
    candela::light::sky::SiteFrame::new(glam::DVec3::Y, glam::DVec3::NEG_Z).unwrap()
}

/// (east, north, up) and scene directions (default site) toward the sun at altitude and azimuth
/// (degrees, azimuth from north through east).
pub fn to_sun(alt_deg: f64, az_deg: f64) -> ([f64; 3], glam::Vec3) {
    let (a, z) = (alt_deg.to_radians(), az_deg.to_radians());
    let enu = [a.cos() * z.sin(), a.cos() * z.cos(), a.sin()];
    (
        enu,
        glam::Vec3::new(enu[0] as f32, enu[2] as f32, -enu[1] as f32),
    )
}

/// Writes `text` as `dir`/scene.ron and builds its world (files it names resolve from `dir`).
pub fn world_in(text: &str, dir: &Path) -> World {
    let path = dir.join("scene.ron");
    std::fs::write(&path, text).unwrap();
    scene::load_world(&path, &Overrides::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// Mean Y (cd/m²) and its standard error over each `b`×`b` pixel block of a film, row by row.
pub fn block_means(film: &Film, b: usize) -> Vec<(f64, f64)> {
    let (w, h) = (film.width, film.height);
    let mut out = Vec::new();
    for by in 0..h / b {
        for bx in 0..w / b {
            let (mut m, mut v) = (0.0, 0.0);
            for y in by * b..(by + 1) * b {
                for x in bx * b..(bx + 1) * b {
                    let p = &film.pixels[y * w + x];
                    m += p.mean_xyz()[1];
                    v += p
                        .y_standard_error(candela::film::DEFAULT_PIXEL_BATCHES)
                        .powi(2);
                }
            }
            let n = (b * b) as f64;
            out.push((m / n, v.sqrt() / n));
        }
    }
    out
}

/// Two renders of one view compared block by block (`b`×`b` pixels): asserts that each block's
/// mean Y agrees within 4.5 combined standard errors, naming the renders `names` in the
/// message; returns the largest |z|.
pub fn assert_blocks_agree(a: &Film, b: &Film, block: usize, names: (&str, &str)) -> f64 {
    let mut worst = 0.0f64;
    let (ba, bb) = (block_means(a, block), block_means(b, block));
    for (i, ((ma, sa), (mb, sb))) in ba.iter().zip(&bb).enumerate() {
        let z = (ma - mb) / (sa * sa + sb * sb).sqrt();
        worst = worst.max(z.abs());
        assert!(
            z.abs() < 4.5,
            "block {i}: {} {ma} ± {sa}, {} {mb} ± {sb} cd/m²",
            names.0,
            names.1
        );
    }
    worst
}

/// A binary glTF (`.glb`) of the JSON `j` and the buffer `bin`: the 12-byte header, the JSON
/// chunk padded with spaces to 4 bytes, and the BIN chunk.
pub fn glb(j: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    let mut text = serde_json::to_vec(j).unwrap();
    while text.len() % 4 != 0 {
        text.push(b' ');
    }
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + text.len() + 8 + bin.len()) as u32).to_le_bytes());
    out.extend((text.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(text);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

/// One textured quad as `dir`/`name`, a `.gltf` with its buffer in `name.bin`: corners
/// `positions` with texture coordinates (0, 0), (1, 0), (1, 1), (0, 1), triangles `indices`
/// (glTF's front faces wind counter-clockwise), the primitive on material 0; `extra` (its
/// materials, images, textures, samplers, extensions) is merged into the document.
#[allow(dead_code)]
pub fn gltf_quad(
    dir: &Path,
    name: &str,
    positions: [[f32; 3]; 4],
    indices: [u32; 6],
    extra: serde_json::Value,
) {
    let uv: [[f32; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let mut bin: Vec<u8> = (positions.iter().flatten())
        .flat_map(|v| v.to_le_bytes())
        .collect();
    bin.extend(uv.iter().flatten().flat_map(|v| v.to_le_bytes()));
    bin.extend(indices.iter().flat_map(|v| v.to_le_bytes()));
    let bin_name = format!("{name}.bin");
    std::fs::write(dir.join(&bin_name), &bin).unwrap();
    let bound = |f: fn(f32, f32) -> f32| {
        (0..3)
            .map(|k| positions.iter().map(|p| p[k]).reduce(f).unwrap())
            .collect::<Vec<_>>()
    };
    let mut doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bin.len(), "uri": bin_name}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 32},
            {"buffer": 0, "byteOffset": 80, "byteLength": 24}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": bound(f32::min), "max": bound(f32::max)},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5125, "count": 6, "type": "SCALAR"}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
                                     "indices": 2, "material": 0}]}],
        "nodes": [{"mesh": 0}],
    });
    for (k, v) in extra.as_object().expect("extra is a JSON object") {
        doc[k] = v.clone();
    }
    std::fs::write(dir.join(name), serde_json::to_vec_pretty(&doc).unwrap()).unwrap();
}

/// The unit direction at the corner shared by pixels (`column`, `row`), (`column` + 1, `row`)
/// and the two below them, of an image `width` pixels wide whose pixels look along
/// `direction`: the mean of the four, normalised (a synthetic source centred there has its
/// weighted centre mid-pixel, away from pixel edges).
pub fn pixel_corner_direction(
    direction: &[[f64; 3]],
    width: usize,
    column: usize,
    row: usize,
) -> [f64; 3] {
    let (w, c, r) = (width, column, row);
    let mut s = [0.0; 3];
    for i in [
        r * w + c,
        r * w + c + 1,
        (r + 1) * w + c,
        (r + 1) * w + c + 1,
    ] {
        for k in 0..3 {
            s[k] += direction[i][k];
        }
    }
    let n = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    s.map(|v| v / n)
}

/// A standard normal deviate number `i` of stream `seed` (Box–Muller on a 64-bit hash),
/// independent of the library's random numbers.
pub fn gauss(seed: u64, i: u64) -> f64 {
    let h = |x: u64| {
        let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    };
    let a = h(seed.wrapping_mul(0x1000_0000_01b3) ^ (2 * i));
    let b = h(a ^ (2 * i + 1));
    let u1 = ((a >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
    let u2 = (b >> 11) as f64 / (1u64 << 53) as f64;
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// Run `cmd`, panicking with `what` and its error output if it fails; its standard output.
pub fn run(cmd: &mut std::process::Command, what: &str) -> Vec<u8> {
    let t0 = std::time::Instant::now();
    let out = cmd.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(
        out.status.success(),
        "{what} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    eprintln!("{what}: {:.1} s", t0.elapsed().as_secs_f64());
    out.stdout
}
