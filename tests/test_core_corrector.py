"""The batched attitude corrector and verifier of the extension (librate._core.attitude_correct,
planar_verify) against the Python-level periodic_attitude, and the typed SweepResult."""

import math

import librate
import librate._core as core
import numpy as np
import pytest
from librate.periodicity import orbit_forcing


@pytest.fixture(scope="module")
def dro1266(em):
    return librate.dro(em, period_days=12.66)


def test_one_call_reproduces_periodic_attitude(em, dro1266):
    """Thesis Fig. 23 solution (Kz = 0.8, N = -1): one attitude_correct call gives the wz0 of
    periodic_attitude (1e-12) and its monodromy (1e-9); planar_verify closes the period (1e-11)."""
    T = dro1266.period
    sol = librate.periodic_attitude(dro1266, kz=0.8, n=-1)
    r = core.attitude_correct(orbit_forcing(dro1266), np.zeros(1), np.array([1 - 2 * math.pi / T]), np.array([0.8]), np.array([-1.0]),
                              t_final=0.5 * T, closure="half")
    assert r.reason == ["converged"] and r.converged.tolist() == [True] and r.residual_norm[0] <= 1e-12
    assert r.wz0[0] == pytest.approx(sol.wz0, abs=1e-12) and round(r.wz0[0] - 1, 4) == -2.4545
    np.testing.assert_allclose(r.monodromy[0], sol.monodromy, atol=1e-9)
    assert r.residual.shape == (1, 2) and math.isnan(r.residual[0, 1])
    v = core.planar_verify(em.mu, list(dro1266.state0), T, np.array([0.8]), r.phi0, r.wz0)
    assert v.error == [None] and v.stm.shape == (1, 2, 2)
    assert abs(v.phi_t[0] - r.phi0[0] + 2 * math.pi) < 1e-11 and abs(v.wz_t[0] - r.wz0[0]) < 1e-11


def test_batch_matches_single_calls(dro1266):
    """A batch over Kz (half and full forms) converges everywhere to the symmetric solutions of
    periodic_attitude, started from the half-period solution 1e-3 off for the full form (1e-10)."""
    T = dro1266.period
    kz = np.linspace(0.2, 0.9, 8)
    n = len(kz)
    f = orbit_forcing(dro1266)
    h = core.attitude_correct(f, np.zeros(n), np.full(n, 1 - 2 * math.pi / T), kz, np.full(n, -1.0), t_final=0.5 * T, closure="half", threads=2)
    g = core.attitude_correct(f, np.full(n, 1e-3), h.wz0 + 1e-3, kz, np.full(n, -1.0), t_final=T, closure="full", threads=1)
    ref = np.array([librate.periodic_attitude(dro1266, kz=float(k), n=-1).wz0 for k in kz])
    assert h.converged.all() and g.converged.all()
    np.testing.assert_allclose(h.wz0, ref, atol=1e-10)
    np.testing.assert_allclose(g.wz0, ref, atol=1e-10)
    np.testing.assert_allclose(g.phi0, 0.0, atol=1e-10)
    assert len(h) == n and h.iterations.dtype == np.int64


BAD = [
    (dict(closure="quarter"), "closure"),
    (dict(closure="half", free="kz"), "free"),
    (dict(closure="half", free="sun_phase"), "free"),
    (dict(closure="full", free="sun_phase"), "free"),
    (dict(closure="full", tol=-1.0), "tol"),
    (dict(closure="full", eps=np.zeros(3)), "eps"),
]


@pytest.mark.parametrize("kw, name", BAD)
def test_bad_corrector_arguments(dro1266, kw, name):
    t = dro1266.period * (0.5 if kw["closure"] == "half" else 1.0)
    with pytest.raises(ValueError, match=name):
        core.attitude_correct(orbit_forcing(dro1266), np.zeros(1), np.array([-1.4]), np.array([0.8]), np.array([-1.0]), t_final=t, **kw)


def test_sweep_result_is_typed_and_indexable(dro1266):
    """map_sweep returns a SweepResult whose fields are also readable as r[name]."""
    r = core.map_sweep(orbit_forcing(dro1266), dro1266.period, np.zeros(2), np.array([-1.0, 1.0]), np.full(2, 0.8),
                       rtol=1e-12, atol=1e-12, max_steps=200_000, stm=False, chunk=8, threads=None)
    assert isinstance(r, core.SweepResult) and len(r) == 2 and r.stm is None and r["stm"] is None
    for name in r.keys():
        if name != "stm":
            np.testing.assert_array_equal(r[name], getattr(r, name))
    with pytest.raises(KeyError):
        r["nope"]
