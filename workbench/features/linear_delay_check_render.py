"""The report section and figure of a linear cross-check of a delay bound
(:class:`~workbench.features.linear_delay_check.LinearDelayCheck`; pure
rendering): :func:`workbench.report.delay_cross_check.delay_cross_check`
and :func:`~workbench.report.delay_cross_check.plot_envelopes` fed from the
check's fields, with the step halving of its test problem
:data:`~workbench.features.linear_delay_check.TEST_PROBLEM`. The study
supplies only its words (what the linearisation is, its reading of the runs).
Test on a toy: ``tests/test_linear_delay_check_render.py``."""
from __future__ import annotations

from ..report.delay_cross_check import delay_cross_check, plot_envelopes
from ..report.markdown import Figure
from .linear_delay_check import TEST_PROBLEM

__all__ = ["linear_check_figure", "linear_check_section"]


def linear_check_section(lc, *, linearisation: str, closing: str) -> str:
    """The cross-check section (Markdown) of ``lc``, a
    :class:`~workbench.features.linear_delay_check.LinearDelayCheck`;
    ``linearisation`` and ``closing`` as in
    :func:`~workbench.report.delay_cross_check.delay_cross_check`."""
    return delay_cross_check(
        linearisation=linearisation, test_problem=TEST_PROBLEM, halving=lc.halving,
        K_finite=lc.K_finite, finite_margin=lc.finite_margin, ratios_finite=lc.ratios_finite,
        K_synth=lc.K, synth_margin=lc.margin, ratios_synth=lc.ratios, closing=closing)


def linear_check_figure(lc, caption: str, size: tuple[float, float] = (7.0, 4.0)) -> Figure:
    """``linear-checks.png``: |E| of the finite-margin gain's runs, labelled
    by their delay as a multiple of its exact margin h*."""
    return Figure("linear-checks", caption, lambda fig: plot_envelopes(
        fig, (f for f, _, _ in lc.ratios_finite), lc.runs), size)
