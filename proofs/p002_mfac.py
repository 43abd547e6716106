"""Paper 002, CFDL-MFAC (eqs 3-9): both update laws derived as minimisers.

Data model (eq 4, compact-form dynamic linearisation):
y(k+1) = y(k) + phi(k) (u(k) - u(k-1)). The formulas of eqs 3-9 were lost
when the paper's text was extracted; the laws are the standard CFDL-MFAC ones
(Hou & Jin), as in the digest. The step factors rho and eta of the laws scale
the minimising step: the minimiser itself is the law at rho = 1 (eta = 1).
"""
from __future__ import annotations

import sympy as sp

from workbench.symbolic.proof import Claim

PAPER = "002"
TITLE = "ATO speed tracking with model-free adaptive control (CFDL-MFAC)"

lam, mu = sp.symbols("lambda mu", positive=True)
u, u_prev, y, y_star, phi = sp.symbols(r"u_k u_{k-1} y_k y^*_{k+1} \phi_k", real=True)
ph, ph_prev, du_prev, dy = sp.symbols(r"\hat{\phi}_k \hat{\phi}_{k-1} \Delta{}u_{k-1} \Delta{}y_k",
                                      real=True)


def claims() -> list[Claim]:
    y_next = y + phi * (u - u_prev)                                      # eq (4)
    J6 = (y_star - y_next) ** 2 + lam * (u - u_prev) ** 2                # eq (6)
    law = u_prev + phi * (y_star - y) / (lam + phi**2)                   # eq (7), rho = 1
    J8 = (dy - ph * du_prev) ** 2 + mu * (ph - ph_prev) ** 2             # eq (8)
    ppd = ph_prev + du_prev * (dy - ph_prev * du_prev) / (mu + du_prev**2)  # eq (9), eta = 1
    return [
        Claim("mfac-eq6-control", PAPER, "4, 6-7",
              "u(k) = u(k-1) + phi (y* - y)/(lambda + phi^2) is the unique minimiser of "
              "J = |y*(k+1) - y(k+1)|^2 + lambda |u(k) - u(k-1)|^2 under data model (4)",
              "minimiser", J6, law, variable=u),
        Claim("mfac-eq8-ppd", PAPER, "8-9",
              "phi(k) = phi(k-1) + du (dy - phi(k-1) du)/(mu + du^2) is the unique minimiser of "
              "J = |dy(k) - phi du(k-1)|^2 + mu |phi - phi(k-1)|^2",
              "minimiser", J8, ppd, variable=ph),
    ]
