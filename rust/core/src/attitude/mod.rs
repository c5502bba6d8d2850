//! Rigid-body attitude coupled with the CR3BP orbit (thesis ch. 3.1-3.2, docs/physics.md, attitude):
//! the 3-D model (quaternion + Euler's equations, torques as plug-in models, optional orbital
//! coupling and 13x13 STM) and the planar reduced model (phi, wz) along an orbit; and the
//! correctors of periodic attitude motions along an orbit (planar: [`periodic`], 3-D:
//! [`periodic3d`], on one Newton driver).

pub mod body;
pub mod dual;
pub mod dynamics;
pub mod linear;
mod newton;
mod periodic;
mod periodic3d;
mod refine;
pub mod planar;
pub mod propagate;
pub mod srp;
pub mod torque;

pub use body::RigidBody;
pub use dynamics::{dcm, dcm_with, quat_kinematics, quat_rate, Coupled, CoupledStm, OrbitMode};
pub use linear::{collinear_equilibrium, Equilibrium};
pub use planar::{forcing_sc, forcing_scp, gravity_gradient_wzdot, planar_gravity_gradient, Forcing, PlanarAlongOrbit, PlanarForced};
pub use propagate::{evaluate_torques, propagate_attitude, propagate_planar, AttitudeTrajectory, PlanarTrajectory};
pub use srp::{flat_plate_wzdot, Facet, FacetBody, FlatPlate, Sun, N_SUN, OMEGA_SUN, P0, SOLAR_PRESSURE_1AU};
pub use torque::{euler_rate, gravity_gradient_by_name, gravity_gradient_torque, euler_ratios, gravity_gradient_euler_rate, tidal_tensor, tidal_term, GravityGradient, Torque, TorqueInput};
pub use periodic::{
    correct_across_family, correct_bordered, correct_planar_attitudes, verify_planar_attitudes, Bordered, Candidate, Closure, Correction, CorrectorOptions, Free, Parameter,
    PlanarEnd, PlanarFamily,
    PlanarStart, StopReason, full_closure_residual,
};
pub use refine::{distinct, refine_planar_attitudes, PlanarOrbit, Refined, SolutionKey, MAX_VERIFIED_RESIDUAL, SAME_SOLUTION};
pub(crate) use periodic3d::{conj, lmat, rmat};
pub use periodic3d::{qexp, qlog, qmul, attitude_residual, correct_attitudes_3d, correct_attitudes_3d_across, Correction3d, CorrectionAcross3d, Options3d, Start3d, StartAcross3d};
