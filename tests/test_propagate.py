"""Propagation against independent references: scipy's DOP853, conserved quantities, finite
differences, analytic event times."""

import math

import librate
import numpy as np
import pytest
from helpers import cr3bp_rhs
from scipy.integrate import solve_ivp


def test_matches_scipy_dop853(em):
    """librate (RKF7(8), rtol = atol = 1e-13) and scipy DOP853 (rtol = 1e-13, atol = 1e-15) agree
    on a 3-D trajectory over 3 TU to 1e-9 (two independent integrators)."""
    s0 = np.array([0.82, 0.0, 0.05, 0.0, 0.52, 0.01])
    ours = librate.propagate(em, s0, 3.0, rtol=1e-13, atol=1e-13).y_final
    ref = solve_ivp(cr3bp_rhs(em.mu), (0, 3.0), s0, method="DOP853", rtol=1e-13, atol=1e-15).y[:, -1]
    assert np.max(np.abs(ours - ref)) < 1e-9


def test_jacobi_drift_over_ten_periods(em, dro_085):
    """Jacobi constant of a Moon-bound DRO over ten periods at rtol = atol = 1e-13: drift < 1e-12."""
    tr = librate.propagate(em, dro_085.state0, 10 * dro_085.period, rtol=1e-13, atol=1e-13)
    assert tr.status == "completed" and len(tr.t) > 100
    drift = np.max(np.abs(tr.jacobi - dro_085.jacobi))
    assert drift < 1e-12


def test_stm_against_central_differences(em, dro_085):
    """STM over one DRO period vs central differences of the flow (relative 1e-6), det = 1 to 1e-10
    (Liouville), and the monodromy eigenvalues in reciprocal pairs (symplectic)."""
    T = dro_085.period
    m = librate.propagate(em, dro_085.state0, T, stm=True, rtol=1e-13, atol=1e-13).stm
    assert m.shape == (6, 6)
    d = 1e-6
    fd = np.empty((6, 6))
    for j in range(6):
        e = np.zeros(6)
        e[j] = d
        plus = librate.propagate(em, dro_085.state0 + e, T, rtol=1e-13, atol=1e-13).y_final
        minus = librate.propagate(em, dro_085.state0 - e, T, rtol=1e-13, atol=1e-13).y_final
        fd[:, j] = (plus - minus) / (2 * d)
    assert np.linalg.norm(m - fd) / np.linalg.norm(m) < 1e-6
    assert abs(np.linalg.det(m) - 1) < 1e-10
    lam = np.linalg.eigvals(m)
    # each eigenvalue's reciprocal is also an eigenvalue
    for z in lam:
        assert np.min(np.abs(lam - 1 / z)) < 1e-6


def test_event_half_period_and_scipy_event_time(em, dro_085):
    """The corrected DRO crosses y = 0 downward at T/2 perpendicularly (|xdot| < 1e-11); the event
    time agrees with scipy's event location to 1e-10."""
    ev = librate.Event.crossing("y", 0.0, direction=-1, terminal=True)
    tr = librate.propagate(em, dro_085.state0, 10.0, stm=True, events=[ev], rtol=1e-13, atol=1e-13)
    assert tr.status == "event" and tr.event_index == 0
    hit = tr.events[0]
    assert hit.t == pytest.approx(dro_085.period / 2, abs=1e-12)
    assert abs(hit.y[3]) < 1e-11 and hit.stm.shape == (6, 6)
    assert tr.t_final == hit.t and tr.t[-1] == hit.t

    def g(t, s):
        return s[1]

    g.terminal, g.direction = True, -1
    ref = solve_ivp(cr3bp_rhs(em.mu), (0, 10), dro_085.state0, method="DOP853", rtol=1e-13, atol=1e-15, events=g)
    assert abs(ref.t_events[0][0] - hit.t) < 1e-10


def test_non_terminal_events_in_both_directions(em, dro_085):
    """Over three periods, a non-terminal y = 0 event fires at T/2, T, 3T/2, ... (5 crossings after
    the start, which does not count); direction filtering keeps every other one."""
    T = dro_085.period
    both = librate.propagate(em, dro_085.state0, 3 * T - 0.1, events=[librate.Event.crossing("y")])
    times = [e.t for e in both.events]
    np.testing.assert_allclose(times, [T / 2, T, 1.5 * T, 2 * T, 2.5 * T], atol=1e-9)
    up = librate.propagate(em, dro_085.state0, 3 * T - 0.1, events=[librate.Event.crossing(1, direction=+1)])
    np.testing.assert_allclose([e.t for e in up.events], [T, 2 * T], atol=1e-9)


def test_t_eval_and_backward(em, dro_085):
    """Output at requested times equals separate propagations to those times (1e-12); backward
    propagation from the final state returns to the start (1e-11)."""
    T = dro_085.period
    times = np.linspace(0, T, 7)
    tr = librate.propagate(em, dro_085.state0, T, t_eval=times, rtol=1e-13, atol=1e-13)
    np.testing.assert_array_equal(tr.t, times)
    for t, y in zip(times[1:], tr.y[1:]):
        direct = librate.propagate(em, dro_085.state0, t, rtol=1e-13, atol=1e-13).y_final
        assert np.max(np.abs(direct - y)) < 1e-12
    back = librate.propagate(em, tr.y_final, (T, 0.0), rtol=1e-13, atol=1e-13)
    assert np.max(np.abs(back.y_final - dro_085.state0)) < 1e-11


def test_fixed_step_mode(em, dro_085):
    """Fixed steps of T/200 reproduce the adaptive result to 1e-10 (8th order: error ~ h^8)."""
    T = dro_085.period
    fixed = librate.propagate(em, dro_085.state0, T, fixed_step=T / 200)
    assert fixed.stats.accepted == 200 and fixed.stats.rejected == 0
    adaptive = librate.propagate(em, dro_085.state0, T, rtol=1e-13, atol=1e-13)
    assert np.max(np.abs(fixed.y_final - adaptive.y_final)) < 1e-10


def test_surface_event_stops_a_fall_into_the_moon(em):
    """From rest at r0 = 0.01 LU from the Moon, the fall reaches the surface R = 1737.4 km after the
    radial Kepler time sqrt(r0^3 / (2 mu)) [sqrt(x (1 - x)) + arccos(sqrt(x))], x = R / r0
    (within 1 %: the Earth's tide and the frame's rotation perturb it)."""
    s0 = [1 - em.mu - 0.01, 0, 0, 0, 0, 0]
    tr = librate.propagate(em, s0, 1.0, events=[librate.Event.surface("moon")])
    assert tr.status == "event"
    r = np.linalg.norm(tr.y_final[:3] - [1 - em.mu, 0, 0])
    assert r == pytest.approx(1737.4 / 384400.0, abs=1e-12)
    x = (1737.4 / 384400.0) / 0.01
    t_fall = math.sqrt(0.01**3 / (2 * em.mu)) * (math.sqrt(x * (1 - x)) + math.acos(math.sqrt(x)))
    assert tr.t_final == pytest.approx(t_fall, rel=0.01)


def test_integration_error_carries_context(em, dro_085):
    with pytest.raises(librate.IntegrationError) as info:
        librate.propagate(em, dro_085.state0, 100.0, max_steps=10)
    err = info.value
    assert isinstance(err, librate.LibrateError)
    assert err.steps == 10 and 0 < err.t < 100 and err.kind == "max_steps_exceeded"
    assert "t =" in str(err)


def test_batch_identical_to_single_calls_for_any_thread_count(em, dro_085):
    """propagate_many is bit-identical to propagate, with 1, 2 or all threads."""
    rng = np.random.default_rng(7)
    states = np.tile(dro_085.state0, (64, 1)) + rng.normal(scale=1e-3, size=(64, 6))
    runs = [librate.propagate_many(em, states, 2.0, stm=True, threads=n) for n in (1, 2, None)]
    for r in runs[1:]:
        np.testing.assert_array_equal(r.y, runs[0].y)
        np.testing.assert_array_equal(r.stm, runs[0].stm)
    for i in (0, 17, 63):
        single = librate.propagate(em, states[i], 2.0, stm=True)
        np.testing.assert_array_equal(runs[0].y[i], single.y_final)
        np.testing.assert_array_equal(runs[0].stm[i], single.stm)
    assert runs[0].ok.all() and runs[0].stats.shape == (64, 3)
    # per-state final times
    tf = np.linspace(0.5, 2.0, 64)
    r = librate.propagate_many(em, states, tf)
    np.testing.assert_array_equal(r.y[5], librate.propagate(em, states[5], tf[5]).y_final)


def test_batch_failure_keeps_the_other_members(em, dro_085):
    states = np.tile(dro_085.state0, (5, 1))
    t_final = [1.0, 1.0, 1000.0, 1.0, 1.0]  # member 2 needs far more than max_steps
    masked = librate.propagate_many(em, states, t_final, on_error="mask", max_steps=2000)
    assert masked.ok.tolist() == [True, True, False, True, True]
    assert np.isnan(masked.y[2]).all() and np.isfinite(masked.y[[0, 1, 3, 4]]).all()
    assert isinstance(masked.errors[2], librate.IntegrationError)
    with pytest.raises(librate.IntegrationError) as info:
        librate.propagate_many(em, states, t_final, max_steps=2000)
    kept = info.value.batch_result
    np.testing.assert_array_equal(kept.y[[0, 1, 3, 4]], masked.y[[0, 1, 3, 4]])
