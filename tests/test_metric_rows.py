"""Metrics kept as rows of floats (:mod:`workbench.sim.metric_rows`) on a toy
dataclass, away from any paper: the defaults as rows, and back to floats or
to one array per field."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from workbench.sim.metric_rows import field_names, from_rows, initial_rows


@dataclass
class Toy:
    t_hit: object = math.nan
    peak: object = -math.inf
    count: object = 0.0


def test_initial_rows_hold_the_defaults_in_field_order():
    assert field_names(Toy) == ("t_hit", "peak", "count")
    M = initial_rows(Toy, 3)
    assert M.shape == (3, 3) and M.dtype == float and M.flags.c_contiguous
    assert np.isnan(M[:, 0]).all() and (M[:, 1] == -np.inf).all() and (M[:, 2] == 0).all()


def test_from_rows_gives_floats_of_one_run_or_columns_of_a_batch():
    M = initial_rows(Toy, 2)
    M[0] = (1.5, 2.0, 3.0)
    M[1, 2] = 7.0
    one = from_rows(Toy, M, single=True)
    assert one == Toy(1.5, 2.0, 3.0) and type(one.peak) is float
    many = from_rows(Toy, M, single=False)
    np.testing.assert_array_equal(many.count, [3.0, 7.0])
    M[1, 2] = 9.0                    # the batch view holds copies, not views of M
    assert many.count[1] == 7.0 and math.isnan(many.t_hit[1])
