"""A result that wraps the kind's general run (:func:`.run.run`) and names
the kind's quantities its own way.

An ``[analysis]`` module whose runs are the kind's (error grid, faults,
nominal stops) keeps the :class:`~.run.StopAccuracyResult` whole in a field
``kind`` and adds what its report needs; :class:`KindView` gives such a
result the kind's ``spec``, ``distance``, ``tolerance`` and quantities
(:attr:`KindView.kind_values`), and :func:`kind_quantity` with
:func:`per_speed` declare the module's quantities as the kind's under the
module's names::

    Declared("{b}.closed.max_abs_m", "m", kind_quantity("{b}.loop.grid.max_abs_m"),
             over=per_speed())
"""
from __future__ import annotations

from functools import cached_property

from ...features.quantities import values
from .run import speed_key

__all__ = ["KindView", "kind_quantity", "per_speed"]


class KindView:
    """Mixin of a (dataclass) result with a field ``kind``, the kind's result."""

    @property
    def spec(self):
        return self.kind.spec

    @property
    def distance(self) -> dict:
        return self.kind.distance

    @property
    def tolerance(self) -> float:
        return self.kind.spec.tolerance

    @cached_property
    def kind_values(self) -> dict:
        """The kind's quantities of :attr:`kind` (:mod:`.quantities`)."""
        from .quantities import TABLE
        return values(TABLE, self.spec, self.kind)


def per_speed(*members):
    """``over`` of a family: per speed ``s`` (km/h) of the design
    ``{"b": "v<s>", "s": s}``, times each member (a dict) of ``members``."""
    return lambda spec: [{"b": speed_key(s), "s": s} | x for s in spec.speeds_kmh
                         for x in (members or ({},))]


def kind_quantity(name: str, f=lambda x: x):
    """``read`` of a :class:`~workbench.features.quantities.Declared`: ``f`` of
    the kind's quantity ``name`` (a template over the index) of a
    :class:`KindView`, ``None`` where the kind's is not determined."""
    return lambda r, **ix: None if (x := r.kind_values[name.format(**ix)]) is None else f(x)
