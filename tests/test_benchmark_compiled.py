"""Shared compilations of the delay benchmark (issue 36, item 4): a fork of a
criterion solves bit for bit as a newly built one, and an order's interval is
implied by the order below only when that one fills the exact window on the
printed grid."""
from types import SimpleNamespace

import numpy as np

from workbench.benchmark_windows import Compiled, fork, implies_next
from workbench.lmi.analysis import make_criterion
from workbench.lmi.core import Outcome

A = np.array([[-2.0, 0.0], [0.0, -0.9]])
AD = np.array([[-1.0, 0.0], [-1.0, -1.0]])


def _same(s, t) -> bool:
    return (s.outcome is t.outcome and s.t_opt == t.t_opt
            and all(np.array_equal(s.certificate[k], t.certificate[k]) for k in s.certificate))


def test_fork_solves_as_a_new_criterion_without_compiling():
    used = make_criterion("wirtinger", A, AD)
    used.solve_at(1.0)
    used.solve_at(2.0)                   # a solver state a new criterion does not have
    twin = fork(used)
    assert twin._problem._cache is used._problem._cache
    new = make_criterion("wirtinger", A, AD)
    s, t = twin.solve_at(3.0), new.solve_at(3.0)
    assert s.outcome is Outcome.CERTIFIED and _same(s, t)
    # and the original keeps its own solver state: as if never forked
    again = make_criterion("wirtinger", A, AD)
    again.solve_at(1.0)
    again.solve_at(2.0)
    assert _same(used.solve_at(2.5), again.solve_at(2.5))


def test_compiled_hands_out_forks():
    comp = Compiled(A, AD, 1e-10)
    a, b = comp.criterion("jensen"), comp.criterion("jensen")
    assert a is not b and a._problem._cache is b._problem._cache
    w1, w2 = comp.interval(b, from_zero=False), comp.interval(a, from_zero=False)
    assert w1 is not w2 and w1._problem._cache is w2._problem._cache
    assert comp.interval(a, from_zero=True)._problem._cache is not w1._problem._cache


def test_wirtinger_is_bessel_legendre_of_order_one():
    comp = Compiled(A, AD, 1e-10)
    w, bl = comp.criterion("wirtinger"), comp.criterion("bessel-legendre", 1)
    assert (w.method, bl.method, bl.N) == ("wirtinger", "bessel-legendre", 1)
    assert bl._problem._cache is w._problem._cache
    assert _same(bl.solve_at(5.0), make_criterion("bessel-legendre", A, AD, N=1).solve_at(5.0))


def _row(lo, hi, n=1):
    return SimpleNamespace(interval=(lo, hi), intervals=((lo, hi),) * n)


def test_implies_next_only_when_the_window_is_filled_on_the_grid():
    pi2 = ((0.0, 1.5707963267948966),)
    assert implies_next(_row(0.0, 1.57), pi2, 100.0)            # next grid value 1.571 > pi/2
    assert not implies_next(_row(0.0, 1.569), pi2, 100.0)       # 1.57 might still be certified
    assert not implies_next(None, pi2, 100.0)
    pocket = ((0.1001683, 1.717858),)
    assert implies_next(_row(0.1002, 1.717), pocket, 100.0)
    assert not implies_next(_row(0.1003, 1.717), pocket, 100.0)  # 0.1002 might be certified
    assert implies_next(_row(0.0, 100.0), ((0.0, float("inf")),), 100.0)   # at the cap
    assert not implies_next(_row(0.0, 95.49), ((0.0, float("inf")),), 100.0)
    two = ((0.0, 1.226441), (6.035517, 6.132204))
    assert not implies_next(_row(0.0, 1.226), two, 100.0)       # a later window may be found
