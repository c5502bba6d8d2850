"""The ``librate`` command line.

Study commands (``family``, ``solve``, ``map``) read a TOML study file (``librate init`` writes a
commented one), validate all of it before any work, and write results with the study and the
package version as attributes; ``plot`` re-draws figures from a saved result. ``demo``, ``dros``
and ``info`` need no study.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import click
import numpy as np

from .._core import __version__
from .._errors import LibrateError
from ..orbits.system import System
from .jobs import run_family, run_map, run_solve

_CONTEXT = {"help_option_names": ["-h", "--help"], "max_content_width": 100}


class UserError(click.ClickException):
    """A user mistake (a bad option value, an output that cannot or may not be written, a path
    that is not a result): one line on stderr, exit status 2, no traceback."""

    exit_code = 2


class StudyInvalid(UserError):
    """An invalid study file: every problem listed, exit status 2, nothing computed."""


def _say(text: str) -> None:
    """A note on stderr (what a run reuses or replaces): shown even with --quiet."""
    click.echo(text, err=True)


@click.group(context_settings=_CONTEXT)
@click.version_option(__version__, prog_name="librate")
def main() -> None:
    """librate: coupled orbit-attitude dynamics of large spacecraft in the Earth-Moon CR3BP.

    \b
    Start here:
      librate demo                         the DRO map at Kz = 0.8 with no study file
      librate init study.toml              write a commented example study
      librate family study.toml            the orbit family (continuation), saved + figures
      librate solve study.toml             periodic attitude motions of each orbit, as a table
      librate map study.toml               the attitude periodicity map (thesis Fig. 24)
      librate plot librate-out/map.zarr    re-draw the figures of any saved result
      librate verify librate-out/map.zarr  checksums: name any damaged chunk or row
      librate dros --x0 0.9                correct DROs and check that they close
      librate info                         version, system presets and their constants

    \b
    Every command writes <command>.zarr (or .nc) and <command>_<figure>.png into its output
    folder (--out, default librate-out), so commands never overwrite each other. Re-running a
    command resumes or reuses its result when the inputs are the same; a result of other
    inputs is refused, naming what changed, unless --force (which says what it replaces).

    Units: nondimensional CR3BP units (LU = distance between the primaries, TU = 1 / mean
    motion; rates in 1/TU, the synodic frame turns at rate 1), angles in rad, periods in days.
    Run `librate COMMAND --help` for what each command computes, reads and writes.
    """


@main.command(context_settings=_CONTEXT, short_help="Version, system presets and their constants, optional parts.")
def info() -> None:
    """Show the version, the build (SIMD levels), the system presets with their constants, and
    the optional parts.

    Build: the Rust profile, the SIMD levels this CPU supports and the one the kernels run at
    (``LIBRATE_SIMD`` forces one). For each preset: the mass ratio mu, the length unit LU (km),
    the time unit TU (s and days) and the x coordinate of L1 (LU). Parts: matplotlib (figures,
    required), the chunked map runner (resumable and distributed maps) and Dask (optional).
    """
    import importlib.util

    from .._build import build_info

    click.echo(f"librate {__version__}")
    b = build_info()
    click.echo(f"  build: {b['profile']} ({b['target_arch']}); SIMD level {b['simd_active']} "
               f"(this CPU supports: {', '.join(b['simd_available'])}; LIBRATE_SIMD forces one)")
    for name in System.presets():
        s = System.preset(name)
        l1 = s.lagrange_points()[0, 0]
        click.echo(f"  {name:16s} mu = {s.mu:.15g}  LU = {s.lu_km} km  TU = {s.tu_s} s ({s.tu_days:.6f} d)  L1 x = {l1:.15f}")
    parts = {
        "figures (matplotlib, a required dependency)": importlib.util.find_spec("matplotlib") is not None,
        "chunked, resumable map runner (librate.app.runner)": importlib.util.find_spec("librate.app.runner") is not None,
        "distributed runs (dask.distributed)": importlib.util.find_spec("dask") is not None,
    }
    for what, ok in parts.items():
        click.echo(f"  {what}: {'available' if ok else 'not installed'}")


_FORCE_HELP = ("--resume (default): continue or reuse the result in the output folder when it was made from the same inputs "
               "(a result of other inputs is refused, naming what changed). --force: recompute and replace it, saying what it replaces; "
               "for solve and map it also lifts the size limits (trajectory-periods, memory) printed before the run.")
_PRESET = click.Choice(System.presets())

# the demo's options, as the study keys its result records (for "changed: --kz 0.8 -> 0.5")
_DEMO_KEYS = {"system.preset": "--system", "body.kz": "--kz", "orbits.x0.num": "--orbits", "rates.wz0.num": "--rates"}


def _demo_study(system_name: str, kz: float, n_orbits: int, n_rates: int) -> str:
    import json

    return json.dumps({"system": {"preset": system_name}, "orbits": {"kind": "dro", "x0": {"start": 0.95, "stop": 0.15, "num": n_orbits}},
                       "body": {"kz": kz}, "rates": {"wz0": {"start": -3.0, "stop": 2.0, "num": n_rates}}}, sort_keys=True)


def _in_cli_words(message: str, keys: dict[str, str]) -> str:
    for key, option in keys.items():
        message = message.replace(f"{key}: ", f"{option} ")
    return message


@main.command(context_settings=_CONTEXT, short_help="The DRO attitude periodicity map at Kz = 0.8, no study file needed.")
@click.option("--system", "system_name", default="earth-moon", show_default=True, type=_PRESET, help="System preset.")
@click.option("--kz", default=0.8, show_default=True, type=click.FloatRange(-1, 1), help="Inertia parameter Kz = (Iy - Ix)/Iz.")
@click.option("--orbits", "n_orbits", default=60, show_default=True, type=click.IntRange(2, 2000), help="DRO family members, x0 from 0.95 to 0.15.")
@click.option("--rates", "n_rates", default=1000, show_default=True, type=click.IntRange(10, 100000), help="Initial rates, phidot0 in [-4, 1] (wz0 in [-3, 2]).")
@click.option("--out", "out_dir", default="librate-out", show_default=True, type=click.Path(file_okay=False), help="Output folder for demo.nc and the demo_*.png figures.")
@click.option("--resume/--force", default=True, help=_FORCE_HELP)
@click.option("--quiet", "-q", is_flag=True, help="No progress bars and no table; print only the written paths.")
def demo(system_name: str, kz: float, n_orbits: int, n_rates: int, out_dir: str, resume: bool, quiet: bool) -> None:
    """The main job on a default study: the attitude periodicity map of the DRO family (thesis
    Fig. 24), its periodic solutions refined by Newton and grouped into families by N (Figs.
    27-29), saved as netCDF with PNG figures in the output folder.

    Computes the DRO family by continuation, integrates the planar attitude of a body with the
    given Kz along every member for a grid of initial rates (Rust engine, SIMD lanes, all
    cores), finds where wz(T) = wz0 and phi(T) = 2 pi N, and prints the solutions by N.

    \b
    Writes to the output folder:
      demo.nc        the map (as `librate map` writes it): dwz, dphi, phi_T over
                     (orbit, kz, wz0), the solutions sol_*, units and parameters
      demo_contours.png, demo_residuals.png, demo_solutions.png, demo_orbits.png
                     Fig. 24, Fig. 23 (first orbit), Figs. 27-29, Fig. 3
    `librate plot OUT/demo.nc` re-draws the first three from the file.
    """
    from ..orbits.families import dro_family
    from ..periodicity.maps import periodicity_map
    from .progress import reporter
    from .results import ResultExists, check_output, open_result, save_dataset

    out = Path(out_dir)
    path = out / "demo.nc"
    study = _demo_study(system_name, kz, n_orbits, n_rates)
    try:
        decision = check_output(path, "map", study, force=not resume, say=lambda text: _say(_in_cli_words(text, _DEMO_KEYS)))
    except ResultExists as err:
        raise UserError(_in_cli_words(str(err), _DEMO_KEYS)) from None
    except FileExistsError as err:
        raise UserError(str(err)) from None
    _check_writable(out, "--out")
    if decision == "resume":
        _say(f"reused: {path} already holds this map (same options; --force recomputes it)")
        ds = open_result(path)
        if not quiet:
            _demo_summary(ds)
        click.echo(f"written: {path} (earlier)")
        return
    system = System.preset(system_name)
    t0 = time.perf_counter()
    fam = dro_family(system, x0=np.linspace(0.95, 0.15, n_orbits))
    t1 = time.perf_counter()
    _echo(quiet, f"DRO family: {len(fam)} members, x0 {fam.x0[0]:.3f} -> {fam.x0[-1]:.3f}, period {fam.period_days.min():.2f} to {fam.period_days.max():.2f} d ({t1 - t0:.2f} s)")
    wz0 = np.linspace(-3.0, 2.0, n_rates)
    ds = periodicity_map(fam, kz=kz, wz0=wz0, progress=reporter("periodicity map (and solutions)", "orbit", None if not quiet else False))
    t2 = time.perf_counter()
    n_traj = ds.dwz.size
    _echo(quiet, f"periodicity map: {len(fam)} orbits x {n_rates} rates at Kz = {kz}: {n_traj} attitude trajectories in {t2 - t1:.2f} s ({n_traj / (t2 - t1):,.0f} per s, with solving)")
    if not quiet:
        _demo_summary(ds)
    from .._core import __version__

    ds.attrs.update({"librate_result": "map", "librate_command": "demo", "study": study, "librate_version": __version__})
    try:
        save_dataset(ds, path)
    except OSError as err:
        raise UserError(f"--out {out}: cannot write {path.name} there ({err.strerror or err})") from None
    click.echo(f"written: {path} (xarray Dataset: dwz, dphi, phi_T over (orbit, kz, wz0), solutions, units and parameters)")
    _figures(ds, path, ("map", "residuals", "solutions"), quiet, extra={"family": lambda lp: lp.plot_family(fam)})


def _demo_summary(ds, shown_n: int = 3) -> None:
    n_, kind_ = ds.sol_n.values, ds.sol_kind.values.astype(str)
    listed = np.abs(n_) <= shown_n
    total = int(ds.sizes["solution"])
    omitted = "" if listed.all() else f"; listed below: |N| <= {shown_n} ({int(listed.sum())}), {total - int(listed.sum())} with |N| > {shown_n} omitted"
    click.echo(f"solutions (phi(T) = 2 pi N, wz(T) = wz0, refined by Newton, residual from an independent re-propagation): {total}{omitted}")
    click.echo(f"{'N':>4} {'kind':>10} {'count':>6} {'stable':>7} {'phidot0 range [1/TU]':>24} {'max residual':>13}")
    for (n, kind) in sorted(set(zip(n_.tolist(), kind_.tolist())), key=lambda x: (x[1], x[0])):
        if abs(n) > shown_n:
            continue
        sel = (n_ == n) & (kind_ == kind)
        pd = ds.sol_phidot0.values[sel]
        click.echo(f"{n:>4g} {kind:>10} {int(sel.sum()):>6} {int(ds.sol_stable.values[sel].sum()):>7} {pd.min():>11.4f} .. {pd.max():<10.4f} {ds.sol_residual.values[sel].max():>13.1e}")


@main.command(name="dros", context_settings=_CONTEXT, short_help="Correct distant retrograde orbits and check that each closes.")
@click.option("--system", "system_name", default="earth-moon", show_default=True, type=_PRESET, help="System preset.")
@click.option("--x0", "x0_values", multiple=True, type=float, help="DRO start(s) on the x axis, between the primaries (default: 0.96 0.93 0.90 0.87 0.84 0.81).")
def dros(system_name: str, x0_values: tuple[float, ...]) -> None:
    """Correct a set of distant retrograde orbits and check each over one full period.

    Each DRO is corrected by half-period shooting with the STM, continued from the previous one
    (its ydot0 seeds the next), then propagated over a whole period to show that it closes.
    """
    from .commands import dro_closures

    system = System.preset(system_name)
    xs = x0_values or (0.96, 0.93, 0.90, 0.87, 0.84, 0.81)
    rows = dro_closures(system, xs)
    try:
        first = next(rows, None)
    except ValueError as err:  # an x0 outside the primaries (named), or the first correction's
        raise UserError(str(err) if str(err).startswith("--x0") else f"--x0 {xs[0]:g}: {err}") from None
    except LibrateError as err:
        raise click.ClickException(f"--x0 {xs[0]:g}: {type(err).__name__}: {str(err).splitlines()[0]}") from None
    click.echo(f"Distant retrograde orbits in {system.name} (mu = {system.mu}), corrected by half-period shooting:")
    click.echo(f"{'x0':>8} {'ydot0':>18} {'period [TU]':>16} {'period [d]':>11} {'Jacobi':>17} {'iter':>4} {'closure':>9} {'time':>7}")
    row, i = first, 0
    while row is not None:
        x0, orbit, closure, elapsed = row
        click.echo(f"{x0:8.4f} {orbit.state0[4]:18.15f} {orbit.period:16.12f} {orbit.period_days:11.6f} "
                   f"{orbit.jacobi:17.14f} {orbit.iterations:4d} {closure:9.1e} {elapsed * 1e3:5.1f}ms")
        i += 1
        try:
            row = next(rows, None)
        except ValueError as err:
            raise UserError(f"--x0 {xs[i]:g}: {err}") from None
        except LibrateError as err:
            raise click.ClickException(f"--x0 {xs[i]:g}: {type(err).__name__}: {str(err).splitlines()[0]}") from None
    click.echo("closure = max |state(T) - state(0)| after one full period at rtol = atol = 1e-13.")


# --- studies ------------------------------------------------------------------------------------
_FAILURES = (FileExistsError, RuntimeError, ValueError, LibrateError, OSError)


def _check_writable(folder: Path, what: str) -> None:
    """Refuse, before any work, an output folder that cannot be created or written."""
    import tempfile

    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as err:
        raise UserError(f"{what} {folder}: cannot write there ({err.strerror or type(err).__name__})") from None


def _failure(err: Exception) -> click.ClickException:
    """A clean message for what went wrong after validation (a member outside the family, a
    refused output folder, a computation that failed)."""
    from .study import StudyError

    if isinstance(err, StudyError):
        return StudyInvalid(str(err))
    if isinstance(err, LibrateError):  # the computation failed: exit status 1
        return click.ClickException(f"{type(err).__name__}: {err}")
    if isinstance(err, (ValueError, FileExistsError)):  # a refused output, a member not on the family
        return UserError(str(err))
    if isinstance(err, OSError):
        return UserError(f"{getattr(err, 'filename', None) or 'output'}: cannot write there ({err.strerror or type(err).__name__})")
    return click.ClickException(str(err))


def _overrides(sets: tuple[str, ...]) -> dict:
    out = {}
    for item in sets:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise click.BadParameter(f"{item!r}: expected KEY=VALUE, e.g. rates.wz0.num=200", param_hint="--set")
        out[key.strip()] = value.strip()
    return out


def _load_study(path: str | None, purpose: str, overrides: dict, force: bool = False, quiet: bool = True):
    """The validated study, or a StudyInvalid listing every problem. ``force``: lift the size
    limits of a solve or a map; unless ``quiet``, say its size (trajectories, memory) first."""
    from .study import Study, StudyError, apply_overrides

    try:
        if path is None:
            st = Study.from_dict(apply_overrides({}, overrides), purpose=purpose, base_dir=Path.cwd(), source="(command-line options)", force=force)
        else:
            st = Study.from_toml(path, purpose=purpose, overrides=overrides, force=force)
    except StudyError as err:
        raise StudyInvalid(str(err)) from None
    if purpose in ("solve", "map") and not quiet:
        _say(f"{purpose}: {st.estimate(purpose).text()}")
    return st


def _show(quiet: bool) -> bool | None:
    """Progress bars: never with --quiet, else only in a terminal (None: decided on stderr)."""
    return False if quiet else None


def _echo(quiet: bool, text: str) -> None:
    if not quiet:
        click.echo(text)


_SET_HELP = "Override a study key, KEY=VALUE with a TOML value (repeatable): --set body.kz=0.5 --set rates.wz0.num=200."


@main.command(context_settings=_CONTEXT, short_help="Write a commented example study file to start from.")
@click.argument("path", default="study.toml", type=click.Path(dir_okay=False))
@click.option("--force", is_flag=True, help="Overwrite PATH if it exists.")
def init(path: str, force: bool) -> None:
    """Write a commented example study to PATH (default study.toml) to start from.

    The example is the DRO attitude periodicity map at Kz = 0.8: 12 DROs (x0 from 0.9 to 0.3 LU),
    300 inertial initial rates wz0 in [-3, 2] 1/TU, results and figures in librate-out/ next to
    the file. Every key is explained in the file; edit it, then run `librate map PATH`.
    """
    from .study import EXAMPLE_STUDY

    p = Path(path)
    if p.exists() and not force:
        raise UserError(f"{p} exists: not overwritten (use --force to replace it)")
    try:
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(EXAMPLE_STUDY, encoding="utf-8")
    except OSError as err:
        raise UserError(f"{p}: cannot write there ({err.strerror or type(err).__name__})") from None
    click.echo(f"written: {p}\nnext: librate map {p}   (or: librate family {p}, librate solve {p})")


def _x0_option(text: str):
    """'START:STOP:NUM' -> a range table, 'a,b,c' -> a list (left as text when unparsable, for
    the study's own error message)."""
    from .study import parse_value

    if ":" in text:
        parts = [parse_value(v) for v in text.split(":")]
        if len(parts) == 3:
            return {"start": parts[0], "stop": parts[1], "num": parts[2]}
        return text
    vals = [parse_value(v) for v in text.split(",")]
    return vals


@main.command(context_settings=_CONTEXT, short_help="An orbit family by continuation, saved with its figures.")
@click.argument("study", required=False, type=click.Path(exists=True, dir_okay=False))
@click.option("--kind", help="Family: dro, lyapunov or halo (orbits.kind).")
@click.option("--point", type=int, help="Lagrange point 1 or 2, for lyapunov and halo (orbits.point).")
@click.option("--branch", help="north or south, for halo (orbits.branch).")
@click.option("--x0", "x0", help="Members by x0 in LU: START:STOP:NUM or a comma list 0.9,0.8 (orbits.x0).")
@click.option("--members", type=int, help="That many members evenly spread along the family (orbits.members).")
@click.option("--system", "system_name", help="System preset, e.g. earth-moon or earth-moon-jpl (system.preset).")
@click.option("--format", "fmt", help="zarr or netcdf (output.format).")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE", help=_SET_HELP)
@click.option("--out", "out_dir", type=click.Path(file_okay=False), help="Output folder (default: output.folder of the study, else librate-out).")
@click.option("--resume/--force", default=True, help=_FORCE_HELP)
@click.option("--quiet", "-q", is_flag=True, help="Print only the written paths.")
def family(study, kind, point, branch, x0, members, system_name, fmt, sets, out_dir, resume, quiet) -> None:
    """Compute an orbit family by continuation and save it, from STUDY and/or options.

    \b
    Reads [system] and [orbits] of the study (or the options alone, e.g.
      librate family --kind lyapunov --point 1
      librate family --kind dro --x0 0.9:0.3:25
    ); the options override the study. DROs: natural-parameter continuation in x0 (the listed
    members, or the whole family 0.985 -> 0.005 LU); Lyapunov and halo families (L1/L2, halo
    branch north/south, into the NRHOs): pseudo-arclength continuation. A selection by
    period_days, resonance or sun_resonance keeps the corrected members found on the family.

    \b
    Writes to the output folder:
      family.zarr (or family.nc)  the members: state0 (LU, LU/TU), period (TU, and days), Jacobi
                                  constant, monodromy eigenvalues and stability indices, with
                                  the study (JSON) and the version as attributes;
                                  reload with librate.open_result(path)
      family_orbits.png, family_period.png, family_stability.png   orbits coloured by Jacobi
                                  constant, period against x0 with the resonances, stability
    A family of the same [system] and [orbits] is reused; one of others is refused (--force).
    """
    ov = {}
    for key, value in (("orbits.kind", kind), ("orbits.point", point), ("orbits.branch", branch), ("orbits.members", members),
                       ("system.preset", system_name), ("output.format", fmt)):
        if value is not None:
            ov[key] = value
    if x0 is not None:
        ov["orbits.x0"] = _x0_option(x0)
    ov = {k: _quote(v) for k, v in ov.items()}  # option words stay strings
    ov.update(_overrides(sets))
    st = _load_study(study, "family", ov)
    _check_writable(st.output_dir(out_dir), "--out" if out_dir else "output.folder")
    t0 = time.perf_counter()
    try:
        from .progress import reporter

        fam, path = run_family(st, out_dir, force=not resume, say=_say, progress=reporter("orbit family", "member", _show(quiet)))
    except _FAILURES as err:
        raise _failure(err) from None
    el = time.perf_counter() - t0
    _echo(quiet, f"{fam.kind} family: {len(fam)} members, x0 {fam.x0[0]:.6g} -> {fam.x0[-1]:.6g} LU, period {fam.period_days.min():.4g} to "
                 f"{fam.period_days.max():.4g} d, Jacobi {fam.jacobi.min():.6g} to {fam.jacobi.max():.6g} ({el:.2f} s)")
    _echo(quiet, f"  continuation end: {fam.end_reason}")
    for b in fam.bifurcations:
        _echo(quiet, f"  bifurcation: {b['index']} index, {b['type']}, near x0 = {b['x0']:.6g}")
    click.echo(f"written: {path}")
    _figures(fam, path, st.figures(("family", "period", "stability")), quiet)


def _quote(v):
    """Options given as plain words (kind, branch, preset, format) are strings, not TOML."""
    import json

    return json.dumps(v) if isinstance(v, str) else v


@main.command(context_settings=_CONTEXT, short_help="The periodic attitude motions of each orbit, as a table.")
@click.argument("study", type=click.Path(exists=True, dir_okay=False))
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE", help=_SET_HELP)
@click.option("--out", "out_dir", type=click.Path(file_okay=False), help="Output folder (default: output.folder of the study).")
@click.option("--resume/--force", default=True, help=_FORCE_HELP)
@click.option("--quiet", "-q", is_flag=True, help="No progress and no table; print only the written path.")
@click.option("--scheduler", metavar="tcp://HOST:PORT", help="Solve each orbit and Kz as a task on this Dask scheduler (planar studies; needs dask.distributed).")
def solve(study, sets, out_dir, resume, quiet, scheduler) -> None:
    """Find the periodic attitude motions of each orbit and Kz of STUDY in its rate window.

    For every selected orbit (period T) and every Kz of [body], scans the study's grid of
    initial rates ([rates]: inertial wz0, or phidot0 = wz0 - 1 relative to the synodic frame,
    1/TU) and refines by Newton every planar attitude motion with wz(T) = wz0 and
    phi(T) = phi0 + 2 pi N (N net turns per orbit; "half-turn" motions, phi(T) = phi0 + pi +
    2 pi N, are reported as their own kind). Gravity gradient of both primaries, plus the flat
    plate SRP of [torques.srp] on a Sun-resonant orbit (solver.n_periods orbits per period).
    Each solution is re-propagated independently: the residual is max(|Dphi| rad, |Dwz| 1/TU);
    it is linearly stable when |trace| of its 2x2 monodromy < 2.

    \b
    Prints one line per solution and writes to the output folder:
      solve.zarr (or solve.nc)  over `solution`: orbit index, x0 (LU), period (d), Kz, N,
                      kind, wz0 and phidot0 (1/TU), phi0 (rad), trace, stable, residual,
                      with the study (JSON) and the version as attributes
      solve_solutions.png   the solutions' rates against x0
    A table of the same inputs is reused; one of other inputs is refused (--force).

    \b
    With [attitude] model = "3d": one periodic 3-D attitude motion (quaternion and three
    rates, body.ix/iy/iz) continued along the selected members in their order, started on
    the first member from attitude.start ("planar": the planar n-family solution found in
    the [rates] scan; "spin": the torque-free spin about synodic Z; "given": attitude.q0,
    attitude.w0). Prints one line per member (q0, w0, multipliers, stability, turns,
    residual) and the located stability changes, and writes solve.zarr (or .nc) with
    solve_multipliers.png (Floquet multipliers along the family) and solve_body_axes.png
    (the body axes along the first member's orbit).
    """
    from .progress import reporter

    st = _load_study(study, "solve", _overrides(sets), force=not resume, quiet=quiet)
    _check_writable(st.output_dir(out_dir), "--out" if out_dir else "output.folder")
    three_d = st.attitude.model == "3d"
    t0 = time.perf_counter()
    try:
        ds, path = run_solve(st, out_dir, progress=reporter("3-D solutions" if three_d else "solutions", "member" if three_d else "orbit-Kz",
                                                           _show(quiet)), force=not resume, say=_say, scheduler=scheduler)
    except _FAILURES as err:
        raise _failure(err) from None
    el = time.perf_counter() - t0
    if three_d:
        if not quiet:
            _summary_3d(ds, el)
        click.echo(f"written: {path}")
        _figures(ds, path, st.figures(("multipliers", "body_axes")), quiet)
        return
    n = ds.sizes["solution"]
    _echo(quiet, f"{n} periodic solution(s) over {ds.sizes['orbit']} orbit(s) x {ds.sizes['kz']} Kz ({el:.2f} s)")
    if n and not quiet:
        click.echo(f"{'orbit':>5} {'x0 [LU]':>9} {'T [d]':>8} {'Kz':>6} {'N':>4} {'kind':>9} {'wz0 [1/TU]':>13} {'phidot0':>13} {'phi0':>9} {'trace':>10} {'stable':>6} {'residual':>9}")
        for j in range(n):
            r = {k: ds[f"sol_{k}"].values[j] for k in ("orbit", "x0", "period_days", "kz", "n", "kind", "wz0", "phidot0", "phi0", "trace", "stable", "residual")}
            click.echo(f"{r['orbit']:>5d} {r['x0']:>9.5f} {r['period_days']:>8.4f} {r['kz']:>6.3g} {r['n']:>4g} {r['kind']:>9} {r['wz0']:>13.8f} "
                       f"{r['phidot0']:>13.8f} {r['phi0']:>9.5f} {r['trace']:>10.4g} {'yes' if r['stable'] else 'no':>6} {r['residual']:>9.1e}")
    click.echo(f"written: {path}")
    _figures(ds, path, st.figures(("solutions",)), quiet)


def _summary_3d(ds, elapsed: float) -> None:
    """The table of a 3-D solve: one line per member, then how the continuation ended and the
    located stability changes."""
    import ast

    from .results import multipliers_3d

    m = multipliers_3d(ds)
    n = ds.sizes["member"]
    click.echo(f"periodic 3-D attitude motion along {n} of {ds.attrs.get('members_requested', n)} member(s) of the {ds.attrs.get('orbit_family')} family, "
               f"body moments ({', '.join(f'{v:.6g}' for v in np.atleast_1d(ds.attrs['body_moments']))}) kg m^2, K = {ds.attrs['n_periods']} ({elapsed:.2f} s); start: {ds.attrs.get('start_description')}")
    click.echo(f"{'member':>6} {'T [d]':>9} {'x0 [LU]':>9} {'z0 [LU]':>9} {'q0 (x, y, z, w)':>36} {'w0 [1/TU] (x, y, z)':>36} "
               f"{'max|mult|':>10} {'stable':>6} {'turns':>6} {'residual':>9}")
    for j in range(n):
        q, w = ds["q0"].values[j], ds["w0"].values[j]
        turns = ds["turns"].values[j]
        click.echo(f"{j:>6d} {ds['period_days'].values[j]:>9.5f} {ds['x0'].values[j]:>9.5f} {ds['z0'].values[j]:>9.5f} "
                   f"{' '.join(f'{v:8.5f}' for v in q):>36} {' '.join(f'{v:11.7f}' for v in w):>36} {np.abs(m[j]).max():>10.6g} "
                   f"{'yes' if ds['stable'].values[j] else 'no':>6} {'-' if np.isnan(turns) else f'{round(turns, 3) + 0.0:.3f}':>6} {ds['residual'].values[j]:>9.1e}")
    click.echo(f"continuation: {ds.attrs.get('end_reason')}")
    for ch in ast.literal_eval(ds.attrs.get("stability_changes", "[]")):
        where = f"at T = {ch['at']:.10g} d" + ("" if ch["located"] else " (interpolated)")
        if ch["between"][1] is None:  # past the last member (the continuation stalled there)
            click.echo(f"stability change ({ch['kind']}) {where}, after T = {ch['between'][0]:.6g} d, the last member "
                       f"(multipliers on the unit circle there: {ch['on_unit_circle'][0]})")
            continue
        click.echo(f"stability change ({ch['kind']}) {where}, between T = {ch['between'][0]:.6g} and {ch['between'][1]:.6g} d "
                   f"(multipliers on the unit circle: {ch['on_unit_circle'][0]} -> {ch['on_unit_circle'][1]})")


@main.command(name="map", context_settings=_CONTEXT, short_help="The attitude periodicity map of a study (thesis Fig. 24).")
@click.argument("study", type=click.Path(exists=True, dir_okay=False))
@click.option("--out", "out_dir", type=click.Path(file_okay=False), help="Output folder (default: output.folder of the study); the map goes to OUT/map.zarr.")
@click.option("--quiet", "-q", is_flag=True, help="No progress bar and no summary; print only the written paths.")
@click.option("--scheduler", metavar="tcp://HOST:PORT", help="Run the map's orbits (planar or 3-D) as tasks on this Dask scheduler (needs dask.distributed).")
@click.option("--resume/--force", default=True, help=_FORCE_HELP)
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE", help=_SET_HELP)
def map_(study, out_dir, quiet, scheduler, resume, sets) -> None:
    """Compute the attitude periodicity map of STUDY (thesis Fig. 24) and its solutions.

    For every selected orbit (period T), every Kz and every initial rate wz0 of the grid
    ([rates], 1/TU), integrates the planar attitude from phi0 over solver.n_periods periods
    (Rust engine, all cores) and records the residuals dwz = wz(T) - wz0 (1/TU) and
    dphi = phi(T) - phi0 wrapped to (-pi, pi] (rad) and the unwrapped phi(T); periodic motions
    lie where both vanish and are refined by Newton (N net turns, kind, stability, residual).
    A map is written chunk by chunk and resumable: re-running the same command after an
    interruption continues from the finished chunks (also after editing keys the map does
    not depend on, such as [output]); a map of other inputs is refused, naming the changed
    keys, unless --force.

    \b
    Writes to the output folder:
      map.zarr     dims (orbit, kz, wz0): dwz, dphi, phi_T, status; coordinates x0 (LU),
                   period (TU), period_days, kz, wz0 and phidot0 = wz0 - 1 (1/TU); the
                   solutions sol_* along `solution`; the study (JSON) and the version as
                   attributes (map.nc too with output.format = "netcdf")
      map_contours.png   zero contours of dwz and dphi over (orbit period, phidot0) with
                   the solutions by N (one file per Kz: map_contours_kz<Kz>.png)
      map_residuals.png  dwz and dphi against phidot0, first orbit (thesis Fig. 23)
      map_solutions.png  the solution families across the orbits (thesis Figs. 27-29)

    With [attitude] model = "3d": the six 3-D closure residuals over (orbit, two rate grids)
    in map.zarr (or .nc), saved orbit by orbit (resumable), and map_residual_norm.png.
    """
    st = _load_study(study, "map", _overrides(sets), force=not resume, quiet=quiet)
    _check_writable(st.output_dir(out_dir), "--out" if out_dir else "output.folder")
    t0 = time.perf_counter()
    try:
        ds, path = run_map(st, out_dir, scheduler=scheduler, progress=_show(quiet), force=not resume, say=_say)
    except _FAILURES as err:
        raise _failure(err) from None
    el = time.perf_counter() - t0
    if ds.attrs.get("librate_result") == "map_3d":
        if not quiet:
            _map_3d_summary(ds, el)
        click.echo(f"written: {path}")
        _figures(ds, path, st.figures(("map",)), quiet)
        return
    if not quiet:
        no, nk, nw = ds.sizes["orbit"], ds.sizes["kz"], ds.sizes["wz0"]
        click.echo(f"periodicity map: {no} orbits x {nk} Kz x {nw} rates = {no * nk * nw} attitude trajectories ({el:.2f} s)"
                   + ("" if int(ds.attrs.get("complete", 1)) else "  [INCOMPLETE: interrupted; re-run to resume]"))
        _solution_summary(ds)
    click.echo(f"written: {path}")
    _figures(ds, path, st.figures(("map", "residuals", "solutions")), quiet)


def _map_3d_summary(ds, elapsed: float) -> None:
    """One line for the 3-D map and one per orbit: its smallest residual max-norm and where."""
    grid = [d for d in ds["residual_norm"].dims if d != "orbit"]
    n = int(np.prod([ds.sizes[d] for d in ds["residual_norm"].dims]))
    click.echo(f"3-D attitude map: {ds.sizes['orbit']} orbits x {' x '.join(f'{ds.sizes[d]} {d}' for d in grid)} = {n} trajectories "
               f"({elapsed:.2f} s); residual = (rotation vector of R(0)' R(KT), w(KT) - w0)")
    for i in range(ds.sizes["orbit"]):
        r = ds["residual_norm"].isel(orbit=i)
        k = np.unravel_index(int(np.nanargmin(r.values)), r.shape)
        at = ", ".join(f"{d} = {float(ds[d].values[j]):.4f}" for d, j in zip(grid, k))
        click.echo(f"  orbit {i} (T = {float(ds['period_days'].values[i]):.4f} d): smallest max |residual| {float(r.values[k]):.2e} at {at}")


def _solution_summary(ds) -> None:
    if "solution" not in ds.sizes or ds.sizes["solution"] == 0:
        click.echo("solutions: none in the rate window")
        return
    n_, kind_ = ds["sol_n"].values, ds["sol_kind"].values.astype(str)
    stable, res, pd = ds["sol_stable"].values, ds["sol_residual"].values, ds["sol_phidot0"].values
    click.echo(f"solutions (wz(T) = wz0, phi(T) = phi0 + 2 pi N, refined by Newton): {ds.sizes['solution']}")
    click.echo(f"{'N':>4} {'kind':>10} {'count':>6} {'stable':>7} {'phidot0 range [1/TU]':>24} {'max residual':>13}")
    for n, kind in sorted(set(zip(n_.tolist(), kind_.tolist())), key=lambda x: (x[1], -x[0])):
        sel = (n_ == n) & (kind_ == kind)
        click.echo(f"{n:>4g} {kind:>10} {int(sel.sum()):>6} {int(stable[sel].sum()):>7} {pd[sel].min():>11.4f} .. {pd[sel].max():<10.4f} {res[sel].max():>13.1e}")


@main.command(context_settings=_CONTEXT, short_help="Re-draw the figures of any saved result, without recomputing.")
@click.argument("result_path", type=click.Path(exists=True))
@click.option("--quiet", "-q", is_flag=True, help="Print only the written paths.")
def plot(result_path, quiet) -> None:
    """Re-draw the figures of a saved result, without recomputing.

    RESULT_PATH: a result written by any command (`family`, `solve`, `map`, `demo`) or by
    the Python API (`OrbitFamily.save`, a map saved with `to_netcdf`): a .zarr folder or a .nc
    file, or an output folder holding one of them. The PNGs are written next to it, named
    after it (STEM_FIGURE.png for STEM.zarr or STEM.nc), so they replace only the figures of
    that result:

    \b
      a family   STEM_orbits.png (orbits coloured by Jacobi constant), STEM_period.png
                 (period in days against x0, with the 1:k resonances), STEM_stability.png
      a map      STEM_contours.png (zero contours and solutions; STEM_contours_kz<Kz>.png
                 per Kz when several), STEM_residuals.png (dwz, dphi against phidot0 for
                 the first orbit), STEM_solutions.png (solution families across the orbits)
      solutions  STEM_solutions.png (initial rates phidot0 of the solutions against x0)
      3-D solutions  STEM_multipliers.png (Floquet multipliers along the family),
                 STEM_body_axes.png (body axes along the first member's orbit)
      a 3-D map  STEM_residual_norm.png (log10 of the residual max-norm over the two rate
                 grids, the first three orbits)
    """
    from .results import open_result, resolve_result_path

    try:
        p = resolve_result_path(result_path)
    except (ValueError, FileNotFoundError) as err:
        raise UserError(str(err)) from None
    try:
        _refuse_damaged_store(p)
    except ValueError as err:  # refused: exit status 2, nothing drawn
        raise UserError(str(err)) from None
    try:
        res = open_result(p)
    except (ValueError, FileNotFoundError) as err:
        raise UserError(str(err)) from None
    _check_writable(p.parent, "the folder of RESULT_PATH,")
    from ..orbits.families import OrbitFamily

    if isinstance(res, OrbitFamily):
        _echo(quiet, f"{res.kind} family: {len(res)} members")
        names = ("family", "period", "stability")
    elif res.attrs.get("librate_result") == "solutions_3d":
        _echo(quiet, f"3-D solutions: {', '.join(f'{k} {v}' for k, v in res.sizes.items() if k == 'member')}")
        names = ("multipliers", "body_axes")
    else:
        kind = res.attrs.get("librate_result") or ("map" if "dwz" in res.variables else "solutions")
        _echo(quiet, f"{kind}: {', '.join(f'{k} {v}' for k, v in res.sizes.items())}")
        names = ("map", "residuals", "solutions") if "dwz" in res.variables or kind == "map_3d" else ("solutions",)
    written = _figures(res, p, names, quiet)
    if not written:
        raise click.ClickException("no figure could be drawn (see the messages above)")


def _refuse_damaged_store(p: Path) -> None:
    """A damaged result (any kind) is refused by name; an incomplete map store is drawn."""
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


@main.command(context_settings=_CONTEXT, short_help="Check a saved result for damage, without recomputing it.")
@click.argument("result_path", type=click.Path(exists=True))
def verify(result_path) -> None:
    """Check a saved result for damage, without recomputing it.

    \b
    RESULT_PATH: a map store written by `librate map` (map.zarr): every row of dwz, dphi,
    phi_T and status is read and compared with the checksum written beside its `done` flag;
    rows not computed yet, missing, truncated or garbled chunks, and damaged coordinates or
    solutions are named. Other results (family, solutions, map.nc): every variable is read and
    compared with its stored checksum. Exit status 0 when intact, 1 when damaged or
    incomplete (re-running the same `librate map` recomputes the damaged rows), 2 when
    RESULT_PATH is not a librate result.
    """
    from .results import resolve_result_path, verify_result

    try:
        p = resolve_result_path(result_path)
        if not (p.is_dir() or p.suffix == ".nc"):
            raise ValueError(f"{str(p)!r} is neither a netCDF file (.nc) nor a Zarr store (.zarr folder)")
        ok, report = verify_result(p)
    except (ValueError, FileNotFoundError) as err:
        raise UserError(str(err)) from None
    click.echo(report)
    if not ok:
        sys.exit(1)


#: The file suffix of each figure: a result STEM.zarr gets STEM_<suffix>.png beside it.
_FIGURE_FILES = {"family": "orbits", "period": "period", "stability": "stability", "map": "contours", "residuals": "residuals",
                 "solutions": "solutions", "multipliers": "multipliers", "body_axes": "body_axes"}


def _figures(result, path: Path, names, quiet: bool, extra: dict | None = None) -> list[Path]:
    """Draw the named figures of the result saved at ``path`` beside it, as
    ``<stem>_<figure>.png``; ``extra``: more figures, ``{name: make(plotting_module)}``. A
    figure that does not apply or fails is skipped with a note (the result is kept)."""
    if not names and not extra:
        return []
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from .. import plotting as lp
    except ImportError as err:
        click.echo(f"figures skipped: matplotlib, a required dependency of librate, cannot be imported ({err}); reinstall librate", err=True)
        return []
    from ..orbits.families import OrbitFamily
    from .progress import bar

    folder, stem = path.parent, path.stem
    fname = lambda name, tail="": f"{stem}_{_FIGURE_FILES.get(name, name)}{tail}.png"
    jobs = []
    if isinstance(result, OrbitFamily):
        table = {"family": lambda: lp.plot_family(result, n_orbits=30), "period": lambda: lp.plot_period(result),
                 "stability": lambda: lp.plot_stability(result)}
        jobs = [(fname(n), table[n]) for n in names if n in table]
    elif result.attrs.get("librate_result") == "map_3d":
        jobs = [(fname("residual_norm"), lambda: lp.plot_map_3d(result)) for n in names if n == "map"]
    elif result.attrs.get("librate_result") == "solutions_3d":
        from .results import multipliers_3d, solution_3d

        table = {"multipliers": lambda: lp.plot_family_multipliers(result.assign(multipliers=(("member", "k"), multipliers_3d(result)))),
                 "body_axes": lambda: lp.plot_body_axes(solution_3d(result, 0))}
        jobs = [(fname(n), table[n]) for n in names if n in table]
    elif "dwz" in result.variables:
        kzs = np.atleast_1d(result["kz"].values)
        for name in names:
            if name == "map":
                if result.sizes["orbit"] < 2:
                    click.echo(f"{fname('map')} skipped: a periodicity map figure needs at least 2 orbits", err=True)
                    continue
                for j, kz in enumerate(kzs):
                    jobs.append((fname("map", "" if kzs.size == 1 else f"_kz{kz:g}"), lambda j=j: lp.plot_map(result, kz_index=j)))
            elif name == "residuals":
                # thesis Fig. 23 is drawn on the 12.66-day DRO: the orbit nearest that period
                near = int(np.argmin(np.abs(np.asarray(result["period_days"].values, dtype=float) - 12.66)))
                jobs.append((fname("residuals"), lambda near=near: lp.plot_residuals(result, orbit_index=near, kz=float(kzs[0]))))
            elif name == "solutions" and "sol_wz0" in result.variables:
                if result.sizes["orbit"] < 2 or result.sizes.get("solution", 0) == 0:
                    continue
                # the thesis families N = 1, 0, -1 (Figs. 27-29) as panels; a rate jump over 1/TU
                # between consecutive orbits starts a new branch (never a line joining two solutions)
                ns = [k for k in (1, 0, -1) if np.any(np.asarray(result["sol_n"].values) == k)] or None
                jobs.append((fname("solutions"), lambda ns=ns: lp.plot_solution_families(result, n=ns, max_jump=1.0)))
    elif "sol_wz0" in result.variables and "solutions" in names and result.sizes.get("solution", 0):
        jobs.append((fname("solutions"), lambda: _solutions_scatter(result)))
    for name, make in (extra or {}).items():
        jobs.append((fname(name), lambda make=make: make(lp)))
    written = []
    with bar(len(jobs), "figures", "figure", _show(quiet)) as progress:
        for name, make in jobs:
            try:
                fig = make()
            except Exception as err:  # a figure must not lose the computed result
                progress.write(f"{name} skipped: {type(err).__name__}: {err}", file=sys.stderr)
                progress.update(1)
                continue
            written.append(lp.save_figure(fig, folder / name))
            plt.close(fig)
            progress.update(1)
            progress.write(f"written: {folder / name}", file=sys.stdout)
    return written


def _solutions_scatter(ds):
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    from .. import plotting as lp

    fig, ax = plt.subplots(figsize=(6.4, 4.8), layout="constrained")
    n = ds["sol_n"].values
    kind = ds["sol_kind"].values.astype(str) if "sol_kind" in ds.variables else np.full(n.shape, "periodic")
    stable = ds["sol_stable"].values.astype(bool)
    x, y = ds["sol_x0"].values, ds["sol_phidot0"].values
    handles = []
    for k in sorted(set(n.tolist()), reverse=True):  # the same N, the same colour as in the map figures
        c = lp.n_color(k)
        for kd, marker in lp.KIND_MARKERS.items():
            for st in (True, False):
                sel = (n == k) & (kind == kd) & (stable == st)
                if sel.any():
                    ax.scatter(x[sel], y[sel], s=22, marker=marker, edgecolors=c, facecolors=c if st else "none",
                               linewidths=1.2, gid="solutions")
        handles.append(Line2D([], [], linestyle="none", marker="s", color=c, label=f"N = {k:g}"))
    gray = dict(linestyle="none", color="0.3", markeredgecolor="0.3")
    for kd, marker in lp.KIND_MARKERS.items():
        if np.any(kind == kd):
            handles.append(Line2D([], [], marker=marker, markerfacecolor="0.8", label=kd, **gray))
    handles.append(Line2D([], [], marker="o", markerfacecolor="none", label="hollow: unstable", **gray))
    ax.set_xlabel("$x_0$ (LU)")
    ax.set_ylabel(r"$\dot\phi(0)$ (1/TU)")
    ax.set_title("periodic attitude solutions (filled: stable)")
    ax.legend(handles=handles, fontsize="small")
    return fig
