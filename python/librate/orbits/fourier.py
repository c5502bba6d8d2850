"""Periodic orbits as truncated Fourier series in time (thesis eq. 44-45, docs/physics.md, periodic orbits).

For a periodic orbit of period T each coordinate q in (x, y, z) is written

    q(t) = a0_q + sum_{n=1..N} [a_{n,q} cos(2 pi n t / T) + c_{n,q} sin(2 pi n t / T)],

the general form. For an x-axis-symmetric planar orbit started on the x axis (a DRO), x has only
cosines and y only sines; the fit finds the other coefficients at rounding level. Velocity and
acceleration are the exact derivatives of the series. Evaluation runs in the Rust core
(``librate._core.fourier_evaluate``), vectorised over the times.

:func:`fit_fourier` builds the series by least squares on dense uniform samples of the integrated
orbit and picks the number of harmonics from a tolerance on the relative Jacobi-constant error
of the series (as the thesis does, Fig. 22).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._checks import as_count, as_size, as_state, as_tolerance
from .._errors import ConvergenceError
from .propagation import propagate
from .system import System, resolve_system

__all__ = ["FourierOrbit", "fit_fourier"]


def _coefficients(value, name: str) -> np.ndarray:
    arr = np.ascontiguousarray(value, dtype=np.float64)
    if arr.ndim == 1 and arr.size == 0:
        arr = arr.reshape(0, 3)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"invalid argument `{name}`: must have shape (N, 3) = one row (x, y, z) per harmonic n = 1..N, "
                         f"got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"invalid argument `{name}`: must be finite")
    return arr


@dataclass(frozen=True, eq=False)
class FourierOrbit:
    """A periodic orbit as a truncated Fourier series (nondimensional units).

    Parameters
    ----------
    period : float
        The period T (TU).
    a0 : numpy.ndarray, shape (3,)
        The mean position.
    cos, sin : numpy.ndarray, shape (N, 3)
        ``cos[n - 1]`` and ``sin[n - 1]``: the (x, y, z) coefficients of cos(2 pi n t / T) and
        sin(2 pi n t / T), n = 1..N.
    system : System, optional
        The system (for the Jacobi constant).
    jacobi0, jacobi_error, jacobi_history, position_error, velocity_error : optional
        How a series from `fit_fourier` was obtained (None for a series built by hand):
        ``jacobi_error`` is the largest relative Jacobi-constant error |C_series(t) - C0| / |C0|
        over the check times, with C = 2U - |v|^2 from the series' positions and velocities;
        ``jacobi_history[k]`` that error with k + 1 harmonics; ``position_error`` and
        ``velocity_error`` the largest distances from the integrated orbit at the check times
        (midway between the fit samples).
    """

    period: float
    a0: np.ndarray
    cos: np.ndarray
    sin: np.ndarray
    system: System | None = None
    jacobi0: float | None = None
    jacobi_error: float | None = None
    jacobi_history: np.ndarray | None = field(default=None, repr=False)
    position_error: float | None = None
    velocity_error: float | None = None

    def __post_init__(self) -> None:
        if not (isinstance(self.period, (int, float, np.floating)) and math.isfinite(self.period) and self.period > 0):
            raise ValueError(f"invalid argument `period`: must be a finite number > 0, got {self.period!r}")
        a0 = np.ascontiguousarray(self.a0, dtype=np.float64).ravel()
        if a0.shape != (3,) or not np.all(np.isfinite(a0)):
            raise ValueError(f"invalid argument `a0`: must be 3 finite numbers (x, y, z), got {self.a0!r}")
        cos, sin = _coefficients(self.cos, "cos"), _coefficients(self.sin, "sin")
        if cos.shape != sin.shape:
            raise ValueError(f"invalid argument `sin`: must have the shape of `cos` {cos.shape}, got {sin.shape}")
        object.__setattr__(self, "period", float(self.period))
        for name, arr in (("a0", a0), ("cos", cos), ("sin", sin)):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    @property
    def n_harmonics(self) -> int:
        """Number of harmonics N."""
        return int(self.cos.shape[0])

    def truncated(self, n_harmonics: int) -> FourierOrbit:
        """The same series keeping harmonics 1..n_harmonics (fit diagnostics dropped)."""
        if not isinstance(n_harmonics, (int, np.integer)) or not 0 <= n_harmonics <= self.n_harmonics:
            raise ValueError(f"invalid argument `n_harmonics`: must be an integer in [0, {self.n_harmonics}], got {n_harmonics!r}")
        n = int(n_harmonics)
        return FourierOrbit(self.period, self.a0, self.cos[:n], self.sin[:n], system=self.system, jacobi0=self.jacobi0)

    # --- evaluation (Rust) ------------------------------------------------------------------
    def _evaluate(self, t, quantity: str, width: int) -> np.ndarray:
        ta = np.asarray(t, dtype=np.float64)
        flat = np.ascontiguousarray(ta.ravel())
        if not np.all(np.isfinite(flat)):
            raise ValueError("invalid argument `t`: times must be finite")
        out = _core.fourier_evaluate(self.period, self.a0, self.cos, self.sin, flat, quantity=quantity)
        return out.reshape(ta.shape + (width,))

    def position(self, t) -> np.ndarray:
        """(x, y, z) at time(s) t: shape t.shape + (3,)."""
        return self._evaluate(t, "position", 3)

    def velocity(self, t) -> np.ndarray:
        """(xd, yd, zd), the exact derivative of the series: shape t.shape + (3,)."""
        return self._evaluate(t, "velocity", 3)

    def acceleration(self, t) -> np.ndarray:
        """(xdd, ydd, zdd), the exact second derivative of the series: shape t.shape + (3,)."""
        return self._evaluate(t, "acceleration", 3)

    def state(self, t) -> np.ndarray:
        """(x, y, z, xd, yd, zd) at time(s) t: shape t.shape + (6,)."""
        return self._evaluate(t, "state", 6)

    def evaluate(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity and acceleration at time(s) t in one pass."""
        all9 = self._evaluate(t, "all", 9)
        return all9[..., :3], all9[..., 3:6], all9[..., 6:]

    def jacobi_relative_error(self, system: System | str, t, jacobi0: float) -> np.ndarray:
        """|C(t) - jacobi0| / |jacobi0| with C = 2U - |v|^2 from the series' position and
        velocity at time(s) t."""
        sys_ = resolve_system(system)
        states = self.state(np.atleast_1d(t))
        c = sys_.jacobi(states.reshape(-1, 6)).reshape(states.shape[:-1])
        return np.abs(c - jacobi0) / abs(jacobi0)


def _design(t: np.ndarray, period: float, n: int) -> np.ndarray:
    """Columns 1, cos(k w t) (k = 1..n), sin(k w t) (k = 1..n)."""
    k = np.arange(1, n + 1)
    phase = np.outer(t, k) * (2.0 * math.pi / period)
    return np.hstack([np.ones((t.size, 1)), np.cos(phase), np.sin(phase)])


def _least_squares(t: np.ndarray, positions: np.ndarray, period: float, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    coef, *_ = np.linalg.lstsq(_design(t, period, n), positions, rcond=None)
    return coef[0], coef[1 : n + 1], coef[n + 1 :]


def fit_fourier(
    system: System | str,
    state0,
    period: float,
    *,
    n_harmonics: int | None = None,
    jacobi_tol: float = 1e-6,
    max_harmonics: int = 60,
    n_samples: int | None = None,
    closure_tol: float = 1e-7,
    rtol: float = 1e-13,
    atol: float = 1e-13,
) -> FourierOrbit:
    """The Fourier series of a periodic orbit (thesis Fig. 22).

    The orbit is integrated over one period and sampled at ``n_samples`` uniform times t_k = k T
    / n_samples; the coefficients of each coordinate are the least-squares fit of the series with
    N harmonics. The fit is checked at the midpoints between samples, which it has not seen.
    Without ``n_harmonics``, N = 1, 2, ... up to ``max_harmonics`` is tried and the smallest N
    whose largest relative Jacobi-constant error is below ``jacobi_tol`` is returned.

    Parameters
    ----------
    system : System or str
        The system.
    state0 : array_like, shape (6,)
        A state on the periodic orbit.
    period : float
        Its period (TU).
    n_harmonics : int, optional
        Use this N.
    jacobi_tol : float, default 1e-6
        The relative Jacobi-constant error to reach.
    max_harmonics : int, default 60
        The largest N tried.
    n_samples : int, optional
        Default max(1024, 8 N_max); must exceed 4 N_max.
    closure_tol : float, default 1e-7
        How closely ``state0`` must return to itself after ``period`` (relative to the orbit's size).
    rtol, atol : float, default 1e-13
        Integration tolerances.

    Returns
    -------
    FourierOrbit
        The series, with its errors (``jacobi_history``: every N tried).

    Raises
    ------
    ValueError
        A bad argument, or a ``state0`` that does not close after ``period``.
    ConvergenceError
        No N <= ``max_harmonics`` meets ``jacobi_tol``.

    Examples
    --------
    >>> import librate
    >>> dro = librate.dro(period_days=12.66)
    >>> series = librate.fit_fourier(dro.system, dro.state0, dro.period)
    >>> series.jacobi_error < 1e-6
    True
    """
    sys_ = resolve_system(system)
    s0 = as_state(state0, "state0")
    if not (isinstance(period, (int, float, np.floating)) and math.isfinite(period) and period > 0):
        raise ValueError(f"invalid argument `period`: must be a finite number > 0 (TU), got {period!r}")
    period = float(period)
    if n_harmonics is not None:
        n_max = as_count(n_harmonics, "n_harmonics", 1)
    else:
        n_max = as_count(max_harmonics, "max_harmonics", 1)
        as_tolerance(jacobi_tol, "jacobi_tol")
    # per sample: its time, state and check point (float64) and a row of the (2 N + 1) harmonics
    m = max(1024, 8 * n_max) if n_samples is None else as_size(n_samples, "n_samples", 4 * n_max + 1, item_bytes=8 * (16 + 2 * n_max + 1))
    as_tolerance(closure_tol, "closure_tol")

    # Samples (even indices) and check points (odd indices), then t = T for the closure.
    t_all = np.arange(2 * m + 1) * (period / (2 * m))
    tr = propagate(sys_, s0, period, t_eval=t_all, rtol=rtol, atol=atol, collision="point")
    y = tr.y
    scale = max(float(np.max(np.abs(y[:, :3] - y[:, :3].mean(axis=0)))), 1e-300)
    closure = float(np.max(np.abs(y[-1] - s0)))
    if closure > closure_tol * max(scale, 1.0):
        raise ValueError(
            f"invalid argument `state0`/`period`: the orbit does not close after one period "
            f"(|x(T) - x(0)| = {closure:.3e} > closure_tol = {closure_tol:.1e}); pass a corrected periodic orbit"
        )
    t_fit, r_fit = t_all[0:-1:2], y[0:-1:2, :3]
    t_chk, y_chk = t_all[1::2], y[1::2]
    c0 = sys_.jacobi(s0)

    def build(n: int) -> tuple[FourierOrbit, float]:
        a0, cos, sin = _least_squares(t_fit, r_fit, period, n)
        f = FourierOrbit(period, a0, cos, sin, system=sys_, jacobi0=c0)
        return f, float(np.max(f.jacobi_relative_error(sys_, t_chk, c0)))

    if n_harmonics is not None:
        f, err = build(n_max)
        history = [err]
    else:
        history = []
        for n in range(1, n_max + 1):
            f, err = build(n)
            history.append(err)
            if err < jacobi_tol:
                break
        else:
            e = ConvergenceError(
                f"Fourier fit: no number of harmonics up to max_harmonics = {n_max} brings the relative "
                f"Jacobi-constant error below jacobi_tol = {jacobi_tol:.1e} (best {min(history):.3e})"
            )
            e.iterations, e.residual, e.tolerance = n_max, float(min(history)), float(jacobi_tol)
            raise e
    pos, vel = f.position(t_chk), f.velocity(t_chk)
    return FourierOrbit(
        period,
        f.a0,
        f.cos,
        f.sin,
        system=sys_,
        jacobi0=c0,
        jacobi_error=err,
        jacobi_history=np.array(history),
        position_error=float(np.max(np.linalg.norm(pos - y_chk[:, :3], axis=1))),
        velocity_error=float(np.max(np.linalg.norm(vel - y_chk[:, 3:], axis=1))),
    )
