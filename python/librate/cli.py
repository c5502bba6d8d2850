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
@click.option("--x0", "x0_values", multiple=True, type=float, help="DRO start(s) on the x axis (default: 0.96 0.93 0.90 0.87 0.84 0.81).")
def demo(system_name: str, x0_values: tuple[float, ...]) -> None:
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
