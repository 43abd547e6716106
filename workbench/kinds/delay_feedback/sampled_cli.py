"""``workbench synthesize sampled DESIGN``: a delay-feedback design's gain (synthesised
as in its report) and its digital implementation check
(:mod:`workbench.features.sampled`)."""
from __future__ import annotations

from ...features.sampled import ImplementationSettings, run_implementation

__all__ = ["sampled_command"]


def sampled_command(design, *, as_json: bool = False) -> int:
    """``workbench synthesize sampled DESIGN``: the design's gain (synthesised as in
    the report), then its implementation check; exit 0 if CERTIFIED, else 1."""
    import json

    from ...digital import render_markdown
    from .run import designed_gain
    spec = design.spec
    settings = spec.implementation or ImplementationSettings(None, (0.0, 0.0), "zoh")
    got = designed_gain(design, what="to implement")
    if got is None:
        return 1
    A, B, syn = got[3], got[4], got[5]
    di = run_implementation(settings, spec.delay, A, B, syn.K)
    if as_json:
        print(json.dumps({"design": design.name, "delays": list(di.delays),
                          **di.result.to_dict()}, indent=2))
    else:
        print(f"{design.name}: digital implementation of K = {syn.K.tolist()} "
              f"(total delay [{di.delays[0]:g}, {di.delays[1]:g}] s)")
        print(render_markdown(di.result))
    return 0 if di.result.outcome.value == "certified" else 1
