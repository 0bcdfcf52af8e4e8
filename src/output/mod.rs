//! Writing and reading candela's output images.
//!
//! * [`write_exr`] / [`read_exr`]: the measured result, as 32-bit float OpenEXR with named
//!   channels (absolute CIE 1931 XYZ, `Y` in cd/m², plus its standard error) and text
//!   header attributes.
//! * [`write_srgb_png`]: an 8-bit sRGB preview, exposed like a camera at a given (or
//!   automatically metered) exposure value. See `docs/outputs.md` for the exact mapping.
//! * [`write_hdr`] / [`read_hdr`]: Radiance RGBE pictures (luminance = 179 × Radiance's
//!   brightness), for Radiance's tools; [`read_image`] reads either format.
//! * [`write_atomic`]: every file this module writes goes through it, so a crash or an error
//!   never leaves a half-written output behind.

pub mod draw;
mod exr_header;
mod exr_io;
mod hdr;
mod png;

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

pub use exr_io::{read_exr, write_exr, Layers};
pub use hdr::{
    min_scanline_bytes, read_hdr, read_hdr_luminance, rgb_to_xyz_matrix, write_hdr, HdrImage,
    RADIANCE_EFFICACY, RADIANCE_PRIMARIES,
};
pub use png::{
    auto_exposure_ev, ev_to_scale, log_average_luminance, write_rgb_png, write_srgb_png, PngInfo,
    PngSettings, CALIBRATION_K, ISO_SPEED, MIDDLE_GREY,
};

/// `stem` followed by `suffix` (`room` + `.exr` → `room.exr`; the stem may contain dots).
pub fn with_suffix(stem: &Path, suffix: &str) -> PathBuf {
    let mut p = stem.as_os_str().to_owned();
    p.push(suffix);
    PathBuf::from(p)
}

/// Channel name of CIE 1931 X (same units as `Y`).
pub const CHANNEL_X: &str = "X";
/// Channel name of CIE 1931 Y, the luminance in cd/m².
pub const CHANNEL_Y: &str = "Y";
/// Channel name of CIE 1931 Z (same units as `Y`).
pub const CHANNEL_Z: &str = "Z";
/// Channel name of the standard error of the mean of `Y` (cd/m²).
///
/// OpenEXR treats the text after the last `.` as the channel and the text before as the
/// layer, so viewers show this as channel `Y` of a layer `stderr`, next to the main `X`,
/// `Y`, `Z` layer.
pub const CHANNEL_Y_STDERR: &str = "stderr.Y";
/// Header attribute holding the units of the `X`, `Y`, `Z` and `stderr.Y` channels.
pub const ATTRIBUTE_UNITS: &str = "units";
/// Illuminance (lx) on the surface seen through each pixel; [`ILLUMINANCE_SENTINEL`] where the
/// pixel sees no surface (sky, emitter, nothing), see [`CHANNEL_E_MASK`].
pub const CHANNEL_E: &str = "E";
/// Standard error of `E`, lx (0 where `E` is undefined).
pub const CHANNEL_E_STDERR: &str = "stderr.E";
/// 1 where every sample of the pixel saw a reflecting surface (E defined), 0 where none did;
/// fractional where the pixel straddles an edge (E is then the mean over the covered samples).
pub const CHANNEL_E_MASK: &str = "mask.E";
/// Value written to `E` where it is undefined (never NaN).
pub const ILLUMINANCE_SENTINEL: f32 = -1.0;
/// Header attribute (EXR) holding the camera's Radiance view options (`-vta -vp … -vh …`),
/// where Radiance has a matching view type (OpenEXR reserves `view` for stereo views).
pub const ATTRIBUTE_VIEW: &str = "radiance_view";
/// Header attribute (EXR) holding the camera's projection in scene syntax, e.g.
/// `Fisheye(mapping: Equisolid, fov_deg: 180)`.
pub const ATTRIBUTE_PROJECTION: &str = "projection";
/// Value of [`ATTRIBUTE_UNITS`] for candela's absolute photometric images.
pub const UNITS_CD_PER_M2: &str = "cd/m^2";

/// Everything that can go wrong writing or reading an output file. Every variant names the
/// file concerned.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The operating system refused a read, write, sync or rename.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// What the operating system said.
        #[source]
        source: io::Error,
    },
    /// The file is not a readable OpenEXR image (corrupt, truncated, unsupported), or the
    /// EXR encoder refused the image.
    #[error("{}: not a valid OpenEXR image: {message}", path.display())]
    Exr {
        /// The file concerned.
        path: PathBuf,
        /// What the EXR library said.
        message: String,
    },
    /// The file is not a readable Radiance picture (malformed, truncated, unsupported).
    #[error("{}: not a valid Radiance HDR image: {message}", path.display())]
    Hdr {
        /// The file concerned.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A pixel value is NaN or infinite; such values are never written.
    #[error(
        "{}: channel '{channel}' has a non-finite value ({value}) at pixel ({x}, {y}); \
         refusing to write it",
        path.display()
    )]
    NonFinite {
        /// The file that was not written.
        path: PathBuf,
        /// The channel containing the value.
        channel: String,
        /// Column of the pixel (0 = left).
        x: usize,
        /// Row of the pixel (0 = top).
        y: usize,
        /// The offending value.
        value: f32,
    },
    /// The image description is inconsistent (sizes, names, settings).
    #[error("{}: {reason}", path.display())]
    InvalidImage {
        /// The file that was not written.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The PNG encoder failed.
    #[error("{}: PNG encoding failed: {message}", path.display())]
    Png {
        /// The file that was not written.
        path: PathBuf,
        /// What the encoder said.
        message: String,
    },
}

impl OutputError {
    /// The file this error is about.
    pub fn path(&self) -> &Path {
        match self {
            OutputError::Io { path, .. }
            | OutputError::Exr { path, .. }
            | OutputError::Hdr { path, .. }
            | OutputError::NonFinite { path, .. }
            | OutputError::InvalidImage { path, .. }
            | OutputError::Png { path, .. } => path,
        }
    }

    pub(crate) fn invalid(path: &Path, reason: impl Into<String>) -> Self {
        OutputError::InvalidImage {
            path: path.to_path_buf(),
            reason: reason.into(),
        }
    }
}

/// Reads an image candela can measure: a Radiance picture (a file starting with `#?`, as
/// [`HdrImage::to_layers`]) or else an OpenEXR file ([`read_exr`]).
pub fn read_image(path: &Path) -> Result<Layers, OutputError> {
    read_image_with(path, &|_| 0)
}

/// What a reader of an image will hold per pixel beside the image's channels while it works
/// on them, in bytes, given the names of the channels the file declares.
pub type BesideBytes<'a> = &'a dyn Fn(&[&str]) -> u64;

/// [`read_image`] for a caller that will hold `beside(channel names)` more bytes per pixel
/// while the image is in memory (its own buffers): the image is refused, before its pixels
/// are decoded, if the decoding and those buffers together would not fit in the memory
/// available ([`crate::limits::check_memory`]), so a command reading a huge image fails with
/// a message naming the file instead of aborting part-way.
pub fn read_image_with(path: &Path, beside: BesideBytes) -> Result<Layers, OutputError> {
    let mut head = [0u8; 2];
    // Only a regular file is opened here (opening a FIFO would block); anything else goes
    // to the EXR reader, which refuses it by kind.
    let regular = fs::metadata(path).is_ok_and(|m| m.is_file());
    let file = if regular { File::open(path).ok() } else { None };
    let is_hdr = match file {
        Some(mut f) => {
            use std::io::Read;
            f.read_exact(&mut head).is_ok() && head == *b"#?"
        }
        None => false,
    };
    if is_hdr {
        let names = [CHANNEL_X, CHANNEL_Y, CHANNEL_Z];
        hdr::read_hdr_layers(path, beside(&names))
    } else {
        exr_io::read_exr_with(path, beside)
    }
}

/// The directory of outputs at `path` ("." for a bare file name).
pub(crate) fn dir_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// The directory entry `path` names: its directory resolved (links, `..`) and its file name.
pub(crate) fn entry(path: &Path) -> Option<PathBuf> {
    Some(dir_of(path).canonicalize().ok()?.join(path.file_name()?))
}

/// Whether writing `output` (a new file renamed over the entry, see
/// [`write_atomic`]) would replace or change `input`: the same directory entry,
/// the entry a link at `input` resolves to, or the same file by another name (inode).
pub fn would_replace(output: &Path, input: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(a), Ok(b)) = (std::fs::metadata(output), std::fs::metadata(input)) {
            if a.dev() == b.dev() && a.ino() == b.ino() {
                return true;
            }
        }
    }
    let Some(out) = entry(output) else {
        return output == input;
    };
    entry(input).is_some_and(|e| e == out) || input.canonicalize().is_ok_and(|c| c == out)
}

/// Temporary files being written right now, so that [`remove_temporary_files`] can delete them
/// before a forced exit (which runs no destructors).
static IN_FLIGHT: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn in_flight() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    IN_FLIGHT.lock().unwrap_or_else(|e| e.into_inner())
}

/// Deletes the temporary files of the atomic writes in progress. For a process about to end
/// without unwinding (`std::process::exit`, e.g. on a second Ctrl-C): their targets are left
/// as they were, and no temporary file is left beside them. The registry stays locked, so
/// that no other thread can start (or finish) an atomic write before the exit: such a write
/// waits for a lock that is never released.
pub fn remove_temporary_files() {
    let mut files = in_flight();
    for path in files.drain(..) {
        let _ = fs::remove_file(path);
    }
    std::mem::forget(files);
}

/// Removes the temporary file when dropped, unless disarmed after the rename. This also
/// cleans up if the writer closure panics.
struct TempGuard {
    path: Option<PathBuf>,
}

impl TempGuard {
    /// Takes charge of `path`, which [`create_temp_beside`] registered before creating it.
    fn new(path: PathBuf) -> Self {
        TempGuard { path: Some(path) }
    }

    /// After the rename: the temporary name no longer exists.
    fn disarm(&mut self) {
        if let Some(path) = self.path.take() {
            in_flight().retain(|p| *p != path);
        }
    }
}

impl Drop for TempGuard {
    fn drop(&mut self) {
        if let Some(path) = self.path.take() {
            let _ = fs::remove_file(&path);
            in_flight().retain(|p| *p != path);
        }
    }
}

/// Creates a new, uniquely named temporary file next to `target`.
fn create_temp_beside(target: &Path) -> Result<(PathBuf, File), OutputError> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let io_err = |source| OutputError::Io {
        path: target.to_path_buf(),
        source,
    };
    let file_name = target
        .file_name()
        .ok_or_else(|| OutputError::invalid(target, "not a file path"))?;
    let dir = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.subsec_nanos())
        .unwrap_or(0);
    for _ in 0..100 {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let mut name = std::ffi::OsString::from(".");
        name.push(file_name);
        name.push(format!(".{}.{n}.{nanos:08x}.tmp", std::process::id()));
        let temp = dir.join(name);
        // Registered before it exists, so that a forced exit in between still deletes it.
        in_flight().push(temp.clone());
        match OpenOptions::new().write(true).create_new(true).open(&temp) {
            Ok(file) => return Ok((temp, file)),
            Err(e) => {
                in_flight().retain(|p| *p != temp);
                if e.kind() == io::ErrorKind::AlreadyExists {
                    continue;
                }
                return Err(io_err(e));
            }
        }
    }
    Err(io_err(io::Error::new(
        io::ErrorKind::AlreadyExists,
        "could not find a free temporary file name",
    )))
}

/// Write bytes atomically: temp file in the same directory (unique name), fsync, rename
/// over the target. Never leaves a partial target; the temp file is removed on error (and if
/// `write` panics).
///
/// The temporary file is `.<file name>.<pid>.<counter>.<nonce>.tmp` in the target's
/// directory, so the final rename never crosses file systems. After the rename the
/// directory is synced too (best effort), so the new name survives a power cut.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), OutputError> {
    let io_err = |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    };
    if path.is_dir() {
        return Err(OutputError::invalid(path, "is a directory"));
    }
    let (temp, file) = create_temp_beside(path)?;
    let mut guard = TempGuard::new(temp.clone());
    let mut writer = BufWriter::new(file);
    write(&mut writer).map_err(io_err)?;
    let file = writer.into_inner().map_err(|e| io_err(e.into_error()))?;
    file.sync_all().map_err(io_err)?;
    drop(file);
    fs::rename(&temp, path).map_err(io_err)?;
    guard.disarm();
    #[cfg(unix)]
    if let Some(dir) = path.parent() {
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
    Ok(())
}
