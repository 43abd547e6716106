"""``[convergence]`` on a ``delay-feedback`` design (issue 35, item 1): every
claim on a scenario metric refined over dt, dt/2, dt/4 by the one
implementation that ``switched-run`` uses (:mod:`workbench.features.convergence`);
an unconverged claim is INCONCLUSIVE."""
from __future__ import annotations

import pytest

from workbench.cli import main
from workbench.design import load_design
from workbench.kinds import renderer
from workbench.outcome import Verdict
from workbench.verify import evaluate_design

from test_delay_feedback import write

SCENARIO = '''
[[scenarios]]
name = "kick"
x0 = { x = 0.7 }
t_end = 4.0
dt = 0.02
'''


def claim(cid, quantity, compare, value):
    return (f'\n[[claims]]\nid = "{cid}"\ndescription = "test"\nquantity = "{quantity}"\n'
            f'compare = "{compare}"\nvalue = {value!r}\nsource = "test"\n')


def _evaluate(tmp_path, extra):
    return evaluate_design(load_design(write(tmp_path, extra=SCENARIO + extra)))


def test_claimed_metrics_are_refined_and_an_unconverged_one_is_inconclusive(tmp_path):
    ev = _evaluate(tmp_path, "\n[convergence]\n"
                   + claim("settles", "simulation.kick.final_error.x", "<=", 1.0)
                   + claim("word", "simulation.kick.converged", "==", "yes"))
    res = ev.result
    sr = res.scenarios[0]
    assert sr.metrics_fine is not None and set(sr.metrics_fine) == set(sr.metrics)
    (row,) = res.refinement                       # the word claim is not refined
    assert row.claim_id == "settles" and row.converged
    q1, q2, q4 = row.values
    assert (q1, q2) == (sr.metrics_coarse["final_error.x"], sr.metrics["final_error.x"])
    assert q4 == sr.metrics_fine["final_error.x"]
    assert row.check.estimate > 0
    assert all(c.verdict is Verdict.PASS for c in ev.claims)
    # a bound a quarter of the estimate above the value: the claim passes at dt/2,
    # but the estimate could carry it across: INCONCLUSIVE with the reason
    tight = q2 + row.check.estimate / 4
    ev = _evaluate(tmp_path, "\n[convergence]\n"
                   + claim("tight", "simulation.kick.final_error.x", "<=", tight))
    (c,) = ev.claims
    assert c.got <= tight
    assert c.verdict is Verdict.INCONCLUSIVE and c.note.startswith("not converged")
    md = "\n\n".join(renderer("delay-feedback")(ev.design, ev.result).sections)
    assert "## Convergence" in md and "`tight`" in md and "q4 (dt/4)" in md


def test_without_the_table_nothing_changes(tmp_path):
    ev = _evaluate(tmp_path, claim("settles", "simulation.kick.final_error.x", "<=", 1.0))
    assert ev.result.refinement == () and ev.result.scenarios[0].metrics_fine is None
    assert not ev.design.spec.convergence
    md = "\n\n".join(renderer("delay-feedback")(ev.design, ev.result).sections)
    assert "## Convergence" not in md
    assert "refinement" not in ev.result.to_json()


@pytest.mark.parametrize("extra, words", [
    ("\n[convergence]\nlevels = 3\n", "convergence.levels"),
    ('\n[convergence]\n', "steps over t_end with [convergence]"),
])
def test_bad_convergence_is_exit_2(tmp_path, capsys, extra, words):
    text = SCENARIO + extra
    if "steps" in words:
        text = text.replace("dt = 0.02", "dt = 0.0000015").replace("t_end = 4.0", "t_end = 2.0")
    p = write(tmp_path, extra=text)
    assert main(["verify", str(p)]) == 2
    err = capsys.readouterr().err
    assert words in err and err.count("\n") == 1 and "Traceback" not in err
