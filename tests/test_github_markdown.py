"""Every committed report renders on GitHub as written.

GitHub applies CommonMark backslash escapes inside ``$...$`` / ``$$...$$``
before it renders math (``\\\\`` becomes ``\\``, ``\\,`` becomes ``,``), so
math is written in its documented safe forms: ```` ```math ```` fences and
``$`...`$``, whose text is code and reaches the math renderer verbatim.
markdown-it-py parses the reports the CommonMark way (with GFM tables): every
math segment must come out of the parser unchanged, no ``$`` may remain
outside code, and every table row must parse as a row.
"""
from __future__ import annotations

import re
from pathlib import Path

import pytest

markdown_it = pytest.importorskip("markdown_it")

from workbench.report.markdown import github_math  # noqa: E402

REPORTS = sorted((Path(__file__).resolve().parents[1] / "reports").glob("*.md"))
INLINE = re.compile(r"\$`(.+?)`\$")
DISPLAY = re.compile(r"^```math\n(.*?)\n```$", re.M | re.S)


def _parser():
    return markdown_it.MarkdownIt("commonmark").enable("table")


def _parsed_code(md: str) -> tuple[list[str], list[str], int]:
    """(inline code contents, ```math fence contents, table rows) as parsed."""
    inline, fences, rows = [], [], 0
    for tok in _parser().parse(md):
        if tok.type == "fence" and tok.info.strip() == "math":
            fences.append(tok.content.rstrip("\n"))
        elif tok.type == "tr_open":
            rows += 1
        elif tok.type == "inline":
            inline += [c.content for c in tok.children or () if c.type == "code_inline"]
    return inline, fences, rows


def _source_rows(md: str) -> int:
    """Table rows in the source: header and body lines of every table."""
    lines = md.split("\n")
    n = 0
    for i, line in enumerate(lines):
        if re.fullmatch(r"\|( *:?-+:? *\|)+", line.strip()):
            n += 1                                    # the header row
            j = i + 1
            while j < len(lines) and lines[j].startswith("|"):
                n, j = n + 1, j + 1
    return n


@pytest.mark.parametrize("path", REPORTS, ids=[p.stem for p in REPORTS])
def test_math_reaches_the_renderer_verbatim(path):
    md = path.read_text(encoding="utf-8")
    inline, fences, _ = _parsed_code(md)
    # in a table cell a literal "|" is written "\|" (GFM unescapes it)
    want_inline = [m.replace("\\|", "|") for m in INLINE.findall(md)]
    want_display = DISPLAY.findall(md)
    assert sorted(want_display) == sorted(fences)
    missing = [m for m in want_inline if m not in inline]
    assert missing == []


@pytest.mark.parametrize("path", REPORTS, ids=[p.stem for p in REPORTS])
def test_no_dollar_math_outside_code(path):
    md = path.read_text(encoding="utf-8")
    outside = DISPLAY.sub("", md)
    outside = INLINE.sub("", outside)
    outside = re.sub(r"`[^`\n]*`", "", outside)
    assert [line for line in outside.split("\n") if "$" in line] == []


@pytest.mark.parametrize("path", REPORTS, ids=[p.stem for p in REPORTS])
def test_tables_keep_parsing(path):
    md = path.read_text(encoding="utf-8")
    assert _parsed_code(md)[2] == _source_rows(md)


def test_the_old_dollar_form_would_lose_backslashes():
    # what the check guards against: CommonMark escapes applied to $$ math
    old = "$$\nA = \\begin{bmatrix} 1 & 2 \\\\ 3 & 4 \\end{bmatrix},\\, x\n$$"
    text = "".join(c.content for tok in _parser().parse(old) if tok.type == "inline"
                   for c in tok.children if c.type == "text")
    assert "\\\\" not in text and "\\," not in text          # both escapes were eaten
    new = github_math(old)
    assert new.startswith("```math\n") and _parsed_code(new)[1] == [old[3:-3].strip("\n")]


def test_converter_leaves_code_alone_and_converts_inline():
    md = "Cost `$x$` and $a \\, b$, then\n```\n$y$\n```\nand $$ not math"
    out = github_math(md)
    assert "`$x$`" in out and "$`a \\, b`$" in out and "\n$y$\n" in out
    assert out.endswith("and $$ not math")
