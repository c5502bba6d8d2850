"""Fourier-series orbits (thesis eq. 44-45, Fig. 22; docs/physics.md, periodic orbits) against the integrated
orbit, an independent integrator and the CR3BP equations of motion."""

import math

import librate
import numpy as np
import pytest
from helpers import cr3bp_rhs, dro_with_period
from scipy.integrate import solve_ivp


def jacobi_numpy(mu, states):
    """C = 2U - |v|^2 written from docs/physics.md, the CR3BP (independent of the core's jacobi)."""
    x, y, z = states[:, 0], states[:, 1], states[:, 2]
    r1 = np.sqrt((x + mu) ** 2 + y**2 + z**2)
    r2 = np.sqrt((x - 1 + mu) ** 2 + y**2 + z**2)
    u = 0.5 * (x**2 + y**2) + (1 - mu) / r1 + mu / r2
    return 2 * u - np.sum(states[:, 3:] ** 2, axis=1)


@pytest.fixture(scope="module")
def dro_1992(em):
    """The DRO of period 19.92 days (thesis Fig. 22): x0 = 0.72257 in earth-moon."""
    return dro_with_period(em, em.from_days(19.92), np.arange(0.95, 0.6, -0.02))


@pytest.fixture(scope="module")
def dro_21(em):
    """The 21-day DRO of the issue's note: x0 = 0.70205."""
    return dro_with_period(em, em.from_days(21.0), np.arange(0.95, 0.6, -0.02))


def test_jacobi_error_falls_with_harmonics_fig22(em, dro_1992):
    """Thesis Fig. 22 (DRO with T = 19.92 d): the relative Jacobi-constant error of the series,
    max over t of |C(t) - C0| / C0 with C from the series' position and velocity, is about 1e-2
    at Nf = 3 and falls fast with Nf.

    Measured (1024 samples, error at the 1024 midpoints): Nf = 1: 3.6e-2, 2: 1.5e-2, 3: 4.4e-3,
    5: 7.8e-4, 10: 2.5e-5, 15: 1.1e-6, 16: 6.0e-7 (the first below 1e-6, chosen by default),
    20: 5.6e-8, 30: 1.6e-10, 40: 5e-13: geometric decay by about 0.56 per harmonic.
    Asserted: 2e-3 < error(Nf = 3) < 5e-2 (the order of magnitude read off Fig. 22), strictly
    decreasing up to the chosen Nf, which is at most 20 and the first below jacobi_tol = 1e-6.
    """
    assert dro_1992.period_days == pytest.approx(19.92, abs=1e-9)
    fit = librate.fit_fourier(em, dro_1992.state0, dro_1992.period)
    h = fit.jacobi_history
    assert fit.n_harmonics == len(h) <= 20
    assert 2e-3 < h[2] < 5e-2
    assert np.all(np.diff(h) < 0)
    assert h[-1] < 1e-6 <= h[-2]
    assert fit.jacobi_error == h[-1]
    # The same error from an independent Jacobi constant and a fresh time grid (tolerance: the
    # fresh grid may find a slightly larger maximum, within 20 %).
    t = np.linspace(0.0, dro_1992.period, 3001)
    c = jacobi_numpy(em.mu, fit.state(t))
    err = np.max(np.abs(c - dro_1992.jacobi) / dro_1992.jacobi)
    assert err == pytest.approx(fit.jacobi_error, rel=0.2)
    # Nf = 20 and 30 keep falling (measured 5.6e-8 and 1.6e-10).
    e20 = librate.fit_fourier(em, dro_1992.state0, dro_1992.period, n_harmonics=20).jacobi_error
    e30 = librate.fit_fourier(em, dro_1992.state0, dro_1992.period, n_harmonics=30).jacobi_error
    assert 1e-8 < e20 < 1e-7 and e30 < 1e-9


def test_dro_series_has_the_symmetric_form(em, dro_1992):
    """Thesis eq. 44-45: for a DRO started on the x axis, x has only cosines and y only sines
    (and z = 0). The general fit finds the other coefficients at rounding level (measured
    3e-15 and 7e-15); tolerance 1e-12."""
    fit = librate.fit_fourier(em, dro_1992.state0, dro_1992.period, n_harmonics=25)
    assert np.max(np.abs(fit.sin[:, 0])) < 1e-12 and np.max(np.abs(fit.cos[:, 1])) < 1e-12
    assert abs(fit.a0[1]) < 1e-12
    assert np.all(fit.cos[:, 2] == 0) and np.all(fit.sin[:, 2] == 0) and fit.a0[2] == 0
    # Fundamental: x ~ a0 + a1 cos, y ~ c1 sin with a1 < 0 < c1, i.e. clockwise (retrograde)
    # about the centre a0, starting on the Earth side with ydot0 > 0.
    assert fit.cos[0, 0] < 0 < fit.sin[0, 1]
    assert fit.a0[0] + fit.cos[:, 0].sum() == pytest.approx(dro_1992.x0, abs=1e-8)


def test_twenty_term_series_of_21_day_dro_position_error(em, dro_21):
    """Issue 3's note: a 20-term series of a 21-day DRO still carries position errors near 1e-8.
    Reference: scipy DOP853 (rtol 1e-13, atol 1e-15) on the CR3BP written independently, at
    997 times not on the fit grid. Measured: max |r_series - r_ref| = 8.0e-9 LU (3.1 m), max
    |v_series - v_ref| = 2.3e-7. Asserted: the position error lies in [1e-9, 3e-8] (the order of
    the note) and the 30-term series is at least 100 times better (measured 2.3e-11)."""
    assert dro_21.period_days == pytest.approx(21.0, abs=1e-9)
    t = np.sort(np.random.default_rng(7).uniform(0.0, dro_21.period, 997))
    ref = solve_ivp(cr3bp_rhs(em.mu), (0.0, dro_21.period), dro_21.state0, method="DOP853", t_eval=t, rtol=1e-13, atol=1e-15)
    errs = {}
    for n in (20, 30):
        fit = librate.fit_fourier(em, dro_21.state0, dro_21.period, n_harmonics=n)
        errs[n] = np.max(np.linalg.norm(fit.position(t) - ref.y[:3].T, axis=1))
        # The fit's own out-of-sample estimate agrees with the independent one within a factor 2.
        assert 0.5 < fit.position_error / errs[n] < 2.0
    assert 1e-9 < errs[20] < 3e-8
    assert errs[30] < errs[20] / 100


def test_series_derivatives_follow_the_cr3bp_vector_field(em, dro_1992):
    """Velocity and acceleration from the series are the exact derivatives of the series, so on
    a converged series they must satisfy the equations of motion: the series' acceleration
    against the CR3BP right-hand side (helpers.cr3bp_rhs, written from docs/physics.md) evaluated at
    the series' own position and velocity, at 777 times. Measured max residual: 3.7e-6 at Nf = 20,
    1.6e-8 at 30, 7e-11 at 40; velocity against the integrated orbit 1.4e-12 at 40.
    Tolerances: 1e-5 at 20, 1e-9 at 40, velocity 1e-10 at 40."""
    t = np.linspace(0.0, dro_1992.period, 777)
    rhs = cr3bp_rhs(em.mu)
    residual = {}
    for n in (20, 40):
        fit = librate.fit_fourier(em, dro_1992.state0, dro_1992.period, n_harmonics=n)
        p, v, a = fit.evaluate(t)
        eom = np.array([rhs(0.0, s)[3:] for s in np.hstack([p, v])])
        residual[n] = np.max(np.abs(a - eom))
        assert np.array_equal(fit.state(t), np.hstack([p, v]))
        assert np.allclose(fit.acceleration(t), a, rtol=1e-14, atol=1e-14)
    assert residual[20] < 1e-5 and residual[40] < 1e-9
    assert fit.velocity_error < 1e-10


def test_fit_does_not_depend_on_the_sample_count(em, dro_1992):
    """Aliasing check: the least-squares coefficients with 512 and 4096 samples agree to 1e-12
    (the harmonics beyond 256 are below rounding for this orbit)."""
    f1 = librate.fit_fourier(em, dro_1992.state0, dro_1992.period, n_harmonics=30, n_samples=512)
    f2 = librate.fit_fourier(em, dro_1992.state0, dro_1992.period, n_harmonics=30, n_samples=4096)
    for a, b in ((f1.a0, f2.a0), (f1.cos, f2.cos), (f1.sin, f2.sin)):
        assert np.max(np.abs(a - b)) < 1e-12


def test_hand_built_series_evaluates_like_numpy():
    """A hand-built series (every kind of term) evaluated in Rust against the same formula and
    its derivatives in numpy, at scalar, 1-D and 2-D times; tolerance 1e-13."""
    period = 2.7
    a0 = [0.1, -0.2, 0.3]
    cos = [[0.5, 0.01, 0.02], [0.03, -0.04, 0.0]]
    sin = [[0.0, -0.6, 0.05], [0.002, 0.0, -0.01]]
    f = librate.FourierOrbit(period, a0, cos, sin)
    assert f.n_harmonics == 2 and f.jacobi_error is None

    def ref(t):
        t = np.asarray(t, dtype=float)[..., None]
        p, v, a = np.array(a0) + 0 * t, 0 * t, 0 * t
        for n in (1, 2):
            w = 2 * math.pi * n / period
            c, s = np.cos(w * t), np.sin(w * t)
            an, cn = np.array(cos[n - 1]), np.array(sin[n - 1])
            p = p + an * c + cn * s
            v = v + w * (-an * s + cn * c)
            a = a - w * w * (an * c + cn * s)
        return p, v, a

    for t in (0.3, np.linspace(-5, 9, 41), np.linspace(0, 3, 12).reshape(3, 4)):
        p, v, a = ref(t)
        assert f.position(t).shape == np.shape(t) + (3,)
        assert f.state(t).shape == np.shape(t) + (6,)
        assert np.allclose(f.position(t), p, rtol=0, atol=1e-13)
        assert np.allclose(f.velocity(t), v, rtol=0, atol=1e-13)
        assert np.allclose(f.acceleration(t), a, rtol=0, atol=1e-13)
    g = f.truncated(1)
    assert g.n_harmonics == 1 and np.array_equal(g.cos, f.cos[:1])


def test_bad_arguments(em, dro_085):
    with pytest.raises(ValueError, match="`period`"):
        librate.FourierOrbit(-1.0, [0, 0, 0], np.zeros((1, 3)), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="`cos`"):
        librate.FourierOrbit(1.0, [0, 0, 0], np.zeros((1, 2)), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="`sin`"):
        librate.FourierOrbit(1.0, [0, 0, 0], np.zeros((2, 3)), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="`a0`"):
        librate.FourierOrbit(1.0, [0, 0], np.zeros((1, 3)), np.zeros((1, 3)))
    f = librate.FourierOrbit(1.0, [0, 0, 0], np.zeros((1, 3)), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="`t`"):
        f.position([0.0, math.nan])
    with pytest.raises(ValueError, match="`n_harmonics`"):
        f.truncated(2)
    s0, T = dro_085.state0, dro_085.period
    with pytest.raises(ValueError, match="`n_harmonics`"):
        librate.fit_fourier(em, s0, T, n_harmonics=0)
    with pytest.raises(ValueError, match="`n_samples`"):
        librate.fit_fourier(em, s0, T, n_harmonics=10, n_samples=40)
    with pytest.raises(ValueError, match="`jacobi_tol`"):
        librate.fit_fourier(em, s0, T, jacobi_tol=0.0)
    with pytest.raises(ValueError, match="`period`"):
        librate.fit_fourier(em, s0, -T)
    with pytest.raises(ValueError, match="state0"):
        librate.fit_fourier(em, s0, 0.9 * T)  # not a period: the orbit does not close
    with pytest.raises(librate.ConvergenceError) as info:
        librate.fit_fourier(em, s0, T, jacobi_tol=1e-9, max_harmonics=3)
    assert info.value.iterations == 3 and info.value.residual > 1e-9 and info.value.tolerance == 1e-9
