//! Errors of the core. Every variant carries the context a user needs to act on it
//! (the parameter and its allowed range, or the time, step count and residual).

use thiserror::Error;

/// Why an integration stopped before reaching its final time.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum IntegrationError {
    /// The step controller asked for a step below `h_min`: the solution is (nearly) singular,
    /// e.g. a collision with a primary, or the tolerances are unreachable.
    #[error("step size underflow at t = {t:.15e} after {steps} steps: step {h:.3e} is below h_min = {h_min:.3e}")]
    StepSizeUnderflow { t: f64, steps: usize, h: f64, h_min: f64 },
    /// More than `max_steps` steps (accepted + rejected) were needed.
    #[error("maximum number of steps ({max_steps}) exceeded at t = {t:.15e}")]
    MaxStepsExceeded { t: f64, steps: usize, max_steps: usize },
    /// The state or its derivative became NaN or infinite (e.g. the trajectory reached a primary).
    #[error("non-finite state at t = {t:.15e} after {steps} steps (collision with a primary?)")]
    NonFinite { t: f64, steps: usize },
    /// The trajectory reached a primary: its distance to primary `primary` (1: the larger, at
    /// x = -mu; 2: the smaller, at x = 1 - mu) fell to the collision `radius` (nondimensional).
    #[error("collision with primary {primary} ({}) at t = {t:.15e}: distance {distance:.3e} <= collision radius {radius:.3e} LU", if *primary == 1 { "the larger, at x = -mu" } else { "the smaller, at x = 1 - mu" })]
    Collision { t: f64, steps: usize, primary: u8, distance: f64, radius: f64 },
}

impl IntegrationError {
    /// Time at which the integration stopped.
    pub fn t(&self) -> f64 {
        match *self {
            Self::StepSizeUnderflow { t, .. } | Self::MaxStepsExceeded { t, .. } | Self::NonFinite { t, .. } | Self::Collision { t, .. } => t,
        }
    }
    /// Steps (accepted and rejected) taken before the failure.
    pub fn steps(&self) -> usize {
        match *self {
            Self::StepSizeUnderflow { steps, .. }
            | Self::MaxStepsExceeded { steps, .. }
            | Self::NonFinite { steps, .. }
            | Self::Collision { steps, .. } => steps,
        }
    }
}

/// All errors of librate-core.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum Error {
    /// A caller-supplied argument is outside its allowed range.
    #[error("invalid argument `{name}`: {message}")]
    InvalidArgument { name: &'static str, message: String },
    #[error(transparent)]
    Integration(#[from] IntegrationError),
    /// An iterative solver (Newton, shooting) did not converge.
    #[error("{what} did not converge after {iterations} iterations (residual {residual:.3e}, tolerance {tolerance:.1e})")]
    Convergence { what: &'static str, iterations: usize, residual: f64, tolerance: f64 },
    /// The caller asked the computation to stop ([`crate::interrupt::request`], Ctrl-C).
    #[error("interrupted")]
    Interrupted,
}

pub type Result<T> = std::result::Result<T, Error>;

/// Shorthand for an [`Error::InvalidArgument`].
pub fn invalid(name: &'static str, message: impl Into<String>) -> Error {
    Error::InvalidArgument { name, message: message.into() }
}

/// `Ok` when `value` is finite and strictly positive.
pub fn check_positive(name: &'static str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(name, format!("must be a finite number > 0, got {value}")))
    }
}

/// `Ok` when every component is finite.
pub fn check_finite(name: &'static str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(invalid(name, format!("must be finite, component {i} is {}", values[i]))),
    }
}
