"""The decay cells solved on one compiled problem (issue 36, item 4): a cell
solved on the shared :class:`CellFamily` is the cell's own problem (same
blocks, same decision, same margins up to the solver's tolerance), and the
deterministic cap of the decay search decides before the wall-clock one."""
from __future__ import annotations

import math

import numpy as np
import pytest

from workbench.lmi import requirements_decay as rd
from workbench.lmi.core import Outcome
from workbench.lmi.requirements_decay import CellFamily, CellLMI, cell_family

#: The pendulum loop of tests/test_requirements.py (K = [-2.622, -2.615]),
#: shifted by alpha = 1 (its certified decay is about 1.3 1/s on [0, 0.3] s).
A = np.array([[0.0, 1.0], [1.0, 0.0]]) + np.eye(2)
AD = np.array([[0.0], [1.0]]) @ np.array([[-2.622, -2.615]])


def _cell(betas, h_a, N=2, family=None):
    return CellLMI(A, AD, betas, h_a, N, family=family)


@pytest.mark.parametrize("h_a, h_b, N", [(0.0, 0.05, 2), (0.1, 0.15, 2), (0.1, 0.15, 1)])
def test_family_blocks_are_the_cells_blocks(h_a, h_b, N):
    """At any point (Theta, S, R), every block of the compiled family loaded
    with a cell equals that cell's own block (numpy), in the same order: the
    parametrisation is the cell's affine function, not another criterion."""
    betas = (math.exp(h_a), math.exp(h_b))
    fam = CellFamily(2, N)
    cell = _cell(betas, h_a, N, fam)
    cell.set_delay(h_b)
    rng = np.random.default_rng(36)
    values = {}
    for k, v in fam._vars.items():
        X = rng.standard_normal(v.shape)
        values[k] = X + X.T
        v.value = values[k]
    own = rd.MarginLMI.evaluate_blocks(cell, values, h_b)
    shared = fam.blocks(fam._vars, fam._params, None)
    assert [b.name for b in shared] == [b.name for b in own]
    for s, o in zip(shared, own):
        assert s.sense == o.sense
        ref = np.asarray(o.matrix, float)
        np.testing.assert_allclose(s.matrix.value, ref, rtol=0, atol=1e-12 * np.abs(ref).max())


@pytest.mark.parametrize("h_a, h_b", [(0.0, 0.05), (0.1, 0.15), (0.25, 0.3), (0.5, 2.0)])
def test_shared_cell_decides_like_a_fresh_cell(h_a, h_b):
    """Same outcome, optimal margin t* and re-checked margins (solver tolerance:
    Clarabel's 1e-8 gap on blocks of unit size) as a fresh CellLMI; [0.5, 2] s
    is refuted by both (the exact margin of this loop is below 0.5 s)."""
    betas = (math.exp(h_a), math.exp(h_b))
    fresh = _cell(betas, h_a).solve_at(h_b)
    shared = _cell(betas, h_a, family=cell_family(2, 2)).solve_at(h_b)
    assert shared.outcome is fresh.outcome
    assert (fresh.outcome is Outcome.REFUTED) == (h_b == 2.0)
    assert shared.solver_status == fresh.solver_status == "optimal"
    assert shared.t_opt == pytest.approx(fresh.t_opt, rel=1e-4, abs=1e-8)
    if fresh.outcome is Outcome.CERTIFIED:
        assert set(shared.recheck) == set(fresh.recheck)
        assert min(shared.recheck.values()) >= 1e-7
        assert min(shared.recheck.values()) == pytest.approx(min(fresh.recheck.values()),
                                                             rel=1e-4)


def test_family_of_another_size_is_refused():
    with pytest.raises(ValueError, match="family of size"):
        _cell((1.0, 1.1), 0.0, 2, CellFamily(3, 2))


def test_search_cell_cap_is_deterministic(monkeypatch):
    """Past MAX_SEARCH_CELLS cells the rate is INCONCLUSIVE with the cap as its
    reason (a count, whatever the machine's speed)."""
    monkeypatch.setattr(rd, "MAX_SEARCH_CELLS", 3)
    br = rd.certified_decay([(A - np.eye(2), AD)], h_lo=0.0, H=0.3, alpha_hi=10.0)
    assert any("cap of 3 delay cells" in s.solver_status for s in br.steps)
    assert sum(s.outcome is not Outcome.INCONCLUSIVE for s in br.steps) <= 3
