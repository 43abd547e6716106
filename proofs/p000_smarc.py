"""Paper 000: brake model (eq 1) and SMARC Lyapunov argument (eqs 13-27).

Plant (eq 14): theta x2' = u + Delta, theta = m in [theta_min, theta_max],
|Delta| <= D. Error e = x1 - x_d, sliding variable z = c e + e' (eq 18), used
here as a coordinate (e' = z - c e). Law (eq 22) u = theta_hat w - k_s z -
eta sgn(z) with w = x_d'' - c e', adaptation (eq 24) theta_hat' = -lambda z w,
theta_tilde = theta_hat - theta.

Errata checked (digest ../shared/SEEDS.md): eq 19 writes theta_tilde z^2 for
theta_tilde^2; eq 20 carries a stray z; eqs 20-24 write x_d' for x_d''.
"""
from __future__ import annotations

import sympy as sp

from workbench.symbolic.proof import Claim, hyp, time_derivative

PAPER = "000"
TITLE = "Electro-pneumatic braking with sliding-mode adaptive robust control (SMARC)"

theta, lam, c, k_s, eta, D = sp.symbols("theta lambda c k_s eta D", positive=True)
th_min, th_max = sp.symbols(r"theta_min theta_max", positive=True)
e, z, th_hat, Delta, xd1, xd2 = sp.symbols(r"e z \hat{\theta} Delta \dot{x}_d \ddot{x}_d",
                                           real=True)
th_tilde = th_hat - theta
TARGET = -k_s * z**2 - eta * sp.Abs(z) + Delta * z       # eq (25), left side


def closed_loop(xd: sp.Expr) -> dict:
    """Flows of (e, z, theta_hat) under law (22) and adaptation (24), both
    written with ``xd`` where the paper has x_d' (printed) or x_d'' (meant)."""
    e_dot = z - c * e
    w = xd - c * e_dot
    u = th_hat * w - k_s * z - eta * sp.sign(z)                      # eq (22)
    x2_dot = (u + Delta) / theta                                     # eq (14)
    return {e: e_dot, z: c * e_dot + x2_dot - xd2,                   # z' = c e' + e''
            th_hat: -lam * z * w}                                    # eq (24)


V_PRINTED = theta * z**2 / 2 + th_tilde * z**2 / (2 * lam)          # eq (19) as printed
V = theta * z**2 / 2 + th_tilde**2 / (2 * lam)                       # eq (19) corrected


def _projection(x, upper_strict: bool):
    """Proj of eq (27): printed with strict ``>`` / ``<`` (or ``>=`` / ``<=``)."""
    up = th_hat > th_max if upper_strict else th_hat >= th_max
    lo = th_hat < th_min if upper_strict else th_hat <= th_min
    return sp.Piecewise((0, up & (x > 0)), (0, lo & (x < 0)), (x, True))


#: Severity of the as-printed projection (eq 27), upper and lower bound alike.
_PROJ_SEVERITY = dict(
    severity="minor",
    severity_reason="the strict form fails only on the boundary itself, where theta_hat can "
                    "pass the bound by the one update that reaches it; the bounds the proof "
                    "uses hold with >= / <=")
#: Severity of eq 1 as printed (branch t > T2).
_EQ1_SEVERITY = dict(
    severity="minor",
    severity_reason="with Table 1's T2 < T1 the printed branch differs only for T2 < t < T1, "
                    "where the lag term is still small; the workbench's brake model "
                    "(workbench/plants/brake000.py) starts it at T1")


def claims() -> list[Claim]:
    good, printed = closed_loop(xd2), closed_loop(xd1)
    zd, thd, tau = sp.symbols(r"\dot{z} \dot{\hat{\theta}} tau", real=True)
    flows_generic = {z: zd, th_hat: thd}
    box = ((theta, 0.5, 2.0), (th_min, 0.5, 1.0), (th_max, 1.0, 2.0))
    out = [
        Claim("smarc-eq19-printed", PAPER, "19, 25",
              "With V as printed (theta_tilde z^2/(2 lambda)), law (22) and adaptation (24) "
              "give V' = -k_s z^2 - eta|z| + Delta z", "identity",
              time_derivative(V_PRINTED, good), TARGET, expect="refuted",
              note="Erratum: eq 19 writes theta_tilde z^2 where theta_tilde^2 is meant.",
              severity="minor",
              severity_reason="a typo in V: the law and adaptation as printed are unchanged and "
                              "with theta_tilde^2 they give eq 25 (smarc-eq19-corrected)"),
        Claim("smarc-eq19-corrected", PAPER, "19-25",
              "With V = theta z^2/2 + theta_tilde^2/(2 lambda), x_d'' in (21)-(24): "
              "V' = -k_s z^2 - eta|z| + Delta z", "identity",
              time_derivative(V, good), TARGET, origin="workbench"),
        Claim("smarc-eq20-printed", PAPER, "20",
              "dV/dt = theta z z' + theta_tilde theta_hat' z / lambda (as printed, stray z)",
              "identity", time_derivative(V, flows_generic),
              theta * z * zd + th_tilde * thd * z / lam, expect="refuted",
              note="Erratum: the factor z of the last term of eq 20 is stray.",
              severity="minor",
              severity_reason="a stray factor in an intermediate line; the derivative without "
                              "it (smarc-eq20-corrected) leads to eq 25"),
        Claim("smarc-eq20-corrected", PAPER, "20",
              "dV/dt = theta z z' + theta_tilde theta_hat' / lambda", "identity",
              time_derivative(V, flows_generic), theta * z * zd + th_tilde * thd / lam,
              origin="workbench"),
        Claim("smarc-eq21-24-printed", PAPER, "21-24",
              "With x_d' (as printed) in the law and the adaptation: "
              "V' = -k_s z^2 - eta|z| + Delta z", "identity",
              time_derivative(V, printed), TARGET, expect="refuted",
              note="Erratum: eqs 20-24 write x_d' where x_d'' is meant; "
                   "the corrected form is smarc-eq19-corrected.",
              severity="changes-the-result",
              severity_reason="the law and adaptation as printed are not those the proof "
                              "covers: their V' gains theta z (x_d' - x_d''), a speed-sized term "
                              "the robust term eta|z| does not dominate, so eq 25 and the "
                              "stability conclusion do not follow for them"),
        Claim("smarc-eq25", PAPER, "16, 22, 25",
              "-k_s z^2 - eta|z| + Delta z <= -k_s z^2 when |Delta| <= D < eta",
              "inequality", TARGET, -k_s * z**2,
              hypotheses=(hyp(eta, ">", D), hyp(D, ">=", sp.Abs(Delta))),
              terms=((eta - D) * sp.Abs(z), (D - sp.Abs(Delta)) * sp.Abs(z),
                     sp.Abs(Delta) * sp.Abs(z) - Delta * z)),
    ]
    # eq (27): on the boundary the projected rate must not point outwards
    for strict, tag, exp in ((True, "printed", "refuted"), (False, "corrected", "proved")):
        rel = ">" if strict else ">="
        out.append(Claim(
            f"smarc-eq27-upper-{tag}", PAPER, "26-27",
            f"Proj with '{rel}': at theta_hat = theta_max the rate Proj(tau) is <= 0 "
            "(theta_hat stays <= theta_max)", "inequality", _projection(tau, strict), 0,
            given=((th_hat, th_max),), hypotheses=(hyp(th_max, ">", th_min),),
            sample=box, expect=exp, origin="paper" if strict else "workbench",
            note="" if not strict else "Eq 27's strict inequalities let the rate point "
            "outwards on the boundary itself; with >= / <= the interval is invariant.",
            **(_PROJ_SEVERITY if strict else {})))
        out.append(Claim(
            f"smarc-eq27-lower-{tag}", PAPER, "26-27",
            f"Proj with '{rel.replace('>', '<')}': at theta_hat = theta_min the rate "
            "Proj(tau) is >= 0", "inequality", 0, _projection(tau, strict),
            given=((th_hat, th_min),), hypotheses=(hyp(th_max, ">", th_min),),
            sample=box, expect=exp, origin="paper" if strict else "workbench",
            **(_PROJ_SEVERITY if strict else {})))
    # eq (27) keeps eq (25): the extra term theta_tilde (Proj(tau) - tau)/lambda <= 0
    proj = _projection(tau, False)
    extra = th_tilde * (proj - tau) / lam
    # (hypotheses are used in order as slack substitutions: the bound on theta
    # that the case needs comes first)
    cases = (("upper", "theta_hat >= theta_max, tau > 0",
              (hyp(th_hat, ">=", th_max), hyp(tau, ">", 0), hyp(theta, "<=", th_max),
               hyp(th_min, "<=", theta))),
             ("lower", "theta_hat <= theta_min, tau < 0",
              (hyp(th_hat, "<=", th_min), hyp(tau, "<", 0), hyp(theta, ">=", th_min),
               hyp(th_max, ">=", theta))))
    for tag, words, hs in cases:
        out.append(Claim(
            f"smarc-eq27-keeps-eq25-{tag}", PAPER, "23, 26-27",
            f"With projection, V' gains theta_tilde (Proj(tau) - tau)/lambda <= 0 "
            f"({words}; theta in its bounds)", "inequality", extra, 0,
            hypotheses=hs, sample=box))
    out.append(Claim(
        "smarc-eq27-keeps-eq25-interior", PAPER, "23, 26-27",
        "Inside the bounds Proj(tau) = tau: the extra term vanishes", "identity",
        extra, 0, given=((th_hat, (th_min + th_max) / 2),), sample=box,
        hypotheses=(hyp(th_max, ">", th_min),)))
    # eq (1): the electric-brake lag starts after the delay T1 ("t > T2" printed)
    T1, T2, t = sp.symbols("T_1 T_2 t", positive=True)
    lag = 1 - sp.exp(-(t - T1) / T2)          # a_real / a_bra on the second branch
    for tag, start, exp in (("printed", T2, "refuted"), ("corrected", T1, "proved")):
        out.append(Claim(
            f"brake-model-eq1-{tag}", PAPER, "1",
            f"on the branch t > {start} of eq 1, a_real = a_bra (1 - exp(-(t - T1)/T2)) "
            "has the sign of a_bra (a_real / a_bra >= 0)", "inequality", 0, lag,
            hypotheses=(hyp(t, ">", start),), expect=exp,
            origin="workbench" if exp == "proved" else "paper",
            note="" if exp == "proved" else "Eq 1 writes t > T2 for the branch that starts "
            "after the delay T1: for T2 < t < T1 the response has the wrong sign.",
            **({} if exp == "proved" else _EQ1_SEVERITY)))
    return out
