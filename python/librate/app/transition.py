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

With ``attitudes`` (CR3BP periodic attitude solutions on the orbit), each epoch's task also
carries every solution along the epoch's ephemeris orbit (:func:`librate.attitude_to_ephemeris`,
corrected) and adds its nodes, defects and deviation figures to the epoch's part (dimensions
``attitude`` and ``attitude_sample``). A correction that does not converge keeps the orbit and
marks that solution ``attitude_status = 1`` (its reason in ``attitude_failures``, keyed
"epoch/solution").
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import numpy as np

from ..orbits.transition import nodes_per_rev_for

__all__ = ["ANGLES", "ATTITUDE_PER_LEG", "COMPONENTS", "CR3BP_SAMPLES", "PER_LEG", "run_transition_to", "transition_sizes",
           "transition_summary"]

#: The state components (position, then velocity).
COMPONENTS = ("x", "y", "z", "vx", "vy", "vz")
#: Samples per leg of the stored ephemeris trajectory (the rotating-frame figure).
PER_LEG = 8
#: Samples of the stored CR3BP orbit over one period (the rotating-frame figure).
CR3BP_SAMPLES = 400
#: Samples per leg of the stored attitude deviation figures (attitude_to_ephemeris's samples_per_leg).
ATTITUDE_PER_LEG = 8
#: The attitude angles stored (EphemerisAttitude.angles_deg), and the components of a quaternion and of a body vector.
ANGLES, QUATERNION, AXES = ("roll", "pitch", "yaw"), ("x", "y", "z", "w"), ("x", "y", "z")
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


def transition_sizes(revolutions: int, nodes_per_rev: int, attitudes: int = 0) -> dict[str, int]:
    """The lengths of an epoch's dimensions: node, leg, revolution, sample, component; with
    ``attitudes`` solutions also attitude, attitude_sample, quaternion, axis and angle."""
    nodes = revolutions * nodes_per_rev + 1
    out = {"node": nodes, "leg": nodes - 1, "revolution": revolutions, "sample": (nodes - 1) * PER_LEG + 1, "component": 6}
    if attitudes:
        out.update({"attitude": int(attitudes), "attitude_sample": (nodes - 1) * ATTITUDE_PER_LEG + 1, "quaternion": 4, "axis": 3,
                    "angle": 3})
    return out


def _failed(sizes: dict, names=None, status: int = 1) -> dict:
    """NaN arrays (counts -1, flags ``status``) of the variables ``names`` (default all)."""
    from ..results.kinds import transition_variables

    out = {}
    for k, (dtype, dims, _) in transition_variables("attitude" in sizes).items():
        if names is not None and k not in names:
            continue
        shape = tuple(sizes[d] for d in dims)
        out[k] = np.full(shape, np.nan) if dtype == "f8" else np.full(shape, status if dtype == "u1" else -1, dtype=dtype)
    return out


def _attitude_parts(r, attitudes, sizes: dict) -> tuple[dict, dict]:
    """Every solution of ``attitudes`` carried along the EphemerisOrbit ``r`` and corrected
    (:func:`librate.attitude_to_ephemeris`): the epoch's attitude arrays, and the reason of each
    solution whose correction did not converge ({index: reason})."""
    from .._errors import ConvergenceError
    from ..periodicity.ephemeris_attitude import attitude_to_ephemeris
    from ..results.kinds import TRANSITION_ATTITUDE_VARIABLES

    out = _failed(sizes, TRANSITION_ATTITUDE_VARIABLES)
    reasons = {}
    for k, sol in enumerate(attitudes):
        try:
            a = attitude_to_ephemeris(sol, r, correct=True, samples_per_leg=ATTITUDE_PER_LEG)
        except ConvergenceError as err:
            out["attitude_status"][k] = 1
            reasons[k] = f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}"
            continue
        cr3bp, eph = a.angles_deg()
        row = {"attitude_status": 0, "attitude_iterations": a.iterations, "attitude_q": a.q, "attitude_w": a.w,
               "attitude_defect_rad": a.defect_rad, "attitude_defect_rate": a.defect_rate, "attitude_growth": a.growth,
               "attitude_max_pointing_deg": a.max_pointing_error_deg, "attitude_placed_max_pointing_deg": a.placed_max_pointing_error_deg,
               "attitude_pointing_deg": a.pointing_error_deg, "attitude_placed_pointing_deg": a.placed_pointing_error_deg,
               "attitude_rate_error": a.rate_error, "attitude_angles_deg": eph, "attitude_cr3bp_angles_deg": cr3bp}
        for name, v in row.items():
            out[name][k] = v
        out["attitude_t_tdb"] = np.asarray(a.t_tdb, dtype=float)  # the same for every solution (NaN when none was corrected)
    return out, reasons


def _transition_epoch(orbit, epoch_tdb: float, revolutions: int, nodes_per_rev: int, path: str | None, sizes: dict, attitudes=()) -> dict:
    """One epoch's transition (a task, picklable for Dask): its per-epoch arrays, or status 1
    and NaN arrays with ``reason`` when the multiple shooting did not converge (its attitudes
    then status 2); with ``attitudes``, their arrays and ``attitude_reasons`` ({index: reason})."""
    from .._errors import ConvergenceError
    from ..orbits.transition import to_ephemeris

    eph = _ephemeris(path)
    try:
        r = to_ephemeris(orbit, epoch_tdb, revolutions=revolutions, nodes_per_rev=nodes_per_rev, ephemeris=eph)
    except ConvergenceError as err:
        from ..results.kinds import TRANSITION_ATTITUDE_VARIABLES, TRANSITION_VARIABLES

        failed = {**_failed(sizes, TRANSITION_VARIABLES), **(_failed(sizes, TRANSITION_ATTITUDE_VARIABLES, status=2) if attitudes else {})}
        return {**failed, "reason": f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}"}
    t_track, x_track = _sampled(r, eph)
    mu = orbit.system.mu
    track = np.array([eph.ephemeris_to_synodic(x, float(t), mu) for t, x in zip(t_track, x_track)])
    out = {"status": np.uint8(0), "iterations": np.int64(r.iterations), "max_departure_km": float(r.max_departure_km),
           "drift_km_per_rev": float(r.drift_km_per_rev), "node_epochs_tdb": np.asarray(r.epochs_tdb, dtype=float),
           "states_km": np.asarray(r.states_km, dtype=float), "synodic": np.asarray(r.synodic(), dtype=float),
           "defects_km": np.asarray(r.defects_km, dtype=float), "defects_km_s": np.asarray(r.defects_km_s, dtype=float),
           "perilune_km": np.asarray(r.perilune_km, dtype=float), "track_t_tdb": t_track, "track_synodic": track}
    if attitudes:
        parts, reasons = _attitude_parts(r, attitudes, sizes)
        out.update(parts)
        if reasons:
            out["attitude_reasons"] = reasons
    from ..results.kinds import transition_variables

    for k, (_, dims, _) in transition_variables(bool(attitudes)).items():
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


def _fingerprint(orbit, epochs, revolutions: int, nodes_per_rev: int, eph_digest: str, attitudes=()) -> str:
    """The digest of every input (a transition without attitudes: as before they were added,
    so its old stores resume)."""
    from .._core import __version__

    h = hashlib.sha256()
    for a in (orbit.state0, [orbit.period, orbit.system.mu, orbit.system.lu_km, orbit.system.tu_s], epochs):
        h.update(np.asarray(a, dtype=np.float64).tobytes())
    h.update(json.dumps([int(revolutions), int(nodes_per_rev), eph_digest, PER_LEG, __version__]).encode())
    for sol in attitudes:
        h.update(json.dumps([type(sol).__name__, ATTITUDE_PER_LEG, *_attitude_inputs(sol)]).encode())
    return h.hexdigest()


def _attitude_inputs(sol) -> list:
    """What defines a CR3BP attitude solution (its body, start and periods), as plain numbers."""
    if hasattr(sol, "wz0"):  # planar
        return [float(sol.kz), float(sol.phi0), float(sol.wz0), int(sol.n_periods), float(sol.n), str(sol.kind)]
    return [*map(float, sol.body.moments), *map(float, sol.q0), *map(float, sol.w0), int(sol.n_periods)]


def _body_moments(sol) -> tuple:
    """The principal moments of a solution's body (a planar one: normalised from its Kz)."""
    from ..attitude.body import RigidBody

    return tuple(sol.body.moments) if hasattr(sol, "body") else tuple(RigidBody.from_kz(float(sol.kz)).moments)


def _attitude_table(attitudes, attitude_n) -> dict:
    """The arrays over ``attitude`` written at the end: N, the periods, stability and start of each solution."""
    planar = [hasattr(s_, "wz0") for s_ in attitudes]
    out = {"attitude_n": (("attitude",), np.asarray(attitude_n, dtype=np.int64), {"long_name": "N: net turns per attitude period"}),
           "attitude_n_periods": (("attitude",), np.array([int(s_.n_periods) for s_ in attitudes], dtype=np.int64),
                                  {"long_name": "orbit periods per attitude period of the CR3BP solution"}),
           "attitude_stable": (("attitude",), np.array([int(bool(s_.stable)) for s_ in attitudes], dtype=np.int64),
                               {"long_name": "the CR3BP solution is linearly stable (1) or not (0)"})}
    if all(planar):
        out["attitude_wz0"] = (("attitude",), np.array([s_.wz0 for s_ in attitudes]),
                               {"units": "1/TU", "long_name": "CR3BP initial inertial rate"})
        out["attitude_phi0"] = (("attitude",), np.array([s_.phi0 for s_ in attitudes]),
                                {"units": "rad", "long_name": "CR3BP initial angle"})
        out["attitude_kz"] = (("attitude",), np.array([s_.kz for s_ in attitudes]), {"long_name": "Kz = (Iy - Ix) / Iz"})
    else:
        out["attitude_q0"] = (("attitude", "quaternion"), np.array([s_.q0 for s_ in attitudes], dtype=float),
                              {"long_name": "CR3BP initial attitude, body relative to the synodic frame, scalar last"})
        out["attitude_w0"] = (("attitude", "axis"), np.array([s_.w0 for s_ in attitudes], dtype=float),
                              {"units": "1/TU", "long_name": "CR3BP initial inertial rate, body axes"})
    return out


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
                      resume: bool = True, scheduler=None, progress: bool | None = None, attrs: dict[str, Any] | None = None,
                      attitudes=(), attitude_n=None):
    """The transitions of ``orbit`` (a :class:`~librate.PeriodicOrbit`) at every epoch of
    ``epochs_tdb`` (TDB s past J2000) over ``revolutions``, written to ``store`` (a ``.zarr`` part
    store, or a ``.nc`` file exported whole at the end from ``<store>.parts``). See the module
    docstring for resuming, faults and ``scheduler``. An existing ``store`` of the same inputs is
    resumed or reused; of others it is refused unless ``resume`` is False (then the new result is
    computed aside and replaces the old one once complete). ``attitudes``: CR3BP periodic
    attitude solutions on ``orbit`` (:class:`~librate.AttitudeSolution` or
    :class:`~librate.AttitudeSolution3D`, gravity gradient) carried at every epoch, ``attitude_n``
    their N (default each planar solution's ``n``). Returns ``(dataset, store_path)``."""
    import dataclasses
    import warnings

    from ..ephemeris.epochs import iso_tdb
    from ..orbits.periodic import PeriodicOrbit
    from ..results.atomic import clean_orphans, remove_path, temporary_sibling
    from ..results.kinds import transition_schema
    from ..results.lock import writer_lock
    from ..results.store import PartStore, store_kind
    from .distribute import PartCommits, Region, Task, run_tasks
    from .progress import bar as progress_bar
    from .results import check_output, open_result, publish_parts

    store = Path(store)
    attrs = dict(attrs or {})
    # the orbit's public fields only: what a corrector keeps for itself does not pickle (Dask)
    orbit = PeriodicOrbit(orbit.system, np.asarray(orbit.state0, dtype=float), float(orbit.period), float(orbit.jacobi), orbit.family,
                          orbit.iterations, orbit.residual)
    attitudes = [dataclasses.replace(s_, orbit=orbit) for s_ in attitudes]  # on the picklable orbit
    if attitude_n is None:
        attitude_n = [int(getattr(s_, "n", 0)) for s_ in attitudes]
    if len(attitude_n) != len(attitudes):
        raise ValueError(f"invalid argument `attitude_n`: one N per solution of `attitudes` ({len(attitudes)}), got {len(attitude_n)}")
    epochs = np.atleast_1d(np.asarray(epochs_tdb, dtype=float))
    npr = nodes_per_rev_for(orbit, nodes_per_rev)
    sizes = transition_sizes(int(revolutions), npr, len(attitudes))
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
        if attitudes:
            coords.update({d: (d, np.arange(sizes[d]), {}) for d in ("attitude", "attitude_sample")})
            coords.update({"quaternion": ("quaternion", np.array(QUATERNION), {}), "axis": ("axis", np.array(AXES), {}),
                           "angle": ("angle", np.array(ANGLES), {})})
        schema = transition_schema(epochs.size, sizes, coords)
        pstore, damaged = PartStore.open(parts, schema, _fingerprint(orbit, epochs, revolutions, npr, eph_digest, attitudes), attrs=attrs,
                                         lock=lock)
        if damaged:
            warnings.warn(f"{parts}: {len(damaged)} damaged epoch(s) are recomputed: "
                          + "; ".join(f"epoch {i}: {why}" for i, why in sorted(damaged.items())), RuntimeWarning, stacklevel=2)
        done = pstore.done_flags(damaged)
        failures = dict(json.loads(pstore.g.attrs.get("failures", "{}")))
        att_failures = dict(json.loads(pstore.g.attrs.get("attitude_failures", "{}")))
        extra = (tuple(attitudes),) if attitudes else ()
        todo = [Task(j, _transition_epoch, (orbit, float(epochs[j]), int(revolutions), npr, eph_path, sizes, *extra))
                for j in range(epochs.size) if not done[j]]

        def note(j, part):
            """An epoch's part, its failure reasons noted (they go into the result's attributes)."""
            if "reason" in part:
                failures[str(j)] = part["reason"]
            for k, why in part.get("attitude_reasons", {}).items():
                att_failures[f"{j}/{k}"] = why
            return j, part

        with progress_bar(epochs.size, "ephemeris transitions", "epoch", progress, initial=int(done.sum())) as bar:
            commits = PartCommits(pstore, done, "epoch", bar, note)
            try:
                run_tasks(todo, commits.commit, scheduler=scheduler, region=None if scheduler is None else Region.of(pstore, lock),
                          commit_written=commits.commit_written)
            except KeyboardInterrupt as err:  # the finished epochs are kept
                raise KeyboardInterrupt(f"transition interrupted ({err}); {int(done.sum())} finished epoch(s) kept in {parts}") from None
        # a failure written by a worker's region carries no reason back: its status says it
        status = pstore.read("status")
        failures = {k: v for k, v in failures.items() if status[int(k)] == 1}
        failures.update({str(j): "did not converge" for j in np.flatnonzero(status == 1) if str(j) not in failures})
        if attitudes:
            a_status = pstore.read("attitude_status")
            att_failures = {k: v for k, v in att_failures.items() if a_status[tuple(map(int, k.split("/")))] == 1}
            att_failures.update({f"{j}/{k}": "did not converge" for j, k in zip(*np.nonzero(a_status == 1))
                                 if f"{j}/{k}" not in att_failures})
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
        if attitudes:
            final.update({"attitude_failures": json.dumps(att_failures, sort_keys=True), "attitude_samples_per_leg": ATTITUDE_PER_LEG,
                          "attitude_model": "3d" if not hasattr(attitudes[0], "wz0") else "planar",
                          "attitude_body_moments": [float(v) for v in _body_moments(attitudes[0])],
                          "attitude_frames": "attitude_q: body -> Moon-centred ICRF, scalar last, attitude_w: inertial, body axes (rad/s); "
                                             "angles and pointing errors relative to the instantaneous rotating frame"})
        arrays = {"orbit_state0": (("component",), np.asarray(orbit.state0, dtype=float),
                                   {"units": "LU, LU/TU", "long_name": "CR3BP orbit initial state"}),
                  "cr3bp_synodic": (("cr3bp_sample", "component"), _cr3bp_track(orbit),
                                    {"units": "LU, LU/TU", "long_name": "the CR3BP orbit over one period, synodic frame"})}
        if attitudes:
            arrays.update(_attitude_table(attitudes, attitude_n))
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
    if "attitude_status" in ds.variables:
        out += _attitude_summary(ds)
    return out


def _attitude_summary(ds) -> list[str]:
    """Per attitude solution: at how many epochs it was corrected, the largest pointing error
    (corrected, and placed without correction), the corrected motion's largest defects and the
    largest span growth; then the failed corrections."""
    status = np.asarray(ds["attitude_status"].values)
    out = [f"attitude in the ephemeris model ({ds.sizes['attitude']} CR3BP solution(s), {ds.attrs.get('attitude_model', 'planar')}):"]
    for k in range(ds.sizes["attitude"]):
        ok = status[:, k] == 0
        n = int(ds["attitude_n"].values[k])
        rate = f", wz0 = {float(ds['attitude_wz0'].values[k]):.6g} 1/TU" if "attitude_wz0" in ds.variables else ""
        head = f"  N = {n}{rate} ({'stable' if int(ds['attitude_stable'].values[k]) else 'unstable'} in the CR3BP): "
        if not ok.any():
            out.append(head + f"corrected at no epoch of {ok.size}")
            continue
        names = ("attitude_max_pointing_deg", "attitude_placed_max_pointing_deg", "attitude_defect_rad", "attitude_defect_rate",
                 "attitude_growth")
        big = {name: np.max(np.asarray(ds[name].values)[ok, k]) for name in names}
        out.append(head + f"corrected at {int(ok.sum())}/{ok.size} epochs; largest pointing error "
                   f"{big['attitude_max_pointing_deg']:.3g} deg "
                   f"(placed, uncorrected: {big['attitude_placed_max_pointing_deg']:.3g} deg); largest defects "
                   f"{big['attitude_defect_rad']:.1e} rad, {big['attitude_defect_rate']:.1e} in rate; "
                   f"span growth up to {big['attitude_growth']:.3g}")
    for key, why in sorted(json.loads(ds.attrs.get("attitude_failures", "{}")).items(), key=lambda kv: tuple(map(int, kv[0].split("/")))):
        j, k = map(int, key.split("/"))
        out.append(f"  epoch {j}, N = {int(ds['attitude_n'].values[k])}: {why}")
    return out
