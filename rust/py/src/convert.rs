//! Array conversions shared by the bindings: fixed-size vectors, (n, k) row arrays, optional
//! per-case arrays, output times, and NumPy results. Each error names the argument.

use librate_core::integrate::Output;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::errors::invalid;

/// A fixed-size vector from a slice, e.g. a CR3BP state of 6 components.
pub(crate) fn fixed<const N: usize>(name: &str, v: &[f64]) -> PyResult<[f64; N]> {
    <[f64; N]>::try_from(v).map_err(|_| invalid(format!("invalid argument `{name}`: must have {N} components, got {}", v.len())))
}

/// A CR3BP state (x, y, z, xd, yd, zd).
pub(crate) fn state6(name: &str, v: &[f64]) -> PyResult<[f64; 6]> {
    <[f64; 6]>::try_from(v).map_err(|_| invalid(format!("invalid argument `{name}`: must have 6 components (x, y, z, xd, yd, zd), got {}", v.len())))
}

/// The rows of an (n, N) array; `n` checked when given.
pub(crate) fn rows<const N: usize>(a: &PyReadonlyArray2<'_, f64>, name: &str, n: Option<usize>) -> PyResult<Vec<[f64; N]>> {
    let a = a.as_array();
    if a.ncols() != N || n.is_some_and(|n| a.nrows() != n) {
        let rows = n.map_or("n".to_string(), |n| n.to_string());
        return Err(invalid(format!("invalid argument `{name}`: must have shape ({rows}, {N}), got {:?}", a.shape())));
    }
    Ok(a.rows().into_iter().map(|r| std::array::from_fn(|k| r[k])).collect())
}

/// A 1-D array as a vector, of length `n` when given.
pub(crate) fn vector<T: numpy::Element + Clone>(a: &PyReadonlyArray1<'_, T>, name: &str, n: Option<usize>) -> PyResult<Vec<T>> {
    let v = a.as_array().to_vec();
    match n {
        Some(n) if v.len() != n => Err(invalid(format!("invalid argument `{name}`: must have length {n}, got {}", v.len()))),
        _ => Ok(v),
    }
}

/// A per-case float array: the given one (length checked against `n`) or zeros.
pub(crate) fn per_case(a: Option<&PyReadonlyArray1<'_, f64>>, name: &str, n: usize) -> PyResult<Vec<f64>> {
    match a {
        None => Ok(vec![0.0; n]),
        Some(v) => vector(v, name, Some(n)),
    }
}

/// The output times of a propagation: the given ones or every step.
pub(crate) fn output(t_eval: &Option<Vec<f64>>) -> Output<'_> {
    match t_eval {
        Some(t) => Output::At(t),
        None => Output::Steps,
    }
}

/// Optional output times from Python.
pub(crate) fn times(t_eval: Option<PyReadonlyArray1<'_, f64>>) -> Option<Vec<f64>> {
    t_eval.map(|a| a.as_array().to_vec())
}

/// A fixed R x C matrix as a NumPy array.
pub(crate) fn matrix<'py, const R: usize, const C: usize>(py: Python<'py>, m: &[[f64; C]; R]) -> Bound<'py, PyAny> {
    Array2::from_shape_fn((R, C), |(i, j)| m[i][j]).into_pyarray(py).into_any()
}

/// A flat row-major vector as an (m, k) NumPy array.
pub(crate) fn table(py: Python<'_>, v: Vec<f64>, m: usize, k: usize) -> PyResult<Py<PyAny>> {
    Ok(v.into_pyarray(py).reshape([m, k])?.into_any().unbind())
}

/// A vector as a 1-D NumPy array.
pub(crate) fn array<T: numpy::Element>(py: Python<'_>, v: Vec<T>) -> Py<PyAny> {
    v.into_pyarray(py).into_any().unbind()
}
