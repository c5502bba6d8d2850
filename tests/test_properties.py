"""Property-based tests (hypothesis) of the public API of the orbits and attitude layers
(issue 12, "Property-based tests"): random invalid inputs give ``ValueError`` naming the
parameter; random valid inputs give finite results or a typed ``librate.LibrateError``. No
other exception type escapes, and nothing runs past a step limit (``max_steps``) or the
per-example deadline. Examples are few per property (CI time): the suite is about a minute.
"""

import math
import re
import sys
from pathlib import Path

import librate
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

EM = librate.System.preset("earth-moon")
MU = EM.mu
SETTINGS = settings(max_examples=100, deadline=4000, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
                    derandomize=True, database=None)
FEW = settings(SETTINGS, max_examples=40)

# --- invalid values ----------------------------------------------------------------------

junk = st.one_of(st.text(max_size=4), st.none(), st.just(object()), st.dictionaries(st.text(max_size=2), st.integers(), max_size=1))
non_finite = st.sampled_from([math.nan, math.inf, -math.inf])
not_a_number = st.one_of(junk, non_finite, st.booleans(), st.lists(st.floats(-1, 1), min_size=2, max_size=3))
not_positive = st.one_of(not_a_number, st.floats(max_value=0.0, allow_nan=False), st.just(0))
not_a_count = st.one_of(junk, st.integers(max_value=0), st.integers(min_value=-(2**80), max_value=-(2**63)),
                        st.floats(0.5, 1e3).filter(lambda v: v != int(v)), st.booleans(), non_finite)
bad_state = st.one_of(junk, st.lists(st.floats(-1, 1), min_size=0, max_size=5), st.lists(st.floats(-1, 1), min_size=7, max_size=9),
                      st.lists(st.floats(-1, 1), min_size=6, max_size=6).flatmap(lambda v: non_finite.map(lambda b: [b, *v[1:]])),
                      st.lists(st.text(max_size=2), min_size=6, max_size=6))


def raises_naming(name, call):
    """``call()`` raises ValueError whose message names the parameter as `name`."""
    with pytest.raises(ValueError) as info:
        call()
    assert f"`{name}`" in str(info.value), f"{name}: {info.value}"


def finite_or_typed(call):
    """``call()`` returns, or raises a typed librate error (never another exception)."""
    try:
        return call()
    except librate.LibrateError:
        return None


# --- propagate / propagate_many ------------------------------------------------------------

STATE = [0.8, 0.0, 0.0, 0.0, 0.5, 0.0]

PROPAGATE_BAD = {
    "system": st.one_of(st.text(max_size=5).filter(lambda s: s not in librate.System.presets()), st.integers(), st.none()),
    "state": bad_state,
    "t_span": st.one_of(junk.filter(lambda v: v is not None), non_finite, st.lists(st.floats(-1, 1), min_size=3, max_size=4),
                        non_finite.map(lambda b: [0.0, b])),
    "rtol": not_positive,
    "atol": not_positive,
    "max_steps": not_a_count,
    "h_max": not_positive.filter(lambda v: v != math.inf),
    "safety": st.one_of(not_positive, st.floats(1.5, 10)),
    "h0": st.one_of(not_positive.filter(lambda v: v is not None)),
    "h_min": st.one_of(junk.filter(lambda v: v is not None), non_finite, st.floats(max_value=-1e-9, allow_nan=False)),
    "fixed_step": st.one_of(not_positive.filter(lambda v: v is not None)),
    "events": st.one_of(st.lists(st.one_of(st.integers(), st.text(max_size=2)), min_size=1, max_size=2)),
    "collision": st.one_of(st.text(max_size=6).filter(lambda s: s not in ("radius", "point")), st.integers(), st.booleans()),
    "t_eval": st.one_of(st.lists(st.text(max_size=2), min_size=1, max_size=2), st.just([0.5, 0.1]), st.just([5.0])),
}


@pytest.mark.parametrize("name", sorted(PROPAGATE_BAD))
@SETTINGS
@given(data=st.data())
def test_propagate_invalid(name, data):
    value = data.draw(PROPAGATE_BAD[name], label=name)
    args = {"system": EM, "state": STATE, "t_span": 1.0}
    kw = {"max_steps": 20000}
    if name in args:
        args[name] = value
    else:
        kw[name] = value
    raises_naming(name, lambda: librate.propagate(args["system"], args["state"], args["t_span"], **kw))


states6 = st.tuples(st.floats(-1.5, 1.5), st.floats(-1.5, 1.5), st.floats(-0.5, 0.5), st.floats(-2, 2),
                    st.floats(-2, 2), st.floats(-0.5, 0.5))


@SETTINGS
@given(s=states6, tf=st.floats(-2, 2), collision=st.sampled_from(["radius", "point", None]), stm=st.booleans())
def test_propagate_valid(s, tf, collision, stm):
    tr = finite_or_typed(lambda: librate.propagate(EM, list(s), tf, max_steps=5000, collision=collision, stm=stm))
    if tr is not None:
        assert np.all(np.isfinite(tr.y)) and np.all(np.isfinite(tr.y_final)) and tr.status in ("completed", "event")
        if stm:
            assert np.all(np.isfinite(tr.stm))


MANY_BAD = {
    "states": st.one_of(junk, st.lists(st.lists(st.floats(-1, 1), min_size=5, max_size=5), min_size=1, max_size=2)),
    "t_final": st.one_of(junk, non_finite, st.lists(st.floats(0, 1), min_size=3, max_size=4)),
    "t0": st.one_of(junk, non_finite),
    "threads": st.one_of(st.integers(max_value=0), st.integers(min_value=-(2**80), max_value=-1), st.text(max_size=2), st.floats(0.5, 3.5)),
    "on_error": st.text(max_size=5).filter(lambda s: s not in ("raise", "mask")),
    "max_steps": not_a_count,
    "rtol": not_positive,
    "collision": st.text(max_size=6).filter(lambda s: s not in ("radius", "point")),
}


@pytest.mark.parametrize("name", sorted(MANY_BAD))
@FEW
@given(data=st.data())
def test_propagate_many_invalid(name, data):
    value = data.draw(MANY_BAD[name], label=name)
    args = {"states": [STATE, STATE], "t_final": 1.0}
    kw = {"max_steps": 20000}
    if name in args:
        args[name] = value
    else:
        kw[name] = value
    raises_naming(name, lambda: librate.propagate_many(EM, args["states"], args["t_final"], **kw))


@SETTINGS
@given(rows=st.lists(states6, min_size=1, max_size=4), tf=st.floats(-1.5, 1.5), threads=st.sampled_from([None, 1, 2]))
def test_propagate_many_valid(rows, tf, threads):
    b = librate.propagate_many(EM, [list(r) for r in rows], tf, max_steps=5000, threads=threads, on_error="mask")
    assert b.ok.shape == (len(rows),) and b.status.shape == (len(rows),)
    assert np.all(np.isfinite(b.y[b.ok]))
    for i in np.flatnonzero(~b.ok):
        assert isinstance(b.errors[int(i)], librate.LibrateError)
        assert b.status[i] != "completed"


# --- System, RigidBody, SRP objects ----------------------------------------------------------

SYSTEM_BAD = {
    "mu": st.one_of(not_positive, st.floats(0.5000001, 10)),
    "lu_km": not_positive,
    "tu_s": not_positive,
    "r1_km": st.one_of(not_a_number, st.floats(max_value=-1e-9, allow_nan=False)),
    "r2_km": st.one_of(not_a_number, st.floats(max_value=-1e-9, allow_nan=False)),
    "name": st.one_of(st.integers(), st.none(), st.just(b"x")),
}


@pytest.mark.parametrize("name", sorted(SYSTEM_BAD))
@FEW
@given(data=st.data())
def test_system_invalid(name, data):
    kw = {"mu": MU, "lu_km": 384400.0, "tu_s": 375190.0}
    kw[name] = data.draw(SYSTEM_BAD[name], label=name)
    raises_naming(name, lambda: librate.System(**kw))


@FEW
@given(mu=st.floats(1e-8, 0.5), lu=st.floats(1, 1e9), tu=st.floats(1, 1e9), r=st.floats(0, 1e4))
def test_system_valid(mu, lu, tu, r):
    s = librate.System(mu=mu, lu_km=lu, tu_s=tu, r1_km=r, r2_km=r)
    assert np.all(np.isfinite(s.lagrange_points())) and math.isfinite(s.jacobi(STATE))


BODY_BAD = {"ix": st.one_of(not_a_number, st.floats(max_value=-1e-9, allow_nan=False)),
            "iy": st.one_of(not_a_number, st.floats(max_value=-1e-9, allow_nan=False)),
            "iz": st.one_of(not_a_number, st.floats(max_value=0.0, allow_nan=False), st.floats(4.01, 100)),
            "mass_kg": st.one_of(not_positive.filter(lambda v: v is not None))}


@pytest.mark.parametrize("name", sorted(BODY_BAD))
@FEW
@given(data=st.data())
def test_rigid_body_invalid(name, data):
    kw = {"ix": 1.0, "iy": 2.0, "iz": 2.5}
    kw[name] = data.draw(BODY_BAD[name], label=name)
    raises_naming(name, lambda: librate.RigidBody(**kw))


@FEW
@given(a=st.floats(0.0, 1.0), b=st.floats(0.0, 1.0), kz=st.floats(-1, 1))
def test_rigid_body_valid(a, b, kz):
    if a + b > 0:
        body = librate.RigidBody(a, b, a + b)  # the planar extreme of the triangle inequality
        assert -1 - 1e-12 <= body.kz <= 1 + 1e-12
    assert librate.RigidBody.from_kz(kz).kz == pytest.approx(kz, abs=1e-15)
    raises_naming("kz", lambda: librate.RigidBody.from_kz(kz + 2.0 * math.copysign(1.0, kz or 1.0)))


FACET_BAD = {"area": not_positive, "normal": st.one_of(junk, st.just([0.0, 0.0, 0.0]), st.lists(st.floats(-1, 1), min_size=2, max_size=2),
                                                       non_finite.map(lambda b: [b, 1.0, 0.0])),
             "center": st.one_of(junk.filter(lambda v: v is not None), st.lists(st.floats(-1, 1), min_size=4, max_size=4),
                                 non_finite.map(lambda b: [b, 0.0, 0.0])),
             "ca": st.one_of(not_a_number, st.floats(1.01, 5), st.floats(-5, -0.01)),
             "cs": st.one_of(not_a_number, st.floats(1.01, 5), st.floats(-5, -0.01)),
             "cd": st.one_of(not_a_number, st.floats(1.01, 5), st.floats(-5, -0.01))}


@pytest.mark.parametrize("name", sorted(FACET_BAD))
@FEW
@given(data=st.data())
def test_facet_invalid(name, data):
    kw = {"area": 2.0, "normal": (1.0, 0.0, 0.0), "center": (0.0, 1.0, 0.0), "ca": 0.6, "cs": 0.3, "cd": 0.1}
    kw[name] = data.draw(FACET_BAD[name], label=name)
    raises_naming(name, lambda: librate.Facet(**kw))


@FEW
@given(area=st.floats(1e-3, 1e3),
       n=st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)).filter(lambda v: np.linalg.norm(v) > 1e-3),
       cs=st.floats(0, 0.5), cd=st.floats(0, 0.5))
def test_facet_and_body_valid(area, n, cs, cd):
    f = librate.Facet(area, n, (0.0, 1.0, 0.0), 1 - cs - cd, cs, cd)
    assert np.linalg.norm(f.normal) == pytest.approx(1.0)
    body = librate.FacetBody(1.0, 2.0, 2.5, facets=(f,))
    force, torque = body.force_torque([1.0, 0.0, 0.0])
    assert np.all(np.isfinite(force)) and np.all(np.isfinite(torque))
    raises_naming("facets", lambda: librate.FacetBody(1.0, 2.0, 2.5, facets=(1, 2)))


PLATE_BAD = {"eps": not_a_number, "cs": st.one_of(not_a_number, st.floats(1.01, 5), st.floats(-5, -0.01)),
             "cd": st.one_of(not_a_number, st.floats(1.01, 5), st.floats(-5, -0.01)), "sun": st.one_of(junk, st.floats())}
SUN_BAD = {"theta0": not_a_number, "pressure": st.one_of(not_a_number, st.floats(max_value=-1e-12, allow_nan=False))}


@pytest.mark.parametrize("name", sorted(PLATE_BAD))
@FEW
@given(data=st.data())
def test_flat_plate_invalid(name, data):
    kw = {"eps": 0.1, "cs": 0.2, "cd": 0.1, "sun": librate.Sun()}
    kw[name] = data.draw(PLATE_BAD[name], label=name)
    raises_naming(name, lambda: librate.FlatPlate(**kw))


@pytest.mark.parametrize("name", sorted(SUN_BAD))
@FEW
@given(data=st.data())
def test_sun_invalid(name, data):
    kw = {"theta0": 0.3}
    kw[name] = data.draw(SUN_BAD[name], label=name)
    raises_naming(name, lambda: librate.Sun(**kw))


@FEW
@given(eps=st.floats(-10, 10), cs=st.floats(0, 0.5), cd=st.floats(0, 0.5), th=st.floats(-10, 10), p=st.floats(0, 1e-3))
def test_flat_plate_and_sun_valid(eps, cs, cd, th, p):
    plate = librate.FlatPlate(eps, cs, cd, librate.Sun(th, p))
    assert np.all(np.isfinite(plate.wzdot(np.linspace(0, 3, 5), 0.2)))


# --- periodic orbits -------------------------------------------------------------------------

SYM_BAD = {"guess": bad_state.filter(lambda v: not (isinstance(v, list) and len(v) == 3
                                                    and all(isinstance(x, float) and math.isfinite(x) for x in v))),
           "tol": not_positive, "max_iter": not_a_count, "t_max": not_positive, "rtol": not_positive, "atol": not_positive,
           "fix": st.text(max_size=3).filter(lambda s: s not in ("x0", "z0", "vy0")),
           "period": not_positive.filter(lambda v: v is not None)}


@pytest.mark.parametrize("name", sorted(SYM_BAD))
@FEW
@given(data=st.data())
def test_correct_symmetric_invalid(name, data):
    kw = {"guess": [0.85, 0.0, 0.5]}
    kw[name] = data.draw(SYM_BAD[name], label=name)
    raises_naming(name, lambda: librate.correct_symmetric(EM, **kw))


DRO_BAD = {"x0": st.one_of(not_a_number, st.floats(1.0, 5.0), st.floats(-5.0, -0.02)),
           "ydot0": st.one_of(not_a_number.filter(lambda v: v is not None)),
           "tol": not_positive, "max_iter": not_a_count, "rtol": not_positive, "atol": not_positive}


@pytest.mark.parametrize("name", sorted(DRO_BAD))
@FEW
@given(data=st.data())
def test_correct_dro_invalid(name, data):
    kw = {"x0": 0.85}
    kw[name] = data.draw(DRO_BAD[name], label=name)
    raises_naming(name, lambda: librate.correct_dro(EM, **kw))


@FEW
@given(x0=st.floats(0.2, 0.98), guess=st.one_of(st.none(), st.floats(0.01, 3)))
def test_correct_dro_valid(x0, guess):
    o = finite_or_typed(lambda: librate.correct_dro(EM, x0, guess, max_iter=15))
    if o is not None:
        assert math.isfinite(o.period) and o.period > 0 and np.all(np.isfinite(o.state0))


@FEW
@given(g=st.tuples(st.floats(0.5, 1.2), st.floats(-0.2, 0.2), st.floats(-2, 2)), spatial=st.booleans())
def test_correct_symmetric_valid(g, spatial):
    o = finite_or_typed(lambda: librate.correct_symmetric(EM, list(g), spatial=spatial, max_iter=8, t_max=8.0))
    if o is not None:
        assert math.isfinite(o.period) and np.all(np.isfinite(o.state0))


@settings(FEW, max_examples=12)
@given(x0=st.one_of(st.floats(0.976, 0.987), st.floats(-0.005, 0.02)))
def test_corrected_orbits_agree_with_propagate_on_collisions(x0):
    """Issue 24 #8: a corrected DRO near a primary is returned only when propagate()'s collision
    check (the system's radii) passes over its period; otherwise CollisionError names the
    primary, and propagate() of the orbit it refuses raises too (the same verdict)."""
    try:
        o = librate.correct_dro(EM, x0)
    except librate.CollisionError as err:
        assert err.primary in (1, 2) and err.closest_km < err.radius_km
        with pytest.raises(librate.CollisionError):
            librate.propagate(EM, err.orbit.state0, err.orbit.period, rtol=1e-13, atol=1e-13)
        return
    except librate.LibrateError:
        return  # no DRO found there (a typed error)
    assert librate.propagate(EM, o.state0, o.period, rtol=1e-13, atol=1e-13).status == "completed"


LOOKUP_BAD = [
    ("point", lambda v: librate.lyapunov(EM, v, x0=0.8), st.one_of(st.integers().filter(lambda k: k not in (1, 2)), st.text(max_size=2),
                                                                   st.none(), st.booleans())),
    ("point", lambda v: librate.halo(EM, v, z0=0.05), st.one_of(st.integers().filter(lambda k: k not in (1, 2)),
                                                                st.text(max_size=2), st.none())),
    ("branch", lambda v: librate.halo(EM, 2, v, z0=0.05),
     st.one_of(st.text(max_size=6).filter(lambda s: s not in ("north", "south")), st.integers())),
    ("x0", lambda v: librate.dro(EM, x0=v), st.one_of(not_a_number.filter(lambda v: v is not None), st.floats(1.0, 3.0),
                                                      st.floats(-3.0, -0.02))),
    ("period_days", lambda v: librate.dro(EM, period_days=v), st.one_of(non_finite, st.floats(-10, -0.1), st.floats(1e4, 1e6))),
    ("z0", lambda v: librate.halo(EM, 2, z0=v), st.one_of(non_finite, st.floats(0.3, 5.0), st.text(max_size=2))),
]


@pytest.mark.parametrize("case", range(len(LOOKUP_BAD)), ids=[f"{n}-{i}" for i, (n, _, _) in enumerate(LOOKUP_BAD)])
@settings(FEW, max_examples=8)
@given(data=st.data())
def test_lookups_invalid(case, data):
    name, call, strat = LOOKUP_BAD[case]
    value = data.draw(strat, label=name)
    raises_naming(name, lambda: call(value))


# --- attitude ----------------------------------------------------------------------------------

ORBIT = librate.correct_dro(EM, 0.85)
ATT_BAD = {"orbit_state": bad_state, "attitude": st.one_of(junk, st.lists(st.floats(-1, 1), min_size=3, max_size=3),
                                                           non_finite.map(lambda b: (b, 1.0))),
           "body": st.one_of(junk, st.floats()), "t_span": st.one_of(non_finite, junk.filter(lambda v: v is not None)),
           "torques": st.one_of(st.text(min_size=1, max_size=5), st.lists(st.integers(), min_size=1, max_size=2), st.integers()),
           "orbit": st.text(max_size=5).filter(lambda s: s not in ("integrate", "held", "coupled")), "max_steps": not_a_count,
           "rtol": not_positive, "srp": st.one_of(st.integers(), st.text(min_size=1, max_size=3)),
           "sun": st.one_of(st.integers(), st.text(min_size=1, max_size=3))}


@pytest.mark.parametrize("name", sorted(ATT_BAD))
@FEW
@given(data=st.data())
def test_propagate_attitude_invalid(name, data):
    args = {"orbit_state": ORBIT.state0, "attitude": (0.0, 1.2), "body": librate.RigidBody.from_kz(0.8), "t_span": 1.0}
    kw = {"planar": True, "max_steps": 20000}
    if name in args:
        args[name] = data.draw(ATT_BAD[name], label=name)
    else:
        kw[name] = data.draw(ATT_BAD[name], label=name)
    raises_naming(name, lambda: librate.propagate_attitude(EM, args["orbit_state"], args["attitude"], args["body"], args["t_span"], **kw))


@FEW
@given(kz=st.floats(-1, 1), phi=st.floats(-4, 4), wz=st.floats(-3, 3), tf=st.floats(-2, 2), orbit=st.sampled_from(["integrate", "held"]))
def test_propagate_attitude_planar_valid(kz, phi, wz, tf, orbit):
    tr = finite_or_typed(lambda: librate.propagate_attitude(EM, ORBIT.state0, (phi, wz), librate.RigidBody.from_kz(kz), tf, planar=True,
                                                           orbit=orbit, max_steps=20000))
    if tr is not None:
        assert np.all(np.isfinite(tr.phi)) and np.all(np.isfinite(tr.wz))


@settings(FEW, max_examples=8)
@given(q=st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)).filter(lambda v: np.linalg.norm(v) > 0.1),
       w=st.tuples(st.floats(-2, 2), st.floats(-2, 2), st.floats(-2, 2)), tf=st.floats(0.01, 1.0))
def test_propagate_attitude_3d_valid(q, w, tf):
    qn = np.asarray(q) / np.linalg.norm(q)
    tr = finite_or_typed(lambda: librate.propagate_attitude(EM, ORBIT.state0, (qn, w),
                                                            librate.RigidBody(1.0, 2.0, 2.5), tf, max_steps=20000))
    if tr is not None:
        assert np.all(np.isfinite(tr.q)) and np.all(np.isfinite(tr.w))


def test_messages_name_parameters_with_backticks():
    """(The convention the properties check: ``invalid argument `name`: ...``.)"""
    with pytest.raises(ValueError, match=re.escape("invalid argument `rtol`")):
        librate.propagate(EM, STATE, 1.0, rtol=-1.0)


GEOMETRY_BAD = {"area_m2": not_positive, "offset_m": not_a_number, "iz_kgm2": not_positive,
                "sun": st.one_of(st.integers(), st.text(min_size=1, max_size=2))}


@pytest.mark.parametrize("name", sorted(GEOMETRY_BAD))
@FEW
@given(data=st.data())
def test_flat_plate_from_geometry_invalid(name, data):
    """Before: one message for three parameters ("need area_m2 > 0, iz_kgm2 > 0 and a finite
    offset_m"), and a TypeError for a string."""
    kw = {"area_m2": 100.0, "offset_m": 2.0, "iz_kgm2": 1e8}
    kw[name] = data.draw(GEOMETRY_BAD[name], label=name)
    raises_naming(name, lambda: librate.FlatPlate.from_geometry(EM, **kw))


# --- issue 24 #6 and #13: bounded inputs, every error naming the parameter ---------------------
# tests/fuzz_api.py runs in a child process: under an address-space limit, so that an allocation
# past it is a MemoryError or an abort (a failure here), not a swapped machine; and with a 60 s
# watchdog per call that ends the child even inside the Rust core (a hang is a failure too).

#: The child's address-space limit (RLIMIT_AS). Importing librate with numpy, scipy and xarray
#: and running two worker threads reserves about 1.5 GiB of address space; the largest array
#: the API lets one argument size is MAX_ARRAY_BYTES = 2 GiB (librate._checks), which the fuzz
#: does not reach (it draws hostile values, not large valid ones).
FUZZ_ADDRESS_SPACE = 4 * 1024**3
FUZZ = Path(__file__).with_name("fuzz_api.py")


def _child(*args, timeout: float):
    import json
    import os
    import resource
    import subprocess

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (FUZZ_ADDRESS_SPACE, FUZZ_ADDRESS_SPACE))

    env = dict(os.environ, RAYON_NUM_THREADS="2")
    p = subprocess.run([sys.executable, str(FUZZ), *args], capture_output=True, text=True, timeout=timeout, preexec_fn=limit, env=env)
    rows = [json.loads(line) for line in p.stdout.splitlines() if line.startswith("[")]
    assert p.returncode == 0, f"the child died (status {p.returncode}) after {rows[-1] if rows else 'no call'}: {p.stderr[-3000:]}"
    return rows


@pytest.mark.skipif(sys.platform == "win32", reason="resource limits (POSIX)")
def test_issue24_reproductions_are_refused_naming_the_parameter():
    """Each reproduction of issue 24 #6 and #13 (rtol = 1000 hung the map, threads = 2**31 hung
    the thread pool, n_grid / n_samples = 2**31 allocated 16-32 GiB, 2**63 raised OverflowError,
    strings raised numpy's messages) is a ValueError naming the parameter, at once (< 2 s each:
    nothing was computed)."""
    from fuzz_api import REGRESSIONS

    rows = _child("regressions", timeout=300)
    assert len(rows) == len(REGRESSIONS)
    for case, param, kind, message, seconds, _, name in rows:
        assert kind == "ValueError" and f"`{name}`" in message, (case, param, kind, message)
        assert seconds < 2.0, (case, param, seconds)


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="resource limits (POSIX)")
def test_fuzz_the_public_api_in_a_limited_process():
    """Hypothesis draws hostile values (2**31, 2**63, 1e300, NaN, strings, None, objects, ...)
    for every parameter of 49 public calls, the other arguments valid (8 examples each, about
    1900 calls): only ValueError, TypeError or a librate error escapes; every ValueError and
    TypeError names a parameter (`name`); no call runs 60 s (the watchdog) and the process stays
    within FUZZ_ADDRESS_SPACE."""
    from fuzz_api import CASES

    rows = _child("fuzz", "8", timeout=1500)
    assert len(rows) >= 8 * sum(len(base) for _, base in CASES.values()) // 2  # hypothesis may stop early on small strategies
    bad = [r for r in rows if r[2].startswith("BAD:")]
    unnamed = [r for r in rows if r[2] in ("ValueError", "TypeError") and not re.search(r"`\w+`", r[3])]
    assert not bad, bad[:10]
    assert not unnamed, unnamed[:10]


def test_sizes_are_refused_with_their_memory_before_allocating():
    """Issue 24 #6: n_grid = 2**31 tried to allocate 16 GiB (numpy MemoryError); a 1000**3 3-D
    map grid 57 GB. Now a ValueError names the parameter, the range and the memory asked for
    (the limit: librate._checks.MAX_ARRAY_BYTES = 2 GiB)."""
    from librate._checks import MAX_ARRAY_BYTES

    with pytest.raises(ValueError,
                       match=r"invalid argument `n_grid`: must be an integer in \[2, [\d,]+\]: 2,147,483,648 would need about 137 GB"):
        librate.find_periodic_attitudes(ORBIT, kz=0.8, wz0_range=(0.5, 1.0), n_grid=2**31)
    w = np.linspace(0.0, 1.0, 1000)
    with pytest.raises(ValueError, match=r"invalid arguments `body`, `wx0`, `wy0`, `wz0`: a grid of 1 x 1,000 x 1,000 x 1,000 .* 57 GB"):
        librate.attitude_map_3d(ORBIT, librate.RigidBody(1.0, 2.0, 2.5), wx0=w, wy0=w, wz0=w)
    assert MAX_ARRAY_BYTES == 2 * 1024**3
