//! Where a job's files go and how a film becomes them: the output stem of `--out`/`-o`, the
//! EXR channels and attributes of a film, and its sRGB preview.

use crate::film::Film;
use crate::output::{self, Layers, PngSettings};
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};

/// The output stem of `--out` / `-o`: `name` if none is given; `DIR/name` for an existing
/// directory (or a path ending in `/`); otherwise the path, with one of `extensions` removed.
pub fn output_stem(out: Option<&Path>, name: &str, extensions: &[&str]) -> PathBuf {
    match out {
        None => PathBuf::from(name),
        Some(p) if p.is_dir() || p.as_os_str().to_string_lossy().ends_with('/') => p.join(name),
        Some(p) => match p.extension().and_then(|e| e.to_str()) {
            Some(e) if extensions.contains(&e) => p.with_extension(""),
            _ => p.to_path_buf(),
        },
    }
}

/// Refuses outputs at `stem` whose directory does not exist.
pub fn check_output_dir(stem: &Path) -> Result<()> {
    if let Some(dir) = stem.parent() {
        if !dir.as_os_str().is_empty() && !dir.is_dir() {
            bail!("output directory {} does not exist", dir.display());
        }
    }
    Ok(())
}

/// Fewest bytes a render state of a `width`×`height` film takes (both buffers when
/// `adaptive`): every pixel's sums are fixed-size floats; its counts take at least a byte.
pub fn state_bytes_at_least(width: usize, height: usize, adaptive: bool) -> u64 {
    let pixel = postcard::to_stdvec(&crate::film::PixelSums::default()).map_or(0, |b| b.len());
    (pixel * width * height * (1 + adaptive as usize)) as u64
}

pub use crate::output::would_replace;
use crate::output::{dir_of, entry};

/// One file a job may write, and what it is for messages ("the EXR image", "the CSV of grid
/// \"desk\"").
pub struct Planned {
    pub path: PathBuf,
    pub what: String,
}

/// Longest file name the file system holding `dir` accepts, in bytes.
fn name_max(dir: &Path) -> usize {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        if let Ok(c) = std::ffi::CString::new(dir.as_os_str().as_bytes()) {
            // SAFETY: `c` is a valid NUL-terminated path; pathconf only reads it.
            let n = unsafe { libc::pathconf(c.as_ptr(), libc::_PC_NAME_MAX) };
            if n > 0 {
                return n as usize;
            }
        }
    }
    255
}

/// Bytes free for this user on the file system holding `dir`, where the system says.
pub fn free_bytes(dir: &Path) -> Option<u64> {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let c = std::ffi::CString::new(dir.as_os_str().as_bytes()).ok()?;
        // SAFETY: statvfs fills the zeroed struct it is given and reads only the path.
        let mut st: libc::statvfs = unsafe { std::mem::zeroed() };
        if unsafe { libc::statvfs(c.as_ptr(), &mut st) } != 0 {
            return None;
        }
        #[allow(clippy::unnecessary_cast)] // the field types differ between platforms
        Some((st.f_bavail as u64).saturating_mul(st.f_frsize as u64))
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
        None
    }
}

/// A size in bytes for messages: "304 kB", "12.5 MB", "3.2 GB".
pub fn bytes_text(n: u64) -> String {
    let n = n as f64;
    if n < 1e6 {
        format!("{:.0} kB", (n / 1e3).ceil())
    } else if n < 1e9 {
        format!("{:.1} MB", n / 1e6)
    } else {
        format!("{:.1} GB", n / 1e9)
    }
}

/// The name of the temporary file [`crate::output::write_atomic`] writes beside `name`, at its
/// longest (a six-digit counter): `.NAME.PID.COUNTER.NONCE.tmp`.
fn temporary_name(name: &std::ffi::OsStr) -> std::ffi::OsString {
    let mut t = std::ffi::OsString::from(".");
    t.push(name);
    t.push(format!(".{}.999999.ffffffff.tmp", std::process::id()));
    t
}

/// Checks, before anything is rendered, that the planned outputs can be written and lose
/// nothing: none is one of `inputs` (path, what it is) or another output, each file name fits
/// the file system, no output path is a directory or special file, the directory accepts a new
/// file (a probe is created and removed), and at least `state_bytes` are free there (what the
/// render state written at the end takes at the least; 0 when none is written).
pub fn check_outputs(
    outputs: &[Planned],
    inputs: &[(PathBuf, String)],
    state_bytes: u64,
) -> Result<()> {
    let shown = |p: &Path| crate::limits::printable(&p.display().to_string(), 300);
    for o in outputs {
        if let Some((input, what)) = inputs.iter().find(|(i, _)| would_replace(&o.path, i)) {
            bail!(
                "refusing to overwrite {what} {} with {} {}; choose another --out (or rename the file)",
                shown(input),
                o.what,
                shown(&o.path)
            );
        }
    }
    let mut seen: std::collections::HashMap<PathBuf, &Planned> = Default::default();
    for o in outputs {
        let key = entry(&o.path).unwrap_or_else(|| o.path.clone());
        if let Some(other) = seen.insert(key, o) {
            bail!(
                "{} and {} would both be written to {}",
                other.what,
                o.what,
                shown(&o.path)
            );
        }
    }
    let mut longest: Option<&Planned> = None;
    for o in outputs {
        let Some(name) = o.path.file_name() else {
            bail!("{} {} is not a file name", o.what, shown(&o.path));
        };
        let dir = dir_of(&o.path);
        let (len, max) = (temporary_name(name).len(), name_max(dir));
        if len > max {
            bail!(
                "{} {} has a file name of {} bytes: with the temporary file written beside it ({len} bytes) that is more than the {max} bytes the file system allows; choose a shorter --out, scene file name or grid name",
                o.what,
                shown(&o.path),
                name.len()
            );
        }
        match std::fs::metadata(&o.path) {
            Ok(m) if !m.is_file() => bail!(
                "{} {} exists and is not a regular file (a directory or special file); choose another --out",
                o.what,
                shown(&o.path)
            ),
            _ => {}
        }
        if longest.is_none_or(|l| l.path.file_name().map_or(0, |n| n.len()) < name.len()) {
            longest = Some(o);
        }
    }
    let Some(longest) = longest else {
        return Ok(());
    };
    let dir = dir_of(&longest.path);
    // A file with the longest name the job will create: the directory is writable and takes
    // such names, before hours of rendering depend on it.
    let probe = dir.join(temporary_name(longest.path.file_name().unwrap_or_default()));
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(f) => {
            drop(f);
            let _ = std::fs::remove_file(&probe);
        }
        Err(e) => bail!(
            "cannot write {} in {}: creating a file there failed: {e}",
            longest.what,
            shown(dir)
        ),
    }
    if let Some(free) = free_bytes(dir) {
        if free < state_bytes {
            bail!(
                "not enough free disk space in {}: the render state alone needs at least {}, {} are free; free some space or choose another --out",
                shown(dir),
                bytes_text(state_bytes),
                bytes_text(free)
            );
        }
    }
    Ok(())
}

/// Largest |EV| accepted for a PNG's exposure: ±100 EV is already 2^100 away from any real
/// scene.
pub const MAX_ABS_EXPOSURE_EV: f64 = 100.0;

/// Refuses a non-finite exposure (EV) or one beyond ±[`MAX_ABS_EXPOSURE_EV`]; the message
/// names the command-line option.
pub fn check_exposure(exposure_ev: Option<f64>) -> Result<()> {
    if let Some(ev) = exposure_ev {
        if !(ev.is_finite() && ev.abs() <= MAX_ABS_EXPOSURE_EV) {
            // Large values in exponent form (-1e308 rather than 309 digits).
            let got = if ev.abs() >= 1e6 {
                format!("{ev:e}")
            } else {
                format!("{ev}")
            };
            return Err(super::invalid_option(format!(
                "--exposure must be a finite number of EV between -{MAX_ABS_EXPOSURE_EV} and {MAX_ABS_EXPOSURE_EV}, got {got}"
            )));
        }
    }
    Ok(())
}

/// The EXR channels and attributes of a film (renders and merges alike): absolute XYZ (Y in
/// cd/m²), the standard error of Y and, with `illuminance`, E in lx with its error and mask.
pub fn film_layers(scene: &str, film: &Film, illuminance: bool) -> Layers {
    let xyz = film.xyz_image();
    let mut layers = Layers::from_xyz(film.width, film.height, &xyz, &film.y_stderr_image());
    layers.attributes.extend([
        (
            "software".to_string(),
            format!("candela {}", env!("CARGO_PKG_VERSION")),
        ),
        ("scene".to_string(), scene.to_string()),
        (
            "channel_units".to_string(),
            "X,Y,Z: absolute CIE 1931 2° tristimulus values, Y = luminance in cd/m^2; stderr.Y: standard error of Y in cd/m^2, from the spread of the pixel's independently scrambled sample batches (see stderr_batches)".to_string(),
        ),
        (
            crate::film::STDERR_BATCHES_ATTRIBUTE.to_string(),
            film.pixel_batches.to_string(),
        ),
        (
            "spp".to_string(),
            format!("{:.2}", film.samples_per_pixel()),
        ),
    ]);
    if illuminance {
        let (e, se, mask) = film.illuminance_images();
        layers.channels.extend([
            (output::CHANNEL_E.to_string(), e),
            (output::CHANNEL_E_STDERR.to_string(), se),
            (output::CHANNEL_E_MASK.to_string(), mask),
        ]);
        layers.attributes.push((
            "illuminance".to_string(),
            format!(
                "E: illuminance in lx on the surface seen through the pixel (hemisphere facing the camera), {} where the pixel sees no receiving surface; stderr.E: its standard error; mask.E: fraction of samples that saw a receiving surface",
                output::ILLUMINANCE_SENTINEL
            ),
        ));
    }
    crate::film::add_health_layers(film, &mut layers);
    layers
}

/// Writes the film's EXR (see [`film_layers`]) with the camera's projection and Radiance view.
pub fn write_exr(
    scene_path: &Path,
    film: &Film,
    illuminance: bool,
    camera: &crate::camera::Camera,
    exr_path: &Path,
) -> Result<()> {
    let mut layers = film_layers(&scene_path.display().to_string(), film, illuminance);
    layers.attributes.push((
        output::ATTRIBUTE_PROJECTION.to_string(),
        crate::camera::describe(camera.projection()),
    ));
    if let Some(view) = camera.radiance_view() {
        layers
            .attributes
            .push((output::ATTRIBUTE_VIEW.to_string(), view));
    }
    output::write_exr(exr_path, &layers).context("cannot write the EXR")?;
    Ok(())
}

/// Writes the film as a Radiance picture with the camera's `VIEW=` (where Radiance has one)
/// and its projection in a `CANDELA_PROJECTION=` line.
pub fn write_hdr(film: &Film, camera: &crate::camera::Camera, hdr_path: &Path) -> Result<()> {
    let extra = [format!(
        "CANDELA_PROJECTION={}",
        crate::camera::describe(camera.projection())
    )];
    output::write_hdr(
        hdr_path,
        film.width,
        film.height,
        &film.xyz_image(),
        camera.radiance_view().as_deref(),
        &extra,
    )
    .context("cannot write the HDR")?;
    Ok(())
}

/// Writes the film's sRGB PNG at `exposure_ev` (None: automatic).
pub fn write_png(film: &Film, png_path: &Path, exposure_ev: Option<f64>) -> Result<()> {
    output::write_srgb_png(
        png_path,
        film.width,
        film.height,
        &film.xyz_image(),
        &PngSettings { exposure_ev },
    )
    .context("cannot write the PNG")?;
    Ok(())
}
