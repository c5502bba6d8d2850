//! The one mapping of core errors to librate's typed Python exceptions.

use librate_core::error::Error;
use librate_core::IntegrationError as CoreIntegrationError;
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyKeyboardInterrupt, PyValueError};
use pyo3::prelude::*;

create_exception!(librate, LibrateError, PyException, "Base class of librate's errors.");
create_exception!(
    librate,
    IntegrationError,
    LibrateError,
    "An integration stopped before its final time (step-size underflow, too many steps, non-finite state). Attributes: t, steps."
);
create_exception!(
    librate,
    CollisionError,
    IntegrationError,
    "The trajectory reached a primary (the system's radius, or a tiny sphere for point masses). Attributes: t, steps, primary (1 or 2), distance, radius."
);
create_exception!(
    librate,
    ConvergenceError,
    LibrateError,
    "An iterative solver did not converge. Attributes: iterations, residual, tolerance."
);

/// Core error -> typed Python exception carrying its context as attributes.
pub(crate) fn to_py(e: Error) -> PyErr {
    Python::attach(|py| match &e {
        Error::InvalidArgument { .. } => PyValueError::new_err(e.to_string()),
        Error::Integration(ie) => {
            let err = match ie {
                CoreIntegrationError::Collision { .. } => CollisionError::new_err(e.to_string()),
                _ => IntegrationError::new_err(e.to_string()),
            };
            let v = err.value(py);
            let kind = match ie {
                CoreIntegrationError::StepSizeUnderflow { .. } => "step_size_underflow",
                CoreIntegrationError::MaxStepsExceeded { .. } => "max_steps_exceeded",
                CoreIntegrationError::NonFinite { .. } => "non_finite",
                CoreIntegrationError::Collision { primary, distance, radius, .. } => {
                    let _ = v.setattr("primary", *primary);
                    let _ = v.setattr("distance", *distance);
                    let _ = v.setattr("radius", *radius);
                    "collision"
                }
            };
            let _ = v.setattr("t", ie.t());
            let _ = v.setattr("steps", ie.steps());
            let _ = v.setattr("kind", kind);
            err
        }
        Error::Convergence { iterations, residual, tolerance, .. } => {
            let err = ConvergenceError::new_err(e.to_string());
            let v = err.value(py);
            let _ = v.setattr("iterations", *iterations);
            let _ = v.setattr("residual", *residual);
            let _ = v.setattr("tolerance", *tolerance);
            err
        }
        Error::Interrupted => PyKeyboardInterrupt::new_err("interrupted"),
    })
}

/// A ValueError for an argument the binding itself checks (shapes and lengths), naming it.
pub(crate) fn invalid(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

/// Add the exception classes to `librate._core`.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("LibrateError", py.get_type::<LibrateError>())?;
    m.add("IntegrationError", py.get_type::<IntegrationError>())?;
    m.add("CollisionError", py.get_type::<CollisionError>())?;
    m.add("ConvergenceError", py.get_type::<ConvergenceError>())?;
    Ok(())
}
