"""Rule evaluation on the published databases: hold-out, repeated splits, grid, baselines,
and the table of issue 6 section 5 (reference mean test precision of the top rule)."""

import json
import warnings

import numpy as np
import pandas as pd
import pytest
from sklearn.model_selection import train_test_split

from holofold.design.database.tables import PUBLISHED, column_roles, read_table
from holofold.design.rules import FewRulesWarning, ForestRuleMiner
from holofold.design.rules.evaluation import (
    baselines,
    grid_search,
    holdout,
    repeated_holdout,
    rule_scores,
    split_indices,
    summarize,
)
from holofold.design.rules.report import (
    plot_feature_importance,
    plot_rule_boxes,
    plot_rule_scatter,
    rules_to_text,
)
from holofold.design.rules.rulefile import rules_to_json
from holofold.design.rules.targets import parse_target
from holofold.design.scenarios import Column

D0_FEATURES = ["tcrease", "tpanel", "W", "gama"]
D3_FEATURES = ["m", "tcrease", "tpanel", "W", "offset", "stripeWidth", "extrude"]


@pytest.fixture(scope="module")
def data0(reference_data):
    df = reference_data.load("data0_SingleMiura")
    return df[D0_FEATURES], parse_target("axialstiff60 < 6000").evaluate(df)


@pytest.fixture(scope="module")
def data3(reference_data):
    return reference_data.load("data3_ShapeFit")


def test_split_is_train_test_split():
    train, test = split_indices(50, test_size=0.4, random_state=3)
    a, b = train_test_split(np.arange(50), test_size=0.4, random_state=3)
    np.testing.assert_array_equal(train, a)
    np.testing.assert_array_equal(test, b)
    with pytest.raises(ValueError, match="test_size"):
        split_indices(50, test_size=1.5)


def test_holdout_scores_on_test_rows(data0):
    X, y = data0
    res = holdout(ForestRuleMiner(n_estimators=30), X, y, random_state=0)
    assert res.miner.random_state == 0  # the forest is seeded with the split seed
    assert len(res.train_index) == 600 and len(res.test_index) == 400
    inside = res.miner.rule_matches(X.iloc[res.test_index])
    yt = y[res.test_index]
    np.testing.assert_array_equal(res.rules["test_support"], inside.sum(1))
    np.testing.assert_allclose(
        res.rules["test_precision"], (inside & yt).sum(1) / np.maximum(inside.sum(1), 1)
    )
    np.testing.assert_allclose(res.rules["test_recall"], (inside & yt).sum(1) / yt.sum())
    assert res.top_test_precision == res.rules["test_precision"].iloc[0]
    # training metrics recomputed on the training rows agree with rules_
    tr = rule_scores(res.miner, X.iloc[res.train_index], y[res.train_index])
    np.testing.assert_allclose(tr["precision"], res.rules["precision"])
    np.testing.assert_array_equal(tr["support"], res.rules["support"])


def test_data0_split0_top_rule_resembles_paper(data0):
    """Paper: t_c < 0.78 mm, t_p < 2.2 mm, W >= 1.9 mm, gamma >= 67 deg (k < 6000 N/m)."""
    X, y = data0
    res = holdout(ForestRuleMiner(), X, y, random_state=0)
    top = res.rules.iloc[0]
    assert 0.70e-3 < top["tcrease_le"] < 0.82e-3
    assert top["tpanel_le"] < 2.4e-3
    assert 1.6e-3 < top["W_gt"] < 2.2e-3
    assert np.isinf(top["tcrease_gt"]) and np.isinf(top["tpanel_gt"]) and np.isinf(top["W_le"])
    assert top["precision"] >= 0.9 and top["support"] >= 10
    # among the three alternatives one also bounds gamma from below near 67 degrees
    gam = np.degrees(res.rules["gama_gt"].to_numpy())
    assert np.any((gam > 60) & (gam < 72))


@pytest.mark.slow
@pytest.mark.parametrize(
    "target, reference",
    [
        ("axialstiff60 < 6000", 0.847),
        ("Zstiff > 800 & Xstiff > 600 & error < 0.1", 0.845),
        ("Zsnap == 1", 0.800),
    ],
)
def test_section5_table_mean_test_precision(reference_data, target, reference):
    """Issue 6 section 5: mean top-rule test precision over splits s = 0..4 (forest seed s)
    is within 0.03 of the reference implementation's figure. (Issue 13 chose the default on
    45 targets, not these three: on the arch target the paper's own ranking gives 0.830 here,
    the default 0.827.)"""
    if target.startswith("axial"):
        df = reference_data.load("data0_SingleMiura")
        X, cats = df[D0_FEATURES], None
    else:
        df = reference_data.load("data3_ShapeFit")
        X, cats = df[D3_FEATURES], ["m"]
    y = parse_target(target).evaluate(df)
    runs = repeated_holdout(
        ForestRuleMiner(categorical_features=cats, n_jobs=2), X, y, seeds=range(5)
    )
    assert (runs["n_rules"] == 3).all()
    summary = summarize(runs)
    assert summary["n_without_rule"] == 0
    assert summary["mean"] >= reference - 0.03, runs[["seed", "test_precision", "rule"]]


def test_repeated_holdout_and_summary(data0):
    X, y = data0
    runs = repeated_holdout(ForestRuleMiner(n_estimators=20), X, y, seeds=[0, 1, 2])
    assert list(runs["seed"]) == [0, 1, 2]
    single = holdout(ForestRuleMiner(n_estimators=20), X, y, random_state=1)
    assert runs.loc[1, "test_precision"] == single.top_test_precision
    s = summarize(runs)
    v = runs["test_precision"].to_numpy()
    assert s["mean"] == pytest.approx(v.mean()) and s["std"] == pytest.approx(v.std(ddof=1))
    assert s["min"] <= s["mean"] <= s["max"]


def test_grid_search_reuses_work_exactly(data0):
    X, y = data0
    runs, table = grid_search(X, y, max_depth=(3, 6), n_estimators=(5, 12), seeds=(0, 1), n_jobs=1)
    assert len(runs) == 2 * 2 * 2 and len(table) == 4
    # a cell equals a fresh, independent hold-out with that many trees and that depth
    for depth, k, seed in [(3, 5, 1), (6, 12, 0), (6, 5, 0)]:
        row = runs[(runs.max_depth == depth) & (runs.n_estimators == k) & (runs.seed == seed)].iloc[
            0
        ]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FewRulesWarning)
            fresh = holdout(
                ForestRuleMiner(n_estimators=k, max_depth=depth), X, y, random_state=seed
            )
        assert row["test_precision"] == pytest.approx(fresh.top_test_precision, nan_ok=True)
    assert (np.diff(table["mean"].dropna()) <= 0).all()


@pytest.mark.slow
def test_baselines_on_same_splits(data3):
    X = data3[D3_FEATURES]
    y = parse_target("Zstiff > 800 & Xstiff > 600 & error < 0.1").evaluate(data3)
    b = baselines(X, y, seeds=[0])
    assert set(b.columns) >= {"seed", "knn_precision", "gb_precision"}
    # both classifiers are far better than the 4.6 % base rate
    assert 0.5 < b.loc[0, "knn_precision"] <= 1 and 0.7 < b.loc[0, "gb_precision"] <= 1


@pytest.mark.slow
def test_reports_and_plots(data3, tmp_path):
    X = data3[D3_FEATURES]
    y = parse_target("Zsnap == 1").evaluate(data3)
    res = holdout(
        ForestRuleMiner(n_estimators=30, categorical_features=["m"]), X, y, random_state=1
    )
    m = res.miner
    test = rule_scores(m, X.iloc[res.test_index], y[res.test_index])
    mm = {n: Column(n, "m", display="mm") for n in D3_FEATURES if n != "m"}
    text = rules_to_text(m, test, columns=mm)
    assert text.count("rule ") == len(m.rules_) and "held-out: precision" in text
    assert text.count("estimate: precision") == len(m.rules_)
    assert " mm" in text and "m >= 0.5" not in text
    recs = json.loads(rules_to_json(m, test))
    assert [r["rank"] for r in recs] == list(range(1, len(recs) + 1))
    assert recs[0]["train"]["precision"] == pytest.approx(m.rules_.loc[0, "precision"])
    assert recs[0]["test"]["support"] == int(test.loc[0, "support"])
    for name, b in recs[0]["bounds"].items():
        assert set(b) in ({"gt", "le"}, {"in"}), name
    if "m" in recs[0]["bounds"]:
        assert all(isinstance(v, int) for v in recs[0]["bounds"]["m"]["in"])
    fig = plot_rule_boxes(m, X, 0)
    fig.savefig(tmp_path / "box.png")
    fig = plot_rule_scatter(m, X, y, ("tcrease", "tpanel"), 0)
    fig.savefig(tmp_path / "scatter.png")
    fig = plot_feature_importance(m)
    fig.savefig(tmp_path / "imp.png")
    for f in ("box.png", "scatter.png", "imp.png"):
        assert (tmp_path / f).stat().st_size > 1000
    with pytest.raises(ValueError, match="feature 'q'"):
        plot_rule_scatter(m, X, y, ("q", "W"))


def test_read_table_and_roles(reference_data, tmp_path):
    p = reference_data.path("data3_ShapeFit")
    df = read_table(p)  # column names from the sibling data3_FeatureName.txt
    assert list(df.columns) == reference_data.columns("data3_ShapeFit")
    assert df.shape == (3000, 11)
    roles = column_roles(df.columns)
    assert roles is PUBLISHED["data3"] and roles.categorical == ("m",)
    assert column_roles(["a", "b"]) is None
    for key, r in PUBLISHED.items():
        assert set(r.categorical) <= set(r.features), key
        assert not set(r.features) & set(r.performance), key
    # CSV with header, and a headerless file without names
    small = pd.DataFrame({"a": [1.0, 2.0], "b": [3.0, 4.0]})
    small.to_csv(tmp_path / "s.csv", index=False)
    pd.testing.assert_frame_equal(read_table(tmp_path / "s.csv"), small)
    small.to_parquet(tmp_path / "s.parquet")
    pd.testing.assert_frame_equal(read_table(tmp_path / "s.parquet", columns=["b"]), small[["b"]])
    (tmp_path / "x_data.txt").write_text("1,3\n2,4\n")
    with pytest.raises(ValueError, match="no header"):
        read_table(tmp_path / "x_data.txt")
    pd.testing.assert_frame_equal(read_table(tmp_path / "x_data.txt", columns=["a", "b"]), small)
    with pytest.raises(ValueError, match="2 columns but 3 names"):
        read_table(tmp_path / "x_data.txt", columns=["a", "b", "c"])
    (tmp_path / "s.xlsx").write_text("")
    with pytest.raises(ValueError, match="unknown database type '.xlsx'"):
        read_table(tmp_path / "s.xlsx")
    with pytest.raises(FileNotFoundError):
        read_table(tmp_path / "missing.csv")
