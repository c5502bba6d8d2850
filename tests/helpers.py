"""Shared test helpers (independent references)."""

import librate


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
    """Independent CR3BP right-hand side for scipy (written from PHYSICS.md section 2)."""

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
