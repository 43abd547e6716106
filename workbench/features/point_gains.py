"""One gain checked at several operating points (the points of a family of
linear loops x' = A_i x + B_i u(t - h)), and named gains compared there.

:func:`check_named_gains` closes each named gain (``[[other_gains]]``-style
rows, :class:`workbench.features.other_gains.OtherGain`) around every point
with :func:`workbench.crosscheck.check_gain`: stability at h = 0, the exact
delay margin and the Bessel-Legendre analysis bound of order N.
:func:`point_table` prints a gain's checks per point (with the spectral
abscissa at its certified delay), :func:`compare_section` the exact margin of
every named gain at every point, with a warning for a gain unstable without
delay; :func:`compare_quantity_names` / :func:`compare_quantities` are the
claimable ``compare[NAME]...`` quantities.
"""
from __future__ import annotations

import math

__all__ = ["bound_cell", "check_named_gains", "compare_quantities", "compare_quantity_names",
           "compare_section", "margin_cell", "point_table"]


def check_named_gains(points, gains, order: int, margin: float) -> tuple:
    """Per gain, its :class:`~workbench.crosscheck.PointCheck` at every point
    (``points``: (A_i, B_i) pairs)."""
    import numpy as np

    from ..crosscheck import check_gain
    return tuple(check_gain(points, np.array([g.K]), N=order, margin=margin) for g in gains)


def compare_quantity_names(ids, gains) -> set[str]:
    """``compare[NAME].unstable_points``, ``.all_stable`` and
    ``.points[ID].exact_margin`` of every gain."""
    names = set()
    for g in gains:
        names |= {f"compare[{g.name}].unstable_points", f"compare[{g.name}].all_stable"}
        names |= {f"compare[{g.name}].points[{i}].exact_margin" for i in ids}
    return names


def compare_quantities(ids, gains, compared) -> dict:
    """Values of :func:`compare_quantity_names`."""
    q = {}
    for g, checks in zip(gains, compared):
        q[f"compare[{g.name}].unstable_points"] = float(sum(not k.stable_at_zero
                                                            for k in checks))
        q[f"compare[{g.name}].all_stable"] = \
            "yes" if all(k.stable_at_zero for k in checks) else "no"
        for i, k in zip(ids, checks):
            q[f"compare[{g.name}].points[{i}].exact_margin"] = k.exact.h
    return q


# -- rendering ---------------------------------------------------------------------------
def margin_cell(pc) -> str:
    """The exact margin of a point check, or the loud word when unstable at h = 0."""
    from ..report.markdown import fmt
    if not pc.stable_at_zero:
        return "**UNSTABLE at h = 0**"
    return fmt(pc.exact.h, 4)


def bound_cell(h: float) -> str:
    """An order-N analysis bound at a point, rounded down to 2 digits: its 4th
    digit depends on the BLAS kernel (47.22 / 47.21 s at one point under
    Haswell / Sandybridge)."""
    from ..report.markdown import fmt, fmt_floor
    return fmt_floor(h, 2) if math.isfinite(h) and h > 0 else fmt(h)


def point_table(ids, checks, abscissa, order: int) -> str:
    """Exact margin, order-N bound and spectral abscissa at the certified
    delay of one gain, per point."""
    from ..report.markdown import fmt, md_table
    return md_table(["point", "exact margin h* (s)",
                     f"certified, BL N={order} (s, 2 digits, rounded down)",
                     "spectral abscissa at h (1/s)"],
                    [[f"`{i}`", margin_cell(c), bound_cell(c.h_certified), fmt(a, 3)]
                     for i, c, a in zip(ids, checks, abscissa)], "lrrr")


def compare_section(ids, gains, compared, own_checks, own_label: str) -> str:
    """``## Compared with printed gains``: the exact margin of every named
    gain (and of the design's own, ``own_label``, unless ``own_checks`` is
    None) at every point."""
    from ..report.markdown import fmt, md_table
    rows, warn = [], []
    for g, checks in zip(gains, compared):
        bad = [i for i, k in zip(ids, checks) if not k.stable_at_zero]
        if bad:
            warn.append(f"> **WARNING — `{g.name}` (K = [{', '.join(fmt(k, 5) for k in g.K)}], "
                        f"{g.source}) is UNSTABLE without any delay at {len(bad)} of {len(ids)} "
                        f"points: {', '.join(f'`{b}`' for b in bad)}.**")
        rows.append([f"`{g.name}`"] + [margin_cell(k) for k in checks])
    if own_checks is not None:
        rows.append([own_label] + [margin_cell(k) for k in own_checks])
    return ("## Compared with printed gains\n\nExact delay margin (s) of each gain at each "
            "point (∞: stable for every constant delay).\n\n" + "\n\n".join(warn)
            + ("\n\n" if warn else "")
            + md_table(["gain"] + [f"`{i}`" for i in ids], rows, "l" + "r" * len(ids)))
