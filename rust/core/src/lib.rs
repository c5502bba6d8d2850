//! librate-core: the pure-Rust numerical core of librate (no Python).
//!
//! - [`integrate`]: the Runge-Kutta-Fehlberg 7(8) integrator built from parts, with events.
//! - [`cr3bp`]: CR3BP dynamics, variational equations, Jacobi constant, Lagrange points, systems.
//! - [`propagation`]: CR3BP propagation with the STM and events; batches on all cores.
//! - [`orbit`]: periodic orbits (symmetric and multiple shooting, stability).
//! - [`attitude`]: rigid-body attitude, and the correctors of periodic attitude motions.
//! - [`map`]: the periodicity maps (sweeps of the SIMD lane integrator, [`integrate::lanes`]).
//! - [`constants`]: physical constants (the Sun's motion, solar pressure).
//! - [`scalar`]: the scalar traits equations are written over (f64, dual numbers, SIMD lanes).
//! - [`newton`]: the dense Newton driver of the multiple-shooting and flexible correctors.
//! - [`fourier`]: periodic orbits as truncated Fourier series, with analytic derivatives.
//! - [`simd`]: runtime CPU dispatch of the hot kernels (baseline, AVX2, AVX-512, NEON).
//! - [`interrupt`]: the Ctrl-C request the long loops poll.
//! - [`threads`]: the global worker pool, its workers bound to CPUs.

pub mod attitude;
pub mod constants;
pub mod cr3bp;
pub mod ephemeris;
pub mod error;
pub mod flexible;
pub mod fourier;
pub mod integrate;
pub mod interrupt;
pub mod map;
pub mod newton;
pub mod orbit;
pub mod propagation;
pub mod scalar;
pub mod simd;
pub mod threads;

pub use error::{Error, IntegrationError, Result};
