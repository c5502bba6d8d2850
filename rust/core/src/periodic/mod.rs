//! Periodic orbits of the CR3BP (PHYSICS.md section 3): symmetric single shooting on the half
//! period, general multiple shooting (free period, phase condition), monodromy matrices and
//! their stability indices.

mod multiple;
mod stability;
mod symmetric;

pub use multiple::{correct_multiple_shooting, MemberCondition, ShotOrbit};
pub use stability::{broucke_indices, monodromy, Stability};
pub use symmetric::{correct_planar_symmetric, Constraint, Evaluation, SymmetricOrbit, SymmetricShooting, Var};
