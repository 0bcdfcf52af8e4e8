//! Emission textures: a surface whose luminance and colour vary over it (glTF's
//! `emissiveTexture`, OBJ's `map_Ke`, a scene emission whose spectrum is a `Texture`). A texel of
//! linear-sRGB colour c ≥ 0 emits luminance Y(c) = 0.2126 r + 0.7152 g + 0.0722 b cd/m² per cd/m²
//! of the light's `Luminance` amount, with the spectral shape of an `Rgb` emission: c / max(c)
//! upsampled to a smooth reflectance-like spectrum, times D65 (a white texel emits D65). Each
//! texel keeps its shape's three sigmoid coefficients, the factor that turns shape × D65 into
//! radiance, and its luminance: [`BYTES_PER_TEXEL`] bytes. Lookups filter bilinearly and wrap as
//! reflectance textures do; since luminance is linear in radiance, the filtered luminance is the
//! luminance of the filtered radiance.

use super::{bilinear_shapes, coefficients, fit_distinct, footprint, shape_at, UvMap, Wrap};
use crate::colour::grid::LEN;
use crate::photometry::K_M;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::Vec2;

/// Memory of one texel once loaded, bytes: three f32 sigmoid coefficients, the f32 radiance
/// factor and the f32 luminance.
pub const BYTES_PER_TEXEL: u64 = 20;

/// An emission texture (see the module docs).
#[derive(Clone)]
pub struct EmissionTexture {
    width: u32,
    height: u32,
    /// Per texel, top row first: the shape's coefficients (as [`Texture`]'s).
    coeffs: Vec<[f32; 3]>,
    /// Per texel: radiance = `scale` · S(λ) · D65(λ) per cd/m² of the light's amount.
    scale: Vec<f32>,
    /// Per texel: luminance, cd/m² per cd/m² of the light's amount (Y of its colour).
    luminance: Vec<f32>,
    /// CIE D65 (relative), the white of every texel's shape.
    d65: DenseSpectrum,
    pub wrap: Wrap,
    /// Texture coordinates are mapped by it before wrapping.
    pub uv: UvMap,
}

impl std::fmt::Debug for EmissionTexture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "EmissionTexture({}×{})", self.width, self.height)
    }
}

/// Rec. 709 luminance weights of linear sRGB.
fn luma(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

impl EmissionTexture {
    /// An emission texture from linear-sRGB colours (negative and non-finite components count
    /// as 0; components above 1 are brighter texels), `width × height`, top row first. Each
    /// distinct colour is fitted once.
    pub fn from_linear_rgb(width: u32, height: u32, texels: &[[f32; 3]]) -> EmissionTexture {
        assert_eq!(texels.len(), width as usize * height as usize);
        let d65 = crate::colour::tables::named_spectrum("D65").expect("D65 ships with candela");
        let d65 = DenseSpectrum::from_fn(|nm| d65.value(nm));
        // K_m D65(λ) V(λ) per 1 nm, the weights of the shape's luminance.
        let v = crate::colour::tables::photopic_v();
        let w: Vec<f64> = (0..LEN)
            .map(|i| K_M * d65.values[i] as f64 * v[i])
            .collect();
        let clean = |c: &[f32; 3]| c.map(|x| if x.is_finite() && x > 0.0 { x } else { 0.0 });
        let (ids, fitted) = fit_distinct(texels, clean, |c| {
            let peak = c[0].max(c[1]).max(c[2]);
            if peak <= 0.0 {
                return ([0.0, 0.0, f32::NEG_INFINITY], 0.0, 0.0);
            }
            let co = coefficients(c.map(|x| (x / peak).min(1.0)));
            let shape_y: f64 = (0..LEN)
                .map(|i| shape_at(co, 360.0 + i as f64) * w[i])
                .sum();
            let y = luma(c);
            let scale = if shape_y > 0.0 { y / shape_y } else { 0.0 };
            (co, scale as f32, y as f32)
        });
        let scale = ids.iter().map(|&i| fitted[i as usize].1).collect();
        let luminance = ids.iter().map(|&i| fitted[i as usize].2).collect();
        EmissionTexture {
            width,
            height,
            coeffs: ids.iter().map(|&i| fitted[i as usize].0).collect(),
            scale,
            luminance,
            d65,
            wrap: Wrap::Repeat,
            uv: UvMap::IDENTITY,
        }
    }

    /// The emission texture of an image: PNG or JPEG (sRGB-encoded, each texel's linear colour
    /// multiplied by `tint`) or OpenEXR (linear R, G, B; `tint` too); checked as
    /// [`super::Texture::load`]. `bytes` are the file's; `path` names it in messages.
    pub fn decode(
        path: &std::path::Path,
        bytes: &[u8],
        tint: [f32; 3],
    ) -> Result<EmissionTexture, super::TextureError> {
        let (w, h, texels) =
            super::linear_texels(path, bytes, tint, super::LOAD_EMISSION_BYTES_PER_TEXEL)?;
        Ok(Self::from_linear_rgb(w, h, &texels))
    }

    /// [`EmissionTexture::decode`] of the file at `path`.
    pub fn load(
        path: &std::path::Path,
        tint: [f32; 3],
    ) -> Result<EmissionTexture, super::TextureError> {
        let bytes = crate::limits::read_file(path, super::MAX_TEXTURE_FILE_BYTES).map_err(|e| {
            super::TextureError {
                path: path.to_path_buf(),
                message: e.to_string(),
            }
        })?;
        Self::decode(path, &bytes, tint)
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

    /// Largest texel luminance, cd/m² per cd/m² of the amount.
    pub fn max_luminance(&self) -> f64 {
        self.luminance.iter().fold(0.0f32, |a, &b| a.max(b)) as f64
    }

    /// Radiance at texture coordinates `tex` (bilinear), W·m⁻²·sr⁻¹·nm⁻¹ per cd/m² of the
    /// amount, per wavelength of `wl`.
    pub fn radiance(&self, tex: Vec2, wl: &SampledWavelengths) -> SampledSpectrum {
        let fp = footprint(&self.uv, self.wrap, self.width, self.height, tex);
        bilinear_shapes(&self.coeffs, self.width, fp, wl, |i| self.scale[i]) * self.d65.sample(wl)
    }

    /// Luminance at texture coordinates `tex` (bilinear), cd/m² per cd/m² of the amount.
    pub fn luminance(&self, tex: Vec2) -> f64 {
        let (cols, rows, wxs, wys) = footprint(&self.uv, self.wrap, self.width, self.height, tex);
        let mut out = 0.0f64;
        for (r, wy) in rows.iter().zip(wys) {
            for (c, wx) in cols.iter().zip(wxs) {
                out += (wx * wy) as f64 * self.luminance[r * self.width as usize + c] as f64;
            }
        }
        out
    }

    /// Radiance of texel (`x`, `y`) (y = 0 the top row) at `nm`, per cd/m² of the amount.
    pub fn texel_radiance(&self, x: u32, y: u32, nm: f64) -> f64 {
        let i = (y * self.width + x) as usize;
        shape_at(self.coeffs[i], nm) * self.scale[i] as f64 * self.d65.value(nm as f32) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photometry::luminous_integral;
    use crate::spectrum::N_LAMBDA;

    /// Each texel's radiance is that of an `Rgb` emission of its colour scaled to its luminance
    /// (the rule of the untextured emitters), and its luminance is Y(c).
    #[test]
    fn texels_emit_as_rgb_emitters_of_their_luminance() {
        let colours = [
            [0.2f32, 0.5, 0.1],
            [1.0, 1.0, 1.0],
            [0.0; 3],
            [3.0, 1.5, 0.75],
        ];
        let t = EmissionTexture::from_linear_rgb(2, 2, &colours);
        let d65 = crate::colour::tables::named_spectrum("D65").unwrap();
        for (i, c) in colours.iter().enumerate() {
            let (x, y) = (i as u32 % 2, i as u32 / 2);
            let dense = DenseSpectrum::from_fn(|nm| t.texel_radiance(x, y, nm));
            let y_c = luma(c.map(|v| v as f64));
            assert!(
                (luminous_integral(&dense) - y_c).abs() < 1e-5 * (1.0 + y_c),
                "{c:?}"
            );
            if y_c > 0.0 {
                let peak = c.iter().fold(0.0f32, |a, &b| a.max(b)) as f64;
                let (sig, _) =
                    crate::spectrum::rgb_upsample::fit_linear_srgb(c.map(|v| v as f64 / peak))
                        .unwrap();
                let want = DenseSpectrum::from_fn(|nm| sig.value(nm) * d65.value(nm));
                let k = y_c / luminous_integral(&want);
                for nm in [400.0, 500.0, 600.0, 700.0] {
                    let (got, w) = (t.texel_radiance(x, y, nm), want.value(nm as f32) as f64 * k);
                    assert!(
                        (got - w).abs() < 1e-5 * w.max(1e-9),
                        "{c:?} {nm}: {got} vs {w}"
                    );
                }
            }
        }
        // Bilinear: the image's centre averages the four texels, in radiance and luminance.
        let wl = SampledWavelengths::sample_visible(0.4);
        let mid = t.radiance(Vec2::splat(0.5), &wl);
        for k in 0..N_LAMBDA {
            let l = wl.lambda[k] as f64;
            let mean = (0..4)
                .map(|i| t.texel_radiance(i % 2, i / 2, l))
                .sum::<f64>()
                / 4.0;
            assert!((mid.0[k] as f64 - mean).abs() < 1e-5 * mean, "{k}");
        }
        let mean_y: f64 = colours
            .iter()
            .map(|c| luma(c.map(|v| v as f64)))
            .sum::<f64>()
            / 4.0;
        assert!((t.luminance(Vec2::splat(0.5)) - mean_y).abs() < 1e-6);
        assert!((t.max_luminance() - luma([3.0, 1.5, 0.75])).abs() < 1e-5);
    }
}
