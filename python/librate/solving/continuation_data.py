"""The continuation driver's data (:mod:`librate.solving.continuation`): the corrected point, the
linear condition that closes a problem's equations, folds, bifurcations and the branch, what the
driver needs from a problem, and the one set of step-size rules."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from .._errors import LibrateError

__all__ = ["Point", "Constraint", "Fold", "Bifurcation", "Branch", "ContinuationProblem", "CorrectionFailed", "StepRules"]


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
            raise ValueError(f"invalid arguments `ds_min`, `ds_max`: ds_min must not exceed ds_max, got ds_min = {self.ds_min}, "
                             f"ds_max = {self.ds_max}")
        if self.growth < 1:
            raise ValueError(f"invalid argument `growth`: must be >= 1, got {self.growth}")

