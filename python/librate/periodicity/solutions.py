"""Periodic orbit-attitude solutions (thesis sec. 3.3, docs/physics.md, periodic attitude motions).

Along a periodic orbit of period T, a planar attitude motion started at phi(0) = phi0 with
inertial rate wz(0) = wz0 is periodic when wz(T) = wz0 and phi(T) = phi0 + 2 pi N (N = net body
turns relative to the synodic frame per orbit). Motions with phi(T) = phi0 + pi (+ 2 pi N) are
dynamically periodic too (the inertia is symmetric under a half turn); they are reported as
their own class, "half-turn". Rates: ``wz0`` is inertial; ``phidot0 = wz0 - 1`` is relative to
the synodic frame (the quantity on the thesis figures' axes).

The grid work runs in the Rust engine (SIMD lanes, all cores, orbit forcing tabulated once per
orbit); refinement uses the engine's 2x2 attitude STM; every reported solution is re-propagated
independently (the orbit integrated alongside instead of the forcing table, tight tolerance).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._checks import as_count, as_number, as_size, as_threads, as_tolerance
from .._display import fmt, html_summary, short_repr
from .._progress import as_progress
from ..attitude.body import RigidBody
from ..attitude.propagate import propagate_attitude
from ..attitude.srp import FlatPlate
from ..orbits.periodic import PeriodicOrbit

__all__ = ["AttitudeSolution", "find_periodic_attitudes", "orbit_forcing", "clear_forcing_cache", "sweep", "candidates",
           "check_orbit", "check_kz", "check_kinds", "KINDS", "check_srp", "is_symmetric", "MAP_RTOL", "MAP_ATOL", "correct", "verified",
           "refine", "refine_groups", "start_refine", "Refining",
           "turns_of", "n_total_of", "per_period", "turns_array", "SOLVE_RTOL", "SOLVE_ATOL", "STEP_MAX_ITER", "MAP_METHOD",
           "STEP_MAX_HALVINGS", "STEP_MAX_CONTRACTION"]

MAP_RTOL = 1e-12
#: The lanes' method of the maps: RKF7(8); RKN8(6) is within 0.9-1.0x of its time at equal
#: accuracy (bench/bench_lanes.py), not enough to change the defaults' results.
MAP_METHOD = "rkf78"
MAP_ATOL = 1e-12
#: A continuation step's corrector: a good prediction converges in a few Newton steps; one that
#: does not is a step too long (the driver halves it), not worth forty iterations.
STEP_MAX_ITER = 10
STEP_MAX_HALVINGS = 4
#: The eps continuation's steps (SRP): a Newton step must leave at most this fraction of the
#: residual (Deuflhard's contraction test, his usual 1/4), else the correction stops at once
#: ("slow_convergence") and the driver halves the step. Without it, the long first steps of the
#: SRP-dominated branches crept (|F| 0.8, 0.7, 0.7, ...) through all STEP_MAX_ITER iterations,
#: holding every branch of the lock step for those rounds, and one such step of the README's
#: srp_map converged onto a neighbouring branch (wz0 0.157 -> 0.287 from eps = 2 to 1.5).
STEP_MAX_CONTRACTION = 0.25
#: The corrector's defaults: convergence at a residual max-norm of CORRECT_TOL, at most
#: CORRECT_MAX_ITER Newton steps and CORRECT_MAX_HALVINGS step halvings of the line search.
CORRECT_TOL = 1e-12
CORRECT_MAX_ITER = 40
CORRECT_MAX_HALVINGS = 10
#: Integration tolerances of the corrector's trajectories.
SOLVE_RTOL = 1e-13
SOLVE_ATOL = 1e-13
_FORCINGS: dict = {}


def orbit_forcing(orbit: PeriodicOrbit, primaries: tuple[bool, bool] = (True, True)):
    """The orbit's gravity-gradient forcing table (computed once per orbit and cached)."""
    key = (orbit.system.mu, tuple(np.asarray(orbit.state0).tolist()), float(orbit.period), tuple(primaries))
    f = _FORCINGS.get(key)
    if f is None:
        if len(_FORCINGS) > 256:
            _FORCINGS.clear()
        f = _core.OrbitForcing(orbit.system.mu, [float(v) for v in orbit.state0], float(orbit.period), primaries=list(primaries))
        _FORCINGS[key] = f
    return f


def clear_forcing_cache() -> None:
    """Forget the cached forcing tables of :func:`orbit_forcing` (e.g. to time their computation)."""
    _FORCINGS.clear()


_METHODS = {"rkf78": _core.LaneMethod.RKF78, "rkn86": _core.LaneMethod.RKN86, "dp87": _core.LaneMethod.DP87}
_CLOSURES = {"half": _core.Closure.HALF, "full": _core.Closure.FULL}
_FREE = {"phi0": _core.Free.PHI0, "sun_phase": _core.Free.SUN_PHASE}
_PARAMETERS = {"kz": _core.BorderedParameter.KZ, "eps": _core.BorderedParameter.EPS}


def _choice(table: dict, value, name: str):
    """The core's enum member for the string ``value`` of the argument ``name``."""
    if not isinstance(value, str) or value not in table:
        allowed = ", ".join(repr(k) for k in table)
        raise ValueError(f"invalid argument `{name}`: must be one of {allowed}, got {value!r}")
    return table[value]


def lane_method(method) -> _core.LaneMethod:
    """The lane engine's method of its name "rkf78", "rkn86" or "dp87" (ValueError naming `method`)."""
    return _choice(_METHODS, method, "method")


def plates_of(eps, cs, cd, theta_sun0) -> _core.Plates:
    """The core's per-case plates of four arrays of one length."""
    return _core.Plates(*(np.ascontiguousarray(v, dtype=np.float64) for v in (eps, cs, cd, theta_sun0)))


def sweep(forcing, t_final, phi0, wz0, kz, *, stm=False, rtol=MAP_RTOL, atol=MAP_ATOL, chunk=64, threads=None, srp=None, eps=None,
          method=MAP_METHOD):
    """The engine over broadcast (phi0, wz0, kz[, eps]) arrays; ``srp`` a FlatPlate (its eps
    overridden per case by ``eps`` when given); ``method`` "rkf78" (Runge-Kutta-Fehlberg 7(8),
    the default), "dp87" (Prince and Dormand's RK8(7)13M on the same states) or "rkn86" (Runge-Kutta-Nyström 8(6) on phi'' = wzdot(t, phi);
    its embedded error estimate is of sixth order, so the same accuracy comes at a looser rtol: see
    bench/bench_lanes.py)."""
    chunk = as_count(chunk, "chunk", 1)
    threads = as_threads(threads)
    rtol, atol = as_tolerance(rtol, "rtol"), as_tolerance(atol, "atol")
    n = np.broadcast(np.asarray(phi0), np.asarray(wz0), np.asarray(kz), np.asarray(0.0 if eps is None else eps)).shape
    flat = lambda a: np.ascontiguousarray(np.broadcast_to(np.asarray(a, dtype=np.float64), n)).ravel()  # noqa: E731
    p, w, k = flat(phi0), flat(wz0), flat(kz)
    plates = None if srp is None else plates_of(flat(srp.eps if eps is None else eps), flat(srp.cs), flat(srp.cd), flat(srp.sun.theta0))
    lanes = _core.LaneOptions(rtol=float(rtol), atol=float(atol), max_steps=200_000, method=lane_method(method),
                              chunk=int(chunk), threads=threads)
    return _core.map_sweep(forcing, float(t_final), _core.PlanarCases(p, w, k, plates=plates), lanes=lanes, stm=bool(stm))


def check_orbit(orbit) -> PeriodicOrbit:
    if not isinstance(orbit, PeriodicOrbit):
        raise ValueError(f"invalid argument `orbit`: must be a librate.PeriodicOrbit, got {type(orbit).__name__}")
    if orbit.state0[2] != 0.0 or orbit.state0[5] != 0.0:
        raise ValueError("invalid argument `orbit`: the planar attitude model needs a planar orbit (z = zd = 0)")
    return orbit


#: The classes of periodic motion: phi(T) = phi0 + 2 pi N, and a half turn more.
KINDS = ("periodic", "half-turn")


def check_kinds(kinds) -> tuple[str, ...]:
    ks = (kinds,) if isinstance(kinds, str) else tuple(kinds)
    if not ks or any(k not in KINDS for k in ks):
        raise ValueError(f"invalid argument `kinds`: must be 'periodic' and/or 'half-turn', got {kinds!r}")
    return ks


def check_kz(kz) -> float:
    if isinstance(kz, bool) or not (isinstance(kz, (int, float, np.floating, np.integer)) and math.isfinite(kz) and -1 <= kz <= 1):
        raise ValueError(f"invalid argument `kz`: must be a number in [-1, 1], got {kz!r}")
    return float(kz)


def is_symmetric(orbit: PeriodicOrbit, phi0: float) -> bool:
    """x-symmetric orbit started on the x axis, and a symmetric initial attitude."""
    s = orbit.state0
    on_axis = s[1] == 0.0 and s[3] == 0.0
    k = phi0 / (0.5 * math.pi)
    return on_axis and abs(k - round(k)) < 1e-15


def n_total_of(n, n_periods: int) -> int:
    """Net turns over the K = ``n_periods`` periods from ``n`` turns per orbit period (n K must
    be a whole number)."""
    if isinstance(n, bool) or not isinstance(n, (int, float, np.integer, np.floating)) or not math.isfinite(n):
        raise ValueError(f"invalid argument `n`: must be a number of turns per orbit period, got {n!r}")
    total = n * n_periods
    if abs(total - round(total)) > 1e-9:
        raise ValueError(f"invalid argument `n`: n x n_periods must be a whole number of turns over the {n_periods} periods, got n = {n!r}")
    return int(round(total))


def per_period(n_total: int, n_periods: int) -> int | float:
    return n_total // n_periods if n_total % n_periods == 0 else n_total / n_periods


def turns_array(values) -> np.ndarray:
    """Turns per orbit period (``AttitudeSolution.n`` values) as a stored array: int64 when all
    are whole numbers (always with ``n_periods=1``), else float64 (n_total / K not whole)."""
    a = np.asarray(list(values), dtype=float)
    return a.astype(np.int64) if np.all(a == np.round(a)) else a


@dataclass(frozen=True)
class AttitudeSolution:
    """A periodic (or half-turn) planar attitude motion along an orbit, over K = ``n_periods`` orbit
    periods.

    Made by `periodic_attitude`, `find_periodic_attitudes` and the maps; the fields are the
    solution, the properties derived from it.

    Parameters
    ----------
    orbit : PeriodicOrbit
        The orbit.
    kz : float
        The body's inertia ratio Kz = (Iy - Ix) / Iz.
    n_total : int
        Net body turns relative to the synodic frame over the K periods: phi(KT) = phi0 +
        2 pi n_total (+ pi for "half-turn" solutions).
    kind : {"periodic", "half-turn"}
        The closure.
    phi0 : float
        Initial angle (rad).
    wz0 : float
        Inertial initial rate (1/TU).
    residual_dphi, residual_dwz : float
        The closure residuals after the K periods, from an independent re-propagation (orbit
        integrated alongside, rtol = atol = 1e-14).
    monodromy : numpy.ndarray, shape (2, 2)
        d(phi, wz)(KT) / d(phi0, wz0).
    iterations : int
        The corrector's accepted Newton steps.
    srp : FlatPlate, optional
        The SRP plate, if any.
    n_periods : int, default 1
        K.

    Attributes
    ----------
    n : int or float
        Turns per orbit period, n_total / K (a whole number when K divides n_total).
    phidot0 : float
        Initial rate relative to the synodic frame, wz0 - 1 (1/TU).
    residual : float
        max(|residual_dphi|, |residual_dwz|).
    trace : float
        The monodromy's trace.
    multipliers : numpy.ndarray
        The monodromy's eigenvalues.
    stable : bool
        Linearly stable: |trace| < 2 (multipliers on the unit circle).
    """

    orbit: PeriodicOrbit
    kz: float
    n_total: int
    kind: str
    phi0: float
    wz0: float
    residual_dphi: float
    residual_dwz: float
    monodromy: np.ndarray = field(repr=False)
    iterations: int = 0
    srp: object = None
    n_periods: int = 1

    # --- display (librate._display): the orbit by its key numbers, never nested whole ----------
    def _rows(self):
        return [("kind", self.kind, ""), ("kz", self.kz, ""), ("n", self.n, "turns/orbit"), ("phi0", self.phi0, "rad"),
                ("phidot0", self.phidot0, "1/TU"), ("stable", self.stable, ""), ("residual", self.residual, "")]

    def __repr__(self) -> str:
        return short_repr("AttitudeSolution", self._rows() + [("orbit_period_days", self.orbit.period_days, "d")])

    def _repr_html_(self) -> str:
        details = {"stability": [("trace", self.trace, ""), ("multipliers", self.multipliers, ""), ("monodromy", self.monodromy, "")],
                   "correction": [("n_total", self.n_total, ""), ("n_periods", self.n_periods, ""), ("wz0", self.wz0, "1/TU"),
                                  ("residual_dphi", self.residual_dphi, "rad"), ("residual_dwz", self.residual_dwz, "1/TU"),
                                  ("iterations", self.iterations, "")],
                   "orbit": [("orbit", repr(self.orbit), ""), ("srp", "none" if self.srp is None else repr(self.srp), "")]}
        title = f"librate.AttitudeSolution N = {fmt(self.n)} {self.kind} (Kz = {fmt(self.kz)}, {'stable' if self.stable else 'unstable'})"
        return html_summary(title, self._rows(), details)


    @property
    def n(self) -> int | float:
        """Net turns per orbit period, n_total / n_periods."""
        return per_period(self.n_total, self.n_periods)

    @property
    def phidot0(self) -> float:
        """Initial rate relative to the synodic frame, wz0 - 1."""
        return self.wz0 - 1.0

    @property
    def residual(self) -> float:
        return max(abs(self.residual_dphi), abs(self.residual_dwz))

    @property
    def trace(self) -> float:
        m = self.monodromy
        return float(m[0, 0] + m[1, 1])  # np.trace's sum, without its ~1.5 us call

    @property
    def multipliers(self) -> np.ndarray:
        return np.linalg.eigvals(self.monodromy)

    @property
    def stable(self) -> bool:
        return abs(self.trace) < 2.0

    def propagate(self, n_periods: float = 1.0, **kwargs):
        """The motion over ``n_periods`` orbits (planar model, orbit integrated alongside)."""
        kwargs.setdefault("rtol", 1e-13)
        kwargs.setdefault("atol", 1e-13)
        return propagate_attitude(self.orbit.system, self.orbit.state0, (self.phi0, self.wz0), RigidBody.from_kz(self.kz),
                                  n_periods * self.orbit.period, planar=True, srp=self.srp, **kwargs)


def check_srp(srp):
    if srp is None:
        return None
    if not isinstance(srp, FlatPlate):
        raise ValueError(f"invalid argument `srp`: must be a librate.FlatPlate or None, got {srp!r}")
    return srp


def turns_of(n_total, kind) -> np.ndarray:
    """Turns of the closure condition: n_total, plus a half for half-turn motions."""
    kinds = np.asarray(kind)
    return np.asarray(n_total, dtype=float) + np.where(kinds == "half-turn", 0.5, 0.0)


def correct(orbit: PeriodicOrbit, *, kz, n_total, kind, phi0, wz0, n_periods: int = 1, srp=None, closure: str = "half",
            free: str = "phi0", theta_sun0=None, eps=None, tol: float = CORRECT_TOL, max_iter: int = CORRECT_MAX_ITER, bordered=None,
            monodromy: bool = True, max_halvings: int = CORRECT_MAX_HALVINGS, search=None, max_contraction: float | None = None):
    """One call of the Rust corrector for a batch of candidates on ``orbit`` (arrays broadcast
    together: kz, n_total, kind, phi0, wz0, and theta_sun0 / eps overriding the plate's):
    ``closure`` "half" (symmetric, over K T / 2) or "full" (over K T); ``free`` "phi0" or
    "sun_phase"; ``bordered``: (parameter "kz" or "eps", condition (a_angle, a_wz0, a_parameter,
    b), or one such row per candidate) for the continuation driver; ``search``: (lo, hi) of
    wz0 per candidate, where a Newton step leaving it stops the candidate ("left_window");
    ``max_contraction``: a continuation step's test (a candidate whose accepted Newton step
    leaves the residual above that fraction of its value stops, "slow_convergence").
    Returns the core's CorrectionBatch."""
    cases, options, t_final = _corrector_inputs(orbit, kz=kz, n_total=n_total, kind=kind, phi0=phi0, wz0=wz0, n_periods=n_periods,
                                                srp=srp, closure=closure, theta_sun0=theta_sun0, eps=eps, tol=tol, max_iter=max_iter,
                                                monodromy=monodromy, max_halvings=max_halvings, search=search,
                                                max_contraction=max_contraction)
    border = None
    if bordered is not None:
        parameter = _choice(_PARAMETERS, bordered[0], "parameter")
        cond = np.asarray(bordered[1], dtype=float)
        if cond.ndim == 2:  # one condition per candidate (branches corrected together)
            border = _core.Bordered(parameter, tuple(cond[0]), conditions=np.ascontiguousarray(np.broadcast_to(cond, (len(cases), 4))))
        else:
            border = _core.Bordered(parameter, tuple(float(v) for v in cond))
    return _core.attitude_correct(orbit_forcing(orbit), cases, t_final=t_final, closure=_choice(_CLOSURES, closure, "closure"),
                                  free=_choice(_FREE, free, "free"), options=options, bordered=border)


def _corrector_inputs(orbit, *, kz, n_total, kind, phi0, wz0, n_periods, srp, closure, theta_sun0, eps, tol, max_iter, monodromy,
                      max_halvings, search, max_contraction=None):
    """The core's PlanarCases, CorrectorOptions and closure time of a batch of candidates (the
    arrays of :func:`correct` broadcast together)."""
    cols = [np.asarray(kz, dtype=float), np.asarray(n_total, dtype=float), np.asarray(kind), np.asarray(phi0, dtype=float),
            np.asarray(wz0, dtype=float), np.asarray(0.0 if eps is None else eps, dtype=float),
            np.asarray(0.0 if theta_sun0 is None else theta_sun0, dtype=float)]
    if any(c.shape != cols[0].shape for c in cols[1:5]) or (eps is not None or theta_sun0 is not None):
        cols = np.broadcast_arrays(*cols)  # (a batch's own columns are of one shape already: not broadcast, ~10 us)
    k, nt, kd, p, w, e, th = (np.ascontiguousarray(c).ravel() for c in cols)
    plates = None
    if srp is not None:
        plates = plates_of(np.full(k.size, srp.eps) if eps is None else e, np.full(k.size, float(srp.cs)), np.full(k.size, float(srp.cd)),
                           np.full(k.size, float(srp.sun.theta0)) if theta_sun0 is None else th)
    T = n_periods * orbit.period
    options = _core.CorrectorOptions(_core.NewtonOptions(tol=float(tol), max_iter=int(max_iter), max_halvings=int(max_halvings),
                                                         max_contraction=max_contraction),
                                     _core.LaneOptions(rtol=SOLVE_RTOL, atol=SOLVE_ATOL), monodromy=bool(monodromy))
    window = None
    if search is not None:
        window = np.empty((k.size, 2))
        window[:, 0], window[:, 1] = search  # each bound one value or one per candidate
    cases = _core.PlanarCases(p, w, k, turns=turns_of(nt, kd), plates=plates, window=window)
    return cases, options, 0.5 * T if closure == "half" else T


def verified(orbit: PeriodicOrbit, *, kz, n_total, kind, phi0, wz0, n_periods: int = 1, plates=None, iterations=None,
             threads: int | None = None) -> list[AttitudeSolution]:
    """AttitudeSolutions for converged corrections: every one re-propagated independently in one
    batched Rust call (the orbit integrated alongside instead of the forcing table, rtol = atol =
    1e-14, with the 2x2 STM: the SIMD lanes in lock-step groups of eight in the given order, the
    groups in parallel on ``threads``, default all cores; the results depend on the order, never
    on the threads); ``plates``: one FlatPlate (or None) per solution."""
    kz, n_total, phi0, wz0, kind = (np.ascontiguousarray(np.atleast_1d(v).ravel())
                                    for v in np.broadcast_arrays(np.asarray(kz, dtype=float), np.asarray(n_total, dtype=float),
                                                                 np.asarray(phi0, dtype=float),
                                                                 np.asarray(wz0, dtype=float), np.asarray(kind)))
    m = kz.size
    if m == 0:
        return []
    plates = [None] * m if plates is None else list(plates)
    per_plate = None
    if any(pl is not None for pl in plates):
        per_plate = plates_of([pl.eps if pl else 0.0 for pl in plates], [pl.cs if pl else 0.0 for pl in plates],
                              [pl.cd if pl else 0.0 for pl in plates], [pl.sun.theta0 if pl else 0.0 for pl in plates])
    T = n_periods * orbit.period
    cases = _core.PlanarCases(np.ascontiguousarray(phi0), np.ascontiguousarray(wz0), np.ascontiguousarray(kz),
                              turns=turns_of(n_total, kind), plates=per_plate)
    v = _core.planar_verify(orbit.system.mu, [float(x) for x in orbit.state0], T, cases, threads=threads)
    its = [0] * m if iterations is None else iterations
    return _solutions(orbit, kz, n_total, kind, phi0, wz0, v.residual, v.stm, its, plates, n_periods)


def _solutions(orbit, kz, n_total, kind, phi0, wz0, residual, stm, iterations, plates, n_periods) -> list[AttitudeSolution]:
    """One AttitudeSolution per verified motion (arrays over them; ``residual`` (m, 2) and ``stm``
    (m, 2, 2) of the core's independent re-propagation), made from plain Python values (numpy
    scalars cost ~1 us each)."""
    k_, nt_, kd_ = np.asarray(kz).tolist(), np.asarray(n_total).astype(int).tolist(), [str(x) for x in np.asarray(kind).tolist()]
    p_, w_, its = np.asarray(phi0).tolist(), np.asarray(wz0).tolist(), np.asarray(iterations).astype(int).tolist()
    res, stm = np.asarray(residual).tolist(), np.asarray(stm)
    return [AttitudeSolution(orbit, k_[i], nt_[i], kd_[i], p_[i], w_[i], res[i][0], res[i][1], stm[i], its[i], plates[i], int(n_periods))
            for i in range(len(k_))]


def _grid_for(T: float, lo: float, hi: float, n_grid: int | None) -> np.ndarray:
    if n_grid is None:
        # phi(T) moves by about T per unit wz0: 16 samples per pi of phi(T).
        n_grid = int(max(200, 16 * (hi - lo) * T / math.pi))
    return np.linspace(lo, hi, int(n_grid))


def candidates(phi_t, phi0, wz, level, max_crossings: int | None = None):
    """wz0 brackets where (phi(t) - phi0) / level crosses an integer; returns (k, wz_interp) in
    order of the grid (linear interpolation; librate_core::map::crossings). ``max_crossings``: an
    interval that crosses more integers than that is left out (the grid does not resolve it)."""
    c = _core.row_crossings(np.ascontiguousarray(phi_t, dtype=float), np.ascontiguousarray(wz, dtype=float), phi0=float(phi0),
                            level=float(level), max_crossings=None if max_crossings is None else int(max_crossings))
    return list(zip(c.k.tolist(), c.wz0.tolist()))


def refine(orbit, kz, phi0, cands, *, n_periods, srp, closure, window, kinds=KINDS, search=None) -> list[AttitudeSolution]:
    """Refine (k, wz0) candidates (k = 2 turns over the K periods, odd k a half turn) in ONE
    corrector call and verify the converged ones in one more: :func:`refine_groups` with every
    candidate in one group."""
    return [s for _, s in refine_groups(orbit, kz, phi0, cands, n_periods=n_periods, srp=srp, closure=closure, window=window, kinds=kinds,
                                        search=search)]


def refine_groups(orbit, kz, phi0, cands, *, n_periods, srp, closure, window, kinds=KINDS, search=None,
                  group=None) -> list[tuple[int, AttitudeSolution]]:
    """Refine (k, wz0) candidates (k = 2 turns over the K periods, odd k a half turn) in ONE
    corrector call and verify the converged ones in one more; keep those inside ``window``
    with an independent residual below 1e-8, one per (turns, kind, wz0 to 1e-8), sorted by wz0:
    :func:`start_refine`, waited for."""
    return start_refine(orbit, kz, phi0, cands, n_periods=n_periods, srp=srp, closure=closure, window=window, kinds=kinds, search=search,
                        group=group).result()


class Refining:
    """Work under way whose outcome ``result()`` waits for: a refinement started by
    :func:`start_refine` runs on the core's pool meanwhile. It is waited for once; later calls
    return that outcome again, or raise that exception again (a KeyboardInterrupt that stopped
    it)."""

    __slots__ = ("_finish", "_out", "_error")

    def __init__(self, finish: Callable[[], list]):
        self._finish: Callable[[], list] | None = finish
        self._out: list = []
        self._error: BaseException | None = None

    def result(self) -> list:
        if self._finish is not None:
            finish, self._finish = self._finish, None
            try:
                self._out = finish()
            except BaseException as err:
                self._error = err
                raise
        if self._error is not None:
            raise self._error
        return self._out


def start_refine(orbit, kz, phi0, cands, *, n_periods, srp, closure, window, kinds=KINDS, search=None, group=None) -> Refining:
    """Start refining (k, wz0) candidates (k = 2 turns over the K periods, odd k a half turn) in
    one core call (librate_core::attitude::refine_planar_attitudes, on the pool while the caller
    goes on): all corrected together, the converged ones inside ``window`` kept once per
    (group, Kz, turns, wz0 to 1e-8), re-propagated independently together and kept with a
    residual of at most 1e-8. ``kz`` and ``phi0`` may be one value or one per candidate.
    ``search``: (lo, hi), a window of wz0 per candidate: the candidates are a map's crossings,
    close guesses of the half-period closure, each refined within its window (a Newton step
    leaving it stops it) and given up after a few Newton steps (see
    ``periodicity.maps.crossing_windows``). ``group``: one integer label per candidate
    (default: all 0); duplicates are merged within a group only. ``result()`` gives (group,
    solution) pairs, group by group (in order of first appearance), each group sorted by Kz and
    wz0."""
    n = len(cands)
    grp = np.zeros(n, dtype=np.int64) if group is None else np.asarray(group, dtype=np.int64)
    p0 = np.broadcast_to(np.asarray(phi0, dtype=float), (n,))
    keep = [i for i, (k, _) in enumerate(cands) if ("periodic" if k % 2 == 0 else "half-turn") in kinds]
    if not keep:
        return Refining(list)
    ks = np.array([cands[i][0] for i in keep])
    n_total = ks // 2
    kind = np.where(ks % 2 == 0, "periodic", "half-turn")
    kzs = np.broadcast_to(np.asarray(kz, dtype=float), (n,))[keep]
    grp, p0 = np.ascontiguousarray(grp[keep]), p0[keep]
    quick = {"max_iter": CORRECT_MAX_ITER, "max_halvings": CORRECT_MAX_HALVINGS, "search": None} if search is None else {
        "max_iter": STEP_MAX_ITER, "max_halvings": 3, "search": tuple(np.asarray(v, dtype=float)[keep] for v in search)}
    # monodromy=False: the verification brings the STM
    wz0 = np.array([cands[i][1] for i in keep])
    cases, options, t_final = _corrector_inputs(orbit, kz=kzs, n_total=n_total, kind=kind, phi0=p0, wz0=wz0, n_periods=n_periods, srp=srp,
                                                closure=closure, theta_sun0=None, eps=None, tol=CORRECT_TOL, monodromy=False, **quick)
    pending = _core.attitude_refine(orbit_forcing(orbit), cases, t_final=t_final, closure=_choice(_CLOSURES, closure, "closure"),
                                    options=options, keep=(float(window[0]), float(window[1])), groups=grp)

    def finish() -> list:
        r = pending.join()
        i = np.asarray(r.index)
        sols = _solutions(orbit, kzs[i], n_total[i], kind[i], r.phi0, r.wz0, r.residual, r.stm, r.iterations, [srp] * len(i), n_periods)
        return list(zip(grp[i].tolist(), sols))

    return Refining(finish)


def find_periodic_attitudes(
    orbit: PeriodicOrbit,
    *,
    kz: float,
    wz0_range: tuple[float, float],
    phi0: float | Sequence[float] = 0.0,
    kinds: Sequence[str] = KINDS,
    n_grid: int | None = None,
    n_periods: int = 1,
    srp=None,
    progress=None,
) -> list[AttitudeSolution]:
    """Every periodic (and half-turn) attitude motion with inertial wz0 in a window of rates.

    A grid scan by the engine brackets the candidates (crossings of phi(T/2) - phi0 through
    multiples of pi/2 for symmetric cases, of phi(T) - phi0 through multiples of pi otherwise);
    all are refined together by one call of the Rust corrector and kept when they converge inside
    the window, each re-propagated independently.

    Parameters
    ----------
    orbit : PeriodicOrbit
        A planar periodic orbit.
    kz : float
        Inertia ratio Kz = (Iy - Ix) / Iz in [-1, 1].
    wz0_range : (float, float)
        The window of inertial initial rates (1/TU).
    phi0 : float or sequence of float, default 0.0
        Initial angle(s) (rad). Several starting attitudes share one engine sweep and one
        corrector call per closure, and find motions a single scan misses where the corrector
        frees phi0 (e.g. with SRP); duplicates are merged within each scan, not across them.
    kinds : sequence of {"periodic", "half-turn"}
        The closures to look for.
    n_grid : int, optional
        Scan points (default: from the window's width).
    n_periods : int, default 1
        K, the orbit periods per attitude period.
    srp : FlatPlate, optional
        Solar radiation pressure.
    progress : bool or callable, optional
        True for a bar on stderr, or ``progress(done, total)`` after the scan and after each
        closure's refinement.

    Returns
    -------
    list of AttitudeSolution
        Sorted by wz0 (scans in the given order where wz0 ties).

    Raises
    ------
    ValueError
        A bad argument, naming it and the allowed range.

    Examples
    --------
    >>> import librate
    >>> dro = librate.dro(period_days=12.66)
    >>> sols = librate.find_periodic_attitudes(dro, kz=0.8, wz0_range=(-3.0, 2.0))
    >>> sorted({s.n for s in sols if s.kind == "periodic"})
    [-1, 0]
    """
    progress = as_progress(progress, "periodic attitudes", "step")
    orbit = check_orbit(orbit)
    kz = check_kz(kz)
    try:
        lo, hi = (float(v) for v in wz0_range)
    except (TypeError, ValueError):
        raise ValueError(f"invalid argument `wz0_range`: must be (lo, hi), got {wz0_range!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ValueError(f"invalid argument `wz0_range`: must be finite with lo < hi, got {wz0_range!r}")
    kinds = check_kinds(kinds)
    n_periods = as_count(n_periods, "n_periods", 1)
    if n_grid is not None:  # the sweep's cases and outputs, float64: about 8 numbers per rate
        n_grid = as_size(n_grid, "n_grid", 2, item_bytes=64)
    seeds = [as_number(v, "phi0") for v in (phi0 if isinstance(phi0, (list, tuple, np.ndarray)) else [phi0])]
    if not seeds:
        raise ValueError("invalid argument `phi0`: need at least one starting attitude")
    srp = check_srp(srp)
    T = n_periods * orbit.period
    wz = _grid_for(T, lo, hi, n_grid)
    found: list[list[AttitudeSolution]] = [[] for _ in seeds]
    closures = [[i for i, p in enumerate(seeds) if (is_symmetric(orbit, p) and (srp is None or srp.eps == 0.0)) == symmetric]
                for symmetric in (True, False)]
    total, done = 2 * sum(1 for idx in closures if idx), 0
    for symmetric, idx in zip((True, False), closures):
        if not idx:
            continue
        t_scan, level = (0.5 * T, 0.5 * math.pi) if symmetric else (T, math.pi)
        p_grid = np.array([seeds[i] for i in idx])[:, None]
        r = sweep(orbit_forcing(orbit), t_scan, p_grid, wz[None, :], kz, srp=srp)
        phi_t = np.asarray(r["phi_t"]).reshape(len(idx), wz.size)
        if progress is not None:
            done += 1
            progress(done, total)
        # symmetric: phi(T/2) - phi0 = k pi/2 -> turns = k/2; else phi(T) - phi0 = k pi -> turns = k/2
        cands, start, group = [], [], []
        for j, i in enumerate(idx):
            c = candidates(phi_t[j], seeds[i], wz, level)
            cands += c
            start += [seeds[i]] * len(c)
            group += [i] * len(c)
        for g, s_ in refine_groups(orbit, kz, np.array(start), cands, n_periods=n_periods, srp=srp, closure="half" if symmetric else "full",
                                   window=(lo, hi), kinds=kinds, group=group):
            found[g].append(s_)
        if progress is not None:
            done += 1
            progress(done, total)
    # each scan sorted by wz0, then all (a stable sort: scans in order where wz0 ties)
    return sorted((s_ for f in found for s_ in sorted(f, key=lambda s_: s_.wz0)), key=lambda s_: s_.wz0)
