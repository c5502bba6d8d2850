"""Every script in examples/ runs to completion (subprocess, Agg backend) and writes its figures."""

import os
import subprocess
import sys
from pathlib import Path

import pytest
from librate.app.study import Study

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
OUTPUTS = {
    "01_dro_map_tutorial.py": ["tutorial/family.png", "tutorial/residuals.png", "tutorial/map.png", "tutorial/map.zarr"],
    "02_halo_family.py": ["halo/halo_family.png", "halo/halo_period.png", "halo/halo_stability.png", "halo/halo.nc"],
    "03_srp_solution.py": ["srp/srp_motion.png"],
    "04_study_from_python.py": ["study/study.toml", "study/map.zarr", "study/map_kz0.8.png"],
}


def test_every_example_is_listed():
    assert sorted(p.name for p in EXAMPLES.glob("*.py")) == sorted(OUTPUTS)


@pytest.mark.parametrize("script", sorted(OUTPUTS))
def test_example_runs(script, tmp_path):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    res = subprocess.run([sys.executable, str(EXAMPLES / script), str(tmp_path)], capture_output=True, text=True, env=env,
                         timeout=300, cwd=tmp_path)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "written:" in res.stdout
    for rel in OUTPUTS[script]:
        assert (tmp_path / rel).exists(), rel


#: The command each example study is for (default `librate solve`).
STUDY_PURPOSE = {"transition.toml": "transition"}


@pytest.mark.parametrize("study", sorted(p.name for p in EXAMPLES.glob("*.toml")))
def test_example_studies_are_valid(study):
    """Every study file in examples/ validates for its command (`librate solve` unless
    STUDY_PURPOSE says otherwise; tests/test_study3d.py and tests/test_transition_app.py run them)."""
    assert Study.from_toml(EXAMPLES / study, purpose=STUDY_PURPOSE.get(study, "solve")).title
