"""Paper 003, antiskid control with input delay: model, linearisation, Theorems 2-3.

Every plant expression comes from the one sympy model
:func:`workbench.plants.adhesion.adhesion_model` and the coefficients of eqs
18 and 23 from :func:`workbench.symbolic.linearise.taylor_coefficients` (their
symbols v, lambda stand for the point (v_d, lambda_d)). The LMI steps of the
proof of Theorem 1 and Remark 3 are in :mod:`proofs.p003_lmi`.

Theorems 2 and 3 are checked *under exact prediction*: the predictor of
Lemma 1 returns X(t + h), so the input applied at t, u(t - h), is the law
evaluated at the current state; what remains of the delay is the
predictor's accuracy, which these claims do not address.
"""
from __future__ import annotations

import sympy as sp

from workbench.plants.adhesion import adhesion_model
from workbench.symbolic.linearise import taylor_coefficients
from workbench.symbolic.proof import Claim, time_derivative

PAPER = "003"
TITLE = "Antiskid control of high-speed trains with input delay"

MDL = adhesion_model()
P = MDL.params
v, lam, u = MDL.v, MDL.lam, MDL.u
#: Sampling box for the model constants: broad, physically plausible ranges
#: (not the paper's values) — the claims must hold for every parameter set.
BOX = ((P["a"], 0.1, 0.5), (P["b"], 10.0, 50.0), (P["c"], 2.0, 10.0), (P["J"], 20.0, 200.0),
       (P["r"], 0.3, 0.6), (P["m"], 1e3, 3e4), (P["zeta"], 0.001, 0.1), (P["c0"], 10.0, 500.0),
       (P["c1"], 1.0, 200.0), (P["c2"], 0.1, 5.0), (P["g"], 9.7, 9.9), (v, 5.0, 100.0))


def _creep_claims() -> list[Claim]:
    """Eqs 10-16: lambda' of both forms, derived from eqs 4, 5 and 7."""
    omega = sp.Symbol("omega", positive=True)
    p = P
    out = []
    for form, mu, lam_of, omega_of, rhs, eqs in (
            ("traction", MDL.mu_traction, 1 - v / (omega * p["r"]),
             v / ((1 - lam) * p["r"]), MDL.traction, "4-5, 7, 10-13"),
            ("braking", MDL.mu_braking, omega * p["r"] / v - 1,
             v * (1 + lam) / p["r"], MDL.braking, "4-5, 7, 14-16")):
        v_dot = mu * p["g"] - MDL.f_r / p["m"]                                      # eq (7)
        omega_dot = (u - mu * p["m"] * p["g"] * p["r"] - p["zeta"] * omega) / p["J"]
        lam_dot = time_derivative(lam_of, {v: v_dot, omega: omega_dot}).subs(omega, omega_of)
        out.append(Claim(
            f"plant-{form}-creep", PAPER, eqs,
            f"{form} form: d/dt of the creep ratio of eq 4, along eq 7, equals "
            f"{'y2 + y3 u' if form == 'traction' else 'z2 + z3 u'} of the model",
            "identity", lam_dot, rhs[1] + rhs[2] * u,
            sample=BOX + ((lam, 0.001, 0.2) if form == "traction" else (lam, -0.2, -0.001),)))
    return out


def _linearisation_claims() -> list[Claim]:
    co = taylor_coefficients()
    y = sp.Matrix(MDL.traction)
    jac = y.jacobian([v, lam])
    lin = sp.Matrix([[co["a1"], co["a2"]], [co["b1"], co["b2"]], [co["b4"], co["b5"]],
                     [co["d1"], co["d2"]], [co["d4"], co["d5"]]])
    affine = sp.Matrix([co["a1"] * v + co["a2"] * lam + co["a3"],
                        co["b1"] * v + co["b2"] * lam + co["b3"],
                        co["b4"] * v + co["b5"] * lam + co["b6"]])
    at_point = sp.Matrix([*affine, co["d3"], co["d6"]])
    box = BOX + ((lam, 0.001, 0.1),)
    # eqs (22)-(23) as structure: abstract coefficients, the d's defined by (23)
    b = sp.symbols("b1:7", real=True)
    ve, le, vd, ld, ucr = sp.symbols(r"v_e \lambda_e v_d \lambda_d u_{cr}", real=True)
    d = (b[0], b[1], b[0] * vd + b[1] * ld + b[2], b[3], b[4], b[3] * vd + b[4] * ld + b[5])
    lam_dot_17 = (b[0] * (ve + vd) + b[1] * (le + ld) + b[2]
                  + (b[3] * (ve + vd) + b[4] * (le + ld) + b[5]) * ucr)
    lam_dot_22 = d[0] * ve + d[1] * le + d[2] + (d[3] * ve + d[4] * le + d[5]) * ucr
    k1, k2 = sp.symbols("k_1 k_2", real=True)
    u61 = (-d[2] + k1 * ve + k2 * le) / (d[3] * ve + d[4] * le + d[5])      # eq (61)
    u_virtual = (d[3] * ve + d[4] * le + d[5]) * u61 + d[2]                  # eq (27)
    y1_zero_c0 = sp.solve(sp.Eq(MDL.traction[0], 0), P["c0"])
    return [
        Claim("lin-eq18-jacobian", PAPER, "17-18, 23, 32",
              "a1, a2, b1, b2, b4, b5 of eq 18 and d1, d2, d4, d5 of eq 23 (so A of eq 32) "
              "are the Jacobian of (y1, y2, y3) of the model", "identity", lin,
              sp.Matrix.vstack(jac, jac[1:, :]), sample=box,
              display=r"\begin{bmatrix} a_1 & a_2 \\ b_1 & b_2 \\ b_4 & b_5 \\ d_1 & d_2 \\ "
                      r"d_4 & d_5 \end{bmatrix} = "
                      r"\frac{\partial (y_1, y_2, y_3)}{\partial (v, \lambda)}"
                      r"\Big|_{(v_d, \lambda_d)}"),
        Claim("lin-eq21-24", PAPER, "18, 21, 23-24",
              "the linear model (17) takes the model's values at (v_d, lambda_d): "
              "a1 v_d + a2 lambda_d + a3 = y1 (eq 24), likewise for y2, y3; d3 = y2 and "
              "d6 = y3 there (eq 23)", "identity", at_point, sp.Matrix([*y, y[1], y[2]]),
              sample=box,
              display=r"a_1 v_d + a_2 \lambda_d + a_3 = y_1(v_d, \lambda_d),\ \dots,\ "
                      r"b_4 v_d + b_5 \lambda_d + b_6 = y_3(v_d, \lambda_d),\ "
                      r"d_3 = y_2(v_d, \lambda_d),\ d_6 = y_3(v_d, \lambda_d)"),
        Claim("lin-eq22-23", PAPER, "17, 19, 22-23",
              "substituting v = v_e + v_d, lambda = lambda_e + lambda_d into (17) gives (22) "
              "with d1..d6 of eq 23", "identity", lam_dot_17, lam_dot_22),
        Claim("lin-eq25-printed", PAPER, "24-25",
              "a1 v_d + a2 lambda_d + a3 = 0 at any linearisation point (eq 25 as stated)",
              "identity", affine[0], 0, sample=box, expect="refuted",
              note="Eq 25 holds only where y1(v_d, lambda_d) = 0: that condition is what "
                   "fixes lambda_d (digest: 'eq 25 relies on y1(v_d, lambda_d) = 0').",
              severity="minor",
              severity_reason="a missing hypothesis: the paper uses eq 25 only at the cruise "
                              "equilibrium y1(v_d, lambda_d) = 0, where it holds "
                              "(lin-eq25-corrected)"),
        Claim("lin-eq25-corrected", PAPER, "24-25",
              "a1 v_d + a2 lambda_d + a3 = 0 at a cruise equilibrium y1(v_d, lambda_d) = 0 "
              "(used as c0 = m(mu g) - c1 v_d - c2 v_d^2)", "identity", affine[0], 0,
              given=((P["c0"], y1_zero_c0[0]),), sample=box, origin="workbench"),
        Claim("lin-eq61", PAPER, "27, 29, 61",
              "under exact prediction, the cruise law (61) makes the virtual input (27) "
              "equal to K E (eq 29)", "identity", u_virtual, k1 * ve + k2 * le),
    ]


def _theorem_claims() -> list[Claim]:
    y1, y2, y3 = MDL.traction
    z1, z2, z3 = MDL.braking
    k_ac, k_de = sp.symbols("k_ac k_de", positive=True)
    lam_opt, vs, vs_dot = sp.symbols(r"\lambda_{opt} v_s^* \dot{v}_s^*", real=True)
    u_ac = (-y2 - k_ac * (lam - lam_opt)) / y3                              # eq (64)
    V_ac = (lam - lam_opt) ** 2 / 2
    e_vs = v * lam - vs                                                     # v_s = omega r - v
    u_de = ((-k_de * (v * lam - vs) + z1 + vs_dot) / v - (1 + lam) / v * z1 - z2) / z3  # (69)
    flows = {v: z1, lam: z2 + z3 * u_de, vs: vs_dot}
    omega_r_dot = time_derivative(v * (1 + lam), flows)                     # eq (73): omega r
    return [
        Claim("thm2-eq68", PAPER, "64, 67-68",
              "Theorem 2: along (12) with u_ac of (64) (exact prediction), "
              "V_ac' = -k_ac (lambda - lambda_opt)^2", "identity",
              time_derivative(V_ac, {lam: y2 + y3 * u_ac}), -k_ac * (lam - lam_opt) ** 2,
              sample=BOX + ((lam, 0.001, 0.3),)),
        Claim("thm3-eq74", PAPER, "69, 72-74",
              "Theorem 3: along (15) with u_de of (69) (exact prediction), "
              "V_de' = e_vs (omega' r - v' - v_s*') = -k_de e_vs^2", "identity",
              e_vs * (omega_r_dot - z1 - vs_dot), -k_de * e_vs**2,
              sample=BOX + ((lam, -0.3, -0.001),)),
    ]


def claims() -> list[Claim]:
    return _creep_claims() + _linearisation_claims() + _theorem_claims()
