"""The ephemeris, its rotating frame and propagation (the computations run in Rust,
``librate._core.EphemerisCore``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import _core
from .epochs import tdb_seconds
from .spk import embedded_spk_path, read_spk

__all__ = ["Ephemeris", "EphemerisBatch", "EphemerisTrajectory", "RotatingFrame", "default_ephemeris",
           "epoch_seconds", "propagate_ephemeris",
           "propagate_ephemeris_many", "sun_phase"]

#: NAIF ids
SUN, EMB, MOON, EARTH = 10, 3, 301, 399


def epoch_seconds(epoch) -> float:
    """TDB seconds past J2000 of a float or an ISO string with a scale (epochs.tdb_seconds)."""
    if isinstance(epoch, (int, float, np.floating, np.integer)) and not isinstance(epoch, bool):
        t = float(epoch)
        if not np.isfinite(t):
            raise ValueError(f"invalid argument `epoch`: must be finite, got {epoch!r}")
        return t
    return float(tdb_seconds(epoch))


@dataclass(frozen=True)
class RotatingFrame:
    """The instantaneous Earth-Moon frame at an epoch: x Earth -> Moon, z along the Earth-Moon
    angular momentum, y = z x x. ``axes`` rows are x, y, z in ICRF; ``omega`` the frame's angular
    velocity in ICRF (rad/s)."""

    epoch_tdb: float
    distance_km: float
    distance_rate_km_s: float
    rate_rad_s: float
    axes: np.ndarray
    omega: np.ndarray


@dataclass(frozen=True)
class EphemerisTrajectory:
    """A propagated Moon-centred ICRF trajectory: epochs ``t_tdb`` (TDB s past J2000) and
    ``states_km`` (n, 6) in km and km/s; ``stm`` the 6x6 STM from the first to the last epoch."""

    t_tdb: np.ndarray
    states_km: np.ndarray
    stm: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class EphemerisBatch:
    """The final states of many legs propagated at once (:func:`propagate_ephemeris_many`).

    Attributes
    ----------
    states_km : numpy.ndarray, shape (n, 6)
        Each leg's final Moon-centred ICRF state (km, km/s); NaN for a leg that failed.
    stm : numpy.ndarray, shape (n, 6, 6), or None
        Each leg's state transition matrix from its start to its end, when asked.
    ok : numpy.ndarray of bool, shape (n,)
        Whether each leg reached its end.
    errors : dict
        ``{index: exception}`` (a :class:`librate.IntegrationError` or a subclass) for the legs
        that failed; the others are kept.
    """

    states_km: np.ndarray
    stm: np.ndarray | None
    ok: np.ndarray
    errors: dict


class Ephemeris:
    """Earth, Moon and Sun from a JPL SPK file (type-2 segments). ``path=None`` uses the embedded
    DE440 excerpt. ``span`` is the (start, end) coverage in TDB s past J2000."""

    def __init__(self, path: str | Path | None = None, *, segments=None):
        if segments is None:
            segments = read_spk(embedded_spk_path() if path is None else Path(path))
        self.path = path
        self._core = _core.EphemerisCore(
            [
                (
                    int(s.target),
                    int(s.center),
                    float(s.start_s),
                    float(s.end_s),
                    float(s.init_s),
                    float(s.intlen_s),
                    np.ascontiguousarray(s.coefficients, dtype=float),
                )
                for s in segments
            ]
        )

    @property
    def span(self) -> tuple[float, float]:
        return tuple(self._core.span())

    def state(self, target: int, center: int, epoch) -> np.ndarray:
        """State of NAIF body ``target`` relative to ``center`` (km, km/s)."""
        return self._core.state(int(target), int(center), epoch_seconds(epoch))

    def rotating_frame(self, epoch) -> RotatingFrame:
        t = epoch_seconds(epoch)
        d = self._core.frame(t)
        return RotatingFrame(t, d["distance_km"], d["distance_rate_km_s"], d["rate_rad_s"], d["axes"], d["omega"])

    def synodic_to_ephemeris(self, state, epoch, mu: float) -> np.ndarray:
        """A synodic CR3BP state (nondimensional) -> Moon-centred ICRF state (km, km/s) at epoch,
        with the instantaneous distance, rate and frame rotation."""
        return self._core.synodic_to_ephemeris(epoch_seconds(epoch), float(mu), np.ascontiguousarray(state, dtype=float).ravel())

    def ephemeris_to_synodic(self, state_km, epoch, mu: float) -> np.ndarray:
        """The inverse of :meth:`synodic_to_ephemeris`."""
        return self._core.ephemeris_to_synodic(epoch_seconds(epoch), float(mu), np.ascontiguousarray(state_km, dtype=float).ravel())

    def transition(self, states_km, epochs_tdb, *, tol: tuple[float, float], scales: tuple[float, float], epoch_free: bool = False,
                   max_iter: int = 30, integration: tuple[float, float] = (1e-13, 1e-9)) -> dict:
        """Multiple shooting of guess nodes (n, 6) at ``epochs_tdb`` (n,) into a continuous trajectory
        (the Rust corrector; :func:`librate.to_ephemeris` is the user's entry): ``tol`` (km, km/s)
        per leg, ``scales`` (km, s) of the unknowns, ``integration`` (rtol, atol). A dict of
        states_km, epochs_tdb, iterations, reason, defects_km, defects_km_s, history."""
        return self._core.transition(np.ascontiguousarray(states_km, dtype=float),
                                     np.ascontiguousarray(epochs_tdb, dtype=float).ravel(), tol, scales,
                                     epoch_free, max_iter, integration)


_DEFAULT: list[Ephemeris] = []


def default_ephemeris(ephemeris: Ephemeris | None = None) -> Ephemeris:
    """``ephemeris``, or the embedded DE440 excerpt (loaded once) when None."""
    if ephemeris is not None:
        return ephemeris
    if not _DEFAULT:
        _DEFAULT.append(Ephemeris())
    return _DEFAULT[0]


def propagate_ephemeris(
    state_km, epoch, duration_s: float, *, ephemeris: Ephemeris | None = None, stm: bool = False, t_eval=None,
    rtol: float = 1e-13, atol: float = 1e-9
) -> EphemerisTrajectory:
    """Propagate a Moon-centred ICRF state (km, km/s) from ``epoch`` for ``duration_s`` seconds
    under Earth, Moon and Sun point masses (DE440 GM values). ``t_eval``: offsets from the epoch
    (s) at which to record (default: every step)."""
    e = default_ephemeris(ephemeris)
    t0 = epoch_seconds(epoch)
    te = None if t_eval is None else np.ascontiguousarray(t_eval, dtype=float).ravel()
    t, y, phi = e._core.propagate(np.ascontiguousarray(state_km, dtype=float).ravel(), t0, float(duration_s), bool(stm), te,
                                  float(rtol), float(atol))
    return EphemerisTrajectory(t, y, phi)


def propagate_ephemeris_many(states_km, epochs, durations_s, *, ephemeris: Ephemeris | None = None, stm: bool = False,
                             rtol: float = 1e-13, atol: float = 1e-9) -> EphemerisBatch:
    """Propagate many Moon-centred ICRF states at once, on all cores (Rust, the GIL released).

    Each leg ``i`` starts from ``states_km[i]`` at ``epochs[i]`` and runs for ``durations_s[i]``
    seconds, as :func:`propagate_ephemeris` would run it alone: the results are the same bits,
    whatever the number of legs or threads. Only the final states (and STMs) are kept.

    Parameters
    ----------
    states_km : array_like, shape (n, 6)
        Initial states (km, km/s).
    epochs : sequence of str or float, length n
        Start epochs (ISO strings with a scale, or TDB seconds past J2000).
    durations_s : array_like, shape (n,) or a number
        Durations (s, finite; negative runs backwards), one per leg or one for all.
    ephemeris : Ephemeris, optional
        The ephemeris; None, the embedded DE440 excerpt.
    stm : bool, default False
        Also integrate each leg's 6x6 state transition matrix.
    rtol, atol : float, default 1e-13 and 1e-9
        Integration tolerances (atol in km and km/s).

    Returns
    -------
    EphemerisBatch
        The final states, the STMs, and which legs failed and why (a failed leg does not lose
        the others).

    Raises
    ------
    ValueError
        Shapes that do not match, a non-finite duration or state, a tolerance out of range, an
        epoch that cannot be read.
    """
    from .._checks import as_tolerance

    e = default_ephemeris(ephemeris)
    x = np.ascontiguousarray(np.asarray(states_km, dtype=float))
    if x.ndim != 2 or x.shape[1] != 6 or not np.all(np.isfinite(x)):
        raise ValueError(f"invalid argument `states_km`: must be a finite array of shape (n, 6), got shape {x.shape}")
    n = x.shape[0]
    if isinstance(epochs, (str, bytes)) or np.ndim(epochs) == 0:
        raise ValueError(f"invalid argument `epochs`: must be a sequence of {n} epochs, got {epochs!r}")
    t0 = np.ascontiguousarray([epoch_seconds(t) for t in epochs], dtype=float)
    d = np.ascontiguousarray(np.broadcast_to(np.asarray(durations_s, dtype=float), (n,)) if np.ndim(durations_s) == 0
                             else np.asarray(durations_s, dtype=float))
    if t0.shape != (n,) or d.shape != (n,):
        raise ValueError(f"invalid argument `epochs`, `durations_s`: one per state ({n}), got {t0.size} epochs and "
                         f"durations of shape {d.shape}")
    if not np.all(np.isfinite(d)):
        raise ValueError("invalid argument `durations_s`: must be finite")
    integration = (as_tolerance(rtol, "rtol"), as_tolerance(atol, "atol"))
    finals, phis, errors = e._core.propagate_batch(x, t0, d, bool(stm), integration)
    ok = np.ones(n, dtype=bool)
    ok[list(errors)] = False
    return EphemerisBatch(finals, phis, ok, dict(errors))


def sun_phase(epoch, ephemeris: Ephemeris | None = None) -> float:
    """The Sun's angle (rad, in [0, 2 pi)) seen from the Earth-Moon barycentre in the rotating
    frame's x-y plane, from x towards y, at the epoch."""
    e = default_ephemeris(ephemeris)
    t = epoch_seconds(epoch)
    f = e.rotating_frame(t)
    s = e._core.state(SUN, EMB, t)[:3]
    return float(np.arctan2(f.axes[1] @ s, f.axes[0] @ s) % (2 * np.pi))
