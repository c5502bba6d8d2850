"""Figures of the periodicity residuals (thesis Fig. 23) and of the periodicity map over
(orbit, rate) (Fig. 24)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.lines import Line2D

from ..periodicity.solutions import KINDS, check_kinds
from ._style import (
    DPHI_COLOR,
    DWZ_COLOR,
    break_wraps,
    check_index,
    check_map,
    draw_solutions,
    family_name,
    figure_axes,
    kz_mask,
    n_color,
    orbit_axis,
    rate_axis,
    set_contour_gid,
    solution_legend,
    solution_table,
)

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def plot_residuals(
    ds,
    ax=None,
    *,
    kz: float | None = None,
    orbit_index: int | None = None,
    rate: str = "relative",
    solutions: bool = True,
    kinds: Sequence[str] = KINDS,
    annotate: bool = True,
) -> Figure:
    """The residuals after one orbital period against the initial rate, for one orbit and one
    Kz (thesis Fig. 23): Dwz = wz(T) - wz(0) (``gid="residual-dwz"``) and Dphi = phi(T) - phi0
    wrapped to (-pi, pi] (``gid="residual-dphi"``; a NaN breaks the line at each +-pi wrap, its
    finite points are the Dataset's values), the zero line (``gid="zero"``) and, with
    ``solutions``, the refined solutions of the listed ``kinds`` at (rate, 0) (``gid="solutions"``;
    colour by N, circle periodic, diamond half-turn, filled when linearly stable), labelled
    "N = ..." when ``annotate``.

    ``ds``: a Dataset from :func:`librate.periodicity_map` (``orbit_index`` picks the orbit when it
    holds several, ``kz`` the Kz value when it holds several); for one orbit, compute its map
    first, ``periodicity_map(orbit, kz=kz, wz0=wz0)``. ``rate``: the horizontal axis,
    ``"relative"`` (default: phidot(0) = wz(0) - 1, relative to the synodic frame, what the thesis
    figures plot under the label wz(0)) or ``"inertial"`` (wz(0)); the axis label says which.
    Returns the Figure.

    Parameters
    ----------
    ds : xarray.Dataset
        A map of `librate.periodicity_map`.
    ax : matplotlib Axes or sequence of Axes, optional
        Draw into these (one per panel); default a new Figure.
    kz : float, optional
        The Kz value, when the map holds several.
    orbit_index : int, optional
        The orbit, when the map holds several.
    rate : {"relative", "inertial"}
        The horizontal axis.
    solutions : bool, default True
        Mark the refined solutions.
    kinds : sequence of {"periodic", "half-turn"}
        The solutions marked.
    annotate : bool, default True
        Label them "N = ...".

    Returns
    -------
    matplotlib.figure.Figure
        The figure.

    Raises
    ------
    ValueError
        A bad argument, naming it and the allowed values.
    """
    offset, xlabel = rate_axis(rate)
    kinds = check_kinds(kinds)
    ds = check_map(ds, "ds")
    norb = ds.sizes["orbit"]
    if orbit_index is None and norb != 1:
        raise ValueError(f"invalid argument `orbit_index`: the Dataset holds {norb} orbits, pick one")
    i = check_index(0 if orbit_index is None else orbit_index, norb, "orbit_index")
    kzs = np.asarray(ds["kz"].values, dtype=float)
    if kz is None:
        if kzs.size != 1:
            raise ValueError(f"invalid argument `kz`: the Dataset holds {kzs.size} Kz values {kzs.tolist()}, pick one")
        j = 0
    else:
        hit = np.flatnonzero(np.abs(kzs - float(kz)) <= 1e-12)
        if not hit.size:
            raise ValueError(f"invalid argument `kz`: {kz!r} is not in the Dataset's Kz values {kzs.tolist()}")
        j = int(hit[0])
    kz_value = float(ds["kz"].values[j])
    x = np.asarray(ds["wz0"].values, dtype=float) - offset
    dwz = np.asarray(ds["dwz"].values[i, j], dtype=float)
    dphi = np.asarray(ds["dphi"].values[i, j], dtype=float)

    created = ax is None
    fig, (a,) = figure_axes(ax, 1, figsize=(7.4, 4.8))
    z = a.axhline(0.0, color="0.35", linewidth=0.8, zorder=1)
    z.set_gid("zero")
    (h,) = a.plot(x, dwz, color=DWZ_COLOR, linewidth=1.4, label="$\\Delta\\omega_z = \\omega_z(T) - \\omega_z(0)$ (1/TU)")
    h.set_gid("residual-dwz")
    (h,) = a.plot(*break_wraps(x, dphi), color=DPHI_COLOR, linewidth=1.4,
                  label="$\\Delta\\varphi = \\varphi(T) - \\varphi_0$, wrapped to $(-\\pi, \\pi]$ (rad)")
    h.set_gid("residual-dphi")
    handles = list(a.get_legend_handles_labels()[0])
    tab = solution_table(ds) if solutions else None
    if tab is not None:
        m = (tab["orbit"] == i) & kz_mask(tab, kz_value) & np.isin(tab["kind"], kinds)
        if m.any():
            xs = tab["wz0"][m] - offset
            draw_solutions(a, xs, np.zeros_like(xs), tab["n"][m], tab["kind"][m], tab["stable"][m])
            if annotate:
                for xv, nn, k in zip(xs, tab["n"][m], tab["kind"][m]):
                    txt = f"$N$ = {nn:g}" + (", half-turn" if k == "half-turn" else "")
                    a.annotate(txt, (xv, 0.0), xytext=(0, 9), textcoords="offset points", ha="center", va="bottom",
                               fontsize=7.5, color=n_color(nn), rotation=90)
            handles += solution_legend(tab["n"][m], tab["kind"][m], tab["stable"][m])
    a.set_xlabel(xlabel)
    a.set_ylabel("residual after one period: $\\Delta\\omega_z$ (1/TU), $\\Delta\\varphi$ (rad)")
    a.set_xlim(x[0], x[-1])
    a.grid(True, linewidth=0.3, alpha=0.5)
    a.legend(handles=handles, loc="best", fontsize=7.5)
    if created:
        a.set_title(f"residuals after one period: orbit T = {float(ds['period_days'].values[i]):.2f} d "
                    f"($x_0$ = {float(ds['x0'].values[i]):.4f}), $K_z$ = {kz_value:g}")
    return fig


def map_contours(a, x, y, dwz, phi_t, dphi, phi0: float, half_turn_contours: bool) -> list:
    """The zero contours of a map on the grid (x columns, y rows): Dwz = 0 (``gid="contour-dwz"``)
    and Dphi = 0 on the unwrapped phi(t) at the levels phi0 + 2 pi k (``gid="contour-dphi"``; with
    ``phi_t`` None, on sin(Dphi) where cos(Dphi) > 0), with ``half_turn_contours`` also Dphi = pi
    (``gid="contour-dphi-half"``, dotted). Arrays are (rate, x). Returns legend proxies."""
    if np.isfinite(dwz).any() and np.nanmin(dwz) < 0 < np.nanmax(dwz):
        cs = a.contour(x, y, dwz, levels=[0.0], colors=DWZ_COLOR, linewidths=1.1)
        set_contour_gid(cs, "contour-dwz")
    if phi_t is not None:
        p = phi_t - phi0
        fin = p[np.isfinite(p)]
        groups = [("contour-dphi", 0.0, dict(linewidths=1.1, linestyles="solid"))]
        if half_turn_contours:
            groups.append(("contour-dphi-half", math.pi, dict(linewidths=0.7, linestyles="dotted")))
        for gid_, shift, style in groups:
            if not fin.size:
                break
            ks = np.arange(math.ceil((fin.min() - shift) / (2 * math.pi)), math.floor((fin.max() - shift) / (2 * math.pi)) + 1)
            levels = shift + 2 * math.pi * ks
            levels = levels[(levels > fin.min()) & (levels < fin.max())]
            if levels.size:
                cs = a.contour(x, y, p, levels=levels, colors=DPHI_COLOR, **style)
                set_contour_gid(cs, gid_)
    else:
        s = np.where(np.cos(dphi) > 0, np.sin(dphi), np.nan)
        if np.isfinite(s).any() and np.nanmin(s) < 0 < np.nanmax(s):
            cs = a.contour(x, y, s, levels=[0.0], colors=DPHI_COLOR, linewidths=1.1)
            set_contour_gid(cs, "contour-dphi")
    handles = [Line2D([], [], color=DWZ_COLOR, linewidth=1.1, label="$\\Delta\\omega_z = 0$"),
               Line2D([], [], color=DPHI_COLOR, linewidth=1.1, label="$\\Delta\\varphi = 0$")]
    if half_turn_contours:
        handles.append(Line2D([], [], color=DPHI_COLOR, linewidth=0.7, linestyle=":", label="$\\Delta\\varphi = \\pi$"))
    return handles


def plot_map(
    ds,
    ax=None,
    *,
    kz_index: int = 0,
    against: str = "period",
    rate: str = "relative",
    solutions: bool = True,
    kinds: Sequence[str] = ("periodic",),
    half_turn_contours: bool | None = None,
    legend: bool = True,
) -> Figure:
    """The attitude periodicity map of an orbit family for one Kz (thesis Fig. 24): over (orbit,
    initial rate), the zero contours of Dwz (``gid="contour-dwz"``) and of Dphi
    (``gid="contour-dphi"``), and the refined solutions where they cross (``gid="solutions"``,
    colour by N, filled when linearly stable, hollow when not; a legend explains them).

    ``ds``: a Dataset from :func:`librate.periodicity_map` with at least 2 orbits;
    ``kz_index`` picks the Kz. The Dwz contour is ``matplotlib.contour`` at level 0 of the
    (orbit, rate) grid. Dphi = 0 is contoured on the unwrapped phi(T) at the levels phi0 + 2 pi k
    (every k in the data's range; the same zero set as the wrapped Dphi, without a false contour
    along the +-pi wrap; a Dataset without ``phi_T`` falls back to sin(Dphi) where cos(Dphi) >
    0). ``kinds``: the solutions marked, ``"periodic"`` (default) and/or ``"half-turn"``
    (diamonds); ``half_turn_contours`` (default: when half-turn solutions are marked) adds the
    contours Dphi = pi, the levels phi0 + pi (2 k + 1), dotted (``gid="contour-dphi-half"``),
    on which those sit. The contours are those of the sampled grid: a feature narrower than the
    rate step is not drawn (beside a stable solution Dwz can dip below zero over a few 1e-3
    1/TU, so the Dwz contour may pass a stable solution at some distance on a coarse grid); the
    markers are the refined solutions, exact whatever the grid. ``against``: the orbit axis, ``"period"`` (days, default)
    or ``"x0"``. ``rate``: the rate axis, ``"relative"`` (phidot(0) = wz(0) - 1, default, the
    thesis convention) or ``"inertial"`` (wz(0)). Returns the Figure.

    Parameters
    ----------
    ds : xarray.Dataset
        A map of `librate.periodicity_map` with at least 2 orbits.
    kz_index : int, default 0
        The Kz drawn.
    against : {"period", "x0"}
        The orbit axis.
    rate : {"relative", "inertial"}
        The rate axis.
    solutions : bool, default True
        Mark the refined solutions.
    kinds : sequence of {"periodic", "half-turn"}
        The solutions marked.
    half_turn_contours : bool, optional
        Add the contours Dphi = pi (default: when half-turns are marked).
    legend : bool, default True
        Draw the legend.
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
    j = check_index(kz_index, ds.sizes["kz"], "kz_index")
    xv, xlabel = orbit_axis(ds, against)
    offset, ylabel = rate_axis(rate)
    kinds = check_kinds(kinds)
    if half_turn_contours is None:
        half_turn_contours = "half-turn" in kinds
    if xv.size < 2:
        raise ValueError("invalid argument `ds`: a map needs at least 2 orbits (plot_residuals draws one)")
    y = np.asarray(ds["wz0"].values, dtype=float) - offset
    kz_value = float(ds["kz"].values[j])
    phi0 = float(ds.attrs.get("phi0", 0.0))

    created = ax is None
    fig, (a,) = figure_axes(ax, 1, figsize=(8.6, 5.8))
    dwz = np.asarray(ds["dwz"].values[:, j, :], dtype=float).T  # (rate, orbit)
    phi_t = np.asarray(ds["phi_T"].values[:, j, :], dtype=float).T if "phi_T" in ds.variables else None
    dphi = np.asarray(ds["dphi"].values[:, j, :], dtype=float).T
    handles = map_contours(a, xv, y, dwz, phi_t, dphi, phi0, half_turn_contours)
    tab = solution_table(ds) if solutions else None
    if tab is not None:
        m = kz_mask(tab, kz_value) & np.isin(tab["kind"], kinds)
        if m.any():
            draw_solutions(a, xv[tab["orbit"][m]], tab["wz0"][m] - offset, tab["n"][m], tab["kind"][m], tab["stable"][m],
                            markersize=5.0)
            handles += solution_legend(tab["n"][m], tab["kind"][m], tab["stable"][m])
    a.set_xlim(np.nanmin(xv), np.nanmax(xv))
    a.set_ylim(y[0], y[-1])
    a.set_xlabel(xlabel)
    a.set_ylabel(ylabel)
    a.grid(True, linewidth=0.3, alpha=0.5)
    if legend:
        a.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7.5, borderaxespad=0.0)
    if created:
        a.set_title(f"attitude periodicity map, {family_name(ds.attrs.get('family', ''))} family, $K_z$ = {kz_value:g}")
    return fig


