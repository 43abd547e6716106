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
"""
from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Any

__all__ = ["Declared", "DeclaredQuantities", "Group", "determined", "names", "units", "values"]


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
    not yet written as :class:`Declared` entries), included when ``present``.

    ``names(spec) -> set``, ``values(result) -> dict``, ``units(spec) -> dict``
    (default: no unit known, ``"?"``) and ``present(spec) -> bool``. With
    ``part``, ``values`` reads ``part(result)``, the result of the feature,
    and the group has no value when that is None (the part did not run).
    """

    names: Callable[[Any], set]
    values: Callable[[Any], dict]
    present: Callable[[Any], bool] = lambda spec: True
    units: Callable[[Any], dict] | None = None
    part: Callable[[Any], Any] | None = None

    def values_of(self, result) -> dict:
        """The group's values in ``result`` (see ``part``)."""
        if self.part is None:
            return self.values(result)
        x = self.part(result)
        return {} if x is None else self.values(x)


def names(table, spec) -> set[str]:
    """Every claimable name of a design (known before running)."""
    out: set[str] = set()
    for d in table:
        if isinstance(d, Group):
            out |= d.names(spec) if d.present(spec) else set()
        else:
            out |= {n for n, _ in d.members(spec)}
    return out


def values(table, spec, result) -> dict:
    """name -> value of every declared quantity (``None``: not determined)."""
    out: dict = {}
    for d in table:
        if isinstance(d, Group):
            if d.present(spec):
                out.update(d.values_of(result))
        else:
            for n, index in d.members(spec):
                out[n] = d.read(result, **index)
    return out


def units(table, spec) -> dict[str, str]:
    """name -> unit of every declared quantity (``"?"``: the feature declares none)."""
    out: dict[str, str] = {}
    for d in table:
        if isinstance(d, Group):
            if d.present(spec):
                u = d.units(spec) if d.units is not None else {}
                out.update({n: u.get(n, "?") for n in d.names(spec)})
        else:
            out.update({n: d.unit.format(**index) for n, index in d.members(spec)})
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
