"""Periodic 3-D attitude motions along any periodic orbit (issue 15), and the out-of-plane
stability of the planar ones.

- :func:`periodic_attitude_3d`: one motion from a guess. The full-period form is the default;
  ``symmetric=True`` uses the mirror-symmetric half-period form.
- :func:`out_of_plane_stability` and :func:`out_of_plane_family`: the roll/yaw multipliers of a
  planar solution, or across a planar family (thesis Figs. 27-29).
- :func:`attitude_family_3d` and :func:`attitude_family_3d_inertia`: motions continued along an
  orbit family (in the period) or in the inertia, on the shared continuation driver.

The equations and checks are derived in docs/physics/periodic-attitude-3d.md.

A 3-D motion (q0, w0) along an orbit of period T is periodic over K = ``n_periods`` revolutions
when the attitude relative to the synodic frame repeats, R(KT) = R(0) (q and -q are one
attitude), and the inertial rate repeats, w(KT) = w0. The Rust corrector
(``rust/core/src/periodic/attitude3d.rs``) solves these six equations by Newton's method on the
one batched driver of the attitude correctors. Its unknowns are a rotation in body axes (a chart
about the guess) and w0. The Jacobian is exact, from the coupled model's 13x13 STM. The 6x6
attitude monodromy is the STM in the coordinates (small body-axis rotation, rate change).

Conventions are those of :func:`librate.propagate_attitude`:

- ``q0`` is scalar-last, the body relative to the synodic frame;
- ``w0`` is the inertial angular velocity in body axes, rad/TU;
- the gravity gradient acts from both primaries, with the orbit integrated alongside.

Every planar periodic motion (:class:`~librate.AttitudeSolution`) is a 3-D one, with the body
z axis on the synodic Z axis. Its monodromy then splits into the in-plane pair, about Z, which
equals the planar 2x2 monodromy, and the out-of-plane roll/yaw block, about X and Y.
:func:`out_of_plane_stability` reports that block's multipliers for planar solutions. A motion
that is stable in the plane can be unstable out of it.
"""

from __future__ import annotations

from .attitude_families_3d import (
    FamilyMember3D,
    InertiaBranch3D,
    OrbitFamilyBranch3D,
    attitude_family_3d,
    attitude_family_3d_inertia,
    floquet_tests,
    rotvec_jacobian,
)
from .periodic_attitude3d import (
    SOLVE_RTOL,
    STABILITY_TOL,
    VERIFY_RTOL,
    AttitudeSolution3D,
    is_mirror_symmetric,
    out_of_plane_family,
    out_of_plane_stability,
    periodic_attitude_3d,
    verified_solution_3d,
)

__all__ = ["AttitudeSolution3D", "periodic_attitude_3d", "is_mirror_symmetric", "out_of_plane_stability",
           "out_of_plane_family", "attitude_family_3d",
           "attitude_family_3d_inertia", "OrbitFamilyBranch3D", "FamilyMember3D", "rotvec_jacobian", "InertiaBranch3D", "STABILITY_TOL",
           "VERIFY_RTOL", "floquet_tests",
           "SOLVE_RTOL", "verified_solution_3d"]
