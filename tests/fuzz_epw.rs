//! Property-based fuzzing of the EPW weather-file reader (`daylight::epw::Weather`): mutated
//! valid files (truncations, byte flips, huge numbers, spliced and swapped lines) and random
//! text must be read, with the documented invariants, or refused with a message naming the
//! file and the line — never a panic. `PROPTEST_CASES=N` sets the number of cases.

mod fuzz_common;

use candela::daylight::epw::Weather;
use fuzz_common::{apply, config, plan};
use proptest::prelude::*;

/// Two days of Lyon and the first of them alone (a file may end at any record).
const EXCERPT: &str = include_str!("data/lyon-excerpt.epw");

fn seeds() -> Vec<String> {
    let lines: Vec<&str> = EXCERPT.lines().collect();
    vec![EXCERPT.to_string(), lines[..8 + 24].join("\n") + "\n"]
}

fn check(bytes: &[u8]) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fuzz.epw");
    std::fs::write(&path, bytes).unwrap();
    match Weather::read(&path) {
        Ok(w) => {
            assert!(!w.records.is_empty());
            for p in w.records.windows(2) {
                assert!(p[0].line < p[1].line);
                assert_ne!(
                    (p[0].month, p[0].day, p[0].hour),
                    (p[1].month, p[1].day, p[1].hour)
                );
            }
            for r in &w.records {
                assert!(r.direct_normal_w_m2.is_finite() && r.direct_normal_w_m2 >= 0.0);
                assert!(r.diffuse_horizontal_w_m2.is_finite() && r.diffuse_horizontal_w_m2 >= 0.0);
                assert!((1..=24).contains(&r.hour) && (1..=12).contains(&r.month));
            }
            assert!(w.site.elevation_m.abs() <= 9000.0);
        }
        Err(m) => {
            assert!(m.contains("fuzz.epw"), "error does not name the file: {m}");
            assert!(m.contains("line "), "error does not name the line: {m}");
        }
    }
}

/// `text` with lines `a` and `b` (modulo its line count) swapped: records out of order.
fn swap_lines(text: &[u8], a: usize, b: usize) -> Vec<u8> {
    let mut lines: Vec<&[u8]> = text.split(|&c| c == b'\n').collect();
    let n = lines.len();
    lines.swap(a % n, b % n);
    lines.join(&b'\n')
}

#[test]
fn seeds_parse() {
    for s in seeds() {
        Weather::parse(&s).unwrap_or_else(|e| panic!("{e}"));
    }
}

proptest! {
    #![proptest_config(config(400))]

    #[test]
    fn mutated_epw_never_panics((seed, muts) in plan(2, 5), a in 0usize..64, b in 0usize..64) {
        let s = seeds();
        let seeds: Vec<&[u8]> = s.iter().map(|s| s.as_bytes()).collect();
        let mutated = apply(seeds[seed], &muts, &seeds);
        check(&mutated);
        check(&swap_lines(&mutated, a, b));
        check(&swap_lines(seeds[seed], a, b));
    }

    #[test]
    fn random_epw_never_panics(
        bytes in proptest::collection::vec(any::<u8>(), 0..200),
        record in "([0-9eE.,+-]|nan|inf|9999|1e300){0,60}",
    ) {
        check(&bytes);
        let lines: Vec<&str> = EXCERPT.lines().collect();
        check((lines[..8].join("\n") + "\n" + &record + "\n").as_bytes());
    }
}
