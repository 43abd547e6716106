"""Paper 003's cruise loop implemented digitally: the certified lowest control
rate on the linearisation (issue 34), to put next to the lowest rate the
sampled-data simulation of the nonlinear laws finds (issue 20,
:mod:`.antiskid_sampled`).

The loop is the cruise linearisation of an ``antiskid-cruise`` design,
delta x' = A delta x + B delta u, closed with a printed gain of paper 003
(``[[synthesis.published]]``, Table 3), u = K x(t_k) held (ZOH). Two
implementations:

* **with the predictor** (exact prediction over the loop delay): the plant
  sees K x(s_k) from s_k on, a delay-free sampled loop — certified for every
  interval sequence by :mod:`workbench.lmi.sampled`;
* **without a predictor**: the command arrives after the loop delay h_m of
  the printed row plus a measurement delay, certified by the input-delay
  approach (:func:`workbench.digital.implementation` with a network delay).

Scope: the linearisation at the cruise point only. The simulated lowest rate
also covers traction from rest and the entry into braking (law 69), which the
linearisation does not see; the two rates answer different questions.

Why it stays in papers/: the general certificate is
:func:`workbench.digital.implementation` (any A, B, K, delays); what is here
is paper 003's choice of loop (its cruise linearisation, a printed row of
Table 3 and its h_m).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["CruiseSampling", "cruise_sampling"]


@dataclass(frozen=True)
class CruiseSampling:
    """Certified sampling bounds of the cruise linearisation with one printed gain."""

    design: str
    eps: float
    K: np.ndarray
    h_m: float
    measurement_delay: float
    predictor: object          # ImplementationResult, delay-free
    delayed: object            # ImplementationResult, network delay [h_m, h_m + measurement]

    @property
    def rate_predictor(self) -> float:
        """Certified lowest control rate with the predictor (Hz): 1 / T_certified."""
        return 1.0 / self.predictor.T_certified

    @property
    def rate_delayed(self) -> float:
        """Certified lowest control rate without a predictor (Hz)."""
        return 1.0 / self.delayed.T_certified


def cruise_sampling(path: str, *, eps: float = 0.35,
                    measurement_delay: float = 0.002) -> CruiseSampling:
    """Certified lowest control rates of a cruise design's loop with the printed gain.

    Parameters
    ----------
    path : str
        An ``antiskid-cruise`` design file.
    eps : float
        Which printed row of ``[[synthesis.published]]`` (its K and h_m).
    measurement_delay : float
        Added to h_m in the implementation without a predictor (s).

    Returns
    -------
    CruiseSampling
    """
    from ...design import load_design
    from ...digital import implementation
    from ...errors import DesignError
    from .antiskid_cruise import operating_point
    design = load_design(path)
    if design.kind != "antiskid-cruise":
        raise DesignError(path, "design.kind", design.kind, 'an "antiskid-cruise" design')
    rows = [p for p in design.spec.published if p.eps == eps]
    if not rows:
        raise DesignError(path, "synthesis.published", eps, "a printed row with this eps")
    row = rows[0]
    lin = operating_point(design.spec)[3]
    A, B = np.asarray(lin.A, float), np.asarray(lin.B, float)
    K = np.asarray(row.K, float).reshape(B.shape[1], -1)
    pred = implementation(A, K, B=B)
    late = implementation(A, K, B=B, network_delay=(row.h_m, row.h_m + measurement_delay))
    return CruiseSampling(design.name, eps, K, row.h_m, measurement_delay, pred, late)
