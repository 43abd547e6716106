"""One ``sympy.lambdify`` per expression and process (issue 36, item 4).

The studies build the same numeric functions many times: every
:class:`~workbench.plants.adhesion.NumericAdhesion` of equal constants, every
linearisation at the same point, every frozen loop of the basin checks.
``sympy.lambdify`` prints the expression to Python source and compiles it
each time (with ``cse=True`` it also eliminates common subexpressions), which
is most of its cost. :func:`lambdify` compiles each distinct (arguments,
expression, backend, cse) once and returns the same function afterwards.

The key is the ``sympy.srepr`` of the arguments and of the expression: the
exact tree, every Float with its precision, so two expressions share a
function only when lambdify would print the same source for both. The
functions are pure (no state between calls), so sharing one is the same as
building it again. A backend that is not a string (a dict or a module list)
is not cached.

References
----------
.. [sympy] SymPy Development Team, ``sympy.utilities.lambdify.lambdify``
   (printing, ``cse``) and ``sympy.srepr`` (exact representation).
"""
from __future__ import annotations

import sympy as sp

__all__ = ["lambdify", "cache_info"]

_CACHE: dict = {}
_STATS = {"hits": 0, "misses": 0}


def lambdify(args, expr, modules: str = "numpy", *, cse: bool = False):
    """``sympy.lambdify(args, expr, modules, cse=cse)``, compiled once per
    process for an equal (srepr of args and expr, modules, cse).

    Parameters
    ----------
    args : sympy.Symbol or sequence of sympy.Symbol
    expr : sympy.Expr or (nested) sequence of sympy.Expr
    modules : str
        The backend ("numpy", "math"); another kind of value bypasses the cache.
    cse : bool
        Common-subexpression elimination (as ``sympy.lambdify``).
    """
    if not isinstance(modules, str):
        return sp.lambdify(args, expr, modules=modules, cse=cse)
    key = (sp.srepr(args), sp.srepr(expr), modules, bool(cse))
    fn = _CACHE.get(key)
    if fn is None:
        _STATS["misses"] += 1
        fn = _CACHE[key] = sp.lambdify(args, expr, modules=modules, cse=cse)
    else:
        _STATS["hits"] += 1
    return fn


def cache_info() -> dict:
    """Hits, misses and the number of functions held (benchmarks)."""
    return {**_STATS, "size": len(_CACHE)}
