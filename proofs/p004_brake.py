"""Paper 004, closed-loop deceleration control: the worked numbers of section 2.

Exact arithmetic (sympy rationals) from the paper's own inputs: g = 9.8
m/s^2, gradients 30 and 15 permille, full service brake 1 m/s^2 and 70 % of
it, 15 % brake-force error, 50 km/h written by the paper as 13.89 m/s.
Braking distance s = v^2 / (2 a).
"""
from __future__ import annotations

import sympy as sp

from workbench.symbolic.proof import Claim

PAPER = "004"
TITLE = "Closed-loop deceleration brake control: worked braking numbers"

R = sp.Rational
g = R(98, 10)


def grade_accel(permille: int) -> sp.Expr:
    """Component of gravity along a grade of ``permille`` (m/s^2): g sin(atan(i))."""
    return g * sp.sin(sp.atan(R(permille, 1000)))


def claims() -> list[Claim]:
    v_printed = R(1389, 100)           # the paper's "50 km/h (13.89 m/s)"
    v_exact = R(50 * 1000, 3600)
    a2 = 1 - R(15, 100) - grade_accel(15)
    s1, s2 = v_printed**2 / 2, v_printed**2 / (2 * a2)

    def value(id_, eqs, words, expr, printed, digits, **kw):
        return Claim(id_, PAPER, eqs, words, "value", expr, printed, digits=digits, **kw)

    return [
        value("brake-grade30-accel", "sec. 2.2", "g sin(atan 0.030) = 0.29387 m/s^2",
              grade_accel(30), 0.29387, 5),
        value("brake-grade30-full", "sec. 2.2", "F1/F2 at 1 m/s^2, 30 permille: 29.39 %",
              100 * grade_accel(30), 29.39, 2),
        value("brake-grade30-70pct", "sec. 2.2", "F1/F2 at 0.7 m/s^2, 30 permille: 41.98 %",
              100 * grade_accel(30) / R(7, 10), 41.98, 2),
        value("brake-grade15-full", "sec. 2.2", "F1/F2 at 1 m/s^2, 15 permille: 14.70 %",
              100 * grade_accel(15), 14.70, 2),
        value("brake-grade15-70pct", "sec. 2.2", "F1/F2 at 0.7 m/s^2, 15 permille: 21.00 %",
              100 * grade_accel(15) / R(7, 10), 21.00, 2),
        value("brake-case2-decel", "sec. 2.3", "-15 % force and 15 permille down-grade: "
              "deceleration 0.703 m/s^2", a2, 0.703, 3),
        value("brake-case1-distance-corrected", "sec. 2.3",
              "with the rounded speed 13.89 m/s, 1 m/s^2 stops in 96.466 m",
              s1, 96.466, 3, origin="workbench"),
        value("brake-case1-distance-printed", "sec. 2.3",
              "50 km/h (exactly 125/9 m/s) at 1 m/s^2 stops in 96.466 m", v_exact**2 / 2,
              96.466, 3, expect="refuted",
              note="96.466 m holds only for the rounded speed 13.89 m/s; exactly 50 km/h "
                   "gives 96.451 m (the paper's inputs, not an error of method).",
              severity="rounding",
              severity_reason="the paper's own rounding of 50 km/h to 13.89 m/s (checked: "
                              "within 0.1 % of the exact value)"),
        value("brake-case2-distance", "sec. 2.3", "13.89 m/s at 0.703 m/s^2 stops in 137.22 m",
              s2, 137.22, 2),
        value("brake-difference-printed", "sec. 2.3", "the two distances differ by 40.754 m",
              s2 - s1, 40.754, 3, expect="refuted",
              note="40.754 is 137.22 - 96.466, the difference of the rounded distances; "
                   "the distances themselves (96.466 m, 137.2175 m) differ by 40.751 m.",
              severity="rounding",
              severity_reason="a difference of two rounded distances (checked: within 0.1 % "
                              "of the exact difference)"),
        value("brake-difference-corrected", "sec. 2.3", "the two distances differ by 40.751 m",
              s2 - s1, 40.751, 3, origin="workbench"),
    ]
