"""The ``librate`` command line."""

from __future__ import annotations

import time

import click
import numpy as np

from . import __version__
from .orbits import correct_dro
from .propagation import propagate
from .system import System


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="librate")
def main() -> None:
    """librate: coupled orbit-attitude dynamics of large spacecraft in the Earth-Moon CR3BP."""


@main.command()
def info() -> None:
    """Show the version and the system presets with their constants."""
    click.echo(f"librate {__version__}")
    for name in System.presets():
        s = System.preset(name)
        l1 = s.lagrange_points()[0, 0]
        click.echo(f"  {name:16s} mu = {s.mu:.15g}  LU = {s.lu_km} km  TU = {s.tu_s} s ({s.tu_days:.6f} d)  L1 x = {l1:.15f}")


@main.command()
@click.option("--system", "system_name", default="earth-moon", show_default=True, help="System preset.")
@click.option("--kz", default=0.8, show_default=True, type=click.FloatRange(-1, 1), help="Inertia parameter Kz = (Iy - Ix)/Iz.")
@click.option("--orbits", "n_orbits", default=60, show_default=True, type=click.IntRange(2, 2000), help="DRO family members, x0 from 0.95 to 0.15.")
@click.option("--rates", "n_rates", default=1000, show_default=True, type=click.IntRange(10, 100000), help="Initial rates, phidot0 in [-4, 1] (wz0 in [-3, 2]).")
@click.option("--out", "out_dir", default="librate-out", show_default=True, type=click.Path(file_okay=False), help="Output folder for the map (netCDF).")
def demo(system_name: str, kz: float, n_orbits: int, n_rates: int, out_dir: str) -> None:
    """The main job on a default study: the attitude periodicity map of the DRO family (thesis
    Fig. 24), its periodic solutions refined by Newton, saved as netCDF.

    Computes the DRO family by continuation, integrates the planar attitude of a body with the
    given Kz along every member for a grid of initial rates (Rust engine, SIMD lanes, all
    cores), finds where wz(T) = wz0 and phi(T) = 2 pi N, and prints the solutions by N.
    """
    import pathlib

    from .families import dro_family
    from .periodicity import periodicity_map

    system = System.preset(system_name)
    t0 = time.perf_counter()
    fam = dro_family(system, x0=np.linspace(0.95, 0.15, n_orbits))
    t1 = time.perf_counter()
    click.echo(f"DRO family: {len(fam)} members, x0 {fam.x0[0]:.3f} -> {fam.x0[-1]:.3f}, period {fam.period_days.min():.2f} to {fam.period_days.max():.2f} d ({t1 - t0:.2f} s)")
    wz0 = np.linspace(-3.0, 2.0, n_rates)
    done = [0]

    def progress(k, total):
        if click.get_text_stream("stdout").isatty() and (k == total or k % max(1, total // 20) == 0):
            click.echo(f"  map: {k}/{total} orbits", err=True)
        done[0] = k

    ds = periodicity_map(fam, kz=kz, wz0=wz0, progress=progress)
    t2 = time.perf_counter()
    n_traj = ds.dwz.size
    click.echo(f"periodicity map: {len(fam)} orbits x {n_rates} rates at Kz = {kz}: {n_traj} attitude trajectories in {t2 - t1:.2f} s ({n_traj / (t2 - t1):,.0f} per s, with solving)")
    click.echo(f"solutions (phi(T) = 2 pi N, wz(T) = wz0, refined by Newton, residual from an independent re-propagation): {ds.sizes['solution']}")
    click.echo(f"{'N':>4} {'kind':>10} {'count':>6} {'stable':>7} {'phidot0 range [1/TU]':>24} {'max residual':>13}")
    for (n, kind) in sorted(set(zip(ds.sol_n.values.tolist(), ds.sol_kind.values.tolist())), key=lambda x: (x[1], x[0])):
        sel = (ds.sol_n.values == n) & (ds.sol_kind.values == kind)
        if abs(n) > 3:
            continue
        pd = ds.sol_phidot0.values[sel]
        click.echo(f"{n:>4} {kind:>10} {int(sel.sum()):>6} {int(ds.sol_stable.values[sel].sum()):>7} {pd.min():>11.4f} .. {pd.max():<10.4f} {ds.sol_residual.values[sel].max():>13.1e}")
    out = pathlib.Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"dro_map_kz{kz:g}.nc"
    ds.to_netcdf(path, engine="scipy")
    click.echo(f"written: {path} (xarray Dataset: dwz, dphi, phi_T over (orbit, kz, wz0), solutions, units and parameters)")


@main.command(name="dros")
@click.option("--system", "system_name", default="earth-moon", show_default=True, help="System preset.")
@click.option("--x0", "x0_values", multiple=True, type=float, help="DRO start(s) on the x axis (default: 0.96 0.93 0.90 0.87 0.84 0.81).")
def dros(system_name: str, x0_values: tuple[float, ...]) -> None:
    """Correct a set of distant retrograde orbits and check each over one full period.

    Each DRO is corrected by half-period shooting with the STM, continued from the previous one
    (its ydot0 seeds the next), then propagated over a whole period to show that it closes.
    """
    system = System.preset(system_name)
    xs = x0_values or (0.96, 0.93, 0.90, 0.87, 0.84, 0.81)
    click.echo(f"Distant retrograde orbits in {system.name} (mu = {system.mu}), corrected by half-period shooting:")
    click.echo(f"{'x0':>8} {'ydot0':>18} {'period [TU]':>16} {'period [d]':>11} {'Jacobi':>17} {'iter':>4} {'closure':>9} {'time':>7}")
    guess = None
    for x0 in xs:
        t_start = time.perf_counter()
        orbit = correct_dro(system, x0, guess)
        one = propagate(system, orbit.state0, orbit.period, rtol=1e-13, atol=1e-13, t_eval=[orbit.period])
        closure = float(np.max(np.abs(one.y[-1] - orbit.state0)))
        elapsed = time.perf_counter() - t_start
        click.echo(
            f"{x0:8.4f} {orbit.state0[4]:18.15f} {orbit.period:16.12f} {orbit.period_days:11.6f} "
            f"{orbit.jacobi:17.14f} {orbit.iterations:4d} {closure:9.1e} {elapsed * 1e3:5.1f}ms"
        )
        guess = orbit.state0[4]
    click.echo("closure = max |state(T) - state(0)| after one full period at rtol = atol = 1e-13.")
