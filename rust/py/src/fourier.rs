//! Bindings of `librate_core::fourier`: evaluate a Fourier-series orbit at many times.

use librate_core::fourier::{FourierOrbit, Quantity};
use numpy::{IntoPyArray, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::to_py;

fn rows3(name: &str, a: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<f64>> {
    if a.shape()[1] != 3 {
        return Err(PyValueError::new_err(format!("invalid argument `{name}`: must have shape (N, 3), got {:?}", a.shape())));
    }
    Ok(a.as_array().iter().copied().collect())
}

/// Evaluate the series (period, a0 (3,), cos (N, 3), sin (N, 3)) at times t (m,):
/// quantity "position" | "velocity" | "acceleration" (m, 3), "state" (m, 6) or "all" (m, 9).
#[pyfunction]
#[pyo3(signature = (period, a0, cos, sin, t, *, quantity))]
fn fourier_evaluate<'py>(
    py: Python<'py>,
    period: f64,
    a0: PyReadonlyArray1<'py, f64>,
    cos: PyReadonlyArray2<'py, f64>,
    sin: PyReadonlyArray2<'py, f64>,
    t: PyReadonlyArray1<'py, f64>,
    quantity: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let a0: [f64; 3] = a0
        .as_array()
        .to_vec()
        .try_into()
        .map_err(|v: Vec<f64>| PyValueError::new_err(format!("invalid argument `a0`: must have 3 components (x, y, z), got {}", v.len())))?;
    let (c, s) = (rows3("cos", &cos)?, rows3("sin", &sin)?);
    let q = Quantity::parse(quantity).map_err(to_py)?;
    let ts: Vec<f64> = t.as_array().to_vec();
    let out = py
        .detach(|| FourierOrbit::from_flat(period, a0, &c, &s).and_then(|f| f.evaluate_many(&ts, q)))
        .map_err(to_py)?;
    out.into_pyarray(py).reshape([ts.len(), q.width()])
}

/// Add this module's functions to `librate._core`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fourier_evaluate, m)?)?;
    Ok(())
}
