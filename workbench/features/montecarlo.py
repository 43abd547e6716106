"""Monte Carlo of station stops over continuous distributions (papers 000, 004).

A design names one distribution per uncertain factor in its
``[montecarlo.distributions]`` table::

    delay    = { dist = "lognormal", median = 1.0, sigma = 0.1, source = "..." }
    mass     = { dist = "normal", mean = 1.0, sd = 0.04, lo = 0.85, hi = 1.15, source = "..." }
    gradient = { dist = "uniform", lo = -3.0, hi = 3.0, source = "..." }

``normal`` may be truncated to [lo, hi] (both optional). Every draw is the
inverse CDF of a seeded uniform (numpy ``default_rng([seed, k])``, k the
factor's index in the study's fixed list), so a factor's draws depend only on
the seed and the sample count, not on which other factors the design names;
every controller meets the same draws (common random numbers).

The statistics of a set of stop errors (:func:`stop_statistics`): the share
within the platform tolerance with its Wilson score interval
(:func:`within_rate`) and the 95th percentile of |error|.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..reader import Reader

DISTRIBUTIONS = ("uniform", "normal", "lognormal")
#: z of a two-sided 95 % interval
Z95 = 1.959963984540054


@dataclass(frozen=True)
class Distribution:
    """One continuous distribution of an uncertain factor.

    Attributes
    ----------
    kind : {"uniform", "normal", "lognormal"}
    a, b : float
        uniform: lo, hi; normal: mean, sd; lognormal: median, sigma (of log).
    lo, hi : float
        Truncation of a normal (-inf, inf: none); the support of a uniform.
    source : str
        Why this distribution (a design-file citation).
    """

    kind: str
    a: float
    b: float
    lo: float
    hi: float
    source: str

    def ppf(self, u) -> np.ndarray:
        """Inverse CDF at the uniforms ``u`` in (0, 1)."""
        from scipy.special import ndtr, ndtri
        u = np.asarray(u, float)
        if self.kind == "uniform":
            return self.a + (self.b - self.a) * u
        if self.kind == "lognormal":
            return self.a * np.exp(self.b * ndtri(u))
        p0, p1 = ndtr((self.lo - self.a) / self.b), ndtr((self.hi - self.a) / self.b)
        return np.clip(self.a + self.b * ndtri(p0 + u * (p1 - p0)), self.lo, self.hi)

    def describe(self) -> str:
        """E.g. "normal(mean 1, sd 0.04) on [0.85, 1.15]"."""
        g = lambda x: f"{x:g}"
        if self.kind == "uniform":
            return f"uniform on [{g(self.a)}, {g(self.b)}]"
        if self.kind == "lognormal":
            return f"lognormal(median {g(self.a)}, sigma of log {g(self.b)})"
        cut = "" if (self.lo, self.hi) == (-math.inf, math.inf) else \
            f" truncated to [{g(self.lo)}, {g(self.hi)}]"
        return f"normal(mean {g(self.a)}, sd {g(self.b)}){cut}"

    @property
    def support(self) -> tuple[float, float]:
        if self.kind == "lognormal":
            return 0.0, math.inf
        return (self.a, self.b) if self.kind == "uniform" else (self.lo, self.hi)


def load_distribution(t: Reader, name: str, *, positive: bool) -> Distribution:
    """One ``{ dist = ..., ... }`` entry; ``positive`` factors must have a
    support inside (0, inf)."""
    d = t.table(name)
    kind = d.string("dist", choices=DISTRIBUTIONS)
    if kind == "uniform":
        lo, hi = d.number("lo"), d.number("hi")
        if not lo < hi:
            raise d.fail("hi", hi, f"a number above lo = {lo}")
        dist = Distribution(kind, lo, hi, lo, hi, d.string("source"))
    elif kind == "lognormal":
        dist = Distribution(kind, d.number("median", positive=True),
                            d.number("sigma", positive=True, hi=2.0), 0.0, math.inf,
                            d.string("source"))
    else:
        mean, sd = d.number("mean"), d.number("sd", positive=True)
        lo, hi = d.number("lo", default=-math.inf), d.number("hi", default=math.inf)
        if not lo < mean < hi:
            raise d.fail("lo", lo, f"truncation bounds lo < mean = {mean} < hi")
        dist = Distribution(kind, mean, sd, lo, hi, d.string("source"))
    if positive and not dist.support[0] > 0 and dist.kind != "lognormal":
        raise d.fail("lo", dist.support[0] if math.isfinite(dist.support[0]) else "<missing>",
                     "a positive lower bound (this factor is a positive ratio)")
    d.finish()
    return dist


@dataclass(frozen=True)
class MonteCarloSpec:
    """``[montecarlo]``: sample count, seed, and the distributions by factor."""

    samples: int
    seed: int
    distributions: dict      # factor -> Distribution (only the factors named)


def load_montecarlo(root: Reader, factors: dict[str, bool], *,
                    max_samples: int = 20000) -> MonteCarloSpec:
    """The ``[montecarlo]`` table; ``factors`` maps each factor the study can
    draw to whether it is a positive ratio. A factor left out stays nominal."""
    mc = root.table("montecarlo")
    samples = mc.number("samples", integer=True, lo=2, hi=max_samples)
    seed = mc.number("seed", integer=True, lo=0)
    dt = mc.table("distributions")
    dists = {}
    for k in dt.data:
        if k not in factors:
            raise dt.fail(k, dt.data[k], "one of the factors " + ", ".join(factors))
        dists[k] = load_distribution(dt, k, positive=factors[k])
    if not dists:
        raise mc.fail("distributions", {}, "at least one factor with a distribution")
    dt.finish()
    mc.finish()
    return MonteCarloSpec(samples, seed, dists)


def draw(spec: MonteCarloSpec, order: tuple[str, ...], nominal: dict) -> dict:
    """Draws of every factor of ``order`` (arrays of ``spec.samples``);
    factors without a distribution take their ``nominal`` value."""
    drawn = drawn_factors(spec, order)
    return {name: drawn[name] if name in drawn else np.full(spec.samples, float(nominal[name]))
            for name in order}


def drawn_factors(spec: MonteCarloSpec, order: tuple[str, ...]) -> dict:
    """The draws of the factors of ``order`` with a distribution only (in
    the order of ``spec.distributions``), each the same as in :func:`draw`:
    the inverse CDF of ``default_rng([seed, k]).random(samples)``, k the
    factor's index in ``order``."""
    return {name: d.ppf(np.random.default_rng([spec.seed, order.index(name)]).random(
        spec.samples)) for name, d in spec.distributions.items() if name in order}


def within_rate(errors, tol: float, z: float = Z95):
    """(k, n, k/n, lo, hi): stops with |error| <= ``tol`` and the Wilson score
    interval of that proportion (95 % for the default z). Wilson's interval
    stays inside [0, 1] and is sound at k = 0 or k = n, where the normal
    approximation collapses to a point."""
    e = [abs(x) for x in errors]
    return wilson_interval(sum(x <= tol for x in e), len(e), z)


def wilson_interval(k: int, n: int, z: float = Z95):
    """(k, n, k/n, lo, hi): the proportion of k successes in n trials and its
    Wilson score interval (95 % for the default z); NaNs for n = 0.

    References
    ----------
    .. [W27] Wilson E. B., "Probable inference, the law of succession, and
       statistical inference", J. Am. Stat. Assoc. 22(158):209-212, 1927.
    """
    if not (isinstance(k, (int, np.integer)) and isinstance(n, (int, np.integer))
            and 0 <= k <= n):
        raise ValueError(f"wilson_interval: k = {k!r}, n = {n!r}; expected whole numbers "
                         "0 <= k <= n")
    if n == 0:
        return 0, 0, math.nan, math.nan, math.nan
    p = k / n
    den = 1 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return k, n, p, max(0.0, mid - half), min(1.0, mid + half)


#: Statistics a claim may name: quantity suffix -> :class:`StopStatistics` attribute.
MC_QUANTITIES = {"p_within": "p", "within_lo": "lo", "within_hi": "hi", "p95_abs_m": "p95",
                 "mean_m": "mean", "overshoot_share": "overshoot"}


@dataclass(frozen=True)
class StopStatistics:
    """Stop errors of one controller (or mode) over a Monte Carlo, in metres.

    Attributes
    ----------
    k, n : int
        Stops within the tolerance, and stops.
    p, lo, hi : float
        k / n and its Wilson 95 % interval.
    p95 : float
        95th percentile of |error| (m; numpy's linear interpolation).
    mean : float
        Signed mean error (m, + = overshoot).
    overshoot : float
        Share of stops beyond the stopping point (a run that never stopped counts
        as beyond; its error is nan, so is the mean).
    errors : tuple[float, ...]
    """

    k: int
    n: int
    p: float
    lo: float
    hi: float
    p95: float
    mean: float
    overshoot: float
    errors: tuple


def stop_statistics(errors, tol: float) -> StopStatistics:
    """:class:`StopStatistics` of ``errors`` (m) against the tolerance ``tol`` (m);
    a run that never stopped (nan) counts as outside."""
    e = np.asarray(errors, float)
    e_in = np.where(np.isfinite(e), e, np.inf)
    k, n, p, lo, hi = within_rate(e_in, tol)
    return StopStatistics(k, n, p, lo, hi, percentile(np.abs(e_in), 95.0),
                          float(np.mean(e)) if e.size else math.nan,
                          float(np.mean(e_in > 0)) if e.size else math.nan,
                          tuple(float(x) for x in e))


def percentile(x, q: float) -> float:
    """The q-th percentile of ``x`` by linear interpolation between order
    statistics (numpy's default), inf when an infinite value takes part, nan
    for no values (as :func:`wilson_interval` for n = 0); ValueError unless
    0 <= q <= 100."""
    if not 0 <= q <= 100:
        raise ValueError(f"percentile: q = {q!r}; expected a number in [0, 100]")
    s = np.sort(np.asarray(x, float))
    if s.size == 0:
        return math.nan
    if np.all(np.isfinite(s)):
        return float(np.percentile(s, q))
    pos = q / 100 * (len(s) - 1)
    i, j = int(np.floor(pos)), int(np.ceil(pos))
    if i == j or not np.isfinite(s[j]):
        return float(s[j])
    return float(s[i] + (pos - i) * (s[j] - s[i]))
