"""Solution branches (thesis sec. 3.3, ch. 4; docs/physics.md: periodic attitude motions, solar radiation pressure): periodic attitude
motions continued by the shared driver (:mod:`librate.solving.continuation`) with the Rust corrector
freeing one parameter: Kz for one orbit (:class:`KzBranch`), the flat-plate amplitude eps
(:class:`EpsBranch`, :func:`continue_srp`). :func:`periodic_attitude` returns, by default, the
member of the N family continued in Kz from Kz = 0.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from .._checks import as_count, as_number, as_tolerance
from .._errors import ConvergenceError
from ..attitude.srp import FlatPlate, Sun
from ..orbits.periodic import PeriodicOrbit
from ..solving.continuation import (
    Constraint,
    CorrectionFailed,
    Point,
    StepRules,
    arclength,
    arclength_steps,
    correct_together,
    run_lockstep,
)
from .solutions import (
    KINDS,
    STEP_MAX_CONTRACTION,
    STEP_MAX_HALVINGS,
    STEP_MAX_ITER,
    AttitudeSolution,
    check_kz,
    check_orbit,
    check_srp,
    correct,
    is_symmetric,
    n_total_of,
    per_period,
    turns_of,
    verified,
)

__all__ = ["periodic_attitude", "KzBranch", "kz_branch", "EpsBranch", "SrpContinuation", "continue_srp", "eps_branch",
           "eps_branches", "branch_solutions",
           "branch_fold"]


def _plate(srp, theta):
    return FlatPlate(srp.eps, srp.cs, srp.cd, Sun(theta0=float(theta), pressure=srp.sun.pressure))


def _failure(what: str, batch, i: int = 0, tol: float = 1e-12) -> ConvergenceError:
    return ConvergenceError(f"{what}: the corrector stopped ({batch.reason[i].replace('_', ' ')}) after "
                            f"{int(batch.iterations[i])} Newton steps at wz0 = {float(batch.wz0[i]):.10g}, residual "
                            f"{float(batch.residual_norm[i]):.3e} (tolerance {tol:.1e})")


def periodic_attitude(
    orbit: PeriodicOrbit,
    *,
    kz: float,
    n: int | float,
    phi0: float = 0.0,
    wz0: float | None = None,
    kind: str = "periodic",
    method: str = "auto",
    n_periods: int = 1,
    srp=None,
    free: str = "phi0",
    tol: float = 1e-12,
    max_iter: int = 40,
) -> AttitudeSolution:
    """The periodic planar attitude motion with ``n`` net turns per orbit period along ``orbit``.

    Which solution, without a guess ``wz0``: the member of the N family continued in Kz from
    Kz = 0, where the motion is torque-free and wz0 = 1 + 2 pi N / T is the unique solution; the
    branch is followed by pseudo-arclength continuation (`librate.solving.continuation`) up to
    ``kz``. This needs the half-period (symmetric) formulation: an x-symmetric orbit started on the
    x axis and ``phi0`` a multiple of pi/2; otherwise the torque-free rate is the starting guess of
    a direct correction. `find_periodic_attitudes` lists every solution in a rate window instead.

    With ``srp`` (docs/physics.md, solar radiation pressure) the gravity-only solution is then
    continued in the plate amplitude eps from 0 to ``srp.eps``. The corrector is the Rust one
    (globalised Newton, one call); the returned solution is re-propagated independently.

    Parameters
    ----------
    orbit : PeriodicOrbit
        A planar periodic orbit (e.g. a member of `dro_family`).
    kz : float
        The body's inertia ratio Kz = (Iy - Ix) / Iz, in [-1, 1].
    n : int or float
        Net turns relative to the synodic frame per orbit period; ``n * n_periods`` must be a
        whole number.
    phi0 : float, default 0.0
        Initial angle of the body x axis from the synodic X axis (rad).
    wz0 : float, optional
        A guess of the inertial initial rate (1/TU): the solution nearest to it is corrected
        directly, with no continuation in Kz.
    kind : {"periodic", "half-turn"}
        ``"half-turn"``: phi(KT) = phi0 + 2 pi n K + pi (a half turn more over the K periods).
    method : {"auto", "half", "newton"}
        ``"half"``: phi(KT/2) = phi0 + pi turns with wz0 unknown (needs the symmetry);
        ``"newton"``: the full-period step [Phi(KT) - I] d = -F with phi0 free (the correct form
        of thesis eq. 53, see docs/physics.md); ``"auto"``: ``"half"`` when it applies.
    n_periods : int, default 1
        K, the orbit periods per attitude period (K = 2 on a 1:2 Sun-resonant orbit with SRP).
    srp : FlatPlate, optional
        Solar radiation pressure on a flat plate.
    free : {"phi0", "theta_sun0"}
        With ``srp``: ``"phi0"`` continues in eps with phi0 corrected together with wz0;
        ``"theta_sun0"`` corrects (Sun phase, wz0) directly, phi0 kept from the gravity-only
        solution (the returned ``srp.sun.theta0`` is the phase found).
    tol : float, default 1e-12
        Corrector tolerance on the closure residuals.
    max_iter : int, default 40
        Newton iterations per correction.

    Returns
    -------
    AttitudeSolution
        The solution: ``wz0``, ``phidot0``, ``phi0``, the monodromy and stability, the residual
        of its independent re-propagation.

    Raises
    ------
    ConvergenceError
        The corrector failed, or the Kz (or eps) branch folds before the target: the message
        names the Kz (or eps) of the fold, located to 1e-8.
    ValueError
        A bad argument, naming it and the allowed range.

    See Also
    --------
    - [`find_periodic_attitudes`][librate.periodicity.solutions.find_periodic_attitudes]: every solution in a window of rates.
    - [`attitude_family`][librate.periodicity.attitude_families.attitude_family]: the solution followed along an
      orbit family, through folds.

    Examples
    --------
    >>> import librate
    >>> dro = librate.dro(period_days=12.66)  # the 12.66-day DRO of the Earth-Moon system
    >>> sol = librate.periodic_attitude(dro, kz=0.8, n=-1)
    >>> round(sol.phidot0, 3), sol.stable
    (-2.455, False)
    """
    orbit = check_orbit(orbit)
    kz = check_kz(kz)
    if kind not in KINDS:
        raise ValueError(f"invalid argument `kind`: must be 'periodic' or 'half-turn', got {kind!r}")
    if method not in ("auto", "half", "newton"):
        raise ValueError(f"invalid argument `method`: must be 'auto', 'half' or 'newton', got {method!r}")
    n_periods = as_count(n_periods, "n_periods", 1)
    n_total = n_total_of(n, n_periods)
    phi0 = as_number(phi0, "phi0")
    tol = as_tolerance(tol, "tol")
    max_iter = as_count(max_iter, "max_iter", 1)
    if wz0 is not None:
        wz0 = as_number(wz0, "wz0")
    srp = check_srp(srp)
    if free == "sun_phase":
        warnings.warn("periodic_attitude(free='sun_phase') is deprecated; use free='theta_sun0'", DeprecationWarning, stacklevel=2)
        free = "theta_sun0"
    if free not in ("phi0", "theta_sun0"):
        raise ValueError(f"invalid argument `free`: must be 'phi0' or 'theta_sun0', got {free!r}")
    if free == "theta_sun0" and (srp is None or srp.eps == 0.0):
        raise ValueError("invalid argument `free`: 'theta_sun0' needs srp with eps != 0")
    if method != "auto" and free == "theta_sun0":
        raise ValueError("invalid argument `method`: with free='theta_sun0' the full-period closure is used; leave method='auto'")
    symmetric = is_symmetric(orbit, phi0)
    if method == "half" and not (symmetric and (srp is None or srp.eps == 0.0)):
        raise ValueError("invalid argument `method`: 'half' needs an x-symmetric orbit started on the x axis, phi0 a "
                         "multiple of pi/2 and no SRP")
    what = f"periodic attitude (N = {per_period(n_total, n_periods)}, {kind}, Kz = {kz})"
    T = n_periods * orbit.period
    gravity = srp is None or srp.eps == 0.0
    if wz0 is None:
        if symmetric and method != "newton":
            base = kz_branch(orbit, kz, n_total, kind, phi0, n_periods, tol=tol, max_iter=max_iter)
        else:
            w0 = 1.0 + 2 * math.pi * float(turns_of(n_total, kind)) / T
            base = _direct(orbit, kz, n_total, kind, phi0, w0, n_periods, None, "full", "phi0", tol, max_iter, what)
        if gravity:
            return base if srp is None else verified(orbit, kz=kz, n_total=n_total, kind=kind, phi0=base.phi0, wz0=base.wz0,
                                                      n_periods=n_periods, plates=[srp], iterations=[base.iterations])[0]
        if free == "theta_sun0":
            return _direct(orbit, kz, n_total, kind, base.phi0, base.wz0, n_periods, srp, "full", "sun_phase", tol, max_iter, what)
        c = continue_srp(base, srp)
        if not c.reached:
            raise ConvergenceError(f"{what}: the branch continued in eps from the gravity-only solution stops "
                                   f"before eps = {srp.eps}: {c.end_reason}")
        return c.solutions[-1]
    if free == "theta_sun0":
        return _direct(orbit, kz, n_total, kind, phi0, wz0, n_periods, srp, "full", "sun_phase", tol, max_iter, what)
    closure = "half" if (method == "half" or (method == "auto" and symmetric and gravity)) else "full"
    return _direct(orbit, kz, n_total, kind, phi0, wz0, n_periods, srp, closure, "phi0", tol, max_iter, what)


def _direct(orbit, kz, n_total, kind, phi0, wz0, n_periods, srp, closure, free, tol, max_iter, what) -> AttitudeSolution:
    b = correct(orbit, kz=kz, n_total=n_total, kind=kind, phi0=phi0, wz0=wz0, n_periods=n_periods, srp=srp, closure=closure, free=free,
                tol=tol, max_iter=max_iter)
    if not b.converged[0]:
        raise _failure(what + f" from wz0 = {wz0:.10g}", b, 0, tol)
    plate = None if srp is None else (_plate(srp, math.remainder(float(b.theta_sun0[0]), 2 * math.pi)) if free == "sun_phase" else srp)
    return verified(orbit, kz=kz, n_total=n_total, kind=kind, phi0=float(b.phi0[0]), wz0=float(b.wz0[0]), n_periods=n_periods,
                    plates=[plate], iterations=b.iterations)[0]


class KzBranch:
    """The symmetric solution family of one orbit in (Kz, wz0), for the continuation driver:
    G(Kz, wz0) = phi(KT/2) - phi0 - pi turns = 0, corrected by the Rust corrector with Kz freed
    and the driver's linear condition. Bifurcation tests: the monodromy trace minus 2 (a fold
    of the full-period problem) and plus 2 (period doubling)."""

    parameter_index = 0
    scale = np.ones(2)

    def __init__(self, orbit, n_total, kind, phi0, n_periods, tol=1e-12, max_iter=40):
        self.orbit, self.n_total, self.kind, self.phi0, self.n_periods = orbit, n_total, kind, phi0, n_periods
        self.tol, self.max_iter = tol, max_iter

    def correct(self, guess, c):
        a_k, a_w = c.a
        b = correct(self.orbit, kz=float(np.clip(guess[0], -1.0, 1.0)), n_total=self.n_total, kind=self.kind,
                    phi0=self.phi0, wz0=float(guess[1]),
                    n_periods=self.n_periods, closure="half", tol=self.tol, max_iter=min(self.max_iter, STEP_MAX_ITER),
                    max_halvings=STEP_MAX_HALVINGS, bordered=("kz", (0.0, a_w, a_k, c.b)))
        if not b.converged[0]:
            raise CorrectionFailed(f"Kz branch: {b.reason[0]}")
        g = b.jacobian[0, 0]
        return Point(np.array([b.parameter[0], b.wz0[0]]), {"g_p": float(g[2]), "g_wz": float(g[1]),
                                                            "trace": float(np.trace(b.monodromy[0])),
                                                            "iterations": int(b.iterations[0])}, int(b.iterations[0]))

    def tangent(self, pt):
        d = pt.data
        return np.array([d["g_wz"], -d["g_p"]])

    def tests(self, pt):
        tr = pt.data["trace"]
        return {"trace = 2 (fold of the full-period problem)": tr - 2.0, "trace = -2 (period doubling)": tr + 2.0}


def kz_branch(orbit, kz, n_total, kind, phi0, n_periods, *, tol=1e-12, max_iter=40) -> AttitudeSolution:
    """The solution of the N family continued in Kz from Kz = 0 (wz0 = 1 + 2 pi turns / (KT)
    there) to ``kz``; ConvergenceError naming the fold's Kz when the branch folds first."""
    T = n_periods * orbit.period
    w0 = 1.0 + 2 * math.pi * float(turns_of(n_total, kind)) / T
    problem = KzBranch(orbit, n_total, kind, phi0, n_periods, tol, max_iter)
    first = problem.correct(np.array([0.0, w0]), Constraint.fix(2, 0, 0.0))
    if kz == 0.0:
        pt = first
    else:
        br = arclength(problem, first, direction=1 if kz > 0 else -1, target=kz, stop_at_fold=True, bounds=(-1.0, 1.0), name="Kz",
                       rules=StepRules(ds=0.05, ds_min=1e-9, ds_max=0.1))
        if not br.reached:
            n = per_period(n_total, n_periods)
            raise ConvergenceError(f"periodic attitude (N = {n}, {kind}): the branch continued in Kz from Kz = 0 does not reach Kz = {kz}: "
                                   f"{br.end_reason}; give a guess wz0= or list the solutions with find_periodic_attitudes")
        pt = br.points[-1]
    return verified(orbit, kz=float(pt.x[0]), n_total=n_total, kind=kind, phi0=phi0, wz0=float(pt.x[1]), n_periods=n_periods,
                    iterations=[pt.iterations])[0]


@dataclass
class SrpContinuation:
    """Solutions continued in the flat-plate SRP amplitude ``eps`` from a starting solution.
    ``reached``: the target eps was reached; otherwise ``fold`` gives where the branch turns
    back ({"eps", "trace", "located"}: the eps of the turning point located to 1e-8, where the
    2x2 monodromy's trace passes 2 and Phi - I is singular) or ``end_reason`` why the
    continuation stopped. ``marked``: (eps, solution) at the requested ``marks``.
    ``bifurcations``: where the trace passes 2 with eps still advancing (a branch point: the
    plate with the Sun phase a multiple of pi/K keeps a mirror symmetry, and asymmetric branches
    split off there) or passes -2 (period doubling), each {"test", "eps", "located"}. No point of
    another branch is ever returned."""

    solutions: list[AttitudeSolution]
    eps: np.ndarray
    reached: bool
    fold: dict | None
    end_reason: str
    marked: list[tuple[float, AttitudeSolution]] = field(default_factory=list)
    bifurcations: list[dict] = field(default_factory=list)


class EpsBranch:
    """Periodic motions with a flat plate continued in its amplitude eps, for the continuation
    driver: x = (eps, phi0, wz0), the full-period closure over the K periods (SRP breaks the
    mirror symmetry: phi0 is corrected with wz0), corrected by the Rust corrector with eps
    freed and the driver's linear condition."""

    parameter_index = 0
    scale = np.ones(3)

    def __init__(self, orbit, kz, n_total, kind, n_periods, plate: FlatPlate):
        self.orbit, self.kz, self.n_total, self.kind, self.n_periods, self.plate = orbit, kz, n_total, kind, n_periods, plate

    @property
    def batch_key(self):
        """Branches on one orbit with one body and plate (eps aside) are corrected together."""
        p = self.plate
        return (id(self.orbit), self.kz, self.n_periods, float(p.cs), float(p.cd), float(p.sun.theta0), float(p.sun.pressure))

    def correct(self, guess, c):
        b = self.corrections([(self, guess, c)])
        if not b.converged[0]:
            raise CorrectionFailed(f"eps branch: {b.reason[0]}")
        return self._point(b, 0)

    def correct_many(self, requests):
        """The bordered corrections of several branches' requests [(problem, guess, condition)]
        (problems with this one's batch_key), in one Rust call."""
        b = self.corrections(requests)
        return [self._point(b, i) if b.converged[i] else None for i in range(len(requests))]

    def corrections(self, requests):
        """The Rust corrector's CorrectionBatch of the bordered corrections of ``requests``
        [(problem, guess, condition)] (problems with this one's batch_key), in one call."""
        g = np.array([r[1] for r in requests], dtype=float)
        cond = np.array([[c.a[1], c.a[2], c.a[0], c.b] for _, _, c in requests], dtype=float)  # (a_phi0, a_wz0, a_eps, b)
        return correct(self.orbit, kz=self.kz, n_total=[p.n_total for p, _, _ in requests], kind=[p.kind for p, _, _ in requests],
                       phi0=g[:, 1], wz0=g[:, 2], n_periods=self.n_periods, srp=self.plate, eps=g[:, 0], closure="full", free="phi0",
                       max_iter=STEP_MAX_ITER, max_halvings=STEP_MAX_HALVINGS, max_contraction=STEP_MAX_CONTRACTION, bordered=("eps", cond))

    @staticmethod
    def _point(b, i):
        j = b.jacobian[i]  # columns (angle, wz0, eps)
        return Point(np.array([b.parameter[i], b.phi0[i], b.wz0[i]]), {"j": j[:, [2, 0, 1]], "trace": float(np.trace(b.monodromy[i]))},
                     int(b.iterations[i]))

    def tangent(self, pt):
        (a0, a1, a2), (b0, b1, b2) = pt.data["j"].tolist()
        # np.cross(j[0], j[1]) written out (the same products and differences; numpy's general
        # cross costs ~50 us a call, a tenth of a lock-step round's Python time)
        return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])

    def correct_batch(self, guesses, constraints, problems=None):
        """Points at fixed eps (the continuation's marks), all corrected in one call: the plain
        full-period correction in (phi0, wz0) at each one's eps; ``problems``: the branch of each
        guess (branches with this one's batch_key), default this one."""
        g = np.array(guesses, dtype=float)
        for c in constraints:
            if c.fixed_index != 0:
                raise ValueError("EpsBranch.correct_batch: only conditions fixing eps")
        owners = [self] * len(g) if problems is None else problems
        b = correct(self.orbit, kz=self.kz, n_total=[p.n_total for p in owners], kind=[p.kind for p in owners], phi0=g[:, 1], wz0=g[:, 2],
                    n_periods=self.n_periods,
                    srp=self.plate, eps=np.array([c.b for c in constraints]), closure="full", free="phi0", monodromy=False,
                    max_iter=STEP_MAX_ITER, max_halvings=STEP_MAX_HALVINGS)
        return [Point(np.array([c.b, b.phi0[i], b.wz0[i]]), None, int(b.iterations[i])) if b.converged[i] else None
                for i, c in enumerate(constraints)]

    def tests(self, pt):
        # trace 2 where the branch does not turn back: a symmetry-breaking (pitchfork) branch
        # point; trace -2: period doubling
        tr = pt.data["trace"]
        return {"trace = 2 (branch point)": tr - 2.0, "trace = -2 (period doubling)": tr + 2.0}


def eps_branch(solution: AttitudeSolution, srp, *, steps: int = 10, min_step: float = 1e-7, marks=()):
    """The driver's Branch of :func:`continue_srp` (points and marks corrected, not yet
    re-propagated: each point's ``data`` holds its Jacobian and monodromy trace); None when the
    target is the starting eps."""
    return eps_branches([(solution, srp, marks)], steps=steps, min_step=min_step)[0]


def eps_branches(jobs, *, steps: int = 10, min_step: float = 1e-7, done=None) -> list:
    """:func:`eps_branch` of every job (solution, target plate, marks), continued in lock step
    (:func:`librate.solving.continuation.run_lockstep`): each round, the corrections of all
    branches on one orbit and plate go to the Rust corrector in one call. Each branch is the one
    :func:`eps_branch` gives alone (to the corrector's tolerance). ``done(j, branch)`` is called
    as job j's branch ends (``branch`` None when there is nothing to continue)."""
    steps = as_count(steps, "steps", 1)
    min_step = as_number(min_step, "min_step", positive=True)
    todo = []
    for j, (solution, srp, marks) in enumerate(jobs):
        srp = check_srp(srp)
        if srp is None:
            raise ValueError("invalid argument `srp`: the target plate is required")
        if not isinstance(solution, AttitudeSolution):
            raise ValueError("invalid argument `solution`: must be a librate.AttitudeSolution")
        e0 = 0.0 if solution.srp is None else float(solution.srp.eps)
        target = float(srp.eps)
        if target != e0:
            problem = EpsBranch(solution.orbit, solution.kz, solution.n_total, solution.kind, solution.n_periods, srp)
            todo.append((j, problem, e0, target, solution, tuple(float(m) for m in marks)))
    firsts = correct_together([(p, np.array([e0, s.phi0, s.wz0]), Constraint.fix(3, 0, e0)) for _, p, e0, _, s, _ in todo])
    runs = []
    for (_, problem, e0, target, solution, marks), first in zip(todo, firsts):
        if first is None:
            raise ConvergenceError(f"continue_srp: the starting solution (wz0 = {solution.wz0:.10g}) does not correct at eps = {e0}")
        h = abs(target - e0) / steps
        rules = StepRules(ds=h, ds_min=min(min_step, h), ds_max=max(h, min(4 * h, 0.25)), predictor="quadratic")
        runs.append((problem, arclength_steps(problem, first, direction=1 if target > e0 else -1, target=target, stop_at_fold=True,
                                              locate_bifurcations=False, marks=marks, rules=rules, max_points=10_000, name="eps")))
    out: list = [None] * len(jobs)
    ids = [t[0] for t in todo]
    for j in sorted(set(range(len(jobs))) - set(ids)):  # nothing to continue
        if done is not None:
            done(j, None)
    for job, branch in zip(ids, run_lockstep(runs, done=None if done is None else (lambda i, br: done(ids[i], br)))):
        out[job] = branch
    return out


def branch_solutions(solution: AttitudeSolution, srp, points) -> list[AttitudeSolution]:
    """AttitudeSolutions of eps-branch points (x = (eps, phi0, wz0)), re-propagated in one batch."""
    return verified(solution.orbit, kz=solution.kz, n_total=solution.n_total, kind=solution.kind, phi0=[p.x[1] for p in points],
                    wz0=[p.x[2] for p in points], n_periods=solution.n_periods, plates=[srp.with_eps(float(p.x[0])) for p in points],
                    iterations=[p.iterations for p in points])


def branch_fold(br) -> dict | None:
    """The first fold of a Branch as {"eps", "trace", "located"}."""
    if not br.folds:
        return None
    f = br.folds[0]
    return {"eps": f.parameter, "trace": f.point.data["trace"], "located": bool(f.located)}


def continue_srp(solution: AttitudeSolution, srp, *, steps: int = 10, min_step: float = 1e-7, marks=()) -> SrpContinuation:
    """Continue a periodic attitude motion in the flat-plate SRP amplitude eps up to a target plate.

    Pseudo-arclength continuation in (eps, phi0, wz0) (`librate.solving.continuation`), every
    point corrected by the Rust corrector with eps freed and re-propagated independently; the
    plate's Cs, Cd and Sun phase are kept along the way. A fold before the target (the branch
    turning back in eps; the monodromy trace passes 2 there) is located to 1e-8 in eps and ends
    the continuation, on the fold.

    Parameters
    ----------
    solution : AttitudeSolution
        The start: gravity-only (eps = 0), or already with SRP.
    srp : FlatPlate
        The target plate; its ``eps`` is the target amplitude.
    steps : int, default 10
        The first step is |target - eps0| / ``steps``.
    min_step : float, default 1e-7
        The smallest step in eps before the continuation gives up.
    marks : sequence of float, optional
        eps values at which the branch is also corrected exactly (``marked`` of the result).

    Returns
    -------
    SrpContinuation
        ``solutions`` and ``eps`` along the branch, ``reached``, the ``fold`` if any,
        ``end_reason``, ``marked`` and ``bifurcations``.

    Raises
    ------
    ValueError
        A bad argument, naming it.

    Examples
    --------
    >>> import librate
    >>> orbit = librate.dro_family(librate.System.preset("earth-moon")).resonant(2, "sun")
    >>> gravity = librate.periodic_attitude(orbit, kz=0.8, n=-1, n_periods=2)
    >>> path = librate.continue_srp(gravity, librate.FlatPlate(0.02, cs=0.4))
    >>> path.reached, float(path.eps[-1])
    (True, 0.02)
    """
    br = eps_branch(solution, srp, steps=steps, min_step=min_step, marks=marks)
    e0 = 0.0 if solution.srp is None else float(solution.srp.eps)
    if br is None:
        return SrpContinuation([solution], np.array([e0]), True, None, "reached the target eps", [(m, solution) for m in marks if m == e0])
    pts = br.points[1:]
    sols = [solution] + branch_solutions(solution, srp, pts)
    marked = list(zip([float(p.x[0]) for p in br.marked], branch_solutions(solution, srp, br.marked))) if br.marked else []
    reason = "reached the target eps" if br.reached else br.end_reason
    bifs = [{"test": b.name, "eps": b.parameter, "located": bool(b.located)} for b in br.bifurcations]
    return SrpContinuation(sols, np.array([e0] + [float(p.x[0]) for p in pts]), br.reached, branch_fold(br), reason, marked, bifs)
