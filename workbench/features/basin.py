"""The basin check of a ``delay-feedback`` design: (sympy plant model,
operating point, gain) -> certified level set, sampled trajectories, claims.

The closed loop is x' = f(x, u* + K (x - x*)) with the design's parameter
values substituted: the *delay-free* loop. Under exact prediction (a
scenario with ``predictor = true``; paper 003, Lemma 1 and Theorems 2-3) the
input applied at t >= h is u* + K (x(t) - x*), so this is the predictor loop
from t = h on; without the predictor the delayed loop is another system,
whose local stability is the LMI certificate's subject, not the basin's.

V = (x - x*)' P (x - x*) with P from the Lyapunov equation
(A + B K)' P + P (A + B K) = -I (:func:`workbench.roa.lyapunov_P`). Not the
certificate's P: the delay LMI's P belongs to a Lyapunov-Krasovskii
functional of the *delayed* loop (an augmented matrix for Bessel-Legendre),
not to a Lyapunov function of the delay-free one.

Design table (optional; absent or ``enabled = false``: no basin section)::

    [basin]
    enabled = true                        # or, before the first table: basin = true
    domain = { x1 = [-1.0, 1.0] }         # box the model is meant for (states not
                                          # named: unbounded); sets the searched level
    plane = ["x1", "x2"]                  # the figure's coordinates (default: first two)
    seed = 0                              # falsifier and sampled starts

The level searched, c_search, is the largest ellipsoid {V <= c} whose
bounding box lies in the domain; without a domain, 4 x the largest level of
the scenarios' initial states. This module's top level stays light (the
design reader imports it); numpy, sympy and the solvers load when it runs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..reader import Reader

LOOP = ("delay-free closed loop x' = f(x, u* + K (x - x*)), the predictor loop from t = h on "
        "under exact prediction (scope: see the section's first paragraph)")
#: Trajectories sampled for the figure, and started on the certified level's boundary.
N_SAMPLED, N_INSIDE = 16, 8
#: The inside check starts on {V = BOUNDARY c_certified}; trajectories are Radau with RADAU_RTOL.
BOUNDARY, RADAU_RTOL = 0.999, 1e-8


@dataclass(frozen=True)
class BasinSettings:
    """The design's ``[basin]`` table (see the module docstring)."""

    domain: dict            # state -> (lo, hi)
    plane: tuple            # one or two state names
    seed: int


def basin_table(root):
    """(reader of the design's ``[basin]`` table, enabled, seed), or None when
    the design has none; a bare ``basin = true | false`` is an empty table
    (``root``: a :class:`workbench.reader.Reader`). Any design's basin table
    has ``enabled = true | false`` (default true) and ``seed`` (falsifier and
    sampled starts, default 0); the caller reads the rest and calls ``finish``."""
    if not root.has("basin"):
        return None
    raw = root.raw("basin")
    if isinstance(raw, bool):
        b, enabled = Reader(root.path, {}, root.key("basin")), raw
    elif isinstance(raw, dict):
        b = root.table("basin")
        enabled = b.boolean("enabled", default=True)
    else:
        raise root.fail("basin", raw, "true, false or a [basin] table")
    return b, enabled, int(b.number("seed", integer=True, default=0, nonneg=True, what="integer"))


def load_basin_settings(root, plant, n_scenarios: int) -> BasinSettings | None:
    """Read ``[basin]`` (or a bare ``basin = true | false``) from a design
    (a :class:`workbench.reader.Reader`); None when absent or disabled."""
    table = basin_table(root)
    if table is None:
        return None
    b, enabled, seed = table
    states = plant.state_names
    dom = b.table("domain", default=None)
    domain = {}
    for k in list(dom.data):
        if k not in states:
            raise dom.fail(k, dom.data[k], "a state: " + ", ".join(states))
        lo_hi = dom.numbers(k, min_len=2, what="range ends")
        if len(lo_hi) != 2 or not lo_hi[0] < lo_hi[1]:
            raise dom.fail(k, dom.data[k], "a range [lo, hi] with lo < hi")
        domain[k] = lo_hi
    dom.finish()
    want = min(len(states), 2)
    plane = b.raw("plane", default=list(states[:want]))
    if (not isinstance(plane, list) or len(plane) != want or len(set(map(str, plane))) != want
            or not all(isinstance(p, str) and p in states for p in plane)):
        raise b.fail("plane", plane, f"{want} different states of: " + ", ".join(states))
    b.finish()
    if not enabled:
        return None
    if not domain and n_scenarios == 0:
        raise b.fail("domain", "<missing>", "a box { state = [lo, hi], ... } (the design has "
                     "no scenario whose initial state sets the searched level)")
    return BasinSettings(domain, tuple(plane), int(seed))


def check_domain(settings: BasinSettings, path: str, names, x_op, scenarios) -> None:
    """Bad input when the operating point is not strictly inside the domain, or
    no scenario starts away from it and no domain is given (DesignError)."""
    from ..errors import DesignError
    for k, (lo, hi) in settings.domain.items():
        x = float(x_op[names.index(k)])
        if not lo < x < hi:
            raise DesignError(path, f"basin.domain.{k}", [lo, hi],
                              f"a range holding the operating point {k} = {x:.6g}")
    if not settings.domain and all(all(float(v) == float(x_op[names.index(k)])
                                       for k, v in s.x0.items()) for s in scenarios):
        raise DesignError(path, "basin.domain", "<missing>", "a box { state = [lo, hi], ... } "
                          "(no scenario starts away from the operating point)")


@dataclass(frozen=True)
class DelayFeedbackBasin:
    """Basin of a delay-feedback design (rendering: :mod:`.basin_render`).

    Attributes
    ----------
    check : workbench.roa.check.BasinCheck
        Estimate, and the verdict for each scenario's initial state.
    outcome : str
        Verdict at the searched level c_search: CERTIFIED (V' < 0 proven on
        the whole of {0 < V <= c_search}), REFUTED (a point of it has V' >= 0)
        or INCONCLUSIVE.
    plane : tuple of int
        State indices of the figure.
    box : (lo, hi)
        Box of the sampled starts: the domain, and x* +- 1.5 x the half-width of
        {V <= c_search} in the coordinates it leaves unbounded (there a trajectory
        "leaves the domain" beyond 100 x that half-width).
    sampled, inside : tuple of Trajectory
        Seeded starts in the box (and the scenarios' initial states); starts
        on the certified level's boundary {V = 0.999 c_certified}.
    inside_ok : bool or None
        Along each ``inside`` trajectory V never rose and ended below 1 % of
        its start (None: nothing certified).
    horizon : float
        Simulated time (s): 10 / |slowest eigenvalue of A + B K|.
    domain : dict
    """

    check: object
    outcome: str
    plane: tuple
    box: tuple
    sampled: tuple
    inside: tuple
    inside_ok: bool | None
    horizon: float
    domain: dict
    names: tuple


def closed_loop(model, values: dict, op, K):
    """(f_cl, states, A + B K) of the delay-free loop u = u* + K (x - x*)."""
    import numpy as np
    import sympy as sp

    K = np.atleast_2d(np.asarray(K, float))
    f = model.substituted(model.f, values)
    Fl = lambda v: sp.Float(float(v))
    law = {u: Fl(op.u[i]) + sum(Fl(K[i, j]) * (x - Fl(op.x[j])) for j, x in enumerate(model.x))
           for i, u in enumerate(model.u)}
    fx, fu = model.jacobian_functions(values)   # as the design's linearisation
    A, B = fx(op.x, op.u), fu(op.x, op.u)
    return [e.xreplace(law) for e in f], tuple(model.x), A + B @ K


def delay_feedback_basin(model, values: dict, op, K, *, points=(), c_search: float | None = None,
                         domain: tuple | None = None, seed: int = 0):
    """Certified basin of the delay-free loop of a delay-feedback design
    (:class:`workbench.roa.check.BasinCheck`).

    Parameters
    ----------
    model : PlantModel
        The design's sympy plant.
    values : dict
        Parameter values (SI).
    op : OperatingPoint
        Equilibrium (x*, u*).
    K : (m, n) array_like
        Gain, u = u* + K (x - x*).
    points : sequence of (label, state)
        States to judge (absolute coordinates).
    c_search, domain, seed
        As :func:`workbench.roa.check.check_basin` (P: the Lyapunov equation with Q = I).
    """
    from ..roa.check import check_basin
    fcl, states, A_cl = closed_loop(model, values, op, K)
    return check_basin(fcl, states, op.x, A_cl=A_cl, points=points,
                       c_search=c_search, domain=domain, names=model.spec.state_names,
                       loop=LOOP, seed=seed)


def run_basin(settings: BasinSettings, spec, model, values: dict, op, K) -> DelayFeedbackBasin:
    """The basin section's computation for a design with a certified gain K."""
    import numpy as np
    import sympy as sp

    from .basin_trajectory import decays
    names = spec.plant.state_names
    n = len(names)
    lo = np.array([settings.domain.get(k, (-math.inf, math.inf))[0] for k in names])
    hi = np.array([settings.domain.get(k, (-math.inf, math.inf))[1] for k in names])
    points = []
    for s in spec.scenarios:
        x0 = op.x.copy()
        for k, v in s.x0.items():
            x0[names.index(k)] = v
        points.append((s.name, tuple(float(v) for v in x0)))
    bounded = bool(np.isfinite(lo).any() or np.isfinite(hi).any())
    chk = delay_feedback_basin(model, values, op, K, points=points,
                               c_search=math.inf if bounded else None,
                               domain=(lo, hi) if bounded else None, seed=settings.seed)
    est = chk.estimate
    outcome = est.verdict(est.c_search).outcome
    fcl, states, A_cl = closed_loop(model, values, op, K)
    slow = float(np.min(np.abs(np.linalg.eigvals(A_cl).real)))
    horizon = float(min(10.0 / slow, 1e4))
    P, x_eq = np.array(est.P), np.array(est.x_eq)
    half = np.sqrt(est.c_search * np.diag(np.linalg.inv(P)))
    box = (np.where(np.isfinite(lo), lo, x_eq - 1.5 * half),
           np.where(np.isfinite(hi), hi, x_eq + 1.5 * half))
    escape = (np.where(np.isfinite(lo), lo, x_eq - 100 * half),
              np.where(np.isfinite(hi), hi, x_eq + 100 * half))
    fn = sp.lambdify(states, fcl, "math")
    V = lambda X: np.einsum("ni,ij,nj->n", X - x_eq, P, X - x_eq)
    plane = tuple(names.index(k) for k in settings.plane)
    rng = np.random.default_rng(np.random.SeedSequence([settings.seed, 2]))
    starts = [x for _, x in points]
    for _ in range(N_SAMPLED):
        x0 = x_eq.copy()
        x0[list(plane)] = rng.uniform(box[0][list(plane)], box[1][list(plane)])
        starts.append(tuple(x0))
    c_cert = est.c_certified
    sampled = tuple(_trajectory(fn, x0, V, c_cert, escape, horizon) for x0 in starts)
    inside, ok = (), None
    if c_cert > 0:
        L = np.linalg.cholesky(P)
        dirs = rng.standard_normal((N_INSIDE, n))
        dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
        X0 = x_eq + np.sqrt(BOUNDARY * c_cert) * dirs @ np.linalg.inv(L.T).T
        inside = tuple(_trajectory(fn, x0, V, c_cert, escape, horizon, full=True)
                       for x0 in X0)
        ok = all(decays(tr.path, V) for tr in inside)
    return DelayFeedbackBasin(chk, outcome.name, plane, (tuple(box[0]), tuple(box[1])), sampled,
                              inside, ok, horizon, dict(settings.domain), tuple(names))


def _trajectory(fn, x0, V, c_cert, box, T, *, full: bool = False):
    """The delay-free loop from x0 over [0, T] (Radau, rtol RADAU_RTOL)
    (:func:`~workbench.features.basin_trajectory.trajectory`). Ends when it
    leaves ``box`` (fate "leaves the domain": the domain, or far away), or,
    unless ``full``, when V falls below 1e-3 c_certified; "converges" when it
    entered {V <= c_certified}; "undecided" when the integrator stops on an
    inf/NaN Jacobian (a vector field not finite near x0, e.g. a scenario at a
    wheel speed of 1e-9 rad/s)."""
    import numpy as np
    from .basin_trajectory import trajectory
    lo, hi = (np.asarray(b, float) for b in box)

    def out(t, x):
        return float(np.min(np.concatenate([x - lo, hi - x])))
    out.terminal = True

    def near(t, x):
        return float(V(np.asarray(x)[None, :])[0] - 1e-3 * c_cert)
    near.terminal = True
    events = [out] if full or not c_cert > 0 else [out, near]
    inside = ((lambda p: V(p) <= c_cert) if c_cert > 0
              else (lambda p: np.zeros(len(p), bool)))
    return trajectory(fn, x0, T, inside, events=events, rtol=RADAU_RTOL)


#: Claimable quantities of any basin estimate (:func:`level_quantities`).
LEVEL_QUANTITIES = frozenset({"basin.c_certified", "basin.c_refuted"})


def level_quantities(est) -> dict:
    """The certified and refuted levels of a basin estimate."""
    return {"basin.c_certified": est.c_certified, "basin.c_refuted": est.c_refuted}


def point_quantity_names(labels, key: str, suffixes=("in_basin",)) -> set:
    """``{key}.{suffix}`` for each label (``key`` formats ``{label}``)."""
    return {f"{key.format(label=lab)}.{x}" for lab in labels for x in suffixes}


def point_quantities(check, key: str, **more) -> dict:
    """``{key}.in_basin`` (the verdict) of each judged point of a
    :class:`workbench.roa.check.BasinCheck`, then ``{key}.{name}`` for each
    keyword ``name`` = a sequence with one value per point."""
    q = {}
    for k, p in enumerate(check.points):
        at = key.format(label=p.label)
        q[f"{at}.in_basin"] = p.verdict.outcome.name
        q.update({f"{at}.{name}": vals[k] for name, vals in more.items()})
    return q


#: Key of a delay-feedback scenario's quantities.
_SCENARIO = "basin.scenario[{label}]"


def basin_quantity_names(spec) -> set:
    """Claimable quantities of the basin check (see :func:`basin_quantities`)."""
    return (set(LEVEL_QUANTITIES)
            | {"basin.c_search", "basin.outcome", "basin.certified", "basin.inside_converge"}
            | point_quantity_names([s.name for s in spec.scenarios], _SCENARIO,
                                   ("in_basin", "level")))


def basin_quantities(res: DelayFeedbackBasin) -> dict:
    """Values of :func:`basin_quantity_names` (a design without a certified
    gain has no basin: its basin claims are not determined)."""
    est = res.check.estimate
    q = level_quantities(est)
    q.update({"basin.c_search": est.c_search, "basin.outcome": res.outcome,
              "basin.certified": "yes" if est.c_certified > 0 else "no",
              "basin.inside_converge": None if res.inside_ok is None
              else ("yes" if res.inside_ok else "no")})
    q.update(point_quantities(res.check, _SCENARIO,
                              level=[est.level_bounds(p.x)[1] for p in res.check.points]))
    return q
