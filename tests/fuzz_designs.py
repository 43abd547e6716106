"""Seeded mutations of shipped designs, run through the CLI in a forked child
with a time limit (used by tests/test_fuzz.py; issue 32, item 1).

Each run calls :func:`workbench.cli.main` in a child forked from the test
process (the imports are already loaded) and is classified: ``exit2`` (bad
input, one line), ``exit1`` (a claim failed or INCONCLUSIVE), ``ok``,
``traceback`` (an exception or panic escaped ``main``, or a message of more
than one line or with "Traceback"), ``timeout`` (killed after the limit).
"""
from __future__ import annotations

import math
import multiprocessing as mp
import os
import random
import re
import sys
import traceback
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DESIGNS = ("antiskid-cruise-dry", "train-brake-lag-delay-feedback",
           "wheel-slip-burckhardt-delay-feedback", "two-train-spacing-delay-feedback")
COMMANDS = ("synthesize", "verify", "report")
#: The designs of the kinds and tables added after the first campaign (issue 32 re-run):
#: a switched-run design (phases, guards, laws, [montecarlo], [sampled], [convergence])
#: and the rail wheel-slip design; two-train-spacing (above) has [montecarlo].
NEW_DESIGNS = ("emu-speed-switched-run", "wheel-slip-rail-delay-feedback")
CAMPAIGN_DESIGNS = DESIGNS + NEW_DESIGNS
#: Commands of a design whose kind has no delay-bound synthesis.
COMMANDS_OF = {"emu-speed-switched-run": ("verify", "report", "verify")}

NUMBERS = ["0", "-0.0", "-1", "1e-300", "5e-324", "1e308", "-1e308", "nan", "inf", "-inf",
           "1" * 1900, "\"12\"", "true", "[1, 2]", "{}", "1e-9", "1e9", "-0.65", "2"]
UNITS = ["km/h", "furlong", "parsec", "blorp", "", "m/s/s/s", "kg^99999", "1/0",
         "degC", "s; rm -rf /", "N*" * 60 + "N"]
EXPRESSIONS = ["omega/0", "log(-1)*x", "__import__('os').system('true')", "x**99999",
               "1/(x - x)", "exp(1e308)", "(", "a.b", "lambda: 1", "x" * 3000,
               "sqrt(-1)", "1e308*1e308", "0/0"]
STRUCTURAL = ["delete_line", "duplicate_header", "deep_nesting", "huge_int", "truncate",
              "bad_utf8", "dotdot_name", "deep_dotted", "empty", "big_matrix"]
LOAD_TIME = ["delete_line", "duplicate_header", "deep_nesting", "huge_int", "truncate",
             "bad_utf8", "dotdot_name", "deep_dotted", "empty"]

#: Mutations of the newer tables: (pattern with one group, replacements).
TABLES = [
    (r'\bto = "(\w+)"', ["nowhere", "accelerate", "cruise", "", "brake"]),
    (r'\bwhen = "([^"]*)"', ["0", "1", "-1", "v", "nan", "omega/0", "1e308*1e308", "(",
                            "v - v_set + 1e-300", "__import__('os')", "u"]),
    (r'\blaw = \{ u = "([^"]*)"', ["0", "1e308", "-1e308", "F_max*1e12", "u", "s/0",
                                  "log(-1)*v", "sqrt(-1)", "v**99999", "F_max + s_stop"]),
    (r'\bterminal = (true)', ["false", "1", '"yes"', "[]"]),
    (r'\buntil = "([^"]*)"', ["1", "-1", "0", "v_stop - v + 0/0", "m"]),
    (r'^(phase) = "', ["phases", "Phase", "phase.x"]),
    (r'^phase = "(\w+)"', ["nowhere", "brake", "cruise", ""]),
    (r'^name = "(accelerate|cruise|brake)"', ["cruise", "brake", "", "a b", "x" * 300]),
    (r'^predictor = (true)', ["false", "1", '"true"']),
    (r'^samples = (\d+)', ["0", "1", "-1", "2", "10000000", "1e9", "2.5", '"299"', "1" * 60]),
    (r'^seed = (\d+)', ["-1", "1" + "0" * 30, "2.5", "nan", '"35"', "0"]),
    (r'\bdist = "(\w+)"', ["cauchy", "", "normal", "uniform", "lognormal", "Normal"]),
    (r'\bsd = ([\d.e]+)', ["0", "-1", "nan", "inf", "1e308", "5e-324"]),
    (r'\bmean = ([\d.e]+)', ["0", "-1", "nan", "1e308", "-1e308"]),
    (r'\blo = ([\d.e]+)', ["1e308", "-1e308", "-1", "0", "nan", "1e9"]),
    (r'\bhi = ([\d.e]+)', ["0", "-1", "1e308", "nan", "5e-324"]),
    (r'^(\w+)\s*= \{ dist', ["v", "nope", "g", "u", "s", "m_eff", "h"]),
    (r'^\[(convergence)\]', ["convergence]\nlevels = 9\n[x", "convergence.deep",
                             "convergence]\n["]),
    (r'^(\[convergence\])', ["", "[convergence]\ntolerance = -1"]),
    (r'^period = ([\d.e]+)', ["0", "-1", "1e-300", "1e9", "0.07", "0.05", "nan", "1000"]),
    (r'\bquantisation = \{ (s) =', ["nope", "u", "F", "v"]),
    (r'\bquantisation = \{ s = ([\d.e]+)', ["0", "-1", "1e308", "nan", "5e-324", "1e12"]),
    (r'^max_switch_rate = ([\d.e]+)', ["0", "1e-300"]),
    (r'^(t_end) = ', ["max_switch_rate = 1e-9\nt_end", "max_switch_rate = 0\nt_end"]),
    (r'^(x0) = \{', ["x0 = { s = 1e12, v = 1e12, F = 1e12 }\nzz", "parameters = { m = 0 }\nzz",
                    "parameters = { m = -1 }\nzz", "parameters = { tau = 1e-300 }\nzz",
                    "parameters = { v = 1 }\nzz", "target = { u = 1 }\nzz"]),
    (r'^(\[montecarlo\])', ["[montecarlo]\nworkers = 9", "[montecarlo.x]", "[[montecarlo]]"]),
]
_TABLES = [(re.compile(p, re.M), new) for p, new in TABLES]

_NUM = re.compile(r"(?<=[=\[,{ ])(-?\d+(\.\d+)?([eE][-+]?\d+)?)(?=[\s,\]}])")
_UNIT = re.compile(r'unit *= *"([^"]*)"')
_EXPR = re.compile(r'^(\w+) *= *"([^"\n]*)"', re.M)


@dataclass(frozen=True)
class Mutation:
    design: str
    kind: str
    detail: str
    text: bytes


def _is_value(text: str, pos: int) -> bool:
    """True when ``pos`` is outside strings and comments (a TOML value)."""
    line = text[text.rfind("\n", 0, pos) + 1:pos]
    return line.count('"') % 2 == 0 and "#" not in line.replace('"#', "")


def mutate(rng: random.Random, design: str, kinds=None) -> Mutation:
    """One seeded mutation of ``design``'s file."""
    text = (ROOT / "designs" / f"{design}.toml").read_text(encoding="utf-8")
    tables = [(p, new) for p, new in _TABLES if p.search(text)]
    default = ["number"] * 5 + ["unit"] * 2 + ["expression"] * 2 + ["structural"]
    # the re-run's campaign (benchmarks/fuzz_campaign.py): the newer tables' mutations too
    if kinds == "tables" and tables and (design in NEW_DESIGNS or "[montecarlo]" in text):
        default += ["table"] * (4 if design == "emu-speed-switched-run" else 2)
    kind = rng.choice(kinds if kinds and kinds != "tables" else default)
    if kind == "table" and not tables:
        kind = "number"
    if kind == "structural":
        kind = rng.choice(STRUCTURAL)
    if kind == "table":
        p, choices = rng.choice(tables)
        m = rng.choice(list(p.finditer(text)))
        new = rng.choice(choices)
        return Mutation(design, kind, f"{m.group(1)[:20]} -> {new[:30]} at {m.start(1)}",
                        (text[:m.start(1)] + new + text[m.end(1):]).encode())
    if kind == "number":
        m = rng.choice([m for m in _NUM.finditer(text) if _is_value(text, m.start())])
        new = rng.choice(NUMBERS)
        return Mutation(design, kind, f"{m.group(1)} -> {new[:20]} at {m.start()}",
                        (text[:m.start()] + new + text[m.end():]).encode())
    if kind == "unit":
        m = rng.choice(list(_UNIT.finditer(text)))
        new = rng.choice(UNITS)
        return Mutation(design, kind, f"{m.group(1)} -> {new[:20]}",
                        (text[:m.start(1)] + new + text[m.end(1):]).encode())
    if kind == "expression":
        ms = [m for m in _EXPR.finditer(text) if m.group(1) not in (
            "name", "kind", "title", "source", "method", "model", "rail", "id", "quantity",
            "description", "unit", "plane", "value", "verdict", "severity", "note")]
        if not ms:
            return mutate(rng, design, ["number"])
        m = rng.choice(ms)
        sym = rng.choice(re.findall(r"[A-Za-z_]\w*", m.group(2)) or ["x"])
        new = rng.choice(EXPRESSIONS).replace("x", sym) if rng.random() < 0.5 else \
            f"{m.group(2)} + {rng.choice(EXPRESSIONS).replace('x', sym)}"
        return Mutation(design, kind, f"{m.group(1)} = {new[:40]}",
                        (text[:m.start(2)] + new + text[m.end(2):]).encode())
    lines = text.splitlines(keepends=True)
    if kind == "delete_line":
        i = rng.randrange(len(lines))
        return Mutation(design, kind, lines[i].strip()[:40], "".join(lines[:i] + lines[i + 1:])
                        .encode())
    if kind == "duplicate_header":
        heads = [ln for ln in lines if ln.startswith("[") and not ln.startswith("[[")]
        return Mutation(design, kind, heads[0].strip(), (text + "\n" + heads[0] + "x = 1\n")
                        .encode())
    if kind == "deep_nesting":
        n = rng.choice([40, 1000, 10000])
        return Mutation(design, kind, f"{n} levels", (text + "\nz = " + "[" * n + "]" * n + "\n")
                        .encode())
    if kind == "deep_dotted":
        n = rng.choice([40, 5000])
        return Mutation(design, kind, f"{n} dots", (text + "\n[zz]\n" + ".".join(["a"] * n) +
                                                    " = 1\n").encode())
    if kind == "huge_int":
        return Mutation(design, kind, "1900 digits", (text + "\nhuge = " + "9" * 1900 + "\n")
                        .encode())
    if kind == "truncate":
        i = rng.randrange(len(text))
        return Mutation(design, kind, f"at {i}", text[:i].encode())
    if kind == "bad_utf8":
        i = rng.randrange(len(text))
        raw = text.encode()
        return Mutation(design, kind, f"at {i}", raw[:i] + b"\xff\xfe" + raw[i:])
    if kind == "dotdot_name":
        return Mutation(design, kind, 'name = ".."',
                        re.sub(r'name = "[^"]*"', 'name = ".."', text, count=1).encode())
    if kind == "big_matrix":
        n = 500
        row = "[" + ", ".join(["1.0"] * n) + "]"
        return Mutation(design, kind, f"{n}x{n} x0", (text + "\n[big]\nA = [" +
                                                      ", ".join([row] * n) + "]\n").encode())
    return Mutation(design, kind, "", b"")


def api_cases():
    """(name, call) misuses of the Python API of the newer kinds and features:
    requirement synthesis (:func:`workbench.design_gain`), the digital
    implementation (:func:`workbench.implementation`,
    :func:`workbench.synthesize_sampled`), the Monte Carlo statistics and the
    switched-run success-run count, and loading a design by path."""
    import numpy as np

    import workbench
    from workbench.design import load_design
    from workbench.features import montecarlo as mc
    from workbench.kinds.switched_run.study import runs_for
    A, B = np.array([[0.0, 1.0], [-2.0, -3.0]]), np.array([[0.0], [1.0]])
    K = np.array([[-1.0, -1.0]])
    yield "design_gain delay reversed", lambda: workbench.design_gain(A, B, delay=(0.5, 0.1))
    yield "design_gain delay nan", lambda: workbench.design_gain(A, B, delay=(0.0, math.nan))
    yield "design_gain delay 1e308", lambda: workbench.design_gain(A, B, delay=(0.0, 1e308))
    yield "design_gain delay scalar", lambda: workbench.design_gain(A, B, delay=0.1)
    yield "design_gain decay -1", lambda: workbench.design_gain(A, B, delay=(0, .1),
                                                                decay_rate=-1.0)
    yield "design_gain objective", lambda: workbench.design_gain(A, B, delay=(0, .1),
                                                                 objective="magic")
    yield "design_gain input_limit 0", lambda: workbench.design_gain(
        A, B, delay=(0, .1), input_limit=0.0, box=[1.0, 1.0])
    yield "design_gain box short", lambda: workbench.design_gain(
        A, B, delay=(0, .1), input_limit=1.0, box=[1.0])
    yield "design_gain vertices junk", lambda: workbench.design_gain(
        A, B, delay=(0, .1), vertices=[("a", "b")])
    yield "design_gain l2 no Bw", lambda: workbench.design_gain(A, B, delay=(0, .1),
                                                                l2_gain=1.0)
    yield "design_gain rate -1", lambda: workbench.design_gain(A, B, delay=(0, .1), rate=-1.0)
    yield "design_gain huge A", lambda: workbench.design_gain(A * 1e300, B, delay=(0, .1))
    yield "implementation sampling nan", lambda: workbench.implementation(A, K, B=B,
                                                                          sampling=math.nan)
    yield "implementation sampling 1e308", lambda: workbench.implementation(A, K, B=B,
                                                                            sampling=1e308)
    yield "implementation sampling reversed", lambda: workbench.implementation(
        A, K, B=B, sampling=(0.2, 0.1))
    yield "implementation network delay -1", lambda: workbench.implementation(
        A, K, B=B, sampling=0.1, network_delay=(-1.0, 0.0))
    yield "implementation hold foh", lambda: workbench.implementation(A, K, B=B, sampling=0.1,
                                                                      hold="foh")
    yield "implementation K shape", lambda: workbench.implementation(A, np.ones((2, 3)), B=B,
                                                                     sampling=0.1)
    yield "implementation T_hi 1e-300", lambda: workbench.implementation(
        A, K, B=B, sampling=0.1, T_hi=1e-300)
    yield "synthesize_sampled T_max 0", lambda: workbench.synthesize_sampled(A, B=B, T_max=0.0)
    yield "synthesize_sampled T_max 1e308", lambda: workbench.synthesize_sampled(
        A, B=B, T_max=1e308)
    yield "synthesize_sampled digits 0", lambda: workbench.synthesize_sampled(
        A, B=B, T_max=0.1, digits=0)
    yield "synthesize_sampled digits 400", lambda: workbench.synthesize_sampled(
        A, B=B, T_max=0.1, digits=400)
    yield "runs_for p 1", lambda: runs_for(1.0)
    yield "runs_for p 0", lambda: runs_for(0.0)
    yield "runs_for alpha 0", lambda: runs_for(0.99, 0.0)
    yield "runs_for nan", lambda: runs_for(math.nan)
    yield "wilson k > n", lambda: mc.wilson_interval(11, 10)
    yield "wilson negative", lambda: mc.wilson_interval(-1, 10)
    yield "stop_statistics empty", lambda: mc.stop_statistics([], 0.5)
    yield "percentile q 200", lambda: mc.percentile([1.0, 2.0], 200.0)
    yield "percentile empty", lambda: mc.percentile([], 50.0)
    yield "load_design missing", lambda: load_design("/nonexistent/x.toml")
    yield "load_design folder", lambda: load_design(ROOT / "designs")


def _api_child(name, err_path):
    fd = os.open(err_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    os.dup2(fd, 2)
    sys.stderr = os.fdopen(2, "w", buffering=1)
    sys.stdout = open(os.devnull, "w")
    call = dict(api_cases())[name]
    try:
        call()
    except ValueError as exc:
        print(f"ValueError: {exc}", file=sys.stderr)
        sys.stderr.flush()
        os._exit(2)
    except BaseException:   # noqa: BLE001 - any other exception is the finding
        traceback.print_exc()
        sys.stderr.flush()
        os._exit(99)
    os._exit(0)


def _forked(target, args, timeout: float) -> int | None:
    """Exit code of ``target(*args)`` in a forked child; None if killed after ``timeout`` s."""
    proc = mp.get_context("fork").Process(target=target, args=args)
    proc.start()
    proc.join(timeout)
    if proc.is_alive():
        proc.kill()
        proc.join()
        return None
    return proc.exitcode


def run_api(name: str, work: Path, timeout: float = 120.0, tag: str = "0") -> tuple[str, str]:
    """Classify one API misuse: ``exit2`` (a ValueError of one line), ``ok``
    (returned), ``traceback`` (another exception, or a message of several
    lines or over 400 characters), ``timeout``."""
    folder = work / f"api-{tag}"
    folder.mkdir(parents=True, exist_ok=True)
    err = folder / "stderr.txt"
    code = _forked(_api_child, (name, str(err)), timeout)
    if code is None:
        return "timeout", f"over {timeout:g} s"
    msg = err.read_text(errors="replace").strip() if err.exists() else ""
    msg = "\n".join(ln for ln in msg.splitlines() if "Warning" not in ln and ln.strip())
    if code == 2:
        return ("exit2", msg) if "\n" not in msg and len(msg) < 400 else ("traceback", msg)
    if code == 0:
        return "ok", ""
    return "traceback", msg[-2000:]


def _child(argv, err_path):
    fd = os.open(err_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    os.dup2(fd, 2)
    os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
    sys.stderr = os.fdopen(2, "w", buffering=1)
    sys.stdout = open(os.devnull, "w")
    try:
        from workbench.cli import main
        code = main(argv)
    except BaseException:   # noqa: BLE001 - a panic (BaseException) is the finding
        traceback.print_exc()
        sys.stderr.flush()
        os._exit(99)
    sys.stderr.flush()
    os._exit(code if isinstance(code, int) else 98)


def run_one(m: Mutation, command: str, work: Path, timeout: float = 120.0, tag: str = "0"
            ) -> tuple[str, str]:
    """Classify one run of ``command`` on the mutated file: (class, message)."""
    name = m.design if m.kind != "dotdot_name" else ".."
    folder = work / f"run-{tag}"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}.toml"
    path.write_bytes(m.text)
    argv = {"synthesize": ["synthesize", "delay-bound", str(path)],
            "verify": ["verify", str(path)],
            "report": ["report", str(path), "--out", str(folder / "reports")]}[command]
    err = folder / "stderr.txt"
    code = _forked(_child, (argv, str(err)), timeout)
    if code is None:
        return "timeout", f"over {timeout:g} s"
    msg = err.read_text(errors="replace") if err.exists() else ""
    lines = [ln for ln in msg.splitlines() if ln.strip() and not ln.startswith(
        ("| design", "|---", "| "))]
    if code == 99 or "Traceback" in msg or "PanicException" in msg:
        return "traceback", msg[-2000:]
    if code == 2:
        return ("exit2", lines[-1] if lines else "") if len(lines) <= 2 else \
            ("traceback", "several lines: " + msg[-1000:])
    if code == 1:
        return "exit1", lines[-1] if lines else ""
    if code == 0:
        return "ok", ""
    return "traceback", f"exit code {code}: {msg[-1000:]}"


def command_of(design: str, i: int) -> str:
    """The command of run ``i`` (rotating over the design's commands)."""
    cmds = COMMANDS_OF.get(design, COMMANDS)
    return cmds[(i // len(CAMPAIGN_DESIGNS)) % len(cmds)]


def campaign(seed: int, n: int, work: Path, kinds=None, timeout: float = 120.0,
             log=None, newer: bool = False) -> list[tuple[Mutation, str, str, str]]:
    """``n`` seeded mutations, commands in rotation: over :data:`DESIGNS`
    (the first campaign), or with ``newer`` over :data:`CAMPAIGN_DESIGNS`
    with the newer tables' mutations (the re-run's campaign,
    benchmarks/fuzz_campaign.py)."""
    import workbench.cli  # noqa: F401 - loaded once here, not in every forked child
    import workbench.design  # noqa: F401
    from workbench import kinds as registry
    for kind in registry.REGISTRY:   # the studies' modules too
        registry.REGISTRY[kind]
    rng = random.Random(seed)
    designs = CAMPAIGN_DESIGNS if newer else DESIGNS
    out = []
    for i in range(n):
        design = designs[i % len(designs)]
        m = mutate(rng, design, (kinds or "tables") if newer else kinds)
        command = command_of(design, i) if newer else COMMANDS[(i // len(DESIGNS)) % len(COMMANDS)]
        cls, msg = run_one(m, command, work, timeout, tag=str(i))
        out.append((m, command, cls, msg))
        if log:
            print(f"{i:4d} {cls:9s} {command:10s} {m.design[:24]:24s} {m.kind:16s} "
                  f"{m.detail[:40]!r} {msg.splitlines()[-1][:160] if msg else ''}",
                  file=log, flush=True)
    return out
