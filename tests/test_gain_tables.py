"""The general gain comparisons on a toy ``delay-feedback`` design (no paper):
``[[synthesis.published]]`` (workbench.features.published_rows),
``[[other_gains]]`` (workbench.features.other_gains) and ``[eps_sweep]``
(workbench.features.eps_sweep), through workbench.kinds.delay_feedback.gain_tables."""
from __future__ import annotations

import numpy as np
import pytest

from workbench.design import load_design
from workbench.errors import DesignError

TOY = '''
[design]
name = "toy"
kind = "delay-feedback"
title = "toy"
source = "tests/test_gain_tables.py"

[states]
x = { unit = "m", source = "test" }
v = { unit = "m/s", source = "test" }

[inputs]
u = { unit = "m/s^2", source = "test" }

[parameters]
k = { value = 1.0, unit = "1/s^2", source = "test" }
c = { value = 1.0, unit = "1/s", source = "test" }

[equations]
x = "v"
v = "k*x - c*v + u"

[operating_point]
x = { value = 0.0, unit = "m", source = "test" }
v = { value = 0.0, unit = "m/s", source = "test" }
u = { value = 0.0, unit = "m/s^2", source = "test" }

[delay]
h = { value = 0.05, unit = "s", source = "test" }

[synthesis]
method = "free-weighting-003"
eps = [0.5, 1.0]
rel_tol = 1e-3
h_max = 10.0

[[synthesis.published]]
eps = 0.5
h_m = 0.1
K = [-3.0, -2.0]
source = "a made-up printed row"
'''

OTHER = '''
[[other_gains]]
name = "stabilising"
K = [-3.0, -2.0]
source = "test"

[[other_gains]]
name = "zero"
K = [0.0, 0.0]
source = "test: the open loop, unstable"

[eps_sweep]
'''


def _write(tmp_path, text):
    p = tmp_path / "toy.toml"
    p.write_text(text, encoding="utf-8")
    return p


@pytest.fixture(scope="module")
def toy(tmp_path_factory):
    from workbench.kinds import REGISTRY, renderer
    path = _write(tmp_path_factory.mktemp("toy"), TOY + OTHER)
    design = load_design(path)
    study = REGISTRY[design.kind]
    res = study.run(design)
    return design, study, res, renderer(design.kind)(design, res)


def test_quantities_are_declared_and_computed(toy):
    design, study, res, _ = toy
    names = study.quantity_names(design.spec)
    q = study.quantities(res)
    expected = {"published[eps=0.5].h_paper_K", "published[eps=0.5].exact_margin_paper_K",
                "published[eps=0.5].eps_matching", "other_gains.min_abscissa",
                "other_gains.stable", "other_gains[zero].abscissa",
                "other_gains[stabilising].exact_margin"}
    assert expected <= names and expected <= set(q)
    # x'' = x - x' + u: open loop s^2 + s - 1, root (sqrt 5 - 1)/2; with K = [-3, -2]
    # the loop is s^2 + 3 s + 2 = (s + 1)(s + 2)
    assert q["other_gains[zero].abscissa"] == pytest.approx((5 ** 0.5 - 1) / 2, rel=1e-12)
    assert q["other_gains[zero].stable"] == "no"
    assert q["other_gains[stabilising].abscissa"] == pytest.approx(-1.0, rel=1e-12)
    assert q["other_gains.stable"] == 1
    assert q["other_gains[stabilising].exact_margin"] > 0


def test_printed_gain_is_certified_by_the_same_lmi(toy):
    from workbench.synthesis import certify_given_gain
    design, _, res, _ = toy
    c = res.gain_tables.published[0]
    st = design.spec.synthesis.settings
    direct = certify_given_gain(res.A, res.B, np.array([[-3.0, -2.0]]), 0.5, st)
    assert c.h_paper_K == direct.h_certified > 0
    assert c.h_ours == next(r.h_certified for r in res.synthesis.rows if r.eps == 0.5)


def test_report_sections_and_figures(toy):
    _, _, res, rendered = toy
    text = "\n".join(rendered.sections)
    for heading in ("## eps sweep", "## Comparison with the printed table",
                    "## Gains designed elsewhere, on this loop"):
        assert heading in text
    assert "**1 of 2 gains leave this loop unstable even without delay**" in text
    names = {f.name for f in rendered.figures}
    assert {"delay-bound-vs-eps", "loop"} <= names
    assert rendered.anchors == (("other_gains", "Gains designed elsewhere, on this loop"),)
    assert len(res.gain_tables.abscissa) > 0


def test_bad_tables_are_design_errors(tmp_path):
    wirtinger = TOY.replace('method = "free-weighting-003"\neps = [0.5, 1.0]',
                            'method = "wirtinger"').split("[[synthesis.published]]")[0]
    with pytest.raises(DesignError, match="free-weighting-003"):
        load_design(_write(tmp_path, wirtinger + "\n[eps_sweep]\n"))
    with pytest.raises(DesignError, match="two gain entries"):
        load_design(_write(tmp_path, TOY.replace("K = [-3.0, -2.0]", "K = [-3.0, -2.0, 1.0]")))


def test_designs_without_the_tables_have_none():
    spec = load_design("designs/antiskid-cruise-dry-generic.toml").spec
    assert not spec.gain_tables


def test_other_gains_at_every_vertex(tmp_path):
    """With [[vertices]] the foreign gains are also checked at every vertex
    (workbench.features.point_gains), next to the design's robust gain."""
    from workbench.kinds import REGISTRY, renderer
    text = TOY.split("[synthesis]")[0] + '''
[synthesis]
method = "robust-descriptor"
grid = [0.1, 1.0]
h_max = 1.0

[[vertices]]
name = "soft"
k = 0.5
source = "test"

[[vertices]]
name = "stiff"
k = 4.0
source = "test"
''' + OTHER.split("[eps_sweep]")[0]
    design = load_design(_write(tmp_path, text))
    study = REGISTRY[design.kind]
    res = study.run(design)
    q = study.quantities(res)
    assert {"compare[zero].all_stable", "compare[stabilising].points[stiff].exact_margin"} <= \
        study.quantity_names(design.spec)
    # K = [-3, -2] at k = 4: s^2 + 3 s - 1 has a positive root; at k = 0.5 it is stable
    assert q["compare[stabilising].all_stable"] == "no"
    assert q["compare[stabilising].unstable_points"] == 1.0
    assert q["compare[zero].unstable_points"] == 2.0
    text = "\n".join(renderer(design.kind)(design, res).sections)
    assert "## Compared with printed gains" in text
    assert "`stabilising` (K = [-3, -2], test) is UNSTABLE without any delay at 1 of 2" in text
