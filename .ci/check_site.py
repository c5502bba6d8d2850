"""Check a built documentation site reads well offline (issue 23): run after `mkdocs build`.

usage: python .ci/check_site.py SITE_DIR

Fails (exit 1, listing page and excerpt) when any HTML page
- still holds raw TeX: ``\\(``, ``\\)``, ``\\[`` ... ``\\]`` math delimiters, ``$$``, or an
  ``arithmatex`` element the build-time renderer did not convert;
- loads a script or stylesheet from another host (a CDN): the site must work without network;
- shows a raw Sphinx role (``:func:``, ``:class:``, ``:meth:``...).
It also requires that the pages with math (physics.md ...) hold MathML (``<math``), at least as
many formulas as the Markdown sources mark, so a formula cannot vanish silently, and that every
example ran into its tutorial page (docs/hooks/tutorials.py): the page exists, shows the examples'
last printed line ("written: ...") and at least one figure whose PNG is in the site, and its
executed notebook is there.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RAW = [
    (re.compile(r"\\\(|\\\)"), "raw inline TeX delimiter"),
    (re.compile(r"\$\$"), "raw $$"),
    (re.compile(r"\\\[[^\]]*\\\]", re.S), "raw display TeX"),
    (re.compile(r'class="arithmatex"'), "unrendered arithmatex element"),
    (re.compile(r'<script[^>]+src="(?:https?:)?//'), "script from another host"),
    (re.compile(r'<link[^>]+href="(?:https?:)?//[^"]+\.(?:css|js)'), "stylesheet from another host"),
    (re.compile(r":(?:func|class|meth|attr|data|mod|exc|obj):"), "raw Sphinx role"),
]
# inline \( \) and display \[ \] formulas in the Markdown sources
SOURCE_MATH = re.compile(r"\\\((.+?)\\\)|\\\[(.+?)\\\]|\$\$(.+?)\$\$", re.S)


def strip_code(html: str) -> str:
    """The page without <pre>/<code> blocks (code may show TeX or roles on purpose)."""
    return re.sub(r"<(pre|code)\b.*?</\1>", "", html, flags=re.S)


def check_tutorials(site: Path) -> list[str]:
    """Every numbered example is an executed tutorial page with its output, figures and notebook."""
    problems = []
    for script in sorted((ROOT / "examples").glob("[0-9][0-9]_*.py")):
        page = site / "tutorials" / script.stem / "index.html"
        if not page.is_file():
            problems.append(f"{page.relative_to(site)}: no tutorial page for examples/{script.name}")
            continue
        text = page.read_text(encoding="utf-8")
        images = re.findall(r'<img[^>]+src="([^"]+\.png)"', text)
        missing = [src for src in images if not (page.parent / src).resolve().is_file()]
        if not images or missing:
            problems.append(f"{page.relative_to(site)}: figures {images}, missing {missing}")
        if "written: " not in text:
            problems.append(f"{page.relative_to(site)}: no 'written: ...' line (every example prints it last): did it run?")
        if not (site / "tutorials" / f"{script.stem}.ipynb").is_file():
            problems.append(f"tutorials/{script.stem}.ipynb: missing")
    return problems


def main(site: Path) -> int:
    problems = []
    pages = sorted(site.rglob("*.html"))
    if not pages:
        print(f"no HTML pages under {site}", file=sys.stderr)
        return 1
    for page in pages:
        text = strip_code(page.read_text(encoding="utf-8"))
        for pattern, what in RAW:
            for m in pattern.finditer(text):
                problems.append(f"{page.relative_to(site)}: {what}: {text[max(0, m.start() - 40):m.end() + 40]!r}")
                break
    n_math = 0
    for md in sorted((ROOT / "docs").rglob("*.md")):
        src = re.sub(r"```.*?```|`[^`\n]*`", "", md.read_text(encoding="utf-8"), flags=re.S)
        expected = len(SOURCE_MATH.findall(src))
        if not expected:
            continue
        rel = md.relative_to(ROOT / "docs").with_suffix("")
        html_path = site / ("index.html" if rel.name == "index" else rel / "index.html")
        found = html_path.read_text(encoding="utf-8").count("<math") if html_path.is_file() else 0
        n_math += found
        if found < expected:
            problems.append(f"{html_path.relative_to(site)}: {found} MathML formulas, the source marks {expected}")
    if not n_math:
        problems.append("no MathML formula anywhere in the site")
    problems += check_tutorials(site)
    for p in problems:
        print(p, file=sys.stderr)
    print(f"site check: {len(pages)} pages, {n_math} MathML formulas, {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1])))
