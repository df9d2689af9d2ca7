"""ForestRuleMiner: exact tree semantics, vectorised extraction and scoring, the estimator API."""

import warnings

import numpy as np
import pandas as pd
import pytest
from sklearn.base import clone
from sklearn.tree import DecisionTreeClassifier
from sklearn.utils.estimator_checks import parametrize_with_checks

from holofold.design.rules import FewRulesWarning, ForestRuleMiner, forest_boxes, stack_trees

# ---------------------------------------------------------------------------------------------
# scikit-learn API compliance
# ---------------------------------------------------------------------------------------------


@parametrize_with_checks([ForestRuleMiner(n_estimators=10, random_state=0)])
def test_sklearn_estimator_checks(estimator, check):
    # every applicable check passes; array-API input is skipped by sklearn itself
    # (SCIPY_ARRAY_API unset). Tiny check data often leaves fewer than n_rules rules.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FewRulesWarning)
        check(estimator)


def test_get_set_params_and_clone():
    m = ForestRuleMiner(max_depth=7, n_rules=5, categorical_features=["m"])
    p = m.get_params()
    assert p["max_depth"] == 7 and p["n_rules"] == 5 and p["beta"] == 0.2
    # the paper's ranking; tightened, tidied and distinct rules (chosen on the target suite)
    assert p["scoring"] == "train" and p["ranking"] == "fbeta" and p["max_overlap"] == 0.5
    assert p["tighten"] is True and p["simplify"] == "idle" and p["prior_strength"] == "auto"
    assert p["criterion"] == "entropy" and p["class_weight"] == "balanced"
    assert p["max_samples"] == 0.5 and p["ccp_alpha"] == 1e-4 and p["n_estimators"] == 100
    m.set_params(beta=0.5, precision_min=0.8)
    c = clone(m)
    assert c.get_params()["beta"] == 0.5 and c.get_params()["precision_min"] == 0.8
    with pytest.raises(ValueError, match="precision_min"):
        ForestRuleMiner(precision_min=1.5).fit(np.zeros((4, 1)), [0, 1, 0, 1])


# ---------------------------------------------------------------------------------------------
# exact semantics
# ---------------------------------------------------------------------------------------------


def _one_tree(**kw):
    base = dict(
        n_estimators=1,
        max_samples=1.0,
        precision_min=0.0,
        min_support=1,
        n_rules=1000,
        ccp_alpha=0.0,
        min_samples_leaf=1,
        min_samples_split=2,
        random_state=0,
        max_overlap=None,
        simplify="none",
        tighten=False,
    )
    base.update(kw)
    return ForestRuleMiner(**base)


def test_threshold_zero_is_a_real_bound():
    # the only split is at the midpoint of -1 and 1: exactly 0.0
    X = np.array([[-1.0], [-1.0], [1.0], [1.0]])
    y = np.array([0, 0, 1, 1])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FewRulesWarning)
        m = _one_tree().fit(X, y)
    assert m.trees_[0].threshold[0] == 0.0
    assert len(m.rules_) == 1
    assert m.rules_.loc[0, "x0_gt"] == 0.0  # not dropped as a "no bound" sentinel
    assert m.rules_.loc[0, "x0_le"] == np.inf
    assert m.rules_.loc[0, "rule"] == "x0 > 0"
    # x <= t goes left (not the target), x > t right
    np.testing.assert_array_equal(m.predict([[0.0], [1e-30], [-1e-30], [5.0]]), [0, 1, 0, 1])


def test_upper_bound_is_inclusive_in_float64():
    X = np.array([[1.0], [2.0], [3.0], [4.0]])
    y = np.array([1, 1, 0, 0])  # split at 2.5, left branch (x <= 2.5) is the target
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FewRulesWarning)
        m = _one_tree().fit(X, y)
    assert m.rules_.loc[0, "x0_le"] == 2.5
    above32 = float(np.nextafter(np.float32(2.5), np.float32(3)))
    above64 = np.nextafter(2.5, 3.0)  # rounds to 2.5 in float32, but is above it: outside
    probe = [[2.5], [above32], [above64], [-7.0]]
    np.testing.assert_array_equal(m.predict(probe), [1, 0, 0, 1])


def test_rules_apply_exactly_like_the_trees():
    """Each leaf's box holds exactly the rows the trees send to that leaf, including values
    at thresholds and one float64 ulp around them (one semantics: float64, x <= t left)."""
    rng = np.random.default_rng(1)
    X = rng.normal(size=(300, 3))
    y = (X[:, 0] + 0.5 * X[:, 1] ** 2 - X[:, 2] > 0.3).astype(int)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FewRulesWarning)
        m = _one_tree(precision_min=0.0).fit(X, y)
    tree = m.trees_[0]
    thr = tree.threshold[tree.left >= 0]
    # probe rows: random, exactly at thresholds, and one float64 ulp around them
    probes = [rng.normal(size=(500, 3))]
    for t in thr:
        for v in (t, np.nextafter(t, np.inf), np.nextafter(t, -np.inf), np.float32(t)):
            row = rng.normal(size=(3, 3))
            row[np.arange(3), np.arange(3)] = v
            probes.append(row)
    P = np.vstack(probes)
    leaf = m.apply(P)[:, 0]
    ids = np.flatnonzero(tree.left < 0)
    positive = tree.positive[ids]
    inside = m.rule_matches(P, which="all")
    # every target leaf is one rule (no duplicates within one tree) ...
    assert inside.shape[0] == positive.sum()
    # ... and its matches are exactly the rows in that leaf
    got = sorted(tuple(np.flatnonzero(r)) for r in inside)
    want = sorted(tuple(np.flatnonzero(leaf == i)) for i in ids[positive])
    assert got == want
    # predict with all rules kept equals the tree's own prediction
    np.testing.assert_array_equal(m.predict(P), tree.positive[leaf])


@pytest.mark.parametrize("ccp_alpha", [0.0, 1e-3])
def test_the_trees_are_scikit_learns_on_a_well_scaled_table(ccp_alpha):
    """Grown on rank codes, a tree is the one scikit-learn grows on the values themselves
    (when no two values are closer than its 1e-7 tie limit): the same leaves for every row,
    its thresholds at the same midpoints, pruned the same way."""
    rng = np.random.default_rng(4)
    X = rng.uniform(1, 5, size=(400, 3))
    y = ((X[:, 0] > 2.5) & (X[:, 1] < 4)) ^ (rng.uniform(size=400) < 0.1)
    # every leaf is asked for (1000 rules): fewer exist, and the miner says so
    with pytest.warns(FewRulesWarning, match="of the 1000 requested rules"):
        m = _one_tree(ccp_alpha=ccp_alpha, min_samples_leaf=2, min_samples_split=4).fit(X, y)
    rows = m.estimators_samples_[0]
    ref = DecisionTreeClassifier(
        criterion="entropy", min_samples_leaf=2, min_samples_split=4, max_depth=20,
        ccp_alpha=ccp_alpha, random_state=int(m._seeds[0]), class_weight="balanced",
    ).fit(X[rows], y[rows])  # fmt: skip
    ours = m.trees_[0]
    probe = rng.uniform(1, 5, size=(2000, 3))
    a, b = m.apply(probe)[:, 0], ref.apply(probe)
    # the same partition of the rows into leaves (node ids differ after pruning)
    pairs = set(zip(a.tolist(), b.tolist(), strict=True))
    assert len(pairs) == len(set(a.tolist())) == len(set(b.tolist()))
    if ccp_alpha:  # pruning cut branches, the same ones
        assert ref.get_n_leaves() < m.estimators_[0].get_n_leaves()
    assert np.count_nonzero(ours.left >= 0) == ref.get_n_leaves() - 1
    ref_thr = np.sort(ref.tree_.threshold[ref.tree_.children_left >= 0])
    np.testing.assert_allclose(np.sort(ours.threshold[ours.left >= 0]), ref_thr, rtol=1e-7)


def test_forest_boxes_match_path_walk():
    rng = np.random.default_rng(3)
    X = rng.uniform(size=(400, 4))
    y = (X[:, 0] > X[:, 1]).astype(int)
    m = ForestRuleMiner(n_estimators=5, random_state=2, max_depth=6).fit(X, y)
    forest = stack_trees(m.trees_)
    lower, upper = forest_boxes(forest, 4)
    for k, tr in enumerate(m.trees_):
        stack = [(0, np.full(4, -np.inf), np.full(4, np.inf))]
        while stack:  # a plain recursive walk, node by node
            i, lo, hi = stack.pop()
            g = forest.offsets[k] + i
            np.testing.assert_array_equal(lower[g], lo)
            np.testing.assert_array_equal(upper[g], hi)
            if tr.left[i] >= 0:
                f, th = tr.feature[i], tr.threshold[i]
                hi2 = hi.copy()
                hi2[f] = min(hi2[f], th)
                lo2 = lo.copy()
                lo2[f] = max(lo2[f], th)
                stack.append((tr.left[i], lo, hi2))
                stack.append((tr.right[i], lo2, hi))


def test_scores_are_exact_and_boxes_unique():
    rng = np.random.default_rng(0)
    X = rng.uniform(size=(600, 3))
    y = ((X[:, 0] > 0.6) & (X[:, 1] < 0.5)) | (rng.uniform(size=600) < 0.03)
    m = ForestRuleMiner(
        n_estimators=30, random_state=0, scoring="train", ranking="fbeta", max_overlap=None,
        simplify="none", tighten=False,
    )  # fmt: skip
    m.fit(X, y)
    c = m.candidate_rules_
    inside = m.rule_matches(X, which="all")
    np.testing.assert_array_equal(c["support"], inside.sum(1))
    np.testing.assert_array_equal(c["true_positives"], (inside & y).sum(1))
    np.testing.assert_allclose(c["precision"], (inside & y).sum(1) / inside.sum(1))
    np.testing.assert_allclose(c["recall"], (inside & y).sum(1) / y.sum())
    b2 = 0.04
    f = (1 + b2) * c["precision"] * c["recall"] / (b2 * c["precision"] + c["recall"])
    np.testing.assert_allclose(c["f_score"], f)
    np.testing.assert_allclose(c["score"], f)  # paper's ranking: score is F-beta
    assert (np.diff(c["score"]) <= 0).all()  # ranked best first
    assert (c["precision"] >= 0.9).all() and (c["support"] >= 10).all()
    # identical boxes merged: no two candidates share a box; some were found by > 1 tree
    keys = c.filter(regex="_(gt|le)$").to_numpy()
    assert len(np.unique(keys, axis=0)) == len(c)
    assert c["n_trees"].max() > 1
    # rules_ is the head of the ranking
    pd.testing.assert_frame_equal(m.rules_, c.iloc[:3].reset_index(drop=True))


def test_oob_scoring_is_out_of_bag():
    rng = np.random.default_rng(5)
    X = rng.uniform(size=(500, 2))
    y = (X[:, 0] > 0.7) ^ (rng.uniform(size=500) < 0.05)
    m = ForestRuleMiner(n_estimators=1, random_state=0, scoring="oob", ranking="fbeta", n_rules=50)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FewRulesWarning)
        m.fit(X, y)
    rows = np.setdiff1d(np.arange(500), m.estimators_samples_[0])
    assert len(m.estimators_samples_[0]) == 250  # half, without replacement
    inside = m.rule_matches(X[rows], which="all")
    c = m.candidate_rules_
    np.testing.assert_array_equal(c["oob_support"], inside.sum(1))
    np.testing.assert_allclose(
        c["oob_precision"], (inside & y[rows]).sum(1) / np.maximum(inside.sum(1), 1)
    )


def test_fewer_than_k_rules_warns_and_returns_what_there_is():
    rng = np.random.default_rng(0)
    X = rng.uniform(size=(200, 2))
    y = X[:, 0] > 0.5
    with pytest.warns(FewRulesWarning, match=r"only \d+ of the 500 requested rules: \d+ reach"):
        m = ForestRuleMiner(n_estimators=5, n_rules=500, random_state=0).fit(X, y)
    assert 0 < len(m.rules_) < 500
    with pytest.warns(FewRulesWarning, match="only 0 of the 3"):
        m = ForestRuleMiner(n_estimators=5, min_support=1000, random_state=0).fit(X, y)
    assert len(m.rules_) == 0
    assert not m.predict(X).any()
    assert (m.decision_function(X) == 0).all()


@pytest.mark.filterwarnings("ignore::holofold.design.rules.FewRulesWarning")
def test_labels_and_positive_class():
    rng = np.random.default_rng(0)
    X = rng.uniform(size=(300, 2))
    y = np.where(X[:, 0] > 0.6, "hit", "miss")  # target class is the larger label: "miss"
    m = ForestRuleMiner(n_estimators=10, random_state=0).fit(X, y)
    assert list(m.classes_) == ["hit", "miss"]
    assert set(m.predict(X)) <= {"hit", "miss"}
    with pytest.raises(ValueError, match="Only binary"):
        m.fit(X, np.arange(300) % 3)


# ---------------------------------------------------------------------------------------------
# categorical features
# ---------------------------------------------------------------------------------------------


def _categorical_data(n=1200, seed=0):
    rng = np.random.default_rng(seed)
    df = pd.DataFrame(
        {
            "m": rng.choice([8.0, 12.0, 16.0, 24.0], size=n),
            "pattern": rng.choice([1.0, 2.0], size=n),
            "t": rng.uniform(0, 1, size=n),
        }
    )
    y = df["m"].isin([16.0, 24.0]) & (df["pattern"] == 2) & (df["t"] > 0.4)
    return df, y.to_numpy()


@pytest.mark.parametrize("encoding", ["onehot", "ordinal"])
def test_categorical_rules_read_as_levels(encoding):
    df, y = _categorical_data()
    m = ForestRuleMiner(
        n_estimators=30,
        random_state=0,
        categorical_features=["m", "pattern"],
        categorical_encoding=encoding,
        n_rules=1,
    ).fit(df, y)
    top = m.rules_.iloc[0]
    assert top["m_in"] == (16.0, 24.0)
    assert top["pattern_in"] == (2.0,)
    assert "m in {16, 24}" in top["rule"] and "pattern = 2" in top["rule"]
    assert ">= 0.5" not in top["rule"] and "m=" not in top["rule"]
    assert top["precision"] == 1.0 and top["t_gt"] == pytest.approx(0.4, abs=0.02)
    assert m.feature_importances_.shape == (3,)
    assert m.feature_importances_.sum() == pytest.approx(1.0)
    # rows are matched on the original values
    probe = pd.DataFrame({"m": [16.0, 12.0, 24.0], "pattern": [2.0, 2.0, 1.0], "t": [0.9] * 3})
    np.testing.assert_array_equal(m.predict(probe), [True, False, False])
    with pytest.raises(ValueError, match="level 20 not seen in fit"):
        m.predict(probe.assign(m=[20.0, 16.0, 16.0]))


def test_string_categories():
    df, y = _categorical_data()
    df["pattern"] = df["pattern"].map({1.0: "Miura", 2.0: "TMP"})
    m = ForestRuleMiner(
        n_estimators=30, random_state=0, categorical_features=["pattern", "m"], n_rules=1
    ).fit(df, y)
    assert "pattern = TMP" in m.rules_.loc[0, "rule"]
    with pytest.raises(ValueError, match="not numeric"):
        ForestRuleMiner(categorical_features=["m"]).fit(df, y)


def test_categorical_feature_errors():
    df, y = _categorical_data(200)
    with pytest.raises(ValueError, match="categorical feature 'q' is not a feature"):
        ForestRuleMiner(categorical_features=["q"]).fit(df, y)
    with pytest.raises(ValueError, match="feature 't' contains NaN"):
        ForestRuleMiner(categorical_features=["m"]).fit(df.assign(t=np.nan), y)


# ---------------------------------------------------------------------------------------------
# work sharing
# ---------------------------------------------------------------------------------------------


def test_first_trees_are_the_smaller_forest_and_depth_reuse_is_exact():
    df, y = _categorical_data(800, seed=1)
    kw = dict(random_state=4, categorical_features=["m", "pattern"], n_rules=5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FewRulesWarning)
        big = ForestRuleMiner(n_estimators=40, max_depth=4, **kw).fit(df, y)
        small = ForestRuleMiner(n_estimators=15, max_depth=4, **kw).fit(df, y)
        deep = ForestRuleMiner(n_estimators=40, max_depth=9, **kw).fit(df, y)
        sub = big.with_n_estimators(15, df, y)
        deeper = big.with_max_depth(9, df, y)
    pd.testing.assert_frame_equal(sub.rules_, small.rules_)
    pd.testing.assert_frame_equal(sub.candidate_rules_, small.candidate_rules_)
    pd.testing.assert_frame_equal(deeper.candidate_rules_, deep.candidate_rules_)
    assert 0 < deeper.n_retrained_ <= 40
    for a, b in zip(deeper.trees_, deep.trees_, strict=True):
        np.testing.assert_array_equal(a.threshold, b.threshold)


@pytest.mark.filterwarnings("ignore::holofold.design.rules.FewRulesWarning")
def test_feature_names_for_arrays():
    rng = np.random.default_rng(0)
    X = rng.uniform(size=(300, 2))
    y = X[:, 1] > 0.7
    m = ForestRuleMiner(n_estimators=10, random_state=0).fit(X, y, feature_names=["tc", "W"])
    assert m.feature_names_ == ["tc", "W"]
    assert m.rules_.loc[0, "rule"].startswith("W > 0.70")  # tightened to the first target row
    assert m.rules_.loc[0, "W_gt"] == pytest.approx(0.7, abs=0.01)
    assert "W_gt" in m.rules_.columns


def test_max_overlap_gives_distinct_alternatives(reference_data):
    db = reference_data.load("data3_ShapeFit")
    feats = ["m", "tcrease", "tpanel", "W", "offset", "stripeWidth", "extrude"]
    X, y = db[feats], (db["Zsnap"] == 1).to_numpy()
    kw = dict(categorical_features=["m"], random_state=0, n_estimators=40, n_rules=3)
    plain = ForestRuleMiner(**kw, max_overlap=None).fit(X, y)
    distinct = ForestRuleMiner(**kw, max_overlap=0.5).fit(X, y)
    assert distinct.rules_["rule"].iloc[0] == plain.rules_["rule"].iloc[0]  # same best rule
    cover = distinct.rule_matches(X, which="top")
    assert cover.shape[0] == len(distinct.rules_) >= 2
    for i in range(len(cover)):
        for j in range(i):
            inter = np.count_nonzero(cover[i] & cover[j])
            union = np.count_nonzero(cover[i] | cover[j])
            assert inter <= 0.5 * union
    # the candidates are the same; only which alternatives are shown changes
    assert len(distinct.candidate_rules_) == len(plain.candidate_rules_)
