"""Boxes after extraction: which rows they hold, and the post-processing of kept rules
(tightening to the target rows, dropping conditions)."""

from __future__ import annotations

import numpy as np

__all__ = ["boxes_contain", "tighten", "simplify_boxes", "drop_idle_conditions"]


def boxes_contain(lower: np.ndarray, upper: np.ndarray, Z: np.ndarray) -> np.ndarray:
    """Which rows lie in which boxes: ``lower < x <= upper`` on every feature, in float64 on
    the table's values (the one semantics of a rule, as :meth:`Rule.mask`).

    Parameters
    ----------
    lower, upper : ndarray, shape (n_boxes, n_features)
    Z : ndarray, shape (n_rows, n_features)

    Returns
    -------
    ndarray of bool, shape (n_boxes, n_rows)
    """
    Zf = np.asarray(Z, dtype=np.float64)
    out = np.ones((lower.shape[0], Zf.shape[0]), dtype=bool)
    for r in range(lower.shape[0]):  # a handful of kept rules; features vectorised
        cols = np.flatnonzero(np.isfinite(lower[r]) | np.isfinite(upper[r]))
        if cols.size:
            sub = Zf[:, cols]
            out[r] = np.all((sub > lower[r, cols]) & (sub <= upper[r, cols]), axis=1)
    return out


def tighten(lower, upper, Z, y_pos, numeric):
    """Move each finite numeric bound of each box inward to its outermost target training row.

    A leaf's bound lies halfway between two values of the rows its tree trained on, so the
    slab between it and the last target row inside holds no target row: a region where the rule
    is a guess. Categorical columns (``numeric`` False) keep their bounds; so does a side that
    is open (no new condition is added).
    """
    Zf = np.asarray(Z, dtype=np.float64)
    inside = boxes_contain(lower, upper, Zf) & (y_pos == 1)
    lower, upper = lower.copy(), upper.copy()
    for i in range(lower.shape[0]):
        z = Zf[inside[i]]
        if not z.shape[0]:
            continue
        for c in np.flatnonzero(np.isfinite(lower[i]) & numeric):
            below = float(np.nextafter(z[:, c].min(), -np.inf))  # x > below: x >= min
            lower[i, c] = max(lower[i, c], below)
        for c in np.flatnonzero(np.isfinite(upper[i]) & numeric):
            upper[i, c] = min(upper[i, c], float(z[:, c].max()))
    return lower, upper


def _conditions(lower: np.ndarray, upper: np.ndarray, Zf: np.ndarray):
    """Conditions of one box as (column, side) and the (n, n_cond) matrix of rows violating each."""
    conds = [(c, 0) for c in np.flatnonzero(np.isfinite(lower))]
    conds += [(c, 1) for c in np.flatnonzero(np.isfinite(upper))]
    viol = np.empty((Zf.shape[0], len(conds)), dtype=bool)
    for j, (c, side) in enumerate(conds):
        viol[:, j] = Zf[:, c] <= lower[c] if side == 0 else Zf[:, c] > upper[c]
    return conds, viol


def _open(lower, upper, i: int, cond) -> None:
    c, side = cond
    if side == 0:
        lower[i, c] = -np.inf
    else:
        upper[i, c] = np.inf


def simplify_boxes(lower, upper, Z, y_pos, weight, prior, precision_min):
    """Drop conditions that do not raise the out-of-bag precision estimate.

    Greedy: repeatedly drop the condition whose removal gives the highest estimate, as long as
    that estimate is not below the current one and the box's training precision stays at
    least ``precision_min``. ``weight[i]`` (n,) marks the rows out of bag for a tree that
    found box ``i``; the estimate is the posterior mean under ``prior`` on those rows.
    """
    mu, k = prior
    Zf = np.asarray(Z, dtype=np.float64)
    pos = y_pos == 1
    lower, upper = lower.copy(), upper.copy()
    for i in range(lower.shape[0]):
        conds, viol = _conditions(lower[i], upper[i], Zf)
        if not conds:
            continue
        oob = weight[i] > 0
        active = np.ones(len(conds), dtype=bool)
        while active.any():
            act = np.flatnonzero(active)
            nv = viol[:, act].sum(axis=1)
            inside = nv == 0
            r1 = np.flatnonzero(nv == 1)
            which = act[np.argmax(viol[r1][:, act], axis=1)]  # each row's one violation

            size = len(conds)

            def added(w, which=which, r1=r1, size=size):
                return np.bincount(which, weights=w[r1], minlength=size)

            n_o, tp_o = np.count_nonzero(inside & oob), np.count_nonzero(inside & oob & pos)
            n_t, tp_t = np.count_nonzero(inside), np.count_nonzero(inside & pos)
            new_n_o, new_tp_o = n_o + added(oob * 1.0), tp_o + added((oob & pos) * 1.0)
            new_prec = (tp_t + added(pos * 1.0)) / (n_t + added(np.ones(len(pos))))
            with np.errstate(invalid="ignore", divide="ignore"):
                cur = (tp_o + k * mu) / (n_o + k) if n_o + k > 0 else mu
                new = np.where(new_n_o + k > 0, (new_tp_o + k * mu) / (new_n_o + k), mu)
            ok = active & (new_prec >= precision_min) & (new >= cur - 1e-12)
            if not ok.any():
                break
            j = int(np.argmax(np.where(ok, new, -np.inf)))
            active[j] = False
            _open(lower, upper, i, conds[j])
    return lower, upper


def drop_idle_conditions(lower, upper, Z):
    """Drop the conditions of each box that no training row depends on.

    A condition is idle when no row violates it alone: without it the box holds the same
    rows. Conditions are tried in column order and dropped one at a time.
    """
    Zf = np.asarray(Z, dtype=np.float64)
    lower, upper = lower.copy(), upper.copy()
    for i in range(lower.shape[0]):
        conds, viol = _conditions(lower[i], upper[i], Zf)
        active = np.ones(len(conds), dtype=bool)
        for j in range(len(conds)):
            others = active.copy()
            others[j] = False
            if not np.any(viol[:, j] & ~viol[:, others].any(axis=1)):
                active[j] = False
                _open(lower, upper, i, conds[j])
    return lower, upper
