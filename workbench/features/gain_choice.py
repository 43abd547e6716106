"""A study's feedback gain, printed or synthesised (issue 35): a design's
controller table either uses its printed gain (``K_table``, with
``K_source`` saying where it comes from) or asks for the certified
delay-bound synthesis (the free-weighting LMI of
:func:`workbench.synthesis.synthesize_delay_bound`) at one ``eps`` on the
study's linearisation (A, B). Both gains are read either way (a report may
compare them)::

    gain = "synthesis" | "table"
    eps = 0.35                 # > 0, the synthesis's scalar
    K_table = [k1, ..., kn]    # the printed gain, n = the loop's states
    K_source = "where the printed gain comes from"

The synthesis runs once per process and run folder for one key
(:func:`workbench.memo.computed_once`): every part of a study that asks for
the gain (cases, Monte Carlo, checks) shares it.
"""
from __future__ import annotations

from dataclasses import dataclass

__all__ = ["GainChoice", "chosen_gain", "read_gain_choice"]


@dataclass(frozen=True)
class GainChoice:
    """The controller table's gain entries (module docstring)."""

    gain: str            # "synthesis" or "table"
    eps: float
    K_table: tuple
    K_source: str


def read_gain_choice(t, n: int) -> GainChoice:
    """The gain entries of the table ``t`` (a :class:`workbench.reader.Reader`,
    not finished here); ``K_table`` of exactly ``n`` entries."""
    gain = t.string("gain", choices=("synthesis", "table"))
    eps = t.number("eps", positive=True)
    K_table = t.numbers("K_table", min_len=n, what="gain entries")
    if len(K_table) != n:
        names = ", ".join(f"k{i + 1}" for i in range(n))
        raise t.fail("K_table", list(K_table), f"{n} gain entries [{names}]")
    return GainChoice(gain, eps, K_table, t.string("K_source"))


def chosen_gain(choice: GainChoice, linearisation, name: str, key, how: str
                ) -> tuple[tuple, str, float | None]:
    """(K, how it was obtained, h_certified or None) of ``choice``.

    Parameters
    ----------
    choice : GainChoice
    linearisation : callable
        ``linearisation()``: the loop x' = A x + B u the synthesis certifies,
        an object with attributes ``A`` and ``B`` (called only when the gain
        is synthesised).
    name, key
        The memo entry of the synthesis (:func:`workbench.memo.computed_once`):
        ``key`` holds everything (A, B) depend on, and eps; an unkeyable
        ``key`` (:func:`workbench.memo.spec_key` None) synthesises every time.
    how : str
        What a synthesised gain is called (the study's words).

    Raises
    ------
    ModelError
        When the synthesis certifies no gain at ``choice.eps``.
    """
    if choice.gain == "table":
        return tuple(choice.K_table), choice.K_source, None
    from ..memo import computed_once, spec_key

    def compute():
        from ..errors import ModelError
        from ..synthesis import synthesize_delay_bound
        lin = linearisation()
        row = synthesize_delay_bound(lin.A, lin.B, (choice.eps,))[0]
        if row.K is None:
            raise ModelError(f"synthesis at eps = {choice.eps} certified no gain")
        return row.K, how, row.h_certified
    k = spec_key(key)
    return compute() if k is None else computed_once(name, k, compute)
