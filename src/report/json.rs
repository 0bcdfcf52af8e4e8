//! `NAME.report.json` and one CSV per calculation grid. The schema is documented in
//! docs/reports.md; every value carries its unit in the `units` object.

use crate::meter::{grid_non_finite, grid_stats, Estimate, Measurements};
use crate::output::{write_atomic, OutputError};
use crate::render::RenderResult;
use crate::world::World;
use crate::world::{Grid, Meter, MeterKind};
use serde_json::{json, Value};
use std::path::Path;

use super::units::UnitSystem;
use crate::photometry::Quantity;

fn v3(v: glam::Vec3) -> Value {
    json!([v.x, v.y, v.z])
}

fn estimate(e: &Estimate, k: f64) -> Value {
    json!({
        "value": e.mean * k,
        "stderr": e.stderr * k,
        "ci95_low": (e.mean - e.ci95()) * k,
        "ci95_high": (e.mean + e.ci95()) * k,
        "samples": e.samples,
        "batches": e.batches,
        "non_finite_samples": e.non_finite,
    })
}

/// What the report must not let pass silently: every meter and grid, and the image, with
/// samples that were not finite (counted as 0, so their values are too low or meaningless).
pub fn warnings(world: &World, render: &RenderResult, m: &Measurements) -> Vec<String> {
    let mut out = Vec::new();
    for (meter, e) in world.meters.iter().zip(&m.meters) {
        if e.non_finite > 0 {
            out.push(format!(
                "meter {:?}: {} of {} samples were not finite and were counted as 0; its value is not reliable",
                meter.name, e.non_finite, e.samples
            ));
        }
    }
    for (grid, est) in world.grids.iter().zip(&m.grids) {
        let n = grid_non_finite(est);
        if n > 0 {
            let points = est.iter().filter(|e| e.non_finite > 0).count();
            out.push(format!(
                "grid {:?}: {n} samples at {points} of {} points were not finite and were counted as 0; those points are not reliable",
                grid.name,
                est.len()
            ));
        }
    }
    if render.stats.non_finite > 0 {
        out.push(format!(
            "image: {} samples were not finite and were counted as 0",
            render.stats.non_finite
        ));
    }
    if let Some(w) = truncation_warning(
        world,
        render.stats.truncated_paths + m.stats.truncated_paths,
    ) {
        out.push(w);
    }
    out
}

/// The warning for `truncated` paths cut short at the scene's finite `max_depth`, if any were.
pub fn truncation_warning(world: &World, truncated: u64) -> Option<String> {
    let max = world.settings.max_depth?;
    (truncated > 0).then(|| {
        format!(
            "{truncated} paths reached max_depth {max} and were cut short: the image, meters and grids lack the light of longer paths and read low; leave max_depth out for unbiased results"
        )
    })
}

/// Everything a report says about one run.
pub struct ReportInput<'a> {
    pub scene_path: &'a Path,
    pub world: &'a World,
    pub render: &'a RenderResult,
    pub measurements: &'a Measurements,
    pub measure_seconds: f64,
    pub units: UnitSystem,
    /// Output files already written, for reference.
    pub outputs: Vec<String>,
    /// How the progressive render ended: stop reason, target and what was reached.
    pub progressive: Value,
}

/// Min, mean and max of defined values.
fn stats(values: impl Iterator<Item = f64>) -> Value {
    let (mut min, mut max, mut sum, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0u64);
    for v in values {
        min = min.min(v);
        max = max.max(v);
        sum += v;
        n += 1;
    }
    if n == 0 {
        return Value::Null;
    }
    json!({"min": min, "mean": sum / n as f64, "max": max, "pixels": n})
}

/// Build the JSON report.
pub fn report_json(r: &ReportInput) -> Value {
    let daylight = crate::light::sky::daylight_reference(&r.world.lights);
    // Daylight factor, %, per lx of illuminance.
    let kdf = daylight
        .as_ref()
        .map(|d| 100.0 / d.horizontal_illuminance_lx);
    let ke = r.units.from_si(Quantity::Illuminance, 1.0);
    let kl = r.units.from_si(Quantity::Luminance, 1.0);
    let w = r.world;
    let film = &r.render.film;
    // A fisheye's pixels outside its circle see nothing and take no samples: left out.
    let luminance = stats(
        film.pixels
            .iter()
            .filter(|p| p.count > 0)
            .map(|p| p.mean_xyz()[1] * kl),
    );
    let illuminance = if w.settings.illuminance {
        stats(film.pixels_e().filter_map(|p| p.mean_e()).map(|e| e * ke))
    } else {
        Value::Null
    };
    let meters: Vec<Value> = w
        .meters
        .iter()
        .zip(&r.measurements.meters)
        .map(|(m, e)| meter_json(r, m, e, ke, kl, kdf))
        .collect();
    let grids: Vec<Value> = w
        .grids
        .iter()
        .zip(&r.measurements.grids)
        .map(|(g, est)| grid_json(r, g, est, ke, kdf))
        .collect();
    let mut stats_all = r.render.stats;
    stats_all.merge(&r.measurements.stats);
    json!({
        "software": "candela",
        "version": env!("CARGO_PKG_VERSION"),
        "created_utc": humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string(),
        "scene": r.scene_path.display().to_string(),
        "units": {
            "system": r.units.name(),
            "luminance": r.units.symbol(Quantity::Luminance),
            "illuminance": r.units.symbol(Quantity::Illuminance),
            "length": "m",
        },
        "settings": {
            "width": film.width, "height": film.height,
            "spp": w.settings.spp, "max_depth": w.settings.max_depth, "rr_depth": w.settings.rr_depth,
            "pixel_batches": w.settings.pixel_batches,
            "seed": w.settings.seed, "threads": r.render.threads, "illuminance": w.settings.illuminance,
            "caustics": if w.caustics.is_some() { "light-tracing" } else { "path-tracing" },
            "meter_samples": w.measure.samples,
            "meter_target_relative_error": w.measure.target_relative_error,
            "meter_max_samples": w.measure.max_samples,
        },
        "timing": {
            "render_seconds": r.render.elapsed.as_secs_f64(),
            "measure_seconds": r.measure_seconds,
            "rays": stats_all.total_rays(),
            "light_paths": stats_all.light_paths,
            "non_finite_samples": stats_all.non_finite,
            "truncated_paths": stats_all.truncated_paths,
        },
        "image": {
            "luminance": luminance,
            "illuminance": illuminance,
            "non_finite_samples": r.render.stats.non_finite,
        },
        "daylight": daylight.map(|d| json!({
            "sky": d.sky,
            "horizontal_illuminance": d.horizontal_illuminance_lx * ke,
        })),
        "meters": meters,
        "grids": grids,
        "outputs": r.outputs,
        "progressive": r.progressive,
        "warnings": warnings(w, r.render, r.measurements),
    })
}

/// One meter's entry: its estimate `e` in display units (`ke` per lx, `kl` per cd/m²), where
/// it is and what its kind adds (daylight factor at `kdf` % per lx, UGR, melanopic values).
fn meter_json(
    r: &ReportInput,
    m: &Meter,
    e: &Estimate,
    ke: f64,
    kl: f64,
    kdf: Option<f64>,
) -> Value {
    match &m.kind {
        MeterKind::Illuminance { position, normal } => {
            let mut v = estimate(e, ke);
            v["name"] = json!(m.name);
            v["kind"] = json!("illuminance");
            v["unit"] = json!(r.units.symbol(Quantity::Illuminance));
            v["position"] = v3(*position);
            v["normal"] = v3(*normal);
            if let Some(k) = kdf {
                v["daylight_factor_percent"] = estimate(e, k);
            }
            v
        }
        MeterKind::Luminance {
            position,
            direction,
            half_angle_rad,
        } => {
            let mut v = estimate(e, kl);
            v["name"] = json!(m.name);
            v["kind"] = json!("luminance");
            v["unit"] = json!(r.units.symbol(Quantity::Luminance));
            v["position"] = v3(*position);
            v["direction"] = v3(*direction);
            v["half_angle_deg"] = json!(half_angle_rad.to_degrees());
            v
        }
        MeterKind::Ugr {
            position,
            direction,
            up,
        } => {
            // The estimate is the vertical illuminance at the eye; UGR is unitless.
            let mut v = estimate(e, ke);
            v["name"] = json!(m.name);
            v["kind"] = json!("ugr");
            v["unit"] = json!(r.units.symbol(Quantity::Illuminance));
            v["position"] = v3(*position);
            v["direction"] = v3(*direction);
            v["up"] = v3(*up);
            v["ugr"] = json!(m.ugr(r.world, e));
            v
        }
        MeterKind::Melanopic {
            position,
            direction,
        } => {
            // The estimate is the vertical illuminance at the eye.
            let mut v = estimate(e, ke);
            v["name"] = json!(m.name);
            v["kind"] = json!("melanopic");
            v["unit"] = json!(r.units.symbol(Quantity::Illuminance));
            v["position"] = v3(*position);
            v["direction"] = v3(*direction);
            v["melanopic"] = melanopic_json(r, m, ke);
            v
        }
    }
}

/// The melanopic quantities of meter `m` (one of the world's), illuminances `ke` per lx.
fn melanopic_json(r: &ReportInput, m: &Meter, ke: f64) -> Value {
    let k = r.world.meters.iter().position(|x| std::ptr::eq(x, m));
    let mel = k.and_then(|k| r.measurements.melanopic.get(k).copied().flatten());
    match mel {
        Some(me) => json!({
            "illuminance": estimate(&me.illuminance_lx, ke),
            "m_edi": estimate(&me.m_edi_lx, ke),
            "m_edi_over_illuminance": {
                "value": me.ratio,
                "stderr": me.ratio_stderr,
                "ci95_half_width": crate::meter::t95(crate::meter::BATCHES - 1) * me.ratio_stderr,
            },
            "equivalent_melanopic_lux": crate::colour::alpha_opic::equivalent_melanopic_lux(me.m_edi_lx.mean) * ke,
        }),
        None => Value::Null,
    }
}

/// One grid's entry: where it is, its values by row (`ke` per lx), statistics, and its
/// daylight factors (`kdf` % per lx) under a daylight sky.
fn grid_json(r: &ReportInput, g: &Grid, est: &[Estimate], ke: f64, kdf: Option<f64>) -> Value {
    let s = grid_stats(est);
    let df = kdf.map(|k| {
        json!({
            "values": (0..g.ny as usize)
                .map(|j| (0..g.nx as usize).map(|i| est[j * g.nx as usize + i].mean * k).collect::<Vec<_>>())
                .collect::<Vec<_>>(),
            "stderr": (0..g.ny as usize)
                .map(|j| (0..g.nx as usize).map(|i| est[j * g.nx as usize + i].stderr * k).collect::<Vec<_>>())
                .collect::<Vec<_>>(),
            "DF_min": s.min * k, "DF_avg": s.avg * k, "DF_max": s.max * k,
        })
    });
    let rows = |f: &dyn Fn(&Estimate) -> Value| -> Value {
        (0..g.ny as usize)
            .map(|j| {
                (0..g.nx as usize)
                    .map(|i| f(&est[j * g.nx as usize + i]))
                    .collect::<Vec<_>>()
            })
            .collect::<Vec<_>>()
            .into()
    };
    json!({
        "name": g.name,
        "unit": r.units.symbol(Quantity::Illuminance),
        "nx": g.nx, "ny": g.ny,
        "origin": v3(g.origin), "edge_u": v3(g.edge_u), "edge_v": v3(g.edge_v), "normal": v3(g.normal),
        "values": rows(&|e| json!(e.mean * ke)),
        "stderr": rows(&|e| json!(e.stderr * ke)),
        "samples": rows(&|e| json!(e.samples)),
        "batches": crate::meter::BATCHES,
        "non_finite_samples": grid_non_finite(est),
        "E_min": s.min * ke, "E_avg": s.avg * ke, "E_max": s.max * ke,
        "U0": s.u0, "E_min_over_E_max": s.min_over_max,
        "daylight_factor_percent": df,
    })
}

/// The CSV of one grid: one row per point.
pub fn grid_csv(world: &World, grid: usize, est: &[Estimate], units: UnitSystem) -> String {
    let g = &world.grids[grid];
    let k = units.from_si(Quantity::Illuminance, 1.0);
    let u = units.symbol(Quantity::Illuminance);
    let daylight = crate::light::sky::daylight_reference(&world.lights);
    let mut s = format!(
        "# candela {} grid {:?}: illuminance on the plane facing ({}, {}, {}); positions in m{}\ni,j,x,y,z,E_{u},stderr_{u},ci95_low_{u},ci95_high_{u},samples{}\n",
        env!("CARGO_PKG_VERSION"),
        g.name,
        g.normal.x,
        g.normal.y,
        g.normal.z,
        match &daylight {
            Some(d) => format!(
                "; daylight factor DF = 100 E / {} lx ({} sky)",
                d.horizontal_illuminance_lx, d.sky
            ),
            None => String::new(),
        },
        if daylight.is_some() {
            ",DF_percent,DF_ci95_low_percent,DF_ci95_high_percent"
        } else {
            ""
        }
    );
    for j in 0..g.ny {
        for i in 0..g.nx {
            let p = g.point(i, j);
            let e = &est[(j * g.nx + i) as usize];
            s.push_str(&format!(
                "{i},{j},{},{},{},{},{},{},{},{}\n",
                p.x,
                p.y,
                p.z,
                e.mean * k,
                e.stderr * k,
                (e.mean - e.ci95()) * k,
                (e.mean + e.ci95()) * k,
                e.samples
            ));
            if let Some(d) = &daylight {
                let kdf = 100.0 / d.horizontal_illuminance_lx;
                s.pop();
                s.push_str(&format!(
                    ",{},{},{}\n",
                    e.mean * kdf,
                    (e.mean - e.ci95()) * kdf,
                    (e.mean + e.ci95()) * kdf
                ));
            }
        }
    }
    s
}

/// Write text atomically.
pub fn write_text(path: &Path, text: &str) -> Result<(), OutputError> {
    write_atomic(path, |w| w.write_all(text.as_bytes()))
}
