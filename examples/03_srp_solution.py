"""A periodic attitude motion under solar radiation pressure (thesis ch. 4).

Run: python examples/03_srp_solution.py [OUTPUT_FOLDER]      (about a second)

With SRP the forcing repeats only when the orbit is commensurate with the apparent Sun period:
the 1:2 Sun-resonant DRO (T = Ts / 2, 14.75 d) repeats its geometry after 2 orbits. The
gravity-gradient solution with N = -2 net turns over those 2 orbits (Kz = 0.8) is continued in
the flat-plate amplitude eps up to 0.02 (cs = 0.4 specular), the initial angle phi0 and rate wz0
corrected together (the mirror symmetry is broken). The figure compares the two motions.
"""

# %%
import sys
from pathlib import Path

import librate
import librate.plotting as lp

out = Path(sys.argv[1] if len(sys.argv) > 1 else "examples-out") / "srp"
em = librate.System.preset("earth-moon")

orbit = librate.dro_family(em).resonant(2, "sun")
print(f"1:2 Sun-resonant DRO: x0 = {orbit.x0:.6f} LU, T = {orbit.period_days:.3f} d")

# %% [markdown]
# ## The gravity-gradient solution, then continuation in the SRP amplitude

# %%
gravity = librate.periodic_attitude(orbit, kz=0.8, n=-1, n_periods=2)
print(f"gravity gradient only: wz0 = {gravity.wz0:.8f} 1/TU, phi0 = {gravity.phi0:.3g} rad, residual {gravity.residual:.1e}")

plate = librate.FlatPlate(0.02, cs=0.4)
path = librate.continue_srp(gravity, plate)
srp = path.solutions[-1]
print(f"continued to eps = {path.eps[-1]:g} in {len(path.eps) - 1} steps ({path.end_reason}):")
print(f"with SRP: wz0 = {srp.wz0:.8f} 1/TU, phi0 = {srp.phi0:.6f} rad, residual {srp.residual:.1e}, "
      f"{'stable' if srp.stable else 'unstable'} (trace {srp.trace:.4f})")

# %% [markdown]
# ## The two motions compared

# %%
# The legend tells the gravity-only motion (dashed) from the SRP one (red, with its eps).
lp.save_figure(lp.plot_srp_comparison(gravity, srp), out / "srp_motion.png", close=True)
print(f"written: {out}/srp_motion.png")
