"""The plant of a ``delay-feedback`` design: text equations -> one sympy model.

The design writes x_i' = f_i(x, u, p) as text; :mod:`workbench.expr` turns
each into sympy without evaluating anything. From that single model this
module derives everything numeric (style rule "one model, many uses"):

* :func:`solve_operating_point`: the states and inputs the design marks
  ``solve = [lo, hi]`` from f(x, u, p) = 0 (Newton from the guess, then a
  deterministic grid of starts; a root outside the stated ranges does not
  count), the others fixed;
* :func:`linearise`: A = df/dx, B = df/du at that point (symbolic Jacobians
  evaluated in double precision);
* :meth:`PlantModel.rhs`: the vector field for the nonlinear simulation.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ...errors import DesignError
from .spec import PlantSpec


#: Largest |entry| of A = df/dx and B = df/du (SI) the LMIs are asked to handle:
#: past it Clarabel's factorisations fail (a Rust panic at J = 1e-300).
MAX_ENTRY = 1e9
#: Largest residual max |f| (state units per second) of a given operating point.
TRIM_TOL = 1e-6


@dataclass(frozen=True)
class OperatingPoint:
    """A solved operating point.

    Attributes
    ----------
    x, u : numpy.ndarray
        States and inputs (SI units of the design).
    residual : float
        max_i |f_i(x, u)| at the point (units of the state derivatives).
    solved : tuple[str, ...]
        Names computed from f = 0 (the others were fixed by the design).
    """

    x: np.ndarray
    u: np.ndarray
    residual: float
    solved: tuple[str, ...]

    def as_dict(self, spec: PlantSpec) -> dict[str, float]:
        names = spec.state_names + spec.input_names
        return dict(zip(names, [float(v) for v in np.concatenate([self.x, self.u])]))


class PlantModel:
    """The sympy model of a :class:`PlantSpec` (built once per spec).

    Attributes
    ----------
    x, u : tuple[sympy.Symbol, ...]
        State and input symbols.
    p : dict[str, sympy.Symbol]
        Parameter symbols.
    definitions : dict[str, sympy.Expr]
        Named sub-expressions, in terms of x, u, p.
    f : sympy.Matrix
        The vector field (n x 1).
    """

    def __init__(self, spec: PlantSpec):
        import sympy as sp

        from ...expr import parse_expression
        self.spec = spec
        self.x = tuple(sp.Symbol(n, real=True) for n in spec.state_names)
        self.u = tuple(sp.Symbol(n, real=True) for n in spec.input_names)
        self.p = {k: sp.Symbol(k, real=True) for k in spec.parameters}
        names = dict(zip(spec.state_names, self.x)) | dict(zip(spec.input_names, self.u))
        names |= self.p
        self.definitions = {}
        for name, text in spec.definitions:
            e = parse_expression(text, names, path=spec.path, key=f"definitions.{name}")
            self.definitions[name] = e
            names[name] = e
        self.f = sp.Matrix([parse_expression(t, names, path=spec.path,
                                             key=f"equations.{s}")
                            for s, t in zip(spec.state_names, spec.equations)])
        self.check_finite(None, "parameters")

    def _texts(self):
        """(key, text, sympy expression) of every definition and equation."""
        sp = self.spec
        yield from ((f"definitions.{n}", t, self.definitions[n]) for n, t in sp.definitions)
        yield from ((f"equations.{s}", t, self.f[i])
                    for i, (s, t) in enumerate(zip(sp.state_names, sp.equations)))

    def check_finite(self, values: dict[str, float] | None, where: str) -> None:
        """No division by zero, infinity or complex value in any definition or
        equation, as written (``values`` None) or at the parameter values.

        Raises
        ------
        DesignError
            Naming the expression (and ``where`` the values come from).
        """
        import sympy as sp
        bad = (sp.zoo, sp.oo, -sp.oo, sp.nan, sp.I)
        for key, text, e in self._texts():
            v = e if values is None else self.substituted(e, values)
            if v.has(*bad) or (values is not None and v.is_real is False):
                kind = ("a division by zero or an infinity" if v.has(*bad[:4])   # zoo: not real
                        else "a complex value")
                at = "" if values is None else f" at the parameter values of {where}"
                raise DesignError(self.spec.path, key, text, f"a finite real expression{at} "
                                  f"(found {kind})")
        if values is None:
            return
        Jx, Ju = self.jacobians          # e.g. F*tanh(a/F) is finite at F = 0, d/da is not
        names = self.spec.state_names + self.spec.input_names
        for i, (s, text) in enumerate(zip(self.spec.state_names, self.spec.equations)):
            for j, d in enumerate(list(Jx.row(i)) + list(Ju.row(i))):
                if self.substituted(d, values).has(*bad):
                    raise DesignError(self.spec.path, f"equations.{s}", text,
                                      f"an expression with finite derivatives at the parameter "
                                      f"values of {where} (d/d{names[j]} has a division by "
                                      f"zero or an infinity)")

    def substituted(self, expr, values: dict[str, float]):
        """``expr`` with every parameter replaced by its (double) value."""
        import sympy as sp
        return expr.subs({self.p[k]: sp.Float(v) for k, v in values.items()})

    def _numeric(self, expr, values):
        import sympy as sp
        return sp.lambdify(self.x + self.u, self.substituted(expr, values), "numpy")

    def definition_function(self, name: str, values: dict[str, float]):
        """Numeric ``name`` of [definitions] as a function of (x, u) arrays
        (states and inputs along the first axis), for the figures."""
        fn = self._numeric(self.definitions[name], values)
        return lambda X, U: np.broadcast_to(np.asarray(fn(*X, *U), float), X.shape[1:])

    @cached_property
    def jacobians(self):
        """(df/dx, df/du) as sympy matrices."""
        import sympy as sp
        return self.f.jacobian(sp.Matrix(self.x)), self.f.jacobian(sp.Matrix(self.u))

    def rhs(self, values: dict[str, float]):
        """Numeric f(x, u) -> (n,) array for the parameter values given."""
        fn = self._numeric(self.f, values)
        n = len(self.x)

        def f(x, u):
            return np.asarray(fn(*x, *u), float).reshape(n)
        return f

    def jacobian_functions(self, values: dict[str, float]):
        """Numeric (df/dx, df/du)(x, u) -> arrays."""
        Jx, Ju = self.jacobians
        fx, fu = self._numeric(Jx, values), self._numeric(Ju, values)
        n, m = len(self.x), len(self.u)
        return (lambda x, u: np.asarray(fx(*x, *u), float).reshape(n, n),
                lambda x, u: np.asarray(fu(*x, *u), float).reshape(n, m))


def linearise(model: PlantModel, values: dict[str, float], op: OperatingPoint):
    """A = df/dx and B = df/du at the operating point (double precision).

    Parameters
    ----------
    model : PlantModel
    values : dict[str, float]
        Parameter values (SI).
    op : OperatingPoint

    Returns
    -------
    (A, B) : tuple of numpy.ndarray
        (n, n) and (n, m); the linear model is dx' = A dx + B du(t - h).
    """
    fx, fu = model.jacobian_functions(values)
    with np.errstate(all="ignore"):
        A, B = fx(op.x, op.u), fu(op.x, op.u)
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(B))):
        raise DesignError(model.spec.path, "operating_point", op.as_dict(model.spec),
                          "a point where the Jacobians of the equations are finite")
    big = max(np.max(np.abs(A), initial=0.0), np.max(np.abs(B), initial=0.0))
    if not big <= MAX_ENTRY:
        raise DesignError(model.spec.path, "parameters", f"<a Jacobian entry of {big:.3g}>",
                          f"a model whose linearisation has entries of magnitude at most "
                          f"{MAX_ENTRY:g} (SI; check the parameters' values and units)")
    return A, B


def solve_operating_point(model: PlantModel, values: dict[str, float], *,
                          key: str = "operating_point") -> OperatingPoint:
    """Solve f(x, u, p) = 0 for the entries marked ``solve``.

    Newton's method (``scipy.optimize.root``, hybrid Powell with the symbolic
    Jacobian) from each entry's guess (default: the middle of its range),
    then from a deterministic grid of starts over the ranges; the first root
    inside every range with max |f| <= 1e-9 (1 + max |f(start)|) is kept.

    Raises
    ------
    DesignError
        No root inside the stated ranges (the message names the ranges).
    """
    from scipy.optimize import root
    spec = model.spec
    n, m = len(spec.states), len(spec.inputs)
    entries = spec.operating_point
    free = [i for i, e in enumerate(entries) if e.solved]
    base = np.array([0.0 if e.solved else e.value for e in entries])
    f = model.rhs(values)
    fx, fu = model.jacobian_functions(values)

    def split(z):
        full = base.copy()
        full[free] = z
        return full[:n], full[n:]

    def F(z):
        return f(*split(z))

    def J(z):
        x, u = split(z)
        return np.hstack([fx(x, u), fu(x, u)])[:, free]

    if not free:   # a given point: an equilibrium, unless the design says trim = false
        x, u = split(np.zeros(0))
        with np.errstate(all="ignore"):
            residual = float(np.max(np.abs(f(x, u))))
        if spec.trim and not residual <= TRIM_TOL:
            raise DesignError(spec.path, key, f"<max |f| = {residual:.3g}>",
                              f"an equilibrium: max |f| <= {TRIM_TOL:g} (state units per "
                              "second) at the given point, or trim = false in "
                              "[operating_point] to linearise off-equilibrium")
        return OperatingPoint(x, u, residual, ())
    lo = np.array([entries[i].lo for i in free])
    hi = np.array([entries[i].hi for i in free])
    first = np.array([entries[i].guess if entries[i].guess is not None
                      else 0.5 * (entries[i].lo + entries[i].hi) for i in free])
    grid = [lo + (hi - lo) * np.array(c) for c in
            itertools.product((0.5, 0.1, 0.9, 0.3, 0.7), repeat=len(free))][:200]
    with np.errstate(all="ignore"):
        for z0 in [first] + grid:
            f0 = F(z0)
            if not np.all(np.isfinite(f0)):
                continue
            sol = root(F, z0, jac=J, method="hybr", options={"xtol": 1e-15})
            z = sol.x
            fz = F(z)
            if not (np.all(np.isfinite(fz)) and np.all(z >= lo) and np.all(z <= hi)):
                continue
            if np.max(np.abs(fz)) <= 1e-9 * (1 + np.max(np.abs(f0))):
                x, u = split(z)
                names = [entries[i].name for i in free]
                return OperatingPoint(x, u, float(np.max(np.abs(fz))), tuple(names))
    ranges = ", ".join(f"{entries[i].name} in [{entries[i].lo:g}, {entries[i].hi:g}]"
                       for i in free)
    raise DesignError(spec.path, key, "<no solution>",
                      f"a root of the equations f = 0 with {ranges} (none found from the guess "
                      f"or a grid of {len(grid)} starts; widen a range or fix another value)")
