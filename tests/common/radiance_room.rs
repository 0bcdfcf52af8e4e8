//! A 4 m × 4 m × 3 m room with a 2 m × 1.2 m window in the wall y = 0 (the room is y > 0,
//! site up +z), written for Radiance (rtrace -I from PyPI `pyradiance`) and for candela with the
//! same geometry, so that a window material can be compared between the two on work-plane
//! illuminance. Walls are Lambertian of reflectance 0.5; outside is a sky and optionally a sun,
//! nothing below the horizon.
//!
//! Radiance's standard error at each point comes from the spread of independent rtrace rays
//! (-u+) at the point, candela's from its meter.

use super::run;
use std::path::Path;
use std::process::Command;

/// Radiance's white-light efficacy (lm/W): a glow of radiance 1 is 179 cd/m².
pub const EFFICACY: f64 = 179.0;
/// Work-plane points (x, y, z).
pub const POINTS: [[f64; 3]; 3] = [[2.0, 1.0, 0.8], [2.0, 2.0, 0.8], [2.5, 3.2, 0.8]];

/// The window's corners, counter-clockwise seen from outside: its normal points out (−y).
const WINDOW: [[f64; 3]; 4] = [[1., 0., 0.9], [3., 0., 0.9], [3., 0., 2.1], [1., 0., 2.1]];

/// The window material in both renderers and which way its surface faces.
pub struct Window {
    /// Radiance primitives before the surfaces, defining the modifier `win`.
    pub radiance: String,
    /// candela's `"win": …` material entry.
    pub candela: String,
    /// Files to copy beside both scenes.
    pub files: Vec<std::path::PathBuf>,
    /// Whether the window's normal points into the room (a `BSDF` surface's convention).
    pub normal_in: bool,
    /// rtrace options the window needs beyond the common ones.
    pub rtrace: &'static [&'static str],
}

/// The sun: direction toward it (unit, +z up) and Radiance's radiance of its disk (W/sr/m²
/// per channel); candela gets the same normal illuminance.
#[derive(Clone, Copy)]
pub struct Sun {
    pub dir: [f64; 3],
    pub radiance: f64,
}

/// Solid angle of Radiance's 0.533° sun, sr.
fn sun_solid_angle() -> f64 {
    2.0 * std::f64::consts::PI * (1.0 - (0.533f64.to_radians() / 2.0).cos())
}

/// The room's surfaces as (name, material, four corners); the window is "win".
fn surfaces(w: &Window) -> Vec<(&'static str, &'static str, [[f64; 3]; 4])> {
    let q = |a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]| [a, b, c, d];
    let [a, b, c, d] = WINDOW;
    let window = if w.normal_in { [a, d, c, b] } else { WINDOW };
    vec![
        (
            "floor",
            "grey",
            q([0., 0., 0.], [4., 0., 0.], [4., 4., 0.], [0., 4., 0.]),
        ),
        (
            "ceiling",
            "grey",
            q([0., 0., 3.], [4., 0., 3.], [4., 4., 3.], [0., 4., 3.]),
        ),
        (
            "north",
            "grey",
            q([0., 4., 0.], [4., 4., 0.], [4., 4., 3.], [0., 4., 3.]),
        ),
        (
            "west",
            "grey",
            q([0., 0., 0.], [0., 4., 0.], [0., 4., 3.], [0., 0., 3.]),
        ),
        (
            "east",
            "grey",
            q([4., 0., 0.], [4., 4., 0.], [4., 4., 3.], [4., 0., 3.]),
        ),
        (
            "sill",
            "grey",
            q([0., 0., 0.], [4., 0., 0.], [4., 0., 0.9], [0., 0., 0.9]),
        ),
        (
            "head",
            "grey",
            q([0., 0., 2.1], [4., 0., 2.1], [4., 0., 3.], [0., 0., 3.]),
        ),
        (
            "jamb_w",
            "grey",
            q([0., 0., 0.9], [1., 0., 0.9], [1., 0., 2.1], [0., 0., 2.1]),
        ),
        (
            "jamb_e",
            "grey",
            q([3., 0., 0.9], [4., 0., 0.9], [4., 0., 2.1], [3., 0., 2.1]),
        ),
        ("window", "win", window),
    ]
}

/// Radiance scene: a uniform glow sky of radiance `sky` over the upper hemisphere, the sun,
/// Lambertian walls of reflectance 0.5 and the window.
fn radiance_scene(w: &Window, sky: f64, sun: Option<Sun>) -> String {
    let mut s = format!(
        "void glow skyglow 0 0 4 {sky} {sky} {sky} 0\nskyglow source sky 0 0 4 0 0 1 180\n\
         void plastic grey 0 0 5 0.5 0.5 0.5 0 0\n{}\n",
        w.radiance
    );
    if let Some(sun) = sun {
        let [x, y, z] = sun.dir;
        let r = sun.radiance;
        s += &format!(
            "void light solar 0 0 3 {r} {r} {r}\nsolar source sun 0 0 4 {x} {y} {z} 0.533\n"
        );
    }
    for (name, m, c) in surfaces(w) {
        let v: Vec<String> = c.iter().flatten().map(|x| x.to_string()).collect();
        s += &format!("{m} polygon {name} 0 0 12 {}\n", v.join(" "));
    }
    s
}

/// The same room for candela: Quads from the corners, a uniform sky of luminance 179·`sky`
/// cd/m² over a black ground, the sun as a distant light of the same normal illuminance,
/// meters at the points facing up.
pub fn candela_scene(w: &Window, sky: f64, sun: Option<Sun>, samples: u64) -> String {
    let objects: Vec<String> = surfaces(w)
        .iter()
        .map(|(name, m, c)| {
            let e = |a: [f64; 3], b: [f64; 3]| [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let (u, v) = (e(c[0], c[1]), e(c[0], c[3]));
            format!(
                "(name: Some({name:?}), material: {m:?}, shape: Quad(origin: ({}, {}, {}), edge_u: ({}, {}, {}), edge_v: ({}, {}, {})))",
                c[0][0], c[0][1], c[0][2], u[0], u[1], u[2], v[0], v[1], v[2]
            )
        })
        .collect();
    let meters: Vec<String> = POINTS
        .iter()
        .enumerate()
        .map(|(i, p)| {
            format!(
                "Illuminance(name: \"p{i}\", position: ({}, {}, {}), normal: (0, 0, 1))",
                p[0], p[1], p[2]
            )
        })
        .collect();
    let mut lights = vec![format!(
        "Sky(model: Uniform, amount: ZenithLuminance({}), spectrum: Named(\"E\"), ground_reflectance: 0.0)",
        EFFICACY * sky
    )];
    if let Some(sun) = sun {
        let [x, y, z] = sun.dir;
        lights.push(format!(
            "Distant(direction: ({}, {}, {}), spectrum: Named(\"E\"), amount: Illuminance({}))",
            -x,
            -y,
            -z,
            EFFICACY * sun.radiance * sun_solid_angle()
        ));
    }
    format!(
        r#"(
        camera: (position: (2, 3.5, 1.5), look_at: (2, 0, 1.5), up: (0, 0, 1), vfov_deg: 60, resolution: (1, 1)),
        render: (spp: 1),
        site: (up: (0, 0, 1), north: (0, 1, 0)),
        materials: {{
            "grey": Diffuse(reflectance: Constant(0.5)),
            {},
        }},
        objects: [{}],
        lights: [{}],
        meters: [{}],
        measure: (samples: {samples}),
    )"#,
        w.candela,
        objects.join(",\n"),
        lights.join(", "),
        meters.join(", ")
    )
}

/// Radiance's illuminance (lx) at each point: mean and standard error of `replicates` rays,
/// traced with `-ab 12 -ad 16384 -as 0 -aa 0 -lw 1e-6` and the window's options in `dir`.
pub fn radiance(
    dir: &Path,
    w: &Window,
    sky: f64,
    sun: Option<Sun>,
    replicates: usize,
) -> Vec<(f64, f64)> {
    let pkg = super::pyradiance_dir();
    let path = format!(
        "{}:{}",
        pkg.join("bin").display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let raypath = format!(".:{}", pkg.join("lib").display());
    for f in &w.files {
        std::fs::copy(f, dir.join(f.file_name().unwrap())).unwrap();
    }
    std::fs::write(dir.join("room.rad"), radiance_scene(w, sky, sun)).unwrap();
    let oct = run(
        Command::new(pkg.join("bin/oconv"))
            .arg("room.rad")
            .current_dir(dir)
            .env("PATH", &path)
            .env("RAYPATH", &raypath),
        "oconv",
    );
    std::fs::write(dir.join("room.oct"), oct).unwrap();
    let mut rays = String::new();
    for p in POINTS {
        for _ in 0..replicates {
            rays += &format!("{} {} {} 0 0 1\n", p[0], p[1], p[2]);
        }
    }
    std::fs::write(dir.join("rays.txt"), rays).unwrap();
    let out = run(
        Command::new(pkg.join("bin/rtrace"))
            .args(["-I", "-h", "-u+", "-ab", "12", "-ad", "16384", "-as", "0"])
            .args(["-aa", "0", "-lw", "1e-6"])
            .args(w.rtrace)
            .arg("room.oct")
            .stdin(std::fs::File::open(dir.join("rays.txt")).unwrap())
            .current_dir(dir)
            .env("PATH", &path)
            .env("RAYPATH", &raypath),
        "rtrace",
    );
    let values: Vec<f64> = String::from_utf8(out)
        .unwrap()
        .lines()
        .map(|l| {
            let c: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            EFFICACY * (0.265 * c[0] + 0.670 * c[1] + 0.065 * c[2])
        })
        .collect();
    assert_eq!(values.len(), POINTS.len() * replicates);
    values
        .chunks(replicates)
        .map(|v| {
            let n = v.len() as f64;
            let m = v.iter().sum::<f64>() / n;
            let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
            (m, (var / n).sqrt())
        })
        .collect()
}

/// What a comparison accepts at each point.
pub struct Tolerance {
    /// Most combined standard errors between the two.
    pub z_max: f64,
    /// Largest standard error of either, relative to its value.
    pub max_rel_se: f64,
    /// Largest relative difference where a known difference of method remains (`None`: the
    /// z bound alone).
    pub max_rel_diff: Option<f64>,
}

/// candela's and Radiance's work-plane illuminance for `w` under `sky` (and `sun`), compared
/// as `tol` says. Prints both; returns the failures.
pub fn compare(
    name: &str,
    w: &Window,
    (sky, sun): (f64, Option<Sun>),
    samples: u64,
    replicates: usize,
    tol: &Tolerance,
) -> Vec<String> {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("room_{name}"));
    std::fs::create_dir_all(&dir).unwrap();
    let rad = radiance(&dir, w, sky, sun, replicates);
    let world = super::world_in(&candela_scene(w, sky, sun, samples), &dir);
    let ours = candela::meter::measure_all(&world).meters;
    let mut failures = Vec::new();
    for (i, (c, r)) in ours.iter().zip(&rad).enumerate() {
        let se = (c.stderr.powi(2) + r.1.powi(2)).sqrt();
        let z = (c.mean - r.0) / se;
        println!(
            "{name} p{i} {:?}: candela {:.3} ± {:.3} lx, Radiance {:.3} ± {:.3} lx, \
             difference {:+.2} % (z = {z:+.2})",
            POINTS[i],
            c.mean,
            c.stderr,
            r.0,
            r.1,
            100.0 * (c.mean / r.0 - 1.0)
        );
        let z_ok = match tol.max_rel_diff {
            Some(d) => (c.mean / r.0 - 1.0).abs() <= d,
            None => z.abs() <= tol.z_max,
        };
        if !z_ok || c.stderr > tol.max_rel_se * c.mean || r.1 > tol.max_rel_se * r.0 {
            failures.push(format!("{name} p{i}: z = {z:.2}"));
        }
    }
    failures
}
