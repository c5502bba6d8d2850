"""Periodic orbits carried into the Earth-Moon-Sun ephemeris model (docs/ephemeris.md).

:func:`to_ephemeris` places a CR3BP periodic orbit at a calendar epoch, samples it at nodes over
several revolutions and corrects the nodes by multiple shooting into one continuous trajectory of
the ephemeris model (the computation runs in Rust: ``EphemerisCore.transition``, with the project's
dense Newton driver, minimum-norm steps). :func:`ephemeris_sweep` does it at many epochs.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._checks import as_count, as_real, as_tolerance
from .._errors import ConvergenceError
from .._progress import as_progress
from ..ephemeris.model import Ephemeris, EphemerisTrajectory, default_ephemeris, epoch_seconds, propagate_ephemeris
from .periodic import PeriodicOrbit
from .propagation import propagate

__all__ = ["EphemerisOrbit", "to_ephemeris", "ephemeris_sweep", "nodes_per_rev_for"]

#: Nodes per revolution unless given: legs of at most about 1.7 days, at least 5 a revolution,
#: and an odd number. The orbits start on their x-z plane crossing, so an odd count puts no node
#: on the other crossing, which for an NRHO is the perilune: there the flow is the most sensitive,
#: and a node on it keeps the Newton iteration of the 9:2 NRHO from converging at some epochs
#: (2030-01-01, 6 or 8 nodes), while 5, 7 or 9 converge in 4-5 steps at every epoch tried.
MAX_LEG_DAYS = 1.7
MIN_NODES_PER_REV = 5
#: By default a continuous trajectory farther than this fraction of the orbit's size (its largest
#: distance from the Moon) from the CR3BP orbit is refused: it is another trajectory, not the
#: orbit's counterpart (``max_departure`` of :func:`to_ephemeris`).
MAX_DEPARTURE = 0.5


@dataclass(frozen=True, eq=False)
class EphemerisOrbit:
    """A periodic orbit's ephemeris counterpart: a continuous trajectory of the Earth-Moon-Sun model
    over ``revolutions`` revolutions from ``epoch_tdb``, given by its nodes.

    Attributes
    ----------
    orbit : PeriodicOrbit
        The CR3BP orbit it was made from.
    epoch_tdb : float
        The first node's epoch (TDB seconds past J2000).
    revolutions, nodes_per_rev : int
        The span and the nodes of each revolution (``revolutions * nodes_per_rev + 1`` nodes).
    epochs_tdb : numpy.ndarray, shape (n,)
        The node epochs (TDB s past J2000).
    states_km : numpy.ndarray, shape (n, 6)
        The Moon-centred ICRF node states (km, km/s), each on the continuous trajectory at its
        epoch, the last node included.
    iterations : int
        Newton steps of the multiple shooting.
    defects_km, defects_km_s : numpy.ndarray, shape (n - 1,)
        Each leg's continuity defect at its end: position (km) and velocity (km/s).
    history : numpy.ndarray
        The largest defect, in units of the tolerances, at the start and after each step.
    max_departure_km : float
        The largest distance of the trajectory, in the instantaneous rotating frame scaled by
        the system's length unit, from the CR3BP orbit.
    perilune_km : numpy.ndarray, shape (revolutions,)
        The closest approach to the Moon's centre in each revolution.
    drift_km_per_rev : float
        The slope, per revolution, of the distance of each revolution's first node (rotating
        frame) from the CR3BP orbit's initial state.
    ephemeris : Ephemeris
        The ephemeris used.
    """

    orbit: PeriodicOrbit
    epoch_tdb: float
    revolutions: int
    nodes_per_rev: int
    epochs_tdb: np.ndarray
    states_km: np.ndarray
    iterations: int
    defects_km: np.ndarray
    defects_km_s: np.ndarray
    history: np.ndarray
    max_departure_km: float
    perilune_km: np.ndarray
    drift_km_per_rev: float
    ephemeris: Ephemeris = field(repr=False)
    departure_km: np.ndarray = field(repr=False, default=None)

    def sample(self) -> EphemerisTrajectory:
        """The continuous trajectory at every integration step of every leg (epochs ``t_tdb`` and
        Moon-centred ICRF ``states_km``), the node epochs included once."""
        ts, ys = [], []
        for i in range(len(self.epochs_tdb) - 1):
            tr = propagate_ephemeris(self.states_km[i], float(self.epochs_tdb[i]), float(self.epochs_tdb[i + 1] - self.epochs_tdb[i]),
                                     ephemeris=self.ephemeris)
            ts.append(tr.t_tdb[:-1])
            ys.append(tr.states_km[:-1])
        ts.append(self.epochs_tdb[-1:])
        ys.append(self.states_km[-1:])
        return EphemerisTrajectory(np.concatenate(ts), np.concatenate(ys))

    def synodic(self, trajectory: EphemerisTrajectory | None = None) -> np.ndarray:
        """Node states (or the states of ``trajectory``) in the instantaneous rotating frame,
        nondimensional (CR3BP synodic coordinates, barycentric)."""
        t, y = (self.epochs_tdb, self.states_km) if trajectory is None else (trajectory.t_tdb, trajectory.states_km)
        mu = self.orbit.system.mu
        return np.array([self.ephemeris.ephemeris_to_synodic(s, float(e), mu) for s, e in zip(y, t)])

    def __repr__(self) -> str:
        return (f"EphemerisOrbit({self.orbit.family}, epoch_tdb={self.epoch_tdb:.1f}, revolutions={self.revolutions}, "
                f"nodes={len(self.epochs_tdb)}, iterations={self.iterations}, defect={float(self.defects_km.max()) * 1e3:.2e} m, "
                f"max_departure={self.max_departure_km:.1f} km, "
                f"perilune={float(self.perilune_km.min()):.0f}..{float(self.perilune_km.max()):.0f} km)")


def nodes_per_rev_for(orbit: PeriodicOrbit, nodes_per_rev: int | None = None) -> int:
    """``nodes_per_rev`` checked, or the default for ``orbit``: legs of at most MAX_LEG_DAYS, at
    least MIN_NODES_PER_REV nodes a revolution, an odd number."""
    if nodes_per_rev is None:
        n = max(MIN_NODES_PER_REV, math.ceil(orbit.period_days / MAX_LEG_DAYS))
        return n + 1 - n % 2
    return as_count(nodes_per_rev, "nodes_per_rev", 2, 1000)


def _guess(orbit: PeriodicOrbit, t0: float, revolutions: int, npr: int, eph: Ephemeris):
    """CR3BP nodes over the revolutions, placed in the ephemeris at t0 + tau tu_s. The orbit is
    integrated over one period and repeated: integrated over all the revolutions, an unstable
    orbit's own rounding errors would grow by its stability index each revolution (the 12-day L2
    halo's guess left the orbit in its tenth)."""
    s = orbit.system
    k = revolutions * npr
    taus = orbit.period * np.arange(k + 1) / npr
    one = propagate(s, orbit.state0, (0.0, float(taus[npr])), t_eval=taus[:npr], rtol=1e-13, atol=1e-13).y
    synodic = np.concatenate([np.tile(one, (revolutions, 1)), orbit.state0[None, :]])
    epochs = t0 + taus * s.tu_s
    states = np.array([eph.synodic_to_ephemeris(y, float(e), s.mu) for y, e in zip(synodic, epochs)])
    return states, epochs


def _perilunes(traj: EphemerisTrajectory, epochs: np.ndarray, revolutions: int, npr: int) -> np.ndarray:
    """Closest approach to the Moon in each revolution: the smallest sampled |r|, refined by a
    parabola through it and its neighbours."""
    r = np.linalg.norm(traj.states_km[:, :3], axis=1)
    out = np.empty(revolutions)
    for k in range(revolutions):
        a, b = epochs[k * npr], epochs[(k + 1) * npr]
        idx = np.flatnonzero((traj.t_tdb >= a) & (traj.t_tdb <= b))
        j = idx[np.argmin(r[idx])]
        best = r[j]
        if 0 < j < len(r) - 1:
            (t0, t1, t2), (r0, r1, r2) = traj.t_tdb[j - 1:j + 2], r[j - 1:j + 2]
            c = np.polyfit([t0 - t1, 0.0, t2 - t1], [r0, r1, r2], 2)
            if c[0] > 0:
                best = min(best, float(np.polyval(c, -c[1] / (2 * c[0]))))
        out[k] = best
    return out


def to_ephemeris(
    orbit: PeriodicOrbit,
    epoch,
    *,
    revolutions: int,
    nodes_per_rev: int | None = None,
    ephemeris: Ephemeris | None = None,
    epoch_free: bool = False,
    tol_km: float = 1e-3,
    tol_km_s: float = 1e-8,
    max_iter: int = 30,
    rtol: float = 1e-13,
    atol: float = 1e-9,
    max_departure: float = MAX_DEPARTURE,
) -> EphemerisOrbit:
    """Carry a CR3BP periodic orbit into the Earth-Moon-Sun ephemeris model at ``epoch``.

    The orbit is sampled at ``nodes_per_rev`` nodes a revolution (equal times) over
    ``revolutions`` revolutions, each node placed in the ephemeris model at its epoch (epoch +
    tau times the system's time unit) with the instantaneous Earth-Moon frame, distance and rate.
    Multiple shooting then makes the trajectory continuous: the unknowns are every node state and
    every node epoch but the first (also the first with ``epoch_free``); the conditions are the
    full-state continuity at every node; each Newton step is the minimum-norm one, so the result
    stays near the CR3BP orbit.

    Parameters
    ----------
    orbit : PeriodicOrbit
        A CR3BP periodic orbit of the Earth-Moon system (a DRO, Lyapunov, halo, NRHO).
    epoch : str or float
        An ISO string with its scale ("2030-01-01T00:00:00 TDB", "... UTC") or TDB seconds past
        J2000.
    revolutions : int
        Revolutions to carry (1..1000).
    nodes_per_rev : int, optional
        Nodes a revolution (2..1000); by default legs of at most 1.7 days, at least 5 a
        revolution, an odd number (no node on the perilune of an orbit that starts at apolune).
    ephemeris : Ephemeris, optional
        The ephemeris; None, the embedded DE440 excerpt.
    epoch_free : bool, default False
        Let the first node's epoch move too.
    tol_km, tol_km_s : float, default 1e-3 and 1e-8
        Continuity asked of every leg: position (km) and velocity (km/s).
    max_iter : int, default 30
        Newton steps at most.
    rtol, atol : float, default 1e-13 and 1e-9
        Integration tolerances (atol in km and km/s).
    max_departure : float, default 0.5
        The largest distance from the CR3BP orbit accepted, as a fraction of the orbit's size
        (its largest distance from the Moon); a continuous trajectory farther away is refused.

    Returns
    -------
    EphemerisOrbit

    Raises
    ------
    ValueError
        An argument out of range, or an epoch span outside the ephemeris (naming the span).
    ConvergenceError
        The multiple shooting stopped before continuity (naming why, the steps and the defects),
        or the continuous trajectory it found leaves the orbit (farther from it than
        ``max_departure`` times the orbit's size: another trajectory, not this orbit's
        counterpart).

    Examples
    --------
    >>> import librate
    >>> dro = librate.dro("earth-moon", x0=0.9)
    >>> eo = librate.to_ephemeris(dro, "2030-01-01T00:00:00 TDB", revolutions=2)
    >>> bool(eo.defects_km.max() < 1e-3)
    True
    """
    if not isinstance(orbit, PeriodicOrbit):
        raise ValueError(f"invalid argument `orbit`: must be a librate.PeriodicOrbit, got {type(orbit).__name__}")
    mu_em = _core.GM_MOON / (_core.GM_EARTH + _core.GM_MOON)
    if not math.isclose(orbit.system.mu, mu_em, rel_tol=1e-3):
        raise ValueError(f"invalid argument `orbit`: the ephemeris model is the Earth-Moon-Sun one (mu = {mu_em:.9f}), got an orbit with "
                         f"mu = {orbit.system.mu!r}")
    revolutions = as_count(revolutions, "revolutions", 1, 1000)
    npr = nodes_per_rev_for(orbit, nodes_per_rev)
    for name, v in (("tol_km", tol_km), ("tol_km_s", tol_km_s)):
        as_real(v, name, positive=True)
    as_tolerance(rtol, "rtol")
    as_tolerance(atol, "atol")
    as_real(max_departure, "max_departure", positive=True)
    max_iter = as_count(max_iter, "max_iter", 1, 1000)
    eph = default_ephemeris(ephemeris)
    t0 = epoch_seconds(epoch)
    span = eph.span
    t_end = t0 + revolutions * orbit.period * orbit.system.tu_s
    if not (span[0] <= t0 and t_end <= span[1]):
        raise ValueError(f"invalid argument `epoch`: the {revolutions} revolutions from {t0:.1f} to {t_end:.1f} TDB s past J2000 "
                         f"leave the ephemeris span [{span[0]:.1f}, {span[1]:.1f}] TDB s")
    states, epochs = _guess(orbit, t0, revolutions, npr, eph)
    s = orbit.system
    d = eph.transition(states, epochs, tol=(float(tol_km), float(tol_km_s)), scales=(s.lu_km, s.tu_s), epoch_free=bool(epoch_free),
                            max_iter=max_iter, integration=(float(rtol), float(atol)))
    if d["reason"] != "converged":
        worst = int(np.argmax(d["defects_km"]))
        err = ConvergenceError(f"ephemeris transition of the {orbit.family} (period {orbit.period_days:.3f} d) at {t0:.1f} TDB s, "
                               f"{revolutions} revolutions, {npr} nodes a revolution: the multiple shooting stopped "
                               f"({d['reason'].replace('_', ' ')}) after {d['iterations']} Newton steps; largest defects "
                               f"{float(d['defects_km'].max()):.3e} km (leg {worst}) and {float(d['defects_km_s'].max()):.3e} km/s, asked "
                               f"{tol_km:.1e} km and {tol_km_s:.1e} km/s. More nodes a revolution (an odd nodes_per_rev: no node on the "
                               "perilune) or fewer revolutions may help")
        raise err
    traj_nodes_t, traj_nodes = d["epochs_tdb"], d["states_km"]
    eo = EphemerisOrbit(orbit, float(traj_nodes_t[0]), revolutions, npr, traj_nodes_t, traj_nodes, int(d["iterations"]),
                        d["defects_km"], d["defects_km_s"],
                        d["history"], math.nan, np.full(revolutions, math.nan), math.nan, eph)
    return _with_figures(eo, float(max_departure))


def _with_figures(eo: EphemerisOrbit, max_departure: float) -> EphemerisOrbit:
    """The departure from the CR3BP orbit, the perilunes and the drift, from the dense trajectory;
    ConvergenceError if it departs by more than ``max_departure`` times the orbit's size."""
    orbit, s = eo.orbit, eo.orbit.system
    traj = eo.sample()
    syn = eo.synodic(traj)[:, :3]
    ref = propagate(s, orbit.state0, (0.0, orbit.period), t_eval=np.linspace(0.0, orbit.period, 4001), rtol=1e-13, atol=1e-13).y[:, :3]
    from scipy.spatial import cKDTree  # here: scipy.spatial costs `import librate` ~0.5 s

    # the distance of each sample to the nearest point of the densely sampled CR3BP orbit
    dmin = cKDTree(ref).query(syn)[0]
    size = float(np.linalg.norm(ref - [1.0 - s.mu, 0.0, 0.0], axis=1).max())
    worst = int(np.argmax(dmin))
    if dmin[worst] > max_departure * size:
        rev = min(int(np.searchsorted(eo.epochs_tdb, traj.t_tdb[worst], side="right") - 1) // eo.nodes_per_rev, eo.revolutions - 1)
        raise ConvergenceError(
            f"ephemeris transition of the {orbit.family} (period {orbit.period_days:.3f} d) at {eo.epoch_tdb:.1f} TDB s over "
            f"{eo.revolutions} revolutions: the multiple shooting made the trajectory continuous, but it leaves the orbit: in revolution "
            f"{rev + 1} it passes {dmin[worst] * s.lu_km:,.0f} km from the CR3BP orbit, more than {max_departure:.0%} of the orbit's size "
            f"({size * s.lu_km:,.0f} km from the Moon at most); that is not this orbit's ephemeris counterpart. Fewer revolutions, or more "
            "nodes a revolution, may hold")
    starts = eo.synodic()[:: eo.nodes_per_rev, :3]
    departure = np.linalg.norm(starts - orbit.state0[:3], axis=1) * s.lu_km
    drift = float(np.polyfit(np.arange(len(departure)), departure, 1)[0]) if len(departure) > 1 else 0.0
    perilune = _perilunes(traj, eo.epochs_tdb, eo.revolutions, eo.nodes_per_rev)
    return EphemerisOrbit(orbit, eo.epoch_tdb, eo.revolutions, eo.nodes_per_rev, eo.epochs_tdb, eo.states_km, eo.iterations,
                          eo.defects_km, eo.defects_km_s,
                          eo.history, float(dmin.max() * s.lu_km), perilune, drift, eo.ephemeris, departure)


def ephemeris_sweep(orbit: PeriodicOrbit, epochs: Sequence, *, revolutions: int, workers: int | None = None, progress=None,
                    **options) -> list[EphemerisOrbit | ConvergenceError]:
    """:func:`to_ephemeris` at each of ``epochs`` (ISO strings or TDB seconds); the transitions that
    do not converge are returned as their :class:`ConvergenceError`, in place (a sweep keeps every
    finished epoch). ``options`` as for :func:`to_ephemeris`.

    ``workers`` epochs run at once (default: the CPU count, at most 8), each transition's legs on
    every core too: the Rust multiple shooting releases the GIL, and its serial parts (the
    linear algebra of each Newton step, the guess and the figures) of one epoch overlap the
    legs of another. The results do not depend on ``workers``: each epoch is computed alone,
    deterministically, and returned in the order of ``epochs``. ``progress``: True for a bar on
    stderr, or ``progress(done, total)`` after each epoch."""
    if isinstance(epochs, (str, bytes)) or not isinstance(epochs, Sequence | np.ndarray):
        raise ValueError(f"invalid argument `epochs`: must be a sequence of epochs, got {type(epochs).__name__}")
    epochs = list(epochs)
    workers = min(8, os.cpu_count() or 1) if workers is None else as_count(workers, "workers", 1, 256)
    report = as_progress(progress, "ephemeris sweep", "epoch")

    def one(e) -> EphemerisOrbit | ConvergenceError:
        try:
            return to_ephemeris(orbit, e, revolutions=revolutions, **options)
        except ConvergenceError as err:
            return err

    if not epochs:
        return []
    first = one(epochs[0])  # bad arguments raise here, before any thread starts
    out: list[EphemerisOrbit | ConvergenceError] = [first]
    if report is not None:
        report(1, len(epochs))
    if workers == 1 or len(epochs) == 1:
        for e in epochs[1:]:
            out.append(one(e))
            if report is not None:
                report(len(out), len(epochs))
        return out
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(max_workers=min(workers, len(epochs) - 1), thread_name_prefix="librate-sweep") as pool:
        futures = [pool.submit(one, e) for e in epochs[1:]]
        try:
            for f in futures:
                out.append(f.result())
                if report is not None:
                    report(len(out), len(epochs))
        except BaseException:
            for f in futures:
                f.cancel()
            raise
    return out
