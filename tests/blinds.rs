//! The `Blinds` shape against Radiance's `genblinds` (run from PyPI `pyradiance`) vertex for
//! vertex, its slats against the closed form of the light that passes flat blinds, and its
//! description's errors, each naming the field.
//!
//! Fails without the Python venv (scripts/setup_python.sh, or CANDELA_PYTHON), as the other
//! reference tests do.

mod common;

use candela::description::context::Context;
use candela::description::schema::ShapeDesc;
use candela::geometry::blinds::MAX_BLINDS_TRIANGLES;
use candela::geometry::Shape;
use candela::scene::{self, Overrides};
use glam::{DVec3, Vec3};
use std::path::Path;
use std::process::Command;

/// genblinds prints 12 significant digits; candela stores single-precision vertices (2.4e-7 m
/// at 3 m from the origin). 1e-5 m leaves room for both, and is far below any slat size.
const VERTEX_TOL_M: f64 = 1e-5;

/// genblinds' polygons for `args` (depth width height nslats angle [-r|+r R]), each four
/// vertices in genblinds' frame.
fn genblinds(args: &[&str]) -> Vec<[DVec3; 4]> {
    let bin = common::pyradiance_dir().join("bin/genblinds");
    let out = Command::new(&bin)
        .args(["slat", "b"])
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("run {}: {e}", bin.display()));
    assert!(
        out.status.success(),
        "genblinds {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let tokens: Vec<&str> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .flat_map(str::split_whitespace)
        .collect();
    // Each polygon: material, "polygon", name, 0, 0, 12, then 12 coordinates.
    assert_eq!(tokens.len() % 18, 0, "genblinds output:\n{text}");
    tokens
        .chunks(18)
        .map(|c| {
            assert_eq!((c[1], c[3], c[4], c[5]), ("polygon", "0", "0", "12"));
            let v: Vec<f64> = c[6..].iter().map(|t| t.parse().unwrap()).collect();
            [0, 1, 2, 3].map(|i| DVec3::new(v[3 * i], v[3 * i + 1], v[3 * i + 2]))
        })
        .collect()
}

/// A frame of the blinds: origin, width_dir (genblinds' Y), up (Z), out (X).
type Frame = ([f32; 3], [f32; 3], [f32; 3], [f32; 3]);

/// The Blinds description of genblinds' `depth width height nslats angle` and `r` (its `-r`).
fn desc(frame: Frame, dims: [f64; 3], count: u32, angle_deg: f64, r: Option<f64>) -> ShapeDesc {
    ShapeDesc::Blinds {
        origin: frame.0,
        width_dir: frame.1,
        up: frame.2,
        out: frame.3,
        depth: dims[0],
        width: dims[1],
        height: dims[2],
        spacing: None,
        count: Some(count),
        angle_deg,
        curvature_radius: r,
        thickness: 0.0,
    }
}

/// Builds `d` through the scene description's path (`Shape::build`) and compares its triangles
/// with genblinds' polygons moved into the frame: polygon i = triangles 2i (v0 v1 v2) and
/// 2i + 1 (v0 v2 v3), the same vertices in the same order.
fn assert_twin(d: &ShapeDesc, frame: Frame, args: &[&str]) {
    let ctx = Context {
        path: Path::new("blinds-test.ron"),
        dir: Default::default(),
        sources: Default::default(),
    };
    let Shape::Mesh(mesh) = Shape::build(&ctx, "objects[0].shape", d).unwrap() else {
        panic!("Blinds must build a triangle mesh");
    };
    let polys = genblinds(args);
    assert_eq!(
        mesh.indices.len(),
        2 * polys.len(),
        "triangles for genblinds {args:?}"
    );
    let v = |a: [f32; 3]| Vec3::from_array(a).as_dvec3();
    let (o, w, u, x) = (v(frame.0), v(frame.1), v(frame.2), v(frame.3));
    let (w, u, x) = (w.normalize(), u.normalize(), x.normalize());
    let place = |p: DVec3| o + p.x * x + p.y * w + p.z * u;
    for (i, poly) in polys.iter().enumerate() {
        for (t, corners) in [[0, 1, 2], [0, 2, 3]].iter().enumerate() {
            let tri = mesh.indices[2 * i + t];
            for (k, &c) in corners.iter().enumerate() {
                let got = mesh.positions[tri[k] as usize].as_dvec3();
                let want = place(poly[c]);
                assert!(
                    (got - want).length() < VERTEX_TOL_M,
                    "genblinds {args:?}, polygon {i}, vertex {c}: candela {got}, genblinds {want}"
                );
            }
        }
    }
}

const DESIGN_FRAME: Frame = (
    [0.1, 0.9, 5.95],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
);
/// A frame turned about the vertical, out = width_dir × up.
const TURNED: Frame = (
    [2.0, -1.0, 0.8],
    [0.6, 0.8, 0.0],
    [0.0, 0.0, 1.0],
    [0.8, -0.6, 0.0],
);
/// The same, left-handed: genblinds' output mirrored.
const MIRRORED: Frame = (
    [2.0, -1.0, 0.8],
    [0.6, 0.8, 0.0],
    [0.0, 0.0, 1.0],
    [-0.8, 0.6, 0.0],
);

#[test]
fn flat_slats_are_genblinds_polygons() {
    for (frame, angle, a) in [
        (DESIGN_FRAME, 45.0, "45"),
        (TURNED, -30.0, "-30"),
        (MIRRORED, 0.0, "0"),
        (TURNED, 90.0, "90"),
    ] {
        let d = desc(frame, [0.025, 3.0, 1.5], 70, angle, None);
        assert_twin(&d, frame, &["0.025", "3", "1.5", "70", a]);
    }
}

#[test]
fn curved_slats_are_genblinds_polygons() {
    // (-r R) is curvature_radius R, (+r R) is −R; radii down to just over depth / 2, where
    // the arc is near a half circle (60 segments of 3°).
    for (frame, angle, r, args) in [
        (
            DESIGN_FRAME,
            30.0,
            0.05,
            ["0.025", "3", "1.5", "70", "30", "-r", "0.05"],
        ),
        (
            TURNED,
            -45.0,
            -0.05,
            ["0.025", "1.2", "1", "20", "-45", "+r", "0.05"],
        ),
        (
            MIRRORED,
            10.0,
            0.0126,
            ["0.025", "1.2", "1", "20", "10", "-r", "0.0126"],
        ),
        (
            TURNED,
            0.0,
            -0.2,
            ["0.08", "2", "2.4", "30", "0", "+r", "0.2"],
        ),
    ] {
        let dims: Vec<f64> = args[..3].iter().map(|a| a.parse().unwrap()).collect();
        let count = args[3].parse().unwrap();
        let d = desc(frame, [dims[0], dims[1], dims[2]], count, angle, Some(r));
        assert_twin(&d, frame, &args);
    }
}

/// Blinds scene: flat slats of depth 0.05 m every 0.04 m (25 in 1 m), out = +x, along +y, up
/// +z; `extra` is appended to the shape's fields.
fn blinds_scene(shape_fields: &str) -> String {
    format!(
        r#"(
    camera: (position: (3, 1, 0.5), look_at: (0, 1, 0.5), vfov_deg: 40, resolution: (4, 4)),
    materials: {{ "slat": Diffuse(reflectance: Constant(0.7)) }},
    objects: [(name: "blinds", material: "slat", shape: Blinds({shape_fields}))],
    lights: [Point(position: (3, 1, 3), spectrum: Named("D65"), amount: Intensity(10.0))],
)"#
    )
}

fn fields(angle_deg: f64) -> String {
    format!(
        "origin: (0, 0, 0), width_dir: (0, 1, 0), up: (0, 0, 1), out: (1, 0, 0), width: 2.0, \
         height: 1.0, depth: 0.05, spacing: 0.04, angle_deg: {angle_deg:?}"
    )
}

/// Parallel rays in the plane normal to the slats at profile angle β (descending toward −out
/// for β > 0) cross flat slats of depth d, spacing s, tilt θ: each slat's shadow on the
/// blinds' plane is d·|sin(θ − β)| / cos β long, so the fraction that passes is
/// max(0, 1 − d·|sin(θ − β)| / (s·cos β)).
#[test]
fn flat_slats_pass_the_closed_form_fraction_of_parallel_light() {
    let (d, s) = (0.05, 0.04);
    for (theta, beta) in [
        (0.0, 30.0),
        (0.0, 10.0),
        (20.0, 0.0),
        (45.0, 60.0),
        (45.0, 0.0),
        (70.0, 45.0),
        (-30.0, -10.0),
        (-30.0, 20.0),
    ] {
        let w = common::world(&blinds_scene(&fields(theta)));
        let (t, b) = (f64::to_radians(theta), f64::to_radians(beta));
        let expected = (1.0 - d * (t - b).sin().abs() / (s * b.cos())).max(0.0);
        let dir = Vec3::new(-b.cos() as f32, 0.0, -b.sin() as f32);
        // Rays crossing the plane x = 0 on an even grid over 10 periods in the middle of the
        // stack: a midpoint grid miscounts each shadow by at most one ray, so the fraction is
        // off by at most (periods + 1) / n.
        let (periods, n) = (10.0, 40_000);
        let tol = (periods + 1.0) / n as f64;
        let mut open = 0usize;
        for i in 0..n {
            let zc = 0.3 + periods * s * (i as f64 + 0.5) / n as f64;
            let x0 = 1.0;
            let o = Vec3::new(x0 as f32, 1.0, (zc + x0 * b.tan()) as f32);
            if w.geometry.intersect(o, dir, f32::INFINITY).is_none() {
                open += 1;
            }
        }
        let got = open as f64 / n as f64;
        eprintln!("θ = {theta}°, β = {beta}°: open {got:.5}, closed form {expected:.5}");
        assert!(
            (got - expected).abs() <= tol,
            "slats at {theta}°, light at profile angle {beta}°: open fraction {got}, closed form {expected} (±{tol})"
        );
    }
}

/// The message of a scene that must be refused.
fn error_of(shape_fields: &str) -> String {
    let text = blinds_scene(shape_fields);
    let path = Path::new("blinds-test.ron");
    match scene::parse(&text, path) {
        Err(e) => e.to_string(),
        Ok(sc) => match scene::build(&sc, path, &Overrides::default()) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("the scene was accepted:\n{text}"),
        },
    }
}

#[test]
fn each_bad_field_is_named() {
    let ok = fields(30.0);
    // Replace one field of the valid description.
    let with = |from: &str, to: &str| {
        assert!(ok.contains(from), "{from}");
        ok.replace(from, to)
    };
    let cases: Vec<(String, &str, &str)> = vec![
        (
            with("width: 2.0", "width: -2.0"),
            "shape.width`",
            "greater than 0",
        ),
        (
            with("height: 1.0", "height: 0.0"),
            "shape.height`",
            "greater than 0",
        ),
        (
            with("depth: 0.05", "depth: NaN"),
            "shape.depth`",
            "not a finite number",
        ),
        (
            with("origin: (0, 0, 0)", "origin: (0, inf, 0)"),
            "shape.origin.y`",
            "finite",
        ),
        (
            with("angle_deg: 30.0", "angle_deg: 95.0"),
            "shape.angle_deg`",
            "[-90, 90]",
        ),
        (
            with("angle_deg: 30.0", "angle_deg: inf"),
            "shape.angle_deg`",
            "finite",
        ),
        (
            with("up: (0, 0, 1)", "up: (0, 0.1, 1)"),
            "shape.up`",
            "perpendicular",
        ),
        (
            with("up: (0, 0, 1)", "up: (0, 0, 0)"),
            "shape.up`",
            "zero vector",
        ),
        (
            with("out: (1, 0, 0)", "out: (1, 0, 0.2)"),
            "shape.out`",
            "perpendicular",
        ),
        (
            with("spacing: 0.04", "spacing: 0.04, count: 25"),
            "shape.spacing`",
            "not both",
        ),
        (with("spacing: 0.04, ", ""), "shape.spacing`", "count"),
        (
            with("spacing: 0.04", "count: 0"),
            "shape.count`",
            "at least 1",
        ),
        (
            with("spacing: 0.04", "spacing: -0.04"),
            "shape.spacing`",
            "greater than 0",
        ),
        (
            with("spacing: 0.04", "spacing: 1.5"),
            "shape.spacing`",
            "more than the height",
        ),
        (
            with("spacing: 0.04", "spacing: 1e-9"),
            "shape.spacing`",
            "1000000",
        ),
        (
            format!("{ok}, curvature_radius: Some(0.02)"),
            "shape.curvature_radius`",
            "half the slat depth",
        ),
        (
            format!("{ok}, curvature_radius: Some(-0.02)"),
            "shape.curvature_radius`",
            "half the slat depth",
        ),
        (
            format!("{ok}, thickness: 0.001"),
            "shape.thickness`",
            "only 0",
        ),
        // 600 000 flat slats are 1.2 million triangles.
        (
            with("spacing: 0.04", "count: 600000"),
            "shape`",
            "more than the 1000000",
        ),
    ];
    assert_eq!(
        MAX_BLINDS_TRIANGLES, 1_000_000,
        "the messages checked quote it"
    );
    for (f, field, words) in cases {
        let msg = error_of(&f);
        for part in ["blinds-test.ron", "objects[0] \"blinds\"", field, words] {
            assert!(
                msg.contains(part),
                "{part:?} missing from the message for ({f}): {msg}"
            );
        }
    }
}

/// The same blinds hung twice through `Instances`: the second copy, 3 m along +y, stops a ray
/// falling onto its slats.
#[test]
fn blinds_can_be_instanced() {
    let text = blinds_scene(&fields(30.0)).replace(
        &format!("Blinds({})", fields(30.0)),
        &format!(
            "Instances(mesh: Blinds({}), transforms: [(translate: (0, 0, 0)), (translate: (0, 3, 0))])",
            fields(30.0)
        ),
    );
    assert!(text.contains("Instances"));
    let w = common::world(&text);
    let hit = w
        .geometry
        .intersect(Vec3::new(0.01, 4.0, 2.0), Vec3::NEG_Z, f32::INFINITY)
        .expect("the second copy's top slat is hit");
    // The top slat (n = 25) pivots at z = 0.98 and rises 0.01·tan 30° at x = 0.01.
    let z = 0.98 + 0.01 * 30f64.to_radians().tan();
    assert!((hit.p.z as f64 - z).abs() < 1e-5, "hit at {}", hit.p);
}
