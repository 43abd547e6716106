"""Paper 002's plant sub-steps: the compiled kernel and a batch over several
trains give exactly the bits of the numpy loop on one train (issue 36, item 4)."""
import itertools
from pathlib import Path

import numpy as np
import pytest

from workbench.design import load_design
from workbench.features.reproducible import NUDGE, nudged
from workbench.kinds.tracking import run as R
from workbench.profiles import build_profile
from workbench.sim.tracking import simulate_tracking

DESIGN = Path("designs/ato-mfac-pid-002.toml")
FIELDS = ("v", "s", "a", "u", "stop_time", "stop_pos", "traction_work")


@pytest.fixture(scope="module")
def spec():
    return load_design(DESIGN).spec


def _grid(spec, reading, sec, trains, kernel, rows=slice(None, None, 97)):
    """A thinned MFAC grid of ``reading`` on ``sec``, one block per train."""
    keys, trains = R.MFAC_KEYS, trains if isinstance(trains, tuple) else (trains,)
    P = np.array(list(itertools.product(*(reading.mfac_grid[k] for k in keys))))[rows]
    PP = np.tile(P, (len(trains), 1))
    ctl = R._mfac(reading, dict(zip(keys, PP.T)), len(PP))
    prof = build_profile(spec.profile_spec(sec), dt=spec.Ts)
    brake = float(prof.t[np.argmax(prof.a < 0)])
    return simulate_tracking(trains, sec.route, prof.speed_at, lambda k, y, yn: ctl.step(y, yn),
                             len(PP), Ts=spec.Ts, dt=spec.dt, horizon=sec.run_time + 60.0,
                             brake_start=brake, kernel=kernel), len(P)


def _same(x, y, rows=slice(None), K=None):
    for f in FIELDS:
        a, b = getattr(x, f)[rows], getattr(y, f)
        if a.ndim == 2:             # histories: the shorter batch ends first
            K = min(a.shape[1], b.shape[1])
            a, b = a[:, :K], b[:, :K]
        np.testing.assert_array_equal(a, b, err_msg=f)


@pytest.mark.parametrize("which", [0, 1])
def test_compiled_substeps_are_bit_identical_to_numpy(spec, which):
    pytest.importorskip("numba")
    reading = spec.readings[which]     # integrating (lag on acceleration), first-order (clipped)
    sec = spec.line[1]                 # three gradient sections, one down-hill
    runs = [_grid(spec, reading, sec, reading.train, k)[0] for k in ("numpy", "compiled")]
    assert np.isfinite(runs[0].stop_time).any()          # the runs reach the stop logic
    _same(*runs)


def test_a_batch_over_nudged_trains_is_each_trains_own_batch(spec):
    reading = spec.readings[1]
    trains = (reading.train, *(nudged(reading.train, s * NUDGE, keep=("delay",)) for s in (1, -1)))
    both, N = _grid(spec, reading, spec.main, trains, None)
    moved = False
    for g, tr in enumerate(trains):
        alone, _ = _grid(spec, reading, spec.main, tr, None)
        _same(both, alone, slice(g * N, (g + 1) * N))
        moved |= g > 0 and not np.array_equal(alone.traction_work, both.traction_work[:N])
    assert moved                        # the nudged trains are other trains


def test_trains_of_different_delays_are_refused(spec):
    tr = spec.readings[0].train
    other = type(tr)(**{**tr.__dict__, "delay": 0.2})
    with pytest.raises(ValueError, match="one delay"):
        simulate_tracking((tr, other), spec.main.route, lambda t: np.zeros_like(t),
                          lambda k, y, yn: np.zeros(2), 2, Ts=0.1, dt=0.01, horizon=1.0,
                          brake_start=1e9)


def test_an_unknown_kernel_is_refused(spec):
    with pytest.raises(ValueError, match="expected 'compiled' or 'numpy'"):
        simulate_tracking(spec.readings[0].train, spec.main.route, lambda t: np.zeros_like(t),
                          lambda k, y, yn: np.zeros(1), 1, Ts=0.1, dt=0.01, horizon=1.0,
                          brake_start=1e9, kernel="fortran")
