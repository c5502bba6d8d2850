"""CR3BP propagation: one state with STM, events and output; many states on all cores."""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from .. import _core
from .._checks import as_count, as_direction, as_float_array, as_real, as_state, as_states, as_threads, as_time_span, as_tolerance
from .._errors import CollisionError
from .system import System, resolve_system

__all__ = ["Event", "EventHit", "Stats", "Trajectory", "BatchResult", "propagate", "propagate_many"]

_COORDS = {"x": 0, "y": 1, "z": 2, "xd": 3, "yd": 4, "zd": 5, "vx": 3, "vy": 4, "vz": 5}
_PRIMARIES = {"earth": 0, "moon": 1, "primary1": 0, "primary2": 1, 1: 0, 2: 1}


@dataclass(frozen=True)
class Event:
    """An event located to about 1e-12 in time during `propagate`.

    Build one with `Event.crossing` (a coordinate through a value), `Event.distance` (a distance
    from a point) or `Event.surface` (a primary's surface). A start exactly on the surface
    (g = 0) is not an occurrence.

    Parameters
    ----------
    kind : {"crossing", "distance", "surface"}
        The event function.
    params : tuple of float
        Its parameters (set by the constructors).
    direction : {0, 1, -1}
        +1: g increasing, -1: decreasing, 0: both.
    terminal : bool, default False
        Stop the integration at the first occurrence.

    Examples
    --------
    >>> import librate
    >>> ev = librate.Event.crossing("y", 0.0, direction=1, terminal=True)
    >>> tr = librate.propagate("earth-moon", [0.85, 0, 0, 0, 0.49, 0], 10.0, events=[ev])
    >>> tr.status
    'event'
    """

    kind: Literal["crossing", "distance", "surface"]
    params: tuple[float, ...]
    direction: int = 0
    terminal: bool = False

    @classmethod
    def crossing(cls, coordinate: str | int, value: float = 0.0, *, direction: int = 0, terminal: bool = False) -> Event:
        """``state[coordinate] == value``; coordinate is one of x, y, z, xd, yd, zd or 0..5."""
        index = _COORDS.get(coordinate, coordinate) if isinstance(coordinate, str) else coordinate
        if not isinstance(index, (int, np.integer)) or not 0 <= int(index) < 6:
            raise ValueError(f"invalid argument `coordinate`: must be one of x, y, z, xd, yd, zd or 0..5, got {coordinate!r}")
        return cls("crossing", (float(index), as_real(value, "value")), as_direction(direction), bool(terminal))

    @classmethod
    def distance(cls, center: Sequence[float], radius: float, *, direction: int = 0, terminal: bool = False) -> Event:
        """``|r - center| == radius`` (nondimensional)."""
        c = as_float_array(center, "center").ravel()
        if c.shape != (3,) or not np.all(np.isfinite(c)):
            raise ValueError(f"invalid argument `center`: must be 3 finite numbers, got {center!r}")
        radius = as_real(radius, "radius", nonnegative=True)
        return cls("distance", (*map(float, c), radius), as_direction(direction), bool(terminal))

    @classmethod
    def surface(cls, primary: str | int = "moon", *, terminal: bool = True) -> Event:
        """Reaching the surface of a primary ("earth"/"moon", or 1/2), using the system's radius;
        terminal by default (the CR3BP itself treats primaries as points)."""
        if primary not in _PRIMARIES:
            raise ValueError(f"invalid argument `primary`: must be 'earth', 'moon', 1 or 2, got {primary!r}")
        return cls("surface", (float(_PRIMARIES[primary]),), -1, bool(terminal))

    def _spec(self, system: System) -> tuple[str, list[float], int, bool]:
        if self.kind != "surface":
            return (self.kind, list(self.params), self.direction, self.terminal)
        k = int(self.params[0])
        radius_km = (system.r1_km, system.r2_km)[k]
        if radius_km <= 0:
            raise ValueError(f"invalid argument `events`: Event.surface needs the system's radius r{k + 1}_km > 0")
        center = system.primary_positions()[k]
        return ("distance", [*center, radius_km / system.lu_km], self.direction, self.terminal)


@dataclass(frozen=True)
class EventHit:
    """One located event: its index in the ``events`` list, time, state and STM (when propagated)."""

    index: int
    t: float
    y: np.ndarray
    stm: np.ndarray | None = None


@dataclass(frozen=True)
class Stats:
    """Integrator counters."""

    accepted: int
    rejected: int
    rhs_evals: int

    @classmethod
    def from_core(cls, stats: _core.Stats) -> Stats:
        """The counters of a run of the Rust core."""
        return cls(stats.accepted, stats.rejected, stats.rhs_evals)


@dataclass(frozen=True)
class Trajectory:
    """Result of :func:`propagate`.

    ``t`` (n,) and ``y`` (n, 6) hold every accepted step (or the ``t_eval`` times); ``stm`` is
    the 6x6 state transition matrix from t0 to ``t_final`` when asked for; ``status`` is
    ``"completed"``, ``"event"`` (a terminal event stopped it: ``event_index``) or
    ``"collision"`` (only on the ``trajectory`` attribute of a :class:`librate.CollisionError`:
    it ends on the collision sphere of ``collision_primary``, 1 or 2, at ``t_final``).
    """

    system: System
    t: np.ndarray
    y: np.ndarray
    t_final: float
    y_final: np.ndarray
    stm: np.ndarray | None
    events: list[EventHit]
    status: str
    event_index: int | None
    stats: Stats
    collision_primary: int | None = None

    def events_of(self, index: int) -> list[EventHit]:
        """The hits of one event of the ``events`` list."""
        return [e for e in self.events if e.index == index]

    @property
    def jacobi(self) -> np.ndarray:
        """Jacobi constant at every output point."""
        return self.system.jacobi(self.y) if len(self.y) else np.empty(0)


@dataclass(frozen=True)
class BatchResult:
    """Result of :func:`propagate_many`: final states ``y`` (n, 6), ``stm`` (n, 6, 6) when asked,
    ``ok`` (n,) and, for members that failed, ``errors`` {index: exception} (their rows are NaN,
    flagged by ``ok``); ``stats`` (n, 3): accepted, rejected steps and RHS evaluations;
    ``status`` (n,): "completed", "collision_primary1" / "collision_primary2" (the member reached
    that primary: a :class:`librate.CollisionError` in ``errors``) or "failed" (another error)."""

    y: np.ndarray
    stm: np.ndarray | None
    ok: np.ndarray
    errors: dict[int, Exception] = field(default_factory=dict)
    stats: np.ndarray | None = None
    status: np.ndarray | None = None


#: What counts as a collision with a primary (the ``collision`` argument of :func:`propagate`).
COLLISION_MODES = ("radius", "point", None)


def collision_radii(system: System, collision) -> tuple[float, float] | None:
    """The collision radii (LU) passed to the core: ``"radius"``: the system's radii (a primary
    of radius 0 gets the core's tiny point radius, 1e-8 LU); ``"point"``: that tiny radius for
    both (point masses, only the singularity counts); ``None``: no collision check."""
    if collision is None:
        return None
    if not isinstance(collision, str) or collision not in ("radius", "point"):
        raise ValueError("invalid argument `collision`: must be 'radius' (the system's radii), 'point' (point masses) or "
                         f"None, got {collision!r}")
    if collision == "point":
        return (0.0, 0.0)
    return (system.r1_km / system.lu_km, system.r2_km / system.lu_km)


def _primary_name(system: System, k: int) -> str:
    if system.name.startswith("earth-moon"):
        return ("the Earth", "the Moon")[k - 1]
    return ("the larger primary", "the smaller primary")[k - 1]


def integration_options(rtol, atol, h0, h_min, h_max, max_steps, safety, fixed_step) -> _core.IntegrationOptions:
    """The integrator settings, each checked for its type here (the core checks the ranges);
    every error names the parameter. With ``fixed_step`` the adaptive step options (h0, h_min,
    h_max, safety) do not apply: giving any of them is an error, not silently ignored."""
    if fixed_step is not None:
        for name, value, default in (("h0", h0, None), ("h_min", h_min, 0.0), ("h_max", h_max, math.inf), ("safety", safety, 0.8)):
            if value != default:
                raise ValueError(f"invalid argument `{name}`: adaptive step options do not apply with fixed_step; got {name} = {value!r}")
    return _core.IntegrationOptions(
        rtol=as_tolerance(rtol, "rtol"),
        atol=as_tolerance(atol, "atol"),
        h0=None if h0 is None else as_real(h0, "h0", positive=True),
        h_min=as_real(h_min, "h_min", nonnegative=True),
        h_max=as_real(h_max, "h_max", positive=True, allow_inf=True),
        max_steps=as_count(max_steps, "max_steps", 1),
        safety=as_real(safety, "safety", positive=True),
        fixed_step=None if fixed_step is None else as_real(fixed_step, "fixed_step", positive=True),
    )


def propagate(
    system: System | str,
    state,
    t_span,
    *,
    rtol: float = 1e-12,
    atol: float = 1e-12,
    stm: bool = False,
    events: Sequence[Event] | None = None,
    t_eval=None,
    h0: float | None = None,
    h_min: float = 0.0,
    h_max: float = math.inf,
    max_steps: int = 1_000_000,
    safety: float = 0.8,
    fixed_step: float | None = None,
    collision: str | None = "radius",
) -> Trajectory:
    """Propagate a CR3BP state with the adaptive RKF7(8) integrator (8th-order solution
    propagated), forward or backward in time.

    Parameters
    ----------
    system : System or str
        The system, or a preset name (``"earth-moon"``).
    state : array_like, shape (6,)
        Initial state (x, y, z, xd, yd, zd), nondimensional.
    t_span : float or (float, float)
        Final time tf, or (t0, tf); tf < t0 integrates backward.
    rtol, atol : float
        Error tolerances per step (> 0).
    stm : bool
        Also integrate the 6x6 state transition matrix (returned at the final time and at events).
    events : list of Event, optional
        Events to locate.
    t_eval : array_like, optional
        Output times (monotonic, inside the span) instead of every accepted step.
    h0, h_min, h_max, max_steps, safety, fixed_step : float
        Step control: the first, smallest and largest step, the step limit and the step
        controller's safety factor; ``fixed_step`` switches to fixed steps of that size.
    collision : {"radius", "point", None}
        Reaching a primary stops the integration with `librate.CollisionError`: ``"radius"``
        (default): within the system's radius of either primary (``r1_km``, ``r2_km``; a primary
        of radius 0 counts as a point, 1e-8 LU); ``"point"``: point masses (only that tiny sphere
        about each primary); ``None``: no check (the bare point-mass model, singular at the
        primaries).

    Returns
    -------
    Trajectory
        The states at every accepted step (or at ``t_eval``), the final state, the STM, the
        event hits and the step statistics.

    Raises
    ------
    ValueError
        Bad arguments, naming the parameter.
    CollisionError
        The trajectory reaches a primary, also for a state starting inside one (then at t0). A
        subclass of `IntegrationError`, with ``t``, ``primary`` (1 or 2), ``distance``, ``radius``
        and ``trajectory`` (the trajectory up to the collision sphere, status ``"collision"``).
    IntegrationError
        The integration cannot reach tf (with ``t`` and ``steps``).

    Examples
    --------
    >>> import librate
    >>> tr = librate.propagate("earth-moon", [0.85, 0, 0, 0, 0.49, 0], 1.0, stm=True)
    >>> tr.stm.shape
    (6, 6)
    """
    sys_ = resolve_system(system)
    s = as_state(state)
    t0, tf = as_time_span(t_span)
    evs = list(events or [])
    for e in evs:
        if not isinstance(e, Event):
            raise ValueError(f"invalid argument `events`: must be librate.Event objects, got {e!r}")
    te = None if t_eval is None else as_float_array(t_eval, "t_eval").ravel()
    radii = collision_radii(sys_, collision)
    return integrate(sys_, s, t0, tf, integration_options(rtol, atol, h0, h_min, h_max, max_steps, safety, fixed_step), radii,
                     stm=bool(stm), t_eval=te, events=evs)


@functools.lru_cache(maxsize=16)
def _tolerance_options(rtol: float, atol: float) -> _core.IntegrationOptions:
    return integration_options(rtol, atol, None, 0.0, math.inf, 1_000_000, 0.8, None)


def tolerance_options(rtol: float, atol: float) -> _core.IntegrationOptions:
    """The integrator settings of :func:`propagate` with the tolerances ``rtol``, ``atol`` and the
    default step control, checked once per pair (for internal callers with fixed settings; the
    frozen object is shared)."""
    return _tolerance_options(float(rtol), float(atol))


def integrate(system: System, state: np.ndarray, t0: float, tf: float, options: _core.IntegrationOptions,
              radii: tuple[float, float] | None, *,
              stm: bool = False, t_eval: np.ndarray | None = None, events: Sequence[Event] = ()) -> Trajectory:
    """The one call of the core's propagator behind :func:`propagate`, on arguments already
    checked where they entered (a System, a (6,) float state, ``options`` from
    :func:`integration_options` or :func:`tolerance_options`, ``radii`` from
    :func:`collision_radii`): internal callers with known-good values call it directly."""
    r = _core.propagate(
        system.mu, state, (t0, tf), stm=stm, t_eval=t_eval, events=[e._spec(system) for e in events], options=options, collision=radii,
    )
    err = r.collision
    tr = Trajectory(
        system=system,
        t=r.t,
        y=r.y,
        t_final=r.t_final,
        y_final=r.y_final,
        stm=r.stm,
        events=[EventHit(e.index, e.t, e.y, e.stm) for e in r.events],
        status=r.status,
        event_index=r.event_index,
        stats=Stats.from_core(r.stats),
        collision_primary=None if err is None else int(err.primary),
    )
    if err is not None:
        raise _collision(system, err, tr)
    return tr


def _collision(system: System, err, trajectory: Trajectory | None):
    """The core's CollisionError, its message naming the primary, with the partial trajectory."""
    what = f"collision with {_primary_name(system, int(err.primary))} (primary {int(err.primary)})"
    new = CollisionError(str(err).replace(str(err).split(" at t = ")[0], what, 1))
    for k in ("t", "steps", "kind", "primary", "distance", "radius"):
        setattr(new, k, getattr(err, k))
    new.trajectory = trajectory
    return new


def propagate_many(
    system: System | str,
    states,
    t_final,
    *,
    t0: float = 0.0,
    stm: bool = False,
    rtol: float = 1e-12,
    atol: float = 1e-12,
    h0: float | None = None,
    h_min: float = 0.0,
    h_max: float = math.inf,
    max_steps: int = 1_000_000,
    safety: float = 0.8,
    fixed_step: float | None = None,
    threads: int | None = None,
    on_error: Literal["raise", "mask"] = "raise",
    collision: str | None = "radius",
) -> BatchResult:
    """Propagate many CR3BP states on all cores, with the GIL released.

    Each member is integrated exactly as `propagate` would, so results are bit-identical to
    one-at-a-time calls whatever ``threads`` is.

    Parameters
    ----------
    system : System or str
        The system.
    states : array_like, shape (n, 6)
        The initial states.
    t_final : float or array_like, shape (n,)
        One final time, or one per state (TU).
    t0 : float, default 0.0
        The initial time.
    stm : bool, default False
        Also integrate each 6x6 state transition matrix.
    rtol, atol : float, default 1e-12
        Tolerances.
    h0, h_min, h_max, max_steps, safety, fixed_step
        Step control, as in `propagate`.
    threads : int, optional
        Worker threads (default: all cores).
    on_error : {"raise", "mask"}
        "raise": raise the first member's error (its ``batch_result`` attribute keeps every
        finished member); "mask": NaN rows flagged by ``ok`` and listed in ``errors``.
    collision : {"radius", "point", None}
        As in `propagate`: a member reaching a primary has ``ok = False``, ``status``
        "collision_primary1" or "collision_primary2" and a `CollisionError` in ``errors``.

    Returns
    -------
    BatchResult
        Final states ``y`` (n, 6), the STMs ``stm`` when asked, ``ok``, ``status``, ``errors`` and
    the step statistics ``stats``.

    Raises
    ------
    ValueError
        A bad argument, naming it.
    IntegrationError
        With ``on_error="raise"``, the first member that failed.

    Examples
    --------
    >>> import librate, numpy as np
    >>> states = np.tile([0.85, 0, 0, 0, 0.49, 0], (4, 1))
    >>> res = librate.propagate_many("earth-moon", states, 1.0)
    >>> res.y.shape, bool(res.ok.all())
    ((4, 6), True)
    """
    sys_ = resolve_system(system)
    arr = as_states(states)
    if not np.all(np.isfinite(arr)) and on_error == "raise":
        bad = int(np.argwhere(~np.isfinite(arr))[0][0])
        raise ValueError(f"invalid argument `states`: row {bad} is not finite")
    tf = np.ascontiguousarray(np.atleast_1d(as_float_array(t_final, "t_final")).ravel())
    if not np.all(np.isfinite(tf)):
        raise ValueError(f"invalid argument `t_final`: must be finite, got {t_final!r}")
    t0 = as_real(t0, "t0")
    if tf.size not in (1, arr.shape[0]):
        raise ValueError(f"invalid argument `t_final`: must be one time or one per state ({arr.shape[0]}), got {tf.size}")
    if on_error not in ("raise", "mask"):
        raise ValueError(f"invalid argument `on_error`: must be 'raise' or 'mask', got {on_error!r}")
    threads = as_threads(threads)
    radii = collision_radii(sys_, collision)
    r = _core.propagate_many(
        sys_.mu, arr, float(t0), tf, stm=bool(stm), threads=threads,
        options=integration_options(rtol, atol, h0, h_min, h_max, max_steps, safety, fixed_step), collision=radii,
    )
    errors = {i: (_collision(sys_, e, None) if isinstance(e, CollisionError) else e) for i, e in r.errors.items()}
    status = np.array(["completed", "collision_primary1", "collision_primary2", "failed"])[np.asarray(r.status, dtype=np.intp)]
    result = BatchResult(y=r.y, stm=r.stm, ok=r.ok, errors=errors, stats=r.stats, status=status)
    if result.errors and on_error == "raise":
        index, err = next(iter(result.errors.items()))
        err.add_note(f"in member {index} of propagate_many ({len(result.errors)} of "
                     f"{arr.shape[0]} members failed)") if hasattr(err, "add_note") else None
        err.batch_result = result
        raise err
    return result
