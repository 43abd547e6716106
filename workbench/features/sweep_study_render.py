"""The report sections of a :mod:`workbench.features.sweep_study` (pure
rendering): the sweep's table with its notes and re-check margins, the
printed rows, the ``[tight]`` comparison, the gains designed elsewhere and
the sweep's figures, each the rendering of its feature module."""
from __future__ import annotations

from ..report.synthesis_text import recheck_table
from .eps_sweep import eps_sweep_figures, eps_sweep_notes, eps_sweep_table, infinite_note
from .other_gains import other_gains_section
from .published_rows import published_section
from .tight_compare_render import tight_section

__all__ = ["sweep_sections"]


def sweep_sections(sw, settings, A, B, *, heading: str, reference: str, where: str,
                   law: str, title: str) -> tuple[list[str], tuple]:
    """(sections, figures) of the sweep result ``sw`` on the loop (A, B).

    Parameters
    ----------
    sw : workbench.features.sweep_study.SweepResult
    settings : workbench.synthesis.SynthesisSettings
    heading : str
        Heading of the sweep's table (after ``## ``).
    reference : str
        How the ``[tight]`` table names the sweep's reference row.
    where, law : str
        The loop and its feedback law, as the ``[[other_gains]]`` section names them.
    title : str
        Title of the bound-against-eps figure.
    """
    sections = [f"## {heading}\n\n" + eps_sweep_table(sw.rows, settings) + "\n\n"
                + eps_sweep_notes(settings) + "\n\n" + infinite_note(sw.rows) + "\n\n"
                + recheck_table(sw)]
    if sw.published:
        sections.append(published_section(sw.published))
    if sw.tight:
        sections.append(tight_section(sw.tight, A, B, reference))
    if sw.other_gains:
        sections.append(other_gains_section(sw.other_gains, where, A, B, law))
    figs, text = eps_sweep_figures(sw.rows, sw.published, A, B, sw.abscissa_vs_h, title)
    return sections + ["## Figures\n\n" + text], figs
