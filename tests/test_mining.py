"""mine_rules: the hold-out mining workflow of ``holofold mine``, and rules files."""

import json

import numpy as np
import pandas as pd
import pytest

from holofold.design import (
    Condition,
    ForestRuleMiner,
    Rule,
    RulesFileError,
    Score,
    column_roles,
    holdout,
    mine_rules,
    mined_rules,
    parse_target,
    read_rules,
    rules_to_records,
    write_rules,
)


def test_mine_rules_is_the_holdout_of_the_published_database(reference_data, tmp_path):
    """data0: the target, the split and the rules are those of evaluation.holdout."""
    df = reference_data.load("data0_SingleMiura")
    mined = mine_rules(df, "axialstiff60 < 6000", roles=column_roles(df.columns), seed=2)
    assert mined.features == ("tcrease", "tpanel", "W", "gama") and mined.categorical == ()
    assert int(mined.meets.sum()) == 70 and mined.n_failed == 0
    assert (len(mined.holdout.train_index), len(mined.holdout.test_index)) == (600, 400)
    ref = holdout(
        ForestRuleMiner(),
        df[list(mined.features)],
        parse_target("axialstiff60 < 6000").evaluate(df),
        random_state=2,
    )
    pd.testing.assert_frame_equal(mined.holdout.rules, ref.rules)
    recs = rules_to_records(mined.miner, mined.test_scores)
    for rec, (_, row) in zip(recs, ref.rules.iterrows(), strict=True):
        assert rec["rule"] == row["rule"]
        assert rec["test"]["precision"] == pytest.approx(row["test_precision"])
        assert rec["train"]["support"] == row["support"]
    rules = mined_rules(mined.miner, mined.test_scores)
    assert [r.to_json() for r in rules] == recs
    path = write_rules(tmp_path / "r.json", rules)
    assert read_rules(path) == rules  # the file round-trips the records exactly


def _table(n=400, seed=0):
    rng = np.random.default_rng(seed)
    df = pd.DataFrame({"a": rng.uniform(size=n), "b": rng.uniform(size=n)})
    df["y"] = df["a"] + 0.1 * df["b"]
    df["status"] = "converged"
    df.loc[:9, "status"] = "failed: RuntimeError: boom"
    return df


def test_failed_rows_are_left_out_and_features_must_be_named():
    df = _table()
    mined = mine_rules(df, "y > 0.8", features=["a", "b"], n_estimators=20, n_rules=1)
    assert mined.n_failed == 10 and len(mined.table) == 390
    with pytest.raises(ValueError, match="list them with --features"):
        mine_rules(df, "y > 0.8")
    with pytest.raises(ValueError, match="'y' is a performance column"):
        mine_rules(df, "y > 0.8", features=["a", "y"])
    with pytest.raises(ValueError, match="met by 0 of 390 rows"):
        mine_rules(df, "y > 9", features=["a", "b"])
    with pytest.raises(ValueError, match="'n_estimators' parameter"):
        mine_rules(df, "y > 0.8", features=["a", "b"], n_estimators=0)


@pytest.mark.parametrize(
    "content, match",
    [
        ("{", "not valid JSON"),
        ("{}", "a list"),
        ("[]", "a list"),
        ('[{"rule": "x"}]', "rule 1: a rule record needs a 'bounds' object"),
        ('[{"bounds": {"a": [1, 2]}}]', "rule 1: bounds of 'a' = \\[1, 2\\] must be"),
        ('[{"bounds": {"a": 3}}]', "bounds of 'a' = 3 must be"),
        ('[{"bounds": {"a": {"in": 3}}}]', "levels must be a list of numbers"),
        ('[{"bounds": {"a": {"in": []}}}]', "non-empty list of finite numbers"),
        ('[{"bounds": {"a": {"gt": "x"}}}]', "'gt' = 'x' must be a number or null"),
        ('[{"bounds": {"a": {"gt": 2, "le": 1}}}]', "empty interval"),
        ('[{"bounds": {"a": {"lo": 2}}}]', "bounds of 'a'"),
        ('[{"bounds": {"a": {"gt": null}}}]', "needs 'gt' or 'le'"),
        ('[{"bounds": {"a": {"in": [1], "gt": 0}}}]', "not both"),
    ],
)
def test_bad_rules_files_are_one_line_errors(tmp_path, content, match):
    path = tmp_path / "rules.json"
    path.write_text(content)
    with pytest.raises(RulesFileError, match=match) as exc:
        read_rules(path)
    assert "\n" not in str(exc.value) and str(path) in str(exc.value)


def test_write_rules_is_strict_json(tmp_path):
    rule = Rule((Condition("a", le=0.5),), train=Score(float("nan"), 0.5, 3))
    text = write_rules(tmp_path / "r.json", [rule]).read_text()
    assert "NaN" not in text and json.loads(text)[0]["train"]["precision"] is None
    assert read_rules(tmp_path / "r.json")[0].conditions == rule.conditions
