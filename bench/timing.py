"""Timing helpers shared by the benchmarks (round-robin races, the CPU's name)."""

import platform
import time

import numpy as np


def race(fns, rounds):
    """Call every function once per round, `rounds` times (round-robin, so that a shared
    machine's load affects every entry alike); {name: (last result, best, median)}."""
    times = {k: [] for k in fns}
    out = {}
    for _ in range(rounds):
        for k, fn in fns.items():
            t0 = time.perf_counter()
            out[k] = fn()
            times[k].append(time.perf_counter() - t0)
    return {k: (out[k], min(v), float(np.median(v))) for k, v in times.items()}


def cpu_name() -> str:
    """The CPU model (Linux /proc/cpuinfo), else the platform's word for it."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()
