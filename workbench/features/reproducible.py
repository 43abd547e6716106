"""Decisions that last-bit differences cannot flip (issue 36, item 5).

A batch of runs of a switching loop (a relay-like MFAC regime, a saturating
controller) can amplify a last-bit difference of its inputs into a different
trajectory: such a run's metrics differ between CPUs and are not results.
The helpers here measure each run's reproducibility band by running the batch
again with its inputs moved by a small relative step (:func:`nudged`), mark the runs whose
band is wider than a stated relative tolerance (:func:`reproducible`), and
decide a threshold only with a margin (:func:`decide`, :func:`count_text`), so
that a printed count or choice does not change under the last-bit
perturbation test (``WORKBENCH_PERTURB_ULPS``, :mod:`workbench.design`).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

__all__ = ["NUDGE", "RTOL", "nudged", "relative_spread", "reproducible", "decide",
           "count_text", "window"]

#: Relative move of each input that measures a run's reproducibility band.
#: Far above the last-bit differences between CPUs (about 1e-16), so that the
#: band of a run that merely rounds differently is its linear response, the
#: same whatever the last bits of the nominal inputs; a chaotic run's band is
#: of the size of its metrics whatever the step.
NUDGE = 1e-9
#: Relative band above which a run is not reproducible (our choice): its
#: metrics move by more than 0.1 % for a 1e-9 move of its inputs, an
#: amplification above 1e6, which only a switching (relay-like, chaotic) or
#: threshold-crossing run shows. Measured on paper 002's grids (1404 MFAC
#: runs): the bands of the runs at the nominal inputs and at +-3 ulp put the
#: same runs above every threshold from 1e-7 to 1e-2.
RTOL = 1e-3


def nudged(obj, rel: float, keep: tuple[str, ...] = ()):
    """A copy of the dataclass ``obj`` with every finite non-zero float field
    multiplied by ``1 + rel``; fields named in ``keep`` (e.g. a delay that must
    stay a whole number of steps), zeros, integers and other fields are kept."""
    changes = {f.name: v * (1.0 + rel) for f in dataclasses.fields(obj)
               if f.name not in keep and isinstance(v := getattr(obj, f.name), float)
               and math.isfinite(v) and v != 0.0}
    return dataclasses.replace(obj, **changes)


def relative_spread(samples) -> np.ndarray:
    """Per run, the largest relative band over its metrics.

    Parameters
    ----------
    samples : array_like
        (M, N, Q): M repetitions (nominal and nudged inputs) of N runs' Q metrics.

    Returns
    -------
    numpy.ndarray
        (N,) max over metrics of (max - min) / max |value| over the repetitions;
        0 where a metric is equal in every repetition or non-finite in all, inf where repetitions disagree on being finite.
    """
    x = np.asarray(samples, float)
    fin = np.isfinite(x)
    mixed = fin.any(axis=0) & ~fin.all(axis=0)
    y = np.where(fin, x, 0.0)
    band = y.max(axis=0) - y.min(axis=0)
    scale = np.abs(y).max(axis=0)
    rel = np.where(band > 0, band / np.where(scale > 0, scale, 1.0), 0.0)
    rel = np.where(mixed, np.inf, rel)
    return rel.max(axis=-1)


def reproducible(samples, rtol: float = RTOL) -> np.ndarray:
    """(N,) bool: runs whose :func:`relative_spread` is at most ``rtol``
    (samples: the nominal run and runs on inputs :func:`nudged` by +-NUDGE)."""
    return relative_spread(samples) <= rtol


def decide(lo, hi, threshold: float, margin: float) -> np.ndarray:
    """Side of ``threshold`` of each band [lo, hi], decided with a margin.

    Returns an int array: -1 where ``hi < threshold - margin`` (below), +1 where
    ``lo > threshold + margin`` (above), 0 otherwise (undecided: the band, or
    its margin, reaches the threshold; also a non-finite end).
    """
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    below = np.isfinite(hi) & (hi < threshold - margin)
    above = np.isfinite(lo) & (lo > threshold + margin)
    return np.where(below, -1, np.where(above, 1, 0))


def count_text(decided: int, undecided: int) -> str:
    """A count with its undecided runs: "53", or "53-54" (53 decided, 1 undecided)."""
    return f"{decided}" if undecided == 0 else f"{decided}-{decided + undecided}"


def window(t, lo: float, hi: float) -> np.ndarray:
    """Mask of the samples of the uniform time grid ``t`` in [lo, hi], each end
    taken with half a step to spare.

    A window end that falls on a sample time (``t = k dt`` against ``t0 + 35``)
    is otherwise a threshold that a last-bit difference of ``dt`` moves: the
    sample is in or out, and a plotted or measured window gains or loses a
    point.
    """
    t = np.asarray(t, float)
    half = 0.5 * float(np.median(np.diff(t))) if t.size > 1 else 0.0
    return (t >= lo - half) & (t <= hi + half)
