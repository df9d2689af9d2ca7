"""Mining design rules for a target from a performance table: the ``holofold mine`` workflow.

:func:`mine_rules` takes a table (a database of simulated designs), a target expression and the
miner's settings, decides which columns are design features (the table's ``meta.json`` or the
published column sets, unless given), leaves out failed simulations, and fits a
:class:`~holofold.design.rules.ForestRuleMiner` on a hold-out training split
(:func:`holofold.design.rules.evaluation.holdout`), scoring its rules on the test rows.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pandas as pd

from holofold.design.database.row_status import failed_rows
from holofold.design.database.tables import ColumnRoles
from holofold.design.rules import ForestRuleMiner
from holofold.design.rules.evaluation import (
    HoldoutResult,
    feature_dependence,
    holdout,
    split_indices,
)
from holofold.design.rules.params import check_params
from holofold.design.rules.targets import Target, parse_target

__all__ = [
    "MinedRules",
    "OneClassSplit",
    "mine_rules",
    "select_features",
    "mining_estimate",
    "check_mining_size",
    "MAX_MINING_BYTES",
    "MAX_MINING_SECONDS",
    "MAX_TREE_DEPTH",
]

#: cost of growing and mining one tree, measured with ``mine_rules`` on tables of 500, 3000 and
#: 20,000 rows (6 features, 100-400 trees, one thread; docs/limits.md): peak memory per row a
#: tree is grown on (270-490 B, rounded up) and time per tree and per such row
BYTES_PER_TREE_ROW = 500
SECONDS_PER_TREE = 5e-3
SECONDS_PER_TREE_ROW = 15e-6
#: the largest work ``mine_rules`` starts without ``force=True`` (``holofold mine --force``):
#: estimated peak memory of the forest and estimated time on one thread
MAX_MINING_BYTES = 4 * 2**30
MAX_MINING_SECONDS = 300.0
#: a tree of depth d has a leaf at depth d below d splits of >= 2 rows each: deeper limits
#: change nothing for the tables mined here (and 1e20 overflowed scikit-learn's C integer)
MAX_TREE_DEPTH = 1000


class OneClassSplit(ValueError):
    """The training split holds only designs that meet the target, or only ones that do not
    (a rare target with a handful of hits, all drawn into the held-out rows)."""


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

        :func:`holofold.design.rules.evaluation.feature_dependence` of the fitted forest on the test
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


def mining_estimate(n_train: int, n_estimators: int, max_samples=0.5) -> tuple[float, float]:
    """(peak bytes, seconds on one thread) of a forest of ``n_estimators`` trees, each grown on
    ``max_samples`` (a fraction or a count) of ``n_train`` rows: the constants above."""
    if isinstance(max_samples, float):
        rows = max(1, int(max_samples * n_train))
    else:
        rows = min(int(max_samples), n_train)
    trees = float(n_estimators)
    return (
        trees * rows * BYTES_PER_TREE_ROW,
        trees * (SECONDS_PER_TREE + rows * SECONDS_PER_TREE_ROW),
    )


def _size(nbytes: float) -> str:
    return f"{nbytes / 2**30:.3g} GiB" if nbytes >= 2**30 else f"{nbytes / 2**20:.3g} MiB"


def _duration(seconds: float) -> str:
    return f"{seconds / 3600:.3g} h" if seconds >= 3600 else f"{seconds:.3g} s"


def check_mining_size(n_train: int, params: dict, *, force: bool = False) -> tuple[float, float]:
    """Refuse a forest whose estimated memory or time is over the limits (unless ``force``),
    a ``max_depth`` over :data:`MAX_TREE_DEPTH` and more threads than 4 per core; returns the
    estimate (bytes, seconds). Messages name the parameter and its ``holofold mine`` option."""
    depth = params.get("max_depth", 20)
    if depth is not None and not isinstance(depth, bool) and isinstance(depth, int | np.integer):
        if depth > MAX_TREE_DEPTH:
            raise ValueError(
                f"max_depth (--depth) = {depth} is over the limit of {MAX_TREE_DEPTH}: a deeper "
                "limit grows the same trees"
            )
    jobs = params.get("n_jobs")
    cores = os.cpu_count() or 1
    if isinstance(jobs, int | np.integer) and not isinstance(jobs, bool) and jobs > 4 * cores:
        raise ValueError(
            f"n_jobs (--jobs) = {jobs} threads is over the limit of {4 * cores} (4 per core of "
            f"the {cores} here); more threads than cores only wait for each other"
        )
    trees = params.get("n_estimators", 100)
    nbytes, seconds = mining_estimate(n_train, trees, params.get("max_samples", 0.5))
    over = []
    if nbytes > MAX_MINING_BYTES:
        over.append(f"{_size(nbytes)} of memory (limit {_size(MAX_MINING_BYTES)})")
    if seconds > MAX_MINING_SECONDS:
        over.append(f"{_duration(seconds)} on one thread (limit {_duration(MAX_MINING_SECONDS)})")
    if over and not force:
        raise ValueError(
            f"n_estimators (--trees) = {trees} trees on {n_train} training rows would take an "
            f"estimated {' and '.join(over)}; use fewer trees, or force it (force=True, "
            "holofold mine --force)"
        )
    return nbytes, seconds


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
    force: bool = False,
    progress: Callable[[str], None] | None = None,
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
        What the columns are (:func:`holofold.design.database.tables.column_roles`).
    features, categorical : sequence of str, optional
        See :func:`select_features`.
    test_size : float
        Test fraction of ``train_test_split(rows, test_size, random_state=seed)``.
    seed : int
        Seed of the split and of the forest.
    force : bool
        Train a forest whose estimated memory or time is over :data:`MAX_MINING_BYTES` or
        :data:`MAX_MINING_SECONDS` (:func:`check_mining_size`), which is refused otherwise.
    progress : callable(str), optional
        Called with one line (the estimate) before training that is estimated to take over
        10 s.
    **params
        :class:`~holofold.design.rules.ForestRuleMiner` parameters (``n_estimators``,
        ``max_depth``, ``n_rules``, ``scoring``, ...); checked by the estimator, and sizes by
        :func:`check_mining_size`.

    Raises
    ------
    ValueError
        Unknown columns, a target met by no row or by every row, a training split with one
        class, or an invalid miner parameter (one line naming it).
    """
    n_failed = 0
    if "status" in table.columns or "state" in table.columns:
        failed = failed_rows(table)
        n_failed = int(failed.sum())
        table = table.loc[~failed]
    table = table.reset_index(drop=True)
    columns = [str(c) for c in table.columns]
    tgt = target if isinstance(target, Target) else parse_target(target, columns=columns)
    feats, cats = select_features(columns, tgt, roles, features, categorical, source=source)
    miner = ForestRuleMiner(categorical_features=list(cats) or None, random_state=seed, **params)
    check_params(miner)  # an invalid parameter is refused before any work
    y = tgt.evaluate(table)
    n_hit = int(y.sum())
    if n_hit == 0 or n_hit == y.size:
        raise ValueError(
            f"the target {str(tgt)!r} is met by {n_hit} of {y.size} rows; rules need both "
            "designs that meet it and designs that do not"
        )
    train, _ = split_indices(len(table), test_size=test_size, random_state=seed)
    if y[train].all() or not y[train].any():
        raise OneClassSplit("the training split holds only one class; change --seed or --test-size")
    nbytes, seconds = check_mining_size(len(train), miner.get_params(), force=force)
    if progress is not None and seconds > 10:
        progress(
            f"training {miner.n_estimators} trees on {len(train)} rows: about "
            f"{_duration(seconds)} on one thread and {_size(nbytes)} (estimated)"
        )
    res = holdout(miner, table[list(feats)], y, test_size=test_size, random_state=seed)
    return MinedRules(res, tgt, feats, cats, table, n_failed)
