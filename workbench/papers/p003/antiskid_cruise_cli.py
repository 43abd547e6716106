"""``workbench synthesize delay-bound`` of an ``antiskid-cruise`` design:
problem (60) of paper 003 at the design's operating point, over eps (printing
only; registered in :data:`workbench.kinds.capabilities.CAPABILITIES`)."""
from __future__ import annotations

__all__ = ["synthesize_command"]


def synthesize_command(design, *, eps=None, as_json: bool = False) -> int:
    """Print problem (60) over ``eps`` (default: the design's); exit 0 if
    every row is certified, else 1."""
    import json

    from ...kinds.delay_feedback.cli import synthesis_table
    from ...report.markdown import fmt
    from ...synthesis import synthesize_delay_bound
    from . import antiskid_cruise
    spec = design.spec
    eps = tuple(eps) if eps else spec.eps
    _, lam_solved, lam, lin = antiskid_cruise.operating_point(spec)
    rows = synthesize_delay_bound(lin.A, lin.B, eps, spec.settings)
    ok = all(r.status.value == "certified" for r in rows)
    if as_json:
        print(json.dumps({"design": design.name, "rows": [r.to_json() for r in rows]}, indent=2))
        return 0 if ok else 1
    print(f"{design.name}: problem (60) of paper 003 at v_d = {fmt(spec.v_d.value)} m/s, "
          f"lambda_d = {fmt(lam, 5)} ({'pinned' if spec.lambda_d_pinned else 'solved'}; "
          f"solved {fmt(lam_solved, 6)})")
    print(synthesis_table(rows, spec.settings))
    return 0 if ok else 1
