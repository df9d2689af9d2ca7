"""Pairs of points closer than a distance, by a uniform grid (numpy only).

The line reader merges drawn end points closer than its tolerance on every file it reads, and
``printability`` pairs the panels of every folded state it checks; a k-d tree
(``scipy.spatial``) does the same but costs 0.1-0.2 s to import, a tenth of
``holofold simulate``'s start-up (issue 37), so the pairs come from cells of the distance's size.
"""

from __future__ import annotations

import itertools

import numpy as np

__all__ = ["close_pairs"]

#: a grid of more cells than this would overflow the int64 cell keys
_MAX_CELLS = 2**60


def _half_neighbourhood(dim: int) -> list[tuple[int, ...]]:
    """The cell itself and the half of its 3^dim - 1 neighbours that come first in order."""
    offsets = itertools.product((-1, 0, 1), repeat=dim)
    return [o for o in offsets if o >= (0,) * dim]


def close_pairs(points: np.ndarray, r: float) -> np.ndarray:
    """Index pairs ``(i, j)``, ``i < j``, of the points at most ``r`` apart, (k, 2) intp, in
    no particular order.

    ``points`` (n, d), d = 1, 2 or 3; ``r`` > 0 in the points' unit. The same set as
    ``scipy.spatial.cKDTree(points).query_pairs(r)``."""
    p = np.asarray(points, float)
    n, dim = p.shape
    if n < 2:
        return np.zeros((0, 2), np.intp)
    cell = np.floor((p - p.min(axis=0)) / r).astype(np.int64) + 1  # neighbours' cells >= 0
    widths = cell.max(axis=0) + 2
    if float(np.prod(widths.astype(float))) > _MAX_CELLS:  # r tiny against the spread
        from scipy.spatial import cKDTree

        return cKDTree(p).query_pairs(r, output_type="ndarray").astype(np.intp)
    stride = np.concatenate([np.cumprod(widths[::-1])[::-1][1:], [1]])
    key = cell @ stride
    order = np.argsort(key, kind="stable")
    skey = key[order]
    found = []
    for offset in _half_neighbourhood(dim):
        want = skey + int(np.dot(offset, stride))  # sorted: the searches walk the keys once
        lo = np.searchsorted(skey, want, "left")
        cnt = np.searchsorted(skey, want, "right") - lo
        if not cnt.any():
            continue
        i = np.repeat(order, cnt)
        start = np.repeat(lo - (np.cumsum(cnt) - cnt), cnt)
        j = order[start + np.arange(len(i))]
        if not any(offset):
            keep = i < j
            i, j = i[keep], j[keep]
        d = p[i] - p[j]
        near = np.einsum("ij,ij->i", d, d) <= r * r
        i, j = i[near], j[near]
        found.append(np.stack([np.minimum(i, j), np.maximum(i, j)], axis=1))
    return np.concatenate(found).astype(np.intp) if found else np.zeros((0, 2), np.intp)
