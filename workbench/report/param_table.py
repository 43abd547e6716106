"""The parameter table of a report: name, value, unit, meaning, source.

A pure function of its inputs, so the same parameters give byte-identical
Markdown.
"""
from __future__ import annotations

from typing import Mapping, Sequence

from .markdown import fmt, md_table


def param_table(params: Mapping, doc: Mapping[str, str], digits: int,
                extra: Sequence[Sequence] = ()) -> str:
    """Markdown table of ``params`` (name -> object with ``value``, ``unit``, ``source``).

    Parameters
    ----------
    params : mapping
        Parameter name -> quantity (``.value``, ``.unit``, ``.source``), in row order.
    doc : mapping
        Parameter name -> meaning (an empty cell for a name it lacks).
    digits : int
        Significant digits of each value (:func:`workbench.report.markdown.fmt`).
    extra : sequence of rows
        Further ready-made five-cell rows appended after the parameters.

    Returns
    -------
    str
        The table with columns parameter, value, unit, meaning, source.
    """
    rows = [[f"`{k}`", fmt(q.value, digits), q.unit, doc.get(k, ""), q.source]
            for k, q in params.items()]
    return md_table(["parameter", "value", "unit", "meaning", "source"], [*rows, *extra],
                    "lrlll")
