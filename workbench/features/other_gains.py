"""Gains designed elsewhere, checked on a design's own loop: ``[[other_gains]]``.

A design with a linear loop x' = A x + B u(t - h) may list gains with their
source that were designed for another operating point, rail, plant or
paper. They are data, never synthesised here. Each is checked on this
design's A, B with no LMI: the eigenvalues of A + B K (the loop without
delay) and the exact delay margin of x' = A x + B K x(t - h)
(:func:`workbench.margins.delay_margin_eig`, which is 0 when the loop is
unstable at h = 0).

Design table::

    [[other_gains]]   name = "letters, digits, _ . -", K = [k1, ..., kn], source = "..."

Quantities (prefixed ``other_gains``): ``[NAME].abscissa`` (1/s, largest
real part of the eigenvalues of A + B K), ``[NAME].exact_margin`` (s),
``[NAME].stable`` ("yes" / "no" at h = 0), ``.min_abscissa`` (1/s, the
least unstable of the listed gains) and ``.stable`` (how many of them
stabilise the loop at h = 0). :func:`other_gains_section` renders them
under :data:`HEADING` (the anchor of :data:`ANCHOR`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..reader import Reader

if TYPE_CHECKING:
    from ..margins import DelayMargin

__all__ = ["ANCHOR", "GainCheck", "HEADING", "OtherGain", "check_other_gains",
           "load_other_gains", "other_gain_quantities", "other_gains_section", "quantity_names"]

_NAME_CHARS = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-")
_WORDS = {2: "two", 3: "three", 4: "four"}
HEADING = "Gains designed elsewhere, on this loop"
#: (quantity prefix, section heading): the report's link from a finding to the section.
ANCHOR = ("other_gains", HEADING)


@dataclass(frozen=True)
class OtherGain:
    """A gain from elsewhere: its name, K = [k1, ..., kn] (one input) and where it comes from."""

    name: str
    K: tuple[float, ...]
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


def gain_entries(t: Reader, n: int) -> tuple[float, ...]:
    """``K`` of a table: ``n`` numbers (the states of a single-input loop)."""
    K = t.numbers("K", min_len=2, what="gain entries")
    if len(K) != n:
        names = ", ".join(f"k{i + 1}" for i in range(n))
        raise t.fail("K", list(K), f"{_WORDS.get(n, n)} gain entries [{names}]")
    return tuple(float(k) for k in K)


def load_other_gains(root: Reader, n: int = 2, table: str = "other_gains"
                     ) -> tuple[OtherGain, ...]:
    """``[[other_gains]]`` (or ``[[table]]``) of a design (none when absent);
    ``n`` entries per K."""
    out, seen = [], set()
    for t in root.tables(table, default=[]):
        name = t.string("name")
        if not name or not set(name) <= _NAME_CHARS or name in seen:
            raise t.fail("name", name, "a new name of letters, digits and _ . - only")
        seen.add(name)
        K = gain_entries(t, n)
        out.append(OtherGain(name, K, t.string("source")))
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

    from ..margins import delay_margin_eig
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


# -- rendering ---------------------------------------------------------------------------
def _eig_text(e: complex) -> str:
    from ..report.markdown import fmt
    if abs(e.imag) < 1e-9 * max(1.0, abs(e.real)):
        return fmt(e.real, 3)
    return f"{fmt(e.real, 3)} ± {fmt(abs(e.imag), 3)}j"


def other_gains_section(checks, where: str, A, B, law: str = "the feedback law") -> str:
    """``## Gains designed elsewhere, on this loop``: the checks of
    :func:`check_other_gains` as a table, with the verdict; ``where`` names
    the loop in words (e.g. "at the operating point"), ``law`` the law the
    gain closes."""
    import numpy as np

    from ..report.markdown import fmt, md_table
    from ..report.synthesis_text import exact_margin_text, gain_text
    k2_max = -(A[0, 0] + A[1, 1]) if np.shape(A) == (2, 2) else None
    above = sum(c.gain.K[1] >= k2_max for c in checks) if k2_max is not None else 0
    trace = ("With B = [0, 1]ᵀ the gain adds to the second row of A, so stability needs "
             "trace(A + B K) = a11 + a22 + k2 < 0, i.e. k2 < "
             f"{fmt(k2_max, 3)} on this loop; {above} of the {len(checks)} gains have a "
             "larger k2. " if k2_max is not None and np.array_equal(np.ravel(B), [0.0, 1.0])
             else "")
    rows = [[f"`{c.gain.name}`", gain_text(c.gain.K, 5), c.gain.source,
             ", ".join(_eig_text(e) for e in c.eigenvalues if e.imag >= 0), fmt(c.abscissa, 3),
             "yes" if c.stable else "**no**", exact_margin_text(c.exact)] for c in checks]
    n_bad = sum(not c.stable for c in checks)
    verdict = (f"**{n_bad} of {len(checks)} gains leave this loop unstable even without "
               "delay**" if n_bad else f"All {len(checks)} gains stabilise this loop at h = 0")
    return (f"## {HEADING}\n\nGains designed for another loop (their source says "
            f"where), closed around this design's linearisation ({where}): eigenvalues of "
            "A + B K (the loop at h = 0) and the exact delay margin of x' = A x + B K x(t - h), "
            "computed without any LMI. " + verdict + ".\n\n"
            + md_table(["gain", "K", "source", "eigenvalues of A + B K (1/s)",
                        "rightmost real part (1/s)", "stable at h = 0", "exact margin h* (s)"],
                       rows, "lllllll")
            + "\n\n" + trace + "A gain with a positive rightmost root is no design for this "
            "loop: the error grows like e^(t Re s) from the moment "
            f"{law} takes over, whatever the delay, so no delay bound of any criterion "
            "applies to it.")
