"""Systems, Lagrange points, Jacobi constant and units against independent values."""

import math

import librate
import numpy as np
import pytest


def test_presets_constants(em):
    # docs/physics.md table 1.
    assert (em.mu, em.lu_km, em.tu_s) == (0.01215, 384400.0, 375190.0)
    assert em.tu_days == pytest.approx(4.342477, abs=1e-6)
    jpl = librate.System.preset("earth-moon-jpl")
    assert jpl.mu == 1.215058560962404e-2
    assert set(librate.System.presets()) >= {"earth-moon", "earth-moon-jpl"}
    # One synodic revolution (2 pi TU) is the synodic month of the model: 27.28 d.
    assert em.period_days(2 * math.pi) == pytest.approx(27.2846, abs=1e-4)
    assert em.distance_km(1.0) == 384400.0 and em.from_km(384400.0) == 1.0
    assert em.from_days(em.period_days(3.0)) == pytest.approx(3.0, rel=1e-15)
    np.testing.assert_allclose(em.to_dimensional([1, 0, 0, 0, 1, 0]), [384400.0, 0, 0, 0, 384400.0 / 375190.0, 0])


def _collinear_independent(mu):
    """L1, L2, L3 from the classical quintics in gamma (Szebehely 1967), solved with numpy.roots."""

    def real_root(coeffs, lo, hi):
        r = [z.real for z in np.roots(coeffs) if abs(z.imag) < 1e-12 and lo < z.real < hi]
        assert len(r) == 1
        return r[0]

    g1 = real_root([1, -(3 - mu), 3 - 2 * mu, -mu, 2 * mu, -mu], 0, 1)
    g2 = real_root([1, 3 - mu, 3 - 2 * mu, -mu, -2 * mu, -mu], 0, 1)
    g3 = real_root([1, 2 + mu, 1 + 2 * mu, -(1 - mu), -2 * (1 - mu), -(1 - mu)], 0, 2)
    return 1 - mu - g1, 1 - mu + g2, -mu - g3


@pytest.mark.parametrize("mu", [0.01215, 1.215058560962404e-2, 3.0034e-6, 0.1, 0.5])
def test_lagrange_points_against_quintic_roots(mu):
    """Tolerance 1e-10 against an independent root solve (numpy.roots of the gamma quintics)."""
    sys_ = librate.System(mu=mu, lu_km=1.0, tu_s=1.0)
    lp = sys_.lagrange_points()
    assert lp.shape == (5, 3)
    np.testing.assert_allclose(lp[:3, 0], _collinear_independent(mu), atol=1e-10, rtol=0)
    np.testing.assert_allclose(lp[3], [0.5 - mu, math.sqrt(3) / 2, 0], atol=1e-15)
    np.testing.assert_allclose(lp[4], [0.5 - mu, -math.sqrt(3) / 2, 0], atol=1e-15)


def test_lagrange_points_physics_md_values(em):
    # docs/physics.md, the CR3BP: L1 0.83692, L2 1.15568, L3 -1.00506 (5 decimals printed).
    np.testing.assert_allclose(em.lagrange_points()[:3, 0], [0.83692, 1.15568, -1.00506], atol=5e-6)


def test_jpl_catalog_l1():
    """The JPL three-body periodic-orbit catalog lists L1 x = 0.836915125772357 for its Earth-Moon
    constants; tolerance 1e-12."""
    l1 = librate.System.preset("earth-moon-jpl").lagrange_points()[0, 0]
    assert abs(l1 - 0.836915125772357) < 1e-12


def test_jacobi_at_equilibria(em):
    """At L4 (unit distance from both primaries, at rest) C = x^2 + y^2 + 2 exactly; at every
    Lagrange point C = 2U."""
    mu = em.mu
    l4 = em.lagrange_points()[3]
    c = em.jacobi([*l4, 0, 0, 0])
    assert isinstance(c, float)
    assert c == pytest.approx(l4[0] ** 2 + l4[1] ** 2 + 2.0, abs=1e-14)
    states = np.zeros((5, 6))
    states[:, :3] = em.lagrange_points()
    cs = em.jacobi(states)
    r1 = np.linalg.norm(states[:, :3] - [-mu, 0, 0], axis=1)
    r2 = np.linalg.norm(states[:, :3] - [1 - mu, 0, 0], axis=1)
    u = 0.5 * (states[:, 0] ** 2 + states[:, 1] ** 2) + (1 - mu) / r1 + mu / r2
    np.testing.assert_allclose(cs, 2 * u, rtol=1e-15)
    # Velocity lowers C by |v|^2.
    assert em.jacobi([*l4, 0.1, 0.2, 0.3]) == pytest.approx(c - 0.14, abs=1e-14)
