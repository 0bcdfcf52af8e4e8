//! candela's colour library on numpy arrays: each spectrum is a row of an (N, W) array sampled
//! at W wavelengths (nm), resampled to candela's 1 nm grid over 360–830 nm by linear
//! interpolation (0 outside the samples) exactly as a spectrum file is, then handed to
//! [`crate::colour`]. Nothing is recomputed here.

use super::error_msg;
use crate::colour::alpha_opic::alpha_opic_quantities;
use crate::colour::colorimetry::{
    sd_to_xyz_absolute_with, sd_to_xyz_emissive_with, sd_to_xyz_relative_with, XyzMethod,
};
use crate::colour::cri::{colour_rendering_index, Cri};
use crate::colour::grid::LEN;
use crate::colour::models::{xyz_to_uv1960, xyz_to_xy};
use crate::colour::sd::{Interpolation, SpectralDistribution};
use crate::colour::tables::Observer;
use crate::colour::temperature::{uv_to_cct_ohno2013, uv_to_cct_robertson1968};
use crate::colour::tm30::{colour_rendition, ColourRendition, HueBin};
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// `f` of each row of `values` as a 1 nm table (360–830 nm); each row is checked as a spectrum
/// file is (finite, increasing wavelengths, finite values). One table at a time: the memory
/// taken is that of the results, whatever the number of rows.
fn per_row<T>(
    wavelengths_nm: PyReadonlyArray1<'_, f64>,
    values: PyReadonlyArray2<'_, f64>,
    f: impl Fn(&[f64; LEN]) -> T,
) -> PyResult<Vec<T>> {
    let wl = wavelengths_nm.as_array().to_vec();
    let v = values.as_array();
    if v.ncols() != wl.len() {
        return Err(error_msg(format!(
            "values has {} columns but wavelengths_nm has {} wavelengths; give spectra as an (N, W) array with one row per spectrum",
            v.ncols(),
            wl.len()
        )));
    }
    v.rows()
        .into_iter()
        .enumerate()
        .map(|(i, row)| {
            SpectralDistribution::new(wl.clone(), row.to_vec())
                .map(|sd| f(&sd.to_table_with(Interpolation::default())))
                .map_err(|e| error_msg(format!("values: spectrum {i}: {e}")))
        })
        .collect()
}

fn observer(name: &str) -> PyResult<Observer> {
    match name {
        "1931" | "CIE 1931 2 Degree Standard Observer" => Ok(Observer::Cie1931_2),
        "1964" | "CIE 1964 10 Degree Standard Observer" => Ok(Observer::Cie1964_10),
        o => Err(error_msg(format!(
            "observer must be \"1931\" (2°) or \"1964\" (10°), got {o:?}"
        ))),
    }
}

fn method(name: &str) -> PyResult<XyzMethod> {
    match name {
        "integration" => Ok(XyzMethod::Integration),
        "astm-e308" => Ok(XyzMethod::AstmE308),
        m => Err(error_msg(format!(
            "method must be \"integration\" (360–830 nm) or \"astm-e308\" (360–780 nm), got {m:?}"
        ))),
    }
}

fn rows<const K: usize>(v: Vec<[f64; K]>) -> Array2<f64> {
    let n = v.len();
    Array2::from_shape_vec((n, K), v.into_iter().flatten().collect()).expect("n rows of K values")
}

/// XYZ of spectra: `kind` "absolute" (K_m Σ S x̄ Δλ: cd/m² for a radiance in W·m⁻²·sr⁻¹·nm⁻¹,
/// lx for an irradiance), "emissive" (Y = 100 for S ≡ 1) or "relative" (object colours under
/// `illuminant`, Y = 100 for the perfect diffuser). Returns (N, 3).
#[pyfunction]
#[pyo3(signature = (wavelengths_nm, values, kind, illuminant=None, observer="1931", method="integration"))]
#[allow(clippy::too_many_arguments)]
fn sd_to_xyz<'py>(
    py: Python<'py>,
    wavelengths_nm: PyReadonlyArray1<'py, f64>,
    values: PyReadonlyArray2<'py, f64>,
    kind: &str,
    illuminant: Option<(PyReadonlyArray1<'py, f64>, PyReadonlyArray1<'py, f64>)>,
    observer: &str,
    method: &str,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let (obs, m) = (self::observer(observer)?, self::method(method)?);
    let xyz: Vec<[f64; 3]> = match kind {
        "absolute" => per_row(wavelengths_nm, values, |s| {
            sd_to_xyz_absolute_with(s, obs, m)
        })?,
        "emissive" => per_row(wavelengths_nm, values, |s| {
            sd_to_xyz_emissive_with(s, obs, m)
        })?,
        "relative" => {
            let (iw, iv) = illuminant.ok_or_else(|| {
                error_msg("kind \"relative\" needs an illuminant (wavelengths_nm, values)")
            })?;
            let ill = SpectralDistribution::new(iw.as_array().to_vec(), iv.as_array().to_vec())
                .map_err(|e| error_msg(format!("illuminant: {e}")))?
                .to_table_with(Interpolation::default());
            per_row(wavelengths_nm, values, |s| {
                sd_to_xyz_relative_with(s, &ill, obs, m)
            })?
        }
        k => {
            return Err(error_msg(format!(
                "kind must be \"absolute\", \"emissive\" or \"relative\", got {k:?}"
            )))
        }
    };
    Ok(rows(xyz).into_pyarray(py))
}

fn xyz_rows(xyz: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<[f64; 3]>> {
    let a = xyz.as_array();
    if a.ncols() != 3 {
        return Err(error_msg(format!(
            "XYZ must be an (N, 3) array, got {} columns",
            a.ncols()
        )));
    }
    Ok(a.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect())
}

/// CIE 1931 chromaticity (x, y) of (N, 3) tristimulus values; returns (N, 2).
#[pyfunction]
fn xyz_to_xy_array<'py>(
    py: Python<'py>,
    xyz: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let v: Vec<[f64; 2]> = xyz_rows(&xyz)?.into_iter().map(xyz_to_xy).collect();
    Ok(rows(v).into_pyarray(py))
}

/// CCT (K) and Duv of (N, 3) tristimulus values by Ohno (2013) or Robertson (1968); (N, 2).
#[pyfunction]
#[pyo3(signature = (xyz, method="ohno2013"))]
fn xyz_to_cct_duv<'py>(
    py: Python<'py>,
    xyz: PyReadonlyArray2<'py, f64>,
    method: &str,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let f: fn([f64; 2]) -> [f64; 2] = match method {
        "ohno2013" => uv_to_cct_ohno2013,
        "robertson1968" => uv_to_cct_robertson1968,
        m => {
            return Err(error_msg(format!(
                "method must be \"ohno2013\" or \"robertson1968\", got {m:?}"
            )))
        }
    };
    let v: Vec<[f64; 2]> = xyz_rows(&xyz)?
        .into_iter()
        .map(|x| f(xyz_to_uv1960(x)))
        .collect();
    Ok(rows(v).into_pyarray(py))
}

/// CIE 13.3 colour rendering of light sources: Ra (N,), R1–R14 (N, 14), CCT (K) and Duv.
#[pyfunction]
fn cri<'py>(
    py: Python<'py>,
    wavelengths_nm: PyReadonlyArray1<'py, f64>,
    values: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let c: Vec<_> = per_row(wavelengths_nm, values, colour_rendering_index)?;
    let d = PyDict::new(py);
    let col = |f: &dyn Fn(&Cri) -> f64| Array1::from_iter(c.iter().map(f)).into_pyarray(py);
    d.set_item("Ra", col(&|c: &Cri| c.ra))?;
    d.set_item("R", rows(c.iter().map(|c| c.r).collect()).into_pyarray(py))?;
    d.set_item("cct_K", col(&|c: &Cri| c.cct_k))?;
    d.set_item("duv", col(&|c: &Cri| c.duv))?;
    Ok(d)
}

/// CIE S 026 α-opic quantities of spectral irradiances (W·m⁻²·nm⁻¹); the five columns are
/// S-cone, M-cone, L-cone, rhodopic, melanopic.
#[pyfunction]
fn alpha_opic<'py>(
    py: Python<'py>,
    wavelengths_nm: PyReadonlyArray1<'py, f64>,
    values: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let q: Vec<_> = per_row(wavelengths_nm, values, alpha_opic_quantities)?;
    let d = PyDict::new(py);
    d.set_item(
        "irradiance_W_m2",
        rows(q.iter().map(|q| q.irradiance_w_m2).collect()).into_pyarray(py),
    )?;
    d.set_item(
        "illuminance_lx",
        Array1::from_iter(q.iter().map(|q| q.illuminance_lx)).into_pyarray(py),
    )?;
    d.set_item(
        "elr_W_per_lm",
        rows(q.iter().map(|q| q.elr_w_per_lm).collect()).into_pyarray(py),
    )?;
    d.set_item(
        "der",
        rows(q.iter().map(|q| q.der).collect()).into_pyarray(py),
    )?;
    d.set_item(
        "edi_lx",
        rows(q.iter().map(|q| q.edi_lx).collect()).into_pyarray(py),
    )?;
    d.set_item(
        "equivalent_melanopic_lux",
        Array1::from_iter(q.iter().map(|q| q.equivalent_melanopic_lux)).into_pyarray(py),
    )?;
    Ok(d)
}

/// TM-30-20 / CIE 224:2017 colour rendition: Rf, Rg, the 16 hue bins' fidelity, chroma shift
/// (%) and hue shift (rad), CCT (K) and Duv; NaN for a spectrum outside the method's domain.
#[pyfunction]
fn tm30<'py>(
    py: Python<'py>,
    wavelengths_nm: PyReadonlyArray1<'py, f64>,
    values: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let r: Vec<_> = per_row(wavelengths_nm, values, colour_rendition)?;
    let scalar = |f: &dyn Fn(&ColourRendition) -> f64| {
        Array1::from_iter(r.iter().map(|c| c.as_ref().map_or(f64::NAN, f))).into_pyarray(py)
    };
    let bins = |f: &dyn Fn(&HueBin) -> f64| {
        rows(
            r.iter()
                .map(|c| {
                    let mut row = [f64::NAN; 16];
                    if let Some(c) = c {
                        for (o, b) in row.iter_mut().zip(&c.bins) {
                            *o = f(b);
                        }
                    }
                    row
                })
                .collect(),
        )
        .into_pyarray(py)
    };
    let d = PyDict::new(py);
    d.set_item("Rf", scalar(&|c: &ColourRendition| c.rf))?;
    d.set_item("Rg", scalar(&|c: &ColourRendition| c.rg))?;
    d.set_item("cct_K", scalar(&|c: &ColourRendition| c.cct_k))?;
    d.set_item("duv", scalar(&|c: &ColourRendition| c.duv))?;
    d.set_item("Rf_bins", bins(&|b: &HueBin| b.fidelity))?;
    d.set_item(
        "chroma_shift_percent",
        bins(&|b: &HueBin| b.chroma_shift_percent),
    )?;
    d.set_item("hue_shift_rad", bins(&|b: &HueBin| b.hue_shift_rad))?;
    Ok(d)
}

/// Wavelengths (nm) and values of a spectrum, as numpy arrays.
type SpectrumArrays<'py> = (
    Bound<'py, numpy::PyArray1<f64>>,
    Bound<'py, numpy::PyArray1<f64>>,
);

/// A named spectrum of candela's tables (`D65`, `A`, `FL2`, `LED-B3`, `TCS01`, …) at its own
/// wavelengths: (wavelengths_nm, values).
#[pyfunction]
fn named_spectrum<'py>(py: Python<'py>, name: &str) -> PyResult<SpectrumArrays<'py>> {
    let sd = crate::colour::tables::named_spectrum(name).ok_or_else(|| {
        error_msg(format!(
            "unknown spectrum {name:?}; known: {}",
            crate::colour::tables::named_spectrum_names().join(", ")
        ))
    })?;
    Ok((
        sd.wavelengths_nm.clone().into_pyarray(py),
        sd.values.clone().into_pyarray(py),
    ))
}

pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(sd_to_xyz, m)?)?;
    m.add_function(wrap_pyfunction!(xyz_to_xy_array, m)?)?;
    m.add_function(wrap_pyfunction!(xyz_to_cct_duv, m)?)?;
    m.add_function(wrap_pyfunction!(cri, m)?)?;
    m.add_function(wrap_pyfunction!(alpha_opic, m)?)?;
    m.add_function(wrap_pyfunction!(tm30, m)?)?;
    m.add_function(wrap_pyfunction!(named_spectrum, m)?)?;
    Ok(())
}
