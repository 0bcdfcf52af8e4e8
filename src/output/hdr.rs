//! Radiance HDR (RGBE) writing and reading.
//!
//! Radiance stores radiance in W/sr/m² of its "white" (equal-energy) spectrum and converts to
//! luminance with the luminous efficacy 179 lm/W: L = 179 · (0.265 R + 0.670 G + 0.065 B) /
//! EXPOSURE for its standard primaries (docs/outputs.md). candela writes its absolute CIE XYZ
//! (cd/m²) divided by 179 and converted to those primaries, with `EXPOSURE=1`, so every
//! Radiance tool reads candela's luminance.

use std::path::Path;

use super::{write_atomic, Layers, OutputError};

/// Luminous efficacy of Radiance's white, lm/W: luminance = 179 × Radiance brightness.
pub const RADIANCE_EFFICACY: f64 = 179.0;

/// Radiance's standard primaries and white point, CIE 1931 xy: R, G, B, white.
pub const RADIANCE_PRIMARIES: [[f64; 2]; 4] = [
    [0.640, 0.330],
    [0.290, 0.600],
    [0.150, 0.060],
    [1.0 / 3.0, 1.0 / 3.0],
];

/// Largest HDR file read at all; below it, the memory available decides.
const MAX_HDR_FILE_BYTES: u64 = 1 << 40;
/// Longest header read, bytes (real headers are a few hundred bytes).
const MAX_HEADER_BYTES: usize = 1 << 20;

/// A decoded Radiance picture in candela's units.
#[derive(Clone, Debug, PartialEq)]
pub struct HdrImage {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Absolute CIE 1931 XYZ per pixel, row-major, top row first (Y = luminance, cd/m²).
    pub xyz: Vec<[f32; 3]>,
    /// The view options of the `VIEW=` lines, if any (several are joined with spaces, as
    /// Radiance applies them in order).
    pub view: Option<String>,
    /// candela's description of the camera's projection (its `CANDELA_PROJECTION=` line), if
    /// the file has one.
    pub projection: Option<String>,
}

impl HdrImage {
    /// Luminance per pixel, cd/m².
    pub fn luminance_cd_m2(&self) -> Vec<f32> {
        self.xyz.iter().map(|p| p[1]).collect()
    }

    /// As [`Layers`]: channels `X`, `Y`, `Z` (no standard error), `units = cd/m^2` and, if the
    /// file has them, the `radiance_view` and `projection` attributes.
    pub fn to_layers(&self) -> Layers {
        let component = |i: usize| self.xyz.iter().map(|p| p[i]).collect::<Vec<f32>>();
        layers_of(
            self.width,
            self.height,
            [component(0), component(1), component(2)],
            &self.view,
            &self.projection,
        )
    }
}

/// The [`Layers`] of a Radiance picture: its X, Y, Z channels and attributes.
fn layers_of(
    width: usize,
    height: usize,
    [x, y, z]: [Vec<f32>; 3],
    view: &Option<String>,
    projection: &Option<String>,
) -> Layers {
    let mut layers = Layers::new(width, height);
    layers.channels = vec![
        (super::CHANNEL_X.to_string(), x),
        (super::CHANNEL_Y.to_string(), y),
        (super::CHANNEL_Z.to_string(), z),
    ];
    layers.attributes.push((
        super::ATTRIBUTE_UNITS.to_string(),
        super::UNITS_CD_PER_M2.to_string(),
    ));
    if let Some(v) = view {
        layers
            .attributes
            .push((super::ATTRIBUTE_VIEW.to_string(), v.clone()));
    }
    if let Some(p) = projection {
        layers
            .attributes
            .push((super::ATTRIBUTE_PROJECTION.to_string(), p.clone()));
    }
    layers
}

/// The RGB → XYZ matrix (rows X, Y, Z) of primaries and white `p` (xy), white scaled to Y = 1.
pub fn rgb_to_xyz_matrix(p: &[[f64; 2]; 4]) -> Option<[[f64; 3]; 3]> {
    let xyz = |[x, y]: [f64; 2]| [x / y, 1.0, (1.0 - x - y) / y];
    let cols = [xyz(p[0]), xyz(p[1]), xyz(p[2])];
    let w = xyz(p[3]);
    let m = [
        [cols[0][0], cols[1][0], cols[2][0]],
        [cols[0][1], cols[1][1], cols[2][1]],
        [cols[0][2], cols[1][2], cols[2][2]],
    ];
    let inv = invert(&m)?;
    let s = mul(&inv, w);
    let out = [
        [m[0][0] * s[0], m[0][1] * s[1], m[0][2] * s[2]],
        [m[1][0] * s[0], m[1][1] * s[1], m[1][2] * s[2]],
        [m[2][0] * s[0], m[2][1] * s[1], m[2][2] * s[2]],
    ];
    out.iter().flatten().all(|v| v.is_finite()).then_some(out)
}

fn mul(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

fn invert(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let c =
        |r0: usize, c0: usize, r1: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    let det = m[0][0] * c(1, 1, 2, 2) - m[0][1] * c(1, 0, 2, 2) + m[0][2] * c(1, 0, 2, 1);
    if det.abs() < 1e-12 || !det.is_finite() {
        return None;
    }
    let d = 1.0 / det;
    Some([
        [c(1, 1, 2, 2) * d, -c(0, 1, 2, 2) * d, c(0, 1, 1, 2) * d],
        [-c(1, 0, 2, 2) * d, c(0, 0, 2, 2) * d, -c(0, 0, 1, 2) * d],
        [c(1, 0, 2, 1) * d, -c(0, 0, 2, 1) * d, c(0, 0, 1, 1) * d],
    ])
}

/// Radiance's RGBE encoding of one colour (truncating mantissas, as its `setcolr`).
fn rgbe([r, g, b]: [f64; 3]) -> [u8; 4] {
    let d = r.max(g).max(b);
    if d <= 1e-32 {
        return [0; 4];
    }
    let (m, e) = frexp(d);
    let k = m * 256.0 / d;
    let byte = |v: f64| (v * k).clamp(0.0, 255.0) as u8;
    [byte(r), byte(g), byte(b), (e + 128).clamp(0, 255) as u8]
}

/// d = m · 2^e with m ∈ [0.5, 1).
fn frexp(d: f64) -> (f64, i32) {
    let e = d.log2().floor() as i32 + 1;
    let mut m = d / 2f64.powi(e);
    let mut e = e;
    // Rounding of log2 near powers of two.
    if m >= 1.0 {
        m /= 2.0;
        e += 1;
    } else if m < 0.5 {
        m *= 2.0;
        e -= 1;
    }
    (m, e)
}

/// Writes absolute XYZ (cd/m², row-major, top row first) as a run-length encoded Radiance
/// RGBE picture in Radiance's standard primaries, atomically. `view` becomes the `VIEW=` line;
/// `extra` are further header lines (`NAME=value`, no newlines). Colours outside the
/// primaries' gamut are clipped to it keeping their luminance exactly (the picture's
/// luminance is candela's to RGBE precision, ~0.4 % of the largest component). NaN or
/// infinite values are refused.
pub fn write_hdr(
    path: &Path,
    width: usize,
    height: usize,
    xyz: &[[f32; 3]],
    view: Option<&str>,
    extra: &[String],
) -> Result<(), OutputError> {
    if width == 0 || height == 0 || width > i32::MAX as usize || height > i32::MAX as usize {
        return Err(OutputError::invalid(
            path,
            format!("image size {width}x{height} cannot be written as Radiance HDR"),
        ));
    }
    if xyz.len() != width * height {
        return Err(OutputError::invalid(
            path,
            format!("{} pixels given for {width}x{height}", xyz.len()),
        ));
    }
    for line in view.iter().copied().chain(extra.iter().map(String::as_str)) {
        if line.contains(['\n', '\r']) {
            return Err(OutputError::invalid(path, "header line contains a newline"));
        }
    }
    if let Some(i) = xyz.iter().position(|p| p.iter().any(|v| !v.is_finite())) {
        let c = xyz[i].iter().position(|v| !v.is_finite()).unwrap_or(0);
        return Err(OutputError::NonFinite {
            path: path.to_path_buf(),
            channel: ["X", "Y", "Z"][c].to_string(),
            x: i % width,
            y: i / width,
            value: xyz[i][c],
        });
    }
    let m = rgb_to_xyz_matrix(&RADIANCE_PRIMARIES).expect("standard primaries");
    let inv = invert(&m).expect("standard primaries");
    let lum = m[1];
    let pixels: Vec<[u8; 4]> = xyz
        .iter()
        .map(|p| {
            let v = p.map(|c| c as f64 / RADIANCE_EFFICACY);
            let y = v[1].max(0.0);
            let mut rgb = mul(&inv, v).map(|c| c.max(0.0));
            let have = lum[0] * rgb[0] + lum[1] * rgb[1] + lum[2] * rgb[2];
            if have > 0.0 {
                rgb = rgb.map(|c| c * y / have);
            } else {
                rgb = [y; 3];
            }
            rgbe(rgb)
        })
        .collect();
    let mut header = String::from("#?RADIANCE\n");
    header += &format!("SOFTWARE=candela {}\n", env!("CARGO_PKG_VERSION"));
    header += "FORMAT=32-bit_rle_rgbe\n";
    header += "EXPOSURE=1.000000e+00\n";
    let p = RADIANCE_PRIMARIES;
    header += &format!(
        "PRIMARIES= {:.4} {:.4} {:.4} {:.4} {:.4} {:.4} {:.6} {:.6}\n",
        p[0][0], p[0][1], p[1][0], p[1][1], p[2][0], p[2][1], p[3][0], p[3][1]
    );
    if let Some(v) = view {
        header += &format!("VIEW= {v}\n");
    }
    for line in extra {
        header += line;
        header += "\n";
    }
    header += &format!("\n-Y {height} +X {width}\n");
    write_atomic(path, |w| {
        w.write_all(header.as_bytes())?;
        let mut buf = Vec::with_capacity(width * 5);
        for row in pixels.chunks(width) {
            buf.clear();
            encode_scanline(row, &mut buf);
            w.write_all(&buf)?;
        }
        Ok(())
    })
}

/// One scanline, new-style run-length encoded when its width allows (8 to 32767), else flat.
fn encode_scanline(row: &[[u8; 4]], out: &mut Vec<u8>) {
    let n = row.len();
    if !(8..=0x7fff).contains(&n) {
        out.extend(row.iter().flatten());
        return;
    }
    out.extend([2, 2, (n >> 8) as u8, (n & 255) as u8]);
    for c in 0..4 {
        let v: Vec<u8> = row.iter().map(|p| p[c]).collect();
        let mut i = 0;
        while i < n {
            // Next run of ≥ 4 equal bytes at or after i.
            let mut beg = i;
            let mut run = 0;
            while beg < n {
                run = 1;
                while run < 127 && beg + run < n && v[beg + run] == v[beg] {
                    run += 1;
                }
                if run >= 4 {
                    break;
                }
                beg += run;
            }
            if beg >= n {
                run = 0;
            }
            // Literals before it, at most 128 at a time.
            while i < beg {
                let k = (beg - i).min(128);
                out.push(k as u8);
                out.extend(&v[i..i + k]);
                i += k;
            }
            if run >= 4 {
                out.extend([128 + run as u8, v[beg]]);
                i = beg + run;
            }
        }
    }
}

/// Reads a Radiance picture (RGBE or XYZE; new-style run-length encoded, old-style or flat
/// scanlines; top-to-bottom or bottom-to-top rows) into absolute XYZ in cd/m², undoing
/// `EXPOSURE` and `COLORCORR` and using its `PRIMARIES`. A malformed, truncated or
/// unsupported file gives [`OutputError::Hdr`] naming it; so does a resolution line that
/// declares more scanlines than the rest of the file could hold at the densest encoding.
/// An image that would not fit in the memory available is refused before its pixels are
/// allocated.
pub fn read_hdr(path: &Path) -> Result<HdrImage, OutputError> {
    let bytes = read_bytes(path)?;
    let hdr_err = |message| OutputError::Hdr {
        path: path.to_path_buf(),
        message,
    };
    let head = parse_header(&bytes).map_err(hdr_err)?;
    let (w, h) = (head.width, head.height);
    let n = head.check_size(path, bytes.len(), 0)?;
    let mut xyz = vec![[0f32; 3]; n];
    head.decode(&bytes, |y, row| {
        xyz[y * w..(y + 1) * w].copy_from_slice(row);
    })
    .map_err(hdr_err)?;
    Ok(HdrImage {
        width: w,
        height: h,
        xyz,
        view: head.view(),
        projection: head.projection,
    })
}

/// A Radiance picture read straight into [`Layers`] (as [`HdrImage::to_layers`], without the
/// intermediate copy), checking first that the decoded channels and `beside_bytes_per_pixel`
/// more (what the caller will hold per pixel beside them) fit in the memory available.
pub(super) fn read_hdr_layers(
    path: &Path,
    beside_bytes_per_pixel: u64,
) -> Result<Layers, OutputError> {
    let bytes = read_bytes(path)?;
    let hdr_err = |message| OutputError::Hdr {
        path: path.to_path_buf(),
        message,
    };
    let head = parse_header(&bytes).map_err(hdr_err)?;
    let w = head.width;
    let n = head.check_size(path, bytes.len(), beside_bytes_per_pixel)?;
    let (mut x, mut y, mut z) = (vec![0f32; n], vec![0f32; n], vec![0f32; n]);
    head.decode(&bytes, |r, row| {
        let at = r * w;
        for (i, p) in row.iter().enumerate() {
            (x[at + i], y[at + i], z[at + i]) = (p[0], p[1], p[2]);
        }
    })
    .map_err(hdr_err)?;
    Ok(layers_of(
        w,
        head.height,
        [x, y, z],
        &head.view(),
        &head.projection,
    ))
}

fn read_bytes(path: &Path) -> Result<Vec<u8>, OutputError> {
    crate::limits::read_file(path, MAX_HDR_FILE_BYTES).map_err(|source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Width, height, luminance (cd/m², row-major, top row first) and the view options (if any)
/// of a Radiance picture: what glare evaluation needs.
pub fn read_hdr_luminance(
    path: &Path,
) -> Result<(usize, usize, Vec<f32>, Option<String>), OutputError> {
    let img = read_hdr(path)?;
    let l = img.luminance_cd_m2();
    Ok((img.width, img.height, l, img.view))
}

/// Whether `bytes` start like a Radiance picture.
pub fn looks_like_hdr(bytes: &[u8]) -> bool {
    bytes.starts_with(b"#?")
}

/// Fewest bytes a scanline of `width` pixels takes in any encoding [`read_scanline`] reads: a
/// literal pixel, then old-style runs of it whose counts are the base-256 digits of the
/// remaining `width − 1` pixels, 4 bytes each (a new-style scanline takes at least 12 bytes,
/// never fewer than this for the widths it allows).
pub fn min_scanline_bytes(width: usize) -> u64 {
    let mut rest = width.saturating_sub(1) as u64;
    let mut bytes = 4;
    while rest > 0 {
        bytes += 4;
        rest >>= 8;
    }
    bytes
}

/// What the header and the resolution line of a Radiance picture say.
struct Header {
    /// Offset of the first scanline.
    data: usize,
    width: usize,
    height: usize,
    /// `+Y`: the first scanline is the bottom row.
    flip: bool,
    exposure: [f64; 3],
    primaries: [[f64; 2]; 4],
    xyze: bool,
    views: Vec<String>,
    projection: Option<String>,
}

impl Header {
    fn view(&self) -> Option<String> {
        (!self.views.is_empty()).then(|| self.views.join(" "))
    }

    /// The number of pixels, once it is known that the file can hold them
    /// ([`OutputError::Hdr`] if not) and that they fit in the memory available as three f32
    /// channels with `beside_bytes_per_pixel` more ([`OutputError::InvalidImage`] if not).
    fn check_size(
        &self,
        path: &Path,
        file_len: usize,
        beside_bytes_per_pixel: u64,
    ) -> Result<usize, OutputError> {
        let (w, h) = (self.width, self.height);
        let hdr_err = |message| OutputError::Hdr {
            path: path.to_path_buf(),
            message,
        };
        let n = w
            .checked_mul(h)
            .ok_or_else(|| hdr_err(format!("image size {w}×{h} is too large")))?;
        let least = (h as u64).saturating_mul(min_scanline_bytes(w));
        let have = (file_len - self.data) as u64;
        if have < least {
            return Err(hdr_err(format!(
                "the resolution line declares {w}×{h} pixels: {h} scanlines of {w} pixels take at least {least} bytes even run-length encoded, and the file has {have} after its header: it is truncated or corrupt"
            )));
        }
        crate::limits::check_memory(
            (n as u64)
                .saturating_mul(12 + beside_bytes_per_pixel)
                .saturating_add(file_len as u64 + crate::limits::BASE_BYTES),
            &format!("decoding the {w}×{h} Radiance picture"),
        )
        .map_err(|reason| OutputError::invalid(path, reason))?;
        Ok(n)
    }

    /// Decodes every scanline, giving `row(y, xyz)` each row (top row first by index `y`) in
    /// absolute XYZ, cd/m².
    fn decode(&self, bytes: &[u8], mut row: impl FnMut(usize, &[[f32; 3]])) -> Result<(), String> {
        let (w, h) = (self.width, self.height);
        let m = if self.xyze {
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        } else {
            rgb_to_xyz_matrix(&self.primaries).ok_or("PRIMARIES are degenerate")?
        };
        let mut rgbe_row = vec![[0u8; 4]; w];
        let mut xyz_row = vec![[0f32; 3]; w];
        let mut data = &bytes[self.data..];
        for s in 0..h {
            read_scanline(&mut data, &mut rgbe_row).map_err(|e| format!("scanline {s}: {e}"))?;
            let y = if self.flip { h - 1 - s } else { s };
            for (x, (p, out)) in rgbe_row.iter().zip(xyz_row.iter_mut()).enumerate() {
                let c = if p[3] == 0 {
                    [0.0; 3]
                } else {
                    let f = 2f64.powi(p[3] as i32 - 136);
                    [0, 1, 2].map(|i| (p[i] as f64 + 0.5) * f / self.exposure[i])
                };
                let v = mul(&m, c).map(|k| (k.max(0.0) * RADIANCE_EFFICACY) as f32);
                if !v.iter().all(|k| k.is_finite()) {
                    return Err(format!(
                        "pixel ({x}, {y}) is too bright for 32-bit floats ({} cd/m² or more)",
                        f32::MAX
                    ));
                }
                *out = v;
            }
            row(y, &xyz_row);
        }
        Ok(())
    }
}

/// The header lines up to the first empty one, and the resolution line after it.
fn parse_header(bytes: &[u8]) -> Result<Header, String> {
    if !looks_like_hdr(bytes) {
        return Err("no Radiance header (the file does not start with \"#?\")".into());
    }
    let mut pos = 0;
    let mut exposure = [1.0f64; 3];
    let mut primaries = RADIANCE_PRIMARIES;
    let mut xyze = false;
    let mut views: Vec<String> = Vec::new();
    let mut projection = None;
    loop {
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .ok_or("the header does not end (no empty line): the file is truncated")?;
        if pos + end > MAX_HEADER_BYTES {
            return Err(format!(
                "the header is longer than {MAX_HEADER_BYTES} bytes"
            ));
        }
        let line = String::from_utf8_lossy(&bytes[pos..pos + end]).into_owned();
        pos += end + 1;
        let line = line.trim_end_matches('\r');
        if line.is_empty() {
            break;
        }
        let numbers = |rest: &str, n: usize, what: &str| -> Result<Vec<f64>, String> {
            let v: Vec<f64> = rest
                .split_whitespace()
                .map(|t| t.parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| format!("{what} line '{line}' is not {n} numbers"))?;
            if v.len() != n || v.iter().any(|x| !x.is_finite()) {
                return Err(format!("{what} line '{line}' is not {n} finite numbers"));
            }
            Ok(v)
        };
        if let Some(f) = line.strip_prefix("FORMAT=") {
            match f.trim() {
                "32-bit_rle_rgbe" => xyze = false,
                "32-bit_rle_xyze" => xyze = true,
                other => return Err(format!("unsupported FORMAT '{other}'")),
            }
        } else if let Some(e) = line.strip_prefix("EXPOSURE=") {
            let e = numbers(e, 1, "EXPOSURE")?[0];
            if e <= 0.0 {
                return Err(format!("EXPOSURE must be positive, got {e}"));
            }
            exposure = exposure.map(|x| x * e);
            if !exposure.iter().all(|x| x.is_normal()) {
                return Err("the EXPOSURE lines multiply to a factor out of range".into());
            }
        } else if let Some(c) = line.strip_prefix("COLORCORR=") {
            let c = numbers(c, 3, "COLORCORR")?;
            if c.iter().any(|&x| x <= 0.0) {
                return Err("COLORCORR factors must be positive".into());
            }
            for i in 0..3 {
                exposure[i] *= c[i];
            }
            if !exposure.iter().all(|x| x.is_normal()) {
                return Err("the COLORCORR lines multiply to a factor out of range".into());
            }
        } else if let Some(p) = line.strip_prefix("PRIMARIES=") {
            let v = numbers(p, 8, "PRIMARIES")?;
            primaries = [[v[0], v[1]], [v[2], v[3]], [v[4], v[5]], [v[6], v[7]]];
        } else if let Some(v) = line.strip_prefix("VIEW=") {
            views.push(v.trim().to_string());
        } else if let Some(v) = line.strip_prefix("CANDELA_PROJECTION=") {
            projection = Some(v.trim().to_string());
        }
    }
    // Resolution string.
    let end = bytes[pos..]
        .iter()
        .position(|&b| b == b'\n')
        .filter(|&e| e < 64)
        .ok_or("no resolution line after the header: the file is truncated or corrupt")?;
    let res = String::from_utf8_lossy(&bytes[pos..pos + end]).into_owned();
    pos += end + 1;
    let t: Vec<&str> = res.split_whitespace().collect();
    let bad_res = || {
        format!(
            "resolution line '{}' is not '-Y H +X W'",
            crate::limits::printable(res.trim(), 64)
        )
    };
    if t.len() != 4 || t[2] != "+X" {
        return Err(bad_res());
    }
    let flip = match t[0] {
        "-Y" => false,
        "+Y" => true,
        _ => return Err(bad_res()),
    };
    let height: usize = t[1].parse().map_err(|_| bad_res())?;
    let width: usize = t[3].parse().map_err(|_| bad_res())?;
    if width == 0 || height == 0 || width > i32::MAX as usize || height > i32::MAX as usize {
        return Err(format!("image size {width}×{height} is empty or too large"));
    }
    Ok(Header {
        data: pos,
        width,
        height,
        flip,
        exposure,
        primaries,
        xyze,
        views,
        projection,
    })
}

fn take<'a>(data: &mut &'a [u8], n: usize) -> Result<&'a [u8], String> {
    if data.len() < n {
        return Err("the file ends early (truncated)".into());
    }
    let (a, b) = data.split_at(n);
    *data = b;
    Ok(a)
}

/// One scanline (new-style RLE, old-style RLE or flat) into `row`.
fn read_scanline(data: &mut &[u8], row: &mut [[u8; 4]]) -> Result<(), String> {
    let n = row.len();
    let new_style = (8..=0x7fff).contains(&n)
        && data.len() >= 4
        && data[0] == 2
        && data[1] == 2
        && data[2] & 0x80 == 0;
    if !new_style {
        return read_old_scanline(data, row);
    }
    let h = take(data, 4)?;
    let len = ((h[2] as usize) << 8) | h[3] as usize;
    if len != n {
        return Err(format!("run-length scanline of {len} pixels, expected {n}"));
    }
    for c in 0..4 {
        let mut j = 0;
        while j < n {
            let code = take(data, 1)?[0] as usize;
            if code > 128 {
                let k = code & 127;
                let v = take(data, 1)?[0];
                if j + k > n {
                    return Err("a run overruns the scanline".into());
                }
                for p in &mut row[j..j + k] {
                    p[c] = v;
                }
                j += k;
            } else {
                if j + code > n {
                    return Err("literal bytes overrun the scanline".into());
                }
                let v = take(data, code)?;
                for (p, &b) in row[j..j + code].iter_mut().zip(v) {
                    p[c] = b;
                }
                j += code;
            }
        }
    }
    Ok(())
}

/// Flat pixels, with old-style runs (1, 1, 1, count) repeating the previous pixel.
fn read_old_scanline(data: &mut &[u8], row: &mut [[u8; 4]]) -> Result<(), String> {
    let n = row.len();
    let mut j = 0;
    let mut shift = 0u32;
    while j < n {
        let p = take(data, 4)?;
        if p[0] == 1 && p[1] == 1 && p[2] == 1 {
            if j == 0 {
                return Err("a run repeats no previous pixel".into());
            }
            if shift > 24 {
                return Err("run-length count too large".into());
            }
            let k = (p[3] as usize) << shift;
            if j + k > n {
                return Err("a run overruns the scanline".into());
            }
            let prev = row[j - 1];
            row[j..j + k].fill(prev);
            j += k;
            shift += 8;
        } else {
            row[j] = [p[0], p[1], p[2], p[3]];
            j += 1;
            shift = 0;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radiance_luminance_coefficients_follow_from_its_primaries() {
        let m = rgb_to_xyz_matrix(&RADIANCE_PRIMARIES).unwrap();
        // Radiance 6's `pvalue -o -b -dd` of pictures of its three unit primaries, solved for
        // the half step RGBE decoding adds to every channel.
        let want = [0.26510582, 0.67010582, 0.06478836];
        for i in 0..3 {
            assert!((m[1][i] - want[i]).abs() < 1e-8, "{:?}", m[1]);
        }
    }

    #[test]
    fn rle_round_trips_runs_and_literals() {
        let mut row: Vec<[u8; 4]> = (0..300).map(|i| [(i / 7) as u8, 3, i as u8, 130]).collect();
        row[100..250].fill([9, 9, 9, 9]);
        let mut buf = Vec::new();
        encode_scanline(&row, &mut buf);
        assert!(buf.len() < 300 * 4);
        let mut back = vec![[0u8; 4]; 300];
        let mut data = buf.as_slice();
        read_scanline(&mut data, &mut back).unwrap();
        assert!(data.is_empty());
        assert_eq!(back, row);
    }

    #[test]
    fn rgbe_is_radiance_setcolr() {
        // 1.0 → mantissa 128, exponent 129; decoding adds half a step.
        assert_eq!(rgbe([1.0, 0.5, 0.0]), [128, 64, 0, 129]);
        assert_eq!(rgbe([0.0; 3]), [0; 4]);
    }
}
