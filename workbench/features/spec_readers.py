"""Readers of design-table entries that any simulating study can use (issue 35):
a ``[low, high]`` range (also as a sub-table with its unit and source), an event time on a decimal grid, a table of numbers
keyed by known names, and the step-halving tolerances of a ``[numerics]``
table (one relative tolerance and an absolute one per metric). Bad input is a :class:`~workbench.errors.DesignError` naming
the key (exit 2 at the CLI).
"""
from __future__ import annotations

__all__ = ["EVENT_DIGITS", "event_time", "keyed_numbers", "named_tables", "read_range",
           "read_step_tolerances", "sourced_range"]

#: Significant digits of the event times of a scenario (:func:`event_time`).
EVENT_DIGITS = 12


def event_time(t: float) -> float:
    """An event time of a scenario (a switch time, the horizon) on the grid of
    :data:`EVENT_DIGITS` significant digits.

    A law that starts at the first step at or after an event time t_e that is
    itself a step time (of dt, dt/2 and dt/4) fires at a step that depends on
    t_e's last bit: moved by a few ulp (the last-bit perturbation test,
    ``WORKBENCH_PERTURB_ULPS``) the switch comes one step later, and a run
    sensitive to its switch time changes its digits. On the 12-digit grid (our
    choice: a design's times are decimals of a few digits) a last-bit move
    cannot change the step."""
    return float(f"{t:.{EVENT_DIGITS}g}")


def read_range(t, key: str, **kw) -> tuple[float, float]:
    """``key = [low, high]`` of the table ``t`` (a :class:`workbench.reader.Reader`)
    with low <= high; ``kw``: ``positive=True``, ``lo=`` and ``hi=`` bounds of
    both ends (named in the message when violated)."""
    lo_hi = t.numbers(key, min_len=2, what="[low, high]")
    if len(lo_hi) != 2 or not lo_hi[0] <= lo_hi[1]:
        raise t.fail(key, list(lo_hi), "a range [low, high] with low <= high")
    for x in lo_hi:
        if kw.get("positive") and not x > 0 or "lo" in kw and x < kw["lo"] or \
                "hi" in kw and x > kw["hi"]:
            raise t.fail(key, list(lo_hi), f"a range within the allowed values ({kw})")
    return lo_hi


def sourced_range(t, key: str, range_key: str, unit: str, **kw):
    """The sub-table ``key = { <range_key> = [low, high], unit = "<unit>",
    source = "..." }`` of ``t``: (range (:func:`read_range`, ``kw`` its
    bounds), source, the sub-table's reader, not finished: the caller reads
    its other keys); ``unit`` is the only unit accepted."""
    s = t.table(key)
    lo_hi = read_range(s, range_key, **kw)
    s.string("unit", choices=(unit,))
    return lo_hi, s.string("source"), s


def keyed_numbers(t, allowed, expected: str, **kw) -> dict[str, float]:
    """``{key = number, ...}`` of the table ``t`` (a :class:`workbench.reader.Reader`,
    finished here), each key one of ``allowed`` (else ``expected`` is the
    message); ``kw``: the bounds of :meth:`~workbench.reader.Reader.number`."""
    out = {}
    for k in list(t.data):
        if k not in allowed:
            raise t.fail(k, t.data[k], expected)
        out[k] = t.number(k, **kw)
    t.finish()
    return out


def named_tables(root, key: str, pattern=None) -> list[tuple[object, str]]:
    """The ``[[key]]`` tables of ``root`` (at least one) with their ``name``
    strings, each name used once and, given ``pattern`` (a compiled regex),
    matching it: ``[(reader, name), ...]`` in file order, the readers not
    finished (the caller reads their other keys)."""
    tables = root.tables(key)
    if not tables:
        raise root.fail(key, [], f"at least one [[{key}]] table")
    out, seen = [], set()
    for t in tables:
        name = t.string("name")
        if (pattern is not None and not pattern.match(name)) or name in seen:
            raise t.fail("name", name, "a name used once"
                         + (" of letters, digits and _" if pattern is not None else ""))
        seen.add(name)
        out.append((t, name))
    return out


def read_step_tolerances(t, metrics, *, rtol_key: str = "convergence_rtol",
                         atol_key: str = "convergence_atol",
                         rtol_max: float = 0.1) -> tuple[float, dict]:
    """(rtol, metric -> atol) of a step-halving comparison
    (:func:`workbench.features.convergence.agree`): ``rtol_key`` in
    (0, ``rtol_max``] and the table ``atol_key`` of non-negative absolute
    tolerances, each keyed by one of ``metrics`` (a metric left out: 0)."""
    rtol = t.number(rtol_key, positive=True, hi=rtol_max)
    return rtol, keyed_numbers(t.table(atol_key), metrics, "a metric name: " + ", ".join(metrics),
                               nonneg=True)
