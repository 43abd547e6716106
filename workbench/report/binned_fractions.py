"""Fractions of flagged runs per bin of one sampled parameter (Monte Carlo).

The parameter's range is cut into equal bins, half-open except the last,
which is closed (it holds the range's upper end); each bin's row gives its
interval, its number of runs and, per flag, the fraction of its runs
flagged (:data:`~workbench.report.case_tables.MISSING` for an empty bin);
:func:`binned_fraction_table` lays the rows out as a Markdown table.

Used by the ``antiskid-run`` study's Monte Carlo section (paper 003);
``tests/test_case_tables.py`` renders a toy.
"""
from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np

from .case_tables import MISSING
from .markdown import fmt, md_table


def binned_fraction_rows(samples, lo: float, hi: float, bins: int,
                         flags: Sequence, sig: int = 3, frac_sig: int = 2) -> list[list]:
    """Rows ``[interval, runs, fraction of flags[0], ...]`` of ``bins`` equal
    bins of [lo, hi] (``samples`` and each flag: one value per run)."""
    s = np.asarray(samples, float)
    flags = [np.asarray(f, bool) for f in flags]
    edges = np.linspace(lo, hi, bins + 1)
    rows = []
    for i, (a, b) in enumerate(zip(edges[:-1], edges[1:])):
        last = i == bins - 1
        sel = (s >= a) & ((s <= b) if last else (s < b))
        n = int(sel.sum())
        rows.append([f"[{fmt(a, sig)}, {fmt(b, sig)}" + ("]" if last else ")"), n]
                    + [fmt(f[sel].mean(), frac_sig) if n else MISSING for f in flags])
    return rows


def binned_fraction_table(name: str, samples, lo: float, hi: float, bins: int,
                          flags: Mapping[str, Sequence], sig: int = 3) -> str:
    """Markdown of :func:`binned_fraction_rows`: columns ``name`` (the
    sampled parameter's bins), runs, then "fraction <label>" per entry of
    ``flags`` (label -> one flag per run), in order."""
    rows = binned_fraction_rows(samples, lo, hi, bins, list(flags.values()), sig)
    return md_table([name, "runs", *(f"fraction {k}" for k in flags)], rows,
                    "lr" + "r" * len(flags))
