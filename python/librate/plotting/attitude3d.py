"""Figures of the 3-D attitude: the stability diagram of the equilibrium attitudes at a collinear
Lagrange point (thesis Fig. 19, after Robinson 1974). Re-exported by :mod:`librate.plotting`."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["plot_equilibrium_stability"]


def plot_equilibrium_stability(ds, ax=None, *, boundaries: bool = True) -> Figure:
    """The stability diagram of :func:`librate.equilibrium_stability` over Robinson's inertia
    ratios k_x = (Iy - Iz)/Ix (horizontal) and k_y = (Iz - Ix)/Iy (vertical): the stable regions
    filled (gid "stable"), the rest shaded by why it is unstable (pitch, roll-yaw divergence or
    flutter; gid "unstable"), and with ``boundaries`` the curves K1 K2 = 0, K3 = 0 and the
    flutter boundary b^2 = 4c (gids "boundary-*"). Returns the Figure."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    from . import _axes

    if not all(v in getattr(ds, "data_vars", {}) for v in ("stable", "pitch_stable", "roll_yaw", "b", "c")):
        raise ValueError("invalid argument `ds`: must be the Dataset of librate.equilibrium_stability")
    fig, (a,) = _axes(ax, 1)
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
