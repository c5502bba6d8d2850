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

from .._integrity import write_atomically

__all__ = ["RESULT_INPUTS", "RESULT_KINDS", "RESULT_STEMS", "ResultExists", "check_output", "describe_result", "open_result", "multipliers_3d", "read_attrs", "result_kind", "run_map_3d_to", "run_map_to", "save_dataset", "save_family", "solution_3d",
           "solutions_3d_dataset", "solutions_dataset",
           "study_changes", "verify_result"]

#: The kinds of result, as stored in the ``librate_result`` attribute.
RESULT_KINDS = ("family", "solutions", "solutions_3d", "map", "map_3d")
#: The file each command writes its result to (``<stem>.zarr`` or ``<stem>.nc``): the name says
#: which command made it. Its figures are ``<stem>_<figure>.png`` beside it.
RESULT_STEMS = {"family": "family", "solve": "solve", "map": "map", "demo": "demo"}
#: The study sections each kind of result depends on: a change elsewhere (e.g. ``output``, or
#: ``body`` for a family) leaves the result valid, so it is resumed rather than refused.
RESULT_INPUTS = {"family": ("system", "orbits"), "solutions": ("system", "orbits", "body", "torques", "rates", "attitude", "solver"),
                 "solutions_3d": ("system", "orbits", "body", "torques", "rates", "attitude", "solver"),
                 "map": ("system", "orbits", "body", "torques", "rates", "attitude", "solver"),
                 "map_3d": ("system", "orbits", "body", "torques", "rates", "attitude", "solver")}
# older names, still read: solutions.* (librate solve before 0.2), dro_map_kz*.nc (librate demo)
_NAMES = tuple(f"{stem}{ext}" for stem in (*RESULT_STEMS.values(), "solutions") for ext in (".zarr", ".nc"))


def _is_zarr(p: Path) -> bool:
    return p.is_dir() and any((p / n).exists() for n in (".zgroup", ".zattrs", ".zmetadata", "zarr.json"))


def result_kind(ds) -> str | None:
    """"family", "solutions" or "map" for a librate result Dataset (from its ``librate_result``
    attribute, or recognised from its variables for files written by ``OrbitFamily.save`` or
    ``periodicity_map``), else None."""
    k = ds.attrs.get("librate_result")
    if k in RESULT_KINDS:
        return str(k)
    if "state0" in ds.variables and "kind" in ds.attrs:
        return "family"
    if "dwz" in ds.variables:
        return "map"
    if "sol_wz0" in ds.variables:
        return "solutions"
    return None


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
    ``"body.kz: 0.8 -> 0.5"`` lines in key order (tables flattened: ``rates.wz0.num: 300 -> 50``); only the keys under ``sections`` count (all
    when None). A missing study (a result saved by the Python API) differs in ``(study)``."""
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
        kind = result_kind(ds) or "unknown"
        sizes = ", ".join(f"{k} {v}" for k, v in ds.sizes.items() if k in ("member", "orbit", "kz", "wz0", "solution"))
        if not sizes and "complete" in ds.attrs:
            sizes = "unfinished"
        version = ds.attrs.get("librate_version")
        return f"{path} (a librate {kind}{': ' + sizes if sizes else ''}{', librate ' + str(version) if version else ''})"
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
        raise FileExistsError(f"{str(p)!r} exists and is not a librate result: refusing to overwrite it; remove it or choose another output folder")
    old_kind, attrs = found
    old_study = attrs.get("study")
    changes = []
    if old_kind != kind:
        changes.append(f"(result): a {old_kind or 'result of unknown kind'} -> a {kind}")
    else:
        changes += study_changes(old_study, study, RESULT_INPUTS.get(kind))
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


def _existing_result(p: Path) -> tuple[str | None, dict] | None:
    """``(kind, root attributes)`` of the librate result or map store at ``p`` (also an
    unfinished map store, which xarray cannot open yet), or None when it is not one."""
    if _is_zarr(p):
        try:
            import zarr

            attrs = dict(zarr.open_group(str(p), mode="r", use_consolidated=False).attrs)
        except Exception:  # noqa: BLE001 - foreign or damaged: judged below
            attrs = {}
        if attrs.get("librate_store") == "periodicity_map":
            return "map", attrs
    try:
        ds = _open_dataset(p)
    except ValueError:
        return None
    try:
        kind = result_kind(ds)
        return None if kind is None else (kind, dict(ds.attrs))
    finally:
        ds.close()


def _open_dataset(p: Path):
    import xarray as xr

    try:
        if p.is_file() and p.suffix == ".nc":
            return xr.open_dataset(p, engine="scipy")
        if _is_zarr(p):
            return xr.open_dataset(p, engine="zarr", chunks=None)
    except (OSError, TypeError, ValueError, KeyError) as err:
        raise ValueError(f"{str(p)!r} cannot be read as a librate result: {type(err).__name__}: {str(err).splitlines()[0]}") from None
    raise ValueError(f"{str(p)!r} is neither a netCDF file (.nc) nor a Zarr store (.zarr folder)")


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
    """Reload a saved result without recomputing: an :class:`~librate.OrbitFamily` for a family
    (through :meth:`OrbitFamily.load`), an ``xarray.Dataset`` for a periodicity map or a table
    of periodic solutions (its ``attrs["study"]`` is the study as JSON).

    ``path``: a ``.zarr`` folder or a ``.nc`` file, or an output folder holding exactly one of
    map/family/solutions. ``verify``: first check the result as :func:`verify_result` does
    (every chunk against its checksum, every map row computed) and raise ``ValueError`` naming
    the damage. Raises ``FileNotFoundError`` or ``ValueError`` (not a librate result, or damaged).
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
    if "row_checksum" in ds.variables:  # the map store's integrity data, not a result
        ds = ds.drop_vars("row_checksum")
    return ds


def verify_result(path: str | Path) -> tuple[bool, str]:
    """Check a saved result without recomputing it. A map store written by ``librate map``:
    every row against its checksum and ``done`` flag, the coordinates and the solutions (see
    :func:`librate.app.store.verify_map_store`). Other results: every variable is read (a
    missing, truncated or garbled chunk is named) and compared with the digests stored in
    its ``librate_checksums`` attribute when it has them. Returns ``(ok, report)``: the report
    names every damaged row or variable."""
    from .._integrity import array_digest, missing_zarr_chunks
    from .store import verify_map_store

    p = resolve_result_path(path)
    if _is_zarr(p):
        import zarr

        try:
            marker = zarr.open_group(str(p), mode="r", use_consolidated=False).attrs.get("librate_store")
        except Exception:  # noqa: BLE001 - judged below, by reading it as a result
            marker = None
        if marker == "periodicity_map":
            rep = verify_map_store(p)
            return rep.ok, rep.describe()
    try:
        ds = _open_dataset(p)
    except ValueError as err:
        return False, str(err)
    problems = []
    try:
        kind = result_kind(ds)
        if kind is None:
            return False, f"{str(p)!r} is not a librate result (no librate_result attribute; neither a family, a map nor solutions)"
        sums = _stored_checksums(ds)
        from .store import quiet_zarr

        for name in ds.variables:
            try:
                with quiet_zarr():
                    values = np.asarray(ds[name].values)
            except Exception as err:  # noqa: BLE001 - named, never a traceback
                problems.append(f"variable {name} is unreadable ({type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''})")
                continue
            if _is_zarr(p):
                chunks_missing = missing_zarr_chunks(p, str(name))
                if chunks_missing:
                    problems.append(f"variable {name}: chunk(s) {', '.join(chunks_missing)} missing")
            if sums is not None and name in sums and array_digest(values) != sums[name]:
                problems.append(f"variable {name} does not match its checksum")
        if sums is None:
            note = " (no checksums stored: written by an older librate; only readability was checked)"
        else:
            note = ", every variable matches its checksum"
    finally:
        ds.close()
    if problems:
        return False, f"{p}: damaged librate result\n" + "\n".join(f"  {q}" for q in problems)
    return True, f"{p}: ok: a librate {kind} result{note}"


def _stored_checksums(ds) -> dict | None:
    import json

    raw = ds.attrs.get("librate_checksums")
    if not isinstance(raw, str):
        return None
    try:
        sums = json.loads(raw)
    except ValueError:
        return None
    return sums if isinstance(sums, dict) else None


def _check_target(p: Path) -> None:
    """Refuse to replace anything that is not a librate result."""
    if not p.exists():
        return
    try:
        ds = _open_dataset(p)
    except Exception as err:  # corrupt or foreign
        raise FileExistsError(f"{str(p)!r} exists and is not a readable librate result ({type(err).__name__}): refusing to overwrite it; remove it or choose another output folder") from None
    try:
        if result_kind(ds) is None:
            raise FileExistsError(f"{str(p)!r} exists and is not a librate result: refusing to overwrite it; remove it or choose another output folder")
    finally:
        ds.close()


def save_dataset(ds, path: str | Path) -> Path:
    """Write ``ds`` to ``path`` (``.zarr``: Zarr v2 folder, consolidated; ``.nc``: netCDF 3 via
    scipy), creating the folder. All or nothing: written to a temporary sibling and renamed.
    An existing ``path`` is replaced only if it is a librate result. Returns the path."""
    p = Path(path)
    if p.suffix not in (".zarr", ".nc"):
        raise ValueError(f"invalid argument `path`: must end in .zarr (Zarr) or .nc (netCDF), got {str(p)!r}")
    p.parent.mkdir(parents=True, exist_ok=True)
    _check_target(p)
    write_atomically(_with_checksums(ds), p)
    return p


def _with_checksums(ds):
    """``ds`` with the digests of every variable in its ``librate_checksums`` attribute (JSON),
    which :func:`verify_result` and :meth:`OrbitFamily.load` check."""
    from .._integrity import CHECKSUM_ATTR, dataset_checksums

    ds = ds.copy()
    ds.attrs[CHECKSUM_ATTR] = dataset_checksums(ds)
    return ds


def save_family(family, path: str | Path, attrs: dict | None = None) -> Path:
    """Save an :class:`~librate.OrbitFamily` (``family.to_dataset()``) with extra ``attrs``
    (e.g. the study); :meth:`OrbitFamily.load` and :func:`open_result` read it back."""
    ds = family.to_dataset()
    ds.attrs.update({"librate_result": "family", **(attrs or {})})
    return save_dataset(ds, path)


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
        "multipliers_imag": (("member", "k"), mult.imag, {"long_name": "Floquet multipliers of the 6x6 attitude monodromy, imaginary part"}),
        "orbit_state0": (("member", "state"), np.array([o.state0 for o in members]).reshape(m, 6),
                         {"units": "LU, LU/TU", "long_name": "orbit initial state (x, y, z, vx, vy, vz), synodic frame"}),
        "orbit_period": (dim, np.array([o.period for o in members]), {"units": "TU"}),
        "orbit_jacobi": (dim, np.array([o.jacobi for o in members]), {"long_name": "Jacobi constant"}),
        "phi0": (dim, np.arctan2(x_axis[:, 1], x_axis[:, 0]), {"units": "rad", "long_name": "angle about Z of the body x axis' projection at t = 0"}),
    })
    ds = ds.assign_coords(member=np.arange(m), state=["x", "y", "z", "vx", "vy", "vz"], quaternion=["x", "y", "z", "w"], axis=["x", "y", "z"])
    meta = {"period_days": ("d", "orbit period"), "x0": ("LU", "orbit x at t = 0"), "z0": ("LU", "orbit z at t = 0"),
            "q0": (None, "attitude at t = 0, body relative to the synodic frame, scalar-last quaternion"),
            "w0": ("1/TU", "inertial angular velocity at t = 0 in body axes"),
            "stable": (None, f"every multiplier on the unit circle to {STABILITY_TOL:g}"),
            "residual": (None, "max(|rotation vector of R(0)' R(KT)| rad, |w(KT) - w0| 1/TU), independent re-propagation at rtol = atol = 1e-14"),
            "turns": (None, "net turns of the body x axis about synodic Z over the K periods (NaN: undefined)")}
    for name, (units, long_name) in meta.items():
        ds[name].attrs.update({"long_name": long_name, **({"units": units} if units else {})})
    sys_ = orbits.system
    ds.attrs.update({"title": "librate periodic 3-D attitude motions along an orbit family", "mu": sys_.mu, "lu_km": sys_.lu_km, "tu_s": sys_.tu_s,
                     "system_name": sys_.name, "orbit_family": orbits.kind, "stability_tol": STABILITY_TOL,
                     "members_requested": len(list(period_days)), **start, **(attrs or {})})
    return ds


def multipliers_3d(ds) -> np.ndarray:
    """The complex Floquet multipliers (member, 6) of a saved 3-D solve (``multipliers_real``
    and ``multipliers_imag``)."""
    return ds["multipliers_real"].values + 1j * ds["multipliers_imag"].values


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


def run_map_3d_to(orbits, store: str | Path, *, body, rates: dict, q0, n_periods: int = 1, tol: float = 1e-12, resume: bool = True,
                  scheduler=None, progress: bool | None = None, attrs: dict[str, Any] | None = None):
    """The 3-D attitude map of a ``[attitude] model = "3d"`` study, written to ``store`` (a
    ``.zarr`` or ``.nc`` result, ``librate_result = "map_3d"``): for every orbit, the six closure
    residuals (:func:`librate.attitude_map_3d`, integration tolerance ``tol``) over the rate
    grids of ``rates`` (``{"wx0", "wy0", "wz0"}``: arrays or single values) from the attitude
    ``q0``, along a dimension ``orbit`` (coordinates ``x0``, ``z0``, ``period_days``).

    Nothing finished is lost: each orbit's map is saved on its own as it finishes, all or nothing
    and with checksums, in the folder ``<store>.parts``; a run stopped at any moment (Ctrl-C, a
    kill) loses at most the orbit in flight, and the same call again reuses the finished orbits
    (one that fails its checksums, or was made for another study, is named and recomputed). The
    whole map is then written to ``store`` (all or nothing) and the parts removed. An existing
    ``store`` of the same study is reused; of another study it is refused unless ``resume`` is
    False. Returns ``(dataset, store_path)``."""
    import shutil
    import warnings

    import xarray as xr

    from ..periodicity.map3d import attitude_map_3d
    from ..periodicity.maps import orbits_of
    from .progress import bar as progress_bar

    if scheduler is not None:
        raise ValueError("invalid argument `scheduler`: 3-D maps run in this process (all cores); a Dask scheduler is for planar maps")
    store = Path(store)
    attrs = dict(attrs or {})
    study = attrs.get("study")
    olist, _ = orbits_of(orbits)
    # a rate given as one value is fixed (a number, not a dimension of length 1)
    rates = {k: float(np.ravel(v)[0]) if np.size(v) == 1 else np.asarray(v, dtype=float) for k, v in rates.items()}
    state = check_output(store, "map_3d", study, force=not resume)
    if state == "resume":
        ds = open_result(store, verify=True)
        if int(ds.attrs.get("complete", 0)) == 1:
            return ds.load(), store
    parts = store.with_name(store.name + ".parts")
    parts.mkdir(parents=True, exist_ok=True)
    maps = []
    with progress_bar(len(olist), "3-D attitude map", "orbit", progress) as bar:
        for i, orbit in enumerate(olist):
            part = parts / f"orbit-{i:05d}.nc"
            ds_i = None
            if part.exists():
                try:
                    ds_i = open_result(part, verify=True).load()
                except Exception as err:  # noqa: BLE001 - any damage: named, then recomputed
                    warnings.warn(f"{part}: damaged ({err}); orbit {i} is recomputed", RuntimeWarning, stacklevel=2)
                if ds_i is not None and not (ds_i.attrs.get("study") == study and int(ds_i.attrs.get("complete", 0)) == 1):
                    ds_i = None
            if ds_i is None:
                ds_i = attitude_map_3d(orbit, body, wx0=rates["wx0"], wy0=rates["wy0"], wz0=rates["wz0"], q0=q0, n_periods=n_periods, tol=tol)
                if int(ds_i.attrs.get("complete", 0)) != 1:  # interrupted: the finished orbits are kept
                    raise KeyboardInterrupt(f"3-D map interrupted in orbit {i}; {i} finished orbit(s) kept in {parts}")
                ds_i.attrs.update({"librate_result": "map_3d", "study": study or "", "orbit_index": i})
                save_dataset(ds_i, part)
            maps.append(ds_i)
            bar.update(1)
    shared = ("mu", "lu_km", "tu_s", "system_name", "n_periods", "tol", "q0", "simd_level", "librate_version")  # the same for every orbit
    ds = xr.concat([m.drop_attrs() for m in maps], dim="orbit", coords="minimal", compat="override")
    ds = ds.assign_coords(orbit=np.arange(len(olist)), x0=("orbit", np.array([o.state0[0] for o in olist])),
                          z0=("orbit", np.array([o.state0[2] for o in olist])), period_days=("orbit", np.array([o.period_days for o in olist])))
    ds["orbit_state0"] = (("orbit", "state"), np.array([np.asarray(o.state0, dtype=float) for o in olist]))
    ds.attrs.update({k: maps[0].attrs[k] for k in shared if k in maps[0].attrs})
    ds.attrs.update({**attrs, "title": "librate 3-D attitude map", "complete": 1})
    save_dataset(ds, store)  # replaces a librate result at store (check_output allowed it) all or nothing
    shutil.rmtree(parts, ignore_errors=True)
    return ds, store


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
):
    """A periodicity map written to the Zarr ``store`` (a ``.zarr`` folder). Uses
    ``librate.app.runner.run_map`` (chunked, resumable, optionally on a Dask scheduler) when it is
    installed; otherwise :func:`librate.periodicity_map` in this process, written with
    ``to_zarr`` (an existing store with the same study and complete is reused; a store of
    another study is refused unless ``resume=False``; a foreign folder is always refused).
    ``progress``: progress bars on stderr (None: only when stderr is a terminal).
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
            raise FileExistsError(f"{str(store)!r} exists and is not a librate map: refusing to overwrite it; remove it or choose another --out")
        same = not study_changes(old.attrs.get("study"), attrs.get("study"), RESULT_INPUTS["map"])
        complete = int(old.attrs.get("complete", 0)) == 1
        if resume and same and complete:
            ds = old.load()
            old.close()
            return ds, store
        old.close()
        if resume and not same:
            raise ResultExists(f"{store} holds a map of another study (changed: {'; '.join(study_changes(old.attrs.get('study'), attrs.get('study')))}): "
                               "not replaced; pass resume=False (--force) to replace it, or choose another folder")
    kw = {} if rtol is None else {"rtol": rtol}
    if atol is not None:
        kw["atol"] = atol
    from .progress import reporter

    ds = periodicity_map(orbits, kz=kz, wz0=wz0, phi0=phi0, n_periods=n_periods, srp=srp, solve=True,
                         progress=reporter("periodicity map", "orbit", progress), **kw)
    ds.attrs.update(attrs)
    save_dataset(ds, store)
    return ds, store
