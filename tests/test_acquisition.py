"""Forest-likelihood sampling: new designs where the forest votes for the target."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from holofold.design import Column, ForestRuleMiner, Scenario, sample_designs
from holofold.design.loop.acquisition import likely_designs
from holofold.mechanics.status import CONVERGED


def _toy():
    return Scenario(
        name="toy", description="toy", check=lambda row: [],
        evaluate=lambda row: {"y": row["a"] * row["b"], "status": CONVERGED},
        features=(Column("a", "m", "", 0.0, 1.0), Column("b", "m", "", 0.0, 1.0),
                  Column("c", "m", "", 0.0, 1.0)),
        performance=(Column("y", "-"),),
    )  # fmt: skip


def test_likely_designs_go_where_the_target_is():
    sc = _toy()
    X = sample_designs(sc, 600, seed=0)[["a", "b", "c"]]
    hit = (X["a"] > 0.85) & (X["b"] > 0.85)  # 2 % of the space
    m = ForestRuleMiner(n_estimators=30, n_rules=1, random_state=0).fit(X, hit)
    new = likely_designs(sc, m, 100, seed=1, start=5000, candidates=5000)
    assert len(new) == 100 and new["sample"].tolist() == list(range(5000, 5100))
    inside = ((new["a"] > 0.85) & (new["b"] > 0.85)).mean()
    assert inside > 0.3  # 15x the rate of random designs
    assert new["c"].std() > 0.2  # the irrelevant feature stays spread
    again = likely_designs(sc, m, 100, seed=1, start=5000, candidates=5000)
    pd.testing.assert_frame_equal(new, again)  # seeded
    flat = likely_designs(sc, m, 100, seed=1, candidates=5000, power=0)
    assert ((flat["a"] > 0.85) & (flat["b"] > 0.85)).mean() < 0.1  # power 0: uniform
    with pytest.raises(ValueError, match="must be in"):
        likely_designs(sc, m, 0, seed=1)
    assert np.all((new[["a", "b", "c"]] >= 0) & (new[["a", "b", "c"]] <= 1))


def _loop_scenario():
    return Scenario(
        name="toy-loop", description="toy", check=lambda row: [],
        evaluate=lambda row: {"y": row["a"] + 0.01 * row["b"], "status": CONVERGED},
        features=(Column("a", "m", "", 0.0, 1.0), Column("b", "m", "", 0.0, 1.0)),
        performance=(Column("y", "-"),),
    )  # fmt: skip


def test_the_loop_stops_once_a_rule_is_verified(tmp_path):
    from holofold.design import run_design

    said = []
    out = run_design(_loop_scenario(), "y > 0.5", tmp_path / "o", samples=120, rounds=4, pilot=0,
                     workers=1, progress=False, files=False, say=said.append)  # fmt: skip
    rounds = out.summary["rounds"]
    assert len(rounds) == 1 and any("is verified; no more rounds" in s for s in said)
    checked = [r for r in rounds[0]["rules"] if r.get("verified_n")]
    assert checked and checked[-1]["verified_precision"] >= 0.9  # the last one tried passed
    assert checked[-1]["verified_95ci"][0] >= 0.8
    assert all(r["estimate"]["precision"] >= 0.85 for r in checked)
    again = run_design(_loop_scenario(), "y > 0.5", tmp_path / "p", samples=120, rounds=2, pilot=0,
                       workers=1, progress=False, files=False, until_verified=False,
                       strategy="around")  # fmt: skip
    assert len(again.summary["rounds"]) == 3
    with pytest.raises(ValueError, match="strategy = 'near' must be one of 'likely', 'around'"):
        run_design(_loop_scenario(), "y > 0.5", tmp_path / "q", strategy="near")


def test_the_loop_stops_on_its_budget_of_simulations(tmp_path):
    from holofold.design import run_design

    # every round runs (until_verified=False) until the budget is spent
    said = []
    kw = dict(samples=60, refine=20, verify=10, top=1, pilot=0, workers=1, progress=False,
              files=False, until_verified=False)  # fmt: skip
    out = run_design(_loop_scenario(), "y > 0.5", tmp_path / "o", budget=200, say=said.append,
                     **kw)  # fmt: skip
    spent = len(out.table)
    assert spent <= 200
    # another round (20 designs and a verification of 10) would not have fitted
    assert spent + 20 + 10 > 200
    assert len(out.summary["rounds"]) >= 4  # no cap on the count of rounds
    assert any("leaves no room" in s for s in said)
    # a cap on rounds still holds, inside the budget
    capped = run_design(_loop_scenario(), "y > 0.5", tmp_path / "p", budget=200, rounds=1, **kw)
    assert len(capped.summary["rounds"]) == 2
    with pytest.raises(ValueError, match="cannot hold the 60 designs of the database"):
        run_design(_loop_scenario(), "y > 0.5", tmp_path / "q", budget=65, **kw)
    assert not (tmp_path / "q").exists()


def _two_regions():
    # the target y > 0.8 holds at both ends of a (a < 0.1 or a > 0.9): two rules, two regions
    return Scenario(
        name="toy-two", description="toy", check=lambda row: [],
        evaluate=lambda row: {"y": 2 * abs(row["a"] - 0.5), "status": CONVERGED},
        features=(Column("a", "m", "", 0.0, 1.0), Column("b", "m", "", 0.0, 1.0)),
        performance=(Column("y", "-"),),
    )  # fmt: skip


def test_a_mixed_round_samples_half_by_vote_and_half_inside_the_best_rule(tmp_path):
    from holofold.design import rule_mask, run_design

    out = run_design(_two_regions(), "y > 0.8", tmp_path / "o", samples=200, rounds=1,
                     refine=40, verify=10, top=2, pilot=0, workers=1, progress=False, files=False,
                     until_verified=False, strategy="mixed")  # fmt: skip
    best = out.record.rounds[0].rules[0].rule
    new = out.table[out.table["origin"] == "refine-1"].sort_values("sample")
    assert len(new) == 40
    inside = np.asarray(rule_mask(new, best), bool)
    assert inside[20:].all()  # the second half: uniform inside the round's best rule
    assert new["b"].iloc[20:].std() > 0.15  # spread over the feature the rule leaves free
    # the first half: where the forest votes, at both ends, so partly outside the best rule
    assert (new["y"].iloc[:20] > 0.8).mean() >= 0.6
    assert 3 <= (~inside[:20]).sum() <= 17


def test_the_loop_stops_looking_at_random_for_a_target_no_design_meets(tmp_path, monkeypatch):
    import holofold.design.loop.design_loop as design_loop
    from holofold.design import run_design

    monkeypatch.setattr(design_loop, "RANDOM_UP_TO", 100)
    said = []
    out = run_design(_loop_scenario(), "y > 2", tmp_path / "o", samples=60, refine=20,
                     verify=10, pilot=0, workers=1, progress=False, files=False,
                     say=said.append)  # fmt: skip
    assert len(out.table) == 100  # 60 + 2 rounds of 20 at random, then it stops
    assert any("fewer than 3 in 100 at 95 % confidence): no more rounds" in s for s in said)
    assert out.record.answer == "nearest"
