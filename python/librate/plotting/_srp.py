"""Figures of flat-plate SRP periodicity maps over (eps, rate) (thesis Figs. 35-36, 40-41) and of
a gravity-only periodic motion beside its SRP counterpart (Figs. 37-38)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.lines import Line2D

from .._checks import as_count, as_number
from ..periodicity.solutions import KINDS, AttitudeSolution, check_kinds
from ..periodicity.srp_motions import sun_resonance
from ._maps import map_contours, plot_map
from ._style import GRAVITY_COLOR, SRP_COLOR, check_map, draw_solutions, figure_axes, n_color, rate_axis, solution_legend

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def _check_srp_map(ds, name: str = "ds"):
    names = getattr(ds, "variables", None)
    if (not hasattr(ds, "data_vars") or names is None or getattr(ds, "attrs", {}).get("map") != "srp-eps"
            or not all(v in names for v in ("dwz", "dphi", "phi_T", "eps", "wz0"))):
        raise ValueError(f"invalid argument `{name}`: must be an xarray Dataset from librate.periodicity.srp_map, got {type(ds).__name__}")
    return ds


def _orbit_name(attrs) -> str:
    k = int(attrs.get("sun_resonance", 0) or 0)
    what = f"1:{k} Sun-resonant orbit" if k else "orbit"
    return f"{what} ($T$ = {attrs['period_days']:.2f} d, $x_0$ = {attrs['x0']:.4f}), $K$ = {attrs['n_periods']}"


def plot_srp_map(
    ds,
    ax=None,
    *,
    rate: str = "relative",
    solutions: bool = True,
    branches: bool = True,
    kinds: Sequence[str] = KINDS,
    half_turn_contours: bool = False,
    reference: float | tuple[float, str] | None = None,
    legend: bool = True,
    markersize: float = 3.5,
) -> Figure:
    """A flat-plate SRP periodicity map over (eps, initial rate) for one orbit (thesis Figs.
    35-36; one panel of Figs. 40-41), from :func:`srp_map`.

    Drawn: the zero contours of Dwz = wz(KT) - wz0 (``gid="contour-dwz"``) and of Dphi =
    phi(KT) - phi0 (``gid="contour-dphi"``, on the unwrapped phi(KT): no false contour along the
    +-pi wrap; ``half_turn_contours`` adds Dphi = pi, ``"contour-dphi-half"``), all for the map's
    fixed phi0, exactly as :func:`plot_map` draws them; with ``solutions``, the solutions at the
    grid's eps values (``gid="solutions"``, colour by N, circle periodic / diamond half-turn,
    filled when linearly stable, at (eps, rate)); with ``branches``, each branch through all its
    continuation points (``gid="branch-{kind}-N{N:+d}"``; solid from the gravity-only solution at
    eps = 0, dotted from the map's far end) and, where it stopped, a cross: ``gid="fold"`` (black X)
    at a fold (monodromy trace 2) or ``gid="branch-end"`` (grey x) where the continuation failed
    otherwise. The branch solutions have phi0 FREE (SRP breaks the symmetry; the contours are for
    the fixed phi0): the gravity-only ones start on the contours' crossings at eps = 0 and leave
    them. ``reference``:
    an eps (or (eps, label)) marked by a vertical line (``gid="eps-reference"``; only named in the
    legend when outside the map's range), e.g. the plate of a given A/m. ``rate``: ``"relative"`` (phidot(0) = wz(0) - 1, default) or
    ``"inertial"``. ``kinds``: the solutions shown. Returns the Figure.

    Parameters
    ----------
    ds : xarray.Dataset
        A map of `librate.srp_map`.
    rate : {"relative", "inertial"}
        The rate axis.
    solutions : bool, default True
        Mark the solutions at the grid's eps values.
    branches : bool, default True
        Draw the branches and where they stopped.
    kinds : sequence of {"periodic", "half-turn"}
        The solutions shown.
    half_turn_contours : bool, default False
        Add the contours Dphi = pi.
    reference : float or (float, str), optional
        An eps (with a label) marked by a vertical line.
    legend : bool, default True
        Draw the legend.
    markersize : float, default 3.5
        Marker size.
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
    ds = _check_srp_map(ds)
    offset, ylabel = rate_axis(rate)
    kinds = check_kinds(kinds)
    ref_label = None
    if reference is not None:
        if isinstance(reference, tuple) and len(reference) == 2:
            reference, ref_label = reference
        reference = as_number(reference, "reference")
    x = np.asarray(ds["eps"].values, dtype=float)
    y = np.asarray(ds["wz0"].values, dtype=float) - offset
    phi0 = float(ds.attrs.get("phi0", 0.0))
    created = ax is None
    fig, (a,) = figure_axes(ax, 1, figsize=(8.6, 5.8))
    handles = map_contours(a, x, y, np.asarray(ds["dwz"].values, dtype=float).T, np.asarray(ds["phi_T"].values, dtype=float).T,
                            np.asarray(ds["dphi"].values, dtype=float).T, phi0, half_turn_contours)
    if branches and "branch_n" in ds.variables:
        pb = np.asarray(ds["path_branch"].values)
        drawn_end = {"fold": False, "branch-end": False}
        for b in range(ds.sizes.get("branch", 0)):
            kind, nn = str(ds["branch_kind"].values[b]), float(ds["branch_n"].values[b])
            if kind not in kinds:
                continue
            sel = pb == b
            far = str(ds["branch_origin"].values[b]) == "end"
            (h,) = a.plot(ds["path_eps"].values[sel], ds["path_wz0"].values[sel] - offset, color=n_color(nn),
                          linewidth=1.3 if far else 1.0, alpha=0.85, linestyle=":" if far else "--" if kind == "half-turn" else "-",
                          zorder=4)
            h.set_gid(f"branch-{kind}-N{nn:+g}")
            ee = float(ds["branch_end_eps"].values[b])
            if math.isfinite(ee):
                fold = bool(ds["branch_fold"].values[b])
                gid_ = "fold" if fold else "branch-end"
                (h,) = a.plot([ee], [float(ds["branch_end_wz0"].values[b]) - offset], linestyle="none", zorder=6,
                              **(dict(marker="X", color="k", markersize=8) if fold else dict(marker="x", color="0.4", markersize=7)))
                h.set_gid(gid_)
                drawn_end[gid_] = True
        origins = set(np.asarray(ds["branch_origin"].values).tolist())
        if "gravity" in origins:
            handles.append(Line2D([], [], color="0.3", linewidth=1.0, label="branch continued from $\\varepsilon$ = 0 ($\\varphi_0$ free)"))
        if "end" in origins:
            handles.append(Line2D([], [], color="0.3", linewidth=1.3, linestyle=":",
                                  label="branch continued from the map's end ($\\varphi_0$ free)"))
        if drawn_end["fold"]:
            handles.append(Line2D([], [], linestyle="none", marker="X", color="k", markersize=8, label="fold (trace $M$ = 2)"))
        if drawn_end["branch-end"]:
            handles.append(Line2D([], [], linestyle="none", marker="x", color="0.4", markersize=7, label="continuation stopped"))
    if solutions and "sol_eps" in ds.variables and ds.sizes.get("solution", 0):
        kind = np.asarray(ds["sol_kind"].values)
        m = np.isin(kind, kinds)
        if m.any():
            n = np.asarray(ds["sol_n"].values)[m]
            st = np.asarray(ds["sol_stable"].values)[m]
            draw_solutions(a, np.asarray(ds["sol_eps"].values)[m], np.asarray(ds["sol_wz0"].values)[m] - offset, n, kind[m], st,
                            markersize=markersize)
            handles += solution_legend(n, kind[m], st)
    if reference is not None:
        inside = x[0] <= reference <= x[-1]
        if inside:
            v = a.axvline(reference, color="0.2", linestyle="-.", linewidth=1.0)
            v.set_gid("eps-reference")
        handles.append(Line2D([], [], color="0.2", linestyle="-.", linewidth=1.0,
                              label=(ref_label or f"$\\varepsilon$ = {reference:.4g}") + ("" if inside else " (beyond this map)")))
    a.set_xlim(x[0], x[-1])
    a.set_ylim(y[0], y[-1])
    a.set_xlabel("SRP amplitude $\\varepsilon = P A d\\, TU^2 / I_z$ (nondimensional)")
    a.set_ylabel(ylabel)
    a.grid(True, linewidth=0.3, alpha=0.5)
    if legend:
        a.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7.5, borderaxespad=0.0)
    if created:
        at = ds.attrs
        a.set_title(f"SRP periodicity map, {_orbit_name(at)}\n$K_z$ = {at['kz']:g}, $C_s$ = {at['cs']:g}, $C_d$ = {at['cd']:g}, "
                    f"$\\theta_{{s0}}$ = {math.degrees(at['theta_sun0']):.4g} deg, $\\varphi_0$ = {at['phi0']:g} rad", fontsize=10)
    return fig


_MAP_PARAMETERS = (("kz", "$K_z$"), ("cs", "$C_s$"), ("cd", "$C_d$"), ("theta_sun0", "$\\theta_{s0}$"), ("eps", "$\\varepsilon$"))
_MAP_UNITS = {"theta_sun0": " deg"}


def _map_parameters(ds) -> dict:
    """The fixed parameters of a map (srp_map or periodicity_map Dataset), by the names above."""
    at = ds.attrs
    if at.get("map") == "srp-eps":
        return {"kz": at["kz"], "cs": at["cs"], "cd": at["cd"], "theta_sun0": math.degrees(at["theta_sun0"])}
    out = {"cs": at.get("srp_cs", 0.0), "cd": at.get("srp_cd", 0.0), "theta_sun0": math.degrees(at.get("theta_sun0", 0.0)),
           "eps": at.get("srp_eps", 0.0)}
    if ds.sizes.get("kz", 0) == 1:
        out["kz"] = float(ds["kz"].values[0])
    return out


def plot_srp_maps(maps, ax=None, *, titles: Sequence[str] | None = None, **kwargs) -> Figure:
    """Several periodicity maps side by side, one panel per parameter value (thesis Figs. 40-41:
    several Cs, several Kz): each :func:`srp_map` Dataset drawn by :func:`plot_srp_map`, each
    :func:`librate.periodicity_map` Dataset by :func:`plot_map` (``kwargs`` are passed on). Each
    panel's title names the parameter values that differ between the maps (e.g. "$C_s$ = 0.4";
    among Kz, Cs, Cd, the Sun phase and eps), or ``titles`` (one per map); the legend is drawn
    beside the last panel only; with ``ax=None`` the suptitle names the common values. ``ax``: one
    Axes per map. Returns the Figure.

    Parameters
    ----------
    maps : sequence of xarray.Dataset
        Maps of `librate.srp_map` or `librate.periodicity_map`.
    titles : sequence of str, optional
        One per map (default: the parameter values that differ).
    **kwargs
        Passed on to `plot_srp_map` or `plot_map`.
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
    try:
        maps = list(maps)
    except TypeError:
        maps = []
    if not maps:
        raise ValueError("invalid argument `maps`: must be a non-empty sequence of map Datasets (srp_map or periodicity_map)")
    for i, ds in enumerate(maps):
        if getattr(ds, "attrs", {}).get("map") != "srp-eps":
            check_map(ds, "maps")
    if titles is not None and (isinstance(titles, str) or len(titles) != len(maps)):
        raise ValueError(f"invalid argument `titles`: need one title per map ({len(maps)}), got {titles!r}")
    params = [_map_parameters(ds) for ds in maps]
    names = [k for k, _ in _MAP_PARAMETERS if all(k in p for p in params)]
    varying = [k for k in names if len({round(p[k], 12) for p in params}) > 1]
    common = [k for k in names if k not in varying]
    label = dict(_MAP_PARAMETERS)
    created = ax is None
    fig, axs = figure_axes(ax, len(maps), figsize=(8.6, 5.8) if len(maps) == 1 else (5.0 * min(len(maps), 3) + 2.6,
                                                                                     5.4 * math.ceil(len(maps) / 3)))
    import inspect

    takes = {f: set(inspect.signature(f).parameters) - {"ds", "ax"} for f in (plot_srp_map, plot_map)}
    for k in kwargs:
        if not any(k in t for t in takes.values()):
            raise ValueError(f"invalid argument `{k}`: neither plot_srp_map nor plot_map takes it")
    for i, (ds, a) in enumerate(zip(maps, axs)):
        last = i == len(maps) - 1
        f = plot_srp_map if ds.attrs.get("map") == "srp-eps" else plot_map
        kw = {k: v for k, v in kwargs.items() if k in takes[f]}  # e.g. reference= only for SRP maps
        kw.setdefault("legend", last)
        f(ds, a, **kw)
        if titles is not None:
            title = titles[i]
        else:
            shown = varying or names
            title = ", ".join(f"{label[k]} = {params[i][k]:.4g}{_MAP_UNITS.get(k, '')}" for k in shown)
        a.set_title(title, fontsize=10)
        if len(maps) > 1:  # the short label; the suptitle says relative or inertial
            a.set_ylabel(a.get_ylabel().split(",")[0] + " (1/TU)")
    if created:
        first = maps[0].attrs
        where = _orbit_name(first) if first.get("map") == "srp-eps" else f"{first.get('family', '') or 'orbit'} family"
        fixed = ", ".join(f"{label[k]} = {params[0][k]:.4g}{_MAP_UNITS.get(k, '')}" for k in common)
        rates = "inertial rates" if kwargs.get("rate") == "inertial" else "rates relative to the synodic frame"
        fig.suptitle(f"periodicity maps, {where}" + (f"; {fixed}" if fixed else "") + f" ({rates})", fontsize=11)
    return fig


# --- gravity-only vs SRP, Sun-pointing (Figs. 37-39) ---------------------------------------------
def plot_srp_comparison(
    gravity_solution,
    srp_solution,
    ax=None,
    *,
    n_periods: float | None = None,
    rate: str = "relative",
    degrees: bool = True,
    samples: int = 400,
) -> Figure:
    """A gravity-only periodic motion and its SRP counterpart (thesis Figs. 37-38, a small and a
    large SRP effect): the rotation angle phi(t) (left; ``gid="gravity-angle"``, dashed black, and
    ``gid="srp-angle"``, red) and the angular velocity (right; ``"gravity-rate"``, ``"srp-rate"``)
    against time in orbital periods t / T, over ``n_periods`` revolutions (default: the SRP
    solution's K, ``srp_solution.n_periods``, after which it repeats), ``samples`` points per
    revolution, each from ``solution.propagate(n_periods)``. Vertical lines mark each K
    revolutions (``gid="repeat"``). Both solutions must be on the same orbit (e.g. ``srp_solution``
    from :func:`librate.continue_srp` of ``gravity_solution``). phi unwrapped from the synodic X
    axis, in degrees unless ``degrees=False``; ``rate``: ``"relative"`` (phidot = wz - 1, default)
    or ``"inertial"`` (wz). ``ax``: two Axes. Returns the Figure.

    Parameters
    ----------
    gravity_solution : AttitudeSolution
        The gravity-only motion.
    srp_solution : AttitudeSolution
        Its SRP counterpart on the same orbit.
    n_periods : float, optional
        Revolutions drawn (default the SRP solution's K).
    rate : {"relative", "inertial"}
        The rate axis.
    degrees : bool, default True
        Angles in degrees.
    samples : int, default 400
        Points per revolution.
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
    for name, s in (("gravity_solution", gravity_solution), ("srp_solution", srp_solution)):
        if not isinstance(s, AttitudeSolution):
            raise ValueError(f"invalid argument `{name}`: must be a librate.AttitudeSolution, got {type(s).__name__}")
    g, s = gravity_solution, srp_solution
    same = (g.orbit.system.mu == s.orbit.system.mu and abs(g.orbit.period - s.orbit.period) <= 1e-9 * g.orbit.period
            and np.allclose(g.orbit.state0, s.orbit.state0, rtol=0.0, atol=1e-9))
    if not same:
        raise ValueError("invalid argument `srp_solution`: must be on the same orbit as `gravity_solution`")
    k_rep = int(s.n_periods)
    n = float(k_rep) if n_periods is None else as_number(n_periods, "n_periods", positive=True)
    samples = as_count(samples, "samples", 2)
    offset, ylabel = rate_axis(rate, initial=False)
    kdeg = 180.0 / math.pi if degrees else 1.0
    T = s.orbit.period
    t = np.linspace(0.0, n * T, max(2, int(math.ceil(samples * n)) + 1))
    created = ax is None
    fig, (a_ang, a_rate) = figure_axes(ax, 2, figsize=(12.4, 4.8))
    for key, sol, color, ls in (("gravity", g, GRAVITY_COLOR, "--"), ("srp", s, SRP_COLOR, "-")):
        tr = sol.propagate(n, t_eval=t)
        eps = 0.0 if sol.srp is None else float(sol.srp.eps)
        what = "gravity only" if sol.srp is None or eps == 0.0 else f"SRP $\\varepsilon$ = {eps:.4g}"
        label = (f"{what}: $N$ = {sol.n:g}, $\\varphi_0$ = {math.degrees(sol.phi0):.3f} deg, $\\dot\\varphi(0)$ = {sol.phidot0:.4f}, "
                 f"{'stable' if sol.stable else 'unstable'}")
        (h,) = a_ang.plot(tr.t / T, kdeg * tr.phi, color=color, linestyle=ls, linewidth=1.4, label=label)
        h.set_gid(f"{key}-angle")
        (h,) = a_rate.plot(tr.t / T, tr.wz - offset, color=color, linestyle=ls, linewidth=1.4, label=label)
        h.set_gid(f"{key}-rate")
    for a in (a_ang, a_rate):
        for j in range(1, int(math.floor(n / k_rep + 1e-9)) + 1):
            v = a.axvline(j * k_rep, color="0.5", linestyle=":", linewidth=0.9)
            v.set_gid("repeat")
        a.set_xlabel("time $t/T$ (orbital periods)")
        a.set_xlim(0.0, n)
        a.margins(y=0.25)
        a.grid(True, linewidth=0.3, alpha=0.5)
        a.legend(fontsize=7.5, loc="best")
    a_ang.set_ylabel(f"rotation angle $\\varphi$ from the synodic $X$ axis ({'deg' if degrees else 'rad'})")
    a_rate.set_ylabel(ylabel.replace(", relative", "\nrelative"))
    if created:
        k = sun_resonance(s.orbit)
        where = f"1:{k} Sun-resonant orbit" if k else "orbit"
        fig.suptitle(f"gravity-only vs SRP periodic motion, {where} (T = {s.orbit.period_days:.2f} d), $K_z$ = {s.kz:g}, "
                     f"{k_rep} revolution{'s' if k_rep > 1 else ''} per repeat")
    return fig


