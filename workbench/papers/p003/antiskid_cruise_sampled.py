"""Paper 003's cruise loop implemented digitally: the certified lowest control
rate on the linearisation (issue 34), to put next to the lowest rate the
sampled-data simulation of the nonlinear laws finds (issue 20,
:mod:`.antiskid_sampled`).

The loop is the cruise linearisation of an ``antiskid-cruise`` design,
delta x' = A delta x + B delta u, closed with a printed gain of paper 003
(``[[synthesis.published]]``, Table 3), u = K x(t_k) held (ZOH), its loop
delay the h_m of the printed row, certified with and without the predictor
(:func:`workbench.features.sampled.predictor_sampling`).

Scope: the linearisation at the cruise point only. The simulated lowest rate
also covers traction from rest and the entry into braking (law 69), which the
linearisation does not see; the two rates answer different questions.

Why it stays in papers/: the general certificate is
:func:`workbench.features.sampled.predictor_sampling` (any A, B, K, delays);
what is here is paper 003's choice of loop (its cruise linearisation, a
printed row of Table 3 and its h_m).
"""
from __future__ import annotations

__all__ = ["cruise_sampling"]


def cruise_sampling(path: str, *, eps: float = 0.35, measurement_delay: float = 0.002):
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
    workbench.features.sampled.PredictorSampling
    """
    from ...design import load_design
    from ...errors import DesignError
    from ...features.sampled import predictor_sampling
    from .antiskid_cruise import operating_point
    design = load_design(path)
    if design.kind != "antiskid-cruise":
        raise DesignError(path, "design.kind", design.kind, 'an "antiskid-cruise" design')
    rows = [p for p in design.spec.published if p.eps == eps]
    if not rows:
        raise DesignError(path, "synthesis.published", eps, "a printed row with this eps")
    lin = operating_point(design.spec)[3]
    return predictor_sampling(lin.A, lin.B, rows[0].K, rows[0].h_m, measurement_delay)
