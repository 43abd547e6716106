"""Findings refined by their own study (``refine_levels``, issue 33 item 4),
paper 003's stop duration, and the noise floor of printed errors (issue 36
item 5)."""
from dataclasses import dataclass, replace

import pytest

from workbench.claims import Claim, ClaimResult, Verdict
from workbench.features.refinement import Levels
from workbench.sim.convergence import CONVERGED, INCONCLUSIVE, NOT_CONVERGED

#: benchmarks/stop_refinement.py on designs/antiskid-run-dry.toml (compensated
#: case): braking time to v_stop at dt, dt/2, dt/4 (s).
STOP_LEVELS = (85.96, 86.68, 86.14)


def _claim(cid, quantity, compare, value, tol=0.0, expect="pass", allow=False, instead=""):
    return Claim(cid, f"claim {cid}", quantity, compare, value, tol, None, "round", "workbench",
                 allow, expect, "why" if expect == "fail" else "", "minor", "workbench",
                 converged_instead=instead)


class _OwnLevels:
    """A stand-in study that refines its own parameters: ``levels`` maps a
    quantity to its Levels (a quantity left out has no three-level check)."""
    kind = "fake-own"
    refine_field, refine_unit = "dt", "s"

    def __init__(self, values, levels):
        self.values, self.levels, self.calls = values, levels, 0

    def run(self, design):
        return "result"

    def quantities(self, res):
        return dict(self.values)

    def refine_levels(self, design, result, findings):
        self.calls += 1
        assert result == "result"
        return {r.claim.id: self.levels[r.claim.quantity] for r in findings
                if r.claim.quantity in self.levels}


def _evaluate(monkeypatch, study, claims):
    from workbench import kinds, verify
    from workbench.design import Design

    @dataclass(frozen=True)
    class Spec:
        dt: float

    monkeypatch.setattr(kinds, "REGISTRY", {"fake-own": study})
    return verify.evaluate_design(Design("f.toml", "fake", "fake-own", "t", "s", Spec(0.01),
                                         tuple(claims)))


def test_stop_duration_is_inconclusive_with_its_levels_and_estimate(monkeypatch):
    study = _OwnLevels({"stop": STOP_LEVELS[1], "dist": 1790.0, "word": "yes", "bare": 1.0},
                       {"stop": Levels(STOP_LEVELS, "dt", 0.01),
                        "dist": Levels((1790.2, 1790.1, 1790.05), "plant_step", 1e-4),
                        "word": Levels(("yes", "yes", "no"), "dt", 0.01)})
    claims = [_claim("stop-duration", "stop", "within", 85.0, 0.5, expect="fail", allow=True,
                     instead="dist"),
              _claim("distance", "dist", "within", 1796.0, 20.0),
              _claim("word", "word", "==", "yes"),
              _claim("bare", "bare", "<=", 2.0)]
    ev = _evaluate(monkeypatch, study, claims)
    assert study.calls == 1
    rows = {r.claim_id: r for r in ev.refinement.rows}
    stop = rows["stop-duration"]
    # observed order log2(0.72 / 0.54) = 0.42 < 0.5: the estimate from the
    # larger difference, 0.72 / (2^0.5 - 1) = 1.74 s > 0.5 s
    assert stop.outcome == INCONCLUSIVE
    assert stop.check.order == pytest.approx(0.415, abs=0.01)
    assert stop.check.estimate == pytest.approx(1.738, abs=0.01)
    assert stop.parameter == "dt = 0.01 s"
    res = {r.claim.id: r for r in ev.claims}
    assert res["stop-duration"].verdict is Verdict.INCONCLUSIVE and res["stop-duration"].ok
    note = res["stop-duration"].note
    assert note.startswith("not converged: stop")
    assert "85.96, 86.68, 86.14 at dt, dt/2, dt/4" in note and "estimate 1.7 > tolerance 0.5" in note
    assert note.endswith("use `dist` instead")
    assert rows["distance"].outcome == CONVERGED and res["distance"].verdict is Verdict.PASS
    assert rows["distance"].parameter == "plant_step = 0.0001 s"
    # a word that changes between levels is not converged; a finding the study
    # does not refine is INCONCLUSIVE, not silently passed
    assert rows["word"].outcome == NOT_CONVERGED and res["word"].verdict is Verdict.INCONCLUSIVE
    assert "yes / yes / no at dt, dt/2, dt/4" in res["word"].note
    assert rows["bare"].outcome == INCONCLUSIVE and not res["bare"].ok
    assert res["bare"].note == ("not converged: no three-level check (its study has no "
                                "three-level check of it)")


def test_refinement_section_names_each_parameter(monkeypatch):
    from workbench.report.writer import refinement_section
    study = _OwnLevels({"stop": STOP_LEVELS[1], "bare": 1.0},
                       {"stop": Levels(STOP_LEVELS, "dt", 0.01)})
    ev = _evaluate(monkeypatch, study, [_claim("s", "stop", "within", 85.0, 0.5, "fail", True),
                                        _claim("b", "bare", "<=", 2.0)])
    text = refinement_section(ev.refinement)[0]
    assert "| finding | metric | parameter | q1 | q2 | q4 |" in text
    assert "| `s` | `stop` | dt = 0.01 s | 85.96 | 86.68 | 86.14 | 0.42 | 1.7 | 0.5 |" in text
    assert "| `b` | `bare` | — | — | — | — | — | — | — | INCONCLUSIVE: not converged: no" in text


def test_designs_without_own_levels_keep_their_table():
    """The parameter column appears only for studies that refine their own
    parameters (the reports of p000, p002, p004 keep their bytes)."""
    from workbench.features.refinement import RefinementRow, RefinementTable
    from workbench.report.writer import refinement_section
    row = RefinementRow("f", "x", (1.0, 1.1, 1.15), 0.5, CONVERGED)
    text = refinement_section(RefinementTable("dt", "s", 0.01, (row,)))[0]
    assert "| finding | metric | q1 | q2 | q4 | p | estimate | tolerance | outcome |" in text
    assert "parameter" not in text.split("\n\n")[-1]


# -- noise floor of printed errors (issue 36, item 5) --------------------------------------
def test_noise_peak_finds_the_state_peak():
    from workbench.report.markdown import noise_peak
    q = {"simulation.kick.final_error.omega": 3.75e-12, "simulation.kick.peak_error.omega": 0.73,
         "final_error.v": 1e-13, "peak_error.v": 2.0, "simulation.kick.final_error.lam": 1e-3}
    assert noise_peak("simulation.kick.final_error.omega", q) == 0.73
    assert noise_peak("final_error.v", q) == 2.0
    assert noise_peak("simulation.kick.final_error.lam", q) is None    # no peak: no floor
    assert noise_peak("simulation.kick.peak_error.omega", q) is None   # not an error at the end


@pytest.mark.parametrize("got", [3.7517e-12, 3.7801e-12])
def test_claims_table_prints_a_rounding_level_error_as_a_bound(got):
    """The wheel-slip creep-recovers cell under a +3 ulp input perturbation
    (issue 36, item 5): both values print the same bound."""
    from workbench.report.writer import claims_table
    c = _claim("creep-recovers", "simulation.creep_kick.final_error.omega", "<=", 0.01)
    table = claims_table((ClaimResult(c, got, Verdict.PASS, peak=1.0),))
    assert "| < 1e-9 × peak | **PASS** |" in table
    above = claims_table((ClaimResult(c, 2e-3, Verdict.PASS, peak=1.0),))
    assert "| 0.002 | **PASS** |" in above
    plain = claims_table((ClaimResult(c, got, Verdict.PASS),))
    assert f"| {got:.5g} | **PASS** |".replace("e-12", "e-12") in plain


def test_verify_attaches_the_peak(monkeypatch):
    from workbench import kinds, verify
    from workbench.design import Design

    class Study:
        kind = "fake-peak"

        def run(self, design):
            return None

        def quantities(self, res):
            return {"s.final_error.w": 4e-12, "s.peak_error.w": 0.5, "other": 1.0}

    monkeypatch.setattr(kinds, "REGISTRY", {"fake-peak": Study()})
    ev = verify.evaluate_design(Design("f.toml", "fake", "fake-peak", "t", "s", None, (
        _claim("a", "s.final_error.w", "<=", 0.01), _claim("b", "other", "<=", 2.0))))
    assert [r.peak for r in ev.claims] == [0.5, None]
    assert replace(ev.claims[0], verdict=Verdict.FAIL).peak == 0.5


# -- paper 003: the compensated case at dt/4 (a real run: ~20-40 s) -------------------------
@pytest.mark.slow
def test_dry_stop_duration_levels_and_the_converged_instead():
    """The stop duration of designs/antiskid-run-dry.toml at dt, dt/2, dt/4 is
    what benchmarks/stop_refinement.py measured (85.96 / 86.68 / 86.14 s): not
    converged within 0.5 s; the time to omega = 3 rad/s, the quantity the
    finding names instead, converges (50.34 s)."""
    from pathlib import Path

    from workbench.design import load_design
    from workbench.papers.p003.antiskid_refine import refine_levels
    from workbench.papers.p003.antiskid_run import RECORD_DT, STUDY, RunResult, linear_check
    from workbench.papers.p003.antiskid_run_spec import gain_for, nominal_cruise
    from workbench.features.refinement import _own_row

    design = load_design(Path(__file__).resolve().parents[1] / "designs/antiskid-run-dry.toml")
    spec = replace(design.spec, cases=tuple(c for c in design.spec.cases
                                            if c.name == "compensated"))
    K = gain_for(spec)[0]
    lin = nominal_cruise(spec)[2]
    res = RunResult(0.0, 0.0, tuple(K), "", None, tuple(STUDY._cases(spec, K)),
                    linear_check(spec, lin.A, lin.B, K), spec.dt, spec=spec)
    stop = next(c for c in design.claims if c.id == "stop-duration")
    assert stop.converged_instead == "cases[compensated].omega3_after_brake"
    omega3 = replace(stop, id="omega3", quantity=stop.converged_instead, value=50.0,
                     tolerance=1.0, expect="pass")
    q = STUDY.quantities(res)
    found = [ClaimResult(c, q[c.quantity], Verdict.FAIL) for c in (stop, omega3)]
    lv = refine_levels(replace(design, spec=spec), res, found, quantities=STUDY.quantities,
                       record_dt=RECORD_DT)
    assert [round(x, 2) for x in lv["stop-duration"].values] == list(STOP_LEVELS)
    row = _own_row(found[0], lv["stop-duration"], "dt")
    assert row.outcome == INCONCLUSIVE and row.check.estimate > 0.5
    assert "use `cases[compensated].omega3_after_brake` instead" in row.reason
    ok = _own_row(found[1], lv["omega3"], "dt")
    assert ok.outcome == CONVERGED and ok.check.estimate < 0.01
    assert lv["omega3"].values[1] == pytest.approx(50.34, abs=0.01)


def test_antiskid_refine_maps_findings_without_running():
    """Findings whose metric has no step (the k2 sweep's certificate) get the
    same value at every level; a metric the study does not refine gets a
    reason (INCONCLUSIVE), and mc-converged's two-step comparison too."""
    from types import SimpleNamespace

    from workbench.papers.p003.antiskid_refine import refine_levels
    design = SimpleNamespace(name="fake-run", spec=SimpleNamespace(dt=0.01))
    found = [ClaimResult(_claim("cert", "basin.compared_certified", "==", 0.0), 0.0,
                         Verdict.PASS),
             ClaimResult(_claim("lin", "linear.paper.exact_margin", ">=", 1.0), 2.0,
                         Verdict.PASS),
             ClaimResult(_claim("mc", "montecarlo.halving.fraction_agree", ">=", 1.0), 0.9,
                         Verdict.FAIL)]
    lv = refine_levels(design, SimpleNamespace(halving=None), found, quantities=None,
                       record_dt=0.05)
    assert lv["cert"].values == ("0", "0", "0") and "no step" in lv["cert"].parameter
    assert lv["lin"].values == () and "linear.paper.exact_margin" in lv["lin"].reason
    assert lv["mc"].values == () and "no step check" in lv["mc"].reason
