//! librate-core: the pure-Rust numerical core of librate (no Python).
//!
//! - [`integrate`]: the Runge-Kutta-Fehlberg 7(8) integrator built from parts, with events.
//! - [`cr3bp`]: CR3BP dynamics, variational equations, Jacobi constant, Lagrange points, systems.
//! - [`propagation`]: CR3BP propagation with the STM and events; batches on all cores.
//! - [`periodic`]: symmetric periodic orbits by half-period shooting.
//! - [`constants`]: physical constants (the Sun's motion, solar pressure).
//! - [`scalar`]: the scalar traits equations are written over (f64, dual numbers, SIMD lanes).
//! - [`fourier`]: periodic orbits as truncated Fourier series, with analytic derivatives.
//! - [`simd`]: runtime CPU dispatch of the hot kernels (baseline, AVX2, AVX-512, NEON).

// Intentional patterns: `!(x <= tol)` is the NaN-safe test (a NaN must fail it); numerical
// kernels take many scalar arguments; dual-number products contain sums by definition.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::too_many_arguments, clippy::suspicious_arithmetic_impl, clippy::type_complexity)]

pub mod attitude;
pub mod constants;
pub mod cr3bp;
pub mod ephemeris;
pub mod error;
pub mod flexible;
pub mod fourier;
pub mod integrate;
pub mod map;
pub mod periodic;
pub mod propagation;
pub mod scalar;
pub mod simd;

pub use error::{Error, IntegrationError, Result};
