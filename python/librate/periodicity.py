"""Periodic orbit-attitude solutions and periodicity maps (thesis sec. 3.3, PHYSICS.md sec. 5).

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
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from . import _core
from ._errors import ConvergenceError
from .families import OrbitFamily
from .orbits import PeriodicOrbit

__all__ = ["AttitudeSolution", "AttitudeFamily", "attitude_family", "SrpContinuation", "continue_srp", "periodic_attitude", "find_periodic_attitudes", "periodicity_map", "orbit_forcing", "zero_contours"]

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


def _sweep(forcing, t_final, phi0, wz0, kz, *, stm=False, rtol=MAP_RTOL, atol=MAP_ATOL, chunk=64, threads=None, srp=None, eps=None):
    """The engine over broadcast (phi0, wz0, kz[, eps]) arrays; ``srp`` a FlatPlateSRP (its eps
    overridden per case by ``eps`` when given)."""
    n = np.broadcast(np.asarray(phi0), np.asarray(wz0), np.asarray(kz), np.asarray(0.0 if eps is None else eps)).shape
    flat = lambda a: np.ascontiguousarray(np.broadcast_to(np.asarray(a, dtype=np.float64), n)).ravel()  # noqa: E731
    p, w, k = flat(phi0), flat(wz0), flat(kz)
    extra = {}
    if srp is not None:
        extra = dict(eps=flat(srp.eps if eps is None else eps), cs=flat(srp.cs), cd=flat(srp.cd), theta_sun0=flat(srp.sun.theta0))
    return _core.map_sweep(forcing, float(t_final), p, w, k, rtol=float(rtol), atol=float(atol), max_steps=200_000,
                           stm=bool(stm), chunk=int(chunk), threads=threads, **extra)


def _check_orbit(orbit) -> PeriodicOrbit:
    if not isinstance(orbit, PeriodicOrbit):
        raise ValueError(f"invalid argument `orbit`: must be a librate.PeriodicOrbit, got {type(orbit).__name__}")
    if orbit.state0[2] != 0.0 or orbit.state0[5] != 0.0:
        raise ValueError("invalid argument `orbit`: the planar attitude model needs a planar orbit (z = zd = 0)")
    return orbit


def _check_kz(kz) -> float:
    if not (isinstance(kz, (int, float, np.floating, np.integer)) and math.isfinite(kz) and -1 <= kz <= 1):
        raise ValueError(f"invalid argument `kz`: must be a number in [-1, 1], got {kz!r}")
    return float(kz)


def _symmetric(orbit: PeriodicOrbit, phi0: float) -> bool:
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
        from .attitude import RigidBody, propagate_attitude

        kwargs.setdefault("rtol", 1e-13)
        kwargs.setdefault("atol", 1e-13)
        return propagate_attitude(self.orbit.system, self.orbit.state0, (self.phi0, self.wz0), RigidBody.from_kz(self.kz),
                                  n_periods * self.orbit.period, planar=True, srp=self.srp, **kwargs)


def _solve_sun_phase(orbit, kz, n, kind, phi0, w, srp, n_periods, turns, tol, max_iter):
    """Newton on (Sun phase, wz0) with phi0 fixed."""
    from .srp import FlatPlateSRP, SunModel

    forcing = orbit_forcing(orbit)
    T = n_periods * orbit.period
    th = float(srp.sun.theta0)

    def plate(theta):
        return FlatPlateSRP(srp.eps, srp.cs, srp.cd, SunModel(theta0=theta, pressure=srp.sun.pressure))

    def F(theta, wz, stm=False):
        r = _sweep(forcing, T, phi0, wz, kz, stm=stm, rtol=1e-13, atol=1e-13, srp=plate(theta))
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


def _check_srp(srp):
    if srp is None:
        return None
    from .srp import FlatPlateSRP

    if not isinstance(srp, FlatPlateSRP):
        raise ValueError(f"invalid argument `srp`: must be a librate.FlatPlateSRP or None, got {srp!r}")
    return srp


def _verify(orbit, kz, phi0, wz0, turns, n_periods, srp=None):
    """Independent re-propagation (scalar planar model with the orbit integrated alongside, at
    rtol = atol = 1e-14): residuals and the 2x2 monodromy."""
    from .attitude import RigidBody, propagate_attitude

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
    ``free="sun_phase"`` keeps phi0 and corrects (Sun phase, wz0) instead (the returned
    solution's ``srp.sun.theta0`` is the phase found; d/d(phase) by central differences). ``wz0``: the guess
    (default: the torque-free solution 1 + 2 pi turns / T). Raises ConvergenceError.
    """
    orbit = _check_orbit(orbit)
    kz = _check_kz(kz)
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
    srp = _check_srp(srp)
    if free not in ("phi0", "sun_phase"):
        raise ValueError(f"invalid argument `free`: must be 'phi0' or 'sun_phase', got {free!r}")
    if free == "sun_phase":
        if srp is None:
            raise ValueError("invalid argument `free`: 'sun_phase' needs srp")
        return _solve_sun_phase(orbit, kz, n, kind, float(phi0), w, srp, n_periods, turns, tol, max_iter)
    symmetric = _symmetric(orbit, phi0) and (srp is None or srp.eps == 0.0)
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
            r = _sweep(forcing, 0.5 * T, p, w, kz, stm=True, rtol=1e-13, atol=1e-13, srp=srp)
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
            r = _sweep(forcing, T, p, w, kz, stm=True, rtol=1e-13, atol=1e-13, srp=srp)
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


def _candidates(phi_t, phi0, wz, level):
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
    orbit = _check_orbit(orbit)
    kz = _check_kz(kz)
    try:
        lo, hi = (float(v) for v in wz0_range)
    except (TypeError, ValueError):
        raise ValueError(f"invalid argument `wz0_range`: must be (lo, hi), got {wz0_range!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ValueError(f"invalid argument `wz0_range`: must be finite with lo < hi, got {wz0_range!r}")
    for k in kinds:
        if k not in ("periodic", "half-turn"):
            raise ValueError(f"invalid argument `kinds`: must be 'periodic' and/or 'half-turn', got {k!r}")
    srp = _check_srp(srp)
    T = n_periods * orbit.period
    wz = _grid_for(T, lo, hi, n_grid)
    symmetric = _symmetric(orbit, phi0) and (srp is None or srp.eps == 0.0)
    forcing = orbit_forcing(orbit)
    t_scan, level = (0.5 * T, 0.5 * math.pi) if symmetric else (T, math.pi)
    r = _sweep(forcing, t_scan, phi0, wz, kz, srp=srp)
    found: list[AttitudeSolution] = []
    for k, w in _candidates(r["phi_t"], phi0, wz, level):
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


def _orbits_of(orbits) -> tuple[list[PeriodicOrbit], OrbitFamily | None]:
    if isinstance(orbits, OrbitFamily):
        return list(orbits), orbits
    if isinstance(orbits, PeriodicOrbit):
        return [orbits], None
    try:
        lst = list(orbits)
    except TypeError:
        raise ValueError(f"invalid argument `orbits`: must be an OrbitFamily, a PeriodicOrbit or a list of them, got {type(orbits).__name__}") from None
    if not lst or not all(isinstance(o, PeriodicOrbit) for o in lst):
        raise ValueError("invalid argument `orbits`: must be a non-empty list of librate.PeriodicOrbit")
    return lst, None


def periodicity_map(
    orbits,
    *,
    kz,
    wz0,
    phi0: float = 0.0,
    n_periods: int = 1,
    solve: bool = True,
    progress: Callable[[int, int], None] | None = None,
    rtol: float = MAP_RTOL,
    atol: float = MAP_ATOL,
    chunk: int = 64,
    threads: int | None = None,
    srp=None,
):
    """Residual grids over (orbit, Kz, wz0) and the periodic solutions they contain.

    ``orbits``: an :class:`OrbitFamily`, a list of planar :class:`PeriodicOrbit` or one orbit;
    ``kz``: one value or an array; ``wz0``: array of inertial initial rates. Returns an xarray
    Dataset with ``dwz`` = wz(T) - wz0, ``dphi`` = phi(T) - phi0 wrapped to (-pi, pi] and the
    unwrapped ``phi_T`` over dims (orbit, kz, wz0), coordinates with units (x0, period,
    period_days per orbit; phidot0 = wz0 - 1), and, with ``solve``, the refined solutions along a
    ``solution`` dimension. Work is done one orbit at a time (``progress(done, total)`` after
    each); on KeyboardInterrupt the finished orbits are kept and returned, with
    ``attrs["complete"] = 0``. Results are bit-identical for any ``chunk`` and ``threads``.
    ``srp``: a :class:`librate.FlatPlateSRP` (with ``n_periods`` = K for Sun-resonant orbits,
    T = Ts / K); its parameters are stored as attributes. A list of plates (e.g. several eps or
    Cs) adds an ``srp`` dimension (orbit, srp, kz, wz0) with their parameters as coordinates. With SRP the mirror symmetry is broken
    and solutions are refined in (phi0, wz0) together (PHYSICS.md sec. 6).
    """


    olist, family = _orbits_of(orbits)
    for o in olist:
        _check_orbit(o)
    if isinstance(srp, (list, tuple)):
        if not srp:
            raise ValueError("invalid argument `srp`: an empty list of plates")
        plates = [_check_srp(p) for p in srp]
        maps = [periodicity_map(olist if family is None else family, kz=kz, wz0=wz0, phi0=phi0, n_periods=n_periods, solve=solve,
                                progress=progress, rtol=rtol, atol=atol, chunk=chunk, threads=threads, srp=p) for p in plates]
        return _stack_srp(maps, plates)
    srp = _check_srp(srp)
    kzs, wz = _map_grid(kz, wz0, n_periods)
    no, nk, nw = len(olist), kzs.size, wz.size
    dwz = np.full((no, nk, nw), np.nan)
    dphi = np.full((no, nk, nw), np.nan)
    phi_t = np.full((no, nk, nw), np.nan)
    status = np.full((no, nk, nw), 255, dtype=np.uint8)
    done = np.zeros(no, dtype=bool)
    sols: list[tuple[int, AttitudeSolution]] = []
    kz_grid, wz_grid = np.meshgrid(kzs, wz, indexing="ij")
    complete = True
    try:
        for i, o in enumerate(olist):
            r = _sweep(orbit_forcing(o), n_periods * o.period, phi0, wz_grid, kz_grid, rtol=rtol, atol=atol, chunk=chunk, threads=threads, srp=srp)
            dwz[i], dphi[i], phi_t[i] = (r[k].reshape(nk, nw) for k in ("dwz", "dphi", "phi_t"))
            status[i] = r["status"].reshape(nk, nw)
            if solve:
                for j, k in enumerate(kzs):
                    sols += [(i, s) for s in _solutions_from_row(o, float(k), phi0, wz, phi_t[i, j], n_periods, srp)]
            done[i] = True
            if progress is not None:
                progress(i + 1, no)
    except KeyboardInterrupt:
        complete = False
        warnings.warn(f"periodicity_map interrupted: {int(done.sum())} of {no} orbits finished and kept", stacklevel=2)
    grid = {"dwz": dwz, "dphi": dphi, "phi_T": phi_t, "status": status}
    ds = _map_dataset(olist, family, kzs, wz, grid, done, phi0=phi0, n_periods=n_periods, rtol=rtol, atol=atol, srp=srp, complete=complete)
    if solve:
        ds = ds.merge(_solutions_dataset(sols))
    return ds



def _map_grid(kz, wz0, n_periods):
    """Validated Kz values and (strictly increasing) inertial rates of a map."""
    kzs = np.atleast_1d(np.asarray(kz, dtype=np.float64))
    if kzs.ndim != 1 or kzs.size == 0 or not np.all(np.isfinite(kzs)) or np.any(np.abs(kzs) > 1):
        raise ValueError(f"invalid argument `kz`: values must be finite and in [-1, 1], got {kz!r}")
    wz = np.asarray(wz0, dtype=np.float64).ravel()
    if wz.size < 2 or not np.all(np.isfinite(wz)) or np.any(np.diff(wz) <= 0):
        raise ValueError("invalid argument `wz0`: must be a finite, strictly increasing array of at least 2 rates")
    if not isinstance(n_periods, (int, np.integer)) or n_periods < 1:
        raise ValueError(f"invalid argument `n_periods`: must be an integer >= 1, got {n_periods!r}")
    return kzs, wz


def _map_coords(olist, kzs, wz) -> dict:
    """name -> (dimension, values, attributes) of a map's coordinates."""
    return {
        "orbit": ("orbit", np.arange(len(olist)), {}),
        "x0": ("orbit", np.array([o.x0 for o in olist]), {"units": "LU"}),
        "period": ("orbit", np.array([o.period for o in olist]), {"units": "TU"}),
        "period_days": ("orbit", np.array([o.period_days for o in olist]), {"units": "d"}),
        "kz": ("kz", kzs, {"long_name": "(Iy - Ix) / Iz"}),
        "wz0": ("wz0", wz, {"units": "1/TU", "long_name": "initial inertial angular rate"}),
        "phidot0": ("wz0", wz - 1.0, {"units": "1/TU", "long_name": "initial rate relative to the synodic frame"}),
    }


def _map_dataset(olist, family, kzs, wz, grid, done, *, phi0, n_periods, rtol, atol, srp, complete, attrs=None):
    """The map's Dataset: residual grids over (orbit, kz, wz0), coordinates with units and the
    parameters as attributes (shared by periodicity_map and run_map)."""
    import xarray as xr

    from . import __version__

    dims = ("orbit", "kz", "wz0")
    return xr.Dataset(
        {
            "dwz": (dims, grid["dwz"], {"units": "1/TU", "long_name": "wz(T) - wz(0)"}),
            "dphi": (dims, grid["dphi"], {"units": "rad", "long_name": "phi(T) - phi0 wrapped to (-pi, pi]"}),
            "phi_T": (dims, grid["phi_T"], {"units": "rad", "long_name": "phi(T), unwrapped"}),
            "status": (dims, grid["status"], {"flag_values": "0 ok, 1 max steps, 2 failed, 255 not computed"}),
            "computed": ("orbit", np.asarray(done, dtype=bool).copy()),
        },
        coords=_map_coords(olist, kzs, wz),
        attrs={
            "title": "librate attitude periodicity map",
            "phi0": float(phi0),
            "n_periods": int(n_periods),
            "rtol": float(rtol),
            "atol": float(atol),
            "complete": int(complete),
            "mu": olist[0].system.mu,
            "lu_km": olist[0].system.lu_km,
            "tu_s": olist[0].system.tu_s,
            "system_name": olist[0].system.name,
            "family": family.kind if family is not None else "",
            "librate_version": __version__,
            "srp_eps": float(srp.eps) if srp is not None else 0.0,
            "srp_cs": float(srp.cs) if srp is not None else 0.0,
            "srp_cd": float(srp.cd) if srp is not None else 0.0,
            "sun_theta0": float(srp.sun.theta0) if srp is not None else 0.0,
            **(attrs or {}),
        },
    )

def _stack_srp(maps, plates):
    """Maps for several plates stacked along an ``srp`` dimension (coordinates eps, cs, cd and
    the Sun phase); solutions gain ``sol_srp``."""
    import xarray as xr

    grid_vars = ["dwz", "dphi", "phi_T", "status"]
    out = xr.concat([m[grid_vars + ["computed"]] for m in maps], dim="srp")
    out = out.transpose("orbit", "srp", "kz", "wz0")
    out = out.assign_coords(
        srp=np.arange(len(plates)),
        srp_eps=("srp", np.array([p.eps for p in plates])),
        srp_cs=("srp", np.array([p.cs for p in plates])),
        srp_cd=("srp", np.array([p.cd for p in plates])),
        srp_theta0=("srp", np.array([p.sun.theta0 for p in plates])),
    )
    out["computed"] = out["computed"].all("srp")
    out.attrs = {k: v for k, v in maps[0].attrs.items() if not k.startswith("srp_") and k != "sun_theta0"}
    out.attrs["complete"] = int(all(m.attrs["complete"] for m in maps))
    if "solution" in maps[0].dims:
        sols = []
        for i, m in enumerate(maps):
            if m.sizes.get("solution", 0):
                part = m[[v for v in m.data_vars if v.startswith("sol_")]]
                sols.append(part.assign(sol_srp=("solution", np.full(m.sizes["solution"], i))))
        if sols:
            out = out.merge(xr.concat(sols, dim="solution"))
    return out


def _solutions_from_row(orbit, kz, phi0, wz, phi_t_row, n_periods, srp=None) -> list[AttitudeSolution]:
    """Candidates from one full-period row (phi(T) - phi0 through multiples of pi), refined."""
    out: list[AttitudeSolution] = []
    for k, w in _candidates(phi_t_row, phi0, wz, math.pi):
        kind = "periodic" if k % 2 == 0 else "half-turn"
        n = k // 2
        try:
            sol = periodic_attitude(orbit, kz=kz, n=n, phi0=phi0, wz0=w, kind=kind, n_periods=n_periods, srp=srp)
        except ConvergenceError:
            continue
        if not (wz[0] <= sol.wz0 <= wz[-1]) or sol.residual > 1e-8:
            continue
        if any(s.n == sol.n and s.kind == sol.kind and abs(s.wz0 - sol.wz0) < 1e-8 for s in out):
            continue
        out.append(sol)
    return out


def _solutions_dataset(sols):
    import xarray as xr

    idx = np.array([i for i, _ in sols], dtype=np.int64)
    s = [x for _, x in sols]
    return xr.Dataset(
        {
            "sol_orbit": ("solution", idx),
            "sol_kz": ("solution", np.array([x.kz for x in s], dtype=float)),
            "sol_wz0": ("solution", np.array([x.wz0 for x in s], dtype=float), {"units": "1/TU"}),
            "sol_phidot0": ("solution", np.array([x.phidot0 for x in s], dtype=float), {"units": "1/TU"}),
            "sol_phi0": ("solution", np.array([x.phi0 for x in s], dtype=float), {"units": "rad"}),
            "sol_n": ("solution", np.array([x.n for x in s], dtype=np.int64)),
            "sol_kind": ("solution", np.array([x.kind for x in s], dtype="<U9")),
            "sol_residual": ("solution", np.array([x.residual for x in s], dtype=float)),
            "sol_trace": ("solution", np.array([x.trace for x in s], dtype=float)),
            "sol_stable": ("solution", np.array([x.stable for x in s], dtype=bool)),
        }
    )


def zero_contours(ds, var: str = "dwz", kz_index: int = 0) -> np.ndarray:
    """Points (orbit x0, wz0) where ``var`` crosses zero along wz0, for each orbit row (linear
    interpolation; for ``dphi`` the wrap jumps at +-pi are not crossings). (m, 2) array."""
    if var not in ("dwz", "dphi"):
        raise ValueError(f"invalid argument `var`: must be 'dwz' or 'dphi', got {var!r}")
    a = ds[var].values[:, kz_index, :]
    wz = ds["wz0"].values
    x0 = ds["x0"].values
    pts = []
    for i in range(a.shape[0]):
        row = a[i]
        for j in range(len(row) - 1):
            u, v = row[j], row[j + 1]
            if not (np.isfinite(u) and np.isfinite(v)) or (u > 0) == (v > 0) or u == v:
                continue
            if var == "dphi" and abs(u - v) > math.pi:
                continue
            pts.append((x0[i], wz[j] + u / (u - v) * (wz[j + 1] - wz[j])))
    return np.array(pts).reshape(-1, 2)


# --- solution families -------------------------------------------------------------------------
@dataclass
class AttitudeFamily:
    """A family of symmetric periodic attitude motions continued along a parameter: ``"kz"``
    for one orbit, or ``"x0"`` across an orbit family. Arrays over the members: ``parameter``
    values, ``wz0`` (inertial), ``trace`` of the 2x2 monodromy, ``stable``; ``folds`` lists the
    turning points (parameter, wz0) where the curve turns back; ``end_reason`` why it stopped."""

    parameter_name: str
    parameter: np.ndarray
    wz0: np.ndarray
    trace: np.ndarray
    n: int
    kind: str
    kz: float | None
    folds: list[dict]
    end_reason: str

    @property
    def phidot0(self) -> np.ndarray:
        return self.wz0 - 1.0

    @property
    def stable(self) -> np.ndarray:
        return np.abs(self.trace) < 2.0

    def __len__(self) -> int:
        return len(self.parameter)


def attitude_family(
    orbits,
    *,
    kz: float,
    n: int,
    kind: str = "periodic",
    start: float | None = None,
    wz0: float | None = None,
    parameter_range: tuple[float, float] | None = None,
    ds: float = 0.02,
    ds_min: float = 1e-6,
    ds_max: float = 0.05,
    max_points: int = 400,
    direction: int = -1,
) -> AttitudeFamily:
    """Continue the symmetric periodic attitude motion with ``n`` turns (``kind``) through folds.

    ``orbits``: an :class:`OrbitFamily` (the parameter is the orbit's x0; each point corrects the
    member at that x0 and tabulates its forcing) or one :class:`PeriodicOrbit` (the parameter
    is Kz, from ``kz``). The curve G(p, wz0) = phi(T/2) - pi * turns = 0 (phi0 = 0) is followed
    by pseudo-arclength continuation in (p, wz0): predictor along the tangent, corrector with
    the arclength condition (dG/dwz0 from the engine's STM at every iteration, dG/dp by central
    differences once per accepted point: a chord method in p); adaptive steps. ``start`` (x0, or Kz) and ``wz0`` pick the first solution
    (default: the family's first member / ``kz``, and the torque-free rate); ``direction`` the
    initial sense in p. Folds (dp/ds changing sign) are recorded and the curve followed past them.
    """
    turns = n + (0.5 if kind == "half-turn" else 0.0)
    if kind not in ("periodic", "half-turn"):
        raise ValueError(f"invalid argument `kind`: must be 'periodic' or 'half-turn', got {kind!r}")
    if not isinstance(n, (int, np.integer)):
        raise ValueError(f"invalid argument `n`: must be an integer, got {n!r}")
    if direction not in (-1, 1):
        raise ValueError(f"invalid argument `direction`: must be -1 or +1, got {direction!r}")
    kz = _check_kz(kz)
    if isinstance(orbits, OrbitFamily):
        if orbits.spatial:
            raise ValueError("invalid argument `orbits`: attitude families need a planar orbit family")
        name = "x0"
        lo, hi = parameter_range or (float(np.min(orbits.x0)), float(np.max(orbits.x0)))
        p0 = float(orbits.x0[0] if start is None else start)
        cache: dict[float, tuple] = {}

        def orbit_at(p):
            if p not in cache:
                if len(cache) > 64:
                    cache.clear()
                o = orbits.member(x0=p)
                cache[p] = (o, orbit_forcing(o))
            return cache[p]

        def g_value(p, w):
            o, f = orbit_at(p)
            r = _sweep(f, 0.5 * o.period, 0.0, w, kz, stm=True, rtol=1e-13, atol=1e-13)
            return r["phi_t"][0] - math.pi * turns, r["stm"][0, 0, 1], o

        def g_p(p, w):
            h = 1e-6
            gp = []
            for q in (p + h, p - h):
                oq, fq = orbit_at(q)
                gp.append(_sweep(fq, 0.5 * oq.period, 0.0, w, kz, rtol=1e-13, atol=1e-13)["phi_t"][0])
            return (gp[0] - gp[1]) / (2 * h)
    elif isinstance(orbits, PeriodicOrbit):
        orbit = _check_orbit(orbits)
        if not _symmetric(orbit, 0.0):
            raise ValueError("invalid argument `orbits`: attitude families need an x-symmetric orbit started on the x axis")
        name = "kz"
        lo, hi = parameter_range or (-1.0, 1.0)
        p0 = kz if start is None else float(start)
        f = orbit_forcing(orbit)

        def g_value(p, w):
            r = _sweep(f, 0.5 * orbit.period, 0.0, w, p, stm=True, rtol=1e-13, atol=1e-13)
            return r["phi_t"][0] - math.pi * turns, r["stm"][0, 0, 1], orbit

        def g_p(p, w):
            h = 1e-6
            a = _sweep(f, 0.5 * orbit.period, 0.0, w, min(p + h, 1.0), rtol=1e-13, atol=1e-13)["phi_t"][0]
            b = _sweep(f, 0.5 * orbit.period, 0.0, w, max(p - h, -1.0), rtol=1e-13, atol=1e-13)["phi_t"][0]
            return (a - b) / (min(p + h, 1.0) - max(p - h, -1.0))
    else:
        raise ValueError(f"invalid argument `orbits`: must be an OrbitFamily or a PeriodicOrbit, got {type(orbits).__name__}")
    if not (lo <= p0 <= hi):
        raise ValueError(f"invalid argument `start`: {p0} is outside the parameter range [{lo}, {hi}]")

    # First point: solve G(p0, w) = 0 in w.
    o0 = g_value(p0, 0.0)[2]
    w = 1.0 + 2 * math.pi * turns / o0.period if wz0 is None else float(wz0)
    for _ in range(50):
        g, gw, _ = g_value(p0, w)
        if abs(g) < 1e-12:
            break
        w -= float(np.clip(g / gw, -0.5, 0.5))
    else:
        raise ConvergenceError(f"attitude family (N = {n}, {kind}): no starting solution at {name} = {p0}")
    ps, ws, traces, folds = [p0], [w], [], []

    def trace_at(p, w):
        o = g_value(p, w)[2]
        f_ = orbit_forcing(o)
        r = _sweep(f_, o.period, 0.0, w, kz if name == "x0" else p, stm=True, rtol=1e-13, atol=1e-13)
        return float(np.trace(r["stm"][0]))

    traces.append(trace_at(p0, w))
    g, gw, _ = g_value(p0, w)
    gp = g_p(p0, w)
    tang = np.array([-gw, gp])
    tang /= np.linalg.norm(tang)
    if np.sign(tang[0]) != direction and tang[0] != 0:
        tang = -tang
    reason = f"completed: max_points = {max_points} reached"
    while len(ps) < max_points:
        ok = False
        while not ok:
            p, w = ps[-1] + ds * tang[0], ws[-1] + ds * tang[1]
            for _ in range(12):
                if not (lo - 1e-12 <= p <= hi + 1e-12):
                    break
                try:
                    g, gw, _ = g_value(p, w)  # chord method: dG/dp from the last accepted point
                except (ValueError, ConvergenceError):
                    break
                arc = tang[0] * (p - ps[-1]) + tang[1] * (w - ws[-1]) - ds
                if abs(g) < 1e-11 and abs(arc) < 1e-12:
                    ok = True
                    break
                jm = np.array([[gp, gw], [tang[0], tang[1]]])
                try:
                    d = np.linalg.solve(jm, [-g, -arc])
                except np.linalg.LinAlgError:
                    break
                p, w = p + d[0], w + d[1]
            if not ok:
                if not (lo - 1e-12 <= p <= hi + 1e-12) and ds <= 2 * ds_min:
                    break
                ds *= 0.5
                if ds < ds_min:
                    break
        if not ok:
            end = "parameter range end" if not (lo <= ps[-1] + ds_max * tang[0] <= hi) else "step floor"
            reason = f"{end}: stopped at {name} = {ps[-1]:.10g}"
            break
        gp = g_p(p, w)
        new_t = np.array([-gw, gp])
        new_t /= np.linalg.norm(new_t)
        if np.dot(new_t, tang) < 0:
            new_t = -new_t
        if np.sign(new_t[0]) != np.sign(tang[0]) and tang[0] != 0:
            folds.append({name: float(p), "wz0": float(w)})
        tang = new_t
        ps.append(float(p))
        ws.append(float(w))
        traces.append(trace_at(p, w))
        ds = min(ds * 1.3, ds_max)
    return AttitudeFamily(name, np.array(ps), np.array(ws), np.array(traces), int(n), kind, kz if name == "x0" else None, folds, reason)


# --- continuation in the SRP amplitude ---------------------------------------------------------
@dataclass
class SrpContinuation:
    """Solutions continued in the flat-plate SRP amplitude ``eps`` from a starting solution.
    ``reached``: the target eps was reached; otherwise ``fold`` gives where the branch turns
    back ({"eps", "trace"}: the 2x2 monodromy's trace passes 2 there, where Phi - I is singular)
    or ``end_reason`` why the continuation stopped. No point of another branch is ever returned."""

    solutions: list[AttitudeSolution]
    eps: np.ndarray
    reached: bool
    fold: dict | None
    end_reason: str


def continue_srp(solution: AttitudeSolution, srp, *, steps: int = 10, min_step: float = 1e-7) -> SrpContinuation:
    """Continue ``solution`` (gravity-only, or with SRP) to the plate ``srp`` (its eps is the
    target; cs, cd and the Sun phase are kept along the way) by natural continuation in eps:
    linear extrapolation of (phi0, wz0), Newton in (phi0, wz0) with [Phi(KT) - I], steps halved on
    failure or on a jump (the corrector landing farther than a quarter of the predicted step from
    the prediction), and the fold detected where the monodromy's trace crosses 2
    (det(Phi - I) = 2 - trace changes sign) or where the step collapses next to trace 2."""
    srp = _check_srp(srp)
    if srp is None:
        raise ValueError("invalid argument `srp`: the target plate is required")
    if not isinstance(solution, AttitudeSolution):
        raise ValueError("invalid argument `solution`: must be a librate.AttitudeSolution")
    if not (isinstance(steps, int) and steps >= 1):
        raise ValueError(f"invalid argument `steps`: must be an integer >= 1, got {steps!r}")
    e0 = 0.0 if solution.srp is None else float(solution.srp.eps)
    target = float(srp.eps)
    sols, eps = [solution], [e0]
    h_nominal = (target - e0) / steps
    h = h_nominal / 16.0  # a small first step: there is no trend yet to guard against jumps
    fold = None
    reason = "reached the target eps"
    while eps[-1] != target:
        e = target if abs(target - eps[-1]) <= abs(h) * (1 + 1e-9) else eps[-1] + h
        a = sols[-1]
        if len(sols) >= 2:
            b = sols[-2]
            r = (e - eps[-1]) / (eps[-1] - eps[-2])
            guess = (a.phi0 + r * (a.phi0 - b.phi0), a.wz0 + r * (a.wz0 - b.wz0))
        else:
            guess = (a.phi0, a.wz0)
        ok = True
        try:
            s = periodic_attitude(a.orbit, kz=a.kz, n=a.n, kind=a.kind, phi0=guess[0], wz0=guess[1], n_periods=a.n_periods,
                                  srp=srp.with_eps(e), method="newton")
        except ConvergenceError:
            ok = False
        if ok:
            # On a smooth branch the corrector lands within a small fraction of the predicted
            # step (the predictor's error is second order in the step); a landing farther off is
            # another branch, or the fold coming up: shorten the step instead.
            jump = math.hypot(s.wz0 - guess[1], s.phi0 - guess[0])
            if len(sols) >= 2:
                ok = jump <= 0.25 * math.hypot(guess[1] - a.wz0, guess[0] - a.phi0) + 1e-9
            else:
                ok = jump <= 1e-2
            ok = ok and s.residual <= 1e-8
        crossing = ok and (2.0 - a.trace) * (2.0 - s.trace) < 0
        if ok and not crossing:
            sols.append(s)
            eps.append(e)
            h = float(np.sign(h_nominal) * min(abs(h) * 1.5, abs(h_nominal)))
            continue
        if abs(h) * 0.5 < min_step:
            if crossing:
                w = (2.0 - a.trace) / (s.trace - a.trace)
                fold = {"eps": eps[-1] + w * (e - eps[-1]), "trace": 2.0}
                reason = f"fold: the monodromy trace crosses 2 at eps = {fold['eps']:.8g} (Phi - I singular)"
            else:
                fold = {"eps": eps[-1], "trace": a.trace}
                reason = f"fold or end of the branch near eps = {eps[-1]:.8g} (trace {a.trace:.6g}; step below {min_step:g})"
            break
        h *= 0.5  # failure, jump, or a trace crossing to pin down: shorten the step
    return SrpContinuation(sols, np.array(eps), eps[-1] == target, fold, reason)
