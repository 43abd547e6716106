"""Claimable quantities declared once: name, unit and the function that reads
the value from a study's result (issue 35, item 3).

A study used to write two parallel functions, ``quantity_names(spec)`` (every
name a claim may use, known before running) and ``quantities(result)`` (the
values), which had to agree name by name. Here a study lists its quantities
once, as :class:`Declared` entries, and both are expanded from that list, so a
name cannot be claimable without a reader, nor read without being claimable::

    TABLE = (
        Declared("exact_margin", "s", lambda r: r.exact.h),
        Declared("synthesis.K[{i},{j}]", "({u})/({x})", read_gain, over=gain_entries),
    )
    names(TABLE, spec)          # {"exact_margin", "synthesis.K[1,1]", ...}
    values(TABLE, spec, result) # {"exact_margin": 0.43, ...}

A reader returns ``None`` for a value that is not determined (the claim is then
INCONCLUSIVE, as for a name the old ``quantities`` left out; :func:`determined`).
A study class gets its three quantity methods from its table by deriving from
:class:`DeclaredQuantities`.

A feature's part of a result that may not have run (a Monte Carlo sweep, a
basin check: a table of the design, or none) is one :class:`Part`: its
entries declare names only when the design has the part, and read the
part's own result, every value undetermined when that is None::

    Part(runs_quantities("montecarlo", ...), lambda spec: spec.montecarlo is not None,
         lambda r: r.montecarlo)
"""
from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Any

__all__ = ["Declared", "DeclaredQuantities", "Group", "Part", "determined", "names", "units",
           "values"]


def determined(x):
    """``x``, or None when it is not determined (None or a float NaN)."""
    return None if x is None or (isinstance(x, float) and math.isnan(x)) else x


@dataclass(frozen=True)
class Declared:
    """One quantity, or a family of them indexed by the design.

    Attributes
    ----------
    name : str
        The name, a :meth:`str.format` template over the index keys
        (``"simulation.{s}.diverged"``).
    unit : str
        The unit of the value, a template over the same keys; ``"1"`` for a
        dimensionless number, ``""`` for a word (``yes``/``no``, an outcome).
    read : callable
        ``read(result, **index) -> value`` (``None``: not determined).
    over : callable or None
        ``over(spec) -> iterable of dict``: the index of each member of the
        family (its keys fill ``name`` and ``unit`` and are passed to
        ``read``); ``None`` for a single quantity.
    """

    name: str
    unit: str
    read: Callable[..., Any]
    over: Callable[[Any], Iterable[dict]] | None = None

    def members(self, spec) -> Iterator[tuple[str, dict]]:
        """(name, index) of every member for a design's spec."""
        if self.over is None:
            yield self.name, {}
            return
        for index in self.over(spec):
            yield self.name.format(**index), index


@dataclass(frozen=True)
class Group:
    """Quantities a feature declares with its own pair of functions (a feature
    not yet written as :class:`Declared` entries): ``names(spec) -> set``,
    ``values(result) -> dict`` and ``units(spec) -> dict`` (default: no unit
    known, ``"?"``). ``present(spec) -> bool`` is short for the group as the
    one entry of a :class:`Part` with that ``present``."""

    names: Callable[[Any], set]
    values: Callable[[Any], dict]
    present: Callable[[Any], bool] = lambda spec: True
    units: Callable[[Any], dict] | None = None


@dataclass(frozen=True)
class Part:
    """A feature's part of a study's result, which may not have run.

    Attributes
    ----------
    entries : tuple
        :class:`Declared` and :class:`Group` entries; they read ``part(result)``.
    present : callable
        ``present(spec) -> bool``: the design has the part; when not, its
        entries declare no name.
    part : callable
        ``part(result)``: the part's result (default: ``result`` itself);
        None: the part did not run, every name of its entries is not
        determined (None, the claim INCONCLUSIVE).
    """

    entries: tuple
    present: Callable[[Any], bool] = lambda spec: True
    part: Callable[[Any], Any] = lambda result: result


def _parts(table, spec) -> Iterator[Part]:
    """The table's parts the design has: each :class:`Part`, a :class:`Group`
    as a part of its own ``present`` and any other entry as a part of the
    whole result."""
    for d in table:
        if isinstance(d, Group):
            d = Part((d,), d.present)
        elif not isinstance(d, Part):
            d = Part((d,))
        if d.present(spec):
            yield d


def _names(entry, spec):
    if isinstance(entry, Group):
        return entry.names(spec)
    return [n for n, _ in entry.members(spec)]


def names(table, spec) -> set[str]:
    """Every claimable name of a design (known before running)."""
    return {n for p in _parts(table, spec) for e in p.entries for n in _names(e, spec)}


def values(table, spec, result) -> dict:
    """name -> value of every declared quantity (``None``: not determined)."""
    out: dict = {}
    for p in _parts(table, spec):
        x = p.part(result)
        for e in p.entries:
            if x is None:
                out.update(dict.fromkeys(_names(e, spec)))
            elif isinstance(e, Group):
                out.update(e.values(x))
            else:
                out.update({n: e.read(x, **index) for n, index in e.members(spec)})
    return out


def units(table, spec) -> dict[str, str]:
    """name -> unit of every declared quantity (``"?"``: the feature declares none)."""
    out: dict[str, str] = {}
    for p in _parts(table, spec):
        for e in p.entries:
            if isinstance(e, Group):
                u = e.units(spec) if e.units is not None else {}
                out.update({n: u.get(n, "?") for n in e.names(spec)})
            else:
                out.update({n: e.unit.format(**index) for n, index in e.members(spec)})
    return out


class DeclaredQuantities:
    """The quantity methods of a study whose quantities are declared in its
    class attribute ``TABLE`` (a mixin): ``quantity_names(spec)``,
    ``quantity_units(spec)`` and ``quantities(result)``, the latter for the
    spec :meth:`result_spec` gives (``result.spec`` unless overridden)."""

    TABLE: tuple = ()

    def quantity_names(self, spec) -> set[str]:
        return names(self.TABLE, spec)

    def quantity_units(self, spec) -> dict[str, str]:
        return units(self.TABLE, spec)

    def quantities(self, result) -> dict:
        return values(self.TABLE, self.result_spec(result), result)

    def result_spec(self, result):
        """The spec whose quantities ``result`` holds."""
        return result.spec
