//! Runge-Kutta-Fehlberg 7(8) integration, built from parts (as in `ode_solvers`):
//! a [`tableau`] of compile-time coefficients, a step-size [`controller`], a [`stepper`] that
//! takes one step with preallocated stage storage, and a [`driver`](solve) that runs the step
//! loop with output, event location and [`Stats`].
//!
//! States are generic over their dimension through [`State`]: fixed-size arrays `[f64; N]`
//! (dimension known at compile time, no heap at all) or `Vec<f64>` (dimension chosen at run
//! time; storage allocated once when the stepper is built). Nothing is allocated inside the step
//! loop except the growth of user-requested output buffers.

pub mod controller;
pub mod driver;
pub mod events;
pub mod forcing;
pub mod lanes;
pub mod lanes3d;
pub mod stepper;
pub mod rkn;
pub mod tableau;

pub use controller::{Controller, StepControl};
pub use driver::{check_tolerances, solve, solve_piecewise, Options, Output, Solution, Status};
pub use events::{Event, EventFn, EventRecord};
pub use stepper::Rkf78;

/// A state vector the integrators can work on.
pub trait State: Clone + Send + Sync {
    fn as_slice(&self) -> &[f64];
    fn as_mut_slice(&mut self) -> &mut [f64];
    /// Number of components.
    fn dim(&self) -> usize {
        self.as_slice().len()
    }
}

impl<const N: usize> State for [f64; N] {
    #[inline(always)]
    fn as_slice(&self) -> &[f64] {
        self
    }
    #[inline(always)]
    fn as_mut_slice(&mut self) -> &mut [f64] {
        self
    }
}

impl State for Vec<f64> {
    #[inline(always)]
    fn as_slice(&self) -> &[f64] {
        self
    }
    #[inline(always)]
    fn as_mut_slice(&mut self) -> &mut [f64] {
        self
    }
}

/// A first-order ODE system y' = f(t, y), evaluated in place.
pub trait System<S: State>: Sync {
    /// Write f(t, y) into `dy` (same dimension as `y`).
    fn derivative(&self, t: f64, y: &S, dy: &mut S);
}

/// Counters of one integration.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    /// Steps accepted.
    pub accepted: usize,
    /// Steps rejected by the error controller.
    pub rejected: usize,
    /// Right-hand-side evaluations (including those spent on output and event location).
    pub rhs_evals: usize,
}

impl Stats {
    pub fn steps(&self) -> usize {
        self.accepted + self.rejected
    }
}

