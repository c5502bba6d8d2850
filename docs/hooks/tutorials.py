"""mkdocs hook: the examples become executed tutorials (issue 23), as heyoka.py's docs run theirs.

At every build each ``examples/NN_*.py`` script (jupytext "percent" format: ``# %%`` starts a code
cell, ``# %% [markdown]`` a text cell; the module docstring becomes the opening text) is read into
a notebook and executed, cell by cell, in a fresh Jupyter kernel (``nbclient``, ``ipykernel``). The
figures a cell saves to the example's output folder are attached to that cell as outputs, so the
page shows each figure under the code that drew it. Each example yields

- ``tutorials/<stem>.md``: a page with the code, its printed output and its figures, all static
  (plain Markdown and PNG files: no JavaScript, no CDN; the site stays offline);
- ``tutorials/<stem>.ipynb``: the executed notebook, linked from the page for download.

A cell that raises fails the build, naming the example and the cell. The pages are generated, not
stored in ``docs/``; ``docs/tutorials/index.md`` lists them.
"""

from __future__ import annotations

import ast
import base64
import tempfile
from pathlib import Path

import jupytext
import nbformat
from mkdocs.exceptions import PluginError
from mkdocs.structure.files import File
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
FOLDER = "tutorials"
# a hidden first cell: the script's command line as a user types it (no argument: the script writes to
# ./examples-out, here in a temporary working folder) and a non-interactive backend
SETUP = "import sys\nimport matplotlib\nmatplotlib.use('Agg')\nsys.argv = [{script!r}]"
TIMEOUT_S = 600


def examples() -> list[Path]:
    """The example scripts that become tutorials, in their numbered order."""
    return sorted(EXAMPLES.glob("[0-9][0-9]_*.py"))


def read_notebook(script: Path) -> nbformat.NotebookNode:
    """The script as a notebook; its module docstring becomes the first (Markdown) cell."""
    nb = jupytext.read(script, fmt="py:percent")
    first = nb.cells[0] if nb.cells else None
    if first is not None and first.cell_type == "code":
        body = ast.parse(first.source).body
        if len(body) == 1 and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
            title, _, rest = str(body[0].value.value).strip().partition("\n")
            # the page says how to run the script; the docstring's own "Run: ..." line is left out
            rest = "\n".join(line for line in rest.splitlines() if not line.startswith("Run: "))
            nb.cells[0] = nbformat.v4.new_markdown_cell(f"# {title}\n\n{rest.strip()}")
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    return nb


def _pngs(folder: Path) -> set[Path]:
    return set(folder.rglob("*.png"))


def _written_order(png: Path) -> tuple[int, str]:
    return png.stat().st_mtime_ns, png.name


def execute(script: Path) -> nbformat.NotebookNode:
    """Run the notebook of ``script`` in a fresh kernel; figures saved by a cell become its outputs."""
    nb = read_notebook(script)
    with tempfile.TemporaryDirectory(prefix="librate-tutorial-") as tmp:
        work = Path(tmp)
        setup = nbformat.v4.new_code_cell(SETUP.format(script=script.name))
        nb.cells.insert(0, setup)
        client = NotebookClient(nb, timeout=TIMEOUT_S, kernel_name="python3", resources={"metadata": {"path": str(work)}},
                                extra_arguments=["--IPKernelApp.log_level=ERROR"])  # no kernel banner in the build log
        seen: set[Path] = set()
        with client.setup_kernel():
            for index, cell in enumerate(nb.cells):
                if cell.cell_type != "code":
                    continue
                try:
                    client.execute_cell(cell, index)
                except CellExecutionError as exc:
                    raise PluginError(f"examples/{script.name}: cell {index} failed:\n{cell.source}\n{exc}") from exc
                new = sorted(_pngs(work) - seen, key=_written_order)
                seen |= set(new)
                for png in new:
                    data = {"image/png": base64.b64encode(png.read_bytes()).decode("ascii"), "text/plain": png.name}
                    cell.outputs.append(nbformat.v4.new_output("display_data", data=data, metadata={"filename": png.name}))
        nb.cells.pop(0)
    for index, cell in enumerate(nb.cells):  # the notebook numbers its cells as if it had run alone
        if cell.cell_type == "code":
            cell.execution_count = index
    nbformat.validate(nb)  # the downloadable notebook opens in Jupyter as it is
    return nb


def _fence(text: str, lang: str) -> str:
    ticks = "```"
    while ticks in text:
        ticks += "`"
    return f"{ticks}{lang}\n{text.rstrip()}\n{ticks}\n"


def render(nb: nbformat.NotebookNode, stem: str) -> tuple[str, dict[str, bytes]]:
    """The executed notebook as Markdown and its figures (file name -> PNG bytes)."""
    how = (f"*Executed when the documentation was built.* [Download it as a notebook]({stem}.ipynb), "
           f"or run it as a script: `python examples/{stem}.py [OUTPUT_FOLDER]`.\n")
    parts: list[str] = []
    images: dict[str, bytes] = {}
    for cell in nb.cells:
        if cell.cell_type == "markdown":
            parts.append(cell.source.strip() + "\n")
            if len(parts) == 1:
                parts.append(how)
            continue
        if cell.cell_type != "code" or not cell.source.strip():
            continue
        parts.append(_fence(cell.source, "python"))
        text = ""
        for out in cell.outputs:
            if out.output_type == "stream":
                text += out.text
            elif out.output_type in ("execute_result", "display_data"):
                if "image/png" in out.data:
                    if text:
                        parts.append(_fence(text, "text"))
                        text = ""
                    name = f"{stem}_{len(images) + 1}_{out.metadata.get('filename', 'figure.png')}"
                    images[name] = base64.b64decode(out.data["image/png"])
                    parts.append(f"![{out.metadata.get('filename', 'figure')}](img/{name})\n")
                elif "text/plain" in out.data:  # rich (HTML) outputs show as their text form: no scripts
                    text += out.data["text/plain"] + "\n"
        if text:
            parts.append(_fence(text, "text"))
    return "\n".join(parts), images


def on_files(files, config):
    for script in examples():
        stem = script.stem
        nb = execute(script)
        markdown, images = render(nb, stem)
        if not markdown.startswith("# "):
            raise PluginError(f"examples/{script.name}: the script needs a module docstring (its first line is the title)")
        files.append(File.generated(config, f"{FOLDER}/{stem}.md", content=markdown))
        files.append(File.generated(config, f"{FOLDER}/{stem}.ipynb", content=nbformat.writes(nb)))
        for name, data in images.items():
            files.append(File.generated(config, f"{FOLDER}/img/{name}", content=data))
    return files
