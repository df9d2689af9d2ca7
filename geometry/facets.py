"""Faces split into triangles where the bar-and-hinge model needs it; added edges are facets.

The models of :mod:`holofold.mechanics.hinges` fan every panel from the mean of its corners.
That is right for every panel the mean sees whole (every fan triangle centre-corner-next corner
turns the panel's way with a real area: convex panels of any number of sides, and most
non-convex ones), but a spoke of another panel would leave it or cross its side, so
:func:`split_faces` triangulates those panels (:func:`unfannable_faces`; ear clipping by
manifold3d, no new vertices) and marks every added edge ``J`` (a join: a facet that stays flat,
Origami Simulator's yellow triangulation line). A panel whose corner is a hair off straight
(1e-5 of its size) is fanned, not split into a sliver. ``mode="all"`` triangulates every face
with more than three vertices, as Origami Simulator does; ``"none"`` leaves them.
``mode="rulings"`` (given ``curve_edges``, the edges that are pieces of curved creases) meshes
every face with a curve piece on its boundary along its rulings
(:func:`~holofold.geometry.ruling_mesh.ruling_triangles`, no new vertices) and the others as
``"as-needed"``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from holofold.geometry.errors import ParameterError
from holofold.geometry.ruling_mesh import ruling_triangles

__all__ = ["SplitFaces", "split_faces", "nonconvex_faces", "unfannable_faces", "SPLIT_MODES"]


class SplitFaces(NamedTuple):
    """What :func:`split_faces` returns (a tuple, so it still unpacks): the new faces (a split
    face's triangles in its place), the edges (ne', 2) with the added ``J`` edges last, their
    assignment and fold angle (ne',), and ``n_split``, how many faces were split."""

    faces: list
    edges: np.ndarray
    assignment: np.ndarray
    fold_angle: np.ndarray
    n_split: int


#: which faces :func:`split_faces` triangulates
SPLIT_MODES = ("as-needed", "all", "none", "rulings")


def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _faces_where(xy, faces, test) -> np.ndarray:
    """Ids of the faces of more than three corners for whose corners ``xy[f]`` (k, 2)
    ``test`` is true."""
    xy = np.asarray(xy, float)
    return np.array([k for k, f in enumerate(faces) if len(f) > 3 and test(xy[f])], np.intp)


def nonconvex_faces(xy, faces, rel_tol: float = 1e-9) -> np.ndarray:
    """Ids of the counter-clockwise faces with a reflex corner (turning clockwise by more than
    ``rel_tol`` x the squared size of the face; straight corners count as convex)."""

    def reflex(p) -> bool:
        d_in = p - np.roll(p, 1, axis=0)
        d_out = np.roll(p, -1, axis=0) - p
        size2 = float(np.ptp(p, axis=0).max()) ** 2
        return bool((_cross(d_in, d_out) < -rel_tol * size2).any())

    return _faces_where(xy, faces, reflex)


def unfannable_faces(xy, faces, rel_area: float = 1e-3) -> np.ndarray:
    """Ids of the counter-clockwise faces that the fan from the mean of their corners does not
    cover: a fan triangle (mean, corner, next corner) with less than ``rel_area`` x the face's
    area divided by its corner count (turning the wrong way, or a sliver)."""

    def thin_fan(p) -> bool:
        c = p.mean(axis=0)
        tri = 0.5 * _cross(p - c, np.roll(p, -1, axis=0) - c)
        total = float(tri.sum())
        return total <= 0 or bool((tri < rel_area * total / len(p)).any())

    return _faces_where(xy, faces, thin_fan)


def split_faces(
    xy, faces, edges, assignment, fold_angle, mode: str = "as-needed", curve_edges=None
) -> SplitFaces:
    """Triangulate faces (see the module docstring).

    Parameters
    ----------
    xy : (nv, 2) float
        Flat layout (faces counter-clockwise in it).
    faces : sequence of (k,) int
    edges : (ne, 2) int
    assignment : (ne,) str
    fold_angle : (ne,) float
    mode : {"as-needed", "all", "none", "rulings"}
    curve_edges : (ne,) bool, optional
        The edges that are pieces of curves (``mode="rulings"``; none if not given).

    Returns
    -------
    SplitFaces
        faces, edges, assignment, fold_angle, n_split: the new faces (a split face's
        triangles in its place), the edges with the added ``J``
        edges last, and how many faces were split.
    """
    if mode not in SPLIT_MODES:
        raise ParameterError(f"mode = {mode!r}; allowed: {', '.join(SPLIT_MODES)}")
    xy = np.asarray(xy, float)
    faces = [np.asarray(f, np.int64) for f in faces]
    edges = np.asarray(edges, np.int64).reshape(-1, 2)
    asg = np.asarray(assignment)
    ang = np.asarray(fold_angle, float)
    if mode == "none":
        return SplitFaces(faces, edges, asg, ang, 0)
    if mode == "all":
        todo = {k for k, f in enumerate(faces) if len(f) > 3}
    else:
        todo = set(unfannable_faces(xy, faces).tolist())
    curved: dict = {}
    if mode == "rulings" and curve_edges is not None and np.any(curve_edges):
        keys = {tuple(e) for e in np.sort(edges, axis=1)[np.asarray(curve_edges, bool)].tolist()}
        for k, f in enumerate(faces):
            on = np.array(
                [(min(a, b), max(a, b)) in keys for a, b in zip(f, np.roll(f, -1), strict=True)]
            )
            if len(f) > 3 and on.any():
                curved[k] = on
        todo |= set(curved)
    if not todo:
        return SplitFaces(faces, edges, asg, ang, 0)
    import manifold3d

    out: list[np.ndarray] = []
    have = {tuple(x) for x in np.sort(edges, axis=1).tolist()}
    added: list[tuple[int, int]] = []
    for k, f in enumerate(faces):
        if k not in todo:
            out.append(f)
            continue
        if k in curved:
            ft = ruling_triangles(xy, f, curved[k])
        else:
            ft = f[np.asarray(manifold3d.triangulate([xy[f]]), np.int64)]
        for t in ft:
            out.append(t)
            for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
                key = (min(a, b), max(a, b))
                if key not in have:
                    have.add(key)
                    added.append(key)
    if added:
        edges = np.vstack([edges, np.array(added, np.int64)])
        asg = np.concatenate([asg, np.full(len(added), "J", dtype=asg.dtype)])
        ang = np.concatenate([ang, np.zeros(len(added))])
    return SplitFaces(out, edges, asg, ang, len(todo))
