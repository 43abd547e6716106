"""The typed reader of design-file tables.

A :class:`Reader` wraps one TOML table of a design file: it returns typed,
validated values (numbers with units and sources as :class:`Quantity`,
strings from a closed set, sub-tables), records which keys were used, and
turns every problem into a :class:`~workbench.errors.DesignError` naming the
file, the key, the value and what was expected. Studies and claims read
their tables through it; it knows neither.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable

from .errors import DesignError

_MISSING = object()


@dataclass(frozen=True)
class Quantity:
    """A parameter value with its unit and source, as written in a design."""

    value: float
    unit: str
    source: str


class Reader:
    """Typed, validating access to one table of a design file.

    Parameters
    ----------
    path : str
        Design file (for messages).
    data : dict
        The table.
    prefix : str
        Dotted key of the table (for messages).
    """

    def __init__(self, path: str, data: dict, prefix: str = ""):
        self.path, self.data, self.prefix = path, data, prefix
        self._used: set[str] = set()

    def key(self, name: str) -> str:
        return f"{self.prefix}.{name}" if self.prefix else name

    def fail(self, name: str, value: Any, expected: str) -> DesignError:
        return DesignError(self.path, self.key(name), value, expected)

    def has(self, name: str) -> bool:
        return name in self.data

    def raw(self, name: str, default: Any = _MISSING) -> Any:
        self._used.add(name)
        if name not in self.data:
            if default is _MISSING:
                raise self.fail(name, "<missing>", "this required key")
            return default
        return self.data[name]

    def number(self, name: str, *, default: Any = _MISSING, positive: bool = False,
               nonneg: bool = False, lo: float | None = None, hi: float | None = None,
               what: str = "number", integer: bool = False) -> float:
        """A finite real number, optionally range-checked (``what``: a noun
        phrase for messages, e.g. ``"number (kg)"``)."""
        val = self.raw(name, default)
        if val is default and default is not _MISSING:
            return val
        ok_type = isinstance(val, int) if integer else isinstance(val, (int, float))
        where = (f"in [{lo:g}, {hi:g}]" if lo is not None and hi is not None else
                 f"at most {hi:g}" if hi is not None else
                 f"at least {lo:g}" if lo is not None else "")
        if isinstance(val, bool) or not ok_type:
            if integer:     # 2.5, nan or 1e-9 where a count is expected
                raise self.fail(name, val, "a whole number" + (
                    "" if what in ("number", "integer") else f" ({what})") +
                    (f" {where}" if where else ""))
            raise self.fail(name, val, f"a {what}")
        try:
            x = int(val) if integer else float(val)
        except OverflowError:         # an int past the float range
            raise self.fail(name, f"<{len(str(abs(val)))}-digit integer>",
                            f"a finite {what}") from None
        if not math.isfinite(x):
            raise self.fail(name, val, f"a finite {what}")
        if positive and not x > 0:
            raise self.fail(name, val, f"a positive {what}")
        if nonneg and not x >= 0:
            raise self.fail(name, val, f"a non-negative {what}")
        if lo is not None and not x >= lo or hi is not None and not x <= hi:
            raise self.fail(name, val, f"{'an' if what[:1] in 'aeiou' else 'a'} {what} {where}")
        return x

    def string(self, name: str, *, default: Any = _MISSING,
               choices: Iterable[str] | None = None) -> str:
        val = self.raw(name, default)
        if val is default and default is not _MISSING:
            return val
        if not isinstance(val, str) or not val.strip():
            raise self.fail(name, val, "a non-empty string")
        if choices is not None and val not in choices:
            raise self.fail(name, val, "one of " + ", ".join(repr(c) for c in choices))
        return val

    def boolean(self, name: str, *, default: Any = _MISSING) -> bool:
        val = self.raw(name, default)
        if not isinstance(val, bool):
            raise self.fail(name, val, "true or false")
        return val

    def numbers(self, name: str, *, default: Any = _MISSING, positive: bool = False,
                min_len: int = 1, what: str = "numbers", lo: float | None = None,
                hi: float | None = None) -> tuple[float, ...]:
        val = self.raw(name, default)
        if val is default and default is not _MISSING:
            return val
        if not isinstance(val, list) or len(val) < min_len:
            raise self.fail(name, val, f"a list of at least {min_len} {what}")
        out = []
        for i, x in enumerate(val):
            if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
                raise self.fail(f"{name}[{i}]", x, f"a finite number ({what})")
            if positive and not x > 0:
                raise self.fail(f"{name}[{i}]", x, f"a positive number ({what})")
            if lo is not None and not x >= lo or hi is not None and not x <= hi:
                raise self.fail(f"{name}[{i}]", x, f"a number in [{lo:g}, {hi:g}] ({what})")
            out.append(float(x))
        return tuple(out)

    def quantity(self, name: str, unit: str, *, positive: bool = False, nonneg: bool = False,
                 lo: float | None = None, hi: float | None = None,
                 default: Any = _MISSING) -> Quantity:
        """A ``{ value = ..., unit = "...", source = "..." }`` entry.

        The unit must be exactly ``unit`` (SI, as the model states it), so a
        value given in another unit is caught rather than misread.
        """
        val = self.raw(name, default)
        if val is default and default is not _MISSING:
            return val
        if not isinstance(val, dict):
            raise self.fail(name, val, f'a table {{ value = ..., unit = "{unit}", source = "..." }}')
        sub = self.table(name)
        x = sub.number("value", positive=positive, nonneg=nonneg, lo=lo, hi=hi,
                       what=f"number ({unit})")
        u = sub.string("unit")
        if u != unit:
            raise sub.fail("unit", u, f'"{unit}"')
        src = sub.string("source")
        sub.finish()
        return Quantity(x, u, src)

    def quantities(self, units: dict[str, str], **kw) -> dict[str, Quantity]:
        """Every key of ``units`` (name -> unit, in that order) as a :meth:`quantity`
        with the bounds ``kw``; then :meth:`finish` (this table holds nothing else)."""
        out = {k: self.quantity(k, u, **kw) for k, u in units.items()}
        self.finish()
        return out

    def strings(self, name: str, choices: Iterable[str]) -> tuple[str, ...]:
        """A non-empty list of strings, each one of ``choices``."""
        val, choices = self.raw(name), tuple(choices)
        if not isinstance(val, list) or not val or any(v not in choices for v in val):
            raise self.fail(name, val, "a non-empty list of strings among "
                            + ", ".join(repr(c) for c in choices))
        return tuple(val)

    def table(self, name: str, *, default: Any = _MISSING) -> "Reader":
        val = self.raw(name, default)
        if val is default and default is not _MISSING:
            return Reader(self.path, {}, self.key(name))
        if not isinstance(val, dict):
            raise self.fail(name, val, "a table")
        return Reader(self.path, val, self.key(name))

    def tables(self, name: str, *, default: Any = _MISSING) -> list["Reader"]:
        val = self.raw(name, default)
        if val is default and default is not _MISSING:
            return []
        if not isinstance(val, list) or not all(isinstance(v, dict) for v in val):
            raise self.fail(name, val, "an array of tables ([[...]])")
        return [Reader(self.path, v, f"{self.key(name)}[{i}]") for i, v in enumerate(val)]

    def finish(self) -> None:
        """Raise on keys that were never read (typos, unsupported options)."""
        for k in self.data:
            if k not in self._used:
                raise self.fail(k, self.data[k], "no such key here (unknown or misspelt)")


def display_path(path: str | Path) -> str:
    """Path as shown in messages: relative to the working directory if possible."""
    p = Path(path)
    try:
        return str(p.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(p)


def read_gradients(r: Reader) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``grade_from`` (m, increasing from 0) and ``grade`` (-, |i| <= 0.05) of a
    table (a route's gradient sections: papers 001 and 002)."""
    g_from = r.numbers("grade_from", default=(0.0,), what="positions (m)")
    grade = r.numbers("grade", default=(0.0,), what="gradients (-)")
    if len(g_from) != len(grade) or g_from[0] != 0.0 or list(g_from) != sorted(g_from):
        raise r.fail("grade_from", list(g_from), "increasing positions starting at 0, one per "
                     "entry of grade")
    if any(abs(x) > 0.05 for x in grade):
        raise r.fail("grade", list(grade), "gradients within +/-0.05 (50 permille)")
    return g_from, grade


def read_paper_module(root: "Reader", load, what: str) -> str | None:
    """``[analysis] module = "pNNN.name"`` of a kind that hands what a design
    cannot express to a paper's module under ``workbench.papers``: the name,
    or None without the table. ``load(name)`` imports it and reads what the
    kind needs (ImportError or AttributeError: a design error saying the
    module should be ``what``)."""
    import re
    if not root.has("analysis"):
        return None
    r = root.table("analysis")
    name = r.string("module")
    r.finish()
    if not re.fullmatch(r"p\d{3}\.[a-z][a-z0-9_]*", name):
        raise r.fail("module", name, 'a paper module "pNNN.name" under workbench.papers')
    try:
        load(name)
    except (ImportError, AttributeError):
        raise r.fail("module", name, what) from None
    return name

