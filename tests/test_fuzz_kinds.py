"""Findings of the fuzz campaign re-run (issue 32, seed 3202,
``benchmarks/fuzz_campaign.py``) on the newer kinds and tables, one fast
regression each: the Python API of the Monte Carlo statistics and of the
switched-run kind, and design-file mutations of phases, guards, laws,
[montecarlo], [sampled] and [convergence].
"""
import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fuzz_designs as fz  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]

#: API misuses cheap enough for the default tier (no LMI solve).
FAST = ("runs_for", "wilson", "stop_statistics", "percentile", "load_design")


def test_api_misuse_of_the_newer_kinds_raises_one_line_value_errors():
    seen = 0
    for name, call in fz.api_cases():
        if not name.startswith(FAST):
            continue
        seen += 1
        try:
            call()
        except ValueError as exc:
            msg = str(exc)
            assert "\n" not in msg and len(msg) < 400, (name, msg)
            assert "math domain error" not in msg and "NaN to integer" not in msg, (name, msg)
        except BaseException as exc:   # noqa: BLE001 - any other exception is the failure
            pytest.fail(f"{name}: {type(exc).__name__}: {str(exc)[:300]}")
    assert seen >= 10


#: API findings of the re-run: each must now raise a ValueError before any solve.
RAISE = {"design_gain delay 1e308": "h_max in [1e-06, 1000] (s)",
         "implementation sampling 1e308": "expected a period T (s) in [1e-06, 1000]",
         "implementation T_hi 1e-300": "at least the required T_max = 0.1",
         "synthesize_sampled T_max 1e308": "expected a sampling interval (s) in [1e-06, 1000]",
         "synthesize_sampled digits 0": "significant digits in [1, 12]",
         "synthesize_sampled digits 400": "significant digits in [1, 12]",
         "design_gain input_limit 0": "input_limit[0] = 0.0; expected a positive"}


def test_api_findings_of_the_rerun_raise_with_the_range():
    """design_gain(delay=(0, 1e308)) said 'eps = nan'; implementation(sampling=1e308)
    named an internal h_lo; T_hi = 1e-300 and synthesize_sampled(T_max=1e308,
    digits=0) returned results; digits = 400 was an OverflowError."""
    cases = dict(fz.api_cases())
    for name, text in RAISE.items():
        with pytest.raises(ValueError) as exc:
            cases[name]()
        assert text in str(exc.value) and "\n" not in str(exc.value), (name, str(exc.value))


def test_runs_for_refuses_a_certain_pass_and_keeps_299():
    """runs_for(1.0) was a ZeroDivisionError, runs_for(0) 'math domain error'."""
    from workbench.kinds.switched_run.study import runs_for
    assert runs_for(0.99) == 299
    for p in (1.0, 0.0, -0.5, math.nan, math.inf):
        with pytest.raises(ValueError, match=r"runs_for: p = .*expected a probability in \(0, 1\)"):
            runs_for(p)
    with pytest.raises(ValueError, match="alpha = 0.0"):
        runs_for(0.99, 0.0)


def test_wilson_interval_names_impossible_counts():
    from workbench.features.montecarlo import wilson_interval
    assert wilson_interval(10, 10)[2] == 1.0
    assert math.isnan(wilson_interval(0, 0)[2])
    for k, n in ((11, 10), (-1, 10), (0.5, 10)):
        with pytest.raises(ValueError, match="expected whole numbers 0 <= k <= n"):
            wilson_interval(k, n)


def test_stop_statistics_of_no_runs_is_nan_not_index_error():
    """stop_statistics([]) and percentile([]) were IndexErrors."""
    from workbench.features.montecarlo import percentile, stop_statistics
    st = stop_statistics([], 0.5)
    assert st.n == 0 and math.isnan(st.p) and math.isnan(st.p95)
    assert math.isnan(percentile([], 50.0))
    assert percentile([1.0, 3.0], 50.0) == 2.0
    with pytest.raises(ValueError, match=r"q = 200.0; expected a number in \[0, 100\]"):
        percentile([1.0], 200.0)


def test_load_design_of_a_folder_says_folder():
    from workbench.design import load_design
    from workbench.errors import DesignError
    with pytest.raises(DesignError, match="<a folder>"):
        load_design(ROOT / "designs")


def _exit2(tmp_path, capsys, design, old, new):
    from workbench.cli import main
    text = (ROOT / "designs" / f"{design}.toml").read_text(encoding="utf-8")
    assert old in text, old
    p = tmp_path / f"{design}.toml"
    p.write_text(text.replace(old, new, 1), encoding="utf-8")
    code = main(["verify", str(p)])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1 and err.startswith("error: ") and "Traceback" not in err
    return err


@pytest.mark.parametrize("old, new, what", [
    ("period = 0.1", "period = 1e-300", "the control period 1e-300 s"),
    ("h = { value = 0.2,", "h = { value = 1e-300,", "the delay h = 1e-300 s"),
])
def test_a_period_or_delay_of_zero_steps_is_refused(tmp_path, capsys, old, new, what):
    """[sampled] period = 1e-300 passed the whole-multiple check (0 steps) and the
    run ended in ZeroDivisionError (step % 0) in switched_run/simulate._loop."""
    err = _exit2(tmp_path, capsys, "emu-speed-switched-run", old, new)
    assert "scenarios[0].dt = 0.05" in err and what in err and "whole multiple (>= 1)" in err


def test_an_equality_claim_on_1e308_compares_without_decimal_error():
    """Run 88: value = 1e308 with digits = 0 on a Monte Carlo claim raised
    decimal.InvalidOperation (28-digit context) in claims._printed."""
    import dataclasses

    from workbench.claims import check_claim
    from workbench.design import load_design
    from workbench.outcome import Verdict
    claim = next(c for c in load_design(ROOT / "designs" / "emu-speed-switched-run.toml").claims
                 if c.id == "run-completes")
    big = dataclasses.replace(claim, value=1e308, digits=0)
    assert check_claim(big, 1.0).verdict is Verdict.FAIL
    assert check_claim(big, 1e308).verdict is Verdict.PASS
    assert check_claim(dataclasses.replace(claim, value=-1e308, digits=12), -1e308).verdict \
        is Verdict.PASS


def test_a_denormal_tight_delay_cap_exits_2(tmp_path, capsys):
    """Run 114: [tight] h_max = 5e-324 underflowed to 0 in lmi/scaling.time_unit
    (ValueError: math domain error) under ``verify``."""
    err = _exit2(tmp_path, capsys, "antiskid-cruise-dry", "h_max = 10.0", "h_max = 5e-324")
    assert "tight.h_max = 5e-324; expected a number (s) in [0.001, 1000]" in err


@pytest.mark.parametrize("new", ["2.5", "1e-9", "nan"])
def test_a_fractional_sample_count_says_whole_number(tmp_path, capsys, new):
    """Run 118: samples = 1e-9 said 'expected a number' (it is one)."""
    err = _exit2(tmp_path, capsys, "emu-speed-switched-run", "samples = 299", f"samples = {new}")
    assert "montecarlo.samples" in err and "expected a whole number in [2, 5000]" in err


def test_a_zero_divisor_is_named_as_one_not_as_a_complex_value(tmp_path, capsys):
    """Runs 135 and 146: e = 1/(dv - dv) said 'found a complex value' (sympy's
    zoo is not real); it is a division by zero."""
    err = _exit2(tmp_path, capsys, "two-train-spacing-delay-feedback", 'e = "dv"',
                 'e = "1/(dv - dv)"')
    assert "equations.e = '1/(dv - dv)'" in err and "division by zero" in err, err


def test_a_denormal_delay_drift_rate_exits_2(tmp_path, capsys):
    """Seed 32 re-run, run 75: [requirements] rate = 5e-324 was an OverflowError
    (float infinity to integer) in requirements.simulate_varying (``synthesize``)."""
    err = _exit2(tmp_path, capsys, "two-train-spacing-delay-feedback",
                 'rate = { value = 0.1,', 'rate = { value = 5e-324,')
    assert "requirements.rate.value = 5e-324" in err and "[1e-06, 1)" in err, err
