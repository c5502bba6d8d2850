//! librate-core: the pure-Rust numerical core of librate (no Python).
//!
//! - [`integrate`]: the Runge-Kutta-Fehlberg 7(8) integrator built from parts, with events.
//! - [`cr3bp`]: CR3BP dynamics, variational equations, Jacobi constant, Lagrange points, systems.
//! - [`propagation`]: CR3BP propagation with the STM and events; batches on all cores.
//! - [`periodic`]: symmetric periodic orbits by half-period shooting.
//! - [`fourier`]: periodic orbits as truncated Fourier series, with analytic derivatives.

pub mod attitude;
pub mod cr3bp;
pub mod error;
pub mod flexible;
pub mod fourier;
pub mod integrate;
pub mod map;
pub mod periodic;
pub mod propagation;

pub use error::{Error, IntegrationError, Result};
