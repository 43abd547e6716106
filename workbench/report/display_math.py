"""Display-math blocks for Markdown reports.

A pure function of its inputs, so the same equations give byte-identical
Markdown.
"""
from __future__ import annotations

from typing import Iterable


def display_math(eqs: Iterable[str]) -> str:
    """Join LaTeX equations as ``$$`` display blocks separated by blank lines.

    Parameters
    ----------
    eqs : iterable of str
        LaTeX source of each equation, without delimiters.

    Returns
    -------
    str
        ``"$$\\n<eq>\\n$$"`` per equation, joined by ``"\\n\\n"``; empty for no
        equations.
    """
    return "\n\n".join(f"$$\n{e}\n$$" for e in eqs)
