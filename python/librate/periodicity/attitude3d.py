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

import math
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._checks import as_count, as_tolerance
from .._display import fmt, html_summary, short_repr
from .._errors import ConvergenceError
from .._progress import as_progress
from ..attitude.body import RigidBody
from ..attitude.propagate import propagate_attitude
from ..orbits.periodic import PeriodicOrbit
from .solutions import AttitudeSolution

__all__ = ["AttitudeSolution3D", "periodic_attitude_3d", "is_mirror_symmetric", "out_of_plane_stability", "out_of_plane_family", "attitude_family_3d",
           "attitude_family_3d_inertia", "OrbitFamilyBranch3D", "FamilyMember3D", "rotvec_jacobian", "InertiaBranch3D", "STABILITY_TOL", "VERIFY_RTOL", "floquet_tests",
           "SOLVE_RTOL", "verified_solution_3d"]

#: A multiplier lies on the unit circle when ||m| - 1| <= STABILITY_TOL. The monodromy is
#: accurate to about 1e-10, and a Krein collision spreads that to its square root.
STABILITY_TOL = 1e-6
#: Integration tolerances of the corrector's trajectories and of the independent
#: re-propagation.
SOLVE_RTOL = 1e-13
VERIFY_RTOL = 1e-14
_IN_PLANE = [2, 5]  # rotation about body z, rate wz
_OUT_OF_PLANE = [0, 1, 3, 4]


def _rotvec(q_from, q_to) -> np.ndarray:
    """Rotation vector of R(q_from)' R(q_to), in body axes of q_from (scipy, independent of the
    corrector's own Log)."""
    from scipy.spatial.transform import Rotation

    return (Rotation.from_quat(q_from).inv() * Rotation.from_quat(q_to)).as_rotvec()


@dataclass(frozen=True)
class AttitudeSolution3D:
    """A periodic 3-D attitude motion along ``orbit`` over K = ``n_periods`` orbit periods.

    Fields:

    - ``q0``: scalar last, the body relative to the synodic frame.
    - ``w0``: the inertial rate in body axes (rad/TU).
    - ``monodromy``: the 6x6 d(theta, w)(KT)/d(theta, w)(0) (theta a small rotation in body axes).
    - ``multipliers``: its six eigenvalues.
    - ``stable``: every multiplier on the unit circle to :data:`STABILITY_TOL`.
    - ``residual``: max(|rotation vector of R(0)' R(KT)|, |w(KT) - w0|), from an independent
      re-propagation. It uses the scalar 3-D model without STM, rtol = atol = 1e-14, and scipy's
      rotation algebra rather than the corrector's; the components are in ``residual_rotation``
      and ``residual_rate``.
    - ``turns``: net turns of the body x axis about the synodic Z axis over the K periods (its
      projection on the synodic XY plane, unwrapped). None where that projection passes within
      1e-3 of zero, because the count is then undefined.
    - ``planar``: True for a motion in the plane (planar orbit, q0 a rotation about Z and w0
      along z, to 1e-10). For those, ``in_plane_multipliers`` are from the (theta_z, w_z) block
      and ``out_of_plane_multipliers`` from the roll/yaw block (theta_x, theta_y, w_x, w_y);
      otherwise both are None.
    """

    orbit: PeriodicOrbit
    body: RigidBody
    n_periods: int
    q0: np.ndarray
    w0: np.ndarray
    monodromy: np.ndarray = field(repr=False)
    residual_rotation: float = math.nan
    residual_rate: float = math.nan
    turns: float | None = None
    iterations: int = 0

    # --- display (librate._display): the orbit and body by their key numbers ------------------
    def _rows(self):
        return [("n_periods", self.n_periods, ""), ("turns", self.turns, ""), ("planar", self.planar, ""), ("stable", self.stable, ""),
                ("residual", self.residual, "")]

    def __repr__(self) -> str:
        return short_repr("AttitudeSolution3D", self._rows() + [("orbit_period_days", self.orbit.period_days, "d")])

    def _repr_html_(self) -> str:
        b = self.body
        details = {"initial attitude": [("q0", self.q0, "scalar last"), ("w0", self.w0, "rad/TU")],
                   "stability": [("multipliers", self.multipliers, ""), ("|multipliers|", np.abs(self.multipliers), ""),
                                 ("monodromy", self.monodromy, "")],
                   "correction": [("residual_rotation", self.residual_rotation, "rad"), ("residual_rate", self.residual_rate, "rad/TU"),
                                  ("iterations", self.iterations, "")],
                   "orbit and body": [("orbit", repr(self.orbit), ""), ("body", f"{type(b).__name__}(ix={fmt(b.ix)}, iy={fmt(b.iy)}, iz={fmt(b.iz)})", "")]}
        title = f"librate.AttitudeSolution3D over {self.n_periods} period(s) ({'stable' if self.stable else 'unstable'})"
        return html_summary(title, self._rows(), details)


    @property
    def residual(self) -> float:
        return max(self.residual_rotation, self.residual_rate)

    @property
    def multipliers(self) -> np.ndarray:
        return np.linalg.eigvals(self.monodromy)

    @property
    def stable(self) -> bool:
        return bool(np.all(np.abs(np.abs(self.multipliers) - 1.0) <= STABILITY_TOL))

    @property
    def planar(self) -> bool:
        s = np.asarray(self.orbit.state0)
        return bool(abs(s[2]) == 0 and abs(s[5]) == 0 and np.all(np.abs(self.q0[:2]) <= 1e-10) and np.all(np.abs(self.w0[:2]) <= 1e-10))

    @property
    def in_plane_multipliers(self) -> np.ndarray | None:
        return np.linalg.eigvals(self.monodromy[np.ix_(_IN_PLANE, _IN_PLANE)]) if self.planar else None

    @property
    def out_of_plane_multipliers(self) -> np.ndarray | None:
        return np.linalg.eigvals(self.monodromy[np.ix_(_OUT_OF_PLANE, _OUT_OF_PLANE)]) if self.planar else None

    @property
    def phi0(self) -> float:
        """The angle about Z of the body x axis from the synodic X axis at t = 0 (rad)."""
        from scipy.spatial.transform import Rotation

        x = Rotation.from_quat(self.q0).as_matrix()[:, 0]
        return float(math.atan2(x[1], x[0]))

    def propagate(self, n_periods: float | None = None, **kwargs):
        """The motion over ``n_periods`` orbits (default its own K) with the 3-D model."""
        kwargs.setdefault("rtol", 1e-13)
        kwargs.setdefault("atol", 1e-13)
        k = self.n_periods if n_periods is None else n_periods
        return propagate_attitude(self.orbit.system, self.orbit.state0, (self.q0, self.w0), self.body, k * self.orbit.period, **kwargs)


def _guess(guess, n_periods: int) -> tuple[np.ndarray, np.ndarray]:
    if isinstance(guess, AttitudeSolution):
        if guess.srp is not None:
            raise ValueError("invalid argument `guess`: a planar solution with solar radiation pressure; the 3-D corrector has the gravity gradient only")
        if guess.n_periods != n_periods:
            raise ValueError(f"invalid argument `n_periods`: the planar guess closes over {guess.n_periods} periods, got n_periods = {n_periods}")
        if guess.kind != "periodic":
            # a half turn about z is a different attitude (R(T) = R(0) Rz(pi)): not a 3-D periodic motion
            raise ValueError("invalid argument `guess`: a half-turn planar solution repeats the attitude only up to a half turn; pass a periodic one")
        h = 0.5 * guess.phi0
        return np.array([0.0, 0.0, math.sin(h), math.cos(h)]), np.array([0.0, 0.0, guess.wz0])
    try:
        q, w = guess
        q = np.asarray(q, dtype=np.float64).ravel()
        w = np.asarray(w, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        raise ValueError(f"invalid argument `guess`: must be a librate.AttitudeSolution or (q0, w0), got {guess!r}") from None
    if q.shape != (4,) or w.shape != (3,) or not (np.all(np.isfinite(q)) and np.all(np.isfinite(w))):
        raise ValueError(f"invalid argument `guess`: (q0, w0) must be 4 and 3 finite numbers, got shapes {q.shape}, {w.shape}")
    n = float(np.linalg.norm(q))
    if abs(n - 1) > 1e-6:
        raise ValueError(f"invalid argument `guess`: q0 must be a unit quaternion (scalar last), |q0| = {n}")
    return q / n, w


def _turns(q: np.ndarray) -> float | None:
    from scipy.spatial.transform import Rotation

    x = Rotation.from_quat(q).as_matrix()[:, :, 0]  # body x axis in synodic components
    rho = np.hypot(x[:, 0], x[:, 1])
    if rho.min() < 1e-3:
        return None
    ang = np.unwrap(np.arctan2(x[:, 1], x[:, 0]))
    return float((ang[-1] - ang[0]) / (2 * math.pi))


def is_mirror_symmetric(orbit: PeriodicOrbit, q0, w0) -> bool:
    """Whether the half-period symmetric form applies. The orbit must start on the x-z plane
    perpendicularly (y = xdot = zdot = 0), and the attitude must be mirror symmetric: body y on
    synodic +-Y and w_y = 0, to 1e-12."""
    from scipy.spatial.transform import Rotation

    s = np.asarray(orbit.state0)
    a = Rotation.from_quat(q0).as_matrix().T
    return bool(s[1] == 0 and s[3] == 0 and s[5] == 0 and abs(a[1, 0]) <= 1e-12 and abs(a[1, 2]) <= 1e-12 and abs(w0[1]) <= 1e-12)


def periodic_attitude_3d(orbit: PeriodicOrbit, body: RigidBody, *, guess, n_periods: int = 1, tol: float = 1e-12,
                         max_iter: int = 40, symmetric: bool = False) -> AttitudeSolution3D:
    """The periodic 3-D attitude motion of ``body`` along ``orbit`` (planar or spatial) over
    ``n_periods`` revolutions, corrected from ``guess``.

    ``guess`` is either a planar :class:`~librate.AttitudeSolution` (its phi0 about Z and wz0)
    or a pair ``(q0, w0)`` (scalar-last quaternion, inertial rate in body axes). The corrector
    stops when the residual max-norm is <= ``tol``. The solution is then re-propagated
    independently, at a tighter tolerance, and ``residual`` reports that check. Raises
    :class:`librate.ConvergenceError` when the corrector stops without converging.

    ``symmetric`` selects the formulation. True uses the half-period form: the orbit and the
    guess must be mirror symmetric (:func:`is_mirror_symmetric`), and the solution then is
    too, with three unknowns and three equations at KT/2. It is cheaper, but from a poor guess
    its Newton basin can be smaller than the full form's. False (the default) uses the full
    period, with six unknowns. The monodromy is always the full-period one.
    """
    if not isinstance(orbit, PeriodicOrbit):
        raise ValueError(f"invalid argument `orbit`: must be a librate.PeriodicOrbit, got {type(orbit).__name__}")
    if not isinstance(body, RigidBody) or body.is_rod or type(body) is not RigidBody:
        raise ValueError(f"invalid argument `body`: must be a librate.RigidBody with every principal moment > 0, got {body!r}")
    n_periods = as_count(n_periods, "n_periods", 1)
    tol = as_tolerance(tol, "tol")
    max_iter = as_count(max_iter, "max_iter", 1)
    q, w = _guess(guess, n_periods)
    if not isinstance(symmetric, (bool, np.bool_)):
        raise ValueError(f"invalid argument `symmetric`: must be True or False, got {symmetric!r}")
    half = bool(symmetric)
    if half and not is_mirror_symmetric(orbit, q, w):
        raise ValueError("invalid argument `symmetric`: the half-period form needs an orbit started on the x-z plane perpendicularly and a "
                         "mirror-symmetric guess (body y on synodic +-Y, w_y = 0)")
    if half:
        w = w.copy()
        w[1] = 0.0  # symmetric to 1e-12: exactly so
    T = n_periods * float(orbit.period)
    r = _core.attitude_correct_3d(orbit.system.mu, list(body.moments), [float(v) for v in orbit.state0], T, q[None, :], w[None, :],
                                  tol=float(tol), max_iter=int(max_iter), rtol=SOLVE_RTOL, atol=SOLVE_RTOL, half=half)
    if r.reason[0] != "converged":
        raise ConvergenceError(f"periodic 3-D attitude: the corrector stopped ({r.reason[0].replace('_', ' ')}) after {int(r.iterations[0])} "
                               f"Newton steps, residual {float(r.residual_norm[0]):.3e} (tolerance {tol:.1e})")
    return verified_solution_3d(orbit, body, n_periods, r.q0[0], r.w0[0], r.monodromy[0], int(r.iterations[0]))


def verified_solution_3d(orbit: PeriodicOrbit, body: RigidBody, n_periods: int, q0, w0, monodromy, iterations: int = 0) -> AttitudeSolution3D:
    """A corrected motion (q0, w0) with the corrector's ``monodromy``, re-propagated
    independently with the scalar 3-D model at rtol = atol = :data:`VERIFY_RTOL` (its residual
    and turns), as an :class:`AttitudeSolution3D`."""
    q0, w0 = np.array(q0, dtype=float), np.array(w0, dtype=float)
    T = n_periods * float(orbit.period)
    t = np.linspace(0.0, T, 512 * n_periods + 1)
    tr = propagate_attitude(orbit.system, orbit.state0, (q0, w0), body, T, t_eval=t, rtol=VERIFY_RTOL, atol=VERIFY_RTOL)
    d_rot = float(np.linalg.norm(_rotvec(q0, tr.q[-1])))
    d_w = float(np.linalg.norm(tr.w[-1] - w0))
    return AttitudeSolution3D(orbit, body, n_periods, q0, w0, np.asarray(monodromy), d_rot, d_w, _turns(tr.q), int(iterations))


def out_of_plane_stability(solution: AttitudeSolution) -> AttitudeSolution3D:
    """The planar ``solution`` as a 3-D motion (body z on synodic Z, the body of its Kz,
    Ix + Iy = Iz), with its roll/yaw multipliers next to the in-plane pair
    (:attr:`AttitudeSolution3D.out_of_plane_multipliers`)."""
    if not isinstance(solution, AttitudeSolution):
        raise ValueError(f"invalid argument `solution`: must be a librate.AttitudeSolution, got {type(solution).__name__}")
    if abs(solution.kz) >= 1:
        raise ValueError(f"invalid argument `solution`: Kz = {solution.kz:g} is a thin rod, which has no 3-D attitude dynamics")
    return periodic_attitude_3d(solution.orbit, RigidBody.from_kz(solution.kz), guess=solution, n_periods=solution.n_periods)


def out_of_plane_family(orbits, family, *, body: RigidBody | None = None, every: int = 1):
    """The 3-D stability of a planar attitude family across an orbit family (thesis Figs. 27-29).

    ``family`` is an :class:`~librate.AttitudeFamily` continued in x0 across the planar orbit
    family ``orbits`` (:func:`librate.attitude_family`). Every ``every``-th member is taken as a
    3-D motion of ``body`` and corrected and verified by :func:`periodic_attitude_3d`, starting
    from its planar (phi0 = 0, wz0). The out-of-plane stability depends on all three moments, not
    only on Kz. The default body is the plate of the family's Kz, :meth:`RigidBody.from_kz`
    (Ix + Iy = Iz).

    Returns an xarray Dataset along ``member`` with:

    - ``x0``, ``period_days``, ``wz0``, ``phidot0``;
    - the planar ``trace`` and ``stable_in_plane``;
    - ``in_plane`` multipliers (member, pair) and ``out_of_plane`` multipliers (member, k = 4),
      both complex;
    - ``out_of_plane_modulus``, the largest |multiplier| of the roll/yaw block;
    - ``stable_out_of_plane`` and ``stable_3d``, all six multipliers on the unit circle to
      :data:`STABILITY_TOL`;
    - ``residual``, from the independent re-propagation.

    Attributes: kz, n, kind, the body's moments.
    """
    import xarray as xr

    from ..orbits.families import OrbitFamily
    from .attitude_families import AttitudeFamily

    if not isinstance(orbits, OrbitFamily):
        raise ValueError(f"invalid argument `orbits`: must be a librate.OrbitFamily, got {type(orbits).__name__}")
    if not isinstance(family, AttitudeFamily) or family.parameter_name != "x0":
        raise ValueError("invalid argument `family`: must be a librate.AttitudeFamily continued in x0 (attitude_family(orbit_family, ...))")
    if family.kind != "periodic":
        raise ValueError("invalid argument `family`: half-turn motions repeat the attitude only up to a half turn; pass a periodic family")
    every = as_count(every, "every", 1)
    kz = float(family.kz)
    if body is None:
        if abs(kz) >= 1:
            raise ValueError(f"invalid argument `body`: Kz = {kz:g} is a thin rod; pass a 3-D body")
        body = RigidBody.from_kz(kz)
    elif not isinstance(body, RigidBody) or abs(body.kz - kz) > 1e-9:
        raise ValueError(f"invalid argument `body`: must be a librate.RigidBody with the family's Kz = {kz:g}, got {body!r}")
    idx = np.arange(0, len(family), every)
    rows = []
    for i in idx:
        orbit = orbits.member(x0=float(family.parameter[i]))
        s = periodic_attitude_3d(orbit, body, guess=([0.0, 0.0, 0.0, 1.0], [0.0, 0.0, float(family.wz0[i])]))
        rows.append((orbit, s))
    inp = np.array([np.sort_complex(s.in_plane_multipliers) for _, s in rows]).reshape(len(rows), 2)
    out = np.array([np.sort_complex(s.out_of_plane_multipliers) for _, s in rows]).reshape(len(rows), 4)
    on_circle = lambda m: np.all(np.abs(np.abs(m) - 1) <= STABILITY_TOL, axis=-1)  # noqa: E731
    dim = ("member",)
    return xr.Dataset(
        {"x0": (dim, family.parameter[idx]), "period_days": (dim, np.array([o.period_days for o, _ in rows])),
         "wz0": (dim, np.array([s.w0[2] for _, s in rows]), {"units": "1/TU", "long_name": "inertial rate"}),
         "phidot0": (dim, np.array([s.w0[2] - 1 for _, s in rows]), {"units": "1/TU"}),
         "trace": (dim, family.trace[idx], {"long_name": "trace of the planar 2x2 monodromy"}),
         "stable_in_plane": (dim, on_circle(inp)),
         "in_plane": (("member", "pair"), inp),
         "out_of_plane": (("member", "k"), out),
         "out_of_plane_modulus": (dim, np.abs(out).max(axis=1)),
         "stable_out_of_plane": (dim, on_circle(out)),
         "stable_3d": (dim, np.array([s.stable for _, s in rows])),
         "residual": (dim, np.array([s.residual for _, s in rows]))},
        attrs={"kz": kz, "n": int(family.n), "kind": family.kind, "body_moments": list(body.moments), "stability_tol": STABILITY_TOL,
               "system": orbits.system.name})


def rotvec_jacobian(r) -> np.ndarray:
    """d rotvec(R(r) Exp(theta)) / d theta at theta = 0 (theta a small rotation in body axes):
    the inverse right Jacobian of SO(3), I + [r]/2 + (1/|r|^2 - (1 + cos|r|)/(2 |r| sin|r|)) [r]^2,
    with [r] the cross-product matrix (series below |r| = 1e-4)."""
    r = np.asarray(r, dtype=float)
    a = float(np.linalg.norm(r))
    k = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
    c = 1.0 / 12.0 + a * a / 720.0 if a < 1e-4 else 1.0 / (a * a) - (1.0 + math.cos(a)) / (2.0 * a * math.sin(a))
    return np.eye(3) + 0.5 * k + c * (k @ k)


@dataclass(frozen=True)
class FamilyMember3D:
    """A point of :class:`OrbitFamilyBranch3D`: the verified ``solution`` and d F / d T of its six
    closure residuals (``dparam``, exact, from the bordered corrector)."""

    solution: AttitudeSolution3D
    dparam: np.ndarray = field(repr=False)


class OrbitFamilyBranch3D:
    """A periodic 3-D attitude motion continued along a family of x-z-symmetric periodic orbits
    (DROs, planar Lyapunov orbits, halos, NRHOs), a bordered problem for the continuation driver
    (:func:`librate.solving.continuation.arclength`, or ``natural``). The vector is x = (orbit
    period in days, the rotation vector of q0, w0).

    Every point is corrected by the Rust bordered corrector
    (:func:`librate._core.attitude_correct_3d_across`): the unknowns are a rotation theta in body
    axes in a chart about the guess's attitude, w0 and the orbit period T, closed by the driver's
    linear condition a . x = b. That condition is taken to the chart linearised:
    rotvec(q_ref Exp(theta)) ~ rotvec(q_ref) + J theta (:func:`rotvec_jacobian`), exact at the
    guess (natural continuation fixes only the period, so there it is exact everywhere). Each
    Newton point's orbit is the family member of its period, corrected in Rust to 1e-12, so the
    solution's orbit is the member at the final period. The tangent is the null vector of the
    family's Jacobian [M - I, dF/dT] in the solution's body-axis chart (M the monodromy), mapped
    to x. The bifurcation tests are :func:`floquet_tests`."""

    parameter_index = 0
    scale = np.ones(7)

    def __init__(self, orbits, body: RigidBody, n_periods: int = 1, tol: float = 1e-12, max_iter: int = 40):
        self.orbits, self.body, self.n_periods, self.tol, self.max_iter = orbits, body, n_periods, tol, max_iter
        self.days = float(orbits.system.period_days(1.0))

    def correct(self, guess, c):
        from scipy.spatial.transform import Rotation

        from ..solving.continuation import CorrectionFailed, Point

        guess = np.asarray(guess, dtype=float)
        try:
            ref = self.orbits.member(period_days=float(guess[0]))
        except (ValueError, ConvergenceError) as e:
            raise CorrectionFailed(str(e)) from None
        rv = guess[1:4]
        a = np.asarray(c.a, dtype=float)
        a_chart = np.concatenate([rotvec_jacobian(rv).T @ a[1:4], a[4:7], [a[0] * self.days]])
        b_chart = float(c.b) - float(a[1:4] @ rv)
        r = _core.attitude_correct_3d_across(self.orbits.system.mu, list(self.body.moments), [float(v) for v in ref.state0], float(ref.period),
                                             self.n_periods, Rotation.from_rotvec(rv).as_quat()[None, :], guess[None, 4:7],
                                             np.array([float(ref.period)]), a_chart[None, :], np.array([b_chart]), tol=float(self.tol),
                                             max_iter=int(self.max_iter), rtol=SOLVE_RTOL, atol=SOLVE_RTOL)
        if r.reason[0] != "converged":
            raise CorrectionFailed(f"3-D attitude across the orbit family: {r.reason[0].replace('_', ' ')} after {int(r.iterations[0])} steps, "
                                   f"residual {float(r.residual_norm[0]):.2e}")
        state0 = np.asarray(r.orbit0[0])
        orbit = PeriodicOrbit(self.orbits.system, state0, float(r.period[0]), float(self.orbits.system.jacobi(state0)), ref.family)
        s = verified_solution_3d(orbit, self.body, self.n_periods, np.asarray(r.q0[0]), np.asarray(r.w0[0]), np.asarray(r.monodromy[0]), int(r.iterations[0]))
        if not s.residual <= 1e-9:
            raise CorrectionFailed(f"re-propagation residual {s.residual:.2e} above 1e-9")
        x = np.concatenate([[orbit.period_days], Rotation.from_quat(s.q0).as_rotvec(), s.w0])
        if c.fixed_index == 0:
            x[0] = float(c.b)  # the member of exactly that period (its orbit corrected to 1e-12 TU)
        return Point(x, FamilyMember3D(s, np.asarray(r.dparam[0])), s.iterations)

    def tangent(self, point):
        from scipy.spatial.transform import Rotation

        m = point.data.solution.monodromy
        jac = np.hstack([m - np.eye(6), point.data.dparam[:, None]])  # (theta, w0, T) in the solution's chart
        if not np.all(np.isfinite(jac)):
            return None
        v = np.linalg.svd(jac)[2][-1]
        rv = Rotation.from_quat(point.data.solution.q0).as_rotvec()
        return np.concatenate([[v[6] * self.days], rotvec_jacobian(rv) @ v[:3], v[3:6]])

    def tests(self, point):
        return floquet_tests(point.data.solution.monodromy)


def attitude_family_3d(orbits, body: RigidBody, *, guess, period_days, n_periods: int = 1, tol: float = 1e-12, ds_min: float = 1e-4,
                       progress=None, method: str = "arclength", max_points: int = 400):
    """A periodic 3-D attitude motion of ``body`` continued along the orbit family ``orbits``
    (e.g. the L2 southern halos into the NRHOs) through the orbit periods ``period_days`` (days,
    in order) from ``guess`` ((q0, w0) or a planar solution) at the first period. ``tol``: the
    corrector's tolerance (NRHOs pass within a few thousand km of the Moon, where the tidal torque
    is some 1e4 times the Earth's at the Moon's distance; their attitude closure is reached to
    ~1e-11, so pass tol=1e-10 there). Every member is re-propagated independently to 1e-9.
    ``progress``: True for a bar on stderr, or ``progress(done, total)``, called with the number
    of requested periods reached so far.
    One period gives the one-member family of that orbit (no continuation).

    ``method``: "arclength" (the default) follows the family by pseudo-arclength continuation
    (:func:`librate.solving.continuation.arclength`, at most ``max_points`` points) on the
    bordered corrector (:class:`OrbitFamilyBranch3D`: the orbit period is an unknown, each Newton
    point on its own family member), through folds, until it leaves the requested periods' range;
    the members are the solutions corrected exactly at the requested periods each time the
    branch crosses one (after a fold a period can have two or more members, in branch order).
    "natural" steps in the period (:func:`librate.solving.continuation.natural`) and stops at a
    fold (the step collapses there).

    Returns an xarray Dataset along ``member`` (attribute ``parameter`` = "period_days"):

    - ``period_days``, ``x0``, ``z0``;
    - ``q0`` and ``w0``;
    - the six ``multipliers`` (complex), ``stable`` and ``residual`` (from the re-propagation);
    - ``turns``, NaN where it is undefined.

    Attributes:

    - ``stability_changes``: where a pair of multipliers passes +1 or -1 ("+1", "-1") or two
      pairs collide ("krein": on the unit circle, or two real pairs meeting off it), located by
      the continuation driver on the test functions :func:`floquet_tests` to 1e-8 in the
      parameter (``at``, ``located``), with the two members around it (``between``; the second None
      when natural continuation stalled past the last member; with arclength, where no two
      consecutive members bracket it, the two branch points around it and ``members`` False) and their
      counts of multipliers on the unit circle (``on_unit_circle``).
    - ``folds`` (arclength): the turning points of the family in the period, located to 1e-8
      (``period_days``, ``located``, the ``w0`` there).
    - ``unmarked_periods`` (arclength): requested periods the branch crossed where no member
      was kept (the correction there landed further from the interpolation between the two
      branch points than the driver's jump guard allows); normally empty.
    - ``end_reason``: why the continuation stopped.
    """

    from ..orbits.families import OrbitFamily
    from ..solving.continuation import Constraint, CorrectionFailed, StepRules, arclength, natural

    progress = as_progress(progress, "3-D attitude family", "member")
    if not isinstance(orbits, OrbitFamily):
        raise ValueError(f"invalid argument `orbits`: must be a librate.OrbitFamily, got {type(orbits).__name__}")
    if method not in ("arclength", "natural"):
        raise ValueError(f"invalid argument `method`: must be 'arclength' or 'natural', got {method!r}")
    targets = np.asarray(period_days, dtype=float).ravel()
    if targets.size < 1 or not np.all(np.isfinite(targets)):
        raise ValueError(f"invalid argument `period_days`: need at least one finite period, got {period_days!r}")
    n_periods = as_count(n_periods, "n_periods", 1)
    max_points = as_count(max_points, "max_points", 2)
    first_orbit = orbits.member(period_days=float(targets[0]))
    tol = as_tolerance(tol, "tol")
    s0 = periodic_attitude_3d(first_orbit, body, guess=guess, n_periods=n_periods, tol=tol)
    problem = OrbitFamilyBranch3D(orbits, body, n_periods, tol)
    from scipy.spatial.transform import Rotation

    x_first = np.concatenate([[float(targets[0])], Rotation.from_quat(s0.q0).as_rotvec(), s0.w0])
    try:
        first = problem.correct(x_first, Constraint.fix(7, 0, float(x_first[0])))
    except CorrectionFailed as e:
        raise ConvergenceError(f"3-D attitude family: the bordered corrector did not reproduce the first solution: {e}") from None
    report = None
    if progress is not None:
        progress(1, targets.size)
        reached = [1]
        sense = 1.0 if targets.size < 2 or targets[-1] >= targets[0] else -1.0

        def report(point):  # the driver's per-point hook: count the requested periods passed
            p = float(point.x[0])
            # a member counts as reached within the orbit correction's tolerance on its period
            while reached[0] < targets.size and (targets[reached[0]] - p) * sense <= 1e-9:
                reached[0] += 1
                progress(reached[0], targets.size)
            return None

    folds = []
    if targets.size == 1:
        br, members = None, [first]
    elif method == "natural":
        br = natural(problem, first, targets[1:], rules=StepRules(ds=abs(targets[1] - targets[0]), ds_min=ds_min), name="period_days", stop=report)
        members = [first] + br.points
    else:
        if not (np.all(np.diff(targets) > 0) or np.all(np.diff(targets) < 0)):
            raise ValueError("invalid argument `period_days`: method='arclength' needs strictly monotonic periods (the branch is followed "
                             "across their range); use method='natural' to visit them in any order")
        lo, hi = float(targets.min()), float(targets.max())
        # steps no longer than the closest requested spacing: each requested period is corrected from a
        # nearby interpolation between two branch points
        ds_max = max(ds_min, float(np.min(np.abs(np.diff(targets)))))
        rules = StepRules(ds=ds_max, ds_min=ds_min, ds_max=ds_max)
        direction = 1 if targets[1] >= targets[0] else -1
        br = arclength(problem, first, direction=direction, rules=rules, bounds=(lo, hi), marks=[float(t) for t in targets[1:]],
                       max_points=max_points, name="period_days", stop=report)
        members = [first] + list(br.marked)
        last = br.points[-1]
        on_target = np.any(np.abs(targets - last.x[0]) <= 1e-12)
        if len(br.points) > 1 and on_target and not any(m is last for m in members):
            members.append(last)  # the branch ended landing exactly on a requested period (a bound)
        folds = [{"period_days": float(f.parameter), "located": bool(f.located), "w0": [float(v) for v in f.point.x[4:7]]} for f in br.folds]
        # requested periods the branch crossed whose correction there was rejected (it left the
        # jump guard: landed too far from the interpolation between the two branch points)
        ps = [float(q.x[0]) for q in br.points]
        crossed = [float(t) for a, b in zip(ps, ps[1:]) for t in targets[1:] if (a - t) * (b - t) < 0 or (b == t and not a == t)]
        got = [float(m.x[0]) for m in members[1:]]
        attrs_unmarked = [t for t in dict.fromkeys(crossed) if crossed.count(t) > sum(abs(g - t) <= 1e-12 for g in got)]
        if br.end_reason.startswith("parameter range end") and abs(last.x[0] - targets[-1]) <= 1e-12:
            br.end_reason = f"completed: {br.end_reason}"  # crossed the whole range to the last requested period
    sols = [m.data.solution for m in members]
    dim = ("member",)
    extra = {"period_days": (dim, np.array([s.orbit.period_days for s in sols])), "x0": (dim, np.array([s.orbit.state0[0] for s in sols])),
             "z0": (dim, np.array([s.orbit.state0[2] for s in sols]))}
    attrs = {"body_moments": list(body.moments), "n_periods": n_periods, "system": orbits.system.name, "method": method}
    if method == "arclength" and br is not None:
        attrs["folds"] = repr(folds)
        attrs["unmarked_periods"] = repr(attrs_unmarked)
    path = [p.data.solution for p in br.points] if method == "arclength" and br is not None else None
    return _family_dataset(sols, "period_days", extra, br, attrs, bracketed=path)


def _family_dataset(sols, parameter: str, extra: dict, branch, attrs: dict, bracketed: list | None = None):
    """The Dataset of a 3-D family: ``extra`` variables (the parameter among them), the
    solutions' q0, w0, multipliers, stable, residual, turns, and the stability changes the
    continuation driver located (the zeros of :func:`floquet_tests`; attribute). ``branch``
    None: one member, no continuation."""
    import xarray as xr

    p = np.asarray(extra[parameter][1], dtype=float)
    mult = np.array([_sorted_multipliers(s.multipliers) for s in sols])
    on = np.abs(np.abs(mult) - 1) <= STABILITY_TOL
    changes = []
    for b in ([] if branch is None else branch.bifurcations):
        if bracketed:
            # the first two consecutive members around it (members are at requested values only);
            # else (e.g. between the last requested period and a fold) the two branch points
            i = next((k for k in range(len(p) - 1) if min(p[k], p[k + 1]) <= b.parameter <= max(p[k], p[k + 1])), None)
            if i is None:
                two = [bracketed[b.after], bracketed[b.after + 1]]
                n_on = [int(np.sum(np.abs(np.abs(t.multipliers) - 1) <= STABILITY_TOL)) for t in two]
                changes.append({"at": float(b.parameter), "located": bool(b.located), "kind": FLOQUET_TESTS[b.name],
                                "between": tuple(float(t.orbit.period_days) for t in two), "on_unit_circle": tuple(n_on), "members": False})
                continue
        else:
            i = b.after + 1  # the member before it (the first member is the start, not a returned point)
        # past the last member (natural continuation stalled after locating it): one side only
        j = i + 1 if i + 1 < len(p) else None
        changes.append({"at": float(b.parameter), "located": bool(b.located), "kind": FLOQUET_TESTS[b.name],
                        "between": (float(p[i]), None if j is None else float(p[j])),
                        "on_unit_circle": (int(on[i].sum()), None if j is None else int(on[j].sum()))})
    end_reason = "one member: no continuation" if branch is None else branch.end_reason
    dim = ("member",)
    return xr.Dataset(
        {**extra,
         "q0": (("member", "quaternion"), np.array([s.q0 for s in sols])), "w0": (("member", "axis"), np.array([s.w0 for s in sols])),
         "multipliers": (("member", "k"), mult), "stable": (dim, np.array([s.stable for s in sols])),
         "residual": (dim, np.array([s.residual for s in sols])),
         "turns": (dim, np.array([np.nan if s.turns is None else s.turns for s in sols]))},
        attrs={**attrs, "parameter": parameter, "end_reason": end_reason, "stability_changes": repr(changes)})


class InertiaBranch3D:
    """A periodic 3-D attitude motion along one orbit, continued in the inertia along the
    straight path between two bodies, I(s) = (1 - s) I_a + s I_b, s in [0, 1], for the
    continuation driver. The vector is x = (s, the rotation vector of q0, w0); the tangent is
    the driver's secant."""

    parameter_index = 0
    scale = np.ones(7)

    def __init__(self, orbit, bodies, n_periods: int = 1, tol: float = 1e-12):
        self.orbit, self.n_periods, self.tol = orbit, n_periods, tol
        self.ia, self.ib = (np.asarray(b.moments, dtype=float) for b in bodies)

    def body(self, s: float) -> RigidBody:
        return RigidBody(*((1 - s) * self.ia + s * self.ib))

    def correct(self, guess, c):
        from scipy.spatial.transform import Rotation

        from ..solving.continuation import CorrectionFailed, Point

        if not (c.a[0] == 1 and not np.any(c.a[1:])) or not (0 <= c.b <= 1):
            raise CorrectionFailed("the inertia path is continued in s in [0, 1] only (natural parameter)")
        q = Rotation.from_rotvec(np.asarray(guess[1:4], dtype=float)).as_quat()
        sol = periodic_attitude_3d(self.orbit, self.body(float(c.b)), guess=(q, np.asarray(guess[4:7], dtype=float)), n_periods=self.n_periods,
                                   tol=self.tol)
        if not sol.residual <= 1e-9:
            raise CorrectionFailed(f"re-propagation residual {sol.residual:.2e} above 1e-9")
        return Point(np.concatenate([[float(c.b)], Rotation.from_quat(sol.q0).as_rotvec(), sol.w0]), sol, sol.iterations)

    def tangent(self, point):
        return None

    def tests(self, point):
        return floquet_tests(point.data.monodromy)


def attitude_family_3d_inertia(orbit: PeriodicOrbit, bodies, *, guess, steps: int = 20, n_periods: int = 1, tol: float = 1e-12,
                               ds_min: float = 1e-5):
    """A periodic 3-D attitude motion along ``orbit`` continued in the inertia, from
    ``bodies[0]`` to ``bodies[1]`` along I(s) = (1 - s) I_a + s I_b (``steps`` equal steps in
    s), by natural-parameter continuation (:func:`librate.solving.continuation.natural`) from
    ``guess`` ((q0, w0) or a planar solution) for the first body.

    A common start is the torque-free sphere: with equal moments, the spin
    (1 + 2 pi N / T) e_Z is periodic at any attitude. The Dataset is that of
    :func:`attitude_family_3d`, along ``s``, with the ``moments`` (member, axis) of each body.
    """
    from ..solving.continuation import Point, StepRules, natural

    if not isinstance(orbit, PeriodicOrbit):
        raise ValueError(f"invalid argument `orbit`: must be a librate.PeriodicOrbit, got {type(orbit).__name__}")
    try:
        b0, b1 = bodies
    except (TypeError, ValueError):
        raise ValueError(f"invalid argument `bodies`: must be two librate.RigidBody, got {bodies!r}") from None
    for b in (b0, b1):
        if not isinstance(b, RigidBody) or b.is_rod:
            raise ValueError(f"invalid argument `bodies`: must be two librate.RigidBody with every moment > 0, got {b!r}")
    steps = as_count(steps, "steps", 1)
    n_periods = as_count(n_periods, "n_periods", 1)
    tol = as_tolerance(tol, "tol")
    problem = InertiaBranch3D(orbit, (b0, b1), n_periods, tol)
    from scipy.spatial.transform import Rotation

    s0 = periodic_attitude_3d(orbit, b0, guess=guess, n_periods=n_periods, tol=tol)
    first = Point(np.concatenate([[0.0], Rotation.from_quat(s0.q0).as_rotvec(), s0.w0]), s0, s0.iterations)
    targets = np.linspace(0.0, 1.0, steps + 1)[1:]
    br = natural(problem, first, targets, rules=StepRules(ds=1.0 / steps, ds_min=ds_min), name="s")
    sols = [s0] + [p.data for p in br.points]
    s_values = np.array([0.0] + [float(p.x[0]) for p in br.points])
    dim = ("member",)
    extra = {"s": (dim, s_values), "moments": (("member", "axis"), np.array([problem.body(v).moments for v in s_values]))}
    return _family_dataset(sols, "s", extra, br, {"orbit_period_days": float(orbit.period_days), "n_periods": n_periods,
                                                  "system": orbit.system.name})


FLOQUET_TESTS = {"Q(2)": "+1", "Q(-2)": "-1", "discriminant": "krein"}


def floquet_tests(monodromy) -> dict[str, float]:
    """Bifurcation test functions of a 6x6 attitude monodromy, whose multipliers come in
    reciprocal pairs (lambda, 1/lambda): with u = lambda + 1/lambda, the three pairs are the roots
    of the cubic Q(u) = u^3 + a u^2 + (b - 3) u + (c - 2a), where lambda^6 + a lambda^5 + b lambda^4
    + c lambda^3 + b lambda^2 + a lambda + 1 is the (palindromic) characteristic polynomial (a, b,
    c from the traces of M, M^2, M^3). Q(2) changes sign where a real pair passes +1, Q(-2) where
    one passes -1 (a complex pair adds |2 -+ u|^2 > 0 and never changes them), and the
    discriminant of Q where two pairs collide: a Krein collision on the unit circle, or two
    real pairs meeting off it. Smooth in the family's parameter, so the continuation driver
    locates their zeros."""
    m = np.asarray(monodromy, dtype=float)
    t1, t2, t3 = np.trace(m), np.trace(m @ m), np.trace(m @ m @ m)
    e1, e2, e3 = t1, (t1 * t1 - t2) / 2, (t1**3 - 3 * t1 * t2 + 2 * t3) / 6
    a, b, c = -e1, e2, -e3
    B, C, D = a, b - 3.0, c - 2.0 * a
    q = lambda u: u**3 + B * u * u + C * u + D  # noqa: E731
    disc = 18 * B * C * D - 4 * B**3 * D + B * B * C * C - 4 * C**3 - 27 * D * D
    return {"Q(2)": float(q(2.0)), "Q(-2)": float(q(-2.0)), "discriminant": float(disc)}


def _sorted_multipliers(m) -> np.ndarray:
    m = np.asarray(m, dtype=complex)
    return m[np.lexsort((m.imag, np.abs(m)))]
