"""The worker pool's binding to CPUs (librate_core::threads, LIBRATE_BIND_THREADS).

Reference: the rule of docs/numerics.md ("Threads"): `auto` binds worker i to the i-th allowed
CPU only when the pool has one worker per allowed CPU (at least two); `on` binds worker i to
allowed CPU i mod n; `off` never binds. Checked in fresh interpreters (the pool starts once per
process, at import), against the kernel's own record of each thread's CPUs (/proc, Linux).
Exact: CPU numbers and counts.
"""

import json
import os
import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="CPU binding is Linux-only")

PROBE = r"""
import json, os
import numpy  # its own threads first
n_before = len(os.listdir("/proc/self/task"))
import librate
from librate.periodicity import orbit_forcing
imported = len(os.listdir("/proc/self/task")) - n_before, librate.build_info()["threads_started"]
# the first parallel work starts the pool
orbit_forcing(librate.dro(librate.System.preset("earth-moon"), x0=0.7))
b = librate.build_info()
assert b["threads_started"]
# every thread's allowed CPUs, as the kernel reports them (the pool's workers included)
lists = []
for tid in os.listdir("/proc/self/task"):
    with open(f"/proc/self/task/{tid}/status") as f:
        for line in f:
            if line.startswith("Cpus_allowed_list:"):
                lists.append(line.split(":", 1)[1].strip())
keys = ("threads", "threads_binding", "threads_cpus", "threads_bound")
print(json.dumps({k: b[k] for k in keys} | {"lists": lists, "imported": imported}))
"""


def probe(**env):
    e = {k: v for k, v in os.environ.items() if k not in ("LIBRATE_BIND_THREADS", "RAYON_NUM_THREADS")}
    e.update(env)
    r = subprocess.run([sys.executable, "-c", PROBE], env=e, capture_output=True, text=True, timeout=120)
    return r


def ok(**env):
    r = probe(**env)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


ALLOWED = sorted(os.sched_getaffinity(0))


def test_auto_binds_one_worker_per_allowed_cpu():
    if len(ALLOWED) >= 2:
        # a pool of one worker per allowed CPU: worker i on the i-th allowed CPU
        b = ok(RAYON_NUM_THREADS=str(len(ALLOWED)))
        assert b["threads_binding"] == "auto"
        assert b["threads_cpus"] == ALLOWED and b["threads_bound"] == len(ALLOWED)
        # the kernel has exactly these threads on one CPU each
        assert sorted(int(x) for x in b["lists"] if x.isdigit()) == ALLOWED
    # the default pool (one worker per CPU the process may use) follows the same rule
    b = ok()
    if b["threads"] == len(ALLOWED) >= 2:
        assert b["threads_cpus"] == ALLOWED and b["threads_bound"] == len(ALLOWED)
    else:  # sized otherwise (a CPU quota below the affinity mask, or one CPU): left to the kernel
        assert b["threads_cpus"] == [] and b["threads_bound"] == 0


def test_auto_leaves_a_narrowed_pool_to_the_kernel():
    b = ok(RAYON_NUM_THREADS="1")
    assert b["threads"] == 1 and b["threads_cpus"] == [] and b["threads_bound"] == 0
    assert not any(x.isdigit() for x in b["lists"]) or len(ALLOWED) == 1


def test_off_never_binds_and_on_binds_round_robin():
    b = ok(LIBRATE_BIND_THREADS="off")
    assert b["threads_binding"] == "off" and b["threads_cpus"] == [] and b["threads_bound"] == 0
    b = ok(LIBRATE_BIND_THREADS="on", RAYON_NUM_THREADS="3")
    want = [ALLOWED[i % len(ALLOWED)] for i in range(3)]
    assert b["threads_binding"] == "on" and b["threads_cpus"] == want and b["threads_bound"] == 3


def test_the_pool_starts_with_the_first_parallel_work_so_a_fork_after_import_works():
    # importing starts no thread (a pool started at import would be missing in a forked child,
    # whose first parallel call would then wait forever)
    assert ok()["imported"] == [0, False]
    code = """
import os, librate
from librate.periodicity import orbit_forcing
pid = os.fork()
if pid == 0:
    orbit_forcing(librate.dro(librate.System.preset("earth-moon"), x0=0.7))
    os._exit(0)
_, st = os.waitpid(pid, 0)
print(os.WEXITSTATUS(st))
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and r.stdout.strip() == "0", r.stderr


def test_an_invalid_binding_fails_the_import_naming_the_variable():
    r = probe(LIBRATE_BIND_THREADS="cores")
    assert r.returncode != 0
    assert "ValueError" in r.stderr and "LIBRATE_BIND_THREADS" in r.stderr and "auto, on or off" in r.stderr
