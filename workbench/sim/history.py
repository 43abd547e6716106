"""History buffers for fixed-step delay simulation.

A signal sampled on the step grid t_k = k dt and held constant on
[t_k, t_k + dt) (zero-order hold, ZOH) is stored in a ring buffer. With the
delay written h = (N + f) dt (N integer, 0 <= f < 1) the *average* of the
delayed signal s(t - h) over the step [t_n, t_n + dt) is exactly

    (1 - f) s_{n-N} + f s_{n-N-1},

and the integral of s over the window [t_n - h, t_n) is

    dt (s_{n-N} + ... + s_{n-1}) + f dt s_{n-N-1}.

Both are what :class:`DelayLine` returns. Entries may be Python floats
(single runs) or numpy arrays (a batch of runs stepped together); the buffer
only stores references, never mutates them.
"""
from __future__ import annotations

import math


def split_delay(h: float, dt: float) -> tuple[int, float]:
    """Write ``h = (N + f) dt`` with integer ``N >= 0`` and ``0 <= f < 1``.

    Values within 1e-9 of a whole number of steps are snapped to it.
    """
    if not (h >= 0 and dt > 0):
        raise ValueError(f"h = {h!r}, dt = {dt!r}; expected h >= 0 and dt > 0 (s)")
    q = h / dt
    n = round(q)
    if abs(q - n) < 1e-9:
        return int(n), 0.0
    n = math.floor(q)
    return int(n), q - n


class DelayLine:
    """Ring buffer of a ZOH signal with exact delayed averages and window sums.

    Parameters
    ----------
    h : float
        Delay (s), >= 0.
    dt : float
        Step (s), > 0.
    initial : float or numpy.ndarray
        Value of the signal before t = 0 (the initial function on [-h, 0),
        constant), unless ``history`` is given.
    history : sequence, optional
        The samples s_{-N-1}, ..., s_{-1} before t = 0 (length N + 1, see
        :attr:`N`); a non-constant initial function.
    """

    def __init__(self, h: float, dt: float, initial, history=None):
        self.N, self.f = split_delay(h, dt)
        self.dt = dt
        self._L = self.N + 2
        self._buf = [initial] * self._L
        if history is not None:
            if len(history) != self.N + 1:
                raise ValueError(f"history has {len(history)} samples; expected N + 1 = {self.N + 1}")
            for k, s in zip(range(-self.N - 1, 0), history):
                self._buf[k % self._L] = s
        self._n = 0                       # number of samples pushed
        self._sum = initial * 0.0         # s_{n-N} + ... + s_{n-1}
        for k in range(-self.N, 0):
            self._sum = self._sum + self._get(k)

    def _get(self, k: int):
        """Sample k (k < 0: the initial value)."""
        return self._buf[k % self._L]

    def push(self, value) -> None:
        """Append the sample s_n of the current step."""
        n = self._n
        if self.N > 0:
            self._sum = self._sum + value - self._get(n - self.N)
        self._buf[n % self._L] = value
        self._n = n + 1

    def delayed(self):
        """Average of s(t - h) over the step that starts at the last pushed
        sample's time (call after :meth:`push`)."""
        n = self._n - 1
        a = self._get(n - self.N)
        return a if self.f == 0.0 else (1.0 - self.f) * a + self.f * self._get(n - self.N - 1)

    def window_integral(self):
        """Integral of s over [t_n - h, t_n), t_n the time of the *next*
        sample (call before :meth:`push` of that sample)."""
        n = self._n
        tail = 0.0 if self.f == 0.0 else self.f * self._get(n - self.N - 1)
        return self.dt * (self._sum + tail)


class BatchDelayLine:
    """:class:`DelayLine` for a batch whose runs have *different* delays.

    Parameters
    ----------
    h : (B,) array_like
        Delay of each run (s).
    dt : float
    initial : float
        Signal before t = 0 (all runs).
    """

    def __init__(self, h, dt: float, initial):
        import numpy as np
        h = np.asarray(h, float)
        parts = [split_delay(float(x), dt) for x in h]
        self.N = np.array([p[0] for p in parts])
        self.f = np.array([p[1] for p in parts])
        self._L = int(self.N.max()) + 2
        self._buf = np.full((self._L, h.size), float(initial))
        self._cols = np.arange(h.size)
        self._n = 0

    def push(self, value) -> None:
        self._buf[self._n % self._L] = value
        self._n += 1

    def delayed(self):
        n = self._n - 1
        a = self._buf[(n - self.N) % self._L, self._cols]
        b = self._buf[(n - self.N - 1) % self._L, self._cols]
        return (1.0 - self.f) * a + self.f * b
