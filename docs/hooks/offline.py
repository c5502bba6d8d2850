"""mkdocs hooks: the site reads well offline (issue 23).

- Math is rendered at build time: every formula that ``pymdownx.arithmatex`` (generic mode) marks,
  ``\\(...\\)`` inline and ``\\[...\\]`` display, becomes MathML (``latex2mathml``), which browsers
  draw natively: no JavaScript, no CDN. A formula the converter rejects fails the build, naming
  the page and the formula.
- Sphinx roles left in docstrings (``:func:`x```, ``:class:`x```...) lose their role prefix, so
  the name shows as code rather than as raw reST.

``.ci/check_site.py`` checks the built HTML: no raw TeX delimiters, MathML present.
"""

from __future__ import annotations

import html
import re

from latex2mathml.converter import convert
from mkdocs.exceptions import PluginError

_MATH = re.compile(r'<(span|div) class="arithmatex">\s*(\\\(|\\\[)(.*?)(\\\)|\\\])\s*</\1>', re.S)
_ROLE = re.compile(r":(?:py:)?(?:func|class|meth|attr|data|mod|exc|obj|const):(?=<code>|<a |<span |`)")


def _mathml(page, match: re.Match) -> str:
    tag, opening, tex = match.group(1), match.group(2), html.unescape(match.group(3)).strip()
    display = "block" if opening == "\\[" else "inline"
    try:
        mathml = convert(tex, display=display)
    except Exception as exc:  # the converter raises several types; the build stops either way
        raise PluginError(f"{page.file.src_path}: cannot render the formula {tex!r}: {exc}") from exc
    return f'<{tag} class="math">{mathml}</{tag}>'


def on_page_content(html_text: str, page, config, files) -> str:
    html_text = _MATH.sub(lambda m: _mathml(page, m), html_text)
    return _ROLE.sub("", html_text)
