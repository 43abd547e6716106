"""The section and figure of a linear cross-check
(:mod:`workbench.features.linear_delay_check_render`) on the toy loop of
``tests/test_linear_delay_check.py``, which names no paper: x1' = -x1,
x2' = -x2 + k x2(t - h) (|k| < 1: stable for every delay; |k| > 1: a finite
margin)."""
from __future__ import annotations

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from workbench.features.linear_delay_check import (TEST_PROBLEM, LinearCheckSpec,  # noqa: E402
                                                   linear_delay_check)
from workbench.features.linear_delay_check_render import (linear_check_figure,  # noqa: E402
                                                          linear_check_section)
from workbench.report.delay_cross_check import delay_cross_check  # noqa: E402


def _toy():
    spec = LinearCheckSpec((0.0, -3.0), (0.9, 1.1), (1.0, 5.0), 30.0)
    return linear_delay_check(spec, -np.eye(2), np.array([[0.0], [1.0]]), (0.0, -0.5),
                              np.array([1.0, 1.0]))


def test_section_is_the_cross_check_of_the_checks_fields():
    lc = _toy()
    md = linear_check_section(lc, linearisation="the toy loop", closing=" (toy).")
    assert md == delay_cross_check(
        linearisation="the toy loop", test_problem=TEST_PROBLEM, halving=lc.halving,
        K_finite=lc.K_finite, finite_margin=lc.finite_margin, ratios_finite=lc.ratios_finite,
        K_synth=lc.K, synth_margin=lc.margin, ratios_synth=lc.ratios, closing=" (toy).")
    assert "on the toy loop, simulated" in md
    assert "exact margin ∞ (no crossing" in md              # |k| = 0.5 < 1
    assert "x' = -x(t - 0.7)" in md                         # the halving test problem
    verdicts = [ln.split("|")[4].strip() for ln in md.splitlines()
                if ln.startswith("| 0.9 ") or ln.startswith("| 1.1 ")]
    assert verdicts == ["decays", "grows"]                  # below and above h*
    assert md.endswith("stops being stable (toy).")


def test_figure_draws_one_envelope_per_finite_margin_run():
    lc = _toy()
    f = linear_check_figure(lc, "toy envelopes")
    assert (f.name, f.caption, f.size) == ("linear-checks", "toy envelopes", (7.0, 4.0))
    fig = plt.figure()
    f.draw(fig)
    labels = [ln.get_label() for ln in fig.axes[0].get_lines()]
    assert labels == ["h = 0.9 h*", "h = 1.1 h*"]
    plt.close(fig)
