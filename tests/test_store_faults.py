"""Fault injection on the resumable map store (issue 12, "Trust the results").

Every case ends either bit-identical to an uninterrupted run or in a refusal that names the
damage:

* kills: a real SIGKILL before every write of the finalisation (the solution table, the root
  attributes, the consolidated metadata), before a sample of the earlier writes (creation,
  rows), and twice in a row (the resume killed too). Regression for issue 12 #1: a kill just
  after the first ``sol_*`` array left a store refused forever as "not a librate map store".
* two writers: a second writer is refused with a message naming the first one's pid (#2).
* corruption: deleted, truncated, bit-flipped and garbage chunks of every kind of array,
  deleted or garbled metadata. ``verify_map_store`` / ``librate verify`` /
  ``open_result(verify=True)`` name the damaged chunk or array, a resume recomputes the damaged
  rows (never a NaN row with ``complete = 1``) and repairs coordinates and solutions (#3).

The map is small (2 orbits x 1 Kz x 40 rates) so that the whole file runs in about half a
minute: the kills fork one process per case from a driver that has imported librate once.
"""

import json
import os
import shutil
import subprocess
import sys
import textwrap
import time
import warnings
import zlib
from pathlib import Path

import librate
import numpy as np
import pytest
from librate.app.runner import run_map
from librate.results import StoreBusyError, writer_lock
from librate.results import verify_store as verify_map_store

ROW_VARS = ("dwz", "dphi", "phi_T", "status")

X0 = [0.9, 0.85]
KZ = [0.8]
WZ = np.linspace(-1.0, 1.5, 40)

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="SIGKILL and fork")

#: The faults here are process deaths (SIGKILL, SIGINT), races and damaged files, never a power
#: loss: a killed process's writes are in the page cache and survive it, so the writers' fsyncs
#: (about 60% of a small map's run time) are no-ops here and in the kill drivers. The order of
#: writes, renames and deletes, which the kills cut, is unchanged.
NO_FSYNC = "os.fsync = lambda fd: None  # a SIGKILL keeps the page cache (see NO_FSYNC in the test module)"


@pytest.fixture(scope="module", autouse=True)
def no_fsync():
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(os, "fsync", lambda fd: None)
        yield


@pytest.fixture(scope="module")
def fam(em):
    return librate.dro_family(em, x0=X0)


@pytest.fixture(scope="module")
def reference(fam):
    """The uninterrupted, in-memory map."""
    return run_map(fam, kz=KZ, wz0=WZ, progress=False)


@pytest.fixture(scope="module")
def good_store(fam, tmp_path_factory):
    out = tmp_path_factory.mktemp("good") / "map.zarr"
    run_map(fam, kz=KZ, wz0=WZ, out=out, progress=False)
    assert verify_map_store(out).ok
    return out


def _same(ds, ref):
    for v in (*ROW_VARS, *(k for k in ref.data_vars if k.startswith("sol_"))):
        np.testing.assert_array_equal(np.asarray(ds[v].values), np.asarray(ref[v].values), err_msg=v)
    assert int(ds.attrs["complete"]) == 1


def _resume_is_identical(out, fam, ref):
    """Resume the store at ``out``: the result and the store itself equal the reference, and
    the store verifies."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # "damaged rows are recomputed"
        ds = run_map(fam, kz=KZ, wz0=WZ, out=out, progress=False)
    _same(ds, ref)
    back = librate.open_result(out, verify=True)  # raises ValueError naming any damage
    try:
        _same(back, ref)
        assert "row_checksum" not in back.variables
    finally:
        back.close()


# ---------------------------------------------------------------------------------------------
# Kills: a driver imports librate once and forks one child per case; the child counts the
# store's writes (and deletes) and SIGKILLs itself just before write number `kill_at`.

DRIVER = textwrap.dedent("""
    import json, os, signal, sys
    import numpy as np
    import threading
    import librate, tqdm.auto, xarray, zarr  # noqa: F401 - imported once, before the forks
    from librate.app.runner import run_map

    # xarray's first Dataset operations load its plugins (most of a child's time otherwise);
    # nothing here may start a thread (a forked child would lack it)
    xarray.Dataset({{"a": ("x", [1.0])}}).merge(xarray.Dataset({{"b": ("x", [2.0])}}))
    xarray.backends.list_engines()
    assert threading.active_count() == 1, threading.enumerate()
    {NO_FSYNC}

    X0, KZ, WZ = {X0!r}, {KZ!r}, np.linspace(-1.0, 1.5, 40)

    def child(out, kill_at):
        from zarr.storage import LocalStore
        n = {{"n": 0, "final": None}}
        real_set, real_del = LocalStore.set, LocalStore.delete
        def tick(key):
            n["n"] += 1
            if n["final"] is None and key.startswith("sol_"):
                n["final"] = n["n"]
            if n["n"] == kill_at:
                os.kill(os.getpid(), signal.SIGKILL)
        async def set_(self, key, value):
            tick(key)
            return await real_set(self, key, value)
        async def del_(self, key):
            tick(key)
            return await real_del(self, key)
        LocalStore.set, LocalStore.delete = set_, del_
        fam = librate.dro_family(librate.System.preset("earth-moon"), x0=X0)
        run_map(fam, kz=KZ, wz0=WZ, out=out, progress=False)
        return n

    def fork(out, kill_at):
        pid = os.fork()
        if pid == 0:
            try:
                n = child(out, kill_at)
                with open(out + ".count.json", "w") as f:
                    json.dump(n, f)
            finally:
                os._exit(0)
        _, st = os.waitpid(pid, 0)
        return os.WIFSIGNALED(st) and os.WTERMSIG(st) == signal.SIGKILL

    root, cases = sys.argv[1], json.loads(sys.argv[2])
    res = []
    for name, kills in cases:
        out = os.path.join(root, name, "map.zarr")
        res.append([name, [fork(out, k) for k in kills]])
    print(json.dumps(res))
""").format(X0=X0, KZ=KZ, NO_FSYNC=NO_FSYNC)


def _drive(root: Path, cases, workers: int = 2):
    """Run the driver on ``cases`` [(name, [kill_at, ...]), ...] (one store per name, the kills
    applied in turn: the second one kills the resume), split over ``workers`` driver processes;
    returns {name: [killed, ...]}."""
    parts = [cases[i::workers] for i in range(workers) if cases[i::workers]]
    procs = [subprocess.Popen([sys.executable, "-c", DRIVER, str(root), json.dumps(p)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)
             for p in parts]
    out = {}
    for proc in procs:
        stdout, stderr = proc.communicate(timeout=300)
        assert proc.returncode == 0, stderr[-3000:]
        out.update((n, k) for n, k in json.loads(stdout.strip().splitlines()[-1]))
    return out


@pytest.fixture(scope="module")
def write_counts(tmp_path_factory):
    """The number of store writes of an uninterrupted run, and the first one of the solution
    table (where the finalisation starts)."""
    root = tmp_path_factory.mktemp("count")
    _drive(root, [("calib", [0])])
    n = json.loads((root / "calib" / "map.zarr.count.json").read_text())
    assert n["final"] is not None and 10 < n["final"] < n["n"]
    return n["n"], n["final"]


def test_kill_before_every_finalisation_write_and_sampled_earlier_writes(tmp_path, fam, reference, write_counts):
    """SIGKILL before each write from the last row's flag to the consolidated metadata (every
    pair of finalisation writes), and before every 10th earlier write (creation and rows): each
    store resumes to the uninterrupted result, bit for bit. Before the fix the kills after the
    first sol_* array made the store unusable ("not a librate map store")."""
    total, final = write_counts
    kills = sorted(set(range(final - 2, total + 1)) | set(range(1, final - 2, 10)))
    res = _drive(tmp_path, [(f"k{k}", [k]) for k in kills])
    assert all(res[f"k{k}"] == [True] for k in kills), res
    t0 = time.perf_counter()
    for k in kills:
        _resume_is_identical(tmp_path / f"k{k}" / "map.zarr", fam, reference)
    print(f"resumes: {time.perf_counter() - t0:.1f} s")
    print(f"kill cases: {len(kills)} ({total - final + 3} in the finalisation)")


def test_kill_the_resume_too(tmp_path, fam, reference, write_counts):
    """Killed once, then killed again while resuming (at its start, during its rows and during
    its finalisation), then resumed: identical."""
    total, final = write_counts
    rng = np.random.default_rng(12)
    pairs = [(int(a), int(b)) for a, b in zip(rng.integers(final - 12, total + 1, 6), (1, 2, 3, 8, 15, 25))]
    res = _drive(tmp_path, [(f"k{a}_{b}", [a, b]) for a, b in pairs])
    for a, b in pairs:
        assert res[f"k{a}_{b}"][0], res
        _resume_is_identical(tmp_path / f"k{a}_{b}" / "map.zarr", fam, reference)


def test_after_a_kill_at_the_end_no_resume_says_what_to_do(tmp_path, fam, write_counts):
    """Issue 12 #1: after a kill in the finalisation, a run with resume=False is refused for
    what the folder is (this map, resumable), not as "not a librate map store"."""
    total, final = write_counts
    _drive(tmp_path, [("end", [final + 1])])
    with pytest.raises(ValueError, match="already holds this map; pass resume=True"):
        run_map(fam, kz=KZ, wz0=WZ, out=tmp_path / "end" / "map.zarr", progress=False, resume=False)


# ---------------------------------------------------------------------------------------------
# Two writers


def test_second_writer_is_refused_naming_the_first(tmp_path, fam, reference):
    """Issue 12 #2: while one process writes a store, another is refused with the first one's
    pid; the store is untouched and later completes identically."""
    out = tmp_path / "map.zarr"
    with writer_lock(out):
        script = textwrap.dedent(f"""
            import numpy as np, librate
            from librate.app.runner import run_map
            fam = librate.dro_family(librate.System.preset("earth-moon"), x0={X0!r})
            run_map(fam, kz={KZ!r}, wz0=np.linspace(-1.0, 1.5, 40), out={str(out)!r}, progress=False)
        """)
        proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
        assert proc.returncode != 0
        assert f"being written by another librate process (pid {os.getpid()}" in proc.stderr
        assert "StoreBusyError" in proc.stderr
        with pytest.raises(StoreBusyError, match=f"pid {os.getpid()}"):
            run_map(fam, kz=KZ, wz0=WZ, out=out, progress=False)
        assert not out.exists()
    _resume_is_identical(out, fam, reference)


def test_two_writers_started_together(tmp_path, fam):
    """Two real processes on one folder at once (the issue's two `librate map` 1.5 s apart):
    one writes, the other is refused naming a pid (or, if it started after the first had
    finished, resumes the complete store); the store ends complete and verified, equal to an
    uninterrupted run."""
    out = tmp_path / "map.zarr"
    wz = np.linspace(-3, 2, 1500)
    script = textwrap.dedent(f"""
        import numpy as np, librate
        from librate.app.runner import run_map
        fam = librate.dro_family(librate.System.preset("earth-moon"), x0={X0!r})
        run_map(fam, kz={KZ!r}, wz0=np.linspace(-3, 2, 1500), out={str(out)!r}, progress=False)
    """)
    procs = [subprocess.Popen([sys.executable, "-c", script], stderr=subprocess.PIPE, text=True) for _ in range(2)]
    errs = [p.communicate(timeout=120)[1] for p in procs]
    codes = [p.returncode for p in procs]
    assert 0 in codes, errs
    for code, err in zip(codes, errs):
        if code != 0:
            assert "being written by another librate process (pid " in err, err
    assert verify_map_store(out).ok
    ref = run_map(fam, kz=KZ, wz0=wz, progress=False)
    ds = run_map(fam, kz=KZ, wz0=wz, out=out, progress=False)
    _same(ds, ref)


# ---------------------------------------------------------------------------------------------
# Corruption

FAULTS = ("delete", "truncate", "bitflip", "bitflip_last", "garbage")


def _damage(path: Path, how: str, seed: int) -> None:
    rng = np.random.default_rng(seed)
    data = bytearray(path.read_bytes())
    if how == "delete":
        path.unlink()
    elif how == "truncate":
        path.write_bytes(bytes(data[: len(data) // 2]))
    elif how in ("bitflip", "bitflip_last"):
        i = len(data) - 1 if how == "bitflip_last" else int(rng.integers(len(data)))
        data[i] ^= 1 << int(rng.integers(8))
        path.write_bytes(bytes(data))
    else:
        path.write_bytes(rng.bytes(len(data)))


def _copy(good: Path, tmp_path: Path) -> Path:
    out = tmp_path / "map.zarr"
    shutil.copytree(good, out)
    return out


def _raw_equal(out: Path, good: Path, name: str) -> bool:
    """Whether array ``name`` still reads (raw, through zarr) exactly as in the intact store."""
    import zarr

    try:
        a = zarr.open_group(str(out), mode="r", use_consolidated=False)[name][...]
    except Exception:  # noqa: BLE001
        return False
    b = zarr.open_group(str(good), mode="r", use_consolidated=False)[name][...]
    return np.array_equal(a, b, equal_nan=a.dtype.kind == "f")


LAST = len(X0) - 1
ROW_CHUNKS = [("dwz/0.0.0", 0)] + [(f"{k}/{LAST}.0.0", LAST) for k in ROW_VARS] + [(f"row_checksum/{LAST}.0", LAST), (f"done/{LAST}", LAST)]


@pytest.mark.parametrize("how", FAULTS)
@pytest.mark.parametrize("key,row", ROW_CHUNKS, ids=[k for k, _ in ROW_CHUNKS])
def test_damaged_row_chunk_is_named_and_recomputed(tmp_path, fam, reference, good_store, key, row, how):
    """Issue 12 #3: a deleted, truncated, bit-flipped or garbage chunk of a row is named by
    `verify` (the chunk and the row), refused by open_result(verify=True), and recomputed by a
    resume (before: exit 0 with a NaN row and complete = 1, an undetected flip, a raw blosc
    error, or an xarray dimension error for phi_T). A flip that decodes to the same values
    (none of these seeds) would be harmless and is accepted as such."""
    out = _copy(good_store, tmp_path)
    _damage(out / key, how, seed=zlib.crc32(f"{key} {how}".encode()))
    rep = verify_map_store(out)
    text = rep.describe()
    if rep.ok:
        assert _raw_equal(out, good_store, key.split("/")[0]), f"undetected damage: {key} {how}"
    else:
        assert "Traceback" not in text
        if key.startswith("done/"):
            assert row in rep.not_done or row in rep.damaged, text
        else:
            assert key in text and f"row {row}" in text, text
        with pytest.raises(ValueError, match=f"row {row}|rows not computed yet: .*{row}"):
            librate.open_result(out, verify=True)
    _resume_is_identical(out, fam, reference)


SIDE = ["orbit/0", "x0/0", "wz0/0", "sol_wz0/0", "sol_kind/0", "sol_stable/0"]


@pytest.mark.parametrize("how", ("delete", "truncate", "bitflip_last", "garbage"))
@pytest.mark.parametrize("key", SIDE)
def test_damaged_coordinate_or_solution_is_named_and_repaired(tmp_path, fam, reference, good_store, key, how):
    """A damaged coordinate or solution chunk is named by verify and repaired by a resume
    (the coordinates are known from the inputs; the solutions are recomputed from the rows)."""
    out = _copy(good_store, tmp_path)
    _damage(out / key, how, seed=zlib.crc32(f"{key} {how}".encode()))
    name = key.split("/")[0]
    rep = verify_map_store(out)
    if rep.ok:
        assert _raw_equal(out, good_store, name), f"undetected damage: {key} {how}"
    else:
        assert any(name in p for p in rep.problems), rep.describe()
        with pytest.raises(ValueError, match=name):
            librate.open_result(out, verify=True)
    _resume_is_identical(out, fam, reference)


@pytest.mark.parametrize("key,what", [("dwz/.zarray", "dwz"), ("status/.zarray", "status"), ("row_checksum/.zarray", "row_checksum"),
                                      (".zattrs", "not a librate map store"), (".zgroup", "not a librate map store")])
@pytest.mark.parametrize("how", ("delete", "garbage"))
def test_damaged_metadata_is_refused_by_name(tmp_path, fam, good_store, key, what, how):
    """Damaged metadata cannot be repaired safely: verify and a resume refuse the store and
    name what is wrong; nothing is overwritten."""
    out = _copy(good_store, tmp_path)
    _damage(out / key, how, seed=7)
    before = sorted(p.relative_to(out).as_posix() for p in out.rglob("*"))
    rep = verify_map_store(out)
    assert not rep.ok and what in rep.describe(), rep.describe()
    with pytest.raises(ValueError, match=what):
        run_map(fam, kz=KZ, wz0=WZ, out=out, progress=False)
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*")) == before


def test_verify_command(tmp_path, good_store):
    """`librate verify PATH`: exit 0 and "ok" for an intact store, exit 1 naming the chunk and
    the row for a damaged one, no traceback."""
    from click.testing import CliRunner
    from librate.app.cli import main

    r = CliRunner().invoke(main, ["verify", str(good_store)])
    assert r.exit_code == 0 and ": ok:" in r.output, r.output
    out = _copy(good_store, tmp_path)
    _damage(out / "dwz" / "1.0.0", "delete", 0)
    r = CliRunner().invoke(main, ["verify", str(out)])
    assert r.exit_code == 1 and "chunk dwz/1.0.0 is missing" in r.output and "row 1" in r.output, r.output
    assert "Traceback" not in r.output


def test_incomplete_store_is_reported_not_damaged(tmp_path, fam, write_counts):
    """A store killed during its rows: verify lists the rows not computed yet."""
    total, final = write_counts
    _drive(tmp_path, [("mid", [final - 4])])
    rep = verify_map_store(tmp_path / "mid" / "map.zarr")
    assert not rep.ok and rep.not_done and not rep.damaged, rep.describe()
    assert "rows not computed yet" in rep.describe()



def test_plot_refuses_a_damaged_store_by_name(tmp_path, good_store):
    """Issue 12 #3: a garbage chunk surfaced in `librate plot` only as "error during blosc
    decompression: -1" with asyncio traceback noise; now the damage is named, no traceback."""
    from click.testing import CliRunner
    from librate.app.cli import main

    out = _copy(good_store, tmp_path)
    _damage(out / "dwz" / "0.0.0", "garbage", 3)
    r = CliRunner().invoke(main, ["plot", str(out)])
    assert r.exit_code == 2 and "chunk dwz/0.0.0" in r.output and "row 0" in r.output, r.output  # refused (issue 24 #4)
    assert "Traceback" not in r.output and "asyncio" not in r.output


# ---------------------------------------------------------------------------------------------
# Issue 24: every result kind (family, solutions, map, map_3d) through librate.results. Each test
# below fails on main 126a94a (the defect it names) and passes with the one writer and store.

from librate.app.map3d_runs import run_map_3d_to  # noqa: E402
from librate.app.results import run_map_to, save_dataset, verify_result  # noqa: E402
from librate.results import atomic  # noqa: E402

BODY = librate.RigidBody(1.0, 1.02, 1.04)
RATES_3D = {"wx0": np.linspace(-0.05, 0.05, 5), "wy0": 0.0, "wz0": np.linspace(1.1, 1.4, 8)}
RATES_3D_OLD = {"wx0": np.linspace(-0.05, 0.05, 3), "wy0": 0.0, "wz0": np.linspace(1.1, 1.4, 8)}


def _map3d(fam, out, rates=RATES_3D, resume=True):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return run_map_3d_to(fam, out, body=BODY, rates=rates, q0=[0.0, 0.0, 0.0, 1.0], tol=1e-10, resume=resume, progress=False)[0]


def _zattrs_edit(folder: Path, key: str, edit) -> None:
    """Apply ``edit`` to the attributes JSON ``key`` (e.g. "period/.zattrs" or ".zattrs") of a Zarr
    folder, in the file and in the consolidated metadata (both: a reader may use either)."""
    f = folder / key
    attrs = json.loads(f.read_text())
    edit(attrs)
    f.write_text(json.dumps(attrs))
    zm = folder / ".zmetadata"
    if zm.exists():
        meta = json.loads(zm.read_text())
        edit(meta["metadata"][key])
        zm.write_text(json.dumps(meta))


def _no_leftovers(path: Path) -> None:
    left = [q.name for q in path.parent.iterdir() if q.name.startswith(f".{path.name}.")]
    assert not left, left


@pytest.fixture(scope="module")
def map3d_ref(fam):
    return run_map_3d_ref(fam)


def run_map_3d_ref(fam):
    """The uninterrupted 3-D map (each orbit by librate.attitude_map_3d, as the store holds it)."""
    maps = [librate.attitude_map_3d(o, BODY, wx0=RATES_3D["wx0"], wy0=0.0, wz0=RATES_3D["wz0"], tol=1e-10) for o in fam]
    return np.stack([m["residual"].values for m in maps]), np.stack([m["status"].values for m in maps])


def _same3d(ds, ref):
    np.testing.assert_array_equal(ds["residual"].values, ref[0])
    np.testing.assert_array_equal(ds["status"].values, ref[1])
    assert ds["status"].dtype == np.uint8 and int(ds.attrs["complete"]) == 1


def test_force_while_another_process_writes_removes_nothing(tmp_path, fam, good_store):
    """#1: `map --force` while another writer holds the store: refused naming the holder, and the
    store is untouched (main removed it before taking the lock)."""
    out = _copy(good_store, tmp_path)
    script = textwrap.dedent(f"""
        import time, librate.results as r
        with r.writer_lock({str(out)!r}):
            print("locked", flush=True)
            time.sleep(60)
    """)
    holder = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(StoreBusyError, match=f"pid {holder.pid}"):
            run_map_to(fam, out, kz=[0.5], wz0=WZ, replace=True, progress=False)
        assert verify_map_store(out).ok
    finally:
        holder.kill()
        holder.wait()
        holder.stdout.close()


def test_force_is_all_or_nothing(tmp_path, fam, good_store, monkeypatch):
    """#5: a replacing map that fails (a full disk at its second row) leaves the old map whole."""
    import errno

    import librate.app.runner as runner

    out = _copy(good_store, tmp_path)
    real, calls = runner._row, []

    def full_disk(*a, **k):
        calls.append(1)
        if len(calls) == 2:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(*a, **k)

    monkeypatch.setattr(runner, "_row", full_disk)
    with pytest.raises(OSError, match="No space left"):
        run_map_to(fam, out, kz=[0.5], wz0=WZ, replace=True, progress=False)
    assert verify_map_store(out).ok and _raw_equal(out, good_store, "dwz")
    monkeypatch.setattr(runner, "_row", real)
    ds, _ = run_map_to(fam, out, kz=[0.5], wz0=WZ, replace=True, progress=False)
    assert float(ds["kz"][0]) == 0.5 and verify_map_store(out).ok
    _no_leftovers(out)


def test_orphans_of_dead_processes_are_cleaned_at_start(tmp_path, fam):
    """#2: temporary siblings left by killed writers (dead pids) are removed at the next write; a
    live process's are kept; an old result set aside by a killed replacement is put back."""
    p = tmp_path / "family.zarr"
    fam.save(p)
    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True).stdout.strip()
    try:
        for what, pid in (("tmp", dead), ("tmp", sleeper.pid)):
            (tmp_path / f".family.zarr.{what}-{pid}").mkdir()
            (tmp_path / f".family.zarr.{what}-{pid}" / "x").write_text("partial")
        fam.save(p)
        assert sorted(q.name for q in tmp_path.iterdir()) == [f".family.zarr.tmp-{sleeper.pid}", "family.zarr"]
    finally:
        sleeper.kill()
        sleeper.wait()
    # a replacement killed between its two renames (systems without an atomic exchange)
    os.rename(p, tmp_path / f".family.zarr.old-{dead}")
    back = atomic.clean_orphans(p)
    assert p.exists() and len(back) == 2 and librate.OrbitFamily.load(p).period.tolist() == fam.period.tolist()


@pytest.mark.parametrize("suffix", [".zarr", ".nc"])
def test_checksums_cover_attributes_names_and_constants_of_a_family(tmp_path, fam, suffix):
    """#3: a `scale_factor` added to an array (its values doubled on reading), a flipped bit in the
    mass ratio, and a flipped bit in a variable name are each detected and named, by
    OrbitFamily.load and by verify."""
    import xarray as xr

    p = tmp_path / f"family{suffix}"
    fam.save(p)
    if suffix == ".nc":  # netCDF: the same three edits through a rewrite with the old digests
        ds = xr.open_dataset(p, engine="scipy").load()
        ds["period"].attrs["scale_factor"] = 2.0
        ds.to_netcdf(tmp_path / "scaled.nc", engine="scipy")
        ds = xr.open_dataset(p, engine="scipy").load()
        ds.attrs["mu"] = float(np.frombuffer((np.frombuffer(np.float64(ds.attrs["mu"]).tobytes(), np.uint64) ^ np.uint64(1)).tobytes())[0])
        ds.to_netcdf(tmp_path / "mu.nc", engine="scipy")
        ds = xr.open_dataset(p, engine="scipy").load().rename({"jacobi": "jacobj"})
        ds.to_netcdf(tmp_path / "name.nc", engine="scipy")
        cases = [(tmp_path / "scaled.nc", "period"), (tmp_path / "mu.nc", "root attributes"), (tmp_path / "name.nc", "jacobi")]
    else:
        cases = []
        for name, edit in (("scaled", lambda q: _zattrs_edit(q, "period/.zattrs", lambda a: a.update(scale_factor=2.0))),
                           ("mu", lambda q: _zattrs_edit(q, ".zattrs", lambda a: a.update(mu=a["mu"] * (1 + 2.0 ** -52)))),
                           ("name", lambda q: (os.rename(q / "jacobi", q / "jacobj"), (q / ".zmetadata").unlink()))):
            q = tmp_path / f"{name}.zarr"
            shutil.copytree(p, q)
            edit(q)
            cases.append((q, {"scaled": "period", "mu": "root attributes", "name": "jacobi"}[name]))
    for q, what in cases:
        with pytest.raises(ValueError, match=f"damaged librate family file|not a librate family file.*{what}"):
            librate.OrbitFamily.load(q)
        ok, report = verify_result(q)
        assert not ok and what in report, report


def test_scale_factor_in_a_map_store_is_named_and_repaired(tmp_path, fam, reference, good_store):
    """#3: `scale_factor` slipped into dwz's metadata doubled dwz and passed verify on main; now
    verify names the array and a resume puts the attributes back."""
    out = _copy(good_store, tmp_path)
    _zattrs_edit(out, "dwz/.zattrs", lambda a: a.update(scale_factor=2.0))
    rep = verify_map_store(out)
    assert not rep.ok and any("array dwz: its dtype, shape or attributes" in q for q in rep.problems), rep.describe()
    with pytest.raises(ValueError, match="array dwz"):
        librate.open_result(out, verify=True)
    _resume_is_identical(out, fam, reference)


_SOLVES: dict = {}


def _solve_dataset(fam):
    """The solve of ``fam``'s first orbit (computed once per family: the tests write it, they do
    not test the solver)."""
    from librate.app.results import solutions_dataset

    if id(fam) not in _SOLVES:
        rows = [(0, s) for s in librate.find_periodic_attitudes(fam[0], kz=0.8, wz0_range=(-1.0, 1.5), n_grid=40)]
        _SOLVES[id(fam)] = (fam, solutions_dataset(rows, list(fam), [0.8], {"librate_result": "solutions", "study": "{}"}))
    return _SOLVES[id(fam)][1].copy(deep=True)


def test_a_damaged_solve_is_named_never_a_crash_and_plot_refuses_it(tmp_path, fam):
    """#4: truncated, padded and garbage chunks of a saved solve: verify names them (exit 1, no
    segfault: chunks are checked before Blosc sees them), `librate plot` refuses with exit 2, and
    the name flip that made `librate solve` raise a KeyError is named too."""
    from click.testing import CliRunner
    from librate.app.cli import main

    p = tmp_path / "good" / "solve.zarr"
    save_dataset(_solve_dataset(fam), p)
    assert verify_result(p)[0]
    for i, how in enumerate(("truncate", "garbage", "bitflip", "delete")):
        q = tmp_path / how / "solve.zarr"
        shutil.copytree(p, q)
        _damage(q / "sol_wz0" / "0", how, i)
        ok, report = verify_result(q)
        assert not ok and "sol_wz0" in report, report
        r = CliRunner().invoke(main, ["verify", str(q)])
        assert r.exit_code == 1 and "sol_wz0" in r.output, r.output
        r = CliRunner().invoke(main, ["plot", str(q)])
        assert r.exit_code == 2 and "sol_wz0" in r.output and not list(q.parent.glob("*.png")), r.output


def test_a_damaged_3d_part_is_really_recomputed(tmp_path, fam, map3d_ref):
    """#4: a truncated chunk of one orbit of a 3-D map is named by verify (no crash), `librate plot`
    refuses the map (exit 2), and the same map again recomputes that orbit: identical to an
    uninterrupted run (on main every rerun exited 2)."""
    from click.testing import CliRunner
    from librate.app.cli import main

    out = tmp_path / "map.zarr"
    _same3d(_map3d(fam, out), map3d_ref)
    _damage(out / "residual" / "1.0.0.0", "truncate", 0)
    rep = verify_map_store(out)
    assert 1 in rep.damaged and "residual/1.0.0.0" in rep.damaged[1], rep.describe()
    r = CliRunner().invoke(main, ["plot", str(out)])
    assert r.exit_code == 2 and "residual/1.0.0.0" in r.output, r.output
    with pytest.warns(RuntimeWarning, match="orbit 1: chunk residual/1.0.0.0"):
        ds = run_map_3d_to(fam, out, body=BODY, rates=RATES_3D, q0=[0, 0, 0, 1.0], tol=1e-10, progress=False)[0]
    _same3d(ds, map3d_ref)
    assert verify_map_store(out).ok


def test_3d_maps_are_locked_and_keep_their_dtypes(tmp_path, fam, map3d_ref):
    """#10: a second writer of a 3-D map is refused; a resumed 3-D map stores status as uint8
    (main: int8 after a resume from its netCDF parts, int16 after two concurrent runs)."""
    out = tmp_path / "map.zarr"
    with writer_lock(out):
        script = textwrap.dedent(f"""
            import numpy as np, librate
            from librate.app.map3d_runs import run_map_3d_to
            fam = librate.dro_family(librate.System.preset("earth-moon"), x0={X0!r})
            run_map_3d_to(fam, {str(out)!r}, body=librate.RigidBody(1.0, 1.02, 1.04), rates={{"wx0": np.linspace(-0.05, 0.05, 5),
                          "wy0": 0.0, "wz0": np.linspace(1.1, 1.4, 8)}}, q0=[0, 0, 0, 1.0], tol=1e-10, progress=False)
        """)
        proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
        assert proc.returncode != 0 and f"pid {os.getpid()}" in proc.stderr and "StoreBusyError" in proc.stderr, proc.stderr[-2000:]
    import librate.periodicity.map3d as m3

    real, calls = m3.attitude_map_3d, []

    def stop_second(*a, **k):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*a, **k)

    m3.attitude_map_3d = stop_second
    try:
        with pytest.raises(KeyboardInterrupt):
            _map3d(fam, out)
    finally:
        m3.attitude_map_3d = real
    import zarr

    assert zarr.open_group(str(out), mode="r")["status"].dtype == np.uint8
    ds = _map3d(fam, out)
    _same3d(ds, map3d_ref)
    assert librate.open_result(out, verify=True)["status"].dtype == np.uint8


def test_two_processes_saving_one_family(tmp_path, fam):
    """#11: two processes saving one OrbitFamily to the same .zarr 20 times each, at once: every
    call succeeds (the second waits for the lock; main: 33 of 80 failed as "damaged"), and the file
    loads and verifies."""
    p = tmp_path / "family.zarr"
    script = textwrap.dedent(f"""
        import os, librate
        {NO_FSYNC}
        fam = librate.dro_family(librate.System.preset("earth-moon"), x0={X0!r})
        for _ in range(20):
            fam.save({str(p)!r})
            librate.OrbitFamily.load({str(p)!r})
    """)
    procs = [subprocess.Popen([sys.executable, "-c", script], stderr=subprocess.PIPE, text=True) for _ in range(2)]
    errs = [q.communicate(timeout=300)[1] for q in procs]
    assert [q.returncode for q in procs] == [0, 0], errs
    assert librate.OrbitFamily.load(p).period.tolist() == fam.period.tolist() and verify_result(p)[0]
    _no_leftovers(p)


def test_a_deleted_lock_file_lets_no_second_writer_in(tmp_path):
    """#11: the lock file deleted while a writer runs: a second process is refused (the first one's
    owner record names a live pid), and the first stops before its next commit."""
    out = tmp_path / "map.zarr"
    with writer_lock(out) as lock:
        (tmp_path / ".map.zarr.lock").unlink()
        script = f"import librate.results as r\nwith r.writer_lock({str(out)!r}): print('in')"
        proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
        assert proc.returncode != 0 and f"pid {os.getpid()}" in proc.stderr and "lock file was removed" in proc.stderr, proc.stderr[-2000:]
        (tmp_path / ".map.zarr.lock").write_text("")  # another process's fresh lock file
        with pytest.raises(StoreBusyError, match="removed or replaced"):
            lock.check()


# ---------------------------------------------------------------------------------------------
# The kill campaign (issue 24, acceptance): real SIGKILLs over every kind of result (a family, a
# solve, a 3-D map from scratch, a 3-D map and a planar map replacing an older one), at sampled
# writes and at every step of the replace window (before the new result takes the name, just
# after, and once the old one is deleted). After each kill the path holds the old result or the
# new one, whole and verified (never a half-deleted one), or a store the same run resumes; the
# run again gives the uninterrupted result bit for bit and leaves no temporary or lock behind.

#: The epochs of the transition kind (TDB s past J2000: 2030-01-01 and ten days apart).
EPOCHS = [946728000.0, 947592000.0, 948456000.0]

CAMPAIGN = textwrap.dedent("""
    import json, os, signal, sys, threading
    import numpy as np
    import librate, xarray, zarr  # noqa: F401 - imported once, before the forks
    from librate.app.map3d_runs import run_map_3d_to
    from librate.app.results import run_map_to, save_dataset, solutions_dataset
    from librate.results import atomic

    xarray.Dataset({{"a": ("x", [1.0])}}).merge(xarray.Dataset({{"b": ("x", [2.0])}}))
    xarray.backends.list_engines()
    assert threading.active_count() == 1, threading.enumerate()
    {NO_FSYNC}
    X0, WZ = {X0!r}, np.linspace(-1.0, 1.5, 40)
    RATES = {{"wx0": np.linspace(-0.05, 0.05, 5), "wy0": 0.0, "wz0": np.linspace(1.1, 1.4, 8)}}
    EPOCHS = {EPOCHS!r}

    def job(kind, d):
        fam = librate.dro_family(librate.System.preset("earth-moon"), x0=X0)
        if kind == "family":
            fam.save(os.path.join(d, "family.zarr"))
        elif kind == "solve":
            rows = [(0, s) for s in librate.find_periodic_attitudes(fam[0], kz=0.8, wz0_range=(-1.0, 1.5), n_grid=40)]
            save_dataset(solutions_dataset(rows, list(fam), [0.8], {{"librate_result": "solutions", "study": "{{}}"}}),
                         os.path.join(d, "solve.zarr"))
        elif kind == "transition":
            from librate.app.transition import run_transition_to
            run_transition_to(fam[0], os.path.join(d, "transition.zarr"), epochs_tdb=EPOCHS, revolutions=2, nodes_per_rev=4, progress=False)
        elif kind.startswith("map3d"):
            run_map_3d_to(fam, os.path.join(d, "map.zarr"), body=librate.RigidBody(1.0, 1.02, 1.04), rates=RATES, q0=[0, 0, 0, 1.0],
                          tol=1e-10, resume=kind == "map3d", progress=False)
        else:
            run_map_to(fam, os.path.join(d, "map.zarr"), kz=[0.5], wz0=WZ, replace=True, progress=False)

    def child(kind, d, kill_at):
        from zarr.storage import LocalStore
        n = {{"n": 0, "replace": []}}
        def tick(what):
            n["n"] += 1
            if what.startswith("replace:"):
                n["replace"].append(n["n"])
            if n["n"] == kill_at:
                os.kill(os.getpid(), signal.SIGKILL)
        real_set, real_del = LocalStore.set, LocalStore.delete
        async def set_(self, key, value):
            tick(key)
            return await real_set(self, key, value)
        async def del_(self, key):
            tick(key)
            return await real_del(self, key)
        LocalStore.set, LocalStore.delete = set_, del_
        atomic.REPLACE_HOOK = lambda step: tick("replace:" + step)
        job(kind, d)
        return n

    res = []
    for name, kind, kill_at in json.loads(sys.argv[2]):
        d = os.path.join(sys.argv[1], name)
        pid = os.fork()
        if pid == 0:
            try:
                n = child(kind, d, kill_at)
                with open(os.path.join(d, "count.json"), "w") as f:
                    json.dump(n, f)
            finally:
                os._exit(0)
        _, st = os.waitpid(pid, 0)
        res.append([name, os.WIFSIGNALED(st) and os.WTERMSIG(st) == signal.SIGKILL])
    print(json.dumps(res))
""").format(X0=X0, NO_FSYNC=NO_FSYNC, EPOCHS=EPOCHS)

KINDS = ("family", "solve", "map3d", "map3d_replace", "map_replace", "transition")
RESULT = {"family": "family.zarr", "solve": "solve.zarr", "map3d": "map.zarr", "map3d_replace": "map.zarr", "map_replace": "map.zarr",
          "transition": "transition.zarr"}
#: The kinds written from scratch (no older result at the path): a kill leaves a store to resume.
FRESH = ("map3d", "transition")


def _campaign(root: Path, cases, workers: int = 2) -> dict:
    parts = [cases[i::workers] for i in range(workers) if cases[i::workers]]
    procs = [subprocess.Popen([sys.executable, "-c", CAMPAIGN, str(root), json.dumps(p)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)
             for p in parts]
    out = {}
    for proc in procs:
        stdout, stderr = proc.communicate(timeout=600)
        assert proc.returncode == 0, stderr[-3000:]
        out.update(json.loads(stdout.strip().splitlines()[-1]))
    return out


_OLD: dict = {}


def _old_result(kind: str, d: Path, fam, em, good_store) -> None:
    """What is at the path before the run: an older result of other inputs (replacing kinds),
    computed once per kind and copied."""
    if kind not in _OLD:
        _OLD[kind] = d.parent / f"old-template-{kind}"
        _make_old_result(kind, _OLD[kind], fam, em, good_store)
    shutil.copytree(_OLD[kind], d)


def _make_old_result(kind: str, d: Path, fam, em, good_store) -> None:
    d.mkdir(parents=True)
    if kind == "family":
        librate.dro_family(em, x0=[0.8]).save(d / "family.zarr")
    elif kind == "solve":
        ds = _solve_dataset(fam)
        save_dataset(ds.isel(solution=slice(0, 1)), d / "solve.zarr")
    elif kind == "map3d_replace":
        _map3d(fam, d / "map.zarr", rates=RATES_3D_OLD)
    elif kind == "map_replace":
        shutil.copytree(good_store, d / "map.zarr")


def _content(kind: str, p: Path):
    """The numbers of the result at ``p`` (verified first: damage is a failure)."""
    ok, report = verify_result(p)
    assert ok, report
    if kind == "family":
        return librate.OrbitFamily.load(p).period.tolist()
    ds = librate.open_result(p, verify=True)
    key = {"solve": "sol_wz0", "map_replace": "dwz", "transition": "states_km"}.get(kind, "residual")
    return np.asarray(ds[key].values).tobytes()


@pytest.mark.slow
def test_kill_campaign_loses_nothing(tmp_path, fam, em, good_store):
    """At least 30 real SIGKILLs over family, solve, 3-D map, planar map and ephemeris transition
    writes, the replace window included: 0 lost or silently wrong results (printed: kills per kind)."""
    calib = [(f"c-{k}", k, 0) for k in KINDS]
    for _, k, _ in calib:
        _old_result(k, tmp_path / f"c-{k}", fam, em, good_store)
    _campaign(tmp_path, calib)
    old, new, cases = {}, {}, []
    for k in KINDS:
        d = tmp_path / f"c-{k}"
        n = json.loads((d / "count.json").read_text())
        new[k] = _content(k, d / RESULT[k])
        if k not in FRESH:
            ref = tmp_path / f"old-{k}"
            _old_result(k, ref, fam, em, good_store)
            old[k] = _content(k, ref / RESULT[k])
        window = sorted(set(n["replace"][-3:]))  # before the new result takes the name, after, once the old one is gone
        spread = [int(x) for x in np.linspace(1, n["n"], 6 if k not in FRESH else 9)[:-1]]
        for j in sorted(set(spread) | set(window)):
            cases.append((f"{k}-{j}", k, j))
    for name, k, _ in cases:
        _old_result(k, tmp_path / name, fam, em, good_store)
    killed = _campaign(tmp_path, cases)
    assert sum(killed.values()) >= 30 and all(killed.values()), killed
    counts = {k: 0 for k in KINDS}
    for name, k, _ in cases:  # what each kill left
        p = tmp_path / name / RESULT[k]
        if k in FRESH:
            assert not p.exists() or verify_map_store(p).problems == [], verify_map_store(p).describe()
        else:  # a replacement: the old result or the new one, whole
            assert _content(k, p) in (old[k], new[k]), name
    # the same run again on each (forked by the drivers, in parallel): the uninterrupted result
    assert not any(_campaign(tmp_path, [(name, k, 0) for name, k, _ in cases]).values())
    for name, k, _ in cases:
        p = tmp_path / name / RESULT[k]
        assert _content(k, p) == new[k], name
        _no_leftovers(p)
        counts[k] += 1
    print(f"kill campaign: {sum(counts.values())} SIGKILLs, {counts}; 0 lost or wrong")


def test_a_killed_transition_resumes_to_the_same_arrays(tmp_path):
    """`librate transition`'s store (one part per epoch): real SIGKILLs spread over its writes
    (creation, each epoch's data, digests and flag, the finalisation); each store then verifies
    or is a store to resume, and the same run gives the uninterrupted arrays bit for bit."""
    d = tmp_path / "c-transition"
    d.mkdir()
    _campaign(tmp_path, [("c-transition", "transition", 0)], workers=1)
    n = json.loads((d / "count.json").read_text())["n"]
    new = _content("transition", d / "transition.zarr")
    cases = [(f"t-{j}", "transition", j) for j in sorted({int(x) for x in np.linspace(1, n, 7)[:-1]} | {n - 1, n})]
    for name, _, _ in cases:
        (tmp_path / name).mkdir()
    killed = _campaign(tmp_path, cases)
    assert all(killed.values()), killed
    for name, _, _ in cases:
        p = tmp_path / name / "transition.zarr"
        assert not p.exists() or verify_map_store(p).problems == [], verify_map_store(p).describe()
    assert not any(_campaign(tmp_path, [(name, "transition", 0) for name, _, _ in cases]).values())
    for name, _, _ in cases:
        p = tmp_path / name / "transition.zarr"
        assert _content("transition", p) == new, name
        _no_leftovers(p)


def test_results_written_by_main_still_open(tmp_path, fam, reference, good_store):
    """Files of librate 126a94a: a map store without the metadata digests verifies and resumes
    (its row checksums are the same); a 3-D map saved whole with status as int8 (as its netCDF
    parts made it) opens with status uint8 (255 = not computed, as written)."""
    out = _copy(good_store, tmp_path)

    def strip(a):  # main's root attributes: the solutions' digests under their old name, no metadata digests
        a["sol_checksums"] = a.pop("extra_checksums")
        for k in ("array_meta", "attrs_checksum"):
            a.pop(k, None)

    _zattrs_edit(out, ".zattrs", strip)
    assert verify_map_store(out).ok
    _resume_is_identical(out, fam, reference)
    from librate._integrity import write_atomically

    m = librate.attitude_map_3d(fam[0], BODY, wx0=RATES_3D["wx0"], wy0=0.0, wz0=RATES_3D["wz0"], tol=1e-10)
    m["status"] = m["status"].astype(np.int8)
    m.attrs.update({"librate_result": "map_3d", "complete": 1})
    write_atomically(m, tmp_path / "old3d.nc")
    back = librate.open_result(tmp_path / "old3d.nc", verify=True)
    assert back["status"].dtype == np.uint8
    np.testing.assert_array_equal(back["status"].values, m["status"].values.astype(np.uint8))


def test_random_bit_flips_in_a_family_file_are_never_silent(tmp_path, fam):
    """#3 (main: 38 of 480 random bit flips went undetected): 200 single-bit flips anywhere in a
    saved family (.nc): each one is refused with a ValueError, or loads to exactly the saved family
    (a flip in padding or in an unused header byte). Reference: the family as saved, compared
    member by member and constant by constant (exact equality)."""
    p = tmp_path / "family.nc"
    fam.save(p)
    raw = p.read_bytes()
    rng = np.random.default_rng(24)
    outcomes = {"refused": 0, "identical": 0}
    for k in range(200):
        data = bytearray(raw)
        data[int(rng.integers(len(data)))] ^= 1 << int(rng.integers(8))
        q = tmp_path / f"flip{k}.nc"
        q.write_bytes(bytes(data))
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                g = librate.OrbitFamily.load(q)
        except ValueError:
            outcomes["refused"] += 1
            continue
        s, t = g.system, fam.system
        assert (s.mu, s.lu_km, s.tu_s, s.r1_km, s.r2_km, s.name) == (t.mu, t.lu_km, t.tu_s, t.r1_km, t.r2_km, t.name), k
        assert (g.kind, g.spatial, g.end_reason, g.parameters, g.bifurcations) == (fam.kind, fam.spatial, fam.end_reason,
                                                                                   fam.parameters, fam.bifurcations), k
        for name in ("state0", "state_half", "period", "jacobi", "eigenvalues", "stability_indices"):
            np.testing.assert_array_equal(getattr(g, name), getattr(fam, name), err_msg=f"flip {k}: {name}")
        outcomes["identical"] += 1
    print(f"200 bit flips: {outcomes}")
    assert outcomes["refused"] > 150


@pytest.mark.parametrize("command", ["map", "plot"])
def test_figures_that_do_not_fit_on_the_disk_keep_the_result(tmp_path, monkeypatch, good_store, command):
    """#5: a full disk while a figure is written (savefig writes part of the file, then raises
    ENOSPC) ends `librate map` / `librate plot` in a one-line error, exit 2, no traceback (before:
    an OSError traceback); the partial figure is removed and the result already written is whole
    (it verifies, and `map` resumes it as complete, nothing recomputed)."""
    import errno

    from click.testing import CliRunner
    from librate.app.cli import main
    from matplotlib.figure import Figure

    def full_disk(self, fname, *a, **k):
        Path(fname).write_bytes(b"\x89PNG partial")
        raise OSError(errno.ENOSPC, "No space left on device", str(fname))

    monkeypatch.chdir(tmp_path)
    if command == "map":
        (tmp_path / "s.toml").write_text('[orbits]\nkind = "dro"\nx0 = [0.9, 0.85]\n[body]\nkz = 0.8\n'
                                         '[rates]\nwz0 = {start = -1.0, stop = 1.5, num = 40}\n')
        args, store = ["map", "s.toml", "-q"], tmp_path / "librate-out" / "map.zarr"
    else:
        store = _copy(good_store, tmp_path)
        args = ["plot", str(store)]
    monkeypatch.setattr(Figure, "savefig", full_disk)
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output and isinstance(r.exception, SystemExit), r.output
    err = [line for line in r.output.splitlines() if "No space left on device" in line]
    assert len(err) == 1 and "cannot write the figure" in err[0] and "is kept" in err[0], r.output
    assert not list(store.parent.glob("*.png")), "a partial figure was left"
    assert verify_map_store(store).ok
    monkeypatch.undo()
    monkeypatch.chdir(tmp_path)
    if command == "map":  # the result is complete: a rerun reuses it
        r2 = CliRunner().invoke(main, ["map", "s.toml", "-q"])
        assert r2.exit_code == 0, r2.output
        assert sorted(p.name for p in store.parent.glob("*.png")), r2.output
