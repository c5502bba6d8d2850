"""The jobs a study runs: the work behind ``librate family``, ``librate solve`` and ``librate map``.

Each job takes a valid :class:`~librate.app.study.Study` (the schema) and an output folder, reuses
or refuses an existing result of the same name (:func:`librate.app.results.check_output`),
computes, and saves the result with the study and the package version as attributes.
``run_solve`` and ``run_map`` dispatch on the study's type (:func:`functools.singledispatch`):
one implementation per attitude model (:class:`~librate.app.study.PlanarStudy`,
:class:`~librate.app.study.Study3D`), registered below.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .study import PlanarStudy, Study, Study3D, StudyError, grid_raw, member_count, problem

__all__ = ["run_family", "run_map", "run_solve", "run_transition"]


# --- jobs ----------------------------------------------------------------------------------
def _result_path(study: Study, out, command: str) -> Path:
    from .results import RESULT_STEMS

    return study.output_dir(out) / (RESULT_STEMS[command] + (".zarr" if study.output.format == "zarr" else ".nc"))


def _reused(path: Path, kind: str, study: Study, what: str, force: bool, say: Callable[[str], None] | None):
    """The existing result at ``path`` when it holds this ``kind`` from the same inputs (said as
    reused), else None; a result of other inputs raises ResultExists unless ``force``."""
    from .results import check_output, open_result

    if check_output(path, kind, study.to_json(), force=force, say=say) != "resume":
        return None
    if say is not None:
        say(f"reused: {path} already holds {what} (--force recomputes {'it' if what.startswith('this') else 'them'})")
    return open_result(path)


def run_family(study: Study, out: str | Path | None = None, *, force: bool = False, say: Callable[[str], None] | None = None,
               progress: Callable[[int, int], None] | None = None):
    """Compute the orbit family (and the selected members, when the selection is a
    subset) and save it as ``family.zarr`` (or ``family.nc``) in the output folder with the
    study and version as attributes. Returns ``(family, path)``.

    An existing family of the same ``[system]`` and ``[orbits]`` is reused (``say`` tells);
    one of other inputs raises :class:`~librate.app.results.ResultExists` naming the changed
    keys, unless ``force`` (then it is replaced, after ``say`` names it). ``progress(done,
    total)`` after each member of the continuation."""
    from .results import save_family

    path = _result_path(study, out, "family")
    if (done := _reused(path, "family", study, "this family", force, say)) is not None:
        return done, path
    fam = study.build_family(progress=progress)
    sel = study.build_orbits(fam)
    if isinstance(sel, list):
        sel = _family_of(fam, sel)
    path = save_family(sel, path, study.result_attrs("family", "family"))
    return sel, path

@functools.singledispatch
def run_solve(study: Study, out: str | Path | None = None, progress: Callable[[int, int], None] | None = None, *, force: bool = False,
              say: Callable[[str], None] | None = None, scheduler=None):
    """``librate solve``: one implementation per attitude model, by the study's type (the
    planar one: :func:`_run_solve_planar`; the 3-D one: :func:`_run_solve_3d`). Returns
    ``(dataset, path)``."""
    raise TypeError(f"invalid argument `study`: must be a librate Study, got {type(study).__name__}")


@run_solve.register
def _run_solve_planar(study: PlanarStudy, out: str | Path | None = None, progress: Callable[[int, int], None] | None = None, *,
                      force: bool = False, say: Callable[[str], None] | None = None, scheduler=None):
    """The periodic attitude solutions of every selected orbit and Kz with wz0 in the rate
    window (:func:`librate.find_periodic_attitudes`, scanning on the study's rate grid),
    saved as ``solve.zarr`` (or ``.nc``). Returns ``(dataset, path)``; the Dataset has a
    ``solution`` dimension (orbit index, x0, period, Kz, N, kind, wz0, phidot0, phi0,
    stability, residual). An existing table of the same inputs is reused, one of other
    inputs refused unless ``force``, as in :func:`run_family`.

    ``scheduler``: None (this process), a Dask ``distributed.Client`` or its address: each
    (orbit, Kz) is one task (:func:`librate.app.distribute.run_tasks`, checksummed on arrival,
    resubmitted when lost with its worker); the table equals the local one bit for bit."""
    from .distribute import Task, run_tasks
    from .results import save_dataset, solutions_dataset

    path = _result_path(study, out, "solve")
    if (done := _reused(path, "solutions", study, "these solutions", force, say)) is not None:
        return done, path
    orbits = study.build_orbits()
    olist = list(orbits)
    wz = study.wz0_values()
    srp = study.build_srp(olist[0].system if olist else None)
    kzs = [float(kz) for kz in study.kz_values()]
    found: dict[tuple[int, int], list] = {}
    tasks = [Task((i, j), _solve_one, (o, kz, (float(wz[0]), float(wz[-1])), study.solver.phi0, int(wz.size), study.n_periods(), srp))
             for i, o in enumerate(olist) for j, kz in enumerate(kzs)]

    class _Count:  # progress(done, total) after each (orbit, Kz)
        n = 0

        def update(self, k: int) -> None:
            self.n += k
            if progress is not None:
                progress(self.n, len(tasks))

    run_tasks(tasks, lambda key, sols: found.__setitem__(key, sols), scheduler=scheduler, bar=_Count())
    rows = [(i, _solution_of(olist[i], srp, d)) for i in range(len(olist)) for j in range(len(kzs)) for d in found[(i, j)]]
    ds = solutions_dataset(rows, olist, study.kz_values(), study.result_attrs("solutions", "solve"))
    flex = study.build_flexible()
    if flex is not None and rows:
        # Flexibility's first-order effect on each rigid solution (the closed quasi-static form).
        from ..periodicity.flexible_periodic import flexible_periodic

        res = [flexible_periodic(sol, flex, resolve=False) for _, sol in rows]
        ds["flex_dphi0"] = ("solution", np.array([r.shift[0] for r in res]),
                            {"units": "rad", "long_name": "first-order shift of phi0 from flexibility"})
        ds["flex_dwz0"] = ("solution", np.array([r.shift[1] for r in res]),
                           {"units": "1/TU", "long_name": "first-order shift of wz0 from flexibility"})
        ds["flex_max_dphi"] = ("solution", np.array([r.max_dphi for r in res]),
                               {"units": "rad", "long_name": "largest attitude departure over a period"})
    path = save_dataset(ds, path)
    return ds, path

def _solve_one(orbit, kz: float, window: tuple[float, float], phi0: float, n_grid: int, n_periods: int, srp) -> list[dict]:
    """The solutions of one orbit and Kz (a task, picklable for Dask), as plain data (every field
    of each AttitudeSolution but its orbit and plate, which the caller holds)."""
    from ..periodicity.solutions import find_periodic_attitudes

    sols = find_periodic_attitudes(orbit, kz=kz, wz0_range=window, phi0=phi0, n_grid=n_grid, n_periods=n_periods, srp=srp)
    return [{f.name: getattr(s_, f.name) for f in dataclasses.fields(s_) if f.name not in ("orbit", "srp")} for s_ in sols]


def _solution_of(orbit, srp, fields: dict):
    """The AttitudeSolution of :func:`_solve_one`'s plain data on the caller's orbit and plate."""
    from ..periodicity.solutions import AttitudeSolution

    return AttitudeSolution(orbit=orbit, srp=srp, **fields)


@run_solve.register
def _run_solve_3d(study: Study3D, out: str | Path | None = None, progress: Callable[[int, int], None] | None = None, *, force: bool = False,
                  say: Callable[[str], None] | None = None, scheduler=None):
    """``librate solve`` on a ``[attitude] model = "3d"`` study: one periodic 3-D attitude
    motion of the body (body.ix/iy/iz) over ``solver.n_periods`` orbit periods, continued
    along the selected members in their order (:func:`librate.attitude_family_3d`, natural
    continuation in the orbit period on the orbit family, with the stability changes
    located), saved as ``solve.zarr`` (or ``.nc``; :func:`~librate.app.results.solutions_3d_dataset`).

    The first member's motion is corrected (:func:`librate.periodic_attitude_3d`) from the
    start of ``attitude.start``: "planar", the planar periodic solution with
    ``attitude.n`` turns found on the first member in the ``[rates]`` scan at
    ``solver.phi0`` (the body's Kz; exactly one must be there); "spin", the torque-free spin
    (1 + 2 pi n / (K T)) e_Z at :meth:`Study.q0_3d`; "given", (:meth:`Study.q0_3d`, ``attitude.w0``).
    Returns ``(dataset, path)``; reuse and ``force`` as in :func:`run_family`.
    ``progress(done, total)`` after each member reached. It is one continuation: it runs in
    this process, and a ``scheduler`` is refused."""
    if scheduler is not None:
        raise ValueError("invalid argument `scheduler`: a 3-D solve is one continuation along the members (sequential); "
                         "it runs in this process (use scheduler=None)")
    from .._errors import ConvergenceError
    from ..periodicity.attitude3d import attitude_family_3d
    from .results import save_dataset, solutions_3d_dataset

    path = _result_path(study, out, "solve")
    if (done := _reused(path, "solutions_3d", study, "these 3-D solutions", force, say)) is not None:
        return done, path
    fam = study.build_family()
    members = list(study.build_orbits(fam))
    if not members:
        sel = member_count(study.orbits)
        key, value = (f"orbits.{sel[0]}", sel[1]) if sel else ("orbits.kind", study.orbits.kind)
        raise StudyError([problem(key, value, "selects no member",
                                  "at least 1 member (with 2 or more, the motion is continued along them in order)")])
    body = study.build_body()
    k = study.n_periods()
    guess, start = _start_3d(study, members[0], body, k)
    periods = [o.period_days for o in members]
    tol = study.tol
    try:
        ds = attitude_family_3d(fam, body, guess=guess, period_days=periods, n_periods=k, tol=tol, progress=progress, method="natural")
    except ConvergenceError as err:
        raise ConvergenceError(f"3-D solve: the start on the first member (x0 = {members[0].x0:.6g} LU, T = {periods[0]:.6g} d; "
                               f"{start['start_description']}) did not converge: {err}") from None
    ds = solutions_3d_dataset(ds, fam, periods, {**start, "attitude_tol": tol}, study.result_attrs("solutions_3d", "solve"))
    path = save_dataset(ds, path)
    return ds, path

def _start_3d(study: Study3D, orbit, body, n_periods: int, n: int | None = None, key_n: str = "attitude.n"):
    """The guess of the first member's 3-D motion and its description (attributes); ``n``: the
    start's net turns (default ``attitude.n``; ``key_n`` the study key a missing solution names)."""
    from scipy.spatial.transform import Rotation

    start = study.attitude_start()
    n = study.attitude.n if n is None else n
    if start == "planar":
        from ..periodicity.solutions import find_periodic_attitudes

        wz = study.wz0_values()
        key = "rates.wz0" if study.rates.wz0 is not None else "rates.phidot0"
        found = find_periodic_attitudes(orbit, kz=float(body.kz), wz0_range=(float(wz[0]), float(wz[-1])), phi0=study.solver.phi0,
                                        n_grid=int(wz.size), n_periods=n_periods)
        hits = [x for x in found if x.kind == "periodic" and x.n == n]
        where = (f"on the first member (x0 = {orbit.x0:.6g} LU, T = {orbit.period_days:.6g} d, Kz = {body.kz:.6g}, "
                 f"phi0 = {study.solver.phi0:g})")
        if not hits:
            others = ", ".join(f"n = {x.n:g} ({x.kind}) at wz0 = {x.wz0:.6g}" for x in found) or "none"
            raise StudyError([problem(key_n, n, f"no planar periodic solution with n = {n} {where} for wz0 in "
                                       f"[{wz[0]:g}, {wz[-1]:g}]; found: {others}",
                                       "the n of a planar periodic solution in the window, or widen " + key)])
        if len(hits) > 1:
            raise StudyError([problem(key, grid_raw(getattr(study.rates, key.split(".")[1])),
                                       f"{len(hits)} planar periodic solutions with n = {n} {where}: wz0 = "
                                       + ", ".join(f"{x.wz0:.6g}" for x in hits) + "; narrow the window to one of them",
                                       f"a rate window holding exactly one planar solution with n = {key_n}")])
        sol = hits[0]
        return sol, {"start": "planar", "start_n": int(n), "start_planar_wz0": float(sol.wz0), "start_planar_phi0": float(sol.phi0),
                     "start_planar_trace": float(sol.trace), "start_planar_stable": int(bool(sol.stable)),
                     "start_description": f"the planar n = {n} solution, phi0 = {sol.phi0:g} rad, wz0 = {sol.wz0:.12g} 1/TU"}
    q0 = study.q0_3d()
    if start == "spin":
        wz = 1.0 + 2.0 * math.pi * n / (n_periods * orbit.period)
        w0 = wz * Rotation.from_quat(q0).as_matrix().T @ np.array([0.0, 0.0, 1.0])
        desc = f"the torque-free spin wz = 1 + 2 pi n / (K T) = {wz:.12g} 1/TU about synodic Z, n = {n}"
        extra = {"start_n": int(n)}
    else:
        w0 = np.asarray(study.attitude.w0, dtype=float)
        desc = "the given attitude.q0, attitude.w0"
        extra = {}
    return (q0, w0), {"start": start, **extra, "start_q0": [float(v) for v in q0], "start_w0": [float(v) for v in w0],
                      "start_description": desc}

@functools.singledispatch
def run_map(study: Study, out: str | Path | None = None, *, scheduler=None, progress: bool | None = None, force: bool = False,
            say: Callable[[str], None] | None = None):
    """``librate map``: one implementation per attitude model, by the study's type (the planar
    one: :func:`_run_map_planar`; the 3-D one: :func:`_run_map_3d`). Returns ``(dataset, path)``."""
    raise TypeError(f"invalid argument `study`: must be a librate Study, got {type(study).__name__}")


@run_map.register
def _run_map_3d(study: Study3D, out: str | Path | None = None, *, scheduler=None, progress: bool | None = None, force: bool = False,
                say: Callable[[str], None] | None = None):
    """The six 3-D closure residuals over (orbit, two rate grids) into ``map.zarr`` (or ``.nc``),
    orbit by orbit, resumable (:func:`librate.app.map3d_runs.run_map_3d_to`); ``force``: recomputed."""
    from .map3d_runs import run_map_3d_to

    return run_map_3d_to(study.build_orbits(), _result_path(study, out, "map"), body=study.build_body(),
                         rates=study.rates_3d(), q0=study.q0_3d(),
                         n_periods=study.n_periods(), tol=study.tol, resume=not force, scheduler=scheduler,
                         progress=progress, attrs=study.result_attrs("map_3d", "map"))


@run_map.register
def _run_map_planar(study: PlanarStudy, out: str | Path | None = None, *, scheduler=None, progress: bool | None = None,
                    force: bool = False, say: Callable[[str], None] | None = None):
    """The attitude periodicity map (grids of wz(T) - wz0 and phi(T) - phi0 over orbit x Kz
    x wz0, and the refined solutions) through ``librate.app.runner.run_map`` into
    ``map.zarr`` in the output folder (resumable), or, when the runner is not installed,
    through :func:`librate.periodicity_map` written with ``to_zarr``. With
    ``output.format = "netcdf"`` a ``map.nc`` copy is exported too. Returns
    ``(dataset, path)``.

    A store of the same inputs (finished or interrupted) is resumed; one of other inputs
    raises :class:`~librate.app.results.ResultExists` naming the changed keys, unless
    ``force``: then it is replaced (after ``say`` names it) once the new map is complete.
    ``progress``: progress bars on stderr (None: only when stderr is a terminal)."""
    from .results import check_output, run_map_to

    folder = study.output_dir(out)
    store = folder / "map.zarr"
    # validated before the store is touched: a study error never costs an existing map
    orbits = study.build_orbits()
    srp = study.build_srp()
    # nothing is removed here: a replaced map gives way only to a complete new one, under its lock
    replace = check_output(store, "map", study.to_json(), force=force, say=say) == "replace"
    ds, path = run_map_to(
        orbits, store, kz=study.kz_values(), wz0=study.wz0_values(), phi0=study.solver.phi0, n_periods=study.n_periods(),
        srp=srp, rtol=study.solver.rtol, atol=study.solver.atol, resume=True, scheduler=scheduler, progress=progress,
        attrs=study.result_attrs("map", "map"), replace=replace,
    )
    if study.output.format == "netcdf":
        from .results import save_dataset

        save_dataset(ds, folder / "map.nc")
    return ds, path


def run_transition(study: Study, out: str | Path | None = None, *, scheduler=None, progress: bool | None = None, force: bool = False,
                   say: Callable[[str], None] | None = None):
    """The orbit of ``[orbits]`` (exactly one) carried into the Earth-Moon-Sun ephemeris model
    at every epoch of ``[ephemeris]`` over ``ephemeris.revolutions`` (multiple shooting,
    :func:`librate.orbits.transition.to_ephemeris`), saved epoch by epoch as
    ``transition.zarr`` (or ``.nc``; :func:`librate.app.transition.run_transition_to`: resumable,
    a killed run keeps every finished epoch). Returns ``(dataset, path)``.

    Every epoch and the end of its revolutions must lie in the ephemeris file's span (a
    StudyError names ``ephemeris.epoch`` and the allowed range). ``scheduler``: None (this
    process), a Dask ``distributed.Client`` or its address: each epoch is one task, checksummed
    on arrival; the result equals the local one bit for bit. A result of the same inputs is
    resumed or reused; one of other inputs is refused unless ``force`` (``say`` names it).
    With ``ephemeris.attitude_n`` every epoch also carries the CR3BP attitude solutions of
    :func:`_transition_attitudes` (found before any epoch is computed)."""
    from ..ephemeris.epochs import iso_tdb
    from .results import check_output
    from .transition import run_transition_to

    path = _result_path(study, out, "transition")
    if study.ephemeris is None:
        raise StudyError(["ephemeris: missing section [ephemeris]: a transition needs the epoch(s) (ephemeris.epoch)"])
    check_output(path, "transition", study.to_json(), force=force, say=say)
    orbits = list(study.build_orbits())
    if len(orbits) != 1:
        sel = member_count(study.orbits)
        key, value = (f"orbits.{sel[0]}", sel[1]) if sel else ("orbits.kind", study.orbits.kind)
        raise StudyError([problem(key, value, f"selects {len(orbits)} orbits",
                                  "exactly one orbit: a transition carries one orbit into the ephemeris model")])
    orbit = orbits[0]
    e = study.ephemeris
    eph = study.build_ephemeris()
    epochs = e.epochs_tdb()
    duration_s = e.revolutions * orbit.period * orbit.system.tu_s
    lo, hi = eph.span
    bad = np.flatnonzero((epochs < lo) | (epochs + duration_s > hi))
    if bad.size:
        raw = e.epoch.model_dump() if hasattr(e.epoch, "model_dump") else e.epoch
        raise StudyError([problem("ephemeris.epoch", raw, f"{iso_tdb(float(epochs[bad[0]]))} and its {e.revolutions} revolutions "
                                  f"({duration_s / 86400:.2f} d) leave the ephemeris file's span",
                                  f"epochs from {iso_tdb(lo)} to {iso_tdb(hi - duration_s)} (the file's span less the "
                                  "revolutions' duration)")])
    file = None if e.file is None else str(Path(e.file) if Path(e.file).is_absolute() else (Path(study.base_dir) / e.file).resolve())
    attitudes = _transition_attitudes(study, orbit)
    return run_transition_to(orbit, path, epochs_tdb=epochs, revolutions=e.revolutions, nodes_per_rev=e.nodes_per_rev, ephemeris_file=file,
                             resume=not force, scheduler=scheduler, progress=progress, attrs=study.result_attrs("transition", "transition"),
                             attitudes=attitudes)


def _transition_attitudes(study: Study, orbit) -> list:
    """The CR3BP periodic attitude solutions ``ephemeris.attitude_n`` asks for on ``orbit``, found
    as ``librate solve`` finds them: for each N the periodic solution with N turns of lowest wz0
    in the planar scan (:func:`_solve_one` on the study's Kz, rate window, phi0 and periods), or,
    in a 3-D study, the 3-D motion started as :func:`_start_3d` starts it with n = N and corrected
    by :func:`librate.periodic_attitude_3d`. A StudyError names an N with no solution."""
    wanted = study.ephemeris.attitude_n
    if not wanted:
        return []
    k = study.n_periods()
    if isinstance(study, Study3D):
        from .._errors import ConvergenceError
        from ..periodicity.periodic_attitude3d import periodic_attitude_3d

        body, out = study.build_body(), []
        for n in wanted:
            guess, start = _start_3d(study, orbit, body, k, n=n, key_n="ephemeris.attitude_n")
            try:
                out.append(periodic_attitude_3d(orbit, body, guess=guess, n_periods=k, tol=study.tol))
            except ConvergenceError as err:
                raise StudyError([problem("ephemeris.attitude_n", wanted, f"the 3-D motion with n = {n} ({start['start_description']}) "
                                          f"did not converge: {str(err).splitlines()[0]}")]) from None
        return out
    wz = study.wz0_values()
    kz = float(study.kz_values()[0])
    window = (float(wz[0]), float(wz[-1]))
    found = [_solution_of(orbit, None, d) for d in _solve_one(orbit, kz, window, study.solver.phi0, int(wz.size), k, None)]
    out = []
    for n in wanted:
        hits = [x for x in found if x.kind == "periodic" and x.n == n]
        if not hits:
            others = ", ".join(f"N = {x.n:g} ({x.kind}) at wz0 = {x.wz0:.6g}" for x in found) or "none"
            key = "rates.wz0" if study.rates.wz0 is not None else "rates.phidot0"
            raise StudyError([problem("ephemeris.attitude_n", wanted, f"no periodic solution with N = {n} on the orbit "
                                      f"(x0 = {orbit.x0:.6g} LU, Kz = {kz:g}, phi0 = {study.solver.phi0:g}) for wz0 in "
                                      f"[{wz[0]:g}, {wz[-1]:g}]; found: {others}",
                                      f"the N of periodic solutions in the window, or widen {key}")])
        out.append(hits[0])
    return out


def _family_of(fam, orbits):
    """An OrbitFamily holding the corrected members ``orbits`` of ``fam`` (for saving)."""
    from ..orbits.families import OrbitFamily

    return OrbitFamily.from_members(fam.system, fam.kind, fam.spatial, orbits, fam.end_reason,
                                    {**fam.parameters, "selected": True})
