"""Periodic 3-D attitude motions continued on the shared driver (:mod:`librate.solving.continuation`):
along an orbit family in the period (:func:`attitude_family_3d`) or in the inertia between two
bodies (:func:`attitude_family_3d_inertia`), with the Floquet bifurcation tests of the 6x6
attitude monodromy (:func:`floquet_tests`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._checks import as_count, as_tolerance
from .._errors import ConvergenceError
from .._progress import as_progress
from ..attitude.body import RigidBody
from ..orbits.periodic import PeriodicOrbit
from .periodic_attitude3d import SOLVE_RTOL, STABILITY_TOL, AttitudeSolution3D, periodic_attitude_3d, verified_solution_3d

__all__ = ["attitude_family_3d", "attitude_family_3d_inertia", "OrbitFamilyBranch3D", "FamilyMember3D",
           "InertiaBranch3D", "rotvec_jacobian",
           "floquet_tests", "FLOQUET_TESTS"]


def rotvec_jacobian(r) -> np.ndarray:
    """d rotvec(R(r) Exp(theta)) / d theta at theta = 0 (theta a small rotation in body axes):
    the inverse right Jacobian of SO(3), I + [r]/2 + (1/|r|^2 - (1 + cos|r|)/(2 |r| sin|r|)) [r]^2,
    with [r] the cross-product matrix (series below |r| = 1e-4)."""
    r = np.asarray(r, dtype=float)
    a = float(np.linalg.norm(r))
    k = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
    c = 1.0 / 12.0 + a * a / 720.0 if a < 1e-4 else 1.0 / (a * a) - (1.0 + math.cos(a)) / (2.0 * a * math.sin(a))
    return np.eye(3) + 0.5 * k + c * (k @ k)


@dataclass(frozen=True)
class FamilyMember3D:
    """A point of :class:`OrbitFamilyBranch3D`: the verified ``solution`` and d F / d T of its six
    closure residuals (``dparam``, exact, from the bordered corrector)."""

    solution: AttitudeSolution3D
    dparam: np.ndarray = field(repr=False)


class OrbitFamilyBranch3D:
    """A periodic 3-D attitude motion continued along a family of x-z-symmetric periodic orbits
    (DROs, planar Lyapunov orbits, halos, NRHOs), a bordered problem for the continuation driver
    (:func:`librate.solving.continuation.arclength`, or ``natural``). The vector is x = (orbit
    period in days, the rotation vector of q0, w0).

    Every point is corrected by the Rust bordered corrector
    (:func:`librate._core.attitude_correct_3d_across`): the unknowns are a rotation theta in body
    axes in a chart about the guess's attitude, w0 and the orbit period T, closed by the driver's
    linear condition a . x = b. That condition is taken to the chart linearised:
    rotvec(q_ref Exp(theta)) ~ rotvec(q_ref) + J theta (:func:`rotvec_jacobian`), exact at the
    guess (natural continuation fixes only the period, so there it is exact everywhere). Each
    Newton point's orbit is the family member of its period, corrected in Rust to 1e-12, so the
    solution's orbit is the member at the final period. The tangent is the null vector of the
    family's Jacobian [M - I, dF/dT] in the solution's body-axis chart (M the monodromy), mapped
    to x. The bifurcation tests are :func:`floquet_tests`."""

    parameter_index = 0
    scale = np.ones(7)

    def __init__(self, orbits, body: RigidBody, n_periods: int = 1, tol: float = 1e-12, max_iter: int = 40):
        self.orbits, self.body, self.n_periods, self.tol, self.max_iter = orbits, body, n_periods, tol, max_iter
        self.days = float(orbits.system.period_days(1.0))

    def correct(self, guess, c):
        from scipy.spatial.transform import Rotation

        from ..solving.continuation import CorrectionFailed, Point

        guess = np.asarray(guess, dtype=float)
        try:
            ref = self.orbits.member(period_days=float(guess[0]))
        except (ValueError, ConvergenceError) as e:
            raise CorrectionFailed(str(e)) from None
        rv = guess[1:4]
        a = np.asarray(c.a, dtype=float)
        a_chart = np.concatenate([rotvec_jacobian(rv).T @ a[1:4], a[4:7], [a[0] * self.days]])
        b_chart = float(c.b) - float(a[1:4] @ rv)
        cases = _core.AttitudeCases3D(Rotation.from_rotvec(rv).as_quat()[None, :], np.asarray(guess[None, 4:7], dtype=float),
                                      period=np.array([float(ref.period)]), a=a_chart[None, :], b=np.array([b_chart]))
        options = _core.CorrectorOptions3D(_core.NewtonOptions(tol=float(self.tol), max_iter=int(self.max_iter)),
                                           rtol=SOLVE_RTOL, atol=SOLVE_RTOL)
        r = _core.attitude_correct_3d_across(self.orbits.system.mu, list(self.body.moments),
                                             [float(v) for v in ref.state0], float(ref.period),
                                             self.n_periods, cases, options=options)
        if r.reason[0] != "converged":
            raise CorrectionFailed(f"3-D attitude across the orbit family: {r.reason[0].replace('_', ' ')} after "
                                   f"{int(r.iterations[0])} steps, residual {float(r.residual_norm[0]):.2e}")
        state0 = np.asarray(r.orbit0[0])
        orbit = PeriodicOrbit(self.orbits.system, state0, float(r.period[0]), float(self.orbits.system.jacobi(state0)), ref.family)
        s = verified_solution_3d(orbit, self.body, self.n_periods, np.asarray(r.q0[0]), np.asarray(r.w0[0]),
                                 np.asarray(r.monodromy[0]), int(r.iterations[0]))
        if not s.residual <= 1e-9:
            raise CorrectionFailed(f"re-propagation residual {s.residual:.2e} above 1e-9")
        x = np.concatenate([[orbit.period_days], Rotation.from_quat(s.q0).as_rotvec(), s.w0])
        if c.fixed_index == 0:
            x[0] = float(c.b)  # the member of exactly that period (its orbit corrected to 1e-12 TU)
        return Point(x, FamilyMember3D(s, np.asarray(r.dparam[0])), s.iterations)

    def tangent(self, point):
        from scipy.spatial.transform import Rotation

        m = point.data.solution.monodromy
        jac = np.hstack([m - np.eye(6), point.data.dparam[:, None]])  # (theta, w0, T) in the solution's chart
        if not np.all(np.isfinite(jac)):
            return None
        v = np.linalg.svd(jac)[2][-1]
        rv = Rotation.from_quat(point.data.solution.q0).as_rotvec()
        return np.concatenate([[v[6] * self.days], rotvec_jacobian(rv) @ v[:3], v[3:6]])

    def tests(self, point):
        return floquet_tests(point.data.solution.monodromy)


def attitude_family_3d(orbits, body: RigidBody, *, guess, period_days, n_periods: int = 1, tol: float = 1e-12, ds_min: float = 1e-4,
                       progress=None, method: str = "arclength", max_points: int = 400):
    """A periodic 3-D attitude motion of ``body`` continued along the orbit family ``orbits``, in the orbit period.

    The motion is corrected from ``guess`` on the member of the first period and followed
    through the requested periods ``period_days`` in order, e.g. along the L2 southern halos
    into the NRHOs. Every member is re-propagated independently, to 1e-9. A single period gives
    the one-member family of that orbit (no continuation).

    ``method`` chooses the continuation. "arclength" (the default) follows the family by
    pseudo-arclength continuation (:func:`librate.solving.continuation.arclength`) on the
    bordered corrector (:class:`OrbitFamilyBranch3D`: the orbit period is an unknown, and each
    Newton point lies on its own family member), through folds, until the branch leaves the
    range of the requested periods. Its members are the solutions corrected exactly at a
    requested period each time the branch crosses one, so after a fold a period can have two
    or more members, in branch order. "natural" steps in the period
    (:func:`librate.solving.continuation.natural`) and stops at a fold, where its step
    collapses. A correction that fails later in the run ends it, with its ``end_reason``.

    Parameters
    ----------
    orbits : OrbitFamily
        The orbit family.
    body : RigidBody
        The body, every principal moment > 0 (as :func:`periodic_attitude_3d` checks).
    guess : AttitudeSolution or (q0, w0)
        The guess at the first period, as in :func:`periodic_attitude_3d`.
    period_days : float or array_like
        The orbit periods wanted (days), finite, at least one, each within the family's range;
        for "arclength", strictly monotonic.
    n_periods : int, default 1
        K, the orbit periods per attitude period, in [1, 1000].
    tol : float, default 1e-12
        The corrector's tolerance, in [1e-15, 1e-3]. NRHOs pass within a few thousand km of the
        Moon, where the tidal torque is some 1e4 times the Earth's at the Moon's distance:
        their attitude closure reaches only ~1e-11, so pass tol=1e-10 there.
    ds_min : float, default 1e-4
        The smallest continuation step (in x = (period in days, rotation vector of q0, w0)),
        a finite number > 0; with "natural", at most 0.05.
    progress : bool or callable, optional
        True for a bar on stderr, or ``progress(done, total)``, called with the number of
        requested periods reached so far.
    method : {"arclength", "natural"}, default "arclength"
        The continuation.
    max_points : int, default 400
        The most branch points of the "arclength" continuation, in [2, 100,000].

    Returns
    -------
    xarray.Dataset
        Along ``member`` (attribute ``parameter`` = "period_days"): ``period_days``, ``x0``,
        ``z0``; ``q0`` and ``w0``; the six ``multipliers`` (complex), ``stable`` and
        ``residual`` (from the re-propagation); ``turns``, NaN where it is undefined.

        The attributes: ``stability_changes``, where a pair of multipliers passes +1 or -1
        ("+1", "-1") or two pairs collide ("krein": on the unit circle, or two real pairs
        meeting off it). They are located by the continuation driver on the test functions
        :func:`floquet_tests`, to 1e-8 in the parameter (``at``, ``located``), each with the two
        members around it (``between``: the second None when natural continuation stalled past
        the last member; with arclength, where no two consecutive members bracket it, the two
        branch points around it, and ``members`` False) and their counts of multipliers on the
        unit circle (``on_unit_circle``). ``folds`` (arclength): the family's turning points in
        the period, located to 1e-8 (``period_days``, ``located``, the ``w0`` there).
        ``unmarked_periods`` (arclength): requested periods the branch crossed where no member
        was kept, because the correction there landed farther from the interpolation between
        the two branch points than the driver's jump guard allows; normally empty.
        ``end_reason``: why the continuation stopped. Also ``body_moments``, ``n_periods``,
        ``system`` and ``method``.

    Raises
    ------
    ValueError
        A bad argument, naming it: ``orbits`` not an :class:`OrbitFamily`, an unknown
        ``method``, ``period_days`` empty, not finite, outside the family's range or (for
        "arclength") not strictly monotonic, a count, tolerance or step out of range, or a bad
        ``body`` or ``guess``.
    ConvergenceError
        The first solution could not be corrected, or the bordered corrector did not reproduce
        it (or the first period's orbit could not be corrected).
    CollisionError
        The first period's orbit passes within a primary's radius.

    Examples
    --------
    >>> import librate, math
    >>> halos = librate.halo_family("earth-moon", 2, "south")
    >>> h = halos.member(period_days=14.0)
    >>> body = librate.RigidBody(0.8, 0.9, 1.0)
    >>> s = librate.periodic_attitude_3d(h, body, guess=([0, 0, 0, 1.0], [0, 0, 1 - 2 * math.pi / h.period]))
    >>> ds = librate.attitude_family_3d(halos, body, guess=(s.q0, s.w0), period_days=[14.0, 13.5, 13.0])
    >>> ds.period_days.values.round(6).tolist(), bool(ds.residual.max() < 1e-9)
    ([14.0, 13.5, 13.0], True)
    >>> ds.attrs["end_reason"]
    'completed: parameter range end: period_days = 13'
    """

    from ..orbits.families import OrbitFamily
    from ..solving.continuation import Constraint, CorrectionFailed, StepRules, arclength, natural

    progress = as_progress(progress, "3-D attitude family", "member")
    if not isinstance(orbits, OrbitFamily):
        raise ValueError(f"invalid argument `orbits`: must be a librate.OrbitFamily, got {type(orbits).__name__}")
    if method not in ("arclength", "natural"):
        raise ValueError(f"invalid argument `method`: must be 'arclength' or 'natural', got {method!r}")
    targets = np.asarray(period_days, dtype=float).ravel()
    if targets.size < 1 or not np.all(np.isfinite(targets)):
        raise ValueError(f"invalid argument `period_days`: need at least one finite period, got {period_days!r}")
    n_periods = as_count(n_periods, "n_periods", 1)
    max_points = as_count(max_points, "max_points", 2)
    first_orbit = orbits.member(period_days=float(targets[0]))
    tol = as_tolerance(tol, "tol")
    s0 = periodic_attitude_3d(first_orbit, body, guess=guess, n_periods=n_periods, tol=tol)
    problem = OrbitFamilyBranch3D(orbits, body, n_periods, tol)
    from scipy.spatial.transform import Rotation

    x_first = np.concatenate([[float(targets[0])], Rotation.from_quat(s0.q0).as_rotvec(), s0.w0])
    try:
        first = problem.correct(x_first, Constraint.fix(7, 0, float(x_first[0])))
    except CorrectionFailed as e:
        raise ConvergenceError(f"3-D attitude family: the bordered corrector did not reproduce the first solution: {e}") from None
    report = None
    if progress is not None:
        progress(1, targets.size)
        reached = [1]
        sense = 1.0 if targets.size < 2 or targets[-1] >= targets[0] else -1.0

        def report(point):  # the driver's per-point hook: count the requested periods passed
            p = float(point.x[0])
            # a member counts as reached within the orbit correction's tolerance on its period
            while reached[0] < targets.size and (targets[reached[0]] - p) * sense <= 1e-9:
                reached[0] += 1
                progress(reached[0], targets.size)
            return None

    folds = []
    if targets.size == 1:
        br, members = None, [first]
    elif method == "natural":
        br = natural(problem, first, targets[1:], rules=StepRules(ds=abs(targets[1] - targets[0]), ds_min=ds_min),
                     name="period_days", stop=report)
        members = [first] + br.points
    else:
        if not (np.all(np.diff(targets) > 0) or np.all(np.diff(targets) < 0)):
            raise ValueError("invalid argument `period_days`: method='arclength' needs strictly monotonic periods (the branch is followed "
                             "across their range); use method='natural' to visit them in any order")
        lo, hi = float(targets.min()), float(targets.max())
        # steps no longer than the closest requested spacing: each requested period is corrected from a
        # nearby interpolation between two branch points
        ds_max = max(ds_min, float(np.min(np.abs(np.diff(targets)))))
        rules = StepRules(ds=ds_max, ds_min=ds_min, ds_max=ds_max)
        direction = 1 if targets[1] >= targets[0] else -1
        br = arclength(problem, first, direction=direction, rules=rules, bounds=(lo, hi), marks=[float(t) for t in targets[1:]],
                       max_points=max_points, name="period_days", stop=report)
        members = [first] + list(br.marked)
        last = br.points[-1]
        on_target = np.any(np.abs(targets - last.x[0]) <= 1e-12)
        if len(br.points) > 1 and on_target and not any(m is last for m in members):
            members.append(last)  # the branch ended landing exactly on a requested period (a bound)
        folds = [{"period_days": float(f.parameter), "located": bool(f.located),
                  "w0": [float(v) for v in f.point.x[4:7]]} for f in br.folds]
        # requested periods the branch crossed whose correction there was rejected (it left the
        # jump guard: landed too far from the interpolation between the two branch points)
        ps = [float(q.x[0]) for q in br.points]
        crossed = [float(t) for a, b in zip(ps, ps[1:]) for t in targets[1:] if (a - t) * (b - t) < 0 or (b == t and not a == t)]
        got = [float(m.x[0]) for m in members[1:]]
        attrs_unmarked = [t for t in dict.fromkeys(crossed) if crossed.count(t) > sum(abs(g - t) <= 1e-12 for g in got)]
        if br.end_reason.startswith("parameter range end") and abs(last.x[0] - targets[-1]) <= 1e-12:
            br.end_reason = f"completed: {br.end_reason}"  # crossed the whole range to the last requested period
    sols = [m.data.solution for m in members]
    dim = ("member",)
    extra = {"period_days": (dim, np.array([s.orbit.period_days for s in sols])), "x0": (dim, np.array([s.orbit.state0[0] for s in sols])),
             "z0": (dim, np.array([s.orbit.state0[2] for s in sols]))}
    attrs = {"body_moments": list(body.moments), "n_periods": n_periods, "system": orbits.system.name, "method": method}
    if method == "arclength" and br is not None:
        attrs["folds"] = repr(folds)
        attrs["unmarked_periods"] = repr(attrs_unmarked)
    path = [p.data.solution for p in br.points] if method == "arclength" and br is not None else None
    return _family_dataset(sols, "period_days", extra, br, attrs, bracketed=path)


def _family_dataset(sols, parameter: str, extra: dict, branch, attrs: dict, bracketed: list | None = None):
    """The Dataset of a 3-D family: ``extra`` variables (the parameter among them), the
    solutions' q0, w0, multipliers, stable, residual, turns, and the stability changes the
    continuation driver located (the zeros of :func:`floquet_tests`; attribute). ``branch``
    None: one member, no continuation."""
    import xarray as xr

    p = np.asarray(extra[parameter][1], dtype=float)
    mult = np.array([_sorted_multipliers(s.multipliers) for s in sols])
    on = np.abs(np.abs(mult) - 1) <= STABILITY_TOL
    changes = []
    for b in ([] if branch is None else branch.bifurcations):
        if bracketed:
            # the first two consecutive members around it (members are at requested values only);
            # else (e.g. between the last requested period and a fold) the two branch points
            i = next((k for k in range(len(p) - 1) if min(p[k], p[k + 1]) <= b.parameter <= max(p[k], p[k + 1])), None)
            if i is None:
                two = [bracketed[b.after], bracketed[b.after + 1]]
                n_on = [int(np.sum(np.abs(np.abs(t.multipliers) - 1) <= STABILITY_TOL)) for t in two]
                changes.append({"at": float(b.parameter), "located": bool(b.located), "kind": FLOQUET_TESTS[b.name],
                                "between": tuple(float(t.orbit.period_days) for t in two), "on_unit_circle": tuple(n_on), "members": False})
                continue
        else:
            i = b.after + 1  # the member before it (the first member is the start, not a returned point)
        # past the last member (natural continuation stalled after locating it): one side only
        j = i + 1 if i + 1 < len(p) else None
        changes.append({"at": float(b.parameter), "located": bool(b.located), "kind": FLOQUET_TESTS[b.name],
                        "between": (float(p[i]), None if j is None else float(p[j])),
                        "on_unit_circle": (int(on[i].sum()), None if j is None else int(on[j].sum()))})
    end_reason = "one member: no continuation" if branch is None else branch.end_reason
    dim = ("member",)
    return xr.Dataset(
        {**extra,
         "q0": (("member", "quaternion"), np.array([s.q0 for s in sols])), "w0": (("member", "axis"), np.array([s.w0 for s in sols])),
         "multipliers": (("member", "k"), mult), "stable": (dim, np.array([s.stable for s in sols])),
         "residual": (dim, np.array([s.residual for s in sols])),
         "turns": (dim, np.array([np.nan if s.turns is None else s.turns for s in sols]))},
        attrs={**attrs, "parameter": parameter, "end_reason": end_reason, "stability_changes": repr(changes)})


class InertiaBranch3D:
    """A periodic 3-D attitude motion along one orbit, continued in the inertia along the
    straight path between two bodies, I(s) = (1 - s) I_a + s I_b, s in [0, 1], for the
    continuation driver. The vector is x = (s, the rotation vector of q0, w0); the tangent is
    the driver's secant."""

    parameter_index = 0
    scale = np.ones(7)

    def __init__(self, orbit, bodies, n_periods: int = 1, tol: float = 1e-12):
        self.orbit, self.n_periods, self.tol = orbit, n_periods, tol
        self.ia, self.ib = (np.asarray(b.moments, dtype=float) for b in bodies)

    def body(self, s: float) -> RigidBody:
        return RigidBody(*((1 - s) * self.ia + s * self.ib))

    def correct(self, guess, c):
        from scipy.spatial.transform import Rotation

        from ..solving.continuation import CorrectionFailed, Point

        if not (c.a[0] == 1 and not np.any(c.a[1:])) or not (0 <= c.b <= 1):
            raise CorrectionFailed("the inertia path is continued in s in [0, 1] only (natural parameter)")
        q = Rotation.from_rotvec(np.asarray(guess[1:4], dtype=float)).as_quat()
        sol = periodic_attitude_3d(self.orbit, self.body(float(c.b)), guess=(q, np.asarray(guess[4:7], dtype=float)),
                                   n_periods=self.n_periods,
                                   tol=self.tol)
        if not sol.residual <= 1e-9:
            raise CorrectionFailed(f"re-propagation residual {sol.residual:.2e} above 1e-9")
        return Point(np.concatenate([[float(c.b)], Rotation.from_quat(sol.q0).as_rotvec(), sol.w0]), sol, sol.iterations)

    def tangent(self, point):
        return None

    def tests(self, point):
        return floquet_tests(point.data.monodromy)


def attitude_family_3d_inertia(orbit: PeriodicOrbit, bodies, *, guess, steps: int = 20, n_periods: int = 1, tol: float = 1e-12,
                               ds_min: float = 1e-5):
    """A periodic 3-D attitude motion along ``orbit`` continued in the inertia, from one body to another.

    The moments follow the straight path I(s) = (1 - s) I_a + s I_b from ``bodies[0]`` (s = 0)
    to ``bodies[1]`` (s = 1) in ``steps`` equal steps of s, by natural-parameter continuation
    (:func:`librate.solving.continuation.natural`), from ``guess`` for the first body. A
    common start is the torque-free sphere: with equal moments, the spin (1 + 2 pi N / T) e_Z
    is periodic at any attitude. A correction that fails later in the run ends it, with its
    ``end_reason``.

    Parameters
    ----------
    orbit : PeriodicOrbit
        The orbit.
    bodies : (RigidBody, RigidBody)
        The first and the last body, each with every principal moment > 0.
    guess : AttitudeSolution or (q0, w0)
        The guess for the first body, as in :func:`periodic_attitude_3d`.
    steps : int, default 20
        Equal steps in s, in [1, 100,000].
    n_periods : int, default 1
        K, the orbit periods per attitude period, in [1, 1000].
    tol : float, default 1e-12
        The corrector's tolerance, in [1e-15, 1e-3].
    ds_min : float, default 1e-5
        The smallest step in s after halvings, a finite number > 0 and at most 0.05.

    Returns
    -------
    xarray.Dataset
        That of :func:`attitude_family_3d`, along ``s`` (attribute ``parameter`` = "s"), with
        the ``moments`` (member, axis) of each member's body; attributes ``orbit_period_days``,
        ``n_periods``, ``system``, ``end_reason`` and ``stability_changes``.

    Raises
    ------
    ValueError
        A bad argument, naming it: ``orbit`` not a :class:`PeriodicOrbit`, ``bodies`` not two
        :class:`RigidBody` with every moment > 0, a count, tolerance or step out of range, or a
        bad ``guess``.
    ConvergenceError
        The first body's motion could not be corrected.

    Examples
    --------
    >>> import librate, math
    >>> h = librate.halo("earth-moon", 2, "south", period_days=13.0)
    >>> bodies = (librate.RigidBody(1.0, 1.0, 1.0), librate.RigidBody(0.8, 0.9, 1.0))
    >>> spin = ([0, 0, 0, 1.0], [0, 0, 1 - 2 * math.pi / h.period])
    >>> ds = librate.attitude_family_3d_inertia(h, bodies, guess=spin, steps=3)
    >>> ds.s.values.round(4).tolist(), ds.moments.values[-1].tolist()
    ([0.0, 0.3333, 0.6667, 1.0], [0.8, 0.9, 1.0])
    >>> ds.attrs["end_reason"]
    'completed: reached the last requested value'
    """
    from ..solving.continuation import Point, StepRules, natural

    if not isinstance(orbit, PeriodicOrbit):
        raise ValueError(f"invalid argument `orbit`: must be a librate.PeriodicOrbit, got {type(orbit).__name__}")
    try:
        b0, b1 = bodies
    except (TypeError, ValueError):
        raise ValueError(f"invalid argument `bodies`: must be two librate.RigidBody, got {bodies!r}") from None
    for b in (b0, b1):
        if not isinstance(b, RigidBody) or b.is_rod:
            raise ValueError(f"invalid argument `bodies`: must be two librate.RigidBody with every moment > 0, got {b!r}")
    steps = as_count(steps, "steps", 1)
    n_periods = as_count(n_periods, "n_periods", 1)
    tol = as_tolerance(tol, "tol")
    problem = InertiaBranch3D(orbit, (b0, b1), n_periods, tol)
    from scipy.spatial.transform import Rotation

    s0 = periodic_attitude_3d(orbit, b0, guess=guess, n_periods=n_periods, tol=tol)
    first = Point(np.concatenate([[0.0], Rotation.from_quat(s0.q0).as_rotvec(), s0.w0]), s0, s0.iterations)
    targets = np.linspace(0.0, 1.0, steps + 1)[1:]
    br = natural(problem, first, targets, rules=StepRules(ds=1.0 / steps, ds_min=ds_min), name="s")
    sols = [s0] + [p.data for p in br.points]
    s_values = np.array([0.0] + [float(p.x[0]) for p in br.points])
    dim = ("member",)
    extra = {"s": (dim, s_values), "moments": (("member", "axis"), np.array([problem.body(v).moments for v in s_values]))}
    return _family_dataset(sols, "s", extra, br, {"orbit_period_days": float(orbit.period_days), "n_periods": n_periods,
                                                  "system": orbit.system.name})


FLOQUET_TESTS = {"Q(2)": "+1", "Q(-2)": "-1", "discriminant": "krein"}


def floquet_tests(monodromy) -> dict[str, float]:
    """Bifurcation test functions of a 6x6 attitude monodromy, whose multipliers come in
    reciprocal pairs (lambda, 1/lambda): with u = lambda + 1/lambda, the three pairs are the roots
    of the cubic Q(u) = u^3 + a u^2 + (b - 3) u + (c - 2a), where lambda^6 + a lambda^5 + b lambda^4
    + c lambda^3 + b lambda^2 + a lambda + 1 is the (palindromic) characteristic polynomial (a, b,
    c from the traces of M, M^2, M^3). Q(2) changes sign where a real pair passes +1, Q(-2) where
    one passes -1 (a complex pair adds |2 -+ u|^2 > 0 and never changes them), and the
    discriminant of Q where two pairs collide: a Krein collision on the unit circle, or two
    real pairs meeting off it. Smooth in the family's parameter, so the continuation driver
    locates their zeros."""
    m = np.asarray(monodromy, dtype=float)
    t1, t2, t3 = np.trace(m), np.trace(m @ m), np.trace(m @ m @ m)
    e1, e2, e3 = t1, (t1 * t1 - t2) / 2, (t1**3 - 3 * t1 * t2 + 2 * t3) / 6
    a, b, c = -e1, e2, -e3
    B, C, D = a, b - 3.0, c - 2.0 * a
    q = lambda u: u**3 + B * u * u + C * u + D  # noqa: E731
    disc = 18 * B * C * D - 4 * B**3 * D + B * B * C * C - 4 * C**3 - 27 * D * D
    return {"Q(2)": float(q(2.0)), "Q(-2)": float(q(-2.0)), "discriminant": float(disc)}


def _sorted_multipliers(m) -> np.ndarray:
    m = np.asarray(m, dtype=complex)
    return m[np.lexsort((m.imag, np.abs(m)))]
