//! The Python module `candela._candela` (feature `python`), wrapped by the pure-Python package
//! in `python/candela/`: rendering through the same [`crate::job::run`] as the command line
//! ([`render`]), scenes from RON text or Python dicts ([`scene`]), the colour library on numpy
//! arrays ([`colour`]) and reading candela's EXR and state files ([`files`]). Every error
//! reaches Python as `candela.CandelaError` with candela's own message (file, line, field).

mod colour;
mod files;
mod render;
mod scene;

use pyo3::prelude::*;

pyo3::create_exception!(
    candela,
    CandelaError,
    pyo3::exceptions::PyValueError,
    "An error candela reports: bad scene or input file (the message names the file, line:column or field), or a job that cannot run."
);
pyo3::create_exception!(
    candela,
    Cancelled,
    CandelaError,
    "A render stopped before it finished (cancelled by the progress callback or the cancel event); the message says what was written."
);

/// A Python `CandelaError` carrying candela's message (the error and its causes).
pub(crate) fn error(e: anyhow::Error) -> PyErr {
    CandelaError::new_err(crate::job::error_text(&e))
}

/// A Python `CandelaError` with `message`.
pub(crate) fn error_msg(message: impl Into<String>) -> PyErr {
    CandelaError::new_err(message.into())
}

#[pymodule]
fn _candela(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("CandelaError", py.get_type::<CandelaError>())?;
    m.add("Cancelled", py.get_type::<Cancelled>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    render::register(m)?;
    scene::register(m)?;
    colour::register(m)?;
    files::register(m)?;
    Ok(())
}
