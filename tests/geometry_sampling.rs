//! Area sampling uniformity and solid-angle pdfs. All tolerances are 5 standard errors
//! computed from the sample variance.

#[path = "../src/cli/bench/rng.rs"]
#[allow(dead_code)]
mod rng;

use candela::geometry::{SceneGeometry, Shape, TriangleMesh};
use glam::{DVec3, Vec3};
use rng::Rng;

const N: usize = 200_000;

struct Stats {
    n: f64,
    sum: f64,
    sum2: f64,
}
impl Stats {
    fn new() -> Self {
        Self {
            n: 0.0,
            sum: 0.0,
            sum2: 0.0,
        }
    }
    fn add(&mut self, x: f64) {
        self.n += 1.0;
        self.sum += x;
        self.sum2 += x * x;
    }
    fn mean(&self) -> f64 {
        self.sum / self.n
    }
    fn se(&self) -> f64 {
        let m = self.mean();
        let var = (self.sum2 / self.n - m * m).max(0.0) * self.n / (self.n - 1.0);
        (var / self.n).sqrt()
    }
    #[track_caller]
    fn check(&self, expected: f64, what: &str) {
        let (m, se) = (self.mean(), self.se());
        let tol = 5.0 * se + 1e-6 * expected.abs() + 1e-12;
        assert!(
            (m - expected).abs() <= tol,
            "{what}: mean {m} vs expected {expected} (5·SE = {})",
            5.0 * se
        );
    }
}

fn one(shape: Shape) -> (SceneGeometry, u32) {
    let g = SceneGeometry::build(&[(shape, 5)]).unwrap();
    let p = g.primitives_of_object(5)[0];
    (g, p)
}

fn tri_area(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    0.5 * (b - a).cross(c - a).length()
}

#[test]
fn area_sampling_triangle_uniform() {
    let (a, b, c) = (
        Vec3::ZERO,
        Vec3::new(3.0, 0.0, 0.0),
        Vec3::new(0.0, 2.0, 1.0),
    );
    let (g, p) = one(Shape::Mesh(TriangleMesh {
        positions: vec![a, b, c],
        normals: None,
        indices: vec![[0, 1, 2]],
    }));
    let area = tri_area(a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
    assert!((g.prim_area(p) as f64 - area).abs() < 1e-6 * area);
    let n_expect = (b - a).cross(c - a).normalize();
    let mut rng = Rng::new(1);
    let (mut mx, mut my, mut mz, mut corner) =
        (Stats::new(), Stats::new(), Stats::new(), Stats::new());
    for _ in 0..N {
        let s = g.sample_prim(p, rng.vec2());
        assert!((s.n - n_expect).length() < 1e-6);
        let q = s.p.as_dvec3();
        mx.add(q.x);
        my.add(q.y);
        mz.add(q.z);
        // Barycentric b0 ≥ 1/2 is the corner sub-triangle at `a` (a quarter of the area).
        let b0 = tri_area(q, b.as_dvec3(), c.as_dvec3()) / area;
        corner.add(if b0 >= 0.5 { 1.0 } else { 0.0 });
        assert!((s.p - a).dot(n_expect).abs() < 1e-5);
    }
    let centroid = (a + b + c) / 3.0;
    mx.check(centroid.x as f64, "triangle mean x");
    my.check(centroid.y as f64, "triangle mean y");
    mz.check(centroid.z as f64, "triangle mean z");
    corner.check(0.25, "triangle corner fraction");
}

#[test]
fn area_sampling_quad_disk_sphere_uniform() {
    let mut rng = Rng::new(2);
    // Quad.
    let (o, eu, ev) = (
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(2.0, 0.0, 1.0),
        Vec3::new(0.0, 1.0, 0.0),
    );
    let (g, p) = one(Shape::Quad {
        origin: o,
        edge_u: eu,
        edge_v: ev,
    });
    assert!((g.prim_area(p) - eu.cross(ev).length()).abs() < 1e-6);
    let (mut mx, mut mz, mut band) = (Stats::new(), Stats::new(), Stats::new());
    for _ in 0..N {
        let s = g.sample_prim(p, rng.vec2());
        assert!((s.n - eu.cross(ev).normalize()).length() < 1e-6);
        mx.add(s.p.x as f64);
        mz.add(s.p.z as f64);
        let su = (s.p - o).dot(eu) / eu.length_squared();
        band.add(if su < 0.3 { 1.0 } else { 0.0 });
    }
    let c = o + 0.5 * eu + 0.5 * ev;
    mx.check(c.x as f64, "quad mean x");
    mz.check(c.z as f64, "quad mean z");
    band.check(0.3, "quad band fraction");

    // Disk.
    let (center, normal, r) = (
        Vec3::new(-1.0, 0.5, 2.0),
        Vec3::new(1.0, 1.0, 0.0).normalize(),
        0.7f32,
    );
    let (g, p) = one(Shape::Disk {
        center,
        normal,
        radius: r,
    });
    assert!((g.prim_area(p) as f64 - std::f64::consts::PI * 0.49).abs() < 1e-6);
    let (mut mx, mut my, mut inner, mut r2) =
        (Stats::new(), Stats::new(), Stats::new(), Stats::new());
    for _ in 0..N {
        let s = g.sample_prim(p, rng.vec2());
        let d = s.p - center;
        assert!(d.dot(normal).abs() < 1e-6 && d.length() <= r * (1.0 + 1e-6));
        mx.add(s.p.x as f64);
        my.add(s.p.y as f64);
        inner.add(if d.length() < 0.5 * r { 1.0 } else { 0.0 });
        r2.add(d.length_squared() as f64);
    }
    mx.check(center.x as f64, "disk mean x");
    my.check(center.y as f64, "disk mean y");
    inner.check(0.25, "disk inner fraction");
    r2.check((r * r / 2.0) as f64, "disk E[r²]");

    // Sphere.
    let (center, r) = (Vec3::new(0.5, -2.0, 1.0), 1.5f32);
    let (g, p) = one(Shape::Sphere { center, radius: r });
    let (mut mx, mut mz, mut cap) = (Stats::new(), Stats::new(), Stats::new());
    for _ in 0..N {
        let s = g.sample_prim(p, rng.vec2());
        let d = s.p - center;
        assert!((d.length() - r).abs() < 1e-5 && (d / r - s.n).length() < 1e-5);
        mx.add(s.p.x as f64);
        mz.add(s.p.z as f64);
        cap.add(if d.z > 0.5 * r { 1.0 } else { 0.0 });
    }
    mx.check(center.x as f64, "sphere mean x");
    mz.check(center.z as f64, "sphere mean z");
    cap.check(0.25, "sphere cap fraction");
}

/// Solid angle of a triangle seen from the origin (Van Oosterom & Strackee 1983).
fn triangle_solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let num = a.dot(b.cross(c)).abs();
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * num.atan2(den)
}

/// E[1/pdf] over samples = subtended solid angle, and the pdf of the traced direction equals
/// the sampled pdf.
fn check_solid_angle(g: &SceneGeometry, prim: u32, reference: Vec3, omega: f64, what: &str) {
    let mut rng = Rng::new(99);
    let mut inv = Stats::new();
    let mut none = 0;
    for k in 0..N {
        match g.sample_prim_solid_angle(prim, reference, rng.vec2()) {
            Some((sp, pdf)) => {
                assert!(pdf > 0.0 && pdf.is_finite());
                inv.add(1.0 / pdf as f64);
                if k % 10 == 0 {
                    // Trace toward the sample: it must be the visible point, with the same pdf.
                    let d = sp.p - reference;
                    let h = g
                        .intersect(reference, d, f32::INFINITY)
                        .expect("sample not visible");
                    assert_eq!(h.prim, prim);
                    assert!(
                        (h.t - 1.0).abs() < 1e-3,
                        "{what}: sample hidden behind t = {}",
                        h.t
                    );
                    let pdf2 = g.pdf_prim_solid_angle(prim, reference, &h);
                    assert!(
                        (pdf2 - pdf).abs() <= 2e-3 * pdf,
                        "{what}: pdf of traced direction {pdf2} vs sampled {pdf}"
                    );
                }
            }
            None => {
                none += 1;
                inv.add(0.0);
            }
        }
    }
    assert!(none < N / 1000, "{what}: {none} samples had no valid pdf");
    inv.check(omega, &format!("{what}: E[1/pdf] vs solid angle"));
}

/// ∫ pdf dω = 1: uniform directions over the sphere, pdf of what they hit.
fn check_pdf_integrates(g: &SceneGeometry, prim: u32, reference: Vec3, what: &str) {
    let mut rng = Rng::new(7);
    let mut s = Stats::new();
    for _ in 0..N {
        let w = rng.unit_vector();
        let v = match g.intersect(reference, w, f32::INFINITY) {
            Some(h) if h.prim == prim => {
                g.pdf_prim_solid_angle(prim, reference, &h) as f64 * 4.0 * std::f64::consts::PI
            }
            _ => 0.0,
        };
        s.add(v);
    }
    s.check(1.0, &format!("{what}: ∫ pdf dω"));
}

#[test]
fn solid_angle_sphere_outside_inside() {
    let (center, r) = (Vec3::new(1.0, 2.0, -1.0), 2.0f32);
    let (g, p) = one(Shape::Sphere { center, radius: r });
    for dist in [5.0f32, 2.2, 2000.0] {
        let reference = center + Vec3::new(0.6, 0.0, 0.8) * dist;
        let sin2 = (r as f64 / dist as f64).powi(2);
        let omega = 2.0 * std::f64::consts::PI * sin2 / (1.0 + (1.0 - sin2).sqrt());
        let what = format!("sphere from distance {dist}");
        check_solid_angle(&g, p, reference, omega, &what);
        if dist < 100.0 {
            check_pdf_integrates(&g, p, reference, &what);
        }
        // Directions are uniform in the cone: E[cos] = (1 + cos θmax) / 2.
        let cos_max = (1.0 - sin2).sqrt();
        let axis = (center - reference).as_dvec3().normalize();
        let mut rng = Rng::new(5);
        let mut c = Stats::new();
        for _ in 0..N {
            let (sp, _) = g.sample_prim_solid_angle(p, reference, rng.vec2()).unwrap();
            c.add((sp.p - reference).as_dvec3().normalize().dot(axis));
        }
        c.check((1.0 + cos_max) / 2.0, &format!("{what}: E[cos θ]"));
    }
    // From inside: area sampling converted; the whole sphere of directions.
    let reference = center + Vec3::new(0.3, -0.5, 0.2);
    check_solid_angle(
        &g,
        p,
        reference,
        4.0 * std::f64::consts::PI,
        "sphere from inside",
    );
    check_pdf_integrates(&g, p, reference, "sphere from inside");
}

#[test]
fn solid_angle_quad_triangle_disk() {
    // Quad (two triangles for the analytic solid angle).
    let (o, eu, ev) = (
        Vec3::new(-1.0, -0.5, 2.0),
        Vec3::new(2.0, 0.0, 0.5),
        Vec3::new(0.0, 1.5, 0.0),
    );
    let (g, p) = one(Shape::Quad {
        origin: o,
        edge_u: eu,
        edge_v: ev,
    });
    for reference in [Vec3::new(0.2, 0.1, 0.0), Vec3::new(3.0, 1.0, 4.0)] {
        let r = reference.as_dvec3();
        let (a, b, c, d) = (
            o.as_dvec3() - r,
            (o + eu).as_dvec3() - r,
            (o + eu + ev).as_dvec3() - r,
            (o + ev).as_dvec3() - r,
        );
        let omega = triangle_solid_angle(a, b, c) + triangle_solid_angle(a, c, d);
        check_solid_angle(&g, p, reference, omega, "quad");
        check_pdf_integrates(&g, p, reference, "quad");
    }
    // Triangle.
    let (a, b, c) = (
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, 1.5),
        Vec3::new(0.0, 1.0, 0.8),
    );
    let (g, p) = one(Shape::Mesh(TriangleMesh {
        positions: vec![a, b, c],
        normals: None,
        indices: vec![[0, 1, 2]],
    }));
    let reference = Vec3::new(0.1, 0.2, -0.3);
    let r = reference.as_dvec3();
    let omega = triangle_solid_angle(a.as_dvec3() - r, b.as_dvec3() - r, c.as_dvec3() - r);
    check_solid_angle(&g, p, reference, omega, "triangle");
    check_pdf_integrates(&g, p, reference, "triangle");
    // Disk on its axis: Ω = 2π (1 − h / √(h² + R²)).
    let (center, normal, radius) = (Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, -1.0, 0.0), 0.8f32);
    let (g, p) = one(Shape::Disk {
        center,
        normal,
        radius,
    });
    let h = 1.5f64;
    let reference = center + Vec3::new(0.0, -1.5, 0.0);
    let omega = 2.0 * std::f64::consts::PI * (1.0 - h / (h * h + 0.64).sqrt());
    check_solid_angle(&g, p, reference, omega, "disk");
    check_pdf_integrates(&g, p, reference, "disk");
}

#[test]
fn solid_angle_degenerate_cases() {
    // Reference in the plane of a quad: every sample is edge-on → None, never NaN.
    let (g, p) = one(Shape::Quad {
        origin: Vec3::ZERO,
        edge_u: Vec3::X,
        edge_v: Vec3::Y,
    });
    let mut rng = Rng::new(3);
    for _ in 0..1000 {
        assert!(g
            .sample_prim_solid_angle(p, Vec3::new(2.0, 0.5, 0.0), rng.vec2())
            .is_none());
    }
}
