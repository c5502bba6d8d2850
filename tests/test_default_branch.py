"""Default calls land on the documented branch: ``periodic_attitude(orbit, kz=..., n=...)`` with
no guess returns the member of the N family continued in Kz from Kz = 0 (where wz0 = 1 + 2 pi N/T
is the unique solution).

Reference: tests/data/kz_branches.json, an independent table made by
tests/data/make_kz_branches.py (scipy DOP853 at 1e-12 on the 6-state system with the
gravity gradient in its angle form, secant shooting, natural continuation in Kz by 0.01 from 0):
four DROs (x0 = 0.85, 0.7, 0.5, 0.3) and the 1:2 and 1:4 Sun-resonant DROs over K = 2 and 4
periods, N = -1, 0, 1 turns per orbit period, Kz in {0.2, 0.5, 0.6, 0.8}. Tolerance: 1e-8 on
wz0 (the two independent integrations agree to ~1e-11). The slow test re-integrates returned
solutions with scipy and checks their periodicity to 1e-8.
"""

import json
import math
from pathlib import Path

import librate
import numpy as np
import pytest
from scipy.integrate import solve_ivp

TABLE = json.loads((Path(__file__).parent / "data" / "kz_branches.json").read_text())
EM = librate.System.preset("earth-moon")
CASES = [(r["orbit"], r["n"], kz) for r in TABLE["rows"] for kz in r["wz0"]]


def _row(name, n):
    return next(r for r in TABLE["rows"] if r["orbit"] == name and r["n"] == n)


def _orbit(row):
    s = np.array(row["state0"])
    return librate.PeriodicOrbit(EM, s, row["period"], EM.jacobi(s), "dro")


@pytest.mark.parametrize("name,n,kz", CASES)
def test_default_lands_on_the_kz_continued_branch(name, n, kz):
    row = _row(name, n)
    sol = librate.periodic_attitude(_orbit(row), kz=float(kz), n=n, n_periods=row["n_periods"])
    assert abs(sol.wz0 - row["wz0"][kz]) < 1e-8, (sol.wz0, row["wz0"][kz])
    assert sol.n == n and sol.n_total == n * row["n_periods"]
    assert sol.residual < 1e-9


def test_sun_resonant_1_4_from_the_issue():
    """The 1:4 Sun-resonant DRO, Kz = 0.6, N = 0 over K = 4 periods: near 2.059, not the
    torque-free start wz0 = 1 (it used to raise ConvergenceError)."""
    row = _row("sun 1:4", 0)
    sol = librate.periodic_attitude(_orbit(row), kz=0.6, n=0, n_periods=4)
    assert abs(sol.wz0 - 2.0591822174621) < 1e-8


def _scipy_closure(orbit, kz, phi0, wz0, t_final):
    mu = EM.mu

    def f(t, s):
        x, y, xd, yd, phi, wz = s
        x1, x2 = x + mu, x - 1 + mu
        r1, r2 = math.hypot(x1, y), math.hypot(x2, y)
        a1, a2 = (1 - mu) / r1**3, mu / r2**3
        th1, th2 = math.atan2(y, x1), math.atan2(y, x2)
        return [xd, yd, x - a1 * x1 - a2 * x2 + 2 * yd, y - a1 * y - a2 * y - 2 * xd, wz - 1.0,
                1.5 * kz * (a1 * math.sin(2 * (th1 - phi)) + a2 * math.sin(2 * (th2 - phi)))]

    s0 = orbit.state0
    sol = solve_ivp(f, (0, t_final), [s0[0], s0[1], s0[3], s0[4], phi0, wz0], method="DOP853", rtol=1e-12, atol=1e-12)
    return sol.y[4, -1], sol.y[5, -1]


@pytest.mark.slow
@pytest.mark.parametrize("name,n,kz", [("dro x0=0.7", -1, "0.8"), ("dro x0=0.3", 1, "0.5"), ("sun 1:2", 0, "0.6"), ("sun 1:4", 1, "0.2")])
def test_default_solutions_are_periodic_under_scipy(name, n, kz):
    row = _row(name, n)
    o = _orbit(row)
    k = row["n_periods"]
    sol = librate.periodic_attitude(o, kz=float(kz), n=n, n_periods=k)
    phi_t, wz_t = _scipy_closure(o, float(kz), sol.phi0, sol.wz0, k * o.period)
    assert abs(phi_t - sol.phi0 - 2 * math.pi * n * k) < 1e-8
    assert abs(wz_t - sol.wz0) < 1e-8
