//! Periodic orbits of the CR3BP (PHYSICS.md section 3): symmetric single shooting on the half
//! period, monodromy matrices and their stability indices.

mod stability;
mod symmetric;

pub use stability::{broucke_indices, monodromy, Stability};
pub use symmetric::{correct_planar_symmetric, Constraint, Evaluation, SymmetricOrbit, SymmetricShooting, Var};
