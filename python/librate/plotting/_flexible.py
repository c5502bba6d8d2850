"""Figures of the flexible spacecraft (thesis ch. 5, Figs. 42-46)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import matplotlib
import numpy as np

from ..attitude.flexible import FlexibleBody, QuasiStaticResponse
from ..attitude.propagate import AttitudeTrajectory
from ..periodicity.flexible_periodic import FrequencyScan
from ._style import figure_axes

if TYPE_CHECKING:
    from matplotlib.figure import Figure


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
            raise ValueError("invalid argument `traj`: must be a flexible librate.AttitudeTrajectory (propagate_attitude "
                             "with a FlexibleBody)")
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



