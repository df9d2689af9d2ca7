"""Evaluating mined rules: hold-out tests, repeated splits, a work-sharing grid search, baselines.

All splits are ``sklearn.model_selection.train_test_split(rows, test_size=0.4,
random_state=s)`` over the rows in their given order, so figures compare with the paper's
scripts and with issue 6's table. Unless told otherwise the forest is seeded with the same ``s``.
"""

from __future__ import annotations

import itertools
import logging
import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd
from joblib import Parallel, delayed
from sklearn.base import clone
from sklearn.ensemble import GradientBoostingClassifier
from sklearn.metrics import precision_score
from sklearn.model_selection import train_test_split
from sklearn.neighbors import KNeighborsClassifier
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

from holofold.design.rules import FewRulesWarning, ForestRuleMiner

__all__ = [
    "HoldoutResult",
    "split_indices",
    "rule_scores",
    "holdout",
    "repeated_holdout",
    "summarize",
    "grid_search",
    "baselines",
    "feature_dependence",
]

logger = logging.getLogger(__name__)

FIG_S8_DEPTHS = (8, 12, 16, 20, 24, 28, 32)
FIG_S8_TREES = (20, 40, 60, 100, 200)


def _take(X, idx):
    return X.iloc[idx] if isinstance(X, pd.DataFrame) else np.asarray(X)[idx]


def split_indices(n_rows: int, *, test_size: float = 0.4, random_state=None):
    """Train and test row indices, exactly as ``train_test_split`` orders them.

    Returns
    -------
    train, test : ndarray of int
    """
    if not 0 < test_size < 1:
        raise ValueError(f"test_size must be in (0, 1), got {test_size}")
    train, test = train_test_split(
        np.arange(n_rows), test_size=test_size, random_state=random_state
    )
    return train, test


def rule_scores(miner: ForestRuleMiner, X, y, *, which: str = "top") -> pd.DataFrame:
    """Precision, recall and support of each rule on the rows ``X, y``.

    Parameters
    ----------
    miner : fitted ForestRuleMiner
    X : array-like of shape (n_samples, n_features)
    y : array-like of shape (n_samples,)
        Labels in the miner's classes; the target class is ``miner.classes_[1]``.
    which : {"top", "all"}, default="top"

    Returns
    -------
    DataFrame with columns ``precision``, ``recall``, ``support``, ``true_positives``, one row
    per rule in the order of ``miner.rules_`` (or ``candidate_rules_``). Precision is 0 for a
    rule matching no row.
    """
    inside = miner.rule_matches(X, which=which)
    pos = np.asarray(y) == miner.classes_[1]
    tp = (inside & pos).sum(axis=1)
    sup = inside.sum(axis=1)
    return pd.DataFrame(
        {
            "precision": np.where(sup > 0, tp / np.maximum(sup, 1), 0.0),
            "recall": tp / max(int(pos.sum()), 1),
            "support": sup.astype(np.intp),
            "true_positives": tp.astype(np.intp),
        }
    )


@dataclass(frozen=True)
class HoldoutResult:
    """A rule miner fitted on the training part of a split and scored on its test part.

    Attributes
    ----------
    miner : ForestRuleMiner
        Fitted on the training rows.
    rules : DataFrame
        ``miner.rules_`` plus ``test_precision``, ``test_recall``, ``test_support`` and
        ``test_true_positives``.
    train_index, test_index : ndarray of int
        Row positions in the input.
    """

    miner: ForestRuleMiner
    rules: pd.DataFrame
    train_index: np.ndarray
    test_index: np.ndarray

    @property
    def top_test_precision(self) -> float:
        """Test precision of the best rule (NaN when no rule survived)."""
        return float(self.rules["test_precision"].iloc[0]) if len(self.rules) else float("nan")


def holdout(
    miner: ForestRuleMiner,
    X,
    y,
    *,
    test_size: float = 0.4,
    random_state=None,
    seed_forest: bool = True,
    feature_names=None,
) -> HoldoutResult:
    """Fit a clone of ``miner`` on a training split and score its rules on the test split.

    Parameters
    ----------
    miner : ForestRuleMiner
        Unfitted template (cloned).
    X, y : array-like
    test_size : float, default=0.4
    random_state : int or None
        Seed of the split.
    seed_forest : bool, default=True
        Also seed the forest with ``random_state`` (otherwise the template's own seed is kept).
    feature_names : sequence of str, optional
        For an array X.
    """
    y = np.asarray(y)
    train, test = split_indices(y.shape[0], test_size=test_size, random_state=random_state)
    est = clone(miner)
    if seed_forest and random_state is not None:
        est.set_params(random_state=random_state)
    est.fit(_take(X, train), y[train], feature_names=feature_names)
    scores = rule_scores(est, _take(X, test), y[test])
    rules = pd.concat([est.rules_, scores.add_prefix("test_")], axis=1)
    return HoldoutResult(est, rules, train, test)


def _top_row(res: HoldoutResult, seed) -> dict:
    r = res.rules
    row = {"seed": seed, "n_rules": len(r)}
    if len(r):
        top = r.iloc[0]
        row.update(
            rule=top["rule"],
            train_precision=top["precision"],
            train_support=top["support"],
            test_precision=top["test_precision"],
            test_recall=top["test_recall"],
            test_support=top["test_support"],
        )
    else:
        row.update(
            rule="",
            train_precision=np.nan,
            train_support=0,
            test_precision=np.nan,
            test_recall=np.nan,
            test_support=0,
        )
    return row


def repeated_holdout(
    miner: ForestRuleMiner,
    X,
    y,
    *,
    seeds=range(5),
    test_size: float = 0.4,
    seed_forest: bool = True,
    feature_names=None,
    n_jobs=None,
) -> pd.DataFrame:
    """Hold-out test of the top rule on several splits.

    Returns
    -------
    DataFrame, one row per seed: ``seed``, ``n_rules``, ``rule``, ``train_precision``,
    ``train_support``, ``test_precision``, ``test_recall``, ``test_support``
    (NaN precision when no rule survived). Use :func:`summarize` for mean and spread.
    """

    def one(s):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FewRulesWarning)
            res = holdout(
                miner,
                X,
                y,
                test_size=test_size,
                random_state=s,
                seed_forest=seed_forest,
                feature_names=feature_names,
            )
        return _top_row(res, s)

    rows = Parallel(n_jobs=n_jobs)(delayed(one)(s) for s in seeds)
    return pd.DataFrame(rows)


def summarize(frame: pd.DataFrame, column: str = "test_precision") -> dict:
    """Mean, standard deviation, min and max of a column over splits (NaN rows ignored)."""
    v = frame[column].to_numpy(dtype=float)
    ok = v[np.isfinite(v)]
    return {
        "mean": float(ok.mean()) if ok.size else float("nan"),
        "std": float(ok.std(ddof=1)) if ok.size > 1 else 0.0,
        "min": float(ok.min()) if ok.size else float("nan"),
        "max": float(ok.max()) if ok.size else float("nan"),
        "n_splits": int(v.size),
        "n_without_rule": int(v.size - ok.size),
    }


def _score_prefixes(est, n_trees, Xtr, ytr, Xte, yte, params, seed):
    rows = []
    for k in n_trees:
        sub = est if k == len(est.estimators_) else est.with_n_estimators(k, Xtr, ytr)
        sc = rule_scores(sub, Xte, yte)
        top = sub.rules_.iloc[0] if len(sub.rules_) else None
        rows.append(
            {
                **params,
                "n_estimators": k,
                "seed": seed,
                "n_rules": len(sub.rules_),
                "train_precision": np.nan if top is None else top["precision"],
                "test_precision": np.nan if top is None else sc["precision"].iloc[0],
                "test_support": 0 if top is None else sc["support"].iloc[0],
            }
        )
    return rows


def _grid_task(base_params, params, depths, X, y, seed, test_size, n_trees, feature_names):
    """All depths of one grid cell on one split, sharing work.

    One forest with ``max(n_trees)`` trees per depth; smaller forests are its first trees.
    Depths run in increasing order and each forest is derived from the previous one with
    ``ForestRuleMiner.with_max_depth``, which retrains only the trees that reached the limit.
    """
    y = np.asarray(y)
    train, test = split_indices(y.shape[0], test_size=test_size, random_state=seed)
    Xtr, ytr, Xte, yte = _take(X, train), y[train], _take(X, test), y[test]
    rows, est, retrained = [], None, 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FewRulesWarning)
        for depth in sorted(depths, key=lambda d: (d is None, d or 0)):
            cell = {**params, "max_depth": depth}
            if est is None:
                est = ForestRuleMiner(
                    **{**base_params, **cell, "n_estimators": max(n_trees), "random_state": seed}
                )
                est.set_params(n_jobs=1)
                est.fit(Xtr, ytr, feature_names=feature_names)
                retrained += len(est.estimators_)
            else:
                est = est.with_max_depth(depth, Xtr, ytr)
                retrained += est.n_retrained_
            rows.extend(_score_prefixes(est, n_trees, Xtr, ytr, Xte, yte, cell, seed))
    logger.info("grid cell %s seed %s: %d trees trained", params, seed, retrained)
    return rows


def grid_search(
    X,
    y,
    *,
    max_depth=FIG_S8_DEPTHS,
    n_estimators=FIG_S8_TREES,
    ccp_alpha=(1e-4,),
    criterion=("entropy",),
    max_samples=(0.5,),
    seeds=range(5),
    test_size: float = 0.4,
    miner: ForestRuleMiner | None = None,
    feature_names=None,
    n_jobs=None,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Grid search over depth x trees x ccp_alpha x criterion x subset ratio on repeated splits.

    Work is shared: for each (depth, ccp_alpha, criterion, subset, split) one forest with
    ``max(n_estimators)`` trees is trained, and the smaller forests are its first trees
    (identical to forests trained alone, see ``ForestRuleMiner.with_n_estimators``); going
    to a larger depth retrains only the trees that reached the smaller limit
    (``ForestRuleMiner.with_max_depth``; exact). The
    (ccp_alpha, criterion, subset, split) cells run in parallel processes (joblib).

    Parameters
    ----------
    X, y : array-like
    max_depth, n_estimators, ccp_alpha, criterion, max_samples : sequences
        Grid values (defaults: Fig. S8 of the paper, other parameters at their defaults).
    seeds : iterable of int
        Split seeds (the forest is seeded with the same value).
    miner : ForestRuleMiner, optional
        Template for all other parameters (e.g. ``categorical_features``).
    n_jobs : int or None
        Parallel processes.

    Returns
    -------
    runs : DataFrame
        One row per (cell, n_estimators, seed): ``test_precision`` of the top rule etc.
    table : DataFrame
        Mean and std of the test precision over seeds per cell, best first.
    """
    base = (miner or ForestRuleMiner()).get_params()
    cells = [
        dict(ccp_alpha=a, criterion=c, max_samples=m)
        for a, c, m in itertools.product(ccp_alpha, criterion, max_samples)
    ]
    depths = tuple(max_depth)
    n_trees = tuple(sorted({int(k) for k in n_estimators}))
    if not n_trees or n_trees[0] < 1:
        raise ValueError(f"n_estimators values must be >= 1, got {n_estimators}")
    tasks = [(cell, s) for cell in cells for s in seeds]
    out = Parallel(n_jobs=n_jobs)(
        delayed(_grid_task)(base, cell, depths, X, y, s, test_size, n_trees, feature_names)
        for cell, s in tasks
    )
    runs = pd.DataFrame([r for rows in out for r in rows])
    keys = ["max_depth", "ccp_alpha", "criterion", "max_samples", "n_estimators"]
    table = (
        runs.groupby(keys, sort=True)["test_precision"]
        .agg(["mean", "std", "count"])
        .reset_index()
        .sort_values(["mean"], ascending=False, kind="stable")
        .reset_index(drop=True)
    )
    return runs, table


def baselines(
    X,
    y,
    *,
    seeds=range(5),
    test_size: float = 0.4,
    n_neighbors: int = 5,
    protocol: str = "holofold",
    categorical=(),
) -> pd.DataFrame:
    """Baselines on the same splits: test precision of kNN and gradient boosting.

    ``protocol="holofold"`` (default) makes both independent of units: each numeric feature is
    standardised first (kNN's distances and boosting's trees then see the same numbers whether
    the table is in m, mm or um), boosting has scikit-learn's defaults seeded with the split
    seed. ``protocol="paper"`` is the paper's scripts: features as given (pass the table in the
    paper's units, mm and um, :func:`paper_features`), categorical features one-hot encoded
    (``categorical``: their names), kNN with scikit-learn's defaults and boosting with 200
    trees, ``min_samples_leaf=4``, ``min_samples_split=8``. Precision is 0 when a model
    predicts no target row.

    Returns
    -------
    DataFrame, one row per seed: ``seed``, ``knn_precision``, ``gb_precision``,
    ``knn_recall``, ``gb_recall``.
    """
    if protocol not in ("holofold", "paper"):
        raise ValueError(f"protocol must be 'holofold' or 'paper', got {protocol!r}")
    y = np.asarray(y)
    frame = X if isinstance(X, pd.DataFrame) else pd.DataFrame(np.asarray(X, dtype=float))
    if protocol == "paper" and categorical:
        frame = pd.get_dummies(frame, columns=list(categorical), dtype=float)
    Xa = frame.to_numpy(dtype=float)
    rows = []
    for s in seeds:
        train, test = split_indices(y.shape[0], test_size=test_size, random_state=s)
        row = {"seed": s}
        if protocol == "paper":
            models = {
                "knn": KNeighborsClassifier(n_neighbors=n_neighbors),
                "gb": GradientBoostingClassifier(
                    n_estimators=200, min_samples_leaf=4, min_samples_split=8, random_state=s
                ),
            }
        else:
            models = {
                "knn": make_pipeline(
                    StandardScaler(), KNeighborsClassifier(n_neighbors=n_neighbors)
                ),
                "gb": make_pipeline(StandardScaler(), GradientBoostingClassifier(random_state=s)),
            }
        for name, model in models.items():
            model.fit(Xa[train], y[train])
            pred = model.predict(Xa[test])
            pos = np.unique(y)[-1]
            row[f"{name}_precision"] = precision_score(
                y[test], pred, pos_label=pos, zero_division=0
            )
            hit = (pred == pos) & (y[test] == pos)
            row[f"{name}_recall"] = hit.sum() / max(int((y[test] == pos).sum()), 1)
        rows.append(row)
    return pd.DataFrame(rows)


def feature_dependence(
    miner: ForestRuleMiner, X, y, *, n_repeats: int = 5, random_state=0, alpha: float = 0.05
) -> pd.DataFrame:
    """Which features the target depends on: permutation importance of the forest on ``X, y``.

    Each feature in turn is shuffled among the rows ``n_repeats`` times; its importance is the
    mean rise of the forest's Brier score (``miner.forest_probability``) over the rows. The
    target depends on the feature when that rise is significant (one-sided z test over the
    rows at level ``alpha``). Use rows the miner did not train on (the test split).

    Returns
    -------
    DataFrame, one row per feature in the miner's order: ``feature``, ``importance``, ``se``,
    ``p_value``, ``depends``.
    """
    from scipy.stats import norm

    names = miner.feature_names_
    frame = X if isinstance(X, pd.DataFrame) else pd.DataFrame(np.asarray(X), columns=names)
    frame = frame.reset_index(drop=True)
    pos = (np.asarray(y) == miner.classes_[1]).astype(float)
    if len(frame) < 2:
        raise ValueError(f"feature_dependence needs at least 2 rows, got {len(frame)}")
    loss = (miner.forest_probability(frame) - pos) ** 2
    rng = np.random.default_rng(random_state)
    rows = []
    for name in names:
        rise = np.zeros(len(frame))
        for _ in range(n_repeats):
            shuffled = frame.copy()
            shuffled[name] = frame[name].to_numpy()[rng.permutation(len(frame))]
            rise += (miner.forest_probability(shuffled) - pos) ** 2 - loss
        rise /= n_repeats
        mean, se = float(rise.mean()), float(rise.std(ddof=1) / np.sqrt(rise.size))
        p = float(norm.sf(mean / se)) if se > 0 else (0.0 if mean > 0 else 1.0)
        rows.append(
            {"feature": name, "importance": mean, "se": se, "p_value": p, "depends": p < alpha}
        )
    return pd.DataFrame(rows)
