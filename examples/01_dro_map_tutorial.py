"""The five-minute tutorial: orbit family -> periodic attitude solution -> periodicity map -> figure.

Run: python examples/01_dro_map_tutorial.py [OUTPUT_FOLDER]      (a few seconds on 2 cores)

1. the distant retrograde orbit (DRO) family of the Earth-Moon system by continuation in x0;
2. on one member, the periodic planar attitude motion with N = -1 net turn per orbit of a body
   with Kz = (Iy - Ix) / Iz = 0.8 (thesis Fig. 23);
3. the attitude periodicity map of the family: residuals wz(T) - wz0 and phi(T) - phi0 over
   (orbit, initial rate) and every periodic solution refined by Newton (thesis Fig. 24);
4. the figures, and the map saved as Zarr and reloaded without recomputing.
Units: LU, TU (rates in 1/TU; phidot0 = wz0 - 1 is relative to the synodic frame), days.
"""

# %%
import sys
from pathlib import Path

import librate
import librate.plotting as lp
import numpy as np
from librate.app.results import save_dataset

out = Path(sys.argv[1] if len(sys.argv) > 1 else "examples-out") / "tutorial"
em = librate.System.preset("earth-moon")

# %% [markdown]
# ## 1. The family
# 15 DROs from x0 = 0.9 to 0.3 LU, by natural-parameter continuation in x0.

# %%
fam = librate.dro_family(em, x0=np.linspace(0.9, 0.3, 15))
print(f"DRO family: {len(fam)} members, periods {fam.period_days.min():.2f} to {fam.period_days.max():.2f} d")

# %% [markdown]
# ## 2. One periodic attitude motion
# On the 12.66-day DRO, a body with Kz = 0.8, N = -1 net turn per orbit (thesis Fig. 23).

# %%
dro = fam.member(period_days=12.66)
sol = librate.periodic_attitude(dro, kz=0.8, n=-1)
print(f"x0 = {dro.x0:.4f}: N = -1 solution phidot0 = {sol.phidot0:.6f} 1/TU, residual {sol.residual:.1e}, "
      f"{'stable' if sol.stable else 'unstable'} (trace {sol.trace:.3f})")

# %% [markdown]
# ## 3. The periodicity map
# 15 orbits x 300 inertial rates wz0 in [-3, 2] 1/TU; every sign change of the residuals is refined
# by Newton into a periodic solution (thesis Fig. 24).

# %%
ds = librate.periodicity_map(fam, kz=0.8, wz0=np.linspace(-3.0, 2.0, 300))
print(f"map: {ds.sizes['orbit']} orbits x {ds.sizes['wz0']} rates, {ds.sizes['solution']} periodic solutions")

# %% [markdown]
# ## 4. Figures, and the map saved with its units and reloaded

# %%
lp.save_figure(lp.plot_family(fam), out / "family.png", close=True)
one = librate.periodicity_map(dro, kz=0.8, wz0=np.linspace(-2.5, 2.5, 1001))  # the figures take data: the one orbit's map
lp.save_figure(lp.plot_residuals(one), out / "residuals.png", close=True)
lp.save_figure(lp.plot_map(ds), out / "map.png", close=True)
path = save_dataset(ds, out / "map.zarr")
again = librate.open_result(path)
assert np.array_equal(again["dwz"].values, ds["dwz"].values, equal_nan=True)
print(f"written: {out}/family.png, residuals.png, map.png, map.zarr")
