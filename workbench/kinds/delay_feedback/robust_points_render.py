"""The report sections of a gain over listed points
(:mod:`.robust_points`; pure rendering): the robust gain with its per-point
checks, every compared gain at every point and the eps search, each the
rendering of its feature module."""
from __future__ import annotations

from ...features.point_gains import compare_section
from ...features.robust_gain_render import eps_search_figure, robust_gain_section

__all__ = ["robust_points_sections"]


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
