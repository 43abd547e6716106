"""Paper 001, NTSM virtual coupling (eqs 5-22): closed loop, V' bound, settling time.

Train i (eq 5): m v_i' = u_i - f_u - f_v + w + d, f_u = c0 + c1 v + c2 v^2,
f_v = m g sin(phi); spacing error e = x_{i-1} - x_i - D (eq 7), so
e'' = v_{i-1}' - v_i' (eq 9). Surface s = e + sig(e')^q / beta (eq 10) with
q = b/a in (1, 2), p = alpha/xi in (0, 1); powers of odd ratios are
sign-preserving: x^(b/a) = sig(x)^q, x^(b/a - 1) = |x|^(q-1) (b - a even),
s^(alpha/xi + 1) = |s|^(p+1).

The sliding variable s is used as a coordinate (a symbol) so that sign(s) can
be split into cases; e'' does not depend on e except through s.
"""
from __future__ import annotations

import sympy as sp

from workbench.symbolic.proof import Claim, hyp, sig, time_derivative

PAPER = "001"
TITLE = "Virtual coupling with non-singular terminal sliding mode (NTSM)"

m, beta, j, k, Gw, Gd, g = sp.symbols("m beta j k G_w G_d g", positive=True)
c0, c1, c2 = sp.symbols("c_0 c_1 c_2", positive=True)
q, p = sp.symbols("q p", positive=True)            # q = b/a, p = alpha/xi
e, ed, s, w, d, v, vlead_dot, phi = sp.symbols(r"e \dot{e} s w d v \dot{v}_{i-1} varphi",
                                               real=True)
SAMPLE = ((q, 1.05, 1.95), (p, 0.05, 0.95))


def closed_loop_edd() -> sp.Expr:
    """e'' of eq (9) under the law of eq (13), from the plant of eq (5)."""
    f_u = c0 + c1 * v + c2 * v**2                    # eq (2), c2 v^2 (typo x''^2)
    f_v = m * g * sp.sin(phi)                        # eq (3)
    u1 = f_u + f_v
    u2 = beta * m / q * sig(ed, 2 - q)
    u3 = beta * m / q * (j * s + k * sig(s, p))
    u4 = (Gw + Gd) * sp.sign(s) + m * vlead_dot
    v_dot = (u1 + u2 + u3 + u4 - f_u - f_v + w + d) / m       # eq (5)
    return vlead_dot - v_dot                                   # eq (9)


def claims() -> list[Claim]:
    edd = closed_loop_edd()
    eq17 = (-beta / q * sig(ed, 2 - q) - beta / q * (j * s + k * sig(s, p))
            - (d + w) / m - (Gw + Gd) / m * sp.sign(s))
    s_dot = time_derivative(e + sig(ed, q) / beta, {e: ed, ed: edd})   # eq (11)
    V_dot = m * s * s_dot                                              # V = m s^2/2
    phi_e = sp.Abs(ed) ** (q - 1)                                      # e'^(b/a-1)
    reach = (j * s**2 + k * sp.Abs(s) ** (p + 1)) * phi_e
    dist = s * q / beta * phi_e * ((Gw + Gd) * sp.sign(s) + d + w)
    bounds = (hyp(Gw, ">=", sp.Abs(w)), hyp(Gd, ">=", sp.Abs(d)))
    u_i = sp.Symbol("u_i", real=True)
    v_dot9 = (u_i - c0 - c1 * v - c2 * v**2 - m * g * sp.sin(phi) + w + d) / m   # eq (9)
    out = [
        Claim("ntsm-eq5-printed", PAPER, "2, 5, 9",
              "eq 9's v_i' solves eq 5 as printed, with f_u = c0 + c1 v + c2 x''^2",
              "identity", m * v_dot9 + c0 + c1 * v + c2 * v_dot9**2,
              u_i - m * g * sp.sin(phi) + w + d, expect="refuted",
              note="Erratum: eqs 2, 4, 5 write c2 x''^2 for the Davis term c2 v^2 "
                   "that eq 9 uses.",
              severity="minor",
              severity_reason="a typo in the resistance term: eq 9 and every later step use "
                              "c2 v^2 (ntsm-eq5-corrected)"),
        Claim("ntsm-eq5-corrected", PAPER, "2, 5, 9",
              "eq 9's v_i' solves eq 5 with f_u = c0 + c1 v + c2 v^2", "identity",
              m * v_dot9 + c0 + c1 * v + c2 * v**2, u_i - m * g * sp.sin(phi) + w + d,
              origin="workbench"),
        Claim("ntsm-eq17", PAPER, "5, 9, 13, 17",
              "Under law (13), the spacing error obeys eq 17", "identity", edd, eq17,
              sample=SAMPLE),
        Claim("ntsm-eq15-printed", PAPER, "14-15",
              "V' = m s s' equals eq 15 as printed (reaching term without m)", "identity",
              V_dot, -reach - dist, sample=SAMPLE, expect="refuted", nonzero=(ed,),
              note="Eq 15 drops the mass m_i from the reaching term; eq 20 has it. "
                   "(Eq 16 as printed still follows when m >= 1, as for a train.)",
              severity="minor",
              severity_reason="eq 20 has the mass again and eq 16 still follows for m >= 1 kg"),
        Claim("ntsm-eq15-corrected", PAPER, "14-15, 20",
              "V' = -m (j s^2 + k|s|^(p+1)) |e'|^(q-1) - (q/beta)|e'|^(q-1) s "
              "((G_w + G_d) sign(s) + d + w), for e' != 0 (as the paper argues)", "identity",
              V_dot, -m * reach - dist, sample=SAMPLE, nonzero=(ed,), origin="workbench"),
        Claim("ntsm-eq20", PAPER, "6, 16, 20",
              "V' <= -m (j s^2 + k|s|^(p+1)) |e'|^(q-1) when |w| <= G_w, |d| <= G_d (e' != 0)",
              "inequality", -m * reach - dist, -m * reach, hypotheses=bounds,
              terms=(q / beta * phi_e * (Gw - sp.Abs(w)) * sp.Abs(s),
                     q / beta * phi_e * (Gd - sp.Abs(d)) * sp.Abs(s),
                     q / beta * phi_e * (sp.Abs(w) * sp.Abs(s) + w * s),
                     q / beta * phi_e * (sp.Abs(d) * sp.Abs(s) + d * s)),
              sample=SAMPLE, nonzero=(ed,)),
    ]
    # The finite-time reaching argument divides by nothing but multiplies by
    # |e'|^(q-1): at e' = 0 the bound of eq 20 is 0, not a negative rate.
    out += [
        Claim("ntsm-reaching-printed", PAPER, "16, 20",
              "eq 20 gives a reaching rate uniform in e' for every s != 0: "
              "V' <= -(m j / 2) s^2 (as finite-time reaching needs), also near e' = 0",
              "inequality", V_dot, -m * j * s**2 / 2, hypotheses=bounds,
              sample=SAMPLE + ((ed, -1e-4, 1e-4),), nonzero=(ed,), expect="refuted",
              note="Degeneracy of the reaching argument: the factor |e'|^(q-1) of eq 20 "
                   "tends to 0 as e' -> 0, so near e' = 0 eq 20 gives no rate at all (at "
                   "e' = 0 the bound is V' <= 0): the counterexample has a small e'.",
              severity="minor",
              severity_reason="a gap in the argument, not in the conclusion: finite-time "
                              "reaching still holds by the standard repair "
                              "(ntsm-reaching-at-rest, proved)"),
        Claim("ntsm-reaching-at-rest", PAPER, "9, 13, 17",
              "at e' = 0 the set is crossed, not a rest point: s e'' <= -(beta/q)(j s^2 + "
              "k|s|^(p+1)) < 0 for s != 0 when |w| <= G_w, |d| <= G_d, so e' leaves 0 "
              "in the direction that reduces |s|",
              "inequality", s * edd.subs(ed, 0),
              -beta / q * (j * s**2 + k * sp.Abs(s) ** (p + 1)), hypotheses=bounds,
              terms=((Gw - sp.Abs(w)) * sp.Abs(s) / m, (sp.Abs(w) * sp.Abs(s) + w * s) / m,
                     (Gd - sp.Abs(d)) * sp.Abs(s) / m, (sp.Abs(d) * sp.Abs(s) + d * s) / m),
              sample=SAMPLE, origin="workbench",
              note="The standard repair of NTSM reaching (Feng, Yu, Man 2002): e' = 0 with "
                   "s != 0 is not an attractor, so the reaching phase still ends in finite "
                   "time; the paper does not make this step."),
    ]
    # eq (21)-(22): on s = 0, e' = -(beta e)^(a/b); for e(t_e) = e0 > 0 the
    # closed form below solves it and reaches 0 at t_f of eq (22).
    t, te, e0, W = sp.symbols("t t_e e_0 W", positive=True)
    x = sp.Symbol("x", positive=True)
    rho = sp.Symbol("rho", positive=True)                              # 1 - a/b = (b-a)/b
    r = 1 - rho                                                        # a/b
    e_t = (e0**rho - rho * beta**r * (t - te)) ** (1 / rho)
    t_f = te + 1 / rho * beta ** (-r) * e0**rho                        # eq (22): b/(b-a) = 1/rho
    out.append(Claim(
        "ntsm-eq22", PAPER, "21-22",
        "On s = 0 (e' = -(beta e)^(a/b)), e(t) = (e0^(1-a/b) - (1-a/b) beta^(a/b) "
        "(t - t_e))^(b/(b-a)) solves eq 21 from e(t_e) = e0 > 0 and reaches 0 at t_f of eq 22",
        "solution", e_t, -(beta * x) ** r, variable=t, state=x,
        initial=(te, e0), terminal=(t_f, 0),
        given=((t, te + (e0**rho - W) / (rho * beta**r)),),
        hypotheses=(hyp(W, "<=", e0**rho),),
        sample=((rho, 0.02, 0.48), (W, 0.01, 0.5), (e0, 0.6, 3.0)),
        note="rho = 1 - a/b = (b-a)/b in (0, 1/2); time is written t = t_e + (e0^rho - W)/"
             "(rho beta^(1-rho)) with W = e(t)^rho > 0, i.e. t in [t_e, t_f); e0 < 0 is "
             "symmetric."))
    return out
