"""Deterministic figure files: Agg backend, fixed metadata, fixed rcParams."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from .markdown import Figure  # noqa: E402

_RC = {"svg.hashsalt": "workbench", "figure.dpi": 100, "savefig.dpi": 100,
       "font.size": 9, "axes.grid": True, "grid.alpha": 0.3}


def save_figure(fig_spec: Figure, path: Path) -> None:
    """Draw ``fig_spec`` and write a PNG with no timestamp or version metadata."""
    with matplotlib.rc_context(_RC):
        fig = plt.figure(figsize=fig_spec.size)
        try:
            fig_spec.draw(fig)
            fig.tight_layout()
            path.parent.mkdir(parents=True, exist_ok=True)
            fig.savefig(path, format="png", metadata={"Software": None})
        finally:
            plt.close(fig)
