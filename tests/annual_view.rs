//! Annual glare of a view, hour by hour against direct renders and closed forms:
//! - an hour's fisheye image rebuilt from the view's sky and sun coefficients has the vertical
//!   illuminance of a direct render of that hour's Perez sky and sun within their combined
//!   error, and the same DGP to 0.01 (the precision evalglare prints), in a glazed side-lit room
//!   (an overcast hour, a high sun whose patch lies on the floor in view, a low sun from the
//!   side);
//! - the sun's disk seen through the pane adds E_n cos θ T(θ) to E_v, θ its angle from the line
//!   of sight and T the thin slab's Fresnel transmittance at its incidence on the pane.

mod common;
use candela::annual::view::{view_camera, view_coefficients, ViewSettings};
use candela::annual::year::HourSky;
use candela::daylight::patches::{SkyPatches, SkyVector};
use candela::daylight::perez::DEFAULT_DEW_POINT_C;
use common::{cli, world};
use glam::Vec3;

const ROOM: &str = concat!(
    r#"materials: {"grey": Diffuse(reflectance: Constant(0.5)), "pane": ThinDielectric(ior: Constant(1.5))},
    objects: ["#,
    crate::side_lit_room_walls!(),
    r#"(material: "pane", shape: Quad(origin: (-1, 0.9, 2), edge_u: (0, 1.2, 0), edge_v: (2, 0, 0)))]"#
);
use common::SIDE_LIT_PORTAL as PORTAL;

/// An eye 2.5 m from the window, facing it, through a 180° fisheye of 32 × 32 pixels.
const EYE: [f32; 3] = [0.0, 1.2, -0.5];
const CAMERA: &str = "camera: (position: (0, 1.2, -0.5), look_at: (0, 1.2, 2), \
     projection: Fisheye(mapping: Equidistant, fov_deg: 180.0), resolution: (32, 32))";

fn hour_sky(patches: &SkyPatches, dn: f64, dh: f64, alt: f64, az: f64) -> HourSky {
    let enu = common::to_sun(alt, az).0;
    HourSky {
        month: 6,
        day: 21,
        hour: 12,
        sun_altitude_deg: alt,
        to_sun_enu: enu,
        sky: SkyVector::perez(patches, dh, dn, enu, 1.0, DEFAULT_DEW_POINT_C, 0.2).unwrap(),
    }
}

fn mean_se(v: &[f64]) -> (f64, f64) {
    let k = v.len() as f64;
    let m = v.iter().sum::<f64>() / k;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (k - 1.0);
    (m, (var / k).sqrt())
}

#[test]
fn an_hour_of_the_view_from_coefficients_equals_its_direct_render() {
    let patches = SkyPatches::new(4).unwrap();
    let sky_world = world(&format!(
        "({CAMERA}, {ROOM}, lights: [Sky(model: Uniform, amount: ZenithLuminance(1.0), \
         ground_reflectance: 1.0, {PORTAL})])"
    ));
    let settings = ViewSettings {
        resolution: 32,
        sky_samples: 1024,
        sun_samples: 256,
    };
    let camera = view_camera(&sky_world.camera, 32);
    let mut vm = view_coefficients(&sky_world, &camera, &patches, &settings).unwrap();
    // (direct-normal W/m², diffuse-horizontal W/m², sun altitude °, azimuth °); the last one
    // low and nearly due south: its disk is seen through the pane.
    let hours = [
        (0.0, 180.0, 30.0, 170.0),
        (650.0, 110.0, 55.0, 190.0),
        (300.0, 70.0, 12.0, 235.0),
        (500.0, 60.0, 10.0, 185.0),
    ];
    let dirs: Vec<[f64; 3]> = hours.iter().map(|h| common::to_sun(h.2, h.3).0).collect();
    let sw = world(&format!(
        "({CAMERA}, {ROOM}, lights: [Sun(sun: (altitude_deg: 45.0, azimuth_deg: 180.0), \
         amount: NormalIlluminance(1.0))])"
    ));
    let lights = sw.lights.clone();
    let mut sun_world = sw.relit(lights);
    vm.add_sun(
        &mut sun_world,
        &camera,
        &common::default_site(),
        &dirs,
        45.0,
        &settings,
        &mut |_, _| {},
    );

    let dir = std::env::temp_dir().join(format!("candela-annual-view-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let options = candela::glare::GlareOptions::default();
    for (h, &(dn, dh, alt, az)) in hours.iter().enumerate() {
        let hs = hour_sky(&patches, dn, dh, alt, az);
        let sunny = (dn > 0.0).then_some(h);
        let (lum, ev, disk_ev) = vm.hour_image(&hs, sunny);
        let (ev_m, ev_se) = mean_se(&ev);
        let dgp_m = candela::glare::indices::evaluate_luminance(&vm.image, &lum, &options).dgp;
        if h == 3 {
            // The disk alone: E_n cos θ T(θ).
            let s = common::to_sun(alt, az).1;
            let view = (Vec3::new(0.0, 1.2, 2.0) - Vec3::from(EYE)).normalize();
            let expected = hs.sky.direct_normal_lx
                * s.dot(view) as f64
                * common::thin_slab_transmittance(s.z as f64, 1.5);
            println!("sun in view: disk E_v {disk_ev:.3} lx, closed form {expected:.3} lx");
            assert!(
                (disk_ev / expected - 1.0).abs() < 2e-3,
                "{disk_ev} vs {expected}"
            );
            continue;
        }
        let sun = format!(", sun: (altitude_deg: {alt}, azimuth_deg: {az})");
        let scene = dir.join(format!("h{h}.ron"));
        std::fs::write(
            &scene,
            format!(
                "({CAMERA}, {ROOM}, lights: [Sky(model: PerezIrradiance(direct_normal_w_m2: {dn}, \
                 diffuse_horizontal_w_m2: {dh}){sun}, ground_reflectance: 0.2, {PORTAL})], \
                 render: (spp: 1024, seed: {}))",
                11 + h
            ),
        )
        .unwrap();
        let out = dir.join(format!("h{h}"));
        let (code, o, e) = cli(
            &[
                "render",
                scene.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
                "--quiet",
            ],
            &dir,
        );
        assert_eq!(code, 0, "{o}\n{e}");
        let exr = format!("{}.exr", out.display());
        let (code, o, e) = cli(&["glare", &exr, "--json"], &dir);
        assert_eq!(code, 0, "{o}\n{e}");
        let g: serde_json::Value = serde_json::from_str(&o).unwrap();
        let r_ev = g["ev_lx"]["value"].as_f64().unwrap();
        let ci = g["ev_lx"]["ci95"].as_array().unwrap();
        let r_se = (ci[1].as_f64().unwrap() - ci[0].as_f64().unwrap()) / (2.0 * 1.96);
        let r_dgp = g["dgp"]["value"].as_f64().unwrap();
        let z = (ev_m - r_ev) / (ev_se * ev_se + r_se * r_se).sqrt();
        println!(
            "hour {h} ({dn}, {dh}, sun {alt}° {az}°): E_v {ev_m:.2} ± {ev_se:.2} lx from coefficients, \
             {r_ev:.2} ± {r_se:.2} lx rendered ({:+.3} %, {z:+.2} σ); DGP {dgp_m:.4} against {r_dgp:.4}",
            100.0 * (ev_m / r_ev - 1.0)
        );
        assert!(ev_se / ev_m < 0.01 && r_se / r_ev < 0.01, "too noisy");
        assert!(z.abs() < 4.0, "hour {h}: E_v {z:+.2} σ");
        assert!(
            (dgp_m - r_dgp).abs() < 0.01,
            "hour {h}: DGP {dgp_m} vs {r_dgp}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
