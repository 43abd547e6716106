"""Seeded mutations of shipped designs, run through the CLI in a forked child
with a time limit (used by tests/test_fuzz.py; issue 32, item 1).

Each run calls :func:`workbench.cli.main` in a child forked from the test
process (the imports are already loaded) and is classified: ``exit2`` (bad
input, one line), ``exit1`` (a claim failed or INCONCLUSIVE), ``ok``,
``traceback`` (an exception or panic escaped ``main``, or a message of more
than one line or with "Traceback"), ``timeout`` (killed after the limit).
"""
from __future__ import annotations

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
    kind = rng.choice(kinds or ["number"] * 5 + ["unit"] * 2 + ["expression"] * 2 +
                      ["structural"])
    if kind == "structural":
        kind = rng.choice(STRUCTURAL)
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
    proc = mp.get_context("fork").Process(target=_child, args=(argv, str(err)))
    proc.start()
    proc.join(timeout)
    if proc.is_alive():
        proc.kill()
        proc.join()
        return "timeout", f"over {timeout:g} s"
    msg = err.read_text(errors="replace") if err.exists() else ""
    lines = [ln for ln in msg.splitlines() if ln.strip() and not ln.startswith(
        ("| design", "|---", "| "))]
    code = proc.exitcode
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


def campaign(seed: int, n: int, work: Path, kinds=None, timeout: float = 120.0,
             log=None) -> list[tuple[Mutation, str, str, str]]:
    """``n`` seeded mutations over :data:`DESIGNS`, commands in rotation."""
    import workbench.cli  # noqa: F401 - loaded once here, not in every forked child
    import workbench.design  # noqa: F401
    from workbench import kinds as registry
    for kind in registry.REGISTRY:   # the studies' modules too
        registry.REGISTRY[kind]
    rng = random.Random(seed)
    out = []
    for i in range(n):
        m = mutate(rng, DESIGNS[i % len(DESIGNS)], kinds)
        command = COMMANDS[(i // len(DESIGNS)) % len(COMMANDS)]
        cls, msg = run_one(m, command, work, timeout, tag=str(i))
        out.append((m, command, cls, msg))
        if log:
            print(f"{i:4d} {cls:9s} {command:10s} {m.design[:24]:24s} {m.kind:16s} "
                  f"{m.detail[:40]!r} {msg.splitlines()[-1][:160] if msg else ''}",
                  file=log, flush=True)
    return out
