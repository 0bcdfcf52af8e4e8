//! The Python module `candela._candela` (feature `python`), wrapped by the pure-Python package
//! in `python/candela/`: rendering through the same [`crate::job::run`] as the command line
//! ([`render`]), scenes from RON text or Python dicts ([`scene`]), the colour library on numpy
//! arrays ([`colour`]) and reading candela's EXR and state files ([`files`]). Every error
//! reaches Python as `candela.CandelaError` with candela's own message (file, line, field); a
//! file that cannot be read or written as `candela.FileError`, which is also an `OSError`.
//! Every file is read through [`crate::limits`], as the command line reads it.

mod args;
mod colour;
mod files;
mod render;
mod scene;

use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

pyo3::create_exception!(
    candela,
    CandelaError,
    pyo3::exceptions::PyValueError,
    "An error candela reports: bad scene or input file (the message names the file, line:column or field), a bad argument (the message names it), or a job that cannot run."
);
pyo3::create_exception!(
    candela,
    Cancelled,
    CandelaError,
    "A render stopped before it finished (cancelled by the progress callback or the cancel event); the message says what was written."
);

/// `candela.FileError(OSError, CandelaError)`: made at import, as pyo3 declares exceptions
/// with one base only.
static FILE_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();

fn file_error_type(py: Python<'_>) -> PyResult<&Bound<'_, PyType>> {
    FILE_ERROR
        .get_or_try_init(py, || {
            let bases = PyTuple::new(
                py,
                // OSError first: its __init__ sets errno from the arguments.
                [
                    py.get_type::<pyo3::exceptions::PyOSError>().into_any(),
                    py.get_type::<CandelaError>().into_any(),
                ],
            )?;
            let namespace = PyDict::new(py);
            namespace.set_item("__module__", "candela")?;
            namespace.set_item(
                "__doc__",
                "A file candela cannot read or write (missing, not permitted, a directory, FIFO or device, larger than its limit, a full disk): both a CandelaError and an OSError; errno is the system's error number when the system refused, else None. str() is candela's message naming the file.",
            )?;
            let t = py
                .get_type::<PyType>()
                .call1(("FileError", bases, namespace))?;
            Ok(t.cast_into::<PyType>()?.unbind())
        })
        .map(|t| t.bind(py))
}

/// The file problem in `e`'s chain: an error the system gave (it has an errno) or one of
/// [`crate::limits::read_file`]'s refusals of the file itself (not a regular file, too large).
fn io_cause(e: &anyhow::Error) -> Option<&std::io::Error> {
    use std::io::ErrorKind;
    e.chain()
        .filter_map(|c| c.downcast_ref::<std::io::Error>())
        .find(|io| {
            io.raw_os_error().is_some()
                || matches!(io.kind(), ErrorKind::InvalidInput | ErrorKind::OutOfMemory)
        })
}

/// A Python `FileError` (errno or None, candela's message).
pub(crate) fn file_error(errno: Option<i32>, message: String) -> PyErr {
    Python::attach(|py| match (file_error_type(py), errno) {
        (Ok(t), Some(n)) => PyErr::from_type(t.clone(), (n, message)),
        // OSError's str() with one argument is the message alone (not "[Errno None] …").
        (Ok(t), None) => PyErr::from_type(t.clone(), (message,)),
        (Err(e), _) => e,
    })
}

/// A Python exception carrying candela's message (the error and its causes): `FileError` for
/// a file that cannot be read or written, `CandelaError` otherwise.
pub(crate) fn error(e: anyhow::Error) -> PyErr {
    let message = crate::job::error_text(&e);
    match io_cause(&e) {
        Some(io) => file_error(io.raw_os_error(), message),
        None => CandelaError::new_err(message),
    }
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
    m.add("FileError", file_error_type(py)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    render::register(m)?;
    scene::register(m)?;
    colour::register(m)?;
    files::register(m)?;
    Ok(())
}
