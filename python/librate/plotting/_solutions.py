"""Figures of periodic attitude motions: the solution families across an orbit family (thesis
Figs. 27-29) and phi(t) of periodic motions (Figs. 30-31)."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING

import matplotlib
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.ticker import MultipleLocator

from ..periodicity.solutions import AttitudeSolution, check_kinds
from ._style import KIND_MARKERS, KZ_STYLES, check_map, figure_axes, kz_mask, n_color, orbit_axis, rate_axis, solution_table

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def _branches(orbit: np.ndarray, rate: np.ndarray, max_jump: float | None) -> list[list[int]]:
    """Solutions (orbit index, rate) joined into branches across consecutive orbits: each
    solution continues the branch ending on the previous orbit nearest in rate (greedy, closest
    pairs first, at most ``max_jump`` apart), else starts a new one."""
    branches: list[list[int]] = []
    for o in np.unique(orbit):
        cur = [int(c) for c in np.flatnonzero(orbit == o)]
        cur.sort(key=lambda c: rate[c])
        ends = [b for b in branches if orbit[b[-1]] == o - 1]
        pairs = sorted((abs(rate[b[-1]] - rate[c]), bi, ci) for bi, b in enumerate(ends) for ci, c in enumerate(cur))
        used_b: set[int] = set()
        used_c: set[int] = set()
        for d, bi, ci in pairs:
            if bi in used_b or ci in used_c or (max_jump is not None and d > max_jump):
                continue
            ends[bi].append(cur[ci])
            used_b.add(bi)
            used_c.add(ci)
        branches += [[c] for ci, c in enumerate(cur) if ci not in used_c]
    return branches


def plot_solution_families(
    ds,
    ax=None,
    *,
    n: int | Iterable[int] | None = None,
    kinds: Sequence[str] = ("periodic",),
    against: str = "period",
    rate: str = "relative",
    separate: bool = True,
    stability: bool = True,
    max_jump: float | None = None,
) -> Figure:
    """Families of periodic attitude solutions across an orbit family (thesis Figs. 27-29): the
    initial rate of the solutions with N net turns per orbit against the orbit's period (or x0),
    one curve per Kz of the Dataset.

    ``ds``: a Dataset from :func:`librate.periodicity_map` with solutions (any number of Kz).
    Solutions of one (kind, N, Kz) are joined across consecutive orbits into branches
    (nearest rate, at most ``max_jump`` apart; None: no limit), each a line with
    ``gid="family-{kind}-N{N:+d}-kz{Kz:g}"`` (e.g. ``"family-periodic-N-1-kz0.8"``) whose points
    are exactly the Dataset's solutions; with ``stability`` the linearly stable ones are
    overdrawn filled (``gid="family-stable"``). ``n``: the N values to show (default: all in
    the Dataset), ``kinds``: ``"periodic"`` (default) and/or ``"half-turn"``. Lines are
    coloured by N (:func:`librate.plotting.n_color`, the same in every figure), Kz told by line
    style. ``separate``: one panel per (kind, N), N descending (``ax``: that many Axes); else a
    single panel. ``against``: ``"period"`` (days) or ``"x0"``;
    ``rate``: ``"relative"`` (phidot(0) = wz(0) - 1, default) or ``"inertial"``. Returns the
    Figure.

    Parameters
    ----------
    ds : xarray.Dataset
        A map of `librate.periodicity_map` with solutions.
    n : int or iterable of int, optional
        The N shown (default all).
    kinds : sequence of {"periodic", "half-turn"}
        The closures shown.
    against : {"period", "x0"}
        The horizontal axis.
    rate : {"relative", "inertial"}
        The vertical axis.
    separate : bool, default True
        One panel per (kind, N).
    stability : bool, default True
        Overdraw the linearly stable solutions, filled.
    max_jump : float, optional
        The largest rate step (1/TU) between consecutive orbits within a branch.
    ax : matplotlib Axes or sequence of Axes, optional
        Draw into these (one per panel); default a new Figure.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.

    Raises
    ------
    ValueError
        A bad argument, naming it and the allowed values.
    """
    ds = check_map(ds)
    tab = solution_table(ds)
    if tab is None:
        raise ValueError("invalid argument `ds`: the map holds no solutions (compute it with solve=True)")
    kinds = check_kinds(kinds)
    xv, xlabel = orbit_axis(ds, against)
    offset, ylabel = rate_axis(rate)
    if max_jump is not None and not (isinstance(max_jump, (int, float, np.integer, np.floating)) and max_jump > 0):
        raise ValueError(f"invalid argument `max_jump`: must be a number > 0 or None, got {max_jump!r}")
    if n is None:
        ns = sorted(set(tab["n"][np.isin(tab["kind"], kinds)].tolist()), reverse=True)
    else:
        ns = [n] if isinstance(n, (int, np.integer)) else list(n)
        if not ns or not all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in ns):
            raise ValueError(f"invalid argument `n`: must be an integer, a sequence of integers or None, got {n!r}")
    groups = [(k, int(v)) for v in ns for k in kinds]
    if n is None:
        groups = [(k, v) for k, v in groups if np.any((tab["kind"] == k) & (tab["n"] == v))]
    if not groups:
        raise ValueError(f"invalid argument `ds`: it holds no solutions of kinds {list(kinds)}")
    kzs = np.asarray(ds["kz"].values, dtype=float)

    created = ax is None
    npanels = len(groups) if separate else 1
    fig, axs = figure_axes(ax, npanels, figsize=(7.4, 5.2) if npanels == 1 else None)
    for g, (kind, nn) in enumerate(groups):
        a = axs[g] if separate else axs[0]
        drawn = False
        for jk, kz in enumerate(kzs):
            sel = np.flatnonzero((tab["kind"] == kind) & (tab["n"] == nn) & kz_mask(tab, kz))
            if not sel.size:
                continue
            color = n_color(nn)  # the same N, the same colour in every figure; Kz by line style
            style = KZ_STYLES[jk % len(KZ_STYLES)]
            name = f"$K_z$ = {kz:g}" if separate else f"$N$ = {nn:g}{' half-turn' if kind == 'half-turn' else ''}, $K_z$ = {kz:g}"
            orb, w = tab["orbit"][sel], tab["wz0"][sel]
            for b_i, br in enumerate(_branches(orb, w, max_jump)):
                idx = sel[br]
                (h,) = a.plot(xv[tab["orbit"][idx]], tab["wz0"][idx] - offset, color=color, linestyle=style, linewidth=1.4,
                              marker=".", markersize=4, label=name if b_i == 0 else "_nolegend_")
                h.set_gid(f"family-{kind}-N{nn:+d}-kz{kz:g}")
            st = sel[tab["stable"][sel]]
            if stability and st.size:
                (h,) = a.plot(xv[tab["orbit"][st]], tab["wz0"][st] - offset, linestyle="none", marker="o", markersize=5,
                              color=color, label="_nolegend_")
                h.set_gid("family-stable")
            drawn = True
        if separate or g == len(groups) - 1:
            handles = list(a.get_legend_handles_labels()[0])
            if stability and any(h.get_gid() == "family-stable" for h in a.get_lines()):
                handles.append(Line2D([], [], linestyle="none", marker="o", markersize=5, color="0.3",
                                      label="linearly stable ($|\\mathrm{tr}\\,M| < 2$)"))
            if handles and separate:
                a.legend(handles=handles, fontsize=7.5, loc="best")
            elif handles:  # one entry per (N, Kz): beside the panel
                a.legend(handles=handles, fontsize=7.5, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
        if separate:
            turns = {0: "", 1: " + 2\\pi", -1: " - 2\\pi"}.get(nn, f" {'+' if nn > 0 else '-'} {2 * abs(nn)}\\pi")
            if kind == "half-turn":
                turns += " + \\pi"
            a.set_title(f"$N$ = {nn:g}{' (half-turn)' if kind == 'half-turn' else ''}: $\\varphi(T) = \\varphi_0{turns}$", fontsize=10)
            if not drawn:
                a.text(0.5, 0.5, "no solutions in the map", transform=a.transAxes, ha="center", va="center", color="0.4")
    lo, hi = float(np.nanmin(xv)), float(np.nanmax(xv))
    pad = 0.02 * (hi - lo)
    for a in axs:
        a.set_xlim(lo - pad, hi + pad)  # the whole orbit family on every panel
        a.set_xlabel(xlabel)
        a.set_ylabel(ylabel)
        a.grid(True, linewidth=0.3, alpha=0.5)
    if created:
        fam = ds.attrs.get("family", "") or "orbit"
        fig.suptitle(f"periodic attitude solution families along the {fam.upper() if fam == 'dro' else fam} family")
    return fig


def plot_solution_scatter(ds, ax=None) -> Figure:
    """The periodic attitude solutions of ``librate solve`` (the ``sol_*`` variables of a
    Dataset, with or without a map): initial rate phidot0 against the orbit's x0, coloured by N
    (the colours of the map figures), marker by kind, filled when linearly stable
    (``gid="solutions"``). Returns the Figure."""
    if not hasattr(ds, "data_vars") or not all(v in ds.variables for v in ("sol_n", "sol_stable", "sol_x0", "sol_phidot0")):
        raise ValueError("invalid argument `ds`: must be an xarray Dataset with the sol_* variables of librate solve, "
                         f"got {type(ds).__name__}")
    fig, (a,) = figure_axes(ax, 1, figsize=(6.4, 4.8))
    n = ds["sol_n"].values
    kind = ds["sol_kind"].values.astype(str) if "sol_kind" in ds.variables else np.full(n.shape, "periodic")
    stable = ds["sol_stable"].values.astype(bool)
    x, y = ds["sol_x0"].values, ds["sol_phidot0"].values
    handles = []
    for k in sorted(set(n.tolist()), reverse=True):  # the same N, the same colour as in the map figures
        c = n_color(k)
        for kd, marker in KIND_MARKERS.items():
            for st in (True, False):
                sel = (n == k) & (kind == kd) & (stable == st)
                if sel.any():
                    a.scatter(x[sel], y[sel], s=22, marker=marker, edgecolors=c, facecolors=c if st else "none",
                              linewidths=1.2, gid="solutions")
        handles.append(Line2D([], [], linestyle="none", marker="s", color=c, label=f"N = {k:g}"))
    gray = dict(linestyle="none", color="0.3", markeredgecolor="0.3")
    for kd, marker in KIND_MARKERS.items():
        if np.any(kind == kd):
            handles.append(Line2D([], [], marker=marker, markerfacecolor="0.8", label=kd, **gray))
    handles.append(Line2D([], [], marker="o", markerfacecolor="none", label="hollow: unstable", **gray))
    a.set_xlabel("$x_0$ (LU)")
    a.set_ylabel(r"$\dot\phi(0)$ (1/TU)")
    a.set_title("periodic attitude solutions (filled: stable)")
    a.legend(handles=handles, fontsize="small")
    return fig


def plot_attitude_motion(
    solutions,
    ax=None,
    *,
    n_periods: float = 1,
    rate: str = "relative",
    degrees: bool = True,
    samples: int = 400,
) -> Figure:
    """Rotation angle phi(t) (left, ``gid="angle"``) and angular velocity (right,
    ``gid="rate"``) of periodic attitude motions against time in orbital periods t / T (thesis
    Figs. 30-31), one line per solution in the given order, coloured by N (dashed: half-turn).

    ``solutions``: an :class:`~librate.AttitudeSolution` or a list of them (e.g. from
    :func:`librate.find_periodic_attitudes`); each is propagated with
    ``solution.propagate(n_periods)``, ``samples`` points per period. phi is measured from the
    synodic X axis (unwrapped, in degrees unless ``degrees=False``): a periodic motion reaches
    phi0 + 360 N deg after each period. ``rate``: ``"relative"`` (phidot = wz - 1, relative to
    the synodic frame, default) or ``"inertial"`` (wz). ``ax``: two Axes. Returns the Figure.

    Parameters
    ----------
    solutions : AttitudeSolution or list of AttitudeSolution
        The motions.
    n_periods : float, default 1
        Orbit periods drawn.
    rate : {"relative", "inertial"}
        phidot = wz - 1, or wz.
    degrees : bool, default True
        Angles in degrees.
    samples : int, default 400
        Points per period.
    ax : matplotlib Axes or sequence of Axes, optional
        Draw into these (one per panel); default a new Figure.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.

    Raises
    ------
    ValueError
        A bad argument, naming it and the allowed values.
    """
    offset, ylabel = rate_axis(rate, initial=False)
    sols = [solutions] if isinstance(solutions, AttitudeSolution) else solutions
    try:
        sols = list(sols)
    except TypeError:
        sols = []
    if not sols or not all(isinstance(s, AttitudeSolution) for s in sols):
        raise ValueError("invalid argument `solutions`: must be a librate.AttitudeSolution or a non-empty list of them, "
                         f"got {type(solutions).__name__}")
    number = isinstance(n_periods, (int, float, np.integer, np.floating)) and not isinstance(n_periods, bool)
    if not (number and math.isfinite(n_periods) and n_periods > 0):
        raise ValueError(f"invalid argument `n_periods`: must be a number > 0, got {n_periods!r}")
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 2:
        raise ValueError(f"invalid argument `samples`: must be an integer >= 2, got {samples!r}")
    k = 180.0 / math.pi if degrees else 1.0
    keys = [(s.n, s.kind) for s in sols]
    by_n = len(set(keys)) == len(keys)  # colour by N unless two motions share (N, kind)
    cycle = matplotlib.rcParams["axes.prop_cycle"].by_key().get("color", ["tab:blue"])

    created = ax is None
    fig, (a_ang, a_rate) = figure_axes(ax, 2, figsize=(12.0, 4.6))
    for i, s in enumerate(sols):
        T = s.orbit.period
        m = max(2, int(math.ceil(samples * n_periods)) + 1)
        tr = s.propagate(n_periods, t_eval=np.linspace(0.0, n_periods * T, m))
        color = n_color(s.n) if by_n else cycle[i % len(cycle)]
        ls = "--" if s.kind == "half-turn" else "-"
        label = (f"$N$ = {s.n:g}{' half-turn' if s.kind == 'half-turn' else ''}, "
                 f"$\\dot\\varphi(0)$ = {s.phidot0:.4f} ($\\omega_z(0)$ = {s.wz0:.4f}), {'stable' if s.stable else 'unstable'}")
        (h,) = a_ang.plot(tr.t / T, k * tr.phi, color=color, linestyle=ls, linewidth=1.4, label=label)
        h.set_gid("angle")
        (h,) = a_rate.plot(tr.t / T, tr.wz - offset, color=color, linestyle=ls, linewidth=1.4, label=label)
        h.set_gid("rate")
    a_ang.set_ylabel(f"rotation angle $\\varphi$ from the synodic $X$ axis ({'deg' if degrees else 'rad'})")
    a_rate.set_ylabel(ylabel.replace(", relative", "\nrelative"))
    for a in (a_ang, a_rate):
        a.set_xlabel("time $t/T$ (orbital periods)")
        a.set_xlim(0.0, float(n_periods))
        a.margins(y=0.22)  # room for the legend
        a.grid(True, linewidth=0.3, alpha=0.5)
        a.legend(fontsize=7.5, loc="best")
    if degrees:
        a_ang.yaxis.set_major_locator(MultipleLocator(90.0 if np.ptp(a_ang.get_ylim()) <= 1080 else 360.0))
    if created:
        orbs = {id(s.orbit) for s in sols}
        kzs = sorted({s.kz for s in sols})
        where = f"orbit T = {sols[0].orbit.period_days:.2f} d" if len(orbs) == 1 else f"{len(orbs)} orbits"
        fig.suptitle(f"periodic attitude motions, {where}, $K_z$ = {', '.join(f'{v:g}' for v in kzs)}")
    return fig


