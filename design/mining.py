"""Mining design rules for a target from a performance table: the ``holofold mine`` workflow.

:func:`mine_rules` takes a table (a database of simulated designs), a target expression and the
miner's settings, decides which columns are design features (the table's ``meta.json`` or the
published column sets, unless given), leaves out failed simulations, and fits a
:class:`~holofold.design.rules.ForestRuleMiner` on a hold-out training split
(:func:`holofold.design.evaluation.holdout`), scoring its rules on the test rows.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pandas as pd

from holofold.design.evaluation import (
    HoldoutResult,
    feature_dependence,
    holdout,
    split_indices,
)
from holofold.design.rules import ForestRuleMiner
from holofold.design.tables import ColumnRoles
from holofold.design.targets import Target, parse_target
from holofold.mechanics.status import failed_mask

__all__ = ["MinedRules", "mine_rules", "select_features"]


@dataclass(frozen=True)
class MinedRules:
    """Rules mined for a target, scored on held-out rows.

    Attributes
    ----------
    holdout : HoldoutResult
        The fitted miner (``holdout.miner``), its rules with ``test_*`` columns
        (``holdout.rules``) and the train/test row positions.
    target : Target
    features, categorical : tuple of str
    table : DataFrame
        The rows used (failed simulations left out), in file order.
    n_failed : int
        Failed simulations left out.
    """

    holdout: HoldoutResult
    target: Target
    features: tuple[str, ...]
    categorical: tuple[str, ...]
    table: pd.DataFrame
    n_failed: int

    @property
    def meets(self) -> np.ndarray:
        """(n,) bool: which rows of ``table`` meet the target."""
        return np.asarray(self.target.evaluate(self.table), bool)

    @property
    def miner(self) -> ForestRuleMiner:
        return self.holdout.miner

    @property
    def test_scores(self) -> pd.DataFrame:
        """Test precision, recall, support and true positives per rule (best first)."""
        cols = ["test_precision", "test_recall", "test_support", "test_true_positives"]
        frame = self.holdout.rules[cols]
        return frame.rename(columns=lambda c: c.removeprefix("test_")).reset_index(drop=True)

    @property
    def estimates(self) -> pd.DataFrame:
        """Each rule's estimate with the held-out rows added to its evidence (best first)."""
        return self.miner.rule_estimates(self.test_scores)

    @cached_property
    def dependence(self) -> pd.DataFrame:
        """Which features the target depends on, tested on the held-out rows.

        :func:`holofold.design.evaluation.feature_dependence` of the fitted forest on the test
        split: one row per feature with ``importance``, ``p_value`` and ``depends``.
        """
        test = self.holdout.test_index
        X = self.table[list(self.features)].iloc[test]
        return feature_dependence(self.miner, X, self.meets[test], random_state=0)

    @property
    def independent_features(self) -> tuple[str, ...]:
        """The features the target shows no dependence on (see :attr:`dependence`)."""
        d = self.dependence
        return tuple(d.loc[~d["depends"], "feature"])


def select_features(
    columns: Sequence[str],
    target: Target,
    roles: ColumnRoles | None,
    features: Sequence[str] | None = None,
    categorical: Sequence[str] | None = None,
    *,
    source: str = "the table",
) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """The design features and categorical features to mine, checked against the columns.

    ``features`` default to the roles' design features; a performance column or a column the
    target uses is refused as a feature. ``categorical`` default to the roles' categorical
    features among them.
    """
    columns = [str(c) for c in columns]
    if features is None:
        if roles is None:
            raise ValueError(
                f"cannot tell design features from performance columns in {source} "
                f"({', '.join(columns)}); list them with --features"
            )
        features = list(roles.features)
    features = list(features)
    for f in features:
        if f not in columns:
            raise ValueError(f"feature {f!r} is not a column; columns: {', '.join(columns)}")
    if len(set(features)) != len(features):
        raise ValueError(f"--features lists a column twice: {', '.join(features)}")
    performance = set(roles.performance) if roles is not None else set()
    bad = [f for f in features if f in performance or f in target.columns]
    if bad:
        raise ValueError(
            f"{bad[0]!r} is a performance column (or used by the target) and cannot be a feature"
        )
    if categorical is None:
        categorical = [c for c in (roles.categorical if roles else ()) if c in features]
    for c in categorical:
        if c not in features:
            raise ValueError(
                f"categorical feature {c!r} is not among the features: {', '.join(features)}"
            )
    return tuple(features), tuple(categorical)


def mine_rules(
    table: pd.DataFrame,
    target: str | Target,
    *,
    roles: ColumnRoles | None = None,
    features: Sequence[str] | None = None,
    categorical: Sequence[str] | None = None,
    test_size: float = 0.4,
    seed: int = 0,
    source: str = "the table",
    **params,
) -> MinedRules:
    """Mine rules for ``target`` on a training split of ``table``, scored on the test split.

    Parameters
    ----------
    table : DataFrame
        Designs with their performance columns (and ``status`` for a holofold database:
        failed simulations are left out).
    target : str or Target
        Target expression over the table's columns, e.g. ``"Zstiff > 800 & error < 0.1"``.
    roles : ColumnRoles, optional
        What the columns are (:func:`holofold.design.tables.column_roles`).
    features, categorical : sequence of str, optional
        See :func:`select_features`.
    test_size : float
        Test fraction of ``train_test_split(rows, test_size, random_state=seed)``.
    seed : int
        Seed of the split and of the forest.
    **params
        :class:`~holofold.design.rules.ForestRuleMiner` parameters (``n_estimators``,
        ``max_depth``, ``n_rules``, ``scoring``, ...); checked by the estimator.

    Raises
    ------
    ValueError
        Unknown columns, a target met by no row or by every row, a training split with one
        class, or an invalid miner parameter (one line naming it).
    """
    n_failed = 0
    if "status" in table.columns:
        failed = failed_mask(table["status"])
        n_failed = int(failed.sum())
        table = table.loc[~failed]
    table = table.reset_index(drop=True)
    columns = [str(c) for c in table.columns]
    tgt = target if isinstance(target, Target) else parse_target(target, columns=columns)
    feats, cats = select_features(columns, tgt, roles, features, categorical, source=source)
    miner = ForestRuleMiner(categorical_features=list(cats) or None, random_state=seed, **params)
    miner._validate_params()  # an invalid parameter is refused before any work
    y = tgt.evaluate(table)
    n_hit = int(y.sum())
    if n_hit == 0 or n_hit == y.size:
        raise ValueError(
            f"the target {str(tgt)!r} is met by {n_hit} of {y.size} rows; rules need both "
            "designs that meet it and designs that do not"
        )
    train, _ = split_indices(len(table), test_size=test_size, random_state=seed)
    if y[train].all() or not y[train].any():
        raise ValueError("the training split holds only one class; change --seed or --test-size")
    res = holdout(miner, table[list(feats)], y, test_size=test_size, random_state=seed)
    return MinedRules(res, tgt, feats, cats, table, n_failed)
