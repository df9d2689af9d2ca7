"""The rule record: one validation, one application (float64, gt < x <= le), its JSON form."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from holofold.design import (
    Column,
    Condition,
    Estimate,
    Rule,
    RuleError,
    Score,
    get_scenario,
    rule_ranges,
)


def _rule():
    return Rule(
        (Condition("tcrease", le=7.792e-4), Condition("W", gt=2.057e-3, le=3e-3),
         Condition("m", levels=(24, 16.0))),
        rank=2,
        estimate=Estimate(0.91, 0.8, 0.97, 120, 100, 20),
        train=Score(0.95, 0.3, 60),
        test=Score(0.9, 0.25, 40),
        oob_precision=0.93,
    )  # fmt: skip


def test_the_rule_applies_with_scikit_learns_sides_in_float64():
    rule = Rule((Condition("x", gt=0.1, le=0.3),))
    x = np.array([0.1, np.nextafter(0.1, 1), 0.2, 0.3, np.nextafter(0.3, 1)])
    assert rule.mask(pd.DataFrame({"x": x})).tolist() == [False, True, True, True, False]
    # a float32 round-off does not move a row across a bound: x is compared as float64
    y = np.array([np.float64(np.float32(0.3)), 0.3 + 1e-12])  # float32(0.3) > 0.3
    assert not Rule((Condition("x", le=0.3),)).mask(pd.DataFrame({"x": y})).any()
    levels = Rule((Condition("m", levels=[16, 24]),))
    assert levels.mask(pd.DataFrame({"m": [8, 16, 24.0]})).tolist() == [False, True, True]
    assert Rule().mask(pd.DataFrame({"x": [1, 2]})).all()  # no condition: every design
    with pytest.raises(RuleError, match="'q', which is not a column"):
        Rule((Condition("q", le=1),)).mask(pd.DataFrame({"x": [1]}))


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"gt": 2, "le": 1}, "empty interval"),
        ({"gt": 1, "le": 1}, "empty interval"),
        ({}, "needs 'gt' or 'le'"),
        ({"gt": float("nan")}, "'gt' = nan must be a number"),
        ({"le": "1"}, "'le' = '1' must be a number"),
        ({"le": True}, "must be a number"),
        ({"gt": math.inf}, "leaves no value"),
        ({"levels": ()}, "non-empty list"),
        ({"levels": (1, math.nan)}, "finite numbers"),
        ({"levels": "ab"}, "list of numbers"),
        ({"levels": (1,), "le": 2}, "not both"),
    ],
)
def test_a_condition_is_checked_once_in_one_line(kwargs, match):
    with pytest.raises(RuleError, match=match) as err:
        Condition("x", **kwargs)
    assert "\n" not in str(err.value) and "'x'" in str(err.value)


def test_open_sides_and_duplicates():
    c = Condition("x", gt=-math.inf, le=2)  # an infinite open side is an open side
    assert (c.gt, c.le) == (None, 2.0) and c.to_json() == {"gt": None, "le": 2.0}
    with pytest.raises(RuleError, match="constrains 'x' twice"):
        Rule((Condition("x", le=1), Condition("x", gt=0)))


def test_text_in_display_units():
    cols = get_scenario("arch").columns
    assert _rule().text(cols) == "tcrease <= 0.779 mm and 2.06 < W <= 3 mm and m in {16, 24}"
    assert _rule().text() == "tcrease <= 0.000779 and 0.00206 < W <= 0.003 and m in {16, 24}"
    gama = {"gama": Column("gama", "rad", display="deg")}
    assert Rule((Condition("gama", gt=math.radians(65.8)),)).text(gama) == "gama > 65.8 deg"
    assert Rule().text() == "(any design)"


def test_json_form_round_trips_and_carries_the_display_form():
    cols = get_scenario("arch").columns
    rec = json.loads(json.dumps(_rule().to_json(cols)))
    assert rec["bounds"] == {"tcrease": {"gt": None, "le": 7.792e-4},
                             "W": {"gt": 2.057e-3, "le": 3e-3}, "m": {"in": [16, 24]}}  # fmt: skip
    assert rec["display"]["tcrease"] == {"gt": None, "le": pytest.approx(0.7792), "unit": "mm"}
    assert rec["rule"].startswith("tcrease <= 0.779 mm")
    assert rec["estimate"]["interval"] == [0.8, 0.97] and rec["test"]["support"] == 40
    assert rec["train"] == {"precision": 0.95, "recall": 0.3, "support": 60, "oob_precision": 0.93}
    assert Rule.from_json(rec) == _rule()
    # only the SI bounds are read: the display form is for people
    rec["display"]["tcrease"]["le"] = 99.0
    assert Rule.from_json(rec).condition("tcrease").le == 7.792e-4


def test_the_verifier_and_the_files_share_the_one_validation():
    arch = get_scenario("arch")
    bad = {"offset": {"gt": 0.2, "le": 0.1}}
    with pytest.raises(ValueError, match="empty interval") as a:
        rule_ranges(arch, bad)
    with pytest.raises(ValueError, match="empty interval") as b:
        Rule.from_bounds(bad)
    assert str(a.value) == str(b.value)
    got = rule_ranges(arch, _rule())
    assert got["tcrease"] == (arch.columns["tcrease"].low, 7.792e-4) and got["m"] == [16.0, 24.0]
