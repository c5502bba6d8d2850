"""Long jobs on a Dask cluster (issue 22, items 1-2): planar maps, 3-D maps, solves over many
orbits and ephemeris epoch sweeps run as tasks on a LocalCluster of two worker processes, one worker is SIGKILLed in the
middle of each run, and the run completes with arrays bit-identical to the local run (the
reference: the same call with ``scheduler=None``; tolerance: exact equality, NaN = NaN).

A task is committed on arrival, so a lost task (its worker killed, or every worker restarted)
is only submitted again; a run whose scheduler is gone for good stops, and the same call resumes
from the finished parts."""

import os
import signal
import threading
import time

import librate
import numpy as np
import pytest

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib

distributed = pytest.importorskip("distributed")

from librate.app.distribute import Region, Task, run_tasks  # noqa: E402
from librate.results.checksum import value_digest  # noqa: E402

# The scheduler's HTTP server (its routes run even with the dashboard off) on a free port: its
# default, 8787, may still be held by another test's cluster, and the warning that it moved is an
# error under filterwarnings = error.
FREE_HTTP_PORT = {"dashboard_address": ":0"}
X0 = [0.9, 0.87, 0.84, 0.81, 0.78, 0.75, 0.72, 0.69]
KZ = [0.4, 0.8]
WZ = np.linspace(-3, 2, 20000)  # ~0.3 s a row: the kill lands mid-run
BODY = librate.RigidBody(1.0, 1.02, 1.04)
RATES_3D = {"wx0": np.linspace(-0.05, 0.05, 5), "wy0": 0.0, "wz0": np.linspace(1.1, 1.4, 16)}


@pytest.fixture(scope="module")
def fam(em):
    return librate.dro_family(em, x0=X0)


@pytest.fixture(scope="module")
def cluster():
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                      scheduler_kwargs=FREE_HTTP_PORT) as c, Client(c) as client:
        yield c, client


def _n_tasks(client) -> int:
    return client.run_on_scheduler(lambda dask_scheduler: sum(str(k).startswith("librate-") for k in dask_scheduler.tasks))


class Killer(threading.Thread):
    """SIGKILLs one worker process in the middle of a run: once at least one task has been
    committed (forgotten by the scheduler) and while a task is running on that worker."""

    def __init__(self, client, n_tasks: int):
        super().__init__(daemon=True)
        self.client, self.n_tasks, self.killed, self.left = client, n_tasks, None, None
        self.stop = threading.Event()

    def run(self):
        deadline = time.monotonic() + 120
        seen = False
        while not self.stop.is_set() and time.monotonic() < deadline:
            try:
                n = _n_tasks(self.client)
                busy = {w: ks for w, ks in self.client.processing().items() if any(str(k).startswith("librate-") for k in ks)}
            except Exception:  # noqa: BLE001 - the cluster is busy: try again
                time.sleep(0.02)
                continue
            seen = seen or n > 0
            if seen and 0 < n < self.n_tasks and busy:
                worker = next(iter(busy))
                pids = self.client.run(os.getpid, workers=[worker])
                if pids:
                    os.kill(pids[worker], signal.SIGKILL)
                    self.killed, self.left = worker, n
                    return
            time.sleep(0.02)

    def __enter__(self):
        self.start()
        return self

    def __exit__(self, *exc):
        self.stop.set()
        self.join(10)


def _wait_workers(cluster, n=2):
    """Both workers back: a killed one is restarted by its nanny; a nanny that gave up (its
    restart timed out on a loaded machine) is replaced by the cluster."""
    c, client = cluster
    try:
        client.wait_for_workers(n, timeout=60)
    except (TimeoutError, distributed.exceptions.WorkerStartTimeoutError):
        from distributed.core import Status

        for name, nanny in list(c.workers.items()):
            if nanny.status in (Status.closed, Status.closing, Status.failed):
                del c.workers[name]  # the cluster starts a new one for its spec
        c.scale(n)
        client.wait_for_workers(n, timeout=240)


def _same_map(a, b, names):
    for v in names:
        np.testing.assert_array_equal(a[v].values, b[v].values, err_msg=v)


# --- the distribution helper itself ------------------------------------------------------------
def _square(x):
    return {"x": np.asarray(x, dtype=float) ** 2, "n": int(np.size(x))}


def test_tasks_commit_once_each_in_order_locally_and_checksummed_on_a_cluster(cluster):
    """Reference: the values themselves (x**2). Locally the commits come in task order; on the
    cluster every task is committed exactly once, and its arrival digest equals the local one."""
    _, client = cluster
    tasks = [Task(i, _square, (np.arange(i + 1),)) for i in range(6)]
    local, remote = [], {}
    run_tasks(tasks, lambda k, v: local.append((k, v)))
    assert [k for k, _ in local] == list(range(6))
    run_tasks(tasks, lambda k, v: remote.setdefault(k, []).append(v), scheduler=client)
    assert sorted(remote) == list(range(6)) and all(len(v) == 1 for v in remote.values())
    for k, v in local:
        assert value_digest(remote[k][0]) == value_digest(v)
        np.testing.assert_array_equal(remote[k][0]["x"], np.arange(k + 1) ** 2)


def test_value_digest_is_exact_and_refuses_objects():
    a = np.array([1.0, 2.0])
    assert value_digest({"a": a, "n": [1, "x"]}) == value_digest({"n": [1, "x"], "a": a.copy()})
    assert value_digest(a) != value_digest(a.astype(np.float32)) != value_digest(np.nextafter(a, 3))
    assert value_digest(0.0) != value_digest(-0.0)
    with pytest.raises(TypeError, match="cannot checksum"):
        value_digest(object())


def test_a_region_is_written_only_where_the_writers_record_is_seen(tmp_path):
    owner = tmp_path / ".map.zarr.lock.owner"
    owner.write_text("pid 1 on here")
    assert Region(str(tmp_path / "map.zarr"), {}, str(owner), "pid 1 on here").visible()
    assert not Region(str(tmp_path / "map.zarr"), {}, str(owner), "pid 2 on there").visible()
    assert not Region(str(tmp_path / "map.zarr"), {}, str(tmp_path / "absent"), "pid 1 on here").visible()


def _part(i):
    return {"x": np.arange(4.0) + i}


def test_a_written_region_that_does_not_check_out_is_computed_again_and_sent_whole(cluster, tmp_path):
    """Workers that see the writer's record write their regions (reference: the values read back
    from the store); a region the client refuses (ArrivalError) is computed again and arrives
    as data instead, committed once."""
    import zarr
    from librate.app.distribute import ArrivalError

    _, client = cluster
    g = zarr.open_group(str(tmp_path / "s.zarr"), mode="w", zarr_format=2)
    g.create_array("x", shape=(3, 4), chunks=(1, 4), dtype="f8", fill_value=np.nan)
    owner = tmp_path / ".s.zarr.lock.owner"
    owner.write_text("pid 1 on here")
    region = Region(str(tmp_path / "s.zarr"), {"x": "f8"}, str(owner), "pid 1 on here")
    refused, values = [], {}

    def commit_written(k, sums):
        refused.append(k)
        raise ArrivalError(f"part {k} refused")

    run_tasks([Task(i, _part, (i,)) for i in range(3)], values.__setitem__, scheduler=client, region=region, commit_written=commit_written)
    assert sorted(refused) == [0, 1, 2] and sorted(values) == [0, 1, 2]
    for i in range(3):
        np.testing.assert_array_equal(values[i]["x"], np.arange(4.0) + i)
        np.testing.assert_array_equal(g["x"][i], np.arange(4.0) + i)  # what the worker wrote


# --- SIGKILL of a worker mid-run: planar map, 3-D map, solve ---------------------------------------
def _count_written(monkeypatch) -> list:
    """Record the parts committed from a worker's own region write (client side)."""
    from librate.results.store import PartStore

    seen, real = [], PartStore.commit_written

    def spy(self, i, digests):
        ok = real(self, i, digests)
        seen.append((i, ok))
        return ok

    monkeypatch.setattr(PartStore, "commit_written", spy)
    return seen


@pytest.mark.parametrize("store", [False, True], ids=["gathered", "written-by-workers"])
def test_planar_map_survives_a_killed_worker_bit_identically(cluster, fam, tmp_path, store, monkeypatch):
    from librate.app.runner import run_map
    from librate.results.store import verify_store

    _, client = cluster
    _wait_workers(cluster)
    out = tmp_path / "map.zarr" if store else None
    written = _count_written(monkeypatch)
    with Killer(client, len(X0)) as k:
        ds = run_map(fam, kz=KZ, wz0=WZ, scheduler=client, progress=False, out=out)
    assert k.killed is not None, "no worker was killed mid-run"
    ref = run_map(fam, kz=KZ, wz0=WZ, progress=False)
    _same_map(ds, ref, ("dwz", "dphi", "phi_T", "status", "sol_wz0", "sol_phi0", "sol_n"))
    if store:  # every row written by its worker (the same filesystem), checked and committed by the client
        assert verify_store(out).ok and ds.attrs["complete"] == 1
        assert sorted(i for i, ok in written if ok) == list(range(len(X0)))
    else:
        assert written == []


@pytest.mark.parametrize("chunk_cases", ["auto", 16], ids=["task-per-orbit", "task-per-chunk"])
def test_3d_map_survives_a_killed_worker_bit_identically(cluster, fam, tmp_path, monkeypatch, chunk_cases):
    """Per orbit (8 orbits of 80 cases: "auto" keeps one task each, written by the workers) and
    per chunk of 16 cases (5 tasks an orbit, gathered, each orbit committed whole): both equal
    the local map, computed one orbit at a time, bit for bit."""
    from librate.app.map3d_runs import run_map_3d_to
    from librate.results.store import verify_store

    _, client = cluster
    _wait_workers(cluster)
    written = _count_written(monkeypatch)
    kw = dict(body=BODY, rates=RATES_3D, q0=[0.0, 0.0, 0.0, 1.0], tol=1e-10, progress=False)
    with Killer(client, len(X0) * (1 if chunk_cases == "auto" else 5)) as k:
        ds, path = run_map_3d_to(fam, tmp_path / "d" / "map.zarr", scheduler=client, chunk_cases=chunk_cases, **kw)
    assert k.killed is not None, "no worker was killed mid-run"
    assert verify_store(path).ok
    assert sorted(i for i, ok in written if ok) == (list(range(len(X0))) if chunk_cases == "auto" else [])
    ref, _ = run_map_3d_to(fam, tmp_path / "l" / "map.zarr", **kw)
    _same_map(ds, ref, ("residual", "residual_norm", "status"))


def test_3d_map_chunks_locally_give_the_same_bits(fam, tmp_path):
    """A count of cases per task applies locally too (rounded up to the 8 lanes: 20 -> 24);
    reference: the map of one task per orbit (exact equality)."""
    from librate.app.map3d_runs import run_map_3d_to

    kw = dict(body=BODY, rates=RATES_3D, q0=[0.0, 0.0, 0.0, 1.0], tol=1e-10, progress=False)
    a, _ = run_map_3d_to(list(fam)[:2], tmp_path / "a.zarr", chunk_cases=20, **kw)
    b, _ = run_map_3d_to(list(fam)[:2], tmp_path / "b.zarr", chunk_cases=None, **kw)
    _same_map(a, b, ("residual", "residual_norm", "status"))
    with pytest.raises(ValueError, match="`chunk_cases`"):
        run_map_3d_to(list(fam)[:2], tmp_path / "c.zarr", chunk_cases=0, **kw)


@pytest.fixture(scope="module")
def solve_study():
    from librate.app.study import EXAMPLE_STUDY, Study, apply_overrides

    raw = apply_overrides(tomllib.loads(EXAMPLE_STUDY), {"orbits.x0": X0, "rates.wz0.num": 4000, "body.kz": [0.2, 0.5, 0.8]})
    return Study.from_dict(raw, purpose="solve")


def test_solve_survives_a_killed_worker_bit_identically(cluster, solve_study, tmp_path):
    from librate.app.jobs import run_solve

    _, client = cluster
    _wait_workers(cluster)
    with Killer(client, len(X0) * 3) as k:
        ds, _ = run_solve(solve_study, tmp_path / "d", scheduler=client)
    assert k.killed is not None, "no worker was killed mid-run"
    ref, _ = run_solve(solve_study, tmp_path / "l")
    assert ds.sizes["solution"] == ref.sizes["solution"] > 0
    for v in ds.data_vars:
        np.testing.assert_array_equal(ds[v].values, ref[v].values, err_msg=v)


#: The epoch sweep: the 70,000 km DRO at 8 epochs two weeks apart from 2030-01-01 (TDB s past J2000).
SWEEP_EPOCHS = 946728000.0 + 14 * 86400.0 * np.arange(8)


@pytest.mark.slow
def test_ephemeris_epoch_sweep_survives_a_killed_worker_bit_identically(cluster, em, tmp_path, monkeypatch):
    """Issue 22 item 1: each epoch of a transition sweep is one task (written by the workers into
    the store, the same filesystem), a worker SIGKILLed mid-run; the store equals the local
    sweep's bit for bit."""
    from librate.app.transition import run_transition_to
    from librate.results.store import verify_store

    _, client = cluster
    _wait_workers(cluster)
    orbit = librate.correct_dro(em, 0.8057)
    written = _count_written(monkeypatch)
    kw = dict(epochs_tdb=SWEEP_EPOCHS, revolutions=4, nodes_per_rev=8, progress=False)
    with Killer(client, SWEEP_EPOCHS.size) as k:
        ds, path = run_transition_to(orbit, tmp_path / "d" / "transition.zarr", scheduler=client, **kw)
    assert k.killed is not None, "no worker was killed mid-run"
    assert verify_store(path).ok and (ds["status"].values == 0).all()
    assert sorted(i for i, ok in written if ok) == list(range(SWEEP_EPOCHS.size))
    ref, _ = run_transition_to(orbit, tmp_path / "l" / "transition.zarr", **kw)
    _same_map(ds, ref, [v for v in ref.data_vars])


def test_solve_3d_refuses_a_scheduler(tmp_path):
    """A 3-D solve is one sequential continuation: a scheduler is refused before any work (the
    3-D study's type picks the 3-D job; nothing is written)."""
    from librate.app.jobs import run_solve
    from librate.app.study import Study, Study3D

    study = Study.from_dict({"attitude": {"model": "3d", "start": "spin", "n": 0}, "orbits": {"x0": [0.85]},
                             "body": {"ix": 12.12e6, "iy": 89.68e6, "iz": 96.95e6}}, purpose="solve")
    assert isinstance(study, Study3D)
    with pytest.raises(ValueError, match="`scheduler`: a 3-D solve is one continuation"):
        run_solve(study, tmp_path, scheduler="tcp://127.0.0.1:1")
    assert not any(tmp_path.iterdir())


# --- every worker restarted, and a scheduler gone for good ------------------------------------------
@pytest.mark.slow
def test_a_restart_of_every_worker_loses_no_finished_part(cluster, fam, tmp_path):
    """client.restart() mid-run cancels every task in flight (lost tasks): they are submitted
    again, and the store equals the local map bit for bit."""
    from librate.app.runner import run_map

    _, client = cluster
    _wait_workers(cluster)

    restarted = []

    def restart():
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            if 0 < (n := _n_tasks(client)) < len(X0):
                client.restart(wait_for_workers=False)
                restarted.append(n)
                return
            time.sleep(0.02)

    t = threading.Thread(target=restart, daemon=True)
    t.start()
    ds = run_map(fam, kz=KZ, wz0=WZ, scheduler=client, progress=False, out=tmp_path / "map.zarr")
    t.join(30)
    assert restarted, "the workers were not restarted mid-run"
    _same_map(ds, run_map(fam, kz=KZ, wz0=WZ, progress=False), ("dwz", "dphi", "phi_T", "status"))


@pytest.mark.slow
def test_a_scheduler_gone_for_good_stops_the_run_and_the_same_call_resumes(fam, tmp_path):
    """The cluster (scheduler and workers) closed mid-run: the run stops with an error saying
    the finished rows are kept; the same call on a new cluster computes only the rest, and the
    store equals the local map bit for bit."""
    import zarr
    from distributed import Client, LocalCluster
    from librate.app.runner import run_map

    out = tmp_path / "map.zarr"
    c = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None, scheduler_kwargs=FREE_HTTP_PORT)
    client = Client(c, timeout=3)

    def close():
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            try:
                if out.exists() and 0 < int(np.sum(zarr.open_group(str(out), mode="r")["done"][:])) < len(X0):
                    c.close()
                    return
            except Exception:  # noqa: BLE001 - the store is being created
                pass
            time.sleep(0.02)

    t = threading.Thread(target=close, daemon=True)
    t.start()
    try:
        with pytest.raises((ConnectionError, RuntimeError, OSError)):
            run_map(fam, kz=KZ, wz0=WZ, scheduler=client, progress=False, out=out, solve=False)
    finally:
        t.join(30)
        client.close()
        c.close()
    kept = int(np.sum(zarr.open_group(str(out), mode="r")["done"][:]))
    assert 0 < kept < len(X0)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                      scheduler_kwargs=FREE_HTTP_PORT) as c2, Client(c2) as client2:
        ds = run_map(fam, kz=KZ, wz0=WZ, scheduler=client2, progress=False, out=out, solve=False)
    assert ds.attrs["complete"] == 1
    _same_map(ds, run_map(fam, kz=KZ, wz0=WZ, progress=False, solve=False), ("dwz", "dphi", "phi_T", "status"))


# --- the command line: --scheduler ADDRESS for a 3-D map and a solve --------------------------------
def test_cli_map_3d_and_solve_on_a_scheduler_address_equal_the_local_run(cluster, cli, tmp_path):
    """`librate map` (a 3-D study) and `librate solve` (a planar one) with --scheduler given as
    the cluster's address: the stored results equal those of the same commands run locally
    (exact equality of every variable)."""
    from pathlib import Path

    c, _ = cluster
    example = Path(__file__).resolve().parents[1] / "examples" / "study_3d_dro.toml"
    text = example.read_text().replace("# wx0 = {", "wx0 = {").replace("# wy0 = 0.0", "wy0 = 0.0")
    (tmp_path / "m3.toml").write_text(text.replace("num = 101", "num = 5").replace("num = 300", "num = 16"))
    from librate.app.study import EXAMPLE_STUDY

    (tmp_path / "s.toml").write_text(EXAMPLE_STUDY)
    tiny = ("--set", "orbits.x0={start = 0.9, stop = 0.7, num = 4}", "--set", "rates.wz0.num=400")
    for args, name in ((("map", "m3.toml"), "map.zarr"), (("solve", "s.toml", *tiny), "solve.zarr")):
        cli(*args, "--quiet", "--out", "far", "--scheduler", c.scheduler_address)
        cli(*args, "--quiet", "--out", "near")
        far, near = librate.open_result(tmp_path / "far" / name), librate.open_result(tmp_path / "near" / name)
        assert sorted(far.data_vars) == sorted(near.data_vars) and far.sizes == near.sizes
        assert near.sizes.get("solution" if name == "solve.zarr" else "orbit", 0) > 0
        for v in near.data_vars:
            np.testing.assert_array_equal(far[v].values, near[v].values, err_msg=f"{name}: {v}")


def _free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.slow
def test_a_scheduler_restarted_at_its_address_loses_no_finished_part(fam, tmp_path):
    """A scheduler (a `dask scheduler` process at a fixed address) SIGKILLed mid-run and started
    again at the same address, with new workers (the old ones exit with their scheduler): the
    client reconnects, the tasks in flight are submitted again, the rows committed before the
    kill stay, and the store equals the local map bit for bit."""
    import subprocess
    import sys

    import zarr
    from distributed import Client
    from librate.app.runner import run_map

    port = _free_port()
    addr = f"tcp://127.0.0.1:{port}"
    out = tmp_path / "map.zarr"

    def scheduler():
        return subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--port", str(port), "--no-dashboard"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def workers():
        return subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", addr, "--nworkers", "2",
                                 "--nthreads", "1", "--no-dashboard"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    procs = [scheduler()]
    kept = []

    def restart():
        deadline = time.monotonic() + 90
        while time.monotonic() < deadline:
            try:
                n = int(np.sum(zarr.open_group(str(out), mode="r")["done"][:]))
            except Exception:  # noqa: BLE001 - the store is being created
                n = 0
            if 0 < n < len(X0):
                procs[0].kill()
                procs[0].wait()
                kept.append(n)
                procs.append(scheduler())
                procs.append(workers())
                return
            time.sleep(0.01)

    try:
        time.sleep(1.0)
        procs.append(workers())
        with Client(addr, timeout=60) as client:
            client.wait_for_workers(2, timeout=60)
            t = threading.Thread(target=restart, daemon=True)
            t.start()
            ds = run_map(fam, kz=KZ, wz0=WZ, scheduler=client, progress=False, out=out, solve=False)
            t.join(30)
    finally:
        for p in reversed(procs):
            if p.poll() is None:
                p.terminate()
        for p in procs:
            try:
                p.wait(20)
            except subprocess.TimeoutExpired:
                p.kill()
    assert kept, "the scheduler was not killed mid-run"
    assert ds.attrs["complete"] == 1
    _same_map(ds, run_map(fam, kz=KZ, wz0=WZ, progress=False, solve=False), ("dwz", "dphi", "phi_T", "status"))
