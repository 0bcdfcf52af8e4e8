//! Checks of the arguments Python gives, with messages that name them (`spp`, not `--spp`):
//! integers within their range whatever size Python's int has, finite numbers, and the kinds
//! of objects a render calls back.

use super::error_msg;
use pyo3::exceptions::{PyOverflowError, PyTypeError};
use pyo3::prelude::*;

/// The text of `v` in a message, cut short.
fn shown(v: &Bound<'_, PyAny>) -> String {
    let text = v
        .repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "?".into());
    crate::limits::printable(&text, 60)
}

/// An integer argument `name` in `lo..=hi`: TypeError for what is not an integer (a bool or a
/// float included), CandelaError (a ValueError) naming the range for any integer outside it.
pub(crate) fn int_in(v: &Bound<'_, PyAny>, name: &str, lo: u64, hi: u64) -> PyResult<u64> {
    let range = || {
        error_msg(format!(
            "{name} must be an integer from {lo} to {hi}, got {}",
            shown(v)
        ))
    };
    if v.is_instance_of::<pyo3::types::PyBool>() {
        return Err(PyTypeError::new_err(format!(
            "{name} must be an integer, got a bool"
        )));
    }
    match v.extract::<u64>() {
        Ok(n) if (lo..=hi).contains(&n) => Ok(n),
        Ok(_) => Err(range()),
        Err(e) if e.is_instance_of::<PyOverflowError>(v.py()) => Err(range()),
        Err(_) => Err(PyTypeError::new_err(format!(
            "{name} must be an integer, got {}",
            v.get_type()
                .name()
                .map_or_else(|_| "?".into(), |n| n.to_string())
        ))),
    }
}

/// [`int_in`] of an optional argument (None stays None).
pub(crate) fn opt_int_in(
    v: &Option<Bound<'_, PyAny>>,
    name: &str,
    lo: u64,
    hi: u64,
) -> PyResult<Option<u64>> {
    v.as_ref()
        .filter(|v| !v.is_none())
        .map(|v| int_in(v, name, lo, hi))
        .transpose()
}

/// A number argument `name` that must be finite and satisfy `ok` (described by `what`).
pub(crate) fn number(name: &str, v: f64, what: &str, ok: impl Fn(f64) -> bool) -> PyResult<()> {
    if v.is_finite() && ok(v) {
        return Ok(());
    }
    let got = if v.abs() >= 1e6 {
        format!("{v:e}")
    } else {
        format!("{v}")
    };
    Err(error_msg(format!("{name} must be {what}, got {got}")))
}

/// Refuses a `progress` that cannot be called and a `cancel` without `is_set()`, before the
/// render starts rather than at its first pass.
pub(crate) fn callbacks(
    progress: &Option<Bound<'_, PyAny>>,
    cancel: &Option<Bound<'_, PyAny>>,
) -> PyResult<()> {
    if let Some(p) = progress.as_ref().filter(|p| !p.is_none()) {
        if !p.is_callable() {
            return Err(PyTypeError::new_err(format!(
                "progress must be callable as progress(samples_done, samples_total, elapsed_s), got {}",
                shown(p)
            )));
        }
    }
    if let Some(c) = cancel.as_ref().filter(|c| !c.is_none()) {
        if !c.hasattr("is_set")? {
            return Err(PyTypeError::new_err(format!(
                "cancel must have an is_set() method (a threading.Event), got {}",
                shown(c)
            )));
        }
    }
    Ok(())
}
