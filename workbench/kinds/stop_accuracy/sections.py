"""Per-section repeats of a ``stop-accuracy`` design with a ``[reference]``:
every controller stops ``count`` times at the end of every section, each
repeat on a plant drawn uniformly from ``[repeats.ranges]``, seeded per
section (paper 000, Tables 3-4: mean |stop error| and its variance per
section and controller).

Tables::

    [[sections]]   name, length = { value, unit = "m", source }
    [repeats]      count, seed, ranges = { factor = [lo, hi] } (factors of
                   [disturbances]; drawn in the order written, one stream per
                   section: numpy SeedSequence(seed).spawn(sections)),
                   controllers = ["name", ...] (optional: those that repeat; all)

Each repeat starts where the target of its section starts braking
(:func:`.run.run_sections` runs them). Statistics
per (section, controller), :class:`CellStats`: mean, variance (ddof 1) and
largest |error| in cm, the jerk |da/dt| and command rate |dc/dt| while moving
(m/s^3, recorded every control period), the mean time to standstill (s).

References
----------
Paper 000 (Yu, Zhang, Zhang 2024), section 3.2, Tables 3 and 4.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["CellStats", "Repeats", "Section", "batch_rates", "cell_stats", "draw_sections",
           "read_sections"]


@dataclass(frozen=True)
class Section:
    name: str
    length: float
    source: str


@dataclass(frozen=True)
class Repeats:
    """``[[sections]]`` and ``[repeats]``."""

    sections: tuple[Section, ...]
    count: int
    seed: int
    ranges: tuple            # ((factor, lo, hi), ...) in draw order
    controllers: tuple = ()  # names of the controllers that repeat (all: ())


@dataclass(frozen=True)
class CellStats:
    """Stop statistics of one controller on one section (cm, cm^2, m/s^3, s)."""

    mean_abs: float
    mean: float
    var: float
    max_abs: float
    jerk_mean: float
    jerk_max: float
    run_time: float
    command_rate: float     # mean |dc/dt| of the brake command while moving (m/s^3)
    errors: tuple[float, ...]


def read_sections(root, factors, reference, controllers=()) -> Repeats | None:
    """``[[sections]]`` with ``[repeats]`` (both or neither; a [reference] needed)."""
    if not root.has("sections") and not root.has("repeats"):
        return None
    if reference is None or not root.has("sections") or not root.has("repeats"):
        raise root.fail("sections" if not root.has("sections") else "repeats", None,
                        "[[sections]] and [repeats] together, with a [reference] (each section "
                        "is a stop-to-stop run of the target)")
    out = []
    for t in root.tables("sections"):
        q = t.quantity("length", "m", positive=True, hi=1e5)
        out.append(Section(t.string("name"), q.value, q.source))
        t.finish()
    if not out or len(out) > 100:
        raise root.fail("sections", len(out), "1 to 100 sections")
    rp = root.table("repeats")
    count = int(rp.number("count", integer=True, lo=2, hi=10000, what="repeats per section"))
    seed = int(rp.number("seed", integer=True, lo=0, what="seed"))
    names = [c.name for c in controllers]
    which = tuple(rp.raw("controllers", names))
    if (not isinstance(rp.raw("controllers", names), list) or not which
            or any(c not in names for c in which) or len(set(which)) < len(which)):
        raise rp.fail("controllers", rp.raw("controllers"), "names of [[controllers]] ("
                      + ", ".join(names) + "), each once")
    rt, ranges = rp.table("ranges"), []
    known = {f.name: f for f in factors}
    for k in list(rt.data):
        if k not in known:
            raise rt.fail(k, rt.data[k], "a factor of [disturbances]")
        b = rt.numbers(k, lo=-1e3, hi=1e3, what="bounds [lo, hi]")
        if len(b) != 2 or not b[0] <= b[1] or known[k].positive and not b[0] > 0:
            raise rt.fail(k, list(b), "two bounds [lo, hi] with lo <= hi" + (
                " above 0 (a ratio)" if known[k].positive else ""))
        ranges.append((k, b[0], b[1]))
    rt.finish()
    rp.finish()
    if not ranges:
        raise root.fail("repeats.ranges", {}, "at least one factor")
    if len(out) * count > 20000:
        raise root.fail("repeats.count", count, "at most 20000 repeats in all (sections x count)")
    return Repeats(tuple(out), count, seed, tuple(ranges),
                   () if len(which) == len(names) else which)


def draw_sections(seed: int, ranges, n_sections: int, count: int) -> dict:
    """factor -> array (n_sections, count) drawn uniformly from ``ranges``
    ((factor, lo, hi), ... in order), one stream per section."""
    seqs = np.random.SeedSequence(seed).spawn(n_sections)
    out = {k: np.empty((n_sections, count)) for k, _, _ in ranges}
    for i, sq in enumerate(seqs):
        rng = np.random.default_rng(sq)
        for k, lo, hi in ranges:
            out[k][i] = rng.uniform(lo, hi, count)
    return out


def batch_rates(tr, dt_ctrl: float) -> tuple:
    """(jerk, command rate, moving) of every run of the traces ``tr`` (recorded
    every ``dt_ctrl``), shape (records - 1, runs), for :func:`cell_stats`."""
    return (np.abs(np.diff(tr.a, axis=0)) / dt_ctrl, np.abs(np.diff(tr.c, axis=0)) / dt_ctrl,
            tr.t[1:, None] <= tr.t_stop[None, :])


def cell_stats(err_cm, tr, m, rates) -> CellStats:
    """:class:`CellStats` of the runs ``m`` (a mask over the batch) of the
    traces ``tr``, stop errors ``err_cm`` (cm), ``rates`` of :func:`batch_rates`."""
    jerk, crate, moving = rates
    e = err_cm[m]
    jm = np.where(moving[:, m], jerk[:, m], np.nan)
    return CellStats(float(np.mean(np.abs(e))), float(np.mean(e)), float(np.var(e, ddof=1)),
                     float(np.max(np.abs(e))), float(np.nanmean(jm)), float(np.nanmax(jm)),
                     float(np.mean(tr.t_stop[m])),
                     float(np.nanmean(np.where(moving[:, m], crate[:, m], np.nan))),
                     tuple(float(x) for x in e))
