"""The kinds of librate result, one class each: what it depends on (the study sections), its
fixed variables and dtypes, its figures, how it converts to and from an xarray Dataset (files
written by older librate versions converted on load), and a one-line summary.

The planar and 3-D maps are part stores (:mod:`librate.results.store`); their schemas are here
too, with the units and long names of their variables (the one place they are written)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .store import StoreSchema, Var

__all__ = ["FIGURE_FILES", "FamilyResult", "KINDS", "Map3DResult", "MAP_3D_VARIABLES", "MAP_VARIABLES", "MapResult",
           "RESIDUALS_PERIOD_DAYS", "RESIDUALS_PERIOD_TOL_DAYS", "ResultKind", "Solutions3DResult", "SolutionsResult",
           "TRANSITION_ATTITUDE_VARIABLES", "TRANSITION_VARIABLES", "TransitionResult", "kind_of", "map3d_schema", "map_schema",
           "residuals_orbit", "transition_schema", "transition_variables"]

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


#: The per-epoch variables of an ephemeris transition (``librate transition``): dtype, the
#: dimensions within an epoch, units and long name. ``status``: 0 converged, 1 not converged.
TRANSITION_VARIABLES = {
    "status": ("u1", (), {"flag_values": "0 converged, 1 not converged (ConvergenceError), 255 not computed"}),
    "iterations": ("i8", (), {"long_name": "Newton iterations of the multiple shooting (-1: not converged)"}),
    "max_departure_km": ("f8", (), {"units": "km", "long_name": "largest distance of the ephemeris trajectory from the CR3BP orbit"}),
    "drift_km_per_rev": ("f8", (), {"units": "km", "long_name": "drift of the ephemeris trajectory from the CR3BP orbit per revolution"}),
    "node_epochs_tdb": ("f8", ("node",), {"units": "s", "long_name": "node epochs, TDB seconds past J2000"}),
    "states_km": ("f8", ("node", "component"), {"units": "km, km/s", "long_name": "node states, Moon-centred ICRF"}),
    "synodic": ("f8", ("node", "component"), {"units": "LU, LU/TU",
                                              "long_name": "node states in the instantaneous Earth-Moon rotating frame, "
                                              "nondimensional (barycentre origin, the CR3BP's synodic frame)"}),
    "defects_km": ("f8", ("leg",), {"units": "km", "long_name": "position defect at the end of each leg, re-propagated from its node"}),
    "defects_km_s": ("f8", ("leg",), {"units": "km/s", "long_name": "velocity defect at the end of each leg, re-propagated from its node"}),
    "perilune_km": ("f8", ("revolution",), {"units": "km", "long_name": "closest approach to the Moon's centre in each revolution"}),
    "track_t_tdb": ("f8", ("sample",), {"units": "s", "long_name": "epochs of the sampled ephemeris trajectory, TDB seconds past J2000"}),
    "track_synodic": ("f8", ("sample", "component"), {"units": "LU, LU/TU",
                                                      "long_name": "the sampled ephemeris trajectory in the rotating frame, "
                                                      "nondimensional"}),
}


#: The per-epoch attitude variables of a transition with ``ephemeris.attitude_n`` (dimension
#: ``attitude``: the CR3BP solutions carried; ``attitude_sample``: the epochs of the deviation
#: figures), as :data:`TRANSITION_VARIABLES`. ``attitude_status``: 0 corrected, 1 not corrected.
TRANSITION_ATTITUDE_VARIABLES = {
    "attitude_status": ("u1", ("attitude",), {
        "flag_values": "0 corrected, 1 the correction did not converge (ConvergenceError), 2 not computed (the epoch's orbit did not "
                       "converge), 255 not computed"}),
    "attitude_iterations": ("i8", ("attitude",), {"long_name": "Newton iterations of the attitude multiple shooting (-1: not corrected)"}),
    "attitude_q": ("f8", ("attitude", "node", "quaternion"), {
        "units": "1", "long_name": "corrected attitude at the node epochs, body -> ICRF (v_icrf = R(q) v_body), scalar last"}),
    "attitude_w": ("f8", ("attitude", "node", "axis"), {
        "units": "rad/s", "long_name": "inertial angular velocity at the node epochs, body axes"}),
    "attitude_defect_rad": ("f8", ("attitude", "leg"), {
        "units": "rad", "long_name": "attitude defect at the end of each leg (rotation angle), re-propagated from its node"}),
    "attitude_defect_rate": ("f8", ("attitude", "leg"), {"units": "1", "long_name": "rate defect |dw| / |w| at the end of each leg"}),
    "attitude_growth": ("f8", ("attitude",), {"units": "1", "long_name": "largest |eigenvalue| of the attitude monodromy over the span"}),
    "attitude_max_pointing_deg": ("f8", ("attitude",), {
        "units": "deg", "long_name": "largest pointing error of the corrected motion, any body axis"}),
    "attitude_placed_max_pointing_deg": ("f8", ("attitude",), {
        "units": "deg", "long_name": "largest pointing error of the placed motion propagated from the first node without correction"}),
    "attitude_t_tdb": ("f8", ("attitude_sample",), {"units": "s", "long_name": "epochs of the attitude samples, TDB seconds past J2000"}),
    "attitude_pointing_deg": ("f8", ("attitude", "attitude_sample", "axis"), {
        "units": "deg", "long_name": "angle between each body axis of the corrected motion and of the CR3BP motion (rotating frame)"}),
    "attitude_placed_pointing_deg": ("f8", ("attitude", "attitude_sample", "axis"), {
        "units": "deg", "long_name": "the same for the placed motion, uncorrected"}),
    "attitude_rate_error": ("f8", ("attitude", "attitude_sample"), {
        "units": "1", "long_name": "|w - w_ref| / |w_ref|, w_ref the CR3BP rate placed at the epoch"}),
    "attitude_angles_deg": ("f8", ("attitude", "attitude_sample", "angle"), {
        "units": "deg", "long_name": "roll, pitch, yaw of the corrected motion relative to the rotating frame (ZYX Euler, unwrapped)"}),
    "attitude_cr3bp_angles_deg": ("f8", ("attitude", "attitude_sample", "angle"), {
        "units": "deg", "long_name": "roll, pitch, yaw of the CR3BP motion relative to the synodic frame, at the same samples"}),
}


def transition_variables(attitude: bool) -> dict:
    """The per-epoch variables of a transition: :data:`TRANSITION_VARIABLES`, and with
    ``attitude`` :data:`TRANSITION_ATTITUDE_VARIABLES`."""
    return {**TRANSITION_VARIABLES, **(TRANSITION_ATTITUDE_VARIABLES if attitude else {})}


def transition_schema(n_epochs: int, sizes: dict, coords: dict) -> StoreSchema:
    """The part store of ``librate transition``: one part per epoch; ``sizes`` the lengths of
    node, leg, revolution, sample and component (and, with attitude, of attitude,
    attitude_sample, quaternion, axis and angle)."""
    v = {}
    for k, (dtype, dims, attrs) in transition_variables("attitude" in sizes).items():
        # no fill value for the counts: xarray would read one (-1: not converged) as missing
        fill = 255 if dtype == "u1" else (None if dtype == "i8" else np.nan)
        v[k] = Var(dtype, tuple(sizes[d] for d in dims), dims, fill, dict(attrs))
    return StoreSchema("ephemeris_transition", "epoch", n_epochs, v, coords)


#: The period (days) of the DRO whose residuals thesis Fig. 23 draws, the 12.66-day DRO of the
#: Earth-Moon system; a map's residuals figure is drawn on the orbit of that period, within
#: :data:`RESIDUALS_PERIOD_TOL_DAYS`, when the map holds one (the demo's map does).
RESIDUALS_PERIOD_DAYS = 12.66
RESIDUALS_PERIOD_TOL_DAYS = 0.01


def residuals_orbit(period_days) -> int:
    """The index of the orbit a map's residuals figure is drawn on (thesis Fig. 23), from the
    orbits' periods in days: the orbit of period :data:`RESIDUALS_PERIOD_DAYS` (within
    :data:`RESIDUALS_PERIOD_TOL_DAYS`) when the map holds one, else the orbit nearest it."""
    return int(np.nanargmin(np.abs(np.asarray(period_days, dtype=float) - RESIDUALS_PERIOD_DAYS)))


#: The file suffix of each figure: a result STEM.zarr gets STEM_<suffix>.png beside it.
FIGURE_FILES = {"family": "orbits", "period": "period", "stability": "stability", "map": "contours", "residuals": "residuals",
                "solutions": "solutions", "multipliers": "multipliers", "body_axes": "body_axes",
                "transition": "rotating", "defects": "defects", "sweep": "sweep", "attitude": "attitude", "pointing": "pointing"}

#: A figure to draw: (its file suffix, a function that draws it and returns the Figure).
Figure = tuple[str, Callable]


def _plotting():
    """librate.plotting, imported when a figure is drawn (matplotlib stays out of the results)."""
    from .. import plotting

    return plotting


_STUDY = ("system", "orbits", "body", "torques", "rates", "attitude", "solver")


class ResultKind:
    """One kind of result. ``kind``: the ``librate_result`` attribute; ``inputs``: the study
    sections it depends on (a change elsewhere leaves it valid); ``figure_names``: the figures
    ``librate plot`` draws for it (:meth:`figures` draws them); ``dtypes``: fixed dtypes of its
    variables."""

    kind = ""
    inputs: tuple[str, ...] = _STUDY
    figure_names: tuple[str, ...] = ()
    dtypes: dict[str, str] = {}
    dims = ("member",)

    def __init__(self, dataset):
        self.dataset = dataset

    @classmethod
    def recognise(cls, ds) -> bool:
        return ds.attrs.get("librate_result") == cls.kind

    @classmethod
    def inputs_of(cls, study: dict | None) -> tuple[str, ...]:
        """The study sections this result depends on for ``study`` (a study as plain data, or
        None): :attr:`inputs`."""
        return cls.inputs

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

    @classmethod
    def figures(cls, result, names=None, skip: Callable[[str, str], None] | None = None, **data) -> list[Figure]:
        """The figures of ``result`` (what :func:`librate.open_result` returns for this kind)
        among ``names`` (default: :attr:`figure_names`), as (file suffix, draw) pairs; ``draw()``
        returns the matplotlib Figure (:mod:`librate.plotting`, imported only then). A figure
        that does not apply to this result is left out, ``skip(suffix, reason)`` told why. ``data``:
        what a figure needs beyond the result, supplied by the computing layer."""
        return []

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
    figure_names = ("family", "period", "stability")

    @classmethod
    def figures(cls, result, names=None, skip=None, **data) -> list[Figure]:
        """The family's orbits (30 of them), its period against x0 and its stability indices."""
        lp = _plotting()
        table = {"family": lambda: lp.plot_family(result, n_orbits=30), "period": lambda: lp.plot_period(result),
                 "stability": lambda: lp.plot_stability(result)}
        return [(FIGURE_FILES[n], table[n]) for n in (cls.figure_names if names is None else names) if n in table]

    @classmethod
    def recognise(cls, ds) -> bool:
        return ds.attrs.get("librate_result") == "family" or ("librate_result" not in ds.attrs and "state0" in ds.variables
                                                              and "kind" in ds.attrs)


class SolutionsResult(ResultKind):
    """The planar periodic attitude solutions of ``librate solve``."""

    kind = "solutions"
    figure_names = ("solutions",)

    @classmethod
    def figures(cls, result, names=None, skip=None, **data) -> list[Figure]:
        """The solutions' initial rates against x0."""
        lp = _plotting()
        want = cls.figure_names if names is None else names
        if "solutions" in want and "sol_wz0" in result.variables and result.sizes.get("solution", 0):
            return [(FIGURE_FILES["solutions"], lambda: lp.plot_solution_scatter(result))]
        return []
    dtypes = {"sol_orbit": "int64", "sol_n_periods": "int64"}

    @classmethod
    def recognise(cls, ds) -> bool:
        return ds.attrs.get("librate_result") == "solutions" or ("librate_result" not in ds.attrs and "sol_wz0" in ds.variables
                                                                   and "dwz" not in ds.variables)


class Solutions3DResult(ResultKind):
    """The periodic 3-D attitude motions along an orbit family (``librate solve``, 3-D)."""

    kind = "solutions_3d"
    figure_names = ("multipliers", "body_axes")

    @staticmethod
    def multipliers(ds) -> np.ndarray:
        """The complex Floquet multipliers (member, 6), stored as ``multipliers_real`` and ``multipliers_imag``."""
        return ds["multipliers_real"].values + 1j * ds["multipliers_imag"].values

    @classmethod
    def figures(cls, result, names=None, skip=None, *, solution: Callable | None = None, **data) -> list[Figure]:
        """The Floquet multipliers along the family, and the body axes along the first member's
        orbit: ``solution()`` returns that member's AttitudeSolution3D (the computing layer
        corrects it again from the stored state; without it the figure is left out)."""
        lp = _plotting()
        mult = cls.multipliers(result)
        table = {"multipliers": lambda: lp.plot_family_multipliers(result.assign(multipliers=(("member", "k"), mult)))}
        if solution is not None:
            table["body_axes"] = lambda: lp.plot_body_axes(solution())
        return [(FIGURE_FILES[n], table[n]) for n in (cls.figure_names if names is None else names) if n in table]


class MapResult(ResultKind):
    """A planar periodicity map (a part store ``map.zarr``, or an exported ``.nc``)."""

    kind = "map"
    figure_names = ("map", "residuals", "solutions")
    dtypes = {"status": "uint8"}

    @classmethod
    def figures(cls, result, names=None, skip=None, **data) -> list[Figure]:
        """The map's zero contours (one figure per Kz), the residuals of the 12.66-day DRO, or
        of the orbit nearest it (thesis Fig. 23, :func:`residuals_orbit`), and the solution
        families across the orbits (Figs. 27-29)."""
        lp = _plotting()
        kzs = np.atleast_1d(result["kz"].values)
        out: list[Figure] = []
        for name in cls.figure_names if names is None else names:
            if name == "map":
                if result.sizes["orbit"] < 2:
                    if skip is not None:
                        skip(FIGURE_FILES["map"], "a periodicity map figure needs at least 2 orbits")
                    continue
                for j, kz in enumerate(kzs):
                    out.append((FIGURE_FILES["map"] + ("" if kzs.size == 1 else f"_kz{kz:g}"), lambda j=j: lp.plot_map(result, kz_index=j)))
            elif name == "residuals":
                near = residuals_orbit(result["period_days"].values)
                out.append((FIGURE_FILES["residuals"], lambda near=near: lp.plot_residuals(result, orbit_index=near, kz=float(kzs[0]))))
            elif name == "solutions" and "sol_wz0" in result.variables:
                if result.sizes["orbit"] < 2 or result.sizes.get("solution", 0) == 0:
                    continue
                # the thesis families N = 1, 0, -1 (Figs. 27-29) as panels; a rate jump over 1/TU
                # between consecutive orbits starts a new branch (never a line joining two solutions)
                ns = [k for k in (1, 0, -1) if np.any(np.asarray(result["sol_n"].values) == k)] or None
                out.append((FIGURE_FILES["solutions"], lambda ns=ns: lp.plot_solution_families(result, n=ns, max_jump=1.0)))
        return out

    @classmethod
    def recognise(cls, ds) -> bool:
        return ds.attrs.get("librate_result") == "map" or ("librate_result" not in ds.attrs and "dwz" in ds.variables)


class Map3DResult(ResultKind):
    """A 3-D attitude map (a part store, or a file written whole by older versions)."""

    kind = "map_3d"
    figure_names = ("map",)
    dtypes = {"status": "uint8"}

    @classmethod
    def figures(cls, result, names=None, skip=None, **data) -> list[Figure]:
        """log10 of the residual max-norm over the two rate grids."""
        lp = _plotting()
        want = cls.figure_names if names is None else names
        return [("residual_norm", lambda: lp.plot_map_3d(result))] if "map" in want else []

    @classmethod
    def recognise(cls, ds) -> bool:
        return ds.attrs.get("librate_result") == "map_3d" or ds.attrs.get("librate_store") == "map_3d"


def _epochs_iso(result) -> list[str]:
    """The epochs of a transition result as ISO strings (its ``epochs_iso`` attribute, JSON)."""
    import json

    return list(json.loads(result.attrs.get("epochs_iso", "[]"))) or [f"{t:.1f} s TDB" for t in result["epoch"].values]


class TransitionResult(ResultKind):
    """Orbit transitions into the ephemeris model at one or more epochs (``librate transition``,
    a part store with one part per epoch)."""

    kind = "transition"
    inputs = ("system", "orbits", "ephemeris")
    figure_names = ("transition", "defects", "sweep", "attitude", "pointing")
    #: What the attitude solutions of ``ephemeris.attitude_n`` depend on besides :attr:`inputs`.
    attitude_inputs = ("body", "torques", "rates", "attitude", "solver")
    dtypes = {"status": "uint8", "iterations": "int64"}
    dims = ("epoch",)

    @classmethod
    def inputs_of(cls, study: dict | None) -> tuple[str, ...]:
        """[system], [orbits] and [ephemeris]; with ``ephemeris.attitude_n`` also the sections
        its CR3BP attitude solutions are found from."""
        att = ((study or {}).get("ephemeris") or {}).get("attitude_n")
        return cls.inputs + (cls.attitude_inputs if att else ())

    @classmethod
    def figures(cls, result, names=None, skip=None, **data) -> list[Figure]:
        """The orbit in the rotating frame in both models (the first converged epoch), the node
        defects of every epoch, (two epochs or more) the sweep's departure and perilune range
        against the epoch, and, with attitude solutions, the attitude angles in both models and
        the pointing error of each body axis (the first epoch where the first solution was
        corrected). A transition without attitude (no ``ephemeris.attitude_n``) leaves the
        attitude figures out, silently unless ``names`` asks for them (as a map without
        solutions leaves out its solutions figure)."""
        lp = _plotting()
        ok = np.flatnonzero(np.asarray(result["status"].values) == 0)
        out: list[Figure] = []
        for name in cls.figure_names if names is None else names:
            if name not in cls.figure_names:
                continue
            if name in ("attitude", "pointing"):
                if names is None and "attitude_status" not in result.variables:
                    continue  # not asked for: the study has no ephemeris.attitude_n
                out += cls._attitude_figure(result, name, skip, lp)
                continue
            if ok.size == 0:
                if skip is not None:
                    skip(FIGURE_FILES[name], "no epoch converged")
                continue
            if name == "transition":
                j = int(ok[0])
                out.append((FIGURE_FILES[name], lambda j=j: lp.plot_transition_orbit(
                    result["cr3bp_synodic"].values, result["track_synodic"].values[j], result["synodic"].values[j],
                    mu=float(result.attrs["mu"]), lu_km=float(result.attrs["lu_km"]), label=_epochs_iso(result)[j][:19] + " TDB")))
            elif name == "defects":
                out.append((FIGURE_FILES[name], lambda: lp.plot_node_defects(
                    result["defects_km"].values[ok], result["defects_km_s"].values[ok], epochs_tdb=result["epoch"].values[ok])))
            elif name == "sweep":
                if ok.size < 2:
                    if skip is not None:
                        skip(FIGURE_FILES[name], "an epoch sweep figure needs at least 2 converged epochs")
                    continue
                out.append((FIGURE_FILES[name], lambda: lp.plot_transition_sweep(
                    result["epoch"].values[ok], result["max_departure_km"].values[ok], result["perilune_km"].values[ok],
                    result["iterations"].values[ok])))
        return out

    @staticmethod
    def _attitude_figure(result, name: str, skip, lp) -> list[Figure]:
        """The attitude angles or the pointing error of the first solution at the first epoch
        where it was corrected."""
        if "attitude_status" not in result.variables:
            why = "the transition carries no attitude (ephemeris.attitude_n)"
        else:
            good = np.flatnonzero(np.asarray(result["attitude_status"].values)[:, 0] == 0)
            why = "the first attitude solution was corrected at no epoch"
        if "attitude_status" not in result.variables or good.size == 0:
            if skip is not None:
                skip(FIGURE_FILES[name], why)
            return []
        j = int(good[0])
        t_days = (result["attitude_t_tdb"].values[j] - result["attitude_t_tdb"].values[j][0]) / 86400.0
        n = int(result["attitude_n"].values[0])
        title = f"N = {n} solution, {_epochs_iso(result)[j][:19]} TDB"
        if name == "attitude":
            def draw():
                fig = lp.plot_ephemeris_attitude(t_days, result["attitude_cr3bp_angles_deg"].values[j, 0],
                                                 result["attitude_angles_deg"].values[j, 0])
                fig.suptitle(f"attitude relative to the rotating frame, {title}")
                return fig
        else:
            def draw():
                fig = lp.plot_pointing_error(t_days, result["attitude_pointing_deg"].values[j, 0])
                fig.axes[0].set_title(f"corrected ephemeris attitude against the CR3BP motion, {title}", fontsize=9)
                return fig
        return [(FIGURE_FILES[name], draw)]

    def summary(self) -> str:
        ds = self.dataset
        n = ds.sizes.get("epoch", 0)
        conv = int((np.asarray(ds["status"].values) == 0).sum()) if "status" in ds.variables else 0
        return (f"a librate transition: {n} epoch(s), {conv} converged, {ds.attrs.get('revolutions', '?')} revolutions, "
                f"librate {ds.attrs.get('librate_version', '?')}")

    @classmethod
    def recognise(cls, ds) -> bool:
        return ds.attrs.get("librate_result") == "transition" or ds.attrs.get("librate_store") == "ephemeris_transition"


#: The classes by kind, in the order they are recognised.
KINDS: dict[str, type[ResultKind]] = {c.kind: c for c in (FamilyResult, SolutionsResult, Solutions3DResult, MapResult,
                                                          Map3DResult, TransitionResult)}


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
