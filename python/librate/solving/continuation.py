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
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from .._errors import LibrateError

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


class CorrectionFailed(LibrateError):
    """A problem's corrector did not converge for the requested condition."""


@dataclass(frozen=True)
class Point:
    """One corrected point: the vector ``x`` (unknowns and parameter), the problem's payload
    (e.g. a PeriodicOrbit or an AttitudeSolution) and the corrector's iteration count."""

    x: np.ndarray
    data: Any = None
    iterations: int = 0


@dataclass(frozen=True)
class Constraint:
    """The linear condition a . x = b that closes the problem's equations."""

    a: np.ndarray
    b: float

    @staticmethod
    def fix(n: int, index: int, value: float) -> Constraint:
        a = np.zeros(n)
        a[index] = 1.0
        return Constraint(a, float(value))

    @property
    def fixed_index(self) -> int | None:
        """The component the condition fixes, when it fixes one (natural continuation)."""
        nz = np.flatnonzero(self.a)
        return int(nz[0]) if nz.size == 1 and self.a[nz[0]] == 1.0 else None


@dataclass(frozen=True)
class Fold:
    """A turning point in the parameter: ``parameter`` located to ``tolerance`` (``located``
    False when the search could not be carried out and the value is interpolated)."""

    parameter: float
    point: Point
    located: bool
    tolerance: float


@dataclass(frozen=True)
class Bifurcation:
    """Where the problem's test function ``name`` changes sign: ``parameter`` (located to the
    run's tolerance, or ``located`` False: interpolated linearly in the test function), the
    ``point`` there (or the nearest corrected one) and ``after``, the index of the branch's
    point before it."""

    name: str
    parameter: float
    point: Point
    located: bool
    after: int = -1


@dataclass
class Branch:
    """A continued branch: its points in order, the folds and bifurcations met on the way, why
    it ended, and how many steps were rejected as jumps."""

    points: list[Point]
    folds: list[Fold] = field(default_factory=list)
    bifurcations: list[Bifurcation] = field(default_factory=list)
    end_reason: str = ""
    rejected_jumps: int = 0
    reached: bool = False
    #: points corrected exactly at requested parameter values met on the way (``marks``), in order
    marked: list[Point] = field(default_factory=list)

    def parameter(self, index: int) -> np.ndarray:
        return np.array([p.x[index] for p in self.points])


class ContinuationProblem(Protocol):
    """What the driver needs from a problem.

    ``parameter_index``: the parameter's component in x. ``scale``: per-component scales that
    make distances in x comparable (steps, jump guard). ``correct(guess, constraint)``: solve
    the problem's equations together with ``constraint`` from ``guess``; raise
    CorrectionFailed (or any LibrateError) on failure. ``tangent(point)``: the (unnormalised)
    null vector of the equations' Jacobian at the point (None: the driver uses secants).
    Optional: ``guard(points, new, ratio)`` returns a reason to reject ``new`` (a jump) or None;
    ``tests(point)`` returns named bifurcation test functions; ``correct_batch(guesses,
    constraints)`` corrects many independent points at once (a list of Point or None), used for
    the marks of :func:`arclength`; ``batch_key`` (hashable) with ``correct_many(requests)``:
    problems of one type with equal keys correct the requests [(problem, guess, constraint)] of
    several branches in one call (:func:`run_lockstep`), and their ``correct_batch`` takes
    ``problems=`` (the owner of each guess) to correct the marks of several branches at once.
    """

    parameter_index: int
    scale: np.ndarray

    def correct(self, guess: np.ndarray, constraint: Constraint) -> Point: ...

    def tangent(self, point: Point) -> np.ndarray | None: ...


@dataclass(frozen=True)
class StepRules:
    """The one set of step-size rules and jump guards.

    ``ds``, ``ds_min``, ``ds_max``: initial, smallest and largest step (scaled units).
    ``growth``: factor after an easy step (at most ``easy_iterations`` corrector iterations).
    ``jump``: largest accepted distance of the corrected point from the prediction, as a
    fraction of the step. ``max_turn``: largest angle (rad) between consecutive tangents.
    ``predictor`` (pseudo-arclength): "linear" (along the tangent) or "quadratic" (the curve's
    second derivative from the point before added: an O(ds^3) guess, fewer corrector iterations
    and so longer steps; the points are the same, their spacing is not).
    """

    ds: float = 1e-2
    ds_min: float = 1e-7
    ds_max: float = 5e-2
    growth: float = 1.5
    easy_iterations: int = 3
    jump: float = 0.5
    max_turn: float = 0.5
    predictor: str = "linear"

    def __post_init__(self):
        if self.predictor not in ("linear", "quadratic"):
            raise ValueError(f"invalid argument `predictor`: must be 'linear' or 'quadratic', got {self.predictor!r}")
        for name in ("ds", "ds_min", "ds_max", "growth", "jump", "max_turn"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"invalid argument `{name}`: must be a finite number > 0, got {v!r}")
        if not self.ds_min <= self.ds_max:
            raise ValueError(f"invalid arguments `ds_min`, `ds_max`: ds_min must not exceed ds_max, got ds_min = {self.ds_min}, ds_max = {self.ds_max}")
        if self.growth < 1:
            raise ValueError(f"invalid argument `growth`: must be >= 1, got {self.growth}")


def _try(problem, guess, constraint):
    """Ask the runner to correct ``guess`` under ``constraint`` (a generator step: the driver's
    algorithms yield their corrections, so that one runner can correct the requests of many
    branches together); the corrected Point, or None when the correction failed."""
    pt = yield (np.asarray(guess, dtype=float), constraint)
    return pt


class _Marks(list):
    """A request for many independent corrections at once (a branch's marks): [(guess,
    constraint)], answered with a list of Point or None."""


def _correct(problem, guess, constraint) -> Point | None:
    """The one place a problem's corrector is called for a single point."""
    try:
        pt = problem.correct(guess, constraint)
    except LibrateError:
        return None
    return _finite(pt)


def _finite(pt: Point | None) -> Point | None:
    return pt if pt is not None and np.all(np.isfinite(pt.x)) else None


def _run(problem, steps):
    """Drive one branch's generator, correcting each request alone."""
    try:
        request = next(steps)
        while True:
            answer = correct_marks([(problem, *r) for r in request]) if isinstance(request, _Marks) else _correct(problem, *request)
            request = steps.send(answer)
    except StopIteration as done:
        return done.value


def _groups(problems, method: str) -> dict:
    """Indices of the problems that one call of ``method`` can serve together (same type and
    ``batch_key``); a problem without either stands alone."""
    groups: dict = {}
    for i, problem in enumerate(problems):
        key = getattr(problem, "batch_key", None)
        groups.setdefault((type(problem), key) if key is not None and hasattr(problem, method) else ("alone", id(problem)), []).append(i)
    return groups


def correct_marks(requests: list) -> list[Point | None]:
    """Independent corrections at fixed parameter values [(problem, guess, constraint)] (the
    marks of one or many branches): one ``correct_batch(guesses, constraints, problems)`` call
    per group of compatible problems (``batch_key``), else the problem's own ``correct_batch``,
    else one by one."""
    out: list[Point | None] = [None] * len(requests)
    for key, idx in _groups([r[0] for r in requests], "correct_batch").items():
        problem = requests[idx[0]][0]
        batch = getattr(problem, "correct_batch", None)
        if batch is None:
            for i in idx:
                out[i] = _correct(*requests[i])
            continue
        extra = {} if key[0] == "alone" else {"problems": [requests[i][0] for i in idx]}
        try:
            got = batch([requests[i][1] for i in idx], [requests[i][2] for i in idx], **extra)
        except LibrateError:
            got = [None] * len(idx)
        for i, pt in zip(idx, got):
            out[i] = _finite(pt)
    return out


def correct_together(requests: list) -> list[Point | None]:
    """Correct one round of requests [(problem, guess, constraint)] of lock-step branches:
    problems that share a ``batch_key`` are corrected in one call of their ``correct_many``
    (e.g. one Rust call integrating every branch's trajectories in the SIMD lanes), the others
    one by one. Results in request order."""
    out: list[Point | None] = [None] * len(requests)
    for key, idx in _groups([r[0] for r in requests], "correct_many").items():
        if key[0] == "alone":
            for i in idx:
                out[i] = _correct(*requests[i])
            continue
        problem = requests[idx[0]][0]
        try:
            got = problem.correct_many([requests[i] for i in idx])
        except LibrateError:
            got = [None] * len(idx)
        for i, pt in zip(idx, got):
            out[i] = _finite(pt)
    return out


def run_lockstep(branches: Sequence[tuple[Any, Any]], done: Callable[[int], None] | None = None) -> list:
    """Run several continuations in lock step: ``branches`` are (problem, steps) pairs, steps a
    generator from :func:`arclength_steps` (or :func:`natural_steps`); each round, every live
    branch's pending correction is gathered and corrected together (:func:`correct_together`).
    Returns each generator's result (a Branch), in order. Each branch takes exactly the path it
    takes alone: only the grouping of the corrector calls changes. ``done(i)`` is called as
    branch i ends (e.g. for progress)."""
    results: list = [None] * len(branches)
    pending: dict[int, tuple] = {}
    for i, (problem, steps) in enumerate(branches):
        try:
            pending[i] = next(steps)
        except StopIteration as end:
            results[i] = end.value
            if done is not None:
                done(i)
    while pending:
        order = sorted(pending)
        single = [i for i in order if not isinstance(pending[i], _Marks)]
        answers = dict(zip(single, correct_together([(branches[i][0], *pending[i]) for i in single])))
        flat = [(i, r) for i in order if isinstance(pending[i], _Marks) for r in pending[i]]
        got = iter(correct_marks([(branches[i][0], *r) for i, r in flat]))
        for i in order:
            if isinstance(pending[i], _Marks):
                answers[i] = [next(got) for _ in pending[i]]
        for i in order:
            try:
                pending[i] = branches[i][1].send(answers[i])
            except StopIteration as end:
                results[i] = end.value
                del pending[i]
                if done is not None:
                    done(i)
    return results


def _norm(problem, v) -> float:
    return float(np.linalg.norm(np.asarray(v) / problem.scale))


def _unit_tangent(problem, point: Point, reference: np.ndarray | None, fallback: np.ndarray | None) -> np.ndarray | None:
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


def _tests(problem, point) -> dict[str, float]:
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


def _guard(problem, points, new, ratio) -> str | None:
    f = getattr(problem, "guard", None)
    return f(points, new, ratio) if f is not None else None


def natural(problem: ContinuationProblem, first: Point, targets: Sequence[float], **options) -> Branch:
    """Natural-parameter continuation (:func:`natural_steps`), each correction alone."""
    return _run(problem, natural_steps(problem, first, targets, **options))


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
    tests_prev = _tests(problem, first)
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
            pt = yield from _try(problem, guess, Constraint.fix(n, k, trial))
            status = "fail"
            if pt is not None:
                ratio = abs(trial - last.x[k]) / max(prev_step, 1e-300)
                moved = _norm(problem, pt.x - guess)
                # the secant predictor's error is a fraction of the larger of this step and the
                # last one; a corrected point farther off is another branch
                reach = max(_norm(problem, guess - last.x), _norm(problem, last.x - history[-2].x)) if len(history) >= 2 else 0.0
                if len(history) >= 2 and moved > rules.jump * reach + 1e-9 * (1 + _norm(problem, last.x)):
                    status = "jump"
                elif _guard(problem, history, pt, ratio):
                    status = "jump"
                else:
                    status = "ok"
            if status == "ok":
                tests_new = _tests(problem, pt)
                for test, u, v, w in sign_changes(tests_prev, tests_new):
                    if locate_bifurcations:
                        b = yield from _locate_natural(problem, test, last, pt, u, v, tol)
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
    return _run(problem, arclength_steps(problem, first, **options))


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

    def curve(u: float) -> np.ndarray:
        u2, u3 = u * u, u * u * u
        return (2 * u3 - 3 * u2 + 1) * x0 + (u3 - 2 * u2 + u) * m0 + (3 * u2 - 2 * u3) * x1 + (u3 - u2) * m1

    def slope(u: float) -> float:
        u2 = u * u
        return float((6 * u2 - 6 * u) * x0[k] + (3 * u2 - 4 * u + 1) * m0[k] + (6 * u - 6 * u2) * x1[k] + (3 * u2 - 2 * u) * m1[k])

    if slope(0.0) * slope(1.0) <= 0 or slope(0.5) * slope(0.0) <= 0:
        return chord
    u = w
    for _ in range(20):
        d = slope(u)
        step = (curve(u)[k] - value) / d
        u -= step
        if not 0.0 <= u <= 1.0:
            return chord
        if abs(step) <= 1e-15:
            break
    guess = curve(u)
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
    t = _unit_tangent(problem, first, ref, None)
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
            got = dict(zip(todo, (yield _Marks((pending_marks[i][0], pending_marks[i][1]) for i in todo))))
        for i, (guess, _, step, on) in enumerate(pending_marks):
            pm = on if on is not None else got.get(i)
            if pm is not None and _norm(problem, pm.x - guess) <= rules.jump * step + 1e-12:
                branch.marked.append(pm)
        return branch
    tests_prev = _tests(problem, first)
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
        return (yield from _try(problem, guess, constraint(base, tb, s)))

    def land(value: float):
        """The point exactly at parameter ``value``, from the last point along the tangent."""
        last = points[-1]
        dp = t[k] * sx[k]
        guess = last.x + (value - last.x[k]) / dp * t * sx if dp != 0 else last.x.copy()
        guess[k] = value
        pt = yield from _try(problem, guess, Constraint.fix(n, k, value))
        if pt is not None and _norm(problem, pt.x - guess) <= rules.jump * max(_norm(problem, guess - last.x), rules.ds_min) + 1e-9:
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
                    branch.end_reason = f"step floor: could not land on {name} = {edge[0]:.12g} from {base.x[k]:.12g} (step below {rules.ds_min:g})"
                    return (yield from finish())
                continue
            new = yield from at(base, t, ds, _bend(points, t, sx, last_ds, ds) if rules.predictor == "quadratic" else None)
            status = "fail"
            t_new = None
            if new is not None:
                moved = _norm(problem, new.x - pred)
                if moved > rules.jump * ds + 1e-12:
                    status = "jump"
                elif _guard(problem, points, new, 1.0):
                    status = "jump"
                else:
                    t_new = _unit_tangent(problem, new, t, (new.x - base.x))
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
                branch.end_reason = f"step floor: arclength step below {rules.ds_min:g} at {name} = {base.x[k]:.12g} after {len(points)} points"
                return (yield from finish())
        assert t_new is not None and new is not None
        # the points inside this step (locating a fold or a sign change) start on the quadratic
        # through base, with its tangent, and new
        bend = 2.0 * (new.x - base.x - ds * t * sx) / (ds * ds)

        def within(b_, tb, s_, bend=bend):
            return at(b_, tb, s_, bend)

        # a fold: the parameter component of the tangent changes sign
        if t[k] * t_new[k] < 0:
            fold = (yield from _locate_fold(problem, base, t, ds, new, t_new, within, fold_tol)) if locate else Fold(float(new.x[k]), new, False, abs(new.x[k] - base.x[k]))
            branch.folds.append(fold)
            if stop_at_fold:
                if fold.located:
                    points.append(fold.point)  # the branch ends on its turning point
                branch.end_reason = f"fold at {name} = {fold.parameter:.12g}" + ("" if fold.located else f" (not located: within {fold.tolerance:.2g})")
                return (yield from finish())
        tests_new = _tests(problem, new)
        for test, u, v, w in sign_changes(tests_prev, tests_new):
            if locate and locate_bifurcations:
                b = yield from _locate_sign(problem, test, base, t, ds, u, v, new, within, fold_tol)
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


def _locate_fold(problem, base, t, ds, new, t_new, at, tol) -> Fold:
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
        tc = None if pc is None else _unit_tangent(problem, pc, t, pc.x - base.x)
        if tc is None:
            c = 0.5 * (a + b)
            pc = yield from at(base, t, c)
            tc = None if pc is None else _unit_tangent(problem, pc, t, pc.x - base.x)
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


def _locate_natural(problem, name, a: Point, b: Point, u: float, v: float, tol: float):
    """A sign change of the test ``name`` between the accepted points ``a`` and ``b`` of a
    natural-parameter run, located to ``tol`` in the parameter: Illinois iterations on the test
    function of points corrected at fixed parameter values (guesses interpolated linearly)."""
    k = problem.parameter_index
    n = a.x.size

    def f(p):
        w = (p - a.x[k]) / (b.x[k] - a.x[k])
        guess = a.x + w * (b.x - a.x)
        guess[k] = p
        pt = yield from _try(problem, guess, Constraint.fix(n, k, p))
        val = None if pt is None else _tests(problem, pt).get(name)
        return None if val is None or not math.isfinite(val) else (val, pt)

    best, ok = yield from _illinois(f, float(a.x[k]), u, float(b.x[k]), v, lambda lo, hi: abs(hi - lo) <= tol)
    if best is None or not ok:
        w = u / (u - v)
        return Bifurcation(name, float(a.x[k] + w * (b.x[k] - a.x[k])), b if best is None else best[1], False)
    return Bifurcation(name, float(best[0]), best[1], True)


def _locate_sign(problem, name, base, t, ds, u, v, new, at, tol) -> Bifurcation:
    k = problem.parameter_index

    def f(s):
        pt = yield from at(base, t, s)
        if pt is None:
            return None
        val = _tests(problem, pt).get(name)
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
