"""The report sections of a gain over listed points
(:mod:`.robust_points`; pure rendering): the robust gain with its per-point
checks, every compared gain at every point and the eps search, each the
rendering of its feature module, and the gain designed to requirements."""
from __future__ import annotations

from ...features.point_gains import compare_section
from ...features.robust_gain_render import eps_search_figure, robust_gain_section
from ...report.markdown import Rendered, fmt
from .requirements_render import requirements_rows

__all__ = ["requirements_section", "robust_points_report", "robust_points_sections"]


def robust_points_report(res, problem: str, own_label: str, note: str = "") -> Rendered:
    """The report of a :class:`~.robust_points.RobustPointsResult`: the study's
    ``problem`` section, opened with ``[requirements]`` by :func:`requirements_section`
    and the study's ``note`` on it (a paragraph, none when empty), then the sections
    and figures of :func:`robust_points_sections` (``own_label`` as there)."""
    if res.requirements is not None:
        problem = (requirements_section(res) + (f"\n\n{note}" if note else "") + "\n\n"
                   + problem)
    sections, figs = robust_points_sections(res, own_label)
    return Rendered((problem, *sections), figs)


def requirements_section(res) -> str:
    """``## Requirements`` (issue 31) of a :class:`~.robust_points.RobustPointsResult`
    with ``[requirements]``: the objective, the delay range and the table of
    :func:`.requirements_render.requirements_rows` (a study may append its comment)."""
    r, q = res.requirements, res.spec.requirements
    return ("## Requirements\n\nOne gain for every operating point below, designed to "
            f"requirements: objective **{q.objective}**, every constant delay in "
            f"[{fmt(q.delay[0])}, {fmt(q.delay[1])}] s "
            "(`workbench/requirements.py`: exponentially weighted descriptor synthesis, the "
            "rounded gain's decay certified by Bessel-Legendre cells over the range, exact "
            "rightmost roots on a delay grid).\n\n"
            + requirements_rows(q, r, res.spec.settings.gain_digits))


def robust_points_sections(res, own_label: str) -> tuple[list[str], tuple]:
    """(sections, figures) of a :class:`~.robust_points.RobustPointsResult`;
    ``own_label`` names the design's gain in the comparison table. Without a
    certified gain only the robust gain's section (it says why)."""
    ids, rg = res.spec.ids, res.robust
    gain = robust_gain_section(ids, rg)
    if rg.synthesis.K is None:
        return [gain], ()
    fig = eps_search_figure(rg)
    return [gain, compare_section(ids, res.spec.compare, res.compared, rg.checks, own_label),
            f"## eps search\n\n![eps]({{figdir}}/{fig.name}.png)"], (fig,)
