"""Statistics of rules: counts of rows inside boxes, F-beta, Wilson bounds, the empirical-Bayes
estimate of a rule's precision on new designs."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from holofold.design.rules.boxes import boxes_contain

__all__ = [
    "LCB_Z",
    "MAX_PRIOR",
    "wilson_lower",
    "fbeta",
    "fit_prior",
    "Posterior",
    "posterior",
    "box_counts",
    "finder_matrix",
    "box_stats",
]

LCB_Z = 1.6448536269514722  # one-sided 95 % normal quantile for the Wilson bound


def wilson_lower(tp: np.ndarray, n: np.ndarray, z: float = LCB_Z) -> np.ndarray:
    n = np.asarray(n, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        p = np.where(n > 0, tp / n, 0.0)
        denom = 1 + z * z / n
        centre = p + z * z / (2 * n)
        half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
        lcb = (centre - half) / denom
    return np.where(n > 0, np.clip(lcb, 0.0, 1.0), 0.0)


def fbeta(precision, recall, beta):
    b2 = beta * beta
    with np.errstate(invalid="ignore", divide="ignore"):
        f = (1 + b2) * precision * recall / (b2 * precision + recall)
    return np.nan_to_num(f, nan=0.0)


MAX_PRIOR = 20.0  # cap of the empirical-Bayes prior strength, in rows (chosen on the suite)


def fit_prior(strength, tp: np.ndarray, n: np.ndarray, base_rate: float) -> tuple[float, float]:
    """Mean and strength (in rows) of the Beta prior of a rule's precision.

    A number shrinks toward the base rate with that strength, None not at all; ``"auto"``
    fits a beta-binomial to the candidates' out-of-bag counts by moments (empirical Bayes):
    the prior mean is their pooled precision and the strength follows from how much their
    precisions vary beyond binomial noise, at most 20 rows: with few candidates the moments
    often show no spread beyond noise, and an unbounded prior would then ignore the rule's own
    rows (on the target suite, 20 gave the smallest error against verified precision).
    """
    if strength is None:
        return base_rate, 0.0
    if strength != "auto":
        return base_rate, float(strength)
    ok = n > 0
    if np.count_nonzero(ok) < 3:
        return base_rate, 0.0
    tp, n = tp[ok], n[ok]
    mu = float(tp.sum() / n.sum())
    if not 0 < mu < 1:
        return mu, 0.0
    inv = float(np.mean(1.0 / n))
    s2 = float(np.mean((tp / n - mu) ** 2))
    tau2 = (s2 - mu * (1 - mu) * inv) / max(1 - inv, 1e-9)  # variance of the true precisions
    if tau2 <= 0:
        return mu, MAX_PRIOR
    return mu, float(np.clip(mu * (1 - mu) / tau2 - 1, 0.0, MAX_PRIOR))


class Posterior(NamedTuple):
    """What :func:`posterior` returns (a tuple, so it still unpacks): the posterior mean of
    precision, its 95 % interval (``lo``, ``hi``) and one-sided 95 % lower bound ``lcb``, each
    shaped as the counts."""

    mean: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    lcb: np.ndarray


def posterior(tp, n, mu: float, k: float) -> Posterior:
    """Posterior mean, 95 % interval and one-sided 95 % lower bound of precision.

    Prior Beta(k mu, k (1 - mu)) on ``tp`` of ``n`` rows; the interval and bound are quantiles
    of the posterior with Jeffreys' half counts added (so k = 0 gives Jeffreys' interval).
    """
    from scipy.special import betaincinv

    tp = np.asarray(tp, dtype=float)
    n = np.asarray(n, dtype=float)
    a = tp + k * mu
    b = n - tp + k * (1 - mu)
    mean = np.where(a + b > 0, a / np.maximum(a + b, 1e-300), mu)
    lo = betaincinv(a + 0.5, b + 0.5, 0.025)
    hi = betaincinv(a + 0.5, b + 0.5, 0.975)
    lcb = betaincinv(a + 0.5, b + 0.5, 0.05)
    return Posterior(mean, lo, hi, lcb)


def box_counts(pair_box, pair_row, pair_bag, y_pos, m: int, n: int) -> dict:
    """Rows and target rows per box from its (row, tree) pairs.

    ``support`` / ``true_positives``: distinct rows in the box; ``estimate_*``: distinct rows
    out of bag for at least one tree that found it; ``bag_*``: distinct rows in bag for at
    least one of them; ``oob_*``: out-of-bag pairs (a row once per such tree).
    """
    out = {}
    for name, sel in (("", None), ("estimate_", ~pair_bag), ("bag_", pair_bag)):
        b, r = (pair_box, pair_row) if sel is None else (pair_box[sel], pair_row[sel])
        codes = np.unique(b * n + r)
        out[f"{name}support" if name else "support"] = np.bincount(codes // n, minlength=m).astype(
            float
        )
        out[f"{name}true_positives" if name else "true_positives"] = np.bincount(
            codes // n, weights=y_pos[codes % n], minlength=m
        )
    oob = ~pair_bag
    out["oob_support"] = np.bincount(pair_box[oob], minlength=m).astype(float)
    out["oob_true_positives"] = np.bincount(
        pair_box[oob], weights=y_pos[pair_row[oob]], minlength=m
    )
    return out


def finder_matrix(inverse, tree_of_cand, m: int, T: int) -> np.ndarray:
    """(m, T) 0/1: which trees found each distinct box."""
    out = np.zeros((m, T))
    out[inverse, tree_of_cand] = 1.0
    return out


def box_stats(lower, upper, Z, y_pos, oob_weight, bag_rows) -> dict:
    """Training statistics of boxes that are not leaves (simplified or tightened ones).

    ``oob_weight`` (n_boxes, n): for each row, the trees that found the box's leaf and did not
    train on it; ``bag_rows`` (n_boxes, n): rows one of them trained on.
    """
    inside = boxes_contain(lower, upper, Z)
    pos = y_pos == 1
    in_oob = inside * oob_weight
    est_rows = in_oob > 0
    sup = inside.sum(axis=1).astype(float)
    tp = (inside & pos).sum(axis=1).astype(float)
    n_pos = max(int(pos.sum()), 1)
    return {
        "precision": np.where(sup > 0, tp / np.maximum(sup, 1), 0.0),
        "recall": tp / n_pos,
        "support": sup,
        "true_positives": tp,
        "oob_precision": (in_oob @ y_pos) / np.maximum(in_oob.sum(axis=1), 1),
        "oob_support": in_oob.sum(axis=1),
        "estimate_true_positives": (est_rows @ y_pos).astype(float),
        "estimate_support": est_rows.sum(axis=1).astype(float),
        "bag_true_positives": ((inside & bag_rows) @ y_pos).astype(float),
        "bag_support": (inside & bag_rows).sum(axis=1).astype(float),
    }
