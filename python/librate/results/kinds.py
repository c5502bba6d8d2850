"""The kinds of librate result, one class each: what it depends on (the study sections), its
fixed variables and dtypes, its figures, how it converts to and from an xarray Dataset (files
written by older librate versions converted on load), and a one-line summary.

The planar and 3-D maps are part stores (:mod:`librate.results.store`); their schemas are here
too, with the units and long names of their variables (the one place they are written)."""

from __future__ import annotations

import numpy as np

from .store import StoreSchema, Var

__all__ = ["FamilyResult", "KINDS", "Map3DResult", "MAP_3D_VARIABLES", "MAP_VARIABLES", "MapResult", "ResultKind", "Solutions3DResult",
           "SolutionsResult", "kind_of", "map3d_schema", "map_schema"]

#: The per-orbit variables of a planar map: units and long names (periodicity_map, run_map and
#: the store all take them from here).
MAP_VARIABLES = {
    "dwz": {"units": "1/TU", "long_name": "wz(T) - wz(0)"},
    "dphi": {"units": "rad", "long_name": "phi(T) - phi0 wrapped to (-pi, pi]"},
    "phi_T": {"units": "rad", "long_name": "phi(T), unwrapped"},
    "status": {"flag_values": "0 ok, 1 max steps, 2 failed, 255 not computed"},
}
#: The per-orbit variables of a 3-D map.
MAP_3D_VARIABLES = {
    "residual": {"long_name": "(rotation vector of R(0)' R(KT) in body axes, w(KT) - w0)", "units": "rad, 1/TU"},
    "residual_norm": {"long_name": "max |residual component|"},
    "status": {"flag_values": "0 ok, 1 max steps, 2 failed, 255 not computed"},
}


def map_schema(no: int, nk: int, nw: int, coords: dict) -> StoreSchema:
    """The part store of a planar map: one part per orbit, (kz, wz0) grids; status uint8."""
    extra = {"coordinates": "x0 period period_days phidot0"}
    v = {k: Var("f8", (nk, nw), ("kz", "wz0"), np.nan, {**extra, **MAP_VARIABLES[k]}) for k in ("dwz", "dphi", "phi_T")}
    v["status"] = Var("u1", (nk, nw), ("kz", "wz0"), 255, {**extra, **MAP_VARIABLES["status"]})
    return StoreSchema("periodicity_map", "orbit", no, v, coords)


def map3d_schema(no: int, shape: tuple[int, ...], dims: tuple[str, ...], coords: dict) -> StoreSchema:
    """The part store of a 3-D map: one part per orbit over the (body?, wx0?, wy0?, wz0?) grid;
    status uint8."""
    extra = {"coordinates": " ".join(n for n in coords if coords[n][0] == "orbit" and n != "orbit")}
    v = {"residual": Var("f8", (*shape, 6), (*dims, "component"), np.nan, {**extra, **MAP_3D_VARIABLES["residual"]}),
         "residual_norm": Var("f8", shape, dims, np.nan, {**extra, **MAP_3D_VARIABLES["residual_norm"]}),
         "status": Var("u1", shape, dims, 255, {**extra, **MAP_3D_VARIABLES["status"]})}
    return StoreSchema("map_3d", "orbit", no, v, coords)


_STUDY = ("system", "orbits", "body", "torques", "rates", "attitude", "solver")


class ResultKind:
    """One kind of result. ``kind``: the ``librate_result`` attribute; ``inputs``: the study
    sections it depends on (a change elsewhere leaves it valid); ``figures``: the figure names
    ``librate plot`` draws for it; ``dtypes``: fixed dtypes of its variables."""

    kind = ""
    inputs: tuple[str, ...] = _STUDY
    figures: tuple[str, ...] = ()
    dtypes: dict[str, str] = {}
    dims = ("member",)

    def __init__(self, dataset):
        self.dataset = dataset

    @classmethod
    def recognise(cls, ds) -> bool:
        return ds.attrs.get("librate_result") == cls.kind

    @classmethod
    def from_dataset(cls, ds):
        """The result held by ``ds`` (as read from a file), its variables in their fixed dtypes."""
        fix = {k: ds[k].astype(t) for k, t in cls.dtypes.items() if k in ds.variables and ds[k].dtype != np.dtype(t)}
        return cls(ds.assign(fix) if fix else ds)

    def to_dataset(self):
        """The Dataset to save (``librate_result`` set, fixed dtypes)."""
        ds = self.dataset.copy()
        for k, t in self.dtypes.items():
            if k in ds.variables and ds[k].dtype != np.dtype(t):
                ds[k] = ds[k].astype(t)
        ds.attrs["librate_result"] = self.kind
        return ds

    def summary(self) -> str:
        ds = self.dataset
        sizes = ", ".join(f"{k} {v}" for k, v in ds.sizes.items() if k in ("member", "orbit", "kz", "wz0", "solution", "wx0", "wy0"))
        if "complete" in ds.attrs and int(ds.attrs["complete"]) != 1:
            sizes = (sizes + ", " if sizes else "") + "unfinished"
        version = ds.attrs.get("librate_version")
        return f"a librate {self.kind}{': ' + sizes if sizes else ''}{', librate ' + str(version) if version else ''}"


class FamilyResult(ResultKind):
    """An orbit family (:class:`librate.OrbitFamily`; its ``to_dataset``/``load`` convert)."""

    kind = "family"
    inputs = ("system", "orbits")
    figures = ("family", "period", "stability")

    @classmethod
    def recognise(cls, ds) -> bool:
        return ds.attrs.get("librate_result") == "family" or ("librate_result" not in ds.attrs and "state0" in ds.variables and "kind" in ds.attrs)


class SolutionsResult(ResultKind):
    """The planar periodic attitude solutions of ``librate solve``."""

    kind = "solutions"
    figures = ("solutions",)
    dtypes = {"sol_orbit": "int64", "sol_n_periods": "int64"}

    @classmethod
    def recognise(cls, ds) -> bool:
        return ds.attrs.get("librate_result") == "solutions" or ("librate_result" not in ds.attrs and "sol_wz0" in ds.variables
                                                                   and "dwz" not in ds.variables)


class Solutions3DResult(ResultKind):
    """The periodic 3-D attitude motions along an orbit family (``librate solve``, 3-D)."""

    kind = "solutions_3d"
    figures = ("multipliers", "body_axes")


class MapResult(ResultKind):
    """A planar periodicity map (a part store ``map.zarr``, or an exported ``.nc``)."""

    kind = "map"
    figures = ("map", "residuals", "solutions")
    dtypes = {"status": "uint8"}

    @classmethod
    def recognise(cls, ds) -> bool:
        return ds.attrs.get("librate_result") == "map" or ("librate_result" not in ds.attrs and "dwz" in ds.variables)


class Map3DResult(ResultKind):
    """A 3-D attitude map (a part store, or a file written whole by older versions)."""

    kind = "map_3d"
    figures = ("map", "residuals", "solutions")
    dtypes = {"status": "uint8"}

    @classmethod
    def recognise(cls, ds) -> bool:
        return ds.attrs.get("librate_result") == "map_3d" or ds.attrs.get("librate_store") == "map_3d"


#: The classes by kind, in the order they are recognised.
KINDS: dict[str, type[ResultKind]] = {c.kind: c for c in (FamilyResult, SolutionsResult, Solutions3DResult, MapResult, Map3DResult)}


def kind_of(ds) -> type[ResultKind] | None:
    """The class of the result ``ds`` holds (from ``librate_result``, or recognised from the
    variables of files written without it), or None."""
    k = ds.attrs.get("librate_result")
    if k in KINDS:
        return KINDS[k]
    for cls in KINDS.values():
        if cls.recognise(ds):
            return cls
    return None
