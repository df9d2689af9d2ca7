"""Forest-to-box extraction: the node arrays of fitted trees and the box of every node."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ForestArrays", "stack_trees", "forest_boxes"]


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
