"""The batched attitude corrector and verifier of the extension (librate._core.attitude_correct,
planar_verify) against the Python-level periodic_attitude, and the typed SweepResult."""

import math

import librate
import librate._core as core
import numpy as np
import pytest
from librate.periodicity import orbit_forcing
from librate.periodicity.solutions import SOLVE_ATOL, SOLVE_RTOL, correct

HALF, FULL, PHI0 = core.Closure.HALF, core.Closure.FULL, core.Free.PHI0


def options(tol=1e-12, threads=None):
    """The corrector's settings of the Python layer (solutions.correct) with the given tolerance."""
    return core.CorrectorOptions(core.NewtonOptions(tol=tol), core.LaneOptions(rtol=SOLVE_RTOL, atol=SOLVE_ATOL, threads=threads))


def cases(phi0, wz0, kz, turns, **kw):
    return core.PlanarCases(np.asarray(phi0, dtype=float), np.asarray(wz0, dtype=float), np.asarray(kz, dtype=float),
                            turns=np.asarray(turns, dtype=float), **kw)


@pytest.fixture(scope="module")
def dro1266(em):
    return librate.dro(em, period_days=12.66)


def test_one_call_reproduces_periodic_attitude(em, dro1266):
    """Thesis Fig. 23 solution (Kz = 0.8, N = -1): one attitude_correct call gives the wz0 of
    periodic_attitude (1e-12) and its monodromy (1e-9); planar_verify closes the period (1e-11)."""
    T = dro1266.period
    sol = librate.periodic_attitude(dro1266, kz=0.8, n=-1)
    r = core.attitude_correct(orbit_forcing(dro1266), cases([0.0], [1 - 2 * math.pi / T], [0.8], [-1.0]),
                              t_final=0.5 * T, closure=HALF, free=PHI0, options=options())
    assert r.reason == ["converged"] and r.converged.tolist() == [True] and r.residual_norm[0] <= 1e-12
    assert r.wz0[0] == pytest.approx(sol.wz0, abs=1e-12) and round(r.wz0[0] - 1, 4) == -2.4545
    np.testing.assert_allclose(r.monodromy[0], sol.monodromy, atol=1e-9)
    assert r.residual.shape == (1, 2) and math.isnan(r.residual[0, 1])
    v = core.planar_verify(em.mu, list(dro1266.state0), T, core.PlanarCases(r.phi0, r.wz0, np.array([0.8])))
    assert v.error == [None] and v.stm.shape == (1, 2, 2)
    assert abs(v.phi_t[0] - r.phi0[0] + 2 * math.pi) < 1e-11 and abs(v.wz_t[0] - r.wz0[0]) < 1e-11


def test_batch_matches_single_calls(dro1266):
    """A batch over Kz (half and full forms) converges everywhere to the symmetric solutions of
    periodic_attitude, started from the half-period solution 1e-3 off for the full form (1e-10)."""
    T = dro1266.period
    kz = np.linspace(0.2, 0.9, 8)
    n = len(kz)
    f = orbit_forcing(dro1266)
    h = core.attitude_correct(f, cases(np.zeros(n), np.full(n, 1 - 2 * math.pi / T), kz, np.full(n, -1.0)), t_final=0.5 * T, closure=HALF,
                              free=PHI0, options=options(threads=2))
    g = core.attitude_correct(f, cases(np.full(n, 1e-3), h.wz0 + 1e-3, kz, np.full(n, -1.0)), t_final=T, closure=FULL, free=PHI0,
                              options=options(threads=1))
    ref = np.array([librate.periodic_attitude(dro1266, kz=float(k), n=-1).wz0 for k in kz])
    assert h.converged.all() and g.converged.all()
    np.testing.assert_allclose(h.wz0, ref, atol=1e-10)
    np.testing.assert_allclose(g.wz0, ref, atol=1e-10)
    np.testing.assert_allclose(g.phi0, 0.0, atol=1e-10)
    assert len(h) == n and h.iterations.dtype == np.int64


BAD = [
    (dict(closure=HALF, free=core.Free.SUN_PHASE), "free"),
    (dict(closure=FULL, free=core.Free.SUN_PHASE), "free"),
    (dict(closure=FULL, tol=-1.0), "tol"),
    (dict(closure=FULL, eps=np.zeros(3)), "plates"),
]


@pytest.mark.parametrize("kw, name", BAD)
def test_bad_corrector_arguments(dro1266, kw, name):
    t = dro1266.period * (0.5 if kw["closure"] == HALF else 1.0)
    with pytest.raises(ValueError, match=name):
        eps = kw.get("eps")
        plates = None if eps is None else core.Plates(eps, np.zeros(3), np.zeros(3), np.zeros(3))
        core.attitude_correct(orbit_forcing(dro1266), cases([0.0], [-1.4], [0.8], [-1.0], plates=plates), t_final=t, closure=kw["closure"],
                              free=kw.get("free", PHI0), options=options(tol=kw.get("tol", 1e-12)))


@pytest.mark.parametrize("kw, name", [(dict(closure="quarter"), "closure"), (dict(free="kz"), "free"),
                                      (dict(bordered=("x0", (0, 0, 1, 0.5))), "parameter")])
def test_variant_names_are_checked_where_they_enter(dro1266, kw, name):
    """The Python layer turns the variants' names into the core's enums, naming the argument."""
    with pytest.raises(ValueError, match=f"invalid argument `{name}`: must be one of"):
        correct(dro1266, kz=0.8, n_total=-1, kind="periodic", phi0=0.0, wz0=-1.4, **kw)


def test_variants_and_cases_are_typed(dro1266):
    """A variant is an enum, never a string; the cases' arrays have one length (their constructor)."""
    with pytest.raises(TypeError):
        core.attitude_correct(orbit_forcing(dro1266), cases([0.0], [-1.4], [0.8], [-1.0]), t_final=1.0, closure="half", free=PHI0,
                              options=options())
    with pytest.raises(ValueError, match="invalid argument `kz`: must have length 2, got 1"):
        core.PlanarCases(np.zeros(2), np.zeros(2), np.zeros(1))
    with pytest.raises(ValueError, match="invalid argument `lanes`"):
        core.CorrectorOptions(core.NewtonOptions(), core.LaneOptions(method=core.LaneMethod.RKN86))


def test_sweep_result_is_typed_and_indexable(dro1266):
    """map_sweep returns a SweepResult whose fields are also readable as r[name]."""
    r = core.map_sweep(orbit_forcing(dro1266), dro1266.period, core.PlanarCases(np.zeros(2), np.array([-1.0, 1.0]), np.full(2, 0.8)),
                       lanes=core.LaneOptions(rtol=1e-12, atol=1e-12, chunk=8), stm=False)
    assert isinstance(r, core.SweepResult) and len(r) == 2 and r.stm is None and r["stm"] is None
    for name in r.keys():
        if name != "stm":
            np.testing.assert_array_equal(r[name], getattr(r, name))
    with pytest.raises(KeyError):
        r["nope"]
