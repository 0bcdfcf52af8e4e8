//! The sky distributions against Radiance 6 (PyPI `pyradiance`): `gensky -c` (traditional CIE
//! overcast), `gensky -s` (CIE clear sky, = standard general sky 12 to 2e-4) and `gendaylit`
//! (Perez all-weather sky, one case per clearness bin). Radiance evaluates its own sky
//! function (`rtrace -ab 0` looking at a glow source), candela its distribution, both
//! divided by their zenith value; they must agree within 0.5 % in every direction tested.
//! Directions lie at cos Z ≥ 0.45, where Radiance's blend of sky and ground,
//! weights (cos Z + 1.01)^±10, moves the sky by less than 0.05 %. The Perez clearness ε and
//! brightness Δ that gendaylit prints must match candela's to its four decimals.

mod common;
use common::{python, python_json};

use candela::daylight::{angle_to_sun, CieSky, PerezSky, SkyCondition};
use serde_json::{json, Value};
use std::path::PathBuf;
use std::process::Command;

fn radiance(cases: &Value) -> Vec<Value> {
    match python_json("daylight/radiance_sky.py", &[], Some(cases)) {
        Value::Array(v) => v,
        other => panic!("radiance_sky.py printed {other}"),
    }
}

/// Directions (Radiance frame: x east, y north, z up) at cos Z ≥ 0.45, around the sky and
/// near the sun.
fn directions(sun: [f64; 3]) -> Vec<[f64; 3]> {
    let mut d = vec![[0.0, 0.0, 1.0]];
    for cz in [0.45, 0.6, 0.75, 0.9, 0.97] {
        let sz = (1.0f64 - cz * cz).sqrt();
        for k in 0..12 {
            let phi = (k as f64 * 30.0 + 7.0).to_radians();
            d.push([sz * phi.cos(), sz * phi.sin(), cz]);
        }
    }
    // Near the sun (its own direction excluded: gensky -s and gendaylit -s draw no disk).
    let up = [0.0, 0.0, 1.0];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let mut t = cross(sun, up);
    let n = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
    t = t.map(|v| v / n);
    for g in [1.0f64, 3.0, 8.0, 20.0] {
        let (c, s) = (g.to_radians().cos(), g.to_radians().sin());
        d.push([0, 1, 2].map(|i| c * sun[i] + s * t[i]));
    }
    d.retain(|v| v[2] >= 0.45);
    d
}

/// Sun direction in Radiance's frame for altitude `alt` and azimuth `az_south_west` (degrees
/// west of south, Radiance's convention).
fn sun_dir(alt: f64, az_south_west: f64) -> [f64; 3] {
    let (a, z) = (alt.to_radians(), az_south_west.to_radians());
    [-z.sin() * a.cos(), -z.cos() * a.cos(), a.sin()]
}

fn compare(
    name: &str,
    dirs: &[[f64; 3]],
    sun: [f64; 3],
    peer: &[f64],
    ours: impl Fn(f64, f64) -> f64,
) {
    assert_eq!(
        peer.len(),
        dirs.len(),
        "{name}: rtrace returned {} values",
        peer.len()
    );
    let sun_zenith = sun[2].acos();
    let rel = |d: &[f64; 3]| {
        let cos_gamma = d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2];
        ours(d[2], cos_gamma.clamp(-1.0, 1.0).acos())
    };
    let (z_ours, z_peer) = (rel(&dirs[0]), peer[0]);
    let mut worst = 0.0f64;
    for (d, &p) in dirs.iter().zip(peer) {
        let r = (rel(d) / z_ours) / (p / z_peer) - 1.0;
        worst = worst.max(r.abs());
        assert!(
            r.abs() < 5e-3,
            "{name}: direction {d:?}: candela L/Lz {} against Radiance {} ({:+.3} %)",
            rel(d) / z_ours,
            p / z_peer,
            100.0 * r
        );
    }
    // The helper's γ must be the same angle.
    let g = angle_to_sun(dirs[1][2], 0.0, sun_zenith);
    assert!(g.is_finite());
    println!(
        "{name}: {} directions, largest difference {:.4} %",
        dirs.len(),
        100.0 * worst
    );
}

#[test]
fn cie_skies_against_gensky() {
    let (alt, az) = (35.0, 20.0);
    let sun = sun_dir(alt, az);
    let dirs = directions(sun);
    let cases = json!([
        {"tool": "gensky", "args": ["-ang", alt.to_string(), az.to_string(), "-c"], "dirs": dirs},
        {"tool": "gensky", "args": ["-ang", alt.to_string(), az.to_string(), "-s"], "dirs": dirs},
    ]);
    let out = radiance(&cases);
    let values = |i: usize| -> Vec<f64> {
        out[i]["values"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let zs = sun[2].acos();
    compare(
        "gensky -c / CIE overcast",
        &dirs,
        sun,
        &values(0),
        |cz, g| CieSky::Overcast.relative_luminance(cz, g, zs),
    );
    compare("gensky -s / CIE clear", &dirs, sun, &values(1), |cz, g| {
        CieSky::Clear.relative_luminance(cz, g, zs)
    });
    let t12 = CieSky::general(12).unwrap();
    compare(
        "gensky -s / CIE general sky 12",
        &dirs,
        sun,
        &values(1),
        |cz, g| t12.relative_luminance(cz, g, zs),
    );
}

#[test]
fn perez_sky_against_gendaylit() {
    // (altitude, azimuth west of south, direct normal W/m², diffuse horizontal W/m²): from
    // overcast (ε = 1) through every clearness bin to a clear sky.
    let conditions = [
        (30.0, -40.0, 0.0, 150.0),
        (50.0, 60.0, 60.0, 250.0),
        (45.0, 10.0, 105.0, 200.0),
        (45.0, -80.0, 210.0, 200.0),
        (60.0, 0.0, 300.0, 220.0),
        (45.0, 30.0, 450.0, 180.0),
        (35.0, -20.0, 650.0, 130.0),
        (45.0, 45.0, 647.0, 100.0),
        (55.0, 45.0, 850.0, 90.0),
    ];
    let mut cases = Vec::new();
    for &(alt, az, dni, dhi) in &conditions {
        let dirs = directions(sun_dir(alt, az));
        cases.push(json!({"tool": "gendaylit",
            "args": ["-ang", alt.to_string(), az.to_string(), "-W", dni.to_string(), dhi.to_string(), "-s"],
            "dirs": dirs}));
    }
    let out = radiance(&Value::Array(cases.clone()));
    let mut bins = std::collections::BTreeSet::new();
    for ((&(alt, az, dni, dhi), case), res) in conditions.iter().zip(&cases).zip(&out) {
        let sun = sun_dir(alt, az);
        let zs = sun[2].acos();
        // gendaylit -ang leaves the day number at 0.
        let cond = SkyCondition::from_irradiance(
            dhi,
            dni,
            zs,
            candela::daylight::perez::eccentricity(0.0),
        )
        .unwrap();
        let header: Vec<&str> = res["header"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap())
            .collect();
        let line = header
            .iter()
            .find(|l| l.contains("epsilon"))
            .expect("gendaylit prints epsilon and delta");
        let nums: Vec<f64> = line
            .split(':')
            .nth(1)
            .unwrap()
            .split_whitespace()
            .map(|s| s.parse().unwrap())
            .collect();
        assert!(
            (nums[0] - cond.clearness).abs() < 6e-5 && (nums[1] - cond.brightness).abs() < 6e-5,
            "ε, Δ: gendaylit {nums:?}, candela {} {}",
            cond.clearness,
            cond.brightness
        );
        bins.insert(perez_bin(cond.clearness));
        let sky = PerezSky::new(cond);
        let dirs: Vec<[f64; 3]> = serde_json::from_value(case["dirs"].clone()).unwrap();
        let values: Vec<f64> = res["values"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        compare(
            &format!(
                "gendaylit ε = {:.3}, Δ = {:.3}",
                cond.clearness, cond.brightness
            ),
            &dirs,
            sun,
            &values,
            |cz, g| sky.relative_luminance(cz, g),
        );
    }
    assert_eq!(
        bins.len(),
        8,
        "the cases cover every clearness bin: {bins:?}"
    );
}

fn perez_bin(e: f64) -> usize {
    candela::daylight::perez::CLEARNESS_BINS
        .iter()
        .rposition(|&lo| e >= lo)
        .unwrap()
}

/// The EPW reader against ladybug-core: a year written by ladybug, read by both. Hourly sums
/// (irradiance, illuminance) are labelled by ladybug with the start of their hour, which
/// [`Weather::at`] takes; point-in-time values (the dew point) with their instant, the end of
/// the record's hour.
#[test]
fn epw_reader_against_ladybug() {
    use candela::daylight::epw::Weather;
    let dir = tempfile::tempdir().unwrap();
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/daylight/epw_ladybug.py");
    let out = Command::new(python())
        .arg(script)
        .arg(dir.path())
        .output()
        .expect("run python");
    assert!(
        out.status.success(),
        "epw_ladybug.py: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lb: Value = serde_json::from_slice(&out.stdout).unwrap();
    let w = Weather::read(std::path::Path::new(lb["path"].as_str().unwrap())).unwrap();
    assert_eq!(w.records.len(), 8760);
    assert_eq!(w.site.latitude_deg, lb["latitude"].as_f64().unwrap());
    assert_eq!(w.site.longitude_deg, lb["longitude"].as_f64().unwrap());
    assert_eq!(w.site.time_zone_h, lb["time_zone"].as_f64().unwrap());
    assert_eq!(w.site.elevation_m, lb["elevation"].as_f64().unwrap());
    type Get = fn(&candela::daylight::epw::Record) -> Option<f64>;
    let summed: [(&str, Get); 4] = [
        ("direct_normal_radiation", |r| Some(r.direct_normal_w_m2)),
        ("diffuse_horizontal_radiation", |r| {
            Some(r.diffuse_horizontal_w_m2)
        }),
        ("direct_normal_illuminance", |r| r.direct_normal_lx),
        ("diffuse_horizontal_illuminance", |r| {
            r.diffuse_horizontal_lx
        }),
    ];
    let mut compared = 0;
    for (name, get) in summed {
        for row in lb["fields"][name].as_array().unwrap() {
            let v: Vec<f64> = row
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect();
            let r = w
                .at(v[0] as u32, v[1] as u32, v[2] as u32, 0)
                .expect("record");
            assert_eq!(get(r), Some(v[3]), "{name} at {v:?}");
            compared += 1;
        }
    }
    for row in lb["fields"]["dew_point_temperature"].as_array().unwrap() {
        let v: Vec<f64> = row
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        if v[2] == 0.0 {
            continue; // the previous day's hour 24
        }
        let r = w
            .records
            .iter()
            .find(|r| r.month == v[0] as u32 && r.day == v[1] as u32 && r.hour == v[2] as u32)
            .unwrap();
        assert_eq!(r.dew_point_c, Some(v[3]), "dew point at {v:?}");
        compared += 1;
    }
    println!("EPW: {compared} values agree with ladybug-core");
}

/// Sky vectors over Reinhart's patches against `gendaymtx -s` (Radiance 6), for five hours of
/// the same weather (W/m²) at the same place, each step's sun where gendaymtx puts it.
/// gendaymtx gives each patch the Perez luminance at its centre, normalised so that the
/// patches' Σ L cos Z ω is the diffuse-horizontal illuminance; candela gives the patch's mean
/// luminance. Centre values computed from candela's Perez sky in the same way must match
/// gendaymtx within 0.01 % on every patch (it writes 32-bit floats); the patch means differ
/// from them by the variation of the distribution across a patch (rms 2.0 % at MF 1, 0.5 % at
/// MF 2), and the ground patch is ρ_g E_h / π in both.
#[test]
fn sky_vectors_against_gendaymtx() {
    use candela::daylight::patches::{SkyPatches, SkyVector};
    let steps = [
        (6, 21, 10.5, 620.0, 110.0),
        (12, 21, 12.0, 40.0, 160.0),
        (3, 21, 8.5, 300.0, 80.0),
        (9, 21, 15.5, 0.0, 210.0),
        (7, 10, 19.0, 150.0, 45.0),
    ];
    for mf in [1u32, 2] {
        let case = json!({"site": [45.76, -4.84, -15.0], "mf": mf,
            "steps": steps.iter().map(|s| json!([s.0, s.1, s.2, s.3, s.4])).collect::<Vec<_>>()});
        let r = python_json("daylight/gendaymtx.py", &[], Some(&case));
        let patches = SkyPatches::new(mf).unwrap();
        let suns = r["suns"].as_array().unwrap();
        assert_eq!(suns.len(), steps.len());
        let (mut worst_centre, mut worst_mean, mut rms_mean) = (0.0f64, 0.0f64, 0.0f64);
        for (t, s) in steps.iter().enumerate() {
            let sun: Vec<f64> = suns[t]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            let sun = [sun[0], sun[1], sun[2]];
            let day = [0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334][s.0 - 1] + s.1;
            let ecc = candela::daylight::perez::eccentricity(day as f64);
            let v = SkyVector::perez(&patches, s.4, s.3, sun, ecc, 11.0, 0.2).unwrap();
            let theirs: Vec<f64> = r["luminance"][t]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            assert_eq!(theirs.len(), patches.len());
            // Ground.
            let g = (v.luminance_cd_m2[0] - theirs[0]).abs() / theirs[0];
            assert!(
                g < 5e-3,
                "MF {mf}, step {t}: ground {} vs {}",
                v.luminance_cd_m2[0],
                theirs[0]
            );
            // Centre values, gendaymtx's way, from candela's Perez sky.
            let zenith = sun[2]
                .max(0.0)
                .acos()
                .clamp(3f64.to_radians(), std::f64::consts::FRAC_PI_2 - 1e-9);
            let (cond, _, e_vd) = SkyCondition::illuminance_from_irradiance(
                s.4,
                if sun[2] > 0.0 { s.3 } else { 0.0 },
                zenith,
                candela::daylight::perez::eccentricity(day as f64),
                11.0,
            )
            .unwrap();
            let sky = PerezSky::new(cond);
            let h = sun[0].hypot(sun[1]);
            let sd = [
                zenith.sin() * sun[0] / h,
                zenith.sin() * sun[1] / h,
                zenith.cos(),
            ];
            let centre: Vec<f64> = (1..patches.len())
                .map(|i| {
                    let c = patches.patch(i).unwrap().centre();
                    let g = (c[0] * sd[0] + c[1] * sd[1] + c[2] * sd[2])
                        .clamp(-1.0, 1.0)
                        .acos();
                    sky.relative_luminance(c[2], g)
                })
                .collect();
            let norm: f64 = (1..patches.len())
                .map(|i| {
                    let p = patches.patch(i).unwrap();
                    centre[i - 1] * p.centre()[2] * p.solid_angle_sr
                })
                .sum();
            for i in 1..patches.len() {
                let ours_c = centre[i - 1] * e_vd / norm;
                let dc = (ours_c - theirs[i]).abs() / theirs[i];
                let dm = (v.luminance_cd_m2[i] - theirs[i]).abs() / theirs[i];
                worst_centre = worst_centre.max(dc);
                worst_mean = worst_mean.max(dm);
                rms_mean += dm * dm;
            }
        }
        rms_mean = (rms_mean / (steps.len() * (patches.len() - 1)) as f64).sqrt();
        println!(
            "gendaymtx MF {mf}: centre values within {:.1e} %, patch means within {:.2} % \
             (rms {:.2} %)",
            100.0 * worst_centre,
            100.0 * worst_mean,
            100.0 * rms_mean
        );
        assert!(worst_centre < 1e-4, "MF {mf}: centre values {worst_centre}");
        // The patch means' departure from the centre values shrinks with the patches.
        let bound = if mf == 1 { 0.03 } else { 0.008 };
        assert!(rms_mean < bound, "MF {mf}: patch means rms {rms_mean}");
    }
}
