"""Results on disk: orbit families, periodic-solution tables and periodicity maps.

Every result is an xarray Dataset written as Zarr (a ``.zarr`` folder, chunked) or netCDF (a
``.nc`` file) whose attributes carry ``librate_result`` ("family", "solutions", "solutions_3d"
or "map"), the
full study as JSON (``study``) and the package version (``librate_version``), next to the units
of every variable. :func:`open_result` reloads any of them without recomputing. Writing is
all-or-nothing (into a temporary sibling, then renamed), and an existing path that is not a
librate result is refused, never overwritten.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ..results.atomic import remove_path, replace_path
from ..results.files import is_zarr as _is_zarr
from ..results.files import open_dataset as _open_dataset
from ..results.files import verify_dataset, write_dataset
from ..results.kinds import KINDS, Solutions3DResult, kind_of
from ..results.lock import writer_lock
from ..results.store import STORE_ATTRS, store_kind, verify_store

__all__ = ["RESULT_INPUTS", "RESULT_KINDS", "RESULT_STEMS", "ResultExists", "check_output", "describe_result", "open_result",
           "multipliers_3d", "publish_parts", "read_attrs", "result_kind", "run_map_to", "save_dataset",
           "save_family", "solution_3d",
           "solutions_3d_dataset", "solutions_dataset",
           "study_changes", "verify_result"]

#: The kinds of result, as stored in the ``librate_result`` attribute.
RESULT_KINDS = tuple(KINDS)
#: The file each command writes its result to (``<stem>.zarr`` or ``<stem>.nc``): the name says
#: which command made it. Its figures are ``<stem>_<figure>.png`` beside it.
RESULT_STEMS = {"family": "family", "solve": "solve", "map": "map", "demo": "demo", "transition": "transition"}
#: The study sections each kind of result depends on: a change elsewhere (e.g. ``output``, or
#: ``body`` for a family) leaves the result valid, so it is resumed rather than refused.
RESULT_INPUTS = {k: c.inputs for k, c in KINDS.items()}
# older names, still read: solutions.* (librate solve before 0.2), dro_map_kz*.nc (librate demo)
_NAMES = tuple(f"{stem}{ext}" for stem in (*RESULT_STEMS.values(), "solutions") for ext in (".zarr", ".nc"))


def result_kind(ds) -> str | None:
    """The kind of a librate result Dataset (``librate_result``, or recognised from its
    variables for files written without it, see :func:`librate.results.kinds.kind_of`), else None."""
    cls = kind_of(ds)
    return None if cls is None else cls.kind


def resolve_result_path(path: str | Path) -> Path:
    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(f"no result at {str(p)!r}")
    if p.is_dir() and not _is_zarr(p):
        found = [p / n for n in _NAMES if (p / n).exists()] + sorted(p.glob("dro_map_kz*.nc"))
        # a map.nc exported beside its map.zarr is the same result: the .zarr stands for both
        found = [f for f in found if not (f.suffix == ".nc" and f.with_suffix(".zarr") in found)]
        if len(found) == 1:
            return found[0]
        if not found:
            raise ValueError(f"{str(p)!r} is a folder with no librate result in it (looked for {', '.join(_NAMES)}) and not a Zarr store")
        raise ValueError(f"{str(p)!r} holds several results ({', '.join(f.name for f in found)}): give one of them")
    return p


def study_changes(old: str | dict | None, new: str | dict | None, sections: tuple[str, ...] | None = None) -> list[str]:
    """The study keys that differ between two studies (JSON text or dicts), as
    ``"body.kz: 0.8 -> 0.5"`` lines in key order (tables flattened: ``rates.wz0.num: 300 -> 50``); only the keys under ``sections`` count
    (all when None). A missing study (a result saved by the Python API) differs in ``(study)``."""
    import json

    if old is None or new is None:
        return [] if old is new else ["(study): none recorded in the existing result"]
    a = json.loads(old) if isinstance(old, str) else old
    b = json.loads(new) if isinstance(new, str) else new

    def flat(d, prefix=""):
        out = {}
        for k, v in d.items():
            key = f"{prefix}{k}"
            if isinstance(v, dict) and v:
                out.update(flat(v, key + "."))
            else:
                out[key] = v
        return out

    fa, fb = flat(a), flat(b)
    keep = (lambda k: True) if sections is None else (lambda k: k.split(".", 1)[0] in sections)
    show = lambda v: "(unset)" if v is None else json.dumps(v)
    return [f"{k}: {show(fa.get(k))} -> {show(fb.get(k))}" for k in sorted(set(fa) | set(fb)) if keep(k) and fa.get(k) != fb.get(k)]


class ResultExists(FileExistsError):
    """The output path holds a librate result that a run would replace: from other inputs
    (``changes`` names the keys), or of another kind. Re-run with ``force=True`` (``--force``)."""

    def __init__(self, message: str, changes: list[str] | None = None):
        super().__init__(message)
        self.changes = list(changes or [])


def describe_result(path: str | Path) -> str:
    """One line on a saved result: its kind, size and the librate version that wrote it."""
    try:
        ds = _open_dataset(Path(path))
    except ValueError:
        return f"{path} (unreadable)"
    try:
        cls = kind_of(ds)
        return f"{path} ({cls(ds).summary() if cls is not None else 'a librate result of unknown kind'})"
    finally:
        ds.close()


def check_output(path: str | Path, kind: str, study: str | None, *, force: bool = False, say: Callable[[str], None] | None = None) -> str:
    """Decide what a run may do with its output ``path`` (a ``.zarr`` or ``.nc`` result of
    ``kind``; ``study``: the run's study as JSON). Returns ``"new"`` (nothing there),
    ``"resume"`` (a result of the same kind from the same inputs: continue or reuse it; only
    keys that do not change this result, such as ``output.*``, may differ) or ``"replace"``
    (``force``: the existing result is replaced, after ``say`` names it). Raises
    :class:`ResultExists` naming the changed study keys, or ``FileExistsError`` when the path
    holds something that is not a librate result (refused even with ``force``)."""
    p = Path(path)
    if not p.exists():
        return "new"
    if p.is_dir() and not any(p.iterdir()):
        return "new"
    found = _existing_result(p)
    if found is None:
        raise FileExistsError(f"{str(p)!r} exists and is not a librate result: refusing to overwrite it; remove it or choose "
                              "another output folder")
    old_kind, attrs = found
    old_study = attrs.get("study")
    changes = []
    if old_kind != kind:
        changes.append(f"(result): a {old_kind or 'result of unknown kind'} -> a {kind}")
    else:
        changes += study_changes(old_study, study, _inputs(kind, old_study, study))
        if old_study is not None and study is not None:
            from .._core import __version__

            old_version = attrs.get("librate_version")
            if old_version is not None and str(old_version) != __version__:
                changes.append(f"librate version: {old_version} -> {__version__}")
    if force:
        if say is not None:
            say(f"--force: replacing {describe_result(p)}" + (f"; changed: {'; '.join(changes)}" if changes else ""))
        return "replace"
    if not changes:
        return "resume"
    raise ResultExists(f"{p} holds a {old_kind or 'result'} of other inputs (changed: {'; '.join(changes)}): "
                       "not replaced; run again with --force to replace it, or choose another --out", changes)


def _inputs(kind: str, *studies) -> tuple[str, ...] | None:
    """The study sections a result of ``kind`` depends on for either of ``studies`` (JSON text,
    dicts or None; :meth:`librate.results.kinds.ResultKind.inputs_of`), None for an unknown kind."""
    import json

    cls = KINDS.get(kind)
    if cls is None:
        return None
    out: tuple[str, ...] = ()
    for st in studies:
        for k in cls.inputs_of(json.loads(st) if isinstance(st, str) else st):
            out += (k,) if k not in out else ()
    return out


def _existing_result(p: Path) -> tuple[str | None, dict] | None:
    """``(kind, root attributes)`` of the librate result or map store at ``p`` (also an
    unfinished map store, which xarray cannot open yet), or None when it is not one."""
    if _is_zarr(p):
        try:
            import zarr

            attrs = dict(zarr.open_group(str(p), mode="r", use_consolidated=False).attrs)
        except Exception:  # noqa: BLE001 - foreign or damaged: judged below
            attrs = {}
        marker = attrs.get("librate_store")
        if marker in ("periodicity_map", "map_3d", "ephemeris_transition"):
            return {"periodicity_map": "map", "map_3d": "map_3d", "ephemeris_transition": "transition"}[marker], attrs
    try:
        ds = _open_dataset(p)
    except ValueError:
        return None
    try:
        kind = result_kind(ds)
        return None if kind is None else (kind, dict(ds.attrs))
    finally:
        ds.close()


def read_attrs(path: str | Path) -> dict:
    """The attributes of a saved result (``librate_result``, ``study`` as JSON,
    ``librate_version``, units and constants), without loading its data."""
    p = resolve_result_path(path)
    ds = _open_dataset(p)
    try:
        return dict(ds.attrs)
    finally:
        ds.close()


def open_result(path: str | Path, *, verify: bool = False):
    """Reload a saved result without recomputing.

    Parameters
    ----------
    path : str or pathlib.Path
        A ``.zarr`` folder or a ``.nc`` file, or an output folder holding exactly one of map,
        family or solutions.
    verify : bool, default False
        First check the result as `verify_result` does (every chunk against its checksum, every
        map row computed).

    Returns
    -------
    OrbitFamily or xarray.Dataset
        An `OrbitFamily` for a family (through `OrbitFamily.load`); an ``xarray.Dataset`` for a
        periodicity map or a table of periodic solutions, its ``attrs["study"]`` the study as
        JSON when a study made it.

    Raises
    ------
    FileNotFoundError
        Nothing at ``path``.
    ValueError
        Not a librate result, or (with ``verify``) damaged: the message names the damage.

    Examples
    --------
    >>> import librate, numpy as np, tempfile, pathlib
    >>> fam = librate.dro_family(librate.System.preset("earth-moon"), x0=[0.9, 0.8])
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "dros.nc"
    >>> fam.save(path)
    >>> same = librate.open_result(path)
    >>> bool(np.array_equal(same.state0, fam.state0))
    True
    """
    from ..orbits.families import OrbitFamily

    p = resolve_result_path(path)
    if verify:
        ok, report = verify_result(p)
        if not ok:
            raise ValueError(report)
    ds = _open_dataset(p)
    kind = result_kind(ds)
    if kind is None:
        ds.close()
        raise ValueError(f"{str(p)!r} is not a librate result (no librate_result attribute; neither a family, a map nor solutions)")
    if kind == "family":
        ds.close()
        if p.suffix not in (".zarr", ".nc"):
            raise ValueError(f"{str(p)!r}: a saved family must be a .zarr folder or a .nc file")
        return OrbitFamily.load(p)
    drop = [v for v in ("row_checksum", "done") if v in ds.variables and store_kind(p) is not None]
    if drop:  # the part store's bookkeeping, not the result
        ds = ds.drop_vars(drop)
    return KINDS[kind].from_dataset(ds).dataset


def verify_result(path: str | Path) -> tuple[bool, str]:
    """Check a saved result without recomputing it. A part store (``librate map``, planar or
    3-D): every part against its digests and ``done`` flag, every array's metadata, the root
    attributes, the coordinates and the solutions (:func:`librate.results.verify_store`).
    Other results: every chunk is checked before it is decoded (missing, truncated or garbled
    ones named), every variable read and compared with its digests, and the names, dtypes and
    attributes of the variables and the root attributes (the system constants) with theirs.
    Returns ``(ok, report)``; never raises for damage."""
    p = resolve_result_path(path)
    try:
        if _is_zarr(p) and store_kind(p) is not None:
            rep = verify_store(p)
            return rep.ok, rep.describe()
        ds = _open_dataset(p)
    except ValueError as err:
        return False, str(err)
    except Exception as err:  # noqa: BLE001 - whatever a damaged file raises: a report, never a traceback
        return False, f"{p}: damaged librate result ({type(err).__name__}: {err})"
    try:
        kind = result_kind(ds)
        if kind is None:
            return False, f"{str(p)!r} is not a librate result (no librate_result attribute; neither a family, a map nor solutions)"
        try:
            problems, checked, _ = verify_dataset(ds, p)
        except Exception as err:  # noqa: BLE001
            problems, checked = [f"unreadable ({type(err).__name__}: {err})"], True
    finally:
        ds.close()
    if problems:
        return False, f"{p}: damaged librate result\n" + "\n".join(f"  {q}" for q in problems)
    note = (", every variable matches its checksum" if checked
            else " (no checksums stored: written by an older librate; only readability was checked)")
    return True, f"{p}: ok: a librate {kind} result{note}"


def _check_target(p: Path) -> None:
    """Refuse to replace anything that is not a librate result."""
    if not p.exists():
        return
    try:
        ds = _open_dataset(p)
    except Exception as err:  # corrupt or foreign
        raise FileExistsError(f"{str(p)!r} exists and is not a readable librate result ({type(err).__name__}): refusing to overwrite it; "
                              "remove it or choose another output folder") from None
    try:
        if result_kind(ds) is None:
            raise FileExistsError(f"{str(p)!r} exists and is not a librate result: refusing to overwrite it; remove it or choose "
                                  "another output folder")
    finally:
        ds.close()


def save_dataset(ds, path: str | Path, *, lock=None, wait: float = 0.0) -> Path:
    """Write ``ds`` to ``path`` (``.zarr``: Zarr v2 folder, consolidated; ``.nc``: netCDF 3 via
    scipy), creating the folder, with its digests (:func:`librate.results.write_dataset`:
    all or nothing, fsynced, the old result removed only after the new one took its name).
    An existing ``path`` is replaced only if it is a librate result. ``lock``: the writer lock
    of ``path`` when the caller holds it; else it is taken here (waiting up to ``wait``
    seconds for another writer). Returns the path."""
    p = Path(path)
    if p.suffix not in (".zarr", ".nc"):
        raise ValueError(f"invalid argument `path`: must end in .zarr (Zarr) or .nc (netCDF), got {str(p)!r}")
    p.parent.mkdir(parents=True, exist_ok=True)
    if lock is None:
        with writer_lock(p, wait=wait) as held:
            return save_dataset(ds, p, lock=held)
    _check_target(p)
    cls = kind_of(ds)
    write_dataset(cls(ds).to_dataset() if cls is not None and "librate_result" in ds.attrs else ds, p, lock=lock)
    return p


def save_family(family, path: str | Path, attrs: dict | None = None) -> Path:
    """Save an :class:`~librate.OrbitFamily` (``family.to_dataset()``) with extra ``attrs``
    (e.g. the study); :meth:`OrbitFamily.load` and :func:`open_result` read it back."""
    p = Path(path)
    family.save(p, attrs)
    return p


def solutions_dataset(rows, orbits, kz, attrs: dict | None = None):
    """The periodic solutions ``rows`` ((orbit index, AttitudeSolution) pairs) as a Dataset over
    ``solution``, with the orbits (x0, period) and Kz values as coordinates and units."""

    from ..periodicity.maps import map_solutions_dataset

    olist = list(orbits)
    ds = map_solutions_dataset(rows)
    idx = ds["sol_orbit"].values
    x0 = np.array([o.x0 for o in olist])
    per = np.array([o.period for o in olist])
    ds["sol_x0"] = ("solution", x0[idx] if idx.size else np.zeros(0), {"units": "LU"})
    ds["sol_period_days"] = ("solution", np.array([olist[i].period_days for i in idx], dtype=float), {"units": "d"})
    ds["sol_kind"] = ds["sol_kind"].astype("<U9")
    ds = ds.assign_coords(
        orbit=np.arange(len(olist)),
        x0=("orbit", x0, {"units": "LU"}),
        period=("orbit", per, {"units": "TU"}),
        period_days=("orbit", np.array([o.period_days for o in olist]), {"units": "d"}),
        kz=("kz", np.atleast_1d(np.asarray(kz, dtype=float)), {"long_name": "(Iy - Ix) / Iz"}),
    )
    s = [x for _, x in rows]
    ds["sol_n_periods"] = ("solution", np.array([x.n_periods for x in s], dtype=np.int64))
    ds["sol_kz"].attrs["long_name"] = "(Iy - Ix) / Iz"
    ds["sol_n"].attrs["long_name"] = "net body turns per orbit period relative to the synodic frame"
    ds["sol_trace"].attrs["long_name"] = "trace of the 2x2 attitude monodromy (stable when |trace| < 2)"
    ds["sol_residual"].attrs["long_name"] = "max(|Dphi|, |Dwz|) after the n_periods periods, independent re-propagation"
    sys_ = olist[0].system if olist else None
    ds.attrs.update({
        "title": "librate periodic attitude solutions",
        **({"mu": sys_.mu, "lu_km": sys_.lu_km, "tu_s": sys_.tu_s, "system_name": sys_.name} if sys_ else {}),
        **(attrs or {}),
    })
    return ds


def solutions_3d_dataset(family_ds, orbits, period_days, start: dict, attrs: dict | None = None):
    """The result of ``librate solve`` on a 3-D study: the Dataset of
    :func:`librate.attitude_family_3d` (members at the requested ``period_days``, in order, or
    the first ones when the continuation ended early) made self-describing and storable in
    netCDF 3 too.

    Adds, per ``member``: the orbit itself (``orbit_state0`` (member, state), ``orbit_period``
    in TU, ``orbit_jacobi``), corrected by ``orbits.member(period_days=...)`` exactly as the
    continuation did, so every motion can be re-propagated from the file; ``phi0`` (the body x
    axis' angle about Z at t = 0). The complex ``multipliers`` are stored as
    ``multipliers_real`` and ``multipliers_imag`` (:func:`multipliers_3d` joins them). Units
    and long names on every variable. Attributes: those of the family Dataset
    (``stability_changes``, ``end_reason``, ``body_moments``, ``n_periods``), the system
    constants, ``stability_tol``, the start (``start`` and ``start_*``) and ``attrs``."""
    from scipy.spatial.transform import Rotation

    from ..periodicity.attitude3d import STABILITY_TOL

    ds = family_ds.copy()
    m = ds.sizes["member"]
    members = [orbits.member(period_days=float(p)) for p in list(period_days)[:m]]
    mult = ds["multipliers"].values
    ds = ds.drop_vars("multipliers")
    dim = ("member",)
    x_axis = Rotation.from_quat(ds["q0"].values).as_matrix()[:, :, 0]
    ds = ds.assign({
        "multipliers_real": (("member", "k"), mult.real, {"long_name": "Floquet multipliers of the 6x6 attitude monodromy, real part"}),
        "multipliers_imag": (("member", "k"), mult.imag,
                             {"long_name": "Floquet multipliers of the 6x6 attitude monodromy, imaginary part"}),
        "orbit_state0": (("member", "state"), np.array([o.state0 for o in members]).reshape(m, 6),
                         {"units": "LU, LU/TU", "long_name": "orbit initial state (x, y, z, vx, vy, vz), synodic frame"}),
        "orbit_period": (dim, np.array([o.period for o in members]), {"units": "TU"}),
        "orbit_jacobi": (dim, np.array([o.jacobi for o in members]), {"long_name": "Jacobi constant"}),
        "phi0": (dim, np.arctan2(x_axis[:, 1], x_axis[:, 0]),
                 {"units": "rad", "long_name": "angle about Z of the body x axis' projection at t = 0"}),
    })
    ds = ds.assign_coords(member=np.arange(m), state=["x", "y", "z", "vx", "vy", "vz"],
                          quaternion=["x", "y", "z", "w"], axis=["x", "y", "z"])
    meta = {"period_days": ("d", "orbit period"), "x0": ("LU", "orbit x at t = 0"), "z0": ("LU", "orbit z at t = 0"),
            "q0": (None, "attitude at t = 0, body relative to the synodic frame, scalar-last quaternion"),
            "w0": ("1/TU", "inertial angular velocity at t = 0 in body axes"),
            "stable": (None, f"every multiplier on the unit circle to {STABILITY_TOL:g}"),
            "residual": (None, "max(|rotation vector of R(0)' R(KT)| rad, |w(KT) - w0| 1/TU), independent re-propagation "
                               "at rtol = atol = 1e-14"),
            "turns": (None, "net turns of the body x axis about synodic Z over the K periods (NaN: undefined)")}
    for name, (units, long_name) in meta.items():
        ds[name].attrs.update({"long_name": long_name, **({"units": units} if units else {})})
    sys_ = orbits.system
    ds.attrs.update({"title": "librate periodic 3-D attitude motions along an orbit family", "mu": sys_.mu,
                     "lu_km": sys_.lu_km, "tu_s": sys_.tu_s,
                     "system_name": sys_.name, "orbit_family": orbits.kind, "stability_tol": STABILITY_TOL,
                     "members_requested": len(list(period_days)), **start, **(attrs or {})})
    return ds


def multipliers_3d(ds) -> np.ndarray:
    """The complex Floquet multipliers (member, 6) of a saved 3-D solve (``multipliers_real``
    and ``multipliers_imag``)."""

    return Solutions3DResult.multipliers(ds)


def solution_3d(ds, member: int = 0):
    """The :class:`~librate.AttitudeSolution3D` of one member of a saved 3-D solve, corrected
    again by :func:`librate.periodic_attitude_3d` from the stored (q0, w0) on the stored orbit
    (it returns at once when the stored motion is periodic; e.g. to draw its body axes)."""
    from ..attitude.body import RigidBody
    from ..orbits.periodic import PeriodicOrbit
    from ..orbits.system import System
    from ..periodicity.attitude3d import periodic_attitude_3d

    a = ds.attrs
    name = str(a["system_name"])
    preset = name in System.presets() and System.preset(name).mu == float(a["mu"])
    system = System.preset(name) if preset else System(mu=float(a["mu"]), lu_km=float(a["lu_km"]), tu_s=float(a["tu_s"]), name=name)
    orbit = PeriodicOrbit(system, np.asarray(ds["orbit_state0"].values[member], dtype=float), float(ds["orbit_period"].values[member]),
                          float(ds["orbit_jacobi"].values[member]))
    body = RigidBody(*(float(v) for v in np.atleast_1d(a["body_moments"])))
    return periodic_attitude_3d(orbit, body, guess=(ds["q0"].values[member], ds["w0"].values[member]), n_periods=int(a["n_periods"]),
                                tol=float(a.get("attitude_tol", 1e-12)))


def publish_parts(parts: Path, store: Path, lock) -> None:
    """A finished part store published at ``store``: written as netCDF (without the store's bookkeeping
    attributes) or, for Zarr, renamed over the old one under the lock; the parts removed after."""
    if parts == store:
        return
    ds = open_result(parts).load()
    if store.suffix == ".nc":
        for k in STORE_ATTRS:
            ds.attrs.pop(k, None)
        save_dataset(ds, store, lock=lock)
    else:
        lock.check()
        replace_path(parts, store)
    remove_path(parts)


def run_map_to(
    orbits,
    store: str | Path,
    *,
    kz,
    wz0,
    phi0: float = 0.0,
    n_periods: int = 1,
    srp=None,
    rtol: float | None = None,
    atol: float | None = None,
    resume: bool = True,
    scheduler=None,
    progress: bool | None = None,
    attrs: dict[str, Any] | None = None,
    replace: bool = False,
):
    """A periodicity map written to the Zarr ``store`` (a ``.zarr`` folder). Uses
    ``librate.app.runner.run_map`` (chunked, resumable, optionally on a Dask scheduler) when it is
    installed; otherwise :func:`librate.periodicity_map` in this process, written with
    ``to_zarr`` (an existing store with the same study and complete is reused; a store of
    another study is refused unless ``resume=False``; a foreign folder is always refused).
    ``progress``: progress bars on stderr (None: only when stderr is a terminal).
    ``replace``: an existing librate result at ``store`` is replaced all or nothing (the new
    map is computed aside under the store's lock and takes its name once complete).
    Returns ``(dataset, store_path)``."""
    store = Path(store)
    attrs = dict(attrs or {})
    try:
        from .runner import run_map
    except ImportError:
        run_map = None
    if run_map is not None:
        kw: dict[str, Any] = dict(kz=kz, wz0=wz0, phi0=phi0, n_periods=n_periods, srp=srp, out=str(store), resume=resume,
                                  scheduler=scheduler, progress=progress, solve=True, attrs=attrs)
        params = inspect.signature(run_map).parameters
        if replace and "replace" in params:
            kw["replace"] = True
        for name, value in (("rtol", rtol), ("atol", atol)):
            if value is not None and name in params:
                kw[name] = value
        return run_map(orbits, **kw), store
    if scheduler is not None:
        raise RuntimeError("a Dask scheduler needs librate.app.runner (chunked, distributed maps), which is not installed in this librate")
    from ..periodicity.maps import periodicity_map

    if store.exists():
        try:
            old = _open_dataset(store)
        except Exception:
            old = None
        if old is None or result_kind(old) != "map":
            if old is not None:
                old.close()
            raise FileExistsError(f"{str(store)!r} exists and is not a librate map: refusing to overwrite it; remove it or "
                                  "choose another --out")
        same = not study_changes(old.attrs.get("study"), attrs.get("study"), RESULT_INPUTS["map"])
        complete = int(old.attrs.get("complete", 0)) == 1
        if resume and same and complete and not replace:
            ds = old.load()
            old.close()
            return ds, store
        old.close()
        if resume and not same and not replace:
            raise ResultExists(f"{store} holds a map of another study (changed: "
                               f"{'; '.join(study_changes(old.attrs.get('study'), attrs.get('study')))}): not replaced; pass resume=False "
                               "(--force) to replace it, or choose another folder")
    kw = {} if rtol is None else {"rtol": rtol}
    if atol is not None:
        kw["atol"] = atol
    from .progress import reporter

    ds = periodicity_map(orbits, kz=kz, wz0=wz0, phi0=phi0, n_periods=n_periods, srp=srp, solve=True,
                         progress=reporter("periodicity map", "orbit", progress), **kw)
    ds.attrs.update(attrs)
    save_dataset(ds, store)
    return ds, store
