"""Time-varying delay h(t) in [0, h2], |h'| <= mu: published table vs ours.

The classic example A = [[-2, 0], [0, -0.9]], A_d = [[-1, 0], [-1, -1]]
(SG13 sec. 4). Per mu: the published maximal h2 of Seuret & Gouaisbaut 2013
(Table 2, Theorem 7), ours with delay windows (SG13 Th. 7's functional) at
the paper's solver margin (1e-9) and at the workbench default (1e-7), ours
with fixed windows (the only form for mu unknown), the exact constant-delay
margin (an upper bound of every interval certificate), solver calls and
seconds. Every h2 is an interval certificate: stable for every h(t) in
[0, h2] with |h'(t)| <= mu. Then the synthesis (eps searched, canonical
gain) on the scalar loop x' = x + K x(t - h(t)).

Run: ``.venv/bin/python benchmarks/varying_delay.py``
"""
from __future__ import annotations

import time

import numpy as np

from workbench.lmi.varying import certified_varying_delay
from workbench.lmi.varying_synthesis import synthesize_varying
from workbench.margins import delay_margin_eig
from workbench.report.markdown import md_table

A = np.array([[-2.0, 0.0], [0.0, -0.9]])
AD = np.array([[-1.0, 0.0], [-1.0, -1.0]])
SCALAR = (np.array([[1.0]]), np.array([[1.0]]))
#: SG13 Table 2, Theorem 7 (3 decimals); None: no published value found.
PUBLISHED = {0.1: 4.703, 0.5: 2.420, 0.8: 2.137, None: None}


def _fmt(x: float | None) -> str:
    return "—" if x is None else f"{x:.4f}"


def main() -> None:
    exact = delay_margin_eig(A, AD).h
    rows, t_all = [], time.perf_counter()
    for mu, pub in PUBLISHED.items():
        cells, solves, secs = [], 0, 0.0
        for windows, margin in (("delay", 1e-9), ("delay", 1e-7), ("fixed", 1e-7)):
            if mu is None and windows == "delay":
                cells.append(None)
                continue
            b = certified_varying_delay(A, AD, mu=mu, windows=windows, margin=margin,
                                        rel_tol=2e-5, h_hi=20.0, guess=pub or 2.0)
            cells.append(b.h2)
            solves, secs = solves + b.solves, secs + b.seconds
        rows.append(["unknown" if mu is None else f"{mu:g}", "—" if pub is None else
                     f"{pub:.3f}"] + [_fmt(c) for c in cells]
                    + [f"{exact:.4f}", solves, f"{secs:.1f}"])
    print("x' = A x + A_d x(t - h(t)), h(t) in [0, h2], |h'(t)| <= mu: largest certified h2 (s)")
    print(md_table(["mu", "SG13 Tab. 2", "delay win. 1e-9", "delay win. 1e-7",
                    "fixed win. 1e-7", "exact const.", "solves", "s"], rows, "lrrrrrrr"))
    print(f"\ntotal {time.perf_counter() - t_all:.1f} s. Every h2 is an interval "
          "certificate [0, h2]; none exceeds the exact constant-delay margin.")
    synthesis_table()


def synthesis_table() -> None:
    """The synthesis on x' = x + u(t - h(t)) (constant-delay limit 1 s for any K)."""
    rows = []
    for mu in (0.1, 0.5, None):
        t0 = time.perf_counter()
        r = synthesize_varying(*SCALAR, mu=mu, h_max=5.0, rel_tol=1e-3)
        rows.append(["unknown" if mu is None else f"{mu:g}", f"{r.eps:.3g}", _fmt(r.h2),
                     "—" if r.K is None else f"{r.K[0, 0]:.4g}",
                     _fmt(r.gain.h_certified if r.gain else None),
                     _fmt(r.analysis.h2 if r.analysis else None),
                     _fmt(delay_margin_eig(SCALAR[0], SCALAR[1] @ r.K).h if r.K is not None else None), f"{time.perf_counter() - t0:.1f}"])
    print("\nsynthesis, x' = x + K x(t - h(t)), h(t) in [0, h2], |h'| <= mu (limit 1 s)")
    print(md_table(["mu", "eps", "h2 synthesis", "K (canonical)", "h2 with K fixed",
                    "h2 analysis of K", "exact const. with K", "s"], rows, "lrrrrrrr"))


if __name__ == "__main__":
    main()
