"""Locating what the continuation driver (:mod:`librate.solving.continuation`) meets between two
accepted points: folds (turning points in the parameter) and sign changes of a problem's test
functions (bifurcations), by Illinois regula falsi on corrections in between; and the driver's
geometry in scaled coordinates (norm, unit tangent)."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .continuation_data import Bifurcation, Constraint, Fold, Point
from .lockstep import correction

__all__ = ["scaled_norm", "unit_tangent", "test_values", "sign_changes", "locate_fold", "locate_natural", "locate_sign"]


def scaled_norm(problem, v) -> float:
    return float(np.linalg.norm(np.asarray(v) / problem.scale))


def unit_tangent(problem, point: Point, reference: np.ndarray | None, fallback: np.ndarray | None) -> np.ndarray | None:
    """Unit tangent in scaled coordinates, oriented along ``reference``."""
    t = problem.tangent(point)
    if t is None or not np.all(np.isfinite(t)) or not np.any(t):
        t = fallback
    if t is None:
        return None
    t = np.asarray(t, dtype=float) / problem.scale
    n = np.linalg.norm(t)
    if n == 0 or not math.isfinite(n):
        return None
    t = t / n
    if reference is not None and float(np.dot(t, reference)) < 0:
        t = -t
    return t


def test_values(problem, point) -> dict[str, float]:
    f = getattr(problem, "tests", None)
    return dict(f(point)) if f is not None else {}


def sign_changes(before: dict[str, float], after: dict[str, float]) -> list[tuple[str, float, float, float]]:
    """The test functions that change sign between two consecutive points: (name, value
    before, value after, w) with w in (0, 1) the zero of their linear interpolation. The one
    detection rule of the driver, also applied to members known without a corrector (e.g. a
    family read from a catalog)."""
    out = []
    for name, v in after.items():
        u = before.get(name)
        if u is not None and math.isfinite(u) and math.isfinite(v) and u * v < 0:
            out.append((name, u, v, u / (u - v)))
    return out


def _illinois(f, a: float, fa: float, b: float, fb: float, done: Callable[[float, float], bool], max_iter: int = 60):
    """Regula falsi (Illinois) on [a, b] with f(a) f(b) < 0; ``f`` (a generator of corrections,
    as this one) returns (value, payload) or None where it cannot be evaluated (then the interval
    is bisected)."""
    side = 0
    best = None
    for _ in range(max_iter):
        if done(a, b):
            break
        c = b - fb * (b - a) / (fb - fa) if fb != fa else 0.5 * (a + b)
        if not (min(a, b) < c < max(a, b)):
            c = 0.5 * (a + b)
        r = yield from f(c)
        if r is None:
            c = 0.5 * (a + b)
            r = yield from f(c)
            if r is None:
                return best, False
        fc, payload = r
        best = (c, payload)
        if fc == 0:
            return best, True
        if (fc > 0) == (fb > 0):
            b, fb = c, fc
            if side == 1:
                fa *= 0.5
            side = 1
        else:
            a, fa = c, fc
            if side == -1:
                fb *= 0.5
            side = -1
    return best, True


def locate_fold(problem, base, t, ds, new, t_new, at, tol) -> Fold:
    """The turning point between ``base`` and ``new``, searched on the hyperplanes
    t . (y - y_base) = s, s in (0, ds): Illinois iterations on g(s) = dp/ds, the parameter's rate
    along them (from the unit tangent at each point). Around the fold p(s) is a parabola, so p*
    is estimated from each end of the bracket, p(a) + g(a) (s* - a) / 2 with s* the zero of g
    interpolated linearly; located when the two estimates agree to ``tol``."""
    k = problem.parameter_index
    sk = float(problem.scale[k])

    def rate(tt):
        return float(tt[k]) * sk / max(float(np.dot(tt, t)), 1e-300)

    a, pa, ga = 0.0, base, rate(t)
    b, pb, gb = ds, new, rate(t_new)
    wa, wb = ga, gb  # the Illinois weights (the rates themselves are kept for the estimates)
    g0 = max(abs(ga), abs(gb))
    side = 0
    est, err = float(new.x[k]), math.inf
    for _ in range(80):
        lin = a - ga * (b - a) / (gb - ga) if gb != ga else 0.5 * (a + b)
        ea = pa.x[k] + 0.5 * ga * (lin - a)
        eb = pb.x[k] + 0.5 * gb * (lin - b)
        est, err = 0.5 * (ea + eb), abs(ea - eb)
        # located: the parameter to tol, and a bracket end on the fold itself (its rate 1e-4 of
        # the step's: quantities that vanish at the fold, det(J), vanish there to that order)
        if err <= tol and min(abs(ga), abs(gb)) <= 1e-4 * g0:
            return Fold(float(est), pa if abs(ga) < abs(gb) else pb, True, float(err))
        c = a - wa * (b - a) / (wb - wa) if wb != wa else 0.5 * (a + b)
        if not a < c < b:
            c = 0.5 * (a + b)
        pc = yield from at(base, t, c)
        tc = None if pc is None else unit_tangent(problem, pc, t, pc.x - base.x)
        if tc is None:
            c = 0.5 * (a + b)
            pc = yield from at(base, t, c)
            tc = None if pc is None else unit_tangent(problem, pc, t, pc.x - base.x)
            if tc is None:
                break
        gc = rate(tc)
        if (gc > 0) == (gb > 0):
            b, pb, gb, wb = c, pc, gc, gc
            if side == 1:
                wa *= 0.5
            side = 1
        else:
            a, pa, ga, wa = c, pc, gc, gc
            if side == -1:
                wb *= 0.5
            side = -1
        if b - a <= 1e-15 * ds:
            break
    return Fold(float(est), pa if abs(ga) < abs(gb) else pb, False, float(err))


def locate_natural(problem, name, a: Point, b: Point, u: float, v: float, tol: float):
    """A sign change of the test ``name`` between the accepted points ``a`` and ``b`` of a
    natural-parameter run, located to ``tol`` in the parameter: Illinois iterations on the test
    function of points corrected at fixed parameter values (guesses interpolated linearly)."""
    k = problem.parameter_index
    n = a.x.size

    def f(p):
        w = (p - a.x[k]) / (b.x[k] - a.x[k])
        guess = a.x + w * (b.x - a.x)
        guess[k] = p
        pt = yield from correction(problem, guess, Constraint.fix(n, k, p))
        val = None if pt is None else test_values(problem, pt).get(name)
        return None if val is None or not math.isfinite(val) else (val, pt)

    best, ok = yield from _illinois(f, float(a.x[k]), u, float(b.x[k]), v, lambda lo, hi: abs(hi - lo) <= tol)
    if best is None or not ok:
        w = u / (u - v)
        return Bifurcation(name, float(a.x[k] + w * (b.x[k] - a.x[k])), b if best is None else best[1], False)
    return Bifurcation(name, float(best[0]), best[1], True)


def locate_sign(problem, name, base, t, ds, u, v, new, at, tol) -> Bifurcation:
    k = problem.parameter_index

    def f(s):
        pt = yield from at(base, t, s)
        if pt is None:
            return None
        val = test_values(problem, pt).get(name)
        if val is None or not math.isfinite(val):
            return None
        return val, pt

    state = {"last": None}

    def g(s):
        r = yield from f(s)
        if r is not None:
            state["last"] = r[1]
        return r

    def done(a, b):
        return abs(b - a) * max(abs(t[k]), 1e-16) * problem.scale[k] <= tol

    best, ok = yield from _illinois(g, 0.0, u, ds, v, done)
    if best is None or not ok:
        # not located (the corrector cannot converge next to it, as at a branch point, where the
        # extended Jacobian is singular): the linear interpolation of the test function
        w = u / (u - v)
        return Bifurcation(name, float(base.x[k] + w * (new.x[k] - base.x[k])), new if best is None else best[1], False)
    return Bifurcation(name, float(best[1].x[k]), best[1], ok)

