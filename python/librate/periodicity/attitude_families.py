"""Families of symmetric periodic attitude motions continued through folds, in Kz for one orbit
or in x0 across an orbit family (thesis sec. 3.3)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._checks import as_count, as_number
from .._errors import ConvergenceError
from .._progress import as_progress
from ..orbits.families import OrbitFamily
from ..orbits.periodic import PeriodicOrbit
from ..solving.continuation import Constraint, CorrectionFailed, Point, StepRules, arclength
from .branches import KzBranch, periodic_attitude
from .solutions import KINDS, SOLVE_ATOL, SOLVE_RTOL, STEP_MAX_HALVINGS, STEP_MAX_ITER, check_kz, check_orbit, is_symmetric, turns_of

__all__ = ["AttitudeFamily", "attitude_family"]

#: The corrector's settings of each step across an orbit family.
_ACROSS_OPTIONS = _core.CorrectorOptions(_core.NewtonOptions(tol=1e-12, max_iter=STEP_MAX_ITER, max_halvings=STEP_MAX_HALVINGS),
                                         _core.LaneOptions(rtol=SOLVE_RTOL, atol=SOLVE_ATOL))


@dataclass
class AttitudeFamily:
    """A family of symmetric periodic attitude motions continued along a parameter: ``"kz"``
    for one orbit, or ``"x0"`` across an orbit family. Arrays over the members: ``parameter``
    values, ``wz0`` (inertial), ``trace`` of the 2x2 monodromy, ``stable``; ``folds`` lists the
    turning points (parameter, wz0; located to 1e-8) where the curve turns back; ``bifurcations``
    where the monodromy trace crosses +-2; ``end_reason`` why it stopped."""

    parameter_name: str
    parameter: np.ndarray
    wz0: np.ndarray
    trace: np.ndarray
    n: int
    kind: str
    kz: float | None
    folds: list[dict]
    end_reason: str
    bifurcations: list[dict] = field(default_factory=list)

    @property
    def phidot0(self) -> np.ndarray:
        return self.wz0 - 1.0

    @property
    def stable(self) -> np.ndarray:
        return np.abs(self.trace) < 2.0

    def __len__(self) -> int:
        return len(self.parameter)


class OrbitFamilyBranch:
    """The symmetric motion across a planar orbit family, for the continuation driver:
    x = (x0, wz0) with G(x0, wz0) = phi(T(x0)/2) - pi turns = 0 (phi0 = 0, one period), corrected
    by the Rust corrector with the orbit's x0 freed (the orbit through any x0 corrected and
    tabulated on demand from the family's members, cached)."""

    parameter_index = 0
    scale = np.ones(2)

    def __init__(self, family: OrbitFamily, kz: float, n_total: int, kind: str):
        self.table = _core.PlanarFamily(family.system.mu, [float(v) for v in family.x0], [float(v) for v in family.state0[:, 4]])
        self.lo, self.hi = self.table.range
        self.kz, self.turns = kz, float(turns_of(n_total, kind))

    def correct(self, guess, c):
        a_x, a_w = c.a
        cases = _core.PlanarCases(np.zeros(1), np.array([float(guess[1])]), np.array([self.kz]), turns=np.array([self.turns]))
        border = _core.Bordered(_core.BorderedParameter.ORBIT_X0, (0.0, a_w, a_x, c.b), step=1e-6, max_step=0.05)
        b = _core.attitude_correct_across(self.table, cases, np.array([float(np.clip(guess[0], self.lo, self.hi))]), bordered=border,
                                          options=_ACROSS_OPTIONS)
        if not b.converged[0]:
            raise CorrectionFailed(f"orbit-family branch: {b.reason[0]}")
        g = b.jacobian[0, 0]
        return Point(np.array([b.parameter[0], b.wz0[0]]), {"g_p": float(g[2]), "g_wz": float(g[1]),
                                                            "trace": float(np.trace(b.monodromy[0]))},
                     int(b.iterations[0]))

    # the tangent and the tests are those of the Kz branch (x = (parameter, wz0) in both)
    tangent = KzBranch.tangent
    tests = KzBranch.tests


def attitude_family(
    orbits,
    *,
    kz: float,
    n: int,
    kind: str = "periodic",
    start: float | None = None,
    wz0: float | None = None,
    parameter_range: tuple[float, float] | None = None,
    ds: float = 0.05,
    ds_min: float = 1e-6,
    ds_max: float = 0.25,
    max_points: int = 400,
    direction: int = -1,
    progress=None,
) -> AttitudeFamily:
    """Continue a symmetric periodic attitude motion with ``n`` turns along a parameter, through folds
    (thesis Figs. 27-29).

    The curve G(p, wz0) = phi(T/2) - pi n = 0 (phi0 = 0) is followed by the shared pseudo-arclength
    driver (`librate.solving.continuation`), every point corrected by the Rust corrector with p
    freed. Folds (p turning back) are located to 1e-8 and the curve is followed past them.

    Parameters
    ----------
    orbits : OrbitFamily or PeriodicOrbit
        An `OrbitFamily`: the parameter is the orbit's x0 (the orbit through any x0 in the
        family's range is corrected and tabulated on demand, in Rust). One `PeriodicOrbit`: the
        parameter is Kz.
    kz : float
        The inertia ratio (the fixed Kz along an orbit family; the first Kz on one orbit).
    n : int
        Net turns per orbit period.
    kind : {"periodic", "half-turn"}
        The closure.
    start : float, optional
        The first parameter value (x0, or Kz); default the family's first member (or ``kz``).
    wz0 : float, optional
        The first solution's rate; default the one continued in Kz from Kz = 0 (as
        `periodic_attitude`).
    parameter_range : (float, float), optional
        Stop outside this range of the parameter.
    ds, ds_min, ds_max : float
        Step rules of the continuation (first, smallest and largest arclength step).
    max_points : int, default 400
        The most points computed.
    direction : {-1, 1}
        The initial sense in the parameter.
    progress : bool or callable, optional
        True for a bar on stderr, or ``progress(done, total)`` after each point (total:
        ``max_points``, then the points found at the end).

    Returns
    -------
    AttitudeFamily
        ``parameter``, ``wz0``, ``phidot0``, ``trace``, ``stable`` over the members; ``folds``,
        ``bifurcations`` (where the monodromy trace crosses +-2) and ``end_reason``.

    Raises
    ------
    ConvergenceError
        The first solution cannot be found.
    ValueError
        A bad argument, naming it.
    """
    progress = as_progress(progress, f"attitude family N = {n}", "point")
    if kind not in KINDS:
        raise ValueError(f"invalid argument `kind`: must be 'periodic' or 'half-turn', got {kind!r}")
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)):
        raise ValueError(f"invalid argument `n`: must be an integer, got {n!r}")
    if direction not in (-1, 1):
        raise ValueError(f"invalid argument `direction`: must be -1 or +1, got {direction!r}")
    kz = check_kz(kz)
    max_points = as_count(max_points, "max_points", 2)
    rules = StepRules(ds=as_number(ds, "ds", positive=True), ds_min=as_number(ds_min, "ds_min", positive=True),
                      ds_max=as_number(ds_max, "ds_max", positive=True), predictor="quadratic")
    n_total = int(n)
    if isinstance(orbits, OrbitFamily):
        if orbits.spatial:
            raise ValueError("invalid argument `orbits`: attitude families need a planar orbit family")
        name = "x0"
        problem = OrbitFamilyBranch(orbits, kz, n_total, kind)
        lo, hi = parameter_range or (problem.lo, problem.hi)
        p0 = float(orbits.x0[0] if start is None else start)
        if not (lo <= p0 <= hi):
            raise ValueError(f"invalid argument `start`: {p0} is outside the parameter range [{lo}, {hi}]")
        first_orbit = orbits.member(x0=p0)
    elif isinstance(orbits, PeriodicOrbit):
        orbit = check_orbit(orbits)
        if not is_symmetric(orbit, 0.0):
            raise ValueError("invalid argument `orbits`: attitude families need an x-symmetric orbit started on the x axis")
        name = "kz"
        problem = KzBranch(orbit, n_total, kind, 0.0, 1)
        lo, hi = parameter_range or (-1.0, 1.0)
        p0 = kz if start is None else check_kz(start)
        if not (lo <= p0 <= hi):
            raise ValueError(f"invalid argument `start`: {p0} is outside the parameter range [{lo}, {hi}]")
        first_orbit = orbit
    else:
        raise ValueError(f"invalid argument `orbits`: must be an OrbitFamily or a PeriodicOrbit, got {type(orbits).__name__}")
    kz0 = kz if name == "x0" else p0
    if wz0 is None:
        w = periodic_attitude(first_orbit, kz=kz0, n=n_total, kind=kind).wz0
    else:
        w = periodic_attitude(first_orbit, kz=kz0, n=n_total, kind=kind, wz0=as_number(wz0, "wz0")).wz0
    try:
        first = problem.correct(np.array([p0, w]), Constraint.fix(2, 0, p0))
    except CorrectionFailed as e:
        raise ConvergenceError(f"attitude family (N = {n}, {kind}): no starting solution at {name} = {p0}: {e}") from None
    count = [1]

    def report(_point) -> None:  # the driver's per-point hook
        count[0] += 1
        progress(min(count[0], max_points), max_points)

    br = arclength(problem, first, direction=direction, rules=rules, max_points=max_points, bounds=(lo, hi), name=name,
                   stop=None if progress is None else report)
    if progress is not None:
        progress(len(br.points), len(br.points))
    ps = np.array([p.x[0] for p in br.points])
    ws = np.array([p.x[1] for p in br.points])
    traces = np.array([p.data["trace"] for p in br.points])
    folds = [{name: f.parameter, "wz0": float(f.point.x[1]), "located": bool(f.located)} for f in br.folds]
    bifs = [{"test": b.name, name: b.parameter, "wz0": float(b.point.x[1]), "located": bool(b.located)} for b in br.bifurcations]
    return AttitudeFamily(name, ps, ws, traces, int(n), kind, kz if name == "x0" else None, folds, br.end_reason, bifs)
