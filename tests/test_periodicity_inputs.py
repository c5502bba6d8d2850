"""Issue 12, the periodicity layer's inputs: each bad value is a ValueError naming the parameter
(and its allowed range) before any work, never an OverflowError, a ZeroDivisionError, an empty
result or a "did not converge after -5 iterations"."""

import librate
import numpy as np
import pytest
from librate.periodicity.solutions import correct

EM = librate.System.preset("earth-moon")
ORBIT = librate.dro(EM, x0=0.85)
WZ = np.linspace(-1.0, 1.0, 50)

BAD = [
    ("map rtol below double precision", lambda: librate.periodicity_map(ORBIT, kz=0.8, wz0=WZ, rtol=1e-30), "rtol"),
    ("map negative chunk", lambda: librate.periodicity_map(ORBIT, kz=0.8, wz0=WZ, chunk=-1), "chunk"),
    ("map negative threads", lambda: librate.periodicity_map(ORBIT, kz=0.8, wz0=WZ, threads=-2), "threads"),
    ("find n_grid = 0", lambda: librate.find_periodic_attitudes(ORBIT, kz=0.8, wz0_range=(-1, 1), n_grid=0), "n_grid"),
    ("continue_srp min_step = 0", lambda: librate.continue_srp(librate.periodic_attitude(ORBIT, kz=0.8, n=0),
                                                               librate.FlatPlate(0.1), min_step=0),
     "min_step"),
    ("tol = 0", lambda: librate.periodic_attitude(ORBIT, kz=0.8, n=0, tol=0.0), "tol"),
    ("max_iter = -5", lambda: librate.periodic_attitude(ORBIT, kz=0.8, n=0, max_iter=-5), "max_iter"),
    ("method with free theta_sun0", lambda: librate.periodic_attitude(ORBIT, kz=0.8, n=0, srp=librate.FlatPlate(0.1),
                                                                      free="theta_sun0", method="half"),
     "method"),
    ("n not a whole number of turns over K periods", lambda: librate.periodic_attitude(ORBIT, kz=0.8, n=0.3, n_periods=2), "n"),
    ("corrector max_contraction = 0", lambda: correct(ORBIT, kz=0.8, n_total=[0], kind=["periodic"], phi0=[0.0], wz0=[0.5],
                                                      max_contraction=0.0), "max_contraction"),
    ("corrector max_contraction NaN", lambda: correct(ORBIT, kz=0.8, n_total=[0], kind=["periodic"], phi0=[0.0], wz0=[0.5],
                                                      max_contraction=float("nan")), "max_contraction"),
]


@pytest.mark.parametrize("name,call,param", BAD, ids=[b[0] for b in BAD])
def test_bad_input_names_the_parameter(name, call, param):
    with pytest.raises(ValueError, match=f"`{param}`"):
        call()


def test_numpy_integers_are_counts():
    s = librate.periodic_attitude(ORBIT, kz=0.8, n=np.int64(0), max_iter=np.int64(30))
    assert s.residual < 1e-9


def test_an_orbit_through_a_primary_is_a_typed_collision_and_the_map_keeps_the_others():
    """Issue 12 (collisions in every map): an 'orbit' started at the Moon's centre makes no
    forcing table of infinite S, C: orbit_forcing raises CollisionError (primary 2), and a map
    over [good, bad] computes the good orbit's row, leaves the bad one uncomputed (status 255,
    NaN, computed False, complete 0) with a warning naming it."""
    mu = EM.mu
    bad = librate.PeriodicOrbit(EM, np.array([1 - mu, 0, 0, 0, 0, 0.0]), 1.0, 3.0, "dro")
    with pytest.raises(librate.CollisionError):
        librate.periodicity.orbit_forcing(bad)
    with pytest.warns(UserWarning, match="orbit 1 .* skipped"):
        ds = librate.periodicity_map([ORBIT, bad], kz=0.8, wz0=WZ, solve=False)
    assert bool(ds.computed.values[0]) and not bool(ds.computed.values[1]) and ds.attrs["complete"] == 0
    assert np.all(np.isfinite(ds.dwz.values[0])) and np.all(np.isnan(ds.dwz.values[1])) and np.all(ds.status.values[1] == 255)
