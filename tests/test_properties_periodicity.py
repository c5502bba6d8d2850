"""Property-based tests (hypothesis) of the periodicity layer's public API (issue 12,
"Property-based tests", completing tests/test_properties.py): random invalid inputs give a
``ValueError`` naming the parameter, before any work; random valid inputs give periodic
solutions (independent residual < 1e-8) or a typed ``librate.LibrateError``. No other exception
type escapes. Few examples per property (CI time).
"""

import math

import librate
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

EM = librate.System.preset("earth-moon")
ORBIT = librate.dro(EM, x0=0.85)
SETTINGS = settings(max_examples=25, deadline=10000, suppress_health_check=[HealthCheck.too_slow], derandomize=True, database=None)

junk = st.one_of(st.text(max_size=3), st.none(), st.just(object()), st.booleans())
non_finite = st.sampled_from([math.nan, math.inf, -math.inf])
not_a_number = st.one_of(junk.filter(lambda v: v is not None), non_finite)
not_kz = st.one_of(not_a_number, st.floats(1.0001, 1e6), st.floats(-1e6, -1.0001))
not_a_count = st.one_of(junk.filter(lambda v: v is not None), st.integers(max_value=0), st.floats(0.5, 9.5).filter(lambda v: v != int(v)))
not_positive = st.one_of(not_a_number, st.floats(max_value=0.0, allow_nan=False))


def raises_naming(name, call):
    with pytest.raises(ValueError) as info:
        call()
    assert f"`{name}`" in str(info.value), f"{name}: {info.value}"


PERIODIC_BAD = {
    "kz": not_kz,
    "n": st.one_of(not_a_number, st.floats(0.01, 0.49)),
    "phi0": not_a_number,
    "wz0": not_a_number,
    "n_periods": not_a_count,
    "tol": not_positive,
    "max_iter": not_a_count,
    "kind": st.text(max_size=5),
    "method": st.text(max_size=5),
    "free": st.text(max_size=5).filter(lambda s: s not in ("phi0", "theta_sun0", "sun_phase")),
    "srp": st.one_of(st.text(max_size=3), st.integers(), st.just(object())),
}


@pytest.mark.parametrize("name", sorted(PERIODIC_BAD))
@SETTINGS
@given(data=st.data())
def test_periodic_attitude_invalid(name, data):
    kw = {"kz": 0.8, "n": 0}
    kw[name] = data.draw(PERIODIC_BAD[name], label=name)
    raises_naming(name, lambda: librate.periodic_attitude(ORBIT, **kw))


MAP_BAD = {
    "kz": st.one_of(not_kz, st.just([])),
    "wz0": st.one_of(junk, st.just([1.0]), st.just([1.0, 0.5]), non_finite.map(lambda b: [0.0, b])),
    "n_periods": not_a_count,
    "chunk": not_a_count,
    "threads": not_a_count,
    "rtol": st.one_of(not_positive, st.floats(1e-300, 1e-16)),
    "srp": st.one_of(st.text(max_size=3), st.integers(), st.just([])),
}


@pytest.mark.parametrize("name", sorted(MAP_BAD))
@SETTINGS
@given(data=st.data())
def test_periodicity_map_invalid(name, data):
    kw = {"kz": 0.8, "wz0": np.linspace(-1, 1, 8)}
    kw[name] = data.draw(MAP_BAD[name], label=name)
    raises_naming(name, lambda: librate.periodicity_map(ORBIT, solve=False, **kw))


FIND_BAD = {
    "kz": not_kz,
    "wz0_range": st.one_of(junk, st.just((1.0, 0.0)), non_finite.map(lambda b: (0.0, b)), st.just((1.0,))),
    "n_grid": not_a_count,
    "n_periods": not_a_count,
    "kinds": st.one_of(st.just(()), st.lists(st.text(max_size=4), min_size=1, max_size=2)),
    "phi0": not_a_number,
}


@pytest.mark.parametrize("name", sorted(FIND_BAD))
@SETTINGS
@given(data=st.data())
def test_find_periodic_attitudes_invalid(name, data):
    kw = {"kz": 0.8, "wz0_range": (-1.0, 1.0)}
    kw[name] = data.draw(FIND_BAD[name], label=name)
    raises_naming(name, lambda: librate.find_periodic_attitudes(ORBIT, **kw))


@settings(SETTINGS, max_examples=12)
@given(kz=st.floats(-1.0, 1.0), n=st.integers(-2, 2), wz0=st.one_of(st.none(), st.floats(-4.0, 4.0)))
def test_periodic_attitude_valid_inputs(kz, n, wz0):
    """Valid inputs: a periodic solution (re-propagated independently, 1e-8) or a typed error."""
    try:
        s = librate.periodic_attitude(ORBIT, kz=kz, n=n, wz0=wz0)
    except librate.LibrateError:
        return
    assert s.residual < 1e-8 and math.isfinite(s.wz0) and math.isfinite(s.trace)


@settings(SETTINGS, max_examples=8)
@given(kz=st.floats(-1.0, 1.0), lo=st.floats(-3.0, 2.0), width=st.floats(0.05, 2.0))
def test_find_periodic_attitudes_valid_inputs(kz, lo, width):
    sols = librate.find_periodic_attitudes(ORBIT, kz=kz, wz0_range=(lo, lo + width))
    assert all(lo <= s.wz0 <= lo + width and s.residual < 1e-8 for s in sols)
