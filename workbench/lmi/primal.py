"""The primal-only solve of every LMI (issue 36, item 4).

:func:`workbench.lmi.core.guarded_solve` solves through cvxpy's
``Problem.solve`` with the solve method :data:`PRIMAL_ONLY`: the same steps
as cvxpy's own ``Problem._solve`` except that Clarabel's dual vector is not
unpacked (the workbench never reads a dual value, and unpacking the duals
of every PSD block into full matrices was the largest part of cvxpy's time
after a solve). Same data, same Clarabel solver, same inversion of the
primal values: bit for bit cvxpy's answer (``tests/test_lmi_fast_paths.py``).
"""
from __future__ import annotations

import cvxpy as cp

__all__ = ["FULL_UNPACK", "PRIMAL_ONLY"]

#: Solve through cvxpy's own ``Problem._solve`` (dual values unpacked too)
#: instead of :func:`_solve_primal`: the path before issue 36's cut, for
#: ``benchmarks/synthesize_times.py`` (same status, same primal values).
FULL_UNPACK = False


class _PrimalOnly:
    """Clarabel's answer without its dual vector ``z``: cvxpy then recovers
    the primal values only (the duals of the ~10-20 PSD blocks are unpacked
    into full matrices, the largest part of cvxpy's time after a solve, and
    the workbench never reads them)."""

    __slots__ = ("status", "solve_time", "iterations", "x", "obj_val", "z")

    def __init__(self, raw):
        self.status, self.solve_time, self.iterations = raw.status, raw.solve_time, raw.iterations
        self.x, self.obj_val, self.z = raw.x, raw.obj_val, None


def _solve_primal(problem: cp.Problem, solver: str = cp.CLARABEL, **settings) -> None:
    """``problem.solve(solver=cp.CLARABEL, **settings)``, primal values only
    (registered as the cvxpy solve method :data:`PRIMAL_ONLY`).

    The same steps as cvxpy's ``Problem._solve`` (``get_problem_data``, the
    solving chain's ``solve_via_data`` with the problem's solver cache, then
    ``unpack_results``): the same data reach Clarabel, a new Clarabel solver
    is built for every solve as before (its data update is refused with
    presolve or chordal decomposition on, the defaults), and the status,
    optimal value and variable values are unpacked by the same inversion,
    bit for bit; only the dual values are left unset (issue 36, item 4).
    """
    for par in problem.parameters():
        if par.value is None:
            raise cp.error.ParameterError(f"parameter {par.name()} has no value")
    data, chain, inverse = problem.get_problem_data(solver, solver_opts=settings)
    raw = chain.solve_via_data(problem, data, True, False, dict(settings))
    problem.unpack_results(_PrimalOnly(raw), chain, inverse)


#: Name of :func:`_solve_primal` as a cvxpy solve method (``Problem.solve(method=...)``).
PRIMAL_ONLY = "workbench_primal_only"
cp.Problem.register_solve(PRIMAL_ONLY, _solve_primal)
