"""Random-forest rule mining: human-readable design rules from a performance database.

The method of Zhu & Filipov (2022), done exactly and fast:

1. train a forest of decision trees (entropy, balanced classes, deep, lightly pruned), each on a
   random subset of the training rows drawn *without* replacement;
2. every leaf that predicts the target class is a candidate rule: an axis-aligned box with
   scikit-learn's own semantics (``x <= t`` left, ``x > t`` right, X compared as float32), the
   tightest bound per feature and side, any real threshold (0 included);
3. identical boxes found by several trees are merged;
4. each rule is scored on the training rows (precision, recall, support) -- or, optionally, on
   the out-of-bag rows of the trees that found it -- filtered by ``precision_min`` and
   ``min_support`` and ranked by F-beta (or by F-beta of a lower confidence bound of precision);
5. the best ``n_rules`` are kept; ``predict`` is "inside any kept rule".

Extraction is one top-down pass over the concatenated node arrays of all trees (a loop over
depth levels, vectorised over all nodes of the forest); scoring uses each tree's ``apply`` and a
``bincount`` over all (row, tree) pairs, which is exact because a leaf's region *is* its box.
"""

from __future__ import annotations

import logging
import warnings
from dataclasses import dataclass
from numbers import Integral, Real

import numpy as np
import pandas as pd
from joblib import Parallel, delayed
from sklearn.base import BaseEstimator, ClassifierMixin, _fit_context
from sklearn.tree import DecisionTreeClassifier
from sklearn.utils import check_random_state
from sklearn.utils._param_validation import Interval, StrOptions
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import check_is_fitted, validate_data

__all__ = [
    "ForestRuleMiner",
    "FewRulesWarning",
    "ForestArrays",
    "stack_trees",
    "forest_boxes",
    "boxes_contain",
    "format_rule",
    "level_value",
]

logger = logging.getLogger(__name__)

_MAX_SEED = np.iinfo(np.int32).max
_LCB_Z = 1.6448536269514722  # one-sided 95 % normal quantile for the Wilson bound


class FewRulesWarning(UserWarning):
    """Fewer rules than requested passed the precision and support filters."""


# ---------------------------------------------------------------------------------------------
# plain-array kernels
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ForestArrays:
    """The node arrays of several fitted trees concatenated into one forest-wide numbering.

    Attributes
    ----------
    offsets : ndarray of int, shape (n_trees + 1,)
        Node ``i`` of tree ``k`` has global id ``offsets[k] + i``.
    left, right : ndarray of int, shape (n_nodes,)
        Global ids of the children, -1 at leaves.
    feature : ndarray of int, shape (n_nodes,)
        Split feature (undefined at leaves).
    threshold : ndarray of float64, shape (n_nodes,)
        Split threshold: left child ``x <= t``, right child ``x > t``.
    positive : ndarray of bool, shape (n_nodes,)
        The node predicts the target class.
    tree_of : ndarray of int, shape (n_nodes,)
        The tree each node belongs to.
    """

    offsets: np.ndarray
    left: np.ndarray
    right: np.ndarray
    feature: np.ndarray
    threshold: np.ndarray
    positive: np.ndarray
    tree_of: np.ndarray

    @property
    def is_leaf(self) -> np.ndarray:
        return self.left < 0


def stack_trees(trees, positive_label=1) -> ForestArrays:
    """Concatenate the node arrays of fitted ``DecisionTreeClassifier`` objects."""
    sizes = np.array([t.tree_.node_count for t in trees], dtype=np.intp)
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.intp)
    left, right, feat, thr, pos = [], [], [], [], []
    for k, t in enumerate(trees):
        tr = t.tree_
        off = offsets[k]
        cl = tr.children_left.astype(np.intp)
        cr = tr.children_right.astype(np.intp)
        left.append(np.where(cl >= 0, cl + off, -1))
        right.append(np.where(cr >= 0, cr + off, -1))
        feat.append(tr.feature.astype(np.intp))
        thr.append(tr.threshold)
        pred = np.asarray(t.classes_)[np.argmax(tr.value[:, 0, :], axis=1)]
        pos.append(pred == positive_label)
    tree_of = np.repeat(np.arange(len(trees)), sizes)
    return ForestArrays(
        offsets,
        np.concatenate(left),
        np.concatenate(right),
        np.concatenate(feat),
        np.concatenate(thr).astype(np.float64),
        np.concatenate(pos),
        tree_of,
    )


def forest_boxes(forest: ForestArrays, n_features: int) -> tuple[np.ndarray, np.ndarray]:
    """Box of every node: the tightest bounds along its root path.

    One top-down pass over depth levels, vectorised over all nodes of all trees.

    Parameters
    ----------
    forest : ForestArrays
    n_features : int

    Returns
    -------
    lower, upper : ndarray of float64, shape (n_nodes, n_features)
        A row ``x`` (as float32) lies in node ``i`` iff ``lower[i] < x <= upper[i]`` on every
        feature; unbounded sides are ``-inf`` / ``+inf``.
    """
    n = forest.left.shape[0]
    lower = np.full((n, n_features), -np.inf)
    upper = np.full((n, n_features), np.inf)
    frontier = forest.offsets[:-1]
    frontier = frontier[frontier < n]
    while frontier.size:
        inner = frontier[forest.left[frontier] >= 0]
        if not inner.size:
            break
        lc, rc = forest.left[inner], forest.right[inner]
        f, t = forest.feature[inner], forest.threshold[inner]
        lower[lc] = lower[inner]
        upper[lc] = upper[inner]
        lower[rc] = lower[inner]
        upper[rc] = upper[inner]
        upper[lc, f] = np.minimum(upper[lc, f], t)
        lower[rc, f] = np.maximum(lower[rc, f], t)
        frontier = np.concatenate([lc, rc])
    return lower, upper


def boxes_contain(lower: np.ndarray, upper: np.ndarray, Z: np.ndarray) -> np.ndarray:
    """Which rows lie in which boxes, with scikit-learn's float32 semantics.

    Parameters
    ----------
    lower, upper : ndarray, shape (n_boxes, n_features)
    Z : ndarray, shape (n_rows, n_features)

    Returns
    -------
    ndarray of bool, shape (n_boxes, n_rows)
    """
    Zf = np.asarray(Z, dtype=np.float32).astype(np.float64)
    out = np.ones((lower.shape[0], Zf.shape[0]), dtype=bool)
    for r in range(lower.shape[0]):  # a handful of kept rules; features vectorised
        cols = np.flatnonzero(np.isfinite(lower[r]) | np.isfinite(upper[r]))
        if cols.size:
            sub = Zf[:, cols]
            out[r] = np.all((sub > lower[r, cols]) & (sub <= upper[r, cols]), axis=1)
    return out


def _wilson_lower(tp: np.ndarray, n: np.ndarray, z: float = _LCB_Z) -> np.ndarray:
    n = np.asarray(n, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        p = np.where(n > 0, tp / n, 0.0)
        denom = 1 + z * z / n
        centre = p + z * z / (2 * n)
        half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
        lcb = (centre - half) / denom
    return np.where(n > 0, np.clip(lcb, 0.0, 1.0), 0.0)


def _fbeta(precision, recall, beta):
    b2 = beta * beta
    with np.errstate(invalid="ignore", divide="ignore"):
        f = (1 + b2) * precision * recall / (b2 * precision + recall)
    return np.nan_to_num(f, nan=0.0)


# ---------------------------------------------------------------------------------------------
# categorical encoding
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Encoding:
    """How original features map to the encoded columns the trees see."""

    names: tuple  # original feature names
    categorical: tuple  # bool per original feature
    levels: tuple  # per original feature: ndarray of levels or None
    columns: tuple  # per encoded column: (original index, level index or -1)
    mode: str  # "onehot" or "ordinal"

    @property
    def n_encoded(self) -> int:
        return len(self.columns)

    def encode(self, X) -> np.ndarray:
        n = X.shape[0]
        Z = np.empty((n, self.n_encoded), dtype=np.float64)
        codes = {}
        for j, is_cat in enumerate(self.categorical):
            if not is_cat:
                continue
            lv = self.levels[j]
            col = X[:, j]
            idx = np.searchsorted(lv, col) if lv.dtype != object else None
            if idx is None:
                lookup = {v: i for i, v in enumerate(lv)}
                bad = [v for v in col if v not in lookup]
                idx = np.array([lookup.get(v, -1) for v in col], dtype=np.intp)
            else:
                idx = np.clip(idx, 0, len(lv) - 1)
                badmask = lv[idx] != col
                bad = list(col[badmask])
            if len(bad):
                raise ValueError(
                    f"categorical feature {self.names[j]!r} has level {_fmt_level(bad[0])} not "
                    f"seen in fit; known levels: {', '.join(_fmt_level(v) for v in lv)}"
                )
            codes[j] = idx
        for c, (j, li) in enumerate(self.columns):
            if not self.categorical[j]:
                Z[:, c] = X[:, j]
            elif self.mode == "ordinal":
                Z[:, c] = codes[j]
            else:
                Z[:, c] = codes[j] == li
        return Z

    def allowed_levels(self, j: int, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
        """Levels of categorical feature ``j`` allowed by each box.

        Parameters
        ----------
        lower, upper : ndarray, shape (n_boxes, n_encoded)

        Returns
        -------
        ndarray of bool, shape (n_boxes, n_levels)
        """
        cols = [c for c, (jj, _) in enumerate(self.columns) if jj == j]
        n_lv = len(self.levels[j])
        if self.mode == "ordinal":
            code = np.arange(n_lv, dtype=np.float64)
            return (code > lower[:, cols[0], None]) & (code <= upper[:, cols[0], None])
        lo, hi = lower[:, cols], upper[:, cols]
        ok_one = (1.0 > lo) & (1.0 <= hi)  # the level's own indicator is 1 ...
        ok_zero = (0.0 > lo) & (0.0 <= hi)  # ... and every other indicator is 0
        others_ok = ok_zero.sum(axis=1, keepdims=True) - ok_zero == n_lv - 1
        return ok_one & others_ok

    def decode_all(self, lower: np.ndarray, upper: np.ndarray) -> dict:
        """Per original feature, the bounds of all boxes (vectorised).

        Returns
        -------
        dict name -> (gt, le) arrays of shape (n_boxes,) for numeric features, or a list of
        tuples of allowed levels (None when unconstrained) for categorical ones.
        """
        out = {}
        for j, name in enumerate(self.names):
            if not self.categorical[j]:
                c = next(c for c, (jj, _) in enumerate(self.columns) if jj == j)
                out[name] = (lower[:, c].astype(float), upper[:, c].astype(float))
            else:
                ok = self.allowed_levels(j, lower, upper)
                lv = self.levels[j]
                out[name] = [None if row.all() else tuple(lv[row].tolist()) for row in ok]
        return out

    def decode(self, lower: np.ndarray, upper: np.ndarray) -> list:
        """Bounds of one box: per original feature (gt, le) or allowed levels (or None)."""
        d = self.decode_all(lower[None, :], upper[None, :])
        return [
            d[n][0] if self.categorical[j] else (float(d[n][0][0]), float(d[n][1][0]))
            for j, n in enumerate(self.names)
        ]


def level_value(v):
    """A categorical level as a plain Python number (8.0 -> 8) for text and JSON."""
    if isinstance(v, float | np.floating) and float(v).is_integer():
        return int(v)
    if isinstance(v, np.generic):
        return v.item()
    return v


def _fmt_level(v) -> str:
    return str(level_value(v))


def _fmt_num(v: float, digits: int) -> str:
    return f"{v:.{digits}g}"


def format_rule(bounds, names, *, categorical=(), digits: int = 4, scale=None, units=None) -> str:
    """Render one decoded rule as text.

    Parameters
    ----------
    bounds : list
        Per feature ``(gt, le)`` for numeric features (``-inf``/``inf`` when unbounded) or a
        tuple of allowed levels (None when unconstrained).
    names : sequence of str
    categorical : collection of str, default=()
        Names of the categorical features (their bounds are tuples of levels).
    digits : int, default=4
        Significant digits of the thresholds.
    scale, units : dict, optional
        Display factor and unit per feature name (e.g. ``{"W": 1e3}``, ``{"W": "mm"}``).

    Returns
    -------
    str
        e.g. ``"tcrease <= 0.00078 and W > 0.0019 and m in {16, 24}"``; ``"(any design)"``
        for an empty box.
    """
    scale = scale or {}
    units = units or {}
    parts = []
    for name, b in zip(names, bounds, strict=True):
        if b is None:
            continue
        if name in categorical:
            levels = [_fmt_level(v) for v in b]
            if len(levels) == 1:
                parts.append(f"{name} = {levels[0]}")
            else:
                parts.append(f"{name} in {{{', '.join(levels)}}}")
            continue
        gt, le = b
        s = scale.get(name, 1.0)
        u = f" {units[name]}" if name in units else ""
        if np.isfinite(gt) and np.isfinite(le):
            parts.append(f"{_fmt_num(gt * s, digits)} < {name} <= {_fmt_num(le * s, digits)}{u}")
        elif np.isfinite(gt):
            parts.append(f"{name} > {_fmt_num(gt * s, digits)}{u}")
        elif np.isfinite(le):
            parts.append(f"{name} <= {_fmt_num(le * s, digits)}{u}")
    return " and ".join(parts) if parts else "(any design)"


# ---------------------------------------------------------------------------------------------
# the estimator
# ---------------------------------------------------------------------------------------------


def _fit_one_tree(params, ccp_alpha, class_weight, Z32, y, n_sub, seed):
    """Fit one tree on ``n_sub`` rows drawn without replacement.

    Returns
    -------
    tree : DecisionTreeClassifier
    rows : ndarray of int
        The training rows it saw.
    grown_depth : int
        Depth of the tree *before* cost-complexity pruning (-1 if unknown). A tree whose grown
        depth is below a depth limit is exactly the same under any larger limit.
    """
    rng = np.random.RandomState(seed)
    idx = np.sort(rng.permutation(Z32.shape[0])[:n_sub])
    ys = y[idx]
    # class weights computed here on the tree's own rows, exactly as class_weight="balanced"
    # would (sklearn's own computation costs more than the tree itself on small data)
    counts = np.bincount(ys, minlength=2).astype(np.float64)
    if class_weight == "balanced":
        present = counts > 0
        w = np.zeros(2)
        w[present] = ys.shape[0] / (present.sum() * counts[present])
    elif isinstance(class_weight, dict):
        w = np.array([class_weight.get(0, 1.0), class_weight.get(1, 1.0)], dtype=np.float64)
    else:
        w = np.ones(2)
    prune = getattr(DecisionTreeClassifier, "_prune_tree", None)
    if ccp_alpha > 0 and prune is not None:
        # grow unpruned, note the depth, then prune exactly as fit() itself does at its end
        tree = DecisionTreeClassifier(**params, ccp_alpha=0.0, random_state=seed)
        tree.fit(Z32[idx], ys, sample_weight=w[ys], check_input=False)
        grown = int(tree.get_depth())
        tree.set_params(ccp_alpha=ccp_alpha)
        tree._prune_tree()
    else:
        tree = DecisionTreeClassifier(**params, ccp_alpha=ccp_alpha, random_state=seed)
        tree.fit(Z32[idx], ys, sample_weight=w[ys], check_input=False)
        grown = int(tree.get_depth()) if ccp_alpha == 0 else -1
    return tree, idx, grown


class ForestRuleMiner(ClassifierMixin, BaseEstimator):
    """Mine axis-aligned design rules from a forest of deep decision trees.

    Parameters
    ----------
    n_estimators : int, default=100
        Number of trees.
    criterion : {"entropy", "gini", "log_loss"}, default="entropy"
    max_depth : int or None, default=20
    ccp_alpha : float, default=1e-4
        Minimal cost-complexity pruning of each tree.
    min_samples_leaf : int, default=2
    min_samples_split : int, default=4
    max_features : int, float, {"sqrt", "log2"} or None, default=None
        Features considered per split (None: all, as in the paper).
    max_samples : float in (0, 1] or int, default=0.5
        Rows per tree, drawn without replacement (fraction of the training rows, or a count).
    class_weight : "balanced", dict or None, default="balanced"
    precision_min : float in [0, 1], default=0.9
        Rules below this precision are dropped.
    recall_min : float in [0, 1], default=0.0
    min_support : int, default=10
        Rules matching fewer training rows are dropped.
    beta : float, default=0.2
        F-beta used for ranking (beta < 1 favours precision).
    n_rules : int, default=3
        How many rules to keep (the top k alternatives).
    max_overlap : float in (0, 1] or None, default=None
        Make the alternatives distinct: walking down the ranking, a rule is kept only if the
        training rows it covers overlap those of every rule kept before it by at most this
        Jaccard index (|A and B| / |A or B|). None keeps the plain top k, which are often
        near-copies of one box.
    scoring : {"oob", "train"}, default="oob"
        Rows on which the precision used for *ranking* is estimated: the out-of-bag rows of
        the trees that found the rule (pooled over those trees; an honest estimate), or all
        training rows (the paper). Filtering by ``precision_min`` and ``min_support`` always
        uses the training rows, as in the paper.
    ranking : {"lcb", "fbeta"}, default="lcb"
        Rank by F-beta(precision, training recall) (the paper), or by F-beta with the
        precision replaced by its one-sided 95 % Wilson lower confidence bound (favours
        well-supported rules). The paper's method is ``scoring="train", ranking="fbeta"``.
    categorical_features : list of str or int, array of bool, or None, default=None
        Features to treat as categorical; they are one-hot (or ordinal) encoded for the trees
        and rules read ``pattern = 2`` or ``m in {16, 24}``.
    categorical_encoding : {"onehot", "ordinal"}, default="onehot"
    random_state : int, RandomState or None, default=None
        Seeds the per-tree subsets and trees; tree ``i`` of an ``n``-tree forest is the same as
        tree ``i`` of a larger forest with the same seed.
    n_jobs : int or None, default=None
        Threads used to train the trees.

    Attributes
    ----------
    classes_ : ndarray of shape (2,)
        Class labels; the target (positive) class is ``classes_[1]``.
    n_features_in_ : int
    feature_names_in_ : ndarray of str
        Only when X was a DataFrame with string column names.
    feature_names_ : list of str
        Names used in the rules.
    estimators_ : list of DecisionTreeClassifier
    estimators_samples_ : list of ndarray of int
        Training rows of each tree.
    rules_ : pandas.DataFrame
        The kept rules, best first: ``rule`` (text), per numeric feature ``<name>_gt`` and
        ``<name>_le`` (the rule is ``gt < x <= le``, +-inf when unbounded), per categorical
        feature ``<name>_in`` (tuple of allowed levels or None), then ``precision``,
        ``recall``, ``support``, ``true_positives`` (training rows), ``f_score``, ``score``
        (the ranking value), ``n_trees`` (trees that found the box) and, with
        ``scoring="oob"``, ``oob_precision`` and ``oob_support``.
    candidate_rules_ : pandas.DataFrame
        All distinct rules that passed the filters, ranked (same columns).
    n_candidates_ : int
        Distinct positive-leaf boxes before filtering.
    feature_importances_ : ndarray of shape (n_features_in_,)
        Mean impurity importance of the trees, summed over the encoded columns of a feature.
    """

    _parameter_constraints: dict = {
        "n_estimators": [Interval(Integral, 1, None, closed="left")],
        "criterion": [StrOptions({"entropy", "gini", "log_loss"})],
        "max_depth": [Interval(Integral, 1, None, closed="left"), None],
        "ccp_alpha": [Interval(Real, 0, None, closed="left")],
        "min_samples_leaf": [Interval(Integral, 1, None, closed="left")],
        "min_samples_split": [Interval(Integral, 2, None, closed="left")],
        "max_features": [
            Interval(Integral, 1, None, closed="left"),
            Interval(Real, 0, 1, closed="right"),
            StrOptions({"sqrt", "log2"}),
            None,
        ],
        "max_samples": [
            Interval(Integral, 1, None, closed="left"),
            Interval(Real, 0, 1, closed="right"),
        ],
        "class_weight": [StrOptions({"balanced"}), dict, None],
        "precision_min": [Interval(Real, 0, 1, closed="both")],
        "recall_min": [Interval(Real, 0, 1, closed="both")],
        "min_support": [Interval(Integral, 1, None, closed="left")],
        "beta": [Interval(Real, 0, None, closed="neither")],
        "n_rules": [Interval(Integral, 1, None, closed="left")],
        "max_overlap": [Interval(Real, 0, 1, closed="right"), None],
        "scoring": [StrOptions({"train", "oob"})],
        "ranking": [StrOptions({"fbeta", "lcb"})],
        "categorical_features": ["array-like", None],
        "categorical_encoding": [StrOptions({"onehot", "ordinal"})],
        "random_state": ["random_state"],
        "n_jobs": [Integral, None],
    }

    def __init__(
        self,
        *,
        n_estimators=100,
        criterion="entropy",
        max_depth=20,
        ccp_alpha=1e-4,
        min_samples_leaf=2,
        min_samples_split=4,
        max_features=None,
        max_samples=0.5,
        class_weight="balanced",
        precision_min=0.9,
        recall_min=0.0,
        min_support=10,
        beta=0.2,
        n_rules=3,
        max_overlap=None,
        scoring="oob",
        ranking="lcb",
        categorical_features=None,
        categorical_encoding="onehot",
        random_state=None,
        n_jobs=None,
    ):
        self.n_estimators = n_estimators
        self.criterion = criterion
        self.max_depth = max_depth
        self.ccp_alpha = ccp_alpha
        self.min_samples_leaf = min_samples_leaf
        self.min_samples_split = min_samples_split
        self.max_features = max_features
        self.max_samples = max_samples
        self.class_weight = class_weight
        self.precision_min = precision_min
        self.recall_min = recall_min
        self.min_support = min_support
        self.beta = beta
        self.n_rules = n_rules
        self.max_overlap = max_overlap
        self.scoring = scoring
        self.ranking = ranking
        self.categorical_features = categorical_features
        self.categorical_encoding = categorical_encoding
        self.random_state = random_state
        self.n_jobs = n_jobs

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.classifier_tags.multi_class = False
        return tags

    # -- input handling ------------------------------------------------------------------

    def _categorical_mask(self, n_features: int, names: list[str]) -> np.ndarray:
        mask = np.zeros(n_features, dtype=bool)
        cats = self.categorical_features
        if cats is None:
            return mask
        cats = np.asarray(cats)
        if cats.dtype == bool:
            if cats.shape != (n_features,):
                raise ValueError(
                    f"categorical_features as a mask needs {n_features} entries, got "
                    f"{cats.shape[0]}"
                )
            return cats.copy()
        for c in cats.tolist():
            if isinstance(c, str):
                if c not in names:
                    raise ValueError(
                        f"categorical feature {c!r} is not a feature; features: {', '.join(names)}"
                    )
                mask[names.index(c)] = True
            elif isinstance(c, Integral) and -n_features <= c < n_features:
                mask[c] = True
            else:
                raise ValueError(
                    f"categorical feature {c!r} must be a feature name or an index in "
                    f"[0, {n_features})"
                )
        return mask

    def _validate_X(self, X, *, y=None, reset: bool):
        cats = self.categorical_features
        has_cat = cats is not None and np.asarray(cats).size > 0
        if has_cat and np.asarray(cats).dtype == bool:
            has_cat = bool(np.any(cats))
        if reset:
            if has_cat:
                X, y = validate_data(self, X, y, dtype=None, ensure_all_finite=False)
            else:
                X, y = validate_data(self, X, y, dtype=np.float64)
        else:
            if has_cat:
                X = validate_data(self, X, dtype=None, ensure_all_finite=False, reset=False)
            else:
                X = validate_data(self, X, dtype=np.float64, reset=False)
        return X, y

    def _numeric_columns(self, X, cat_mask) -> np.ndarray:
        """Check the non-categorical columns of an object array are finite numbers."""
        if X.dtype != object:
            bad = ~np.all(np.isfinite(X[:, ~cat_mask]), axis=0)
            if bad.any():
                name = self.feature_names_[np.flatnonzero(~cat_mask)[np.argmax(bad)]]
                raise ValueError(f"feature {name!r} contains NaN or infinity")
            return X
        for j in np.flatnonzero(~cat_mask):
            try:
                col = X[:, j].astype(np.float64)
            except (TypeError, ValueError) as exc:
                raise ValueError(
                    f"feature {self.feature_names_[j]!r} is not numeric; declare it in "
                    "categorical_features"
                ) from exc
            if not np.all(np.isfinite(col)):
                raise ValueError(f"feature {self.feature_names_[j]!r} contains NaN or infinity")
        return X

    # -- fitting ---------------------------------------------------------------------------

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y, feature_names=None):
        """Train the forest and mine the rules.

        Parameters
        ----------
        X : array-like or DataFrame of shape (n_samples, n_features)
            Design features.
        y : array-like of shape (n_samples,)
            Binary labels (True / 1 = meets the target); the target class is the larger label.
        feature_names : sequence of str, optional
            Names for the columns of an array X (a DataFrame's own names take precedence).

        Returns
        -------
        self
        """
        X, y = self._validate_X(X, y=y, reset=True)
        check_classification_targets(y)
        self.classes_, y_codes = np.unique(y, return_inverse=True)
        if self.classes_.shape[0] != 2:
            raise ValueError(
                "Only binary classification is supported: ForestRuleMiner needs exactly 2 "
                "classes in y (the target met or not), got "
                f"{self.classes_.shape[0]} class(es): {self.classes_.tolist()[:5]}"
            )
        n, d = X.shape
        if hasattr(self, "feature_names_in_"):
            names = [str(c) for c in self.feature_names_in_]
        elif feature_names is not None:
            names = [str(c) for c in feature_names]
            if len(names) != d:
                raise ValueError(f"feature_names has {len(names)} names for {d} features")
        else:
            names = [f"x{j}" for j in range(d)]
        self.feature_names_ = names
        cat_mask = self._categorical_mask(d, names)
        X = self._numeric_columns(X, cat_mask)
        self._encoding = self._make_encoding(X, names, cat_mask)
        Z = self._encoding.encode(X)
        y_pos = (y_codes == 1).astype(np.intp)

        rng = check_random_state(self.random_state)
        self._seeds = rng.randint(_MAX_SEED, size=self.n_estimators)
        Z32 = np.ascontiguousarray(Z, dtype=np.float32)
        fitted = self._grow(Z32, y_pos, self._seeds)
        self.estimators_ = [t for t, _, _ in fitted]
        self.estimators_samples_ = [i for _, i, _ in fitted]
        self._grown_depth = np.array([g for _, _, g in fitted], dtype=np.intp)
        self._mine(Z32, y_pos, len(self.estimators_))
        return self

    def _grow(self, Z32, y_pos, seeds):
        n = Z32.shape[0]
        if isinstance(self.max_samples, Integral):
            n_sub = min(int(self.max_samples), n)
        else:
            n_sub = max(1, int(self.max_samples * n))
        params = dict(
            criterion=self.criterion,
            max_depth=self.max_depth,
            min_samples_leaf=self.min_samples_leaf,
            min_samples_split=self.min_samples_split,
            max_features=self.max_features,
        )
        class_weight = self.class_weight
        if isinstance(class_weight, dict):  # keys are class labels; map them to 0/1 codes
            class_weight = {
                code: class_weight.get(label, class_weight.get(str(label), 1.0))
                for code, label in enumerate(self.classes_.tolist())
            }
        return Parallel(n_jobs=self.n_jobs, prefer="threads")(
            delayed(_fit_one_tree)(params, self.ccp_alpha, class_weight, Z32, y_pos, n_sub, s)
            for s in seeds
        )

    def _make_encoding(self, X, names, cat_mask) -> _Encoding:
        levels, columns = [], []
        for j in range(X.shape[1]):
            if cat_mask[j]:
                col = X[:, j]
                try:
                    lv = np.unique(col.astype(np.float64))
                except (TypeError, ValueError):
                    lv = np.unique(col.astype(object))
                levels.append(lv)
                if self.categorical_encoding == "ordinal":
                    columns.append((j, 0))
                else:
                    columns.extend((j, i) for i in range(len(lv)))
            else:
                levels.append(None)
                columns.append((j, -1))
        return _Encoding(
            tuple(names),
            tuple(bool(c) for c in cat_mask),
            tuple(levels),
            tuple(columns),
            self.categorical_encoding,
        )

    def _mine(self, Z32: np.ndarray, y_pos: np.ndarray, n_trees: int) -> None:
        trees = self.estimators_[:n_trees]
        forest = stack_trees(trees, positive_label=1)
        lower, upper = forest_boxes(forest, Z32.shape[1])
        n, T = Z32.shape[0], len(trees)
        leaves = np.empty((n, T), dtype=np.intp)
        for k, t in enumerate(trees):
            leaves[:, k] = t.tree_.apply(Z32) + forest.offsets[k]
        flat = leaves.ravel()
        N = forest.left.shape[0]
        support = np.bincount(flat, minlength=N)
        tp = np.bincount(leaves[y_pos == 1].ravel(), minlength=N)

        cand = np.flatnonzero(forest.is_leaf & forest.positive & (support > 0))
        self.n_candidates_ = 0
        keys = np.concatenate([lower[cand], upper[cand]], axis=1)
        if cand.size:
            _, first, inverse, counts = np.unique(
                keys, axis=0, return_index=True, return_inverse=True, return_counts=True
            )
            inverse = inverse.ravel()
            uniq = cand[first]
            self.n_candidates_ = int(uniq.size)
        else:
            uniq = cand
            inverse = np.zeros(0, dtype=np.intp)
            counts = np.zeros(0, dtype=np.intp)
        n_pos = max(int(y_pos.sum()), 1)
        sup = support[uniq].astype(float)
        tpu = tp[uniq].astype(float)
        prec = np.where(sup > 0, tpu / np.maximum(sup, 1), 0.0)
        rec = tpu / n_pos
        keep = (prec >= self.precision_min) & (sup >= self.min_support) & (rec >= self.recall_min)
        extra = {}
        p_est, n_est = prec, sup
        if self.scoring == "oob":
            # honest estimate: each tree's leaf scored on the training rows that tree never saw,
            # pooled over the trees that found the same box. OOB counts = all - in-bag counts.
            samples = self.estimators_samples_[:T]
            rows = np.concatenate(samples)
            cols = np.repeat(np.arange(T), [len(r) for r in samples])
            in_leaf = leaves[rows, cols]
            o_sup = (support - np.bincount(in_leaf, minlength=N))[cand].astype(float)
            o_tp = (tp - np.bincount(in_leaf[y_pos[rows] == 1], minlength=N))[cand].astype(float)
            m = uniq.size
            o_sup = np.bincount(inverse, weights=o_sup, minlength=m)
            o_tp = np.bincount(inverse, weights=o_tp, minlength=m)
            o_prec = np.where(o_sup > 0, o_tp / np.maximum(o_sup, 1), 0.0)
            extra = {"oob_precision": o_prec, "oob_support": o_sup.astype(np.intp)}
            p_est, n_est = o_prec, o_sup
        if self.ranking == "lcb":
            p_est = _wilson_lower(p_est * n_est, n_est)
        score = _fbeta(p_est, rec, self.beta)
        fscore = _fbeta(prec, rec, self.beta)
        idx = np.flatnonzero(keep)
        # best score first; ties: larger support, then first found (deterministic)
        order = idx[np.lexsort((idx, -sup[idx], -score[idx]))]

        self._all_lower = lower[uniq[order]]
        self._all_upper = upper[uniq[order]]
        self._all_stats = {
            "precision": prec[order],
            "recall": rec[order],
            "support": sup[order].astype(np.intp),
            "true_positives": tpu[order].astype(np.intp),
            "f_score": fscore[order],
            "score": score[order],
            "n_trees": counts[order].astype(np.intp),
            **{k: v[order] for k, v in extra.items()},
        }
        self._candidate_frame = None
        k = self.n_rules
        pick = self._pick(Z32, k)
        self.rules_ = self._rules_frame(
            self._all_lower[pick],
            self._all_upper[pick],
            {key: v[pick] for key, v in self._all_stats.items()},
        )
        self._lower = self._all_lower[pick]
        self._upper = self._all_upper[pick]
        if len(self.rules_) < k:
            msg = (
                f"only {len(self.rules_)} of the {k} requested rules reach precision >= "
                f"{self.precision_min} with support >= {self.min_support} "
                f"({self.n_candidates_} distinct candidate boxes)"
            )
            logger.info(msg)
            warnings.warn(msg, FewRulesWarning, stacklevel=3)

    def _pick(self, Z32: np.ndarray, k: int) -> np.ndarray:
        """Positions in the ranking of the rules to keep (the top k, or distinct ones)."""
        n = len(self._all_lower)
        if self.max_overlap is None or n <= 1:
            return np.arange(min(k, n))
        kept: list[int] = []
        covered: list[np.ndarray] = []
        for start in range(0, n, 256):  # rows covered, for a block of candidates at a time
            block = boxes_contain(
                self._all_lower[start : start + 256], self._all_upper[start : start + 256], Z32
            )
            for j, rows in enumerate(block):
                inter = [np.count_nonzero(rows & c) for c in covered]
                union = [np.count_nonzero(rows | c) for c in covered]
                if all(
                    i <= self.max_overlap * max(u, 1) for i, u in zip(inter, union, strict=True)
                ):
                    kept.append(start + j)
                    covered.append(rows)
                    if len(kept) == k:
                        return np.asarray(kept)
        return np.asarray(kept, dtype=np.intp)

    @property
    def candidate_rules_(self) -> pd.DataFrame:
        """All distinct rules that passed the filters, ranked (built on first access)."""
        check_is_fitted(self)
        if getattr(self, "_candidate_frame", None) is None:
            self._candidate_frame = self._rules_frame(
                self._all_lower, self._all_upper, self._all_stats
            )
        return self._candidate_frame

    def _rules_frame(self, lower, upper, stats: dict) -> pd.DataFrame:
        enc = self._encoding
        dec = enc.decode_all(lower, upper)
        per_rule = [
            [
                dec[n][r] if enc.categorical[j] else (dec[n][0][r], dec[n][1][r])
                for j, n in enumerate(enc.names)
            ]
            for r in range(lower.shape[0])
        ]
        cats = {n for n, c in zip(enc.names, enc.categorical, strict=True) if c}
        cols: dict = {"rule": [format_rule(b, enc.names, categorical=cats) for b in per_rule]}
        for j, name in enumerate(enc.names):
            if enc.categorical[j]:
                cols[f"{name}_in"] = dec[name]
            else:
                cols[f"{name}_gt"], cols[f"{name}_le"] = dec[name]
        cols.update(stats)
        return pd.DataFrame(cols)

    # -- using the rules ---------------------------------------------------------------------

    def _encode_new(self, X) -> np.ndarray:
        check_is_fitted(self)
        X, _ = self._validate_X(X, reset=False)
        X = self._numeric_columns(X, np.asarray(self._encoding.categorical))
        return self._encoding.encode(X)

    def rule_matches(self, X, *, which: str = "top") -> np.ndarray:
        """Rows inside each rule.

        Parameters
        ----------
        X : array-like of shape (n_samples, n_features)
        which : {"top", "all"}, default="top"
            The kept rules (``rules_``) or all candidates that passed the filters.

        Returns
        -------
        ndarray of bool, shape (n_rules, n_samples)
        """
        Z = self._encode_new(X)
        if which == "top":
            return boxes_contain(self._lower, self._upper, Z)
        if which == "all":
            return boxes_contain(self._all_lower, self._all_upper, Z)
        raise ValueError(f"which must be 'top' or 'all', got {which!r}")

    def predict(self, X):
        """Target class where a row lies in any kept rule, the other class elsewhere.

        Parameters
        ----------
        X : array-like of shape (n_samples, n_features)

        Returns
        -------
        ndarray of shape (n_samples,)
        """
        inside = self.rule_matches(X).any(axis=0)
        return np.where(inside, self.classes_[1], self.classes_[0])

    def decision_function(self, X):
        """Training precision of the best kept rule containing each row (0 outside all rules).

        Returns
        -------
        ndarray of float, shape (n_samples,)
        """
        m = self.rule_matches(X)
        prec = self.rules_["precision"].to_numpy(dtype=float)
        if not m.shape[0]:
            return np.zeros(m.shape[1])
        return np.max(np.where(m, prec[:, None], 0.0), axis=0)

    def with_n_estimators(self, n_estimators: int, X, y) -> ForestRuleMiner:
        """A copy whose rules come from the first ``n_estimators`` trees only (no retraining).

        Tree ``i`` of a forest does not depend on the forest size, so this equals a fresh fit
        with ``n_estimators`` trees and the same seed. ``X, y`` must be the training data.
        """
        check_is_fitted(self)
        if not 1 <= n_estimators <= len(self.estimators_):
            raise ValueError(
                f"n_estimators must be in [1, {len(self.estimators_)}], got {n_estimators}"
            )
        new = self.__class__(**{**self.get_params(), "n_estimators": n_estimators})
        for key, val in self.__dict__.items():
            if key.endswith("_") and not key.startswith("__") or key == "_encoding":
                setattr(new, key, val)
        new.estimators_ = self.estimators_[:n_estimators]
        new.estimators_samples_ = self.estimators_samples_[:n_estimators]
        new._seeds = self._seeds[:n_estimators]
        new._grown_depth = self._grown_depth[:n_estimators]
        Z = self._encode_new(X)
        y = np.asarray(y)
        y_pos = (y == self.classes_[1]).astype(np.intp)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FewRulesWarning)
            new._mine(np.ascontiguousarray(Z, dtype=np.float32), y_pos, n_estimators)
        return new

    def with_max_depth(self, max_depth, X, y) -> ForestRuleMiner:
        """A copy refitted with another ``max_depth``, retraining only the trees that need it.

        A tree whose unpruned depth stayed below both the old and the new limit is exactly
        the tree the new limit grows (same rows, same seed), so it is kept; the others are
        retrained. The result equals a fresh fit with ``max_depth``. ``X, y`` must be the
        training data.
        """
        check_is_fitted(self)
        if max_depth is not None and (not isinstance(max_depth, Integral) or max_depth < 1):
            raise ValueError(f"max_depth must be a positive integer or None, got {max_depth!r}")
        new = self.__class__(**{**self.get_params(), "max_depth": max_depth})
        for key, val in self.__dict__.items():
            if key.endswith("_") and not key.startswith("__") or key in ("_encoding", "_seeds"):
                setattr(new, key, val)
        Z = np.ascontiguousarray(self._encode_new(X), dtype=np.float32)
        y_pos = (np.asarray(y) == self.classes_[1]).astype(np.intp)
        limit = min(
            np.inf if self.max_depth is None else self.max_depth,
            np.inf if max_depth is None else max_depth,
        )
        redo = np.flatnonzero((self._grown_depth < 0) | (self._grown_depth >= limit))
        trees = list(self.estimators_)
        rows = list(self.estimators_samples_)
        grown = self._grown_depth.copy()
        for i, (t, r, g) in zip(redo, new._grow(Z, y_pos, self._seeds[redo]), strict=True):
            trees[i], rows[i], grown[i] = t, r, g
        new.estimators_, new.estimators_samples_, new._grown_depth = trees, rows, grown
        new.n_retrained_ = int(redo.size)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FewRulesWarning)
            new._mine(Z, y_pos, len(trees))
        return new

    @property
    def feature_importances_(self) -> np.ndarray:
        check_is_fitted(self)
        enc = self._encoding
        imp = np.mean([t.feature_importances_ for t in self.estimators_], axis=0)
        owner = np.array([j for j, _ in enc.columns])
        out = np.bincount(owner, weights=imp, minlength=len(enc.names))
        total = out.sum()
        return out / total if total > 0 else out

    def rule_bounds(self, i: int = 0) -> list:
        """Decoded bounds of kept rule ``i``: per feature ``(gt, le)`` or allowed levels."""
        check_is_fitted(self)
        if not 0 <= i < len(self.rules_):
            raise ValueError(f"rule index must be in [0, {len(self.rules_)}), got {i}")
        return self._encoding.decode(self._lower[i], self._upper[i])
