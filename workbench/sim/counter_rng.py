"""Counter-based random numbers: splitmix64 of (seed, stream, run, counter).

Every number is a pure function of its key, so a run's measurement noise
and its gradient profile depend on (seed, run index) only, never on the
chunk the run is simulated in, the sweep's size or the stepping path. The
same Python functions serve numpy (vectorised ``uint64`` arrays, overflow
wrapping modulo 2^64) and numba (:func:`jit_functions` compiles them for
``uint64`` scalars); only integer operations, one exact ``uint64 -> float``
conversion of a 53-bit integer and additions, so the two paths give the
same bits (no ``log`` or ``cos``, whose last bits differ between numpy's
SIMD loops and numba's libm calls).

* :func:`run_key` -- ``splitmix64(splitmix64(splitmix64(seed) + stream) + run)``;
* :func:`uniform` -- the 53 high bits of ``splitmix64(key + k)`` over 2^53, in [0, 1);
* :func:`normal4` -- ``(u_0 + u_1 + u_2 + u_3 - 2) sqrt(3)`` of four
  uniforms of the counters 4k .. 4k + 3: mean 0, variance 1 (the Irwin-Hall
  sum of four, bounded by +-2 sqrt(3); close to Gaussian inside +-2.5).

References
----------
.. [SLF14] Steele G. L., Lea D., Flood C. H., "Fast splittable pseudorandom
   number generators", OOPSLA 2014 (splitmix64 and its finaliser constants).
.. [SMD11] Salmon J. K., Moraes M. A., Dror R. O., Shaw D. E., "Parallel random
   numbers: as easy as 1, 2, 3", SC 2011 (counter-based generators).
"""
from __future__ import annotations

import math

import numpy as np

GOLDEN = np.uint64(0x9E3779B97F4A7C15)
M1, M2 = np.uint64(0xBF58476D1CE4E5B9), np.uint64(0x94D049BB133111EB)
S30, S27, S31, S11 = np.uint64(30), np.uint64(27), np.uint64(31), np.uint64(11)
U1, U2, U3, U4 = np.uint64(1), np.uint64(2), np.uint64(3), np.uint64(4)
TWO_M53 = 2.0 ** -53
SQRT3 = math.sqrt(3.0)

#: Streams of the antiskid sweep's perturbations (one key per run and stream).
NOISE_V, NOISE_OMEGA, GRADE, DELAY_PERIOD, DELAY_PHASE = 1, 2, 3, 4, 5


def splitmix64(x):
    """The splitmix64 output of state ``x`` (``uint64`` array or scalar)."""
    z = x + GOLDEN
    z = (z ^ (z >> S30)) * M1
    z = (z ^ (z >> S27)) * M2
    return z ^ (z >> S31)


def _unit_array(bits):
    return (bits >> S11).astype(np.float64) * TWO_M53


def _unit_scalar(bits):
    return float(bits >> S11) * TWO_M53


def _make(sm, unit):
    """(run_key, uniform, normal4) over the primitives ``sm`` and ``unit``."""

    def run_key(seed, stream, run):
        """Key of (seed, stream, run), all ``uint64``."""
        return sm(sm(sm(seed) + stream) + run)

    def uniform(key, k):
        """Uniform on [0, 1) number ``k`` (``uint64``) of ``key``."""
        return unit(sm(key + k))

    def normal4(key, k):
        """Unit-variance number ``k`` (``uint64``) of ``key`` (module docstring)."""
        c = key + k * U4
        s = unit(sm(c)) + unit(sm(c + U1)) + unit(sm(c + U2)) + unit(sm(c + U3))
        return (s - 2.0) * SQRT3

    return run_key, uniform, normal4


_run_key, _uniform, _normal4 = _make(splitmix64, _unit_array)


def run_key(seed: int, stream: int, run) -> np.ndarray:
    """Keys (``uint64`` array) of runs ``run`` (int array) in ``stream`` of ``seed``."""
    with np.errstate(over="ignore"):
        return _run_key(np.uint64(seed), np.uint64(stream),
                        np.asarray(run, np.int64).astype(np.uint64))


def uniform(key, k) -> np.ndarray:
    """:func:`uniform` of keys ``key`` (``uint64`` array) at counter ``k``
    (int, or int array broadcast with ``key``)."""
    with np.errstate(over="ignore"):
        return _uniform(np.asarray(key, np.uint64), np.asarray(k, np.int64).astype(np.uint64))


def normal4(key, k) -> np.ndarray:
    """:func:`normal4` of keys ``key`` at counter ``k`` (as :func:`uniform`)."""
    with np.errstate(over="ignore"):
        return _normal4(np.asarray(key, np.uint64), np.asarray(k, np.int64).astype(np.uint64))


def jit_functions():
    """(run_key, uniform, normal4) compiled with numba for ``uint64`` scalars
    (the same source as the numpy functions)."""
    import numba
    jit = numba.njit(nogil=True, error_model="numpy")
    return tuple(jit(f) for f in _make(jit(splitmix64), jit(_unit_scalar)))
