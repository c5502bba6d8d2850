"""Benchmark: what turning maps into answers costs, as ratios against the map alone.

Measured side by side in this one script (same process, same machine, round-robin so that a
shared machine's load affects every entry alike), each reported by its best and median time
and as a ratio against the standard map without solutions:

1. the standard map: the DRO through x0 = 0.70 (preset "earth-moon"), Kz = 0.8, 2000 inertial
   rates wz0 in [-3, 2], one period: ``periodicity_map(..., solve=False)`` (the reference) and
   with its solutions (``solve=True``: every candidate refined in one batch by the Rust
   corrector and re-propagated independently). Target: <= 1.3x the map alone.
2. ``attitude_family`` of the N = 0 motion across a 300-member DRO family (x0 = 0.95 ... 0.25),
   Kz = 0.8 (the family itself computed beforehand, not timed). Target: < 0.5 s.
3. the README's flat-plate SRP map: the 1:2 Sun-resonant DRO, Kz = 0.6, 41 eps in [0, 2] x 400
   rates in [-1.6, 1.2], cs = 0.4, cd = 0.1, K = 2, with its branches (``srp_map``). Target: < 2 s.

No timing is asserted anywhere; the numbers are printed with the CPU they were measured on.

Run: python bench/bench_solve.py [--rounds N]
"""

import argparse
import os
import platform

import librate
import numpy as np
from timing import cpu_name, race


def workloads(n_rates=2000, n_eps=41, n_srp_rates=400, family=True):
    """The timed calls, {name: function}, after a warm-up (forcing table cached, imports done).
    The defaults are the issue's sizes (``n_eps`` x ``n_srp_rates`` = the README's srp_map);
    ``family=False`` leaves out the 300-member attitude family (its family is computed here)."""
    em = librate.System.preset("earth-moon")
    o7 = librate.dro(em, x0=0.70)
    wz = np.linspace(-3.0, 2.0, n_rates)
    o2 = librate.dro_family(em).resonant(2, "sun")
    librate.periodicity_map(o7, kz=0.8, wz0=wz, solve=True)  # warm-up: forcing table cached, imports done
    fns = {
        f"map alone ({n_rates} rates)": lambda: librate.periodicity_map(o7, kz=0.8, wz0=wz, solve=False),
        "map with its solutions": lambda: librate.periodicity_map(o7, kz=0.8, wz0=wz, solve=True),
    }
    if family:
        fam300 = librate.dro_family(em, x0=np.linspace(0.95, 0.25, 300))
        fns["attitude_family across 300 DROs"] = lambda: librate.attitude_family(fam300, kz=0.8, n=0)
    fns[f"srp_map {n_eps} eps x {n_srp_rates} rates, K = 2"] = lambda: librate.srp_map(
        o2, kz=0.6, wz0=np.linspace(-1.6, 1.2, n_srp_rates), eps=np.linspace(0, 2, n_eps), cs=0.4, cd=0.1)
    return fns


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    print(f"librate {librate.__version__} on {cpu_name()}, {os.cpu_count()} cores, python {platform.python_version()}")
    print(f"SIMD and build: {librate.build_info() if hasattr(librate, 'build_info') else 'n/a'}")
    fns = workloads()
    res = race(fns, args.rounds)
    out = {k: v[0] for k, v in res.items()}
    t = {k: (v[1], v[2]) for k, v in res.items()}
    ref = t["map alone (2000 rates)"][0]
    print(f"\n{'what':36s} {'best':>10s} {'median':>10s} {'ratio to the map alone':>24s}")
    for k, (best, med) in t.items():
        print(f"{k:36s} {best * 1e3:8.1f} ms {med * 1e3:8.1f} ms {best / ref:22.2f}x")
    ds = out["map with its solutions"]
    fam = out["attitude_family across 300 DROs"]
    m = out["srp_map 41 eps x 400 rates, K = 2"]
    print(f"\nsolutions on the standard map: {ds.sizes.get('solution', 0)}, worst residual {float(ds.sol_residual.max()):.2e}")
    print(f"attitude family: {len(fam)} points, folds at x0 = {[round(f['x0'], 8) for f in fam.folds]}, {fam.end_reason}")
    print(f"srp map: {m.sizes.get('branch', 0)} branches, {m.sizes.get('solution', 0)} solutions at grid eps, "
          f"folds at eps = {[round(float(e), 8) for e, f in zip(m.branch_end_eps.values, m.branch_fold.values) if f]}")
    print("\ntargets (issue 11): map with solutions <= 1.3x the map alone; attitude family < 0.5 s; srp_map < 2 s")


if __name__ == "__main__":
    main()
