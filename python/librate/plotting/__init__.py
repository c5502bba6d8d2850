"""Figures of periodic-orbit families and orbits (thesis ch. 2), of periodic attitude motions
(thesis sec. 3.3) and of solar radiation pressure (thesis ch. 4), drawn with matplotlib.

This module is the only part of librate that uses matplotlib, and ``import librate`` does not
import it: import it explicitly, ``import librate.plotting as lp``. matplotlib is a required
dependency (the command line draws its figures by default), installed with librate.
``matplotlib.pyplot`` itself is imported only when a function has to create a figure.

Every ``plot_*`` function takes the data (an :class:`~librate.OrbitFamily`,
:class:`~librate.PeriodicOrbit` objects, a Dataset from :func:`librate.periodicity_map`,
:class:`~librate.AttitudeSolution` objects) and an optional ``ax``: with ``ax=None`` it creates a
new figure (through ``pyplot``, so ``plt.show()`` displays it; close it with ``plt.close(fig)``
when drawing many), otherwise it draws into the given Axes (a sequence of Axes where a
function draws several panels). **Every function returns the matplotlib Figure** it drew
into; it never calls ``plt.show()``. Axes are labelled with units: LU (the primaries'
distance, ``system.lu_km``), TU, days or km. Attitude rates are plotted RELATIVE to the
synodic frame by default, phidot = wz - 1 (the quantity on the thesis figures' axes, which
label it wz(0)); ``rate="inertial"`` plots wz, and the axis label says which. Artists carry a ``gid`` naming what they show
(``"orbit"``, ``"earth"``, ``"resonance-synodic-2"``, ...), so figures can be inspected.

- :func:`plot_family`: a family's orbits in the synodic frame, coloured by Jacobi constant (Fig. 3)
- :func:`plot_period`: period against x0 with synodic and Sun resonances (Fig. 6)
- :func:`plot_stability`: stability indices against x0 with bifurcations (Fig. 5)
- :func:`plot_eci`: orbits in the Earth-centred inertial frame, in km (Figs. 7a, 10, 11)
- :func:`plot_attitude`: an attitude response, rates and Euler angles (Figs. 16-21)
- :func:`plot_residuals`: Dwz and Dphi after one period against the initial rate (Fig. 23)
- :func:`plot_map`: the periodicity map, zero contours and solutions over (orbit, rate) (Fig. 24)
- :func:`plot_solution_families`: solutions of each N across the orbit family, per Kz (Figs. 27-29)
- :func:`plot_attitude_motion`: phi(t) and the rate of periodic motions (Figs. 30-31)
- :func:`plot_sun_motion`: the apparent Sun motion in the synodic frame (Fig. 33)
- :func:`plot_sun_resonant`: the Sun-resonant members T = Ts / K of a family (Fig. 34)
- :func:`plot_srp_map`: flat-plate SRP periodicity maps of one orbit over (eps, rate), zero
  contours and solution branches with folds (Figs. 35-36), from the data of
  :func:`librate.periodicity.srp_map` (also importable from here)
- :func:`plot_srp_maps`: several maps side by side, one per Cs, Kz, ... (Figs. 40-41)
- :func:`plot_srp_comparison`: a gravity-only periodic motion and its SRP counterpart (Figs. 37-38)
- :func:`plot_sun_pointing`: gravity-gradient and SRP angular accelerations on a Sun-pointing
  spacecraft (Fig. 39), computed by :func:`librate.periodicity.sun_pointing_accelerations` (also
  importable from here)

This package only draws: the data come from :mod:`librate.periodicity` and the layers below.
- :func:`save_figure`: write a figure to a file

The SRP amplitude of the flat plate is eps = P A d TU^2 / Iz = P (A/m) d TU^2 / k^2 (k the radius
of gyration, Iz = m k^2): with the Earth-Moon TU (375190 s), P = 4.56e-6 N/m^2 and A/m = 0.016
m^2/kg, eps = 1.03e4 d / k^2 (d, k in m). The samples and examples take k = 10 m and a centre of
pressure d = 1 cm from the centre of mass: eps = 1.03. Far from the primaries the gravity gradient
is weak: on the 1:2 Sun-resonant DRO its angular acceleration is below 1 1/TU^2 (7e-12 1/s^2) for
Kz = 0.6, so a CoP offset of 1 m (eps ~ 100) makes SRP dominate by two orders of magnitude, and the
gravity-only solution branches there fold at eps ~ 0.3 - 0.7 (d ~ 3 - 7 mm for k = 10 m).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

try:
    import matplotlib
    from matplotlib.axes import Axes
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from matplotlib.lines import Line2D
    from matplotlib.ticker import FuncFormatter, MultipleLocator
    from matplotlib.transforms import blended_transform_factory
except ImportError as exc:  # pragma: no cover - depends on the environment
    raise ImportError("librate.plotting needs matplotlib >= 3.6, a required dependency of librate: reinstall librate") from exc

from .._checks import as_count, as_number
from ..attitude.flexible import FlexibleBody, QuasiStaticResponse
from ..attitude.propagate import AttitudeTrajectory
from ..attitude.srp import FlatPlate
from ..constants import OMEGA_SUN, SUN_SYNODIC_PERIOD
from ..orbits.families import OrbitFamily
from ..orbits.frames import synodic_to_eci
from ..orbits.periodic import PeriodicOrbit
from ..orbits.system import check_system
from ..periodicity.flexible import FrequencyScan
from ..periodicity.maps import periodicity_map
from ..periodicity.solutions import KINDS, AttitudeSolution, check_kinds
from ..periodicity.srp import srp_map, sun_angle, sun_pointing_accelerations, sun_resonance

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "plot_family",
    "plot_period",
    "plot_stability",
    "plot_eci",
    "plot_attitude",
    "plot_residuals",
    "plot_map",
    "plot_solution_families",
    "plot_attitude_motion",
    "plot_sun_motion",
    "plot_sun_resonant",
    "srp_map",
    "plot_srp_map",
    "plot_srp_maps",
    "plot_srp_comparison",
    "sun_pointing_accelerations",
    "plot_sun_pointing",
    "save_figure",
]

_EARTH = dict(marker="o", color="tab:blue", markersize=9, markeredgecolor="k", linestyle="none")
_MOON = dict(marker="o", color="0.6", markersize=6, markeredgecolor="k", linestyle="none")
_LPOINT = dict(marker="x", color="k", markersize=6, linestyle="none")
# Label offsets (points) and alignment, so that L1, the Moon and L2 do not overlap.
_LABEL_OFFSETS = {"Earth": (-6, 6, "right"), "Moon": (0, -13, "center"), "L1": (-4, 5, "right"),
                  "L2": (4, 5, "left"), "L3": (-4, 5, "right")}
_PROJECTIONS = ("xy", "xz", "yz", "3d")
_QUANTITIES = {
    "x0": "$x_0$ (LU)",
    "z0": "$z_0$ (LU)",
    "jacobi": "Jacobi constant $C$ (LU$^2$/TU$^2$)",
}


# --- helpers -----------------------------------------------------------------------------------
def _check_family(family) -> OrbitFamily:
    if not isinstance(family, OrbitFamily):
        raise ValueError(f"invalid argument `family`: must be a librate.OrbitFamily, got {type(family).__name__}")
    return family


def figure_axes(ax, n: int, *, three_d: Sequence[bool] | None = None, figsize=None) -> tuple[Figure, list[Axes]]:
    """The figure and a list of ``n`` Axes: new ones (up to three per row, constrained layout)
    when ``ax`` is None, else the given Axes (one, or a sequence of ``n``)."""
    three_d = list(three_d or [False] * n)
    if ax is None:
        import matplotlib.pyplot as plt

        ncols = min(n, 3)
        nrows = math.ceil(n / ncols)
        fig = plt.figure(figsize=figsize or (5.2 * ncols, 4.8 * nrows), layout="constrained")
        axs = [fig.add_subplot(nrows, ncols, i + 1, projection="3d" if three_d[i] else None) for i in range(n)]
        return fig, axs
    axs = [ax] if isinstance(ax, Axes) else list(ax)
    if len(axs) != n or not all(isinstance(a, Axes) for a in axs):
        raise ValueError(f"invalid argument `ax`: this figure needs {n} matplotlib Axes, got {ax!r}")
    for a, want in zip(axs, three_d):
        if want and a.name != "3d":
            raise ValueError("invalid argument `ax`: a 3-D projection needs Axes created with projection='3d'")
    return axs[0].figure, axs


def _pick(n: int, n_orbits: int | None) -> np.ndarray:
    """Indices of ``n_orbits`` members evenly spread over ``n`` (first and last included)."""
    if n_orbits is None or n_orbits >= n:
        return np.arange(n)
    if isinstance(n_orbits, bool) or not isinstance(n_orbits, (int, np.integer)) or n_orbits < 1:
        raise ValueError(f"invalid argument `n_orbits`: must be an integer >= 1 or None (all members), got {n_orbits!r}")
    return np.round(np.linspace(0, n - 1, int(n_orbits))).astype(int)


def _against(family: OrbitFamily, against: str) -> tuple[np.ndarray, str]:
    if against not in _QUANTITIES:
        raise ValueError(f"invalid argument `against`: must be one of {', '.join(_QUANTITIES)}, got {against!r}")
    q = {"x0": family.x0, "z0": family.z0, "jacobi": family.jacobi}[against]
    return np.asarray(q, dtype=float), _QUANTITIES[against]


def _length_scale(system, units: str) -> tuple[float, str]:
    if units == "LU":
        return 1.0, "LU"
    if units == "km":
        return system.lu_km, "km"
    raise ValueError(f"invalid argument `units`: must be 'LU' or 'km', got {units!r}")


def _time_scale(system, units: str) -> tuple[float, str]:
    if units == "days":
        return system.tu_days, "days"
    if units == "TU":
        return 1.0, "TU"
    raise ValueError(f"invalid argument `units`: must be 'days' or 'TU', got {units!r}")


def _crossings(x: np.ndarray, y: np.ndarray, level: float) -> list[float]:
    """x where the polyline (x, y) crosses y = level (linear interpolation)."""
    out = []
    d = y - level
    for i in range(len(d) - 1):
        if not (np.isfinite(d[i]) and np.isfinite(d[i + 1])):
            continue
        if d[i] == 0:
            out.append(float(x[i]))
        elif d[i] * d[i + 1] < 0:
            w = d[i] / (d[i] - d[i + 1])
            out.append(float(x[i] + w * (x[i + 1] - x[i])))
    if len(d) and d[-1] == 0:
        out.append(float(x[-1]))
    return out


def _resonance_label(orbit: PeriodicOrbit, tol: float = 1e-6) -> str | None:
    """'1:K' when T = 2 pi / K, '1:K Sun' when T = Ts / K (relative tolerance ``tol``)."""
    for base, suffix in ((2 * math.pi, ""), (SUN_SYNODIC_PERIOD, " Sun")):
        k = base / orbit.period
        if round(k) >= 1 and abs(k - round(k)) < tol * k:
            return f"1:{round(k)}{suffix}"
    return None


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
    """
    fam = _check_family(family)
    sys_ = fam.system
    if projection is None:
        projection = ("xy", "xz") if fam.spatial else "xy"
    projs = [projection] if isinstance(projection, str) else list(projection)
    if not projs or any(p not in _PROJECTIONS for p in projs):
        raise ValueError(f"invalid argument `projection`: must be one of {', '.join(_PROJECTIONS)} or a sequence of them, got {projection!r}")
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 2:
        raise ValueError(f"invalid argument `samples`: must be an integer >= 2, got {samples!r}")
    scale, unit = _length_scale(sys_, units)
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
    sel = _pick(len(fam), n_orbits)
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
            marks += [(e, "Earth", _EARTH, "earth"), (m, "Moon", _MOON, "moon")]
        if lpoints:
            lp = sys_.lagrange_points() * scale
            for k in lpoints:
                marks.append((lp[k - 1], f"L{k}", _LPOINT, f"L{k}"))
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
                dx, dy, ha = _LABEL_OFFSETS.get(name, (4, 5, "left"))
                a.annotate(name, (u, v), xytext=(dx, dy), textcoords="offset points", fontsize=8, ha=ha)
            h.set_gid(gid)
        if proj == "3d":
            a.set_xlabel(f"x ({unit})")
            a.set_ylabel(f"y ({unit})")
            a.set_zlabel(f"z ({unit})")
            a.set_box_aspect(np.maximum(np.ptp(allp, axis=0), 1e-3 * np.ptp(allp)))
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
        axs[0].set_title(f"{fam.kind} family, synodic frame ({len(sel)} of {len(fam)} members)")
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
    the Moon (1 - mu). Returns the Figure.
    """
    fam = _check_family(family)
    sys_ = fam.system
    tscale, tunit = _time_scale(sys_, units)
    x, xlabel = _against(fam, against)
    res, sres = list(resonances), list(sun_resonances)
    if not all(isinstance(k, (int, np.integer)) and not isinstance(k, bool) and k >= 1 for k in res + sres):
        raise ValueError(f"invalid argument: resonance orders must be integers >= 1, got {tuple(res)} and {tuple(sres)}")
    res, sres = [int(k) for k in res], [int(k) for k in sres]
    created = ax is None
    fig, (a,) = figure_axes(ax, 1, figsize=(7.0, 5.0))
    period = fam.period * tscale
    (line,) = a.plot(x, period, color="k", linewidth=1.6, label=f"{fam.kind} period")
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
            xs = _crossings(x, period, level)
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
    a.set_ylim(bottom=0)
    a.grid(True, linewidth=0.3, alpha=0.5)
    a.legend(loc="lower left", fontsize=7.5)
    if created:
        a.set_title(f"{fam.kind} family: period and resonances")
    return fig


# --- stability (Fig. 5) ------------------------------------------------------------------------
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
    ``"stability-1"`` (out-of-plane), their y data equal to ``family.stability_indices.real``.
    A member is linearly stable when both are real with |nu| <= 1: the band -1 <= nu <= 1 is
    shaded (``band``). For a stable pair lambda = exp(+-i phi), nu = cos phi = Re(lambda), so
    the curves are the real parts of the eigenvalues the thesis plots. ``bifurcations``: a
    vertical line (``gid="bifurcation"``) and a label at each crossing of +1 or -1 listed in
    ``family.bifurcations``. ``imag`` adds the imaginary parts dashed (``"stability-imag-j"``).
    ``yscale``: ``"linear"``, ``"symlog"`` or None (symlog when some |nu| exceeds 10).
    Returns the Figure.
    """
    fam = _check_family(family)
    x, xlabel = _against(fam, against)
    nu = np.asarray(fam.stability_indices)
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
            a.text(xb, 0.02 if n % 2 == 0 else 0.98, f" {b['index']} $\\nu = {b['level']:+g}$ at $x_0$ = {b['x0']:.4f} ",
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
        a.set_title(f"{fam.kind} family: stability indices")
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
    """
    if isinstance(orbits, PeriodicOrbit):
        orbits = [orbits]
    orbits = list(orbits)
    if not orbits or not all(isinstance(o, PeriodicOrbit) for o in orbits):
        raise ValueError("invalid argument `orbits`: must be a librate.PeriodicOrbit or a non-empty sequence of them")
    if n_periods is not None and not (isinstance(n_periods, (int, float, np.integer, np.floating)) and math.isfinite(n_periods) and n_periods > 0):
        raise ValueError(f"invalid argument `n_periods`: must be a number > 0 or None, got {n_periods!r}")
    if isinstance(samples_per_period, bool) or not isinstance(samples_per_period, (int, np.integer)) or samples_per_period < 8:
        raise ValueError(f"invalid argument `samples_per_period`: must be an integer >= 8, got {samples_per_period!r}")
    if labels is not None and len(labels) != len(orbits):
        raise ValueError(f"invalid argument `labels`: need one per orbit ({len(orbits)}), got {len(labels)}")
    if labels is None:
        labels = [_resonance_label(o) or f"$x_0$ = {o.x0:.4f}, T = {o.period_days:.2f} d" for o in orbits]
    sys_ = orbits[0].system
    scale, unit = _length_scale(sys_, units)
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
        (e,) = a.plot([0.0], [0.0], label="Earth", **_EARTH)
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


# --- periodic attitude motions: residuals, maps, families, motions (Figs. 23-31) --------------
_KIND_MARKER = {"periodic": "o", "half-turn": "D"}
# Solutions are coloured by N (the same N, the same colour in every figure), |N| > 3 in one grey;
# blue and orange are left to the residuals Dwz and Dphi (curves in Fig. 23, contours in Fig. 24).
_N_COLORS = {0: "tab:green", 1: "tab:red", -1: "tab:purple", 2: "tab:brown", -2: "tab:pink", 3: "tab:olive", -3: "tab:cyan"}
_N_OTHER = "0.55"
_DWZ_COLOR, _DPHI_COLOR = "tab:blue", "tab:orange"
_KZ_STYLES = ("-", "--", ":", "-.")
_ORBIT_AXES = {"period": "orbit period $T$ (days)", "x0": "orbit $x_0$ (LU)"}


def _n_color(n: int) -> str:
    """The colour of N (|N| <= 3 each its own, the others one grey)."""
    return _N_COLORS.get(int(n), _N_OTHER)


def _rate_axis(rate: str, *, initial: bool = True) -> tuple[float, str]:
    """(offset subtracted from inertial rates, axis label) for ``rate="relative"`` (phidot =
    wz - 1, the quantity on the thesis figures' axes) or ``"inertial"`` (wz)."""
    t = "(0)" if initial else "(t)"
    what = "initial rate" if initial else "angular velocity"
    if rate == "relative":
        return 1.0, f"{what} $\\dot\\varphi{t} = \\omega_z{t} - 1$, relative to the synodic frame (1/TU)"
    if rate == "inertial":
        return 0.0, f"{what} $\\omega_z{t}$, inertial (1/TU)"
    raise ValueError(f"invalid argument `rate`: must be 'relative' (wz - 1, the thesis figures' axis) or 'inertial', got {rate!r}")


def _check_map(ds, name: str = "ds"):
    names = getattr(ds, "variables", None)
    if not hasattr(ds, "data_vars") or names is None or not all(v in names for v in ("dwz", "dphi", "wz0", "x0", "period_days", "kz")):
        raise ValueError(f"invalid argument `{name}`: must be an xarray Dataset from librate.periodicity_map, got {type(ds).__name__}")
    return ds


def _index(value, size: int, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not -size <= value < size:
        raise ValueError(f"invalid argument `{name}`: must be an integer index below {size}, got {value!r}")
    return int(value) % size


def _orbit_axis(ds, against: str) -> tuple[np.ndarray, str]:
    if against not in _ORBIT_AXES:
        raise ValueError(f"invalid argument `against`: must be 'period' (days) or 'x0', got {against!r}")
    return np.asarray(ds["period_days" if against == "period" else "x0"].values, dtype=float), _ORBIT_AXES[against]


def _solution_table(ds) -> dict[str, np.ndarray] | None:
    """The ``sol_*`` variables of a map as arrays (None when it was computed with solve=False),
    ``orbit`` turned into the position along the Dataset's orbit dimension (solutions of orbits
    not in it, after ``ds.isel(orbit=...)``, are dropped)."""
    if "sol_wz0" not in ds.variables:
        return None
    tab = {k: np.asarray(ds[f"sol_{k}"].values) for k in ("orbit", "kz", "wz0", "n", "kind", "stable")}
    labels = np.asarray(ds["orbit"].values)
    pos = {int(v): i for i, v in enumerate(labels)}
    where = np.array([pos.get(int(o), -1) for o in tab["orbit"]], dtype=np.int64)
    keep = where >= 0
    tab = {k: v[keep] for k, v in tab.items()}
    tab["orbit"] = where[keep]
    return tab


def _kz_mask(tab, kz: float) -> np.ndarray:
    return np.abs(tab["kz"].astype(float) - float(kz)) <= 1e-12 * max(1.0, abs(float(kz)))


def _draw_solutions(a, x, y, n, kind, stable, *, markersize: float = 6.5) -> None:
    """Markers for solutions: colour by N, circle periodic / diamond half-turn, filled when
    linearly stable, hollow when not; one Line2D per group, all with ``gid="solutions"``."""
    for k in KINDS:
        for nn in sorted(set(n[kind == k].tolist()), reverse=True):
            for st in (True, False):
                m = (kind == k) & (n == nn) & (stable == st)
                if not m.any():
                    continue
                c = _n_color(nn)
                (h,) = a.plot(x[m], y[m], linestyle="none", marker=_KIND_MARKER[k], color=c, markeredgecolor=c,
                              markerfacecolor=c if st else "none", markeredgewidth=1.4, markersize=markersize, zorder=5,
                              label="_nolegend_")
                h.set_gid("solutions")


def _solution_legend(n, kind, stable) -> list:
    """Legend proxies explaining the solution markers."""
    out = []
    ns = sorted(set(np.asarray(n).tolist()), reverse=True)
    others = [nn for nn in ns if nn not in _N_COLORS]
    for nn in ns:
        if nn in _N_COLORS or len(others) == 1:
            out.append(Line2D([], [], linestyle="none", marker="s", color=_n_color(nn), markersize=7, label=f"$N$ = {nn:g}"))
    if len(others) > 1:
        out.append(Line2D([], [], linestyle="none", marker="s", color=_N_OTHER, markersize=7,
                          label=f"other $N$ ({min(others)} ... {max(others)})"))
    gray = dict(linestyle="none", color="0.3", markeredgecolor="0.3", markersize=6.5, markeredgewidth=1.4)
    if "periodic" in kind:
        out.append(Line2D([], [], marker="o", markerfacecolor="0.8", label="periodic, $\\varphi(T) = \\varphi_0 + 2\\pi N$", **gray))
    if "half-turn" in kind:
        out.append(Line2D([], [], marker="D", markerfacecolor="0.8",
                          label="half-turn, $\\varphi(T) = \\varphi_0 + 2\\pi N + \\pi$", **gray))
    if np.any(stable):
        out.append(Line2D([], [], marker="o", label="filled: linearly stable ($|\\mathrm{tr}\\,M| < 2$)", **gray))
    if not np.all(stable):
        out.append(Line2D([], [], marker="o", markerfacecolor="none", label="hollow: unstable", **gray))
    return out


def _set_gid(cs, gid: str) -> None:
    if hasattr(cs, "set_gid"):  # matplotlib >= 3.8: a ContourSet is one Collection
        cs.set_gid(gid)
    else:  # pragma: no cover - matplotlib < 3.8
        for c in cs.collections:
            c.set_gid(gid)


def _break_wraps(x: np.ndarray, y: np.ndarray, jump: float = math.pi) -> tuple[np.ndarray, np.ndarray]:
    """(x, y) with a NaN point inserted where y jumps by more than ``jump`` (the +-pi wrap of
    Dphi), so that no vertical line joins the two sides; the finite points are (x, y) unchanged."""
    cut = np.flatnonzero(np.abs(np.diff(y)) > jump) + 1
    return np.insert(np.asarray(x, dtype=float), cut, np.nan), np.insert(np.asarray(y, dtype=float), cut, np.nan)


def plot_residuals(
    orbit_or_ds,
    ax=None,
    *,
    kz: float | None = None,
    wz0=None,
    orbit_index: int | None = None,
    phi0: float = 0.0,
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

    ``orbit_or_ds``: a Dataset from :func:`librate.periodicity_map` (``orbit_index`` picks the
    orbit when it holds several, ``kz`` the Kz value when it holds several), or a planar
    :class:`~librate.PeriodicOrbit` with ``kz`` (a number) and ``wz0`` (the grid of INERTIAL
    initial rates, increasing): the map is then computed here (``phi0``: the initial angle).
    ``rate``: the horizontal axis, ``"relative"`` (default: phidot(0) = wz(0) - 1, relative to
    the synodic frame, what the thesis figures plot under the label wz(0)) or ``"inertial"``
    (wz(0)); the axis label says which. Returns the Figure.
    """
    offset, xlabel = _rate_axis(rate)
    kinds = check_kinds(kinds)
    if isinstance(orbit_or_ds, PeriodicOrbit):
        if kz is None:
            raise ValueError("invalid argument `kz`: a number in [-1, 1] is needed with an orbit")
        if wz0 is None:
            raise ValueError("invalid argument `wz0`: the inertial initial rates to scan are needed with an orbit")
        if orbit_index not in (None, 0):
            raise ValueError(f"invalid argument `orbit_index`: one orbit was given, got {orbit_index!r}")
        ds = periodicity_map(orbit_or_ds, kz=kz, wz0=wz0, phi0=phi0, solve=bool(solutions))
        i = j = 0
    else:
        ds = _check_map(orbit_or_ds, "orbit_or_ds")
        if wz0 is not None:
            raise ValueError("invalid argument `wz0`: rates are given only with an orbit (a Dataset has its own)")
        norb = ds.sizes["orbit"]
        if orbit_index is None and norb != 1:
            raise ValueError(f"invalid argument `orbit_index`: the Dataset holds {norb} orbits, pick one")
        i = _index(0 if orbit_index is None else orbit_index, norb, "orbit_index")
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
    (h,) = a.plot(x, dwz, color=_DWZ_COLOR, linewidth=1.4, label="$\\Delta\\omega_z = \\omega_z(T) - \\omega_z(0)$ (1/TU)")
    h.set_gid("residual-dwz")
    (h,) = a.plot(*_break_wraps(x, dphi), color=_DPHI_COLOR, linewidth=1.4,
                  label="$\\Delta\\varphi = \\varphi(T) - \\varphi_0$, wrapped to $(-\\pi, \\pi]$ (rad)")
    h.set_gid("residual-dphi")
    handles = list(a.get_legend_handles_labels()[0])
    tab = _solution_table(ds) if solutions else None
    if tab is not None:
        m = (tab["orbit"] == i) & _kz_mask(tab, kz_value) & np.isin(tab["kind"], kinds)
        if m.any():
            xs = tab["wz0"][m] - offset
            _draw_solutions(a, xs, np.zeros_like(xs), tab["n"][m], tab["kind"][m], tab["stable"][m])
            if annotate:
                for xv, nn, k in zip(xs, tab["n"][m], tab["kind"][m]):
                    txt = f"$N$ = {nn:g}" + (", half-turn" if k == "half-turn" else "")
                    a.annotate(txt, (xv, 0.0), xytext=(0, 9), textcoords="offset points", ha="center", va="bottom",
                               fontsize=7.5, color=_n_color(nn), rotation=90)
            handles += _solution_legend(tab["n"][m], tab["kind"][m], tab["stable"][m])
    a.set_xlabel(xlabel)
    a.set_ylabel("residual after one period: $\\Delta\\omega_z$ (1/TU), $\\Delta\\varphi$ (rad)")
    a.set_xlim(x[0], x[-1])
    a.grid(True, linewidth=0.3, alpha=0.5)
    a.legend(handles=handles, loc="best", fontsize=7.5)
    if created:
        a.set_title(f"residuals after one period: orbit T = {float(ds['period_days'].values[i]):.2f} d "
                    f"($x_0$ = {float(ds['x0'].values[i]):.4f}), $K_z$ = {kz_value:g}")
    return fig


def _map_contours(a, x, y, dwz, phi_t, dphi, phi0: float, half_turn_contours: bool) -> list:
    """The zero contours of a map on the grid (x columns, y rows): Dwz = 0 (``gid="contour-dwz"``)
    and Dphi = 0 on the unwrapped phi(t) at the levels phi0 + 2 pi k (``gid="contour-dphi"``; with
    ``phi_t`` None, on sin(Dphi) where cos(Dphi) > 0), with ``half_turn_contours`` also Dphi = pi
    (``gid="contour-dphi-half"``, dotted). Arrays are (rate, x). Returns legend proxies."""
    if np.isfinite(dwz).any() and np.nanmin(dwz) < 0 < np.nanmax(dwz):
        cs = a.contour(x, y, dwz, levels=[0.0], colors=_DWZ_COLOR, linewidths=1.1)
        _set_gid(cs, "contour-dwz")
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
                cs = a.contour(x, y, p, levels=levels, colors=_DPHI_COLOR, **style)
                _set_gid(cs, gid_)
    else:
        s = np.where(np.cos(dphi) > 0, np.sin(dphi), np.nan)
        if np.isfinite(s).any() and np.nanmin(s) < 0 < np.nanmax(s):
            cs = a.contour(x, y, s, levels=[0.0], colors=_DPHI_COLOR, linewidths=1.1)
            _set_gid(cs, "contour-dphi")
    handles = [Line2D([], [], color=_DWZ_COLOR, linewidth=1.1, label="$\\Delta\\omega_z = 0$"),
               Line2D([], [], color=_DPHI_COLOR, linewidth=1.1, label="$\\Delta\\varphi = 0$")]
    if half_turn_contours:
        handles.append(Line2D([], [], color=_DPHI_COLOR, linewidth=0.7, linestyle=":", label="$\\Delta\\varphi = \\pi$"))
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
    """
    ds = _check_map(ds)
    j = _index(kz_index, ds.sizes["kz"], "kz_index")
    xv, xlabel = _orbit_axis(ds, against)
    offset, ylabel = _rate_axis(rate)
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
    handles = _map_contours(a, xv, y, dwz, phi_t, dphi, phi0, half_turn_contours)
    tab = _solution_table(ds) if solutions else None
    if tab is not None:
        m = _kz_mask(tab, kz_value) & np.isin(tab["kind"], kinds)
        if m.any():
            _draw_solutions(a, xv[tab["orbit"][m]], tab["wz0"][m] - offset, tab["n"][m], tab["kind"][m], tab["stable"][m],
                            markersize=5.0)
            handles += _solution_legend(tab["n"][m], tab["kind"][m], tab["stable"][m])
    a.set_xlim(np.nanmin(xv), np.nanmax(xv))
    a.set_ylim(y[0], y[-1])
    a.set_xlabel(xlabel)
    a.set_ylabel(ylabel)
    a.grid(True, linewidth=0.3, alpha=0.5)
    if legend:
        a.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7.5, borderaxespad=0.0)
    if created:
        fam = ds.attrs.get("family", "") or "orbit"
        a.set_title(f"attitude periodicity map, {fam.upper() if fam == 'dro' else fam} family, $K_z$ = {kz_value:g}")
    return fig


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
    the Dataset), ``kinds``: ``"periodic"`` (default) and/or ``"half-turn"``. ``separate``: one
    panel per (kind, N), N descending, Kz by colour (``ax``: that many Axes); else a single
    panel, N by colour and Kz by line style. ``against``: ``"period"`` (days) or ``"x0"``;
    ``rate``: ``"relative"`` (phidot(0) = wz(0) - 1, default) or ``"inertial"``. Returns the
    Figure.
    """
    ds = _check_map(ds)
    tab = _solution_table(ds)
    if tab is None:
        raise ValueError("invalid argument `ds`: the map holds no solutions (compute it with solve=True)")
    kinds = check_kinds(kinds)
    xv, xlabel = _orbit_axis(ds, against)
    offset, ylabel = _rate_axis(rate)
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
    kz_colors = (["k"] if kzs.size == 1 else
                 [matplotlib.colormaps["viridis"](v) for v in np.linspace(0.0, 0.85, kzs.size)])

    created = ax is None
    npanels = len(groups) if separate else 1
    fig, axs = figure_axes(ax, npanels, figsize=(7.4, 5.2) if npanels == 1 else None)
    for g, (kind, nn) in enumerate(groups):
        a = axs[g] if separate else axs[0]
        drawn = False
        for jk, kz in enumerate(kzs):
            sel = np.flatnonzero((tab["kind"] == kind) & (tab["n"] == nn) & _kz_mask(tab, kz))
            if not sel.size:
                continue
            color = kz_colors[jk] if separate else _n_color(nn)
            style = "-" if separate else _KZ_STYLES[jk % len(_KZ_STYLES)]
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
    """
    offset, ylabel = _rate_axis(rate, initial=False)
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
        color = _n_color(s.n) if by_n else cycle[i % len(cycle)]
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


# --- solar radiation pressure (thesis ch. 4, Figs. 33-41) ---------------------------------------
_SUN_COLOR = "#f2a900"
_SRP_COLOR, _GRAVITY_COLOR = "tab:red", "0.15"


def _primaries(a, system, scale: float = 1.0) -> None:
    e, m = system.primary_positions() * scale
    for pos, name, style, gid in ((e, "Earth", _EARTH, "earth"), (m, "Moon", _MOON, "moon")):
        (h,) = a.plot([pos[0]], [pos[1]], zorder=4, **style)
        h.set_gid(gid)
        dx, dy, ha = _LABEL_OFFSETS[name]
        a.annotate(name, (pos[0], pos[1]), xytext=(dx, dy), textcoords="offset points", fontsize=8, ha=ha)


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
    """
    sys_ = check_system(system)
    theta_sun0 = as_number(theta_sun0, "theta_sun0")
    n_periods = as_number(n_periods, "n_periods", positive=True)
    n_directions = as_count(n_directions, "n_directions", 1)
    tscale, tunit = _time_scale(sys_, units)
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
    (h,) = a_geo.plot(radius * np.cos(th), radius * np.sin(th), color=_SUN_COLOR, linewidth=1.0, linestyle="--", zorder=1,
                      label=f"Sun direction over one apparent solar period $T_s$ = {ts * tscale:.2f} {tname}")
    h.set_gid("sun-path")
    for f in (0.06, 0.31, 0.56, 0.81):  # arrow heads: the clockwise sense
        t1, t2 = f * ts, (f + 0.02) * ts
        p1, p2 = [radius * np.array([math.cos(v), math.sin(v)]) for v in sun_angle(theta_sun0, [t1, t2])]
        arr = a_geo.annotate("", xy=p2, xytext=p1, arrowprops=dict(arrowstyle="-|>", color=_SUN_COLOR, linewidth=1.2,
                                                                  mutation_scale=14))
        arr.set_gid("sun-path-arrow")
    cm = matplotlib.colormaps["plasma"]
    for k in range(n_directions):
        tk = k * ts / n_directions
        ang = float(sun_angle(theta_sun0, tk))
        c, s = math.cos(ang), math.sin(ang)
        color = cm(0.85 * k / n_directions)
        (h,) = a_geo.plot([0.0, radius * c], [0.0, radius * s], color=color, linewidth=2.0 if k == 0 else 1.0, zorder=2,
                          label=f"Sun direction at $t$ = 0 ($\\theta_{{s0}}$ = {math.degrees(theta_sun0):.4g} deg)" if k == 0 else "_nolegend_")
        h.set_gid("sun-direction")
        (h,) = a_geo.plot([radius * c], [radius * s], marker="o", markersize=11 if k == 0 else 8, color=_SUN_COLOR,
                          markeredgecolor=color, markeredgewidth=1.5, linestyle="none", zorder=4)
        h.set_gid("sun")
        a_geo.annotate(f"{tk * tscale:.1f} {tname}", (radius * c, radius * s), xytext=(14 * c, 14 * s), textcoords="offset points",
                       ha="center", va="center", fontsize=7.5, color="0.2")
    _primaries(a_geo, sys_)
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
    (h,) = a_ang.plot(t * tscale, deg, color=_SUN_COLOR, linewidth=1.8,
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
    """
    fam = _check_family(family)
    try:
        ks = [ks] if isinstance(ks, (int, np.integer)) else list(ks)
    except TypeError:
        ks = None
    if not ks or not all(isinstance(k, (int, np.integer)) and not isinstance(k, bool) and k >= 1 for k in ks):
        raise ValueError(f"invalid argument `ks`: must be a non-empty sequence of integers >= 1, got {ks!r}")
    samples = as_count(samples, "samples", 2)
    sys_ = fam.system
    scale, unit = _length_scale(sys_, units)
    found, missing = [], []
    for k in ks:
        try:
            found.append((int(k), fam.resonant(int(k), "sun")))
        except ValueError:
            missing.append(int(k))
    if not found:
        raise ValueError(f"invalid argument `ks`: no Sun-resonant member 1:K (T = Ts/K) for K in {tuple(ks)} lies in the "
                         f"{fam.kind} family's period range [{fam.period_days.min():.2f}, {fam.period_days.max():.2f}] d")
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
        for pos, name, style, gid in ((e, "Earth", _EARTH, "earth"), (m, "Moon", _MOON, "moon")):
            near = bool(np.all((pos[:2] >= lo - pad) & (pos[:2] <= hi + pad)))
            if near:
                (h,) = a.plot([pos[0]], [pos[1]], zorder=4, **style)
                dx, dy, ha = _LABEL_OFFSETS[name]
                a.annotate(name, (pos[0], pos[1]), xytext=(dx, dy), textcoords="offset points", fontsize=8, ha=ha)
            else:  # drawn, but kept out of the data limits: an arrow at the edge points to it
                h = a.add_artist(Line2D([pos[0]], [pos[1]], **style))
                a.annotate(f"$\\leftarrow$ {name} at $x$ = {pos[0]:.4g} {unit}" if pos[0] < lo[0] else f"{name} at $x$ = {pos[0]:.4g} {unit} $\\rightarrow$",
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
        a.set_title(f"Sun-resonant {fam.kind.upper() if fam.kind == 'dro' else fam.kind} orbits ($T = T_s/K$, $T_s$ = {SUN_SYNODIC_PERIOD * sys_.tu_days:.2f} d), synodic frame")
    return fig


# --- periodicity maps over (eps, rate) ----------------------------------------------------------
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
    legend when outside the map's range), e.g. the plate of a given A/m. ``rate``: ``"relative"`` (phidot(0) = wz(0) - 1, default) or ``"inertial"``.
    ``kinds``: the solutions shown. Returns the Figure.
    """
    ds = _check_srp_map(ds)
    offset, ylabel = _rate_axis(rate)
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
    handles = _map_contours(a, x, y, np.asarray(ds["dwz"].values, dtype=float).T, np.asarray(ds["phi_T"].values, dtype=float).T,
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
            (h,) = a.plot(ds["path_eps"].values[sel], ds["path_wz0"].values[sel] - offset, color=_n_color(nn),
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
            _draw_solutions(a, np.asarray(ds["sol_eps"].values)[m], np.asarray(ds["sol_wz0"].values)[m] - offset, n, kind[m], st,
                            markersize=markersize)
            handles += _solution_legend(n, kind[m], st)
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
    """
    try:
        maps = list(maps)
    except TypeError:
        maps = []
    if not maps:
        raise ValueError("invalid argument `maps`: must be a non-empty sequence of map Datasets (srp_map or periodicity_map)")
    for i, ds in enumerate(maps):
        if getattr(ds, "attrs", {}).get("map") != "srp-eps":
            _check_map(ds, "maps")
    if titles is not None and (isinstance(titles, str) or len(titles) != len(maps)):
        raise ValueError(f"invalid argument `titles`: need one title per map ({len(maps)}), got {titles!r}")
    params = [_map_parameters(ds) for ds in maps]
    names = [k for k, _ in _MAP_PARAMETERS if all(k in p for p in params)]
    varying = [k for k in names if len({round(p[k], 12) for p in params}) > 1]
    common = [k for k in names if k not in varying]
    label = dict(_MAP_PARAMETERS)
    created = ax is None
    fig, axs = figure_axes(ax, len(maps), figsize=(8.6, 5.8) if len(maps) == 1 else (5.0 * min(len(maps), 3) + 2.6, 5.4 * math.ceil(len(maps) / 3)))
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
    offset, ylabel = _rate_axis(rate, initial=False)
    kdeg = 180.0 / math.pi if degrees else 1.0
    T = s.orbit.period
    t = np.linspace(0.0, n * T, max(2, int(math.ceil(samples * n)) + 1))
    created = ax is None
    fig, (a_ang, a_rate) = figure_axes(ax, 2, figsize=(12.4, 4.8))
    for key, sol, color, ls in (("gravity", g, _GRAVITY_COLOR, "--"), ("srp", s, _SRP_COLOR, "-")):
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
    """
    sys_ = check_system(system)
    if not isinstance(orbit, PeriodicOrbit):
        raise ValueError(f"invalid argument `orbit`: must be a librate.PeriodicOrbit, got {type(orbit).__name__}")
    if n_periods is None:
        n_periods = max(1, math.ceil(SUN_SYNODIC_PERIOD / orbit.period - 1e-6))
    n_periods = as_number(n_periods, "n_periods", positive=True)
    samples = as_count(samples, "samples", 2)
    tscale, tunit = _time_scale(sys_, units)
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
                  label=f"gravity gradient $\\frac{{3}}{{2}} K_z (S\\cos 2\\varphi - C\\sin 2\\varphi)$, max |.| = {np.max(np.abs(gg)):.3g}")
    h.set_gid("gravity-gradient")
    (h,) = a.plot(t * tscale, srp, color=_SRP_COLOR, linewidth=1.4, label=f"SRP ({what}), max |.| = {np.max(np.abs(srp)):.3g}")
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


# --- output --------------------------------------------------------------------------------------
def save_figure(fig, path, *, dpi: int = 150, close: bool = False, **kwargs) -> Path:
    """Write ``fig`` (a Figure, or an Axes: its figure) to ``path`` (format from the suffix:
    .png, .pdf, .svg, ...), creating missing directories; ``bbox_inches="tight"`` unless given
    in ``kwargs`` (passed to ``Figure.savefig``). ``close`` closes it in pyplot afterwards.
    Returns the path."""
    if isinstance(fig, Axes):
        fig = fig.figure
    if not hasattr(fig, "savefig"):
        raise ValueError(f"invalid argument `fig`: must be a matplotlib Figure or Axes, got {type(fig).__name__}")
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    kwargs.setdefault("bbox_inches", "tight")
    fig.savefig(p, dpi=dpi, **kwargs)
    if close:
        import matplotlib.pyplot as plt

        plt.close(fig)
    return p


# --- flexible spacecraft (thesis ch. 5, Figs. 42-46) --------------------------------------------
# plot_flexible_body: the lumped model's schematic from its parameters (Figs. 42-43);
# plot_flexible_coordinate: a flexible coordinate against the closed form (Fig. 44);
# plot_flexible_response: structural response and body rate with lowered frequencies (Figs. 45-46);
# plot_frequency_scan: quasi-static amplification and attitude departure against frequency.
def _check_flexible_body(body):
    if not isinstance(body, FlexibleBody):
        raise ValueError(f"invalid argument `body`: must be a librate.FlexibleBody, got {type(body).__name__}")
    return body


def _time_axis(t, period):
    if period is None:
        return np.asarray(t), "t (TU)"
    if not (isinstance(period, (int, float, np.floating, np.integer)) and math.isfinite(period) and period > 0):
        raise ValueError(f"invalid argument `period`: must be a number > 0 or None, got {period!r}")
    return np.asarray(t) / period, "revolutions (-)"


def _indices(n, index):
    if index is None:
        return list(range(n))
    idx = [index] if isinstance(index, (int, np.integer)) else list(index)
    if not idx or any(isinstance(i, bool) or not isinstance(i, (int, np.integer)) or not 0 <= i < n for i in idx):
        raise ValueError(f"invalid argument `index`: must be appendage indices in [0, {n}), got {index!r}")
    return [int(i) for i in idx]


def _spring(p0, p1, coils=6, width=0.18):
    """Zigzag from p0 to p1 (width relative to the length)."""
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    d = p1 - p0
    length = float(np.hypot(*d))
    u = d / length
    nrm = np.array([-u[1], u[0]])
    s = np.linspace(0.15, 0.85, 2 * coils + 1)
    pts = [p0, p0 + 0.15 * d]
    for k, sk in enumerate(s[1:-1]):
        pts.append(p0 + sk * d + (1 if k % 2 == 0 else -1) * width * length * nrm)
    pts += [p0 + 0.85 * d, p1]
    return np.array(pts)


def plot_flexible_body(body, ax=None, *, annotate: bool = True, deflection=None, scale: float | None = None) -> Figure:
    """The lumped-parameter model drawn from its parameters (thesis Figs. 42-43), body axes, m.

    The hub is a rectangle with the hub's mass and in-plane second moments (half-widths
    sqrt(3 Q / m0)) at its centre (``gid="hub"``); a rigid arm runs from the hub centre to each
    mass's rest position b_j (``gid="arm-j"``), which ends in a rail along t_j where a spring
    (``gid="spring-j"``) and, when c_j > 0, a dashpot (``gid="damper-j"``) hold the mass
    (``gid="mass-j"``, area proportional to m_j); an arrow shows the positive deflection
    direction t_j (``gid="direction-j"``). The system's centre of mass is the origin
    (``gid="cm"``), with the body axes (``gid="axes"``). ``annotate`` numbers the masses and lists
    name, mass, clamped frequency and damping ratio in a table (``gid="table"``). ``deflection``:
    q (n,) in m to draw the deformed shape (magnified by ``scale``, default so that the largest
    deflection is a tenth of the largest arm; ``gid="deformed-j"``). Returns the Figure.
    """
    from matplotlib.patches import FancyArrow, Rectangle

    b = _check_flexible_body(body)
    n = b.n
    q = None
    if deflection is not None:
        q = np.asarray(deflection, dtype=float).ravel()
        if q.shape != (n,) or not np.all(np.isfinite(q)):
            raise ValueError(f"invalid argument `deflection`: need {n} finite deflections (m), got {deflection!r}")
    if scale is not None and not (isinstance(scale, (int, float, np.floating, np.integer)) and math.isfinite(scale) and scale > 0):
        raise ValueError(f"invalid argument `scale`: must be a number > 0 or None, got {scale!r}")
    fig, (a,) = figure_axes(ax, 1, figsize=(8.0, 6.0))
    reach = max([math.hypot(*ap.position) for ap in b.appendages] + [1.0])
    hub = b.hub
    m0 = float(hub.mass_kg)
    qxx = max(0.5 * (hub.iy + hub.iz - hub.ix), 0.0)
    qyy = max(0.5 * (hub.ix + hub.iz - hub.iy), 0.0)
    hx, hy = math.sqrt(3 * qxx / m0), math.sqrt(3 * qyy / m0)
    hp = np.array(b.hub_position)
    rect = Rectangle((hp[0] - hx, hp[1] - hy), 2 * hx, 2 * hy, facecolor="0.88", edgecolor="0.3", linewidth=1.2, zorder=1)
    rect.set_gid("hub")
    a.add_patch(rect)
    mmax = max([ap.mass for ap in b.appendages] + [1.0])
    rail = 0.09 * reach
    if q is not None and scale is None:
        qmax = float(np.max(np.abs(q))) if n else 0.0
        scale = 0.1 * reach / qmax if qmax > 0 else 1.0
    pts_all = [hp + [hx, hy], hp - [hx, hy]]
    for j, ap in enumerate(b.appendages):
        bj, tj = np.array(ap.position), np.array(ap.direction)
        (arm,) = a.plot([hp[0], bj[0]], [hp[1], bj[1]], color="0.35", linewidth=2.2, solid_capstyle="round", zorder=2)
        arm.set_gid(f"arm-{j}")
        (rl,) = a.plot([bj[0] - rail * tj[0], bj[0] + rail * tj[0]], [bj[1] - rail * tj[1], bj[1] + rail * tj[1]],
                       color="0.35", linewidth=1.0, zorder=2)
        rl.set_gid(f"arm-{j}")
        radial = bj / np.hypot(*bj)
        lift = 0.035 * reach * radial  # spring and damper drawn beside the rail
        z = _spring(bj - rail * tj + lift, bj + lift)
        (sp,) = a.plot(z[:, 0], z[:, 1], color="tab:blue", linewidth=1.0, zorder=3)
        sp.set_gid(f"spring-{j}")
        if ap.damping > 0:
            p0, p1 = bj + rail * tj + lift, bj + lift
            w = 0.02 * reach * radial
            c0 = p0 + 0.3 * (p1 - p0)
            c1 = p0 + 0.7 * (p1 - p0)
            cyl = np.array([c0 + w, c1 + w, c1 - w, c0 - w])
            piston = p0 + 0.55 * (p1 - p0)
            (d1,) = a.plot([p0[0], c1[0]], [p0[1], c1[1]], color="tab:purple", linewidth=0.9, zorder=3)
            (d2,) = a.plot(cyl[:, 0], cyl[:, 1], color="tab:purple", linewidth=0.9, zorder=3)
            (d3,) = a.plot([piston[0] + 0.7 * w[0], piston[0] - 0.7 * w[0], piston[0], p1[0]],
                           [piston[1] + 0.7 * w[1], piston[1] - 0.7 * w[1], piston[1], p1[1]], color="tab:purple", linewidth=0.9, zorder=3)
            for h in (d1, d2, d3):
                h.set_gid(f"damper-{j}")
        ms = math.sqrt(40 + 260 * math.sqrt(ap.mass / mmax))
        (mk,) = a.plot([bj[0]], [bj[1]], "o", markersize=ms, color="tab:orange", markeredgecolor="k", zorder=4)
        mk.set_gid(f"mass-{j}")
        base = bj - 0.06 * reach * radial
        arrow = FancyArrow(base[0], base[1], 0.08 * reach * tj[0], 0.08 * reach * tj[1], width=0.004 * reach, head_width=0.018 * reach,
                           color="tab:red", length_includes_head=True, zorder=5)
        arrow.set_gid(f"direction-{j}")
        a.add_patch(arrow)
        if annotate:
            a.annotate(str(j + 1), bj, xytext=(16 * radial[0], 16 * radial[1]), textcoords="offset points", fontsize=9,
                       ha="center", va="center", fontweight="bold")
        if q is not None:
            pd = bj + scale * q[j] * tj
            (dm,) = a.plot([hp[0], pd[0]], [hp[1], pd[1]], color="tab:green", linestyle="--", linewidth=1.0, zorder=3)
            (dd,) = a.plot([pd[0]], [pd[1]], "o", markersize=0.8 * ms, markerfacecolor="none", markeredgecolor="tab:green", zorder=4)
            dm.set_gid(f"deformed-{j}")
            dd.set_gid(f"deformed-{j}")
            pts_all.append(pd)
        pts_all += [bj + 0.12 * reach * radial, bj - rail * tj, bj + rail * tj]
    (cm,) = a.plot([0.0], [0.0], marker="+", color="k", markersize=12, markeredgewidth=1.5, linestyle="none", zorder=6)
    cm.set_gid("cm")
    ax_len = 0.16 * reach
    for vec, name in (((1.0, 0.0), "$x_B$"), ((0.0, 1.0), "$y_B$")):
        arr = FancyArrow(0.0, 0.0, ax_len * vec[0], ax_len * vec[1], width=0.002 * reach, head_width=0.014 * reach, color="k",
                         length_includes_head=True, zorder=6)
        arr.set_gid("axes")
        a.add_patch(arr)
        a.annotate(name, (ax_len * vec[0], ax_len * vec[1]), xytext=(3, 3), textcoords="offset points", fontsize=8)
    pts = np.array(pts_all)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    pad = 0.08 * np.max(hi - lo)
    a.set_xlim(lo[0] - pad, hi[0] + pad)
    a.set_ylim(lo[1] - pad, hi[1] + pad)
    a.set_aspect("equal", adjustable="box")
    a.set_xlabel("$x_B$ (m), from the undeformed centre of mass")
    a.set_ylabel("$y_B$ (m)")
    a.grid(True, linewidth=0.3, alpha=0.4)
    if annotate:
        rows = [f"hub: {m0 / 1000:.4g} t, $I_{{x0}}, I_{{y0}}, J_0$ = {hub.ix:.3g}, {hub.iy:.3g}, {hub.iz:.3g} kg m$^2$"]
        for j, ap in enumerate(b.appendages):
            rows.append(f"{j + 1}: {ap.name or 'appendage'}, {ap.mass / 1000:.4g} t, {ap.frequency_hz:.3g} Hz, "
                        f"$\\zeta$ = {ap.damping_ratio:.2g}")
        rows.append(f"composite: {b.total_mass / 1000:.4g} t, $I_0$ = {b.inertia:.4g} kg m$^2$, $K_z$ = {b.kz:.3f}")
        txt = a.text(0.01, 0.01, "\n".join(rows), transform=a.transAxes, fontsize=6.5, va="bottom", ha="left",
                     bbox=dict(boxstyle="round", facecolor="white", alpha=0.85, edgecolor="0.7"), zorder=7)
        txt.set_gid("table")
    if ax is None:
        a.set_title(f"{b.name}: lumped-parameter model", fontsize=10)
    return fig


def plot_flexible_coordinate(quasi, traj=None, ax=None, *, index=None, period: float | None = None) -> Figure:
    """A flexible coordinate against its closed form (thesis Fig. 44).

    ``quasi``: a :class:`librate.attitude.QuasiStaticResponse` (:func:`librate.quasi_static`):
    the closed-form q_j(t) along the rigid solution (``gid="closed-form-j"``, dashed). ``traj``:
    an optional flexible :class:`librate.AttitudeTrajectory` on the same times, drawn solid
    (``gid="full-j"``) with its difference from the closed form in a second panel
    (``gid="error-j"``). ``index``: the appendage(s) (default all). ``period``: one revolution
    (TU) for the time axis. Deflections in m. Returns the Figure.
    """
    if not isinstance(quasi, QuasiStaticResponse):
        raise ValueError(f"invalid argument `quasi`: must be a librate.attitude.QuasiStaticResponse, got {type(quasi).__name__}")
    if traj is not None:
        if getattr(traj, "flex", None) is None:
            raise ValueError("invalid argument `traj`: must be a flexible librate.AttitudeTrajectory (propagate_attitude with a FlexibleBody)")
        if traj.t.shape != quasi.t.shape or not np.allclose(traj.t, quasi.t, rtol=0, atol=1e-12 * max(1.0, float(np.max(np.abs(quasi.t))))):
            raise ValueError("invalid argument `traj`: must be sampled at the closed form's times (same t_eval)")
    idx = _indices(quasi.body.n, index)
    fig, axs = figure_axes(ax, 2 if traj is not None else 1, figsize=(11, 4.2) if traj is not None else (7, 4.4))
    x, xlabel = _time_axis(quasi.t, period)
    cycle = matplotlib.rcParams["axes.prop_cycle"].by_key().get("color", ["tab:blue"])
    for k, j in enumerate(idx):
        c = cycle[k % len(cycle)]
        name = quasi.body.appendages[j].name or f"$q_{{{j + 1}}}$"
        if traj is not None:
            (h,) = axs[0].plot(x, traj.flex.q[:, j], color=c, linewidth=1.2, label=f"{name}: full model")
            h.set_gid(f"full-{j}")
            (e,) = axs[1].plot(x, traj.flex.q[:, j] - quasi.q[:, j], color=c, linewidth=1.0, label=name)
            e.set_gid(f"error-{j}")
        (h,) = axs[0].plot(x, quasi.q[:, j], color=c if traj is None else "k", linestyle="--", linewidth=1.0,
                           label=f"{name}: closed form" if traj is None or k == 0 else None)
        h.set_gid(f"closed-form-{j}")
    axs[0].set_xlabel(xlabel)
    axs[0].set_ylabel("deflection $q_j$ (m)")
    axs[0].legend(fontsize=7.5)
    axs[0].grid(alpha=0.3)
    if traj is not None:
        axs[1].set_xlabel(xlabel)
        axs[1].set_ylabel("full model - closed form (m)")
        axs[1].grid(alpha=0.3)
        axs[1].legend(fontsize=7.5)
    if ax is None:
        fig.suptitle(f"{quasi.body.name}: flexible coordinates, quasi-static closed form $q_j = L_j / k_j$")
    return fig


def plot_flexible_response(traj, rigid=None, ax=None, *, index=None, period: float | None = None) -> Figure:
    """Structural response and body rate (thesis Figs. 45-46, lowered frequencies): the
    deflections q_j(t) of a flexible :class:`librate.AttitudeTrajectory` (left, m,
    ``gid="q-j"``) and its inertial body rate wz(t) (right, 1/TU, ``gid="wz"``), with the rigid
    reference's rate (dashed, ``gid="wz-rigid"``) when ``rigid`` is given: an AttitudeTrajectory
    (e.g. the rigid composite body :meth:`FlexibleBody.rigid_body` from the same state) or a
    QuasiStaticResponse (its rigid solution). ``index``: the appendage(s) (default all).
    ``period``: one revolution (TU) for the time axis. Returns the Figure.
    """
    if not isinstance(traj, AttitudeTrajectory) or traj.flex is None:
        raise ValueError("invalid argument `traj`: must be a flexible librate.AttitudeTrajectory (propagate_attitude with a FlexibleBody)")
    if rigid is not None and not isinstance(rigid, (AttitudeTrajectory, QuasiStaticResponse)):
        raise ValueError(f"invalid argument `rigid`: must be an AttitudeTrajectory or a QuasiStaticResponse, got {type(rigid).__name__}")
    if rigid is not None and getattr(rigid, "wz", None) is None:
        raise ValueError("invalid argument `rigid`: needs a planar run (wz)")
    idx = _indices(traj.flex.body.n, index)
    fig, (aq, aw) = figure_axes(ax, 2, figsize=(11, 4.2))
    x, xlabel = _time_axis(traj.t, period)
    for j in idx:
        name = traj.flex.body.appendages[j].name or f"$q_{{{j + 1}}}$"
        (h,) = aq.plot(x, traj.flex.q[:, j], linewidth=1.0, label=name)
        h.set_gid(f"q-{j}")
    (h,) = aw.plot(x, traj.wz, color="tab:blue", linewidth=1.2, label="flexible")
    h.set_gid("wz")
    if rigid is not None:
        xr, _ = _time_axis(rigid.t, period)
        (h,) = aw.plot(xr, rigid.wz, color="k", linestyle="--", linewidth=1.0, label="rigid (composite)")
        h.set_gid("wz-rigid")
    aq.set_xlabel(xlabel)
    aq.set_ylabel("structural response $q_j$ (m)")
    aw.set_xlabel(xlabel)
    aw.set_ylabel("body rate $\\omega_z$, inertial (1/TU)")
    for a in (aq, aw):
        a.grid(alpha=0.3)
        a.legend(fontsize=7.5)
    if ax is None:
        f = traj.flex.body.frequencies_nd(traj.system)
        fig.suptitle(f"{traj.flex.body.name}: structural frequencies {f.min():.3g}-{f.max():.3g} rad/TU")
    return fig


def plot_frequency_scan(scan, ax=None, *, index=None) -> Figure:
    """The coupled response against the structural frequency (a :class:`librate.periodicity.FrequencyScan`):
    the amplification of the deflections over the quasi-static closed form (left,
    ``gid="amplification-j"``, 1 in the quasi-static regime) and the largest departure of the
    attitude from the rigid solution (right, ``gid="dphi"``), against the clamped frequency of
    the first selected appendage (rad/TU), log-log. Returns the Figure."""
    if not isinstance(scan, FrequencyScan):
        raise ValueError(f"invalid argument `scan`: must be a librate.periodicity.FrequencyScan, got {type(scan).__name__}")
    idx = _indices(scan.frequency.shape[1], index)
    fig, (aa, ad) = figure_axes(ax, 2, figsize=(11, 4.2))
    w = scan.frequency[:, idx[0]]
    for j in idx:
        (h,) = aa.loglog(w, scan.amplification[:, j], marker=".", linewidth=1.0, label=f"$q_{{{j + 1}}}$")
        h.set_gid(f"amplification-{j}")
    (h,) = ad.loglog(w, scan.max_dphi, marker=".", color="tab:red", linewidth=1.0, label="max $|\\phi - \\phi_{rigid}|$ (rad)")
    h.set_gid("dphi")
    (h,) = ad.loglog(w, scan.max_dwz, marker=".", color="tab:purple", linewidth=1.0, label="max $|\\omega_z - \\omega_{z,rigid}|$ (1/TU)")
    h.set_gid("dwz")
    for a in (aa, ad):
        a.set_xlabel(f"clamped frequency $\\Omega_{{{idx[0]}}}$ (rad/TU)")
        a.grid(True, which="both", alpha=0.3)
        a.legend(fontsize=7.5)
    aa.set_ylabel("max |q| / max |q quasi-static| (-)")
    ad.set_ylabel("attitude departure from the rigid solution")
    return fig


__all__ += ["plot_flexible_body", "plot_flexible_coordinate", "plot_flexible_response", "plot_frequency_scan"]

from .attitude3d import plot_body_axes, plot_equilibrium_stability, plot_family_multipliers, plot_map_3d, plot_out_of_plane_stability  # noqa: E402

__all__ += ["plot_equilibrium_stability", "plot_out_of_plane_stability", "plot_family_multipliers", "plot_body_axes", "plot_map_3d"]
