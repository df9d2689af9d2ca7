"""Forest-likelihood sampling: new designs where the forest votes for the target."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from holofold.design import Column, ForestRuleMiner, Scenario, sample_designs
from holofold.design.acquisition import likely_designs
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
    m = ForestRuleMiner(n_estimators=30, random_state=0).fit(X, hit)
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
