"""Safe expressions: design-file text -> sympy, without evaluating any code.

A design of kind ``delay-feedback`` writes its plant as text, e.g.
``"a*(1 - exp(-b*lam)) - lam/c"``. sympy's ``sympify`` and ``parse_expr``
run Python ``eval`` on such text, so they are never used here. Instead the
text is parsed by Python's :mod:`ast` (which only *reads* it), every node is
checked against a whitelist, and the sympy object is built from the checked
tree by this module's own code:

* numbers (int or float literals); names declared by the design (states,
  inputs, parameters, definitions);
* ``+ - * / **`` and unary ``-`` / ``+``;
* the functions of :data:`FUNCTIONS` (``exp log sqrt sin cos tanh atan abs
  sign min max``) and ``where(cond, a, b)`` / ``piecewise(c1, v1, c2, v2,
  ..., otherwise)``, whose conditions are single comparisons
  (``< <= > >=``) of two expressions.

Anything else (attribute access, subscripts, calls of other names, lambdas,
comprehensions, strings, keyword or starred arguments, ``:=``, ...) is a
:class:`~workbench.errors.DesignError` naming the file, the key, the column
and the token found. Limits against hostile input: :data:`MAX_LENGTH`
characters, :data:`MAX_DEPTH` levels of nesting, numeric exponents up to
:data:`MAX_EXPONENT` in magnitude, and numeric powers up to
:data:`MAX_POWER_BITS` bits.

:func:`check_expression` validates without importing sympy (a design is
rejected before anything heavy loads); :func:`parse_expression` validates
and builds.
"""
from __future__ import annotations

import ast
import math
from typing import Any, Iterable, Mapping

from .errors import DesignError

#: Longest expression text accepted (characters).
MAX_LENGTH = 2000
#: Deepest syntax tree accepted (levels of nested operations and calls).
MAX_DEPTH = 100
#: Largest magnitude of a numeric exponent (x**k).
MAX_EXPONENT = 64
#: Largest size (bits) of an exact numeric power such as 2**64.
MAX_POWER_BITS = 4096

#: Function name -> number of arguments (None: two or more).
FUNCTIONS: dict[str, int | None] = {
    "exp": 1, "log": 1, "sqrt": 1, "sin": 1, "cos": 1, "tanh": 1, "atan": 1,
    "abs": 1, "sign": 1, "min": None, "max": None, "where": 3, "piecewise": None,
}
_CONDITIONAL = ("where", "piecewise")
_BINOPS = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.Pow: "**"}
_CMPOPS = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">="}
_WHAT = {
    ast.Attribute: "an attribute access", ast.Subscript: "a subscript",
    ast.Lambda: "a lambda", ast.ListComp: "a comprehension", ast.SetComp: "a comprehension",
    ast.DictComp: "a comprehension", ast.GeneratorExp: "a comprehension",
    ast.JoinedStr: "an f-string", ast.FormattedValue: "an f-string",
    ast.NamedExpr: "an assignment (:=)", ast.Starred: "a starred argument",
    ast.IfExp: "a conditional expression (use where(cond, a, b))",
    ast.BoolOp: "a boolean operator", ast.List: "a list", ast.Tuple: "a tuple",
    ast.Dict: "a dict", ast.Set: "a set", ast.Await: "an await", ast.Yield: "a yield",
    ast.YieldFrom: "a yield", ast.Slice: "a slice",
}
ALLOWED = ("numbers, declared names, + - * / ** and unary minus, and the functions "
           + ", ".join(FUNCTIONS))


def _fail(path: str, key: str, text: str, node: ast.AST | None, what: str,
          token: str | None = None, note: str = "") -> DesignError:
    col = getattr(node, "col_offset", None)
    if token is None and node is not None:
        token = ast.get_source_segment(text, node) or type(node).__name__
    if token is not None and len(token) > 40:
        token = token[:37] + "..."
    shown = text if len(text) <= 80 else text[:77] + "..."
    found = f"{what}" + ("" if token is None else f" {token!r}")
    at = "" if col is None else f" at col {col + 1}"
    return DesignError(path, key, shown,
                       f"a safe expression ({ALLOWED}); found {found}{at}{note}")


def _parse(text: Any, path: str, key: str) -> ast.Expression:
    if not isinstance(text, str) or not text.strip():
        raise DesignError(path, key, text, "an expression (a non-empty string)")
    if len(text) > MAX_LENGTH:
        raise DesignError(path, key, f"<{len(text)} characters>",
                          f"an expression of at most {MAX_LENGTH} characters")
    if "\n" in text or "\r" in text:
        raise DesignError(path, key, text, "an expression on one line")
    try:
        return ast.parse(text, mode="eval")
    except SyntaxError as exc:
        col = exc.offset if exc.offset and exc.offset <= len(text) else None
        at = f"at col {col}" if col else "at the end of the expression"
        raise DesignError(path, key, text if len(text) <= 80 else text[:77] + "...",
                          f"an expression; found a syntax error {at} ({exc.msg})") from None
    except (RecursionError, MemoryError, ValueError):
        raise DesignError(path, key, text[:77] + "...", f"an expression nested at most "
                          f"{MAX_DEPTH} levels deep") from None


def _declared_note(name: str, names) -> str:
    """The declared names after an undeclared one: all of them when there are
    at most :data:`NAMES_SHOWN`, else their count and the closest spellings
    (issue 32: one line, not a list of every name)."""
    import difflib
    names = sorted(names)
    if len(names) <= NAMES_SHOWN:
        return " (declared: " + ", ".join(names) + ")"
    close = difflib.get_close_matches(name, names, n=3, cutoff=0.5)
    return (f" ({len(names)} names declared" + (f"; did you mean {', '.join(close)}?" if close
                                                else "") + ")")


#: Declared names listed in full after an undeclared one (more: the closest).
NAMES_SHOWN = 8


class _Checker:
    """Walks a parsed expression and rejects every node outside the whitelist."""

    def __init__(self, text: str, path: str, key: str, names: frozenset[str]):
        self.text, self.path, self.key, self.names = text, path, key, names

    def fail(self, node, what, token=None, note=""):
        return _fail(self.path, self.key, self.text, node, what, token, note)

    def check(self, node: ast.AST, depth: int = 0, condition: bool = False) -> None:
        if depth > MAX_DEPTH:
            raise self.fail(node, f"nesting deeper than {MAX_DEPTH} levels")
        d = depth + 1
        if isinstance(node, ast.Constant):
            v = node.value
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                kind = {str: "a string", bytes: "a bytes literal", complex:
                        "an imaginary number", bool: "a boolean"}.get(type(v), "a constant")
                raise self.fail(node, kind)
            if isinstance(v, float) and not math.isfinite(v):
                raise self.fail(node, "a non-finite number")
        elif isinstance(node, ast.Name):
            if node.id.startswith("__"):
                raise self.fail(node, "a dunder name")
            if node.id in FUNCTIONS:
                raise self.fail(node, "a function name used as a value")
            if node.id not in self.names:
                raise self.fail(node, "an undeclared name", note=_declared_note(node.id, self.names))
        elif isinstance(node, ast.BinOp):
            if type(node.op) not in _BINOPS:
                op = {ast.BitXor: "^ (write ** for a power)", ast.Mod: "%",
                      ast.FloorDiv: "//", ast.MatMult: "@"}.get(type(node.op), "this operator")
                raise self.fail(node, f"the operator {op}")
            self.check(node.left, d)
            self.check(node.right, d)
            if isinstance(node.op, ast.Pow):
                self.check_power(node)
        elif isinstance(node, ast.UnaryOp):
            if not isinstance(node.op, (ast.USub, ast.UAdd)):
                raise self.fail(node, "this unary operator")
            self.check(node.operand, d)
        elif isinstance(node, ast.Call):
            self.check_call(node, d)
        elif isinstance(node, ast.Compare):
            if not condition:
                raise self.fail(node, "a comparison outside the condition of where/piecewise")
            if len(node.ops) != 1 or type(node.ops[0]) not in _CMPOPS:
                raise self.fail(node, "a comparison other than one of < <= > >=")
            self.check(node.left, d)
            self.check(node.comparators[0], d)
        else:
            raise self.fail(node, _WHAT.get(type(node), f"a {type(node).__name__} node"))

    def check_power(self, node: ast.BinOp) -> None:
        """Numeric exponents at most MAX_EXPONENT; numeric powers at most
        MAX_POWER_BITS bits (checked on the tree, before anything is built)."""
        e = _constant(node.right)
        if e is None:
            return
        if not abs(e) <= MAX_EXPONENT:
            raise self.fail(node.right, f"an exponent beyond +/-{MAX_EXPONENT}")
        b = _constant(node.left)
        if b is not None and b != 0 and math.isfinite(b):
            if abs(math.log2(abs(b))) * abs(e) > MAX_POWER_BITS:
                raise self.fail(node, f"a power larger than {MAX_POWER_BITS} bits")

    def check_call(self, node: ast.Call, d: int) -> None:
        f = node.func
        if not isinstance(f, ast.Name):
            raise self.fail(f, _WHAT.get(type(f), "a call of something other than a function "
                                         "name") + " called as a function")
        if f.id not in FUNCTIONS:
            raise self.fail(f, "a call of an undeclared function")
        if node.keywords:
            kw = node.keywords[0]
            raise self.fail(kw, "a keyword argument", kw.arg and f"{kw.arg}=")
        for a in node.args:
            if isinstance(a, ast.Starred):
                raise self.fail(a, "a starred argument")
        n, want = len(node.args), FUNCTIONS[f.id]
        if f.id == "piecewise":
            ok, need = n >= 3 and n % 2 == 1, "an odd number >= 3 (c1, v1, ..., otherwise)"
        elif want is None:
            ok, need = n >= 2, "two or more"
        else:
            ok, need = n == want, str(want)
        if not ok:
            raise self.fail(node, f"{f.id}() with {n} argument(s), not {need},")
        for i, a in enumerate(node.args):
            cond = f.id in _CONDITIONAL and i % 2 == 0 and i < n - 1
            if cond and not isinstance(a, ast.Compare):
                raise self.fail(a, f"a condition of {f.id}() that is not a comparison")
            self.check(a, d, condition=cond)


def check_expression(text: Any, names: Iterable[str], *, path: str, key: str) -> ast.Expression:
    """Validate an expression without building it (no sympy import).

    Parameters
    ----------
    text : str
        The expression as written in the design file.
    names : iterable of str
        Declared names it may use.
    path, key : str
        Design file and dotted key, for messages.

    Returns
    -------
    ast.Expression
        The checked tree.

    Raises
    ------
    DesignError
        Naming the file, the key, the column and the token found.
    """
    tree = _parse(text, path, key)
    _Checker(text, path, key, frozenset(names)).check(tree.body)
    return tree


def _constant(node: ast.AST) -> float | None:
    """Value of a numbers-only subtree (already checked) in floating point
    (``inf`` past the float range), or None when it holds a name or a call."""
    if isinstance(node, ast.Constant):
        return float(node.value)
    if isinstance(node, ast.UnaryOp):
        v = _constant(node.operand)
        return None if v is None else (-v if isinstance(node.op, ast.USub) else v)
    if isinstance(node, ast.BinOp):
        a, b = _constant(node.left), _constant(node.right)
        if a is None or b is None:
            return None
        try:
            op = type(node.op)
            if op is ast.Add:
                return a + b
            if op is ast.Sub:
                return a - b
            if op is ast.Mult:
                return a * b
            if op is ast.Div:
                return a / b if b != 0 else math.inf
            return math.inf if abs(b) > MAX_EXPONENT else float(abs(a) ** b)
        except (OverflowError, ZeroDivisionError):
            return math.inf
    return None


class _Builder:
    def __init__(self, text, path, key, symbols):
        import sympy as sp
        self.sp, self.text, self.path, self.key, self.symbols = sp, text, path, key, symbols

    def build(self, node):
        sp = self.sp
        if isinstance(node, ast.Constant):
            return sp.Integer(node.value) if isinstance(node.value, int) else sp.Float(node.value)
        if isinstance(node, ast.Name):
            return self.symbols[node.id]
        if isinstance(node, ast.UnaryOp):
            x = self.build(node.operand)
            return -x if isinstance(node.op, ast.USub) else x
        if isinstance(node, ast.BinOp):
            a, b = self.build(node.left), self.build(node.right)
            op = type(node.op)
            if op is ast.Add:
                return a + b
            if op is ast.Sub:
                return a - b
            if op is ast.Mult:
                return a * b
            if op is ast.Div:
                return a / b
            return a ** b   # exponent size checked by _Checker.check_power
        if isinstance(node, ast.Compare):
            a, b = self.build(node.left), self.build(node.comparators[0])
            return {ast.Lt: sp.Lt, ast.LtE: sp.Le, ast.Gt: sp.Gt,
                    ast.GtE: sp.Ge}[type(node.ops[0])](a, b)
        return self.call(node)

    def call(self, node: ast.Call):
        sp = self.sp
        name = node.func.id
        args = [self.build(a) for a in node.args]
        if name == "where":
            return sp.Piecewise((args[1], args[0]), (args[2], True))
        if name == "piecewise":
            pairs = [(args[i + 1], args[i]) for i in range(0, len(args) - 1, 2)]
            return sp.Piecewise(*pairs, (args[-1], True))
        fn = {"exp": sp.exp, "log": sp.log, "sqrt": sp.sqrt, "sin": sp.sin, "cos": sp.cos,
              "tanh": sp.tanh, "atan": sp.atan, "abs": sp.Abs, "sign": sp.sign,
              "min": sp.Min, "max": sp.Max}[name]
        return fn(*args)


def parse_expression(text: Any, symbols: Mapping[str, Any], *, path: str, key: str):
    """Parse a design expression into a sympy expression, safely.

    Parameters
    ----------
    text : str
        The expression as written in the design file.
    symbols : mapping of str to sympy.Expr
        Declared names and what they stand for (a ``sympy.Symbol`` or a
        previously built expression, e.g. a definition).
    path, key : str
        Design file and dotted key, for messages.

    Returns
    -------
    sympy.Expr

    Raises
    ------
    DesignError
        Anything outside the whitelist (see the module docstring), or past
        the limits, naming the file, the key, the column and the token.
    """
    tree = check_expression(text, symbols, path=path, key=key)
    return _Builder(text, path, key, dict(symbols)).build(tree.body)
