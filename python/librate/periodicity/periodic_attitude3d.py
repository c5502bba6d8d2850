"""One periodic 3-D attitude motion along a periodic orbit: :class:`AttitudeSolution3D`, its
corrector :func:`periodic_attitude_3d` and the out-of-plane stability of the planar motions
(:mod:`librate.periodicity.attitude3d` gives the equations and conventions)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._checks import as_count, as_tolerance
from .._display import fmt, html_summary, short_repr
from .._errors import ConvergenceError
from ..attitude.body import RigidBody
from ..attitude.propagate import propagate_attitude
from ..orbits.periodic import PeriodicOrbit
from .solutions import AttitudeSolution

__all__ = ["AttitudeSolution3D", "periodic_attitude_3d", "verified_solution_3d", "is_mirror_symmetric", "out_of_plane_stability",
           "out_of_plane_family", "STABILITY_TOL", "SOLVE_RTOL", "VERIFY_RTOL"]

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
    """A periodic 3-D attitude motion along ``orbit``, over K = ``n_periods`` orbit periods.

    Made by :func:`periodic_attitude_3d`, :func:`out_of_plane_stability` and the 3-D families.
    The residuals and turns come from an independent re-propagation of the corrected motion:
    the scalar 3-D model without STM at rtol = atol = 1e-14 (:data:`VERIFY_RTOL`), with scipy's
    rotation algebra rather than the corrector's. ``propagate(n_periods=None, **kwargs)``
    integrates the motion again (default over its own K periods, rtol = atol = 1e-13).

    Parameters
    ----------
    orbit : PeriodicOrbit
        The orbit.
    body : RigidBody
        The body.
    n_periods : int
        K, the orbit periods per attitude period.
    q0 : numpy.ndarray, shape (4,)
        The initial attitude, a unit quaternion (scalar last): the body relative to the synodic
        frame.
    w0 : numpy.ndarray, shape (3,)
        The initial inertial angular rate in body axes (rad/TU).
    monodromy : numpy.ndarray, shape (6, 6)
        d(theta, w)(KT) / d(theta, w)(0), theta a small rotation in body axes.
    residual_rotation : float, default nan
        |rotation vector of R(0)' R(KT)| after the K periods (rad), from the re-propagation.
    residual_rate : float, default nan
        |w(KT) - w0| after the K periods (rad/TU), from the re-propagation.
    turns : float or None, default None
        The net turns of the body x axis about the synodic Z axis over the K periods (of its
        projection on the synodic XY plane, unwrapped). None where that projection passes
        within 1e-3 of zero: the count is then undefined.
    iterations : int, default 0
        The corrector's Newton steps.

    Attributes
    ----------
    residual : float
        max(``residual_rotation``, ``residual_rate``).
    multipliers : numpy.ndarray, shape (6,), complex
        The monodromy's six eigenvalues.
    stable : bool
        Every multiplier on the unit circle, to :data:`STABILITY_TOL`.
    planar : bool
        A motion in the plane: a planar orbit, q0 a rotation about Z and w0 along z (to 1e-10).
    in_plane_multipliers : numpy.ndarray or None
        For a planar motion the multipliers of the (theta_z, w_z) block of the monodromy;
        otherwise None.
    out_of_plane_multipliers : numpy.ndarray or None
        For a planar motion the multipliers of the roll/yaw block (theta_x, theta_y, w_x,
        w_y); otherwise None.
    phi0 : float
        The angle about Z of the body x axis from the synodic X axis at t = 0 (rad).

    Examples
    --------
    >>> import librate
    >>> orbit = librate.dro(period_days=12.66)
    >>> planar = librate.periodic_attitude(orbit, kz=0.8, n=-1)
    >>> s = librate.periodic_attitude_3d(orbit, librate.RigidBody.from_kz(0.8), guess=planar)
    >>> s.planar, round(s.turns, 6), bool(s.residual < 1e-9), s.stable
    (True, -1.0, True, False)
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
                   "orbit and body": [("orbit", repr(self.orbit), ""),
                                      ("body", f"{type(b).__name__}(ix={fmt(b.ix)}, iy={fmt(b.iy)}, iz={fmt(b.iz)})", "")]}
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
            raise ValueError("invalid argument `guess`: a planar solution with solar radiation pressure; the 3-D corrector has the "
                             "gravity gradient only")
        if guess.n_periods != n_periods:
            raise ValueError(f"invalid argument `n_periods`: the planar guess closes over {guess.n_periods} periods, got "
                             f"n_periods = {n_periods}")
        if guess.kind != "periodic":
            # a half turn about z is a different attitude (R(T) = R(0) Rz(pi)): not a 3-D periodic motion
            raise ValueError("invalid argument `guess`: a half-turn planar solution repeats the attitude only up to a half "
                             "turn; pass a periodic one")
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
    """The periodic 3-D attitude motion of ``body`` along ``orbit``, corrected from ``guess``.

    The orbit may be planar or spatial; the motion closes over ``n_periods`` revolutions. The
    corrector (Newton, in Rust) stops once the max-norm of the closure residual is <= ``tol``.
    The solution is then re-propagated independently at a tighter tolerance, and its
    ``residual`` reports that check.

    ``symmetric`` chooses the formulation. The full-period form (the default) has six
    unknowns. The half-period form needs the orbit and the guess to be mirror symmetric
    (:func:`is_mirror_symmetric`), and the solution then is too: three unknowns and three
    equations at KT/2. It is cheaper, but from a poor guess its Newton basin can be smaller
    than the full form's. The monodromy is the full-period one either way.

    Parameters
    ----------
    orbit : PeriodicOrbit
        The orbit.
    body : RigidBody
        The body: a :class:`RigidBody` with every principal moment > 0 (not a rod).
    guess : AttitudeSolution or (q0, w0)
        A planar periodic :class:`~librate.AttitudeSolution` over the same ``n_periods``,
        without SRP (its phi0 about Z and its wz0), or a pair of a unit quaternion q0 (4
        numbers, scalar last, |q0| = 1 to 1e-6) and an inertial rate w0 in body axes (3
        numbers, rad/TU), all finite.
    n_periods : int, default 1
        K, the orbit periods per attitude period, in [1, 1000].
    tol : float, default 1e-12
        The corrector's tolerance on the residual's max-norm, in [1e-15, 1e-3].
    max_iter : int, default 40
        Newton steps at most, in [1, 10,000].
    symmetric : bool, default False
        Use the mirror-symmetric half-period form (True) rather than the full period.

    Returns
    -------
    AttitudeSolution3D
        The verified solution.

    Raises
    ------
    ValueError
        A bad argument, naming it: an orbit that is not a :class:`PeriodicOrbit`, a rod or
        other body, a guess of the wrong form (not a unit quaternion, a half-turn or SRP
        planar solution, one over another K), a count or tolerance out of range, or
        ``symmetric`` without a mirror-symmetric orbit and guess.
    ConvergenceError
        The corrector stopped without converging (its reason, steps and residual named).

    Examples
    --------
    >>> import librate, math
    >>> halo = librate.halo("earth-moon", 2, "south", period_days=13.0)
    >>> body = librate.RigidBody(0.8, 0.9, 1.0)
    >>> guess = ([0, 0, 0, 1.0], [0, 0, 1 - 2 * math.pi / halo.period])
    >>> s = librate.periodic_attitude_3d(halo, body, guess=guess)
    >>> s.planar, round(s.turns, 6), bool(s.residual < 1e-9)
    (False, -1.0, True)
    >>> half = librate.periodic_attitude_3d(halo, body, guess=guess, symmetric=True)
    >>> bool(abs(half.w0 - s.w0).max() < 1e-9)
    True
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
    options = _core.CorrectorOptions3D(_core.NewtonOptions(tol=float(tol), max_iter=int(max_iter)), rtol=SOLVE_RTOL,
                                       atol=SOLVE_RTOL, half=bool(half))
    r = _core.attitude_correct_3d(orbit.system.mu, list(body.moments), [float(v) for v in orbit.state0], T,
                                  _core.AttitudeCases3D(q[None, :], w[None, :]), options=options)
    if r.reason[0] != "converged":
        raise ConvergenceError(f"periodic 3-D attitude: the corrector stopped ({r.reason[0].replace('_', ' ')}) after "
                               f"{int(r.iterations[0])} Newton steps, residual {float(r.residual_norm[0]):.3e} (tolerance {tol:.1e})")
    return verified_solution_3d(orbit, body, n_periods, r.q0[0], r.w0[0], r.monodromy[0], int(r.iterations[0]))


def verified_solution_3d(orbit: PeriodicOrbit, body: RigidBody, n_periods: int, q0, w0, monodromy,
                         iterations: int = 0) -> AttitudeSolution3D:
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
    """The planar ``solution`` as a 3-D motion, with its out-of-plane (roll/yaw) multipliers.

    The motion is corrected by :func:`periodic_attitude_3d` from the planar solution, with body
    z along synodic Z and the planar body of its Kz (Ix + Iy = Iz,
    :meth:`RigidBody.from_kz`). Its roll/yaw multipliers
    (:attr:`AttitudeSolution3D.out_of_plane_multipliers`) stand next to the in-plane pair.

    Parameters
    ----------
    solution : AttitudeSolution
        A planar periodic solution without SRP, of a body with |Kz| < 1 (not a thin rod).

    Returns
    -------
    AttitudeSolution3D
        The planar motion in 3-D (``planar`` True).

    Raises
    ------
    ValueError
        ``solution`` not an :class:`AttitudeSolution`, a thin rod (|Kz| = 1), a half-turn
        solution or one with SRP.
    ConvergenceError
        The 3-D corrector did not converge.

    Examples
    --------
    >>> import librate
    >>> orbit = librate.dro(period_days=12.66)
    >>> s = librate.out_of_plane_stability(librate.periodic_attitude(orbit, kz=0.8, n=-1))
    >>> sorted(abs(s.out_of_plane_multipliers).round(4).tolist())
    [0.8843, 0.8843, 1.1308, 1.1308]
    """
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
