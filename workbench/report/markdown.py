"""Pure Markdown helpers: numbers with their meaningful digits, tables, LaTeX.

Everything here is a pure function of its inputs, so the same results give
byte-identical Markdown.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Callable, Sequence

from ..printed_grid import sig_round


@dataclass(frozen=True)
class Figure:
    """A figure to draw: ``draw(fig)`` fills a matplotlib Figure.

    Attributes
    ----------
    name : str
        File name (``<name>.png`` in the design's figure folder).
    caption : str
    draw : callable
        Pure function of the results it closes over.
    size : tuple[float, float]
        Inches.
    title : str
        Drawn above the figure (design, figure and key parameters), so a
        figure cut into a review pack keeps its meaning; the report writer
        fills it (:func:`workbench.report.writer.build`).
    """

    name: str
    caption: str
    draw: Callable = field(compare=False, repr=False)
    size: tuple[float, float] = (6.4, 4.0)
    title: str = ""


@dataclass(frozen=True)
class Rendered:
    """Markdown sections (each starting with a ``## `` heading) and figures.

    ``anchors``: (pattern, section heading) pairs; a finding whose claim
    names a quantity whose start matches the pattern (a regular expression,
    :func:`re.match`) links to that section.
    """

    sections: tuple[str, ...]
    figures: tuple[Figure, ...] = ()
    anchors: tuple[tuple[str, str], ...] = ()


def slug(heading: str) -> str:
    """The anchor GitHub gives a heading: lower case, every character but
    letters, digits, spaces, ``-`` and ``_`` dropped, spaces made ``-``."""
    text = heading.strip().lower()
    return "".join("-" if ch == " " else ch for ch in text
                   if ch.isalnum() or ch in " -_")


def fmt_floor(x: float, sig: int = 2) -> str:
    """A positive finite lower bound rounded *down* to ``sig`` significant
    digits (a lower bound may only be rounded down). For LMI bounds of a given
    gain, whose last digits depend on the bisection's path and hence on the
    CPU's BLAS kernels."""
    return fmt(sig_round(x, sig, math.floor, 1e-12), sig)


def fmt(x, sig: int = 4) -> str:
    """A number with ``sig`` significant digits (solver noise below them does
    not change the text); ``inf``, ``nan``, ``None`` and words pass through."""
    if x is None:
        return "—"
    if isinstance(x, str):
        return x
    if isinstance(x, bool):
        return str(x).lower()
    x = float(x)
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "∞" if x > 0 else "−∞"
    if x == 0:
        return "0"
    s = f"{x:.{sig}g}"
    if "e" in s:
        m, e = s.split("e")
        return f"{m}e{int(e)}"
    return s


#: A final or minimum error below this fraction of the same state's peak error
#: is rounding noise of the integration (its last bits differ between CPUs and
#: under a few-ulp change of the inputs): printed as a bound, not as digits
#: (issue 36, item 5). The one source of the floor: the claims table and the
#: studies' own tables use :func:`noise_cell`.
NOISE_FLOOR = 1e-9
#: ``<prefix>.final_error.<state>`` / ``<prefix>.min_error.<state>``: a metric
#: :func:`noise_peak` finds the peak of (``<prefix>.peak_error.<state>``).
_ERROR_METRIC = re.compile(r"^(?P<pre>(?:.*\.)?)(?:final_error|min_error)\.(?P<state>[^.]+)$")


def noise_peak(name: str, values: dict) -> float | None:
    """The peak error that sets the noise floor of metric ``name``: for
    ``<prefix>.final_error.<state>`` or ``<prefix>.min_error.<state>``, the
    value of ``<prefix>.peak_error.<state>`` in ``values``; else None."""
    m = _ERROR_METRIC.match(name)
    if m is None:
        return None
    peak = values.get(f"{m['pre']}peak_error.{m['state']}")
    return float(peak) if isinstance(peak, (int, float)) and not isinstance(peak, bool) \
        else None


def noise_cell(v, peak: float | None, sig: int = 4) -> str:
    """``fmt(v, sig)``, or "< 1e-9 × peak" when ``v`` is below
    :data:`NOISE_FLOOR` times ``peak`` (both finite; None: no floor)."""
    if (peak is not None and isinstance(v, (int, float)) and not isinstance(v, bool)
            and math.isfinite(v) and math.isfinite(peak) and abs(v) < NOISE_FLOOR * peak):
        return f"< {fmt(NOISE_FLOOR)} × peak"
    return fmt(v, sig)


def md_table(header: Sequence[str], rows: Sequence[Sequence[object]],
             align: str | None = None) -> str:
    """A GitHub Markdown table; ``align`` is a string of l/r/c per column."""
    align = align or "l" * len(header)
    marks = {"l": ":---", "r": "---:", "c": ":---:"}
    esc = lambda c: str(c).replace("|", "\\|").replace("\n", " ")
    lines = ["| " + " | ".join(esc(h) for h in header) + " |",
             "| " + " | ".join(marks[a] for a in align) + " |"]
    lines += ["| " + " | ".join(esc(c) for c in r) + " |" for r in rows]
    return "\n".join(lines)


def latex_matrix(M, sig: int = 4) -> str:
    """``\\begin{bmatrix}...`` of a numeric matrix."""
    rows = [" & ".join(_tex_num(v, sig) for v in row) for row in M]
    return r"\begin{bmatrix} " + r" \\ ".join(rows) + r" \end{bmatrix}"


def _tex_num(v, sig):
    s = fmt(v, sig)
    if "e" in s:
        m, e = s.split("e")
        return rf"{m}\times 10^{{{int(e)}}}"
    return s.replace("−", "-")


def margin_text(margin: float) -> str:
    """A re-check margin as the decade it lies in (``"≥ 1e-05"`` for 3.2e-5),
    or ``"fail"``: the digits of a solver's internal value that hold on every
    machine."""
    if not (math.isfinite(margin) and margin > 0):
        return "fail"
    return f"≥ 1e{math.floor(math.log10(margin)):+03d}"


_FENCE = re.compile(r"^(```|~~~)")
_DISPLAY = re.compile(r"^\$\$\n(.*?)\n\$\$$", re.M | re.S)
_CODE_SPAN = re.compile(r"(`+)(?:.*?[^`])?\1(?!`)")
_INLINE = re.compile(r"(?<![$\\])\$(?![$\s])((?:[^$\n\\]|\\.)+?)(?<![\s\\])\$(?![$\w])")


def github_math(markdown: str) -> str:
    """Math in the forms GitHub renders without touching backslashes.

    GitHub's Markdown applies backslash escapes inside ``$...$`` and
    ``$$...$$`` before it renders the math, so ``\\\\``, ``\\,`` and ``\\:``
    break (a matrix collapses to one row). Its documented safe forms are
    code: display math as a fenced ```` ```math ```` block and inline math as
    ``$`...`$``; the text between the delimiters is then passed verbatim.
    Fenced code blocks and existing code spans are left alone.
    """
    out, fenced = [], False
    for block in re.split(r"(^```.*?^```$)", _DISPLAY.sub(lambda m: f"```math\n{m[1]}\n```",
                                                          markdown), flags=re.M | re.S):
        if block.startswith("```"):
            out.append(block)
            continue
        lines = []
        for line in block.split("\n"):
            fenced ^= bool(_FENCE.match(line))
            if fenced:
                lines.append(line)
                continue
            parts, last = [], 0
            for m in _CODE_SPAN.finditer(line):
                parts.append(_INLINE.sub(r"$`\1`$", line[last:m.start()]))
                parts.append(m[0])
                last = m.end()
            parts.append(_INLINE.sub(r"$`\1`$", line[last:]))
            lines.append("".join(parts))
        out.append("\n".join(lines))
    return "".join(out)
