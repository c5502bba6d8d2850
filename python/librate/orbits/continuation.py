"""Continuation of symmetric periodic-orbit families (thesis eq. 20-22 and pseudo-arclength).

The numerical kernels (shooting with the STM and event location) are in Rust; this module runs
the continuation loop: prediction, correction, guards against silent jumps to another family,
adaptive steps and clean termination with a reason.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._errors import LibrateError
from .periodic import SHOOT_ATOL, SHOOT_RTOL, PeriodicOrbit, orbit_from_core
from .system import System

__all__ = ["Geometry", "geometry", "continue_natural", "continue_arclength", "ContinuationResult"]

_VAR_INDEX = {"x0": 0, "z0": 1, "vy0": 2}


@dataclass(frozen=True)
class Geometry:
    """Winding numbers of an orbit about each primary and its closest approach to each."""

    winding: tuple[int, int]
    min_distance: tuple[float, float]


def geometry(orbit: PeriodicOrbit) -> Geometry:
    """Winding numbers (signed turns of the projected position about each primary over one
    period) and closest approaches, from the integrated orbit."""
    tr = orbit.propagate(rtol=1e-11, atol=1e-11)
    y = tr.y
    wind, dmin = [], []
    for c in orbit.system.primary_positions():
        rel = y[:, :3] - c
        ang = np.unwrap(np.arctan2(rel[:, 1], rel[:, 0]))
        wind.append(int(round((ang[-1] - ang[0]) / (2 * math.pi))))
        dmin.append(float(np.min(np.linalg.norm(rel, axis=1))))
    return Geometry((wind[0], wind[1]), (dmin[0], dmin[1]))


@dataclass
class ContinuationResult:
    members: list[PeriodicOrbit]
    geometries: list[Geometry]
    end_reason: str
    rejected_jumps: int = 0
    extra: dict = field(default_factory=dict)


def _correct(system: System, p, spatial: bool, kind: str, values, family: str, t_max: float) -> PeriodicOrbit:
    r = _core.symmetric_correct(
        system.mu, [float(v) for v in p], spatial=spatial, constraint=kind, values=[float(v) for v in values],
        tol=1e-12, max_iter=25, t_max=t_max, rtol=SHOOT_RTOL, atol=SHOOT_ATOL,
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


def _guarded(system, history, geoms, new, ratio, check_geometry) -> tuple[bool, Geometry | None]:
    if not _smooth(history, new, ratio):
        return False, None
    if not check_geometry:
        return True, None
    g = geometry(new)
    # Winding numbers of the projection on the x-y plane are invariants of planar families
    # only: a 3-D orbit (a halo whose perilune passes beneath the Moon) changes them smoothly.
    if new.planar and geoms and geoms[-1] is not None and g.winding != geoms[-1].winding:
        return False, g
    return True, g


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
) -> ContinuationResult:
    """Natural-parameter continuation in ``var`` ("x0", "z0" or "vy0") through ``values``
    (thesis eq. 20-22: the other unknowns extrapolated linearly from the last two members).

    Between requested values the step is halved on a failed correction or a detected jump
    (Jacobi-constant or period discontinuity, change of winding numbers) and grows back after
    a success; the members returned are exactly at ``values``. Ends after the last value, at a
    ``stop`` reason, or when the step falls below ``min_step`` (with the reason).
    """
    k = _VAR_INDEX[var]
    history = [first]  # every corrected member, intermediate ones included (for extrapolation)
    g0 = geometry(first) if check_geometry else None
    geoms = [g0]
    out: list[PeriodicOrbit] = []
    geoms_out: list[Geometry | None] = []
    jumps = 0
    for target in (float(v) for v in np.atleast_1d(values)):
        cur = _p(history[-1])[k]
        if target == cur:
            out.append(history[-1])
            geoms_out.append(geoms[-1])
            continue
        h = target - cur
        while True:
            # snap to the target when the remaining step is (nearly) covered: no sliver steps
            trial = target if abs(h) >= abs(target - cur) * (1 - 1e-6) else cur + h
            status = _continue_one(system, history, geoms, k, trial, spatial, family, check_geometry, t_max)
            if status == "ok":
                why = stop(history[-1], geoms[-1]) if stop else None
                if why:
                    return ContinuationResult(out, geoms_out, why, jumps)
                cur = trial
                if trial == target:
                    out.append(history[-1])
                    geoms_out.append(geoms[-1])
                    break
                h *= 2.0
            else:
                jumps += status == "jump"
                h *= 0.5
                if abs(h) < min_step:
                    return ContinuationResult(
                        out, geoms_out, f"step floor: could not continue past {var} = {cur:.12g} (step below {min_step:g})", jumps
                    )
    return ContinuationResult(out, geoms_out, "completed: reached the last requested value", jumps)


def _continue_one(system, history, geoms, k, target, spatial, family, check_geometry, t_max) -> str:
    """Predict (linear extrapolation in the parameter), correct, guard; "ok", "fail" or "jump"."""
    pl = _p(history[-1])
    if len(history) >= 2:
        pp = _p(history[-2])
        dk = pl[k] - pp[k]
        guess = pl + (pl - pp) * ((target - pl[k]) / dk) if dk != 0 else pl.copy()
        prev_step = abs(dk)
    else:
        guess = pl.copy()
        prev_step = abs(target - pl[k])
    guess[k] = target
    try:
        orbit = _correct(system, guess, spatial, "fix", [k, target], family, t_max)
    except LibrateError:
        return "fail"
    ok, g = _guarded(system, history, geoms, orbit, abs(target - pl[k]) / max(prev_step, 1e-300), check_geometry)
    if not ok:
        return "jump"
    history.append(orbit)
    geoms.append(g)
    return "ok"


def tangent(orbit: PeriodicOrbit, spatial: bool, previous: np.ndarray | None = None, orient: np.ndarray | None = None) -> np.ndarray:
    """Unit tangent of the family at ``orbit`` in p = (x0, z0, vy0): the null vector of the
    symmetric conditions' Jacobian, oriented along ``previous`` (or ``orient``)."""
    e = orbit._evaluation
    d = np.array(e["dcond"], dtype=float)
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
) -> ContinuationResult:
    """Pseudo-arclength continuation in p = (x0, z0, vy0), through folds.

    Predictor p + ds * tangent, corrector with the arclength condition tangent . (p - p_k) = ds.
    ds grows by 1.5 after an easy correction (<= 3 iterations), is halved on failure or on a
    detected jump, and the run ends when ds falls below ``ds_min``, at ``max_members``, or when
    ``stop`` returns a reason.
    """
    members, geoms = [first], [geometry(first) if check_geometry else None]
    t = tangent(first, spatial, orient=np.asarray(orient, dtype=float))
    jumps = 0
    while len(members) < max_members:
        last = members[-1]
        pl = _p(last)
        ok = False
        while not ok:
            guess = pl + ds * t
            try:
                orbit = _correct(system, guess, spatial, "arclength", [*pl, *t, ds], family, t_max)
                ok, g = _guarded(system, members, geoms, orbit, 1.0, check_geometry)
                if not ok:
                    jumps += 1
            except LibrateError:
                ok = False
            if not ok:
                ds *= 0.5
                if ds < ds_min:
                    return ContinuationResult(members, geoms, f"step floor: arclength step below {ds_min:g} after {len(members)} members", jumps)
        members.append(orbit)
        geoms.append(g)
        why = stop(orbit, g) if stop else None
        if why:
            return ContinuationResult(members, geoms, why, jumps)
        try:
            t = tangent(orbit, spatial, previous=t)
        except LibrateError as err:
            return ContinuationResult(members, geoms, f"stopped: {err}", jumps)
        if orbit.iterations <= 3:
            ds = min(ds * 1.5, ds_max)
    return ContinuationResult(members, geoms, f"completed: max_members = {max_members} reached", jumps)
