"""Gains designed elsewhere, checked on a cruise design's own loop.

A cruise design may list ``[[other_gains]]``: gains with their source that
were designed for another operating point or rail (e.g. paper 003's Table 3,
designed on dry rail at v_d = 70 m/s, put on the wet-rail loop at
v_d = 60 m/s). They are data, never synthesised here. Each is checked on
this design's linearisation A, B with no LMI: the eigenvalues of A + B K
(the loop without delay) and the exact delay margin of
x' = A x + B K x(t - h) (:func:`workbench.margins.delay_margin_eig`, which
is 0 when the loop is unstable at h = 0).

Quantities (prefixed ``other_gains``): ``[NAME].abscissa`` (1/s, largest
real part of the eigenvalues of A + B K), ``[NAME].exact_margin`` (s),
``[NAME].stable`` ("yes" / "no" at h = 0), ``.min_abscissa`` (1/s, the
least unstable of the listed gains) and ``.stable`` (how many of them
stabilise the loop at h = 0).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from ...reader import Reader

if TYPE_CHECKING:
    from ...margins import DelayMargin

_NAME_CHARS = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-")


@dataclass(frozen=True)
class OtherGain:
    """A gain from elsewhere: its name, K = [k1, k2] and where it comes from."""

    name: str
    K: tuple[float, float]
    source: str


@dataclass(frozen=True)
class GainCheck:
    """An :class:`OtherGain` on this loop.

    Attributes
    ----------
    gain : OtherGain
    eigenvalues : tuple[complex, ...]
        Of A + B K (1/s), the loop at h = 0.
    abscissa : float
        Largest real part of ``eigenvalues`` (1/s).
    exact : DelayMargin
        Exact delay margin of x' = A x + B K x(t - h).
    """

    gain: OtherGain
    eigenvalues: tuple[complex, ...]
    abscissa: float
    exact: DelayMargin

    @property
    def stable(self) -> bool:
        return self.abscissa < 0


def load_other_gains(root: Reader) -> tuple[OtherGain, ...]:
    """``[[other_gains]]`` of a design (none when absent)."""
    out, seen = [], set()
    for t in root.tables("other_gains", default=[]):
        name = t.string("name")
        if not name or not set(name) <= _NAME_CHARS or name in seen:
            raise t.fail("name", name, "a new name of letters, digits and _ . - only")
        seen.add(name)
        K = t.numbers("K", min_len=2, what="gain entries")
        if len(K) != 2:
            raise t.fail("K", list(K), "two gain entries [k1, k2]")
        out.append(OtherGain(name, (float(K[0]), float(K[1])), t.string("source")))
        t.finish()
    return tuple(out)


def quantity_names(gains: tuple[OtherGain, ...]) -> set[str]:
    """The quantities of the module docstring for these gains."""
    if not gains:
        return set()
    names = {"other_gains.min_abscissa", "other_gains.stable"}
    for g in gains:
        names |= {f"other_gains[{g.name}].{f}" for f in ("abscissa", "exact_margin", "stable")}
    return names


def check_other_gains(A, B, gains: tuple[OtherGain, ...]) -> tuple[GainCheck, ...]:
    """Eigenvalues and exact delay margin of the loop closed with each gain."""
    import numpy as np

    from ...margins import delay_margin_eig
    out = []
    for g in gains:
        K = np.array([g.K])
        ev = np.linalg.eigvals(A + B @ K)
        ev = tuple(sorted((complex(e) for e in ev), key=lambda e: (-e.real, e.imag)))
        out.append(GainCheck(g, ev, max(e.real for e in ev), delay_margin_eig(A, B @ K)))
    return tuple(out)


def other_gain_quantities(checks: tuple[GainCheck, ...]) -> dict:
    """Values of :func:`quantity_names` (empty without gains)."""
    if not checks:
        return {}
    q = {"other_gains.min_abscissa": min(c.abscissa for c in checks),
         "other_gains.stable": sum(c.stable for c in checks)}
    for c in checks:
        base = f"other_gains[{c.gain.name}]"
        q[f"{base}.abscissa"] = c.abscissa
        q[f"{base}.exact_margin"] = c.exact.h
        q[f"{base}.stable"] = "yes" if c.stable else "no"
    return q
