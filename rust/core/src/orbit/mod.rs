//! Periodic orbits of the CR3BP (docs/physics.md, periodic orbits): symmetric single shooting on the half
//! period, general multiple shooting (free period, phase condition), monodromy matrices and
//! their stability indices. (The periodic attitude motions along an orbit are corrected in
//! [`crate::attitude`].)

mod multiple;
mod stability;
mod symmetric;

pub use multiple::{correct_multiple_shooting, MemberCondition, ShotOrbit};
pub use stability::{broucke_indices, monodromy, Stability};
pub use symmetric::{correct_planar_symmetric, Constraint, Evaluation, SymmetricOrbit, SymmetricShooting, Var};
