//! `candela annual` from the command line: a year on the shoebox office, its JSON report
//! consistent with its own hourly CSV (DA, UDI and sDA recomputed from the CSV's hours agree
//! exactly; ASE agrees with the points' sun hours), and bad input refused with a message.

mod common;
use common::cli;
use common::weather::synthetic_year;
use std::path::{Path, PathBuf};

fn scene() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/annual-shoebox.ron")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-annual-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn a_year_on_the_shoebox_is_consistent_with_its_hourly_csv() {
    let dir = tmp("year");
    let epw = dir.join("year.epw");
    synthetic_year(&epw);
    let scene = scene();
    let (code, out, err) = cli(
        &[
            "annual",
            scene.to_str().unwrap(),
            "--weather",
            epw.to_str().unwrap(),
            "--out",
            dir.join("sb").to_str().unwrap(),
            "--mf",
            "1",
            "--sky-samples",
            "512",
            "--sun-samples",
            "256",
            "--direct-samples",
            "16",
            "--draws",
            "20",
            "--coefficients",
            "-q",
        ],
        &dir,
    );
    assert_eq!(code, 0, "{out}\n{err}");
    println!("{out}");
    assert!(out.contains("sDA 300 lx / 50 %") && out.contains("ASE 1000 lx, 250 h"));
    sky_coefficients_sum_to_a_uniform_sky(&dir, &scene);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("sb.annual.json")).unwrap())
            .unwrap();
    let g = &json["grids"][0];
    let points = g["points"].as_array().unwrap();
    assert_eq!(points.len(), 35);
    assert_eq!(json["occupied"]["hours"], 3650);
    for key in ["da", "udi", "sun-hours"] {
        let png = dir.join(format!("sb.annual.grid-work-plane.{key}.png"));
        let img = image::open(&png).unwrap_or_else(|e| panic!("{}: {e}", png.display()));
        assert!(img.width() > 300 && img.height() > 300);
    }

    // The CSV: month, day, hour, then (E, se, direct sun) per point, for every daylight hour.
    let csv = std::fs::read_to_string(dir.join("sb.annual.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.len(), 3 + 3 * 35);
    assert_eq!(header[3], "work plane[0;0]_lx");
    let mut da = [0usize; 35];
    let mut udi = [[0usize; 3]; 35];
    let mut rows = 0;
    for line in lines {
        rows += 1;
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let hour = v[2] as usize;
        // Occupied 8:00–18:00: records of hours 9 … 18.
        if !(9..=18).contains(&hour) {
            continue;
        }
        for p in 0..35 {
            let e = v[3 + 3 * p];
            assert!(v[4 + 3 * p] >= 0.0);
            assert!(v[5 + 3 * p] >= 0.0 && v[5 + 3 * p] <= e + 1e-6);
            if e >= 300.0 {
                da[p] += 1;
            }
            udi[p][if e < 100.0 {
                0
            } else if e <= 3000.0 {
                1
            } else {
                2
            }] += 1;
        }
    }
    assert!(rows > 4000 && rows < 5000, "{rows} daylight hours");
    let mut sda = 0;
    for (p, pt) in points.iter().enumerate() {
        // The CSV holds 6 decimals: the counts agree unless an hour sits within 10⁻⁶ lx of a
        // threshold.
        let d = pt["da"]["value"].as_f64().unwrap();
        assert!(
            (d - da[p] as f64 / 3650.0).abs() < 0.5 / 3650.0,
            "point {p}: {d} vs {}",
            da[p]
        );
        let u = pt["udi_useful"]["value"].as_f64().unwrap();
        assert!(
            (u - udi[p][1] as f64 / 3650.0).abs() < 0.5 / 3650.0,
            "point {p}"
        );
        let ci = pt["da"]["ci95"].as_array().unwrap();
        assert!(ci[0].as_f64().unwrap() <= d + 1e-12 && d <= ci[1].as_f64().unwrap() + 1e-12);
        sda += (d >= 0.5) as usize;
    }
    assert_eq!(g["sda"]["value"].as_f64().unwrap(), sda as f64 / 35.0);
    let ase = points
        .iter()
        .filter(|p| p["sun_hours"]["value"].as_f64().unwrap() > 250.0)
        .count();
    assert_eq!(g["ase"]["value"].as_f64().unwrap(), ase as f64 / 35.0);
    // The window row sees the sun for hundreds of hours; the back of the room never.
    assert!(ase > 0 && ase < 35, "ASE {ase} of 35");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The sky coefficients of NAME.annual-sky-dc.csv: their sum over the patches (ground
/// included) is the illuminance under a sky of 1 cd/m² everywhere with a ground of 1 cd/m²
/// (a uniform sky over a white ground: ρ E_h / π = 1), which a direct render of the scene under
/// that sky measures. The sum's standard error is taken as √Σ se², an upper bound here (a path
/// credits one patch or another, so the patches' errors are not positively correlated).
fn sky_coefficients_sum_to_a_uniform_sky(dir: &Path, scene: &Path) {
    let text = std::fs::read_to_string(dir.join("sb.annual-sky-dc.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "grid,i,j,patch,altitude_deg,azimuth_deg,solid_angle_sr,lx_per_cd_m2,stderr_lx_per_cd_m2"
    );
    let mut sum = [[0.0f64; 2]; 35];
    let mut omega = 0.0;
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let (i, j): (usize, usize) = (f[1].parse().unwrap(), f[2].parse().unwrap());
        let (c, se): (f64, f64) = (f[7].parse().unwrap(), f[8].parse().unwrap());
        assert!(c >= 0.0 && se >= 0.0, "{line}");
        sum[j * 5 + i][0] += c;
        sum[j * 5 + i][1] += se * se;
        if i == 0 && j == 0 && f[3] != "0" {
            omega += f[6].parse::<f64>().unwrap();
        }
    }
    // MF 1: 145 sky patches covering the hemisphere.
    assert!((omega - 2.0 * std::f64::consts::PI).abs() < 1e-6, "{omega}");
    let uniform = dir.join("uniform.ron");
    let text = std::fs::read_to_string(scene).unwrap();
    let a = text.find("Sky(model: CieOvercast").unwrap();
    let b = a + text[a..].find("portals").unwrap();
    std::fs::write(
        &uniform,
        format!(
            "{}Sky(model: Uniform, amount: ZenithLuminance(1.0), ground_reflectance: 1.0, {}",
            &text[..a],
            &text[b..]
        ),
    )
    .unwrap();
    let (code, out, err) = cli(
        &[
            "render",
            uniform.to_str().unwrap(),
            "--out",
            dir.join("u").to_str().unwrap(),
            "--spp",
            "1",
            "--quiet",
        ],
        dir,
    );
    assert_eq!(code, 0, "{out}\n{err}");
    let grid = std::fs::read_to_string(dir.join("u.grid-work-plane.csv")).unwrap();
    let mut worst = 0.0f64;
    for line in grid
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with('i'))
    {
        let f: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let (i, j, e, se) = (f[0] as usize, f[1] as usize, f[5], f[6]);
        let [c, v] = sum[j * 5 + i];
        let z = (c - e) / (v + se * se).sqrt();
        worst = worst.max(z.abs());
        assert!(
            z.abs() < 4.0,
            "point ({i}, {j}): coefficients {c} ± {}, render {e} ± {se}",
            v.sqrt()
        );
    }
    println!("sky coefficients against a uniform sky: worst {worst:.2} σ");
}

/// The view's annual glare (`--view`) on scenes/annual-glare.ron: the hourly CSV holds every
/// occupied hour with daylight, and the JSON's fractions of hours above the DGP limits and the
/// DGP exceeded in 5 % of the occupied hours follow from it (the dark occupied hours count as
/// without glare).
#[test]
fn a_year_of_glare_on_the_view_is_consistent_with_its_csv() {
    let dir = tmp("view");
    let epw = dir.join("year.epw");
    synthetic_year(&epw);
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/annual-glare.ron");
    let (code, out, err) = cli(
        &[
            "annual",
            scene.to_str().unwrap(),
            "--weather",
            epw.to_str().unwrap(),
            "--out",
            dir.join("g").to_str().unwrap(),
            "--mf",
            "1",
            "--sky-samples",
            "128",
            "--sun-samples",
            "64",
            "--direct-samples",
            "4",
            "--view",
            "--view-resolution",
            "24",
            "--view-sky-samples",
            "64",
            "--view-sun-samples",
            "16",
            "--draws",
            "20",
            "-q",
        ],
        &dir,
    );
    assert_eq!(code, 0, "{out}\n{err}");
    println!("{out}");
    assert!(out.contains("DGP ≥ 0.40 (disturbing)"), "{out}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("g.annual.json")).unwrap()).unwrap();
    let v = &json["view"];
    assert_eq!(v["width"], 24);
    let csv = std::fs::read_to_string(dir.join("g.annual-glare.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "month,day,hour,dgp,ev_lx,ev_stderr_lx,ev_sun_disk_lx,sources"
    );
    let mut dgps = Vec::new();
    let mut disk_hours = 0;
    for line in lines {
        let f: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        assert!((9.0..=18.0).contains(&f[2]), "{line}");
        assert!(
            (0.0..=1.0).contains(&f[3]) && f[4] > 0.0 && f[5] >= 0.0,
            "{line}"
        );
        assert!(f[6] >= 0.0 && f[6] <= f[4], "{line}");
        if f[6] > 0.0 {
            disk_hours += 1;
            // The sun's disk in view (thousands of cd/m² over a pixel) is a glare source.
            assert!(f[7] >= 1.0, "{line}");
        }
        dgps.push(f[3]);
    }
    let occupied = 3650.0;
    assert!(dgps.len() > 3000 && dgps.len() <= 3650, "{}", dgps.len());
    // The south window faces the eye: the low winter sun is in view for some hours.
    assert!(disk_hours > 20, "{disk_hours} hours with the sun in view");
    for (k, limit) in [0.35, 0.40, 0.45].iter().enumerate() {
        let n = dgps.iter().filter(|&&d| d >= *limit).count() as f64;
        let j = v["hours_dgp_at_least"][k]["value"].as_f64().unwrap();
        // The CSV holds 6 decimals.
        assert!(
            (j - n / occupied).abs() <= 0.5 / occupied,
            "DGP ≥ {limit}: {j} vs {n}"
        );
    }
    dgps.sort_by(|a, b| b.total_cmp(a));
    let p95 = dgps[(0.05 * occupied) as usize];
    let j = v["dgp_5_percent"]["value"].as_f64().unwrap();
    assert!((j - p95).abs() < 1e-6, "{j} vs {p95}");
    let ci = v["dgp_5_percent"]["ci95"].as_array().unwrap();
    assert!(ci[0].as_f64().unwrap() <= j + 1e-12 && j <= ci[1].as_f64().unwrap() + 1e-12);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_input_is_refused_with_a_message() {
    let dir = tmp("bad");
    let scene = scene();
    let s = scene.to_str().unwrap();
    let excerpt = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/lyon-excerpt.epw");
    let out = dir.join("o");
    let o = out.to_str().unwrap();
    let cases: Vec<(Vec<&str>, i32, &str)> = vec![
        (vec!["annual", s, "--out", o], 1, "no weather file"),
        (
            vec![
                "annual",
                s,
                "--weather",
                excerpt.to_str().unwrap(),
                "--out",
                o,
            ],
            1,
            "one whole calendar year of hourly records (8760, or 8784 with 29 February, from 01-01 hour 1 to 12-31 hour 24); the file has 48, from 06-21 hour 1 (line 9)",
        ),
        (
            vec!["annual", s, "--weather", "/nonexistent/x.epw", "--out", o],
            1,
            "/nonexistent/x.epw",
        ),
        (
            vec!["annual", s, "--weather", "w.epw", "--mf", "9"],
            2,
            "--mf",
        ),
        (
            vec!["annual", s, "--weather", "w.epw", "--occupied", "18-8"],
            2,
            "--occupied",
        ),
        (
            vec!["annual", s, "--weather", "w.epw", "--udi", "x-3"],
            2,
            "--udi",
        ),
        (
            vec!["annual", s, "--weather", "w.epw", "--draws", "1"],
            2,
            "--draws",
        ),
        (
            vec!["annual", s, "--weather", "w.epw", "--da", "nan"],
            2,
            "--da",
        ),
        (
            vec!["annual", s, "--weather", "w.epw", "--view-resolution", "4"],
            2,
            "--view-resolution",
        ),
        (
            vec![
                "annual",
                s,
                "--weather",
                "w.epw",
                "--view",
                "--view-resolution",
                "18446744073709551615",
            ],
            2,
            "--view-resolution",
        ),
        (
            vec!["annual", s, "--weather", "w.epw", "--sky-samples", "0"],
            2,
            "--sky-samples",
        ),
        (
            vec![
                "annual",
                s,
                "--weather",
                "w.epw",
                "--out",
                "/nonexistent-dir/x",
            ],
            1,
            "nonexistent-dir",
        ),
    ];
    for (args, want, msg) in cases {
        let (code, stdout, err) = cli(&args, &dir);
        assert_eq!(code, want, "{args:?}: {stdout}\n{err}");
        assert!(err.contains(msg), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    // A scene without grids.
    let no_grid = dir.join("nogrid.ron");
    std::fs::write(
        &no_grid,
        "(camera: (position: (0, 1, 0), look_at: (0, 1, 1), vfov_deg: 30, resolution: (1, 1)))",
    )
    .unwrap();
    let epw = dir.join("year.epw");
    synthetic_year(&epw);
    let (code, _, err) = cli(
        &[
            "annual",
            no_grid.to_str().unwrap(),
            "--weather",
            epw.to_str().unwrap(),
        ],
        &dir,
    );
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("grids"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// On a file system too small for the hourly CSV, `annual` refuses before computing, naming
/// the directory and the sizes (a 64 kB tmpfs: the shoebox's CSV alone takes megabytes). Needs
/// root to mount; elsewhere the test says so and checks nothing.
#[test]
fn annual_refuses_a_disk_without_room_before_computing() {
    let dir = tmp("full");
    let epw = dir.join("year.epw");
    synthetic_year(&epw);
    let small = dir.join("small");
    std::fs::create_dir_all(&small).unwrap();
    let mounted = std::process::Command::new("mount")
        .args(["-t", "tmpfs", "-o", "size=64k", "tmpfs"])
        .arg(&small)
        .status()
        .is_ok_and(|s| s.success());
    if !mounted {
        println!("SKIPPED: cannot mount a tmpfs here (not root?)");
        return;
    }
    let t = std::time::Instant::now();
    let (code, _, err) = cli(
        &[
            "annual",
            scene().to_str().unwrap(),
            "--weather",
            epw.to_str().unwrap(),
            "--out",
            small.join("sb").to_str().unwrap(),
            "--mf",
            "1",
            "-q",
        ],
        &dir,
    );
    let secs = t.elapsed().as_secs_f64();
    let listing: Vec<_> = std::fs::read_dir(&small).unwrap().collect();
    let _ = std::process::Command::new("umount").arg(&small).status();
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("not enough free disk space in")
            && err.contains("small")
            && err.contains("free"),
        "{err}"
    );
    assert!(listing.is_empty(), "nothing written");
    // Refused before the sky coefficients (4096 paths per point by default).
    assert!(secs < 20.0, "{secs} s");
}

/// Every output of `annual` is attempted when one fails: with the hourly CSV's and one heat
/// map's paths taken by directories after the computation, the report, the glare-free rest
/// and the other heat maps are written, and the error lists the two that were not.
#[test]
fn annual_attempts_every_output() {
    use candela::annual::{output, run};
    let dir = tmp("writes");
    let epw = dir.join("year.epw");
    synthetic_year(&epw);
    let settings = run::AnnualSettings {
        weather: Some(epw),
        mf: 1,
        sky_samples: 256,
        sun_samples: 128,
        direct_samples: 8,
        draws: 0,
        ..Default::default()
    };
    let r = run::run(&scene(), &settings, &mut |_, _, _| {}).unwrap();
    let stem = dir.join("sb");
    std::fs::create_dir(dir.join("sb.annual.csv")).unwrap();
    let grid = candela::world::measure::slug(&r.grids[0].name);
    let blocked = format!("sb.annual.grid-{grid}.udi.png");
    std::fs::create_dir(dir.join(&blocked)).unwrap();
    let e = output::write_all(&stem, &r).unwrap_err();
    let msg = format!("{e:#}");
    assert!(msg.starts_with("2 files could not be written"), "{msg}");
    assert!(
        msg.contains("sb.annual.csv") && msg.contains(&blocked),
        "{msg}"
    );
    for f in [
        "sb.annual.json".to_string(),
        format!("sb.annual.grid-{grid}.da.png"),
        format!("sb.annual.grid-{grid}.sun-hours.png"),
    ] {
        assert!(dir.join(&f).is_file(), "{f} missing: {msg}");
    }
}
