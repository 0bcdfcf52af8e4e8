//! Image textures of diffuse reflectance. An sRGB PNG or JPEG (decoded with the sRGB transfer
//! function) or a linear OpenEXR (channels R, G, B) is turned, once at load, into one smooth
//! reflectance spectrum per texel by [`crate::spectrum::rgb_upsample`]: each texel keeps the
//! three sigmoid coefficients of its spectrum (12 bytes, [`BYTES_PER_TEXEL`]), not the
//! spectrum. A lookup filters bilinearly, evaluating the four texels' spectra at the path's
//! wavelengths. Texture coordinates go through a 2×3 affine map ([`UvMap`]: scale, rotation,
//! offset), then are wrapped (repeated or clamped); v = 0 is the bottom row of the image, as in
//! OBJ files. Scalar and normal maps (one to three linear 8-bit channels) are in [`bytes`].

pub mod bytes;
pub mod emission;

use crate::spectrum::rgb_upsample::fit_linear_srgb;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, N_LAMBDA};
use glam::{Affine2, Vec2};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Memory of one texel once loaded, bytes: three f32 sigmoid coefficients.
pub const BYTES_PER_TEXEL: u64 = 12;

/// Most texels of one texture (16 k × 16 k).
pub const MAX_TEXELS: u64 = 1 << 28;

/// Largest image file read.
pub(crate) const MAX_TEXTURE_FILE_BYTES: u64 = 4 << 30;

/// Peak bytes per texel while loading a reflectance texture, with room to spare: the decoded
/// image (up to 16 B, the limit the decoder is given), its 8-bit copy (3 B), the linear colours (12 B), the
/// colour index (4 B), the map of distinct colours (up to ~24 B) and the coefficients (12 B).
pub(crate) const LOAD_BYTES_PER_TEXEL: u64 = 64;

/// The same for an emission texture, which keeps 8 B more per texel (a scale and a luminance,
/// [`emission::BYTES_PER_TEXEL`] in all).
pub(crate) const LOAD_EMISSION_BYTES_PER_TEXEL: u64 = LOAD_BYTES_PER_TEXEL + 8;

/// Peak bytes per texel while loading a byte texture ([`bytes::ByteTexture`]): the decoded
/// image (up to 16 B, the decoder's limit), its 8-bit RGB copy (3 B) and the kept channels (up
/// to 3 B).
pub(crate) const LOAD_BYTE_MAP_BYTES_PER_TEXEL: u64 = 22;

/// Wavelength span of the normalised coefficients: t = (λ − 360 nm) / 470 nm.
const T_MIN_NM: f64 = 360.0;
const T_SPAN_NM: f64 = 470.0;

/// How texture coordinates outside [0, 1] are mapped into the image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
pub enum Wrap {
    /// Tiles the image.
    #[default]
    Repeat,
    /// Extends the edge texels.
    Clamp,
}

/// A texture could not be loaded.
#[derive(Debug, thiserror::Error)]
#[error("cannot use texture image '{}': {message}.", path.display())]
pub struct TextureError {
    pub path: PathBuf,
    pub message: String,
}

/// A reflectance texture (see the module docs).
#[derive(Clone, Debug)]
pub struct Texture {
    width: u32,
    height: u32,
    /// Per texel, top row first: (a0, a1, a2) of R(λ) = S((a0·t + a1)·t + a2), t as
    /// [`T_MIN_NM`]; ±∞ in a2 for the exact constants 1 and 0.
    coeffs: Vec<[f32; 3]>,
    pub wrap: Wrap,
    /// Texture coordinates are mapped by it before wrapping.
    pub uv: UvMap,
}

/// The affine map applied to texture coordinates before wrapping (identity by default).
pub type UvMap = Affine2;

/// `uv · scale + offset`.
pub fn scale_offset(scale: [f32; 2], offset: [f32; 2]) -> UvMap {
    Affine2::from_scale_angle_translation(Vec2::from(scale), 0.0, Vec2::from(offset))
}

/// glTF's `KHR_texture_transform` (uv′ = T(offset)·R(rotation)·S(scale)·uv, the rotation's
/// matrix [[cos, −sin], [sin, cos]] as the extension's GLSL gives it, in glTF's coordinates
/// whose v runs down the image) as a map of candela's coordinates (v up, v_candela =
/// 1 − v_glTF): F·M·F with F(u, v) = (u, 1 − v).
pub fn gltf_uv_map(offset: [f32; 2], rotation_rad: f32, scale: [f32; 2]) -> UvMap {
    let m =
        Affine2::from_scale_angle_translation(Vec2::from(scale), rotation_rad, Vec2::from(offset));
    let flip = Affine2::from_cols(Vec2::X, -Vec2::Y, Vec2::Y);
    flip * m * flip
}

/// The bilinear footprint of texture coordinates `tex` on a `width × height` image: the two
/// columns and two rows (top row 0) and their weights.
#[inline(always)]
pub(crate) fn footprint(
    uv: &UvMap,
    wrap: Wrap,
    width: u32,
    height: u32,
    tex: Vec2,
) -> ([usize; 2], [usize; 2], [f32; 2], [f32; 2]) {
    let uv = uv.transform_point2(tex);
    let x = uv.x * width as f32 - 0.5;
    let y = (1.0 - uv.y) * height as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = match (x - x0, y - y0) {
        (fx, fy) if fx.is_finite() && fy.is_finite() => (fx, fy),
        _ => (0.0, 0.0),
    };
    let (xi, yi) = (x0 as i64, y0 as i64);
    let index = |i: i64, n: u32| match wrap {
        Wrap::Repeat => i.rem_euclid(n as i64) as usize,
        Wrap::Clamp => i.clamp(0, n as i64 - 1) as usize,
    };
    (
        [index(xi, width), index(xi + 1, width)],
        [index(yi, height), index(yi + 1, height)],
        [1.0 - fx, fx],
        [1.0 - fy, fy],
    )
}

/// Refuses an image of `w × h` texels that is empty, over [`MAX_TEXELS`] or too large for the
/// memory available, loading taking `per_texel` bytes per texel at its peak.
pub(crate) fn check_size(path: &Path, w: u64, h: u64, per_texel: u64) -> Result<(), TextureError> {
    let err = |message: String| TextureError {
        path: path.to_path_buf(),
        message,
    };
    let n = w.saturating_mul(h);
    if w == 0 || h == 0 {
        return Err(err("the image has no pixels".into()));
    }
    if n > MAX_TEXELS {
        return Err(err(format!(
            "the image is {w}×{h} pixels, more than the {MAX_TEXELS} texels a texture may have"
        )));
    }
    crate::limits::check_memory(
        n.saturating_mul(per_texel),
        &format!("loading this {w}×{h} texture"),
    )
    .map_err(err)
}

/// The sigmoid S(x) = ½ + x / (2√(1+x²)) in f32 (exactly 0 or 1 beyond |x| = 10¹⁰).
#[inline(always)]
fn sigmoid(x: f32) -> f32 {
    if x.abs() > 1e10 {
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    0.5 + 0.5 * x / (1.0 + x * x).sqrt()
}

impl Texture {
    /// A texture from linear-sRGB reflectance colours (each component clamped to [0, 1]),
    /// `width × height`, top row first. Each distinct colour is fitted once.
    pub fn from_linear_rgb(width: u32, height: u32, texels: &[[f32; 3]]) -> Texture {
        assert_eq!(texels.len(), width as usize * height as usize);
        let (ids, fitted) = fit_distinct(texels, |c| c.map(|v| v.clamp(0.0, 1.0)), coefficients);
        Texture {
            width,
            height,
            coeffs: ids.iter().map(|&i| fitted[i as usize]).collect(),
            wrap: Wrap::Repeat,
            uv: UvMap::IDENTITY,
        }
    }

    /// Loads an image: PNG or JPEG (sRGB-encoded; alpha ignored) or OpenEXR (linear R, G, B);
    /// components are clamped to [0, 1]. A missing or unreadable file, another format, an
    /// image over [`MAX_TEXELS`] or one that would not fit in the memory available (checked
    /// from its header, before decoding) is an error naming the file.
    pub fn load(path: &Path) -> Result<Texture, TextureError> {
        let bytes =
            crate::limits::read_file(path, MAX_TEXTURE_FILE_BYTES).map_err(|e| TextureError {
                path: path.to_path_buf(),
                message: e.to_string(),
            })?;
        let (w, h, texels) = linear_texels(path, &bytes, [1.0; 3], LOAD_BYTES_PER_TEXEL)?;
        Ok(Texture::from_linear_rgb(w, h, &texels))
    }

    /// A texture from the bytes of a PNG or JPEG image (sRGB-encoded; alpha ignored), each
    /// texel's linear colour multiplied by `tint` (in [0, 1]) before upsampling; `path` names it
    /// in messages. Checked as [`Texture::load`].
    pub fn decode(path: &Path, bytes: &[u8], tint: [f32; 3]) -> Result<Texture, TextureError> {
        let (w, h, texels) = linear_texels(path, bytes, tint, LOAD_BYTES_PER_TEXEL)?;
        Ok(Texture::from_linear_rgb(w, h, &texels))
    }

    pub fn width(&self) -> u32 {
        self.width
    }
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Heap memory, bytes.
    pub fn memory_bytes(&self) -> usize {
        self.coeffs.capacity() * BYTES_PER_TEXEL as usize
    }

    /// Reflectance of texel (`x`, `y`) (y = 0 the top row) at `nm`.
    pub fn texel_reflectance(&self, x: u32, y: u32, nm: f64) -> f64 {
        shape_at(self.coeffs[(y * self.width + x) as usize], nm)
    }

    /// Reflectance at texture coordinates `tex` (bilinear), per wavelength of `wl`.
    pub fn reflectance(&self, tex: Vec2, wl: &SampledWavelengths) -> SampledSpectrum {
        let fp = footprint(&self.uv, self.wrap, self.width, self.height, tex);
        bilinear_shapes(&self.coeffs, self.width, fp, wl, |_| 1.0)
    }
}

/// The spectrum of sigmoid coefficients `co` (as [`Texture`] keeps them) at `nm`, in f64.
fn shape_at(co: [f32; 3], nm: f64) -> f64 {
    let [a0, a1, a2] = co.map(|v| v as f64);
    let t = (nm - T_MIN_NM) / T_SPAN_NM;
    let x = (a0 * t + a1) * t + a2;
    if x.is_infinite() {
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    0.5 + 0.5 * x / (1.0 + x * x).sqrt()
}

/// Σ w·`weight`(texel)·S_texel(λ) over the bilinear footprint `fp` ([`footprint`]) of an image
/// `width` texels wide whose texels' spectra have coefficients `coeffs`, at the wavelengths
/// of `wl`.
#[inline(always)]
fn bilinear_shapes(
    coeffs: &[[f32; 3]],
    width: u32,
    (cols, rows, wxs, wys): ([usize; 2], [usize; 2], [f32; 2], [f32; 2]),
    wl: &SampledWavelengths,
    weight: impl Fn(usize) -> f32,
) -> SampledSpectrum {
    let mut t = [0.0f32; N_LAMBDA];
    for (t, l) in t.iter_mut().zip(wl.lambda.iter()) {
        *t = (l - T_MIN_NM as f32) * (1.0 / T_SPAN_NM as f32);
    }
    let mut out = SampledSpectrum::ZERO;
    for (r, wy) in rows.iter().zip(wys) {
        for (c, wx) in cols.iter().zip(wxs) {
            let i = r * width as usize + c;
            let w = wx * wy;
            if w == 0.0 {
                continue;
            }
            let w = w * weight(i);
            let [a0, a1, a2] = coeffs[i];
            for (o, t) in out.0.iter_mut().zip(t) {
                *o += w * sigmoid((a0 * t + a1) * t + a2);
            }
        }
    }
    out
}

/// The linear-sRGB colours of an image's texels (top row first) times `tint`, with its width
/// and height: an OpenEXR file's R, G, B as they are (non-finite values as 0; read from
/// `path`, which `bytes` came from), or a PNG's or JPEG's decoded with the sRGB transfer
/// function (alpha ignored). Checked as [`Texture::load`], loading taking `per_texel` bytes per
/// texel at its peak; `path` names the image in messages.
pub(crate) fn linear_texels(
    path: &Path,
    bytes: &[u8],
    tint: [f32; 3],
    per_texel: u64,
) -> Result<(u32, u32, Vec<[f32; 3]>), TextureError> {
    let err = |message: String| TextureError {
        path: path.to_path_buf(),
        message,
    };
    if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        let layers = crate::output::read_exr(path).map_err(|e| err(e.to_string()))?;
        check_size(path, layers.width as u64, layers.height as u64, per_texel)?;
        let ch = |name: &str| {
            layers
                .channel(name)
                .ok_or_else(|| err(format!("the OpenEXR image has no channel {name:?}")))
        };
        let (r, g, b) = (ch("R")?, ch("G")?, ch("B")?);
        let texels = (0..r.len())
            .map(|i| {
                let c = [r[i], g[i], b[i]].map(|v| if v.is_finite() { v } else { 0.0 });
                [c[0] * tint[0], c[1] * tint[1], c[2] * tint[2]]
            })
            .collect();
        return Ok((layers.width as u32, layers.height as u32, texels));
    }
    let rgb = decode_rgb8(path, bytes, per_texel)?;
    let (w, h) = rgb.dimensions();
    let lut: Vec<f32> = (0..=255u8)
        .map(|v| crate::colour::rgb::srgb_decode(v as f64 / 255.0) as f32)
        .collect();
    let texels = rgb
        .pixels()
        .map(|p| {
            let c = p.0.map(|v| lut[v as usize]);
            [c[0] * tint[0], c[1] * tint[1], c[2] * tint[2]]
        })
        .collect();
    Ok((w, h, texels))
}

/// Each distinct colour of `texels` (after `clean`) passed once to `fit`, in parallel: per
/// texel the index of its colour's fit, and the fits.
fn fit_distinct<T: Send>(
    texels: &[[f32; 3]],
    clean: impl Fn(&[f32; 3]) -> [f32; 3],
    fit: impl Fn([f64; 3]) -> T + Sync,
) -> (Vec<u32>, Vec<T>) {
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    let mut distinct: Vec<[u32; 3]> = Vec::new();
    let ids: Vec<u32> = texels
        .iter()
        .map(|c| {
            let k = clean(c).map(f32::to_bits);
            *index.entry(k).or_insert_with(|| {
                distinct.push(k);
                distinct.len() as u32 - 1
            })
        })
        .collect();
    drop(index);
    use rayon::prelude::*;
    let fitted = distinct
        .par_iter()
        .map(|k| fit(k.map(|b| f32::from_bits(b) as f64)))
        .collect();
    (ids, fitted)
}

/// The 8-bit RGB texels of a PNG or JPEG image (alpha dropped), after the checks of
/// [`Texture::load`] (loading taking `per_texel` bytes per texel at its peak, checked from the
/// header before decoding); `path` names it in messages.
pub(crate) fn decode_rgb8(
    path: &Path,
    bytes: &[u8],
    per_texel: u64,
) -> Result<image::RgbImage, TextureError> {
    let err = |message: String| TextureError {
        path: path.to_path_buf(),
        message,
    };
    let check = |w: u64, h: u64| check_size(path, w, h, per_texel);
    let reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| err(e.to_string()))?;
    match reader.format() {
        Some(image::ImageFormat::Png | image::ImageFormat::Jpeg) => {}
        _ => {
            return Err(err(
                "it is not a PNG, JPEG or OpenEXR image (judged by its first bytes)".into(),
            ))
        }
    }
    let (w, h) = reader
        .into_dimensions()
        .map_err(|e| err(format!("cannot read its header: {e}")))?;
    check(w as u64, h as u64)?;
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| err(e.to_string()))?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(w);
    limits.max_image_height = Some(h);
    // The decoder's own bound, so that an image whose data claims more than its header cannot
    // allocate past what was checked.
    limits.max_alloc = Some((w as u64 * h as u64).saturating_mul(16).max(1 << 20));
    reader.limits(limits);
    let img = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| reader.decode()))
        .map_err(|_| err("the image decoder failed on malformed input".into()))?
        .map_err(|e| err(e.to_string()))?;
    Ok(img.to_rgb8())
}

/// Normalised sigmoid coefficients of the smooth spectrum of a linear-sRGB colour in [0, 1].
fn coefficients(rgb: [f64; 3]) -> [f32; 3] {
    let (s, _) = fit_linear_srgb(rgb).expect("components are clamped to [0, 1]");
    if let Some(v) = s.constant {
        return [
            0.0,
            0.0,
            if v > 0.5 {
                f32::INFINITY
            } else {
                f32::NEG_INFINITY
            },
        ];
    }
    // c in nm: c0 λ² + c1 λ + c2 with λ = L + S t.
    let [c0, c1, c2] = s.c;
    let (l, sp) = (T_MIN_NM, T_SPAN_NM);
    [
        (c0 * sp * sp) as f32,
        ((c1 + 2.0 * c0 * l) * sp) as f32,
        (c0 * l * l + c1 * l + c2) as f32,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texels_hold_the_upsampled_spectra() {
        let colours = [
            [0.2f32, 0.5, 0.1],
            [1.0, 1.0, 1.0],
            [0.0, 0.0, 0.0],
            [0.3; 3],
        ];
        let t = Texture::from_linear_rgb(2, 2, &colours);
        for (i, c) in colours.iter().enumerate() {
            let (s, _) = fit_linear_srgb(c.map(|v| v as f64)).unwrap();
            for nm in [380.0, 455.5, 560.0, 700.0, 780.0] {
                let want = s.value(nm);
                let got = t.texel_reflectance(i as u32 % 2, i as u32 / 2, nm);
                assert!((got - want).abs() < 1e-5, "{c:?} at {nm}: {got} vs {want}");
            }
        }
        // Bilinear: the centre of the image averages the four texels; a texel's centre is
        // the texel (v = 0 is the bottom row).
        let wl = SampledWavelengths::sample_visible(0.3);
        let mid = t.reflectance(Vec2::new(0.5, 0.5), &wl);
        let corner = t.reflectance(Vec2::new(0.25, 0.25), &wl);
        for k in 0..N_LAMBDA {
            let l = wl.lambda[k] as f64;
            let mean = (0..4)
                .map(|i| t.texel_reflectance(i % 2, i / 2, l))
                .sum::<f64>()
                / 4.0;
            assert!((mid.0[k] as f64 - mean).abs() < 1e-5);
            let want = t.texel_reflectance(0, 1, l);
            assert!((corner.0[k] as f64 - want).abs() < 1e-5);
        }
    }
}

#[cfg(test)]
mod uv_map_tests {
    use super::bytes::ByteTexture;
    use super::*;

    /// The extension's formula written out in glTF's coordinates: u′ = oₓ + cos·sₓ·u −
    /// sin·s_y·v, v′ = o_y + sin·sₓ·u + cos·s_y·v.
    fn by_hand(o: [f32; 2], r: f32, s: [f32; 2], g: Vec2) -> Vec2 {
        let (sin, cos) = r.sin_cos();
        Vec2::new(
            o[0] + cos * s[0] * g.x - sin * s[1] * g.y,
            o[1] + sin * s[0] * g.x + cos * s[1] * g.y,
        )
    }

    #[test]
    fn gltf_map_is_the_extensions_formula_with_v_flipped() {
        let (o, r, s) = ([0.3, -0.2], 0.7, [1.5, 0.5]);
        let map = gltf_uv_map(o, r, s);
        for c in [Vec2::ZERO, Vec2::new(0.2, 0.9), Vec2::new(-1.3, 2.5)] {
            let g = by_hand(o, r, s, Vec2::new(c.x, 1.0 - c.y));
            let want = Vec2::new(g.x, 1.0 - g.y);
            assert!((map.transform_point2(c) - want).length() < 1e-5, "{c}");
        }
        // Without rotation it is the scale and offset candela had: v·s + (1 − s − o).
        let m = gltf_uv_map([0.25, 0.5], 0.0, [2.0, 3.0]);
        let want = scale_offset([2.0, 3.0], [0.25, 1.0 - 3.0 - 0.5]);
        assert!(m.abs_diff_eq(want, 1e-6));
    }

    #[test]
    fn rotated_texture_equals_the_image_rotated_beforehand() {
        // A 90° rotation reads image I at glTF (u′, v′) = (−v, u): texel (row j, column i) of
        // the pre-rotated image P is texel (row i, column N − 1 − j) of I.
        let n = 4u32;
        let value = |row: u32, col: u32| [(row * n + col) as u8 * 13];
        let i_img: Vec<[u8; 1]> = (0..n * n).map(|k| value(k / n, k % n)).collect();
        let p_img: Vec<[u8; 1]> = (0..n * n).map(|k| value(k % n, n - 1 - k / n)).collect();
        let mut rotated = ByteTexture::<1>::from_texels(n, n, i_img);
        rotated.uv = gltf_uv_map([0.0, 0.0], std::f32::consts::FRAC_PI_2, [1.0, 1.0]);
        let pre = ByteTexture::<1>::from_texels(n, n, p_img);
        for row in 0..n {
            for col in 0..n {
                // Texel centre in candela's coordinates (v up from the bottom row).
                let c = Vec2::new(
                    (col as f32 + 0.5) / n as f32,
                    1.0 - (row as f32 + 0.5) / n as f32,
                );
                let (a, b) = (rotated.lookup(c)[0], pre.lookup(c)[0]);
                assert!((a - b).abs() < 1e-4, "row {row} col {col}: {a} vs {b}");
                assert!((b - pre.texel(col, row)[0]).abs() < 1e-6);
            }
        }
    }
}
