"""``workbench synthesize delay-bound`` of an ``antiskid-cruise`` design:
problem (60) of paper 003 at the design's operating point, over eps (printing
only; registered in :data:`workbench.kinds.capabilities.CAPABILITIES`)."""
from __future__ import annotations

__all__ = ["synthesize_command"]


def synthesize_command(design, *, eps=None, as_json: bool = False) -> int:
    """Print problem (60) over ``eps`` (default: the design's); exit 0 if
    every row is certified, else 1."""
    from ...kinds.delay_feedback.cli import print_sweep
    from ...report.markdown import fmt
    from ...synthesis import synthesize_delay_bound
    from . import antiskid_cruise
    spec = design.spec
    _, lam_solved, lam, lin = antiskid_cruise.operating_point(spec)
    sw = spec.sweep
    rows = synthesize_delay_bound(lin.A, lin.B, tuple(eps) if eps else sw.eps, sw.settings)
    return print_sweep(
        design.name, f"{design.name}: problem (60) of paper 003 at v_d = "
        f"{fmt(spec.v_d.value)} m/s, lambda_d = {fmt(lam, 5)} "
        f"({'pinned' if spec.lambda_d_pinned else 'solved'}; solved {fmt(lam_solved, 6)})",
        rows, sw.settings, as_json)
