"""The plant tables of a ``delay-feedback`` design as validated data (no
numpy, no sympy: reading or rejecting a design stays light)."""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Variable:
    """A state or input of the design: its unit, source and meaning."""

    name: str
    unit: str
    source: str
    description: str = ""


@dataclass(frozen=True)
class OperatingEntry:
    """``[operating_point]`` entry: fixed ``value`` or ``solve`` in [lo, hi]."""

    name: str
    value: float | None
    lo: float | None = None
    hi: float | None = None
    guess: float | None = None
    source: str = ""

    @property
    def solved(self) -> bool:
        return self.value is None


@dataclass(frozen=True)
class PlantSpec:
    """The plant tables of a design (validated text, nothing built yet).

    Attributes
    ----------
    path : str
        Design file (for messages).
    states, inputs : tuple[Variable, ...]
    parameters : dict[str, Quantity]
    definitions : tuple[tuple[str, str], ...]
        Named sub-expressions (name, text), each may use earlier ones.
    equations : tuple[str, ...]
        f_i as text, in the order of ``states``.
    operating_point : tuple[OperatingEntry, ...]
        One entry per state, then per input.
    trim : bool
        A given point must be an equilibrium (``operating_point.trim``,
        default true); false: linearise off-equilibrium, as the report says.
    """

    path: str
    states: tuple[Variable, ...]
    inputs: tuple[Variable, ...]
    parameters: dict
    definitions: tuple[tuple[str, str], ...]
    equations: tuple[str, ...]
    operating_point: tuple[OperatingEntry, ...] = field(default=())
    trim: bool = True

    @property
    def state_names(self) -> tuple[str, ...]:
        return tuple(v.name for v in self.states)

    @property
    def input_names(self) -> tuple[str, ...]:
        return tuple(v.name for v in self.inputs)

    def values(self, overrides: dict | None = None) -> dict[str, float]:
        """Parameter values (SI), with optional overrides (a polytope vertex)."""
        out = {k: q.value for k, q in self.parameters.items()}
        out.update(overrides or {})
        return out
