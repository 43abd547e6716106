"""A zero-order Sugeno fuzzy controller on (error, error rate), vectorised.

Paper 004 (section 2.5, fig 3) proposes fuzzy control of the deceleration
when its error is large and PID when small, without giving the rule base. We
use the textbook incremental fuzzy-PI table: five triangular sets {NB, NS, ZE,
PS, PB} on each normalised input, output singletons on the diagonal rule
table du = S(i + j) (i, j in -2..2, clipped), defuzzified by the weighted
mean. The output is an *increment* of the command, so the switch to PID can
be bumpless.

References
----------
.. [004] Wang Q., Wang L., Wang C., "Brake system of urban rail transit train
   with large closed loop control mode", Urban Mass Transit 2019(4), §2.5.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_CENTRES = np.array([-1.0, -0.5, 0.0, 0.5, 1.0])


def memberships(x) -> np.ndarray:
    """Triangular memberships of the normalised input (clipped to [-1, 1]);
    shape ``x.shape + (5,)``, rows sum to 1."""
    x = np.clip(np.asarray(x, float), -1.0, 1.0)[..., None]
    return np.clip(1.0 - np.abs(x - _CENTRES) / 0.5, 0.0, 1.0)


@dataclass(frozen=True)
class FuzzyIncrement:
    """Incremental fuzzy controller du = F(e / e_scale, de / de_scale) * du_scale.

    Attributes
    ----------
    e_scale : float
        Error at which the input saturates (unit of e).
    de_scale : float
        Error rate at which the input saturates (unit of e per s).
    du_scale : float
        Largest increment per sample (unit of u).
    """

    e_scale: float
    de_scale: float
    du_scale: float

    def __post_init__(self):
        if not (self.e_scale > 0 and self.de_scale > 0 and self.du_scale > 0):
            raise ValueError(f"{self}: expected positive scales")

    def increment(self, e, de) -> np.ndarray:
        """du for error e and its rate de (arrays broadcast)."""
        me = memberships(np.asarray(e) / self.e_scale)
        md = memberships(np.asarray(de) / self.de_scale)
        idx = np.arange(5) - 2
        out = np.clip(idx[:, None] + idx[None, :], -2, 2) / 2.0          # rule table
        w = me[..., :, None] * md[..., None, :]
        return self.du_scale * (w * out).sum(axis=(-1, -2)) / w.sum(axis=(-1, -2))
