"""Flexibility and periodic attitude motion (docs/physics.md, flexible spacecraft): what the appendages' flexibility
does to a rigid periodic solution (:func:`flexible_periodic`, first order in closed form or the
coupled model re-solved), and the coupled response against the structural frequency
(:func:`frequency_scan`). The flexible models themselves are in :mod:`librate.attitude.flexible`."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .. import _core
from .._checks import as_float_array, as_size
from ..attitude.flexible import FlexibleBody, flexible_run_inputs, quasi_static
from ..attitude.propagate import propagate_attitude
from ..orbits.propagation import integration_options
from ..orbits.system import System
from ..solving.continuation import Constraint, CorrectionFailed, Point, StepRules, natural
from .solutions import AttitudeSolution

__all__ = ["FlexiblePeriodic", "FrequencyScan", "flexible_periodic", "frequency_scan"]


@dataclass(frozen=True)
class FlexiblePeriodic:
    """Result of :func:`flexible_periodic`: what flexibility does to a rigid periodic solution.

    First order (closed form, always computed): ``drift`` = (dphi(T), dwz(T)), the flexible
    motion's departure from the rigid one after one period when started from the rigid initial
    state on the quasi-static manifold; ``max_dphi``, ``max_dwz`` over the period; ``shift`` =
    (dphi0, dwz0) = -(M - I)^{-1} drift, the first-order move of the periodic solution (M the
    rigid monodromy).

    Full model (``method="full"``): ``full_drift`` from a re-propagation of the coupled model over
    one period, ``full_max_dphi``, ``full_max_dwz``; when re-solved, the periodic solution of the
    coupled model (``phi0``, ``wz0``, ``q0`` (m), ``qdot0`` (m/TU)) by the Rust corrector (globalised
    Newton on all 2 + 2n initial values, finite-difference Jacobian integrated in parallel), its
    ``residual`` (scaled: rad, rad/TU and q relative to the quasi-static amplitude),
    ``iterations``, why it stopped (``reason``, "converged" or the failure), ``multipliers``
    (eigenvalues of the coupled monodromy) and ``full_shift`` = (phi0 - phi0_rigid, wz0 - wz0_rigid).
    A body whose lowest frequency is not well above the attitude and orbital rates is re-solved by
    continuation in the compliance 1/f^2 from a copy stiffened by ``start_factor`` (:class:`CompliancePath`,
    the shared continuation driver; 1: corrected directly from the quasi-static state).
    """

    solution: object
    body: FlexibleBody
    method: str
    drift: np.ndarray
    max_dphi: float
    max_dwz: float
    shift: np.ndarray
    full_drift: np.ndarray | None = None
    full_max_dphi: float | None = None
    full_max_dwz: float | None = None
    phi0: float | None = None
    wz0: float | None = None
    q0: np.ndarray | None = None
    qdot0: np.ndarray | None = None
    residual: float | None = None
    iterations: int | None = None
    multipliers: np.ndarray | None = None
    reason: str | None = None
    start_factor: float = 1.0

    @property
    def full_shift(self) -> np.ndarray | None:
        if self.phi0 is None:
            return None
        r = self.solution
        return np.array([self.phi0 - (r.phi0 - self.body.principal_angle), self.wz0 - r.wz0])

    @property
    def stable(self) -> bool | None:
        """Coupled solution linearly stable (all multipliers within 1e-6 of the unit circle or inside)."""
        if self.multipliers is None:
            return None
        return bool(np.max(np.abs(self.multipliers)) <= 1 + 1e-6)


def flexible_periodic(
    solution,
    body: FlexibleBody,
    *,
    method: str = "auto",
    resolve: bool = True,
    tol: float = 1e-10,
    max_iter: int = 20,
    rtol: float = 1e-12,
    atol: float = 1e-12,
    max_steps: int = 2_000_000,
) -> FlexiblePeriodic:
    """What flexibility does to a rigid periodic orbit-attitude solution.

    Parameters
    ----------
    solution : AttitudeSolution
        A rigid solution of `periodic_attitude` computed with ``kz=body.kz``, over one orbit
        period.
    body : FlexibleBody
        The flexible spacecraft.
    method : {"auto", "quasi-static", "full"}
        "quasi-static": first order in (rate / Omega)^2, closed form, cheap at any stiffness;
        "full": the coupled model re-propagated (and re-solved, with ``resolve``); "auto": "full"
        when the stiffest mode makes fewer than 2e4 radians per orbit period, else
        "quasi-static".
    resolve : bool, default True
        With "full": re-solve the periodic solution of the coupled model (Rust corrector on all
        2 + 2n initial values).
    tol : float, default 1e-10
        The corrector's tolerance.
    max_iter : int, default 20
        Its iterations.
    rtol, atol : float, default 1e-12
        Integration tolerances.
    max_steps : int
        Step limit.

    Returns
    -------
    FlexiblePeriodic
        The first-order drift and shift of the solution; with "full" the coupled model's drift
        and, when re-solved, its periodic solution, residual and multipliers.

    Raises
    ------
    ValueError
        A bad argument (e.g. a solution computed with another Kz), naming it.
    """
    if not isinstance(solution, AttitudeSolution):
        raise ValueError(f"invalid argument `solution`: must be a librate.AttitudeSolution, got {type(solution).__name__}")
    if not isinstance(body, FlexibleBody):
        raise ValueError(f"invalid argument `body`: must be a librate.FlexibleBody, got {type(body).__name__}")
    if abs(solution.kz - body.kz) > 1e-9 * max(1.0, abs(body.kz)):
        raise ValueError(f"invalid argument `solution`: it was computed for Kz = {solution.kz!r}, the body's composite Kz is {body.kz!r}; "
                         "solve the rigid problem with kz=body.kz")
    if method not in ("auto", "quasi-static", "full"):
        raise ValueError(f"invalid argument `method`: must be 'auto', 'quasi-static' or 'full', got {method!r}")
    orbit = solution.orbit
    sys_ = orbit.system
    T = orbit.period
    if method == "auto":
        method = "full" if float(np.max(body.frequencies_nd(sys_))) * T <= 2e4 else "quasi-static"
    phi0 = solution.phi0 - body.principal_angle
    wz0 = solution.wz0
    turns = solution.n_total + (0.5 if solution.kind == "half-turn" else 0.0)
    te = np.linspace(0.0, T, 401)
    qs = quasi_static(sys_, orbit.state0, (phi0, wz0), body, T, t_eval=te, rtol=rtol, atol=atol, max_steps=max_steps)
    drift = np.array([qs.dphi[-1], qs.dwz[-1]])
    try:
        shift = -np.linalg.solve(np.asarray(solution.monodromy) - np.eye(2), drift)
    except np.linalg.LinAlgError:
        shift = np.full(2, np.nan)
    out = dict(solution=solution, body=body, method=method, drift=drift, max_dphi=float(np.max(np.abs(qs.dphi))),
               max_dwz=float(np.max(np.abs(qs.dwz))), shift=shift)
    if method == "quasi-static":
        return FlexiblePeriodic(**out)

    opts = integration_options(rtol, atol, None, 0.0, math.inf, max_steps, 0.8, None)
    model = body._core_model(sys_, [True, True])
    s0 = [float(v) for v in orbit.state0]
    n = body.n

    def flow(x, t_eval=None):
        return _core.flexible_propagate(model, s0, (float(x[0]), float(x[1])), list(x[2:2 + n]), list(x[2 + n:]),
                                        (0.0, T), options=opts, t_eval=t_eval)

    x = np.concatenate([[phi0, wz0], qs.q[0], qs.qdot[0]])
    r = flow(x, te)
    out.update(full_drift=np.array([r.phi[-1] - phi0 - 2 * math.pi * turns, r.wz[-1] - wz0]),
               full_max_dphi=float(np.max(np.abs(r.phi - qs.phi))), full_max_dwz=float(np.max(np.abs(r.wz - qs.wz))))
    if not resolve:
        return FlexiblePeriodic(**out)

    # The re-solve: the Rust corrector (globalised Newton on all 2 + 2n initial values, residuals
    # scaled by the quasi-static amplitudes, the Jacobian's columns integrated in parallel),
    # driven by the continuation driver in the compliance s = 1/f^2 from a stiff start, where the
    # quasi-static state is accurate, to the body itself (s = 1); one correction when the body is
    # stiff enough already.
    omega = body.frequencies_nd(sys_)
    qscale = np.maximum(np.max(np.abs(qs.q), axis=0), 1e-12)
    problem = CompliancePath(sys_, body, s0, T, turns, opts, qscale, tol, max_iter)
    f0 = max(1.0, STIFF_START * max(abs(wz0), 2 * math.pi / T) / float(np.min(omega)))
    c0 = 1.0 / (f0 * f0)
    start = f"the body stiffened x{f0:.4g}" if c0 < 1.0 else "the quasi-static state"
    out["start_factor"] = f0
    try:
        first = problem.correct(np.concatenate([[c0, phi0, wz0], c0 * qs.q[0], c0 * qs.qdot[0]]), Constraint.fix(3 + 2 * n, 0, c0))
    except CorrectionFailed as e:
        return FlexiblePeriodic(**out, reason=f"not re-solved: the correction from {start} failed ({e})")
    br = natural(problem, first, [1.0], rules=StepRules(ds_min=1e-4 * (1.0 - c0) + 1e-12), name="compliance 1/f^2")
    if not br.reached:
        return FlexiblePeriodic(**out, reason=f"not re-solved: the continuation from {start} stopped: {br.end_reason}")
    last = br.points[-1]
    x, mono = last.x[1:], last.data["monodromy"]
    out.update(phi0=float(x[0]), wz0=float(x[1]), q0=x[2:2 + n].copy(), qdot0=x[2 + n:].copy(), residual=float(last.data["residual"]),
               iterations=int(last.iterations), multipliers=np.linalg.eigvals(mono) if np.all(np.isfinite(mono)) else None,
               reason=last.data["reason"])
    return FlexiblePeriodic(**out)


#: The re-solve starts from a body stiffened until its lowest clamped frequency is this many times
#: the larger of the attitude rate and the orbital rate (quasi-static start accurate to ~1e-3).
STIFF_START = 30.0


class CompliancePath:
    """The coupled model's periodic solution continued in the compliance s = 1/f^2 (the body's
    frequencies multiplied by f = 1/sqrt(s)), for the continuation driver (natural parameter):
    x = (s, phi0, wz0, q0, qdot0), each point corrected by the Rust corrector at fixed s. The
    quasi-static deflection is linear in s, so the driver's linear predictor starts close."""

    parameter_index = 0

    def __init__(self, sys_, body, s0, T, turns, opts, qscale, tol, max_iter):
        self.sys, self.body, self.s0, self.T, self.turns, self.opts = sys_, body, s0, T, turns, opts
        self.qscale, self.omega = qscale, body.frequencies_nd(sys_)
        self.tol, self.max_iter = tol, max_iter
        self.scale = np.concatenate([[1.0, 1.0, 1.0], qscale, qscale * self.omega])

    def correct(self, guess, c):
        if c.fixed_index != 0:
            raise ValueError("CompliancePath: natural continuation only (the compliance fixed)")
        s = float(c.b)
        if not s > 0:
            raise CorrectionFailed(f"compliance {s} out of range")
        f = 1.0 / math.sqrt(s)
        b = self.body if s == 1.0 else self.body.scaled(f)
        scale = np.concatenate([[1.0, 1.0], self.qscale * s, self.qscale * s * self.omega * f])
        r = _core.flexible_correct_periodic(b._core_model(self.sys, [True, True]), (self.s0, self.T),
                                            [float(v) for v in guess[1:]], float(self.turns), [float(v) for v in scale],
                                            options=self.opts, newton=_core.NewtonOptions(tol=float(self.tol), max_iter=int(self.max_iter)))
        if r.reason != "converged":
            raise CorrectionFailed(f"flexible re-solve at compliance {s:.6g}: {r.reason}")
        return Point(np.concatenate([[s], r.x]), {"residual": float(r.residual), "reason": r.reason, "monodromy": np.asarray(r.monodromy)},
                     int(r.iterations))

    def tangent(self, pt):
        return None


# --- low frequencies: the coupled response against the structural frequency --------------------
@dataclass(frozen=True)
class FrequencyScan:
    """Result of :func:`frequency_scan`, one row per frequency factor: ``factors``; ``frequency``
    (n_f, n) the clamped frequencies (rad/TU); ``max_q`` (n_f, n) the largest deflection of the
    coupled model (m) and ``max_q_quasi_static`` that of the closed form (m), their ratio
    ``amplification`` (1 in the quasi-static regime, large near resonances); ``max_dphi``,
    ``max_dwz``: the largest departure of the attitude from the rigid composite solution (rad,
    rad/TU); ``max_structural`` (J): the largest structural energy."""

    factors: np.ndarray
    frequency: np.ndarray
    max_q: np.ndarray
    max_q_quasi_static: np.ndarray
    max_dphi: np.ndarray
    max_dwz: np.ndarray
    max_structural: np.ndarray

    @property
    def amplification(self) -> np.ndarray:
        return self.max_q / self.max_q_quasi_static


def frequency_scan(
    system: System | str,
    orbit_state,
    attitude,
    body: FlexibleBody,
    t_span,
    factors,
    *,
    torques: Sequence[str] = ("gravity_gradient",),
    orbit: str = "integrate",
    deflection: str = "quasi-static",
    samples: int = 1001,
    rtol: float = 1e-11,
    atol: float = 1e-11,
    max_steps: int = 2_000_000,
) -> FrequencyScan:
    """The coupled response of a flexible body over a range of structural frequencies (thesis
    Fig. 46).

    For each factor f, ``body.scaled(f)`` (every clamped frequency times f, the damping ratios
    kept) is
    propagated in the coupled model and as the rigid composite body from the same ``attitude``
    (and ``deflection`` start), compared at ``samples`` times. Where a structural frequency meets
    the orbital and attitude forcing, the deflections exceed the quasi-static ones
    (amplification) and the attitude departs from the rigid motion.

    Parameters
    ----------
    system : System or str
        The system.
    orbit_state : array_like, shape (6,)
        The initial orbit state.
    attitude : (float, float)
        (phi0, wz0).
    body : FlexibleBody
        The body at factor 1.
    t_span : float or (float, float)
        The time span (TU).
    factors : array_like
        Frequency factors.
    torques : sequence of str, default ("gravity_gradient",)
        Torque names.
    orbit : {"integrate", "held"}
        As in `propagate_attitude`.
    deflection : {"quasi-static"} or (q0, qdot0)
        The initial deflections.
    samples : int, default 1001
        Comparison times.
    rtol, atol : float, default 1e-11
        Tolerances.
    max_steps : int
        Step limit.

    Returns
    -------
    FrequencyScan
        Per factor: the frequencies, the largest deflections of the coupled model and of the
        closed form, their ratio ``amplification``, the attitude's largest departure from the rigid
        motion and the largest structural energy.
    """
    sys_, s, t0, tf, names = flexible_run_inputs(system, orbit_state, body, t_span, torques, orbit)
    fs = as_float_array(factors, "factors").ravel()
    if fs.size == 0 or not np.all(np.isfinite(fs)) or np.any(fs <= 0):
        raise ValueError(f"invalid argument `factors`: must be positive numbers, got {factors!r}")
    # per sample and factor: the coupled and the rigid runs' times, states and deflections (float64)
    te = np.linspace(t0, tf, as_size(samples, "samples", 2, item_bytes=8 * 64 * max(fs.size, 1)))
    rows = []
    bodies = []
    for f in fs:  # every factor checked before any work
        try:
            bodies.append(body.scaled(float(f)))
        except ValueError as err:
            raise ValueError(f"invalid argument `factors`: {float(f):g}: {err}") from None
    for f, b in zip(fs, bodies):
        qs = quasi_static(sys_, s, attitude, b, (t0, tf), torques=names, orbit=orbit, t_eval=te, rtol=rtol, atol=atol, max_steps=max_steps)
        tr = propagate_attitude(sys_, s, attitude, b, (t0, tf), torques=names, orbit=orbit, t_eval=te, deflection=deflection,
                                rtol=rtol, atol=atol, max_steps=max_steps)
        e = tr.flex.energies()
        rows.append((b.frequencies_nd(sys_), np.max(np.abs(tr.flex.q), axis=0), np.max(np.abs(qs.q), axis=0),
                     float(np.max(np.abs(tr.phi - qs.phi))), float(np.max(np.abs(tr.wz - qs.wz))), float(np.max(e["structural"]))))
    cols = list(zip(*rows))
    return FrequencyScan(fs, np.array(cols[0]), np.array(cols[1]), np.array(cols[2]), np.array(cols[3]),
                         np.array(cols[4]), np.array(cols[5]))
