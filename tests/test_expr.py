"""Safe expressions (workbench/expr.py): what parses, and hostile text that must not.

Every hostile expression goes through the CLI (``workbench verify FILE``) in a
design file: exit 2, one line naming file, key and column, no traceback, and
nothing runs (no operating point is solved, no file the text asks for is
created).
"""
from __future__ import annotations

import sympy as sp
import pytest

from workbench.cli import main
from workbench.errors import DesignError
from workbench.expr import MAX_DEPTH, check_expression, parse_expression

X, Y, A = sp.symbols("x y a", real=True)
SYMS = {"x": X, "y": Y, "a": A}


def parse(text):
    return parse_expression(text, SYMS, path="d.toml", key="equations.x")


@pytest.mark.parametrize("text, expected", [
    ("a*(1 - exp(-x)) - y/3", A * (1 - sp.exp(-X)) - Y / 3),
    ("-x**2", -X**2),
    ("x**-1", 1 / X),
    ("2**10", sp.Integer(1024)),
    ("sqrt(x) + log(y) + tanh(a)", sp.sqrt(X) + sp.log(Y) + sp.tanh(A)),
    ("sin(x)*cos(y) + atan(a)", sp.sin(X) * sp.cos(Y) + sp.atan(A)),
    ("abs(x)*sign(y)", sp.Abs(X) * sp.sign(Y)),
    ("min(x, y) + max(x, y, a)", sp.Min(X, Y) + sp.Max(X, Y, A)),
    ("where(x >= 0, x, -x)", sp.Piecewise((X, X >= 0), (-X, True))),
    ("piecewise(x < 0, 1, x <= 1, 2, 3)", sp.Piecewise((1, X < 0), (2, X <= 1), (3, True))),
    ("1.5e-3*x", sp.Float(1.5e-3) * X),
])
def test_whitelisted_expressions_build_sympy(text, expected):
    assert sp.simplify(parse(text) - expected) == 0


def test_float_literals_are_the_doubles_written():
    assert float(parse("0.3315")) == 0.3315


def test_check_needs_no_sympy_objects():
    tree = check_expression("exp(-x)*a", {"x", "a"}, path="d.toml", key="k")
    assert tree.body is not None


HOSTILE = [
    ("x.__class__", "attribute access"),
    ("x.real", "attribute access"),
    ("__import__('os').system('touch PWNED')", "__import__"),
    ("__builtins__", "dunder name"),
    ("(lambda: 1)()", "lambda"),
    ("[i for i in range(3)]", "comprehension"),
    ("sum(i for i in (1, 2))", "undeclared function"),
    ("open('PWNED', 'w')", "undeclared function"),
    ("eval('1')", "undeclared function"),
    ("exec('open(1)')", "undeclared function"),
    ("exp.__globals__", "attribute access"),
    ("zz + x", "undeclared name"),
    ("9**9**9", "exponent"),
    ("x**100000", "exponent"),
    ("(10**60)**60", "power larger"),
    ("x**(2**7)", "exponent"),
    ("exp(" * (MAX_DEPTH + 2) + "x" + ")" * (MAX_DEPTH + 2), "nesting deeper"),
    ("(" * 300 + "x" + ")" * 300, "syntax error"),
    ("'x' + x", "string"),
    ("x[0]", "subscript"),
    ("f'{x}'", "f-string"),
    ("(x := 1)", "assignment"),
    ("max(*x)", "starred"),
    ("exp(x=1)", "keyword argument"),
    ("x if a else y", "conditional expression"),
    ("x and y", "boolean operator"),
    ("x ^ 2", "operator ^"),
    ("x % 2", "operator %"),
    ("x < y", "comparison outside"),
    ("where(x, 1, 2)", "not a comparison"),
    ("exp(x, y)", "2 argument"),
    ("1e999*x", "non-finite"),
    ("1j*x", "imaginary"),
    ("{x: 1}", "dict"),
    ("x +* 2", "syntax error"),
    ("x\ny", "one line"),
    ("x" + "+x" * 1200, "at most 2000 characters"),
    ("", "non-empty"),
]


@pytest.mark.parametrize("text, word", HOSTILE)
def test_hostile_expression_is_rejected(text, word):
    with pytest.raises(DesignError) as err:
        parse(text)
    msg = str(err.value)
    assert msg.startswith("d.toml: equations.x = ")
    assert word in msg


DESIGN = '''
[design]
name = "{name}"
kind = "delay-feedback"
title = "hostile expression test"
source = "tests/test_expr.py"

[states]
x = {{ unit = "1", source = "test" }}

[inputs]
u = {{ unit = "1/s", source = "test" }}

[parameters]
a = {{ value = 1.0, unit = "1/s", source = "test" }}

[equations]
x = {expr}

[operating_point]
x = {{ value = 0.0, unit = "1", source = "test" }}
u = {{ solve = [-1.0, 1.0] }}

[delay]
h = {{ value = 0.1, unit = "s", source = "test" }}

[synthesis]
method = "wirtinger"
'''


def _toml_string(text: str) -> str:
    """A TOML literal for any text (basic string with escapes)."""
    out = text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
    return f'"{out}"'


@pytest.mark.parametrize("text, word", HOSTILE)
def test_hostile_expression_through_the_cli(text, word, tmp_path, monkeypatch, capsys):
    from workbench.kinds.delay_feedback import run as delay_feedback_run
    ran = []
    monkeypatch.setattr(delay_feedback_run, "nominal_point", lambda *a, **k: ran.append(a))
    monkeypatch.setattr(delay_feedback_run, "run", lambda *a, **k: ran.append(a))
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "hostile.toml"
    path.write_text(DESIGN.format(name="hostile", expr=_toml_string(text)), encoding="utf-8")
    code = main(["verify", str(path)])
    out, err = capsys.readouterr()
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: hostile.toml: equations.x = ")
    assert "Traceback" not in err and out == ""
    assert word in lines[0]
    assert ran == []                                  # nothing was solved or run
    assert sorted(p.name for p in tmp_path.iterdir()) == ["hostile.toml"]   # nothing written


def test_a_harmless_design_of_the_same_shape_loads(tmp_path, monkeypatch):
    """The template above is valid: the hostile tests fail for the expression alone."""
    from workbench.design import load_design
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "fine.toml"
    path.write_text(DESIGN.format(name="fine", expr='"a*x + u"'), encoding="utf-8")
    d = load_design(path)
    assert d.spec.plant.equations == ("a*x + u",)


def test_undeclared_name_lists_the_declared(tmp_path):
    with pytest.raises(DesignError, match=r"declared: a, x, y"):
        parse("x + q")


def test_undeclared_name_among_many_names_is_one_short_line():
    """Issue 32: with 40 declared names the message names the count and the
    closest spellings, not all 40 (it was 400 characters in switched-run)."""
    names = [f"gain_{i}" for i in range(38)] + ["v_ref", "lam_d"]
    with pytest.raises(DesignError) as e:
        check_expression("v_rf + 1", names, path="d.toml", key="laws.cruise")
    msg = str(e.value)
    assert "40 names declared; did you mean v_ref?" in msg and "gain_3" not in msg, msg
    assert len(msg) < 320, msg        # the whitelist itself is ~270 characters


def test_definition_may_not_use_a_later_definition(tmp_path, monkeypatch):
    from workbench.design import load_design
    monkeypatch.chdir(tmp_path)
    text = DESIGN.format(name="order", expr='"d1"').replace(
        "[equations]", '[definitions]\nd1 = "d2*x"\nd2 = "a"\n\n[equations]')
    path = tmp_path / "order.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(DesignError, match=r"definitions\.d1 .*undeclared name 'd2'"):
        load_design(path)
