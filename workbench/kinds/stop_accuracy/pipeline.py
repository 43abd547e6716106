"""The stop-error pipeline shared by every station-stop study (papers 000 and
004, and the ``stop-accuracy`` kind): one implementation of

* the brake plant's ``[plant]`` table (:func:`read_brake_plant`);
* uncertain factors and how they act on the plant (:class:`Factor`,
  :func:`apply_factors`): a factor scales brake parameters, or is the station
  gradient, or changes the load-weighing gain (force error, mass ratio);
* the stopping point of a held command (:func:`open_loop_distance`);
* the stop-error statistics of runs grouped by case (:func:`group_statistics`,
  on :func:`workbench.features.montecarlo.stop_statistics`).

The plant is the electro-pneumatic brake of paper 000
(:mod:`workbench.plants.brake000`, simulated by
:func:`workbench.sim.stopping.simulate`): two transmission delays with
linear interpolation and the electric/air hand-over cap falling at ``k_bra``
are not expressible in the text plants of ``delay-feedback`` (one input delay,
smooth right-hand sides), so the design names this model and writes its
parameters, each with its SI unit checked.

References
----------
Paper 000 (brake model, Table 1); paper 004 section 1.3 (stop errors).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...features.montecarlo import stop_statistics
from ...plants.brake000 import PARAMETER_UNITS
from ...reader import Reader

__all__ = ["EFFECTS", "LAW_NAMES", "Factor", "apply_factors", "group_statistics", "open_loop_distance",
           "read_brake_plant"]

#: Names every law of the ``stop-accuracy`` kind may use: name -> unit.
LAW_NAMES = {"x": "m", "v": "m/s", "decel": "m/s^2", "d_go": "m", "D": "m", "v0": "m/s",
             "t": "s"}
#: How a factor acts: scales brake parameters (ratio, nominal 1), is the station
#: gradient (permille, nominal 0), adds to the load-weighing gain (kappa = 1 + x,
#: nominal 0), or divides it (true / estimated mass: kappa = 1 / x, nominal 1).
EFFECTS = ("scale", "gradient", "force_error", "mass_ratio")


@dataclass(frozen=True)
class Factor:
    """One uncertain factor.

    Attributes
    ----------
    name : str
    effect : {"scale", "gradient", "force_error", "mass_ratio"}
    parameters : tuple of str
        Brake parameters a ``scale`` factor multiplies (in order).
    what, unit : str
        Description and unit, for the report.
    """

    name: str
    effect: str
    parameters: tuple[str, ...] = ()
    what: str = ""
    unit: str = "1"

    @property
    def nominal(self) -> float:
        return 0.0 if self.effect in ("gradient", "force_error") else 1.0

    @property
    def positive(self) -> bool:
        """A positive ratio (its distribution must stay above 0)."""
        return self.effect in ("scale", "mass_ratio")


def read_brake_plant(root: Reader) -> dict:
    """The ``[plant]`` table: ``model = "brake-000"`` and every brake parameter
    with its SI unit (name -> :class:`~workbench.reader.Quantity`)."""
    plant = root.table("plant")
    plant.string("model", choices=("brake-000",))
    params = {k: plant.quantity(k, u, nonneg=k in ("v_ho", "d1", "d2"), positive=k not in
                                ("v_ho", "d1", "d2")) for k, u in PARAMETER_UNITS.items()}
    plant.finish()
    return params


def apply_factors(base: dict, factors, values: dict, n: int):
    """Brake-parameter overrides, gradient and load-weighing gain of ``n`` runs.

    Parameters
    ----------
    base : dict
        Nominal brake parameters (floats).
    factors : iterable of Factor
        In order: a parameter scaled by two factors is ``base * f1 * f2``.
    values : dict
        Factor name -> array of shape (n,) (a factor left out is nominal).

    Returns
    -------
    overrides, theta, kappa
        For :func:`workbench.sim.stopping.batch_params` and ``simulate``.
    """
    over, theta, kappa = {}, np.zeros(n), np.ones(n)
    for f in factors:
        if f.name not in values:
            continue
        x = values[f.name]
        if f.effect == "scale":
            for p in f.parameters:
                over[p] = over.get(p, base[p]) * x
        elif f.effect == "gradient":
            theta = x
        elif f.effect == "force_error":
            kappa = 1 + x
        else:
            kappa = 1.0 / x
    return over, theta, kappa


def open_loop_distance(base: dict, command: float, v0: float, *, dt: float,
                       dt_ctrl: float) -> float:
    """Stopping distance (m) of the nominal plant from ``v0`` (m/s) under the
    held ``command`` (m/s^2): the stopping point of paper 004 section 1."""
    from ...sim.stopping import batch_params, simulate
    p = batch_params(base, 1)
    tr = simulate(p, lambda t, o: np.full(1, command), n=1, t_end=200.0, dt=dt, dt_ctrl=dt_ctrl,
                  v0=v0)
    return float(tr.x_stop[0])


def group_statistics(errors, cases, samples: int, tolerance: float) -> dict:
    """{case: StopStatistics} of the stop errors (m) of ``len(cases)``
    consecutive blocks of ``samples`` runs."""
    err = np.asarray(errors, float)
    return {c: stop_statistics(err[i * samples:(i + 1) * samples], tolerance)
            for i, c in enumerate(cases)}
