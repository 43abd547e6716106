"""The five findings of the seeded fuzz run (``test_fuzz_full``, seed 32) on the
merged tree, one fast regression each (issue 32, item 1), and the guarded
solve of the sampled-data LMIs (a solver panic is INCONCLUSIVE).

Fuzz runs 9, 18, 123, 141 and 190 of ``tests/fuzz_designs.campaign(32, 300)``:
each mutation is rebuilt here from the shipped design (one value replaced).
"""
import math
from pathlib import Path

import numpy as np
import pytest

from workbench.cli import main
from workbench.lmi.core import Outcome

ROOT = Path(__file__).resolve().parents[1]


def _exit2(tmp_path, capsys, design, old, new, argv=("verify",)):
    text = (ROOT / "designs" / f"{design}.toml").read_text()
    assert text.count(old) >= 1, old
    p = tmp_path / f"{design}.toml"
    p.write_text(text.replace(old, new, 1))
    code = main([*argv, str(p)])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1 and err.startswith("error: ") and "Traceback" not in err
    return err


def test_run9_a_zero_adhesion_vertex_names_the_equation(tmp_path, capsys):
    """mu = -0.0 at a vertex: F_max tanh(m0 a / F_max) is finite (0) but its
    derivative in a is not; it was a sympy KeyError 'ComplexInfinity' while
    printing the Jacobian (``report``)."""
    err = _exit2(tmp_path, capsys, "train-brake-lag-delay-feedback", "m = 4.0e5\nmu = 0.212",
                 "m = 4.0e5\nmu = -0.0")
    assert "equations.v" in err and "vertices[light_wet]" in err and "d/da" in err


def test_run18_a_scenario_delay_beyond_its_horizon(tmp_path, capsys):
    """A scenario's h = 1e308: OverflowError in sim/history.split_delay (``verify``)."""
    err = _exit2(tmp_path, capsys, "wheel-slip-burckhardt-delay-feedback", "h = 0.04\nt_end",
                 "h = 1e308\nt_end")
    assert "scenarios[0].h = 1e+308" in err and "at most 3" in err


def test_split_delay_refuses_an_absurd_ratio():
    from workbench.sim.history import split_delay
    with pytest.raises(ValueError, match="at most 1e9 steps"):
        split_delay(1e308, 0.002)


def test_run123_a_denormal_delay_range(tmp_path, capsys):
    """[requirements] delay = [5e-324, 0.5]: LinAlgError (inf/NaN) in
    margins/spectrum.rightmost_roots (``synthesize``)."""
    err = _exit2(tmp_path, capsys, "two-train-spacing-delay-feedback",
                 "delay = [0.1, 0.5]", "delay = [5e-324, 0.5]", ("synthesize", "delay-bound"))
    assert "requirements.delay = [5e-324, 0.5]" in err and "[1e-06, 1000]" in err


def test_rightmost_roots_of_a_denormal_delay_is_not_converged():
    from workbench.margins import SpectrumNotConverged, rightmost_roots
    with pytest.raises(SpectrumNotConverged, match="overflows"):
        rightmost_roots([[-1.0]], [[0.5]], 5e-324)


@pytest.mark.parametrize("old, new, words", [
    ("decay_rate = { value = 0.2,", "decay_rate = { value = 1e308,",
     ["requirements.decay_rate.value = 1e+308", "in [1e-06, 1000]"]),
    ("input_limit = { u = { value = 0.9,", "input_limit = { u = { value = 1e-300,",
     ["requirements.input_limit.u.value = 1e-300", "in [1e-09, 1e+09]"]),
    ("sampling = 0.1 ", "sampling = 1e-300 ",
     ["implementation.sampling = 1e-300", "in [1e-06, 1000]"]),
    ("network_delay = [0.0, 0.02]", "network_delay = [0.0, 1e308]",
     ["implementation.network_delay", "tau_max <= 1000"]),
])
def test_requirement_and_implementation_ranges(tmp_path, capsys, old, new, words):
    err = _exit2(tmp_path, capsys, "train-brake-lag-delay-feedback", old, new)
    for w in words:
        assert w in err, (w, err)


def test_run190_an_inf_jacobian_trajectory_is_undecided():
    """A basin start where the vector field overflows (wheel speed 1e-9 rad/s):
    Radau's LU of an inf/NaN Jacobian raised ValueError (``report``)."""
    from workbench.features.basin import _trajectory
    fn = lambda x, y: (1.0 / x ** 40, -y)            # noqa: E731 - overflows near x = 0
    V = lambda X: np.sum(X ** 2, axis=1)             # noqa: E731
    tr = _trajectory(fn, (1e-9, 1.0), V, 1.0, ([-10.0, -10.0], [10.0, 10.0]), 1.0)
    assert tr.fate in ("undecided", "leaves the domain")


def test_run141_decay_cells_are_capped(monkeypatch):
    """The decay search has a cell cap and a wall-clock cap (INCONCLUSIVE with the
    cap as reason); run 141 (a claim value, 0.1 -> 2) spent over 120 s in the
    design's own decay search on a loaded machine."""
    from workbench.lmi import requirements_decay as rd
    A, Ad = np.array([[-1.0]]), np.array([[0.5]])
    step = rd._decide([(A, Ad)], 1e4, 0.0, 10.0, 2, 1e-7)
    assert step.outcome is Outcome.INCONCLUSIVE and "above the cap of 400" in step.solver_status
    monkeypatch.setattr(rd, "MAX_SECONDS", 0.0)
    br = rd.certified_decay([(A, Ad)], h_lo=0.0, H=1.0, alpha_hi=1.0)
    assert br.outcome is Outcome.INCONCLUSIVE
    assert any("wall-clock cap" in s.solver_status for s in br.steps)


# -- item 2: the sampled-data LMIs go through the guarded solve -------------------------
class PanicException(BaseException):
    """Stands for pyo3_runtime.PanicException (Clarabel's Rust panic)."""


def _panic(self, *a, **kw):
    raise PanicException("SVD error")


def test_a_panic_in_the_sampled_lmis_is_inconclusive(monkeypatch):
    import cvxpy as cp

    from workbench.lmi.sampled import certified_sampling_bound
    from workbench.lmi.sampled_synthesis import synthesize_sampled_gain
    monkeypatch.setattr(cp.Problem, "solve", _panic)
    A, B, K = np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [1.0]]), np.array(
        [[-1.0, -1.5]])
    sb = certified_sampling_bound(A, B, K, T_hi=1.0)
    assert sb.bracket.outcome is Outcome.INCONCLUSIVE and sb.bracket.h_certified == 0.0
    assert all(s.solver_status == "error: solver panic: SVD error" for s in sb.bracket.steps)
    K2, status, t = synthesize_sampled_gain(A, B, 0.5)
    assert K2 is None and status == "error: solver panic: SVD error" and t is None


# -- item 3: API messages --------------------------------------------------------------
@pytest.mark.parametrize("h_max", [1e308, 1e-300, math.inf])
def test_api_h_max_range_is_the_clis(h_max):
    import workbench
    U, B = np.array([[0.0, 1.0], [2.0, -1.0]]), np.array([[0.0], [1.0]])
    with pytest.raises(ValueError, match=r"h_max = .*; expected a number \(s\) in "
                                         r"\[0\.001, 10000\]"):
        workbench.delay_bound(U, B, method="wirtinger", h_max=h_max)


def test_api_refuses_a_feedthrough():
    import control

    import workbench
    sys = control.ss([[0, 1], [2, -1]], [[0], [1]], [[1, 0]], [[0.5]])
    with pytest.raises(ValueError, match="D != 0"):
        workbench.delay_bound(sys, method="wirtinger")


def test_antiskid_run_simulate_writes_csv(tmp_path, capsys):
    out = tmp_path / "run.csv"
    assert main(["simulate", str(ROOT / "designs" / "antiskid-run-dry.toml"), "--csv",
                 str(out)]) == 0
    lines = out.read_text().splitlines()
    assert lines[0] == "t_s,v,lambda,u,u_applied" and len(lines) > 100
    t = [float(ln.split(",")[0]) for ln in lines[1:4]]
    assert t == pytest.approx([0.0, 0.01, 0.02])


@pytest.mark.slow
def test_run32_no_certified_row_draws_no_loop_figure(tmp_path, capsys):
    """Seed-32 campaign of 2026-11-27, run 32: adhesion a = 2 leaves no eps row
    with a certified gain; ``report`` raised ValueError (max of an empty
    sequence) drawing the loop figure. Now the report has no loop figure."""
    text = (ROOT / "designs" / "antiskid-cruise-dry.toml").read_text()
    old = 'a    = { value = 0.3315,'
    assert old in text
    d = tmp_path / "d"
    d.mkdir()
    (d / "antiskid-cruise-dry.toml").write_text(text.replace(old, 'a    = { value = 2,', 1))
    code = main(["report", str(d / "antiskid-cruise-dry.toml"), "--out", str(tmp_path / "r")])
    assert code in (0, 1), capsys.readouterr().err
    figs = sorted(p.name for p in (tmp_path / "r" / "antiskid-cruise-dry").iterdir())
    assert figs == ["delay-bound-vs-eps.png"]
