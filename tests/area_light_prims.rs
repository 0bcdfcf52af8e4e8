//! An area light samples its flat primitives (quads; triangles unless textured) from data it
//! copies at build, and evaluates the density of a hit on them the same way: the points,
//! directions, radiances and densities equal, bit for bit, those of the scene's general
//! primitive sampling ([`SceneGeometry::sample_prim_solid_angle_with`],
//! [`SceneGeometry::pdf_prim_solid_angle`]), which the other primitives (and textured
//! triangles) still use.

mod common;

use candela::geometry::SceneGeometry;
use candela::light::{AreaLight, Light};
use candela::scene::{self, Overrides};
use candela::spectrum::SampledWavelengths;
use glam::{Vec2, Vec3};
use std::path::PathBuf;

fn next(s: &mut u64) -> f32 {
    *s = s
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*s >> 40) as f32) / (1u64 << 24) as f32
}

/// Two-colour 4 × 2 texture, for textured emitters.
fn texture_dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("area_light_prims");
    std::fs::create_dir_all(&d).unwrap();
    let mut img = image::RgbImage::new(4, 2);
    for (x, _, p) in img.enumerate_pixels_mut() {
        p.0 = if x < 2 { [250, 120, 60] } else { [20, 60, 200] };
    }
    img.save(d.join("tex.png")).unwrap();
    d
}

fn scene_text() -> String {
    let tri = "Triangles(positions: [(-2, 4, -1), (-1, 4.2, -1), (-2, 3.9, 0.5), (-0.5, 4.1, 0.7)], indices: [(0, 1, 2), (1, 3, 2)])";
    let objects = [
        "Quad(origin: (0.1, 3, 0.2), edge_u: (0.6, 0, 0), edge_v: (0, 0.05, 0.6))".to_string(),
        "Quad(origin: (1.5, 2, -1), edge_u: (0, 0.7, 0), edge_v: (0, 0, 0.4))".to_string(),
        tri.to_string(),
        "Sphere(center: (2, 3, 2), radius: 0.3)".to_string(),
        "Disk(center: (-1, 3, 2), normal: (0, -1, 0.2), radius: 0.4)".to_string(),
        "Quad(origin: (-3, 3.5, -3), edge_u: (1, 0, 0), edge_v: (0, 0, 0.5))".to_string(),
        tri.replace("4", "5"),
    ];
    let emission = [
        "(spectrum: Blackbody(5000), amount: Luminance(2000))",
        "(spectrum: Named(\"E\"), amount: Flux(800), two_sided: true)",
        "(spectrum: Blackbody(3000), amount: Luminance(900))",
        "(spectrum: Blackbody(2700), amount: Flux(2000))",
        "(spectrum: Blackbody(6500), amount: Luminance(700))",
        "(spectrum: Texture(file: \"tex.png\"), amount: Luminance(1500))",
        "(spectrum: Texture(file: \"tex.png\"), amount: Luminance(1200), two_sided: true)",
    ];
    let objects: Vec<String> = objects
        .iter()
        .zip(emission)
        .map(|(s, e)| format!("(shape: {s}, material: \"grey\", emission: {e})"))
        .collect();
    format!(
        "(camera: (position: (0, 1, -8), look_at: (0, 1, 0), vfov_deg: 40, resolution: (1, 1)),
          materials: {{ \"grey\": Diffuse(reflectance: Constant(0.5)) }},
          objects: [(shape: Quad(origin: (-5, 0, -5), edge_u: (0, 0, 10), edge_v: (10, 0, 0)), material: \"grey\"), {}],
          lights: [])",
        objects.join(",\n")
    )
}

/// What `AreaLight::sample_li_prim` gives, from the scene's general sampling.
fn reference(
    a: &AreaLight,
    geom: &SceneGeometry,
    p: Vec3,
    prim: u32,
    u: Vec2,
    wl: &SampledWavelengths,
) -> Option<[u32; 13]> {
    let (sp, pdf) = geom.sample_prim_solid_angle_with(prim, p, u, a.is_textured())?;
    let d = sp.p - p;
    let dist = d.length();
    if dist == 0.0 || pdf.is_nan() || pdf <= 0.0 || !pdf.is_finite() {
        return None;
    }
    let wi = d / dist;
    if sp.n.dot(-wi) <= 0.0 && !a.two_sided {
        return None;
    }
    let li = a.radiance_at(sp.tex, wl);
    Some(bits(wi, pdf, dist, sp.p, sp.n, li.0))
}

fn bits(wi: Vec3, pdf: f32, dist: f32, p: Vec3, n: Vec3, li: [f32; 4]) -> [u32; 13] {
    let v = [
        wi.x, wi.y, wi.z, pdf, dist, p.x, p.y, p.z, n.x, n.y, n.z, li[0], li[3],
    ];
    v.map(f32::to_bits)
}

#[test]
fn flat_primitives_sample_and_evaluate_as_the_scene_does() {
    let dir = texture_dir();
    let path = dir.join("scene.ron");
    let s = scene::parse(&scene_text(), &path).unwrap_or_else(|e| panic!("{e}"));
    let w = scene::build(&s, &path, &Overrides::default()).unwrap_or_else(|e| panic!("{e}"));
    let geom = &w.geometry;
    let wl = SampledWavelengths::sample_visible(0.41);
    let areas: Vec<(usize, &AreaLight)> = w
        .lights
        .iter()
        .enumerate()
        .filter_map(|(i, l)| match l {
            Light::Area(a) => Some((i, a)),
            _ => None,
        })
        .collect();
    assert_eq!(areas.len(), 7);
    let mut s = 5u64;
    let (mut samples, mut hits) = (0, 0);
    for &(li, a) in &areas {
        for &prim in &a.prims {
            for _ in 0..3000 {
                let p = Vec3::new(
                    -4.0 + 8.0 * next(&mut s),
                    0.5 + 5.0 * next(&mut s),
                    -4.0 + 8.0 * next(&mut s),
                );
                let u = Vec2::new(next(&mut s), next(&mut s));
                let got = a.sample_li_prim(geom, p, prim, u, &wl).map(|ls| {
                    let (q, n) = ls.point.expect("an area light's point");
                    bits(ls.wi, ls.pdf, ls.dist, q, n, ls.li.0)
                });
                assert_eq!(
                    got,
                    reference(a, geom, p, prim, u, &wl),
                    "light {li} prim {prim} from {p} u {u}"
                );
                let Some(ls) = a.sample_li_prim(geom, p, prim, u, &wl) else {
                    continue;
                };
                samples += 1;
                // The density of the ray that reaches the light, hit by hit.
                let Some(hit) = geom.intersect(p, ls.wi, f32::INFINITY) else {
                    continue;
                };
                let Some(l) = w.objects[hit.object as usize].light else {
                    continue;
                };
                let Light::Area(h) = &w.lights[l as usize] else {
                    panic!("an emitting object's light is an area light");
                };
                hits += 1;
                let want = geom.pdf_prim_solid_angle(hit.prim, p, &hit);
                let got = w.lights[l as usize].pdf_li_hit_prim(geom, p, &hit);
                assert_eq!(got.to_bits(), want.to_bits(), "hit pdf, light {l}");
                let want = geom.prim_area(hit.prim) / h.total_area * want;
                let got = h.pdf_li_hit(geom, p, &hit);
                assert_eq!(got.to_bits(), want.to_bits(), "hit pdf with the choice");
            }
        }
    }
    assert!(
        samples > 10_000 && hits > 5_000,
        "{samples} samples, {hits} hits"
    );
}
