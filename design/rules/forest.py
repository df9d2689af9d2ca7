"""Forest-to-box extraction: the trees as node arrays in the table's units, and every node's box.

The trees are grown on rank codes of the features (:class:`~.encoding.RankCodes`), so that no
unit makes two different values look equal to scikit-learn's splitter (it treats values closer
than 1e-7 as one, which in metres hides the gripper's micrometre thicknesses). A tree on codes
is the tree scikit-learn grows on any well-scaled copy of the table: splits depend only on the
order of the values. :func:`tree_arrays` then maps each split back to the table's own units
exactly as scikit-learn places a threshold, halfway between the largest value sent left and
the smallest sent right among the rows the tree trained on, and prunes the tree by minimal
cost-complexity (Breiman's weakest link, as scikit-learn's ``ccp_alpha``). From then on every
rule, count and prediction uses these arrays in float64 on the table's values: a leaf's region
*is* its box (:func:`forest_boxes`, :func:`forest_apply`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "TreeArrays",
    "tree_arrays",
    "prune",
    "ForestArrays",
    "stack_trees",
    "forest_boxes",
    "forest_apply",
]


@dataclass(frozen=True)
class TreeArrays:
    """One fitted tree as node arrays, its thresholds in the table's units, pruned.

    Attributes
    ----------
    left, right : ndarray of int, shape (n_nodes,)
        Children (node ids of this tree), -1 at leaves (a pruned node is a leaf; the nodes
        that were below it are leaves no row reaches).
    feature : ndarray of int, shape (n_nodes,)
        Split feature (encoded column; undefined at leaves).
    threshold : ndarray of float64, shape (n_nodes,)
        Split threshold in the table's units: left child ``x <= t``, right child ``x > t``.
    positive : ndarray of bool, shape (n_nodes,)
        The node predicts the target class.
    share : ndarray of float64, shape (n_nodes,)
        The class-weighted share of target rows in the node (the tree's vote there).
    gain : ndarray of float64, shape (n_nodes,)
        Weighted impurity decrease of each kept split (0 at leaves), for importances.
    grown_depth : int
        Depth before pruning: a tree whose grown depth is below a depth limit is the same tree
        under any larger limit.
    """

    left: np.ndarray
    right: np.ndarray
    feature: np.ndarray
    threshold: np.ndarray
    positive: np.ndarray
    share: np.ndarray
    gain: np.ndarray
    grown_depth: int

    @property
    def n_nodes(self) -> int:
        return int(self.left.shape[0])


def prune(left, right, impurity, weight, ccp_alpha: float) -> np.ndarray:
    """Minimal cost-complexity pruning: which nodes become leaves.

    Breiman's weakest link, as scikit-learn prunes with ``ccp_alpha`` (same order of sums and
    the same tie rule, the first node of smallest effective alpha): while the weakest link's
    effective alpha ``(R(t) - R(T_t)) / (|leaves of T_t| - 1)`` is at most ``ccp_alpha``, its
    branch is cut. ``R(t) = weight[t] impurity[t] / weight[root]``.

    Parameters
    ----------
    left, right : ndarray of int, shape (n_nodes,)
        Children, -1 at leaves; node ids in depth-first order (a node's subtree is the range
        that follows it), as scikit-learn builds them.
    impurity, weight : ndarray of float, shape (n_nodes,)
        Node impurity and weighted number of training rows.
    ccp_alpha : float

    Returns
    -------
    ndarray of bool, shape (n_nodes,)
        The internal nodes cut into leaves.
    """
    n = left.shape[0]
    cut = np.zeros(n, dtype=bool)
    if ccp_alpha <= 0 or n < 3:
        return cut
    leaf = left < 0
    parent = np.full(n, -1, dtype=np.intp)
    inner = np.flatnonzero(~leaf)
    parent[left[inner]] = inner
    parent[right[inner]] = inner
    r_node = weight * impurity / weight[0]
    # size of every subtree (depth-first ids: the subtree of i is i .. i + size - 1)
    size = np.ones(n, dtype=np.intp)
    for i in inner[::-1]:
        size[i] = 1 + size[left[i]] + size[right[i]]
    # leaves' costs bubbled up in leaf order, as scikit-learn sums them
    r_branch = np.where(leaf, r_node, 0.0)
    n_leaves = np.zeros(n, dtype=np.intp)
    pairs_leaf, pairs_anc = [], []
    cur = np.flatnonzero(leaf)
    src = cur.copy()
    while True:
        up = parent[cur]
        keep = up >= 0
        if not keep.any():
            break
        cur, src = up[keep], src[keep]
        pairs_leaf.append(src)
        pairs_anc.append(cur)
    if pairs_leaf:
        lf = np.concatenate(pairs_leaf)
        anc = np.concatenate(pairs_anc)
        order = np.argsort(lf, kind="stable")
        np.add.at(r_branch, anc[order], r_node[lf[order]])
        np.add.at(n_leaves, anc, 1)
    candidate = ~leaf
    while candidate[0]:
        cand = np.flatnonzero(candidate)
        alpha = (r_node[cand] - r_branch[cand]) / (n_leaves[cand] - 1)
        k = int(np.argmin(alpha))
        if ccp_alpha < alpha[k]:
            break
        node = int(cand[k])
        below = slice(node + 1, node + size[node])
        candidate[node] = False
        candidate[below] = False
        cut[node] = True
        cut[below] = False
        pruned_leaves = n_leaves[node] - 1
        n_leaves[node] = 0
        r_diff = r_node[node] - r_branch[node]
        r_branch[node] = r_node[node]
        a = parent[node]
        while a >= 0:
            n_leaves[a] -= pruned_leaves
            r_branch[a] += r_diff
            a = parent[a]
    return cut


def _split_values(tree, codes: np.ndarray, rows: np.ndarray, values) -> np.ndarray:
    """Each split's threshold in the table's units, placed as scikit-learn places it.

    ``codes`` (n, d) are the rank codes the tree was trained on and ``rows`` its training rows;
    ``values[j]`` the sorted distinct values of encoded column ``j``. For a split of node ``t``
    on column ``j``: the midpoint of the largest value of the rows it sent left and the smallest
    it sent right (the lower one where the midpoint rounds onto the upper).
    """
    tr = tree.tree_
    n_nodes = tr.node_count
    cl, cr, feat = tr.children_left, tr.children_right, tr.feature
    thr = np.full(n_nodes, np.nan)
    inner = np.flatnonzero(cl >= 0)
    if not inner.size:
        return thr
    parent = np.full(n_nodes, -1, dtype=np.intp)
    parent[cl[inner]] = inner
    parent[cr[inner]] = inner
    is_left = np.zeros(n_nodes, dtype=bool)
    is_left[cl[inner]] = True
    sub = np.ascontiguousarray(codes[rows])
    path = tree.decision_path(sub)
    row_of = np.repeat(np.arange(sub.shape[0]), np.diff(path.indptr))
    node = path.indices
    ok = parent[node] >= 0
    row_of, node = row_of[ok], node[ok]
    par = parent[node]
    code = sub[row_of, feat[par]].astype(np.int64)
    big = np.iinfo(np.int64).max
    lo = np.full(n_nodes, -1, dtype=np.int64)  # largest code sent left, per split node
    hi = np.full(n_nodes, big, dtype=np.int64)  # smallest code sent right
    left_side = is_left[node]
    np.maximum.at(lo, par[left_side], code[left_side])
    np.minimum.at(hi, par[~left_side], code[~left_side])
    flat = np.concatenate(values)
    start = np.concatenate([[0], np.cumsum([len(v) for v in values])[:-1]])
    f = feat[inner]
    code = np.floor(tr.threshold[inner]).astype(np.int64)  # a split no row reached: its codes
    a = flat[start[f] + np.where(lo[inner] >= 0, lo[inner], code)]
    b = flat[start[f] + np.where(hi[inner] < big, hi[inner], code + 1)]
    mid = a / 2.0 + b / 2.0
    thr[inner] = np.where((mid >= b) | ~np.isfinite(mid), a, mid)
    return thr


def tree_arrays(
    tree, codes: np.ndarray, rows: np.ndarray, values, ccp_alpha: float, positive_label=1
) -> TreeArrays:
    """The node arrays of a tree grown (unpruned) on rank ``codes`` of rows ``rows``, with
    thresholds in the table's units (``values``: per encoded column its sorted distinct
    values) and minimal cost-complexity pruning with ``ccp_alpha`` applied."""
    tr = tree.tree_
    left = tr.children_left.astype(np.intp)
    right = tr.children_right.astype(np.intp)
    weight = tr.weighted_n_node_samples.astype(np.float64)
    impurity = tr.impurity.astype(np.float64)
    grown = int(tree.get_depth())
    cut = prune(left, right, impurity, weight, ccp_alpha)
    left = np.where(cut, -1, left)
    right = np.where(cut, -1, right)
    value = tr.value[:, 0, :].astype(np.float64)
    classes = np.asarray(tree.classes_)
    pred = classes[np.argmax(value, axis=1)]
    col = np.flatnonzero(classes == positive_label)
    total = value.sum(axis=1)
    share = value[:, col[0]] / np.where(total > 0, total, 1.0) if col.size else np.zeros(len(left))
    reach = np.zeros(len(left), dtype=bool)  # nodes below a pruned branch are never reached
    frontier = np.array([0])
    while frontier.size:
        reach[frontier] = True
        frontier = frontier[left[frontier] >= 0]
        frontier = np.concatenate([left[frontier], right[frontier]])
    left = np.where(reach, left, -1)  # unreached nodes: leaves no row gets to
    right = np.where(reach, right, -1)
    gain = np.zeros(len(left))
    inner = np.flatnonzero(left >= 0)
    gain[inner] = (
        weight[inner] * impurity[inner]
        - weight[left[inner]] * impurity[left[inner]]
        - weight[right[inner]] * impurity[right[inner]]
    )
    return TreeArrays(
        left=left,
        right=right,
        feature=tr.feature.astype(np.intp),
        threshold=_split_values(tree, codes, rows, values),
        positive=pred == positive_label,
        share=share,
        gain=gain,
        grown_depth=grown,
    )


@dataclass(frozen=True)
class ForestArrays:
    """The node arrays of several trees concatenated into one forest-wide numbering.

    Attributes
    ----------
    offsets : ndarray of int, shape (n_trees + 1,)
        Node ``i`` of tree ``k`` has global id ``offsets[k] + i``.
    left, right : ndarray of int, shape (n_nodes,)
        Global ids of the children, -1 at leaves.
    feature : ndarray of int, shape (n_nodes,)
        Split feature (undefined at leaves).
    threshold : ndarray of float64, shape (n_nodes,)
        Split threshold in the table's units: left child ``x <= t``, right child ``x > t``.
    positive : ndarray of bool, shape (n_nodes,)
        The node predicts the target class.
    share : ndarray of float64, shape (n_nodes,)
        The node's class-weighted share of target rows.
    tree_of : ndarray of int, shape (n_nodes,)
        The tree each node belongs to.
    """

    offsets: np.ndarray
    left: np.ndarray
    right: np.ndarray
    feature: np.ndarray
    threshold: np.ndarray
    positive: np.ndarray
    share: np.ndarray
    tree_of: np.ndarray

    @property
    def is_leaf(self) -> np.ndarray:
        return self.left < 0

    @property
    def n_trees(self) -> int:
        return int(self.offsets.shape[0] - 1)


def stack_trees(trees) -> ForestArrays:
    """Concatenate :class:`TreeArrays` into one :class:`ForestArrays`."""
    sizes = np.array([t.n_nodes for t in trees], dtype=np.intp)
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.intp)

    def cat(name, dtype):
        parts = [getattr(t, name) for t in trees]
        return np.concatenate(parts).astype(dtype) if parts else np.zeros(0, dtype)

    def children(name):
        parts = [np.where(getattr(t, name) >= 0, getattr(t, name) + offsets[k], -1)
                 for k, t in enumerate(trees)]  # fmt: skip
        return np.concatenate(parts).astype(np.intp) if parts else np.zeros(0, np.intp)

    return ForestArrays(
        offsets,
        children("left"),
        children("right"),
        cat("feature", np.intp),
        cat("threshold", np.float64),
        cat("positive", bool),
        cat("share", np.float64),
        np.repeat(np.arange(len(trees)), sizes),
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
        A row ``x`` (float64, the table's units) lies in node ``i`` iff
        ``lower[i] < x <= upper[i]`` on every feature; unbounded sides are ``-inf`` / ``+inf``.
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


def forest_apply(forest: ForestArrays, Z: np.ndarray) -> np.ndarray:
    """The leaf of every row in every tree (global ids), walking the trees in float64.

    Parameters
    ----------
    forest : ForestArrays
    Z : ndarray, shape (n_rows, n_features)
        Rows in the table's units (encoded columns).

    Returns
    -------
    ndarray of int, shape (n_rows, n_trees)
    """
    Z = np.asarray(Z, dtype=np.float64)
    n, T = Z.shape[0], forest.n_trees
    node = np.broadcast_to(forest.offsets[:-1], (n, T)).copy()
    flat = node.ravel()  # a view: rows x trees
    row = np.repeat(np.arange(n), T)
    active = np.flatnonzero(forest.left[flat] >= 0)
    while active.size:
        nd = flat[active]
        go_left = Z[row[active], forest.feature[nd]] <= forest.threshold[nd]
        flat[active] = np.where(go_left, forest.left[nd], forest.right[nd])
        active = active[forest.left[flat[active]] >= 0]
    return node
