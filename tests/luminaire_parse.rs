//! IES LM-63 and EULUMDAT parsing: every version and symmetry, type A/B/C, tilt tables, and
//! each malformed-file case with its file, line and field. Plus a deterministic mutation fuzzer
//! (no panic on random or mutated input; run longer with CANDELA_FUZZ_ITERS=N).

use candela::luminaire::{ies, ldt, Kind, ParseError, Symmetry};
use std::path::Path;

fn ies_text(version: &str, tilt: &str, line10: &str, v: &str, h: &str, cd: &str) -> String {
    format!("{version}[TEST] t\n[MANUFAC] candela\nTILT={tilt}{line10}\n1 1 0\n{v}\n{h}\n{cd}\n")
}

fn parse_ies(t: &str) -> Result<candela::luminaire::Photometry, ParseError> {
    ies::parse(t, Path::new("lamp.ies"))
}

/// A valid 2002 file: 3 vertical angles, 2 horizontal (0, 180: bilateral), 1000 lm lamp.
fn base() -> String {
    ies_text(
        "IESNA:LM-63-2002\n",
        "NONE",
        "\n1 1000 2 3 2 1 2 0.5 0.6 0.1",
        "0 45 90",
        "0 180",
        "100 80 10\n90 70 5",
    )
}

#[test]
fn a_valid_file_and_its_fields() {
    let p = parse_ies(&base()).unwrap();
    assert_eq!(p.kind, Kind::C);
    assert_eq!(p.symmetry, Symmetry::C0C180);
    assert_eq!(
        p.candela,
        vec![vec![200.0, 160.0, 20.0], vec![180.0, 140.0, 10.0]]
    );
    assert_eq!(p.stated_lumens, Some(1000.0));
    assert_eq!(p.size_m, [0.6, 0.5, 0.1]);
    assert_eq!(p.header[0], ("TEST".into(), "t".into()));
}

#[test]
fn every_version() {
    let body = "TILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n10 20\n";
    for (head, v) in [
        ("", "LM-63-1986"),
        ("IESNA91\n", "LM-63-1991"),
        ("IESNA:LM-63-1995\n", "LM-63-1995"),
        ("IESNA:LM-63-2002\n", "LM-63-2002"),
        ("IES:LM-63-2019\n", "LM-63-2019"),
    ] {
        let text = format!("{head}some free text label\n{body}");
        let p = parse_ies(&text).unwrap_or_else(|e| panic!("{v}: {e}"));
        assert_eq!(p.format, candela::luminaire::Format::Ies(v.into()));
        assert_eq!(p.symmetry, Symmetry::Rotational);
        assert_eq!(p.stated_lumens, None, "absolute photometry");
    }
    // 1995: the ballast-lamp photometric factor multiplies; 2002: it does not.
    let t = |v: &str| format!("{v}TILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n0.9 0.5 0\n0 90\n0\n10 20\n");
    assert_eq!(
        parse_ies(&t("IESNA:LM-63-1995\n")).unwrap().candela[0][0],
        10.0 * 0.9 * 0.5
    );
    assert_eq!(
        parse_ies(&t("IESNA:LM-63-2002\n")).unwrap().candela[0][0],
        10.0 * 0.9
    );
    // Commas as separators and CRLF line ends.
    let crlf =
        "IESNA:LM-63-2002\r\nTILT=NONE\r\n1,-1,1,2,1,1,2,0,0,0\r\n1,1,0\r\n0,90\r\n0\r\n10,20\r\n";
    assert_eq!(parse_ies(crlf).unwrap().candela, vec![vec![10.0, 20.0]]);
}

#[test]
fn tilt_include_applies_the_factor_at_zero() {
    let t = "IESNA:LM-63-2002\nTILT=INCLUDE\n1\n3\n-10 0 10\n0.5 0.8 1.0\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n10 20\n";
    assert_eq!(parse_ies(t).unwrap().candela, vec![vec![8.0, 16.0]]);
}

#[test]
fn every_symmetry_mirrors_correctly() {
    // Value encodes the plane: I = C + 1 at every γ.
    let case = |h: &str| {
        let hs: Vec<f64> = h.split(' ').map(|s| s.parse().unwrap()).collect();
        let cd: Vec<String> = hs
            .iter()
            .map(|c| format!("{} {}", c + 1.0, c + 1.0))
            .collect();
        let t = format!(
            "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2 {} 1 2 0 0 0\n1 1 0\n0 90\n{h}\n{}\n",
            hs.len(),
            cd.join("\n")
        );
        parse_ies(&t).unwrap().distribution()
    };
    let quad = case("0 30 60 90");
    close(quad.eval_angles(150.0, 45.0), 31.0); // 180 − 150 = 30
    close(quad.eval_angles(210.0, 45.0), 31.0);
    close(quad.eval_angles(300.0, 45.0), 61.0);
    let bil = case("0 60 120 180");
    close(bil.eval_angles(300.0, 45.0), 61.0);
    close(bil.eval_angles(240.0, 10.0), 121.0);
    let b90 = case("90 150 210 270");
    close(b90.eval_angles(30.0, 45.0), 151.0); // mirror of 30 about 90–270 is 150
    close(b90.eval_angles(330.0, 45.0), 211.0);
    let full = case("0 90 180 270 360");
    close(full.eval_angles(45.0, 20.0), 46.0);
    close(full.eval_angles(225.0, 20.0), 226.0);
    // Rotational.
    let rot = case("0");
    close(rot.eval_angles(123.0, 45.0), 1.0);
}

#[test]
fn type_a_and_b_with_lateral_symmetry() {
    for (ty, kind) in [(2, Kind::B), (3, Kind::A)] {
        let t = format!(
            "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 3 3 {ty} 2 0 0 0\n1 1 0\n-90 0 90\n0 45 90\n\
             10 100 10\n5 50 5\n0 0 0\n"
        );
        let p = parse_ies(&t).unwrap();
        assert_eq!((p.kind, p.symmetry), (kind, Symmetry::Lateral));
        let d = p.distribution();
        // The main axis (H = V = 0) is nadir.
        assert!((d.eval([0.0, -1.0, 0.0]) - 100.0).abs() < 1e-9);
        assert_eq!(d.eval_angles(-45.0, 0.0), 50.0);
        // Flux: positive, and the brute-force check over directions agrees with the exact sum.
        let brute = candela::luminaire::integrate_sphere(400, |c, g| {
            let (a, b) = (c.to_radians(), g.to_radians());
            d.eval([b.sin() * a.cos(), -b.cos(), -b.sin() * a.sin()])
        });
        assert!(
            (brute / d.lumens() - 1.0).abs() < 2e-3,
            "{kind:?}: {brute} vs {}",
            d.lumens()
        );
    }
}

fn close(a: f64, b: f64) {
    assert!((a - b).abs() < 1e-9, "{a} vs {b}");
}

/// Expect an error at `line` whose field contains `field`.
fn expect_err(r: Result<candela::luminaire::Photometry, ParseError>, line: usize, field: &str) {
    match r {
        Ok(_) => panic!("expected an error in {field:?} on line {line}"),
        Err(e) => {
            let msg = e.to_string();
            assert!(
                msg.contains("lamp.") && e.line == line && e.field.contains(field),
                "expected line {line} field {field:?}, got {msg}"
            );
        }
    }
}

#[test]
fn malformed_ies_files_give_their_errors() {
    let b = base();
    // Lines: 1 version, 2-3 keywords, 4 TILT, 5 counts, 6 ballast, 7 vertical, 8 horizontal, 9-10 candela.
    let cases: Vec<(String, usize, &str)> = vec![
        // Truncated table.
        (b.replace("90 70 5\n", "90 70\n"), 10, "candela value 6"),
        // Wrong count: more vertical angles announced than given → the angle list eats candela.
        (
            b.replace("1 1000 2 3 2", "1 1000 2 4 2"),
            8,
            "vertical angle 4",
        ),
        // Wrong count: fewer → extra value at the end.
        (
            b.replace("1 1000 2 3 2", "1 1000 2 3 1"),
            9,
            "end of candela table",
        ),
        // Non-numeric field.
        (b.replace("0.5 0.6", "wide 0.6"), 5, "width"),
        (b.replace("100 80", "100 x80"), 9, "candela value 2"),
        // Negative candela.
        (b.replace("90 70 5", "90 -70 5"), 10, "candela value 5"),
        // Angles out of order.
        (b.replace("0 45 90", "0 90 45"), 7, "vertical angle 3"),
        (b.replace("\n0 180\n", "\n180 0\n"), 8, "horizontal angle 2"),
        // Bad enumerations and ranges.
        (b.replace("2 3 2 1 2", "2 3 2 7 2"), 5, "photometric type"),
        (b.replace("\n0 180\n", "\n0 120\n"), 8, "horizontal angle 1"),
        (b.replace("TILT=NONE", "TILT=lamp.tlt"), 4, "TILT"),
        (
            b.replace("IESNA:LM-63-2002", "IESNA:LM-63-2042"),
            1,
            "format line",
        ),
        (
            b.replace("1 1000 2 3 2", "1 1000 2 0 2"),
            5,
            "number of vertical angles",
        ),
        (
            b.replace("1 1000 2 3 2", "1 1000 -2 3 2"),
            5,
            "candela multiplier",
        ),
        (
            b.replace("1 1000 2 3 2", "1 1000 2 3 1e9"),
            5,
            "number of horizontal angles",
        ),
        (
            b.replace("1 1000 2 3 2", "1 1000 2 NaN 2"),
            5,
            "number of vertical angles",
        ),
    ];
    for (text, line, field) in cases {
        expect_err(parse_ies(&text), line, field);
    }
    // No TILT line at all.
    expect_err(parse_ies("IESNA:LM-63-2002\n[TEST] x\n"), 2, "TILT");
    expect_err(parse_ies(""), 1, "TILT");
}

fn ldt_text(isym: u32, mc: usize, c: &[f64], cd: &[f64]) -> String {
    let mut l: Vec<String> = vec![
        "candela test".into(),
        "1".into(),
        isym.to_string(),
        mc.to_string(),
        "90".into(),
        "3".into(),
        "45".into(),
        "".into(),
        "lum".into(),
        "".into(),
        "".into(),
        "".into(),
    ];
    l.extend(["600", "300", "50", "600", "300", "0", "0", "0", "0"].map(String::from));
    l.extend(
        [
            "100", "80", "1", "0", "1", "1", "LED", "2000", "3000K", "80", "20",
        ]
        .map(String::from),
    );
    l.extend((0..10).map(|_| "0.5".to_string()));
    l.extend(c.iter().map(|v| v.to_string()));
    l.extend(["0", "45", "90"].map(String::from));
    l.extend(cd.iter().map(|v| v.to_string().replace('.', ",")));
    l.join("\r\n") + "\r\n"
}

fn parse_ldt(t: &str) -> Result<candela::luminaire::Photometry, ParseError> {
    ldt::parse(t, Path::new("lamp.ldt"))
}

#[test]
fn eulumdat_symmetries_and_scaling() {
    let c4 = [0.0, 90.0, 180.0, 270.0];
    // Isym 4: C0 and C90 given.
    let p = parse_ldt(&ldt_text(4, 4, &c4, &[100.0, 50.0, 0.0, 80.0, 40.0, 0.0])).unwrap();
    assert_eq!(p.symmetry, Symmetry::Quadrant);
    assert_eq!(p.candela[0][0], 200.0, "cd/klm × 2000 lm / 1000");
    assert_eq!(p.stated_lumens, Some(1600.0), "lamp flux × LOR 80 %");
    let d = p.distribution();
    assert_eq!(d.eval_angles(270.0, 45.0), 80.0);
    // Isym 1, 2, 3, 0.
    assert_eq!(
        parse_ldt(&ldt_text(1, 4, &c4, &[1.0, 2.0, 3.0]))
            .unwrap()
            .symmetry,
        Symmetry::Rotational
    );
    let p2 = parse_ldt(&ldt_text(2, 4, &c4, &[1.0; 9])).unwrap();
    assert_eq!(
        (p2.symmetry, p2.planes.clone()),
        (Symmetry::C0C180, vec![0.0, 90.0, 180.0])
    );
    let p3 = parse_ldt(&ldt_text(
        3,
        4,
        &c4,
        &[1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 3.0, 3.0, 3.0],
    ))
    .unwrap();
    assert_eq!(
        (p3.symmetry, p3.planes.clone()),
        (Symmetry::C90C270, vec![90.0, 180.0, 270.0])
    );
    assert_eq!(
        p3.distribution().eval_angles(0.0, 0.0),
        4.0,
        "C0 mirrors C180 (2 cd/klm × 2)"
    );
    let p0 = parse_ldt(&ldt_text(0, 4, &c4, &[1.0; 12])).unwrap();
    assert_eq!(p0.symmetry, Symmetry::None);
}

#[test]
fn malformed_eulumdat_files_give_their_errors() {
    let c4 = [0.0, 90.0, 180.0, 270.0];
    let good = ldt_text(4, 4, &c4, &[100.0, 50.0, 0.0, 80.0, 40.0, 0.0]);
    // Layout: C angles on lines 43–46, γ on 47–49, intensities from line 50.
    let lines: Vec<&str> = good.lines().collect();
    let with = |k: usize, v: &str| {
        let mut l = lines.clone();
        l[k - 1] = v;
        l.join("\n")
    };
    expect_err(parse_ldt(&lines[..50].join("\n")), 50, "intensity 2");
    expect_err(parse_ldt(&with(3, "7")), 3, "Isym");
    expect_err(parse_ldt(&with(4, "four")), 4, "Mc");
    expect_err(parse_ldt(&with(51, "-3")), 51, "intensity 2");
    expect_err(parse_ldt(&with(45, "80")), 45, "C angle 3");
    expect_err(parse_ldt(&with(49, "30")), 49, "gamma angle 3");
    expect_err(
        parse_ldt(&(good.clone() + "17\n")),
        56,
        "end of intensity table",
    );
    expect_err(parse_ldt(&with(24, "zero")), 24, "conversion factor");
    expect_err(parse_ldt(&with(29, "lots")), 29, "total luminous flux");
    // Isym 3 but the C angles do not contain 90…270.
    expect_err(
        parse_ldt(&ldt_text(3, 2, &[0.0, 45.0], &[1.0; 3])),
        3,
        "Isym",
    );
}

/// Deterministic mutation fuzzer: random bytes, random token edits of valid files (delete,
/// duplicate, replace with a random number or junk, truncate). Parsing must never panic, and a
/// file that parses must expand, integrate, sample and summarise without panicking.
/// Default 3000 iterations per format (well under a second in release);
/// `CANDELA_FUZZ_ITERS=1000000` for a long run.
#[test]
fn fuzz_parsers_never_panic() {
    let iters: usize = std::env::var("CANDELA_FUZZ_ITERS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3000);
    let mut state = 0x243f6a8885a308d3u64;
    let mut rnd = move |n: usize| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % n.max(1) as u64) as usize
    };
    let seeds_ies = [
        base(),
        std::fs::read_to_string("data/luminaires/wall-washer.ies").unwrap(),
        std::fs::read_to_string("data/luminaires/narrow-spot.ies").unwrap(),
        "IESNA:LM-63-2002\nTILT=INCLUDE\n1\n3\n-10 0 10\n0.5 0.8 1.0\n1 -1 1 3 3 2 2 0 0 0\n1 1 0\n-90 0 90\n0 45 90\n10 100 10\n5 50 5\n0 0 0\n".to_string(),
    ];
    let seeds_ldt = [
        std::fs::read_to_string("data/luminaires/batwing-office.ldt").unwrap(),
        ldt_text(3, 4, &[0.0, 90.0, 180.0, 270.0], &[1.0; 9]),
    ];
    let junk = [
        "",
        "-1",
        "0",
        "1e308",
        "NaN",
        "inf",
        "-0",
        "360",
        "90",
        "x",
        "[MORE]",
        "TILT=NONE",
        "4000000",
        "1e-300",
        "2",
        "3",
        "180",
    ];
    let check = |p: candela::luminaire::Photometry| {
        let d = p.distribution();
        let lm = d.lumens();
        assert!(!lm.is_nan());
        let _ = d.sample(0.3, 0.6, 0.9);
        let _ = d.eval([0.0, -1.0, 0.0]);
        let _ = candela::luminaire::summary::summarise(&p);
    };
    for (seeds, is_ldt) in [(&seeds_ies[..], false), (&seeds_ldt[..], true)] {
        for _ in 0..iters {
            let seed = &seeds[rnd(seeds.len())];
            let text = match rnd(5) {
                0 => {
                    (0..rnd(400))
                        .map(|_| (rnd(96) as u8 + 32) as char)
                        .collect::<String>()
                        + if rnd(2) == 0 { "\n" } else { "" }
                }
                1 => seed.chars().take(rnd(seed.len() + 1)).collect(),
                _ => {
                    let mut toks: Vec<String> = seed
                        .split_inclusive(|c: char| c.is_whitespace())
                        .map(String::from)
                        .collect();
                    for _ in 0..1 + rnd(4) {
                        if toks.is_empty() {
                            break;
                        }
                        let k = rnd(toks.len());
                        match rnd(4) {
                            0 => {
                                toks.remove(k);
                            }
                            1 => {
                                let t = toks[k].clone();
                                toks.insert(k, t);
                            }
                            2 => toks[k] = format!("{} ", junk[rnd(junk.len())]),
                            _ => toks[k] = format!("{}\n", rnd(1000) as f64 / 7.0 - 20.0),
                        }
                    }
                    toks.concat()
                }
            };
            let r = if is_ldt {
                ldt::parse(&text, Path::new("fuzz.ldt"))
            } else {
                ies::parse(&text, Path::new("fuzz.ies"))
            };
            if let Ok(p) = r {
                check(p);
            }
        }
    }
}
