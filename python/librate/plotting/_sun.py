"""Figures of the Sun in the synodic frame (thesis Figs. 33-34) and of the gravity-gradient and SRP
angular accelerations on a Sun-pointing spacecraft (Fig. 39)."""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import TYPE_CHECKING

import matplotlib
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.ticker import MultipleLocator

from .._checks import as_count, as_number
from ..attitude.srp import FlatPlate
from ..constants import OMEGA_SUN, SUN_SYNODIC_PERIOD
from ..orbits.families import OrbitFamily
from ..orbits.periodic import PeriodicOrbit
from ..orbits.system import check_system
from ..periodicity.srp_motions import sun_angle, sun_pointing_accelerations, sun_resonance
from ._style import (
    EARTH,
    LABEL_OFFSETS,
    MOON,
    SRP_COLOR,
    SUN_COLOR,
    check_family,
    draw_primaries,
    family_name,
    figure_axes,
    length_scale,
    time_scale,
)

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def plot_sun_motion(
    system,
    ax=None,
    *,
    theta_sun0: float = 0.0,
    n_periods: float = 1,
    n_directions: int = 8,
    units: str = "days",
) -> Figure:
    """The apparent motion of the Sun in the synodic frame (thesis Fig. 33).

    The Sun direction s(t) = (cos theta_s, sin theta_s, 0), theta_s(t) = omega_sun t + theta_sun0
    (docs/physics.md, solar radiation pressure; parallax neglected, so it is the same everywhere in the system), turns
    CLOCKWISE at omega_sun = -(1 - n_sun) = :data:`librate.constants.OMEGA_SUN` (1/TU): one
    apparent solar period Ts = 2 pi / (1 - n_sun) (29.49 d with the Earth-Moon TU).

    Left panel: the synodic frame with the Earth-Moon line (``gid="earth-moon-line"``, the X axis
    from the Earth to the Moon), the Sun directions at t_k = k Ts / ``n_directions``, k = 0 ...
    n_directions - 1 (rays from the barycentre, ``gid="sun-direction"``, in that order, angle
    theta_s(t_k), each ending at a Sun marker ``gid="sun"`` labelled with t_k), and the circle they
    sweep with arrows showing the clockwise sense (``gid="sun-path"``). Right panel: theta_s(t),
    unwrapped, in degrees against time over ``n_periods`` apparent solar periods
    (``gid="sun-angle"``), a vertical line at each multiple of Ts (``gid="solar-period"``) and the
    angles at which the Sun lies on the Earth-Moon line: beyond the Moon (theta_s = 0 mod 360 deg,
    new Moon, ``gid="sun-beyond-moon"``) and behind the Earth (180 deg mod 360, full Moon,
    ``gid="sun-behind-earth"``). ``theta_sun0``: the Sun's phase at t = 0 (rad, the
    ``theta0`` of a :class:`librate.Sun`); ``units``: ``"days"`` or ``"TU"``; ``ax``: two Axes. Returns the
    Figure.

    Parameters
    ----------
    system : System or str
        The system.
    theta_sun0 : float, default 0.0
        The Sun's phase at t = 0 (rad).
    n_periods : float, default 1
        Apparent solar periods drawn.
    n_directions : int, default 8
        Sun directions drawn.
    units : {"days", "TU"}
        Time unit.
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
    sys_ = check_system(system)
    theta_sun0 = as_number(theta_sun0, "theta_sun0")
    n_periods = as_number(n_periods, "n_periods", positive=True)
    n_directions = as_count(n_directions, "n_directions", 1)
    tscale, tunit = time_scale(sys_, units)
    tname = "d" if tunit == "days" else "TU"
    ts = SUN_SYNODIC_PERIOD
    created = ax is None
    fig, (a_geo, a_ang) = figure_axes(ax, 2, figsize=(12.4, 5.4))

    # --- geometry in the synodic frame
    radius = 1.45
    e, m = sys_.primary_positions()
    a_geo.axhline(0.0, color="0.7", linewidth=0.6, linestyle=":", zorder=0)
    (h,) = a_geo.plot([e[0], m[0]], [e[1], m[1]], color="0.25", linewidth=1.8, zorder=3, label="Earth-Moon line (synodic $X$ axis)")
    h.set_gid("earth-moon-line")
    t_path = np.linspace(0.0, ts, 361)
    th = sun_angle(theta_sun0, t_path)
    (h,) = a_geo.plot(radius * np.cos(th), radius * np.sin(th), color=SUN_COLOR, linewidth=1.0, linestyle="--", zorder=1,
                      label=f"Sun direction over one apparent solar period $T_s$ = {ts * tscale:.2f} {tname}")
    h.set_gid("sun-path")
    for f in (0.06, 0.31, 0.56, 0.81):  # arrow heads: the clockwise sense
        t1, t2 = f * ts, (f + 0.02) * ts
        p1, p2 = [radius * np.array([math.cos(v), math.sin(v)]) for v in sun_angle(theta_sun0, [t1, t2])]
        arr = a_geo.annotate("", xy=p2, xytext=p1, arrowprops=dict(arrowstyle="-|>", color=SUN_COLOR, linewidth=1.2,
                                                                  mutation_scale=14))
        arr.set_gid("sun-path-arrow")
    cm = matplotlib.colormaps["plasma"]
    for k in range(n_directions):
        tk = k * ts / n_directions
        ang = float(sun_angle(theta_sun0, tk))
        c, s = math.cos(ang), math.sin(ang)
        color = cm(0.85 * k / n_directions)
        (h,) = a_geo.plot([0.0, radius * c], [0.0, radius * s], color=color, linewidth=2.0 if k == 0 else 1.0, zorder=2,
                          label=f"Sun direction at $t$ = 0 ($\\theta_{{s0}}$ = {math.degrees(theta_sun0):.4g} deg)" if k == 0
                          else "_nolegend_")
        h.set_gid("sun-direction")
        (h,) = a_geo.plot([radius * c], [radius * s], marker="o", markersize=11 if k == 0 else 8, color=SUN_COLOR,
                          markeredgecolor=color, markeredgewidth=1.5, linestyle="none", zorder=4)
        h.set_gid("sun")
        a_geo.annotate(f"{tk * tscale:.1f} {tname}", (radius * c, radius * s), xytext=(14 * c, 14 * s), textcoords="offset points",
                       ha="center", va="center", fontsize=7.5, color="0.2")
    draw_primaries(a_geo, sys_)
    (b,) = a_geo.plot([0.0], [0.0], marker="+", color="k", markersize=7, linestyle="none")
    b.set_gid("barycentre")
    lim = radius * 1.3
    a_geo.set_xlim(-lim, lim)
    a_geo.set_ylim(-lim, lim)
    a_geo.set_aspect("equal")
    a_geo.set_xlabel("$X$ (LU), synodic frame")
    a_geo.set_ylabel("$Y$ (LU)")
    a_geo.grid(True, linewidth=0.3, alpha=0.5)
    a_geo.legend(loc="upper center", bbox_to_anchor=(0.5, -0.11), fontsize=7.5, ncols=1)
    a_geo.text(0.98, 0.98, f"clockwise: $\\omega_s$ = {OMEGA_SUN:.4f} 1/TU", transform=a_geo.transAxes, ha="right", va="top",
               fontsize=8, color="0.2")

    # --- the Sun's angle against time
    t = np.linspace(0.0, n_periods * ts, max(2, int(math.ceil(360 * n_periods)) + 1))
    deg = np.degrees(sun_angle(theta_sun0, t))
    (h,) = a_ang.plot(t * tscale, deg, color=SUN_COLOR, linewidth=1.8,
                      label=f"$\\theta_s(t) = \\omega_s t + \\theta_{{s0}}$, $\\omega_s$ = {OMEGA_SUN:.4f} 1/TU = "
                            f"{math.degrees(OMEGA_SUN) / sys_.tu_days:.2f} deg/d")
    h.set_gid("sun-angle")
    for k in range(1, int(math.floor(n_periods + 1e-9)) + 1):
        v = a_ang.axvline(k * ts * tscale, color="0.35", linestyle="--", linewidth=0.9,
                          label=f"$t = k T_s$, $T_s$ = {ts * tscale:.2f} {tname}" if k == 1 else "_nolegend_")
        v.set_gid("solar-period")
    lo, hi = float(deg.min()), float(deg.max())
    for shift, gid_, name, style in ((0.0, "sun-beyond-moon", "Sun beyond the Moon on the Earth-Moon line (new Moon)", "-."),
                                     (180.0, "sun-behind-earth", "Sun behind the Earth on the Earth-Moon line (full Moon)", ":")):
        levels = shift + 360.0 * np.arange(math.ceil((lo - shift) / 360.0), math.floor((hi - shift) / 360.0) + 1)
        for i, lv in enumerate(levels):
            hl = a_ang.axhline(lv, color="0.45", linestyle=style, linewidth=0.9, label=name if i == 0 else "_nolegend_")
            hl.set_gid(gid_)
    a_ang.yaxis.set_major_locator(MultipleLocator(90.0 if hi - lo <= 1080 else 360.0))
    a_ang.set_xlim(0.0, n_periods * ts * tscale)
    a_ang.set_xlabel(f"time $t$ ({tunit})")
    a_ang.set_ylabel("Sun angle $\\theta_s$ from the synodic $X$ axis (deg, unwrapped)")
    a_ang.grid(True, linewidth=0.3, alpha=0.5)
    a_ang.legend(loc="upper right", fontsize=7.5)
    if created:
        fig.suptitle(f"apparent Sun motion in the synodic frame ({sys_.name}): clockwise, one turn in $T_s$ = {ts * tscale:.2f} {tname}")
    return fig


def plot_sun_resonant(
    family: OrbitFamily,
    ax=None,
    ks: Iterable[int] = (1, 2, 3, 4),
    *,
    units: str = "LU",
    samples: int = 600,
    primaries: bool = True,
) -> Figure:
    """The Sun-resonant members of a planar family in the synodic frame (thesis Fig. 34): for each
    K in ``ks`` the member with T = Ts / K (``family.resonant(K, "sun")``; the Sun then returns
    to the same direction relative to the orbit after K revolutions), propagated over one period
    with ``samples`` points (``gid="sun-resonant-K"``, labelled with T, T in days and x0) and its
    start (x0, 0) marked (``gid="start"``). A K whose period lies outside the family's range is
    not drawn but listed in a note (``gid="missing-resonances"``): for the Earth-Moon DROs the 1:1
    member (T = Ts = 29.49 d) is longer than the family's longest period (27.39 d, where the DROs
    reach the Earth). ``units``: ``"LU"`` or ``"km"``; ``primaries`` marks the Earth and the Moon.
    Raises ValueError (naming ``ks``) when no K is in range. Returns the Figure.

    Parameters
    ----------
    family : OrbitFamily
        A planar family.
    ks : iterable of int, default (1, 2, 3, 4)
        The Sun resonances 1:K drawn.
    units : {"LU", "km"}
        Length unit.
    samples : int, default 600
        Points per orbit.
    primaries : bool, default True
        Mark the Earth and the Moon.
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
    try:
        ks = [ks] if isinstance(ks, (int, np.integer)) else list(ks)
    except TypeError:
        ks = None
    if not ks or not all(isinstance(k, (int, np.integer)) and not isinstance(k, bool) and k >= 1 for k in ks):
        raise ValueError(f"invalid argument `ks`: must be a non-empty sequence of integers >= 1, got {ks!r}")
    samples = as_count(samples, "samples", 2)
    sys_ = fam.system
    scale, unit = length_scale(sys_, units)
    found, missing = [], []
    for k in ks:
        try:
            found.append((int(k), fam.resonant(int(k), "sun")))
        except ValueError:
            missing.append(int(k))
    if not found:
        raise ValueError(f"invalid argument `ks`: no Sun-resonant member 1:K (T = Ts/K) for K in {tuple(ks)} lies in the "
                         f"{family_name(fam.kind)} family's period range [{fam.period_days.min():.2f}, {fam.period_days.max():.2f}] d")
    created = ax is None
    fig, (a,) = figure_axes(ax, 1, figsize=(7.2, 6.2))
    cm = matplotlib.colormaps["viridis"]
    for i, (k, o) in enumerate(found):
        color = cm(0.85 * i / max(1, len(found) - 1))
        tr = o.propagate(t_eval=np.linspace(0.0, o.period, samples))
        p = tr.y[:, :2] * scale
        (h,) = a.plot(p[:, 0], p[:, 1], color=color, linewidth=1.5,
                      label=f"1:{k} Sun: $T = T_s/{k}$ = {o.period_days:.2f} d, $x_0$ = {o.x0:.4f} LU")
        h.set_gid(f"sun-resonant-{k}")
        (s,) = a.plot([p[0, 0]], [p[0, 1]], "o", color=color, markersize=4)
        s.set_gid("start")
    if primaries:
        allp = np.vstack([ln.get_xydata() for ln in a.get_lines() if (ln.get_gid() or "").startswith("sun-resonant-")])
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        pad = 0.25 * np.max(hi - lo)
        e, m = sys_.primary_positions() * scale
        for pos, name, style, gid in ((e, "Earth", EARTH, "earth"), (m, "Moon", MOON, "moon")):
            near = bool(np.all((pos[:2] >= lo - pad) & (pos[:2] <= hi + pad)))
            if near:
                (h,) = a.plot([pos[0]], [pos[1]], zorder=4, **style)
                dx, dy, ha = LABEL_OFFSETS[name]
                a.annotate(name, (pos[0], pos[1]), xytext=(dx, dy), textcoords="offset points", fontsize=8, ha=ha)
            else:  # drawn, but kept out of the data limits: an arrow at the edge points to it
                h = a.add_artist(Line2D([pos[0]], [pos[1]], **style))
                a.annotate(f"$\\leftarrow$ {name} at $x$ = {pos[0]:.4g} {unit}" if pos[0] < lo[0]
                           else f"{name} at $x$ = {pos[0]:.4g} {unit} $\\rightarrow$",
                           xy=(0.0 if pos[0] < lo[0] else 1.0, 0.5), xycoords="axes fraction", xytext=(4 if pos[0] < lo[0] else -4, 8),
                           textcoords="offset points", ha="left" if pos[0] < lo[0] else "right", va="center", fontsize=8,
                           color="0.3").set_gid(f"{gid}-direction")
            h.set_gid(gid)
    if missing:
        txt = ", ".join(f"1:{k} ($T$ = {SUN_SYNODIC_PERIOD / k * sys_.tu_days:.2f} d)" for k in missing)
        note = a.text(0.02, 0.02, f"not in the family's period range [{fam.period_days.min():.2f}, {fam.period_days.max():.2f}] d: {txt}",
                      transform=a.transAxes, fontsize=7.5, color="0.35", ha="left", va="bottom")
        note.set_gid("missing-resonances")
    a.set_xlabel(f"x ({unit}), synodic frame")
    a.set_ylabel(f"y ({unit})")
    a.set_aspect("equal", adjustable="datalim")
    a.grid(True, linewidth=0.3, alpha=0.5)
    a.legend(loc="upper left", fontsize=7.5)
    if created:
        ts_days = SUN_SYNODIC_PERIOD * sys_.tu_days
        a.set_title(f"Sun-resonant {family_name(fam.kind)} orbits ($T = T_s/K$, $T_s$ = {ts_days:.2f} d), synodic frame")
    return fig


# --- periodicity maps over (eps, rate) ----------------------------------------------------------
def plot_sun_pointing(
    system,
    body_or_plate,
    ax=None,
    *,
    orbit: PeriodicOrbit,
    offset: float = 0.0,
    kz: float | None = None,
    sun=None,
    n_periods: float | None = None,
    samples: int = 1500,
    units: str = "days",
) -> Figure:
    """Angular accelerations on a Sun-pointing spacecraft (thesis Fig. 39): the body is held at
    phi(t) = theta_s(t) + ``offset`` (``offset`` = 0: body x axis, the plate's normal, at the Sun;
    it then turns at the Sun's rate, phidot = omega_sun, wz = 1 + omega_sun = n_sun, constant), along
    ``orbit``; drawn against time: the gravity-gradient angular acceleration 1.5 Kz [S cos 2 phi
    - C sin 2 phi] (``gid="gravity-gradient"``), the SRP one (``gid="srp"``; constant for a body
    fixed relative to the Sun) and their sum (``gid="total"``, dashed), which a control torque
    must cancel to hold the pointing (see :func:`sun_pointing_accelerations` for the models and
    ``kz`` / ``sun``). ``body_or_plate``: a :class:`librate.FlatPlate` (with ``kz``) or a
    :class:`librate.FacetBody`. ``n_periods``: orbital periods shown (default: the whole number
    covering one apparent solar period, ceil(Ts / T), after which a Sun-resonant orbit's pattern
    repeats), ``samples`` points per period; ``units``: ``"days"`` or ``"TU"``. Accelerations in
    1/TU^2 (nondimensional torque per Iz). Returns the Figure.

    Parameters
    ----------
    system : System or str
        The system.
    body_or_plate : FlatPlate or FacetBody
        The spacecraft (a plate needs ``kz``).
    orbit : PeriodicOrbit
        The orbit.
    offset : float, default 0.0
        The body x axis's angle from the Sun (rad).
    kz : float, optional
        Inertia ratio (with a plate).
    sun : Sun, optional
        With a `FacetBody`: the Sun.
    n_periods : float, optional
        Orbit periods drawn (default ceil(Ts / T)).
    samples : int, default 1500
        Points per period.
    units : {"days", "TU"}
        Time unit.
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
    sys_ = check_system(system)
    if not isinstance(orbit, PeriodicOrbit):
        raise ValueError(f"invalid argument `orbit`: must be a librate.PeriodicOrbit, got {type(orbit).__name__}")
    if n_periods is None:
        n_periods = max(1, math.ceil(SUN_SYNODIC_PERIOD / orbit.period - 1e-6))
    n_periods = as_number(n_periods, "n_periods", positive=True)
    samples = as_count(samples, "samples", 2)
    tscale, tunit = time_scale(sys_, units)
    t = np.linspace(0.0, n_periods * orbit.period, max(2, int(math.ceil(samples * n_periods)) + 1))
    gg, srp = sun_pointing_accelerations(sys_, body_or_plate, t, orbit=orbit, offset=offset, kz=kz, sun=sun)
    if isinstance(body_or_plate, FlatPlate):
        what = f"flat plate $\\varepsilon$ = {body_or_plate.eps:.4g}, $C_s$ = {body_or_plate.cs:g}, $C_d$ = {body_or_plate.cd:g}"
        kz_value = float(kz)
    else:
        what = f"{len(body_or_plate.facets)}-facet body"
        kz_value = float(body_or_plate.kz)
    created = ax is None
    fig, (a,) = figure_axes(ax, 1, figsize=(8.4, 4.8))
    z = a.axhline(0.0, color="0.5", linewidth=0.7)
    z.set_gid("zero")
    (h,) = a.plot(t * tscale, gg, color="tab:blue", linewidth=1.4,
                  label="gravity gradient $\\frac{3}{2} K_z (S\\cos 2\\varphi - C\\sin 2\\varphi)$, max |.| = "
                        f"{np.max(np.abs(gg)):.3g}")
    h.set_gid("gravity-gradient")
    (h,) = a.plot(t * tscale, srp, color=SRP_COLOR, linewidth=1.4, label=f"SRP ({what}), max |.| = {np.max(np.abs(srp)):.3g}")
    h.set_gid("srp")
    (h,) = a.plot(t * tscale, gg + srp, color="k", linestyle="--", linewidth=1.1, label="total (a control torque cancels it)")
    h.set_gid("total")
    k = sun_resonance(orbit)
    for j in range(1, int(math.floor(n_periods + 1e-9)) + 1):
        v = a.axvline(j * orbit.period * tscale, color="0.7", linestyle=":", linewidth=0.8)
        v.set_gid("period")
    a.set_xlim(0.0, t[-1] * tscale)
    a.set_xlabel(f"time $t$ ({tunit}); dotted: orbital periods")
    a.set_ylabel("angular acceleration $\\dot\\omega_z$ (1/TU$^2$)")
    a.margins(y=0.3)
    a.grid(True, linewidth=0.3, alpha=0.5)
    a.legend(fontsize=7.5, loc="upper right")
    if created:
        where = f"1:{k} Sun-resonant orbit" if k else "orbit"
        a.set_title(f"Sun-pointing spacecraft ($\\varphi = \\theta_s + {math.degrees(offset):.4g}$ deg), {where} "
                    f"($T$ = {orbit.period_days:.2f} d), $K_z$ = {kz_value:.4g}", fontsize=10)
    return fig


