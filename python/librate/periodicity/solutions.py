"""Periodic orbit-attitude solutions (thesis sec. 3.3, PHYSICS.md sec. 5).

Along a periodic orbit of period T, a planar attitude motion started at phi(0) = phi0 with
inertial rate wz(0) = wz0 is periodic when wz(T) = wz0 and phi(T) = phi0 + 2 pi N (N = net body
turns relative to the synodic frame per orbit). Motions with phi(T) = phi0 + pi (+ 2 pi N) are
dynamically periodic too (the inertia is symmetric under a half turn); they are reported as
their own class, "half-turn". Rates: ``wz0`` is inertial; ``phidot0 = wz0 - 1`` is relative to
the synodic frame (the quantity on the thesis figures' axes).

The grid work runs in the Rust engine (SIMD lanes, all cores, orbit forcing tabulated once per
orbit); refinement uses the engine's 2x2 attitude STM; every reported solution is re-propagated
independently (scalar model, orbit integrated alongside, tight tolerance).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._errors import ConvergenceError
from ..attitude.body import RigidBody
from ..attitude.propagate import propagate_attitude
from ..attitude.srp import FlatPlate, Sun
from ..orbits.periodic import PeriodicOrbit

__all__ = ["AttitudeSolution", "periodic_attitude", "find_periodic_attitudes", "orbit_forcing", "clear_forcing_cache", "sweep", "candidates",
           "check_orbit", "check_kz", "check_kinds", "KINDS", "check_srp", "is_symmetric", "MAP_RTOL", "MAP_ATOL"]

MAP_RTOL = 1e-12
MAP_ATOL = 1e-12
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


def sweep(forcing, t_final, phi0, wz0, kz, *, stm=False, rtol=MAP_RTOL, atol=MAP_ATOL, chunk=64, threads=None, srp=None, eps=None):
    """The engine over broadcast (phi0, wz0, kz[, eps]) arrays; ``srp`` a FlatPlate (its eps
    overridden per case by ``eps`` when given)."""
    n = np.broadcast(np.asarray(phi0), np.asarray(wz0), np.asarray(kz), np.asarray(0.0 if eps is None else eps)).shape
    flat = lambda a: np.ascontiguousarray(np.broadcast_to(np.asarray(a, dtype=np.float64), n)).ravel()  # noqa: E731
    p, w, k = flat(phi0), flat(wz0), flat(kz)
    extra = {}
    if srp is not None:
        extra = dict(eps=flat(srp.eps if eps is None else eps), cs=flat(srp.cs), cd=flat(srp.cd), theta_sun0=flat(srp.sun.theta0))
    return _core.map_sweep(forcing, float(t_final), p, w, k, rtol=float(rtol), atol=float(atol), max_steps=200_000,
                           stm=bool(stm), chunk=int(chunk), threads=threads, **extra)


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
    if not (isinstance(kz, (int, float, np.floating, np.integer)) and math.isfinite(kz) and -1 <= kz <= 1):
        raise ValueError(f"invalid argument `kz`: must be a number in [-1, 1], got {kz!r}")
    return float(kz)


def is_symmetric(orbit: PeriodicOrbit, phi0: float) -> bool:
    """x-symmetric orbit started on the x axis, and a symmetric initial attitude."""
    s = orbit.state0
    on_axis = s[1] == 0.0 and s[3] == 0.0
    k = phi0 / (0.5 * math.pi)
    return on_axis and abs(k - round(k)) < 1e-15


@dataclass(frozen=True)
class AttitudeSolution:
    """A periodic (or half-turn) planar attitude motion along an orbit.

    ``n``: net body turns per orbit relative to the synodic frame (for "half-turn" solutions
    phi(T) = phi0 + 2 pi n + pi). ``residual``: max(|Dphi|, |Dwz|) after one period from an
    independent re-propagation. ``monodromy``: the 2x2 d(phi, wz)(T)/d(phi0, wz0); the motion is
    linearly stable when |trace| < 2 (multipliers on the unit circle).
    """

    orbit: PeriodicOrbit
    kz: float
    n: int
    kind: str
    phi0: float
    wz0: float
    residual_dphi: float
    residual_dwz: float
    monodromy: np.ndarray = field(repr=False)
    iterations: int = 0
    srp: object = None
    n_periods: int = 1

    @property
    def phidot0(self) -> float:
        """Initial rate relative to the synodic frame, wz0 - 1."""
        return self.wz0 - 1.0

    @property
    def residual(self) -> float:
        return max(abs(self.residual_dphi), abs(self.residual_dwz))

    @property
    def trace(self) -> float:
        return float(np.trace(self.monodromy))

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


def _solve_sun_phase(orbit, kz, n, kind, phi0, w, srp, n_periods, turns, tol, max_iter):
    """Newton on (Sun phase, wz0) with phi0 fixed."""
    forcing = orbit_forcing(orbit)
    T = n_periods * orbit.period
    th = float(srp.sun.theta0)

    def plate(theta):
        return FlatPlate(srp.eps, srp.cs, srp.cd, Sun(theta0=theta, pressure=srp.sun.pressure))

    def F(theta, wz, stm=False):
        r = sweep(forcing, T, phi0, wz, kz, stm=stm, rtol=1e-13, atol=1e-13, srp=plate(theta))
        return np.array([r["phi_t"][0] - phi0 - 2 * math.pi * turns, r["wz_t"][0] - wz]), r

    res = math.inf
    for it in range(1, max_iter + 1):
        f, r = F(th, w, stm=True)
        res = float(np.max(np.abs(f)))
        if res < tol:
            break
        h = 1e-6
        dth = (F(th + h, w)[0] - F(th - h, w)[0]) / (2 * h)
        m = r["stm"][0]
        jac = np.array([[dth[0], m[0, 1]], [dth[1], m[1, 1] - 1.0]])
        try:
            d = np.linalg.solve(jac, -f)
        except np.linalg.LinAlgError:
            raise ConvergenceError(f"periodic attitude (Sun phase free): singular Jacobian at wz0 = {w}") from None
        scale = min(1.0, 0.5 / max(abs(d[0]), abs(d[1]), 1e-300))
        th += float(d[0]) * scale
        w += float(d[1]) * scale
    else:
        raise ConvergenceError(f"periodic attitude (Sun phase free, N = {n}) did not converge after {max_iter} iterations (residual {res:.3e})")
    found = plate(math.remainder(th, 2 * math.pi))
    dphi, dwz, mono = _verify(orbit, kz, phi0, w, turns, n_periods, found)
    return AttitudeSolution(orbit, kz, int(n), kind, phi0, w, float(dphi), float(dwz), mono, it, found, int(n_periods))


def check_srp(srp):
    if srp is None:
        return None
    if not isinstance(srp, FlatPlate):
        raise ValueError(f"invalid argument `srp`: must be a librate.FlatPlate or None, got {srp!r}")
    return srp


def _verify(orbit, kz, phi0, wz0, turns, n_periods, srp=None):
    """Independent re-propagation (scalar planar model with the orbit integrated alongside, at
    rtol = atol = 1e-14): residuals and the 2x2 monodromy."""
    T = n_periods * orbit.period
    tr = propagate_attitude(orbit.system, orbit.state0, (phi0, wz0), RigidBody.from_kz(kz), T, planar=True, stm=True,
                            rtol=1e-14, atol=1e-14, t_eval=[T], srp=srp)
    dphi = tr.phi[-1] - phi0 - 2 * math.pi * turns
    dwz = tr.wz[-1] - wz0
    return dphi, dwz, tr.stm


def periodic_attitude(
    orbit: PeriodicOrbit,
    *,
    kz: float,
    n: int,
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
    """The periodic attitude motion with ``n`` net turns per orbit (``kind="half-turn"``: a half
    turn more) along ``orbit``, for the body with ``kz``.

    ``method``: "half" solves phi(KT/2) = phi0 + pi * turns for wz0 (a scalar Newton with the
    STM; exact for x-symmetric orbits with phi0 a multiple of pi/2 and no SRP; K = ``n_periods``),
    "newton" corrects
    (phi0, wz0) together with the full-period Newton step [Phi(T) - I] d = -F (PHYSICS.md: the
    correct form of thesis eq. 53), "auto" picks "half" when it applies. With SRP the mirror
    symmetry is broken (PHYSICS.md sec. 6): ``free="phi0"`` (default) corrects (phi0, wz0);
    ``free="theta_sun0"`` keeps phi0 and corrects (Sun phase theta_sun0, wz0) instead (the returned
    solution's ``srp.sun.theta0`` is the phase found; d/d(phase) by central differences; the old
    spelling ``free="sun_phase"`` still works, with a DeprecationWarning). ``wz0``: the guess
    (default: the torque-free solution 1 + 2 pi turns / T). Raises ConvergenceError.
    """
    orbit = check_orbit(orbit)
    kz = check_kz(kz)
    if not isinstance(n, (int, np.integer)):
        raise ValueError(f"invalid argument `n`: must be an integer, got {n!r}")
    if kind not in ("periodic", "half-turn"):
        raise ValueError(f"invalid argument `kind`: must be 'periodic' or 'half-turn', got {kind!r}")
    if method not in ("auto", "half", "newton"):
        raise ValueError(f"invalid argument `method`: must be 'auto', 'half' or 'newton', got {method!r}")
    if not isinstance(n_periods, (int, np.integer)) or n_periods < 1:
        raise ValueError(f"invalid argument `n_periods`: must be an integer >= 1, got {n_periods!r}")
    if not math.isfinite(phi0):
        raise ValueError(f"invalid argument `phi0`: must be finite, got {phi0!r}")
    turns = n + (0.5 if kind == "half-turn" else 0.0)
    T = n_periods * orbit.period
    w = 1.0 + 2 * math.pi * turns / T if wz0 is None else float(wz0)
    if not math.isfinite(w):
        raise ValueError(f"invalid argument `wz0`: must be finite, got {wz0!r}")
    srp = check_srp(srp)
    if free == "sun_phase":
        warnings.warn("periodic_attitude(free='sun_phase') is deprecated; use free='theta_sun0'", DeprecationWarning, stacklevel=2)
        free = "theta_sun0"
    if free not in ("phi0", "theta_sun0"):
        raise ValueError(f"invalid argument `free`: must be 'phi0' or 'theta_sun0', got {free!r}")
    if free == "theta_sun0":
        if srp is None:
            raise ValueError("invalid argument `free`: 'theta_sun0' needs srp")
        return _solve_sun_phase(orbit, kz, n, kind, float(phi0), w, srp, n_periods, turns, tol, max_iter)
    symmetric = is_symmetric(orbit, phi0) and (srp is None or srp.eps == 0.0)
    if method == "auto":
        method = "half" if symmetric else "newton"
    if method == "half" and not symmetric:
        raise ValueError("invalid argument `method`: 'half' needs an x-symmetric orbit started on the x axis, phi0 a multiple of pi/2 and no SRP")
    forcing = orbit_forcing(orbit)
    p = float(phi0)
    it = 0
    res = math.inf
    for it in range(1, max_iter + 1):
        if method == "half":
            r = sweep(forcing, 0.5 * T, p, w, kz, stm=True, rtol=1e-13, atol=1e-13, srp=srp)
            g = r["phi_t"][0] - p - math.pi * turns
            d = r["stm"][0, 0, 1]
            res = abs(g)
            if res < tol:
                break
            if d == 0 or not math.isfinite(d):
                raise ConvergenceError(f"periodic attitude (half period): zero derivative at wz0 = {w}")
            step = -g / d
            w += float(np.clip(step, -0.5, 0.5))
        else:
            r = sweep(forcing, T, p, w, kz, stm=True, rtol=1e-13, atol=1e-13, srp=srp)
            F = np.array([r["phi_t"][0] - p - 2 * math.pi * turns, r["wz_t"][0] - w])
            res = float(np.max(np.abs(F)))
            if res < tol:
                break
            J = r["stm"][0] - np.eye(2)
            try:
                dx = np.linalg.solve(J, -F)
            except np.linalg.LinAlgError:
                raise ConvergenceError(f"periodic attitude: Phi(T) - I is singular at wz0 = {w} (trace 2: a fold)") from None
            scale = min(1.0, 0.5 / max(abs(dx[1]), 1e-300))
            p += float(dx[0]) * scale
            w += float(dx[1]) * scale
        if not (math.isfinite(w) and math.isfinite(p)):
            break
    else:
        raise ConvergenceError(f"periodic attitude (N = {n}, {kind}) did not converge after {max_iter} iterations (residual {res:.3e}, tolerance {tol:.1e})")
    if not math.isfinite(res) or res >= tol:
        raise ConvergenceError(f"periodic attitude (N = {n}, {kind}) diverged (residual {res:.3e})")
    dphi, dwz, m = _verify(orbit, kz, p, w, turns, n_periods, srp)
    return AttitudeSolution(orbit, kz, int(n), kind, p, w, float(dphi), float(dwz), m, it, srp, int(n_periods))


def _grid_for(T: float, lo: float, hi: float, n_grid: int | None) -> np.ndarray:
    if n_grid is None:
        # phi(T) moves by about T per unit wz0: 16 samples per pi of phi(T).
        n_grid = int(max(200, 16 * (hi - lo) * T / math.pi))
    return np.linspace(lo, hi, int(n_grid))


def candidates(phi_t, phi0, wz, level):
    """wz0 brackets where (phi(t) - phi0) / level crosses an integer; returns (k, wz_interp)."""
    u = (phi_t - phi0) / level
    out = []
    ok = np.isfinite(u)
    for i in range(len(u) - 1):
        if not (ok[i] and ok[i + 1]):
            continue
        a, b = u[i], u[i + 1]
        lo, hi = (a, b) if a <= b else (b, a)
        for k in range(math.ceil(lo), math.floor(hi) + 1):
            if a == b:
                continue
            w = wz[i] + (k - a) / (b - a) * (wz[i + 1] - wz[i])
            out.append((k, w))
    return out


def find_periodic_attitudes(
    orbit: PeriodicOrbit,
    *,
    kz: float,
    wz0_range: tuple[float, float],
    phi0: float = 0.0,
    kinds: Sequence[str] = ("periodic", "half-turn"),
    n_grid: int | None = None,
    n_periods: int = 1,
    srp=None,
) -> list[AttitudeSolution]:
    """Every periodic (and half-turn) attitude motion with inertial wz0 in ``wz0_range``.

    A grid scan by the engine brackets the candidates (crossings of phi(T/2) - phi0 through
    multiples of pi/2 for symmetric cases, of phi(T) - phi0 through multiples of pi otherwise);
    each is refined by :func:`periodic_attitude` and kept when it converges inside the window.
    Sorted by wz0.
    """
    orbit = check_orbit(orbit)
    kz = check_kz(kz)
    try:
        lo, hi = (float(v) for v in wz0_range)
    except (TypeError, ValueError):
        raise ValueError(f"invalid argument `wz0_range`: must be (lo, hi), got {wz0_range!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ValueError(f"invalid argument `wz0_range`: must be finite with lo < hi, got {wz0_range!r}")
    for k in kinds:
        if k not in ("periodic", "half-turn"):
            raise ValueError(f"invalid argument `kinds`: must be 'periodic' and/or 'half-turn', got {k!r}")
    srp = check_srp(srp)
    T = n_periods * orbit.period
    wz = _grid_for(T, lo, hi, n_grid)
    symmetric = is_symmetric(orbit, phi0) and (srp is None or srp.eps == 0.0)
    forcing = orbit_forcing(orbit)
    t_scan, level = (0.5 * T, 0.5 * math.pi) if symmetric else (T, math.pi)
    r = sweep(forcing, t_scan, phi0, wz, kz, srp=srp)
    found: list[AttitudeSolution] = []
    for k, w in candidates(r["phi_t"], phi0, wz, level):
        # symmetric: phi(T/2) - phi0 = k pi/2 -> turns = k/2; else phi(T) - phi0 = k pi -> turns = k/2
        kind = "periodic" if k % 2 == 0 else "half-turn"
        if kind not in kinds:
            continue
        n = k // 2
        try:
            sol = periodic_attitude(orbit, kz=kz, n=n, phi0=phi0, wz0=w, kind=kind, n_periods=n_periods, srp=srp)
        except ConvergenceError:
            continue
        if not (lo <= sol.wz0 <= hi) or sol.residual > 1e-8:
            continue
        if any(s.n == sol.n and s.kind == sol.kind and abs(s.wz0 - sol.wz0) < 1e-8 for s in found):
            continue
        found.append(sol)
    return sorted(found, key=lambda s: s.wz0)
