//! Linear textures of 1 to 3 channels kept as the image's 8-bit values (C bytes per texel,
//! [`ByteTexture::BYTES_PER_TEXEL`]): glTF's metallic-roughness texture (roughness in G,
//! metallic in B) and tangent-space normal maps (x, y, z in R, G, B, each 2·c/255 − 1). They
//! are read from PNG or JPEG with no transfer function (the values are data, not colours); a
//! 16-bit PNG keeps its high 8 bits. Lookups filter bilinearly and map coordinates as
//! [`super::Texture`] does.

use super::{decode_rgb8, footprint, TextureError, UvMap, Wrap};
use glam::Vec2;
use std::path::Path;

/// `C` linear channels per texel, each one byte (value / 255 in [0, 1]).
#[derive(Clone, Debug)]
pub struct ByteTexture<const C: usize> {
    width: u32,
    height: u32,
    /// Top row first.
    texels: Vec<[u8; C]>,
    pub wrap: Wrap,
    pub uv: UvMap,
}

impl<const C: usize> ByteTexture<C> {
    /// Memory of one texel, bytes.
    pub const BYTES_PER_TEXEL: u64 = C as u64;

    /// A texture of `width × height` texels, top row first.
    pub fn from_texels(width: u32, height: u32, texels: Vec<[u8; C]>) -> Self {
        assert_eq!(texels.len(), width as usize * height as usize);
        ByteTexture {
            width,
            height,
            texels,
            wrap: Wrap::Repeat,
            uv: UvMap::IDENTITY,
        }
    }

    /// Channels `channels` (0 = R, 1 = G, 2 = B) of the PNG or JPEG image in `bytes`, checked
    /// as [`super::Texture::load`] checks images; `path` names it in messages.
    pub fn decode(path: &Path, bytes: &[u8], channels: [usize; C]) -> Result<Self, TextureError> {
        let rgb = decode_rgb8(path, bytes, super::LOAD_BYTE_MAP_BYTES_PER_TEXEL)?;
        let (w, h) = rgb.dimensions();
        let texels = rgb.pixels().map(|p| channels.map(|c| p.0[c])).collect();
        Ok(Self::from_texels(w, h, texels))
    }

    /// Reads the PNG or JPEG image at `path` as [`ByteTexture::decode`] does.
    pub fn load(path: &Path, channels: [usize; C]) -> Result<Self, TextureError> {
        let bytes = crate::limits::read_file(path, super::MAX_TEXTURE_FILE_BYTES).map_err(|e| {
            TextureError {
                path: path.to_path_buf(),
                message: e.to_string(),
            }
        })?;
        Self::decode(path, &bytes, channels)
    }

    pub fn width(&self) -> u32 {
        self.width
    }
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Heap memory, bytes.
    pub fn memory_bytes(&self) -> usize {
        self.texels.capacity() * C
    }

    /// Smallest and largest value of channel `k` over the texels (bilinear lookups stay within
    /// them).
    pub fn channel_range(&self, k: usize) -> (u8, u8) {
        self.texels
            .iter()
            .fold((u8::MAX, 0), |(lo, hi), t| (lo.min(t[k]), hi.max(t[k])))
    }

    /// Texel (`x`, `y`) (y = 0 the top row), each channel in [0, 1].
    pub fn texel(&self, x: u32, y: u32) -> [f32; C] {
        self.texels[(y * self.width + x) as usize].map(|v| v as f32 / 255.0)
    }

    /// The channels at texture coordinates `tex`, filtered bilinearly, each in [0, 1].
    #[inline]
    pub fn lookup(&self, tex: Vec2) -> [f32; C] {
        self.lookup_raw(tex).map(|v| v * (1.0 / 255.0))
    }

    /// The channels at `tex`, filtered bilinearly, in the texels' units (0 to 255). Written as
    /// interpolations between texels, so that where the four texels agree the value is theirs
    /// exactly.
    #[inline]
    pub fn lookup_raw(&self, tex: Vec2) -> [f32; C] {
        let (cols, rows, wxs, wys) = footprint(&self.uv, self.wrap, self.width, self.height, tex);
        let (fx, fy) = (wxs[1], wys[1]);
        let at = |r: usize, c: usize| self.texels[r * self.width as usize + c];
        let row = |r: usize| -> [f32; C] {
            let (a, b) = (at(r, cols[0]), at(r, cols[1]));
            std::array::from_fn(|k| {
                let (a, b) = (a[k] as f32, b[k] as f32);
                a + (b - a) * fx
            })
        };
        let (top, bottom) = (row(rows[0]), row(rows[1]));
        std::array::from_fn(|k| top[k] + (bottom[k] - top[k]) * fy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_filters_bilinearly_and_wraps() {
        let t = ByteTexture::<1>::from_texels(2, 2, vec![[0], [255], [51], [102]]);
        // Texel centres (v = 0 the bottom row) and the image centre.
        assert_eq!(t.lookup(Vec2::new(0.25, 0.75)), [0.0]);
        assert_eq!(t.lookup(Vec2::new(0.75, 0.75)), [1.0]);
        assert!((t.lookup(Vec2::new(0.25, 0.25))[0] - 0.2).abs() < 1e-6);
        let mid = (0.0 + 255.0 + 51.0 + 102.0) / 4.0 / 255.0;
        assert!((t.lookup(Vec2::splat(0.5))[0] - mid).abs() < 1e-6);
        // Repeat: one period on, the same value.
        assert!((t.lookup(Vec2::new(1.25, -0.75))[0] - 0.2).abs() < 1e-6);
        assert_eq!(ByteTexture::<2>::BYTES_PER_TEXEL, 2);
    }
}
