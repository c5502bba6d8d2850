"""The public API's docstrings follow the numpy convention the reference renders as tables (issue 23).

Every function and class of ``librate.__all__`` that the README or docs/capabilities.md names has
numpydoc sections: a function ``Parameters`` and ``Returns``; a class ``Parameters`` or
``Attributes`` (an error class may be a sentence: it takes no arguments of its own). Every
``Examples`` section runs as a doctest and prints what it says (reference: the docstrings' own
outputs, computed by the package; the examples are small, a few seconds in all).
"""

import doctest
import inspect
import re
from pathlib import Path

import librate
import pytest

ROOT = Path(__file__).resolve().parents[1]
NAMED_TEXT = (ROOT / "README.md").read_text(encoding="utf-8") + (ROOT / "docs" / "capabilities.md").read_text(encoding="utf-8")
NAMED = sorted(n for n in librate.__all__ if re.search(rf"\b{re.escape(n)}\b", NAMED_TEXT))


def sections(obj) -> set[str]:
    doc = inspect.getdoc(obj) or ""
    return set(re.findall(r"^(\w[\w ]*)\n-{3,}$", doc, re.M))


def test_the_named_api_is_found():
    """The README and capabilities.md name most of the API (so the checks below check something)."""
    assert len(NAMED) >= 40 and {"propagate", "periodicity_map", "System", "OrbitFamily"} <= set(NAMED)


@pytest.mark.parametrize("name", NAMED)
def test_named_api_has_numpydoc_sections(name):
    obj = getattr(librate, name)
    have = sections(obj)
    if inspect.isclass(obj) and issubclass(obj, Exception):
        assert (inspect.getdoc(obj) or "").strip(), name
    elif inspect.isclass(obj):
        assert have & {"Parameters", "Attributes"}, f"{name}: sections {sorted(have)}"
    else:
        assert {"Parameters", "Returns"} <= have, f"{name}: sections {sorted(have)}"


EXAMPLES = sorted(n for n in librate.__all__ if "Examples" in sections(getattr(librate, n)))


def test_examples_are_many():
    assert len(EXAMPLES) >= 15, EXAMPLES


@pytest.mark.parametrize("name", EXAMPLES)
def test_docstring_examples_run(name):
    obj = getattr(librate, name)
    finder = doctest.DocTestFinder(recurse=False)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    tests = finder.find(obj, name, globs={})
    assert tests and any(t.examples for t in tests), name
    for t in tests:
        runner.run(t)
    res = runner.summarize(verbose=False)
    assert res.failed == 0, f"{name}: {res.failed} of {res.attempted} examples failed (see the output above)"
