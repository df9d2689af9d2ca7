"""Choosing rules from a forest: candidate boxes (the target leaves, merged), their counts and
estimates, the filters, the ranking, and the kept rules (distinct, tightened, tidied)."""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from holofold.design.rules.boxes import (
    boxes_contain,
    drop_idle_conditions,
    simplify_boxes,
    tighten,
)
from holofold.design.rules.forest import forest_apply, forest_boxes, stack_trees
from holofold.design.rules.statistics import (
    box_counts,
    box_stats,
    fbeta,
    finder_matrix,
    fit_prior,
    posterior,
    wilson_lower,
)

__all__ = ["Settings", "Selection", "select_rules", "score", "pick_rules"]


@dataclass(frozen=True)
class Settings:
    """The selection parameters of :class:`~holofold.design.rules.miner.ForestRuleMiner`
    (see its docstring)."""

    precision_min: float
    recall_min: float
    min_support: int
    beta: float
    n_rules: int
    max_overlap: float | None
    scoring: str
    ranking: str
    prior_strength: object
    simplify: str
    tighten: bool

    @classmethod
    def of(cls, estimator) -> Settings:
        return cls(**{f.name: getattr(estimator, f.name) for f in fields(cls)})


@dataclass(frozen=True)
class Selection:
    """What :func:`select_rules` found.

    Attributes
    ----------
    n_candidates : int
        Distinct target-leaf boxes before filtering.
    prior : dict
        ``mean``, ``strength`` and ``base_rate`` of the estimate's prior.
    all_lower, all_upper, all_stats
        The candidates that passed the filters, ranked: boxes (n_pass, d) and statistics.
    lower, upper, kept
        The kept rules: boxes (k, d) and statistics.
    short : str or None
        Why fewer rules than asked for were kept.
    """

    n_candidates: int
    prior: dict
    all_lower: np.ndarray
    all_upper: np.ndarray
    all_stats: dict
    lower: np.ndarray
    upper: np.ndarray
    kept: dict
    short: str | None


def select_rules(trees, bags, Z: np.ndarray, y_pos: np.ndarray, numeric, s: Settings) -> Selection:
    """Candidate rules and the kept ones from trees, on their training rows.

    Parameters
    ----------
    trees : list of TreeArrays
    bags : list of ndarray of int
        The training rows of each tree.
    Z : ndarray, shape (n, d)
        The training rows (the table's units, encoded columns).
    y_pos : ndarray of int, shape (n,)
        1 where the row meets the target.
    numeric : ndarray of bool, shape (d,)
        The encoded columns of numeric features (tightening moves only their bounds).
    s : Settings
    """
    forest = stack_trees(trees)
    lower, upper = forest_boxes(forest, Z.shape[1])
    n, T = Z.shape[0], forest.n_trees
    leaves = forest_apply(forest, Z)
    N = forest.left.shape[0]
    support = np.bincount(leaves.ravel(), minlength=N)

    cand = np.flatnonzero(forest.is_leaf & forest.positive & (support > 0))
    keys = np.concatenate([lower[cand], upper[cand]], axis=1)
    if cand.size:
        _, first, inverse, counts = np.unique(
            keys, axis=0, return_index=True, return_inverse=True, return_counts=True
        )
        inverse = inverse.ravel()
        uniq = cand[first]
    else:
        uniq = cand
        inverse = np.zeros(0, dtype=np.intp)
        counts = np.zeros(0, dtype=np.intp)
    n_candidates = int(uniq.size)
    m = uniq.size
    n_pos = max(int(y_pos.sum()), 1)
    lo_u, up_u = lower[uniq], upper[uniq]

    # every (row, tree) pair whose row lies in one of the tree's candidate leaves, with the
    # box it stands for and whether the tree trained on the row (in bag) or not (out of bag)
    in_bag = np.zeros((n, T), dtype=bool)
    for k, rows in enumerate(bags[:T]):
        in_bag[rows, k] = True
    node_box = np.full(N, -1, dtype=np.intp)
    node_box[cand] = inverse
    box_of = node_box[leaves]
    pair_row, pair_tree = np.nonzero(box_of >= 0)
    pair_box = box_of[pair_row, pair_tree]
    pair_bag = in_bag[pair_row, pair_tree]
    c = box_counts(pair_box, pair_row, pair_bag, y_pos, m, n)
    sup, tpu = c["support"], c["true_positives"]
    prec = np.where(sup > 0, tpu / np.maximum(sup, 1), 0.0)
    rec = tpu / n_pos
    enough = (sup >= s.min_support) & (rec >= s.recall_min)
    o_n, o_tp = c["estimate_support"], c["estimate_true_positives"]
    b_n, b_tp = c["bag_support"], c["bag_true_positives"]
    pooled_n, pooled_tp = c["oob_support"], c["oob_true_positives"]
    # candidates are filtered on the training rows (the paper); the prior of the estimate is
    # fitted to the leaves that pass the filter on the rows their trees trained on, a
    # population chosen without looking at the out-of-bag rows
    in_bag_ok = enough & (b_tp >= s.precision_min * np.maximum(b_n, 1))
    keep = enough & (prec >= s.precision_min)

    base_rate = float(y_pos.mean()) if n else 0.0
    prior = fit_prior(s.prior_strength, o_tp[in_bag_ok], o_n[in_bag_ok], base_rate)
    prior_ = {"mean": prior[0], "strength": prior[1], "base_rate": base_rate}
    stats = {
        "precision": prec,
        "recall": rec,
        "support": sup,
        "true_positives": tpu,
        "n_trees": counts.astype(np.intp),
        "oob_precision": np.where(pooled_n > 0, pooled_tp / np.maximum(pooled_n, 1), 0.0),
        "oob_support": pooled_n,
        "estimate_true_positives": o_tp,
        "estimate_support": o_n,
        "bag_true_positives": b_tp,
        "bag_support": b_n,
        "_box": np.arange(m),
    }
    idx = np.flatnonzero(keep)
    lo_all, up_all = lo_u[idx], up_u[idx]
    stats = {key: v[idx] for key, v in stats.items()}
    score(stats, n_pos, prior_, s)
    order = np.lexsort((np.arange(idx.size), -stats["support"], -stats["score"]))
    lo_all, up_all = lo_all[order], up_all[order]
    stats = {key: v[order] for key, v in stats.items()}

    finders = finder_matrix(inverse, forest.tree_of[cand], m, T)  # (m, T) 0/1
    if s.simplify == "estimate" and idx.size:
        top = min(idx.size, max(8 * s.n_rules, 32))
        f_top = finders[stats["_box"][:top]]
        weight = f_top @ (~in_bag).T.astype(float)  # (top, n) out-of-bag pairs per row
        new_lo, new_up = simplify_boxes(
            lo_all[:top], up_all[:top], Z, y_pos, weight, prior, s.precision_min
        )
        simplified = box_stats(new_lo, new_up, Z, y_pos, weight, f_top @ in_bag.T > 0)
        simplified["n_trees"] = stats["n_trees"][:top]
        simplified["_box"] = stats["_box"][:top]
        score(simplified, n_pos, prior_, s)
        lo_all = np.concatenate([new_lo, lo_all[top:]])
        up_all = np.concatenate([new_up, up_all[top:]])
        stats = {key: np.concatenate([simplified[key], v[top:]]) for key, v in stats.items()}
        order = np.lexsort((np.arange(len(lo_all)), -stats["support"], -stats["score"]))
        lo_all, up_all = lo_all[order], up_all[order]
        stats = {key: v[order] for key, v in stats.items()}
    if s.simplify == "estimate" and len(lo_all):
        # boxes made identical by simplification: the best ranked one stays
        _, first = np.unique(np.concatenate([lo_all, up_all], axis=1), axis=0, return_index=True)
        first = np.sort(first)
        lo_all, up_all = lo_all[first], up_all[first]
        stats = {key: v[first] for key, v in stats.items()}

    for key in ("support", "true_positives", "oob_support", "estimate_support", "bag_support"):
        stats[key] = stats[key].astype(np.intp)
    k = s.n_rules

    def shape(lo, up):  # what a kept rule becomes: tightened to its target rows, or as is
        return tighten(lo, up, Z, y_pos, numeric) if s.tighten else (lo, up)

    pick, lower, upper = pick_rules(lo_all, up_all, Z, k, shape, s.max_overlap)
    kept = {key: v[pick] for key, v in stats.items()}
    if s.tighten and len(pick):
        f_kept = finders[kept["_box"]]
        weight = f_kept @ (~in_bag).T.astype(float)
        new = box_stats(lower, upper, Z, y_pos, weight, f_kept @ in_bag.T > 0)
        kept.update(new)
        score(kept, n_pos, prior_, s)
        for key in (
            "support",
            "true_positives",
            "oob_support",
            "estimate_support",
            "bag_support",
        ):
            kept[key] = kept[key].astype(np.intp)
    if s.simplify != "none":
        lower, upper = drop_idle_conditions(lower, upper, Z)
    kept.pop("_box")
    short = None
    if len(pick) < k:
        n_pass = len(lo_all)
        short = (
            f"only {len(pick)} of the {k} requested rules: {n_pass} reach precision "
            f">= {s.precision_min} with support >= {s.min_support} "
            f"({n_candidates} distinct candidate boxes)"
        )
        if n_pass > len(pick):
            short += (
                f"; the others copy a kept rule (overlap > {s.max_overlap})"
                if s.max_overlap is not None
                else "; the others are copies of a kept rule"
            )
    return Selection(n_candidates, prior_, lo_all, up_all, stats, lower, upper, kept, short)


def score(stats: dict, n_pos: int, prior: dict, s: Settings) -> None:
    """Add the estimate (mean and interval), ``f_score`` and the ranking ``score``."""
    mu, k = prior["mean"], prior["strength"]
    est, lo, hi, lcb = posterior(stats["estimate_true_positives"], stats["estimate_support"], mu, k)
    stats["estimate"], stats["estimate_low"], stats["estimate_high"] = est, lo, hi
    if s.scoring == "train":
        p, n = stats["precision"], stats["support"]
    elif s.scoring == "oob":
        p, n = stats["oob_precision"], stats["oob_support"]
    if s.scoring == "estimate":
        p_rank = est if s.ranking == "fbeta" else lcb
    else:
        p_rank = p if s.ranking == "fbeta" else wilson_lower(p * n, n)
    stats["f_score"] = fbeta(stats["precision"], stats["recall"], s.beta)
    stats["score"] = fbeta(p_rank, stats["recall"], s.beta)


def pick_rules(all_lower, all_upper, Z: np.ndarray, k: int, shape, max_overlap):
    """The rules to keep: positions in the ranking and their (shaped) boxes.

    Walking down the ranking, each candidate is shaped (``shape(lower, upper)``, e.g.
    tightened) and kept unless it equals a kept box or, with ``max_overlap``, the training
    rows it covers overlap those of a kept rule by a Jaccard index above ``max_overlap``.
    """
    n = len(all_lower)
    kept: list[int] = []
    boxes: list[tuple[np.ndarray, np.ndarray]] = []
    covered: list[np.ndarray] = []
    block = 4 * k if max_overlap is None else 256
    for start in range(0, n, block):  # a block of candidates at a time
        lo, up = shape(all_lower[start : start + block], all_upper[start : start + block])
        rows_of = boxes_contain(lo, up, Z) if max_overlap is not None else None
        for j in range(lo.shape[0]):
            if any(np.array_equal(lo[j], a) and np.array_equal(up[j], b) for a, b in boxes):
                continue
            if rows_of is not None:
                rows = rows_of[j]
                inter = [np.count_nonzero(rows & c) for c in covered]
                union = [np.count_nonzero(rows | c) for c in covered]
                if any(i > max_overlap * max(u, 1) for i, u in zip(inter, union, strict=True)):
                    continue
                covered.append(rows)
            kept.append(start + j)
            boxes.append((lo[j], up[j]))
            if len(kept) == k:
                break
        if len(kept) == k:
            break
    d = all_lower.shape[1]
    lower = np.array([a for a, _ in boxes]).reshape(-1, d)
    upper = np.array([b for _, b in boxes]).reshape(-1, d)
    return np.asarray(kept, dtype=np.intp), lower, upper
