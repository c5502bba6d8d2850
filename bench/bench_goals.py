"""Benchmark: librate's speed goals (issue 22), side by side in one script and one process.

Each goal is a ratio of two times measured here, in the same process, round-robin (one call of
each candidate per round, so that a shared machine's load affects both alike; best of the
rounds), at equal accuracy: each side at the loosest rung of a 1-2-5 tolerance ladder that
meets 2e-10 against a long-double Taylor reference (heyoka at 1e-19; see bench_map.py and
bench_map3d.py for the metrics).

a. the standard map (DRO x0 = 0.70, Kz = 0.8, 2000 rates, one period; the librate engine with its
   orbit forcing table) against heyoka's batch mode (best of batch 4 and 8, 1 and 2 threads, JIT
   excluded): goal >= 4x;
b. the 600k map (100 DROs x 2000 rates x 3 Kz, ``periodicity_map(solve=False)``, forcing tables
   included) against heyoka integrating the same trajectories (the batch size found best in (a),
   1 and 2 threads), at the tolerances chosen in (a): goal >= 4x;
c. the standard map with its solutions against the map alone (``periodicity_map``, default
   tolerances on both sides): goal <= 1.2x;
d. the README's ``srp_map`` (41 eps x 400 rates, K = 2, with its branches) against the map alone:
   goal <= 150x;
e. the 3-D map (2000 trajectories on the 12-day L2 halo, bench_map3d.py's) against heyoka's
   batch mode on the 13-state system: goal >= 4x.

heyoka is not a librate dependency (``pip install heyoka``); without it (a), (b) and (e) are
reported as not measured and (c), (d) are measured. The CPU model (/proc/cpuinfo) and librate's
active SIMD level are printed and stored. No goal is asserted: a missed goal is reported, the
exit status is 0 unless something fails.

AVX2 on an AVX-512 CPU: ``LIBRATE_SIMD=avx2`` restricts librate only; heyoka's JIT still compiles
for AVX-512. ``--no-avx512`` hides AVX-512 from the process's CPUID first (bench/cpu_mask.py, Linux
CPUID faulting), so that both sides run their AVX2 code, as on an AVX2 machine.

    python bench/bench_goals.py [--json FILE]          # the full sizes, a few minutes
    python bench/bench_goals.py --quick [--json FILE]  # CI: 200 rates, 4 DROs x 2000 rates for (b),
                                                       # 400 3-D trajectories; (d) at full size
    python bench/bench_goals.py --smoke --json FILE    # tiny sizes, for tests/test_bench.py
    python bench/bench_goals.py --no-heyoka            # only (c) and (d)
    python bench/bench_goals.py --no-avx512            # both sides at AVX2 (on an AVX-512 CPU)
"""

import argparse
import copy
import json
import math
import os
import platform
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cpu_mask  # noqa: E402

if __name__ == "__main__" and cpu_mask.FLAG in sys.argv[1:]:
    cpu_mask.mask_avx512()  # before numpy, librate and heyoka read the CPU's features

import bench_map as bm  # noqa: E402
import bench_map3d as b3  # noqa: E402
import bench_solve  # noqa: E402
import librate  # noqa: E402
import numpy as np  # noqa: E402
from librate.periodicity import MAP_RTOL, clear_forcing_cache, orbit_forcing, sweep  # noqa: E402
from timing import cpu_name, race  # noqa: E402

hy = bm.hy  # heyoka, or None
TARGET = 2e-10
KZS = (0.3, 0.6, 0.8)

# rates of the standard map, rounds, (DROs, rates) of the large map and its passes, (eps, rates) of
# srp_map, (wx0, wz0) of the 3-D map, its reference trajectories, and the rounds of (c)
SIZES = {
    "full": dict(rates=2000, rounds=15, big=(100, 2000), big_rounds=2, srp=(41, 400), srp_rounds=5, map3d=(40, 50), ref3d=200,
                 rounds3d=10, solve_rounds=200),
    "quick": dict(rates=200, rounds=5, big=(4, 2000), big_rounds=1, srp=(41, 400), srp_rounds=2, map3d=(10, 40), ref3d=40, rounds3d=3,
                  solve_rounds=50),
    "smoke": dict(rates=48, rounds=2, big=(2, 48), big_rounds=1, srp=(6, 50), srp_rounds=1, map3d=(4, 8), ref3d=8, rounds3d=1,
                  solve_rounds=2),
}


def loosest(label, ladder, acc_of):
    """The loosest rung of ``ladder`` whose accuracy meets TARGET (else the tightest): (tol, acc)."""
    for tol in ladder:
        acc = acc_of(tol)
        print(f"  {label} rtol = atol = {tol:.0e}: accuracy {acc:.2e}")
        if acc <= TARGET:
            return tol, acc
    print(f"  NOTE: no {label} tolerance met {TARGET:.0e}; using the tightest")
    return tol, acc


def goal(what, ratio, sense, value, **details):
    met = None if ratio is None else (ratio >= value if sense == ">=" else ratio <= value)
    return dict(what=what, ratio=ratio, goal=f"{sense} {value:g}x", met=met, **details)


def not_measured(what, sense, value):
    return goal(what, None, sense, value,
                note="heyoka not installed (pip install heyoka)" if bm.hy is None else "heyoka left out (--no-heyoka)")


def heyoka_configs(make, states, tol, n_threads=(1, 2)):
    """{name: (integrators, states, batch)} for batch 4 and 8 (compact mode off), 1 and 2 threads;
    ``make(tol, batch)`` returns an integrator, ``states(batch)`` the batched initial states."""
    out = {}
    for batch in (4, 8):
        ta = make(tol, batch)
        tas = [ta, copy.deepcopy(ta)]
        for nt in n_threads:
            out[f"heyoka batch {batch}, {nt} thread{'s' if nt > 1 else ''}"] = (tas[:nt], states(batch), batch)
    return out


def standard_map(sz):
    """(a): the standard map against heyoka's batch mode."""
    what = f"the standard map (DRO x0 {bm.X0}, Kz {bm.KZ}, {sz['rates']} rates) against heyoka's batch mode"
    if sz["rates"] != 2000:
        what += " (smaller: the goal is for 2000 rates)"
    em = librate.System.preset("earth-moon")
    orbit = librate.dro(em, x0=bm.X0)
    T, wz0 = orbit.period, np.linspace(*bm.WZ_RANGE, sz["rates"])
    ref = bm.reference(em.mu, orbit.state0, T, wz0, bm.KZ)[0]

    def table():
        clear_forcing_cache()
        return orbit_forcing(orbit)

    _, t_table = bm.timed(table, 5)
    forcing = table()

    def lib(tol, threads=None):
        return sweep(forcing, T, bm.PHI0, wz0, bm.KZ, rtol=tol, atol=tol, threads=threads)

    def lib_acc(tol):
        r = lib(tol)
        return bm.accuracy(r["phi_t"], r["wz_t"], ref)

    lib(1e-12)  # warm-up (thread pool)
    lib_tol, lib_acc = loosest("librate", bm.LADDER, lib_acc)
    hy.llvm_state.set_diskcache_enabled(False)
    hyr = bm.HeyokaRunner(em.mu, orbit.state0, T, bm.KZ)

    def hy_acc(tol):
        return bm.accuracy(*[v[:len(wz0)] for v in hyr.run([hyr.integrator(tol, 8, False)[0]], hyr.states(wz0, 8))], ref)

    hy_tol, hy_acc_ = loosest("heyoka", bm.LADDER, hy_acc)
    cfg = heyoka_configs(lambda tol, b: hyr.integrator(tol, b, False)[0], lambda b: hyr.states(wz0, b), hy_tol)
    cands = {"librate, all cores": lambda: lib(lib_tol), "librate, 1 thread": lambda: lib(lib_tol, threads=1)}
    cands.update({k: (lambda tas=tas, st=st: hyr.run(tas, st)) for k, (tas, st, _) in cfg.items()})
    res = race(cands, sz["rounds"])
    t_lib, lib_name = min((v[1], k) for k, v in res.items() if k.startswith("librate"))
    t_hy, hy_name = min((v[1], k) for k, v in res.items() if k.startswith("heyoka"))
    acc_hy = bm.accuracy(*[v[:len(wz0)] for v in res[hy_name][0]], ref)
    ratio = t_hy / (t_lib + t_table)
    print(f"  librate best: {lib_name}, {t_lib * 1e3:.2f} ms + forcing table {t_table * 1e3:.2f} ms (tol {lib_tol:.0e}, accuracy "
          f"{lib_acc:.2e}); heyoka best: {hy_name}, {t_hy * 1e3:.2f} ms (tol {hy_tol:.0e}, accuracy {acc_hy:.2e}, JIT excluded)")
    out = goal(what, ratio, ">=", 4, librate_s=t_lib + t_table, heyoka_s=t_hy, librate_tol=lib_tol, heyoka_tol=hy_tol,
               librate_accuracy=lib_acc, heyoka_accuracy=acc_hy, librate_config=lib_name, heyoka_config=hy_name)
    batch = cfg[hy_name][2]
    return out, dict(em=em, lib_tol=lib_tol, hy_tol=hy_tol, hy_cfg={k: v for k, v in cfg.items() if v[2] == batch})


def large_map(sz, std):
    """(b): the large map against heyoka on the same trajectories (the best configuration of (a))."""
    n_orb, n_rates = sz["big"]
    n = n_orb * n_rates * len(KZS)
    what = f"the {n:,} map ({n_orb} DROs x {n_rates} rates x {len(KZS)} Kz) against heyoka's throughput"
    if n_orb < 100 or n_rates < 2000:
        what += " (a sample: the goal is for 100 DROs x 2000 rates)"
    em, tol, cfg = std["em"], std["lib_tol"], std["hy_cfg"]
    batch = next(iter(cfg.values()))[2]
    fam = librate.dro_family(em, x0=np.linspace(0.95, 0.2, n_orb))
    wz0 = np.linspace(*bm.WZ_RANGE, n_rates)
    runners = [bm.HeyokaRunner(em.mu, o.state0, o.period, KZS[0]) for o in fam]
    states = [r.states(wz0, batch) for r in runners]

    def lib():
        clear_forcing_cache()  # every orbit's forcing table included
        return librate.periodicity_map(fam, kz=list(KZS), wz0=wz0, solve=False, rtol=tol, atol=tol)

    def heyoka(tas):
        for r, st in zip(runners, states):
            for kz in KZS:
                for ta in tas:
                    ta.pars[:] = kz
                r.run(tas, st)

    lib()  # warm-up (first-call costs of the Dataset)
    cands = {"librate": lib}
    cands.update({k: (lambda tas=tas: heyoka(tas)) for k, (tas, _, _) in cfg.items()})
    res = race(cands, sz["big_rounds"])
    t_lib = res["librate"][1]
    t_hy, hy_name = min((v[1], k) for k, v in res.items() if k.startswith("heyoka"))
    bad = int((res["librate"][0]["status"].values != 0).sum())
    print(f"  librate periodicity_map: {t_lib:.2f} s = {n / t_lib:,.0f} traj/s (tol {tol:.0e}, {bad} not ok); heyoka best "
          f"({hy_name}, tol {std['hy_tol']:.0e}): {t_hy:.2f} s = {n / t_hy:,.0f} traj/s")
    return goal(what, t_hy / t_lib, ">=", 4, librate_s=t_lib, heyoka_s=t_hy, trajectories=n, librate_tol=tol,
                heyoka_tol=std["hy_tol"], heyoka_config=hy_name, note="tolerances chosen on the standard map (a)")


def solve_costs(sz):
    """(c) and (d): the map with its solutions and the README's srp_map, against the map alone."""
    n_eps, n_srp = sz["srp"]
    rates = 2000 if sz["rates"] >= 200 else sz["rates"]
    fns = bench_solve.workloads(n_rates=rates, n_eps=n_eps, n_srp_rates=n_srp, family=False)
    (k_map, f_map), (k_sol, f_sol), (k_srp, f_srp) = fns.items()
    # 3-ms calls, each side's best of many rounds (0.03-0.1 ms of scheduling noise in a 15-round best: 1.15-1.25x)
    res = race({k_map: f_map, k_sol: f_sol}, sz["solve_rounds"])
    res_srp = race({k_map: f_map, k_srp: f_srp}, sz["srp_rounds"])
    t_map = min(res[k_map][1], res_srp[k_map][1])
    t_sol, t_srp = res[k_sol][1], res_srp[k_srp][1]
    print(f"  {k_map}: {t_map * 1e3:.2f} ms; with its solutions {t_sol * 1e3:.2f} ms; {k_srp}: {t_srp:.2f} s")
    sample = "" if (n_eps, n_srp) == (41, 400) else " (a sample: the goal is for 41 eps x 400 rates)"
    return (goal(f"the map with its solutions against the map alone ({rates} rates)", t_sol / t_map, "<=", 1.2, map_s=t_map,
                 with_solutions_s=t_sol, solutions=int(res[k_sol][0].sizes.get("solution", 0))),
            goal(f"the README's srp_map ({n_eps} eps x {n_srp} rates, K = 2) against the map alone{sample}", t_srp / t_map, "<=",
                 150, map_s=t_map, srp_map_s=t_srp, branches=int(res_srp[k_srp][0].sizes.get("branch", 0))))


def map_3d(sz):
    """(e): the 3-D map against heyoka's batch mode (13 states)."""
    from librate import _core  # the engine, as bench_map3d.py times it

    nx, nz = sz["map3d"]
    em, halo, w0 = b3.problem(nx, nz)
    T, n = halo.period, len(w0)
    what = f"the 3-D map ({n} trajectories on the {b3.PERIOD_DAYS:g}-day L2 halo) against heyoka"
    if n != 2000:
        what += " (smaller: the goal is for 2000)"
    idx = np.unique(np.linspace(0, n - 1, sz["ref3d"]).round().astype(int))
    ref = b3.reference(em.mu, halo.state0, T, w0, idx)[0]
    args = (em.mu, [float(v) for v in halo.state0], float(T))
    table, t_table = bm.timed(lambda: _core.TidalTable(*args, tol=1e-13), 5)
    q0, inertia = np.tile([0.0, 0.0, 0.0, 1.0], (n, 1)), np.tile(b3.BODY, (n, 1))

    def lib(tol, threads=None):
        return _core.map_sweep_3d(table, float(T), q0, w0, inertia, lanes=_core.LaneOptions(rtol=tol, atol=tol, threads=threads))

    def lib_acc(tol):
        r = lib(tol)
        return b3.accuracy(r.q_t[idx], r.w_t[idx], ref)

    lib(1e-10)  # warm-up
    lib_tol, lib_acc = loosest("librate", bm.LADDER, lib_acc)
    hyr = b3.HeyokaRunner(em.mu, halo.state0, T)

    def hy_acc(tol):
        q, w = hyr.run([hyr.integrator(tol, 8)[0]], hyr.states(w0, 8), n)
        return b3.accuracy(q[idx], w[idx], ref)

    hy_tol, _ = loosest("heyoka", bm.LADDER, hy_acc)
    cfg = heyoka_configs(lambda tol, b: hyr.integrator(tol, b)[0], lambda b: hyr.states(w0, b), hy_tol)
    cands = {"librate, all cores": lambda: lib(lib_tol), "librate, 1 thread": lambda: lib(lib_tol, threads=1)}
    cands.update({k: (lambda tas=tas, st=st: hyr.run(tas, st, n)) for k, (tas, st, _) in cfg.items()})
    res = race(cands, sz["rounds3d"])
    t_lib, lib_name = min((v[1], k) for k, v in res.items() if k.startswith("librate"))
    t_hy, hy_name = min((v[1], k) for k, v in res.items() if k.startswith("heyoka"))
    acc_hy = b3.accuracy(res[hy_name][0][0][idx], res[hy_name][0][1][idx], ref)
    print(f"  librate best: {lib_name}, {t_lib * 1e3:.2f} ms + tidal table {t_table * 1e3:.2f} ms (tol {lib_tol:.0e}, accuracy "
          f"{lib_acc:.2e} on {len(idx)}); heyoka best: {hy_name}, {t_hy * 1e3:.2f} ms (tol {hy_tol:.0e}, accuracy {acc_hy:.2e})")
    return goal(what, t_hy / (t_lib + t_table), ">=", 4, librate_s=t_lib + t_table, heyoka_s=t_hy, librate_tol=lib_tol,
                heyoka_tol=hy_tol, librate_accuracy=lib_acc, heyoka_accuracy=acc_hy, librate_config=lib_name, heyoka_config=hy_name)


def table(goals):
    print(f"\n{'':3s}{'what':<100s} {'ratio':>8s} {'goal':>8s}  result")
    for key, g in goals.items():
        r = "n/a" if g["ratio"] is None else f"{g['ratio']:.2f}x"
        met = "not measured: " + g.get("note", "") if g["met"] is None else ("met" if g["met"] else "NOT MET")
        print(f"{key}. {g['what']:<100s} {r:>8s} {g['goal']:>8s}  {met}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--quick", action="store_true", help="smaller sizes, under a minute on 2 cores (CI)")
    mode.add_argument("--smoke", action="store_true", help="tiny sizes, for the tests")
    ap.add_argument("--json", metavar="FILE", help="also write the results as JSON")
    ap.add_argument("--no-heyoka", action="store_true", help="the librate-only ratios (c, d), as without heyoka")
    ap.add_argument(cpu_mask.FLAG, action="store_true",
                    help="hide AVX-512 from CPUID (bench/cpu_mask.py): librate and heyoka's JIT both see an AVX2 CPU")
    args = ap.parse_args(argv)
    if args.no_avx512 and not cpu_mask.masked():
        ap.error(f"{cpu_mask.FLAG} hides AVX-512 when this script starts, before its imports: give it on the command line")
    heyoka = None if args.no_heyoka else hy
    name = "quick" if args.quick else "smoke" if args.smoke else "full"
    sz = SIZES[name]
    info = librate.build_info()
    cpu = cpu_name()
    load0 = os.getloadavg()
    print(f"librate {librate.__version__} ({info['profile']} build), heyoka "
          f"{heyoka.__version__ if heyoka else 'not used' if hy else 'not installed'}, python {platform.python_version()}, {name} sizes")
    print(f"CPU: {cpu}, {os.cpu_count()} cores, librate SIMD level {info['simd_active']}; load average {load0[0]:.2f}")
    if cpu_mask.masked():
        print("AVX-512 hidden from CPUID (bench/cpu_mask.py): librate and heyoka's JIT both see an AVX2 CPU")
    print(f"equal accuracy: each side at the loosest tolerance meeting {TARGET:.0e} (map default rtol {MAP_RTOL:.0e} in c, d)")
    t0 = time.perf_counter()
    goals = {}
    if heyoka is not None:
        print("\n[a] standard map")
        goals["a"], std = standard_map(sz)
        print("\n[b] large map")
        goals["b"] = large_map(sz, std)
    else:
        print(f"\nheyoka {'left out (--no-heyoka)' if args.no_heyoka else 'is not installed (pip install heyoka)'}: goals a, b "
              "and e are not measured")
        goals["a"] = not_measured("the standard map against heyoka's batch mode", ">=", 4)
        goals["b"] = not_measured("the 600k map against heyoka's throughput", ">=", 4)
    print("\n[c, d] solutions and srp_map against the map alone")
    goals["c"], goals["d"] = solve_costs(sz)
    if heyoka is not None:
        print("\n[e] 3-D map")
        goals["e"] = map_3d(sz)
    else:
        goals["e"] = not_measured("the 3-D map against heyoka", ">=", 4)
    for g in goals.values():
        if g["ratio"] is not None and not (math.isfinite(g["ratio"]) and g["ratio"] > 0):
            raise RuntimeError(f"a ratio is not a positive finite number: {g}")
    table(goals)
    load1 = os.getloadavg()
    print(f"\n{time.perf_counter() - t0:.1f} s; load average {load0[0]:.2f} at start, {load1[0]:.2f} at end (a shared machine "
          "slows both sides of a ratio alike, round-robin, but not exactly)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(dict(cpu=cpu, cores=os.cpu_count(), simd=info["simd_active"], avx512_hidden=cpu_mask.masked(), build=info,
                           librate=librate.__version__, heyoka=heyoka.__version__ if heyoka else None, sizes=name,
                           accuracy_target=TARGET, load_average=[load0[0], load1[0]],
                           goals=goals), f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
