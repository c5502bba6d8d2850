"""Families of symmetric periodic attitude motions continued through folds, in Kz for one orbit
or in x0 across an orbit family (thesis sec. 3.3)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._errors import ConvergenceError
from ..orbits.families import OrbitFamily
from ..orbits.periodic import PeriodicOrbit
from .solutions import check_kz, check_orbit, is_symmetric, orbit_forcing, sweep

__all__ = ["AttitudeFamily", "attitude_family"]


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
    kz = check_kz(kz)
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
            r = sweep(f, 0.5 * o.period, 0.0, w, kz, stm=True, rtol=1e-13, atol=1e-13)
            return r["phi_t"][0] - math.pi * turns, r["stm"][0, 0, 1], o

        def g_p(p, w):
            h = 1e-6
            gp = []
            for q in (p + h, p - h):
                oq, fq = orbit_at(q)
                gp.append(sweep(fq, 0.5 * oq.period, 0.0, w, kz, rtol=1e-13, atol=1e-13)["phi_t"][0])
            return (gp[0] - gp[1]) / (2 * h)
    elif isinstance(orbits, PeriodicOrbit):
        orbit = check_orbit(orbits)
        if not is_symmetric(orbit, 0.0):
            raise ValueError("invalid argument `orbits`: attitude families need an x-symmetric orbit started on the x axis")
        name = "kz"
        lo, hi = parameter_range or (-1.0, 1.0)
        p0 = kz if start is None else float(start)
        f = orbit_forcing(orbit)

        def g_value(p, w):
            r = sweep(f, 0.5 * orbit.period, 0.0, w, p, stm=True, rtol=1e-13, atol=1e-13)
            return r["phi_t"][0] - math.pi * turns, r["stm"][0, 0, 1], orbit

        def g_p(p, w):
            h = 1e-6
            a = sweep(f, 0.5 * orbit.period, 0.0, w, min(p + h, 1.0), rtol=1e-13, atol=1e-13)["phi_t"][0]
            b = sweep(f, 0.5 * orbit.period, 0.0, w, max(p - h, -1.0), rtol=1e-13, atol=1e-13)["phi_t"][0]
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
        r = sweep(f_, o.period, 0.0, w, kz if name == "x0" else p, stm=True, rtol=1e-13, atol=1e-13)
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
