"""bench/bench_goals.py runs at its smoke sizes and writes its JSON report (issue 22 item 4): every
measured goal a positive finite ratio with its goal and verdict, the CPU model and the SIMD level
named. The timings themselves are not tested (a shared machine); only that they were taken."""

import importlib.util
import json
import math
import subprocess
import sys
from pathlib import Path

import librate
import pytest

BENCH = Path(__file__).resolve().parents[1] / "bench" / "bench_goals.py"


def run_goals(tmp_path, *flags):
    out = tmp_path / "goals.json"
    res = subprocess.run([sys.executable, str(BENCH), "--smoke", "--json", str(out), *flags], capture_output=True, text=True,
                         timeout=600, cwd=tmp_path)
    assert res.returncode == 0, res.stderr[-3000:]
    return json.loads(out.read_text()), res.stdout


def check_report(report, stdout, measured):
    assert report["cpu"] and report["cpu"] in stdout
    assert report["simd"] == librate.build_info()["simd_active"]
    assert sorted(report["goals"]) == ["a", "b", "c", "d", "e"]
    for key, g in report["goals"].items():
        assert g["goal"].startswith((">=", "<=")), g
        if key in measured:
            assert isinstance(g["ratio"], float) and math.isfinite(g["ratio"]) and g["ratio"] > 0, (key, g)
            assert isinstance(g["met"], bool), (key, g)
            assert f"{g['ratio']:.2f}x" in stdout
        else:
            assert g["ratio"] is None and g["met"] is None and "heyoka" in g["note"], (key, g)


def test_goals_without_heyoka_report_the_librate_ratios(tmp_path):
    report, stdout = run_goals(tmp_path, "--no-heyoka")
    assert report["heyoka"] is None
    check_report(report, stdout, measured="cd")
    assert report["goals"]["c"]["with_solutions_s"] > 0 and report["goals"]["d"]["srp_map_s"] > 0


@pytest.mark.slow
@pytest.mark.skipif(importlib.util.find_spec("heyoka") is None, reason="heyoka is not installed (not a librate dependency)")
def test_goals_with_heyoka_report_all_five_ratios(tmp_path):
    report, stdout = run_goals(tmp_path)
    assert report["heyoka"]
    check_report(report, stdout, measured="abcde")
    for key in "abe":
        assert report["goals"][key]["heyoka_s"] > 0 and report["goals"][key]["librate_s"] > 0


def _cpu_mask():
    spec = importlib.util.spec_from_file_location("cpu_mask", BENCH.parent / "cpu_mask.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


_MASK_UNAVAILABLE = _cpu_mask().unavailable()
_PROBE = r"""
import json, shutil, subprocess, sys, tempfile
import librate
out = {"available": librate.build_info()["simd_available"], "active": librate.build_info()["simd_active"]}
try:
    import heyoka as hy
except ImportError:
    hy = None
if hy is not None and shutil.which("objdump"):
    x, v = hy.make_vars("x", "v")
    ta = hy.taylor_adaptive_batch([(x, v), (v, -hy.sin(x))], [[0.1] * 8, [0.0] * 8], tol=1e-12)
    with tempfile.NamedTemporaryFile(suffix=".o") as f:
        f.write(bytes(ta.llvm_state.object_code))
        f.flush()
        asm = subprocess.run(["objdump", "-d", f.name], capture_output=True, text=True, check=True).stdout
    out["jit_zmm"] = asm.count("%zmm")
    out["jit_ymm"] = asm.count("%ymm")
print(json.dumps(out))
"""


@pytest.mark.skipif(_MASK_UNAVAILABLE is not None, reason=f"AVX-512 cannot be hidden here: {_MASK_UNAVAILABLE}")
def test_cpu_mask_hides_avx512_from_librate_and_heyokas_jit(tmp_path):
    """bench/cpu_mask.py (CPUID faulting): in the masked process librate's dispatch offers no
    AVX-512 level and picks AVX2 by itself, and heyoka's JIT (when installed, with objdump)
    emits 256-bit code with no zmm register; unmasked, the same probe sees this CPU's levels."""
    probe = tmp_path / "probe.py"
    probe.write_text(_PROBE)
    run = [sys.executable, str(BENCH.parent / "cpu_mask.py"), str(probe)]
    res = subprocess.run(run, capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert res.returncode == 0, res.stderr[-3000:]
    masked = json.loads(res.stdout.strip().splitlines()[-1])
    assert "avx512" not in masked["available"], masked
    assert masked["active"] == ("avx2" if "avx2" in librate.build_info()["simd_available"] else "baseline"), masked
    if "jit_zmm" in masked:
        assert masked["jit_zmm"] == 0 and masked["jit_ymm"] > 0, masked
    res = subprocess.run([sys.executable, str(probe)], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert res.returncode == 0, res.stderr[-3000:]
    plain = json.loads(res.stdout.strip().splitlines()[-1])
    assert plain["available"] == librate.build_info()["simd_available"]
    if "avx512" in plain["available"] and "jit_zmm" in plain:
        assert plain["jit_zmm"] > 0, plain  # the JIT's own choice on an AVX-512 CPU, which the mask removes


@pytest.mark.skipif(_MASK_UNAVAILABLE is not None, reason=f"AVX-512 cannot be hidden here: {_MASK_UNAVAILABLE}")
def test_goals_with_avx512_hidden_run_at_avx2(tmp_path):
    report, stdout = run_goals(tmp_path, "--no-heyoka", "--no-avx512")
    assert report["avx512_hidden"] is True and "AVX-512 hidden from CPUID" in stdout
    assert report["simd"] == ("avx2" if "avx2" in librate.build_info()["simd_available"] else "baseline")
    assert report["goals"]["c"]["ratio"] > 0 and report["goals"]["d"]["ratio"] > 0


def test_goals_refuse_the_mask_flag_after_their_imports(tmp_path):
    """--no-avx512 must take effect before numpy, librate and heyoka are imported: main() called
    from an importing module rejects it (a usage error) instead of reporting an unmasked run."""
    code = (f"import sys; sys.path.insert(0, {str(BENCH.parent)!r}); import bench_goals; "
            "bench_goals.main(['--smoke', '--no-heyoka', '--no-avx512'])")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert res.returncode == 2 and "before its imports" in res.stderr, res.stderr[-3000:]
