"""The digital implementation of a ``delay-feedback`` design: the largest
sampling interval its gain tolerates on top of the plant's input delay,
certified (LMI, every interval and delay sequence) and exact (periodic).

Loop: the nominal linearisation x' = A x + B u, u(t) = K x(t_k) held (ZOH)
from t_k + h + tau_k, h the design's input delay (constant, in
[delay.min, delay.max]) and tau_k the network delay of the table below. The
plant delay and the network delay add, so the study calls
:func:`workbench.digital.implementation` with the total delay range
[h_min + tau_min, h_max + tau_max] (the input-delay criterion: the loop is
x' = A x + B K x(t - d(t)), d(t) in [h_min + tau_min, h_max + tau_max + T_max]).
The vertices of a robust design are not covered (nominal plant only).

Design table (optional; absent: no implementation section)::

    [implementation]
    sampling = 0.05               # s: a period T, or [T_min, T_max] (aperiodic)
    network_delay = [0.0, 0.01]   # s (default [0, 0])
    hold = "zoh"                  # the only hold implemented

Claimable quantities: ``implementation.T_certified``, ``.T_exact`` (first
unstable constant period at the total delays' ends), ``.ratio``,
``.outcome``, ``.rate_certified`` (1 / T_certified, Hz).

:func:`predictor_sampling`: a loop whose commands reach the plant a known
loop delay late, certified with a predictor covering it (a delay-free
sampled loop) and without (the delay, plus a measurement delay, as a
network delay); :func:`published_row_sampling`: the same with a printed
row's gain and delay bound. Test on a system of no paper:
``tests/test_sampled_implementation.py``.
This module's top level stays light (the design reader imports it).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["ImplementationSettings", "load_implementation_settings", "run_implementation",
           "implementation_quantity_names", "implementation_quantities",
           "render_implementation_section", "PredictorSampling", "predictor_sampling", "published_row_sampling"]

#: Grid of the (T, tau) stability map of the figure, and the largest input queue drawn.
MAP_T, MAP_TAU, MAP_QUEUE = 48, 36, 120
#: Declared ranges (issue 32): the sampling period T (s) and the network delay (s).
T_RANGE, TAU_MAX = (1e-6, 1e3), 1e3


@dataclass(frozen=True)
class ImplementationSettings:
    """The design's ``[implementation]`` table."""

    sampling: object            # float (period) or (T_min, T_max)
    network_delay: tuple[float, float]
    hold: str


@dataclass(frozen=True)
class DesignImplementation:
    """The result: the API result, the total delay range and the (T, tau) map."""

    settings: ImplementationSettings
    delays: tuple[float, float]       # total delay range (s)
    result: object                    # workbench.digital.ImplementationResult
    T_axis: tuple
    tau_axis: tuple
    radius: tuple                     # rows over tau, columns over T; nan: not computed


def load_implementation_settings(root) -> ImplementationSettings | None:
    """Read ``[implementation]`` from a design (a :class:`workbench.reader.Reader`)."""
    if not root.has("implementation"):
        return None
    t = root.table("implementation")
    raw = t.raw("sampling")
    lo, hi = T_RANGE
    if isinstance(raw, list):
        lo_hi = t.numbers("sampling", min_len=2, what="interval ends (s)")
        if len(lo_hi) != 2 or not 0 <= lo_hi[0] <= lo_hi[1] or not lo <= lo_hi[1] <= hi:
            raise t.fail("sampling", raw, f"a period T in [{lo:g}, {hi:g}] or [T_min, T_max] "
                         f"with 0 <= T_min <= T_max, T_max in [{lo:g}, {hi:g}] (s)")
        sampling = lo_hi
    else:
        sampling = t.number("sampling", lo=lo, hi=hi, what="period (s) or [T_min, T_max]")
    nd = t.numbers("network_delay", default=(0.0, 0.0), min_len=2, what="delays (s)")
    if len(nd) != 2 or not 0 <= nd[0] <= nd[1] <= TAU_MAX:
        raise t.fail("network_delay", list(nd),
                     f"[tau_min, tau_max] with 0 <= tau_min <= tau_max <= {TAU_MAX:g} (s)")
    hold = t.string("hold", default="zoh", choices=("zoh",))
    t.finish()
    return ImplementationSettings(sampling, (float(nd[0]), float(nd[1])), hold)


def _stability_map(A, B, K, T_top: float, tau_top: float):
    import numpy as np

    from ..margins.sampled import lifted_map, spectral_radius
    from ..printed_grid import quantised
    Ts = np.linspace(T_top / MAP_T, T_top, MAP_T)
    taus = np.linspace(0.0, tau_top, MAP_TAU)
    rho = np.full((MAP_TAU, MAP_T), np.nan)
    for i, tau in enumerate(taus):
        for j, T in enumerate(Ts):
            if tau / T <= MAP_QUEUE:
                rho[i, j] = spectral_radius(lifted_map(A, B, K, float(T), float(tau)))
    # drawn to 0.001 (an eighth of a colour level over [0, 2]): the same map on every CPU
    rho = quantised(rho, scale=1.0)
    return tuple(map(float, Ts)), tuple(map(float, taus)), tuple(map(tuple, rho.tolist()))


def run_implementation(settings: ImplementationSettings, delay, A, B, K) -> DesignImplementation:
    """Certify and check the design's gain K on the nominal (A, B); ``delay`` is
    the design's DelaySpec (h_min, h_max)."""
    from ..digital import implementation
    from ..printed_grid import axis_end
    tau = settings.network_delay
    total = (delay.h_min + tau[0], delay.h_max + tau[1])
    res = implementation(A, K, B=B, sampling=settings.sampling, network_delay=total,
                         hold=settings.hold)
    req = res.sampling[1] if res.sampling else 0.0
    top = max(res.T_certified, req)
    if math.isfinite(res.first_unstable):
        top = max(top, res.first_unstable)
    # axis ends on a 2-digit grid (first_unstable is an exact value with noisy last bits)
    T_top = axis_end(1.25 * top) if top > 0 else 1.0
    Ts, taus, rho = _stability_map(A, B, K, T_top, axis_end(1.25 * max(total[1], 1e-3)))
    return DesignImplementation(settings, total, res, Ts, taus, rho)


def implementation_quantity_names(spec) -> set:
    """Claimable quantities when the design has an ``[implementation]`` table."""
    return {f"implementation.{k}" for k in
            ("T_certified", "T_exact", "ratio", "outcome", "rate_certified")}


def implementation_quantities(di: DesignImplementation) -> dict:
    return {f"implementation.{k}": v for k, v in di.result.quantities().items()}


def render_implementation_section(spec, di: DesignImplementation) -> tuple[str, tuple]:
    """(Markdown section, figures) of the implementation check."""
    from ..digital import render_markdown
    from ..report.markdown import Figure, fmt, fmt_floor, md_table
    r, (d0, d1) = di.result, di.delays
    cert = fmt_floor(r.T_certified, 3) if r.T_certified > 0 else "0"
    cert = f"≥ {cert} (search cap)" if r.at_cap else cert
    q = r.quantities()
    rows = [["certified T_max (every interval sequence, every delay in range)", cert,
             "lowest certified rate (Hz): " + (fmt(q["rate_certified"], 3)
                                               if r.T_certified > 0 else "—")],
            ["exact: first unstable constant period", fmt(r.first_unstable, 4), "lifted map"],
            ["ratio certified / exact", "—" if math.isnan(r.ratio) else
             fmt_floor(r.ratio, 3) if r.ratio > 0 else "0", ""]]
    text = (
        "## Digital implementation\n\n"
        "Loop: the nominal linearisation with u(t) = K x(t_k) held (zero-order hold) from "
        f"t_k + d_k, d_k the plant's input delay plus the network delay: d_k in "
        f"[{fmt(d0)}, {fmt(d1)}] s (design delay [{fmt(spec.delay.h_min)}, "
        f"{fmt(spec.delay.h_max)}] s + network [{fmt(di.settings.network_delay[0])}, "
        f"{fmt(di.settings.network_delay[1])}] s). The certificate is the input-delay approach "
        "(Fridman 2010): the held input is K x(t − d(t)) with d(t) in [d_min, d_max + T_max] "
        "for any interval and delay sequence (packets in order), proved by the "
        "time-varying-delay LMI of `workbench.lmi.varying` (unknown derivative). The exact "
        "check is the spectral radius of the lifted one-period map at constant period and "
        "delay (no LMI). Robust vertices are not covered; the decay rate of the synthesis is "
        "not carried by this criterion (stability only).\n\n"
        + md_table(["", "s", "note"], rows, "lrl") + "\n\n" + render_markdown(r)
        + "\n\n![implementation]({figdir}/implementation.png)\n\n"
        "The figure shows the spectral radius of the lifted map over constant (T, delay) "
        "(stable where it is below 1, the black line), and the certified region "
        "(hatched: constant T and delay d with d >= d_min and T + d <= "
        "d_max + T_certified; the certificate itself covers every interval sequence up to "
        "T_certified with every delay sequence in [d_min, d_max]).\n")
    fig = Figure("implementation", "Exact periodic stability over (T, delay) and the "
                 "certified region.", lambda f, d=di: _plot(f, d), (6.4, 4.4))
    return text, (fig,)


@dataclass(frozen=True)
class PredictorSampling:
    """Certified sampling of u = K x(t_k), held (ZOH), with and without a
    predictor over the loop delay ``h`` (:func:`predictor_sampling`)."""

    K: object
    h: float
    measurement_delay: float
    predictor: object          # ImplementationResult, delay-free
    delayed: object            # ImplementationResult, network delay [h, h + measurement_delay]

    @property
    def rate_delayed(self) -> float:
        """Certified lowest control rate without a predictor (Hz)."""
        return 1.0 / self.delayed.T_certified


def predictor_sampling(A, B, K, h: float, measurement_delay: float) -> PredictorSampling:
    """Certified lowest control rates of the loop x' = A x + B u, u = K x(t_k)
    held, whose commands reach the plant ``h`` s after the sample.

    **With the predictor** (exact prediction over the loop delay): the plant
    sees K x(s_k) from s_k on, a delay-free sampled loop, certified for every
    interval sequence by :mod:`workbench.lmi.sampled`. **Without a
    predictor**: the command arrives ``h`` plus ``measurement_delay`` late,
    certified by the input-delay approach (:func:`workbench.digital.implementation`
    with that network delay).
    """
    import numpy as np

    from ..digital import implementation
    A, B = np.asarray(A, float), np.asarray(B, float)
    K = np.asarray(K, float).reshape(B.shape[1], -1)
    return PredictorSampling(K, h, measurement_delay, implementation(A, K, B=B),
                             implementation(A, K, B=B, network_delay=(h, h + measurement_delay)))


def published_row_sampling(A, B, published, eps: float,
                           measurement_delay: float) -> PredictorSampling:
    """:func:`predictor_sampling` of the loop (A, B) closed with the printed
    row ``eps`` of ``published``
    (:class:`workbench.features.published_rows.Published`, its gain K and its
    delay bound h_m as the loop delay); ValueError when no row has this eps."""
    rows = [p for p in published if p.eps == eps]
    if not rows:
        raise ValueError(f"no printed row [[synthesis.published]] with eps = {eps:g}")
    return predictor_sampling(A, B, rows[0].K, rows[0].h_m, measurement_delay)


def _plot(fig, di: DesignImplementation) -> None:
    import numpy as np
    ax = fig.add_subplot(1, 1, 1)
    T, tau = np.array(di.T_axis), np.array(di.tau_axis)
    rho = np.array(di.radius, dtype=float)
    mesh = ax.pcolormesh(T, tau, np.minimum(rho, 2.0), shading="auto", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="spectral radius (clipped at 2)")
    if np.nanmin(rho) < 1 < np.nanmax(rho):
        ax.contour(T, tau, rho, levels=[1.0], colors="k", linewidths=1.2)
    r, (d0, d1) = di.result, di.delays
    if r.T_certified > 0:
        h2 = d1 + r.T_certified
        xs = [0, h2 - d0, 0]           # d(t) in [d, T + d] within [d0, h2]
        ys = [d0, d0, h2]
        ax.fill(xs + [0], ys + [d0], facecolor="none", edgecolor="w", hatch="//",
                label=f"certified (T + d <= {h2:.3g} s)")
    ax.axhspan(d0, d1, color="w", alpha=0.15, label="design delay range")
    ax.set_xlabel("sampling period T (s)")
    ax.set_ylabel("total delay d (s)")
    ax.set_xlim(0, T[-1])
    ax.set_ylim(0, tau[-1])
    ax.legend(loc="upper right", fontsize=8)

