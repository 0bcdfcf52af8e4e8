//! OpenEXR writing and reading.

use std::io::Cursor;
use std::path::Path;

use exr::meta::attribute::{AttributeValue, Text};
use exr::meta::header::standard_names;
use exr::prelude::{
    read, AnyChannel, AnyChannels, Blocks, Compression, Encoding, FlatSamples, Image, Layer,
    LayerAttributes, LineOrder, ReadChannels, ReadLayers, SmallVec, WritableImage,
};

use super::{write_atomic, OutputError};

/// A float image with named channels, row-major, top row first.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Layers {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `(name, samples)`; each channel holds `width * height` values, row-major, top row
    /// first. [`read_exr`] returns channels in the file's order, which OpenEXR sorts by name.
    pub channels: Vec<(String, Vec<f32>)>,
    /// Text header attributes such as `units`, `scene`, `software`. [`read_exr`] returns them
    /// sorted by name.
    pub attributes: Vec<(String, String)>,
}

impl Layers {
    /// An image with no channels or attributes yet.
    pub fn new(width: usize, height: usize) -> Self {
        Layers {
            width,
            height,
            channels: Vec::new(),
            attributes: Vec::new(),
        }
    }

    /// Candela's standard measured image: channels `X`, `Y`, `Z` (absolute CIE 1931 XYZ,
    /// `Y` = luminance) and `stderr.Y` (standard error of `Y`), with attribute
    /// `units = cd/m^2`. Panics if a slice is not `width * height` long.
    pub fn from_xyz(width: usize, height: usize, xyz: &[[f32; 3]], y_stderr: &[f32]) -> Self {
        let n = width * height;
        assert_eq!(xyz.len(), n, "xyz has {} pixels, expected {n}", xyz.len());
        assert_eq!(
            y_stderr.len(),
            n,
            "y_stderr has {} pixels, expected {n}",
            y_stderr.len()
        );
        let component = |i: usize| xyz.iter().map(|p| p[i]).collect::<Vec<f32>>();
        Layers {
            width,
            height,
            channels: vec![
                (super::CHANNEL_X.to_string(), component(0)),
                (super::CHANNEL_Y.to_string(), component(1)),
                (super::CHANNEL_Z.to_string(), component(2)),
                (super::CHANNEL_Y_STDERR.to_string(), y_stderr.to_vec()),
            ],
            attributes: vec![(
                super::ATTRIBUTE_UNITS.to_string(),
                super::UNITS_CD_PER_M2.to_string(),
            )],
        }
    }

    /// The samples of the channel called `name`, if any.
    pub fn channel(&self, name: &str) -> Option<&[f32]> {
        self.channels
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// The value of the text attribute called `name`, if any.
    pub fn attribute(&self, name: &str) -> Option<&str> {
        self.attributes
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    /// Replaces every NaN or infinite sample by `value`; returns how many were replaced.
    /// [`write_exr`] refuses non-finite samples, so a caller that prefers a written image
    /// with marked pixels over no image can call this first.
    pub fn replace_non_finite(&mut self, value: f32) -> usize {
        let mut count = 0;
        for (_, samples) in &mut self.channels {
            for s in samples.iter_mut().filter(|s| !s.is_finite()) {
                *s = value;
                count += 1;
            }
        }
        count
    }

    /// Checks sizes, names and values before writing to `path`.
    fn validate(&self, path: &Path) -> Result<(), OutputError> {
        if self.width == 0 || self.height == 0 {
            return Err(OutputError::invalid(
                path,
                format!("image size {}x{} is empty", self.width, self.height),
            ));
        }
        if self.width > i32::MAX as usize || self.height > i32::MAX as usize {
            return Err(OutputError::invalid(path, "image too large for OpenEXR"));
        }
        if self.channels.is_empty() {
            return Err(OutputError::invalid(path, "image has no channels"));
        }
        let n = self.width * self.height;
        for (i, (name, samples)) in self.channels.iter().enumerate() {
            check_name(path, "channel", name)?;
            if self.channels[..i].iter().any(|(other, _)| other == name) {
                return Err(OutputError::invalid(
                    path,
                    format!("channel name '{name}' is used twice"),
                ));
            }
            if samples.len() != n {
                return Err(OutputError::invalid(
                    path,
                    format!(
                        "channel '{name}' has {} samples, expected {}x{} = {n}",
                        samples.len(),
                        self.width,
                        self.height
                    ),
                ));
            }
            if let Some(i) = samples.iter().position(|s| !s.is_finite()) {
                return Err(OutputError::NonFinite {
                    path: path.to_path_buf(),
                    channel: name.clone(),
                    x: i % self.width,
                    y: i / self.width,
                    value: samples[i],
                });
            }
        }
        for (i, (name, _)) in self.attributes.iter().enumerate() {
            check_name(path, "attribute", name)?;
            if self.attributes[..i].iter().any(|(other, _)| other == name) {
                return Err(OutputError::invalid(
                    path,
                    format!("attribute name '{name}' is used twice"),
                ));
            }
            if TEXT_FIELDS.iter().all(|f| f.0 != name)
                && standard_names::ALL.contains(&name.as_bytes())
            {
                return Err(OutputError::invalid(
                    path,
                    format!("attribute name '{name}' is reserved by OpenEXR for a non-text value"),
                ));
            }
        }
        Ok(())
    }
}

/// Standard OpenEXR text attributes, which the exr crate keeps in dedicated fields rather
/// than in its map of other attributes.
#[allow(clippy::type_complexity)]
const TEXT_FIELDS: &[(&str, fn(&mut LayerAttributes) -> &mut Option<Text>)] = &[
    ("software", |a| &mut a.software_name),
    ("owner", |a| &mut a.owner),
    ("comments", |a| &mut a.comments),
    ("capDate", |a| &mut a.capture_date),
];

fn check_name(path: &Path, what: &str, name: &str) -> Result<(), OutputError> {
    if name.is_empty() || name.len() > 255 || name.contains('\0') {
        return Err(OutputError::invalid(
            path,
            format!("{what} name '{name}' must be 1 to 255 bytes without NUL"),
        ));
    }
    Ok(())
}

/// OpenEXR text is a byte string; candela stores UTF-8 (so `cd/m²` survives a round trip).
fn to_text(s: &str) -> Text {
    Text::from_slice_unchecked(s.as_bytes())
}

fn from_text(t: &Text) -> String {
    String::from_utf8_lossy(t.as_slice()).into_owned()
}

/// Writes `layers` as a single-part, scan-line, ZIP-compressed OpenEXR file with 32-bit
/// float channels, atomically (see [`write_atomic`](super::write_atomic)).
///
/// Text attributes become header attributes of type `string` (UTF-8). Names of standard
/// OpenEXR attributes that are not text (e.g. `channels`, `dataWindow`) are refused; the
/// standard text attributes `software`, `owner`, `comments` and `capDate` are allowed.
///
/// NaN and infinite samples are refused with [`OutputError::NonFinite`] (naming the channel
/// and pixel); nothing is written then. See [`Layers::replace_non_finite`].
pub fn write_exr(path: &Path, layers: &Layers) -> Result<(), OutputError> {
    layers.validate(path)?;
    let exr_err = |e: exr::error::Error| OutputError::Exr {
        path: path.to_path_buf(),
        message: e.to_string(),
    };

    let mut attributes = LayerAttributes::default();
    for (name, value) in &layers.attributes {
        match TEXT_FIELDS.iter().find(|f| f.0 == name) {
            Some((_, field)) => *field(&mut attributes) = Some(to_text(value)),
            None => {
                attributes
                    .other
                    .insert(to_text(name), AttributeValue::Text(to_text(value)));
            }
        }
    }
    let channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = layers
        .channels
        .iter()
        .map(|(name, samples)| {
            let mut channel = AnyChannel::new(to_text(name), FlatSamples::F32(samples.clone()));
            // Absolute photometric values are not perceptually linear (a hint for lossy
            // codecs only, but keep it truthful).
            channel.quantize_linearly = false;
            channel
        })
        .collect();
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        (layers.width, layers.height),
        attributes,
        encoding,
        AnyChannels::sort(channels),
    );
    let image = Image::from_layer(layer);

    // The encoder needs `Seek`, so encode in memory and then write the bytes atomically.
    let mut bytes = Cursor::new(Vec::new());
    image.write().to_buffered(&mut bytes).map_err(exr_err)?;
    let mut bytes = bytes.into_inner();
    super::exr_header::sort_header_attributes(&mut bytes);
    write_atomic(path, |w| w.write_all(&bytes))
}

/// Largest EXR file read at all; below it, the memory available decides.
const MAX_EXR_FILE_BYTES: u64 = 1 << 40;

/// Reads an OpenEXR file into [`Layers`]: the largest resolution level of every channel
/// (f16 and u32 samples are converted to f32) and every text header attribute.
///
/// A multi-part file is flattened: channels of a named part are called `part.channel`. All
/// parts must have the same size. A corrupt or truncated file gives
/// [`OutputError::Exr`] or [`OutputError::Io`] naming the file; the decoder is additionally
/// guarded against panics. The file is read through [`crate::limits::read_file`] (a FIFO, a
/// device or a directory is refused unread), and the header is read first: an image whose
/// decoded samples would not fit in the memory available, or could not fit in the file at any
/// compression, is refused before decoding, as [`OutputError::InvalidImage`] naming its size
/// (the decoder allocates the whole image from the header alone).
pub fn read_exr(path: &Path) -> Result<Layers, OutputError> {
    read_exr_with(path, &|_| 0)
}

/// [`read_exr`] for a caller that will hold `beside(channel names)` more bytes per pixel
/// beside the image; that is part of the memory checked before decoding.
pub(super) fn read_exr_with(
    path: &Path,
    beside: super::BesideBytes,
) -> Result<Layers, OutputError> {
    let exr_err = |message: String| OutputError::Exr {
        path: path.to_path_buf(),
        message,
    };
    let bytes =
        crate::limits::read_file(path, MAX_EXR_FILE_BYTES).map_err(|source| OutputError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    check_decoded_size(path, &bytes, beside)?;
    let decoded = std::panic::catch_unwind(|| {
        read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .all_layers()
            .all_attributes()
            .non_parallel()
            .from_buffered(Cursor::new(&bytes))
    });
    let image = match decoded {
        Ok(Ok(image)) => image,
        Ok(Err(e)) => return Err(exr_err(e.to_string())),
        Err(_) => return Err(exr_err("the EXR decoder failed on this file".to_string())),
    };

    let mut out = Layers::default();
    let multi = image.layer_data.len() > 1;
    let image_attributes = image.attributes;
    for (i, mut layer) in image.layer_data.into_iter().enumerate() {
        let (w, h) = (layer.size.width(), layer.size.height());
        if i == 0 {
            out.width = w;
            out.height = h;
        } else if (w, h) != (out.width, out.height) {
            return Err(exr_err(format!(
                "parts have different sizes ({}x{} and {w}x{h})",
                out.width, out.height
            )));
        }
        let prefix = match (&layer.attributes.layer_name, multi) {
            (Some(name), true) => format!("{}.", from_text(name)),
            _ => String::new(),
        };
        for channel in std::mem::take(&mut layer.channel_data.list) {
            // f32 samples are moved, not copied: a second copy of the image would double the
            // peak memory.
            let samples: Vec<f32> = match channel.sample_data {
                FlatSamples::F32(v) => v,
                other => other.values_as_f32().collect(),
            };
            if samples.len() != w * h {
                return Err(exr_err(format!(
                    "channel '{}' has {} samples, expected {}",
                    channel.name,
                    samples.len(),
                    w * h
                )));
            }
            out.channels
                .push((format!("{prefix}{}", from_text(&channel.name)), samples));
        }
        let mut attrs = layer.attributes.clone();
        for (name, field) in TEXT_FIELDS {
            if let Some(value) = field(&mut attrs) {
                out.attributes.push((name.to_string(), from_text(value)));
            }
        }
        for (name, value) in attrs.other.iter().chain(image_attributes.other.iter()) {
            if let AttributeValue::Text(text) = value {
                let name = from_text(name);
                if out.attributes.iter().all(|(n, _)| *n != name) {
                    out.attributes.push((name, from_text(text)));
                }
            }
        }
    }
    out.attributes.sort();
    Ok(out)
}

/// Most bytes of samples one byte of an OpenEXR file can expand to: deflate (ZIP, PXR24) packs
/// at most 1032 bytes into one, PXR24 then widens 24-bit floats to 32 bits (1376), and RLE,
/// PIZ and B44 pack less. A header that promises more than this times the file's size
/// describes pixels the file cannot hold.
const MAX_EXPANSION: u64 = 2048;

/// Refuses, from the header alone, an image whose samples would exceed the memory available,
/// or more than the file could hold at any compression ([`MAX_EXPANSION`]). The memory is the
/// larger of what decoding holds at once (the file's bytes, every channel of every part at its
/// largest size as the decoder stores it, and the f32 copy [`read_exr`] returns) and what the
/// caller then holds (that copy and `beside(channel names)` per pixel of the first part). A
/// header that cannot be read is left to the decoder to report.
fn check_decoded_size(
    path: &Path,
    bytes: &[u8],
    beside: super::BesideBytes,
) -> Result<(), OutputError> {
    let meta = std::panic::catch_unwind(|| {
        exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
    });
    let Ok(Ok(meta)) = meta else {
        return Ok(());
    };
    let Some(first) = meta.headers.first() else {
        return Ok(());
    };
    let (mut stored, mut samples, mut f32_bytes) = (0u64, 0u64, 0u64);
    let mut names = Vec::new();
    let multi = meta.headers.len() > 1;
    for header in meta.headers.iter() {
        let prefix = match (&header.own_attributes.layer_name, multi) {
            (Some(name), true) => format!("{}.", from_text(name)),
            _ => String::new(),
        };
        names.extend(
            header
                .channels
                .list
                .iter()
                .map(|c| format!("{prefix}{}", from_text(&c.name))),
        );
        let (w, h) = (header.layer_size.width(), header.layer_size.height());
        for channel in header.channels.list.iter() {
            let n =
                (w / channel.sampling.x().max(1)) as u64 * (h / channel.sampling.y().max(1)) as u64;
            let bytes_per_sample = channel.sample_type.bytes_per_sample() as u64;
            samples = samples.saturating_add(n);
            stored = stored.saturating_add(n.saturating_mul(bytes_per_sample));
            if channel.sample_type == exr::meta::attribute::SampleType::F32 {
                f32_bytes = f32_bytes.saturating_add(n.saturating_mul(4));
            }
        }
    }
    let pixels = first.layer_size.width() as u64 * first.layer_size.height() as u64;
    // Decoding: the file, the decoded samples, and the f32 copy of those that are not f32
    // already; then the f32 channels and the caller's buffers.
    let converted = samples.saturating_mul(4).saturating_sub(f32_bytes);
    let decoding = (bytes.len() as u64)
        .saturating_add(stored)
        .saturating_add(converted);
    let after = samples
        .saturating_mul(4)
        .saturating_add(pixels.saturating_mul(beside(
            &names.iter().map(String::as_str).collect::<Vec<_>>(),
        )));
    let need = decoding
        .max(after)
        .saturating_add(crate::limits::BASE_BYTES);
    let what = format!(
        "the image ({}×{} pixels, {} part(s), {samples} samples in all)",
        first.layer_size.width(),
        first.layer_size.height(),
        meta.headers.len()
    );
    let refuse = |reason: String| OutputError::InvalidImage {
        path: path.to_path_buf(),
        reason,
    };
    crate::limits::check_memory(need, &format!("decoding {what}")).map_err(refuse)?;
    let len = bytes.len() as u64;
    if stored > len.saturating_mul(MAX_EXPANSION) {
        return Err(refuse(format!(
            "the header describes {what}, {stored} bytes of samples, more than any OpenEXR compression fits in this file of {len} bytes: the file is truncated or corrupt"
        )));
    }
    Ok(())
}
