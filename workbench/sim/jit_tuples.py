"""Arrays read into tuples of floats in compiled (numba) loops.

A loop that reads a parameter array in every step, or a row of a 2-D
array, reloads it and, for a row, makes an array view (two atomic
reference-count updates). Read once into a tuple, the entries are values
the compiler keeps in registers and hoists out of the loop. numba has no
unrolled array-to-tuple of a length known at compile time, so the readers
are generated here for a given length.
"""
from __future__ import annotations

__all__ = ["tuple_readers"]


def tuple_readers(jit, n: int, pad: int = 0):
    """Compiled ``(vector(p), row(a, j))`` with the decorator ``jit``:
    ``vector(p) = (p[0], ..., p[n-1])`` followed by ``pad`` zeros, and
    ``row(a, j) = (a[j, 0], ..., a[j, n + pad - 1])`` (the same length, so a
    row of a 2-D array with the padded entries filled stands where a vector
    stood)."""
    m = n + pad
    vec = ", ".join([f"p[{i}]" for i in range(n)] + ["0.0"] * pad)
    row = ", ".join(f"a[j, {i}]" for i in range(m))
    ns = {}
    exec(f"def vector(p):\n    return ({vec},)\n"
         f"def row(a, j):\n    return ({row},)\n", ns)
    return jit(ns["vector"]), jit(ns["row"])
