"""Continuation of symmetric periodic-orbit families (thesis eq. 20-22 and pseudo-arclength).

The numerical kernels (shooting with the STM and event location) are in Rust; the loop
(prediction, step rules, jump guards, termination with a reason) is the shared continuation
driver of :mod:`librate.solving.continuation`. This module defines the orbit family as a
problem for it: the corrector call and the family's own guards (Jacobi-constant and period
continuity, winding numbers).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._errors import LibrateError
from .._progress import as_progress
from ..solving.continuation import Bifurcation, Branch, Constraint, Point, StepRules, arclength, natural
from .periodic import SHOOT_ATOL, SHOOT_RTOL, Geometry, PeriodicOrbit, geometry, index_tests, orbit_from_core, symmetric_monodromy
from .system import System

#: The shooting's Newton and integrator settings of every continuation step.
_SHOOT_NEWTON = _core.NewtonOptions(tol=1e-12, max_iter=25)
_SHOOT_OPTIONS = _core.IntegrationOptions(rtol=SHOOT_RTOL, atol=SHOOT_ATOL)

__all__ = ["Geometry", "geometry", "continue_natural", "continue_arclength", "ContinuationResult"]

_VAR_INDEX = {"x0": 0, "z0": 1, "vy0": 2}


@dataclass
class ContinuationResult:
    """The members of a continued family, their geometries, why the run ended, and the
    bifurcations the driver found on the way (sign changes of the stability-index test
    functions, located to 1e-8 in the parameter; ``after``: the member before each)."""

    members: list[PeriodicOrbit]
    geometries: list[Geometry]
    end_reason: str
    rejected_jumps: int = 0
    extra: dict = field(default_factory=dict)
    bifurcations: list[Bifurcation] = field(default_factory=list)


def _correct(system: System, p, spatial: bool, kind: str, values, family: str, t_max: float) -> PeriodicOrbit:
    r = _core.symmetric_correct(
        system.mu, [float(v) for v in p], spatial=spatial, constraint=kind, values=[float(v) for v in values], t_max=t_max,
        newton=_SHOOT_NEWTON, options=_SHOOT_OPTIONS,
    )
    return orbit_from_core(system, r, family)


def _p(o: PeriodicOrbit) -> np.ndarray:
    return np.array([o.x0, o.z0, o.vy0])


def _smooth(history: list[PeriodicOrbit], new: PeriodicOrbit, ratio: float) -> bool:
    """Jacobi-constant and period continuity: the change to the new member may not exceed five
    times the previous change scaled by the step ratio (plus a small floor)."""
    if len(history) < 2:
        return True
    a, b = history[-2], history[-1]
    for f, floor in ((lambda o: o.jacobi, 1e-7), (lambda o: o.period, 1e-6)):
        prev = abs(f(b) - f(a))
        if abs(f(new) - f(b)) > 5.0 * prev * ratio + floor:
            return False
    return True


def tangent(orbit: PeriodicOrbit, spatial: bool, previous: np.ndarray | None = None, orient: np.ndarray | None = None) -> np.ndarray:
    """Unit tangent of the family at ``orbit`` in p = (x0, z0, vy0): the null vector of the
    symmetric conditions' Jacobian, oriented along ``previous`` (or ``orient``)."""
    e = orbit._evaluation
    if e is None:
        raise LibrateError("family tangent undefined: the orbit was not corrected by the symmetric shooting")
    d = e.dcond
    if spatial:
        t = np.cross(d[0], d[1])
    else:
        g = d[0]
        t = np.array([g[2], 0.0, -g[0]])
    n = np.linalg.norm(t)
    if n == 0 or not np.isfinite(n):
        raise LibrateError("family tangent undefined (singular shooting Jacobian)")
    t /= n
    ref = previous if previous is not None else orient
    if ref is not None and np.dot(t, ref) < 0:
        t = -t
    return t


class SymmetricFamilyProblem:
    """A family of x-z-symmetric periodic orbits for the continuation driver: x = (x0, z0, vy0),
    corrected by the Rust half-period shooting with the driver's linear condition (a fixed
    unknown, or the pseudo-arclength condition); guarded by Jacobi-constant and period
    continuity and, for planar families, by the winding numbers about both primaries."""

    scale = np.ones(3)

    def __init__(self, system: System, *, spatial: bool, family: str, t_max: float, check_geometry: bool, parameter: str = "x0"):
        self.system, self.spatial, self.family, self.t_max = system, spatial, family, t_max
        self.check_geometry = check_geometry
        self.parameter_index = _VAR_INDEX[parameter]
        self.geometries: dict[int, Geometry | None] = {}

    def point(self, orbit: PeriodicOrbit) -> Point:
        if id(orbit) not in self.geometries:
            self.geometries[id(orbit)] = geometry(orbit) if self.check_geometry else None
        return Point(_p(orbit), orbit, orbit.iterations)

    def correct(self, guess: np.ndarray, c: Constraint) -> Point:
        k = c.fixed_index
        if k is not None:
            kind, values = "fix", [k, c.b]
        else:  # a . p = b, as the core's arclength condition t . (p - p_k) = ds with p_k = 0
            kind, values = "arclength", [0.0, 0.0, 0.0, *c.a, c.b]
        orbit = _correct(self.system, guess, self.spatial, kind, values, self.family, self.t_max)
        return Point(_p(orbit), orbit, orbit.iterations)

    def tangent(self, pt: Point) -> np.ndarray:
        return tangent(pt.data, self.spatial)

    def tests(self, pt: Point) -> dict[str, float]:
        """Bifurcation tests: each stability index minus +-1 (:func:`librate.orbits.periodic.index_tests`),
        from the monodromy the half-period correction gives (no extra propagation)."""
        m = symmetric_monodromy(pt.data)
        if m is None:
            return {}
        return index_tests(_core.stability(np.ascontiguousarray(m), not self.spatial)[1], self.spatial)

    def guard(self, points: list[Point], new: Point, ratio: float) -> str | None:
        if not _smooth([p.data for p in points], new.data, ratio):
            return "Jacobi constant or period jump"
        if not self.check_geometry:
            return None
        g = geometry(new.data)
        self.geometries[id(new.data)] = g
        last = self.geometries.get(id(points[-1].data)) if points else None
        # Winding numbers of the projection on the x-y plane are invariants of planar families
        # only: a 3-D orbit (a halo whose perilune passes beneath the Moon) changes them smoothly.
        if new.data.planar and last is not None and g.winding != last.winding:
            return f"winding numbers changed {last.winding} -> {g.winding}"
        return None


def _result(problem: SymmetricFamilyProblem, branch: Branch, points: list[Point]) -> ContinuationResult:
    members = [p.data for p in points]
    return ContinuationResult(members, [problem.geometries.get(id(m)) for m in members], branch.end_reason, branch.rejected_jumps,
                              bifurcations=list(branch.bifurcations))


def _stop(problem, stop, progress=None, total: int = 0):
    """The driver's per-point hook: the family's ``stop(orbit, geometry)`` and ``progress(done,
    total)`` after each accepted member (total: the requested members, or the most the run
    may take)."""
    if stop is None and progress is None:
        return None
    count = [1]

    def hook(pt):
        count[0] += 1
        if progress is not None:
            progress(min(count[0], total), total)
        return stop(pt.data, problem.geometries.get(id(pt.data))) if stop is not None else None

    return hook


def continue_natural(
    system: System,
    first: PeriodicOrbit,
    var: str,
    values,
    *,
    spatial: bool = False,
    family: str = "symmetric",
    min_step: float = 1e-6,
    check_geometry: bool = True,
    stop: Callable[[PeriodicOrbit, Geometry | None], str | None] | None = None,
    t_max: float = 50.0,
    progress: Callable[[int, int], None] | None = None,
) -> ContinuationResult:
    """Natural-parameter continuation in ``var`` ("x0", "z0" or "vy0") through ``values``
    (thesis eq. 20-22), by the continuation driver (:func:`librate.solving.continuation.natural`):
    the other unknowns extrapolated linearly from the last two members, the step halved on a
    failed correction or a detected jump (Jacobi-constant or period discontinuity, change of
    winding numbers, a corrected point far from its prediction) and grown back after a
    success; the members returned are exactly at ``values``. Ends after the last value, at a
    ``stop`` reason, or when the step falls below ``min_step`` (with the reason).
    """
    progress = as_progress(progress, f"{family} family", "member")
    problem = SymmetricFamilyProblem(system, spatial=spatial, family=family, t_max=t_max, check_geometry=check_geometry, parameter=var)
    total = int(np.size(values))
    br = natural(problem, problem.point(first), values, rules=StepRules(ds_min=min_step, ds_max=max(min_step, 1.0)), name=var,
                 stop=_stop(problem, stop, progress, total))
    if progress is not None:
        progress(total, total)
    return _result(problem, br, br.points)


def continue_arclength(
    system: System,
    first: PeriodicOrbit,
    *,
    spatial: bool,
    orient: np.ndarray,
    ds: float = 1e-3,
    ds_min: float = 1e-7,
    ds_max: float = 2e-2,
    max_members: int = 500,
    family: str = "symmetric",
    check_geometry: bool = True,
    stop: Callable[[PeriodicOrbit, Geometry | None], str | None] | None = None,
    t_max: float = 50.0,
    progress: Callable[[int, int], None] | None = None,
) -> ContinuationResult:
    """Pseudo-arclength continuation in p = (x0, z0, vy0), through folds, by the continuation
    driver (:func:`librate.solving.continuation.arclength`): predictor along the tangent,
    corrector with the arclength condition, the driver's step rules (growth by 1.5 after an
    easy correction, halving on failure or a detected jump) and this family's guards; ends when
    the step falls below ``ds_min``, at ``max_members``, or when ``stop`` returns a reason.
    ``progress(done, total)`` after each member (total: ``max_members``, the found count at the end).
    """
    progress = as_progress(progress, f"{family} family", "member")
    problem = SymmetricFamilyProblem(system, spatial=spatial, family=family, t_max=t_max, check_geometry=check_geometry)
    rules = StepRules(ds=ds, ds_min=ds_min, ds_max=ds_max, jump=0.5, max_turn=0.5)
    br = arclength(problem, problem.point(first), direction=np.asarray(orient, dtype=float), rules=rules, max_points=max_members,
                   name="x0", stop=_stop(problem, stop, progress, max_members))
    if progress is not None:
        progress(len(br.points), len(br.points))
    return _result(problem, br, br.points)
