"""A study driven from Python: the same TOML study the command line runs, validated first.

Run: python examples/04_study_from_python.py [OUTPUT_FOLDER]      (a few seconds)

Equivalent to `librate map study.toml` then `librate plot OUTPUT/map.zarr`. An invalid study
raises librate.StudyError listing every problem (key, value, what is allowed) before any work.
"""

# %%
import sys
from pathlib import Path

import librate
import librate.plotting as lp
from librate.app.jobs import run_map

out = Path(sys.argv[1] if len(sys.argv) > 1 else "examples-out") / "study"
out.mkdir(parents=True, exist_ok=True)
toml = out / "study.toml"
toml.write_text('''
title = "Lyapunov L1 orbits, two Kz values"
[orbits]
kind = "lyapunov"
point = 1
x0 = { start = 0.83, stop = 0.75, num = 5 }   # members by x0 (LU), found on the family
[body]
kz = [0.5, 0.8]
[rates]
phidot0 = { start = -3.0, stop = 1.0, num = 120 }   # relative to the synodic frame, 1/TU
[output]
folder = "."                    # next to this file
''')

# %% [markdown]
# ## An invalid study is refused before any work, with every problem listed

# %%
try:
    librate.Study.from_dict({"body": {"kz": 1.5}, "rates": {"wz0": [2.0, 1.0]}}, purpose="map")
except librate.StudyError as err:
    print(err)  # body.kz = 1.5 ... rates.wz0 = [2.0, 1.0] ...

# %% [markdown]
# ## The study run, its result reloaded, and its figure

# %%
study = librate.Study.from_toml(toml, purpose="map")
ds, path = run_map(study)
print(f"map: {dict(ds.sizes)}, written to {path}")

ds = librate.open_result(path)  # reload without recomputing; the study travels with it
print("study stored with the result:", librate.Study.from_json(ds.attrs["study"]).title)
lp.save_figure(lp.plot_map(ds, kz_index=1), out / "map_kz0.8.png", close=True)
print(f"written: {out}/map_kz0.8.png")
