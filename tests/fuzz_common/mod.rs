//! Shared by the `fuzz_*` tests: case counts, a byte-level mutation plan (a proptest value, so
//! failures shrink to a small plan), and numeric-token replacement with hostile values.
#![allow(dead_code)]

use proptest::prelude::*;

/// Number of cases per fuzz test: `PROPTEST_CASES` if set, else `default` (chosen so each test
/// runs in well under 20 s with `cargo test --release`).
pub fn cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

pub fn config(default_cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases: cases(default_cases),
        // Failures are reported with the shrunk input; no persistence files in the source tree.
        failure_persistence: None,
        max_shrink_iters: 2000,
        rng_seed: rng_seed(),
        ..ProptestConfig::default()
    }
}

/// The random seed: fixed by default so that the test suite (and CI) is deterministic;
/// `PROPTEST_RNG_SEED=<u64>` picks another, `PROPTEST_RNG_SEED=random` a fresh one per run
/// (for long exploratory runs, see docs/fuzzing.md).
pub fn rng_seed() -> proptest::test_runner::RngSeed {
    use proptest::test_runner::RngSeed;
    match std::env::var("PROPTEST_RNG_SEED").ok().as_deref() {
        Some("random") => RngSeed::Random,
        Some(s) => s
            .parse()
            .map(RngSeed::Fixed)
            .unwrap_or(RngSeed::Fixed(0x0063_616e_6465_6c61)),
        None => RngSeed::Fixed(0x0063_616e_6465_6c61),
    }
}

/// Hostile replacements for a number in a text format.
pub const HOSTILE_NUMBERS: &[&str] = &[
    "NaN",
    "nan",
    "inf",
    "-inf",
    "+inf",
    "1e38",
    "-1e38",
    "3.5e38",
    "1e300",
    "-1e300",
    "1e-30",
    "1e-45",
    "1e-320",
    "0",
    "-0",
    "0.0",
    "-0.0",
    "-1",
    "-1.5",
    "1",
    "2",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "18446744073709551616",
    "-9223372036854775808",
    "99999999999999999999999999999",
    "65536",
    "1e6",
    "1e-6",
    "0x10",
    "1_000",
    ".5",
    "5.",
    "1e",
    "--1",
    "",
];

/// One step of a mutation plan; positions are taken modulo the current length.
#[derive(Clone, Debug)]
pub enum Mutation {
    /// Replace the `k`-th numeric token with `HOSTILE_NUMBERS[v]`.
    Number { k: usize, v: usize },
    /// XOR one byte.
    FlipByte { pos: usize, mask: u8 },
    /// Overwrite one byte.
    SetByte { pos: usize, byte: u8 },
    /// Insert bytes.
    Insert { pos: usize, bytes: Vec<u8> },
    /// Delete a range.
    Delete { pos: usize, len: usize },
    /// Copy a range of the input to another place (splice within the input).
    Duplicate { from: usize, len: usize, to: usize },
    /// Cut the input at `pos`.
    Truncate { pos: usize },
    /// Splice in a range of another seed.
    Splice {
        seed: usize,
        from: usize,
        len: usize,
        to: usize,
    },
}

/// Bytes worth inserting into a text format: structure characters and tokens.
const TOKENS: &[&[u8]] = &[
    b"(",
    b")",
    b"[",
    b"]",
    b"{",
    b"}",
    b",",
    b":",
    b"\"",
    b"//",
    b"/*",
    b"*/",
    b"\n",
    b"\0",
    b"\xff\xfe",
    b"\xc3",
    b"Some(",
    b"None",
    b"NaN",
    b"inf",
    b"-",
    b"e9",
    b"#",
    b";",
    b"\t",
    b" ",
    b"\r\n",
];

pub fn mutation(n_seeds: usize) -> impl Strategy<Value = Mutation> {
    prop_oneof![
        4 => (any::<usize>(), 0..HOSTILE_NUMBERS.len()).prop_map(|(k, v)| Mutation::Number { k, v }),
        1 => (any::<usize>(), 1..=255u8).prop_map(|(pos, mask)| Mutation::FlipByte { pos, mask }),
        1 => (any::<usize>(), any::<u8>()).prop_map(|(pos, byte)| Mutation::SetByte { pos, byte }),
        2 => (any::<usize>(), prop_oneof![
                (0..TOKENS.len()).prop_map(|t| TOKENS[t].to_vec()),
                proptest::collection::vec(any::<u8>(), 1..6),
            ]).prop_map(|(pos, bytes)| Mutation::Insert { pos, bytes }),
        1 => (any::<usize>(), 1..40usize).prop_map(|(pos, len)| Mutation::Delete { pos, len }),
        1 => (any::<usize>(), 1..200usize, any::<usize>())
            .prop_map(|(from, len, to)| Mutation::Duplicate { from, len, to }),
        1 => any::<usize>().prop_map(|pos| Mutation::Truncate { pos }),
        1 => (0..n_seeds.max(1), any::<usize>(), 1..300usize, any::<usize>())
            .prop_map(|(seed, from, len, to)| Mutation::Splice { seed, from, len, to }),
    ]
}

/// Byte ranges of numeric tokens (optional sign, digits, '.', exponent) in `s`.
pub fn number_spans(s: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut i = 0;
    while i < s.len() {
        let starts = s[i].is_ascii_digit()
            || ((s[i] == b'-' || s[i] == b'.') && i + 1 < s.len() && s[i + 1].is_ascii_digit());
        let prev_ident = i > 0 && (s[i - 1].is_ascii_alphanumeric() || s[i - 1] == b'_');
        if starts && !prev_ident {
            let a = i;
            i += 1;
            while i < s.len()
                && (s[i].is_ascii_digit()
                    || s[i] == b'.'
                    || s[i] == b'e'
                    || s[i] == b'E'
                    || ((s[i] == b'-' || s[i] == b'+') && (s[i - 1] == b'e' || s[i - 1] == b'E')))
            {
                i += 1;
            }
            spans.push((a, i));
        } else {
            i += 1;
        }
    }
    spans
}

/// Apply a mutation plan to `input` (seeds are used by `Splice`).
pub fn apply(input: &[u8], plan: &[Mutation], seeds: &[&[u8]]) -> Vec<u8> {
    let mut s = input.to_vec();
    for m in plan {
        let n = s.len();
        match m {
            Mutation::Number { k, v } => {
                let spans = number_spans(&s);
                if spans.is_empty() {
                    continue;
                }
                let (a, b) = spans[k % spans.len()];
                s.splice(a..b, HOSTILE_NUMBERS[*v].bytes());
            }
            Mutation::FlipByte { pos, mask } => {
                if n > 0 {
                    s[pos % n] ^= mask;
                }
            }
            Mutation::SetByte { pos, byte } => {
                if n > 0 {
                    s[pos % n] = *byte;
                }
            }
            Mutation::Insert { pos, bytes } => {
                let p = pos % (n + 1);
                s.splice(p..p, bytes.iter().copied());
            }
            Mutation::Delete { pos, len } => {
                if n > 0 {
                    let a = pos % n;
                    let b = (a + len).min(n);
                    s.drain(a..b);
                }
            }
            Mutation::Duplicate { from, len, to } => {
                if n > 0 {
                    let a = from % n;
                    let b = (a + len).min(n);
                    let piece: Vec<u8> = s[a..b].to_vec();
                    let t = to % (n + 1);
                    s.splice(t..t, piece);
                }
            }
            Mutation::Truncate { pos } => {
                s.truncate(pos % (n + 1));
            }
            Mutation::Splice {
                seed,
                from,
                len,
                to,
            } => {
                let other = seeds[seed % seeds.len()];
                if !other.is_empty() {
                    let a = from % other.len();
                    let b = (a + len).min(other.len());
                    let t = to % (n + 1);
                    s.splice(t..t, other[a..b].iter().copied());
                }
            }
        }
    }
    s
}

/// A seed index and a mutation plan of 1..=max steps.
pub fn plan(n_seeds: usize, max: usize) -> impl Strategy<Value = (usize, Vec<Mutation>)> {
    (
        0..n_seeds,
        proptest::collection::vec(mutation(n_seeds), 1..=max),
    )
}
