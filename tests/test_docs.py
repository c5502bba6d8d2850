"""The documentation stays in the repository and in step with the code (issue 14): nothing points
at files outside the repository, the gallery has a page section, a command and a runtime for every
figure its script makes, every command has a how-to, and the README keeps its two commands and
links the docs. (The site itself is built with `mkdocs build --strict` in .ci/run.)"""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


def test_nothing_points_outside_the_repository():
    hits = []
    for folder in ("python", "rust", "docs", "examples", "bench"):
        for p in (ROOT / folder).rglob("*"):
            if p.suffix in (".py", ".rs", ".md", ".pyi", ".toml") and "PHYSICS" in p.read_text(encoding="utf-8", errors="replace"):
                hits.append(str(p.relative_to(ROOT)))
    assert "PHYSICS" not in (ROOT / "README.md").read_text() and not hits, hits


def test_every_gallery_figure_has_its_section_command_and_runtime():
    res = subprocess.run([sys.executable, str(DOCS / "gallery" / "gallery.py"), "--list"], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    figures = [line.split()[0] for line in res.stdout.splitlines() if line.strip()]
    assert len(figures) >= 16
    pages = "\n".join(p.read_text() for p in (DOCS / "gallery").glob("*.md"))
    for f in figures:
        assert f"](img/{f}.png)" in pages and (DOCS / "gallery" / "img" / f"{f}.png").is_file(), f
        m = re.search(rf"\*\*Command:\*\* `python docs/gallery/gallery.py {f}` &nbsp; \*\*Runtime:\*\* ([\d.]+) s", pages)
        assert m and float(m.group(1)) > 0, f


def test_every_command_has_a_how_to():
    from librate.app.cli import main

    text = (DOCS / "cli.md").read_text()
    for name in main.commands:
        assert f"\n## {name}:" in text, name


@pytest.mark.parametrize("command", ['pip install . && librate demo', 'pip install ".[test]" && cargo test && python -m pytest'])
def test_readme_keeps_its_commands_and_links_the_docs(command):
    readme = (ROOT / "README.md").read_text()
    assert f"\n{command}\n" in readme
    for link in re.findall(r"\]\((docs/[^)#]+)", readme):
        assert (ROOT / link).exists(), link
    assert "(docs/index.md)" in readme and "(docs/physics.md)" in readme


@pytest.mark.slow
def test_every_readme_python_block_runs_as_pasted(tmp_path):
    """Issue 23 #9: each ```python block of the README runs on its own, as a new user pastes it
    (a fresh interpreter, an empty working folder, matplotlib on Agg)."""
    blocks = re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S)
    assert blocks
    for i, code in enumerate(blocks):
        res = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600,
                             env={**os.environ, "MPLBACKEND": "Agg"})
        assert res.returncode == 0, f"README block {i + 1} failed:\n{res.stderr[-2000:]}"


@pytest.mark.slow
def test_the_cluster_recipe_runs_on_a_local_cluster_with_worker_processes(tmp_path):
    """Issue 22 #3: docs/cluster.md's recipe. Its SLURM block is valid Python naming SLURMCluster
    (dask-jobqueue needs a batch system); its work block runs as pasted on the page's
    LocalCluster of two worker processes, in a fresh interpreter, and writes complete stores."""
    import ast

    blocks = re.findall(r"```python\n(.*?)```", (DOCS / "cluster.md").read_text(), re.S)
    assert len(blocks) == 3, "the page holds the SLURM cluster, the work and the local cluster"
    slurm, work, local = blocks
    ast.parse(slurm)
    assert "SLURMCluster(" in slurm and "LocalCluster(" in local and "Client(cluster)" in work
    code = local + "\n" + work + "\ncluster.close()\n"
    res = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr[-3000:]
    assert "complete = 1" in res.stdout and "3-D map: 6 orbits" in res.stdout, res.stdout
    from librate.results.store import verify_store

    for store in ("runs/map.zarr", "runs/map3d.zarr"):
        assert verify_store(tmp_path / store).ok, store
