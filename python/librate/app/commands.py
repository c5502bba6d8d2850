"""The work behind the command line's commands that run no study (``demo``, ``dros``, ``plot``,
``verify``) and the figures of every command (the CLI parses and prints; this module computes
and draws; the study jobs are in :mod:`librate.app.jobs`): each function takes plain arguments
and returns or yields results."""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

import numpy as np

__all__ = ["demo_family", "demo_study", "demo_summary", "describe_for_plot", "draw_figures", "dro_closures", "map_3d_summary",
           "map_solutions_summary",
           "refuse_damaged", "result_kind_of", "run_demo", "solutions_table", "solve_3d_summary", "writable_problem"]


def dro_closures(system, xs: Sequence[float]) -> Iterator[tuple[float, object, float, float]]:
    """For each x0 of ``xs``: the DRO corrected by half-period shooting (its ydot0 seeds the
    next one), propagated over one whole period at rtol = atol = 1e-13; yields (x0, orbit,
    closure = max |state(T) - state(0)|, seconds). Raises ValueError for an x0 outside the
    primaries, and the correction's LibrateError."""
    from ..orbits.families import correct_dro
    from ..orbits.propagation import propagate

    lo, hi = -system.mu, 1.0 - system.mu
    for x0 in xs:
        if not lo < x0 < hi:
            raise ValueError(f"--x0 {x0:g}: a DRO starts between the primaries, {lo:.6g} < x0 < {hi:.6g} LU (Earth at -mu, Moon at 1 - mu)")
    guess = None
    for x0 in xs:
        t_start = time.perf_counter()
        orbit = correct_dro(system, x0, guess)
        one = propagate(system, orbit.state0, orbit.period, rtol=1e-13, atol=1e-13, t_eval=[orbit.period], collision="point")
        yield x0, orbit, float(np.max(np.abs(one.y[-1] - orbit.state0))), time.perf_counter() - t_start
        guess = orbit.state0[4]


def writable_problem(folder: Path) -> str | None:
    """Why ``folder`` cannot be created or written (None when it can): checked before any work."""
    import tempfile

    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as err:
        return err.strerror or type(err).__name__
    return None


def demo_study(system_name: str, kz: float, n_orbits: int, n_rates: int) -> str:
    """The demo's inputs as the study its result records (JSON): its members are ``n_orbits``
    DROs with x0 evenly from 0.95 to 0.15 and the DRO of period RESIDUALS_PERIOD_DAYS (12.66 d,
    thesis Fig. 23), as :func:`demo_family` computes them."""
    import json

    from ..results.kinds import RESIDUALS_PERIOD_DAYS

    orbits = {"kind": "dro", "x0": {"start": 0.95, "stop": 0.15, "num": n_orbits}, "period_days": [RESIDUALS_PERIOD_DAYS]}
    return json.dumps({"system": {"preset": system_name}, "orbits": orbits, "body": {"kz": kz},
                       "rates": {"wz0": {"start": -3.0, "stop": 2.0, "num": n_rates}}}, sort_keys=True)


def demo_family(system, n_orbits: int):
    """The demo's DRO family: ``n_orbits`` members with x0 evenly from 0.95 to 0.15 (natural
    continuation, :func:`librate.dro_family`) and, in x0 order among them, the DRO of thesis
    Fig. 23, of period RESIDUALS_PERIOD_DAYS (12.66 d), corrected with that period imposed
    (:meth:`librate.OrbitFamily.member`). The members' stability comes from one batched
    propagation (:meth:`librate.OrbitFamily.from_members`; bifurcations interpolated between
    consecutive members). Returns ``(family, index of the 12.66-day DRO)``."""
    from ..orbits.families import dro_family
    from ..orbits.orbit_family import OrbitFamily
    from ..results.kinds import RESIDUALS_PERIOD_DAYS

    grid = dro_family(system, x0=np.linspace(0.95, 0.15, n_orbits))
    fig23 = grid.member(period_days=RESIDUALS_PERIOD_DAYS)
    k = int(np.searchsorted(-grid.x0, -fig23.x0))  # x0 decreases along the grid
    if k < len(grid) and grid.x0[k] == fig23.x0:
        return grid, k
    members = list(grid)
    members.insert(k, fig23)
    return OrbitFamily.from_members(system, "dro", False, members, grid.end_reason, grid.parameters), k


def run_demo(system_name: str, kz: float, n_orbits: int, n_rates: int, path: Path, *, force: bool, say: Callable[[str], None],
             echo: Callable[[str], None], progress=None):
    """The demo's map: the DRO family (:func:`demo_family`: ``n_orbits`` members with x0 from
    0.95 to 0.15, and the 12.66-day DRO of thesis Fig. 23), its periodicity map at ``kz`` over
    ``n_rates`` inertial rates wz0 in [-3, 2] with the solutions, saved at ``path``. Returns
    ``(ds, family)``; ``family`` is None when the map at ``path`` was made from the same options
    and is reused (``say`` tells). ``echo`` receives the timing lines. Raises
    :class:`~librate.app.results.ResultExists` for a map of other options (unless ``force``)
    and OSError when ``path`` cannot be written."""
    from .._core import __version__
    from ..orbits.system import System
    from ..periodicity.maps import periodicity_map
    from .results import check_output, open_result, save_dataset

    study = demo_study(system_name, kz, n_orbits, n_rates)
    if check_output(path, "map", study, force=force, say=say) == "resume":
        say(f"reused: {path} already holds this map (same options; --force recomputes it)")
        return open_result(path), None
    system = System.preset(system_name)
    t0 = time.perf_counter()
    fam, k = demo_family(system, n_orbits)
    t1 = time.perf_counter()
    echo(f"DRO family: {len(fam)} members, x0 {fam.x0[0]:.3f} -> {fam.x0[-1]:.3f}, "
         f"period {fam.period_days.min():.2f} to {fam.period_days.max():.2f} d, with the {fam.period_days[k]:.2f}-day DRO "
         f"(thesis Fig. 23) at x0 = {fam.x0[k]:.4f} ({t1 - t0:.2f} s)")
    ds = periodicity_map(fam, kz=kz, wz0=np.linspace(-3.0, 2.0, n_rates), progress=progress)
    t2 = time.perf_counter()
    n_traj = ds.dwz.size
    echo(f"periodicity map: {len(fam)} orbits x {n_rates} rates at Kz = {kz}: {n_traj} attitude trajectories in {t2 - t1:.2f} s "
         f"({n_traj / (t2 - t1):,.0f} per s, with solving)")
    ds.attrs.update({"librate_result": "map", "librate_command": "demo", "study": study, "librate_version": __version__})
    save_dataset(ds, path)
    return ds, fam


def refuse_damaged(p: Path) -> None:
    """Raise ValueError naming the damage of the result at ``p`` (any kind); an incomplete map
    store is not damaged (it is drawn)."""
    from ..results.store import store_kind, verify_store
    from .results import verify_result

    if p.is_dir() and store_kind(p) is not None:
        rep = verify_store(p)
        if rep.damaged or rep.problems:
            raise ValueError(rep.describe())
        return
    ok, report = verify_result(p)
    if not ok:
        raise ValueError(report)


def result_kind_of(result):
    """The result kind class (:mod:`librate.results.kinds`) of what :func:`librate.open_result`
    returned, or None."""
    from ..orbits.orbit_family import OrbitFamily
    from ..results.kinds import FamilyResult, kind_of

    return FamilyResult if isinstance(result, OrbitFamily) else kind_of(result)


def describe_for_plot(result) -> str:
    """One line on what ``librate plot`` draws the figures of."""
    kind = result_kind_of(result)
    if kind is not None and kind.kind == "family":
        return f"{result.kind} family: {len(result)} members"
    if kind is not None and kind.kind == "solutions_3d":
        return f"3-D solutions: {', '.join(f'{k} {v}' for k, v in result.sizes.items() if k == 'member')}"
    name = result.attrs.get("librate_result") or ("map" if "dwz" in result.variables else "solutions")
    return f"{name}: {', '.join(f'{k} {v}' for k, v in result.sizes.items())}"


def draw_figures(result, path: Path, names=None, *, show: bool | None = None, extra: dict | None = None) -> list[Path]:
    """Draw the figures of the result saved at ``path`` beside it, as ``<stem>_<figure>.png``:
    those its kind draws (:meth:`librate.results.kinds.ResultKind.figures`) among ``names``
    (default: all of them), and ``extra``, more figures ``{name: make(plotting_module)}``. The
    data a figure needs beyond the result are computed here. A figure that does not apply or
    fails is skipped with a note on stderr (the result is kept); each written path is printed.
    A figure that cannot be written (a full disk) raises OSError naming it (its partial file
    removed; the result is kept). Returns the written paths."""
    import sys

    if names is not None and not names and not extra:
        return []
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from .. import plotting as lp
    except ImportError as err:
        print("figures skipped: matplotlib, a required dependency of librate, cannot be imported "
              f"({err}); reinstall librate", file=sys.stderr)
        return []
    from .progress import bar
    from .results import solution_3d

    folder, stem = path.parent, path.stem
    kind = result_kind_of(result)
    data = {"solution": lambda: solution_3d(result, 0)} if kind is not None and kind.kind == "solutions_3d" else {}

    def skip(suffix: str, reason: str) -> None:
        print(f"{stem}_{suffix}.png skipped: {reason}", file=sys.stderr)

    figs = [] if kind is None else kind.figures(result, names, skip=skip, **data)
    jobs = [(f"{stem}_{suffix}.png", make) for suffix, make in figs]
    for name, make in (extra or {}).items():
        jobs.append((f"{stem}_{name}.png", lambda make=make: make(lp)))
    written = []
    with bar(len(jobs), "figures", "figure", show) as progress:
        for name, make in jobs:
            try:
                fig = make()
            except Exception as err:  # a figure must not lose the computed result
                progress.write(f"{name} skipped: {type(err).__name__}: {err}", file=sys.stderr)
                progress.update(1)
                continue
            try:
                written.append(lp.save_figure(fig, folder / name))
            except OSError as err:  # a full disk (issue 24 #5): no partial figure left, the result kept
                plt.close(fig)
                with contextlib.suppress(OSError):
                    (folder / name).unlink(missing_ok=True)
                raise OSError(err.errno, f"cannot write the figure ({err.strerror or type(err).__name__}); the result "
                                         f"{path} is kept, complete",
                              str(folder / name)) from None
            plt.close(fig)
            progress.update(1)
            progress.write(f"written: {folder / name}", file=sys.stdout)
    return written


# --- the tables the commands print --------------------------------------------------------------
def demo_summary(ds, shown_n: int = 3) -> list[str]:
    out: list[str] = []
    n_, kind_ = ds.sol_n.values, ds.sol_kind.values.astype(str)
    listed = np.abs(n_) <= shown_n
    total = int(ds.sizes["solution"])
    omitted = "" if listed.all() else (f"; listed below: |N| <= {shown_n} ({int(listed.sum())}), "
                                       f"{total - int(listed.sum())} with |N| > {shown_n} omitted")
    out.append("solutions (phi(T) = 2 pi N, wz(T) = wz0, refined by Newton, residual from an independent "
               f"re-propagation): {total}{omitted}")
    out.append(f"{'N':>4} {'kind':>10} {'count':>6} {'stable':>7} {'phidot0 range [1/TU]':>24} {'max residual':>13}")
    for (n, kind) in sorted(set(zip(n_.tolist(), kind_.tolist())), key=lambda x: (x[1], x[0])):
        if abs(n) > shown_n:
            continue
        sel = (n_ == n) & (kind_ == kind)
        pd = ds.sol_phidot0.values[sel]
        out.append(f"{n:>4g} {kind:>10} {int(sel.sum()):>6} {int(ds.sol_stable.values[sel].sum()):>7} {pd.min():>11.4f} .. "
                   f"{pd.max():<10.4f} {ds.sol_residual.values[sel].max():>13.1e}")
    return out


def solve_3d_summary(ds, elapsed: float) -> list[str]:
    """The table of a 3-D solve: one line per member, then how the continuation ended and the
    located stability changes."""
    out: list[str] = []
    import ast

    from .results import multipliers_3d

    m = multipliers_3d(ds)
    n = ds.sizes["member"]
    out.append(f"periodic 3-D attitude motion along {n} of {ds.attrs.get('members_requested', n)} member(s) of the "
               f"{ds.attrs.get('orbit_family')} family, body moments "
               f"({', '.join(f'{v:.6g}' for v in np.atleast_1d(ds.attrs['body_moments']))}) kg m^2, K = {ds.attrs['n_periods']} "
               f"({elapsed:.2f} s); start: {ds.attrs.get('start_description')}")
    out.append(f"{'member':>6} {'T [d]':>9} {'x0 [LU]':>9} {'z0 [LU]':>9} {'q0 (x, y, z, w)':>36} {'w0 [1/TU] (x, y, z)':>36} "
               f"{'max|mult|':>10} {'stable':>6} {'turns':>6} {'residual':>9}")
    for j in range(n):
        q, w = ds["q0"].values[j], ds["w0"].values[j]
        turns = ds["turns"].values[j]
        out.append(f"{j:>6d} {ds['period_days'].values[j]:>9.5f} {ds['x0'].values[j]:>9.5f} {ds['z0'].values[j]:>9.5f} "
                   f"{' '.join(f'{v:8.5f}' for v in q):>36} {' '.join(f'{v:11.7f}' for v in w):>36} {np.abs(m[j]).max():>10.6g} "
                   f"{'yes' if ds['stable'].values[j] else 'no':>6} {'-' if np.isnan(turns) else f'{round(turns, 3) + 0.0:.3f}':>6} "
                   f"{ds['residual'].values[j]:>9.1e}")
    out.append(f"continuation: {ds.attrs.get('end_reason')}")
    for ch in ast.literal_eval(ds.attrs.get("stability_changes", "[]")):
        where = f"at T = {ch['at']:.10g} d" + ("" if ch["located"] else " (interpolated)")
        if ch["between"][1] is None:  # past the last member (the continuation stalled there)
            out.append(f"stability change ({ch['kind']}) {where}, after T = {ch['between'][0]:.6g} d, the last member "
                       f"(multipliers on the unit circle there: {ch['on_unit_circle'][0]})")
            continue
        out.append(f"stability change ({ch['kind']}) {where}, between T = {ch['between'][0]:.6g} and {ch['between'][1]:.6g} d "
                   f"(multipliers on the unit circle: {ch['on_unit_circle'][0]} -> {ch['on_unit_circle'][1]})")
    return out


def map_3d_summary(ds, elapsed: float) -> list[str]:
    """One line for the 3-D map and one per orbit: its smallest residual max-norm and where."""
    out: list[str] = []
    grid = [d for d in ds["residual_norm"].dims if d != "orbit"]
    n = int(np.prod([ds.sizes[d] for d in ds["residual_norm"].dims]))
    out.append(f"3-D attitude map: {ds.sizes['orbit']} orbits x {' x '.join(f'{ds.sizes[d]} {d}' for d in grid)} = {n} trajectories "
               f"({elapsed:.2f} s); residual = (rotation vector of R(0)' R(KT), w(KT) - w0)")
    for i in range(ds.sizes["orbit"]):
        r = ds["residual_norm"].isel(orbit=i)
        k = np.unravel_index(int(np.nanargmin(r.values)), r.shape)
        at = ", ".join(f"{d} = {float(ds[d].values[j]):.4f}" for d, j in zip(grid, k))
        out.append(f"  orbit {i} (T = {float(ds['period_days'].values[i]):.4f} d): smallest max |residual| "
                   f"{float(r.values[k]):.2e} at {at}")
    return out


def map_solutions_summary(ds) -> list[str]:
    out: list[str] = []
    if "solution" not in ds.sizes or ds.sizes["solution"] == 0:
        out.append("solutions: none in the rate window")
        return out
    n_, kind_ = ds["sol_n"].values, ds["sol_kind"].values.astype(str)
    stable, res, pd = ds["sol_stable"].values, ds["sol_residual"].values, ds["sol_phidot0"].values
    out.append(f"solutions (wz(T) = wz0, phi(T) = phi0 + 2 pi N, refined by Newton): {ds.sizes['solution']}")
    out.append(f"{'N':>4} {'kind':>10} {'count':>6} {'stable':>7} {'phidot0 range [1/TU]':>24} {'max residual':>13}")
    for n, kind in sorted(set(zip(n_.tolist(), kind_.tolist())), key=lambda x: (x[1], -x[0])):
        sel = (n_ == n) & (kind_ == kind)
        out.append(f"{n:>4g} {kind:>10} {int(sel.sum()):>6} {int(stable[sel].sum()):>7} {pd[sel].min():>11.4f} .. {pd[sel].max():<10.4f} "
                   f"{res[sel].max():>13.1e}")
    return out


def solutions_table(ds) -> list[str]:
    """One line per planar solution of a solve (orbit, x0, period, Kz, N, kind, rates, phi0, trace, stability, residual)."""
    cols = ("orbit", "x0", "period_days", "kz", "n", "kind", "wz0", "phidot0", "phi0", "trace", "stable", "residual")
    out = [f"{'orbit':>5} {'x0 [LU]':>9} {'T [d]':>8} {'Kz':>6} {'N':>4} {'kind':>9} {'wz0 [1/TU]':>13} {'phidot0':>13} {'phi0':>9} "
           f"{'trace':>10} {'stable':>6} {'residual':>9}"]
    for j in range(ds.sizes["solution"]):
        r = {k: ds[f"sol_{k}"].values[j] for k in cols}
        out.append(f"{r['orbit']:>5d} {r['x0']:>9.5f} {r['period_days']:>8.4f} {r['kz']:>6.3g} {r['n']:>4g} "
                   f"{r['kind']:>9} {r['wz0']:>13.8f} {r['phidot0']:>13.8f} {r['phi0']:>9.5f} {r['trace']:>10.4g} "
                   f"{'yes' if r['stable'] else 'no':>6} {r['residual']:>9.1e}")
    return out
