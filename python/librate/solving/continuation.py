"""The continuation driver: one place for predictor, step-size rules, jump guards, folds and
bifurcations, shared by every family in librate (periodic orbits, periodic attitude motions in
Kz, in the SRP amplitude or across an orbit family, flexible re-solves).

A *problem* owns the equations and their corrector (in the Rust core); the driver never runs a
Newton iteration itself. The problem's unknowns and parameter form one vector ``x`` (the
parameter at ``problem.parameter_index``), and its ``correct`` solves the equations together
with one linear condition ``a . x = b`` that the driver chooses:

- natural-parameter continuation fixes the parameter: ``a = e_p``, ``b = p``;
- pseudo-arclength continuation fixes the step along the unit tangent ``t_k`` at the last point:
  ``a = t_k``, ``b = t_k . x_k + ds``.

Both modes share the step rules: a step that fails to correct, or whose corrected point lands
farther from the prediction than ``jump`` times the step (a silent jump to another branch), is
halved; an easy step (at most ``easy_iterations`` corrector iterations) grows the next one by
``growth``, up to ``ds_max``; the run ends with a reason when the step falls below ``ds_min``.
The problem may add its own guard (orbit families check Jacobi-constant continuity and winding
numbers).

Folds (turning points in the parameter) are detected where the parameter component of the
tangent changes sign between two accepted points and are then *located*: the arclength between
the two points is searched (Illinois regula falsi on that tangent component) until the fold's
parameter is known to ``fold_tol``. Bifurcations are detected where a problem's test function
(for example a stability index minus one) changes sign, and located the same way.

The algorithms are generators (:func:`arclength_steps`, :func:`natural_steps`): they yield each
correction they need and receive the corrected point. :func:`arclength` and :func:`natural`
correct them one by one; :func:`run_lockstep` advances many branches together and corrects each
round's requests in one call per group of compatible problems (``batch_key``/``correct_many``:
for example every branch of an SRP map in one Rust call, the SIMD lanes full). A branch takes
the same path either way.

The driver's data (points, conditions, branches, step rules) is in
:mod:`librate.solving.continuation_data`, the runners in :mod:`librate.solving.lockstep`, the
location of folds and bifurcations in :mod:`librate.solving.locate`; every name is importable
from here.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence

import numpy as np

from .._errors import LibrateError
from .continuation_data import Bifurcation, Branch, Constraint, ContinuationProblem, CorrectionFailed, Fold, Point, StepRules
from .locate import locate_fold, locate_natural, locate_sign, scaled_norm, sign_changes, test_values, unit_tangent
from .lockstep import Marks, correct_marks, correct_together, correction, run_alone, run_lockstep

__all__ = [
    "Point",
    "Constraint",
    "Fold",
    "Bifurcation",
    "Branch",
    "ContinuationProblem",
    "CorrectionFailed",
    "StepRules",
    "natural",
    "natural_steps",
    "arclength",
    "arclength_steps",
    "run_lockstep",
    "correct_together",
    "correct_marks",
    "sign_changes",
]


def _guard(problem, points, new, ratio) -> str | None:
    f = getattr(problem, "guard", None)
    return f(points, new, ratio) if f is not None else None


def natural(problem: ContinuationProblem, first: Point, targets: Sequence[float], **options) -> Branch:
    """Natural-parameter continuation (:func:`natural_steps`), each correction alone."""
    return run_alone(problem, natural_steps(problem, first, targets, **options))


def natural_steps(
    problem: ContinuationProblem,
    first: Point,
    targets: Sequence[float],
    *,
    rules: StepRules | None = None,
    name: str = "parameter",
    stop: Callable[[Point], str | None] | None = None,
    locate_bifurcations: bool = True,
    tol: float = 1e-8,
):
    """Natural-parameter continuation through the parameter values ``targets`` (the points
    returned are exactly at them). Prediction: linear extrapolation of every component from the
    last two corrected points (thesis eq. 20-22). Between targets the step is halved on a failed
    correction or a jump and doubled after a success; the run ends at the last target, at a
    ``stop`` reason, or when the step falls below ``rules.ds_min`` (in the parameter) with the
    reason. A fold ahead shows as the step collapsing: the end reason then names the last
    parameter reached. Bifurcations: where a test function of ``problem.tests`` changes sign
    between two accepted points, located to ``tol`` in the parameter by corrections at fixed
    parameter values in between (Illinois), unless ``locate_bifurcations`` is False (then
    interpolated linearly). A generator: it yields its corrections (:func:`run_lockstep`) and
    returns the Branch."""
    rules = rules or StepRules()
    k = problem.parameter_index
    n = first.x.size
    history = [first]
    tests_prev = test_values(problem, first)
    out: list[Point] = []
    branch = Branch(out)
    for target in (float(v) for v in np.atleast_1d(np.asarray(targets, dtype=float))):
        cur = float(history[-1].x[k])
        if target == cur:
            out.append(history[-1])
            continue
        h = target - cur
        while True:
            trial = target if abs(h) >= abs(target - cur) * (1 - 1e-6) else cur + h
            last = history[-1]
            if len(history) >= 2:
                prev = history[-2]
                dk = last.x[k] - prev.x[k]
                guess = last.x + (last.x - prev.x) * ((trial - last.x[k]) / dk) if dk != 0 else last.x.copy()
                prev_step = abs(dk)
            else:
                guess = last.x.copy()
                prev_step = abs(trial - last.x[k])
            guess[k] = trial
            pt = yield from correction(problem, guess, Constraint.fix(n, k, trial))
            status = "fail"
            if pt is not None:
                ratio = abs(trial - last.x[k]) / max(prev_step, 1e-300)
                moved = scaled_norm(problem, pt.x - guess)
                # the secant predictor's error is a fraction of the larger of this step and the
                # last one; a corrected point farther off is another branch
                reach = (max(scaled_norm(problem, guess - last.x), scaled_norm(problem, last.x - history[-2].x))
                         if len(history) >= 2 else 0.0)
                if len(history) >= 2 and moved > rules.jump * reach + 1e-9 * (1 + scaled_norm(problem, last.x)):
                    status = "jump"
                elif _guard(problem, history, pt, ratio):
                    status = "jump"
                else:
                    status = "ok"
            if status == "ok":
                tests_new = test_values(problem, pt)
                for test, u, v, w in sign_changes(tests_prev, tests_new):
                    if locate_bifurcations:
                        b = yield from locate_natural(problem, test, last, pt, u, v, tol)
                    else:
                        b = Bifurcation(test, float(last.x[k] + w * (pt.x[k] - last.x[k])), pt, False)
                    # "after": the index of the last returned point (at a target) before it
                    branch.bifurcations.append(dataclasses.replace(b, after=len(out) - 1))
                tests_prev = tests_new
                history.append(pt)
                why = stop(pt) if stop else None
                if why:
                    branch.end_reason = why
                    return branch
                cur = trial
                if trial == target:
                    out.append(pt)
                    break
                h *= 2.0
            else:
                branch.rejected_jumps += status == "jump"
                h *= 0.5
                if abs(h) < rules.ds_min:
                    branch.end_reason = f"step floor: could not continue past {name} = {cur:.12g} (step below {rules.ds_min:g})"
                    return branch
    branch.end_reason = "completed: reached the last requested value"
    branch.reached = True
    return branch


def arclength(problem: ContinuationProblem, first: Point, **options) -> Branch:
    """Pseudo-arclength continuation (:func:`arclength_steps`), each correction alone."""
    return run_alone(problem, arclength_steps(problem, first, **options))


def _bend(points: list, t: np.ndarray, sx: np.ndarray, h: float, ds: float) -> np.ndarray | None:
    """The second derivative in arclength of the branch at its last point, from the point before
    (a step ``h`` back) and the unit tangent ``t`` there (in the scaled coordinates x / sx):
    x(-h) = x - h x' + h^2/2 x''. For a quadratic predictor x + ds x' + ds^2/2 x''; None without
    a point before, or when that term would move the guess by more than ds/4 (scaled; a sharp
    turn: the linear predictor is safer)."""
    if len(points) < 2 or h <= 0.0:
        return None
    c = 2.0 * (points[-2].x - points[-1].x + h * t * sx) / (h * h)
    if not (np.all(np.isfinite(c)) and 0.5 * ds * ds * float(np.linalg.norm(c / sx)) <= 0.25 * ds):
        return None
    return c


def _mark_guess(x0: np.ndarray, m0: np.ndarray, x1: np.ndarray, m1: np.ndarray, k: int, value: float) -> np.ndarray:
    """The guess for the point at parameter ``value`` between two points of a step: the cubic
    Hermite curve through x0 and x1 with end derivatives m0, m1 (the unit tangents times the
    step), at the curve parameter where component k equals ``value`` (Newton from the chord's
    crossing). Its error is O(ds^4) against the chord's O(ds^2), so the mark's correction needs
    fewer Newton steps; where the cubic is not monotone in component k over the step, or its
    crossing leaves the step, the chord's point."""
    w = (value - x0[k]) / (x1[k] - x0[k])
    chord = x0 + w * (x1 - x0)
    chord[k] = value

    def hermite(u: float, a0, b0, a1, b1):
        u2, u3 = u * u, u * u * u
        return (2 * u3 - 3 * u2 + 1) * a0 + (u3 - 2 * u2 + u) * b0 + (3 * u2 - 2 * u3) * a1 + (u3 - u2) * b1

    # the Newton iteration needs only component k: the same operations on floats
    xk0, mk0, xk1, mk1 = float(x0[k]), float(m0[k]), float(x1[k]), float(m1[k])

    def slope(u: float) -> float:
        u2 = u * u
        return (6 * u2 - 6 * u) * xk0 + (3 * u2 - 4 * u + 1) * mk0 + (6 * u - 6 * u2) * xk1 + (3 * u2 - 2 * u) * mk1

    if slope(0.0) * slope(1.0) <= 0 or slope(0.5) * slope(0.0) <= 0:
        return chord
    u = w
    for _ in range(20):
        d = slope(u)
        step = (hermite(u, xk0, mk0, xk1, mk1) - value) / d
        u -= step
        if not 0.0 <= u <= 1.0:
            return chord
        if abs(step) <= 1e-15:
            break
    guess = hermite(u, x0, m0, x1, m1)
    guess[k] = value
    return guess if np.all(np.isfinite(guess)) else chord


def arclength_steps(
    problem: ContinuationProblem,
    first: Point,
    *,
    direction: np.ndarray | int = 1,
    rules: StepRules | None = None,
    max_points: int = 500,
    bounds: tuple[float, float] | None = None,
    target: float | None = None,
    locate: bool = True,
    fold_tol: float = 1e-8,
    stop_at_fold: bool = False,
    locate_bifurcations: bool = True,
    marks: Sequence[float] = (),
    name: str = "parameter",
    stop: Callable[[Point], str | None] | None = None,
):
    """Pseudo-arclength continuation from ``first``, through folds. A generator: it yields its
    corrections (:func:`run_lockstep` corrects those of many branches together) and returns the
    Branch.

    ``direction``: the initial sense, a vector in x or +-1 for the sense of the parameter.
    ``bounds``: the parameter's range; the branch ends on the bound it reaches (the last point
    corrected exactly there). ``target``: a parameter value at which to stop, landing exactly on
    it (``Branch.reached``). Folds are located to ``fold_tol`` in the parameter and bifurcations
    (sign changes of ``problem.tests``) to the same tolerance when ``locate``; a fold is passed
    and the branch followed on, back in the parameter, unless ``stop_at_fold`` (then the branch
    ends at the located fold: its last point is the turning point, within ``fold_tol``).
    ``locate_bifurcations=False`` reports them at the linear interpolation of the test function
    (cheaper; branch points cannot be located more finely by a corrector anyway, the extended
    Jacobian being singular there). ``marks``: parameter values at which
    the branch is also corrected exactly, each time a step crosses one (``Branch.marked``; a
    branch that folds back over a value marks it again).
    """
    rules = rules or StepRules()
    k = problem.parameter_index
    n = first.x.size
    lo, hi = bounds if bounds is not None else (-math.inf, math.inf)
    if isinstance(direction, (int, np.integer)):
        if direction not in (-1, 1):
            raise ValueError(f"invalid argument `direction`: must be -1, +1 or a vector, got {direction!r}")
        ref = np.zeros(n)
        ref[k] = float(direction)
    else:
        ref = np.asarray(direction, dtype=float) / problem.scale
    t = unit_tangent(problem, first, ref, None)
    if t is None:
        raise LibrateError("continuation: the tangent at the first point is undefined (singular Jacobian)")
    if t[k] * ref[k] < 0 or (ref[k] == 0 and float(np.dot(t, ref)) < 0):
        t = -t
    points = [first]
    branch = Branch(points)
    pending_marks: list = []  # (guess, condition, step, point if already on the mark)

    def finish():
        """Correct the marks met on the way, in one batch when the problem can
        (``correct_batch``), and keep those that land near their guess."""
        todo = [i for i, pm in enumerate(pending_marks) if pm[3] is None]
        got: dict[int, Point | None] = {}
        if todo:
            got = dict(zip(todo, (yield Marks((pending_marks[i][0], pending_marks[i][1]) for i in todo))))
        for i, (guess, _, step, on) in enumerate(pending_marks):
            pm = on if on is not None else got.get(i)
            if pm is not None and scaled_norm(problem, pm.x - guess) <= rules.jump * step + 1e-12:
                branch.marked.append(pm)
        return branch
    tests_prev = test_values(problem, first)
    ds = rules.ds
    last_ds = 0.0
    sx = problem.scale

    def constraint(base: Point, tb: np.ndarray, s: float) -> Constraint:
        # t (scaled) . (x - x_k)/scale = s  <=>  (t/scale) . x = (t/scale) . x_k + s
        a = tb / sx
        return Constraint(a, float(np.dot(a, base.x)) + s)

    def at(base: Point, tb: np.ndarray, s: float, bend: np.ndarray | None = None):
        """Correct the point ``s`` along ``tb`` from ``base``; ``bend``: the curve's second
        derivative in arclength, for a quadratic predictor (the guess only: the point is the
        same)."""
        guess = base.x + s * tb * sx
        if bend is not None:
            guess = guess + 0.5 * s * s * bend
        return (yield from correction(problem, guess, constraint(base, tb, s)))

    def land(value: float):
        """The point exactly at parameter ``value``, from the last point along the tangent."""
        last = points[-1]
        dp = t[k] * sx[k]
        guess = last.x + (value - last.x[k]) / dp * t * sx if dp != 0 else last.x.copy()
        guess[k] = value
        pt = yield from correction(problem, guess, Constraint.fix(n, k, value))
        reach = max(scaled_norm(problem, guess - last.x), rules.ds_min)
        if pt is not None and scaled_norm(problem, pt.x - guess) <= rules.jump * reach + 1e-9:
            return pt
        return None

    while len(points) < max_points:
        base = points[-1]
        while True:
            pred = base.x + ds * t * sx
            p_pred = pred[k]
            # the parameter range or the target lies within this step: land exactly on it (when
            # that fails, the branch may turn back first: shorter steps find out)
            edge = next(((e, r, ok) for e, r, ok in ((target, "reached the target parameter", True), (lo, "parameter range end", False),
                                                     (hi, "parameter range end", False))
                         if e is not None and math.isfinite(e) and (base.x[k] - e) * (p_pred - e) < 0 and base.x[k] != e), None)
            if edge is not None:
                landed = yield from land(edge[0])
                if landed is not None:
                    points.append(landed)
                    branch.reached = edge[2]
                    branch.end_reason = f"{edge[1]}: {name} = {edge[0]:.12g}"
                    return (yield from finish())
                ds *= 0.5
                if ds < rules.ds_min:
                    branch.end_reason = (f"step floor: could not land on {name} = {edge[0]:.12g} from {base.x[k]:.12g} "
                                         f"(step below {rules.ds_min:g})")
                    return (yield from finish())
                continue
            new = yield from at(base, t, ds, _bend(points, t, sx, last_ds, ds) if rules.predictor == "quadratic" else None)
            status = "fail"
            t_new = None
            if new is not None:
                moved = scaled_norm(problem, new.x - pred)
                if moved > rules.jump * ds + 1e-12:
                    status = "jump"
                elif _guard(problem, points, new, 1.0):
                    status = "jump"
                else:
                    t_new = unit_tangent(problem, new, t, (new.x - base.x))
                    if t_new is None:
                        status = "fail"
                    elif math.acos(max(-1.0, min(1.0, float(np.dot(t_new, t))))) > rules.max_turn:
                        status = "jump"
                    else:
                        status = "ok"
            if status == "ok":
                break
            branch.rejected_jumps += status == "jump"
            ds *= 0.5
            if ds < rules.ds_min:
                branch.end_reason = (f"step floor: arclength step below {rules.ds_min:g} at {name} = {base.x[k]:.12g} "
                                     f"after {len(points)} points")
                return (yield from finish())
        assert t_new is not None and new is not None
        # the points inside this step (locating a fold or a sign change) start on the quadratic
        # through base, with its tangent, and new
        bend = 2.0 * (new.x - base.x - ds * t * sx) / (ds * ds)

        def within(b_, tb, s_, bend=bend):
            return at(b_, tb, s_, bend)

        # a fold: the parameter component of the tangent changes sign
        if t[k] * t_new[k] < 0:
            fold = ((yield from locate_fold(problem, base, t, ds, new, t_new, within, fold_tol)) if locate
                    else Fold(float(new.x[k]), new, False, abs(new.x[k] - base.x[k])))
            branch.folds.append(fold)
            if stop_at_fold:
                if fold.located:
                    points.append(fold.point)  # the branch ends on its turning point
                branch.end_reason = (f"fold at {name} = {fold.parameter:.12g}"
                                     + ("" if fold.located else f" (not located: within {fold.tolerance:.2g})"))
                return (yield from finish())
        tests_new = test_values(problem, new)
        for test, u, v, w in sign_changes(tests_prev, tests_new):
            if locate and locate_bifurcations:
                b = yield from locate_sign(problem, test, base, t, ds, u, v, new, within, fold_tol)
            else:  # the linear interpolation of the test function between the two points
                b = Bifurcation(test, float(base.x[k] + w * (new.x[k] - base.x[k])), new, False)
            branch.bifurcations.append(dataclasses.replace(b, after=len(points) - 1))
        tests_prev = tests_new
        for m in marks:
            if (base.x[k] - m) * (new.x[k] - m) < 0 or new.x[k] == m:
                guess = _mark_guess(base.x, t * sx * ds, new.x, t_new * sx * ds, k, m)
                pending_marks.append((guess, Constraint.fix(n, k, m), ds, new if new.x[k] == m else None))
        points.append(new)
        t = t_new
        last_ds = ds
        why = stop(new) if stop else None
        if why:
            branch.end_reason = why
            return (yield from finish())
        if new.iterations <= rules.easy_iterations:
            ds = max(ds, min(ds * rules.growth, rules.ds_max))  # grows to ds_max, never shrinks (a first ds above it)
    branch.end_reason = f"completed: max_points = {max_points} reached"
    return (yield from finish())

