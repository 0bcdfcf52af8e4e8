//! `candela bench`: throughput on the Cornell box and on a generated mesh of about a million
//! triangles. Prints samples/s and rays/s; nothing here is asserted by tests.

use crate::render::render;
use crate::scene::{self, schema::*, Overrides};
use std::path::Path;
use std::time::Instant;

const CORNELL: &str = include_str!("../scenes/cornell-box.ron");

fn report(name: &str, r: &crate::render::RenderResult) {
    println!(
        "{name:<28} {:>4}×{:<4} {:>4} spp  {:>7.2} s  {:>8.3} M samples/s  {:>8.3} M rays/s  ({} threads)",
        r.film.width,
        r.film.height,
        r.film.total_samples() / (r.film.width * r.film.height) as u64,
        r.elapsed.as_secs_f64(),
        r.samples_per_second() / 1e6,
        r.rays_per_second() / 1e6,
        r.threads
    );
}

pub fn run(threads: Option<usize>, spp: u32, triangles: usize) -> anyhow::Result<()> {
    let overrides = Overrides {
        spp: Some(spp),
        ..Default::default()
    };
    let path = Path::new("scenes/cornell-box.ron");
    let world = scene::build(&scene::parse(CORNELL, path)?, path, &overrides)?;
    let r = render(&world, threads, &|_, _| {})?;
    report("cornell-box", &r);

    // A displaced sphere of ~`triangles` triangles on a floor, under a sky and a sun.
    let t0 = Instant::now();
    let subdivisions = ((triangles as f64 / 12.0).sqrt().ceil() as u32).max(1);
    let mesh = crate::geometry::generate::bumpy_sphere(subdivisions);
    let n_tris = mesh.indices.len();
    let scene = SceneFile {
        camera: CameraDesc {
            position: [0.0, 1.2, -3.2],
            look_at: [0.0, 0.9, 0.0],
            up: [0.0, 1.0, 0.0],
            vfov_deg: 45.0,
            resolution: (256, 256),
            lens: None,
        },
        render: RenderDesc {
            spp,
            ..Default::default()
        },
        materials: [(
            "grey".to_string(),
            MaterialDesc::Diffuse {
                reflectance: SpectrumDesc::Constant(0.6),
            },
        )]
        .into_iter()
        .collect(),
        objects: vec![
            ObjectDesc {
                name: Some("mesh".into()),
                shape: ShapeDesc::Triangles {
                    positions: mesh.positions.iter().map(|p| p.to_array()).collect(),
                    indices: mesh.indices.clone(),
                    normals: None,
                },
                material: "grey".into(),
                emission: None,
                transform: Some(TransformDesc {
                    translate: Some([0.0, 1.0, 0.0]),
                    rotate_deg: None,
                    scale: None,
                }),
            },
            ObjectDesc {
                name: Some("floor".into()),
                shape: ShapeDesc::Quad {
                    origin: [-10.0, 0.0, -10.0],
                    edge_u: [0.0, 0.0, 20.0],
                    edge_v: [20.0, 0.0, 0.0],
                },
                material: "grey".into(),
                emission: None,
                transform: None,
            },
        ],
        lights: vec![
            LightDesc::Environment {
                spectrum: SpectrumDesc::Named("D65".into()),
                amount: Amount::Luminance(5000.0),
            },
            LightDesc::Distant {
                direction: [0.3, -1.0, 0.5],
                spectrum: SpectrumDesc::Named("D50".into()),
                amount: Amount::Illuminance(50_000.0),
            },
        ],
        meters: Vec::new(),
        grids: Vec::new(),
        measure: MeasureDesc::default(),
    };
    drop(mesh);
    let world = scene::build(&scene, Path::new("<generated>"), &overrides)?;
    println!(
        "generated mesh: {n_tris} triangles, scene built (incl. BVH) in {:.2} s, geometry ≈ {:.1} bytes/triangle",
        t0.elapsed().as_secs_f64(),
        world.geometry.memory_bytes() as f64 / n_tris as f64
    );
    let r = render(&world, threads, &|_, _| {})?;
    report(&format!("mesh {}k triangles", n_tris / 1000), &r);
    Ok(())
}
