"""The continuation driver on problems with analytic answers.

Reference problems (each with its own small Newton corrector: a TEST REFERENCE, not library
code): the unit circle u^2 + p^2 = 1 (folds at p = +-1 exactly), and a cubic fold
u^3 - u + p = 0 (folds at p = +-2/(3 sqrt 3), u = -+1/sqrt 3). Tolerances: folds located to
1e-8 in the parameter (the issue's requirement), bifurcation test functions to 1e-8.
"""

import math

import numpy as np
import pytest
from librate.solving.continuation import Constraint, CorrectionFailed, Point, StepRules, arclength, natural


class Implicit:
    """F(p, u) = 0 with x = (p, u); corrector: Newton on [F; a . x - b] (test reference)."""

    parameter_index = 0
    scale = np.ones(2)

    def __init__(self, f, grad, tests=None):
        self.f, self.grad, self._tests = f, grad, tests
        self.calls = 0

    def correct(self, guess, c: Constraint) -> Point:
        self.calls += 1
        x = np.array(guess, dtype=float)
        for it in range(1, 30):
            r = np.array([self.f(x), c.a @ x - c.b])
            if np.max(np.abs(r)) < 1e-14:
                return Point(x, None, it)
            J = np.vstack([self.grad(x), c.a])
            x = x - np.linalg.solve(J, r)
        raise CorrectionFailed("reference Newton did not converge")

    def tangent(self, pt):
        g = self.grad(pt.x)
        return np.array([g[1], -g[0]])

    def tests(self, pt):
        return self._tests(pt) if self._tests else {}


def circle(tests=None):
    return Implicit(lambda x: x[0] ** 2 + x[1] ** 2 - 1, lambda x: np.array([2 * x[0], 2 * x[1]]), tests)


def cubic():
    return Implicit(lambda x: x[1] ** 3 - x[1] + x[0], lambda x: np.array([1.0, 3 * x[1] ** 2 - 1]))


def test_circle_fold_located_to_1e8():
    pb = circle()
    br = arclength(pb, Point(np.array([0.0, 1.0])), direction=1, rules=StepRules(ds=0.1, ds_max=0.3), max_points=80)
    assert len(br.folds) >= 2  # p = +1 and, going round, p = -1
    f = br.folds[0]
    assert f.located and abs(f.parameter - 1.0) <= 1e-8
    assert abs(br.folds[1].parameter + 1.0) <= 1e-8
    # the branch was followed through the fold: points with u < 0 exist, all on the circle
    xs = np.array([p.x for p in br.points])
    assert np.any(xs[:, 1] < -0.5)
    assert np.max(np.abs(np.hypot(xs[:, 0], xs[:, 1]) - 1)) < 1e-13


def test_cubic_fold_and_bounds():
    pb = cubic()
    u0 = 1.2
    first = Point(np.array([u0 - u0**3, u0]))
    br = arclength(pb, first, direction=1, rules=StepRules(ds=0.05, ds_max=0.1), bounds=(-1.0, 1.0), max_points=400)
    fold = 2 / (3 * math.sqrt(3))
    assert [round(f.parameter, 6) for f in br.folds] == [round(fold, 6), round(-fold, 6)]
    assert all(f.located and abs(abs(f.parameter) - fold) <= 1e-8 for f in br.folds)
    assert br.end_reason.startswith("parameter range end")
    assert br.points[-1].x[0] == 1.0  # landed exactly on the bound


def test_stop_at_fold():
    br = arclength(cubic(), Point(np.array([0.0, 1.0])), direction=1, target=0.5, stop_at_fold=True, rules=StepRules(ds=0.05))
    assert not br.reached and len(br.folds) == 1
    assert abs(br.folds[0].parameter - 2 / (3 * math.sqrt(3))) <= 1e-8
    assert br.end_reason.startswith("fold at parameter = 0.38490")


def test_marks_corrected_exactly_on_both_sides_of_a_fold():
    br = arclength(circle(), Point(np.array([0.0, 1.0])), direction=1, marks=[0.5, 0.9], rules=StepRules(ds=0.1), max_points=30)
    got = [(round(p.x[0], 15), round(p.x[1], 12)) for p in br.marked]
    s5, s9 = math.sqrt(0.75), math.sqrt(1 - 0.81)
    assert got[:4] == [(0.5, round(s5, 12)), (0.9, round(s9, 12)), (0.9, round(-s9, 12)), (0.5, round(-s5, 12))]


def test_target_reached_exactly():
    br = arclength(cubic(), Point(np.array([0.0, 1.0])), direction=-1, target=-0.2, rules=StepRules(ds=0.03))
    assert br.reached and br.points[-1].x[0] == -0.2
    u = br.points[-1].x[1]
    assert abs(u**3 - u - 0.2) < 1e-13


def test_bifurcation_test_function_located():
    pb = circle(tests=lambda pt: {"u=1/2": pt.x[1] - 0.5})
    br = arclength(pb, Point(np.array([0.0, 1.0])), direction=1, rules=StepRules(ds=0.1), max_points=12)
    b = br.bifurcations[0]
    assert b.located and abs(b.point.x[1] - 0.5) < 1e-8 and abs(b.parameter - math.sqrt(0.75)) < 1e-8


def test_natural_lands_on_targets_and_stops_before_a_fold():
    pb = cubic()
    first = Point(np.array([0.0, 1.0]))
    br = natural(pb, first, [0.1, 0.2, 0.3])
    assert br.reached and [p.x[0] for p in br.points] == [0.1, 0.2, 0.3]
    assert all(abs(p.x[1] ** 3 - p.x[1] + p.x[0]) < 1e-13 and p.x[1] > 1 / math.sqrt(3) for p in br.points)
    # the upper branch (u > 1/sqrt 3) folds at p = 2/(3 sqrt 3) ~ 0.3849: beyond it there is no
    # solution nearby, the natural step collapses, with a reason naming the last parameter
    br2 = natural(pb, first, [0.5], rules=StepRules(ds_min=1e-6))
    assert not br2.reached and br2.end_reason.startswith("step floor")
    assert "0.38489" in br2.end_reason


def test_jump_guard_rejects_a_silent_branch_switch():
    class Jumpy(Implicit):
        def correct(self, guess, c):
            pt = super().correct(guess, c)
            if pt.x[0] > 0.5 and pt.x[1] > 0:  # a "corrector" that lands on the other branch
                return Point(np.array([pt.x[0], -pt.x[1]]), None, 1)
            return pt

    pb = Jumpy(lambda x: x[0] ** 2 + x[1] ** 2 - 1, lambda x: np.array([2 * x[0], 2 * x[1]]))
    br = arclength(pb, Point(np.array([0.0, 1.0])), direction=1, rules=StepRules(ds=0.1, ds_min=1e-4), max_points=50)
    assert br.rejected_jumps > 0
    assert all(p.x[1] > 0 for p in br.points)  # never returned a point of the other branch
    assert br.end_reason.startswith("step floor")


@pytest.mark.parametrize("bad", [dict(ds=0.0), dict(ds_min=-1.0), dict(growth=0.5), dict(ds_min=1.0, ds_max=0.1), dict(jump=float("nan"))])
def test_step_rules_validated(bad):
    with pytest.raises(ValueError, match="invalid argument"):
        StepRules(**bad)


class Batched(Implicit):
    """The reference problem with a ``batch_key`` and ``correct_many``/``correct_batch`` (each
    request still solved by the reference Newton), counting the batched calls."""

    batches = 0

    def __init__(self, key, *args):
        super().__init__(*args)
        self.batch_key = key

    def correct_many(self, requests):
        Batched.batches += 1
        out = []
        for pb, g, c in requests:
            try:
                out.append(pb.correct(g, c))
            except CorrectionFailed:
                out.append(None)
        return out

    def correct_batch(self, guesses, constraints, problems=None):
        return self.correct_many(list(zip(problems or [self] * len(guesses), guesses, constraints)))


def test_lockstep_runs_each_branch_as_alone():
    """run_lockstep (several branches advanced together, their corrections batched per
    batch_key) returns exactly the Branch each run gives alone: same points (bitwise, the
    reference corrector being deterministic), folds, marks and end reason; rounds are shared,
    so there are fewer batched calls than corrections."""
    from librate.solving.continuation import arclength_steps, run_lockstep

    radii = [1.0, 1.5, 0.7]

    def problem(r, key):
        return Batched(key, lambda x, r=r: x[0] ** 2 + x[1] ** 2 - r * r, lambda x: np.array([2 * x[0], 2 * x[1]]))

    kw = dict(direction=1, rules=StepRules(ds=0.1, ds_max=0.3), max_points=40, marks=(0.25, 0.5), stop_at_fold=True)
    alone = [arclength(problem(r, None), Point(np.array([0.0, r])), **kw) for r in radii]
    Batched.batches = 0
    pbs = [problem(r, "circle") for r in radii]
    together = run_lockstep([(pb, arclength_steps(pb, Point(np.array([0.0, r])), **kw)) for pb, r in zip(pbs, radii)])
    for a, b, r in zip(alone, together, radii):
        assert len(a.points) == len(b.points) and all(np.array_equal(p.x, q.x) for p, q in zip(a.points, b.points))
        assert [m.x.tolist() for m in a.marked] == [m.x.tolist() for m in b.marked] and len(b.marked) == 2
        assert a.end_reason == b.end_reason and abs(b.folds[0].parameter - r) <= 1e-8
    assert 0 < Batched.batches < sum(pb.calls for pb in pbs)


class Recording(Implicit):
    """The reference corrector, recording each (guess, corrected point, condition)."""

    def __init__(self, *args):
        super().__init__(*args)
        self.log = []

    def correct(self, guess, c: Constraint) -> Point:
        pt = super().correct(guess, c)
        self.log.append((np.array(guess, dtype=float), pt.x.copy(), c))
        return pt


def test_predictor_and_mark_guesses_are_higher_order():
    """The guesses the driver hands the corrector, on the cubic u^3 - u + p = 0 at fixed steps
    ds = 0.02 and 0.01 (reference: Taylor's theorem). With predictor="quadratic" (the
    curvature from the point before) the step's guess: its distance to the corrected point falls 8-fold when ds
    halves (O(ds^3); a linear predictor's falls 4-fold), ratio in [6, 10]. A mark's guess is the
    cubic Hermite curve through the step's ends with their tangents: O(ds^4), ratio >= 12 (the
    chord's would be 4). Medians over the steps and marks of the run."""
    marks = [round(v, 3) for v in np.arange(-0.5, 0.3, 0.01)]

    def errors(ds):
        pb = Recording(lambda x: x[1] ** 3 - x[1] + x[0], lambda x: np.array([1.0, 3 * x[1] ** 2 - 1]))
        u0 = 1.2
        arclength(pb, Point(np.array([u0 - u0**3, u0])), direction=1, rules=StepRules(ds=ds, ds_max=ds, predictor="quadratic"), target=0.3,
                  max_points=2000, marks=marks)
        is_mark = [c.a[0] == 1 and c.a[1] == 0 and c.b in marks for _, _, c in pb.log]
        step = [np.linalg.norm(g - x) for (g, x, _), m in zip(pb.log, is_mark) if not m]
        mark = [np.linalg.norm(g - x) for (g, x, _), m in zip(pb.log, is_mark) if m]
        return np.median(step[2:]), np.median(mark)  # the first steps have no point before

    (s2, m2), (s1, m1) = errors(0.02), errors(0.01)
    assert 6.0 <= s2 / s1 <= 10.0, s2 / s1
    assert m2 / m1 >= 12.0, m2 / m1


def test_step_rules_name_a_bad_predictor():
    with pytest.raises(ValueError, match="`predictor`: must be 'linear' or 'quadratic'"):
        StepRules(predictor="cubic")
