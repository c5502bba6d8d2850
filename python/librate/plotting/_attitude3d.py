"""Figures of the 3-D attitude: the stability diagram of the equilibrium attitudes at a collinear
Lagrange point (thesis Fig. 19, after Robinson 1974), the out-of-plane stability of planar
families, Floquet multipliers along 3-D families, the body axes along the orbit and 3-D
attitude maps.
Re-exported by :mod:`librate.plotting`."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ._style import figure_axes

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["plot_equilibrium_stability", "plot_out_of_plane_stability", "plot_family_multipliers", "plot_body_axes", "plot_map_3d"]


def plot_equilibrium_stability(ds, ax=None, *, boundaries: bool = True) -> Figure:
    """The stability diagram of :func:`librate.equilibrium_stability` over Robinson's inertia
    ratios k_x = (Iy - Iz)/Ix (horizontal) and k_y = (Iz - Ix)/Iy (vertical): the stable regions
    filled (gid "stable"), the rest shaded by why it is unstable (pitch, roll-yaw divergence or
    flutter; gid "unstable"), and with ``boundaries`` the curves K1 K2 = 0, K3 = 0 and the
    flutter boundary b^2 = 4c (gids "boundary-*"). Returns the Figure.

    Parameters
    ----------
    ds : xarray.Dataset
        From `librate.equilibrium_stability`.
    boundaries : bool, default True
        Draw the stability boundaries.
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
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch


    if not all(v in getattr(ds, "data_vars", {}) for v in ("stable", "pitch_stable", "roll_yaw", "b", "c")):
        raise ValueError("invalid argument `ds`: must be the Dataset of librate.equilibrium_stability")
    fig, (a,) = figure_axes(ax, 1)
    kx, ky = ds["k_x"].values, ds["k_y"].values
    # 0 stable, 1 pitch unstable, 2 roll-yaw divergent, 3 roll-yaw flutter (pitch stable)
    code = np.where(ds["stable"].values, 0, np.where(~ds["pitch_stable"].values, 1, np.where(ds["roll_yaw"].values == 1, 2, 3)))
    colors = ["tab:red", "0.88", "0.72", "0.55"]
    mesh = a.pcolormesh(kx, ky, code, cmap=ListedColormap(colors), vmin=-0.5, vmax=3.5, shading="nearest")
    mesh.set_gid("stable")
    if boundaries:
        b, c = ds["b"].values, ds["c"].values
        for field, gid, style in ((c, "boundary-k1k2", "-"), (b * b - 4 * c, "boundary-flutter", "--")):
            cs = a.contour(kx, ky, field, levels=[0.0], colors="k", linewidths=0.8, linestyles=style)
            for art in getattr(cs, "collections", [cs]):
                art.set_gid(gid)
        # K3 = 0 (pitch): Iy = Ix, the line k_y = -k_x
        (line,) = a.plot(kx, -kx, color="k", linewidth=0.8, linestyle=":")
        line.set_gid("boundary-pitch")
    a.set_xlim(kx[0], kx[-1])
    a.set_ylim(ky[0], ky[-1])
    a.set_xlabel("$(I_y - I_z) / I_x$")
    a.set_ylabel("$(I_z - I_x) / I_y$")
    a.set_aspect("equal")
    point = ds.attrs.get("point", "")
    a.set_title(f"Equilibrium attitude at {point} (h = {ds.attrs.get('h', float('nan')):.2f})")
    labels = ["stable", "pitch unstable", "roll-yaw divergent", "roll-yaw flutter"]
    a.legend(handles=[Patch(color=col, label=lab) for col, lab in zip(colors, labels)], loc="lower left", fontsize="small", framealpha=0.9)
    return fig


#: Marker of each (in-plane stable, out-of-plane stable) class of plot_out_of_plane_stability.
_CLASSES = {
    (True, True): ("stable in 3-D", dict(marker="o", color="tab:green", linestyle="none")),
    (True, False): ("stable in the plane, unstable out of it", dict(marker="^", color="tab:red", linestyle="none")),
    (False, True): ("unstable in the plane only", dict(marker="o", color="0.45", markerfacecolor="none", linestyle="none")),
    (False, False): ("unstable in and out of the plane", dict(marker="x", color="0.3", linestyle="none")),
}


def plot_out_of_plane_stability(datasets, ax=None, *, against: str = "period") -> Figure:
    """The 3-D stability of planar attitude families across an orbit family, one column per
    Dataset of :func:`librate.periodicity.out_of_plane_family` (e.g. N = 1, 0, -1 of thesis Figs.
    27-29). The top row shows the initial rate phidot(0) = wz(0) - 1 against the orbit's period
    (days) or x0 (``against``). Each member's marker shows whether it is stable in the plane and
    out of it (gids ``"class-<in>-<out>"``, e.g. ``"class-1-0"``: stable in the plane, unstable
    out of it). The bottom row shows the largest |roll/yaw multiplier| on a log scale (gid
    ``"out-of-plane-modulus"``). Returns the Figure.

    Parameters
    ----------
    datasets : sequence of xarray.Dataset
        From `librate.periodicity.out_of_plane_family`, one column each.
    against : {"period", "x0"}
        The horizontal axis.
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

    dss = [datasets] if hasattr(datasets, "data_vars") else list(datasets)
    if not dss or not all("out_of_plane_modulus" in getattr(d, "data_vars", {}) for d in dss):
        raise ValueError("invalid argument `datasets`: Datasets of librate.periodicity.out_of_plane_family")
    if against not in ("period", "x0"):
        raise ValueError(f"invalid argument `against`: must be 'period' or 'x0', got {against!r}")
    ncol = len(dss)
    if ax is None:
        import matplotlib.pyplot as plt

        fig = plt.figure(figsize=(4.8 * ncol, 7.0), layout="constrained")
        axs = fig.subplots(2, ncol, sharex="col", squeeze=False)
        top, bottom = list(axs[0]), list(axs[1])
    else:
        fig, flat = figure_axes(ax, 2 * ncol)
        top, bottom = flat[:ncol], flat[ncol:]
    for d, a, b in zip(dss, top, bottom):
        x = d["period_days"].values if against == "period" else d["x0"].values
        y = d["phidot0"].values
        a.plot(x, y, color="0.8", linewidth=0.8, zorder=0)
        for (sin, sout), (label, style) in _CLASSES.items():
            m = (d["stable_in_plane"].values == sin) & (d["stable_out_of_plane"].values == sout)
            if m.any():
                (ln,) = a.plot(x[m], y[m], label=label, markersize=5, **style)
                ln.set_gid(f"class-{int(sin)}-{int(sout)}")
        a.set_title(f"N = {d.attrs.get('n')}, Kz = {d.attrs.get('kz'):g}")
        a.set_ylabel(r"$\dot\phi(0) = w_z(0) - 1$ (1/TU)")
        (ln,) = b.semilogy(x, d["out_of_plane_modulus"].values, ".-", color="tab:red", markersize=4)
        ln.set_gid("out-of-plane-modulus")
        b.axhline(1.0, color="k", linewidth=0.6)
        b.set_ylabel("largest |roll/yaw multiplier|")
        b.set_xlabel("orbit period (days)" if against == "period" else "$x_0$ (LU)")
    from matplotlib.lines import Line2D

    top[0].legend(handles=[Line2D([], [], label=label, **style) for label, style in _CLASSES.values()], fontsize="small", loc="best")
    return fig


def plot_family_multipliers(ds, ax=None, *, against: str = "period") -> Figure:
    """Floquet multipliers along a 3-D attitude family (:func:`librate.attitude_family_3d`).
    The left panel shows |multiplier| of the six against the orbit period in days (or x0, z0)
    on a log scale (gid ``"modulus"``), with the unit circle as a line. The right panel shows the
    multipliers in the complex plane, coloured along the family (gid ``"multipliers"``). The
    stability changes listed in the Dataset are shaded (gid ``"stability-change"``). Returns the
    Figure.

    Parameters
    ----------
    ds : xarray.Dataset
        From `librate.attitude_family_3d` (or a ``librate solve`` result of a 3-D study).
    against : {"period", "x0", "z0"}
        The horizontal axis.
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
    import ast

    from matplotlib import colormaps
    from matplotlib.patches import Circle
    from matplotlib.ticker import MaxNLocator

    if "multipliers" not in getattr(ds, "data_vars", {}) or "period_days" not in getattr(ds, "data_vars", {}):
        raise ValueError("invalid argument `ds`: must be the Dataset of librate.attitude_family_3d")
    if against not in ("period", "x0", "z0"):
        raise ValueError(f"invalid argument `against`: must be 'period', 'x0' or 'z0', got {against!r}")
    fig, (a, b) = figure_axes(ax, 2)
    x = ds["period_days" if against == "period" else against].values
    m = ds["multipliers"].values
    for k in range(m.shape[1]):
        (ln,) = a.semilogy(x, np.abs(m[:, k]), ".-", markersize=3, linewidth=0.8)
        ln.set_gid("modulus")
    a.axhline(1.0, color="k", linewidth=0.6)
    along_period = ds.attrs.get("parameter") == "period_days" and against == "period"
    for ch in ast.literal_eval(ds.attrs.get("stability_changes", "[]")) if along_period else []:
        lo, hi = ch["between"]
        hi = ch.get("at", lo) if hi is None else hi  # natural continuation stalled past the last member
        a.axvspan(min(lo, hi), max(lo, hi), color="tab:orange", alpha=0.3, gid="stability-change")
        if "at" in ch:  # located by the continuation driver
            a.axvline(ch["at"], color="tab:orange", linewidth=1.0, gid="stability-change-at")
    a.set_xlabel({"period": "orbit period (days)", "x0": "$x_0$ (LU)", "z0": "$z_0$ (LU)"}[against])
    a.set_ylabel("|Floquet multiplier|")
    moments = ds.attrs.get("body_moments")
    if isinstance(moments, str):
        moments = ast.literal_eval(moments)
    body = "" if moments is None else ", body $I_x, I_y, I_z$ = " + ", ".join(f"{float(v):.4g}" for v in np.ravel(moments)) + " kg m$^2$"
    a.set_title(f"|multiplier| of the {m.shape[1]}", fontsize="medium")
    if ax is None:
        fig.suptitle(f"Floquet multipliers along the 3-D attitude family{body}", fontsize="medium")
    # one colour per member: integer steps on the colour bar (a member index has no fractions)
    n_members = m.shape[0]
    colors = np.broadcast_to(np.arange(n_members)[:, None], m.shape)
    sc = b.scatter(m.real.ravel(), m.imag.ravel(), c=colors.ravel(), cmap=colormaps["viridis"].resampled(max(n_members, 1)),
                   vmin=-0.5, vmax=n_members - 0.5, s=8)
    sc.set_gid("multipliers")
    b.add_patch(Circle((0, 0), 1.0, fill=False, color="k", linewidth=0.6))
    b.set_aspect("equal", adjustable="datalim")
    b.set_xlabel("Re")
    b.set_ylabel("Im")
    cb = fig.colorbar(sc, ax=b, label="member index (along the family)")
    cb.ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    b.set_title("the multipliers in the complex plane (unit circle)", fontsize="medium")
    return fig


def plot_body_axes(solution, ax=None, *, samples: int = 16, planes=("xy", "xz")) -> Figure:
    """The body axes along the orbit of a periodic 3-D attitude motion
    (:class:`librate.AttitudeSolution3D`): one panel per synodic plane of ``planes`` ("xy",
    "xz" or "yz"), the orbit over the solution's K periods (gid ``"orbit"``) and, at ``samples``
    evenly spaced times, the projections of the body x, y and z axes as arrows (gids
    ``"axis-x"``, ``"axis-y"``, ``"axis-z"``; red, green, blue), scaled to 6 % of the orbit's
    extent. Returns the Figure.

    Parameters
    ----------
    solution : AttitudeSolution3D
        The motion.
    samples : int, default 16
        Arrow positions along the orbit.
    planes : sequence of {"xy", "xz", "yz"}
        One panel each.
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

    if not all(hasattr(solution, a) for a in ("q0", "w0", "orbit", "propagate", "n_periods")):
        raise ValueError(f"invalid argument `solution`: must be a librate.AttitudeSolution3D, got {type(solution).__name__}")
    samples = int(samples)
    if samples < 1:
        raise ValueError(f"invalid argument `samples`: must be an integer >= 1, got {samples!r}")
    index = {"x": 0, "y": 1, "z": 2}
    planes = tuple(planes)
    if not planes or any(len(p) != 2 or p[0] not in index or p[1] not in index or p[0] == p[1] for p in planes):
        raise ValueError(f"invalid argument `planes`: must be planes such as 'xy', 'xz', 'yz', got {planes!r}")
    t_end = solution.n_periods * solution.orbit.period
    dense = solution.propagate(t_eval=np.linspace(0.0, t_end, 400))
    marks = solution.propagate(t_eval=np.linspace(0.0, t_end, samples, endpoint=False))
    pos, at = dense.orbit[:, :3], marks.orbit[:, :3]
    axes = marks.dcm()  # (n, 3, 3): row i is body axis i in synodic components
    extent = float(np.max(np.ptp(pos, axis=0)))
    length = 0.06 * (extent if extent > 0 else 1.0)
    fig, panels = figure_axes(ax, len(planes))
    for a, plane in zip(panels, planes):
        i, j = index[plane[0]], index[plane[1]]
        (ln,) = a.plot(pos[:, i], pos[:, j], color="0.5", linewidth=0.8)
        ln.set_gid("orbit")
        for k, (name, color) in enumerate((("x", "tab:red"), ("y", "tab:green"), ("z", "tab:blue"))):
            q = a.quiver(at[:, i], at[:, j], length * axes[:, k, i], length * axes[:, k, j], color=color, angles="xy", scale_units="xy",
                         scale=1.0, width=0.004, label=f"body {name}")
            q.set_gid(f"axis-{name}")
        a.set_aspect("equal", adjustable="datalim")
        a.set_xlabel(f"{plane[0]} (LU)")
        a.set_ylabel(f"{plane[1]} (LU)")
    panels[0].legend(fontsize="small", loc="best")
    panels[0].set_title(f"body axes along the orbit (T = {solution.orbit.period_days:.3f} d, K = {solution.n_periods})")
    return fig


def plot_map_3d(ds, ax=None, *, orbits=None) -> Figure:
    """A 3-D attitude map (:func:`librate.attitude_map_3d`, or the ``librate map`` result of a
    3-D study with its ``orbit`` dimension): log10 of the residual max-norm over its two rate
    grids, one panel per orbit (``orbits``: the indices to draw, default the first three), the
    smallest residual marked (gid ``"minimum"``; where the 3-D corrector's seeds come from).
    Returns the Figure.

    Parameters
    ----------
    ds : xarray.Dataset
        From `librate.attitude_map_3d`, or a ``librate map`` result of a 3-D study.
    orbits : sequence of int, optional
        The orbits drawn (default the first three).
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

    if "residual_norm" not in getattr(ds, "data_vars", {}):
        raise ValueError("invalid argument `ds`: must be a 3-D attitude map (librate.attitude_map_3d)")
    has_orbit = "orbit" in ds["residual_norm"].dims
    idx = list(range(min(3, ds.sizes["orbit"]))) if has_orbit and orbits is None else list(orbits or [None])
    rate_dims = [d for d in ds["residual_norm"].dims if d in ("wx0", "wy0", "wz0")]
    if len(rate_dims) != 2 or len(ds["residual_norm"].dims) != 2 + has_orbit:
        raise ValueError("invalid argument `ds`: the figure needs exactly two rate grids (and at most an orbit dimension), got dims "
                         f"{ds['residual_norm'].dims}")
    fig, axs = figure_axes(ax, len(idx))
    for a, i in zip(axs, idx):
        r = ds["residual_norm"] if i is None else ds["residual_norm"].isel(orbit=i)
        r = r.transpose(rate_dims[1], rate_dims[0])
        x, y = ds[rate_dims[0]].values, ds[rate_dims[1]].values
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.log10(r.values)
        mesh = a.pcolormesh(x, y, z, shading="nearest", cmap="viridis")
        mesh.set_gid("log-residual")
        k = np.nanargmin(r.values)
        iy, ix = np.unravel_index(k, r.shape)
        (pt,) = a.plot(x[ix], y[iy], "r*", markersize=10)
        pt.set_gid("minimum")
        a.set_xlabel(f"{rate_dims[0]} (1/TU)")
        a.set_ylabel(f"{rate_dims[1]} (1/TU)")
        title = "" if i is None else f"orbit {i}"
        if i is not None and "period_days" in ds.coords:
            title += f": T = {float(ds['period_days'].values[i]):.3f} d"
        a.set_title(f"{title}  smallest {float(np.nanmin(r.values)):.2e} (red star)".strip(), fontsize="medium")
        fig.colorbar(mesh, ax=a, label="log10 max |residual| (closure after K periods)")
    fixed = [d for d in ("wx0", "wy0", "wz0") if d not in rate_dims and d in ds.variables and ds[d].size == 1]
    held = ", ".join(f"{d} = {float(ds[d].values):g} 1/TU" for d in fixed)
    if ax is None:
        fig.suptitle("3-D attitude map: the six closure residuals' max-norm over the initial rates" + (f" ({held})" if held else ""),
                     fontsize="medium")
    return fig
