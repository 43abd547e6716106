"""Online metrics of runs as rows of floats, the form a compiled loop updates.

A study's metrics of a run are a dataclass of float fields whose defaults
are the values before anything happened (NaN: not reached, -inf / +inf: the
running maximum / minimum). A compiled (numba) loop cannot update a
dataclass, so it updates one row of floats per run, the fields in their
declared order; :func:`initial_rows` makes those rows and :func:`from_rows`
the dataclass back (floats for a single run, one array per field for a
batch). Nothing here knows what the metrics are.
"""
from __future__ import annotations

from dataclasses import fields

import numpy as np

__all__ = ["field_names", "initial_rows", "from_rows"]


def field_names(cls) -> tuple[str, ...]:
    """The fields of the dataclass ``cls`` in declared order: the columns of a row."""
    return tuple(f.name for f in fields(cls))


def initial_rows(cls, n: int) -> np.ndarray:
    """(n, fields) float array, every row the defaults of ``cls`` (``cls()``'s values)."""
    first = cls()
    return np.tile(np.array([getattr(first, k) for k in field_names(cls)], float), (n, 1))


def from_rows(cls, M: np.ndarray, single: bool):
    """``cls`` of the rows ``M``: the floats of row 0 (``single``), else a
    copy of each column (one value per run)."""
    names = field_names(cls)
    if single:
        return cls(**{k: float(x) for k, x in zip(names, M[0])})
    return cls(**{k: M[:, j].copy() for j, k in enumerate(names)})
