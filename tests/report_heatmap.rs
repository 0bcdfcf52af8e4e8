//! Grid heat maps: the statistics printed (Emin, Eavg, Emax, U₀) match the values, and each
//! cell is painted with its value's colour, row 0 at the bottom.

use candela::photometry::LX_PER_FC;
use candela::report::falsecolour::FalsecolourSettings;
use candela::report::heatmap::{write_grid_heatmap, GridValues};
use candela::report::units::{format_sig, UnitSystem};

fn grid() -> GridValues {
    let (nx, ny) = (6, 4);
    let values: Vec<f64> = (0..nx * ny)
        .map(|k| 300.0 + 20.0 * (k % nx) as f64 + 55.0 * (k / nx) as f64)
        .collect();
    GridValues {
        name: "work plane".into(),
        nx,
        ny,
        stderr: values.iter().map(|v| v * 0.01).collect(),
        values,
        size_m: (3.0, 2.0),
    }
}

#[test]
fn statistics_and_cells_match_the_values() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("grid.png");
    let g = grid();
    let settings = FalsecolourSettings {
        min: Some(0.0),
        max: Some(600.0),
        steps: Some(12),
        ..Default::default()
    };
    let info = write_grid_heatmap(&png, &g, &settings).unwrap();
    let min = 300.0;
    let max = 300.0 + 100.0 + 165.0;
    let avg = g.values.iter().sum::<f64>() / g.values.len() as f64;
    let s = info.stats;
    assert_eq!((s.min, s.max), (min, max));
    assert!((s.avg - avg).abs() < 1e-9);
    assert!((s.u0.unwrap() - min / avg).abs() < 1e-12);
    assert!((s.min_over_max.unwrap() - min / max).abs() < 1e-12);
    assert!((s.max_stderr.unwrap() - max * 0.01).abs() < 1e-9);
    let line = &info.title_lines[1];
    for needle in [
        format!("Emin {}", format_sig(min, 4)),
        format!("Eavg {}", format_sig(avg, 4)),
        format!("Emax {} lx", format_sig(max, 4)),
        format!("U₀ = Emin/Eavg = {:.2}", min / avg),
    ] {
        assert!(line.contains(&needle), "'{line}' lacks '{needle}'");
    }
    assert!(info.title_lines[0].contains("work plane"));

    let img = image::open(&png).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), info.image_size);
    let c = info.cell_px;
    for j in 0..g.ny {
        for i in 0..g.nx {
            // Sample near the cell's corner, away from the printed value.
            let (cx, cy) = info.cell_centre(i, j, g.ny);
            let p = img.get_pixel(cx - c / 2 + 3, cy - c / 2 + 3).0;
            let want = info.scale.colour(g.values[j * g.nx + i]);
            assert_eq!(p, want, "cell ({i}, {j})");
        }
    }
    // Row 0 is drawn at the bottom: its cell centre is lower in the image than row 3's.
    assert!(info.cell_centre(0, 0, g.ny).1 > info.cell_centre(0, 3, g.ny).1);
}

#[test]
fn imperial_statistics_are_footcandles() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("grid-fc.png");
    let g = grid();
    let settings = FalsecolourSettings {
        units: UnitSystem::Imperial,
        ..Default::default()
    };
    let info = write_grid_heatmap(&png, &g, &settings).unwrap();
    assert_eq!(info.unit, "fc");
    assert!((info.stats.min - 300.0 / LX_PER_FC).abs() < 1e-9);
    assert_eq!(info.stats.u0, info.stats_si.u0);
    assert!(info.title_lines[1].contains(" fc"));
    assert!(info.title_lines[2].contains(" ft"));
    assert!(png.exists());
}

#[test]
fn inconsistent_grid_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("bad.png");
    let mut g = grid();
    g.values.pop();
    let err = write_grid_heatmap(&png, &g, &FalsecolourSettings::default()).unwrap_err();
    assert!(err.to_string().contains("bad.png"), "{err}");
    assert!(!png.exists());
}

/// Writes example images for eyeballing:
/// `CANDELA_REPORT_SAMPLES=/tmp/x cargo test --test report_heatmap -- --ignored`.
#[test]
#[ignore]
fn sample_images() {
    use candela::output::{Layers, CHANNEL_E, CHANNEL_E_MASK, CHANNEL_E_STDERR};
    use candela::photometry::Quantity;
    use candela::report::falsecolour::{write_falsecolour, Scale};
    let dir = std::path::PathBuf::from(std::env::var("CANDELA_REPORT_SAMPLES").unwrap());
    // A point source of 1000 cd, 2 m above a 6 × 4 m work plane: E = I cos θ / d².
    let (nx, ny, sx, sy) = (12, 8, 6.0, 4.0);
    let e = |x: f64, y: f64| {
        let (dx, dy, h) = (x - 2.0, y - 2.5, 2.0);
        let d2: f64 = dx * dx + dy * dy + h * h;
        1000.0 * h / d2.powf(1.5)
    };
    let values: Vec<f64> = (0..nx * ny)
        .map(|k| {
            let (i, j) = (k % nx, k / nx);
            e(
                (i as f64 + 0.5) * sx / nx as f64,
                (j as f64 + 0.5) * sy / ny as f64,
            )
        })
        .collect();
    let grid = GridValues {
        name: "work plane 0.8 m".into(),
        nx,
        ny,
        stderr: values.iter().map(|v| v * 0.008).collect(),
        values,
        size_m: (sx, sy),
    };
    write_grid_heatmap(
        &dir.join("grid.png"),
        &grid,
        &FalsecolourSettings::default(),
    )
    .unwrap();
    let imperial = FalsecolourSettings {
        units: UnitSystem::Imperial,
        steps: Some(8),
        ..Default::default()
    };
    write_grid_heatmap(&dir.join("grid-fc.png"), &grid, &imperial).unwrap();

    // An illuminance image: the plane seen from above, sky (undefined) in the top rows.
    let (w, h) = (240, 160);
    let mut layers = Layers::from_xyz(w, h, &vec![[1.0; 3]; w * h], &vec![0.0; w * h]);
    let (mut ev, mut mask) = (Vec::new(), Vec::new());
    for py in 0..h {
        for px in 0..w {
            if py < 30 {
                ev.push(-1.0);
                mask.push(0.0);
            } else {
                ev.push(e(px as f64 / 40.0, py as f64 / 40.0) as f32);
                mask.push(1.0);
            }
        }
    }
    layers.channels.push((CHANNEL_E.into(), ev));
    layers
        .channels
        .push((CHANNEL_E_STDERR.into(), vec![0.0; w * h]));
    layers.channels.push((CHANNEL_E_MASK.into(), mask));
    let s = FalsecolourSettings {
        quantity: Quantity::Illuminance,
        steps: Some(10),
        contours: true,
        ..Default::default()
    };
    write_falsecolour(&dir.join("illuminance.png"), &layers, &s).unwrap();
    let s = FalsecolourSettings {
        quantity: Quantity::Illuminance,
        scale: Scale::Log,
        ..Default::default()
    };
    write_falsecolour(&dir.join("illuminance-log.png"), &layers, &s).unwrap();
}
