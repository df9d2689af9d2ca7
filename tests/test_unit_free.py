"""Mining does not depend on units: a table in m, mm or um gives the same rules (thresholds
scaled) and the same precisions, and a tiny column in SI is split like any other."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import sklearn
from packaging.version import Version
from sklearn.tree import DecisionTreeClassifier

from holofold.design import ForestRuleMiner, column_roles, mine_rules, mined_rules
from holofold.design.rules.evaluation import baselines, feature_dependence

#: per shipped scenario: its published database (sample files joined) and a target on it
CASES = {
    "single-miura": (["data0_SingleMiura"], "axialstiff60 < 6000"),
    "canopy": (
        ["data1_MiuraSheet_sample", "data1_TMPSheet_sample"],
        "bendstiff60 < 15000 & axialstiff90 < 150000",
    ),
    "arch": (["data3_ShapeFit"], "Zstiff > 800 & Xstiff > 600 & error < 0.1"),
    "gripper": (
        ["data2_MiuraBased_sample", "data2_SplittedMiura_sample", "data2_TwoPanel_sample"],
        "stiff > 0.0015",
    ),
}


def _table(reference_data, stems):
    return pd.concat([reference_data.load(s) for s in stems], ignore_index=True)


def _scaled(table, roles, factor):
    """The table with every numeric feature multiplied by ``factor`` (m -> mm or um)."""
    out = table.copy()
    for c in roles.features:
        if c not in roles.categorical:
            out[c] = out[c] * factor
    return out


@pytest.mark.parametrize("scenario", list(CASES))
def test_the_same_rules_in_m_mm_and_um(reference_data, scenario):
    stems, target = CASES[scenario]
    table = _table(reference_data, stems)
    roles = column_roles(table.columns)
    kw = dict(roles=roles, seed=1, n_estimators=30, n_rules=3)
    base = mine_rules(table, target, **kw)
    rules = mined_rules(base.miner, base.test_scores)
    assert rules, scenario
    for factor in (1e3, 1e6):
        other = mine_rules(_scaled(table, roles, factor), target, **kw)
        again = mined_rules(other.miner, other.test_scores)
        assert other.miner.n_candidates_ == base.miner.n_candidates_
        assert len(again) == len(rules)
        for a, b in zip(rules, again, strict=True):
            assert a.features == b.features
            for ca, cb in zip(a.conditions, b.conditions, strict=True):
                assert ca.levels == cb.levels
                for side in ("gt", "le"):
                    va, vb = getattr(ca, side), getattr(cb, side)
                    assert (va is None) == (vb is None)
                    if va is not None:  # thresholds scaled, to a few ulps
                        factor_c = 1.0 if ca.feature in roles.categorical else factor
                        assert vb == pytest.approx(va * factor_c, rel=1e-12, abs=0)
            # the same rows: the same scores, exactly
            assert (a.train, a.test, a.estimate) == (b.train, b.test, b.estimate)
        pd.testing.assert_frame_equal(other.dependence, base.dependence, check_exact=False,
                                      rtol=1e-9)  # fmt: skip


def test_a_micrometre_column_in_metres_is_split_and_found_to_matter():
    """y depends on t (1.5e-7 to 2.5e-7 m) and on w; x is noise. scikit-learn's splitter
    treats values closer than 1e-7 as equal and cannot split t in metres (from 1.8 on; 1.6 and
    1.7 do split it); the miner can with any, and says the target depends on t."""
    rng = np.random.default_rng(0)
    n = 1500
    X = pd.DataFrame(
        {
            "t": rng.uniform(1.5e-7, 2.5e-7, n),
            "w": rng.uniform(1e-4, 3e-4, n),
            "x": rng.uniform(0, 1, n),
        }
    )
    y = (X["t"] < 1.9e-7) & (X["w"] > 1.5e-4)
    plain = DecisionTreeClassifier(random_state=0).fit(X, y)
    if Version(sklearn.__version__) >= Version("1.8"):  # 1.6 and 1.7 split on t here
        assert not np.any(plain.tree_.feature == 0)  # the cause: no split on t at all
    m = ForestRuleMiner(n_estimators=30, n_rules=1, random_state=0).fit(X.iloc[:1000], y[:1000])
    assert any(np.any(t.feature[t.left >= 0] == 0) for t in m.trees_)
    top = mined_rules(m)[0]
    assert top.condition("t").le == pytest.approx(1.9e-7, rel=0.03)
    dep = feature_dependence(m, X.iloc[1000:], y[1000:], random_state=0)
    assert dep.set_index("feature")["depends"].to_dict() == {"t": True, "w": True, "x": False}


def test_baselines_do_not_depend_on_units():
    rng = np.random.default_rng(1)
    X = pd.DataFrame({"t": rng.uniform(1.5e-7, 2.5e-7, 600), "w": rng.uniform(0, 1, 600)})
    y = ((X["t"] < 2e-7) & (X["w"] > 0.3)).to_numpy()
    a = baselines(X, y, seeds=range(2))
    b = baselines(X.assign(t=X["t"] * 1e6), y, seeds=range(2))
    pd.testing.assert_frame_equal(a, b)
    assert (a["gb_precision"] > 0.85).all()  # boosting splits t too
