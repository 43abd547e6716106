"""eps_matching (one solve per eps step where it settles the step) returns
eps_for_bound's eps bit for bit (workbench.features.eps_match),
with fewer solves."""
import pytest

from workbench.lmi import freeweighting003 as FW
from workbench.features.eps_match import eps_matching
from workbench.plants.adhesion import NumericAdhesion
from workbench.symbolic.linearise import linearise_cruise
from workbench.synthesis import SynthesisSettings, eps_for_bound

DRY = dict(a=0.3315, b=40.19, c=5.392, J=80.0, r=0.445, m=12000.0, zeta=0.01, c0=180.9,
           c1=112.2, c2=2.6, g=9.8)   # 003 Tables 1-2
SETTINGS = SynthesisSettings(h_max=100.0)     # as designs/antiskid-cruise-dry.toml


@pytest.fixture(scope="module")
def lin():
    p = NumericAdhesion.from_dict(DRY)
    return linearise_cruise(p, 70.0, p.cruise_lambda(70.0))


def _counted(monkeypatch, fn, *args):
    n = [0]
    orig = FW.FreeWeighting003.solve_at

    def count(self, h):
        n[0] += 1
        return orig(self, h)
    monkeypatch.setattr(FW.FreeWeighting003, "solve_at", count)
    out = fn(*args)
    monkeypatch.setattr(FW.FreeWeighting003, "solve_at", orig)
    return out, n[0]


# 003 Table 3's printed h_m = 0.0255 at eps = 0.20, in the design's bracket [0.05, 0.525];
# and a bound no eps there certifies (None)
@pytest.mark.parametrize("h_m", [0.0255, 5.0])
def test_same_eps_as_eps_for_bound(lin, monkeypatch, h_m):
    new, n_new = _counted(monkeypatch, eps_matching, lin.A, lin.B, h_m, 0.05, 0.525, SETTINGS)
    old, n_old = _counted(monkeypatch, lambda *a: eps_for_bound(*a, settings=SETTINGS),
                          lin.A, lin.B, h_m, 0.05, 0.525)
    assert new == old                                  # bit for bit (None == None too)
    assert n_new < n_old
    print(f"h_m = {h_m}: eps {new!r}, {n_new} solves against {n_old}")
