"""The estimator: :class:`ForestRuleMiner`, a scikit-learn classifier whose model is a few
human-readable rules (see the package docstring for the method)."""

from __future__ import annotations

import logging
import warnings
from numbers import Integral

import numpy as np
import pandas as pd
from joblib import Parallel, delayed
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.model_selection import train_test_split
from sklearn.tree import DecisionTreeClassifier
from sklearn.utils import check_random_state
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import check_is_fitted, validate_data

from holofold.design.rules.boxes import boxes_contain
from holofold.design.rules.encoding import Encoding, RankCodes
from holofold.design.rules.forest import forest_apply, stack_trees, tree_arrays
from holofold.design.rules.params import check_params
from holofold.design.rules.selection import Settings, select_rules
from holofold.design.rules.statistics import posterior
from holofold.design.rules.text import box_text

__all__ = ["ForestRuleMiner", "FewRulesWarning", "SELECTION_PARAMS"]

logger = logging.getLogger(__name__)

_MAX_SEED = np.iinfo(np.int32).max
#: column order of the statistics in ``rules_``
STAT_ORDER = (
    "precision", "recall", "support", "true_positives", "estimate", "estimate_low",
    "estimate_high", "estimate_support", "estimate_true_positives", "f_score", "score",
    "n_trees", "oob_precision", "oob_support",
)  # fmt: skip
#: the parameters that choose rules from a trained forest (no retraining needed)
SELECTION_PARAMS = (
    "precision_min", "recall_min", "min_support", "beta", "n_rules", "max_overlap", "scoring",
    "ranking", "prior_strength", "simplify", "tighten",
)  # fmt: skip


class FewRulesWarning(UserWarning):
    """Fewer rules than requested passed the precision and support filters."""


def tree_rows(n: int, n_sub: int, seed: int, scheme: str) -> np.ndarray:
    """The ``n_sub`` of ``n`` training rows a tree grows on, drawn without replacement.

    ``"random"``: sorted rows of ``RandomState(seed).permutation(n)[:n_sub]``; ``"index"``: the
    rows ``train_test_split(rows, train_size=n_sub, random_state=seed)`` keeps, in its order
    (the paper's scripts: tree ``i`` on the half of the rows kept with ``random_state=i``).
    """
    if scheme == "index":
        if n_sub >= n:
            return np.arange(n)
        return train_test_split(np.arange(n), train_size=n_sub, random_state=int(seed))[0]
    return np.sort(np.random.RandomState(seed).permutation(n)[:n_sub])


def fit_one_tree(params, ccp_alpha, class_weight, codes, values, y, n_sub, seed, scheme):
    """Grow one tree on ``n_sub`` rows (:func:`tree_rows`) of the rank ``codes``.

    The tree is grown unpruned; :func:`~holofold.design.rules.forest.tree_arrays` places its
    thresholds in the table's units (``values``) and prunes it with ``ccp_alpha``.

    Returns
    -------
    tree : DecisionTreeClassifier
        Grown on rank codes, before pruning.
    rows : ndarray of int
        The training rows it saw.
    arrays : TreeArrays
    """
    idx = tree_rows(codes.shape[0], n_sub, seed, scheme)
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
    tree = DecisionTreeClassifier(**params, ccp_alpha=0.0, random_state=int(seed))
    tree.fit(codes[idx], ys, sample_weight=w[ys], check_input=False)
    return tree, idx, tree_arrays(tree, codes, idx, values, ccp_alpha)


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
    max_overlap : float in (0, 1] or None, default=0.5
        Make the alternatives distinct: walking down the ranking, a rule is kept only if the
        training rows it covers overlap those of every rule kept before it by at most this
        Jaccard index (|A and B| / |A or B|). None keeps the plain top k, which are often
        near-copies of one box.
    scoring : {"train", "oob", "estimate"}, default="train"
        The precision used for *ranking*: on all training rows (the paper), on the out-of-bag
        rows of the trees that found the rule (pooled over those trees), or the rule's
        ``estimate``. Filtering by ``precision_min`` and ``min_support`` always uses the
        training rows, as in the paper.
    ranking : {"fbeta", "lcb"}, default="fbeta"
        Rank by F-beta(precision, training recall) (the paper), or by F-beta with the
        precision replaced by a one-sided 95 % lower confidence bound (Wilson; for
        ``scoring="estimate"`` the posterior quantile).
    prior_strength : "auto", float >= 0 or None, default="auto"
        The prior of the ``estimate``: ``"auto"`` fits a beta-binomial to the out-of-bag counts
        of the leaves that pass the filters on the rows their trees trained on (empirical
        Bayes); a number shrinks toward the base rate with that many rows' weight; None or 0
        does not shrink.
    simplify : {"idle", "estimate", "none"}, default="idle"
        ``"idle"``: drop the conditions of a kept rule that change none of its training rows;
        ``"estimate"``: before ranking, also drop (greedily) conditions of the top candidates
        whose removal does not lower the estimate; ``"none"``: keep the leaf's box as it is.
    tighten : bool, default=True
        Move each finite bound of a kept rule on a numeric feature in to the outermost target
        row inside (the leaf's bound lies halfway to the next training value, in a slab
        without evidence). Training statistics and the estimate are recounted. The paper's
        method is ``tighten=False, simplify="none"`` (with the default ``scoring`` and
        ``ranking``); ``max_overlap`` only changes which alternatives follow the best rule.
    categorical_features : list of str or int, array of bool, or None, default=None
        Features to treat as categorical; they are one-hot (or ordinal) encoded for the trees
        and rules read ``pattern = 2`` or ``m in {16, 24}``.
    categorical_encoding : {"onehot", "ordinal"}, default="onehot"
    tree_seeds : {"random", "index"}, default="random"
        ``"random"``: tree ``i``'s seed is drawn from ``random_state``; ``"index"``: tree ``i``
        is seeded with ``i`` and grows on the rows ``train_test_split(rows,
        train_size=max_samples, random_state=i)`` keeps, as the paper's scripts do
        (``random_state`` is then unused).
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
        The trees as scikit-learn grew them: on the rank codes of the (encoded) features and
        before cost-complexity pruning. The miner's own node arrays hold each tree pruned
        (``ccp_alpha``) with its thresholds in the table's units; rules, ``predict`` and
        ``forest_probability`` use those.
    estimators_samples_ : list of ndarray of int
        Training rows of each tree.
    trees_ : list of TreeArrays
        Each tree as node arrays (:class:`~holofold.design.rules.forest.TreeArrays`): pruned,
        with its thresholds in the table's units (encoded columns); ``apply``, the rules and
        ``forest_probability`` walk these in float64.
    rules_ : pandas.DataFrame
        The kept rules, best first: ``rule`` (text), per numeric feature ``<name>_gt`` and
        ``<name>_le`` (the rule is ``gt < x <= le``, +-inf when unbounded), per categorical
        feature ``<name>_in`` (tuple of allowed levels or None), then ``precision``,
        ``recall``, ``support``, ``true_positives`` (training rows), ``estimate`` with its
        95 % interval ``estimate_low``, ``estimate_high`` and the rows behind it
        (``estimate_support``, ``estimate_true_positives``: rows out of bag for a tree that
        found the rule), ``f_score``, ``score`` (the ranking value), ``n_trees`` (trees that
        found the box), ``oob_precision`` and ``oob_support`` (pooled out-of-bag pairs) and
        ``bag_support``, ``bag_true_positives`` (rows in bag for one of those trees).
    candidate_rules_ : pandas.DataFrame
        All distinct rules that passed the filters, ranked (same columns), as the leaves
        found them (neither tightened nor tidied).
    prior_ : dict
        ``mean`` and ``strength`` (rows) of the estimate's beta prior, and ``base_rate``.
    n_candidates_ : int
        Distinct positive-leaf boxes before filtering.
    feature_importances_ : ndarray of shape (n_features_in_,)
        Mean impurity importance of the trees, summed over the encoded columns of a feature.
    """

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
        max_overlap=0.5,
        scoring="train",
        ranking="fbeta",
        prior_strength="auto",
        simplify="idle",
        tighten=True,
        categorical_features=None,
        categorical_encoding="onehot",
        tree_seeds="random",
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
        self.prior_strength = prior_strength
        self.simplify = simplify
        self.tighten = tighten
        self.categorical_features = categorical_features
        self.categorical_encoding = categorical_encoding
        self.tree_seeds = tree_seeds
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
        check_params(self)
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

        if self.tree_seeds == "index":
            self._seeds = np.arange(self.n_estimators)
        else:
            rng = check_random_state(self.random_state)
            self._seeds = rng.randint(_MAX_SEED, size=self.n_estimators)
        self._codes = RankCodes.fit(Z)
        fitted = self._grow(Z, y_pos, self._seeds)
        self.estimators_ = [t for t, _, _ in fitted]
        self.estimators_samples_ = [i for _, i, _ in fitted]
        self.trees_ = [a for _, _, a in fitted]
        self._mine(Z, y_pos, len(self.estimators_))
        return self

    def _grow(self, Z, y_pos, seeds):
        """Grow a tree per seed on the rank codes of ``Z`` (:class:`.encoding.RankCodes`)."""
        codes = np.ascontiguousarray(self._codes.codes(Z))
        n = codes.shape[0]
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
            delayed(fit_one_tree)(
                params,
                self.ccp_alpha,
                class_weight,
                codes,
                self._codes.values,
                y_pos,
                n_sub,
                s,
                self.tree_seeds,
            )  # fmt: skip
            for s in seeds
        )

    def _make_encoding(self, X, names, cat_mask) -> Encoding:
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
        return Encoding(
            tuple(names),
            tuple(bool(c) for c in cat_mask),
            tuple(levels),
            tuple(columns),
            self.categorical_encoding,
        )

    def _mine(self, Z: np.ndarray, y_pos: np.ndarray, n_trees: int) -> None:
        """Rules from the first ``n_trees`` trees, on the training rows ``Z`` (the table's
        units, encoded) with target indicator ``y_pos`` (:func:`.selection.select_rules`)."""
        enc = self._encoding
        numeric = np.array([not enc.categorical[j] for j, _ in enc.columns])
        sel = select_rules(self.trees_[:n_trees], self.estimators_samples_, Z, y_pos, numeric,
                           Settings.of(self))  # fmt: skip
        self.n_candidates_ = sel.n_candidates
        self.prior_ = sel.prior
        self._all_lower, self._all_upper = sel.all_lower, sel.all_upper
        self._all_stats = sel.all_stats
        self._candidate_frame = None
        self._lower, self._upper = sel.lower, sel.upper
        self.rules_ = self._rules_frame(sel.lower, sel.upper, sel.kept)
        if sel.short is not None:
            logger.info(sel.short)
            warnings.warn(sel.short, FewRulesWarning, stacklevel=3)

    @property
    def candidate_rules_(self) -> pd.DataFrame:
        """All distinct rules that passed the filters, ranked (built on first access)."""
        check_is_fitted(self)
        if getattr(self, "_candidate_frame", None) is None:
            stats = {k: v for k, v in self._all_stats.items() if k != "_box"}
            self._candidate_frame = self._rules_frame(self._all_lower, self._all_upper, stats)
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
        cols: dict = {"rule": [box_text(b, enc.names, categorical=cats) for b in per_rule]}
        for j, name in enumerate(enc.names):
            if enc.categorical[j]:
                cols[f"{name}_in"] = dec[name]
            else:
                cols[f"{name}_gt"], cols[f"{name}_le"] = dec[name]
        first = [c for c in STAT_ORDER if c in stats]
        cols.update({c: stats[c] for c in first + [c for c in stats if c not in first]})
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

    def rule_estimates(self, held_out: pd.DataFrame | None = None) -> pd.DataFrame:
        """The estimate of each kept rule, optionally with held-out rows as more evidence.

        Parameters
        ----------
        held_out : DataFrame, optional
            Scores of the kept rules on rows the miner never saw (``evaluation.rule_scores``:
            ``support`` and ``true_positives``, or ``precision``, per rule); those rows join the
            out-of-bag rows of the estimate.

        Returns
        -------
        DataFrame with ``estimate``, ``estimate_low``, ``estimate_high`` (95 % interval) and
        ``estimate_support`` (rows of evidence), one row per kept rule.
        """
        check_is_fitted(self)
        tp = self.rules_["estimate_true_positives"].to_numpy(dtype=float)
        n = self.rules_["estimate_support"].to_numpy(dtype=float)
        if held_out is not None:
            if len(held_out) != tp.size:
                raise ValueError(f"held_out has {len(held_out)} rows for {tp.size} kept rules")
            extra_n = held_out["support"].to_numpy(dtype=float)
            if "true_positives" in held_out:
                extra_tp = held_out["true_positives"].to_numpy(dtype=float)
            else:
                extra_tp = np.rint(held_out["precision"].to_numpy(dtype=float) * extra_n)
            if np.any(extra_tp < 0) or np.any(extra_tp > extra_n):
                raise ValueError("held-out true_positives must lie between 0 and support")
            tp, n = tp + extra_tp, n + extra_n
        mean, lo, hi, _ = posterior(tp, n, self.prior_["mean"], self.prior_["strength"])
        return pd.DataFrame(
            {
                "estimate": mean,
                "estimate_low": lo,
                "estimate_high": hi,
                "estimate_support": n.astype(np.intp),
            }
        )

    #: fitted state that is not a public attribute: what the ``with_*`` copies share
    _STATE = ("_encoding", "_codes", "_seeds")

    def _copy_with(self, **params) -> ForestRuleMiner:
        """An unfitted-parameter copy with ``params`` set, sharing this one's fitted state."""
        new = self.__class__(**{**self.get_params(), **params})
        check_params(new)
        for key, val in self.__dict__.items():
            if key.endswith("_") and not key.startswith("__") or key in self._STATE:
                setattr(new, key, val)
        return new

    def _training(self, X, y) -> tuple[np.ndarray, np.ndarray]:
        """(encoded rows, target indicator) of the training data ``X, y``."""
        Z = self._encode_new(X)
        return Z, (np.asarray(y) == self.classes_[1]).astype(np.intp)

    def with_selection(self, X, y, **params) -> ForestRuleMiner:
        """A copy that chooses its rules with other selection parameters, reusing the trees.

        ``params`` may set only :data:`SELECTION_PARAMS` (``scoring``, ``ranking``,
        ``n_rules``, ``simplify``, ...); the result equals a fresh fit with them and the same
        seed. ``X, y`` must be the training data.
        """
        check_is_fitted(self)
        bad = sorted(set(params) - set(SELECTION_PARAMS))
        if bad:
            raise ValueError(
                f"with_selection sets only {', '.join(SELECTION_PARAMS)}; got {', '.join(bad)}"
            )
        new = self._copy_with(**params)
        Z, y_pos = self._training(X, y)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FewRulesWarning)
            new._mine(Z, y_pos, len(new.estimators_))
        return new

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
        new = self._copy_with(n_estimators=n_estimators)
        new.estimators_ = self.estimators_[:n_estimators]
        new.estimators_samples_ = self.estimators_samples_[:n_estimators]
        new._seeds = self._seeds[:n_estimators]
        new.trees_ = self.trees_[:n_estimators]
        Z, y_pos = self._training(X, y)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FewRulesWarning)
            new._mine(Z, y_pos, n_estimators)
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
        new = self._copy_with(max_depth=max_depth)
        Z, y_pos = self._training(X, y)
        limit = min(
            np.inf if self.max_depth is None else self.max_depth,
            np.inf if max_depth is None else max_depth,
        )
        grown = np.array([a.grown_depth for a in self.trees_])
        redo = np.flatnonzero(grown >= limit)
        trees, rows, arrays = (
            list(self.estimators_),
            list(self.estimators_samples_),
            list(self.trees_),
        )
        for i, (t, r, a) in zip(redo, new._grow(Z, y_pos, self._seeds[redo]), strict=True):
            trees[i], rows[i], arrays[i] = t, r, a
        new.estimators_, new.estimators_samples_, new.trees_ = trees, rows, arrays
        new.n_retrained_ = int(redo.size)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FewRulesWarning)
            new._mine(Z, y_pos, len(trees))
        return new

    def apply(self, X) -> np.ndarray:
        """The leaf each row reaches in each tree (node ids of that tree), walking the trees
        in float64 in the table's units, as the rules are applied.

        Returns
        -------
        ndarray of int, shape (n_samples, n_estimators)
        """
        forest = stack_trees(self.trees_)
        return forest_apply(forest, self._encode_new(X)) - forest.offsets[:-1]

    def forest_probability(self, X) -> np.ndarray:
        """The forest's vote for the target class: the mean over trees of the leaf's share.

        Shares are class-weighted as the trees were trained (``class_weight``), so this ranks
        rows but is not a calibrated probability; the rules never use it. The trees are walked
        in the table's units, as the rules are applied.

        Returns
        -------
        ndarray of float, shape (n_samples,)
        """
        Z = self._encode_new(X)
        forest = stack_trees(self.trees_)
        return forest.share[forest_apply(forest, Z)].mean(axis=1)

    @property
    def feature_importances_(self) -> np.ndarray:
        """Mean over trees of each tree's normalised impurity decrease (pruned trees), summed
        over the encoded columns of a feature."""
        check_is_fitted(self)
        enc = self._encoding
        per_tree = []
        for a in self.trees_:
            imp = np.bincount(a.feature[a.gain > 0], weights=a.gain[a.gain > 0],
                              minlength=enc.n_encoded).astype(float)  # fmt: skip
            total = imp.sum()
            per_tree.append(imp / total if total > 0 else imp)
        imp = np.mean(per_tree, axis=0)
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
