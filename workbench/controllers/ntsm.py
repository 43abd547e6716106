"""Non-singular terminal sliding-mode (NTSM) spacing control of paper 001, and
the constant-spacing PD law it is compared with.

Spacing error of follower i (eq 7) e = x_{i-1} - x_i - D, e' = v_{i-1} - v_i;
surface (eq 10) s = e + (1/beta) e'^(b/a); reaching law (eq 12)
s' = -(j s + k s^(alpha/xi)) e'^(b/a - 1); control (eq 13)::

    u1 = c0 + c1 v + c2 v^2 + m g sin(phi)
    u2 = (beta a m / b) e'^(2 - b/a)
    u3 = (beta a m / b) (j s + k s^(alpha/xi))
    u4 = (G_w + G_d) sign(s) + m v'_{i-1}

Fractional powers x^(p/q) with q odd are the real odd roots
``sign(x)^p |x|^(p/q)``: sign-preserving (sig(x)^r = sign(x)|x|^r) when p is
odd (b/a, 2 - b/a, alpha/xi), even and non-negative when p is even
(b/a - 1 = (b - a)/a with a, b odd) — which is what the paper's proof uses
("e'^(b/a - 1) > 0 for e' != 0"). On s = 0, e' = -sig(beta e)^(a/b) and e
reaches 0 in (eq 22) t_f - t_e = b/(b - a) beta^(-a/b) |e(t_e)|^(1 - a/b).

References
----------
.. [001] Fan L., "Virtual formation train tracking control strategy based on
   sliding mode control", Urban Mass Transit 2024(10), eqs 7-22.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def odd_root_power(x, num: int, den: int):
    """Real value of x^(num/den) for an odd ``den``: sign(x)^num |x|^(num/den)."""
    if den % 2 == 0:
        raise ValueError(f"den = {den}; expected an odd denominator (real odd root)")
    mag = np.abs(x) ** (num / den)
    return np.sign(x) * mag if num % 2 else mag


@dataclass(frozen=True)
class NTSMGains:
    """Parameters of eqs 10-13 (paper 001 gives none: they are design data).

    Attributes
    ----------
    beta : float
        Surface gain (> 0), units making e'^(b/a)/beta a length.
    a, b : int
        Positive odd integers, 1 < b/a < 2.
    j, k : float
        Reaching-law gains (> 0).
    alpha, xi : int
        Positive odd integers, 0 < alpha/xi < 1.
    """

    beta: float
    a: int
    b: int
    j: float
    k: float
    alpha: int
    xi: int

    def problems(self) -> list[tuple[str, object, str]]:
        """(field, value, expected) for every condition of eqs 10-12 that fails."""
        out = []
        for name in ("a", "b", "alpha", "xi"):
            val = getattr(self, name)
            if not (isinstance(val, int) and val > 0 and val % 2 == 1):
                out.append((name, val, "a positive odd integer"))
        if not out:
            if not 1 < self.b / self.a < 2:
                out.append(("b", self.b, f"1 < b/a < 2 with a = {self.a}"))
            if not 0 < self.alpha / self.xi < 1:
                out.append(("alpha", self.alpha, f"0 < alpha/xi < 1 with xi = {self.xi}"))
        for name in ("beta", "j", "k"):
            if not getattr(self, name) > 0:
                out.append((name, getattr(self, name), "a positive number"))
        return out


def surface(e, de, g: NTSMGains):
    """NTSM surface s = e + (1/beta) e'^(b/a) (m), eq 10."""
    return e + odd_root_power(de, g.b, g.a) / g.beta


def ntsm_force(e, de, s, resist, m: float, a_pred, bound: float, g: NTSMGains):
    """Control force u = u1 + u2 + u3 + u4 (N) of eq 13.

    Parameters
    ----------
    e, de, s : array
        Spacing error (m), its rate (m/s) and the surface value (m).
    resist : array
        u1: the nominal Davis plus gradient force (N) the law cancels.
    m : float
        Nominal mass (kg).
    a_pred : array
        Predecessor acceleration v'_{i-1} (m/s^2), as communicated.
    bound : float
        G_w + G_d (N).
    """
    c = g.beta * g.a * m / g.b
    u2 = c * odd_root_power(de, 2 * g.a - g.b, g.a)
    u3 = c * (g.j * s + g.k * odd_root_power(s, g.alpha, g.xi))
    u4 = bound * np.sign(s) + m * a_pred
    return resist + u2 + u3 + u4


def convergence_time(e_te, g: NTSMGains, e_end=0.0):
    """Time (s) to slide from |e(t_e)| to |e_end| on s = 0.

    With ``e_end = 0`` this is eq 22, b/(b - a) beta^(-a/b) |e|^(1 - a/b); for a
    band ``e_end > 0`` the same integral of e' = -sig(beta e)^(a/b) stops there.
    """
    r = 1.0 - g.a / g.b
    return g.b / (g.b - g.a) * g.beta ** (-g.a / g.b) * (np.abs(e_te) ** r
                                                        - np.abs(e_end) ** r)


def pd_force(e, de, resist, m: float, kp: float, kd: float):
    """Constant-spacing PD baseline u = u1 + m (kp e + kd e') (N).

    The usual predecessor-following law with resistance feed-forward but
    WITHOUT the predecessor's acceleration (which the NTSM law of eq 13 uses):
    the textbook string-unstable case for constant spacing.
    """
    return resist + m * (kp * e + kd * de)


def pd_ff_force(e, de, resist, m: float, a_pred, kp: float, kd: float):
    """PD with acceleration feed-forward u = u1 + m (kp e + kd e' + v'_{i-1}) (N).

    The fair baseline for eq 13: the same information as the NTSM law (the
    predecessor's communicated acceleration ``a_pred``, m/s^2, fed forward
    as in u4), but linear feedback and no switching term.
    """
    return pd_force(e, de, resist, m, kp, kd) + m * a_pred


def linear_member(g: NTSMGains) -> tuple[float, float]:
    """Gains (k_e (1/s^2), k_d (1/s)) of the NTSM family's linear member.

    With b = a and alpha = xi (every power 1) and without the switching term,
    eqs 10-13 become the linear sliding-mode law on s = e + e'/beta with
    s' = -(j + k) s, i.e. (u - u1)/m = v'_{i-1} + k_e e + k_d e' with
    k_e = beta (j + k), k_d = beta + j + k. It is the surrogate the exact
    delay margin is computed on: the law itself has no linearisation at
    e = e' = 0 (powers 2 - b/a and alpha/xi below 1, and sign(s)).
    """
    return g.beta * (g.j + g.k), g.beta + g.j + g.k
