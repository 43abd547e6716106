"""The linear cross-check of an LMI delay bound: the section and its figure.

A delay-dependent LMI (Lyapunov-Krasovskii) bound h_m on the input delay is
sufficient, not necessary. The cross-check simulates the linear error system
E' = A E + B K E(t - h) at chosen delays and compares each run's envelope
with the gain's exact delay margin h* (frequency sweep): the study supplies
the runs, the margins and what the linearisation is; this module lays them
out. The integrator's accuracy is shown by step halving on a scalar test
problem x' = -a x(t - h) with a known method-of-steps solution.

Used by the ``antiskid-run`` study (paper 003); ``tests/test_case_tables.py``
renders a toy.
"""
from __future__ import annotations

import math
from typing import Iterable, Sequence

import numpy as np

from .markdown import fmt, md_table


def envelope_verdict(ratio: float) -> str:
    """``decays`` when max |E| over the last window is below that over the
    second window (``ratio`` < 1), else ``grows``."""
    return "decays" if ratio < 1 else "grows"


def delay_cross_check(*, linearisation: str, test_problem: tuple[float, float, float],
                      halving: Iterable, K_finite: Sequence[float], finite_margin,
                      ratios_finite: Iterable[tuple[float, float, float]],
                      K_synth: Sequence[float], synth_margin,
                      ratios_synth: Iterable[tuple[float, float]], closing: str) -> str:
    """The cross-check section (Markdown).

    Parameters
    ----------
    linearisation : str
        Where the linear error system comes from ("the cruise linearisation").
    test_problem : (a, h, t_end)
        The step-halving test problem x' = -a x(t - h), x = 1 on [-h, 0].
    halving : rows with ``dt``, ``error``, ``order``.
    K_finite, finite_margin : a gain with a finite exact margin and its margin
        (``h``, ``omega``).
    ratios_finite : (h / h*, h, envelope ratio) of its runs.
    K_synth, synth_margin : the synthesised gain and its exact margin (``h``).
    ratios_synth : (h, envelope ratio) of its runs.
    closing : the study's reading of its runs, appended to the general one.
    """
    ha, hh, ht = test_problem
    rows = [[fmt(f, 3), fmt(h, 4), fmt(r, 3), envelope_verdict(r)] for f, h, r in ratios_finite]
    prow = [[fmt(h, 3), fmt(r, 3), envelope_verdict(r)] for h, r in ratios_synth]
    pm = synth_margin
    ptxt = "∞ (no crossing: stable for every constant delay)" if math.isinf(pm.h) else fmt(pm.h, 4)
    return (
        "## Linear cross-checks of the delay bound\n\n"
        f"E' = A E + B K E(t - h) on {linearisation}, simulated by Heun's method on "
        "a grid with h = N dt. Accuracy, by step halving against the exact method-of-steps "
        f"solution of x' = -{'' if ha == 1 else fmt(ha) + ' '}x(t - {fmt(hh)}), x = 1 on "
        f"[-{fmt(hh)}, 0], over {fmt(ht)} s:\n\n"
        + md_table(["dt (s)", "max error", "observed order"],
                   [[fmt(r.dt, 3), fmt(r.error, 3), fmt(r.order, 3)] for r in halving],
                   "rrr")
        + "\n\nThe envelope ratio is max |E| over the last window / over the second window.\n\n"
        f"Gain with a finite exact margin, K = [{', '.join(fmt(k, 3) for k in K_finite)}]: "
        f"h* = {fmt(finite_margin.h, 4)} s at omega = {fmt(finite_margin.omega, 4)} rad/s.\n\n"
        + md_table(["h / h*", "h (s)", "envelope ratio", "verdict"], rows, "rrrl")
        + f"\n\nSynthesised gain K = [{', '.join(fmt(k, 4) for k in K_synth)}]: exact "
        f"margin {ptxt}.\n\n"
        + md_table(["h (s)", "envelope ratio", "verdict"], prow, "rrl")
        + "\n\nThe LMI bound h_m is where the Lyapunov-Krasovskii criterion stops proving "
        "stability, not where the loop stops being stable" + closing)


def plot_envelopes(fig, factors: Iterable[float], runs: Iterable) -> None:
    """|E| of each cross-check run (``t``, ``x`` with states in rows) on a
    log axis, labelled by its delay as a multiple of h*."""
    ax = fig.add_subplot(111)
    for fac, r in zip(factors, runs):
        ax.semilogy(r.t, np.linalg.norm(r.x, axis=0) + 1e-300, label=f"h = {fac:g} h*")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("|E|")
    ax.legend(fontsize=7)
