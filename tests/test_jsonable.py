"""The generic JSON serialisation (workbench.jsonable, issue 35) and the one
outcome module (workbench.outcome): conversions, views, and the JSON of a
checked claim, key for key as the hand-written method printed it."""
from __future__ import annotations

import enum
import json
import math
from dataclasses import dataclass

import numpy as np
import pytest

from workbench.claims import Claim, Verdict, check_claim, origin_of
from workbench.jsonable import OMIT, finite_or_none, json_method, to_json
from workbench.outcome import Outcome, word


class _Colour(str, enum.Enum):
    RED = "red"


@dataclass(frozen=True)
class _Inner:
    x: float
    tags: tuple


@dataclass(frozen=True)
class _Outer:
    name: str
    inner: _Inner
    M: np.ndarray
    colour: _Colour
    extra: dict


@dataclass(frozen=True)
class _Viewed:
    a: float
    b: _Inner | None
    hidden: np.ndarray

    JSON_FIELDS = {"A": "a", "bx": "b.x", "twice": lambda r: 2 * r.a,
                   "maybe": lambda r: OMIT if r.b is None else "here"}
    to_json = json_method


def test_dataclasses_enums_numpy_and_infinities_nest():
    o = _Outer("o", _Inner(math.inf, (1, np.float64(-math.inf))), np.eye(2), _Colour.RED,
               {"k": np.int64(3), "nan": math.nan})
    got = to_json(o)
    assert got["inner"] == {"x": "inf", "tags": [1, "-inf"]}
    assert got["M"] == [[1.0, 0.0], [0.0, 1.0]] and got["colour"] == "red"
    assert got["extra"]["k"] == 3 and type(got["extra"]["k"]) is int
    assert math.isnan(got["extra"]["nan"])        # NaN is left to the views
    json.dumps(got)                                # plain data only


def test_a_view_selects_renames_reads_paths_and_omits():
    assert _Viewed(1.5, _Inner(2.0, ()), np.zeros(3)).to_json() == \
        {"A": 1.5, "bx": 2.0, "twice": 3.0, "maybe": "here"}
    # a path through None gives None; OMIT leaves the key out
    assert _Viewed(1.5, None, np.zeros(3)).to_json() == {"A": 1.5, "bx": None, "twice": 3.0}


def test_an_unknown_type_is_an_error_not_a_string():
    with pytest.raises(TypeError, match="object is not serialisable"):
        to_json(object())


def test_finite_or_none():
    assert finite_or_none(2) == 2.0 and finite_or_none(math.nan) is None
    assert finite_or_none(math.inf) is None and finite_or_none(None) is None


def _claim(value, compare="<=", tol=0.0):
    return Claim("c1", "claim c1", "q", compare, value, tol, None, "round", "003 Table 3",
                 False, "pass", "", None, origin_of("003 Table 3"))


def test_claim_json_is_the_one_the_hand_written_method_printed():
    # the keys, their order and the "inf" strings of the former ClaimResult.to_json
    r = check_claim(_claim(math.inf), 2.5)
    assert list(r.to_json()) == ["id", "quantity", "compare", "expected", "tolerance", "got",
                                 "verdict", "ok", "expect", "source", "note", "severity",
                                 "origin"]
    assert r.to_json() == {"id": "c1", "quantity": "q", "compare": "<=", "expected": "inf",
                           "tolerance": 0.0, "got": 2.5, "verdict": "PASS", "ok": True,
                           "expect": "pass", "source": "003 Table 3", "note": r.note,
                           "severity": None, "origin": r.claim.origin}
    assert check_claim(_claim(1.0), -math.inf).to_json()["got"] == "-inf"


def test_one_outcome_and_one_verdict():
    # the certificate outcome keeps the LMI words as values and the basin
    # tables' words as names; the claim verdict its upper-case words
    assert [o.value for o in Outcome] == ["certified", "refuted", "inconclusive", "infeasible"]
    assert [word(o) for o in Outcome] == ["CERTIFIED", "REFUTED", "INCONCLUSIVE", "INFEASIBLE"]
    assert [v.value for v in Verdict] == ["PASS", "FAIL", "INCONCLUSIVE"]
    from workbench.lmi.core import Outcome as LmiOutcome
    from workbench.roa.basin import Outcome as BasinOutcome
    assert LmiOutcome is Outcome and BasinOutcome is Outcome
