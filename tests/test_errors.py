"""Bad inputs raise the documented exceptions, naming the parameter (never a panic, never NaN)."""

import math

import librate
import numpy as np
import pytest

EM = librate.System.preset("earth-moon")
S0 = [0.85, 0, 0, 0, 0.47, 0]

CASES = [
    # (description, callable, exception, text that must appear in the message)
    ("mu above 0.5", lambda: librate.System(mu=0.6, lu_km=1, tu_s=1), ValueError, "mu"),
    ("mu zero", lambda: librate.System(mu=0.0, lu_km=1, tu_s=1), ValueError, "(0, 0.5]"),
    ("mu NaN", lambda: librate.System(mu=math.nan, lu_km=1, tu_s=1), ValueError, "mu"),
    ("negative length unit", lambda: librate.System(mu=0.1, lu_km=-1, tu_s=1), ValueError, "lu_km"),
    ("infinite time unit", lambda: librate.System(mu=0.1, lu_km=1, tu_s=math.inf), ValueError, "tu_s"),
    ("unknown preset", lambda: librate.System.preset("mars-phobos"), ValueError, "earth-moon"),
    ("system of wrong type", lambda: librate.propagate(0.01215, S0, 1.0), ValueError, "system"),
    ("state of 5 components", lambda: librate.propagate(EM, S0[:5], 1.0), ValueError, "state"),
    ("state with NaN", lambda: librate.propagate(EM, [math.nan, 0, 0, 0, 0.5, 0], 1.0), ValueError, "state"),
    ("state with inf", lambda: librate.propagate(EM, [0.8, 0, 0, 0, math.inf, 0], 1.0), ValueError, "state"),
    ("rtol zero", lambda: librate.propagate(EM, S0, 1.0, rtol=0.0), ValueError, "rtol"),
    ("atol negative", lambda: librate.propagate(EM, S0, 1.0, atol=-1e-12), ValueError, "atol"),
    ("rtol NaN", lambda: librate.propagate(EM, S0, 1.0, rtol=math.nan), ValueError, "rtol"),
    ("t_span of three", lambda: librate.propagate(EM, S0, (0, 1, 2)), ValueError, "t_span"),
    ("t_span infinite", lambda: librate.propagate(EM, S0, math.inf), ValueError, "t_span"),
    ("t_eval reversed", lambda: librate.propagate(EM, S0, 1.0, t_eval=[0.5, 0.2]), ValueError, "t_eval"),
    ("t_eval outside span", lambda: librate.propagate(EM, S0, 1.0, t_eval=[2.0]), ValueError, "t_eval"),
    ("max_steps zero", lambda: librate.propagate(EM, S0, 1.0, max_steps=0), ValueError, "max_steps"),
    ("safety above one", lambda: librate.propagate(EM, S0, 1.0, safety=2.0), ValueError, "safety"),
    ("fixed step negative", lambda: librate.propagate(EM, S0, 1.0, fixed_step=-0.1), ValueError, "fixed_step"),
    ("h_max below h_min", lambda: librate.propagate(EM, S0, 1.0, h_min=0.1, h_max=0.01), ValueError, "h_max"),
    ("event not an Event", lambda: librate.propagate(EM, S0, 1.0, events=[lambda t, y: y[1]]), ValueError, "events"),
    ("unknown coordinate", lambda: librate.Event.crossing("w"), ValueError, "coordinate"),
    ("bad direction", lambda: librate.Event.crossing("y", direction=2), ValueError, "direction"),
    ("negative radius", lambda: librate.Event.distance([0, 0, 0], -1.0), ValueError, "radius"),
    ("unknown primary", lambda: librate.Event.surface("sun"), ValueError, "primary"),
    ("batch of 5 columns", lambda: librate.propagate_many(EM, np.zeros((3, 5)), 1.0), ValueError, "states"),
    ("batch with NaN", lambda: librate.propagate_many(EM, [S0, [math.nan] * 6], 1.0), ValueError, "states"),
    ("batch t_final mismatch", lambda: librate.propagate_many(EM, [S0, S0, S0], [1.0, 2.0]), ValueError, "t_final"),
    ("batch zero threads", lambda: librate.propagate_many(EM, [S0], 1.0, threads=0), ValueError, "threads"),
    ("batch on_error", lambda: librate.propagate_many(EM, [S0], 1.0, on_error="ignore"), ValueError, "on_error"),
    ("jacobi wrong shape", lambda: EM.jacobi(np.zeros((2, 3))), ValueError, "states"),
    ("DRO x0 beyond the Moon", lambda: librate.correct_dro(EM, 1.2), ValueError, "x0"),
    ("DRO negative ydot0", lambda: librate.correct_dro(EM, 0.9, -0.5), ValueError, "ydot0"),
    ("DRO tolerance zero", lambda: librate.correct_dro(EM, 0.9, tol=0.0), ValueError, "tol"),
]


@pytest.mark.parametrize("desc, call, exc, text", CASES, ids=[c[0] for c in CASES])
def test_bad_input_raises_named_error(desc, call, exc, text):
    with pytest.raises(exc) as info:
        call()
    assert text in str(info.value), f"{desc}: message {info.value!s} does not name {text!r}"


def test_exception_hierarchy():
    assert issubclass(librate.IntegrationError, librate.LibrateError)
    assert issubclass(librate.ConvergenceError, librate.LibrateError)
    assert issubclass(librate.LibrateError, Exception)
    assert librate.IntegrationError.__module__ == "librate"
