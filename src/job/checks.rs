//! The job's own options, checked before the scene is read: values that no input can make
//! valid are [`InvalidOption`]s (the command line's usage errors).

use super::{check_exposure, RenderJob};
use anyhow::Result;

/// An option of a job with a value that no input can make valid (a thread count of 0, an
/// exposure of NaN, …). The command line exits with code 2 for it, as for its other usage
/// errors; the message names the command-line option.
#[derive(Debug)]
pub struct InvalidOption(pub String);

impl std::fmt::Display for InvalidOption {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for InvalidOption {}

/// An [`InvalidOption`] error.
pub fn invalid_option(message: impl Into<String>) -> anyhow::Error {
    InvalidOption(message.into()).into()
}

/// Largest worker-thread count accepted: 16 per available core
/// ([`std::thread::available_parallelism`]). More only adds contention and memory, and tens of
/// thousands of threads make the process unresponsive.
pub fn max_threads() -> usize {
    16 * std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Refuses a thread count (named `flag` in the message) of 0 or above [`max_threads`].
pub fn check_threads(flag: &str, n: usize) -> Result<()> {
    if n == 0 {
        return Err(invalid_option(format!("{flag} must be at least 1, got 0")));
    }
    let max = max_threads();
    if n > max {
        return Err(invalid_option(format!(
            "{flag} {n} is too many: at most {max} threads are accepted (16 per available core, {} cores here)",
            max / 16
        )));
    }
    Ok(())
}

/// Refuses a target fraction outside (0, 1] or a luminance floor (cd/m²) that is negative or
/// not finite; the messages name the command-line options.
pub fn check_target(fraction: f64, floor_cd_m2: Option<f64>) -> Result<()> {
    if !(fraction > 0.0 && fraction <= 1.0) {
        return Err(invalid_option(format!(
            "--target-fraction must lie in (0, 1], got {fraction}"
        )));
    }
    if let Some(f) = floor_cd_m2 {
        if !(f.is_finite() && f >= 0.0) {
            return Err(invalid_option(format!(
                "--target-floor must be a luminance ≥ 0 in cd/m², got {f}"
            )));
        }
    }
    Ok(())
}

/// Checks the job's own settings (before the scene is read).
pub(super) fn check_job(job: &RenderJob) -> Result<()> {
    if let Some(n) = job.threads {
        check_threads("--threads", n)?;
    }
    check_exposure(job.exposure_ev)?;
    if let Some(t) = &job.target {
        check_target(t.fraction, t.floor_cd_m2)?;
    }
    if job.max_spp == Some(0) {
        return Err(invalid_option("--max-spp must be at least 1"));
    }
    if job.overrides.spp == Some(0) {
        return Err(invalid_option("--spp must be at least 1"));
    }
    if job.shard.is_some() && job.target.is_some() {
        return Err(invalid_option(
            "--shard splits a fixed number of samples per pixel among the shards; --target-error decides it pixel by pixel as the render goes, which separate shards cannot share: give --shard with --spp",
        ));
    }
    if job.health.spectral_bands > crate::film::MAX_SPECTRAL_BANDS {
        return Err(invalid_option(format!(
            "--spectral-bands must be at most {}",
            crate::film::MAX_SPECTRAL_BANDS
        )));
    }
    if job.resume && job.overwrite {
        return Err(invalid_option(
            "--resume continues NAME.state and --overwrite replaces it: give one of them",
        ));
    }
    Ok(())
}
