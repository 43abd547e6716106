"""``workbench.design_gain``: a state-feedback gain designed to requirements.

(Not ``workbench.design``: that name is the design-file module :mod:`workbench.design`.)

The API face of :mod:`workbench.requirements` (the same as a
``delay-feedback`` design's requirement set): a delay range, a decay rate,
an L2 gain from a declared disturbance to a declared output, an input limit
and the objective to optimise subject to the others.
"""
from __future__ import annotations

import math
from typing import Literal, Sequence

import numpy as np

from .api import _matrix, _system
from .requirements import RequirementResult, Requirements, design_to_requirements

__all__ = ["design_gain"]

#: Declared range of h_max (s), as a design's ``[requirements] delay``
#: (:data:`workbench.kinds.delay_feedback.requirements.H_MIN`, ``H_MAX``; issue 32).
H_RANGE = (1e-6, 1e3)


def _positive(name: str, v, *, allow_none: bool = True) -> float | None:
    if v is None and allow_none:
        return None
    if isinstance(v, bool) or not isinstance(v, (int, float, np.floating)) or not (
            0 < v < math.inf):
        shown = float(v) if isinstance(v, np.floating) else v     # not "np.float64(0.0)"
        raise ValueError(f"{name} = {shown!r}; expected a positive finite number")
    return float(v)


def design_gain(sys, B=None, *, delay: tuple[float, float], decay_rate: float | None = None,
           l2_gain: float | None = None, input_limit: Sequence[float] | float | None = None,
           box: Sequence[float] | None = None,
           objective: Literal["decay", "l2_gain", "delay"] = "decay",
           vertices: Sequence[tuple] | None = None, Bw=None, Cz=None, Dz=None,
           rate: float | None = None) -> RequirementResult:
    """A gain u = K x(t - h) designed to requirements over a delay range.

    Parameters
    ----------
    sys : control.StateSpace or (n, n) array_like
        The plant x' = A x + B u(t - h) (or A with ``B``).
    delay : (float, float)
        [h_min, h_max] (s): every constant delay the loop must tolerate.
    decay_rate : float, optional
        Required decay rate alpha (1/s): every solution decays at least like
        e^{-alpha t}, for every delay in the range and every vertex.
    l2_gain : float, optional
        Required L2 gain gamma from w to z (needs ``Bw`` and ``Cz``).
    input_limit : float or sequence of float, optional
        |u_k| <= u_max_k for every constant initial history in ``box``.
    box : sequence of float, optional
        Half-widths of the initial-deviation box (state units).
    objective : {"decay", "l2_gain", "delay"}
        What is optimised subject to the other requirements.
    vertices : sequence of (A_i, B_i), optional
        Further operating points (one gain for all; ``sys`` is the first).
    Bw, Cz, Dz : array_like, optional
        Disturbance input matrix and performance output z = Cz x + Dz u(t - h)
        (Dz defaults to 0).
    rate : float, optional
        A time-varying delay h(t) in ``delay`` with |h'(t)| <= rate
        (0 <= rate < 1): every certificate then covers every such delay
        function (h(t) in [0, h_max]); the exact checks stay on constant
        delays, a special case.

    Returns
    -------
    RequirementResult
        The rounded gain (the gain every certificate is about) and one row per
        requirement: required, certified, exact, verdict.

    Raises
    ------
    ValueError
        Bad shapes, values or a missing disturbance/output/box.
    """
    A, B = _system(sys, B)
    n = A.shape[0]
    if B is None:
        raise ValueError("B is missing; pass a StateSpace or A and B")
    B = _matrix(B, "B", n, None if np.ndim(B) == 2 else 1)
    points = [(A, B)] + [(_matrix(Ai, f"vertices[{i}].A", n, n),
                          _matrix(Bi, f"vertices[{i}].B", n, B.shape[1]))
                         for i, (Ai, Bi) in enumerate(vertices or ())]
    try:
        lo, hi = (float(v) for v in delay)
    except (TypeError, ValueError):
        raise ValueError(f"delay = {delay!r}; expected [h_min, h_max] (s)") from None
    if not (0 <= lo <= hi and H_RANGE[0] <= hi <= H_RANGE[1]):
        raise ValueError(f"delay = {delay!r}; expected 0 <= h_min <= h_max, h_max in "
                         f"[{H_RANGE[0]:g}, {H_RANGE[1]:g}] (s)")
    if objective not in ("decay", "l2_gain", "delay"):
        raise ValueError(f"objective = {objective!r}; expected 'decay', 'l2_gain' or 'delay'")
    decay_rate = _positive("decay_rate", decay_rate)
    l2_gain = _positive("l2_gain", l2_gain)
    l2 = l2_gain is not None or objective == "l2_gain"
    if l2:
        if Bw is None or Cz is None:
            raise ValueError("l2_gain needs Bw (disturbance input) and Cz (output); "
                             "got None")
        Bw = _matrix(Bw, "Bw", n, None if np.ndim(Bw) == 2 else 1)
        Cz = _matrix(Cz, "Cz", None, n)
        Dz = (np.zeros((Cz.shape[0], B.shape[1])) if Dz is None
              else _matrix(Dz, "Dz", Cz.shape[0], B.shape[1]))
    limit = None
    if input_limit is not None:
        limit = tuple(_positive(f"input_limit[{k}]", u) for k, u in
                      enumerate(np.atleast_1d(np.asarray(input_limit, float))))
        if len(limit) != B.shape[1]:
            raise ValueError(f"input_limit has {len(limit)} entries; expected {B.shape[1]}")
        if box is None or np.size(box) != n:
            raise ValueError(f"box = {box!r}; expected {n} half-widths with input_limit")
        box = tuple(float(b) for b in np.ravel(box))
        if not all(0 <= b < math.inf for b in box) or not any(box):
            raise ValueError(f"box = {box!r}; expected non-negative finite half-widths")
    if rate is not None and (isinstance(rate, bool) or not isinstance(
            rate, (int, float, np.floating)) or not 0 <= rate < 1):
        raise ValueError(f"rate = {rate!r}; expected a delay-derivative bound 0 <= rate < 1")
    req = Requirements((lo, hi), decay_rate, l2_gain, limit, box if limit else None, objective,
                       None if rate is None else float(rate))
    return design_to_requirements(points, req, Bw=Bw, Cz=Cz, Dz=Dz)
