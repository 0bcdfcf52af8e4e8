//! Fuzzing of the Radiance HDR reader behind `candela probe`, `report`, `falsecolour` and
//! `glare`: pictures written by candela (new-style runs), in the densest old-style runs, flat,
//! bottom-to-top, mutated (bytes flipped, header lines added or changed, resolution lines
//! replaced by odd or huge sizes, run codes corrupted, truncated). `read_hdr` and
//! `read_image` must give `Ok` with every channel the declared size, or an `Err` naming the
//! file — never a panic. `CANDELA_FUZZ_CASES=N` sets the number of mutated cases (default
//! 3000).

use candela::output::{read_hdr, read_image, write_hdr};
use std::path::Path;

/// A small deterministic generator (64-bit LCG, high bits).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Valid pictures of several encodings and orientations.
fn seeds(dir: &Path) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    for (w, h) in [(9, 4), (40, 3), (1, 5), (300, 2)] {
        let xyz: Vec<[f32; 3]> = (0..w * h)
            .map(|i| {
                let v = 1.0 + (i % 7) as f32 * 10.0;
                [v * 0.9, v, v * 1.1]
            })
            .collect();
        let p = dir.join("seed.hdr");
        write_hdr(&p, w, h, &xyz, Some("-vta -vh 180 -vv 180"), &[]).unwrap();
        out.push(std::fs::read(&p).unwrap());
    }
    for (w, h, orient) in [(257, 3, "-Y"), (5, 2, "+Y"), (70000, 1, "-Y")] {
        let mut b =
            format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n{orient} {h} +X {w}\n").into_bytes();
        let mut line = vec![128, 128, 128, 129];
        let mut rest = w - 1;
        while rest > 0 {
            line.extend([1, 1, 1, (rest & 255) as u8]);
            rest >>= 8;
        }
        for _ in 0..h {
            b.extend(&line);
        }
        out.push(b);
    }
    // Flat XYZE pixels with an exposure and a colour correction.
    let mut b =
        b"#?RADIANCE\nFORMAT=32-bit_rle_xyze\nEXPOSURE=2\nCOLORCORR=1 1.1 0.9\n\n+Y 2 +X 3\n"
            .to_vec();
    for i in 0..6u8 {
        b.extend([100 + i, 120, 90, 130]);
    }
    out.push(b);
    out
}

/// One mutation of `b`.
fn mutate(rng: &mut Rng, b: &mut Vec<u8>) {
    let header_end = b.windows(2).position(|w| w == b"\n\n").map_or(0, |p| p + 2);
    match rng.below(9) {
        0 if !b.is_empty() => {
            let i = rng.below(b.len());
            b[i] ^= 1 << rng.below(8);
        }
        1 => {
            let i = rng.below(b.len() + 1);
            b.truncate(i);
        }
        2 if !b.is_empty() => {
            let i = rng.below(b.len());
            b[i] = [0, 1, 2, 127, 128, 129, 255, b'\n', b'-'][rng.below(9)];
        }
        3 => {
            // A new or odd header line.
            let lines: [&[u8]; 8] = [
                b"EXPOSURE=0\n",
                b"EXPOSURE=1e-320\n",
                b"COLORCORR=1 2\n",
                b"PRIMARIES=0 0 0 0 0 0 0 0\n",
                b"FORMAT=32-bit_rle_xyze\n",
                b"FORMAT=float\n",
                b"VIEW= -vtv -vh nan\n",
                b"\r\n",
            ];
            let at = header_end.saturating_sub(1).min(b.len());
            let line = lines[rng.below(lines.len())];
            b.splice(at..at, line.iter().copied());
        }
        4 => {
            // Another resolution line: odd, huge or turned.
            let res: [&str; 10] = [
                "-Y 0 +X 5",
                "-Y 5 +X 0",
                "+X 3 -Y 2",
                "-Y 4294967296 +X 1",
                "-Y 2147483647 +X 2147483647",
                "-Y 30000 +X 30000",
                "-Y 1 +X 1000000",
                "+Y 3 +X 9",
                "-Y -1 +X 3",
                "-Y 3 +X 9 extra",
            ];
            if header_end > 0 && header_end <= b.len() {
                let end = b[header_end..]
                    .iter()
                    .position(|&c| c == b'\n')
                    .map_or(b.len(), |p| header_end + p);
                let r = res[rng.below(res.len())];
                b.splice(header_end..end, r.bytes());
            }
        }
        5 if b.len() > header_end + 4 => {
            // A run code: new-style run or old-style repeat.
            let i = header_end + rng.below(b.len() - header_end - 3);
            let code: [u8; 4] = [
                [2, 2, 0x7f, 0xff],
                [1, 1, 1, 255],
                [2, 2, 0, 8],
                [255, 0, 0, 0],
            ][rng.below(4)];
            b[i..i + 4].copy_from_slice(&code);
        }
        6 => b.extend(std::iter::repeat_n(rng.below(256) as u8, rng.below(64))),
        7 if b.len() > header_end => {
            // Cut the pixel data in half.
            let keep = header_end + (b.len() - header_end) / 2;
            b.truncate(keep);
        }
        _ => {
            let i = rng.below(b.len() + 1);
            b.insert(i, rng.below(256) as u8);
        }
    }
}

fn check(path: &Path, name: &str) {
    let r = std::panic::catch_unwind(|| {
        read_hdr(path).map(|img| (img.width, img.height, img.xyz.len()))
    });
    match r {
        Err(_) => panic!(
            "read_hdr panicked on {name}: {:?}",
            std::fs::read(path).unwrap()
        ),
        Ok(Ok((w, h, n))) => assert_eq!(w * h, n),
        Ok(Err(e)) => assert!(
            e.to_string().contains(name),
            "error does not name {name}: {e}"
        ),
    }
    let r = std::panic::catch_unwind(|| read_image(path));
    match r {
        Err(_) => panic!("read_image panicked on {name}"),
        Ok(Ok(l)) => {
            for (c, v) in &l.channels {
                assert_eq!(v.len(), l.width * l.height, "channel {c}");
            }
        }
        Ok(Err(e)) => assert!(
            e.to_string().contains(name),
            "error does not name {name}: {e}"
        ),
    }
}

#[test]
fn mutated_pictures_are_read_or_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let seeds = seeds(dir.path());
    let cases: usize = std::env::var("CANDELA_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3000);
    let mut rng = Rng(0x5eed_4d52);
    let path = dir.path().join("fuzz.hdr");
    for (k, s) in seeds.iter().enumerate() {
        std::fs::write(&path, s).unwrap();
        read_hdr(&path).unwrap_or_else(|e| panic!("seed {k}: {e}"));
    }
    for _ in 0..cases {
        let mut b = seeds[rng.below(seeds.len())].clone();
        for _ in 0..1 + rng.below(3) {
            mutate(&mut rng, &mut b);
        }
        std::fs::write(&path, &b).unwrap();
        check(&path, "fuzz.hdr");
    }
    // Random bytes after a Radiance signature.
    for _ in 0..cases / 10 {
        let mut b = b"#?RADIANCE\n".to_vec();
        b.extend((0..rng.below(200)).map(|_| rng.below(256) as u8));
        std::fs::write(&path, &b).unwrap();
        check(&path, "fuzz.hdr");
    }
}
