"""A mkdocs hook: the equations as MathML, written at build time, so that the site needs no
script and no network to show them (every current browser renders MathML).

``pymdownx.arithmatex`` in generic mode leaves each equation as TeX in
``<span class="arithmatex">\\(...\\)</span>`` (inline) or ``<div class="arithmatex">\\[...\\]</div>``
(display); this hook replaces each by the MathML that ``latex2mathml`` makes of it. TeX that
``latex2mathml`` cannot read stops the build, naming the page and the equation.
"""
from __future__ import annotations

import html
import re

from mkdocs.exceptions import PluginError

_MATH = re.compile(
    r'<(?P<tag>span|div) class="arithmatex">\s*'
    r'(?:\\\((?P<inline>.*?)\\\)|\\\[(?P<display>.*?)\\\])'
    r'\s*</(?P=tag)>', re.S)


def _tex(escaped: str) -> str:
    """The TeX arithmatex wrote, its &, < and > escaped once (inline) or twice (display)."""
    tex = html.unescape(escaped)
    if re.search(r"&(?:amp|lt|gt);", tex):
        tex = html.unescape(tex)
    return tex.strip()


def to_mathml(tex: str, display: bool) -> str:
    """MathML of one equation: a ``<math>`` element, ``display="block"`` for a displayed one."""
    from latex2mathml.converter import convert
    return convert(tex, display="block" if display else "inline")


def on_page_content(html_text: str, page, config, files) -> str:
    """Replace every arithmatex equation of a page by its MathML."""
    def replace(match: re.Match) -> str:
        display = match.group("display") is not None
        tex = _tex(match.group("display") if display else match.group("inline"))
        try:
            mathml = to_mathml(tex, display)
        except Exception as error:   # latex2mathml raises its own exception types and plain ones
            raise PluginError(f"{page.file.src_uri}: cannot convert the equation {tex!r} to MathML: {error}") from error
        css = "arithmatex arithmatex-display" if display else "arithmatex"
        return f'<{match.group("tag")} class="{css}">{mathml}</{match.group("tag")}>'

    return _MATH.sub(replace, html_text)
