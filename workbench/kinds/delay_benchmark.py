"""Study ``delay-benchmark``: every delay LMI on literature examples with
known exact margins (the computation is :mod:`workbench.benchmark`).

Design tables read here: ``[benchmark]`` (settings, see
:class:`~workbench.benchmark.BenchmarkSettings`; ``examples`` names a folder
of example files relative to the design). Quantities (for claims), with
``<ex>`` an example name and ``<m>`` a method name:

* ``examples[<ex>].exact_margin`` / ``.exact_margin_sweep`` (s, two methods),
  ``.exact_agreement`` (the relative difference as the power of ten it stays
  below, floored at 1e-12: :func:`agreement_bound`);
* ``examples[<ex>].<m>.h_certified`` / ``.ratio`` / ``.exact_check`` (the
  **point** certificate: stable at h_certified), ``.interval_lo`` /
  ``.interval_hi`` / ``.interval_ratio`` (the **interval** certificate:
  stable for every constant delay in [lo, hi]; None when none; ends to 4
  significant digits rounded inwards, ratio of the rounded end truncated to
  4 decimals), with
  ``<m>`` one of the methods, ``bessel-legendre[N=k]`` or
  ``bessel-legendre-auto`` (plus ``.N`` for the order reached);
* ``examples[<ex>].windows`` (number of exact stable windows in [0, h_max]),
  ``examples[<ex>].window[<k>].lo`` / ``.hi`` (s, k = 1, 2, ...);
* ``examples[<ex>].bessel-legendre.monotone`` ("yes"/"no");
* ``suite.max_ratio`` (largest end of a certified interval [0, hi] over h*,
  finite margins; points are not margins);
* ``suite.sound`` ("yes" when every certified point lies in an exact stable
  window and every certified interval inside one);
* ``suite.exact_methods_agree`` ("yes" when the two exact methods agree on
  every example within :data:`~workbench.margins.AGREEMENT_RTOL`, else "no").

"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..benchmark import (AUTO, BenchmarkResult, BenchmarkSettings, Example, agreement_bound,
                         load_examples, load_settings, run_benchmark)
from ..benchmark_windows import directed, printed_ratio
from ..reader import Reader

FIELDS = ("h_certified", "ratio", "exact_check", "interval_lo", "interval_hi",
          "interval_ratio")
#: Window quantities exist for k = 1..MAX_WINDOWS.
MAX_WINDOWS = 4


@dataclass(frozen=True)
class BenchmarkSpec:
    settings: BenchmarkSettings
    examples: tuple[Example, ...]


def _method_keys(s: BenchmarkSettings) -> list[str]:
    keys = [m for m in s.methods if m != "bessel-legendre"]
    if "bessel-legendre" in s.methods:
        keys += [f"bessel-legendre[N={N}]" for N in range(s.orders + 1)] + [AUTO]
    return keys


def _row_key(r) -> str:
    return f"bessel-legendre[N={r.N}]" if r.method == "bessel-legendre" else r.method


class DelayBenchmark:
    kind = "delay-benchmark"
    #: its spec reads the example folder too (:func:`workbench.design.load_design`
    #: validates such a design again on every load)
    reads_other_files = True

    def load(self, root: Reader) -> BenchmarkSpec:
        settings = load_settings(root.table("benchmark"))
        folder = Path(root.path).parent / settings.examples
        return BenchmarkSpec(settings, load_examples(folder))

    def quantity_names(self, spec: BenchmarkSpec) -> set[str]:
        names = {"suite.max_ratio", "suite.exact_methods_agree", "suite.sound"}
        for e in spec.examples:
            base = f"examples[{e.name}]"
            names |= {f"{base}.exact_margin", f"{base}.exact_margin_sweep",
                      f"{base}.exact_agreement", f"{base}.bessel-legendre.monotone",
                      f"{base}.{AUTO}.N", f"{base}.windows"}
            names |= {f"{base}.window[{k}].{e}" for k in range(1, MAX_WINDOWS + 1)
                      for e in ("lo", "hi")}
            names |= {f"{base}.{k}.{f}" for k in _method_keys(spec.settings) for f in FIELDS}
        return names

    def run(self, design) -> BenchmarkResult:
        return run_benchmark(design.spec.examples, design.spec.settings)

    def quantities(self, res: BenchmarkResult) -> dict:
        q = {"suite.max_ratio": res.max_ratio(),
             "suite.exact_methods_agree": "yes" if res.exact_agree else "no",
             "suite.sound": "yes" if res.sound else "no"}
        for e in res.examples:
            base = f"examples[{e.example.name}]"
            q[f"{base}.exact_margin"] = e.exact.h
            q[f"{base}.exact_margin_sweep"] = e.exact_sweep.h
            q[f"{base}.exact_agreement"] = agreement_bound(e.agreement)
            q[f"{base}.windows"] = float(len(e.windows))
            for k, (lo, hi) in enumerate(e.windows[:MAX_WINDOWS], start=1):
                q[f"{base}.window[{k}].lo"], q[f"{base}.window[{k}].hi"] = lo, hi
            q[f"{base}.bessel-legendre.monotone"] = \
                "yes" if e.bl_monotone(res.settings.rel_tol) else "no"
            for r in e.rows:
                k = _row_key(r)
                q[f"{base}.{k}.h_certified"] = r.h_certified   # 0: nothing certified
                q[f"{base}.{k}.ratio"] = r.ratio
                q[f"{base}.{k}.exact_check"] = r.exact_check
                lo, hi = r.interval or (None, None)      # printed digits (see module doc)
                q[f"{base}.{k}.interval_lo"] = None if lo is None else directed(lo, up=True)
                q[f"{base}.{k}.interval_hi"] = None if hi is None else directed(hi, up=False)
                q[f"{base}.{k}.interval_ratio"] = printed_ratio(r)
                if r.method == AUTO:
                    q[f"{base}.{AUTO}.N"] = float(r.N)
        return q


STUDY = DelayBenchmark()
