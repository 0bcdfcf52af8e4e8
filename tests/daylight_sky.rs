//! Skies and the sun as lights, against closed forms (closed-forms.md §2.7, §2.4):
//! - every sky's unobstructed horizontal illuminance equals its stated amount (the CIE 15
//!   general skies, the traditional overcast, uniform and clear skies; Perez skies, whose
//!   amount is their diffuse-horizontal illuminance), and a zenith-luminance amount is the
//!   luminance seen at the zenith;
//! - the ground below the horizon has luminance ρ_g E_h / π, E_h from sky and sun together;
//! - the sun: a surface facing it receives its normal illuminance, one tilted by θ that times
//!   cos θ, and its disk's luminance is E_n / Ω;
//! - through a roof opening of a black room, a horizontal meter reads π L F under the uniform
//!   sky (F the configuration factor of the opening) and the integral of L(Z) cos Z dω over
//!   the opening under the traditional overcast sky.
//!
//! Meter tolerances are their calibrated standard errors (common::assert_estimate_near).

mod common;
use candela::meter::measure_all;
use common::{assert_estimate_near, world};
use std::f64::consts::PI;

const CAMERA: &str =
    "camera: (position: (0, 1, 0), look_at: (0, 1, 1), vfov_deg: 30, resolution: (1, 1))";

/// Meter readings (mean, stderr) of a scene with `lights`, `objects` and `meters`.
fn measure(lights: &str, objects: &str, meters: &str, samples: u64) -> Vec<(f64, f64)> {
    let w = world(&format!(
        "({CAMERA}, objects: [{objects}], lights: [{lights}], meters: [{meters}], measure: (samples: {samples}))"
    ));
    measure_all(&w)
        .meters
        .iter()
        .map(|e| (e.mean, e.stderr))
        .collect()
}

const UP_METER: &str = r#"Illuminance(name: "up", position: (0, 0, 0), normal: (0, 1, 0))"#;

#[test]
fn every_sky_gives_its_horizontal_illuminance() {
    let sun = "sun: (altitude_deg: 40.0, azimuth_deg: 200.0)";
    let mut models: Vec<String> = (1..=15).map(|k| format!("CieGeneral({k})")).collect();
    models.extend(["CieOvercast".into(), "Uniform".into(), "CieClear".into()]);
    for m in &models {
        let sky = format!("Sky(model: {m}, {sun}, amount: HorizontalIlluminance(10000.0))");
        let r = measure(&sky, "", UP_METER, 4096);
        assert_estimate_near(r[0].0, r[0].1, 10_000.0, 0.01, m);
    }
    // Perez skies: the diffuse-horizontal illuminance, and with the sun's disk the direct
    // part on the horizontal, E_n sin(altitude), beside it.
    for (dn, dh) in [(0.0, 18_000.0), (30_000.0, 25_000.0), (80_000.0, 12_000.0)] {
        let perez = format!("Perez(direct_normal_lx: {dn}, diffuse_horizontal_lx: {dh})");
        let sky = format!("Sky(model: {perez}, {sun}, sun_disk: false)");
        let r = measure(&sky, "", UP_METER, 4096);
        assert_estimate_near(r[0].0, r[0].1, dh, 0.01, &perez);
        let sky = format!("Sky(model: {perez}, {sun})");
        let r = measure(&sky, "", UP_METER, 4096);
        let expected = dh + dn * 40f64.to_radians().sin();
        assert_estimate_near(
            r[0].0,
            r[0].1,
            expected,
            0.01,
            &format!("{perez} with its sun"),
        );
    }
}

#[test]
fn zenith_luminance_is_seen_at_the_zenith() {
    let meter = r#"Luminance(name: "zenith", position: (0, 0, 0), direction: (0, 1, 0))"#;
    for m in ["CieGeneral(3)", "CieGeneral(12)", "CieOvercast"] {
        let sky = format!(
            "Sky(model: {m}, sun: (altitude_deg: 30.0, azimuth_deg: 90.0), amount: ZenithLuminance(2500.0))"
        );
        let r = measure(&sky, "", meter, 256);
        assert_estimate_near(r[0].0, r[0].1.max(1e-9), 2500.0, 0.01, m);
    }
}

#[test]
fn ground_reflects_sky_and_sun() {
    // A meter facing down in open space sees only the ground: E = π L_g = ρ_g (E_sky + E_sun).
    let down = r#"Illuminance(name: "down", position: (0, 0, 0), normal: (0, -1, 0))"#;
    let lights = "Sky(model: CieGeneral(12), sun: (altitude_deg: 30.0, azimuth_deg: 135.0), \
                  amount: HorizontalIlluminance(15000.0), ground_reflectance: 0.3), \
                  Sun(sun: (altitude_deg: 30.0, azimuth_deg: 135.0), amount: NormalIlluminance(50000.0))";
    let r = measure(lights, "", &format!("{UP_METER}, {down}"), 4096);
    let e_sun_h = 50_000.0 * 30f64.to_radians().sin();
    assert_estimate_near(r[0].0, r[0].1, 15_000.0 + e_sun_h, 0.01, "up");
    assert_estimate_near(r[1].0, r[1].1, 0.3 * (15_000.0 + e_sun_h), 0.01, "down");
    // The default ground reflectance is 0.2.
    let r = measure(
        "Sky(model: Uniform, amount: HorizontalIlluminance(8000.0))",
        "",
        down,
        1024,
    );
    assert_estimate_near(r[0].0, r[0].1, 0.2 * 8000.0, 0.01, "default ground");
}

#[test]
fn sun_normal_illuminance_cosine_and_disk_luminance() {
    // The sun at altitude 35°, azimuth 250° (west-south-west); the site's default frame has
    // +y up and north −z, so east is +x.
    let (alt, az) = (35f64.to_radians(), 250f64.to_radians());
    let to_sun = [alt.cos() * az.sin(), alt.sin(), -alt.cos() * az.cos()];
    let e_n = 90_000.0;
    let sun = format!(
        "Sun(sun: (altitude_deg: 35.0, azimuth_deg: 250.0), amount: NormalIlluminance({e_n}))"
    );
    // A tilted receiver: 50° from the sun in the sun's vertical plane.
    let tilt = (35.0f64 + 50.0).to_radians();
    let n_tilt = [tilt.cos() * az.sin(), tilt.sin(), -tilt.cos() * az.cos()];
    let omega = candela::daylight::sun::sun_solid_angle_sr();
    let meters = format!(
        r#"Illuminance(name: "facing", position: (0, 0, 0), normal: ({}, {}, {})),
           Illuminance(name: "tilted", position: (0, 0, 0), normal: ({}, {}, {})),
           Luminance(name: "disk", position: (0, 0, 0), direction: ({}, {}, {}), half_angle_deg: 0.1)"#,
        to_sun[0],
        to_sun[1],
        to_sun[2],
        n_tilt[0],
        n_tilt[1],
        n_tilt[2],
        to_sun[0],
        to_sun[1],
        to_sun[2]
    );
    let r = measure(&sun, "", &meters, 1024);
    // A disk of angular radius α facing the receiver: E = L π sin²α = E_n (1 + cos α)/2.
    let alpha = (0.5 * candela::daylight::sun::SUN_DIAMETER_DEG).to_radians();
    let facing = e_n * (1.0 + alpha.cos()) / 2.0;
    assert_estimate_near(r[0].0, r[0].1.max(1e-9), facing, 0.01, "facing the sun");
    assert_estimate_near(
        r[1].0,
        r[1].1.max(1e-9),
        facing * 50f64.to_radians().cos(),
        0.01,
        "tilted 50°",
    );
    assert_estimate_near(
        r[2].0,
        r[2].1.max(1e-9),
        e_n / omega,
        0.01,
        "the disk's luminance",
    );
    println!(
        "sun: facing {:.2} lx, tilted {:.2} lx, disk {:.4e} cd/m² (E_n/Ω = {:.4e})",
        r[0].0,
        r[1].0,
        r[2].0,
        e_n / omega
    );
}

/// A black room 4 × 4 m, 3 m high, with an a × a opening centred in its roof.
fn room_with_roof_opening(a: f64) -> String {
    let h = a / 2.0;
    let quad = |o: [f64; 3], u: [f64; 3], v: [f64; 3]| {
        format!(
            "(material: \"black\", shape: Quad(origin: ({}, {}, {}), edge_u: ({}, {}, {}), edge_v: ({}, {}, {}))),",
            o[0], o[1], o[2], u[0], u[1], u[2], v[0], v[1], v[2]
        )
    };
    let mut s = String::new();
    // Floor and walls (x, z in [−2, 2], y in [0, 3]).
    s += &quad([-2.0, 0.0, -2.0], [4.0, 0.0, 0.0], [0.0, 0.0, 4.0]);
    s += &quad([-2.0, 0.0, -2.0], [0.0, 3.0, 0.0], [4.0, 0.0, 0.0]);
    s += &quad([-2.0, 0.0, 2.0], [0.0, 3.0, 0.0], [4.0, 0.0, 0.0]);
    s += &quad([-2.0, 0.0, -2.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0]);
    s += &quad([2.0, 0.0, -2.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0]);
    // Roof at y = 3 around the opening [−h, h]².
    s += &quad([-2.0, 3.0, -2.0], [4.0, 0.0, 0.0], [0.0, 0.0, 2.0 - h]);
    s += &quad([-2.0, 3.0, h], [4.0, 0.0, 0.0], [0.0, 0.0, 2.0 - h]);
    s += &quad([-2.0, 3.0, -h], [2.0 - h, 0.0, 0.0], [0.0, 0.0, 2.0 * h]);
    s += &quad([h, 3.0, -h], [2.0 - h, 0.0, 0.0], [0.0, 0.0, 2.0 * h]);
    s
}

/// Configuration factor from a horizontal element to a parallel rectangle a × b at height c
/// with a corner above it (closed-forms.md §2.4).
fn corner_factor(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
}

#[test]
fn roof_opening_configuration_factor() {
    let a = 1.2;
    let objects = room_with_roof_opening(a);
    // The meter on the floor below the opening's centre, 3 m under it.
    let meter = r#"Illuminance(name: "floor", position: (0, 0.001, 0), normal: (0, 1, 0))"#;
    let c = 3.0 - 0.001;
    let f = 4.0 * corner_factor(a / 2.0, a / 2.0, c);
    // Uniform sky of luminance L: E = π L F.
    let l = 1000.0 / PI;
    // The opening is the sky's portal: light sampling aims through it.
    let portal = format!(
        "portals: [(origin: ({}, 3, {}), edge_u: ({a}, 0, 0), edge_v: (0, 0, {a}))]",
        -a / 2.0,
        -a / 2.0
    );
    let r = measure(
        &format!("Sky(model: Uniform, amount: HorizontalIlluminance(1000.0), {portal})"),
        &objects,
        meter,
        4096,
    );
    assert_estimate_near(
        r[0].0,
        r[0].1,
        PI * l * f,
        0.01,
        "uniform sky through the opening",
    );
    // Traditional overcast, L_z = 9 E_h / (7π): E = ∫ L(Z) cos Z dω over the opening,
    // dω cos Z = c² / r⁴ dA for a horizontal element below a horizontal opening.
    let lz = 9.0 * 1000.0 / (7.0 * PI);
    let n = 400;
    let mut e = 0.0;
    for i in 0..n {
        for j in 0..n {
            let x = -a / 2.0 + a * (i as f64 + 0.5) / n as f64;
            let z = -a / 2.0 + a * (j as f64 + 0.5) / n as f64;
            let r2 = x * x + z * z + c * c;
            let cos_z = c / r2.sqrt();
            e += lz * (1.0 + 2.0 * cos_z) / 3.0 * c * c / (r2 * r2);
        }
    }
    e *= (a / n as f64).powi(2);
    let u = r[0];
    let r = measure(
        &format!("Sky(model: CieOvercast, amount: HorizontalIlluminance(1000.0), {portal})"),
        &objects,
        meter,
        4096,
    );
    assert_estimate_near(r[0].0, r[0].1, e, 0.01, "CIE overcast through the opening");
    // Without the portal, light sampling draws from the whole sky and the estimate is
    // noisier, but still right.
    let o = measure(
        "Sky(model: CieOvercast, amount: HorizontalIlluminance(1000.0))",
        &objects,
        meter,
        65536,
    );
    assert_estimate_near(o[0].0, o[0].1, e, 0.01, "CIE overcast, no portal");
    println!(
        "roof opening: uniform {:.4} ± {:.4} lx (π L F = {:.4}), overcast {:.4} ± {:.4} lx \
         (exact {:.4}; without the portal {:.4} ± {:.4})",
        u.0,
        u.1,
        PI * l * f,
        r[0].0,
        r[0].1,
        e,
        o[0].0,
        o[0].1
    );
}

#[test]
fn bad_skies_are_refused_with_their_field() {
    use candela::scene::{self, Overrides};
    let path = std::path::Path::new("bad.ron");
    let cases = [
        ("Sky(model: CieGeneral(16), amount: HorizontalIlluminance(1.0))", "lights[0].model"),
        ("Sky(model: CieGeneral(12), amount: HorizontalIlluminance(1.0))", "lights[0].sun"),
        ("Sky(model: Uniform)", "lights[0].amount"),
        ("Sky(model: Uniform, amount: Luminance(1.0))", "lights[0].amount"),
        ("Sky(model: Uniform, amount: HorizontalIlluminance(-1.0))", "lights[0].amount"),
        ("Sky(model: Uniform, amount: HorizontalIlluminance(1.0), ground_reflectance: 1.5)", "lights[0].ground_reflectance"),
        ("Sky(model: Perez(direct_normal_lx: 1.0, diffuse_horizontal_lx: 1.0))", "lights[0].sun"),
        ("Sky(model: Perez(direct_normal_lx: 1.0, diffuse_horizontal_lx: 1.0), sun: (altitude_deg: 10.0, azimuth_deg: 0.0), amount: HorizontalIlluminance(1.0))", "lights[0].amount"),
        ("Sky(model: Uniform, amount: HorizontalIlluminance(1.0)), Sky(model: Uniform, amount: HorizontalIlluminance(1.0))", "lights[1]"),
        ("Sun(sun: (altitude_deg: 10.0), amount: NormalIlluminance(1.0))", "lights[0].sun"),
        ("Sun(sun: (altitude_deg: 100.0, azimuth_deg: 0.0), amount: NormalIlluminance(1.0))", "lights[0].sun.altitude_deg"),
        ("Sun(sun: (latitude_deg: 45.0, longitude_deg: 5.0, time: \"2026-06-21T10:00\"), amount: NormalIlluminance(1.0))", "lights[0].sun.time"),
        ("Sun(sun: (altitude_deg: 10.0, azimuth_deg: 0.0, latitude_deg: 4.0), amount: NormalIlluminance(1.0))", "lights[0].sun"),
        ("Sun(sun: (altitude_deg: 10.0, azimuth_deg: 0.0), amount: Illuminance(1.0))", "lights[0].amount"),
        ("Sky(model: Uniform, amount: HorizontalIlluminance(1.0), spectrum: Daylight(3000.0))", "lights[0].spectrum"),
    ];
    for (lights, field) in cases {
        let text = format!("({CAMERA}, lights: [{lights}])");
        let s = scene::parse(&text, path).unwrap_or_else(|e| panic!("{lights}: {e}"));
        let e = scene::build(&s, path, &Overrides::default())
            .err()
            .unwrap_or_else(|| panic!("{lights} was accepted"))
            .to_string();
        assert!(
            e.contains(field),
            "{lights}: the error names no {field}: {e}"
        );
    }
    let text = format!("({CAMERA}, site: (up: (0, 1, 0), north: (0, 2, 0)))");
    let s = scene::parse(&text, path).unwrap();
    let e = scene::build(&s, path, &Overrides::default())
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("site.north"), "{e}");
}

#[test]
fn site_frame_turns_the_sky() {
    // A z-up model with north +y: the sun at azimuth 90° (east) lies toward +x, so a meter
    // facing +x sees more of a clear sky than one facing −x; swapping north flips them.
    let sky = "Sky(model: CieGeneral(12), sun: (altitude_deg: 20.0, azimuth_deg: 90.0), amount: HorizontalIlluminance(10000.0), ground_reflectance: 0.0)";
    let meters = r#"Illuminance(name: "east", position: (0, 0, 0), normal: (1, 0, 0)),
                    Illuminance(name: "west", position: (0, 0, 0), normal: (-1, 0, 0))"#;
    let run = |site: &str| {
        let w = world(&format!(
            "({CAMERA}, lights: [{sky}], meters: [{meters}], measure: (samples: 1024), site: {site})"
        ));
        let m = measure_all(&w);
        (m.meters[0].mean, m.meters[1].mean)
    };
    let (e, w) = run("(up: (0, 0, 1), north: (0, 1, 0))");
    assert!(e > 2.0 * w, "east {e}, west {w}");
    let (e2, w2) = run("(up: (0, 0, 1), north: (0, -1, 0))");
    assert!(w2 > 2.0 * e2, "east {e2}, west {w2}");
    assert!((e / w2 - 1.0).abs() < 0.02 && (w / e2 - 1.0).abs() < 0.05);
}

#[test]
fn daylight_factor_in_the_report() {
    use candela::light::sky::daylight_reference;
    let w = world(&format!(
        "({CAMERA}, lights: [Sky(model: CieOvercast, amount: HorizontalIlluminance(12000.0))])"
    ));
    let d = daylight_reference(&w.lights).expect("an overcast sky alone has a DF reference");
    assert_eq!(d.sky, "CieOvercast");
    assert!((d.horizontal_illuminance_lx / 12_000.0 - 1.0).abs() < 1e-12);
    // Not with a sun, a sun-dependent sky, or another light.
    for lights in [
        "Sky(model: CieOvercast, amount: HorizontalIlluminance(1.0)), Sun(sun: (altitude_deg: 30.0, azimuth_deg: 0.0), amount: NormalIlluminance(1.0))",
        "Sky(model: CieGeneral(2), sun: (altitude_deg: 30.0, azimuth_deg: 0.0), amount: HorizontalIlluminance(1.0))",
        "Sky(model: Uniform, amount: HorizontalIlluminance(1.0)), Point(position: (0, 1, 0), spectrum: Named(\"D65\"), amount: Flux(1.0))",
    ] {
        let w = world(&format!("({CAMERA}, lights: [{lights}])"));
        assert!(daylight_reference(&w.lights).is_none(), "{lights}");
    }
}

/// The report JSON and grid CSV of a render under an overcast sky carry the daylight factor:
/// DF = 100 E / E_h for every meter and grid point, with the same relative interval.
#[test]
fn daylight_factor_in_report_files() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("df.ron"),
        format!(
            r#"({CAMERA}, render: (spp: 1),
            lights: [Sky(model: CieOvercast, amount: HorizontalIlluminance(8000.0))],
            meters: [{UP_METER}],
            grids: [(name: "g", origin: (0, 0, 0), edge_u: (1, 0, 0), edge_v: (0, 0, 1), nx: 2, ny: 1)],
            measure: (samples: 256))"#
        ),
    )
    .unwrap();
    let (code, _, err) = common::cli(&["render", "df.ron"], dir.path());
    assert_eq!(code, 0, "{err}");
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("df.report.json")).unwrap())
            .unwrap();
    assert_eq!(r["daylight"]["sky"], "CieOvercast");
    assert_eq!(
        r["daylight"]["horizontal_illuminance"].as_f64().unwrap(),
        8000.0
    );
    let m = &r["meters"][0];
    let df = &m["daylight_factor_percent"];
    let rel = |a: &serde_json::Value, b: f64| (a.as_f64().unwrap() / b - 1.0).abs() < 1e-12;
    assert!(
        rel(&df["value"], m["value"].as_f64().unwrap() / 80.0),
        "{df}"
    );
    assert!(
        rel(&df["ci95_high"], m["ci95_high"].as_f64().unwrap() / 80.0),
        "{df}"
    );
    // An unobstructed horizontal meter under the sky alone: DF = 100 %.
    assert!(
        (df["value"].as_f64().unwrap() - 100.0).abs() <= 5.0 * df["stderr"].as_f64().unwrap(),
        "{df}"
    );
    let g = &r["grids"][0]["daylight_factor_percent"];
    assert!((g["DF_avg"].as_f64().unwrap() - 100.0).abs() < 5.0, "{g}");
    let csv = std::fs::read_to_string(dir.path().join("df.grid-g.csv")).unwrap();
    assert!(
        csv.lines()
            .nth(1)
            .unwrap()
            .ends_with("DF_percent,DF_ci95_low_percent,DF_ci95_high_percent"),
        "{csv}"
    );
    let row: Vec<f64> = csv
        .lines()
        .nth(2)
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert!((row[10] / (row[5] / 80.0) - 1.0).abs() < 1e-9, "{csv}");
}

/// `Weather(file, time)`: the Perez sky and sun of one hour of tests/data/lyon-excerpt.epw (a
/// synthetic excerpt in EPW format). An unobstructed horizontal meter reads the diffuse-
/// horizontal illuminance plus the direct-normal illuminance times the sine of the sun's
/// altitude at that time (local standard time UTC+1, the file's site), the illuminances those
/// of the record's irradiances under the Perez efficacy model (the file's own illuminance
/// fields, 77 000 and 11 160 lx, are not used).
#[test]
fn weather_file_hour() {
    use candela::daylight::perez::{eccentricity, SkyCondition};
    use candela::daylight::sun::{sun_position, Atmosphere, CivilTime};
    let file = "tests/data/lyon-excerpt.epw";
    let alt = |iso: &str| {
        let t = CivilTime::parse(iso).unwrap();
        sun_position(45.73, 4.94, 201.0, &t, Atmosphere::default(), None)
            .unwrap()
            .altitude_deg
            .to_radians()
    };
    // 10:30 is in the record of hour 11: 770 W/m² direct normal, 93 W/m² diffuse, dew point
    // 12.3 °C; 21 June is day 172.
    let a = alt("2003-06-21T10:30:00+01:00");
    let (_, e_vn, e_vd) = SkyCondition::illuminance_from_irradiance(
        93.0,
        770.0,
        std::f64::consts::FRAC_PI_2 - a,
        eccentricity(172.0),
        12.3,
    )
    .unwrap();
    // The efficacies are those of a clear sky.
    assert!((90.0..110.0).contains(&(e_vn / 770.0)), "{e_vn}");
    assert!((100.0..140.0).contains(&(e_vd / 93.0)), "{e_vd}");
    let r = measure(
        &format!(r#"Weather(file: "{file}", time: "06-21 10:30")"#),
        "",
        UP_METER,
        4096,
    );
    let expected = e_vd + e_vn * a.sin();
    assert_estimate_near(r[0].0, r[0].1, expected, 0.01, "weather 06-21 10:30");
    // Without its sun's disk: the diffuse part alone.
    let r = measure(
        &format!(r#"Weather(file: "{file}", time: "06-21 10:30", sun_disk: false)"#),
        "",
        UP_METER,
        4096,
    );
    assert_estimate_near(r[0].0, r[0].1, e_vd, 0.01, "weather, no disk");
    // 22 June has irradiances only: the efficacy model turns them into illuminances, so the
    // sky's diffuse part lies between 100 and 140 lm/W times its 260 sin(…) W/m².
    let w = common::world(&format!(
        "({CAMERA}, lights: [Weather(file: \"{file}\", time: \"06-22 13:15\", sun_disk: false)])"
    ));
    let candela::light::Light::Sky(sky) = &w.lights[0] else {
        panic!("a sky")
    };
    let ed = 260.0 * (std::f64::consts::PI * (13.5 - 5.5) / 15.5).sin();
    let k = sky.horizontal_illuminance_lx / ed.round();
    assert!((100.0..140.0).contains(&k), "diffuse efficacy {k} lm/W");
    // Errors name the field.
    use candela::scene::{self, Overrides};
    let path = std::path::Path::new("bad.ron");
    for (time, why) in [
        ("06-23 10:00", "no record"),
        ("06-21 02:00", "no daylight"),
        ("6/21 10:00", "MM-DD hh:mm"),
        ("06-21 25:00", "MM-DD hh:mm"),
    ] {
        let text = format!("({CAMERA}, lights: [Weather(file: \"{file}\", time: \"{time}\")])");
        let s = scene::parse(&text, path).unwrap();
        let e = scene::build(&s, path, &Overrides::default())
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.contains("lights[0].time") && e.contains(why),
            "{time}: {e}"
        );
    }
    let text =
        format!("({CAMERA}, lights: [Weather(file: \"missing.epw\", time: \"06-21 10:00\")])");
    let s = scene::parse(&text, path).unwrap();
    let e = scene::build(&s, path, &Overrides::default())
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("lights[0].file") && e.contains("missing.epw"),
        "{e}"
    );
}

/// A vertical surface in the open sees half the sky and half the ground: under a uniform sky
/// of horizontal illuminance E_h over a ground of reflectance ρ_g, E_v = E_h (1 + ρ_g) / 2
/// (the sky component 50 % and the externally reflected component 50 ρ_g % of closed-forms.md
/// §2.7, for a façade element with nothing in front of it).
#[test]
fn vertical_surface_sees_half_sky_half_ground() {
    let meters = r#"Illuminance(name: "east", position: (0, 0, 0), normal: (1, 0, 0)),
                    Illuminance(name: "north", position: (0, 0, 0), normal: (0, 0, -1))"#;
    for rho in [0.0, 0.2, 0.5] {
        let r = measure(
            &format!("Sky(model: Uniform, amount: HorizontalIlluminance(10000.0), ground_reflectance: {rho})"),
            "",
            meters,
            4096,
        );
        for (m, label) in r.iter().zip(["east", "north"]) {
            assert_estimate_near(
                m.0,
                m.1,
                5000.0 * (1.0 + rho),
                0.01,
                &format!("{label}, ρ_g {rho}"),
            );
        }
    }
}

/// A one-pixel camera with a 0.05° field of view aimed at the sun's centre sees only the disk:
/// its pixel is the disk's luminance E_n / Ω in every sample.
#[test]
fn camera_sees_the_sun_disk_luminance() {
    let (alt, az) = (50f64.to_radians(), 160f64.to_radians());
    let to_sun = [alt.cos() * az.sin(), alt.sin(), -alt.cos() * az.cos()];
    let e_n = 100_000.0;
    let w = world(&format!(
        "(camera: (position: (0, 0, 0), look_at: ({}, {}, {}), vfov_deg: 0.05, resolution: (1, 1)),
          render: (spp: 64),
          lights: [Sun(sun: (altitude_deg: 50.0, azimuth_deg: 160.0), amount: NormalIlluminance({e_n}))])",
        to_sun[0], to_sun[1], to_sun[2]
    ));
    let film = common::render(&w, 1);
    let (mean, se) = common::luminance(&film.pixels[0]);
    let expected = e_n / candela::daylight::sun::sun_solid_angle_sr();
    println!("sun disk in a pixel: {mean:.6e} ± {se:.1e} cd/m² (E_n/Ω = {expected:.6e})");
    // Every sample lands on the disk; what varies is the spectral sampling of its colour.
    assert_estimate_near(mean, se, expected, 0.01, "the sun's disk in one pixel");
}

/// `solar_time: true`: 12:00 local apparent solar time puts the sun on the meridian, due south.
#[test]
fn solar_time_noon_is_due_south() {
    // A meter facing south (+z with the default north −z) and one facing east (+x) under the
    // sun alone. At solar noon the east-facing meter's plane cuts the disk (radius α) through
    // its centre, and it receives L ∫ cos over the half disk in front: E_n · 2α / (3π) (79 lx
    // here). One hundredth of a degree of azimuth moves that by about 10 lx.
    let lights = "Sun(sun: (latitude_deg: 45.76, longitude_deg: 4.84, time: \"2026-04-15T12:00:00\", solar_time: true), amount: NormalIlluminance(80000.0))";
    let meters = r#"Illuminance(name: "south", position: (0, 0, 0), normal: (0, 0, 1)),
                    Illuminance(name: "east", position: (0, 0, 0), normal: (1, 0, 0))"#;
    let r = measure(lights, "", meters, 256);
    assert!(r[0].0 > 30_000.0, "south {r:?}");
    let alpha = (0.5 * candela::daylight::sun::SUN_DIAMETER_DEG).to_radians();
    let grazing = 80_000.0 * 2.0 * alpha / (3.0 * PI);
    println!(
        "solar noon: east-facing meter {:.2} ± {:.2} lx (exactly on the meridian: {grazing:.2})",
        r[1].0, r[1].1
    );
    assert!(
        (r[1].0 - grazing).abs() < 5.0 * r[1].1 + 10.0,
        "east {r:?}, expected {grazing}"
    );
}

/// `PerezIrradiance`: a Perez sky from W/m², as `gendaylit -W`. The efficacy model turns them
/// into illuminances (diffuse efficacies of clear skies reach 140–150 lm/W, direct 60–120),
/// and the sky and its sun then light an unobstructed horizontal meter with
/// E_vd + E_vn sin(altitude).
#[test]
fn perez_from_irradiance() {
    use candela::daylight::perez::{SkyCondition, DEFAULT_DEW_POINT_C};
    let (en, ed) = (600.0, 150.0);
    let (_, dn, dh) = SkyCondition::illuminance_from_irradiance(
        ed,
        en,
        50f64.to_radians(),
        1.0,
        DEFAULT_DEW_POINT_C,
    )
    .unwrap();
    assert!(
        (90.0..160.0).contains(&(dh / ed)),
        "diffuse efficacy {}",
        dh / ed
    );
    assert!(
        (60.0..120.0).contains(&(dn / en)),
        "direct efficacy {}",
        dn / en
    );
    let sky = format!(
        "Sky(model: PerezIrradiance(direct_normal_w_m2: {en}, diffuse_horizontal_w_m2: {ed}), \
         sun: (altitude_deg: 40.0, azimuth_deg: 200.0))"
    );
    let r = measure(&sky, "", UP_METER, 4096);
    let expected = dh + dn * 40f64.to_radians().sin();
    assert_estimate_near(r[0].0, r[0].1, expected, 0.01, "Perez from irradiance");
}

/// A year of physically possible weather at Lyon (45.73° N, 4.94° E, UTC+1) in EPW format:
/// direct light while the sun is up at the end of the hour (so the hour of sunrise has some
/// with the sun still down at its middle), diffuse light growing with the sun's height.
fn lyon_year(path: &std::path::Path) {
    use candela::daylight::sun::{sun_position, Atmosphere, CivilTime};
    let mut out = String::from(
        "LOCATION,Lyon-Bron,ARA,FRA,candela synthetic,074800,45.73,4.94,1.0,201.0\n\
         DESIGN CONDITIONS,0\nTYPICAL/EXTREME PERIODS,0\nGROUND TEMPERATURES,0\n\
         HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0\nCOMMENTS 1,synthetic\nCOMMENTS 2,synthetic\n\
         DATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n",
    );
    let days = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];
    let sin_alt = |m: u32, d: u32, s: f64| {
        let t = CivilTime {
            year: 2003,
            month: m,
            day: d,
            seconds: s,
            offset_s: 3600.0,
        };
        let p = sun_position(45.73, 4.94, 201.0, &t, Atmosphere::default(), None).unwrap();
        p.altitude_deg.to_radians().sin()
    };
    for (m, &n) in (1u32..).zip(days.iter()) {
        for d in 1..=n {
            let k = [0.1, 0.5, 1.0][(d % 3) as usize];
            for h in 1..=24u32 {
                let (mid, end) = (
                    sin_alt(m, d, (h as f64 - 0.5) * 3600.0),
                    sin_alt(m, d, h as f64 * 3600.0),
                );
                let dn = if end > 0.005 { 800.0 * k } else { 0.0 };
                let dh = if mid > -0.1 || end > 0.0 {
                    10.0 + 200.0 * mid.max(0.0)
                } else {
                    0.0
                };
                out += &format!(
                    "2003,{m},{d},{h},60,A7A7E8E8*0?9?9?9?9?9?9?9A7A7A7A7A7*0*0E8E8*0*0,10.0,12.0,60,\
                     98600,1310,1367,350,9999,{dn:.0},{dh:.0},999999,999999,999999,9999,180,\
                     3.0,5,3,20.0,77777,9,999999999,0,0.2,0,88,0.0,0.0,0.0\n"
                );
            }
        }
    }
    std::fs::write(path, out).unwrap();
}

/// A `Weather` light at the middle of a record's hour and `candela annual`'s sky of that hour
/// are one sky: the same diffuse-horizontal and direct-normal illuminances (to 10⁻⁸: annual keeps
/// the model's sun 10⁻⁹ rad off the horizon), and the
/// same luminance on each of Reinhart's 577 patches (by annual's 4 × 4 quadrature) and on the ground (to 2·10⁻⁴: the two
/// normalise the distribution on grids of 512 × 1024 and 128 × 256 cells), for a morning, a
/// noon, a winter afternoon and the hour of sunrise, whose direct light both drop because the
/// sun is still down at its middle. A render of the noon hour's unobstructed horizontal
/// illuminance with the light agrees with annual's E_vd + E_vn sin(altitude) within its
/// Monte Carlo error.
#[test]
fn weather_light_and_annual_see_the_same_sky() {
    use candela::annual::year::hourly_skies;
    use candela::daylight::epw::Weather;
    use candela::daylight::patches::SkyPatches;
    use candela::light::Light;
    use candela::photometry::luminous_integral;
    use glam::DVec3;
    let dir = tempfile::tempdir().unwrap();
    let epw = dir.path().join("year.epw");
    lyon_year(&epw);
    let weather = Weather::read(&epw).unwrap();
    assert!(weather.is_full_year());
    let patches = SkyPatches::new(2).unwrap();
    let year = hourly_skies(&weather, &patches, 0.2).unwrap();
    let file = epw.to_str().unwrap();
    let mut sunrise_checked = false;
    for (m, d, h) in [(3, 21, 9), (6, 21, 14), (12, 21, 15), (6, 21, 5)] {
        let hs = year
            .iter()
            .find(|s| (s.month, s.day, s.hour) == (m, d, h))
            .unwrap();
        let time = format!("{m:02}-{d:02} {:02}:30", h - 1);
        let w = world(&format!(
            "({CAMERA}, lights: [Weather(file: \"{file}\", time: \"{time}\")])"
        ));
        let Light::Sky(sky) = &w.lights[0] else {
            panic!("a sky first")
        };
        let sun_lx = w
            .lights
            .iter()
            .find_map(|l| match l {
                Light::Sun(s) => Some(s.normal_illuminance_lx),
                _ => None,
            })
            .unwrap_or(0.0);
        let label = format!(
            "{time}: annual {:?}",
            (hs.sky.diffuse_horizontal_lx, hs.sky.direct_normal_lx)
        );
        assert!(hs.sky.diffuse_horizontal_lx > 0.0, "{label}");
        assert!(
            (sky.horizontal_illuminance_lx / hs.sky.diffuse_horizontal_lx - 1.0).abs() < 1e-8,
            "{label}: the light's {}",
            sky.horizontal_illuminance_lx
        );
        assert!(
            (sun_lx - hs.sky.direct_normal_lx).abs() <= 1e-8 * sun_lx.max(1.0),
            "{label}: the light's sun {sun_lx}"
        );
        if h == 5 {
            // 04:30 on 21 June: the sun is below the horizon, the record has direct light.
            let r = weather.at(6, 21, 4, 30).unwrap();
            assert!(r.direct_normal_w_m2 > 0.0 && hs.sun_altitude_deg < 0.0);
            assert_eq!(sun_lx, 0.0);
            sunrise_checked = true;
        }
        let k = luminous_integral(&sky.radiance);
        let mut worst = 0.0f64;
        for i in 1..patches.len() {
            let p = patches.patch(i).unwrap();
            let mean = k * patches.integrate(i, 4, |v| {
                sky.distribution.relative(DVec3::from_array(v), sky.sun)
            }) / p.solid_angle_sr;
            let a = hs.sky.luminance_cd_m2[i];
            worst = worst.max((mean - a).abs() / a);
        }
        assert!(
            worst < 2e-4,
            "{label}: patch luminance differs by {worst:e}"
        );
        let ground = luminous_integral(&sky.ground);
        assert!(
            (ground / hs.sky.luminance_cd_m2[0] - 1.0).abs() < 2e-4,
            "{label}: ground {ground} against {}",
            hs.sky.luminance_cd_m2[0]
        );
        if h == 14 {
            let r = measure(
                &format!(r#"Weather(file: "{file}", time: "{time}")"#),
                "",
                UP_METER,
                4096,
            );
            let e = hs.sky.diffuse_horizontal_lx
                + hs.sky.direct_normal_lx * hs.sun_altitude_deg.to_radians().sin();
            assert_estimate_near(r[0].0, r[0].1, e, 0.01, &label);
        }
    }
    assert!(sunrise_checked);
}
