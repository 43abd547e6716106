"""Values decided on a grid, so that a last-bit difference cannot change what
a report prints or draws (issue 36, item 5).

Two CPUs (OpenBLAS kernels, numpy's SIMD loops) or inputs moved by a few ulp
give results that differ in their last bits. A printed digit or a drawn pixel
changes with them only where the value lies within that noise of a rounding
point. So printed bounds are decided *on* the grid of printed values (the
callers certify the grid value itself, e.g.
:func:`workbench.benchmark_windows.settle_interval`), and figure data is
snapped to a stated resolution far coarser than the noise and far finer than
a pixel: axis ends to :data:`AXIS_DIGITS` significant digits (rounded up),
plotted values to a resolution relative to their decade (:func:`quantised`).
"""
from __future__ import annotations

import math
from decimal import Decimal

import numpy as np

__all__ = ["AXIS_DIGITS", "TIE_BAND", "sig_round", "directed", "axis_end", "printed_digits",
           "quantised"]

#: Significant digits of a figure's data-derived axis end (:func:`axis_end`).
AXIS_DIGITS = 2
#: Relative distance to a rounding tie within which :func:`printed_digits`
#: adds a digit: 1e6 times the last-bit noise of a converged result, and a
#: value drawn at random lands this close to a 4-digit tie with probability
#: about 2e-6.
TIE_BAND = 1e-9


#: Decimal exponents of the rounding step within which the step 10**e is a
#: normal float (and x / 10**e loses nothing): outside it (x subnormal, or
#: above 1e300) :func:`sig_round` scales in exact decimal arithmetic.
_FLOAT_STEP = range(-290, 291)


def sig_round(x: float, sig: int, how, nudge: float = 0.0) -> float:
    """x rounded with ``how`` (``math.floor``, ``math.ceil`` or ``round``) to
    ``sig`` significant digits: ``how(x / q + nudge) * q`` with the step
    ``q = 10**(floor(log10|x|) - sig + 1)``.

    The one place printed values are cut to their digits. For every x whose
    step is a normal float this is that float expression, bit for bit; for a
    subnormal x (5e-324, where 10**e underflows to 0) or a huge one the step
    is applied in exact decimal arithmetic instead, so no finite input divides
    by zero (fuzz campaign 3202, round 3). Zero and non-finite x are returned
    unchanged."""
    if x == 0 or not math.isfinite(x):
        return x
    e = math.floor(math.log10(abs(x))) - sig + 1
    if e in _FLOAT_STEP:
        q = 10.0 ** e
        return how(x / q + nudge) * q
    return float(Decimal(how(float(Decimal(x).scaleb(-e)) + nudge)).scaleb(e))


def directed(x: float, *, up: bool, sig: int = 4) -> float:
    """x to ``sig`` significant digits, rounded up (a lower end) or down (an upper
    end): an interval quantity never claims more than was certified, and its
    last digits, which differ between CPUs, are dropped."""
    if x == 0 or math.isinf(x) or math.isnan(x):
        return x
    return float(f"{sig_round(x, sig, math.ceil if up else math.floor):.{sig}g}")


def axis_end(x: float, sig: int = AXIS_DIGITS) -> float:
    """A figure's horizon computed from data (e.g. 1.25 times an exact
    margin), rounded *up* to ``sig`` significant digits: the axis and the grid
    drawn on it are then the same on every CPU unless ``x`` lies within
    last-bit noise of a ``sig``-digit value (a relative 1e-12 against 1e-2)."""
    return directed(float(x), up=True, sig=sig)


def quantised(values, digits: int = 4, scale: float | None = None) -> np.ndarray:
    """``values`` rounded to multiples of 10**(floor(log10(scale)) - digits + 1),
    ``scale`` the largest finite magnitude (default), NaN kept.

    With the default 4 digits the step is at most 1e-3 of the plotted range's
    decade: a fraction of a pixel and of one of a colour map's 256 levels,
    and some 1e8 times the last-bit noise of a converged eigenvalue or
    simulation, so a plotted value changes only when it lies within that
    noise of a step's midpoint (probability about 1e-8 per value)."""
    v = np.asarray(values, dtype=float)
    finite = np.abs(v[np.isfinite(v)])
    s = scale if scale is not None else (float(finite.max()) if finite.size else 0.0)
    if not s > 0:
        return v.copy()
    e = math.floor(math.log10(s)) - digits + 1
    if e not in _FLOAT_STEP:   # a subnormal or huge scale: nothing to snap to
        return v.copy()
    q = 10.0 ** e
    return np.round(v / q) * q


def printed_digits(x, sig: int = 4) -> int:
    """``sig``, or ``sig + 1`` when ``x`` lies within :data:`TIE_BAND`
    (relative) of a rounding tie at ``sig`` significant digits.

    A value that sits on a tie (typically an input or an exact combination
    of inputs, such as 0.0022875 printed to 4 digits) prints either way
    depending on its last bit: 0.002287 as designed, 0.002288 with the
    inputs moved +3 ulp. One more digit prints it exactly, the same on
    every CPU. Non-finite, zero and non-numbers keep ``sig``."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return sig
    x = abs(float(x))
    if x == 0 or not math.isfinite(x):
        return sig
    e = math.floor(math.log10(x)) - sig + 1
    if e not in _FLOAT_STEP:
        return sig
    q = 10.0 ** e
    frac = x / q - math.floor(x / q)
    return sig + 1 if abs(frac - 0.5) * q <= TIE_BAND * x else sig
