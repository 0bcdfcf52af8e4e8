//! Building models: OBJ files with MTL materials (one world object per material, overrides by
//! name) and image textures of diffuse reflectance, checked against closed forms and against
//! the RON Cornell box; bad models and textures end with a clear error.

mod common;
use candela::colour::tables::{cmfs, named_spectrum, Observer};
use candela::texture::Texture;
use std::path::Path;

/// The Cornell box scene file with a small film.
fn cornell_text() -> String {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box.ron"),
    )
    .unwrap();
    let small = text
        .replace("resolution: (256, 256)", "resolution: (48, 48)")
        .replace("spp: 64", "spp: 128");
    assert_ne!(small, text);
    small
}

/// The Cornell box's triangle objects as OBJ groups (`usemtl` per wall colour, the blocks a
/// fourth material) with an MTL of plausible colours, and the scene text that uses them with
/// the RON materials given by name through `materials_from_file`.
fn cornell_obj(dir: &Path) -> String {
    let text = cornell_text();
    let scene = candela::scene::parse(&text, Path::new("cornell.ron")).unwrap();
    let mut obj = String::from("mtllib cornell.mtl\n");
    let mut base = 1;
    for o in &scene.objects {
        let candela::description::schema::ShapeDesc::Triangles {
            positions, indices, ..
        } = &o.shape
        else {
            continue;
        };
        let name = o.name.as_deref().unwrap();
        let mtl = match o.material.as_str() {
            _ if name.contains("block") => "Block",
            "white" => "Wall_White",
            "red" => "Wall_Red",
            "green" => "Wall_Green",
            m => panic!("unexpected material {m}"),
        };
        obj += &format!("o {}\nusemtl {mtl}\n", name.replace(' ', "_"));
        for p in positions {
            obj += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
        for t in indices {
            obj += &format!("f {} {} {}\n", t[0] + base, t[1] + base, t[2] + base);
        }
        base += positions.len() as u32;
    }
    std::fs::write(dir.join("cornell.obj"), obj).unwrap();
    std::fs::write(
        dir.join("cornell.mtl"),
        "newmtl Wall_White\nKd 0.73 0.73 0.73\nnewmtl Wall_Red\nKd 0.63 0.065 0.05\n\
         newmtl Wall_Green\nKd 0.14 0.45 0.091\nnewmtl Block\nKd 0.73 0.73 0.73\nKs 0.1 0.1 0.1\nNs 30\n",
    )
    .unwrap();
    // Replace the triangle objects (everything before the light) by the model.
    let start = text.find("objects: [").unwrap() + "objects: [".len();
    let end = text.find("// The light:").unwrap();
    format!(
        "{}\n        (name: \"box\", shape: Model(file: \"cornell.obj\", materials_from_file: {{\n            \"Wall_White\": Named(\"white\"), \"Wall_Red\": Named(\"red\"), \"Wall_Green\": Named(\"green\"),\n            \"Block\": Material(Diffuse(reflectance: Named(\"cornell-white\"))),\n        }})),\n        {}",
        &text[..start],
        &text[end..]
    )
}

/// The Cornell box built from OBJ + MTL with the RON spectra given by name renders the same
/// image as the RON scene: every 6×6-pixel block agrees within 4.5 combined standard errors
/// (64 blocks: a false alarm has probability 4·10⁻⁴), and so does the image mean.
#[test]
fn cornell_box_from_obj_renders_as_the_ron_scene() {
    let dir = tempfile::tempdir().unwrap();
    let obj_text = cornell_obj(dir.path()).replace("seed: 0", "seed: 7");
    let ron = common::world_in(&cornell_text(), dir.path());
    let obj = common::world_in(&obj_text, dir.path());
    // Four MTL materials, each its own object (the light is one more object).
    assert_eq!(obj.objects.len(), 5);
    let (a, b) = (common::render(&ron, 1), common::render(&obj, 1));
    let worst = common::assert_blocks_agree(&a, &b, 6, ("RON", "OBJ"));
    let ((ya, sa), (yb, sb)) = (common::image_mean(&a), common::image_mean(&b));
    let z = (ya[1] - yb[1]) / (sa.powi(2) + sb.powi(2)).sqrt();
    eprintln!(
        "Cornell OBJ vs RON: image mean Y {:.3} vs {:.3} cd/m² (z = {z:.2}), worst block |z| = {worst:.2}",
        ya[1], yb[1]
    );
    assert!(z.abs() < 4.0 && sa < 0.01 * ya[1]);
}

/// Without overrides each MTL material is mapped by the documented rule: `Kd` alone a
/// Lambertian of the upsampled `Kd`, `Kd` with `Ks` a Phong.
#[test]
fn mtl_materials_map_by_rule() {
    let dir = tempfile::tempdir().unwrap();
    cornell_obj(dir.path());
    let text = cornell_text();
    let start = text.find("objects: [").unwrap() + "objects: [".len();
    let end = text.find("// The light:").unwrap();
    let text = format!(
        "{}(shape: Model(file: \"cornell.obj\")),\n{}",
        &text[..start],
        &text[end..]
    );
    let w = common::world_in(&text, dir.path());
    // The scene's own materials come first: search the model's, from the end.
    let red = w
        .materials
        .iter()
        .rev()
        .filter_map(|m| match m {
            candela::bxdf::Material::Diffuse(d) => Some(d),
            _ => None,
        })
        .find(|d| d.reflectance.value(650.0) > 2.0 * d.reflectance.value(450.0))
        .expect("the red wall is a Lambertian");
    let (fit, _) = candela::spectrum::rgb_upsample::fit_linear_srgb([0.63, 0.065, 0.05]).unwrap();
    for nm in [400.0, 500.0, 600.0, 700.0] {
        assert!((red.reflectance.value(nm) as f64 - fit.value(nm as f64)).abs() < 1e-6);
    }
    let phong = w
        .materials
        .iter()
        .filter(|m| matches!(m, candela::bxdf::Material::Phong(_)))
        .count();
    assert_eq!(phong, 1, "the block (Kd, Ks 0.1, Ns 30) is the one Phong");
}

/// Writes an sRGB PNG of `w`×`h` 8-bit texels (top row first).
fn png(path: &Path, w: u32, h: u32, texels: &[[u8; 3]]) {
    let raw: Vec<u8> = texels.iter().flatten().copied().collect();
    image::RgbImage::from_raw(w, h, raw)
        .unwrap()
        .save(path)
        .unwrap();
}

/// Luminous reflectance of a texel under D65: ∫ρ S ȳ / ∫S ȳ at 1 nm.
fn luminous_reflectance(t: &Texture, x: u32, y: u32) -> f64 {
    let (s, c) = (named_spectrum("D65").unwrap(), cmfs(Observer::Cie1931_2));
    let (mut num, mut den) = (0.0, 0.0);
    for nm in 360..=830 {
        let w = s.value(nm as f64) * c.at(nm as f64)[1];
        num += t.texel_reflectance(x, y, nm as f64) * w;
        den += w;
    }
    num / den
}

/// A plane facing a camera straight above it (so pixels cover equal areas of it), seen across
/// exactly four periods of its texture, lit by a D65 distant light of illuminance E.
fn plane_scene(reflectance: &str, spp: u32) -> String {
    format!(
        r#"(
    camera: (position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 90, resolution: (32, 32)),
    render: (spp: {spp}, max_depth: 1),
    materials: {{ "floor": Diffuse(reflectance: {reflectance}) }},
    objects: [(shape: Quad(origin: (-2, 0, -2), edge_u: (0, 0, 4), edge_v: (4, 0, 0)), material: "floor")],
    lights: [Distant(direction: (0, -1, 0), spectrum: Named("D65"), amount: Illuminance(1000.0))],
)"#
    )
}

/// A textured Lambertian under illuminance E: mean luminance E·ρ̄/π, ρ̄ the texels' mean
/// luminous reflectance (bilinear filtering keeps the mean over whole periods), for an sRGB
/// PNG and a linear OpenEXR texture.
#[test]
fn textured_plane_mean_luminance_is_e_rho_over_pi() {
    let dir = tempfile::tempdir().unwrap();
    let mut texels = Vec::new();
    let mut state = 12345u32;
    for _ in 0..16 {
        let mut c = [0u8; 3];
        for v in &mut c {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            *v = (state >> 24) as u8;
        }
        texels.push(c);
    }
    png(&dir.path().join("t.png"), 4, 4, &texels);
    let mut layers = candela::output::Layers::new(4, 3);
    for (k, name) in ["B", "G", "R"].iter().enumerate() {
        let ch = (0..12)
            .map(|i| ((i * 7 + k * 5) % 11) as f32 / 10.0)
            .collect();
        layers.channels.push((name.to_string(), ch));
    }
    candela::output::write_exr(&dir.path().join("t.exr"), &layers).unwrap();
    for file in ["t.png", "t.exr"] {
        let tex = Texture::load(&dir.path().join(file)).unwrap();
        let n = (tex.width() * tex.height()) as f64;
        let mut rho = 0.0;
        for y in 0..tex.height() {
            for x in 0..tex.width() {
                rho += luminous_reflectance(&tex, x, y) / n;
            }
        }
        let expected = 1000.0 * rho / std::f64::consts::PI;
        // uv runs 0..1 across the 4 m quad; the camera sees its middle 2 m: 4 periods.
        let r = format!("Texture(file: \"{file}\", uv_scale: (8, 8))");
        let w = common::world_in(&plane_scene(&r, 64), dir.path());
        let film = common::render(&w, 1);
        let (m, se) = common::image_mean(&film);
        eprintln!(
            "{file}: mean Y {:.4} ± {se:.4}, E·ρ̄/π = {expected:.4} cd/m²",
            m[1]
        );
        common::assert_estimate_near(m[1], se, expected, 0.01, file);
    }
}

/// CIE L*a*b* of XYZ with white `wt`.
fn lab(xyz: [f64; 3], wt: [f64; 3]) -> [f64; 3] {
    let f = |t: f64| {
        if t > (6.0f64 / 29.0).powi(3) {
            t.cbrt()
        } else {
            t / (3.0 * (6.0f64 / 29.0).powi(2)) + 4.0 / 29.0
        }
    };
    let (fx, fy, fz) = (f(xyz[0] / wt[0]), f(xyz[1] / wt[1]), f(xyz[2] / wt[2]));
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// CIEDE2000 colour difference (Sharma, Wu & Dalal 2005).
fn delta_e_2000(a: [f64; 3], b: [f64; 3]) -> f64 {
    let (l1, a1, b1) = (a[0], a[1], a[2]);
    let (l2, a2, b2) = (b[0], b[1], b[2]);
    let p7 = |c: f64| c.powi(7) / (c.powi(7) + 25f64.powi(7));
    let cbar = (a1.hypot(b1) + a2.hypot(b2)) / 2.0;
    let g = 0.5 * (1.0 - p7(cbar).sqrt());
    let (a1p, a2p) = ((1.0 + g) * a1, (1.0 + g) * a2);
    let (c1, c2) = (a1p.hypot(b1), a2p.hypot(b2));
    let hue = |b: f64, a: f64| {
        if a == 0.0 && b == 0.0 {
            0.0
        } else {
            b.atan2(a).to_degrees().rem_euclid(360.0)
        }
    };
    let (h1, h2) = (hue(b1, a1p), hue(b2, a2p));
    let dl = l2 - l1;
    let dc = c2 - c1;
    let dh = if c1 * c2 == 0.0 {
        0.0
    } else if (h2 - h1).abs() <= 180.0 {
        h2 - h1
    } else if h2 - h1 > 180.0 {
        h2 - h1 - 360.0
    } else {
        h2 - h1 + 360.0
    };
    let dhh = 2.0 * (c1 * c2).sqrt() * (dh.to_radians() / 2.0).sin();
    let lbar = (l1 + l2) / 2.0;
    let cbarp = (c1 + c2) / 2.0;
    let hbar = if c1 * c2 == 0.0 {
        h1 + h2
    } else if (h1 - h2).abs() <= 180.0 {
        (h1 + h2) / 2.0
    } else if h1 + h2 < 360.0 {
        (h1 + h2 + 360.0) / 2.0
    } else {
        (h1 + h2 - 360.0) / 2.0
    };
    let cosd = |d: f64| d.to_radians().cos();
    let t =
        1.0 - 0.17 * cosd(hbar - 30.0) + 0.24 * cosd(2.0 * hbar) + 0.32 * cosd(3.0 * hbar + 6.0)
            - 0.20 * cosd(4.0 * hbar - 63.0);
    let dtheta = 30.0 * (-((hbar - 275.0) / 25.0).powi(2)).exp();
    let rc = 2.0 * p7(cbarp).sqrt();
    let sl = 1.0 + 0.015 * (lbar - 50.0).powi(2) / (20.0 + (lbar - 50.0).powi(2)).sqrt();
    let sc = 1.0 + 0.045 * cbarp;
    let sh = 1.0 + 0.015 * cbarp * t;
    let rt = -(2.0 * dtheta).to_radians().sin() * rc;
    ((dl / sl).powi(2) + (dc / sc).powi(2) + (dhh / sh).powi(2) + rt * (dc / sc) * (dhh / sh))
        .sqrt()
}

/// An sRGB texel of a ColorChecker patch, rendered under D65, has the patch's sRGB colour:
/// the image's CIELAB (white: a perfect diffuser under the same light, E/π times D65's
/// chromaticity) is within ΔE00 < 1 of the sRGB value's.
#[test]
fn colorchecker_texels_render_their_srgb_colour() {
    // CIEDE2000 against Sharma et al.'s test data (pairs 1, 7 and 17).
    for (a, b, want) in [
        ([50.0, 2.6772, -79.7751], [50.0, 0.0, -82.7485], 2.0425),
        ([50.0, 0.0, 0.0], [50.0, -1.0, 2.0], 2.3669),
        ([50.0, 2.5, 0.0], [73.0, 25.0, -18.0], 27.1492),
    ] {
        assert!((delta_e_2000(a, b) - want).abs() < 1e-4, "{a:?} {b:?}");
    }
    let c = cmfs(Observer::Cie1931_2);
    let d65 = named_spectrum("D65").unwrap();
    let mut white = [0.0; 3];
    for nm in 360..=830 {
        let x = c.at(nm as f64);
        for k in 0..3 {
            white[k] += d65.value(nm as f64) * x[k];
        }
    }
    let white = white.map(|v| v / (white[1]) * 1000.0 / std::f64::consts::PI);
    let dir = tempfile::tempdir().unwrap();
    // Dark skin, light skin, blue sky, foliage, orange, purplish blue (sRGB, 8 bit).
    let patches: [[u8; 3]; 6] = [
        [115, 82, 68],
        [194, 150, 130],
        [98, 122, 157],
        [87, 108, 67],
        [214, 126, 44],
        [80, 91, 166],
    ];
    for p in patches {
        png(&dir.path().join("patch.png"), 1, 1, &[p]);
        let w = common::world_in(&plane_scene("Texture(file: \"patch.png\")", 16), dir.path());
        let (xyz, _) = common::image_mean(&common::render(&w, 1));
        let lin = p.map(|v| candela::colour::rgb::srgb_decode(v as f64 / 255.0));
        let m = [
            [0.4124, 0.3576, 0.1805],
            [0.2126, 0.7152, 0.0722],
            [0.0193, 0.1192, 0.9505],
        ];
        let want: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| m[i][j] * lin[j]).sum::<f64>());
        let d = delta_e_2000(lab(xyz, white), lab(want, [0.950_47, 1.0, 1.088_83]));
        eprintln!("sRGB {p:?}: ΔE00 = {d:.3}");
        assert!(d < 1.0, "sRGB {p:?}: ΔE00 = {d}");
    }
}

/// `candela render` of `scene` in `dir`: (exit code, stderr).
fn render_cli(dir: &Path, scene: &str) -> (i32, String) {
    std::fs::write(dir.join("scene.ron"), scene).unwrap();
    let (code, _, stderr) = common::cli(&["render", "--quiet", "--out", "out", "scene.ron"], dir);
    assert!(!stderr.contains("panicked"), "{stderr}");
    (code, stderr)
}

/// A scene of one `Model` object.
fn model_scene(extra: &str) -> String {
    format!(
        r#"(
    camera: (position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), vfov_deg: 90, resolution: (4, 4)),
    render: (spp: 1),
    objects: [(name: "room", shape: Model(file: "m.obj"{extra}))],
    lights: [Distant(direction: (0, -1, 0), spectrum: Named("D65"), amount: Illuminance(1000.0))],
)"#
    )
}

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\n";

/// A bad-input case: what it is, how to write its files, what the message must contain.
type Case<'a> = (&'a str, Box<dyn Fn() + 'a>, Vec<&'a str>);

/// Bad models and textures: each ends with exit code 1 and a message naming the file and the
/// line or field at fault, without a panic or an allocation of the size a header claims.
#[test]
fn bad_models_and_textures_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let write = |name: &str, text: &[u8]| std::fs::write(d.join(name), text).unwrap();
    let obj = |mtllib: &str| format!("mtllib {mtllib}\n{TRIANGLE}usemtl Floor\nf 1/1 2/2 3/3\n");
    let cases: Vec<Case> = vec![
        (
            "missing MTL",
            Box::new(|| write("m.obj", obj("nowhere.mtl").as_bytes())),
            vec!["nowhere.mtl", "m.obj"],
        ),
        (
            "/dev/zero as MTL",
            Box::new(|| write("m.obj", obj("/dev/zero").as_bytes())),
            vec!["/dev/zero", "m.obj", "outside the model's folder"],
        ),
        (
            "malformed MTL statement",
            Box::new(|| {
                write("m.obj", obj("m.mtl").as_bytes());
                write("m.mtl", b"newmtl Floor\n\nKd 0.5 x 0.5\n");
            }),
            vec!["m.mtl", "line 3", "`Kd` expects numbers"],
        ),
        (
            "usemtl naming no material",
            Box::new(|| {
                write("m.obj", obj("m.mtl").as_bytes());
                write("m.mtl", b"newmtl Wall\nKd 0.5 0.5 0.5\n");
            }),
            vec!["m.obj", "line 8", "usemtl Floor", "Wall"],
        ),
        (
            "missing texture",
            Box::new(|| {
                write("m.obj", obj("m.mtl").as_bytes());
                write("m.mtl", b"newmtl Floor\nmap_Kd floor.png\n");
            }),
            vec!["floor.png", "m.mtl", "line 1", "map_Kd"],
        ),
        (
            "huge texture header",
            Box::new(|| {
                write("m.obj", obj("m.mtl").as_bytes());
                write("m.mtl", b"newmtl Floor\nmap_Kd floor.png\n");
                write("floor.png", &png_header(1 << 20, 1 << 20));
            }),
            vec!["floor.png", "1048576×1048576", "texels"],
        ),
    ];
    for (what, setup, needles) in cases {
        setup();
        let (code, stderr) = render_cli(d, &model_scene(""));
        assert_eq!(code, 1, "{what}: exit code {code}\n{stderr}");
        for n in needles {
            assert!(stderr.contains(n), "{what}: message lacks {n:?}:\n{stderr}");
        }
    }
    // An override naming no material of the file names the field.
    write("m.obj", obj("m.mtl").as_bytes());
    write("m.mtl", b"newmtl Floor\nKd 0.5 0.5 0.5\n");
    let (code, stderr) = render_cli(
        d,
        &model_scene(", materials_from_file: { \"Flor\": Material(Black) }"),
    );
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("materials_from_file[\"Flor\"]") && stderr.contains("Floor"),
        "{stderr}"
    );
    // A texture given in the scene that does not exist.
    let scene = plane_scene("Texture(file: \"nothing.png\")", 1);
    let (code, stderr) = render_cli(d, &scene);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("nothing.png") && stderr.contains("materials[\"floor\"].reflectance"),
        "{stderr}"
    );
    // And the good model renders.
    let (code, stderr) = render_cli(d, &model_scene(""));
    assert_eq!(code, 0, "{stderr}");
}

/// A PNG signature and IHDR chunk claiming `w`×`h` 8-bit RGB pixels, and no image data.
fn png_header(w: u32, h: u32) -> Vec<u8> {
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in bytes {
            c ^= b as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend(w.to_be_bytes());
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 2, 0, 0, 0]);
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    out.extend(13u32.to_be_bytes());
    out.extend(&ihdr);
    out.extend(crc32(&ihdr).to_be_bytes());
    // An empty IDAT: decoders read the header up to the first data chunk.
    out.extend(0u32.to_be_bytes());
    out.extend(b"IDAT");
    out.extend(crc32(b"IDAT").to_be_bytes());
    out.extend(0u32.to_be_bytes());
    out.extend(b"IEND");
    out.extend(crc32(b"IEND").to_be_bytes());
    out
}
