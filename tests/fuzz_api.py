"""Hostile calls of the public API (issue 24, "Trust under every fault", #6 and #13), run in a
child process by tests/test_properties.py under an address-space limit (``RLIMIT_AS``, stated
there) and a 60 s watchdog per call (``faulthandler.dump_traceback_later(exit=True)``: it fires
even inside the Rust core, which a Python timeout cannot interrupt).

``python tests/fuzz_api.py regressions``: the issue's reproductions, one line each.
``python tests/fuzz_api.py fuzz K``: K hypothesis examples for every parameter of every case in
``CASES``, the other arguments valid. Each call prints one JSON line ``[case, param, outcome,
message, seconds]``; the outcome is ``ok``, an exception type, or ``BAD:<type>`` for anything
but the documented ``ValueError``, ``TypeError`` and ``librate.LibrateError``. A crash, an
abort or a hang ends the child with a nonzero status (the parent names the last call started).

Drawn values: the hostile ones of the issue (2**31, 2**63, 1e300, NaN, inf, strings, None,
objects, bools, lists, complex numbers, numpy scalars) and small integers and any floats. Large
*valid* sizes (a grid of 10**7 rates, legitimately hours of work) are not drawn: the API bounds
what it can (counts, tolerances, memory), not the patience a valid study needs.
"""

from __future__ import annotations

import faulthandler
import json
import math
import sys
import time

import librate
import numpy as np

EM = librate.System.preset("earth-moon")
ORB = librate.dro(EM, x0=0.85)
BODY = librate.RigidBody(1.0, 2.0, 2.5)
S = [0.8, 0.0, 0.0, 0.0, 0.5, 0.0]
FLEX = librate.FlexibleBody.sample_station()
_LAZY: dict = {}


def _solution():
    if "sol" not in _LAZY:
        _LAZY["sol"] = librate.periodic_attitude(ORB, kz=0.8, n=0)
    return _LAZY["sol"]


def _family():
    if "fam" not in _LAZY:
        _LAZY["fam"] = librate.dro_family(EM, x0=[0.85, 0.8])
    return _LAZY["fam"]


def _call(f):
    return lambda **k: f(**{n: (v() if n in ("orbits", "solution") and callable(v) else v) for n, v in k.items()})


#: name -> (call, valid keyword arguments): every parameter is fuzzed in turn, the others kept.
CASES = {
    "propagate": (librate.propagate, dict(system=EM, state=S, t_span=1.0, rtol=1e-12, atol=1e-12, max_steps=20000, h0=None, h_min=0.0,
                                          h_max=math.inf, safety=0.8, fixed_step=None, t_eval=None, collision="radius")),
    "propagate_many": (librate.propagate_many, dict(system=EM, states=[S, S], t_final=1.0, t0=0.0, rtol=1e-12, atol=1e-12, max_steps=20000,
                                                    threads=None, h0=None, safety=0.8, on_error="raise")),
    "correct_dro": (librate.correct_dro, dict(system=EM, x0=0.85, ydot0=None, tol=1e-12, max_iter=30, rtol=1e-13, atol=1e-13)),
    "correct_symmetric": (librate.correct_symmetric, dict(system=EM, guess=[0.85, 0.0, 0.5], period=None, tol=1e-11,
                                                          max_iter=40, t_max=50.0,
                                                          rtol=1e-13, atol=1e-13)),
    "correct_periodic": (librate.correct_periodic, dict(system=EM, states=ORB.state0, period=ORB.period, tol=1e-10, max_iter=25, rtol=1e-13,
                                                        atol=1e-13)),
    "dro": (librate.dro, dict(system=EM, x0=0.85)),
    "dro_period_days": (librate.dro, dict(system=EM, period_days=14.0)),
    "lyapunov": (librate.lyapunov, dict(system=EM, point=1, x0=0.8)),
    "halo": (librate.halo, dict(system=EM, point=2, z0=-0.05)),
    "dro_family": (librate.dro_family, dict(system=EM, x0=[0.85])),
    "lyapunov_family": (librate.lyapunov_family, dict(system=EM, point=1, max_members=5, ds_max=0.02)),
    "fit_fourier": (librate.fit_fourier, dict(system=EM, state0=ORB.state0, period=ORB.period, n_harmonics=None,
                                              jacobi_tol=1e-6, max_harmonics=60,
                                              n_samples=None, closure_tol=1e-7)),
    "synodic_to_eci": (librate.synodic_to_eci, dict(system=EM, t=0.0, states=S, theta0=0.0)),
    "osculating_elements": (librate.osculating_elements, dict(system=EM, t=0.0, states=S, theta0=0.0)),
    "mean_elements": (librate.mean_elements, dict(system=EM, orbit_state0=ORB.state0, period=ORB.period, n_periods=1,
                                                  samples_per_period=200)),
    "propagate_attitude": (librate.propagate_attitude, dict(system=EM, orbit_state=ORB.state0, attitude=(0.0, 1.2),
                                                            body=librate.RigidBody.from_kz(0.8),
                                                            t_span=1.0, planar=True, rtol=1e-12, atol=1e-12,
                                                            max_steps=20000, orbit="integrate")),
    "propagate_attitude_3d": (librate.propagate_attitude, dict(system=EM, orbit_state=ORB.state0,
                                                               attitude=([0, 0, 0, 1], [0, 0, 1.2]), body=BODY,
                                                               t_span=1.0, rtol=1e-12, max_steps=20000)),
    "attitude_equilibrium": (librate.attitude_equilibrium, dict(system=EM, point=1, body=BODY)),
    "equilibrium_stability": (librate.equilibrium_stability, dict(system=EM, point=1, n=21, k_range=(-1.0, 1.0))),
    "quaternion_from_euler": (librate.quaternion_from_euler, dict(angles=[0.1, 0.2, 0.3], sequence="123")),
    "periodic_attitude": (librate.periodic_attitude, dict(orbit=ORB, kz=0.8, n=0, phi0=0.0, wz0=None, n_periods=1, tol=1e-12, max_iter=40)),
    "periodic_attitude_3d": (librate.periodic_attitude_3d, dict(orbit=ORB, body=BODY,
                                                                guess=([0, 0, 0, 1], [0, 0, 1.0]), n_periods=1, tol=1e-12,
                                                                max_iter=40)),
    "attitude_map_3d": (librate.attitude_map_3d, dict(orbit=ORB, body=BODY, wx0=[0.0], wy0=0.0, wz0=[0.5, 1.0], n_periods=1,
                                                      tol=1e-10, threads=None)),
    "find_periodic_attitudes": (librate.find_periodic_attitudes, dict(orbit=ORB, kz=0.8, wz0_range=(0.5, 1.0), phi0=0.0,
                                                                      n_grid=None, n_periods=1)),
    "periodicity_map": (librate.periodicity_map, dict(orbits=ORB, kz=0.8, wz0=np.linspace(0.5, 1.0, 4), phi0=0.0, n_periods=1, solve=False,
                                                      rtol=1e-12, atol=1e-12, chunk=64, threads=None)),
    "attitude_family": (_call(librate.attitude_family), dict(orbits=_family, kz=0.8, n=0, ds=0.05, ds_min=1e-6, ds_max=0.25, max_points=3)),
    "srp_map": (librate.srp_map, dict(orbit=ORB, kz=0.8, wz0=np.linspace(0.5, 1.0, 3), eps=[0.0, 0.01], cs=0.0, cd=0.0,
                                      theta_sun0=0.0, phi0=0.0,
                                      n_periods=1, solve=False, steps=4)),
    "continue_srp": (_call(librate.continue_srp), dict(solution=_solution, srp=librate.FlatPlate(0.001), steps=2, min_step=1e-7)),
    "System": (librate.System, dict(mu=0.0121, lu_km=384400.0, tu_s=375190.0, r1_km=0.0, r2_km=0.0)),
    "RigidBody": (librate.RigidBody, dict(ix=1.0, iy=2.0, iz=2.5, mass_kg=None)),
    "Sun": (librate.Sun, dict(theta0=0.0, pressure=4.56e-6)),
    "FlatPlate": (librate.FlatPlate, dict(eps=0.1, cs=0.0, cd=0.0)),
    "Facet": (librate.Facet, dict(area=1.0, normal=(1.0, 0, 0), center=(0, 0, 0), ca=1.0, cs=0.0, cd=0.0)),
    "Event.crossing": (librate.Event.crossing, dict(coordinate="y", value=0.0, direction=0)),
    "Event.distance": (librate.Event.distance, dict(center=[0.0, 0, 0], radius=0.1, direction=0)),
    "Appendage.from_frequency": (librate.Appendage.from_frequency, dict(mass=1.0, position=(1.0, 0.0),
                                                                        direction=(0.0, 1.0), frequency_hz=0.1,
                                                                        damping_ratio=0.0)),
    "quasi_static": (librate.quasi_static, dict(system=EM, orbit_state=ORB.state0, attitude=(0.0, 1.0), body=FLEX,
                                                t_span=0.5, max_steps=20000)),
    "frequency_scan": (librate.frequency_scan, dict(system=EM, orbit_state=ORB.state0, attitude=(0.0, 1.0), body=FLEX,
                                                    t_span=0.5, factors=[1.0],
                                                    samples=11, max_steps=200000)),
    "FlexibleBody.scaled": (FLEX.scaled, dict(frequency_factor=2.0)),
    "PeriodicOrbit.propagate": (ORB.propagate, dict(n_periods=1.0)),
    "OrbitFamily.member": (lambda **k: _family().member(**k), dict(x0=0.85)),
    "OrbitFamily.resonant": (lambda **k: _family().resonant(**k), dict(k=3)),
    "System.jacobi": (EM.jacobi, dict(states=S)),
    "System.distance_km": (EM.distance_km, dict(length=1.0)),
    "Sun.angle": (librate.Sun().angle, dict(t=1.0)),
    "FlatPlate.wzdot": (librate.FlatPlate(0.1).wzdot, dict(t=1.0, phi=0.1)),
    "FlatPlate.from_geometry": (librate.FlatPlate.from_geometry, dict(system=EM, area_m2=100.0, offset_m=2.0, iz_kgm2=1e8)),
    "sun_pointing_accelerations": (librate.sun_pointing_accelerations, dict(system=EM, body_or_plate=librate.FlatPlate(0.1), t=[0.0, 1.0],
                                                                            orbit=ORB, offset=0.0, kz=0.8)),
}

#: The reproductions of issue 24 #6 and #13 (each hung, blew up memory or raised an
#: OverflowError, MemoryError or a message naming no parameter before): case, arguments, the
#: parameter the ValueError must name.
REGRESSIONS = [
    ("periodicity_map", {"rtol": 1000.0}, "rtol"),
    ("periodicity_map", {"rtol": 1000.0, "solve": True}, "rtol"),
    ("periodicity_map", {"threads": 2**31}, "threads"),
    ("periodicity_map", {"chunk": 2**63}, "chunk"),
    ("periodicity_map", {"phi0": math.nan}, "phi0"),
    ("propagate_many", {"threads": 2**31}, "threads"),
    ("propagate_many", {"threads": 2**63}, "threads"),
    ("attitude_map_3d", {"threads": 2**31}, "threads"),
    ("attitude_map_3d", {"threads": -1}, "threads"),
    ("attitude_map_3d", {"wx0": np.linspace(-1, 1, 2000), "wy0": np.linspace(-1, 1, 2000), "wz0": np.linspace(0, 1, 2000)}, "wx0"),
    ("find_periodic_attitudes", {"n_grid": 2**31}, "n_grid"),
    ("find_periodic_attitudes", {"n_periods": 2**31}, "n_periods"),
    ("fit_fourier", {"n_samples": 2**31}, "n_samples"),
    ("fit_fourier", {"n_harmonics": 2**31}, "n_harmonics"),
    ("fit_fourier", {"max_harmonics": 2**63}, "max_harmonics"),
    ("fit_fourier", {"closure_tol": "x"}, "closure_tol"),
    ("mean_elements", {"samples_per_period": 2**31}, "samples_per_period"),
    ("mean_elements", {"n_periods": 2**31}, "n_periods"),
    ("frequency_scan", {"samples": 2**31}, "samples"),
    ("frequency_scan", {"factors": [1e300]}, "factors"),
    ("propagate", {"max_steps": 2**63}, "max_steps"),
    ("propagate", {"rtol": 1000.0}, "rtol"),
    ("correct_dro", {"max_iter": 2**63}, "max_iter"),
    ("correct_symmetric", {"max_iter": 2**80}, "max_iter"),
    ("periodic_attitude_3d", {"max_iter": 2**63}, "max_iter"),
    ("lyapunov_family", {"max_members": "x"}, "max_members"),
    ("lyapunov_family", {"ds_max": 1e-300}, "ds_max"),
    ("attitude_family", {"ds_max": 1e-300}, "ds_max"),
    ("dro_family", {"x0": "x"}, "x0"),
    ("dro", {"x0": None}, "x0"),
    ("OrbitFamily.member", {"x0": None}, "x0"),
    ("OrbitFamily.resonant", {"k": 1}, "k"),
    ("synodic_to_eci", {"t": "x"}, "t"),
    ("osculating_elements", {"states": {"a": 1}}, "states"),
    ("quaternion_from_euler", {"angles": None}, "angles"),
    ("quaternion_from_euler", {"sequence": 5}, "sequence"),
    ("equilibrium_stability", {"n": 2**31}, "n"),
    ("Event.crossing", {"value": "x"}, "value"),
    ("Event.distance", {"radius": None}, "radius"),
    ("Appendage.from_frequency", {"frequency_hz": 1e300}, "frequency_hz"),
    ("PeriodicOrbit.propagate", {"n_periods": "x"}, "n_periods"),
    ("System.jacobi", {"states": "x"}, "states"),
    ("System.distance_km", {"length": "x"}, "length"),
    ("Sun.angle", {"t": object()}, "t"),
    ("FlatPlate.wzdot", {"phi": "x"}, "phi"),
    ("FlatPlate.from_geometry", {"system": 5}, "system"),
    ("sun_pointing_accelerations", {"t": "x"}, "t"),
    ("srp_map", {"theta_sun0": math.nan}, "theta_sun0"),
    ("srp_map", {"eps": "x"}, "eps"),
]

HOSTILE = [2**31, 2**63, 2**80, -(2**31), -(2**63), -1, 0, 1e300, -1e300, 1000.0, 1e-300, math.nan, math.inf,
           -math.inf, True, False, None, "",
           "x", [], [1.0, 2.0], object(), np.int64(2**40), np.float32(1e30), 1j, {"a": 1}, b"1", (0.5,)]
DOCUMENTED = (ValueError, TypeError, librate.LibrateError)
WATCHDOG_S = 60


def outcome(case: str, param: str | None, value) -> list:
    """[case, param, outcome, message, seconds] of one call, the watchdog armed."""
    call, base = CASES[case]
    kw = dict(base)
    if param is not None:
        kw[param] = value
    faulthandler.dump_traceback_later(WATCHDOG_S, exit=True)
    t = time.perf_counter()
    try:
        call(**kw)
        res = ["ok", ""]
    except DOCUMENTED as err:
        res = [type(err).__name__, str(err)[:300]]
    except BaseException as err:  # noqa: BLE001 - what the fuzz looks for
        res = ["BAD:" + type(err).__name__, str(err)[:300]]
    finally:
        faulthandler.cancel_dump_traceback_later()
    return [case, param, *res, round(time.perf_counter() - t, 3)]


def _emit(row) -> None:
    print(json.dumps(row), flush=True)


def regressions() -> None:
    for case, kw, name in REGRESSIONS:
        call, base = CASES[case]
        args = dict(base, **kw)
        (param, value), *rest = kw.items()
        CASES["_"] = (call, {k: v for k, v in args.items() if k != param})
        _emit([*outcome("_", param, value), case, name])


def fuzz(examples: int) -> None:
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    values = st.one_of(st.sampled_from(HOSTILE), st.integers(-5, 5), st.integers(2**31, 2**70), st.integers(-(2**70), -(2**31)),
                       st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=3),
                       st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=3))
    run = settings(max_examples=examples, derandomize=True, database=None, deadline=None,
                   suppress_health_check=list(HealthCheck))
    def prop(case, param):
        @run
        @given(v=values)
        def each(v):
            _emit(outcome(case, param, v))

        return each

    for case, (_, base) in CASES.items():
        for param in base:
            prop(case, param)()


if __name__ == "__main__":
    faulthandler.enable()
    if sys.argv[1] == "regressions":
        regressions()
    else:
        fuzz(int(sys.argv[2]))
