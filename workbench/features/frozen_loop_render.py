"""Table cells of a loop frozen at a state (:mod:`workbench.features.frozen_loop`;
pure rendering): its Jacobian, delay-free spectral abscissa and exact delay
margin, as printed. Test on toys: ``tests/test_frozen_loop.py``."""
from __future__ import annotations

import math

from ..printed_grid import quantised
from ..report.markdown import fmt, latex_matrix

__all__ = ["A_DIGITS", "FROZEN_ALIGN", "FROZEN_HEADS", "frozen_loop_cells", "margin_cell"]

#: The Jacobian A is printed on the grid of 1e-5 of its largest entry's decade
#: (:func:`workbench.printed_grid.quantised`): its central differences (step
#: 1e-7 on a state of order 0.1, say) carry a rounding error of about
#: eps |f| / 1e-7 ~ 1e-9, so an entry of 2.6e-7 has no reproducible second
#: digit (2.6e-7 as designed, 2.62e-7 with the inputs moved 3 ulp); on the
#: grid it prints 0.
A_DIGITS = 6
#: Column headers of :func:`frozen_loop_cells` and their alignment (``md_table``).
FROZEN_HEADS, FROZEN_ALIGN = ("A_loc", "abscissa (1/s)", "exact margin"), "lrl"


def margin_cell(margin) -> str:
    """An exact delay margin (:class:`workbench.margins.DelayMargin`) in a
    table cell: "unstable at h = 0", "∞ (delay-independent)" or 3 digits in s."""
    if margin.reason == "unstable-at-zero-delay":
        return "unstable at h = 0"
    return "∞ (delay-independent)" if math.isinf(margin.h) else fmt(margin.h, 3) + " s"


def frozen_loop_cells(A, abscissa: float, margin, digits: int = A_DIGITS) -> list[str]:
    """[A as an inline LaTeX matrix (3 digits, on the grid of ``digits``),
    the delay-free spectral abscissa (1/s, 3 digits), :func:`margin_cell`]."""
    return [f"${latex_matrix(quantised(A, digits), 3)}$", fmt(abscissa, 3), margin_cell(margin)]
