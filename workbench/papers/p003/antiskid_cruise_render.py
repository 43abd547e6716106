"""Markdown and figures of the ``antiskid-cruise`` study (pure rendering).

The sweep's sections and figures (table, printed rows, ``[tight]``, foreign
gains) are :func:`workbench.features.sweep_study_render.sweep_sections`; this
module keeps paper 003's model section and its problem and operating-point
wording.
"""
from __future__ import annotations

import numpy as np
import sympy as sp

from ...features.other_gains import ANCHOR
from ...features.sweep_study_render import sweep_sections
from ...plants.adhesion import adhesion_model
from ...report.display_math import display_math
from ...report.markdown import Rendered, fmt, latex_matrix, md_table
from ...report.param_table import param_table
from .antiskid_cruise import PARAM_DOC


def _model_section() -> str:
    m = adhesion_model()
    y1, y2, y3 = m.traction
    z1, z2, z3 = m.braking
    lam = sp.Symbol(r"\lambda")
    ren = lambda e: sp.latex(e.subs(m.lam, lam))
    eqs = [
        r"\lambda = \frac{v_w - v}{\max(v_w, v)}, \quad v_w = \omega r \qquad \text{(eqs 4-5)}",
        r"\mu(\lambda) = " + ren(m.mu_traction) + r"\ (\lambda \ge 0), \qquad "
        r"\mu(\lambda) = " + ren(m.mu_braking) + r"\ (\lambda < 0) \qquad \text{(eq 6)}",
        r"m\dot v = \mu m g - f_r(v),\quad J\dot\omega = u(t-h) - \mu m g r - \zeta\omega,"
        r"\quad f_r = " + ren(m.f_r) + r" \qquad \text{(eqs 7, 9)}",
        r"\text{traction (eq 13): } \dot v = y_1,\ \dot\lambda = y_2 + y_3 u(t-h)",
        r"y_1 = " + ren(y1), r"y_2 = " + ren(y2), r"y_3 = " + ren(y3),
        r"\text{braking (eq 16): } \dot v = z_1,\ \dot\lambda = z_2 + z_3 u(t-h)",
        r"z_2 = " + ren(z2), r"z_3 = " + ren(z3),
    ]
    return ("## Model (paper 003, eqs 4-16)\n\nRendered from the workbench's sympy model "
            "(`workbench/plants/adhesion.py`), the single source of every numeric function "
            "and Jacobian below.\n\n" + display_math(eqs))


def render(design, res) -> Rendered:
    spec = design.spec
    sections = []
    # -- problem --------------------------------------------------------------
    prow = [["`v_d`", fmt(spec.v_d.value, 6), spec.v_d.unit, "cruise speed", spec.v_d.source]]
    if spec.lambda_d_pinned:
        q = spec.lambda_d_pinned
        prow.append(["`lambda_d` (pinned)", fmt(q.value, 6), q.unit, "cruise creep ratio", q.source])
    sections.append(f"## Problem\n\nRail: **{spec.rail}**. Delay-bound synthesis for the cruise "
                    "error system of paper 003 (Theorem 1 with Remark 3, problem (60)).\n\n"
                    + param_table(spec.params, PARAM_DOC, 6, prow))
    sections.append(_model_section())
    # -- operating point ------------------------------------------------------
    lin = res.lin
    ev = np.linalg.eigvals(lin.A)
    op = md_table(["quantity", "value", "how"], [
        ["lambda_opt", fmt(res.lambda_opt, 5), "argmax mu (d mu/d lambda = 0)"],
        ["lambda_d (solved)", fmt(res.lambda_d_solved, 5), "root of y1(v_d, lambda) = 0 in (0, lambda_opt)"],
        ["lambda_d (used)", fmt(res.lambda_d_used, 5),
         "pinned by the design" if spec.lambda_d_pinned else "the solved value"],
        ["y1(v_d, lambda_d used)", (fmt(lin.y1_residual, 3) if abs(lin.y1_residual) > 1e-12
                                    else "0 (below 1e-12)") + " m/s²",
         "eq (25) holds exactly only when this is 0"],
    ], "lrl")
    co = md_table(["coefficient", "value"],
                  [[k, fmt(v, 5)] for k, v in lin.coefficients.items()], "lr")
    sections.append(
        "## Operating point and linearisation (eqs 17-32)\n\n" + op +
        "\n\nError system $\\dot E = A E + B\\,\\tilde u(t-h)$, $E = [v - v_d,\\ \\lambda - \\lambda_d]^T$:"
        f"\n\n$$\nA = {latex_matrix(lin.A, 5)}, \\qquad B = {latex_matrix(lin.B)}\n$$\n\n"
        f"Eigenvalues of $A$: {', '.join(fmt(complex(e).real, 4) for e in ev)} "
        "(the open loop is already stable).\n\n<details><summary>Taylor coefficients "
        "(eqs 18, 23)</summary>\n\n" + co + "\n\n</details>")
    # -- synthesis, comparisons, figures ----------------------------------------
    more, figs = sweep_sections(
        res.sweep, spec.sweep.settings, lin.A, lin.B,
        heading="Certified delay bounds (problem 60, cf. Table 3)",
        reference="ours: problem (60), free weighting, eps fixed",
        where=f"{spec.rail} rail, v_d = {fmt(spec.v_d.value)} m/s", law="the cruise law",
        title="Problem (60): certified delay bound vs eps")
    return Rendered(tuple(sections + more), figs, (ANCHOR,))
