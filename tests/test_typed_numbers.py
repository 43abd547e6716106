"""No typed numbers (issue 19, item 4): claim texts and report prose name
results instead of retyping them.

The rule for a claim's ``description`` and ``reason`` in ``designs/*.toml``
-------------------------------------------------------------------------
Every *decimal number* in the text — digits with a decimal point or an
exponent: ``0.38``, ``86.25``, ``1e-3`` — must be one of

1. a template field ``{quantity}``, ``{quantity:N}`` or ``{quantity:N%}``,
   filled from the design's results when the claim is evaluated
   (:func:`workbench.claims.fill_claim`);
2. inside quotes (``'...'``, ``"..."`` or backticks): a value quoted from the
   paper, e.g. ``('137.22 - 96.466 = 40.754')``;
3. equal to the claim's own ``value`` or ``tolerance``, or to a number in the
   name of its ``quantity`` (``eps = 0.35`` of ``synthesis.rows[eps=0.35]``);
4. equal to a number the design gives as input outside ``[[claims]]`` (a
   parameter, a scenario value, a printed row), or in a data file of a
   ``designs/`` subfolder the design names (``examples = "benchmarks"``):
   an input, not a result, and the test checks that the design holds it.

Integers are not checked: equation, table and section numbers, counts and
years would drown the rule; an integer result is still written as a template
field where the design computes it (``{line.pid.within_tolerance} of
{line.sections} sections``).

The rule for report prose
-------------------------
Report prose comes from the renderers. Every decimal number in a string
literal of a module that writes report text (docstrings aside) is either
formatted from the constant or result it states, or listed in
:data:`RENDERER_CONSTANTS` with why it may be typed (a section number, a
value the paper printed, a display floor, a colour).
"""
from __future__ import annotations

import ast
import math
import re
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DESIGNS = sorted((ROOT / "designs").glob("*.toml"))

#: A decimal number: digits with a decimal point, or with an exponent.
DECIMAL = re.compile(r"(?<![\d.A-Za-wyz_])[-+]?(?:\d+\.\d+(?:e[-+]?\d+)?|\d+e[-+]?\d+)(?![\d\w])")
#: Text a decimal may stand in: template fields, quotes (an apostrophe inside
#: a word, as in "paper's", opens none), code spans.
EXEMPT = re.compile(r"\{[^{}]*\}|(?<![A-Za-z])'[^']*'(?![A-Za-z])|\"[^\"]*\"|`[^`]*`")


def _numbers(obj, out: set[float]) -> set[float]:
    """Every number in a parsed TOML value except under ``claims``."""
    if isinstance(obj, dict):
        for k, v in obj.items():
            if k != "claims":
                _numbers(v, out)
    elif isinstance(obj, list):
        for v in obj:
            _numbers(v, out)
    elif isinstance(obj, (int, float)) and not isinstance(obj, bool):
        out.add(float(obj))
    return out


def _strings(obj):
    if isinstance(obj, dict):
        for k, v in obj.items():
            if k != "claims":
                yield from _strings(v)
    elif isinstance(obj, list):
        for v in obj:
            yield from _strings(v)
    elif isinstance(obj, str):
        yield obj


def design_inputs(data: dict, folder: Path) -> set[float]:
    """Numbers a design gives as input (rule 4)."""
    out = _numbers(data, set())
    for s in _strings(data):
        if not s or "/" in s or len(s) > 100:     # a sentence, not a folder's name
            continue
        sub = folder / s
        if sub.is_dir():
            for f in sorted(sub.glob("*.toml")):
                _numbers(tomllib.loads(f.read_text(encoding="utf-8")), out)
    return out


def _same(x: float, pool) -> bool:
    return any(math.isclose(abs(x), abs(y), rel_tol=1e-9, abs_tol=0.0) for y in pool)


def typed_numbers(data: dict, folder: Path) -> list[tuple[str, str, str]]:
    """(claim id, key, number) of every decimal the rule of the module
    docstring does not allow in the claims of a parsed design."""
    inputs = design_inputs(data, folder)
    bad = []
    for c in data.get("claims", []):
        own = {float(v) for v in (c.get("value"), c.get("tolerance"))
               if isinstance(v, (int, float)) and not isinstance(v, bool)}
        own |= {float(m) for m in DECIMAL.findall(c.get("quantity", ""))}
        own |= {float(m) for m in re.findall(r"\d+(?:\.\d+)?", c.get("quantity", ""))}
        for key in ("description", "reason"):
            text = EXEMPT.sub(" ", c.get(key, ""))
            bad += [(c.get("id", "?"), key, m) for m in DECIMAL.findall(text)
                    if not _same(float(m), own | inputs)]
    return bad


@pytest.mark.parametrize("path", DESIGNS, ids=lambda p: p.stem)
def test_no_typed_numbers_in_claim_texts(path):
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    assert typed_numbers(data, path.parent) == []


SYNTHETIC = '''
[scenario]
h = { value = 0.0433, unit = "s", source = "003" }
[[claims]]
id = "stop-duration"
description = "braking until v <= v_stop, within 0.5 s of 85 s at h = 0.0433 s"
quantity = "cases[eps=0.35].braking_duration"
compare = "within"
value = 85.0
tolerance = 0.5
source = "003 section 4.2"
reason = "REASON"
'''


@pytest.mark.parametrize("reason, typed", [
    ("we find 86.25 s to the stop", ["86.25"]),                       # a measured number
    ("42.1 m and 1e-3 off", ["42.1", "1e-3"]),
    ("the force x0.8 corner is 0.62 m", ["0.8", "0.62"]),             # 'x0.8' is a number too
    ("we find {cases[paper].braking_duration:4} s", []),              # a template field
    ("the paper's '137.22 - 96.466 = 40.754'", []),                   # quoted from the paper
    ("the paper's 85 s, printed 85.0 ± 0.5", []),                     # the claim's own numbers
    ("at eps = 0.35 with h = 0.0433 s", []),                          # quantity name, an input
])
def test_the_rule_fails_on_a_typed_number(reason, typed):
    data = tomllib.loads(SYNTHETIC.replace("REASON", reason))
    assert [n for _, _, n in typed_numbers(data, Path("."))] == typed


# -- report prose: string literals of the renderers ----------------------------------
#: Modules whose strings become report text.
RENDERERS = sorted([*(ROOT / "workbench").glob("[fkp]*/**/*_render.py"),
                    ROOT / "workbench/kinds/delay_feedback/render.py",
                    ROOT / "workbench/papers/p003/antiskid_run_figures.py",
                    ROOT / "workbench/papers/p000/brake_fit.py",
                    *(ROOT / "workbench/report").glob("*.py"),
                    ROOT / "workbench/roa/render.py", ROOT / "workbench/prove.py"])

def _key(path: Path) -> str:
    """A module's path under workbench/ (the key of :data:`RENDERER_CONSTANTS`)."""
    return path.relative_to(ROOT / "workbench").as_posix()


#: (module, number) typed in a renderer's prose on purpose, and why.
RENDERER_CONSTANTS = {
    ("papers/p003/antiskid_cruise_render.py", "1e-12"): "display floor of a printed residual",
    ("kinds/delay_feedback/render.py", "1e-12"): "display floor of a printed residual",
    ("kinds/delay_benchmark_render.py", "1e-12"): "display floor of a printed relative difference",
    ("papers/p004/closed_loop_brake_render.py", "1.3"): "section number of paper 004",
    ("papers/p004/closed_loop_brake_render.py", "0.703"):
        "the deceleration paper 004 printed (its rounding is the finding)",
    ("papers/p000/station_stopping_render.py", "3.2"): "section number of paper 000",
    ("papers/p000/station_stopping_render.py", "85.16"): "K1/K2 as paper 000's Table 1 prints it",
    ("kinds/platoon/realism_render.py", "1e-9"):
        "display floor of a printed relative difference",
    ("papers/p004/closed_loop_brake_fair_render.py", "0.5"):
        "the horizon before the retuning (a t_predict_sweep value)",
    ("papers/p004/closed_loop_brake_fair_render.py", "0.7"):
        "paper 000's damping criterion of its PID",
}


def _docstrings(tree) -> set[int]:
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.FunctionDef, ast.ClassDef, ast.AsyncFunctionDef)):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                out.add(id(body[0].value))
    return out


def renderer_numbers(path: Path) -> list[tuple[str, int]]:
    """(number, line) of every decimal in the string literals of a module,
    docstrings aside."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    skip = _docstrings(tree)
    return [(m, node.lineno) for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str)
            and id(node) not in skip for m in DECIMAL.findall(node.value)]


@pytest.mark.parametrize("path", RENDERERS, ids=lambda p: _key(p))
def test_no_typed_numbers_in_report_prose(path):
    typed = [(n, line) for n, line in renderer_numbers(path)
             if (_key(path), n) not in RENDERER_CONSTANTS]
    assert typed == [], f"{_key(path)}: format these from the result or constant they state"


def test_the_prose_rule_fails_on_a_typed_number(tmp_path):
    f = tmp_path / "x_render.py"
    f.write_text('"""Doc 0.5 is fine."""\ntext = "the dip decays with time constant 84.2 s"\n'
                 'ok = f"rate {fmt(x)} s"\n')
    assert renderer_numbers(f) == [("84.2", 2)]


def test_template_fields_fill_and_escape():
    from workbench.claims import fill_text
    from workbench.report.markdown import fmt
    q = {"cases[paper].t_diverged": 31.4372, "sensitivity.oat.rho": 0.0779, "none": None}
    text = ("at t = {cases[paper].t_diverged:4} s, rho {sensitivity.oat.rho:2%} %, "
            "{none}, the ellipsoid {{V <= c}}")
    assert fill_text(text, q, fmt) == "at t = 31.44 s, rho 7.8 %, —, the ellipsoid {V <= c}"
