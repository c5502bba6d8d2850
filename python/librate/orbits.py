"""Periodic orbits. For now: planar x-symmetric orbits (DROs) by half-period shooting."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import _core
from .system import System, resolve_system

__all__ = ["PeriodicOrbit", "correct_dro"]


@dataclass(frozen=True)
class PeriodicOrbit:
    """A corrected periodic orbit: initial state, period (TU), Jacobi constant, and how the
    correction ended (Newton iterations, final residual |xdot| at the half-period crossing)."""

    system: System
    state0: np.ndarray
    period: float
    jacobi: float
    iterations: int
    residual: float

    @property
    def x0(self) -> float:
        return float(self.state0[0])

    @property
    def period_days(self) -> float:
        return self.system.period_days(self.period)


def correct_dro(
    system: System | str,
    x0: float,
    ydot0: float | None = None,
    *,
    tol: float = 1e-12,
    max_iter: int = 30,
    rtol: float = 1e-13,
    atol: float = 1e-13,
) -> PeriodicOrbit:
    """Correct the distant retrograde orbit through (x0, 0, 0) with ydot0 > 0 (PHYSICS.md sec. 3).

    Single shooting on the half period (thesis eq. 19): integrate with the STM to the next
    y = 0 crossing, located in time, and drive xdot there to zero by correcting ydot0.
    ``x0`` must lie between the primaries (-mu < x0 < 1 - mu). Without ``ydot0`` the guess is
    a retrograde circle about the Moon seen in the rotating frame, sqrt(mu/d) + d with
    d = 1 - mu - x0: good near the Moon (d below about 0.2); farther out, pass a guess (for
    instance from a neighbouring member).

    Raises :class:`librate.ConvergenceError` if the correction does not converge.
    """
    sys_ = resolve_system(system)
    mu = sys_.mu
    if not (math.isfinite(x0) and -mu < x0 < 1.0 - mu):
        raise ValueError(f"invalid argument `x0`: a DRO starts between the primaries, -mu < x0 < 1 - mu = ({-mu}, {1 - mu}), got {x0!r}")
    if ydot0 is None:
        d = 1.0 - mu - x0
        ydot0 = math.sqrt(mu / d) + d
    if not (math.isfinite(ydot0) and ydot0 > 0):
        raise ValueError(f"invalid argument `ydot0`: must be finite and > 0 (retrograde about the Moon), got {ydot0!r}")
    if not isinstance(max_iter, int) or max_iter < 1:
        raise ValueError(f"invalid argument `max_iter`: must be an integer >= 1, got {max_iter!r}")
    state0, period, jc, iterations, residual = _core.correct_planar_symmetric(
        mu, float(x0), float(ydot0), crossing_direction=-1, tol=float(tol), max_iter=max_iter, rtol=float(rtol), atol=float(atol)
    )
    return PeriodicOrbit(sys_, state0, period, jc, iterations, residual)
