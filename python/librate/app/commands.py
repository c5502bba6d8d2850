"""The computing behind the small command-line commands (the CLI parses and prints; this
module computes): each function takes plain arguments and returns or yields results."""

from __future__ import annotations

import time
from collections.abc import Iterator, Sequence

import numpy as np

__all__ = ["dro_closures"]


def dro_closures(system, xs: Sequence[float]) -> Iterator[tuple[float, object, float, float]]:
    """For each x0 of ``xs``: the DRO corrected by half-period shooting (its ydot0 seeds the
    next one), propagated over one whole period at rtol = atol = 1e-13; yields (x0, orbit,
    closure = max |state(T) - state(0)|, seconds). Raises ValueError for an x0 outside the
    primaries, and the correction's LibrateError."""
    from ..orbits.families import correct_dro
    from ..orbits.propagation import propagate

    lo, hi = -system.mu, 1.0 - system.mu
    for x0 in xs:
        if not lo < x0 < hi:
            raise ValueError(f"--x0 {x0:g}: a DRO starts between the primaries, {lo:.6g} < x0 < {hi:.6g} LU (Earth at -mu, Moon at 1 - mu)")
    guess = None
    for x0 in xs:
        t_start = time.perf_counter()
        orbit = correct_dro(system, x0, guess)
        one = propagate(system, orbit.state0, orbit.period, rtol=1e-13, atol=1e-13, t_eval=[orbit.period], collision="point")
        yield x0, orbit, float(np.max(np.abs(one.y[-1] - orbit.state0))), time.perf_counter() - t_start
        guess = orbit.state0[4]
