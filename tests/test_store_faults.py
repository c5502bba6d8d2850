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
""").format(X0=X0, KZ=KZ)


def _drive(root: Path, cases, workers: int = 2):
    """Run the driver on ``cases`` [(name, [kill_at, ...]), ...] (one store per name, the kills
    applied in turn: the second one kills the resume), split over ``workers`` driver processes;
    returns {name: [killed, ...]}."""
    parts = [cases[i::workers] for i in range(workers) if cases[i::workers]]
    procs = [subprocess.Popen([sys.executable, "-c", DRIVER, str(root), json.dumps(p)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
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
