"""The workbench's closed sets of outcomes: one for a certificate, one for a claim.

Issue 35 asks for one verdict enum instead of one per study. Two remain, and
they answer different questions, so they cannot be one:

:class:`Outcome` -- the status of a **certificate** (an LMI at a delay or on a
    delay interval, a synthesis bracket, a sampled-data check, a level of a
    Lyapunov function in a region-of-attraction estimate). CERTIFIED when a
    proof was found and re-checked, REFUTED when the criterion provably fails,
    INCONCLUSIVE otherwise, and INFEASIBLE when a diagnosis proves that
    nothing can be certified (never a solver's answer). It says what the
    *mathematics* established and knows nothing of what a paper expected.
:class:`Verdict` -- the status of a **claim** of a design file (a paper's
    number or a requirement compared with a computed quantity): PASS, FAIL, or
    INCONCLUSIVE when the quantity was not established. A claim about a
    certificate compares its Outcome with the expected one, so a REFUTED
    certificate can be a PASS (an erratum the paper printed) and a CERTIFIED
    one a FAIL.

Printed words. :attr:`Outcome.value` (lower case: ``"certified"``) is the word
of the JSON output and of the LMI tables; the region-of-attraction tables and
quantities print :attr:`Outcome.name` (``"CERTIFIED"``), as the basin's own
enum did before it was merged here (see :func:`word`). Both are the same word;
only its case was kept, so that no committed report or claim changes.
The symbolic proof engine keeps its own words (PROVED / REFUTED /
INCONCLUSIVE, :class:`workbench.symbolic.proof.Verdict`): a proof is not a
numerical certificate re-checked with a margin, and its words are those of
the proofs reports.

References
----------
cvxpy, ``settings.py``: solver statuses in closed groups (optimal,
infeasible, unbounded, inaccurate), the model of a closed set of answers.
"""
from __future__ import annotations

import enum

__all__ = ["Outcome", "Verdict", "word"]


class Outcome(str, enum.Enum):
    """Closed set of outcomes of a certificate (see the module docstring)."""

    CERTIFIED = "certified"
    REFUTED = "refuted"
    INCONCLUSIVE = "inconclusive"
    #: a diagnosis proves that nothing can be certified (e.g. an uncontrollable
    #: unstable mode, :mod:`workbench.lmi.diagnosis`); never a solver's answer
    INFEASIBLE = "infeasible"


class Verdict(str, enum.Enum):
    """Closed set of verdicts of a design claim (see the module docstring)."""

    PASS = "PASS"
    FAIL = "FAIL"
    INCONCLUSIVE = "INCONCLUSIVE"


def word(outcome: Outcome) -> str:
    """The upper-case word of an outcome, as tables and claim quantities print it.

    Parameters
    ----------
    outcome : Outcome

    Returns
    -------
    str
        ``"CERTIFIED"``, ``"REFUTED"``, ``"INCONCLUSIVE"`` or ``"INFEASIBLE"``.
    """
    return outcome.name
