"""Cuts (FOLD ``C`` edges): separate the faces on both sides of a cut.

In a drawing or a FOLD file a cut is one line between two faces; the faces must then not share
it. :func:`separate_cuts` gives every vertex on a cut one copy per group of faces around it
that hang together through edges that are not cuts (the faces around a vertex form a fan; each
cut splits the fan), so a cut from the border into the sheet opens along its length and stays
joined at its inner end, and a closed cut loop frees the piece inside. Each side of a cut then
has its own ``C`` edge on one face. A cut whose two sides still share both end vertices (a cut
inside the sheet that reaches no border and no other cut) cannot open without meshing the
panels around it: it stays one edge, reported in ``notes``, and the model treats it as a
passive crease.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["SeparatedCuts", "separate_cuts"]


class SeparatedCuts(NamedTuple):
    """What :func:`separate_cuts` returns (a tuple, so ``xy, faces, ... = separate_cuts(...)``
    still unpacks): the new vertices (nv', d), faces, edges (ne', 2), assignment and fold
    angle (ne',), ``origin`` (nv',) the original vertex of each, and notes (one line per
    problem)."""

    coords: np.ndarray
    faces: list
    edges: np.ndarray
    assignment: np.ndarray
    fold_angle: np.ndarray
    origin: np.ndarray
    notes: tuple


def _find(parent: np.ndarray, i: int) -> int:
    root = i
    while parent[root] != root:
        root = parent[root]
    while parent[i] != root:
        parent[i], i = root, parent[i]
    return root


def separate_cuts(coords, faces, edges, assignment, fold_angle) -> SeparatedCuts:
    """Faces on both sides of every ``C`` edge made to share no edge there.

    Parameters
    ----------
    coords : (nv, d) float
    faces : sequence of (k,) int
        Simple vertex loops.
    edges : (ne, 2) int
    assignment : (ne,) str
    fold_angle : (ne,) float

    Returns
    -------
    SeparatedCuts
        coords, faces, edges, assignment, fold_angle, origin, notes: the new arrays
        (vertices copied where the cuts split them; ``origin`` (nv',) the
        original vertex of each), edges in order of first use by the faces, and notes (one
        line per problem).
    """
    coords = np.asarray(coords, float)
    edges = np.asarray(edges, np.int64).reshape(-1, 2)
    asg = np.asarray(assignment)
    ang = np.asarray(fold_angle, float)
    faces = [np.asarray(f, np.int64) for f in faces]
    nv = len(coords)
    if not (asg == "C").any():
        return SeparatedCuts(coords, faces, edges, asg, ang, np.arange(nv), ())
    sizes = np.array([len(f) for f in faces])
    fv = np.concatenate(faces)
    start = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    nxt = np.arange(len(fv)) + 1
    nxt[start + sizes - 1] = start
    # the edge of every face side (corner q -> nxt[q])
    ekey = np.minimum(edges[:, 0], edges[:, 1]) * nv + np.maximum(edges[:, 0], edges[:, 1])
    eorder = np.argsort(ekey)
    skey = np.minimum(fv, fv[nxt]) * nv + np.maximum(fv, fv[nxt])
    pos = np.minimum(np.searchsorted(ekey, skey, sorter=eorder), len(ekey) - 1)
    side_edge = eorder[pos]
    if not np.array_equal(ekey[side_edge], skey):
        raise ValueError("a face side is not an edge")
    cut_side = asg[side_edge] == "C"
    # join corners across sides that are not cuts: side q (a -> b) of one face and side r
    # (b -> a) of the other: corner q ~ corner nxt[r] (at a), corner nxt[q] ~ corner r (at b)
    parent = np.arange(len(fv))
    o = np.argsort(skey, kind="stable")
    k = skey[o]
    pair = np.flatnonzero(k[1:] == k[:-1])
    for q, r in zip(o[pair].tolist(), o[pair + 1].tolist(), strict=True):
        if cut_side[q]:
            continue
        for x, y in ((q, nxt[r]), (nxt[q], r)):
            rx, ry = _find(parent, x), _find(parent, y)
            if rx != ry:
                parent[rx] = ry
    roots = np.array([_find(parent, q) for q in range(len(fv))])
    _, cls = np.unique(roots, return_inverse=True)
    origin = np.zeros(cls.max() + 1, np.int64)
    origin[cls] = fv
    new_faces = [cls[start[f] : start[f] + sizes[f]] for f in range(len(faces))]
    a, b = cls, cls[nxt]
    nk = np.minimum(a, b) * (cls.max() + 1) + np.maximum(a, b)
    _, first, inv, cnt = np.unique(nk, return_index=True, return_inverse=True, return_counts=True)
    rank = np.argsort(np.argsort(first))  # edges numbered in order of first use
    new_edges = np.zeros((len(first), 2), np.int64)
    new_edges[rank] = np.sort(np.stack([a[first], b[first]], 1), axis=1)
    new_asg = np.empty(len(first), dtype=asg.dtype)
    new_asg[rank] = asg[side_edge[first]]
    new_ang = np.zeros(len(first))
    new_ang[rank] = ang[side_edge[first]]
    notes = []
    shared = cut_side & (cnt[inv] > 1)  # a cut whose two sides are still one edge
    if shared.any():
        ids = np.unique(rank[inv[shared]])
        notes.append(
            f"{ids.size} cut edge(s) inside the sheet reach no border and no other cut, so "
            "they cannot open: kept joined (a passive crease)"
        )
        new_asg[ids] = "U"
    return SeparatedCuts(
        coords[origin], new_faces, new_edges, new_asg, new_ang, origin, tuple(notes)
    )
