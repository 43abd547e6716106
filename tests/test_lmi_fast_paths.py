"""Issue 36 item 4: the cheaper LMI paths decide exactly as the old ones.

* Every LMI solve unpacks the primal values only
  (:mod:`workbench.lmi.primal`): the same data reach Clarabel and
  the same inversion gives the values, so status, optimum and every variable
  are bit for bit those of cvxpy's ``Problem.solve``.
* The canonical gain's bisection decides its probes at or above the
  synthesis's refuted delay without a solve: the same probes, the same bracket
  and gain, fewer solver calls.
* Repeat solves of a compiled problem take the lean path
  (:class:`workbench.lmi.primal._Lean`): the same data arrays and the same
  values as cvxpy's ``get_problem_data`` and ``unpack_results``, bit for bit,
  whatever parameter changed (delay, eps, a shared gain, an interval's lower
  end); a map that does not reproduce cvxpy's is not used.
"""
from __future__ import annotations

import cvxpy as cp
import numpy as np
import pytest

from workbench.lmi import core, gain, primal
from workbench.lmi.analysis import BesselLegendreLMI, DelayIndependentLMI
from workbench.lmi.core import IMPLIED, Outcome
from workbench.lmi.freeweighting003 import FreeWeighting003, FreeWeighting003FixedK
from workbench.lmi.interval import IntervalLMI
from workbench.synthesis import synthesize_delay_bound

A2 = np.array([[0.0, 1.0], [-2.0, -0.5]])
B2 = np.array([[0.0], [1.0]])


def _values(lmi):
    return ({k: np.array(v.value) for k, v in lmi._vars.items()}, lmi._t.value,
            lmi._problem.status)


@pytest.mark.parametrize("make, hs", [
    (lambda: FreeWeighting003(A2, B2, 0.3), (0.05, 0.6, 3.0)),
    (lambda: BesselLegendreLMI(np.array([[-2.0, 0.0], [0.0, -0.9]]),
                               np.array([[-1.0, 0.0], [-1.0, -1.0]]), N=2), (1.0, 6.2, 6.3)),
])
def test_primal_only_solve_is_cvxpys_bit_for_bit(make, hs):
    # two twins solved along the same delays (cvxpy may reuse a problem's
    # Clarabel solver between solves, so each path keeps its own history)
    old, lmi = make(), make()
    for h in hs:
        old.set_delay(h)
        old._problem.solve(solver=cp.CLARABEL)           # cvxpy's own path, duals too
        full = _values(old)
        lmi.set_delay(h)
        core.guarded_solve(lmi._problem)                 # the primal-only path
        fast = _values(lmi)
        assert fast[2] == full[2] and fast[1] == full[1]
        assert all(np.array_equal(fast[0][k], full[0][k]) for k in full[0])


def test_gain_probes_above_the_refuted_delay_need_no_solve(monkeypatch):
    rows = {}
    for implied in (False, True):
        monkeypatch.setattr(gain, "IMPLIED_PROBES", implied)
        rows[implied] = synthesize_delay_bound(A2, B2, (0.3,))[0]
    old, new = rows[False], rows[True]
    assert new.status is Outcome.CERTIFIED
    assert (new.h_certified, new.h_refuted, new.K, new.h_gain) == (
        old.h_certified, old.h_refuted, old.K, old.h_gain)
    probes = [s.h for s in new.gain.analysis.steps]
    assert probes == [s.h for s in old.gain.analysis.steps]      # the same path
    implied = [s for s in new.gain.analysis.steps if s.solver_status.startswith(IMPLIED)]
    assert implied and all(s.outcome is Outcome.REFUTED and s.h >= new.h_refuted
                           for s in implied)
    # ... each of which the solver refutes too, and each saves a solve
    assert all(o.outcome is Outcome.REFUTED for o, s in zip(old.gain.analysis.steps,
                                                          new.gain.analysis.steps)
               if s in implied)
    assert new.solves == old.solves - len(implied)
    assert new.gain.analysis.solves == len(probes) - len(implied)


def test_no_implied_probe_without_a_bounded_gain():
    """The implication needs |V| = |K X| <= bound: with a gain whose row sum is
    above the bound every probe is solved, with a bounded one not."""
    from workbench.lmi.freeweighting003 import FreeWeighting003FixedK
    lmi = FreeWeighting003(A2, B2, 0.3)

    def fixed(K):
        return FreeWeighting003FixedK(A2, B2, 0.3, K=K)
    for K, bounded in (([[-1.0, -1.0]], True), ([[-2e3, 0.0]], False)):
        lmi.gain = lambda values, K=K: np.array(K)
        g = gain.canonical_gain(lmi, 0.05, fixed, np.eye(2), h_hi=10.0, refuted_from=1e-3)
        above = [s for s in g.analysis.steps if s.h >= 1e-3]
        assert above and all(s.solver_status.startswith(IMPLIED) is bounded for s in above)
        below = [s for s in g.analysis.steps if s.h < 1e-3]
        assert not any(s.solver_status.startswith(IMPLIED) for s in below)
        assert g.analysis.solves == len(below) + (0 if bounded else len(above))


AW, ADW = np.array([[-2.0, 0.0], [0.0, -0.9]]), np.array([[-1.0, 0.0], [-1.0, -1.0]])


def _vary(lmi, i):
    """Change every parameter of ``lmi`` besides the delay for solve ``i``."""
    if isinstance(lmi, FreeWeighting003FixedK):
        lmi.set_gain([[-1.0 - 0.25 * i, -2.0 + 0.125 * i]])
    if isinstance(lmi, FreeWeighting003):
        lmi.set_eps(0.3 + 0.01 * i)
    if isinstance(lmi, IntervalLMI):
        lmi.set_lower(0.05 * (i + 1))


@pytest.mark.parametrize("make", [
    lambda: FreeWeighting003(A2, B2, 0.3),
    lambda: FreeWeighting003FixedK(A2, B2, 0.3, K=[[-1.0, -2.0]], shared=True),
    lambda: BesselLegendreLMI(AW, ADW, N=2),
    lambda: IntervalLMI(BesselLegendreLMI(AW, ADW, N=2), from_zero=False),
    lambda: DelayIndependentLMI(AW, ADW),
], ids=["free-weighting-003", "fixed-gain", "bessel-legendre", "interval", "no-parameter"])
def test_lean_repeat_solves_are_cvxpys_bit_for_bit(make, monkeypatch):
    old, lmi = make(), make()
    # certified, refuted and near-boundary delays
    for i, h in enumerate((0.05, 0.6, 3.0, 1.0, 6.2, 6.3, 0.01)):
        for twin, lean in ((old, False), (lmi, True)):
            monkeypatch.setattr(primal, "LEAN", lean)
            _vary(twin, i)
            twin.set_delay(h)
            core.guarded_solve(twin._problem)
        full, fast = _values(old), _values(lmi)
        assert fast[2] == full[2] and fast[1] == full[1]
        assert all(np.array_equal(fast[0][k], full[0][k]) for k in full[0])
    maps = lmi._problem._workbench_lean           # ... and the lean maps were used
    assert maps.data_ok and maps.values_ok
    assert not hasattr(old._problem, "_workbench_lean")


def test_lean_data_map_that_differs_from_cvxpys_is_not_used():
    lmi = FreeWeighting003(A2, B2, 0.3)
    lmi.set_delay(0.1)
    p = lmi._problem
    data, chain, inverse = p.get_problem_data(cp.CLARABEL, solver_opts={})
    assert primal._Lean(p, data, chain, inverse).data_ok
    tampered = dict(data, A=data["A"].copy())
    tampered["A"].data[0] = np.nextafter(tampered["A"].data[0], np.inf)
    assert not primal._Lean(p, tampered, chain, inverse).data_ok


def test_lean_value_map_that_combines_entries_is_not_used(monkeypatch):
    lmi = FreeWeighting003(A2, B2, 0.3)
    lmi.set_delay(0.1)
    p = lmi._problem
    data, chain, inverse = p.get_problem_data(cp.CLARABEL, solver_opts={})
    assert primal._Lean(p, data, chain, inverse).values_ok
    first, L = chain.reductions[0], lmi._vars["L"]
    invert = first.invert

    def mixed(solution, inv):
        # L[0, 0] = a + (b - floor(b)) with b = L[1, 1]: on the positions marker
        # (integers) a copy of a, on the random marker not: only the second marker
        # can reject this map
        sol = invert(solution, inv)
        x = np.array(sol.primal_vars[L.id], dtype=float)
        x[0, 0] = x[0, 0] + (x[1, 1] - np.floor(x[1, 1]))
        sol.primal_vars[L.id] = x
        return sol
    monkeypatch.setattr(first, "invert", mixed)
    assert not primal._Lean(p, data, chain, inverse).values_ok
