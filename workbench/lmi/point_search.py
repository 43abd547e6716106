"""The point search continued past an inconclusive answer (issue 21 item 4).

:func:`~workbench.lmi.core.bisect_delay` shrinks its search interval at an
inconclusive step as at a refuted one. When the search ended on such a step
(the smallest not-certified delay above the certified one is inconclusive and
nothing at or below it was refuted), one inaccurate solve has decided the
bound: the search is run again above that delay, and the larger certified
point is kept. Certified steps are point certificates either way.
"""
from __future__ import annotations

import math
from typing import Callable

from .core import Bracket, Outcome, Step, bisect_delay

#: Times the search is resumed past an inconclusive answer.
MAX_RESUMES = 2


def blocking_inconclusive(br: Bracket) -> float | None:
    """The inconclusive delay (s) that ended the search, or None."""
    above = [s for s in br.steps if s.outcome is not Outcome.CERTIFIED and s.h > br.h_certified]
    if not above:
        return None
    first = min(above, key=lambda s: s.h)
    if first.outcome is not Outcome.INCONCLUSIVE:
        return None
    return first.h


def resumed(decide: Callable[[float], Step], br: Bracket, *, h_hi: float, rel_tol: float,
            max_solves: int) -> Bracket:
    """``br`` continued above an inconclusive step that ended it (module docstring)."""
    for _ in range(MAX_RESUMES):
        h = blocking_inconclusive(br)
        budget = max_solves - len(br.steps)
        if h is None or budget <= 0 or not h < h_hi:
            return br
        start = min(h * (1 + 10 * rel_tol), h_hi)
        more = bisect_delay(decide, h_lo=start, h_hi=h_hi, rel_tol=rel_tol, guess=start,
                            max_solves=budget)
        steps = br.steps + more.steps
        refuted = min((s.h for s in steps if s.outcome is Outcome.REFUTED), default=math.inf)
        if more.h_certified > br.h_certified:
            br = Bracket(more.h_certified, refuted, Outcome.CERTIFIED, more.certificate, steps)
        else:
            return Bracket(br.h_certified, refuted, br.outcome, br.certificate, steps)
    return br
