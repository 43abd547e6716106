"""The gain comparisons of a ``delay-feedback`` design: printed rows, gains
designed elsewhere, the eps sweep's figures (all optional).

Design tables (each documented in its feature module):

* ``[[synthesis.published]]`` (method ``free-weighting-003`` only): rows a
  source printed, compared with our sweep (:mod:`workbench.features.published_rows`);
* ``[[other_gains]]``: gains designed for another loop, checked on this one
  without any LMI (:mod:`workbench.features.other_gains`); with
  ``[[vertices]]`` also at every vertex (exact margin and Bessel-Legendre
  bound of order N, :mod:`workbench.features.point_gains`), next to the
  design's own gain;
* ``[eps_sweep]`` (no keys; method ``free-weighting-003`` only): the sweep's
  full table with a second exact method, the bound against eps, the loop's
  Bode and Nyquist plots and the spectral abscissa against h
  (:mod:`workbench.features.eps_sweep`).

All three need a single-input plant (K is one row). :func:`load_gain_tables`
reads them, :func:`run_gain_tables` computes, :func:`gain_tables_names` /
:func:`gain_tables_values` are the claimable quantities and
:func:`gain_tables_sections` the report's sections.
"""
from __future__ import annotations

from dataclasses import dataclass

__all__ = ["GainTables", "GainTablesResult", "gain_tables_names", "gain_tables_sections",
           "gain_tables_values", "load_gain_tables", "run_gain_tables"]


@dataclass(frozen=True)
class GainTables:
    """What a design asks for (empty: nothing)."""

    published: tuple = ()      # features.published_rows.Published
    other_gains: tuple = ()    # features.other_gains.OtherGain
    eps_sweep: bool = False

    def __bool__(self) -> bool:
        return bool(self.published or self.other_gains or self.eps_sweep)


@dataclass(frozen=True)
class GainTablesResult:
    published: tuple = ()      # features.published_rows.PublishedCheck
    other_gains: tuple = ()    # features.other_gains.GainCheck
    abscissa: tuple = ()       # features.eps_sweep.abscissa_vs_h
    at_vertices: tuple = ()    # per other gain, crosscheck.PointCheck per vertex


def load_gain_tables(root, plant, syn) -> GainTables:
    """The tables of the module docstring (``syn``: the design's
    :class:`~workbench.kinds.delay_feedback.SynthesisChoice`, which holds its
    ``[[synthesis.published]]``)."""
    from ...features.other_gains import load_other_gains
    published = syn.published
    n = len(plant.states)
    other = load_other_gains(root, n)
    sweep = root.has("eps_sweep")
    if sweep:
        root.table("eps_sweep").finish()
    if (sweep or published) and syn.method != "free-weighting-003":
        key = "eps_sweep" if sweep else "synthesis.published"
        raise root.fail(key, "<table>", 'a design whose synthesis.method is "free-weighting-003"')
    if (sweep or published or other) and len(plant.inputs) != 1:
        raise root.fail("inputs", [v.name for v in plant.inputs],
                        "a single input with [[other_gains]], [[synthesis.published]] or "
                        "[eps_sweep]")
    return GainTables(published, other, sweep)


def run_gain_tables(tables: GainTables, A, B, synthesis, syn, points=()):
    """The checks on the loop (A, B) (and at the vertex ``points``, (A_i, B_i));
    ``syn``: the design's synthesis choice. None when the design asks for none."""
    if not tables:
        return None
    from ...features.eps_sweep import abscissa_vs_h
    from ...features.other_gains import check_other_gains
    from ...features.point_gains import check_named_gains
    from ...features.published_rows import check_published
    rows, st = synthesis.rows, syn.settings
    at_vertices = (check_named_gains(list(points), tables.other_gains, syn.order, st.margin)
                   if points and tables.other_gains else ())
    return GainTablesResult(
        check_published(A, B, rows, tables.published, syn.eps, st) if tables.published
        else (), check_other_gains(A, B, tables.other_gains),
        abscissa_vs_h(A, B, rows) if tables.eps_sweep else (), at_vertices)


def gain_tables_names(spec) -> set[str]:
    """The quantities of the three feature modules (``compare[...]`` at the vertices)."""
    from ...features.other_gains import quantity_names
    from ...features.point_gains import compare_quantity_names
    from ...features.published_rows import published_quantity_names
    t = spec.gain_tables
    at = (compare_quantity_names([v.name for v in spec.vertices], t.other_gains)
          if spec.vertices else set())
    return published_quantity_names(t.published) | quantity_names(t.other_gains) | at


def gain_tables_values(res) -> dict:
    from ...features.other_gains import other_gain_quantities
    from ...features.point_gains import compare_quantities
    from ...features.published_rows import published_quantities
    r = res.gain_tables
    if r is None:
        return {}
    at = compare_quantities([v.name for v in res.spec.vertices], res.spec.gain_tables.other_gains,
                            r.at_vertices)
    return published_quantities(r.published) | other_gain_quantities(r.other_gains) | at


def gain_tables_sections(spec, res) -> tuple[list[str], tuple, tuple]:
    """(sections, figures, anchors) of the report (anchors: a finding on
    ``other_gains`` links to its section)."""
    from ...features.eps_sweep import (eps_sweep_figures, eps_sweep_notes, eps_sweep_table,
                                       infinite_note)
    from ...features.other_gains import ANCHOR, other_gains_section
    from ...features.published_rows import published_section
    t, r, st = spec.gain_tables, res.gain_tables, spec.synthesis.settings
    if r is None:
        return [], (), ()
    rows, sections, figs = res.synthesis.rows, [], ()
    if t.eps_sweep:
        figs, text = eps_sweep_figures(rows, r.published, res.A, res.B, r.abscissa,
                                       "Certified delay bound vs eps")
        sections.append("## eps sweep\n\n" + eps_sweep_table(rows, st) + "\n\n"
                        + eps_sweep_notes(st) + "\n\n" + infinite_note(rows) + "\n\n" + text)
    if r.published:
        sections.append(published_section(r.published))
    if r.other_gains:
        sections.append(other_gains_section(r.other_gains, "at the operating point",
                                            res.A, res.B))
    if r.at_vertices:
        from ...features.point_gains import compare_section
        own = None if res.synthesis.robust is None else res.synthesis.robust[1]
        sections.append(compare_section([v.name for v in spec.vertices], t.other_gains,
                                        r.at_vertices, own, "this design's gain"))
    return sections, figs, (ANCHOR,) if r.other_gains else ()
