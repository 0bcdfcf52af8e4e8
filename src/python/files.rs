//! Reading candela's files from Python: an EXR's channels and attributes, and a render state's
//! summary and estimate, through the same readers as `candela probe`, `glare` and `merge`.

use super::error;
use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// Channels of `layers` as (height, width) float32 arrays.
pub(super) fn channel_dict<'py>(
    py: Python<'py>,
    layers: &crate::output::Layers,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, values) in &layers.channels {
        let a = Array2::from_shape_vec((layers.height, layers.width), values.clone())
            .map_err(|e| super::error_msg(e.to_string()))?;
        d.set_item(name, a.into_pyarray(py))?;
    }
    Ok(d)
}

/// An EXR image: width, height, channels (name → (height, width) float32 array; for a candela
/// render `X`, `Y`, `Z`, `stderr.Y` in cd/m², and `E`, `stderr.E` in lx with `mask.E`) and the
/// text attributes.
#[pyfunction]
fn read_exr(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyDict>> {
    let layers = py
        .detach(|| crate::output::read_exr(&path))
        .map_err(|e| error(e.into()))?;
    let d = PyDict::new(py);
    d.set_item("width", layers.width)?;
    d.set_item("height", layers.height)?;
    d.set_item("channels", channel_dict(py, &layers)?)?;
    let attributes = PyDict::new(py);
    for (k, v) in &layers.attributes {
        attributes.set_item(k, v)?;
    }
    d.set_item("attributes", attributes)?;
    Ok(d)
}

/// A render state (checksum and values checked as for `--resume`): its scene, seed, settings,
/// shard, samples, and the estimate it holds as the channels its EXR would have.
#[pyfunction]
fn read_state(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyDict>> {
    // Read here rather than by `RenderState::load`, so that a file problem reaches Python as
    // a FileError with its errno.
    let st = py.detach(|| {
        let bytes =
            crate::limits::read_file(&path, crate::state::MAX_STATE_BYTES).map_err(|e| {
                super::file_error(
                    e.raw_os_error(),
                    format!("cannot read state file {}: {e}", path.display()),
                )
            })?;
        crate::state::RenderState::decode(&bytes, &path).map_err(error)
    })?;
    let d = PyDict::new(py);
    d.set_item("scene", &st.scene)?;
    d.set_item("scene_hash", st.scene_hash)?;
    d.set_item("version", st.version)?;
    d.set_item("seed", st.seed)?;
    d.set_item("merged_seeds", &st.merged_seeds)?;
    d.set_item(
        "max_depth",
        (st.max_depth != crate::state::UNLIMITED_DEPTH).then_some(st.max_depth),
    )?;
    d.set_item("illuminance", st.illuminance)?;
    d.set_item("width", st.film.width)?;
    d.set_item("height", st.film.height)?;
    d.set_item("adaptive", st.film.decision.is_some())?;
    d.set_item("total_samples", st.film.total_samples())?;
    d.set_item("samples_per_pixel", st.film.samples_per_pixel())?;
    d.set_item("shard", st.shard.map(|s| (s.index, s.count, s.spp)))?;
    d.set_item("pixel_batches", st.film.pixel_batches)?;
    d.set_item("meter_sums", st.meters.len())?;
    let layers = crate::job::files::film_layers(&st.scene, &st.film, st.illuminance);
    d.set_item("channels", channel_dict(py, &layers)?)?;
    Ok(d)
}

pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_exr, m)?)?;
    m.add_function(wrap_pyfunction!(read_state, m)?)?;
    Ok(())
}
