//! Bindings of the 3-D periodicity-map engine: convert, call the core with the GIL released,
//! convert (the result arrays are moved into NumPy, not copied).

use librate_core::attitude::RigidBody;
use librate_core::integrate::forcing::TidalTable;
use librate_core::integrate::lanes3d::Case3d;
use librate_core::map::sweep_3d;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::convert::rows;
use crate::options::LaneOptions;
use crate::interrupt::interruptible;
use crate::to_py;

/// The synodic-frame tidal tensor of one periodic orbit (planar or spatial), tabulated once
/// (piecewise Chebyshev) and shared by every 3-D attitude trajectory on it.
#[pyclass(frozen, name = "TidalTable", module = "librate._core")]
pub struct PyTidalTable {
    inner: TidalTable,
}

#[pymethods]
impl PyTidalTable {
    #[new]
    #[pyo3(signature = (mu, state0, period, *, primaries=[true, true], tol=1e-12))]
    fn new(py: Python<'_>, mu: f64, state0: [f64; 6], period: f64, primaries: [bool; 2], tol: f64) -> PyResult<Self> {
        let inner = py.detach(|| TidalTable::tidal(mu, &state0, period, primaries, tol)).map_err(to_py)?;
        Ok(Self { inner })
    }
    #[getter]
    fn period(&self) -> f64 {
        self.inner.period
    }
    #[getter]
    fn segments(&self) -> usize {
        self.inner.segments()
    }
    #[getter]
    fn max_error(&self) -> f64 {
        self.inner.max_error
    }
    /// The tensor (xx, yy, zz, xy, xz, yz) at the given times, (n, 6).
    fn tensor<'py>(&self, py: Python<'py>, t: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyAny>> {
        let t = t.as_array();
        let v: Vec<f64> = t.iter().flat_map(|&ti| self.inner.eval(ti)).collect();
        Ok(Array2::from_shape_vec((t.len(), 6), v).map_err(|e| PyValueError::new_err(e.to_string()))?.into_pyarray(py).into_any())
    }
}

/// The outcome of `map_sweep_3d`: arrays over the cases.
#[pyclass(frozen, get_all, name = "Sweep3DResult", module = "librate._core")]
pub struct PySweep3DResult {
    /// The six closure residuals (n, 6): the rotation vector of R(0)' R(t_final) in body axes,
    /// then w(t_final) - w0.
    residual: Py<PyAny>,
    /// The attitude at t_final (n, 4), scalar last.
    q_t: Py<PyAny>,
    /// The inertial rate at t_final in body axes (n, 3).
    w_t: Py<PyAny>,
    /// Lane status per case (0 ok, 1 max steps, 2 failed), uint8 (n,).
    status: Py<PyAny>,
    /// Accepted and rejected steps per case, (n, 2).
    steps: Py<PyAny>,
}

#[pymethods]
impl PySweep3DResult {
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.status.bind(py).len()
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("Sweep3DResult(n={})", self.__len__(py)?))
    }
}

/// Integrate 3-D attitude trajectories (q0 (n, 4) scalar last, w0 (n, 3) inertial in body axes,
/// inertia (n, 3) principal moments) over t_final along the tabulated orbit. Returns a
/// `Sweep3DResult`: residual (n, 6), q_t (n, 4), w_t (n, 3), status (n,) uint8 (0 ok, 1 max
/// steps, 2 failed), steps (n, 2) accepted and rejected.
#[pyfunction]
#[pyo3(signature = (table, t_final, q0, w0, inertia, *, lanes))]
fn map_sweep_3d<'py>(
    py: Python<'py>,
    table: PyRef<'py, PyTidalTable>,
    t_final: f64,
    q0: PyReadonlyArray2<'py, f64>,
    w0: PyReadonlyArray2<'py, f64>,
    inertia: PyReadonlyArray2<'py, f64>,
    lanes: PyRef<'py, LaneOptions>,
) -> PyResult<PySweep3DResult> {
    let n = q0.as_array().nrows();
    let (q, w, m) = (rows::<4>(&q0, "q0", Some(n))?, rows::<3>(&w0, "w0", Some(n))?, rows::<3>(&inertia, "inertia", Some(n))?);
    let cases: Vec<Case3d> = (0..n).map(|i| Case3d { q0: q[i], w0: w[i], body: RigidBody { ix: m[i][0], iy: m[i][1], iz: m[i][2] } }).collect();
    let (opts, chunk, threads) = (lanes.core(), lanes.chunk, lanes.threads);
    let f = &table.inner;
    let out = interruptible(py, || sweep_3d(f, t_final, &cases, &opts, chunk, threads))?;
    let flat = |k: usize, g: &dyn Fn(&librate_core::integrate::lanes3d::Outcome3d) -> Vec<f64>| -> PyResult<Py<PyAny>> {
        let v: Vec<f64> = out.iter().flat_map(g).collect();
        Ok(Array2::from_shape_vec((n, k), v).map_err(|e| PyValueError::new_err(e.to_string()))?.into_pyarray(py).into_any().unbind())
    };
    let steps: Vec<u32> = out.iter().flat_map(|o| [o.accepted, o.rejected]).collect();
    Ok(PySweep3DResult {
        residual: flat(6, &|o| o.residual.to_vec())?,
        q_t: flat(4, &|o| o.q_t.to_vec())?,
        w_t: flat(3, &|o| o.w_t.to_vec())?,
        status: out.iter().map(|o| o.status as u8).collect::<Vec<u8>>().into_pyarray(py).into_any().unbind(),
        steps: Array2::from_shape_vec((n, 2), steps).map_err(|e| PyValueError::new_err(e.to_string()))?.into_pyarray(py).into_any().unbind(),
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyTidalTable>()?;
    m.add_class::<PySweep3DResult>()?;
    m.add_function(wrap_pyfunction!(map_sweep_3d, m)?)?;
    m.add("MAP3D_ALIGN", librate_core::integrate::lanes3d::ALIGN)?;
    Ok(())
}
