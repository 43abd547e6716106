"""The free-weighting synthesis swept over eps on one single-input loop
x' = A x + B u(t - h), with everything a design compares it with: the rows
a source printed, the tighter Wirtinger synthesis and gains designed
elsewhere (read, computed and declared as claimable quantities).

A study that owns its loop (its own plant and linearisation) keeps only
that: it reads its ``[synthesis]`` table with :func:`load_sweep`, computes
with :func:`run_sweep` on its (A, B) and lists :func:`sweep_quantities` in
its :class:`~workbench.features.quantities.Declared` table; its spec and its
result hold the :class:`SweepSpec` and :class:`SweepResult` as ``.sweep``.
:func:`workbench.features.sweep_study_render.sweep_sections` renders it.

Design tables (each documented in its feature module): ``[synthesis]``
``eps``, the settings (:func:`workbench.features.eps_sweep.read_settings`),
``[[synthesis.published]]`` and ``compare_published``
(:mod:`~workbench.features.published_rows`); ``[tight]``
(:mod:`~workbench.features.tight_compare`); ``[[other_gains]]``
(:mod:`~workbench.features.other_gains`).

Quantities: ``synthesis.rows[eps=E].<field>`` for each field of
:data:`ROW_FIELDS`, ``synthesis.best.h_certified`` and ``exact_margin`` (the
row with the largest certified bound), and those of the three comparisons.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..reader import Reader
from .quantities import Declared, Group

__all__ = ["ROW_FIELDS", "SweepResult", "SweepSpec", "load_sweep", "row_value", "run_sweep",
           "sweep_quantities"]

#: Fields of a sweep row a claim may name, with their units (K1, K2: the
#: gain's entries, whose units depend on the loop's states).
ROW_FIELDS = {"h_certified": "s", "h_refuted": "s", "K1": "?", "K2": "?", "exact_margin": "s",
              "exact_margin_siso": "s", "ratio": "1", "status": ""}


@dataclass(frozen=True)
class SweepSpec:
    """The sweep's eps, settings (:class:`~workbench.synthesis.SynthesisSettings`)
    and comparisons (printed rows, ``[tight]`` or None, ``[[other_gains]]``)."""

    eps: tuple[float, ...]
    settings: object
    published: tuple = ()
    compare_published: bool = True
    tight: object = None
    other_gains: tuple = ()


@dataclass(frozen=True)
class SweepResult:
    """One :class:`~workbench.synthesis.SynthesisRow` per eps and the comparisons.

    ``abscissa_vs_h``: (h, spectral abscissa) of the loop closed with the
    canonical gain of the row with the largest certified bound
    (:func:`workbench.features.eps_sweep.abscissa_vs_h`)."""

    rows: tuple
    published: tuple = ()      # published_rows.PublishedCheck
    tight: object = None       # tight_compare.TightComparison or None
    abscissa_vs_h: tuple = ()
    other_gains: tuple = ()    # other_gains.GainCheck


def load_sweep(root: Reader, syn: Reader) -> SweepSpec:
    """The sweep of the ``[synthesis]`` table ``syn`` (finished here) and the
    ``[tight]`` and ``[[other_gains]]`` tables of ``root``."""
    from .eps_sweep import read_eps, read_settings
    from .other_gains import load_other_gains
    from .published_rows import load_published
    from .tight_compare import load_tight
    eps, settings = read_eps(syn), read_settings(syn)
    published = load_published(syn)
    compare = syn.boolean("compare_published", default=True)
    syn.finish()
    return SweepSpec(eps, settings, published, compare, load_tight(root, eps),
                     load_other_gains(root))


def run_sweep(A, B, s: SweepSpec, eps=None) -> SweepResult:
    """The sweep over ``eps`` (default the spec's) on (A, B) and its comparisons."""
    from ..synthesis import synthesize_delay_bound
    from .eps_sweep import abscissa_vs_h
    from .other_gains import check_other_gains
    from .published_rows import check_published
    from .tight_compare import run_tight
    rows = synthesize_delay_bound(A, B, s.eps if eps is None else tuple(eps), s.settings)
    checks = (check_published(A, B, rows, s.published, s.eps, s.settings)
              if s.compare_published else ())
    tight = run_tight(A, B, s.tight, s.settings, rows, s.published) if s.tight else None
    return SweepResult(rows, checks, tight, abscissa_vs_h(A, B, rows),
                       check_other_gains(A, B, s.other_gains))


def row_value(row, field: str):
    """The value of :data:`ROW_FIELDS` ``field`` (or any attribute) of a sweep
    row; ``h_certified`` only when the row is certified (else None)."""
    if field == "h_certified":
        return row.h_certified if row.status.value == "certified" else None
    if field == "status":
        return row.status.value
    if field in ("exact_margin", "exact_margin_siso"):
        m = row.exact if field == "exact_margin" else row.exact_siso
        return m.h if m else None
    if field in ("K1", "K2"):
        return row.K[int(field[1]) - 1] if row.K else None
    return getattr(row, field)


def _eps_key(eps: float) -> str:
    return f"{eps:g}"


def _best(r):
    return max(r.sweep.rows, key=lambda x: x.h_certified)


def sweep_quantities() -> tuple:
    """The sweep's entries of a :class:`~workbench.features.quantities.Declared`
    table (spec and result hold it as ``.sweep``)."""
    from .other_gains import other_gain_quantities, quantity_names
    from .published_rows import published_quantities, published_quantity_names
    from .tight_compare import TIGHT_QUANTITIES, tight_quantities
    return (
        *(Declared("synthesis.rows[eps={e}]." + f, unit,
                   lambda r, e, f=f: row_value(next(x for x in r.sweep.rows
                                                    if _eps_key(x.eps) == e), f),
                   over=lambda spec: [{"e": _eps_key(e)} for e in spec.sweep.eps])
          for f, unit in ROW_FIELDS.items()),
        Declared("synthesis.best.h_certified", "s",
                 lambda r: _best(r).h_certified if _best(r).h_certified > 0 else None),
        Declared("exact_margin", "s", lambda r: _best(r).exact.h if _best(r).exact else None),
        Group(lambda spec: published_quantity_names(spec.sweep.published),
               lambda r: published_quantities(r.sweep.published)),
        Group(lambda spec: {f"tight.{k}" for k in TIGHT_QUANTITIES},
               lambda r: tight_quantities(r.sweep.tight) if r.sweep.tight else {},
               lambda spec: spec.sweep.tight is not None),
        Group(lambda spec: quantity_names(spec.sweep.other_gains),
               lambda r: other_gain_quantities(r.sweep.other_gains)))
