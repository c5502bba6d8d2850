"""The work behind ``librate transition``: one CR3BP periodic orbit carried into the Earth-Moon-Sun
ephemeris model at each epoch of a study (:func:`librate.orbits.transition.to_ephemeris`), saved
epoch by epoch in a part store (:class:`librate.results.PartStore`, ``librate_store =
"ephemeris_transition"``; one part per epoch, its digests and done flag).

A run stopped at any moment (Ctrl-C, a kill) loses at most the epochs in flight; the same call
again reuses the finished epochs (a damaged one is named in a warning and recomputed). On a Dask
cluster (``scheduler``: a ``distributed.Client`` or its address) each epoch is one task through
:func:`librate.app.distribute.run_tasks`: checksummed on arrival, written by the worker itself
where it shares the store's filesystem, submitted again when lost with its worker; the arrays
equal the local run's bit for bit (the transitions are deterministic).

An epoch whose multiple shooting does not converge is kept with ``status = 1`` (its arrays NaN,
its reason in the ``failures`` attribute) and the sweep goes on.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import numpy as np

from ..orbits.transition import nodes_per_rev_for

__all__ = ["COMPONENTS", "CR3BP_SAMPLES", "PER_LEG", "run_transition_to", "transition_sizes", "transition_summary"]

#: The state components (position, then velocity).
COMPONENTS = ("x", "y", "z", "vx", "vy", "vz")
#: Samples per leg of the stored ephemeris trajectory (the rotating-frame figure).
PER_LEG = 8
#: Samples of the stored CR3BP orbit over one period (the rotating-frame figure).
CR3BP_SAMPLES = 400
#: What the frames of the stored states are (the result's ``frames`` attribute).
FRAMES = ("states_km: Moon-centred ICRF (km, km/s), TDB; synodic, track_synodic, cr3bp_synodic: the instantaneous "
          "Earth-Moon rotating frame (x Earth -> Moon, z along the Earth-Moon angular momentum, y = z x x; origin the Earth-Moon "
          "barycentre), nondimensional with the instantaneous Earth-Moon distance and rotation rate (Ephemeris.ephemeris_to_synodic)")

_EPHEMERIS: dict[str | None, Any] = {}


def _ephemeris(path: str | None):
    """The Ephemeris of ``path`` (None: the embedded excerpt), read once per process."""
    if path not in _EPHEMERIS:
        from ..ephemeris.model import Ephemeris

        _EPHEMERIS[path] = Ephemeris(path)
    return _EPHEMERIS[path]


def transition_sizes(revolutions: int, nodes_per_rev: int) -> dict[str, int]:
    """The lengths of an epoch's dimensions: node, leg, revolution, sample, component."""
    nodes = revolutions * nodes_per_rev + 1
    return {"node": nodes, "leg": nodes - 1, "revolution": revolutions, "sample": (nodes - 1) * PER_LEG + 1, "component": 6}


def _failed(sizes: dict) -> dict:
    from ..results.kinds import TRANSITION_VARIABLES

    out = {}
    for k, (dtype, dims, _) in TRANSITION_VARIABLES.items():
        shape = tuple(sizes[d] for d in dims)
        out[k] = np.full(shape, np.nan) if dtype == "f8" else np.full(shape, 1 if k == "status" else -1, dtype=dtype)
    return out


def _transition_epoch(orbit, epoch_tdb: float, revolutions: int, nodes_per_rev: int, path: str | None, sizes: dict) -> dict:
    """One epoch's transition (a task, picklable for Dask): its per-epoch arrays, or status 1
    and NaN arrays with ``reason`` when the multiple shooting did not converge."""
    from .._errors import ConvergenceError
    from ..orbits.transition import to_ephemeris

    eph = _ephemeris(path)
    try:
        r = to_ephemeris(orbit, epoch_tdb, revolutions=revolutions, nodes_per_rev=nodes_per_rev, ephemeris=eph)
    except ConvergenceError as err:
        return {**_failed(sizes), "reason": f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}"}
    t_track, x_track = _sampled(r, eph)
    mu = orbit.system.mu
    track = np.array([eph.ephemeris_to_synodic(x, float(t), mu) for t, x in zip(t_track, x_track)])
    out = {"status": np.uint8(0), "iterations": np.int64(r.iterations), "max_departure_km": float(r.max_departure_km),
           "drift_km_per_rev": float(r.drift_km_per_rev), "node_epochs_tdb": np.asarray(r.epochs_tdb, dtype=float),
           "states_km": np.asarray(r.states_km, dtype=float), "synodic": np.asarray(r.synodic(), dtype=float),
           "defects_km": np.asarray(r.defects_km, dtype=float), "defects_km_s": np.asarray(r.defects_km_s, dtype=float),
           "perilune_km": np.asarray(r.perilune_km, dtype=float), "track_t_tdb": t_track, "track_synodic": track}
    from ..results.kinds import TRANSITION_VARIABLES

    for k, (_, dims, _) in TRANSITION_VARIABLES.items():
        want = tuple(sizes[d] for d in dims)
        if np.shape(out[k]) != want:
            raise ValueError(f"the transition at {epoch_tdb!r} s TDB gave {k} of shape {np.shape(out[k])}, the store holds {want}")
    return out


def _sampled(r, eph) -> tuple[np.ndarray, np.ndarray]:
    """The continuous trajectory of the EphemerisOrbit ``r`` at PER_LEG equal steps of every
    leg (each leg propagated from its node), the last node included: (t_tdb, states_km)."""
    from ..ephemeris.model import propagate_ephemeris

    t, x = np.asarray(r.epochs_tdb, dtype=float), np.asarray(r.states_km, dtype=float)
    ts, xs = [], []
    for i in range(t.size - 1):
        dt = float(t[i + 1] - t[i])
        leg = propagate_ephemeris(x[i], float(t[i]), dt, ephemeris=eph, t_eval=dt * np.arange(PER_LEG) / PER_LEG)
        ts.append(leg.t_tdb)
        xs.append(leg.states_km)
    return np.concatenate([*ts, t[-1:]]), np.concatenate([*xs, x[-1:]])


def _fingerprint(orbit, epochs, revolutions: int, nodes_per_rev: int, eph_digest: str) -> str:
    from .._core import __version__

    h = hashlib.sha256()
    for a in (orbit.state0, [orbit.period, orbit.system.mu, orbit.system.lu_km, orbit.system.tu_s], epochs):
        h.update(np.asarray(a, dtype=np.float64).tobytes())
    h.update(json.dumps([int(revolutions), int(nodes_per_rev), eph_digest, PER_LEG, __version__]).encode())
    return h.hexdigest()


def _file_digest(path: str | None) -> tuple[str, str]:
    """(name, BLAKE2b digest) of the SPK file (None: the embedded excerpt)."""
    from ..ephemeris.spk import embedded_spk_path

    p = Path(embedded_spk_path() if path is None else path)
    h = hashlib.blake2b(digest_size=16)
    with open(p, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return ("embedded DE440 excerpt " + p.name if path is None else str(p)), h.hexdigest()


def _cr3bp_track(orbit) -> np.ndarray:
    """The CR3BP orbit over one period at CR3BP_SAMPLES epochs (synodic, nondimensional)."""
    from ..orbits.propagation import propagate

    t = np.linspace(0.0, orbit.period, CR3BP_SAMPLES)
    return np.asarray(propagate(orbit.system, orbit.state0, orbit.period, t_eval=t, rtol=1e-12, atol=1e-12).y, dtype=float)


def run_transition_to(orbit, store: str | Path, *, epochs_tdb, revolutions: int, nodes_per_rev: int | None = None,
                      ephemeris_file: str | None = None,
                      resume: bool = True, scheduler=None, progress: bool | None = None, attrs: dict[str, Any] | None = None):
    """The transitions of ``orbit`` (a :class:`~librate.PeriodicOrbit`) at every epoch of
    ``epochs_tdb`` (TDB s past J2000) over ``revolutions``, written to ``store`` (a ``.zarr`` part
    store, or a ``.nc`` file exported whole at the end from ``<store>.parts``). See the module
    docstring for resuming, faults and ``scheduler``. An existing ``store`` of the same inputs is
    resumed or reused; of others it is refused unless ``resume`` is False (then the new result is
    computed aside and replaces the old one once complete). Returns ``(dataset, store_path)``."""
    import warnings

    from ..ephemeris.epochs import iso_tdb
    from ..orbits.periodic import PeriodicOrbit
    from ..results.atomic import clean_orphans, remove_path, temporary_sibling
    from ..results.kinds import transition_schema
    from ..results.lock import writer_lock
    from ..results.store import PartStore, store_kind
    from .distribute import ArrivalError, Region, Task, run_tasks
    from .progress import bar as progress_bar
    from .results import check_output, open_result, publish_parts

    store = Path(store)
    attrs = dict(attrs or {})
    # the orbit's public fields only: what a corrector keeps for itself does not pickle (Dask)
    orbit = PeriodicOrbit(orbit.system, np.asarray(orbit.state0, dtype=float), float(orbit.period), float(orbit.jacobi), orbit.family,
                          orbit.iterations, orbit.residual)
    epochs = np.atleast_1d(np.asarray(epochs_tdb, dtype=float))
    npr = nodes_per_rev_for(orbit, nodes_per_rev)
    sizes = transition_sizes(int(revolutions), npr)
    eph_path = None if ephemeris_file is None else str(ephemeris_file)
    eph_name, eph_digest = _file_digest(eph_path)
    state = check_output(store, "transition", attrs.get("study"), force=not resume)
    with writer_lock(store) as lock:
        clean_orphans(store)
        if state == "resume" and store_kind(store) is None:  # a .nc written whole: reused
            return open_result(store, verify=True).load(), store
        parts = store if store.suffix == ".zarr" else store.with_name(store.name + ".parts")
        if state == "replace" and parts == store:
            parts = temporary_sibling(store)
        if state == "replace":
            remove_path(parts)
        coords = {"epoch": ("epoch", epochs, {"units": "s", "long_name": "epoch of the first node, TDB seconds past J2000"}),
                  **{d: (d, np.arange(sizes[d]), {}) for d in ("node", "leg", "revolution", "sample")},
                  "component": ("component", np.array(COMPONENTS), {})}
        schema = transition_schema(epochs.size, sizes, coords)
        pstore, damaged = PartStore.open(parts, schema, _fingerprint(orbit, epochs, revolutions, npr, eph_digest), attrs=attrs, lock=lock)
        if damaged:
            warnings.warn(f"{parts}: {len(damaged)} damaged epoch(s) are recomputed: "
                          + "; ".join(f"epoch {i}: {why}" for i, why in sorted(damaged.items())), RuntimeWarning, stacklevel=2)
        done = pstore.done_flags(damaged)
        failures = dict(json.loads(pstore.g.attrs.get("failures", "{}")))
        todo = [Task(j, _transition_epoch, (orbit, float(epochs[j]), int(revolutions), npr, eph_path, sizes))
                for j in range(epochs.size) if not done[j]]

        def commit(j, part):
            if "reason" in part:
                failures[str(j)] = part["reason"]
            pstore.write_part(j, part)
            done[j] = True
            bar.update(1)

        def commit_written(j, sums):
            if not pstore.commit_written(j, sums):
                raise ArrivalError(f"epoch {j}: the region written by a worker does not match its digests")
            done[j] = True
            bar.update(1)

        with progress_bar(epochs.size, "ephemeris transitions", "epoch", progress, initial=int(done.sum())) as bar:
            try:
                run_tasks(todo, commit, scheduler=scheduler, region=None if scheduler is None else Region.of(pstore, lock),
                          commit_written=commit_written)
            except KeyboardInterrupt as err:  # the finished epochs are kept
                raise KeyboardInterrupt(f"transition interrupted ({err}); {int(done.sum())} finished epoch(s) kept in {parts}") from None
        # a failure written by a worker's region carries no reason back: its status says it
        status = pstore.read("status")
        failures = {k: v for k, v in failures.items() if status[int(k)] == 1}
        failures.update({str(j): "did not converge" for j in np.flatnonzero(status == 1) if str(j) not in failures})
        from .. import _core

        system = orbit.system
        final = {**attrs, "librate_result": "transition", "title": "librate orbit transition into the ephemeris model",
                 "mu": float(system.mu), "lu_km": float(system.lu_km), "tu_s": float(system.tu_s), "system_name": str(system.name),
                 "orbit_family": str(getattr(orbit, "family", "")), "orbit_period": float(orbit.period),
                 "orbit_period_days": float(orbit.period_days),
                 "revolutions": int(revolutions), "nodes_per_rev": int(npr), "samples_per_leg": PER_LEG,
                 "epochs_iso": json.dumps([iso_tdb(float(t)) for t in epochs]), "frames": FRAMES, "time_scale": "TDB",
                 "ephemeris_file": eph_name, "ephemeris_digest": eph_digest,
                 "ephemeris_span_tdb": [float(v) for v in _ephemeris(eph_path).span],
                 "gm_km3_s2": [float(_core.GM_EARTH), float(_core.GM_MOON), float(_core.GM_SUN)], "gm_bodies": "earth moon sun (DE440)",
                 "failures": json.dumps(failures, sort_keys=True)}
        arrays = {"orbit_state0": (("component",), np.asarray(orbit.state0, dtype=float),
                                   {"units": "LU, LU/TU", "long_name": "CR3BP orbit initial state"}),
                  "cr3bp_synodic": (("cr3bp_sample", "component"), _cr3bp_track(orbit),
                                    {"units": "LU, LU/TU", "long_name": "the CR3BP orbit over one period, synodic frame"})}
        pstore.finalise(arrays, final, complete=True)
        publish_parts(parts, store, lock)
        return open_result(store).load(), store


def transition_summary(ds, elapsed: float) -> list[str]:
    """The table ``librate transition`` prints: one line per epoch (iterations, the largest node
    defects, the largest departure from the CR3BP orbit, the perilune range), then the failures."""
    epochs = json.loads(ds.attrs.get("epochs_iso", "[]"))
    n = ds.sizes["epoch"]
    ok = np.asarray(ds["status"].values) == 0
    out = [f"{ds.attrs.get('orbit_family') or 'orbit'} (T = {float(ds.attrs['orbit_period_days']):.4f} d) into the ephemeris model "
           f"({ds.attrs.get('ephemeris_file')}): {n} epoch(s), {int(ok.sum())} converged, {ds.attrs['revolutions']} revolutions, "
           f"{ds.attrs['nodes_per_rev']} nodes per revolution ({elapsed:.2f} s)",
           f"{'epoch (TDB)':<27} {'iter':>4} {'max defect [m]':>14} {'[km/s]':>9} {'max departure [km]':>18} {'perilune [km]':>23} "
           f"{'drift [km/rev]':>14}"]
    for j in range(n):
        label = epochs[j][:19] if j < len(epochs) else f"{float(ds['epoch'].values[j]):.1f} s"
        if not ok[j]:
            out.append(f"{label:<27} did not converge")
            continue
        per = ds["perilune_km"].values[j]
        out.append(f"{label:<27} {int(ds['iterations'].values[j]):>4d} {1e3 * np.max(ds['defects_km'].values[j]):>14.2e} "
                   f"{np.max(ds['defects_km_s'].values[j]):>9.1e} {float(ds['max_departure_km'].values[j]):>18.1f} "
                   f"{np.min(per):>10.1f} .. {np.max(per):<10.1f} {float(ds['drift_km_per_rev'].values[j]):>14.2f}")
    for j, why in sorted(json.loads(ds.attrs.get("failures", "{}")).items(), key=lambda kv: int(kv[0])):
        out.append(f"  epoch {j}: {why}")
    return out
