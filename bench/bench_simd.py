"""Benchmark: the standard periodicity map at every SIMD level this CPU supports, in one process.

What it measures
    The standard map of bench_map.py (Earth-Moon, the DRO through x0 = 0.70, Kz = 0.8,
    phi0 = 0, 2000 inertial rates in [-3, 2], one period) with the lane engine at the default
    map tolerance, on all cores and on 1 thread, at each level of ``librate.build_info()
    ["simd_available"]`` (``baseline``: SSE2 without FMA; ``avx2``: x86-64-v3; ``avx512``:
    x86-64-v4), switched in this process with ``librate._core.simd_set_active``. The levels run
    round-robin (one call of each per round, so that a shared machine's load affects all alike);
    best and median of the rounds. The forcing table is built once, outside the timings.

Also printed: the largest difference of the residuals (phi(T), wz(T)) between each level and the
first FMA level, relative to max(1, |value|) (the tests bound it by 1e-12).

Targets (issue 13; ratios, not times): baseline no more than 2.5x slower than avx2; for the
portable build against a native one (``-C target-cpu=native``), run this script in both and
compare the active level's time.

How to run
    python bench/bench_simd.py            # 30 rounds
    python bench/bench_simd.py --quick    # 5 rounds
"""
import argparse
import os

import librate
import numpy as np
from librate import _core
from librate.periodicity import MAP_RTOL, orbit_forcing, sweep
from timing import cpu_name, race

X0, KZ, N_RATES = 0.70, 0.8, 2000


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    rounds = 5 if args.quick else 30

    info = librate.build_info()
    levels = info["simd_available"]
    print(f"CPU: {cpu_name()} ({os.cpu_count()} logical cores); librate {info['version']} ({info['profile']} build, "
          f"{info['target_arch']}); levels available: {', '.join(levels)} (active at import: {info['simd_active']})")
    print(f"load average at start: {os.getloadavg()[0]:.2f}")

    em = librate.System.preset("earth-moon")
    orbit = librate.correct_dro(em, X0)
    forcing = orbit_forcing(orbit)
    wz0 = np.linspace(-3.0, 2.0, N_RATES)

    def at(level, threads):
        def call():
            _core.simd_set_active(level)
            return sweep(forcing, orbit.period, 0.0, wz0, KZ, threads=threads)
        return call

    fns = {}
    for level in levels:
        fns[(level, None)] = at(level, None)
        fns[(level, 1)] = at(level, 1)
    for fn in fns.values():
        fn()  # warm-up (thread pool, pages)
    res = race(fns, rounds)
    _core.simd_set_active(info["simd_active"])

    fma = [lv for lv in levels if lv != "baseline"]
    ref_level = fma[0] if fma else levels[0]
    ref = res[(ref_level, None)][0]
    base = "avx2" if "avx2" in levels else ref_level
    t_base = res[(base, None)][1]
    print(f"\nthe standard map ({N_RATES} rates, rtol = atol = {MAP_RTOL:.0e}), best / median of {rounds} rounds:")
    print(f"{'level':10s} {'all cores':>12s} {'1 thread':>12s} {'ratio to ' + base:>16s} {'max rel. diff vs ' + ref_level:>22s}")
    for level in levels:
        r, best, med = res[(level, None)]
        _, best1, med1 = res[(level, 1)]
        d = max(float(np.max(np.abs(r[k] - ref[k]) / np.maximum(1.0, np.abs(ref[k])))) for k in ("phi_t", "wz_t"))
        print(f"{level:10s} {best * 1e3:7.2f} ms ({med * 1e3:5.2f}) {best1 * 1e3:6.2f} ms ({med1 * 1e3:5.2f}) "
              f"{best / t_base:16.2f} {d:22.1e}")
    print(f"load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
