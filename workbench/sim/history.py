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
    if not q <= 1e9:
        raise ValueError(f"h = {h!r}, dt = {dt!r}; expected h / dt at most 1e9 steps")
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

    def push(self, value, ticks=None) -> None:
        """Append the sample s_n of the current step (``ticks`` is for the
        interface of :class:`TimedDelayLine`; the step here is fixed)."""
        n, buf, L = self._n, self._buf, self._L
        if self.N > 0:
            self._sum = self._sum + value - buf[(n - self.N) % L]
        buf[n % L] = value
        self._n = n + 1

    def delayed(self):
        """Average of s(t - h) over the step that starts at the last pushed
        sample's time (call after :meth:`push`)."""
        k, buf, L = self._n - 1 - self.N, self._buf, self._L
        a = buf[k % L]
        return a if self.f == 0.0 else (1.0 - self.f) * a + self.f * buf[(k - 1) % L]

    def window_integral(self):
        """Integral of s over [t_n - h, t_n), t_n the time of the *next*
        sample (call before :meth:`push` of that sample)."""
        n = self._n
        tail = 0.0 if self.f == 0.0 else self.f * self._get(n - self.N - 1)
        return self.dt * (self._sum + tail)

    def pieces(self) -> list:
        """The window [t_n - h, t_n) (t_n as in :meth:`window_integral`) as
        (value, duration in s) pieces, oldest first."""
        n, dt, buf, L = self._n, self.dt, self._buf, self._L
        out = [(buf[(n - self.N - 1) % L], self.f * dt)] if self.f > 0 else []
        out += [(buf[k % L], dt) for k in range(n - self.N, n)]
        return out


class TimedDelayLine:
    """:class:`DelayLine` for steps of varying length (a refined mesh).

    Time is counted in integer *ticks* (the finest step), so step ends are
    exact; the delay ``H`` (in ticks) need not be whole. The signal is
    zero-order hold: sample s_k holds over its step [T_k, T_k + n_k).

    Parameters
    ----------
    H : float
        Delay in ticks, >= 0.
    tick : float
        Tick length (s).
    initial : float
        Signal before the first stored sample.
    history : sequence, optional
        Samples before t = 0, oldest first, each held for ``history_ticks``.
    history_ticks : int
    """

    def __init__(self, H: float, tick: float, initial, history=(), history_ticks: int = 1):
        if not (H >= 0 and tick > 0):
            raise ValueError(f"H = {H!r}, tick = {tick!r}; expected H >= 0 and tick > 0")
        self.H, self.tick, self.initial = H, tick, initial
        self._segs = []          # [start, end, value], oldest first, ticks
        self._first = 0          # index of the oldest segment still needed
        start = -len(history) * history_ticks
        for value in history:
            self._segs.append((start, start + history_ticks, value))
            start += history_ticks
        self._T = 0              # end of the last pushed step = time of the next sample

    def push(self, value, ticks: int) -> None:
        """Append the sample of the step that starts now and lasts ``ticks``."""
        T0 = self._T
        self._T = T0 + ticks
        self._segs.append((T0, self._T, value))
        keep = T0 - self.H               # nothing before this is read again
        while self._segs[self._first][1] <= keep - 1:
            self._first += 1
        if self._first > 4096:           # compact now and then
            del self._segs[:self._first]
            self._first = 0

    def integral(self, a: float, b: float):
        """Integral of s over [a, b) (ticks; result in signal x ticks)."""
        segs = self._segs
        total = 0.0 * self.initial
        i = self._first
        if i >= len(segs) or a < segs[i][0]:
            lo = segs[i][0] if i < len(segs) else b
            total = total + self.initial * (min(b, lo) - a)
        while i < len(segs) and segs[i][0] < b:
            s0, s1, val = segs[i]
            lo, hi = max(a, s0), min(b, s1)
            if hi > lo:
                total = total + val * (hi - lo)
            i += 1
        return total

    def delayed(self):
        """Average of s(t - h) over the last pushed step."""
        T0, T1, _ = self._segs[-1]
        return self.integral(T0 - self.H, T1 - self.H) / (T1 - T0)

    def window_integral(self):
        """Integral (signal x s) of s over [t - h, t), t the time of the next sample."""
        return self.integral(self._T - self.H, self._T) * self.tick

    def pieces(self, ticks: int) -> list:
        """The window [t - h, t) cut, from its end, into pieces of ``ticks``
        (the first one shorter), each as (average of s, duration in s)."""
        out, b = [], float(self._T)
        a_end = self._T - self.H
        while b > a_end + 1e-9:
            a = max(b - ticks, a_end)
            out.append((self.integral(a, b) / (b - a), (b - a) * self.tick))
            b = a
        return out[::-1]


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

    def push(self, value, ticks=None) -> None:
        self._buf[self._n % self._L] = value
        self._n += 1

    def delayed(self):
        n = self._n - 1
        a = self._buf[(n - self.N) % self._L, self._cols]
        b = self._buf[(n - self.N - 1) % self._L, self._cols]
        return (1.0 - self.f) * a + self.f * b
