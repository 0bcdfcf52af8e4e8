//! `candela report` and `render --report-html`: the page embeds the image's channels losslessly
//! (decoded here as the page decodes them), and a corrupt image or a report JSON from another
//! render (size, seed, scene, illuminance) is refused with exit code 1 and a message naming the
//! file. The page itself is tested in a browser by tests/browser/test_report_html.py.

mod common;
use common::cli;
use std::path::Path;

use candela::output::{read_exr, CHANNEL_Y};
use serde_json::Value;

const SCENE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/python/data/small-room.ron"
);

fn render(dir: &Path, name: &str, extra: &[&str]) {
    let mut args = vec![
        "render",
        SCENE,
        "--quiet",
        "--illuminance",
        "--checkpoint-interval",
        "0s",
        "--out",
        name,
    ];
    args.extend_from_slice(extra);
    let (code, _, err) = cli(&args, dir);
    assert_eq!(code, 0, "{err}");
}

/// The JSON data of a page.
fn page_data(html: &str) -> Value {
    let start = html
        .find(r#"<script type="application/json" id="candela-data">"#)
        .unwrap();
    let body = &html[start..];
    let body = &body[body.find('>').unwrap() + 1..];
    let end = body.find("</script>").unwrap();
    serde_json::from_str(&body[..end]).unwrap()
}

fn decode_base64(s: &str) -> Vec<u8> {
    let val = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let mut out = Vec::new();
    for q in s.as_bytes().chunks(4) {
        let pad = q.iter().filter(|&&c| c == b'=').count();
        let v = q.iter().fold(0u32, |a, &c| {
            (a << 6) | if c == b'=' { 0 } else { val(c) as u32 }
        });
        out.extend_from_slice(&[(v >> 16) as u8, (v >> 8) as u8, v as u8][..3 - pad]);
    }
    out
}

#[test]
fn pages_hold_the_exact_channels_and_mismatches_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    render(d, "room", &["--report-html"]);
    let html = std::fs::read_to_string(d.join("room.html")).unwrap();
    assert!(!html.contains("http://") && !html.contains("https://"));

    // Every embedded channel is bit-identical to the EXR's after the page's decoding.
    let layers = read_exr(&d.join("room.exr")).unwrap();
    let data = page_data(&html);
    assert_eq!(data["width"], layers.width);
    let channels = data["channels"].as_array().unwrap();
    assert_eq!(channels.len(), 7, "X Y Z stderr.Y E stderr.E mask.E");
    for c in channels {
        let name = c["name"].as_str().unwrap();
        let z = decode_base64(c["data"].as_str().unwrap());
        let raw = miniz_oxide::inflate::decompress_to_vec_zlib(&z).unwrap();
        let got = candela::report::html::decode_plane_bytes(raw);
        let want = layers.channel(name).unwrap();
        assert!(
            got.iter()
                .zip(want)
                .all(|(a, b)| a.to_bits() == b.to_bits())
                && got.len() == want.len(),
            "channel {name}"
        );
    }
    assert_eq!(
        data["report"]["settings"]["width"], layers.width,
        "the report JSON is embedded"
    );

    // `candela report` finds NAME.report.json beside the EXR.
    let (code, out, err) = cli(&["report", "room.exr", "-o", "again.html"], d);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("report room.report.json"), "{out}");
    let again = std::fs::read_to_string(d.join("again.html")).unwrap();
    assert_eq!(
        page_data(&again)["channels"],
        data["channels"],
        "same image, same data"
    );
    assert!(layers.channel(CHANNEL_Y).is_some());

    // Another seed: same size and scene, other pixels.
    render(d, "other", &["--seed", "99"]);
    let refused = |args: &[&str], needle: &str| {
        let (code, out, err) = cli(args, d);
        assert_eq!(code, 1, "{args:?}: {out} {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!d.join("bad.html").exists(), "{args:?} wrote a page");
    };
    refused(
        &["report", "room.exr", "other.report.json", "-o", "bad.html"],
        "other.report.json: not the report of room.exr",
    );
    refused(
        &["report", "room.exr", "other.report.json", "-o", "bad.html"],
        "brightest pixel",
    );
    // Another size, another scene, no illuminance: edited copies of the report.
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("room.report.json")).unwrap())
            .unwrap();
    let edited = |name: &str, f: &dyn Fn(&mut Value)| {
        let mut r = report.clone();
        f(&mut r);
        std::fs::write(d.join(name), serde_json::to_string(&r).unwrap()).unwrap();
    };
    edited("size.json", &|r| r["settings"]["width"] = 64.into());
    refused(
        &["report", "room.exr", "size.json", "-o", "bad.html"],
        "describes a 64×36 render, the image is 48×36",
    );
    edited("scene.json", &|r| r["scene"] = "elsewhere.ron".into());
    refused(
        &["report", "room.exr", "scene.json", "-o", "bad.html"],
        "it is the report of scene \"elsewhere.ron\"",
    );
    edited("noe.json", &|r| r["settings"]["illuminance"] = false.into());
    refused(
        &["report", "room.exr", "noe.json", "-o", "bad.html"],
        "the report has no illuminance, the image has an E channel",
    );
    edited("spp.json", &|r| {
        r["progressive"]["image_samples_per_pixel"] = 3.0.into()
    });
    refused(
        &["report", "room.exr", "spp.json", "-o", "bad.html"],
        "it has 3.00 samples per pixel, the image 8.00",
    );
    std::fs::write(d.join("text.json"), "not json").unwrap();
    refused(
        &["report", "room.exr", "text.json", "-o", "bad.html"],
        "text.json: not valid JSON",
    );
    refused(
        &[
            "report",
            "room.exr",
            "--glare",
            "room.report.json",
            "-o",
            "bad.html",
        ],
        "room.report.json: not a glare evaluation",
    );

    // A corrupt EXR: truncated, and with a NaN luminance.
    let bytes = std::fs::read(d.join("room.exr")).unwrap();
    std::fs::write(d.join("cut.exr"), &bytes[..bytes.len() / 2]).unwrap();
    refused(&["report", "cut.exr", "-o", "bad.html"], "cut.exr");
    std::fs::write(d.join("junk.exr"), b"this is not an image at all").unwrap();
    refused(&["report", "junk.exr", "-o", "bad.html"], "junk.exr");
    let mut nan = read_exr(&d.join("room.exr")).unwrap();
    let y = nan
        .channels
        .iter_mut()
        .find(|(n, _)| n == CHANNEL_Y)
        .unwrap();
    y.1[5] = -1.0;
    candela::output::write_exr(&d.join("neg.exr"), &nan).unwrap();
    refused(
        &["report", "neg.exr", "-o", "bad.html"],
        "neg.exr: channel Y holds -1 at pixel (5, 0)",
    );
    refused(&["report", "missing.exr", "-o", "bad.html"], "missing.exr");
    // The output may not replace an input.
    let (code, _, err) = cli(&["report", "room.exr", "-o", "room.exr"], d);
    assert_eq!(code, 1);
    assert!(
        err.contains("refusing to overwrite the input room.exr"),
        "{err}"
    );
    assert_eq!(std::fs::read(d.join("room.exr")).unwrap(), bytes);
}
