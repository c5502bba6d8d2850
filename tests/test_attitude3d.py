"""Periodic 3-D attitude motions (issue 15, item 1): the planar embedding (thesis Fig. 23), the
torque-free sphere's closed-form monodromy, the symplectic structure of the multipliers, and
independent re-propagation; the out-of-plane stability of planar motions (item 2)."""

import math

import librate
import numpy as np
import pytest
from scipy.linalg import expm
from scipy.spatial.transform import Rotation


@pytest.fixture(scope="module")
def dro(em):
    """The 12.66-day DRO of thesis Fig. 23."""
    return librate.dro(em, period_days=12.66)


@pytest.fixture(scope="module")
def planar_n_minus_1(dro):
    return librate.periodic_attitude(dro, kz=0.8, n=-1)


def reciprocal_gap(m):
    """Largest distance of a multiplier's reciprocal from the set (a symplectic monodromy's
    multipliers come in pairs m, 1/m)."""
    m = np.asarray(m)
    return max(np.min(np.abs(1 / z - m)) for z in m)


def test_planar_embedding_fig23(dro, planar_n_minus_1):
    """Thesis Fig. 23 (12.66-day DRO, Kz = 0.8, N = -1): started from the planar solution, the 3-D
    corrector returns it (wz0 to 1e-10, q0 a rotation about z, w0 along z); its in-plane
    multiplier pair equals the planar 2x2 monodromy's to 1e-8; multipliers come in reciprocal
    pairs (1e-8); the independent re-propagation repeats to 1e-9; one turn backwards."""
    p = planar_n_minus_1
    s = librate.periodic_attitude_3d(dro, librate.RigidBody.from_kz(0.8), guess=p)
    assert s.w0[2] == pytest.approx(p.wz0, abs=1e-10)
    assert np.max(np.abs(s.q0[:2])) < 1e-12 and np.max(np.abs(s.w0[:2])) < 1e-12
    assert s.phi0 == pytest.approx(p.phi0, abs=1e-10)
    assert s.planar
    np.testing.assert_allclose(np.sort_complex(s.in_plane_multipliers), np.sort_complex(p.multipliers.astype(complex)), atol=1e-8)
    assert reciprocal_gap(s.multipliers) < 1e-8
    assert s.residual < 1e-9
    assert s.turns == pytest.approx(-1.0, abs=1e-9)


def test_perturbed_guess_returns_to_the_planar_solution(dro, planar_n_minus_1):
    """A guess tilted by ~0.03 rad out of the plane with out-of-plane rates of 1e-3 converges
    back onto the Fig. 23 solution (wz0 to 1e-10, no tilt left)."""
    p = planar_n_minus_1
    q = Rotation.from_rotvec([0.02, -0.015, 0.01]).as_quat()
    s = librate.periodic_attitude_3d(dro, librate.RigidBody.from_kz(0.8), guess=(q, [1e-3, -2e-3, p.wz0 + 1e-3]))
    assert s.w0[2] == pytest.approx(p.wz0, abs=1e-10)
    assert np.max(np.abs(s.q0[:2])) < 1e-10 and np.max(np.abs(s.w0[:2])) < 1e-10
    assert s.iterations >= 1 and s.residual < 1e-9


@pytest.mark.parametrize("n", [-1, 0, 2])
def test_torque_free_sphere_closed_form(dro, n):
    """A sphere feels no torque: w is constant in body axes, and the periodic motions are the
    spins w = (1 + 2 pi N / T) e_Z (inertial), at any attitude. The linearised motion is
    theta' = -w x theta + dw, dw' = 0, so the monodromy is expm([[-[w x] T, T I], [0, 0]]) (a tilted
    spin axis, fixed in inertial space, turns by -T per orbit in the synodic frame). The computed
    monodromy matches it to 1e-10, and the multipliers are exp(+-i T) and four 1s: all 1 only
    when T is a multiple of 2 pi (it is not: T = 2.93)."""
    T = dro.period
    wz = 1 + 2 * math.pi * n / T
    q = Rotation.from_rotvec([0.1, -0.05, 0.2]).as_quat()
    guess_w = Rotation.from_quat(q).as_matrix().T @ [0.0, 1e-3, wz]
    s = librate.periodic_attitude_3d(dro, librate.RigidBody(1.0, 1.0, 1.0), guess=(q, guess_w))
    np.testing.assert_allclose(Rotation.from_quat(s.q0).as_matrix() @ s.w0, [0, 0, wz], atol=1e-12)
    w = s.w0
    wx = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    a = np.zeros((6, 6))
    a[:3, :3] = -wx * T
    a[:3, 3:] = T * np.eye(3)
    assert np.max(np.abs(s.monodromy - expm(a))) < 1e-10
    for z in (np.exp(1j * T), np.exp(-1j * T)):
        assert np.min(np.abs(s.multipliers - z)) < 1e-10
    assert np.sum(np.abs(s.multipliers - 1) < 1e-6) == 4
    assert abs(np.exp(1j * T) - 1) > 0.1
    assert s.residual < 1e-9


def test_spatial_halo_solution(em):
    """A 3-D periodic motion along the 13-day southern L2 halo (body 0.8 : 0.9 : 1, N = -1,
    started from the torque-free rate): converged, re-propagated independently to 1e-9,
    multipliers in reciprocal pairs to 1e-8, one turn backwards about Z."""
    h = librate.halo(em, 2, "south", period_days=13.0)
    T = h.period
    s = librate.periodic_attitude_3d(h, librate.RigidBody(0.8, 0.9, 1.0), guess=([0, 0, 0, 1.0], [0, 0, 1 - 2 * math.pi / T]))
    assert s.residual < 1e-9
    assert reciprocal_gap(s.multipliers) < 1e-8
    assert s.turns == pytest.approx(-1.0, abs=1e-9)
    assert not s.planar and s.in_plane_multipliers is None


def test_invalid_arguments(dro, planar_n_minus_1):
    body = librate.RigidBody.from_kz(0.8)
    with pytest.raises(ValueError, match="guess"):
        librate.periodic_attitude_3d(dro, body, guess=([0, 0, 0, 2.0], [0, 0, 1]))
    with pytest.raises(ValueError, match="guess"):
        librate.periodic_attitude_3d(dro, body, guess="x")
    with pytest.raises(ValueError, match="n_periods"):
        librate.periodic_attitude_3d(dro, body, guess=planar_n_minus_1, n_periods=2)
    with pytest.raises(ValueError, match="body"):
        librate.periodic_attitude_3d(dro, librate.RigidBody.from_kz(1.0), guess=planar_n_minus_1)
    with pytest.raises(ValueError, match="tol"):
        librate.periodic_attitude_3d(dro, body, guess=planar_n_minus_1, tol=-1)
    with pytest.raises(librate.ConvergenceError):
        librate.periodic_attitude_3d(dro, body, guess=([0, 0, 0, 1.0], [0.0, 0.0, 5.0]), max_iter=2)
