"""The primal-only solve of every LMI, and its lean repeat (issue 36, item 4).

:func:`workbench.lmi.core.guarded_solve` solves through cvxpy's
``Problem.solve`` with the solve method :data:`PRIMAL_ONLY`: the same steps
as cvxpy's own ``Problem._solve`` except that Clarabel's dual vector is not
unpacked (the workbench never reads a dual value, and unpacking the duals
of every PSD block into full matrices was the largest part of cvxpy's time
after a solve). Same data, same Clarabel solver, same inversion of the
primal values: bit for bit cvxpy's answer (``tests/test_lmi_fast_paths.py``).

Every later solve of the same compiled problem (a bisection's next delay)
takes the **lean** path (:class:`_Lean`): the solver's data are the
compiled map applied to the parameter vector, ``flat = M p`` (the same sparse
product cvxpy computes), placed into the same sparse structure cvxpy builds,
and the variables' values are the entries of Clarabel's ``x`` that cvxpy's
inversion copies into them. Both maps are taken from cvxpy's own path at the
problem's first solve and kept only when they reproduce it exactly: the data
array for array, the inversion on two marker vectors (the positions, and
seeded random reals: each value must be one entry of ``x``, not a
combination). Clarabel, its settings, its solver cache and the status map are
cvxpy's; only cvxpy's per-solve bookkeeping (about a millisecond a solve)
is skipped, so the lean path is bit for bit cvxpy's answer too.
"""
from __future__ import annotations

import cvxpy as cp
import numpy as np
import scipy.sparse as sp
from cvxpy import settings as cps
from cvxpy.cvxcore.python import canonInterface
from cvxpy.reductions.solution import Solution
from cvxpy.reductions.solvers.conic_solvers.conic_solver import ConicSolver
from cvxpy.reductions.solvers.solver_inverse_data import SolverInverseData

__all__ = ["FULL_UNPACK", "LEAN", "PRIMAL_ONLY"]

#: Solve through cvxpy's own ``Problem._solve`` (dual values unpacked too)
#: instead of :func:`_solve_primal`: the path before issue 36's cut, for
#: ``benchmarks/synthesize_times.py`` (same status, same primal values).
FULL_UNPACK = False
#: Repeat solves of a compiled problem take the lean path (:class:`_Lean`);
#: False: cvxpy's ``get_problem_data`` and ``unpack_results`` every time
#: (``benchmarks/synthesize_times.py``; the same bits either way).
LEAN = True
#: Seed of the random marker that checks the lean value map (:class:`_Lean`).
MARKER_SEED = 36


class _PrimalOnly:
    """Clarabel's answer without its dual vector ``z``: cvxpy then recovers
    the primal values only (the duals of the ~10-20 PSD blocks are unpacked
    into full matrices, the largest part of cvxpy's time after a solve, and
    the workbench never reads them)."""

    __slots__ = ("status", "solve_time", "iterations", "x", "obj_val", "z")

    def __init__(self, raw):
        self.status, self.solve_time, self.iterations = raw.status, raw.solve_time, raw.iterations
        self.x, self.obj_val, self.z = raw.x, raw.obj_val, None


class _Lean:
    """The data and value maps of one compiled problem (module docstring).

    Built from cvxpy's answer to the problem's first solve (``data``,
    ``inverse``); ``data_ok`` / ``values_ok`` say whether each map reproduced
    cvxpy's exactly (else cvxpy's own step runs every time).
    """

    def __init__(self, problem: cp.Problem, data: dict, chain, inverse: list):
        self.prog = problem._cache.param_prog
        self.chain, self.inverse = chain, inverse[:-1]
        self.solver_inverse = inverse[-1]
        self.data_ok = self.values_ok = False
        try:
            self._data_map(data)
        except Exception:             # an unexpected layout: cvxpy's own step
            self.data_ok = False
        try:
            self._value_map(problem, chain, inverse)
        except Exception:
            self.values_ok = False

    # -- data: flat = M p into cvxpy's sparse structure ---------------------------
    def _data_map(self, data: dict) -> None:
        prog = self.prog
        red = prog.reduced_A
        if (red.problem_data_index is None or red.mapping_nonzero is not None
                or prog.P is not None or prog.lb_tensor is not None
                or prog.ub_tensor is not None):
            return
        indices, indptr, shape = red.problem_data_index
        m, n1 = shape
        n = n1 - 1
        self.mat, self.m, self.n = red.reduced_mat, m, n
        self.nnz_A = int(indptr[n])
        self.A_indices = np.asarray(indices[:self.nnz_A])
        self.A_indptr = np.asarray(indptr[:n + 1])
        self.b_rows = np.asarray(indices[self.nnz_A:indptr[n1]])
        if len(np.unique(self.b_rows)) != len(self.b_rows):    # summed by cvxpy
            return
        q_param = prog.q[:, :-1] if prog.q.shape[1] > 1 else None
        if q_param is not None and q_param.nnz:            # c depends on parameters
            return
        self.c = data[cps.C]
        self.dims = data[ConicSolver.DIMS]
        mine = self.data(self._param_vector())
        self.data_ok = (isinstance(data[cps.A], type(mine[cps.A]))
                        and all(np.array_equal(getattr(data[cps.A], k), getattr(mine[cps.A], k))
                                for k in ("data", "indices", "indptr", "shape"))
                        and data[cps.A].data.dtype == mine[cps.A].data.dtype
                        and np.array_equal(data[cps.B], mine[cps.B])
                        and data[cps.B].dtype == mine[cps.B].dtype
                        and np.array_equal(data[cps.C], mine[cps.C]))

    def _param_vector(self):
        prog = self.prog
        return canonInterface.get_parameter_vector(
            prog.total_param_size, prog.param_id_to_col, prog.param_id_to_size,
            lambda idx: np.array(prog.id_to_param[idx].value))

    def data(self, pvec) -> dict:
        """The solver's data at parameter vector ``pvec`` (cvxpy's layout)."""
        # (no parameter: cvxpy flattens the constant map itself)
        flat = self.mat.toarray().flatten() if pvec is None else self.mat @ pvec
        A = sp.csc_array((-flat[:self.nnz_A], self.A_indices, self.A_indptr),
                         shape=(self.m, self.n))
        b = np.zeros(self.m)
        b[self.b_rows] = flat[self.nnz_A:]
        return {cps.A: A, cps.B: b, cps.C: self.c, ConicSolver.DIMS: self.dims,
                cps.LOWER_BOUNDS: None, cps.UPPER_BOUNDS: None}

    # -- values: the entries of x cvxpy's inversion copies ------------------------
    def _value_map(self, problem, chain, inverse) -> None:
        var_id = self.solver_inverse[chain.solver.VAR_ID]
        n = int(self.prog.x.size)
        # two markers: the positions 1..n, and seeded random reals (an entry that
        # cvxpy combines from several entries of x, e.g. an average, matches
        # one random marker only by a measure-zero accident)
        noise = np.random.default_rng(MARKER_SEED).standard_normal(n)
        values = []
        for marker in (np.arange(1.0, n + 1.0), noise):
            # the solver step's own inversion gives {var_id: x}; invert the rest
            sol = Solution(cps.OPTIMAL, 0.0, {var_id: marker}, {}, {})
            for r, inv in reversed(list(zip(chain.reductions[:-1], self.inverse))):
                sol = r.invert(sol, inv)
            values.append(sol.primal_vars)
        self.take = {}
        for v in problem.variables():
            val = np.asarray(values[0][v.id], dtype=float)
            pos = val.ravel(order="F")
            if not (np.all(pos == np.round(pos)) and np.all((pos >= 1) & (pos <= n))):
                return
            idx = pos.astype(np.intp) - 1
            if not np.array_equal(np.asarray(values[1][v.id], dtype=float).ravel(order="F"),
                                  noise[idx]):
                return
            self.take[v.id] = (v, idx, val.shape)
        self.var_id = var_id
        self.values_ok = True

    def unpack(self, problem: cp.Problem, raw, settings: dict) -> None:
        """``problem.unpack_results`` of Clarabel's answer ``raw``: the lean
        value map when a solution is present, cvxpy's inversion otherwise."""
        inv = SolverInverseData(self.solver_inverse.inverse_data, self.chain.solver, settings)
        answer = _PrimalOnly(raw)
        if self.values_ok:
            sol = self.chain.solver.invert(answer, inv)
            if sol.status in cps.SOLUTION_PRESENT:
                x = np.asarray(sol.primal_vars[self.var_id])
                vals = {vid: x[idx].reshape(shape, order="F")
                        for vid, (v, idx, shape) in self.take.items()}
                problem.unpack(Solution(sol.status, sol.opt_val, vals, {}, sol.attr))
                return
        problem.unpack_results(answer, self.chain, self.inverse + [inv])


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
    Repeat solves take the lean path (module docstring).
    """
    for par in problem.parameters():
        if par.value is None:
            raise cp.error.ParameterError(f"parameter {par.name()} has no value")
    lean = problem.__dict__.get("_workbench_lean")
    cache = problem._cache
    if (LEAN and lean is not None and lean.data_ok and cache.param_prog is lean.prog
            and cache.solving_chain is lean.chain):
        for reduction in lean.chain.reductions:
            reduction.update_parameters(problem)
        data = lean.data(lean._param_vector())
        raw = lean.chain.solve_via_data(problem, data, True, False, dict(settings))
        lean.unpack(problem, raw, dict(settings))
        return
    data, chain, inverse = problem.get_problem_data(solver, solver_opts=settings)
    raw = chain.solve_via_data(problem, data, True, False, dict(settings))
    if LEAN and cache.param_prog is not None and lean is None:
        problem._workbench_lean = lean = _Lean(problem, data, chain, inverse)
    if LEAN and lean is not None and lean.values_ok and cache.param_prog is lean.prog:
        lean.unpack(problem, raw, dict(settings))
    else:
        problem.unpack_results(_PrimalOnly(raw), chain, inverse)


def precompile(problem: cp.Problem) -> None:
    """Compile ``problem`` for Clarabel ahead of its first solve (e.g. in a
    worker process while another process solves): cvxpy keeps the compiled
    chain in the problem's cache under the key every solve here uses, so the
    first solve only applies the parameters. The parameters need values; a
    DPP compilation does not depend on them."""
    problem.get_problem_data(cp.CLARABEL)


#: Name of :func:`_solve_primal` as a cvxpy solve method (``Problem.solve(method=...)``).
PRIMAL_ONLY = "workbench_primal_only"
cp.Problem.register_solve(PRIMAL_ONLY, _solve_primal)
