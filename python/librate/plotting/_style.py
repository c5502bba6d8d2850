"""The shared visual language of librate's figures: one colour per N (:data:`N_COLORS`, the same
N the same colour in every figure), the markers of periodic and half-turn motions, the styles
of the primaries and Lagrange points, axis helpers, and :func:`save_figure`."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.lines import Line2D

from ..constants import SUN_SYNODIC_PERIOD
from ..orbits.families import OrbitFamily
from ..orbits.periodic import PeriodicOrbit
from ..periodicity.solutions import KINDS

if TYPE_CHECKING:
    from matplotlib.figure import Figure


EARTH = dict(marker="o", color="tab:blue", markersize=9, markeredgecolor="k", linestyle="none")
MOON = dict(marker="o", color="0.6", markersize=6, markeredgecolor="k", linestyle="none")
LPOINT = dict(marker="x", color="k", markersize=6, linestyle="none")
# Label offsets (points) and alignment, so that L1, the Moon and L2 do not overlap.
LABEL_OFFSETS = {"Earth": (-6, 6, "right"), "Moon": (0, -13, "center"), "L1": (-4, 5, "right"),
                  "L2": (4, 5, "left"), "L3": (-4, 5, "right")}
PROJECTIONS = ("xy", "xz", "yz", "3d")
_QUANTITIES = {
    "x0": "$x_0$ (LU)",
    "z0": "$z_0$ (LU)",
    "jacobi": "Jacobi constant $C$ (LU$^2$/TU$^2$)",
}


# --- helpers -----------------------------------------------------------------------------------
def check_family(family) -> OrbitFamily:
    if not isinstance(family, OrbitFamily):
        raise ValueError(f"invalid argument `family`: must be a librate.OrbitFamily, got {type(family).__name__}")
    return family


def family_name(kind: str) -> str:
    """A family's kind as figure titles show it: the acronym DRO in capitals, other kinds as
    named (``lyapunov-L1``, ``halo-L2-south``); an unnamed one is "orbit"."""
    return "DRO" if kind == "dro" else (kind or "orbit")


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


def pick_orbits(n: int, n_orbits: int | None) -> np.ndarray:
    """Indices of ``n_orbits`` members evenly spread over ``n`` (first and last included)."""
    if n_orbits is None or n_orbits >= n:
        return np.arange(n)
    if isinstance(n_orbits, bool) or not isinstance(n_orbits, (int, np.integer)) or n_orbits < 1:
        raise ValueError(f"invalid argument `n_orbits`: must be an integer >= 1 or None (all members), got {n_orbits!r}")
    return np.round(np.linspace(0, n - 1, int(n_orbits))).astype(int)


def family_axis(family: OrbitFamily, against: str) -> tuple[np.ndarray, str]:
    if against not in _QUANTITIES:
        raise ValueError(f"invalid argument `against`: must be one of {', '.join(_QUANTITIES)}, got {against!r}")
    q = {"x0": family.x0, "z0": family.z0, "jacobi": family.jacobi}[against]
    return np.asarray(q, dtype=float), _QUANTITIES[against]


def length_scale(system, units: str) -> tuple[float, str]:
    if units == "LU":
        return 1.0, "LU"
    if units == "km":
        return system.lu_km, "km"
    raise ValueError(f"invalid argument `units`: must be 'LU' or 'km', got {units!r}")


def time_scale(system, units: str) -> tuple[float, str]:
    if units == "days":
        return system.tu_days, "days"
    if units == "TU":
        return 1.0, "TU"
    raise ValueError(f"invalid argument `units`: must be 'days' or 'TU', got {units!r}")


def level_crossings(x: np.ndarray, y: np.ndarray, level: float) -> list[float]:
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


def resonance_label(orbit: PeriodicOrbit, tol: float = 1e-6) -> str | None:
    """'1:K' when T = 2 pi / K, '1:K Sun' when T = Ts / K (relative tolerance ``tol``)."""
    for base, suffix in ((2 * math.pi, ""), (SUN_SYNODIC_PERIOD, " Sun")):
        k = base / orbit.period
        if round(k) >= 1 and abs(k - round(k)) < tol * k:
            return f"1:{round(k)}{suffix}"
    return None



# --- periodic attitude motions: residuals, maps, families, motions (Figs. 23-31) --------------
#: The marker of each kind of periodic attitude motion, in every figure (filled: stable).
KIND_MARKERS = {"periodic": "o", "half-turn": "D"}
# Solutions are coloured by N (the same N, the same colour in every figure), |N| > 3 in one grey;
# blue and orange are left to the residuals Dwz and Dphi (curves in Fig. 23, contours in Fig. 24).
N_COLORS = {0: "tab:green", 1: "tab:red", -1: "tab:purple", 2: "tab:brown", -2: "tab:pink", 3: "tab:olive", -3: "tab:cyan"}
N_OTHER = "0.55"
DWZ_COLOR, DPHI_COLOR = "tab:blue", "tab:orange"
KZ_STYLES = ("-", "--", ":", "-.")
_ORBIT_AXES = {"period": "orbit period $T$ (days)", "x0": "orbit $x_0$ (LU)"}


def n_color(n: int) -> str:
    """The colour of N (|N| <= 3 each its own, the others one grey)."""
    return N_COLORS.get(int(n), N_OTHER)


def rate_axis(rate: str, *, initial: bool = True) -> tuple[float, str]:
    """(offset subtracted from inertial rates, axis label) for ``rate="relative"`` (phidot =
    wz - 1, the quantity on the thesis figures' axes) or ``"inertial"`` (wz)."""
    t = "(0)" if initial else "(t)"
    what = "initial rate" if initial else "angular velocity"
    if rate == "relative":
        return 1.0, f"{what} $\\dot\\varphi{t} = \\omega_z{t} - 1$, relative to the synodic frame (1/TU)"
    if rate == "inertial":
        return 0.0, f"{what} $\\omega_z{t}$, inertial (1/TU)"
    raise ValueError(f"invalid argument `rate`: must be 'relative' (wz - 1, the thesis figures' axis) or 'inertial', got {rate!r}")


def check_map(ds, name: str = "ds"):
    names = getattr(ds, "variables", None)
    if not hasattr(ds, "data_vars") or names is None or not all(v in names for v in ("dwz", "dphi", "wz0", "x0", "period_days", "kz")):
        raise ValueError(f"invalid argument `{name}`: must be an xarray Dataset from librate.periodicity_map, got {type(ds).__name__}")
    return ds


def check_index(value, size: int, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not -size <= value < size:
        raise ValueError(f"invalid argument `{name}`: must be an integer index below {size}, got {value!r}")
    return int(value) % size


def orbit_axis(ds, against: str) -> tuple[np.ndarray, str]:
    if against not in _ORBIT_AXES:
        raise ValueError(f"invalid argument `against`: must be 'period' (days) or 'x0', got {against!r}")
    return np.asarray(ds["period_days" if against == "period" else "x0"].values, dtype=float), _ORBIT_AXES[against]


def solution_table(ds) -> dict[str, np.ndarray] | None:
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


def kz_mask(tab, kz: float) -> np.ndarray:
    return np.abs(tab["kz"].astype(float) - float(kz)) <= 1e-12 * max(1.0, abs(float(kz)))


def draw_solutions(a, x, y, n, kind, stable, *, markersize: float = 6.5) -> None:
    """Markers for solutions: colour by N, circle periodic / diamond half-turn, filled when
    linearly stable, hollow when not; one Line2D per group, all with ``gid="solutions"``."""
    for k in KINDS:
        for nn in sorted(set(n[kind == k].tolist()), reverse=True):
            for st in (True, False):
                m = (kind == k) & (n == nn) & (stable == st)
                if not m.any():
                    continue
                c = n_color(nn)
                (h,) = a.plot(x[m], y[m], linestyle="none", marker=KIND_MARKERS[k], color=c, markeredgecolor=c,
                              markerfacecolor=c if st else "none", markeredgewidth=1.4, markersize=markersize, zorder=5,
                              label="_nolegend_")
                h.set_gid("solutions")


def solution_legend(n, kind, stable) -> list:
    """Legend proxies explaining the solution markers."""
    out = []
    ns = sorted({int(v) for v in np.asarray(n).tolist()}, reverse=True)  # integer N: legends never print "4.0"
    others = [nn for nn in ns if nn not in N_COLORS]
    for nn in ns:
        if nn in N_COLORS or len(others) == 1:
            out.append(Line2D([], [], linestyle="none", marker="s", color=n_color(nn), markersize=7, label=f"$N$ = {nn}"))
    if len(others) > 1:
        out.append(Line2D([], [], linestyle="none", marker="s", color=N_OTHER, markersize=7,
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


def set_contour_gid(cs, gid: str) -> None:
    if hasattr(cs, "set_gid"):  # matplotlib >= 3.8: a ContourSet is one Collection
        cs.set_gid(gid)
    else:  # pragma: no cover - matplotlib < 3.8
        for c in cs.collections:
            c.set_gid(gid)


def break_wraps(x: np.ndarray, y: np.ndarray, jump: float = math.pi) -> tuple[np.ndarray, np.ndarray]:
    """(x, y) with a NaN point inserted where y jumps by more than ``jump`` (the +-pi wrap of
    Dphi), so that no vertical line joins the two sides; the finite points are (x, y) unchanged."""
    cut = np.flatnonzero(np.abs(np.diff(y)) > jump) + 1
    return np.insert(np.asarray(x, dtype=float), cut, np.nan), np.insert(np.asarray(y, dtype=float), cut, np.nan)


# --- solar radiation pressure (thesis ch. 4, Figs. 33-41) ---------------------------------------
SUN_COLOR = "#f2a900"
SRP_COLOR, GRAVITY_COLOR = "tab:red", "0.15"


def draw_primaries(a, system, scale: float = 1.0) -> None:
    e, m = system.primary_positions() * scale
    for pos, name, style, gid in ((e, "Earth", EARTH, "earth"), (m, "Moon", MOON, "moon")):
        (h,) = a.plot([pos[0]], [pos[1]], zorder=4, **style)
        h.set_gid(gid)
        dx, dy, ha = LABEL_OFFSETS[name]
        a.annotate(name, (pos[0], pos[1]), xytext=(dx, dy), textcoords="offset points", fontsize=8, ha=ha)

# --- output --------------------------------------------------------------------------------------
def save_figure(fig, path, *, dpi: int = 150, close: bool = False, **kwargs) -> Path:
    """Write ``fig`` (a Figure, or an Axes: its figure) to ``path`` (format from the suffix:
    .png, .pdf, .svg, ...), creating missing directories; ``bbox_inches="tight"`` unless given
    in ``kwargs`` (passed to ``Figure.savefig``). ``close`` closes it in pyplot afterwards.
    Returns the path.

    Parameters
    ----------
    fig : matplotlib Figure or Axes
        The figure (or an Axes of it).
    path : str or pathlib.Path
        The file; the format from its suffix.
    dpi : int, default 150
        Resolution.
    close : bool, default False
        Close the figure in pyplot afterwards.
    **kwargs
        Passed to ``Figure.savefig``.

    Returns
    -------
    pathlib.Path
        The path written.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import librate, librate.plotting as lp, tempfile, pathlib
    >>> fam = librate.dro_family(librate.System.preset("earth-moon"), x0=[0.9, 0.8, 0.7])
    >>> path = lp.save_figure(lp.plot_family(fam), pathlib.Path(tempfile.mkdtemp()) / "dros.png", close=True)
    >>> path.suffix
    '.png'
    """
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
