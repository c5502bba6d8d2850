//! Periodic orbits of the CR3BP (docs/physics.md, periodic orbits): symmetric single shooting on the half
//! period, general multiple shooting (free period, phase condition), monodromy matrices and
//! their stability indices; periodic planar attitude motions along an orbit (batched corrector
//! and independent verifier).

mod attitude;
mod attitude3d;
mod multiple;
mod newton;
mod stability;
mod symmetric;

pub use attitude3d::{attitude_residual, correct_attitudes_3d, correct_attitudes_3d_across, Correction3d, CorrectionAcross3d, Options3d, Start3d, StartAcross3d};
pub use multiple::{correct_multiple_shooting, MemberCondition, ShotOrbit};
pub use stability::{broucke_indices, monodromy, Stability};
pub use symmetric::{correct_planar_symmetric, Constraint, Evaluation, SymmetricOrbit, SymmetricShooting, Var};
pub use attitude::{
    correct_across_family, correct_bordered, correct_planar_attitudes, verify_planar_attitudes, Bordered, Candidate, Closure, Correction, CorrectorOptions, Free, Parameter,
    PlanarEnd, PlanarFamily,
    PlanarStart, StopReason,
};
