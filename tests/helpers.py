"""Shared test helpers (independent references)."""

import copy

import librate


def edit(data: dict, key: str, value=...) -> dict:
    """``data`` with the dotted ``key`` set to ``value`` (deleted when value is omitted)."""
    out = copy.deepcopy(data)
    parts = key.split(".")
    d = out
    for p in parts[:-1]:
        d = d.setdefault(p, {})
    if value is ...:
        d.pop(parts[-1], None)
    else:
        d[parts[-1]] = value
    return out


def continue_dros(system, xs):
    """Natural-parameter continuation of DROs over decreasing x0 (linear extrapolation of ydot0,
    thesis eq. 20-22), returning the corrected orbits."""
    orbits, guess = [], None
    for x in xs:
        if len(orbits) >= 2:
            (x1, v1), (x2, v2) = [(o.x0, o.state0[4]) for o in orbits[-2:]]
            guess = v2 + (v2 - v1) / (x2 - x1) * (x - x2)
        orbits.append(librate.correct_dro(system, float(x), guess))
    return orbits


def cr3bp_rhs(mu):
    """Independent CR3BP right-hand side for scipy (written from docs/physics.md, the CR3BP)."""

    def f(t, s):
        x, y, z, vx, vy, vz = s
        r1 = ((x + mu) ** 2 + y * y + z * z) ** 1.5
        r2 = ((x - 1 + mu) ** 2 + y * y + z * z) ** 1.5
        return [
            vx,
            vy,
            vz,
            2 * vy + x - (1 - mu) * (x + mu) / r1 - mu * (x - 1 + mu) / r2,
            -2 * vx + y - (1 - mu) * y / r1 - mu * y / r2,
            -(1 - mu) * z / r1 - mu * z / r2,
        ]

    return f


def dro_with_period(system, period, xs):
    """The DRO of the given period (TU): continue DROs over the decreasing x0 grid ``xs`` (the
    period grows as x0 decreases), bracket ``period`` and refine x0 by the secant method on
    T(x0) - period, each member corrected from an extrapolated ydot0, until |T - period| < 1e-12."""
    import numpy as np

    orbits = continue_dros(system, xs)
    periods = np.array([o.period for o in orbits])
    if not periods[0] < period < periods[-1]:
        raise ValueError(f"period {period} is outside the continued range [{periods[0]}, {periods[-1]}]")
    k = int(np.argmax(periods > period))
    (xa, va, ta), (xb, vb, tb) = [(o.x0, o.state0[4], o.period) for o in orbits[k - 1 : k + 1]]
    o = orbits[k]
    for _ in range(30):
        x = xb + (period - tb) * (xb - xa) / (tb - ta)
        guess = vb + (vb - va) / (xb - xa) * (x - xb)
        o = librate.correct_dro(system, x, guess)
        (xa, va, ta), (xb, vb, tb) = (xb, vb, tb), (x, o.state0[4], o.period)
        if abs(tb - period) < 1e-12:
            return o
    raise RuntimeError(f"secant on the DRO period did not converge: |T - {period}| = {abs(tb - period):.2e}")
