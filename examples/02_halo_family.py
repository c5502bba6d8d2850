"""A halo family: the L2 southern halos from their bifurcation off the planar Lyapunov family
into the near-rectilinear halo orbits (NRHOs), with a member looked up by period.

Run: python examples/02_halo_family.py [OUTPUT_FOLDER]      (about a second)

Prints the family's span (period in days, Jacobi constant, stability indices), finds the 9-day
NRHO-like member by root finding on the family, and draws the orbits in 3-D (coloured by Jacobi
constant), the period and the stability indices. The family is saved as netCDF and reloaded.
"""

# %%
import sys
from pathlib import Path

import librate
import librate.plotting as lp
import numpy as np

out = Path(sys.argv[1] if len(sys.argv) > 1 else "examples-out") / "halo"
em = librate.System.preset("earth-moon")

# %% [markdown]
# ## The family, from the bifurcation to the NRHOs

# %%
fam = librate.halo_family(em, point=2, branch="south", max_members=120)
print(f"L2 south halo family: {len(fam)} members, period {fam.period_days.min():.2f} to {fam.period_days.max():.2f} d, "
      f"Jacobi {fam.jacobi.min():.4f} to {fam.jacobi.max():.4f} ({fam.end_reason})")
print(f"stable members: {int(fam.stable.sum())}")

# %% [markdown]
# ## A member by its period
# `OrbitFamily.member` finds the member of a given period by root finding along the family, and
# corrects it.

# %%
nrho = fam.member(period_days=9.0)
print(f"9-day member: x0 = {nrho.x0:.6f} LU, z0 = {nrho.z0:.6f} LU ({em.distance_km(nrho.z0):.0f} km), "
      f"Jacobi {nrho.jacobi:.6f}, stability indices {np.round(nrho.stability_indices.real, 3)}")

# %% [markdown]
# ## Figures, and the family saved as netCDF and reloaded

# %%
lp.save_figure(lp.plot_family(fam, n_orbits=25, projection=("3d", "xz")), out / "halo_family.png", close=True)
lp.save_figure(lp.plot_period(fam), out / "halo_period.png", close=True)
lp.save_figure(lp.plot_stability(fam, yscale="symlog"), out / "halo_stability.png", close=True)
out.mkdir(parents=True, exist_ok=True)
fam.save(out / "halo.nc")
same = librate.open_result(out / "halo.nc")
assert np.array_equal(same.state0, fam.state0)
print(f"written: {out}/halo_family.png, halo_period.png, halo_stability.png, halo.nc")
