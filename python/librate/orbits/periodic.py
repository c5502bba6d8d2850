"""Periodic orbits: corrected members of symmetric families and their stability."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from .. import _core
from .._checks import as_count, as_number, as_real, as_tolerance
from .._display import html_summary, short_repr
from .._errors import CollisionError
from .system import System, resolve_system

__all__ = ["PeriodicOrbit", "Geometry", "geometry", "primary_passes", "inside_primary_index", "collision_mode", "check_outside_primaries",
           "correct_symmetric", "correct_periodic", "real_if_real", "INDEX_TESTS", "index_tests", "symmetric_monodromy"]

_VARS = {"x0": 0, "z0": 1, "vy0": 2}
# Tolerances of the shooting propagations: the 8th-order solution at 1e-13 puts the
# closure of a corrected member near 1e-12.
SHOOT_RTOL = 1e-13
SHOOT_ATOL = 1e-13


def real_if_real(nu) -> np.ndarray:
    """Stability indices as float when every one is real, complex otherwise.

    The core returns each index nu = x / 2 from the roots x of Broucke's quadratic: real ones
    (a real discriminant: a saddle pair, or a pair on the unit circle) have imaginary part
    exactly 0, a complex quadruplet of multipliers gives a genuinely complex pair. So the
    float array loses nothing; a complex array is returned only when some index is complex."""
    a = np.asarray(nu)
    if not np.iscomplexobj(a):
        return a.astype(np.float64, copy=True)
    return a.real.copy() if np.all(a.imag == 0) else a.copy()


@dataclass(frozen=True)
class PeriodicOrbit:
    """A corrected periodic orbit.

    Made by the correctors (`correct_symmetric`, `correct_periodic`, `dro`, `halo`, ...) and the
    families. ``monodromy``, ``eigenvalues`` and ``stability_indices`` are computed on first use
    (one propagation over the period with the STM).

    Parameters
    ----------
    system : System
        The system.
    state0 : numpy.ndarray, shape (6,)
        The initial state; symmetric orbits start on the x-z plane, perpendicular to it.
    period : float
        The period (TU).
    jacobi : float
        The Jacobi constant.
    family : str, default "symmetric"
        The family's name ("dro", "lyapunov-L1", "halo-L2-south", ...).
    iterations : int
        The corrector's Newton iterations.
    residual : float
        The corrector's final residual.

    Attributes
    ----------
    x0, z0, vy0 : float
        Components of ``state0``.
    planar : bool
        z0 = 0 and no out-of-plane velocity.
    period_days : float
        The period in days.
    monodromy : numpy.ndarray, shape (6, 6)
        The state transition matrix over one period.
    eigenvalues : numpy.ndarray
        The monodromy's eigenvalues.
    stability_indices : numpy.ndarray
        nu = (lambda + 1/lambda) / 2 of the non-trivial pairs: [in-plane, out-of-plane] for
        planar orbits; stable when |nu| <= 1.
    is_stable : bool
        Every |nu| <= 1.

    Examples
    --------
    >>> import librate
    >>> dro = librate.dro(period_days=12.66)
    >>> round(dro.period_days, 2), bool(dro.planar)
    (12.66, True)
    """

    system: System
    state0: np.ndarray
    period: float
    jacobi: float
    family: str = "symmetric"
    iterations: int = 0
    residual: float = 0.0
    _evaluation: _core.ShootingEvaluation | None = field(default=None, repr=False, compare=False)

    # --- display (librate._display) -----------------------------------------------------------
    def _rows(self):
        return [("family", self.family, ""), ("x0", self.x0, "LU"), ("z0", self.z0, "LU"), ("period", self.period, "TU"),
                ("period_days", self.period_days, "d"), ("jacobi", self.jacobi, "")]

    def __repr__(self) -> str:
        return short_repr("PeriodicOrbit", self._rows())

    def _repr_html_(self) -> str:
        fit = [("iterations", self.iterations, ""), ("residual", self.residual, "")]
        if "stability_indices" in self.__dict__:  # already computed: shown, never computed for display
            fit.append(("stability_indices", self.__dict__["stability_indices"], ""))
        return html_summary(f"librate.PeriodicOrbit ({self.family}, {self.period_days:.4g} d)", self._rows(),
                            {"initial state": [("state0", self.state0, "LU, LU/TU")], "correction": fit,
                             "system": [("system", repr(self.system), "")]})

    @property
    def x0(self) -> float:
        return float(self.state0[0])

    @property
    def z0(self) -> float:
        return float(self.state0[2])

    @property
    def vy0(self) -> float:
        return float(self.state0[4])

    @property
    def planar(self) -> bool:
        return self.state0[2] == 0.0 and self.state0[5] == 0.0

    @property
    def period_days(self) -> float:
        return self.system.period_days(self.period)

    @cached_property
    def monodromy(self) -> np.ndarray:
        """Monodromy matrix Phi(T, 0) (6, 6)."""
        from .propagation import propagate

        return propagate(self.system, self.state0, self.period, stm=True, rtol=SHOOT_RTOL, atol=SHOOT_ATOL, collision="point").stm

    @cached_property
    def _stability(self):
        return _core.stability(np.ascontiguousarray(self.monodromy), self.planar)

    @property
    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues (6,) of the monodromy matrix (complex)."""
        return self._stability[0]

    @property
    def stability_indices(self) -> np.ndarray:
        """The two non-trivial stability indices: a float array when both are real (saddle
        pairs and stable pairs), complex only for a complex quadruplet of multipliers."""
        return real_if_real(self._stability[1])

    @property
    def is_stable(self) -> bool:
        nu = self.stability_indices
        return bool(np.all(np.abs(nu.imag) < 1e-9) and np.all(np.abs(nu.real) <= 1 + 1e-9))

    def propagate(self, n_periods: float = 1.0, **kwargs):
        """Propagate the orbit over ``n_periods`` periods (keyword arguments go to
        :func:`librate.propagate`; default tolerances 1e-13). The orbit is a solution of the
        point-mass model, so by default only the singular point counts as a collision
        (``collision="point"``); pass ``collision="radius"`` to stop at a primary's surface."""
        from .propagation import propagate

        kwargs.setdefault("collision", "point")
        kwargs.setdefault("rtol", SHOOT_RTOL)
        kwargs.setdefault("atol", SHOOT_ATOL)
        return propagate(self.system, self.state0, as_real(n_periods, "n_periods") * self.period, **kwargs)


@dataclass(frozen=True)
class Geometry:
    """Winding numbers of an orbit about each primary and its closest approach to each."""

    winding: tuple[int, int]
    min_distance: tuple[float, float]


def geometry(orbit: PeriodicOrbit) -> Geometry:
    """Winding numbers (signed turns of the projected position about each primary over one
    period) and closest approaches, from the integrated orbit (at rtol = atol = 1e-11, point
    masses; the orbit's fields were checked when it was made)."""
    from .propagation import collision_radii, integrate, tolerance_options

    sys_ = orbit.system
    tr = integrate(sys_, np.ascontiguousarray(orbit.state0, dtype=float), 0.0, float(orbit.period), tolerance_options(1e-11, 1e-11),
                   collision_radii(sys_, "point"))
    y = tr.y
    wind, dmin = [], []
    for c in orbit.system.primary_positions():
        rel = y[:, :3] - c
        ang = np.unwrap(np.arctan2(rel[:, 1], rel[:, 0]))
        wind.append(int(round((ang[-1] - ang[0]) / (2 * math.pi))))
        dmin.append(float(np.min(np.linalg.norm(rel, axis=1))))
    return Geometry((wind[0], wind[1]), (dmin[0], dmin[1]))



def primary_passes(system: System, states, periods, collision: str = "radius"):
    """Which orbits pass within a primary's radius: each (6,) state of ``states`` propagated over
    its period by :func:`librate.propagate_many` with its collision check (``collision="radius"``:
    the system's radii ``r1_km``, ``r2_km``; a primary of radius 0 counts as a point), at the
    shooting tolerances. Returns the :class:`librate.orbits.propagation.BatchResult`: ``status``
    "collision_primary1" / "collision_primary2" marks an orbit reaching that primary (the
    collision located in time), "completed" one that stays outside both. The one check used
    for imported catalog rows, corrected orbits and family members."""
    from .propagation import propagate_many

    return propagate_many(system, states, periods, rtol=SHOOT_RTOL, atol=SHOOT_ATOL, on_error="mask", collision=collision)


def inside_primary_index(status) -> np.ndarray:
    """(n,) int8 from the ``status`` of :func:`primary_passes`: 1 or 2 (the primary reached), 0
    (outside both), -1 (the propagation failed for another reason)."""
    st = np.asarray(status)
    out = np.where(st == "collision_primary1", 1, np.where(st == "collision_primary2", 2, np.where(st == "completed", 0, -1)))
    return out.astype(np.int8)


def collision_mode(collision) -> str | None:
    """``collision`` checked: "radius", "point" or None (ValueError naming it otherwise)."""
    if collision is not None and (not isinstance(collision, str) or collision not in ("radius", "point")):
        raise ValueError("invalid argument `collision`: must be 'radius' (the system's radii), 'point' (point masses) or "
                         f"None, got {collision!r}")
    return collision


def check_outside_primaries(orbit: PeriodicOrbit, collision: str | None = "radius") -> PeriodicOrbit:
    """``orbit`` itself when it stays outside both primaries' radii over its period
    (:func:`primary_passes`); otherwise :class:`librate.CollisionError` naming the primary, the
    orbit's closest approach to its centre (km, from :func:`geometry`) and the radius, with
    attributes ``primary`` (1 or 2), ``closest_km``, ``radius_km``, ``t`` (the time it first
    reaches the radius, TU) and ``orbit`` (the corrected point-mass orbit, for who wants it
    anyway). ``collision=None`` skips the check; ``"point"`` counts only the singular points.
    A system with radii 0 (point masses) never collides."""
    if collision is None:
        return orbit
    run = primary_passes(orbit.system, orbit.state0[None, :], orbit.period, collision)
    k = int(inside_primary_index(run.status)[0])
    if k <= 0:
        return orbit
    sys_ = orbit.system
    err0 = run.errors.get(0)
    radius_km = (sys_.r1_km, sys_.r2_km)[k - 1] if collision == "radius" else 0.0
    closest_km = geometry(orbit).min_distance[k - 1] * sys_.lu_km
    name = (("the Earth", "the Moon") if sys_.name.startswith("earth-moon") else ("the larger primary", "the smaller primary"))[k - 1]
    err = CollisionError(
        f"the corrected {orbit.family} orbit (x0 = {orbit.x0:.10g}, z0 = {orbit.z0:.10g}, period {orbit.period:.10g} TU) passes within "
        f"{name}'s radius (primary {k}): closest approach {closest_km:.1f} km from its centre, radius {radius_km} km "
        f"(first reached at t = {getattr(err0, 't', float('nan')):.6g} TU); it is a solution of the point-mass model only: "
        "pass collision=None to keep it")
    err.primary, err.closest_km, err.radius_km, err.orbit = k, closest_km, radius_km, orbit
    for attr in ("t", "steps", "kind", "distance", "radius"):
        if hasattr(err0, attr):
            setattr(err, attr, getattr(err0, attr))
    raise err


#: The stability-index test functions of symmetric orbit families: name -> (index, level, type).
#: nu - level changes sign where a pair of multipliers passes +1 (a family branches off, or a
#: fold) or -1 (period doubling); undefined (NaN) where the index is complex.
INDEX_TESTS = {
    f"{index} {level:+.0f}": (index, level, kind)
    for index in ("in-plane", "out-of-plane", "index 1", "index 2")
    for level, kind in ((1.0, "tangent (+1): a new family branches off, or a fold"), (-1.0, "period-doubling (-1)"))
}


def index_tests(stability_indices, spatial: bool) -> dict[str, float]:
    """The test functions of one orbit: nu_j - 1 and nu_j + 1 for its two stability indices
    ([in-plane, out-of-plane], or [index 1, index 2] for spatial families); NaN where nu_j is
    complex (|Im| > 1e-6)."""
    names = ("index 1", "index 2") if spatial else ("in-plane", "out-of-plane")
    out = {}
    for name, nu in zip(names, np.asarray(stability_indices).ravel()):
        real = np.isfinite(nu) and abs(complex(nu).imag) <= 1e-6
        for level in (1.0, -1.0):
            out[f"{name} {level:+.0f}"] = float(complex(nu).real - level) if real else math.nan
    return out


def symmetric_monodromy(orbit: PeriodicOrbit) -> np.ndarray | None:
    """The monodromy of a symmetric orbit from its half-period STM (the core's correction
    carries it: Phi(T) = S Phi(T/2)^-1 S Phi(T/2)), or None when the orbit has none."""
    m = None if orbit._evaluation is None else orbit._evaluation.monodromy
    return None if m is None else np.asarray(m, dtype=float)


def correct_symmetric(
    system: System | str,
    guess,
    *,
    spatial: bool = False,
    fix: str | None = "x0",
    period: float | None = None,
    jacobi: float | None = None,
    family: str = "symmetric",
    tol: float = 1e-11,
    max_iter: int = 40,
    t_max: float = 50.0,
    rtol: float = SHOOT_RTOL,
    atol: float = SHOOT_ATOL,
    collision: str | None = "radius",
) -> PeriodicOrbit:
    """Correct an orbit symmetric about the x-z plane by half-period single shooting.

    The unknowns are (x0, vy0) for planar orbits and (x0, z0, vy0) in 3-D; one extra condition
    closes the Newton system: ``fix`` one unknown at its guessed value, or a target ``period``,
    or a target ``jacobi`` constant.

    Parameters
    ----------
    system : System or str
        The system.
    guess : array_like
        (x0, z0, vy0), or a full (6,) state on the plane.
    spatial : bool, default False
        Correct in 3-D (z0 free).
    fix : {"x0", "z0", "vy0", None}
        The unknown held at its guess (None with ``period`` or ``jacobi``).
    period : float, optional
        A target period (TU).
    jacobi : float, optional
        A target Jacobi constant.
    family : str, default "symmetric"
        The name stored on the orbit.
    tol : float, default 1e-11
        Newton tolerance on the half-period crossing residuals.
    max_iter : int, default 40
        Newton iterations.
    t_max : float, default 50.0
        The longest half period searched for the x-z plane crossing (TU).
    rtol, atol : float, default 1e-13
        Integration tolerances.
    collision : {"radius", "point", None}
        As in `propagate`: a corrected orbit that passes within a primary's radius over its
        period raises `CollisionError` naming the primary, the closest approach (km) and the
        radius; ``"point"``: only the singular points count; ``None``: no check.

    Returns
    -------
    PeriodicOrbit
        The corrected orbit.

    Raises
    ------
    ConvergenceError
        Newton did not converge (with ``iterations``, ``residual``, ``tolerance``).
    CollisionError
        The orbit passes within a primary's radius.
    ValueError
        A bad argument, naming it.

    Examples
    --------
    >>> import librate
    >>> orbit = librate.correct_symmetric("earth-moon", (0.8, 0.0, 0.5), fix="x0")
    >>> round(orbit.x0, 6), orbit.family
    (0.8, 'symmetric')
    """
    sys_ = resolve_system(system)
    collision_mode(collision)
    as_tolerance(tol, "tol")
    as_count(max_iter, "max_iter", 1)
    as_real(t_max, "t_max", positive=True)
    for name, v in (("rtol", rtol), ("atol", atol)):
        as_tolerance(v, name)
    if period is not None:
        period = as_real(period, "period", positive=True)
    if jacobi is not None:
        jacobi = as_real(jacobi, "jacobi")
    try:
        g = np.asarray(guess, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        raise ValueError(f"invalid argument `guess`: must be finite (x0, z0, vy0) or a (6,) state, got {guess!r}") from None
    if g.shape == (6,):
        g = g[[0, 2, 4]]
    if g.shape != (3,) or not np.all(np.isfinite(g)):
        raise ValueError(f"invalid argument `guess`: must be finite (x0, z0, vy0) or a (6,) state, got {guess!r}")
    given = [c for c in (("fix", fix), ("period", period), ("jacobi", jacobi)) if c[1] is not None]
    if period is not None or jacobi is not None:
        given = [c for c in given if c[0] != "fix"]
    if len(given) != 1:
        raise ValueError("invalid arguments `fix`, `period`, `jacobi`: give exactly one of them")
    kind, value = given[0]
    if kind == "fix":
        if value not in _VARS:
            raise ValueError(f"invalid argument `fix`: must be one of x0, z0, vy0, got {value!r}")
        if value == "z0" and not spatial:
            raise ValueError("invalid argument `fix`: z0 is zero for planar orbits; fix x0 or vy0")
        values = [float(_VARS[value]), float(g[_VARS[value]])]
    else:
        if not (math.isfinite(value) and (kind == "jacobi" or value > 0)):
            raise ValueError(f"invalid argument `{kind}`: must be finite{' and > 0' if kind == 'period' else ''}, got {value!r}")
        values = [float(value)]
    r = _core.symmetric_correct(
        sys_.mu, [float(v) for v in g], spatial=bool(spatial), constraint=kind, values=values, t_max=float(t_max),
        newton=_core.NewtonOptions(tol=float(tol), max_iter=int(max_iter)),
        options=_core.IntegrationOptions(rtol=float(rtol), atol=float(atol)),
    )
    return check_outside_primaries(orbit_from_core(sys_, r, family), collision)


def orbit_from_core(system: System, r: _core.SymmetricOrbit, family: str) -> PeriodicOrbit:
    return PeriodicOrbit(system, r.state0, r.period, r.jacobi, family, r.iterations, r.residual, r.evaluation)


def _check_jacobi_reachable(system: System, patches: np.ndarray, target: float) -> None:
    """Refuse a Jacobi target that no state at the patches' positions has: C = 2U - |v|^2 is at
    most 2U(r) (its zero-velocity value) at a position r, so a target above 2U(r_i) puts patch i
    in the forbidden region of the member wanted. Newton then drives the patches toward a
    primary, where U grows without bound, and each step's trajectories pass near the
    singularity: they run to the integrator's step limit, and the correction took 26 s (target
    +5) to 139 s (+10) from the x0 = 0.3 DRO before failing. A ValueError says so at once."""
    at_rest = patches.copy()
    at_rest[:, 3:] = 0.0
    reach = np.atleast_1d(system.jacobi(at_rest))  # 2U(r_i), the largest C at each position
    i = int(np.argmin(reach))
    if target > reach[i]:
        raise ValueError(f"invalid argument `jacobi`: {target:.10g} is out of reach of the guess: at patch {i} (r = "
                         f"{', '.join(f'{v:.6g}' for v in patches[i, :3])} LU) no state has a Jacobi constant above "
                         f"2U(r) = {reach[i]:.10g} (C = 2U - |v|^2), so the member wanted does not pass there; "
                         f"the guess has C = {float(system.jacobi(patches[0])):.10g}. "
                         "Give a guess on that member, or reach it by continuation (small steps in `jacobi`)")


def correct_periodic(
    system: System | str,
    states,
    period: float,
    *,
    jacobi: float | None = None,
    fixed_period: bool = False,
    family: str = "periodic",
    tol: float = 1e-10,
    max_iter: int = 25,
    rtol: float = SHOOT_RTOL,
    atol: float = SHOOT_ATOL,
    collision: str | None = "radius",
) -> PeriodicOrbit:
    """Correct a periodic orbit with no symmetry assumed, by single or multiple shooting.

    The period is free and a Poincare phase condition pins the first patch near its guess; the
    member of the family is selected by its Jacobi constant or, with ``fixed_period=True``, by
    the period. Multiple shooting is the remedy for long or strongly unstable orbits: each
    segment's sensitivity stays moderate. The least-squares Newton step absorbs the conserved
    Jacobi constant's redundant equation.

    Parameters
    ----------
    system : System or str
        The system.
    states : array_like, shape (6,) or (m, 6)
        One state (single shooting) or m patch states equally spaced in time over the period guess.
    period : float
        The period guess (TU).
    jacobi : float, optional
        The target Jacobi constant (default: the first patch's). It must not exceed 2U at any
        patch's position (the largest Jacobi constant a state there can have).
    fixed_period : bool, default False
        Hold the period instead of the Jacobi constant.
    family : str, default "periodic"
        The name stored on the orbit.
    tol : float, default 1e-10
        Newton tolerance.
    max_iter : int, default 25
        Newton iterations.
    rtol, atol : float, default 1e-13
        Integration tolerances.
    collision : {"radius", "point", None}
        As in `correct_symmetric`.

    Returns
    -------
    PeriodicOrbit
        The corrected orbit.

    Raises
    ------
    ConvergenceError
        Newton did not converge.
    CollisionError
        The orbit passes within a primary's radius.
    ValueError
        A bad argument, naming it.
    """
    sys_ = resolve_system(system)
    collision_mode(collision)
    as_tolerance(tol, "tol")
    as_count(max_iter, "max_iter", 1)
    for name, v in (("rtol", rtol), ("atol", atol)):
        as_tolerance(v, name)
    if jacobi is not None:
        jacobi = as_real(jacobi, "jacobi")
    try:
        patches = np.ascontiguousarray(np.atleast_2d(np.asarray(states, dtype=np.float64)))
    except (TypeError, ValueError):
        raise ValueError(f"invalid argument `states`: must be (6,) or (n, 6) finite numbers, got {states!r}") from None
    if patches.ndim != 2 or patches.shape[1] != 6:
        raise ValueError(f"invalid argument `states`: must be (6,) or (n, 6), got shape {np.shape(states)}")
    if not np.all(np.isfinite(patches)):
        raise ValueError("invalid argument `states`: must be finite")
    as_number(period, "period", positive=True)
    if fixed_period and jacobi is not None:
        raise ValueError("invalid argument: give `jacobi` or `fixed_period=True`, not both")
    if fixed_period:
        cond, value = "period", float(period)
    else:
        cond, value = "jacobi", float(sys_.jacobi(patches[0]) if jacobi is None else jacobi)
        _check_jacobi_reachable(sys_, patches, value)
    r = _core.multiple_shooting(sys_.mu, patches, float(period), condition=cond, value=value,
                                newton=_core.NewtonOptions(tol=float(tol), max_iter=int(max_iter)),
                                options=_core.IntegrationOptions(rtol=float(rtol), atol=float(atol)))
    return check_outside_primaries(PeriodicOrbit(sys_, r.patches[0].copy(), r.period, r.jacobi, family,
                                                 r.iterations, r.residual), collision)
