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
