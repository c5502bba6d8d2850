//! Flexible spacecraft (thesis ch. 5, docs/physics.md, flexible spacecraft): a planar lumped-parameter model,
//! coupled attitude-structure dynamics along a CR3BP orbit, and the quasi-static closed form
//! for high structural frequencies.
//!
//! # Model
//!
//! Symbols (all in the body frame B unless said otherwise; 2-D vectors in the orbit plane):
//!
//! | symbol | meaning |
//! |---|---|
//! | m0, (Ix0, Iy0, Iz0 = J0) | hub mass and principal moments about its own centre, axes along B |
//! | m_j, j = 1..n | appendage masses |
//! | b_j | rest position of m_j, measured from the undeformed system's centre of mass |
//! | t_j | unit deflection direction of m_j, normal to b_j (t_j . b_j = 0) |
//! | q_j | deflection of m_j along t_j; k_j spring, c_j >= 0 damper, Omega_j = sqrt(k_j/m_j) |
//! | h = -sum_j m_j b_j / m0 | hub centre (so that sum_k m_k p_k = 0 when q = 0) |
//! | M = m0 + sum_j m_j | total mass |
//! | phi | angle from the synodic X axis to the body x axis; the synodic frame turns at rate 1 |
//! | wz = phidot + 1 | inertial rate of B |
//! | a x b = a_x b_y - a_y b_x | 2-D cross product (a scalar); J r = e_z x r |
//! | a_j = b_j x t_j | signed lever arm of the deflection (= +-|b_j|) |
//!
//! Positions of the mass points in B, from the undeformed centre of mass: p_0 = h (hub),
//! p_j = b_j + q_j t_j. The deflections move the system's centre of mass to
//! c(q) = sum_j m_j q_j t_j / M; it is the centre of mass, not the point b_j are measured from,
//! that follows the orbit R(t) (one-way coupling, like the rigid model: the orbit is integrated
//! alongside or held). Everything below is written with positions relative to the *instantaneous*
//! centre of mass, rho_k = p_k - c, so sum_k m_k rho_k = 0 exactly: the CM shift is kept
//! exactly, no approximation (its effect is O(q^2) in the inertia and O(q) in the loads).
//!
//! **Kinetic energy** (König): T = M |Rdot|^2 / 2 + T_rel, the first term independent of the
//! attitude and deflections. With v_k = wz J rho_k + rhodot_k, rhodot_j = qdot_j t_j - cdot,
//! rhodot_0 = -cdot:
//!
//!   2 T_rel = J0 wz^2 + sum_k m_k |v_k|^2 = I(q) wz^2 + 2 wz gamma(q) . qdot + qdot^T M_qq qdot,
//!
//!   I(q) = J0 + sum_k m_k |rho_k|^2 = I0 + q^T M_qq q     (I0 the composite inertia, q = 0),
//!   gamma_j(q) = m_j rho_j x t_j = m_j a_j + (m_j / M) sum_l m_l (t_j x t_l) q_l,
//!   M_qq(j, l) = m_j delta_jl - m_j m_l (t_j . t_l) / M     (constant, positive definite).
//!
//! **Tidal potential** (second-order gravity of both primaries about the centre of mass; the
//! first-order term vanishes because sum m_k rho_k = 0). Per unit mass at rho it is
//! -(1/2) sum_i mu_i / r_i^3 [3 (rhat_i . rho)^2 - |rho|^2] = -(1/2) rho^T T_B rho with the
//! in-plane tidal tensor
//!
//!   T_B = sum_i mu_i / r_i^3 (3 rhat_i rhat_i^T - I_2) = (P / 2) I_2 + (3/2) [[Cb, Sb], [Sb, -Cb]],
//!   P = sum_i mu_i / r_i^3,   Cb + i Sb = w = W e^{-2 i phi},   W = C + i S = sum_i mu_i zeta_i^2 / r_i^5,
//!
//! (zeta_i = x_i + i y_i the position relative to primary i in the synodic frame; C, S those of
//! the planar model, docs/physics.md: attitude; so Cb, Sb are the same sums with theta_i replaced by theta_i - phi). The hub
//! adds its own second moments, -(3/4)(Iy0 - Ix0) Cb - (P/2)(Iz0 - (Ix0 + Iy0)/2):
//!
//!   V_tidal = -(1/2) sum_k m_k rho_k^T T_B rho_k - (3/4)(Iy0 - Ix0) Cb - (P/2)(Iz0 - (Ix0 + Iy0)/2).
//!
//! **Elastic potential and dissipation**: V_el = sum_j k_j q_j^2 / 2, D = sum_j c_j qdot_j^2 / 2.
//!
//! **Lagrange's equations** for L = T_rel - V_tidal - V_el in the coordinates (phi, q)
//! (dL/dphidot = dL/dwz; V_tidal depends on phi through w and on t through the orbit):
//!
//!   d/dt (I wz + gamma . qdot) = tau,
//!   d/dt (wz gamma + M_qq qdot) - dT_rel/dq + dV_tidal/dq + K q + C qdot = 0,
//!
//! (K = diag(k_j), C = diag(c_j); the second line from dD/dqdot = C qdot),
//! where tau = -dV_tidal/dphi = sum_k m_k rho_k x (T_B rho_k) + (3/2)(Iy0 - Ix0) Sb
//!          = (3/2) Im(conj(Z(q)) w),   Z(q) = (Iy0 - Ix0) + sum_k m_k rho_k^2 (rho_k as complex
//!            numbers x + i y; Z0 = Z(0), |Z0| = Iy - Ix of the composite principal axes) is
//! the tidal torque on the deformed body. Expanding (gammadot . qdot = 0 because t_j x t_l is antisymmetric):
//!
//!   I(q) wzdot + gamma(q) . qddot = tau - Idot wz,           Idot = 2 sum_j m_j qdot_j (t_j . rho_j),
//!   gamma_j wzdot + (M_qq qddot)_j = F_j,
//!   F_j = m_j t_j . (T_B rho_j)          (tidal load, incl. the CM shift: the -m_j t_j . T_B c part)
//!       + m_j wz^2 (t_j . rho_j)         (centrifugal; q_j - t_j . c since t_j . b_j = 0)
//!       + 2 wz m_j (cdot x t_j)          (Coriolis of the moving centre of mass)
//!       - k_j q_j - c_j qdot_j.
//!
//! Every term is a Newtonian force seen in B about the centre of mass (tidal, centrifugal,
//! Coriolis, Euler = -gamma_j wzdot): the Lagrangian derivation and the force balance agree.
//! The (n + 1) x (n + 1) symmetric positive-definite system is solved in O(n) at every
//! right-hand-side call with the Schur complement on wzdot and the Woodbury form
//! (M_qq^{-1} x)_j = x_j / m_j + t_j . [(M I_2 - sum_l m_l t_l t_l^T)^{-1} sum_l t_l x_l]:
//!
//!   wzdot = (tau - Idot wz - gamma . M_qq^{-1} F) / (I - gamma . M_qq^{-1} gamma),
//!   qddot = M_qq^{-1} (F - gamma wzdot),   phidot = wz - 1.
//!
//! State: (x, y, z, xd, yd, zd, phi, wz, q_1..q_n, qdot_1..qdot_n); the attitude-structure part
//! has dimension 2 + 2n.
//!
//! **Rigid limit**: with q = 0 the equation reduces to I0 wzdot = (3/2) Im(conj(Z0) w), the
//! planar rigid model of docs/physics.md, attitude with Kz = |Z0| / I0 for the principal x axis at
//! arg(Z0) / 2 from the body x axis. As k_j -> infinity the deflections are quasi-static,
//! q_j = O(1/k_j), and the attitude differs from the rigid composite one by O(1/k).
//!
//! **Energy integral**: on a circular orbit of mean motion n about one primary (the other one
//! off), V_tidal depends on the body angle relative to the local vertical only, so the
//! Lagrangian is autonomous in the frame turning with the orbit (psi = body angle - n t) and
//! its Jacobi integral is E_J = T_rel + V_el + V_tidal - n h_z (h_z = I wz + gamma . qdot the
//! inertial angular momentum about the centre of mass), with dE_J/dt = -sum_j c_j qdot_j^2.
//!
//! **Units**: time in TU (the rates are those of the CR3BP), any mass and length unit (the
//! attitude equation is homogeneous in mass and length; q is in the length unit of b_j): the
//! stiffness is then in mass / TU^2 and the damping in mass / TU. The Python API takes SI (kg, m,
//! N/m, N s/m) and converts with the system's TU: k TU^2, c TU.
//!
//! # Extension to complex cases (3-D and continuous structures)
//!
//! - 3-D: replace phi by the quaternion and wz by the body rate w (3); t_j become 3-D unit vectors
//!   normal to b_j (two per mass for two bending directions). The same Lagrangian gives
//!   [[I(q), Gamma^T], [Gamma, M_qq]] [wdot; qddot] = [tau - Idot w - Gammadot^T qdot - w x (I w + Gamma^T qdot); F]
//!   (Gammadot^T qdot vanishes in the plane but not in 3-D)
//!   with I(q) = J0 + sum_k m_k (|rho_k|^2 I_3 - rho_k rho_k^T), Gamma_j = m_j rho_j x t_j
//!   (3-vectors), tau = sum_k m_k rho_k x T rho_k + the hub's 3 mu / r^5 (r x I0 r),
//!   T = sum_i mu_i / r_i^3 (3 rhat_i rhat_i^T - I_3), and
//!   F_j = m_j t_j . [T rho_j + |w|^2 rho_j - (w . rho_j) w + 2 rhodot_j x w] - k_j q_j - c_j qdot_j
//!   (tidal, centrifugal, Coriolis; the Euler force is in the Gamma wdot coupling). M_qq keeps its form with t_j . t_l. The quaternion kinematics and the
//!   orbit follow [`crate::attitude`]'s 3-D model unchanged.
//! - Several modes per appendage or a finite-element model: q becomes a vector of modal
//!   coordinates with mode shapes Phi(x); m_j t_j is replaced by the modal momentum coefficients
//!   int Phi dm, gamma_j by the modal angular-momentum coefficients int rho x Phi dm, M_qq by the
//!   modal mass matrix, k_j by m Omega^2 per mode, and the tidal load by int Phi . T rho dm.
//!   The structure of the equations (and the O(n) solve when M_qq is diagonal plus low rank) is
//!   unchanged.
//! - Two-way coupling: the deflection-dependent second moments change the extended-body orbital
//!   acceleration (thesis eq. 37) at O(q / |b|) of a term already ~1e-13 of the point-mass one.
//!
//! # High structural frequencies
//!
//! See [`quasi_static`]: q_j = L_j / k_j along the rigid solution with L_j the transverse load, its
//! derivatives in closed form, the first-order torque perturbation and attitude perturbation.

pub mod body;
pub mod dynamics;
pub mod periodic;
pub mod propagate;
pub mod quasi_static;

pub use body::{Appendage, FlexibleBody, GEOMETRY_TOL};
pub use periodic::{correct_flexible_periodic, FlexiblePeriodic};
pub use dynamics::{tidal_field, tidal_field_derivatives, BodyField, Energies, FlexibleAlongOrbit};
pub use propagate::{evaluate_energies, flexible_rates, propagate_flexible, propagate_quasi_static, quasi_static_point, FlexibleTrajectory, QuasiStaticTrajectory};
pub use quasi_static::{QuasiStaticAlongOrbit, QuasiStaticPoint};
