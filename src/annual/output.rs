//! What `candela annual` writes: NAME.annual.json (the metrics with their intervals; schema in
//! docs/annual.md), NAME.annual.csv (every daylight hour's illuminance and standard error at
//! every grid point) and the summary printed on the terminal. Files are written atomically.

use super::results::{Estimate, GridResult};
use super::run::AnnualRun;
use crate::output::OutputError;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn est(e: &Estimate) -> Value {
    match e.ci95 {
        Some((lo, hi)) => json!({"value": e.value, "ci95": [lo, hi]}),
        None => json!({"value": e.value, "ci95": null}),
    }
}

/// The JSON report.
pub fn json_report(run: &AnnualRun) -> Value {
    let s = &run.settings;
    let t = &s.thresholds;
    let grids: Vec<Value> = run
        .grids
        .iter()
        .zip(&run.results)
        .map(|(g, r): (_, &GridResult)| {
            let points: Vec<Value> = g
                .points
                .iter()
                .zip(&r.points)
                .enumerate()
                .map(|(k, (p, m))| {
                    json!({
                        "i": k % g.nx as usize,
                        "j": k / g.nx as usize,
                        "position_m": [p.x, p.y, p.z],
                        "da": est(&m.da),
                        "cda": est(&m.cda),
                        "udi_below": est(&m.udi_below),
                        "udi_useful": est(&m.udi_useful),
                        "udi_above": est(&m.udi_above),
                        "sun_hours": est(&m.sun_hours),
                    })
                })
                .collect();
            json!({
                "name": g.name,
                "nx": g.nx,
                "ny": g.ny,
                "normal": [g.normal.x, g.normal.y, g.normal.z],
                "sda": est(&r.sda),
                "ase": est(&r.ase),
                "en17037_target": est(&r.en17037_target),
                "en17037_minimum": est(&r.en17037_minimum),
                "points": points,
            })
        })
        .collect();
    json!({
        "candela": env!("CARGO_PKG_VERSION"),
        "scene": run.scene.display().to_string(),
        "weather": {
            "file": run.weather.display().to_string(),
            "city": run.site.city,
            "country": run.site.country,
            "latitude_deg": run.site.latitude_deg,
            "longitude_deg": run.site.longitude_deg,
            "time_zone_h": run.site.time_zone_h,
            "elevation_m": run.site.elevation_m,
        },
        "method": {
            "sky_patches": run.patches,
            "reinhart_mf": s.mf,
            "sky_samples": s.sky_samples,
            "sun_samples": s.sun_samples,
            "direct_sun_samples": s.direct_samples,
            "replicate_years": s.draws,
            "sunny_hours_traced": run.sunny_hours,
            "sun_nodes": run.sun_nodes,
        },
        "thresholds": {
            "da_lx": t.da_lx,
            "sda_fraction": t.sda_fraction,
            "udi_lx": [t.udi_lx.0, t.udi_lx.1],
            "ase_lx": t.ase_lx,
            "ase_hours": t.ase_hours,
            "en17037_target": {"lx": super::results::EN17037_TARGET.0, "plane_fraction": super::results::EN17037_TARGET.1},
            "en17037_minimum": {"lx": super::results::EN17037_MINIMUM.0, "plane_fraction": super::results::EN17037_MINIMUM.1},
        },
        "occupied": {"from_h": s.occupied.0, "to_h": s.occupied.1, "hours": run.occupied_hours},
        "daylight_hours": run.daylight_hours,
        "seconds": {"sky": run.seconds.0, "sun": run.seconds.1, "metrics": run.seconds.2},
        "notes": run.notes,
        "grids": grids,
        "view": run.view.as_ref().map(view_json),
    })
}

fn view_json(v: &super::run::ViewRun) -> Value {
    let r = &v.result;
    json!({
        "width": v.width,
        "height": v.height,
        "projection": v.projection,
        "sky_samples_per_pixel": v.sky_samples,
        "sun_samples_per_pixel_and_node": v.sun_samples,
        "daylight_hours_evaluated": v.hours.len(),
        "dgp_limits": super::view::DGP_LIMITS,
        "hours_dgp_at_least": [est(&r.hours_above[0]), est(&r.hours_above[1]), est(&r.hours_above[2])],
        "dgp_5_percent": est(&r.dgp_5_percent),
        "en17037_glare_protection": super::view::en17037_glare_level(r.dgp_5_percent.value),
        "seconds": {"coefficients": v.seconds.0, "glare": v.seconds.1},
    })
}

/// Writes the grid points' coefficients, when the run kept them: `sky` gets one row per point
/// and sky patch (`grid,i,j,patch,altitude_deg,azimuth_deg,solid_angle_sr,lx_per_cd_m2,
/// stderr_lx_per_cd_m2`; patch 0 is the ground, without a direction), `sun` one row per sunny
/// hour and point (`month,day,hour,grid,i,j,total_lx_per_lx,total_stderr,direct_lx_per_lx,
/// direct_stderr`: the illuminance per lx of direct-normal illuminance, in total and of the
/// direct sun alone).
pub fn write_coefficients(sky: &Path, sun: &Path, run: &AnnualRun) -> Result<(), OutputError> {
    write_sky_coefficients(sky, run)?;
    write_sun_coefficients(sun, run)
}

/// Each grid point as (grid name made CSV-safe, i, j).
fn coefficient_points(run: &AnnualRun) -> Vec<(String, usize, usize)> {
    run.grids
        .iter()
        .flat_map(|g| {
            let name = g.name.replace([',', '"', '\n', '\r'], "_");
            (0..g.points.len()).map(move |k| (name.clone(), k % g.nx as usize, k / g.nx as usize))
        })
        .collect()
}

/// The sky half of [`write_coefficients`].
pub fn write_sky_coefficients(sky: &Path, run: &AnnualRun) -> Result<(), OutputError> {
    let Some((c, _)) = &run.coefficients else {
        return Ok(());
    };
    let points = coefficient_points(run);
    crate::output::write_atomic(sky, |w| {
        writeln!(
            w,
            "grid,i,j,patch,altitude_deg,azimuth_deg,solid_angle_sr,lx_per_cd_m2,stderr_lx_per_cd_m2"
        )?;
        for (r, (g, i, j)) in points.iter().enumerate() {
            for p in 0..c.patches.len() {
                let dir = match c.patches.patch(p) {
                    Some(pt) => {
                        let d = pt.centre();
                        let alt = d[2].clamp(-1.0, 1.0).asin().to_degrees();
                        let az = d[0].atan2(d[1]).to_degrees().rem_euclid(360.0);
                        format!("{alt:.4},{az:.4},{:.8}", pt.solid_angle_sr)
                    }
                    None => ",,".into(),
                };
                writeln!(
                    w,
                    "{g},{i},{j},{p},{dir},{:.9e},{:.4e}",
                    c.mean(r, p),
                    c.stderr(r, p)
                )?;
            }
        }
        Ok(())
    })
}

/// The sun half of [`write_coefficients`].
pub fn write_sun_coefficients(sun: &Path, run: &AnnualRun) -> Result<(), OutputError> {
    let Some((_, sc)) = &run.coefficients else {
        return Ok(());
    };
    let points = coefficient_points(run);
    crate::output::write_atomic(sun, |w| {
        writeln!(
            w,
            "month,day,hour,grid,i,j,total_lx_per_lx,total_stderr,direct_lx_per_lx,direct_stderr"
        )?;
        let sunny = run.year.iter().filter(|h| h.has_sun());
        for (h, hs) in sunny.enumerate() {
            for (r, (g, i, j)) in points.iter().enumerate() {
                let (t, d) = sc.batches(h, r);
                let (tm, ts) = mean_se(t);
                let (dm, ds) = mean_se(d);
                writeln!(
                    w,
                    "{},{},{},{g},{i},{j},{tm:.9e},{ts:.4e},{dm:.9e},{ds:.4e}",
                    hs.month, hs.day, hs.hour
                )?;
            }
        }
        Ok(())
    })
}

fn mean_se(b: &[f64]) -> (f64, f64) {
    let k = b.len() as f64;
    let m = b.iter().sum::<f64>() / k;
    let var = b.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (k - 1.0);
    (m, (var / k).sqrt())
}

/// Writes the view's hourly glare: one row per occupied hour with daylight, `month,day,hour`
/// (the EPW record hour), DGP, E_v and its standard error (lx), the sun disk's part of E_v (lx)
/// and the number of glare sources.
pub fn write_glare_csv(path: &Path, run: &AnnualRun) -> Result<(), OutputError> {
    let Some(v) = &run.view else {
        return Ok(());
    };
    crate::output::write_atomic(path, |w| {
        writeln!(
            w,
            "month,day,hour,dgp,ev_lx,ev_stderr_lx,ev_sun_disk_lx,sources"
        )?;
        for g in &v.hours {
            let hs = &run.year[g.hour];
            writeln!(
                w,
                "{},{},{},{:.6},{:.6},{:.6},{:.6},{}",
                hs.month, hs.day, hs.hour, g.dgp, g.ev_lx, g.ev_stderr_lx, g.ev_disk_lx, g.sources
            )?;
        }
        Ok(())
    })
}

/// Writes the JSON report.
pub fn write_json(path: &Path, run: &AnnualRun) -> Result<(), OutputError> {
    let text = serde_json::to_string_pretty(&json_report(run)).expect("JSON of plain values");
    crate::report::json::write_text(path, &(text + "\n"))
}

/// Writes the hourly CSV: one row per hour with daylight, the columns `month,day,hour` (the
/// EPW record hour, 1–24), then per grid point its illuminance, standard error and direct
/// sunlight (lx).
pub fn write_csv(path: &Path, run: &AnnualRun) -> Result<(), OutputError> {
    let h = &run.hourly;
    crate::output::write_atomic(path, |w| {
        write!(w, "month,day,hour")?;
        for g in &run.grids {
            let name = g.name.replace([',', '"', '\n', '\r'], "_");
            for k in 0..g.points.len() {
                let (i, j) = (k % g.nx as usize, k / g.nx as usize);
                write!(
                    w,
                    ",{name}[{i};{j}]_lx,{name}[{i};{j}]_stderr_lx,{name}[{i};{j}]_direct_sun_lx"
                )?;
            }
        }
        writeln!(w)?;
        for (t, hs) in run.year.iter().enumerate() {
            if !hs.is_daylight() {
                continue;
            }
            write!(w, "{},{},{}", hs.month, hs.day, hs.hour)?;
            for r in 0..h.receivers {
                let i = t * h.receivers + r;
                write!(w, ",{:.6},{:.6},{:.6}", h.mean[i], h.stderr[i], h.direct[i])?;
            }
            writeln!(w)?;
        }
        Ok(())
    })
}

fn pct(e: &Estimate) -> String {
    match e.ci95 {
        Some((lo, hi)) => format!(
            "{:5.1} %  [{:.1}, {:.1}]",
            100.0 * e.value,
            100.0 * lo,
            100.0 * hi
        ),
        None => format!("{:5.1} %", 100.0 * e.value),
    }
}

/// The summary table: per grid its LEED/LM-83 and EN 17037 figures with 95 % intervals.
pub fn summary(run: &AnnualRun) -> String {
    let t = &run.settings.thresholds;
    let mut s = format!(
        "annual daylight of {} under {} ({}, {:.2}°, {:.2}°): {} occupied hours ({}:00–{}:00), {} sunny hours traced\n",
        run.scene.display(),
        run.weather.display(),
        run.site.city,
        run.site.latitude_deg,
        run.site.longitude_deg,
        run.occupied_hours,
        run.settings.occupied.0,
        run.settings.occupied.1,
        run.sunny_hours
    );
    for (g, r) in run.grids.iter().zip(&run.results) {
        let pass = |e: &Estimate, ok: &dyn Fn(f64) -> bool| match e.ci95 {
            Some((lo, hi)) if ok(lo) && ok(hi) => "yes",
            Some((lo, hi)) if !ok(lo) && !ok(hi) => "no",
            Some(_) => "undecided (the interval straddles the limit)",
            None if ok(e.value) => "yes",
            None => "no",
        };
        let mean_da =
            r.points.iter().map(|p| p.da.value).sum::<f64>() / r.points.len().max(1) as f64;
        s += &format!(
            "grid \"{}\" ({} × {} points), 95 % intervals in brackets:\n",
            g.name, g.nx, g.ny
        );
        s += &format!(
            "  sDA {:.0} lx / {:.0} %        {}   (LEED v4, 2 points at ≥ 55 %: {})\n",
            t.da_lx,
            100.0 * t.sda_fraction,
            pct(&r.sda),
            pass(&r.sda, &|v| v >= 0.55)
        );
        s += &format!(
            "  ASE {:.0} lx, {:.0} h         {}   (LEED v4, at most 10 %: {})\n",
            t.ase_lx,
            t.ase_hours,
            pct(&r.ase),
            pass(&r.ase, &|v| v <= 0.10)
        );
        s += &format!(
            "  EN 17037 target (300 lx over 50 %)   {} of daylight hours (met at ≥ 50 %: {})\n",
            pct(&r.en17037_target),
            pass(&r.en17037_target, &|v| v >= 0.5)
        );
        s += &format!(
            "  EN 17037 minimum (100 lx over 95 %)  {} of daylight hours (met at ≥ 50 %: {})\n",
            pct(&r.en17037_minimum),
            pass(&r.en17037_minimum, &|v| v >= 0.5)
        );
        s += &format!(
            "  mean DA {:.0} lx           {:5.1} %\n",
            t.da_lx,
            100.0 * mean_da
        );
    }
    if let Some(v) = &run.view {
        let r = &v.result;
        s += &format!(
            "view ({} × {} {}), occupied hours with daylight glare, 95 % intervals in brackets:\n",
            v.width, v.height, v.projection
        );
        for (k, name) in ["perceptible", "disturbing", "intolerable"]
            .iter()
            .enumerate()
        {
            s += &format!(
                "  DGP ≥ {:.2} ({name}){}  {}\n",
                super::view::DGP_LIMITS[k],
                " ".repeat(12 - name.len()),
                pct(&r.hours_above[k])
            );
        }
        let d = &r.dgp_5_percent;
        s += &format!(
            "  DGP exceeded in 5 % of hours  {:.3}{}   (EN 17037 glare protection: {})\n",
            d.value,
            d.ci95
                .map(|(lo, hi)| format!("  [{lo:.3}, {hi:.3}]"))
                .unwrap_or_default(),
            super::view::en17037_glare_level(d.value)
        );
    }
    for n in &run.notes {
        s += &format!("note: {n}\n");
    }
    s
}

/// The output stem NAME (heat maps are NAME.annual.grid-…png), NAME.annual.json and
/// NAME.annual.csv for `out` (an output name, a directory or `None`: the
/// scene's name in the current directory); refused when the directory does not exist or an
/// output would replace an input.
pub fn output_paths(
    out: Option<&Path>,
    scene: &Path,
    weather: Option<&Path>,
) -> anyhow::Result<(PathBuf, PathBuf, PathBuf)> {
    use crate::job::files;
    let name = scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let stem = files::output_stem(out, &name, &["json", "csv"]);
    files::check_output_dir(&stem)?;
    let json = PathBuf::from(format!("{}.annual.json", stem.display()));
    let csv = PathBuf::from(format!("{}.annual.csv", stem.display()));
    // The optional outputs (glare, coefficients) share the stem.
    let extra = ["annual-glare.csv", "annual-sky-dc.csv", "annual-sun-dc.csv"]
        .map(|e| PathBuf::from(format!("{}.{e}", stem.display())));
    for p in [&json, &csv].into_iter().chain(&extra) {
        if files::would_replace(p, scene) || weather.is_some_and(|w| files::would_replace(p, w)) {
            return Err(crate::job::invalid_option(format!(
                "{} would replace an input",
                p.display()
            )));
        }
    }
    Ok((stem, json, csv))
}

/// The heat maps of each grid: daylight autonomy and useful daylight illuminance (%, on a
/// fixed 0–100 scale) and hours of direct sun above the ASE threshold (h, 0 to the largest),
/// as NAME.annual.grid-SLUG.da.png, .udi.png and .sun-hours.png, each attempted whether or
/// not an earlier one failed.
pub fn write_heatmaps(stem: &Path, run: &AnnualRun, writes: &mut crate::job::Writes) {
    use crate::report::falsecolour::FalsecolourSettings;
    use crate::report::heatmap::{render_metric_heatmap, GridMetric, GridValues};
    let t = &run.settings.thresholds;
    for (g, r) in run.grids.iter().zip(&run.results) {
        let (nx, ny) = (g.nx as usize, g.ny as usize);
        // (file key, title, unit, values, scale maximum)
        #[allow(clippy::type_complexity)]
        let maps: [(&str, String, &str, Vec<f64>, Option<f64>); 3] = [
            (
                "da",
                format!("daylight autonomy DA{}", t.da_lx),
                "%",
                r.points.iter().map(|p| 100.0 * p.da.value).collect(),
                Some(100.0),
            ),
            (
                "udi",
                format!(
                    "useful daylight illuminance UDI {}–{} lx",
                    t.udi_lx.0, t.udi_lx.1
                ),
                "%",
                r.points
                    .iter()
                    .map(|p| 100.0 * p.udi_useful.value)
                    .collect(),
                Some(100.0),
            ),
            (
                "sun-hours",
                format!(
                    "hours of direct sun above {} lx (ASE counts > {} h)",
                    t.ase_lx, t.ase_hours
                ),
                "h",
                r.points.iter().map(|p| p.sun_hours.value).collect(),
                None,
            ),
        ];
        for (key, name, unit, values, max) in maps {
            let path = crate::output::with_suffix(
                stem,
                &format!(
                    ".annual.grid-{}.{key}.png",
                    crate::world::measure::slug(&g.name)
                ),
            );
            let max = max.or_else(|| {
                let m = values.iter().copied().fold(0.0, f64::max);
                Some(if m > 0.0 { m } else { 1.0 })
            });
            let grid = GridValues {
                name: g.name.clone(),
                nx,
                ny,
                values,
                stderr: Vec::new(),
                size_m: g.size_m,
            };
            let settings = FalsecolourSettings {
                min: Some(0.0),
                max,
                ..Default::default()
            };
            let metric = GridMetric {
                name,
                unit: unit.to_string(),
            };
            writes.attempt(&path, || {
                let (img, _) = render_metric_heatmap(&grid, &metric, &settings)
                    .map_err(|e| OutputError::invalid(&path, e))?;
                crate::output::write_rgb_png(&path, &img)?;
                Ok(())
            });
        }
    }
}

/// Every file of a run with output stem `stem`: the JSON report, the hourly CSV, the glare CSV
/// (with a view), the coefficient CSVs (when kept) and the heat maps. Each is attempted
/// whether or not an earlier one failed; the error lists every file that could not be
/// written. Returns the files written.
pub fn write_all(stem: &Path, run: &AnnualRun) -> anyhow::Result<Vec<String>> {
    let mut writes = crate::job::Writes::default();
    let named = |suffix: &str| crate::output::with_suffix(stem, suffix);
    let json = named(".annual.json");
    writes.attempt(&json, || Ok(write_json(&json, run)?));
    let csv = named(".annual.csv");
    writes.attempt(&csv, || Ok(write_csv(&csv, run)?));
    if run.view.is_some() {
        let glare = named(".annual-glare.csv");
        writes.attempt(&glare, || Ok(write_glare_csv(&glare, run)?));
    }
    if run.coefficients.is_some() {
        let (sky, sun) = (named(".annual-sky-dc.csv"), named(".annual-sun-dc.csv"));
        writes.attempt(&sky, || Ok(write_sky_coefficients(&sky, run)?));
        writes.attempt(&sun, || Ok(write_sun_coefficients(&sun, run)?));
    }
    write_heatmaps(stem, run, &mut writes);
    let written = std::mem::take(&mut writes.written);
    writes.finish()?;
    Ok(written)
}
