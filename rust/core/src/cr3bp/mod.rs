//! The circular restricted three-body problem in the synodic (rotating) frame, nondimensional
//! units (docs/physics.md: units, the CR3BP): Earth (m1) at (-mu, 0, 0), Moon (m2) at (1 - mu, 0, 0),
//! U = (x^2 + y^2)/2 + (1 - mu)/r1 + mu/r2,
//! xdd - 2 yd = U_x, ydd + 2 xd = U_y, zdd = U_z, Jacobi constant C = 2U - |v|^2.

mod dynamics;
mod lagrange;
mod system;

pub use dynamics::{acceleration, jacobi, potential, potential_gradient, potential_hessian, Cr3bp, Cr3bpStm, STM_DIM};
pub use lagrange::{collinear_point, lagrange_points};
pub use system::{check_mu, SystemConstants, PRESETS};
