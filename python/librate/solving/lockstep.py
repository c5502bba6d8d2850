"""Who corrects the continuation's requests (:mod:`librate.solving.continuation`): the driver's
algorithms are generators that yield each correction they need; :func:`run_alone` corrects one
branch's requests one by one, :func:`run_lockstep` advances many branches together and corrects
each round's requests in one call per group of compatible problems (``batch_key``)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from .._errors import LibrateError
from .continuation_data import Point

__all__ = ["Marks", "correction", "run_alone", "run_lockstep", "correct_together", "correct_marks"]


def correction(problem, guess, constraint):
    """Ask the runner to correct ``guess`` under ``constraint`` (a generator step: the driver's
    algorithms yield their corrections, so that one runner can correct the requests of many
    branches together); the corrected Point, or None when the correction failed."""
    pt = yield (np.asarray(guess, dtype=float), constraint)
    return pt


class Marks(list):
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


def run_alone(problem, steps):
    """Drive one branch's generator, correcting each request alone."""
    try:
        request = next(steps)
        while True:
            answer = correct_marks([(problem, *r) for r in request]) if isinstance(request, Marks) else _correct(problem, *request)
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


def run_lockstep(branches: Sequence[tuple[Any, Any]], done: Callable[[int, Any], None] | None = None) -> list:
    """Run several continuations in lock step: ``branches`` are (problem, steps) pairs, steps a
    generator from :func:`arclength_steps` (or :func:`natural_steps`); each round, every live
    branch's pending correction is gathered and corrected together (:func:`correct_together`).
    Returns each generator's result (a Branch), in order. Each branch takes exactly the path it
    takes alone: only the grouping of the corrector calls changes. ``done(i, result)`` is called
    as branch i ends, with its result (e.g. for progress, or to start work on that branch while
    the others go on)."""
    results: list = [None] * len(branches)
    pending: dict[int, tuple] = {}
    for i, (problem, steps) in enumerate(branches):
        try:
            pending[i] = next(steps)
        except StopIteration as end:
            results[i] = end.value
            if done is not None:
                done(i, end.value)
    while pending:
        order = sorted(pending)
        single = [i for i in order if not isinstance(pending[i], Marks)]
        answers = dict(zip(single, correct_together([(branches[i][0], *pending[i]) for i in single])))
        flat = [(i, r) for i in order if isinstance(pending[i], Marks) for r in pending[i]]
        got = iter(correct_marks([(branches[i][0], *r) for i, r in flat]))
        for i in order:
            if isinstance(pending[i], Marks):
                answers[i] = [next(got) for _ in pending[i]]
        for i in order:
            try:
                pending[i] = branches[i][1].send(answers[i])
            except StopIteration as end:
                results[i] = end.value
                del pending[i]
                if done is not None:
                    done(i, end.value)
    return results

