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

from .._core import __version__
from .._errors import LibrateError
from ..orbits.system import System
from .commands import demo_summary, map_3d_summary, map_solutions_summary, solutions_table, solve_3d_summary

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
      librate transition study.toml        the orbit carried into the Earth-Moon-Sun ephemeris
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
    cpus = b["threads_cpus"]
    bound = f"bound to CPUs {', '.join(map(str, cpus))}" if cpus else "not bound to CPUs"
    click.echo(f"  threads: {b['threads']} workers, {bound} (LIBRATE_BIND_THREADS={b['threads_binding']})")
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


def _in_cli_words(message: str, keys: dict[str, str]) -> str:
    for key, option in keys.items():
        message = message.replace(f"{key}: ", f"{option} ")
    return message


@main.command(context_settings=_CONTEXT, short_help="The DRO attitude periodicity map at Kz = 0.8, no study needed.")
@click.option("--system", "system_name", default="earth-moon", show_default=True, type=_PRESET, help="System preset.")
@click.option("--kz", default=0.8, show_default=True, type=click.FloatRange(-1, 1), help="Inertia parameter Kz = (Iy - Ix)/Iz.")
@click.option("--orbits", "n_orbits", default=60, show_default=True, type=click.IntRange(2, 2000),
              help="DRO family members with x0 evenly from 0.95 to 0.15; the 12.66-day DRO (thesis Fig. 23) is added to them.")
@click.option("--rates", "n_rates", default=1000, show_default=True, type=click.IntRange(10, 100000),
              help="Initial rates, phidot0 in [-4, 1] (wz0 in [-3, 2]).")
@click.option("--out", "out_dir", default="librate-out", show_default=True, type=click.Path(file_okay=False),
              help="Output folder for demo.nc and the demo_*.png figures.")
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
                     Fig. 24, Fig. 23 (the 12.66-day DRO), Figs. 27-29, Fig. 3
    `librate plot OUT/demo.nc` re-draws the first three from the file.
    """
    from .commands import run_demo
    from .progress import reporter
    from .results import ResultExists

    out = Path(out_dir)
    path = out / "demo.nc"
    _check_writable(out, "--out")
    try:
        ds, fam = run_demo(system_name, kz, n_orbits, n_rates, path, force=not resume,
                           say=lambda text: _say(_in_cli_words(text, _DEMO_KEYS)),
                           echo=lambda text: _echo(quiet, text),
                           progress=reporter("periodicity map (and solutions)", "orbit", None if not quiet else False))
    except ResultExists as err:
        raise UserError(_in_cli_words(str(err), _DEMO_KEYS)) from None
    except FileExistsError as err:
        raise UserError(str(err)) from None
    except OSError as err:
        raise UserError(f"--out {out}: cannot write {path.name} there ({err.strerror or err})") from None
    if not quiet:
        _lines(demo_summary(ds))
    if fam is None:
        click.echo(f"written: {path} (earlier)")
        return
    click.echo(f"written: {path} (xarray Dataset: dwz, dphi, phi_T over (orbit, kz, wz0), solutions, units and parameters)")
    _figures(ds, path, ("map", "residuals", "solutions"), quiet, extra={"orbits": lambda lp: lp.plot_family(fam)})


@main.command(name="dros", context_settings=_CONTEXT, short_help="Correct distant retrograde orbits and check that each closes.")
@click.option("--system", "system_name", default="earth-moon", show_default=True, type=_PRESET, help="System preset.")
@click.option("--x0", "x0_values", multiple=True, type=float,
              help="DRO start(s) on the x axis, between the primaries (default: 0.96 0.93 0.90 0.87 0.84 0.81).")
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
    from .commands import writable_problem

    why = writable_problem(folder)
    if why is not None:
        raise UserError(f"{what} {folder}: cannot write there ({why})")


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
            st = Study.from_dict(apply_overrides({}, overrides), purpose=purpose, base_dir=Path.cwd(),
                                 source="(command-line options)", force=force)
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


def _lines(lines: list[str]) -> None:
    for line in lines:
        click.echo(line)


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
@click.option("--out", "out_dir", type=click.Path(file_okay=False),
              help="Output folder (default: output.folder of the study, else librate-out).")
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
        from .jobs import run_family
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
    _figures(fam, path, _wanted(st, ("family", "period", "stability")), quiet)


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
@click.option("--scheduler", metavar="tcp://HOST:PORT",
              help="Solve each orbit and Kz as a task on this Dask scheduler (planar studies; needs dask.distributed).")
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
    from .jobs import run_solve
    from .progress import reporter
    from .study import Study3D

    st = _load_study(study, "solve", _overrides(sets), force=not resume, quiet=quiet)
    _check_writable(st.output_dir(out_dir), "--out" if out_dir else "output.folder")
    three_d = isinstance(st, Study3D)
    t0 = time.perf_counter()
    try:
        ds, path = run_solve(st, out_dir, progress=reporter("3-D solutions" if three_d else "solutions",
                                                           "member" if three_d else "orbit-Kz",
                                                           _show(quiet)), force=not resume, say=_say, scheduler=scheduler)
    except _FAILURES as err:
        raise _failure(err) from None
    el = time.perf_counter() - t0
    if three_d:
        if not quiet:
            _lines(solve_3d_summary(ds, el))
        click.echo(f"written: {path}")
        _figures(ds, path, _wanted(st, ("multipliers", "body_axes")), quiet)
        return
    n = ds.sizes["solution"]
    _echo(quiet, f"{n} periodic solution(s) over {ds.sizes['orbit']} orbit(s) x {ds.sizes['kz']} Kz ({el:.2f} s)")
    if n and not quiet:
        _lines(solutions_table(ds))
    click.echo(f"written: {path}")
    _figures(ds, path, _wanted(st, ("solutions",)), quiet)


@main.command(name="map", context_settings=_CONTEXT, short_help="The attitude periodicity map of a study (thesis Fig. 24).")
@click.argument("study", type=click.Path(exists=True, dir_okay=False))
@click.option("--out", "out_dir", type=click.Path(file_okay=False),
              help="Output folder (default: output.folder of the study); the map goes to OUT/map.zarr.")
@click.option("--quiet", "-q", is_flag=True, help="No progress bar and no summary; print only the written paths.")
@click.option("--scheduler", metavar="tcp://HOST:PORT",
              help="Run the map's orbits (planar or 3-D) as tasks on this Dask scheduler (needs dask.distributed).")
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
      map_residuals.png  dwz and dphi against phidot0, the orbit nearest 12.66 d (thesis Fig. 23)
      map_solutions.png  the solution families across the orbits (thesis Figs. 27-29)

    With [attitude] model = "3d": the six 3-D closure residuals over (orbit, two rate grids)
    in map.zarr (or .nc), saved orbit by orbit (resumable), and map_residual_norm.png.
    """
    from .jobs import run_map

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
            _lines(map_3d_summary(ds, el))
        click.echo(f"written: {path}")
        _figures(ds, path, _wanted(st, ("map",)), quiet)
        return
    if not quiet:
        no, nk, nw = ds.sizes["orbit"], ds.sizes["kz"], ds.sizes["wz0"]
        click.echo(f"periodicity map: {no} orbits x {nk} Kz x {nw} rates = {no * nk * nw} attitude trajectories ({el:.2f} s)"
                   + ("" if int(ds.attrs.get("complete", 1)) else "  [INCOMPLETE: interrupted; re-run to resume]"))
        _lines(map_solutions_summary(ds))
    click.echo(f"written: {path}")
    _figures(ds, path, _wanted(st, ("map", "residuals", "solutions")), quiet)


@main.command(context_settings=_CONTEXT, short_help="Carry the study's orbit into the ephemeris model at its epochs.")
@click.argument("study", type=click.Path(exists=True, dir_okay=False))
@click.option("--out", "out_dir", type=click.Path(file_okay=False),
              help="Output folder (default: output.folder of the study); the result goes to OUT/transition.zarr.")
@click.option("--quiet", "-q", is_flag=True, help="No progress bar and no table; print only the written paths.")
@click.option("--scheduler", metavar="tcp://HOST:PORT", help="Run each epoch as a task on this Dask scheduler (needs dask.distributed).")
@click.option("--resume/--force", default=True, help=_FORCE_HELP)
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE", help=_SET_HELP)
def transition(study, out_dir, quiet, scheduler, resume, sets) -> None:
    """Carry the orbit of STUDY into the Earth-Moon-Sun ephemeris model at each epoch of its
    [ephemeris] section.

    The one orbit selected by [orbits] (a DRO, Lyapunov or halo member, NRHOs included) is
    placed at each epoch in the instantaneous Earth-Moon frame of the ephemeris (the embedded
    DE440 excerpt, or ephemeris.file), and corrected by multiple shooting over
    ephemeris.revolutions (ephemeris.nodes_per_rev nodes a revolution) into a continuous
    trajectory under the Earth, Moon and Sun point masses. Prints per epoch the Newton
    iterations, the largest node defects (position in m, velocity in km/s, re-propagated from
    every node), the largest departure from the CR3BP orbit (km), the perilune range (km) and
    the drift per revolution. An epoch that does not converge is kept as such and the sweep
    goes on. The result is written epoch by epoch: re-running after an interruption keeps
    every finished epoch.

    \b
    Writes to the output folder:
      transition.zarr (or .nc)  over `epoch`: status, iterations, node epochs (TDB s past J2000),
                   node states (Moon-centred ICRF, km, km/s) and in the rotating frame
                   (nondimensional), the defects, perilunes, departure and drift, the sampled
                   trajectory; the epochs (ISO), frames, GM values, ephemeris file, study and
                   version as attributes
      transition_rotating.png   the orbit in the rotating frame in both models (first epoch)
      transition_defects.png    the node defects of every epoch
      transition_sweep.png      departure and perilune range against the epoch (2+ epochs)
      transition_attitude.png   with ephemeris.attitude_n: attitude angles against time in both
                   models (first epoch, first solution)
      transition_pointing.png   with ephemeris.attitude_n: the pointing error of each body axis

    With ephemeris.attitude_n = [N, ...] the CR3BP periodic attitude solutions with those N
    (found on the orbit as `librate solve` finds them, from [body], [rates] and [solver]) are
    carried along the ephemeris orbit at each epoch and corrected by multiple shooting; the
    table then adds per solution the largest pointing error and the corrected motion's defects.
    """
    from .jobs import run_transition

    st = _load_study(study, "transition", _overrides(sets))
    _check_writable(st.output_dir(out_dir), "--out" if out_dir else "output.folder")
    t0 = time.perf_counter()
    try:
        ds, path = run_transition(st, out_dir, scheduler=scheduler, progress=_show(quiet), force=not resume, say=_say)
    except _FAILURES as err:
        raise _failure(err) from None
    if not quiet:
        from .transition import transition_summary

        _lines(transition_summary(ds, time.perf_counter() - t0))
    click.echo(f"written: {path}")
    att = ("attitude", "pointing") if st.ephemeris.attitude_n else ()
    _figures(ds, path, _wanted(st, ("transition", "defects", "sweep", *att)), quiet)


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
                 the orbit nearest 12.66 d), STEM_solutions.png (solution families across the orbits)
      solutions  STEM_solutions.png (initial rates phidot0 of the solutions against x0)
      3-D solutions  STEM_multipliers.png (Floquet multipliers along the family),
                 STEM_body_axes.png (body axes along the first member's orbit)
      a 3-D map  STEM_residual_norm.png (log10 of the residual max-norm over the two rate
                 grids, the first three orbits)
      a transition  STEM_rotating.png (the orbit in the rotating frame in both models),
                 STEM_defects.png (node defects), STEM_sweep.png (against the epoch),
                 STEM_attitude.png and STEM_pointing.png (with attitude solutions)
    """
    from .results import open_result, resolve_result_path

    try:
        p = resolve_result_path(result_path)
    except (ValueError, FileNotFoundError) as err:
        raise UserError(str(err)) from None
    from .commands import refuse_damaged

    try:
        refuse_damaged(p)
    except ValueError as err:  # refused: exit status 2, nothing drawn
        raise UserError(str(err)) from None
    try:
        res = open_result(p)
    except (ValueError, FileNotFoundError) as err:
        raise UserError(str(err)) from None
    _check_writable(p.parent, "the folder of RESULT_PATH,")
    from .commands import describe_for_plot

    _echo(quiet, describe_for_plot(res))
    written = _figures(res, p, None, quiet)
    if not written:
        raise click.ClickException("no figure could be drawn (see the messages above)")


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


def _wanted(st, available: tuple[str, ...]) -> list[str]:
    """The study's figures among this command's ``available``; says so when its output.figures
    names none of them (a command never leaves its figures out silently)."""
    names = st.figures(available)
    if not names:
        click.echo(f"figures: none drawn: output.figures = {list(st.output.figures)} names none of this command's "
                   f"({', '.join(available)})", err=True)
    return names


def _figures(result, path: Path, names, quiet: bool, extra: dict | None = None) -> list[Path]:
    """Draw the figures of the result saved at ``path`` beside it (:func:`librate.app.commands.draw_figures`)."""
    from .commands import draw_figures

    try:
        return draw_figures(result, path, names, show=_show(quiet), extra=extra)
    except OSError as err:  # a figure that does not fit on the disk: one line, exit 2 (issue 24 #5)
        raise UserError(f"{err.filename}: {err.strerror}") from None
