"""Figures of the ephemeris model (``librate transition``): the orbit in the rotating frame in
both models, the node defects of the multiple shooting, an epoch sweep, and attitude in the
ephemeris model (angles against time in both models, the pointing error). Every function takes
arrays (the data of a transition result, :class:`~librate.orbits.transition.EphemerisOrbit`
or an attitude comparison), never computes them, and returns the Figure."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure

from ._style import figure_axes

__all__ = ["plot_ephemeris_attitude", "plot_node_defects", "plot_pointing_error", "plot_transition_orbit", "plot_transition_sweep"]

_S_PER_DAY = 86400.0
#: Days from J2000 (TDB) to 2000-01-01T00:00 of the year axis (J2000 is 2000-01-01T12:00 TDB).
_J2000_YEAR = 2000.0 + 0.5 / 365.25
#: The continuity the transition converges to (issue 21): 1 m and 1e-8 km/s.
TOL_KM, TOL_KM_S = 1e-3, 1e-8


def _array(v, name: str, ndim: int | tuple[int, ...], last: int | None = None) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    dims = (ndim,) if isinstance(ndim, int) else ndim
    if a.ndim not in dims or (last is not None and a.shape[-1] < last) or a.size == 0:
        want = " or ".join(f"{d}-D" for d in dims) + (f" with at least {last} columns" if last else "")
        raise ValueError(f"invalid argument `{name}`: must be a non-empty {want} array, got shape {a.shape}")
    return a


def _years(epochs_tdb) -> np.ndarray:
    """TDB seconds past J2000 as decimal years (Julian years of 365.25 d)."""
    return _J2000_YEAR + np.asarray(epochs_tdb, dtype=float) / (365.25 * _S_PER_DAY)


def plot_transition_orbit(cr3bp, ephemeris, nodes=None, *, mu: float | None = None, lu_km: float | None = None, label: str | None = None,
                          ax=None) -> Figure:
    """An orbit in the Earth-Moon rotating frame in both models: the CR3BP periodic orbit and its
    ephemeris counterpart (a continuous trajectory over several revolutions, converted to the
    instantaneous rotating frame by :meth:`librate.Ephemeris.ephemeris_to_synodic`), in the x-y
    and x-z planes.

    Parameters
    ----------
    cr3bp : array_like, shape (n, 3) or (n, 6)
        The CR3BP orbit, synodic and nondimensional (LU).
    ephemeris : array_like, shape (m, 3) or (m, 6)
        The ephemeris trajectory in the rotating frame, nondimensional.
    nodes : array_like, shape (k, 3) or (k, 6), optional
        The multiple-shooting nodes, drawn as points.
    mu : float, optional
        The mass ratio: the Moon is drawn at x = 1 - mu.
    lu_km : float, optional
        The length unit: the axes are in km (about the Moon with ``mu``) instead of LU.
    label : str, optional
        What the ephemeris trajectory is (e.g. its epoch), in the legend.
    ax : sequence of two matplotlib Axes, optional
        Draw into these; default a new Figure.

    Returns
    -------
    matplotlib.figure.Figure
        The figure (artists' gid: "cr3bp", "ephemeris", "nodes", "moon").
    """
    a = _array(cr3bp, "cr3bp", 2, 3)
    b = _array(ephemeris, "ephemeris", 2, 3)
    c = None if nodes is None else _array(nodes, "nodes", 2, 3)
    origin = np.array([1.0 - mu, 0.0, 0.0]) if mu is not None else np.zeros(3)
    scale = 1.0 if lu_km is None else float(lu_km)
    unit = "LU" if lu_km is None else "km"
    where = " about the Moon" if (mu is not None and lu_km is not None) else ""
    shift = origin if (mu is not None and lu_km is not None) else np.zeros(3)

    def xyz(p):
        return (p[:, :3] - shift) * scale

    fig, axs = figure_axes(ax, 2, figsize=(11.0, 4.8))
    for panel, (i, j, name) in zip(axs, ((0, 1, "y"), (0, 2, "z"))):
        pa, pb = xyz(a), xyz(b)
        panel.plot(pa[:, i], pa[:, j], color="0.3", lw=2.2, label="CR3BP", gid="cr3bp")
        panel.plot(pb[:, i], pb[:, j], color="tab:red", lw=0.9, label=f"ephemeris{' (' + label + ')' if label else ''}", gid="ephemeris")
        if c is not None:
            pc = xyz(c)
            panel.scatter(pc[:, i], pc[:, j], s=12, color="tab:blue", zorder=3, label="nodes", gid="nodes")
        if mu is not None:
            m = (origin - shift) * scale
            panel.scatter([m[i]], [m[j]], s=40, color="0.5", marker="o", zorder=4, label="Moon", gid="moon")
        panel.set_xlabel(f"x{where} [{unit}]")
        panel.set_ylabel(f"{name} [{unit}]")
        panel.set_aspect("equal", adjustable="datalim")
        panel.grid(True, alpha=0.3)
    axs[1].legend(fontsize=7, loc="upper right")
    axs[0].set_title("rotating frame, x-y")
    axs[1].set_title("rotating frame, x-z")
    return fig


def plot_node_defects(defects_km, defects_km_s, *, epochs_tdb=None, tol_km: float = TOL_KM, tol_km_s: float = TOL_KM_S, ax=None) -> Figure:
    """The continuity defects at the end of every leg of a multiple-shooting transition
    (re-propagated from its node): position in m and velocity in km/s, log scale, one line per
    epoch, with the convergence thresholds (default 1 m and 1e-8 km/s).

    Parameters
    ----------
    defects_km, defects_km_s : array_like, shape (legs,) or (epochs, legs)
        The position (km) and velocity (km/s) defects. A zero defect is drawn at 1e-16.
    epochs_tdb : array_like, shape (epochs,), optional
        The epochs (TDB s past J2000), for the legend.
    tol_km, tol_km_s : float
        The thresholds drawn (gid "tolerance").
    ax : sequence of two matplotlib Axes, optional
        Draw into these; default a new Figure.

    Returns
    -------
    matplotlib.figure.Figure
        The figure (one line per epoch, gid "defects").
    """
    dk = np.atleast_2d(_array(defects_km, "defects_km", (1, 2)))
    dv = np.atleast_2d(_array(defects_km_s, "defects_km_s", (1, 2)))
    if dk.shape != dv.shape:
        raise ValueError(f"invalid arguments `defects_km`, `defects_km_s`: must have the same shape, got {dk.shape} and {dv.shape}")
    years = None if epochs_tdb is None else _years(np.atleast_1d(epochs_tdb))
    if years is not None and years.size != dk.shape[0]:
        raise ValueError(f"invalid argument `epochs_tdb`: must have one epoch per row of the defects ({dk.shape[0]}), got {years.size}")
    fig, axs = figure_axes(ax, 2, figsize=(11.0, 4.4))
    legs = np.arange(1, dk.shape[1] + 1)
    many = dk.shape[0] > 8
    for r in range(dk.shape[0]):
        lab = None if years is None or many else f"{years[r]:.3f}"
        kw = {"lw": 0.8, "alpha": 0.5 if many else 0.9, "marker": None if many else "o", "ms": 3, "gid": "defects"}
        axs[0].plot(legs, np.maximum(1e3 * dk[r], 1e-16), label=lab, **kw)
        axs[1].plot(legs, np.maximum(dv[r], 1e-16), **kw)
    for panel, tol, what in ((axs[0], 1e3 * tol_km, "position defect [m]"), (axs[1], tol_km_s, "velocity defect [km/s]")):
        panel.axhline(tol, color="k", ls="--", lw=0.8, gid="tolerance")
        panel.set_yscale("log")
        panel.set_xlabel("leg (its end node)")
        panel.set_ylabel(what)
        panel.grid(True, which="both", alpha=0.3)
    axs[0].set_title(f"node defects, {dk.shape[0]} epoch{'s' if dk.shape[0] != 1 else ''}")
    if years is not None and not many:
        axs[0].legend(title="epoch [yr]", fontsize=7)
    return fig


def plot_transition_sweep(epochs_tdb, max_departure_km, perilune_km, iterations=None, *, ax=None) -> Figure:
    """An epoch sweep of transitions: the largest departure from the CR3BP orbit and the
    perilune range (the band from the lowest to the highest perilune of the revolutions),
    against the epoch; the Newton iterations too when given.

    Parameters
    ----------
    epochs_tdb : array_like, shape (n,)
        The epochs (TDB s past J2000).
    max_departure_km : array_like, shape (n,)
    perilune_km : array_like, shape (n,) or (n, revolutions)
    iterations : array_like, shape (n,), optional
    ax : sequence of matplotlib Axes (two, three with ``iterations``), optional

    Returns
    -------
    matplotlib.figure.Figure
        The figure (gids "departure", "perilune", "iterations").
    """
    t = _years(_array(epochs_tdb, "epochs_tdb", 1))
    dep = _array(max_departure_km, "max_departure_km", 1)
    per = _array(perilune_km, "perilune_km", (1, 2))
    per = per[:, None] if per.ndim == 1 else per
    if dep.size != t.size or per.shape[0] != t.size:
        raise ValueError(f"invalid arguments: one value per epoch ({t.size}), got max_departure_km {dep.shape}, perilune_km "
                         f"{np.shape(perilune_km)}")
    n = 2 if iterations is None else 3
    fig, axs = figure_axes(ax, n, figsize=(5.0 * n, 4.2))
    axs[0].plot(t, dep, color="tab:red", marker="." if t.size < 60 else None, gid="departure")
    axs[0].set_ylabel("largest departure from the CR3BP orbit [km]")
    lo, hi = np.nanmin(per, axis=1), np.nanmax(per, axis=1)
    axs[1].fill_between(t, lo, hi, color="tab:blue", alpha=0.25, lw=0)
    axs[1].plot(t, lo, color="tab:blue", lw=0.9, gid="perilune")
    axs[1].plot(t, hi, color="tab:blue", lw=0.9, gid="perilune")
    axs[1].set_ylabel("perilune range [km]")
    if iterations is not None:
        it = _array(iterations, "iterations", 1)
        axs[2].plot(t, it, color="0.3", marker="." if t.size < 60 else None, drawstyle="steps-mid", gid="iterations")
        axs[2].set_ylabel("Newton iterations")
        from matplotlib.ticker import MaxNLocator

        axs[2].yaxis.set_major_locator(MaxNLocator(integer=True))
    for panel in axs:
        panel.set_xlabel("epoch [yr, TDB]")
        panel.grid(True, alpha=0.3)
    axs[0].set_title(f"epoch sweep, {t.size} epochs")
    return fig


def plot_ephemeris_attitude(t_days, angles_cr3bp, angles_ephemeris, *, names: Sequence[str] = ("roll", "pitch", "yaw"), ax=None) -> Figure:
    """Attitude angles against time in both models: the CR3BP periodic attitude motion and its
    ephemeris counterpart, one panel per angle (degrees).

    Parameters
    ----------
    t_days : array_like, shape (n,)
        Time from the first epoch (days).
    angles_cr3bp, angles_ephemeris : array_like, shape (n, k)
        The angles (degrees) of each model at those times, one column per name.
    names : sequence of str
        The angles' names (k of them).
    ax : sequence of k matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
        The figure (gids "cr3bp", "ephemeris").
    """
    t = _array(t_days, "t_days", 1)
    a = _array(angles_cr3bp, "angles_cr3bp", 2)
    b = _array(angles_ephemeris, "angles_ephemeris", 2)
    k = len(names)
    if a.shape != (t.size, k) or b.shape != (t.size, k):
        raise ValueError(f"invalid arguments: the angles must be ({t.size}, {k}) arrays (time x names), got {a.shape} and {b.shape}")
    fig, axs = figure_axes(ax, k, figsize=(5.0 * min(k, 3), 4.0))
    for j, panel in enumerate(axs):
        panel.plot(t, a[:, j], color="0.3", lw=2.0, label="CR3BP", gid="cr3bp")
        panel.plot(t, b[:, j], color="tab:red", lw=0.9, label="ephemeris", gid="ephemeris")
        panel.set_xlabel("time [d]")
        panel.set_ylabel(f"{names[j]} [deg]")
        panel.grid(True, alpha=0.3)
    axs[0].legend(fontsize=8)
    return fig


def plot_pointing_error(t_days, error_deg, *, axes_names: Sequence[str] = ("x", "y", "z"), ax=None) -> Figure:
    """The pointing error of each body axis (degrees: the angle between the axis in the
    ephemeris motion and in the CR3BP motion, both in ICRF) against time, log scale.

    Parameters
    ----------
    t_days : array_like, shape (n,)
    error_deg : array_like, shape (n, k)
        One column per body axis. A zero error is drawn at 1e-12 deg.
    axes_names : sequence of str
        The axes' names (k of them).
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
        The figure (gid "pointing-<axis>").
    """
    t = _array(t_days, "t_days", 1)
    e = _array(error_deg, "error_deg", 2)
    if e.shape != (t.size, len(axes_names)):
        raise ValueError(f"invalid argument `error_deg`: must be a ({t.size}, {len(axes_names)}) array (time x body axes), got {e.shape}")
    fig, (a,) = figure_axes(ax, 1, figsize=(7.0, 4.2))
    for j, name in enumerate(axes_names):
        a.plot(t, np.maximum(e[:, j], 1e-12), lw=1.0, label=f"body {name}", gid=f"pointing-{name}")
    a.set_yscale("log")
    a.set_xlabel("time [d]")
    a.set_ylabel("pointing error [deg]")
    a.grid(True, which="both", alpha=0.3)
    a.legend(fontsize=8)
    a.set_title("ephemeris attitude against the CR3BP motion")
    return fig
