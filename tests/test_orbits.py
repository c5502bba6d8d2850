"""DRO correction against the thesis/docs/physics.md facts and an independent integrator."""

import math

import librate
import numpy as np
import pytest
from helpers import continue_dros, cr3bp_rhs
from scipy.integrate import solve_ivp


@pytest.mark.parametrize("x0", [0.95, 0.9, 0.8])
def test_corrected_dro_closes_in_scipy(em, x0):
    """The corrected initial state is periodic when propagated by an independent integrator
    (scipy DOP853 at rtol = 1e-13): closure after one period below 1e-9."""
    orbit = librate.correct_dro(em, x0)
    assert orbit.residual < 1e-12 and orbit.state0[4] > 0
    ref = solve_ivp(cr3bp_rhs(em.mu), (0, orbit.period), orbit.state0, method="DOP853", rtol=1e-13, atol=1e-15)
    assert np.max(np.abs(ref.y[:, -1] - orbit.state0)) < 1e-9
    assert orbit.jacobi == pytest.approx(em.jacobi(orbit.state0), abs=0)


def test_one_to_one_resonant_dro_starts_at_x0_0_1521(em):
    """docs/physics.md / thesis Fig. 7: the DRO whose period is the synodic 2 pi starts at x0 = 0.1521
    (4 digits). Continue the family from the Moon, root-find T(x0) = 2 pi by the secant method,
    and compare at the printed precision."""
    orbits = continue_dros(em, np.arange(0.95, 0.14, -0.02))
    periods = np.array([o.period for o in orbits])
    assert np.all(np.diff(periods) > 0)  # the period grows monotonically as x0 decreases
    k = int(np.argmax(periods > 2 * math.pi))
    (xa, va), (xb, vb) = [(o.x0, o.state0[4]) for o in orbits[k - 1 : k + 1]]
    ta, tb = periods[k - 1], periods[k]
    for _ in range(20):
        x = xb + (2 * math.pi - tb) * (xb - xa) / (tb - ta)
        guess = vb + (vb - va) / (xb - xa) * (x - xb)
        o = librate.correct_dro(em, x, guess)
        (xa, va, ta), (xb, vb, tb) = (xb, vb, tb), (x, o.state0[4], o.period)
        if abs(tb - 2 * math.pi) < 1e-12:
            break
    assert round(xb, 4) == 0.1521
    assert o.period_days == pytest.approx(27.28, abs=0.01)


def test_convergence_error_is_typed(em):
    with pytest.raises(librate.ConvergenceError) as info:
        librate.correct_dro(em, 0.3, 0.3, max_iter=2)
    assert info.value.iterations >= 1 and info.value.residual > 0


def test_correct_dro_far_from_the_moon_is_a_dro(em):
    """Issue 11: correct_dro(em, 0.7) returned an orbit about the Earth (T = 10.79) labelled
    "dro". Reference: the DRO family member at x0 = 0.7 (librate.dro, by continuation from the
    Moon), T = 4.859 TU, to 1e-10; and a ydot0 guess that converges to the Earth orbit raises."""
    o = librate.correct_dro(em, 0.7)
    ref = librate.dro(em, x0=0.7)
    assert o.family == "dro" and abs(o.period - ref.period) < 1e-10 and abs(o.period - 4.8588) < 1e-3
    assert librate.orbits.geometry(o).winding == (0, -1)
    with pytest.raises(librate.ConvergenceError, match=r"not a DRO.*\(1, 0\)"):
        librate.correct_dro(em, 0.7, 0.5393417437774825)
