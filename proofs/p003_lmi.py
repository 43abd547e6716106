"""Paper 003, proof of Theorem 1 and Remark 3 (eqs 45-59): the matrix steps.

Checked on generic matrices of the paper's sizes (n = 2 states, one input):
every entry of A, B, K, M1, M2 and of the symmetric L, R, W, Y.. is its own
symbol, so an identity proved here holds for every value of them (L, R, Y11,
Y22 invertible where inverted).

Finding (eq 55): the congruence diag(I, I, 1/h_m) of eq (53) gives the (3,3)
block -iota eps L, not the printed -eps L (iota = 1/h_m); (57) inherits it.
Eq (59) is nevertheless right: with (58), Y1 <= iota L, so -eps Y1 >= -eps
iota L and (59) < 0 implies the corrected (57) < 0.
"""
from __future__ import annotations

import sympy as sp

from workbench.symbolic.proof import Claim, hyp

PAPER = "003"
TITLE = "Antiskid control with input delay: LMI steps of Theorem 1 and Remark 3"

N = 2
h, eps = sp.symbols("h_m varepsilon", positive=True)
iota = 1 / h


#: Severity of the three as-printed (3,3) blocks of eqs 55, 57 and 59.
_LMI_SEVERITY = dict(
    severity="minor",
    severity_reason="intermediate forms only: the two slips cancel, so the LMIs the paper "
                    "solves, (58)-(60), do imply (53) (lmi-eq58-59, proved) and the bounds "
                    "of Table 3 are not affected by them")

def gen(name: str, rows: int = N, cols: int = N) -> sp.Matrix:
    return sp.Matrix(rows, cols, lambda i, j: sp.Symbol(f"{name}_{i + 1}{j + 1}", real=True))


def sym(name: str) -> sp.Matrix:
    return sp.Matrix(N, N, lambda i, j: sp.Symbol(f"{name}_{min(i, j) + 1}{max(i, j) + 1}",
                                                   real=True))


A, B, K = gen("a"), gen("b", N, 1), gen("k", 1, N)
M1, M2, Y12 = gen("m"), gen("n"), gen("y^{12}")
L, R, W, Y11, Y22 = sym("l"), sym("r"), sym("w"), sym("y^{11}"), sym("y^{22}")
Y1, Y2, Y3 = sym("y^{1}"), sym("y^{2}"), sym("y^{3}")
I, Z = sp.eye(N), sp.zeros(N)
V = K * L                                                                   # eq (47)


def blocks(rows) -> sp.Matrix:
    """Block matrix from rows of blocks; ``None`` below the diagonal means the
    transpose of the mirrored block (the paper's ``*``)."""
    full = [[rows[j][i].T if b is None else b for j, b in enumerate(r)]
            for i, r in enumerate(rows)]
    return sp.BlockMatrix(full).as_explicit()


def diag(*ms) -> sp.Matrix:
    return sp.diag(*ms)


def _pi(Y11_, Y12_, Y22_, hh):
    """Pi11, Pi12, Pi22 of eq (35) (hh = 0: the barred ones of eq 56)."""
    return (A * L + L * A.T + M1 + M1.T + W + hh * Y11_,
            B * V - M1 + M2.T + hh * Y12_,
            -M2 - M2.T - W + hh * Y22_)


def claims() -> list[Claim]:
    Li, Ri = L.inv(), R.inv()
    BK = B * K
    s11 = Li * A + A.T * Li + Li * M1 * Li + Li * M1.T * Li + Li * W * Li + h * Li * Y11 * Li
    s12 = Li * BK - Li * M1 * Li + Li * M2.T * Li + h * Li * Y12 * Li
    s22 = -Li * M2 * Li - Li * M2.T * Li - Li * W * Li + h * Li * Y22 * Li
    Xi = blocks([[s11 + h * A.T * Ri * A, s12 + h * A.T * Ri * BK],
                 [None, s22 + h * BK.T * Ri * BK]])                            # eq (45)
    P11, P12, P22 = _pi(Y11, Y12, Y22, h)
    Theta = blocks([[P11 + h * L * A.T * Ri * A * L, P12 + h * L * A.T * Ri * B * V],
                    [None, P22 + h * (B * V).T * Ri * B * V]])                 # eqs (48)-(49)
    Gamma = blocks([[P11, P12, h * L * A.T * Ri], [None, P22, h * V.T * B.T * Ri],
                    [None, None, -h * Ri]])                                   # eq (50)
    G11, G12, G22 = Gamma[:2 * N, :2 * N], Gamma[:2 * N, 2 * N:], Gamma[2 * N:, 2 * N:]
    Lam = blocks([[P11, P12, h * L * A.T], [None, P22, h * V.T * B.T],
                  [None, None, -h * R]])                                      # eq (51)
    Phi = blocks([[Li * Y11 * Li, Li * Y12 * Li, Li * M1 * Li],
                  [None, Li * Y22 * Li, Li * M2 * Li], [None, None, Ri]])     # eq (45)
    Psi = blocks([[Y11, Y12, M1], [None, Y22, M2], [None, None, L * Ri * L]])  # eq (52)
    R_eps = dict(zip(R, eps * L))                                             # Remark 3
    eq53 = blocks([[P11, P12, h * L * A.T], [None, P22, h * V.T * B.T],
                   [None, None, -h * eps * L]])
    eq54 = blocks([[Y11, Y12, M1], [None, Y22, M2], [None, None, L / eps]])
    Pb11, Pb12, Pb22 = _pi(Y11, Y12, Y22, 0)                                   # eq (56)
    hY = blocks([[Y11, Y12, Z], [None, Y22, Z], [None, None, Z]])

    def eq55(c33):
        return blocks([[Pb11, Pb12, L * A.T], [None, Pb22, V.T * B.T],
                       [None, None, c33]]) + h * hY

    T = diag(I, I, I / h)
    Y0 = {y: 0 for y in Y12}

    def eq57(c33):
        return blocks([[Pb11, Pb12, L * A.T, Y11, Z], [None, Pb22, V.T * B.T, Z, Y22],
                       [None, None, c33, Z, Z], [None, None, None, -iota * Y11, Z],
                       [None, None, None, None, -iota * Y22]])

    eq59 = blocks([[Pb11, Pb12, L * A.T, Y11, Z], [None, Pb22, V.T * B.T, Z, Y22],
                   [None, None, -eps * Y1, Z, Z], [None, None, None, -Y2, Z],
                   [None, None, None, None, -Y3]])

    def schur57(M):
        return M[:3 * N, :3 * N] - M[:3 * N, 3 * N:] * M[3 * N:, 3 * N:].inv() * M[3 * N:, :3 * N]

    slack58 = diag(Z, Z, eps * (iota * L - Y1), iota * Y11 - Y2, iota * Y22 - Y3)
    y1, l1, io = sp.symbols("Y_1 L iota", positive=True)
    return [
        Claim("lmi-eq48-49", PAPER, "45, 47-49",
              "diag(L, L) Xi diag(L, L) = Theta with V = K L (Pi of eq 35, X of eq 49)",
              "identity", diag(L, L) * Xi * diag(L, L), Theta,
              display=r"\operatorname{diag}(L,L)\,\Xi\,\operatorname{diag}(L,L) = \Theta,"
                      r"\quad V = KL",
              note="Eq 49's block labelled X13 is X22 and its h_m^T is h_m (label typos)."),
        Claim("lmi-eq50-schur", PAPER, "48-50",
              "Theta is the Schur complement of the (3,3) block -h_m R^{-1} of Gamma "
              "(that block is < 0 for R > 0, so Gamma < 0 <=> Theta < 0)", "identity",
              G11 - G12 * G22.inv() * G12.T, Theta,
              display=r"\Gamma_{[1:2]} - \Gamma_{[1:2],3}\,(-h_m R^{-1})^{-1}\,"
                      r"\Gamma_{3,[1:2]} = \Theta"),
        Claim("lmi-eq51-congruence", PAPER, "50-51, 33",
              "diag(I, I, R) Gamma diag(I, I, R) = Lambda (eq 51, printed as 'A' in eq 33)",
              "identity", diag(I, I, R) * Gamma * diag(I, I, R), Lam,
              display=r"\operatorname{diag}(I,I,R)\,\Gamma\,\operatorname{diag}(I,I,R) = \Lambda"),
        Claim("lmi-eq52", PAPER, "45, 52, 34",
              "diag(L, L, L) Phi diag(L, L, L) = Psi", "identity",
              diag(L, L, L) * Phi * diag(L, L, L), Psi,
              display=r"\operatorname{diag}(L,L,L)\,\Phi\,\operatorname{diag}(L,L,L) = \Psi"),
        Claim("lmi-eq53-54", PAPER, "33-34, 53-54",
              "R = eps L turns (33) into (53) and (34) into (54)", "identity",
              sp.Matrix.vstack(Lam.subs(R_eps), Psi.subs(R_eps)),
              sp.Matrix.vstack(eq53, eq54),
              display=r"\Lambda|_{R=\varepsilon L} = (53),\quad \Psi|_{R=\varepsilon L} = (54)"),
        Claim("lmi-eq55-printed", PAPER, "53, 55-56",
              "diag(I, I, 1/h_m) (53) diag(I, I, 1/h_m) = (55) as printed ((3,3) block -eps L)",
              "identity", T * eq53 * T, eq55(-eps * L), expect="refuted",
              display=r"T\,(53)\,T = (55),\ T = \operatorname{diag}(I, I, h_m^{-1} I),\ "
                      r"(55)_{33} = -\varepsilon L",
              note="The congruence gives (3,3) = -h_m eps L / h_m^2 = -iota eps L.",
              **_LMI_SEVERITY),
        Claim("lmi-eq55-corrected", PAPER, "53, 55-56",
              "diag(I, I, 1/h_m) (53) diag(I, I, 1/h_m) = (55) with (3,3) block -iota eps L",
              "identity", T * eq53 * T, eq55(-iota * eps * L), origin="workbench",
              display=r"T\,(53)\,T = (55),\ (55)_{33} = -\iota\varepsilon L"),
        Claim("lmi-eq57-printed", PAPER, "53, 55, 57",
              "with Y12 = 0, (57) as printed is (by Schur complement) the congruent "
              "form of (53)", "identity", schur57(eq57(-eps * L)), (T * eq53 * T).subs(Y0),
              expect="refuted",
              display=r"\mathrm{Schur}\big((57)\big) = T\,(53)\,T\,|_{Y_{12}=0},\ "
                      r"(57)_{33} = -\varepsilon L",
              note="(57) inherits the (3,3) block of (55).", **_LMI_SEVERITY),
        Claim("lmi-eq57-corrected", PAPER, "53, 55, 57",
              "with Y12 = 0 and (3,3) block -iota eps L, the Schur complement of (57) "
              "w.r.t. -iota diag(Y11, Y22) is the congruent form of (53)", "identity",
              schur57(eq57(-iota * eps * L)), (T * eq53 * T).subs(Y0), origin="workbench",
              display=r"\mathrm{Schur}\big((57)\big) = T\,(53)\,T\,|_{Y_{12}=0},\ "
                      r"(57)_{33} = -\iota\varepsilon L"),
        Claim("lmi-eq58-59", PAPER, "57-59",
              "(57, corrected) = (59) - diag(0, 0, eps(iota L - Y1), iota Y11 - Y2, "
              "iota Y22 - Y3): the subtracted blocks are >= 0 by (58), so (59) < 0 implies "
              "(57) < 0", "identity", eq57(-iota * eps * L), eq59 - slack58,
              display=r"(57) = (59) - \operatorname{diag}\big(0, 0, \varepsilon(\iota L - Y_1),"
                      r" \iota Y_{11} - Y_2, \iota Y_{22} - Y_3\big)"),
        Claim("lmi-eq59-block-printed", PAPER, "57-59",
              "scalar blocks: (58) Y1 <= iota L gives -eps Y1 >= -eps L, so (59) bounds "
              "the printed (3,3) block of (57)", "inequality", -eps * l1, -eps * y1,
              hypotheses=(hyp(y1, "<=", io * l1),), sample=((io, 1.0, 60.0),),
              expect="refuted",
              note="Fails whenever iota > 1, i.e. h_m < 1 s (all of Table 3).",
              **_LMI_SEVERITY),
        Claim("lmi-eq59-block-corrected", PAPER, "57-59",
              "scalar blocks: (58) Y1 <= iota L gives -eps Y1 >= -eps iota L, the "
              "corrected (3,3) block of (57)", "inequality", -eps * io * l1, -eps * y1,
              hypotheses=(hyp(y1, "<=", io * l1),), sample=((io, 1.0, 60.0),),
              terms=(eps * (io * l1 - y1),), origin="workbench"),
    ]
