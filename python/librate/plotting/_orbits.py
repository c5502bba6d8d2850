"""Figures of periodic-orbit families and orbits (thesis ch. 2, Figs. 3-11) and of an attitude
response (Figs. 16-21)."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING

import matplotlib
import numpy as np
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Normalize
from matplotlib.lines import Line2D
from matplotlib.ticker import FuncFormatter, MaxNLocator
from matplotlib.transforms import blended_transform_factory

from ..attitude.propagate import AttitudeTrajectory
from ..constants import SUN_SYNODIC_PERIOD
from ..orbits.families import OrbitFamily
from ..orbits.frames import synodic_to_eci
from ..orbits.periodic import PeriodicOrbit
from ._style import (
    EARTH,
    LABEL_OFFSETS,
    LPOINT,
    MOON,
    PROJECTIONS,
    check_family,
    family_axis,
    family_name,
    figure_axes,
    length_scale,
    level_crossings,
    pick_orbits,
    resonance_label,
    time_scale,
)

if TYPE_CHECKING:
    from matplotlib.figure import Figure


# --- synodic-frame family (Fig. 3) ------------------------------------------------------------
def plot_family(
    family: OrbitFamily,
    ax=None,
    *,
    n_orbits: int | None = 30,
    color_by: str | None = "jacobi",
    projection: str | Sequence[str] | None = None,
    units: str = "LU",
    samples: int = 600,
    primaries: bool = True,
    lagrange_points: Iterable[int] = (1, 2),
    cmap: str = "turbo",
    clim: tuple[float, float] | None = None,
    colorbar: bool = True,
    linewidth: float = 0.8,
) -> Figure:
    """The orbits of a family in the synodic frame, coloured by Jacobi constant (thesis Fig. 3).

    ``n_orbits`` members evenly spread along the family (the first and last included; None:
    all) are propagated over one period and drawn with ``samples`` points each, one line per
    orbit (``gid="orbit"``, in family order). ``color_by``: ``"jacobi"``, ``"period"`` (days),
    ``"x0"`` or None (one colour); the colour scale spans the whole family's range (or
    ``clim=(vmin, vmax)``) and a colorbar shows it. ``projection``: ``"xy"``, ``"xz"``,
    ``"yz"``, ``"3d"`` or a sequence of them, one panel each; default ``"xy"`` for planar
    families and ``("xy", "xz")`` for spatial ones. ``ax``: one Axes per panel (3-D panels need
    ``projection="3d"`` Axes). ``units``: ``"LU"`` or ``"km"``. ``primaries`` marks the Earth
    and the Moon, ``lagrange_points`` the listed L-points (``()`` for none); a marker far from
    the orbits does not widen the view. Returns the Figure.

    Parameters
    ----------
    family : OrbitFamily
        The family.
    n_orbits : int or None, default 30
        Members drawn, evenly spread (None: all).
    color_by : {"jacobi", "period", "x0", None}
        The colour scale (None: one colour).
    projection : str or sequence of str, optional
        "xy", "xz", "yz" or "3d", or several (one panel each); default "xy" for planar families,
        ("xy", "xz") for spatial ones.
    units : {"LU", "km"}
        Length unit.
    samples : int, default 600
        Points per orbit.
    primaries : bool, default True
        Mark the Earth and the Moon.
    lagrange_points : iterable of int, default (1, 2)
        The L-points marked.
    cmap : str, default "turbo"
        Colour map.
    clim : (float, float), optional
        The colour range (default the family's).
    colorbar : bool, default True
        Draw the colour bar.
    linewidth : float, default 0.8
        Line width.
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
    fam = check_family(family)
    sys_ = fam.system
    if projection is None:
        projection = ("xy", "xz") if fam.spatial else "xy"
    projs = [projection] if isinstance(projection, str) else list(projection)
    if not projs or any(p not in PROJECTIONS for p in projs):
        raise ValueError(f"invalid argument `projection`: must be one of {', '.join(PROJECTIONS)} or a sequence of "
                         f"them, got {projection!r}")
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 2:
        raise ValueError(f"invalid argument `samples`: must be an integer >= 2, got {samples!r}")
    scale, unit = length_scale(sys_, units)
    colors = {"jacobi": (fam.jacobi, "Jacobi constant $C$ (LU$^2$/TU$^2$)"),
              "period": (fam.period_days, "period $T$ (days)"),
              "x0": (fam.x0, "$x_0$ (LU)")}
    if color_by is not None and color_by not in colors:
        raise ValueError(f"invalid argument `color_by`: must be one of {', '.join(colors)} or None, got {color_by!r}")
    if clim is not None and not (len(clim) == 2 and all(math.isfinite(float(c)) for c in clim) and clim[0] < clim[1]):
        raise ValueError(f"invalid argument `clim`: must be (vmin, vmax) with vmin < vmax, got {clim!r}")
    lpoints = [int(k) for k in lagrange_points]
    if any(k not in (1, 2, 3, 4, 5) for k in lpoints):
        raise ValueError(f"invalid argument `lagrange_points`: must list L-point numbers 1..5, got {lagrange_points!r}")

    created = ax is None
    fig, axs = figure_axes(ax, len(projs), three_d=[p == "3d" for p in projs],
                     figsize=(7.0, 5.6) if len(projs) == 1 else None)
    sel = pick_orbits(len(fam), n_orbits)
    if color_by is not None:
        values, clabel = colors[color_by]
        finite = np.asarray(values)[np.isfinite(values)]
        vmin, vmax = (float(finite.min()), float(finite.max())) if clim is None else (float(clim[0]), float(clim[1]))
        norm = Normalize(vmin=vmin, vmax=vmax)
        cm = matplotlib.colormaps[cmap]

    paths = []
    for i in sel:
        orbit = fam[int(i)]
        tr = orbit.propagate(t_eval=np.linspace(0.0, orbit.period, int(samples)))
        paths.append(tr.y[:, :3] * scale)
    comps = {"x": 0, "y": 1, "z": 2}
    for a, proj in zip(axs, projs):
        for i, p in zip(sel, paths):
            color = cm(norm(float(values[i]))) if color_by is not None else "tab:blue"
            if proj == "3d":
                (line,) = a.plot(p[:, 0], p[:, 1], p[:, 2], color=color, linewidth=linewidth)
            else:
                (line,) = a.plot(p[:, comps[proj[0]]], p[:, comps[proj[1]]], color=color, linewidth=linewidth)
            line.set_gid("orbit")
        allp = np.vstack(paths)
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        pad = 0.25 * np.max(hi - lo)
        marks = []
        if primaries:
            e, m = sys_.primary_positions() * scale
            marks += [(e, "Earth", EARTH, "earth"), (m, "Moon", MOON, "moon")]
        if lpoints:
            lp = sys_.lagrange_points() * scale
            for k in lpoints:
                marks.append((lp[k - 1], f"L{k}", LPOINT, f"L{k}"))
        for pos, name, style, gid in marks:
            # A marker far outside the orbits (the Earth, for halos about L2) does not zoom out.
            shown = [0, 1, 2] if proj == "3d" else [comps[proj[0]], comps[proj[1]]]
            near = bool(np.all((pos[shown] >= lo[shown] - pad) & (pos[shown] <= hi[shown] + pad)))
            if proj == "3d":
                if not near:
                    continue
                (h,) = a.plot([pos[0]], [pos[1]], [pos[2]], **style)
                a.text(pos[0], pos[1], pos[2], f"  {name}", fontsize=8)
            else:
                u, v = pos[comps[proj[0]]], pos[comps[proj[1]]]
                if near:
                    (h,) = a.plot([u], [v], **style)
                else:  # drawn, but kept out of the data limits
                    h = a.add_artist(Line2D([u], [v], **style))
                dx, dy, ha = LABEL_OFFSETS.get(name, (4, 5, "left"))
                a.annotate(name, (u, v), xytext=(dx, dy), textcoords="offset points", fontsize=8, ha=ha)
            h.set_gid(gid)
        if proj == "3d":
            a.set_xlabel(f"x ({unit})")
            a.set_ylabel(f"y ({unit})")
            a.set_zlabel(f"z ({unit})")
            a.set_box_aspect(np.maximum(np.ptp(allp, axis=0), 1e-3 * np.ptp(allp)))
            for axis in (a.xaxis, a.yaxis, a.zaxis):  # a few ticks: a narrow 3-D axis would print its labels over each other
                axis.set_major_locator(MaxNLocator(4))
        else:
            a.set_xlabel(f"{proj[0]} ({unit})")
            a.set_ylabel(f"{proj[1]} ({unit})")
            a.set_aspect("equal", adjustable="datalim")
            a.grid(True, linewidth=0.3, alpha=0.5)
    if color_by is not None and colorbar:
        sm = ScalarMappable(norm=norm, cmap=cm)
        sm.set_array(np.asarray(values))
        fig.colorbar(sm, ax=axs, label=clabel, shrink=0.9)
    if created:
        axs[0].set_title(f"{family_name(fam.kind)} family, synodic frame ({len(sel)} of {len(fam)} members)")
    return fig


# --- period and resonances (Fig. 6) ------------------------------------------------------------
def plot_period(
    family: OrbitFamily,
    ax=None,
    *,
    resonances: Iterable[int] = (1, 2, 3, 4),
    sun_resonances: Iterable[int] = (2, 4),
    units: str = "days",
    against: str = "x0",
    primaries: bool = True,
    markers: bool = True,
) -> Figure:
    """The period of a family's members against x0 (thesis Fig. 6), with the resonances.

    The family's period is the line ``gid="period"``; horizontal lines mark the synodic 1:K
    resonances, T = 2 pi / K (``gid="resonance-synodic-K"``, dashed), and the Sun-resonant 1:K,
    T = Ts / K with Ts = :data:`librate.constants.SUN_SYNODIC_PERIOD` the apparent solar period
    in the synodic frame (``gid="resonance-sun-K"``, dotted), each labelled in the legend; with
    ``markers``, a labelled dot marks where the family crosses each line (interpolated between
    members). ``units``: ``"days"`` (via the system's TU) or ``"TU"``. ``against``: ``"x0"``,
    ``"z0"`` or ``"jacobi"``; for x0, ``primaries`` draws vertical lines at the Earth (-mu) and
    the Moon (1 - mu). The view is the data's range (widened to take in a line within 35 % of
    that range beyond it); lines out of the view are left out of the legend. Returns the Figure.

    Parameters
    ----------
    family : OrbitFamily
        The family.
    resonances : iterable of int, default (1, 2, 3, 4)
        The synodic 1:K resonances drawn.
    sun_resonances : iterable of int, default (2, 4)
        The Sun 1:K resonances drawn.
    units : {"days", "TU"}
        Period unit.
    against : {"x0", "z0", "jacobi"}
        The horizontal axis.
    primaries : bool, default True
        With x0: vertical lines at the primaries.
    markers : bool, default True
        Mark the family's crossings of the resonance lines.
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
    fam = check_family(family)
    sys_ = fam.system
    tscale, tunit = time_scale(sys_, units)
    x, xlabel = family_axis(fam, against)
    res, sres = list(resonances), list(sun_resonances)
    if not all(isinstance(k, (int, np.integer)) and not isinstance(k, bool) and k >= 1 for k in res + sres):
        raise ValueError(f"invalid argument: resonance orders must be integers >= 1, got {tuple(res)} and {tuple(sres)}")
    res, sres = [int(k) for k in res], [int(k) for k in sres]
    created = ax is None
    fig, (a,) = figure_axes(ax, 1, figsize=(7.0, 5.0))
    period = fam.period * tscale
    (line,) = a.plot(x, period, color="k", linewidth=1.6, label=f"{family_name(fam.kind)} period")
    line.set_gid("period")
    groups = [(k, 2 * math.pi / k, "synodic", "tab:red", "--", f"1:{k}") for k in res]
    groups += [(k, SUN_SYNODIC_PERIOD / k, "sun", "tab:orange", ":", f"1:{k} Sun") for k in sres]
    tname = "d" if tunit == "days" else "TU"
    for k, t_tu, kind, color, ls, short in groups:
        level = t_tu * tscale
        formula = f"2\\pi/{k}" if kind == "synodic" else f"T_s/{k}"
        label = f"{short} {'synodic ' if kind == 'synodic' else ''}resonance, $T = {formula}$ = {level:.2f} {tname}"
        h = a.axhline(level, color=color, linestyle=ls, linewidth=1.1, label=label)
        h.set_gid(f"resonance-{kind}-{k}")
        if markers:
            xs = level_crossings(x, period, level)
            if xs:
                (m,) = a.plot(xs, [level] * len(xs), "o", color=color, markersize=5, markeredgecolor="k")
                m.set_gid(f"resonant-member-{kind}-{k}")
                for xc in xs:
                    a.annotate(short, (xc, level), xytext=(-7, 0), textcoords="offset points", ha="right", va="center",
                               fontsize=7.5, color=color)
    if primaries and against == "x0":
        for xp, name, color in ((-sys_.mu, "Earth position ($-\\mu$)", "tab:blue"), (1 - sys_.mu, "Moon position ($1-\\mu$)", "0.4")):
            v = a.axvline(xp, color=color, linestyle="-.", linewidth=1.0, label=name)
            v.set_gid("earth" if name.startswith("Earth") else "moon")
    a.set_xlabel(xlabel)
    a.set_ylabel(f"period $T$ ({tunit})")
    xlim, ylim = _data_view(x, period, [g[1] * tscale for g in groups],
                            [-sys_.mu, 1 - sys_.mu] if primaries and against == "x0" else [])
    a.set_xlim(*xlim)
    a.set_ylim(*ylim)
    for h in a.get_lines():  # a reference line out of the view is not listed in the legend
        gid = h.get_gid() or ""
        if gid.startswith("resonance-") and not ylim[0] <= h.get_ydata()[0] <= ylim[1] or \
                gid in ("earth", "moon") and not xlim[0] <= h.get_xdata()[0] <= xlim[1]:
            h.set_label("_nolegend_")
    a.grid(True, linewidth=0.3, alpha=0.5)
    a.legend(loc="best", fontsize=7.5)
    if created:
        a.set_title(f"{family_name(fam.kind)} family: period and resonances")
    return fig


def _data_view(x, y, levels, positions, reach: float = 0.35, pad: float = 0.05):
    """(xlim, ylim) of the data (x, y), widened to take in a reference level (y) or position
    (x) lying within ``reach`` of the data's span beyond it, then padded by ``pad``."""
    def span(v, refs):
        v = np.asarray(v, dtype=float)
        lo, hi = float(np.nanmin(v)), float(np.nanmax(v))
        w = hi - lo or max(abs(hi), 1.0) * 0.1
        near = [r for r in refs if lo - reach * w <= r <= hi + reach * w]
        lo, hi = min([lo, *near]), max([hi, *near])
        w = hi - lo
        return lo - pad * w, hi + pad * w
    return span(x, positions), span(y, levels)


# --- stability (Fig. 5) ------------------------------------------------------------------------
def follow_indices(nu: np.ndarray) -> np.ndarray:
    """The members' index pairs (rows of ``nu``) reordered so that each index continues the
    nearest one of the previous member (least sum of |difference|, complex), not the order the
    family lists them in: no line jumps where two indices swap places between members."""
    out = np.array(nu, copy=True)
    for i in range(1, out.shape[0]):
        prev, cur = out[i - 1], out[i]
        if np.all(np.isfinite(prev)) and np.all(np.isfinite(cur)) and \
                np.sum(np.abs(cur[::-1] - prev)) < np.sum(np.abs(cur - prev)):
            out[i] = cur[::-1]
    return out


def plot_stability(
    family: OrbitFamily,
    ax=None,
    *,
    against: str = "x0",
    imag: bool = False,
    band: bool = True,
    bifurcations: bool = True,
    yscale: str | None = None,
) -> Figure:
    """The two stability indices nu = (lambda + 1/lambda) / 2 of a family's members against x0
    (thesis Fig. 5), real parts: ``gid="stability-0"`` (in-plane for planar families) and
    ``"stability-1"`` (out-of-plane), their y data equal to ``family.stability_indices.real``;
    for spatial families (halos) each member's pair is matched to the previous member's by
    nearest value, so that a curve follows one index, not the sort order.
    A member is linearly stable when both are real with |nu| <= 1: the band -1 <= nu <= 1 is
    shaded (``band``). For a stable pair lambda = exp(+-i phi), nu = cos phi = Re(lambda), so
    the curves are the real parts of the eigenvalues the thesis plots. ``bifurcations``: a
    vertical line (``gid="bifurcation"``) and a label at each crossing of +1 or -1 listed in
    ``family.bifurcations``. ``imag`` adds the imaginary parts dashed (``"stability-imag-j"``).
    ``yscale``: ``"linear"``, ``"symlog"`` or None (symlog when some |nu| exceeds 10).
    Returns the Figure.

    Parameters
    ----------
    family : OrbitFamily
        The family.
    against : {"x0", "z0", "jacobi", "period"}
        The horizontal axis.
    imag : bool, default False
        Add the imaginary parts, dashed.
    band : bool, default True
        Shade the stable band |nu| <= 1.
    bifurcations : bool, default True
        Mark the crossings of +1 and -1.
    yscale : {"linear", "symlog", None}
        None: symlog when some |nu| exceeds 10.
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
    fam = check_family(family)
    x, xlabel = family_axis(fam, against)
    nu = np.asarray(fam.stability_indices)
    if fam.spatial:  # no in-plane / out-of-plane: follow each index from member to member
        nu = follow_indices(nu)
    names = ("in-plane $\\nu_1$", "out-of-plane $\\nu_2$") if not fam.spatial else ("$\\nu_1$", "$\\nu_2$")
    created = ax is None
    fig, (a,) = figure_axes(ax, 1, figsize=(7.0, 5.0))
    if band:
        s = a.axhspan(-1.0, 1.0, color="tab:green", alpha=0.08, label="$|\\nu| \\leq 1$ (stable)")
        s.set_gid("stable-band")
        for lv in (-1.0, 1.0):
            a.axhline(lv, color="tab:green", linewidth=0.8)
    colors = ("tab:blue", "tab:red")
    for j in range(2):
        (h,) = a.plot(x, nu[:, j].real, color=colors[j], linewidth=1.5, label=f"Re {names[j]}")
        h.set_gid(f"stability-{j}")
        if imag:
            (h,) = a.plot(x, nu[:, j].imag, color=colors[j], linewidth=1.0, linestyle="--", label=f"Im {names[j]}")
            h.set_gid(f"stability-imag-{j}")
    if bifurcations:
        trans = blended_transform_factory(a.transData, a.transAxes)
        for n, b in enumerate(fam.bifurcations):
            i = int(b["member"])
            if against == "x0":
                xb = float(b["x0"])
            else:
                w = (b["x0"] - fam.x0[i]) / (fam.x0[i + 1] - fam.x0[i]) if fam.x0[i + 1] != fam.x0[i] else 0.0
                xb = float(x[i] + w * (x[i + 1] - x[i]))
            v = a.axvline(xb, color="0.3", linestyle=":", linewidth=1.0)
            v.set_gid("bifurcation")
            which = b["index"]
            if fam.spatial:  # the curve that crosses there (the indices are drawn followed, not as listed)
                ends = nu[i:i + 2].real - b["level"]
                cost = np.nanmin(np.abs(ends), axis=0) - (np.prod(ends, axis=0) <= 0)  # a sign change first, then nearest
                which = names[int(np.argmin(cost))]
            a.text(xb, 0.02 if n % 2 == 0 else 0.98, f" {which} $\\nu = {b['level']:+g}$ at $x_0$ = {b['x0']:.4f} ",
                   transform=trans, rotation=90, ha="right", va="bottom" if n % 2 == 0 else "top", fontsize=7.5, color="0.2")
    finite = np.abs(nu[np.isfinite(nu)])
    if yscale is None:
        yscale = "symlog" if finite.size and finite.max() > 10 else "linear"
    if yscale not in ("linear", "symlog"):
        raise ValueError(f"invalid argument `yscale`: must be 'linear', 'symlog' or None, got {yscale!r}")
    if yscale == "symlog":
        a.set_yscale("symlog", linthresh=1.0)
    a.set_xlabel(xlabel)
    a.set_ylabel("stability index $\\nu$ (nondimensional)")
    a.grid(True, linewidth=0.3, alpha=0.5)
    a.legend(loc="best", fontsize=8)
    if created:
        a.set_title(f"{family_name(fam.kind)} family: stability indices")
    return fig


# --- Earth-centred inertial frame (Figs. 7, 10, 11) --------------------------------------------
def plot_eci(
    orbits: PeriodicOrbit | Iterable[PeriodicOrbit],
    ax=None,
    *,
    n_periods: float | None = None,
    samples_per_period: int = 2000,
    theta0: float = 0.0,
    units: str = "km",
    separate: bool = False,
    labels: Sequence[str] | None = None,
    moon_path: bool = True,
) -> Figure:
    """Periodic orbits in the Earth-centred inertial frame (thesis Figs. 7a, 10, 11), X-Y plane.

    Each orbit is propagated in the synodic frame from its ``state0`` (``samples_per_period``
    points per period) and mapped with :func:`librate.synodic_to_eci` (``theta0``: the synodic x
    axis' angle from X at t = 0), one line per orbit (``gid="orbit"``), starting at
    |r0 - r_earth| LU from the Earth (origin, ``gid="earth"``); ``moon_path`` draws the Moon's
    circle of radius 1 LU (``gid="moon-path"``). ``n_periods``: default (None) the whole
    number of periods covering one synodic revolution 2 pi, ceil(2 pi / T): a 1:K resonant
    orbit (get it with ``family.resonant(K)``) then closes after K periods, while a
    non-resonant one shows its apsidal rotation. ``separate``: one panel per orbit instead of
    all in one (``ax`` a sequence of that many Axes). ``labels``: one per orbit; default "1:K"
    for resonant orbits, else x0 and the period. ``units``: ``"km"`` or ``"LU"``. Returns the
    Figure.

    Parameters
    ----------
    orbits : PeriodicOrbit or iterable of PeriodicOrbit
        The orbits.
    n_periods : float, optional
        Periods drawn; default ceil(2 pi / T).
    samples_per_period : int, default 2000
        Points per period.
    theta0 : float, default 0.0
        The synodic x axis's angle from the ECI X axis at t = 0 (rad).
    units : {"km", "LU"}
        Length unit.
    separate : bool, default False
        One panel per orbit.
    labels : sequence of str, optional
        One per orbit.
    moon_path : bool, default True
        Draw the Moon's circle.
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
    if isinstance(orbits, PeriodicOrbit):
        orbits = [orbits]
    orbits = list(orbits)
    if not orbits or not all(isinstance(o, PeriodicOrbit) for o in orbits):
        raise ValueError("invalid argument `orbits`: must be a librate.PeriodicOrbit or a non-empty sequence of them")
    if n_periods is not None and not (isinstance(n_periods, (int, float, np.integer,
                                                             np.floating)) and math.isfinite(n_periods) and n_periods > 0):
        raise ValueError(f"invalid argument `n_periods`: must be a number > 0 or None, got {n_periods!r}")
    if isinstance(samples_per_period, bool) or not isinstance(samples_per_period, (int, np.integer)) or samples_per_period < 8:
        raise ValueError(f"invalid argument `samples_per_period`: must be an integer >= 8, got {samples_per_period!r}")
    if labels is not None and len(labels) != len(orbits):
        raise ValueError(f"invalid argument `labels`: need one per orbit ({len(orbits)}), got {len(labels)}")
    if labels is None:
        labels = [resonance_label(o) or f"$x_0$ = {o.x0:.4f}, T = {o.period_days:.2f} d" for o in orbits]
    sys_ = orbits[0].system
    scale, unit = length_scale(sys_, units)
    created = ax is None
    npanels = len(orbits) if separate else 1
    fig, axs = figure_axes(ax, npanels, figsize=(6.4, 6.0) if npanels == 1 else None)
    cycle = matplotlib.rcParams["axes.prop_cycle"].by_key().get("color", ["tab:blue"])
    for j, (orbit, label) in enumerate(zip(orbits, labels)):
        a = axs[j] if separate else axs[0]
        n = n_periods if n_periods is not None else max(1, math.ceil(2 * math.pi / orbit.period - 1e-9))
        m = max(2, int(round(samples_per_period * n)) + 1)
        tr = orbit.propagate(n, t_eval=np.linspace(0.0, n * orbit.period, m))
        r = synodic_to_eci(orbit.system, tr.t, tr.y, theta0=theta0)[:, :3] / orbit.system.lu_km * scale
        (h,) = a.plot(r[:, 0], r[:, 1], color=cycle[j % len(cycle)] if not separate else "tab:blue", linewidth=1.0, label=label)
        h.set_gid("orbit")
        (s,) = a.plot([r[0, 0]], [r[0, 1]], "o", color=h.get_color(), markersize=3.5)
        s.set_gid("start")
        if separate:
            a.set_title(label)
    for a in axs:
        if moon_path:
            th = np.linspace(0, 2 * math.pi, 721)
            (c,) = a.plot(scale * np.cos(th), scale * np.sin(th), color="0.5", linestyle=":", linewidth=1.0, label="Moon path")
            c.set_gid("moon-path")
        (e,) = a.plot([0.0], [0.0], label="Earth", **EARTH)
        e.set_gid("earth")
        if units == "km":
            # Data in km, ticks in thousands of km.
            for axis in (a.xaxis, a.yaxis):
                axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v / 1000:g}"))
        tick_unit = "10$^3$ km" if units == "km" else unit
        a.set_xlabel(f"X ({tick_unit}), Earth-centred inertial")
        a.set_ylabel(f"Y ({tick_unit})")
        a.set_aspect("equal", adjustable="datalim")
        a.grid(True, linewidth=0.3, alpha=0.5)
        a.legend(loc="upper right", fontsize=8)
    if created and not separate:
        axs[0].set_title("Earth-centred inertial frame")
    return fig


# --- attitude response (Figs. 16-21) ------------------------------------------------------------
def plot_attitude(traj, ax=None, *, period: float | None = None, relative_to: str | None = None, degrees: bool = True) -> Figure:
    """Attitude response of an :class:`librate.AttitudeTrajectory` against revolutions (thesis
    Fig. 16-21): the angular rates (left) and the 1-2-3 Euler angles (right) for roll, pitch and
    yaw about the body x, y, z axes.

    ``period``: time of one revolution (TU) for the horizontal axis (default: time in TU).
    ``relative_to``: "earth" or "moon" to show the angles relative to that primary's local
    vertical (the two-body convention of Fig. 16-18), else relative to the synodic frame.
    Rates are the inertial angular velocity components in body axes (1/TU).

    Parameters
    ----------
    traj : AttitudeTrajectory
        A 3-D run of `librate.propagate_attitude`.
    period : float, optional
        One revolution (TU) for the horizontal axis; default time in TU.
    relative_to : {"earth", "moon", None}
        Angles relative to that primary's local vertical, else to the synodic frame.
    degrees : bool, default True
        Angles in degrees.
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
    if not isinstance(traj, AttitudeTrajectory):
        raise ValueError(f"invalid argument `traj`: must be a librate.AttitudeTrajectory, got {type(traj).__name__}")
    if period is not None and not (math.isfinite(period) and period > 0):
        raise ValueError(f"invalid argument `period`: must be finite and > 0, got {period!r}")
    fig, (a_rate, a_ang) = figure_axes(ax, 2, figsize=(11, 4.2))
    x = traj.t / period if period else traj.t
    xlabel = "revolutions (-)" if period else "t (TU)"
    ang = traj.relative_to_vertical(relative_to) if relative_to else traj.euler_angles("123")
    ang = np.unwrap(ang, axis=0)
    k = 180.0 / math.pi if degrees else 1.0
    for i, name in enumerate(("roll (x)", "pitch (y)", "yaw (z)")):
        (line,) = a_rate.plot(x, traj.w[:, i], label=f"$\\omega_{'xyz'[i]}$ {name}")
        line.set_gid(f"rate-{i}")
        (line,) = a_ang.plot(x, k * ang[:, i], label=name)
        line.set_gid(f"angle-{i}")
    a_rate.set_xlabel(xlabel)
    a_rate.set_ylabel("inertial angular rate, body axes (1/TU)")
    a_ang.set_xlabel(xlabel)
    frame = f"{relative_to}'s local vertical" if relative_to else "synodic frame"
    a_ang.set_ylabel(f"Euler angles 1-2-3 from the {frame} ({'deg' if degrees else 'rad'})")
    for a in (a_rate, a_ang):
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    if ax is None:
        fig.suptitle("attitude response")
    return fig

