"""Do the panels of a folded state pass through each other?

The mid-surface of a state is its pattern's faces fanned into triangles over the vertex
coordinates. Two triangles intersect when an edge of one crosses the other's interior
(strictly: touching within a tolerance of the sheet size does not count). Only edges that
share no vertex with the other triangle are tested, as IPC Toolkit does: triangles that share
a side never count, two that share a corner do when the side opposite it passes through the
other (two panels around a vertex folded through each other).

:func:`has_intersections` uses IPC Toolkit (``ipctk``, the ``contact`` extra) where it is
installed and the numpy test of :func:`intersecting_faces` otherwise, so a verdict never depends
on the optional install; :func:`intersecting_faces` also says which faces cross.

The numpy test: a broad phase of triangle bounding boxes (compared in blocks), then for every
candidate pair the six edge-against-triangle tests (signed volumes, as in Moller's
triangle-triangle test: an edge crosses a triangle when its ends lie strictly on either side
of the triangle's plane and the line through it passes strictly inside the three sides).
Coplanar overlaps (two layers lying exactly on each other) are touching, not crossing.
"""

from __future__ import annotations

import numpy as np

__all__ = ["has_intersections", "intersecting_faces", "triangulate"]

_BLOCK = 512
_REL_TOL = 1e-9


def triangulate(faces) -> tuple[np.ndarray, np.ndarray]:
    """Fan triangulation of polygon ``faces`` (lists of vertex ids): ``(T, owner)``, (m, 3)
    vertex ids and the face id of every triangle."""
    tris, owner = [], []
    for i, f in enumerate(faces):
        f = list(f)
        for k in range(1, len(f) - 1):
            tris.append((f[0], f[k], f[k + 1]))
            owner.append(i)
    return np.array(tris, np.intp).reshape(-1, 3), np.array(owner, np.intp)


def _candidates(X: np.ndarray, T: np.ndarray, pad: float) -> np.ndarray:
    """(p, 2) triangle pairs i < j whose bounding boxes overlap and that share no vertex."""
    P = X[T]  # (m, 3, 3)
    lo, hi = P.min(axis=1) - pad, P.max(axis=1) + pad
    m = len(T)
    out = []
    for s in range(0, m, _BLOCK):
        e = min(m, s + _BLOCK)
        ov = np.all((lo[s:e, None] <= hi[None]) & (lo[None] <= hi[s:e, None]), axis=-1)
        i, j = np.nonzero(ov)
        i = i + s
        keep = j > i
        i, j = i[keep], j[keep]
        shared = (T[i][:, :, None] == T[j][:, None, :]).sum(axis=(1, 2))
        keep = shared < 2  # triangles sharing a side never cross
        out.append(np.column_stack([i[keep], j[keep]]))
    return np.concatenate(out) if out else np.zeros((0, 2), np.intp)


def _det(a, b, c):
    return np.einsum("...i,...i->...", a, np.cross(b, c))


def _edges_cross(A, B, TA, TB, eps: float) -> np.ndarray:
    """(p,) bool: an edge of triangle A (p, 3, 3) that shares no vertex with triangle B
    (vertex ids TA, TB, (p, 3)) crosses B."""
    a, b, c = B[:, 0], B[:, 1], B[:, 2]
    hit = np.zeros(len(A), bool)
    for k in range(3):
        p, q = A[:, k], A[:, (k + 1) % 3]
        free = ~((TA[:, k, None] == TB).any(axis=1) | (TA[:, (k + 1) % 3, None] == TB).any(axis=1))
        dp = _det(b - a, c - a, p - a)
        dq = _det(b - a, c - a, q - a)
        across = ((dp > eps) & (dq < -eps)) | ((dp < -eps) & (dq > eps))
        s1 = _det(q - p, a - p, b - p)
        s2 = _det(q - p, b - p, c - p)
        s3 = _det(q - p, c - p, a - p)
        inside = ((s1 > eps) & (s2 > eps) & (s3 > eps)) | ((s1 < -eps) & (s2 < -eps) & (s3 < -eps))
        hit |= free & across & inside
    return hit


def intersecting_faces(coords, faces) -> np.ndarray:
    """(p, 2) face pairs (i < j, sorted) whose triangles cross each other in the state
    ``coords`` ((nv, 3) vertex positions, any length unit); empty when the state is clean."""
    X = np.asarray(coords, float)
    T, owner = triangulate(faces)
    if len(T) < 2:
        return np.zeros((0, 2), np.intp)
    size = float(np.ptp(X, axis=0).max()) or 1.0
    eps = _REL_TOL * size**3  # signed volumes scale with length^3
    pairs = _candidates(X, T, _REL_TOL * size)
    if not len(pairs):
        return np.zeros((0, 2), np.intp)
    TA, TB = T[pairs[:, 0]], T[pairs[:, 1]]
    A, B = X[TA], X[TB]
    hit = _edges_cross(A, B, TA, TB, eps) | _edges_cross(B, A, TB, TA, eps)
    fp = np.sort(owner[pairs[hit]], axis=1)
    fp = fp[fp[:, 0] != fp[:, 1]]
    return np.unique(fp, axis=0) if len(fp) else np.zeros((0, 2), np.intp)


def has_intersections(coords, faces, *, backend: str = "auto") -> bool:
    """True when panels of the state ``coords`` pass through each other.

    ``backend``: ``"ipctk"`` (IPC Toolkit's ``has_intersections`` on the triangulated
    mid-surface), ``"numpy"`` (:func:`intersecting_faces`) or ``"auto"`` (ipctk where installed).
    """
    if backend not in ("auto", "ipctk", "numpy"):
        from holofold.geometry.errors import ParameterError

        raise ParameterError(f"backend = {backend!r}; allowed: auto, ipctk, numpy")
    if backend != "numpy":
        try:
            import ipctk
        except ImportError:
            if backend == "ipctk":
                from holofold.geometry.errors import ParameterError

                raise ParameterError(
                    "the ipctk backend needs IPC Toolkit: pip install 'holofold[contact]'"
                ) from None
        else:
            X = np.ascontiguousarray(coords, float)
            T, _ = triangulate(faces)
            if len(T) < 2:
                return False
            E = ipctk.edges(T)
            mesh = ipctk.CollisionMesh(X, E, T)
            return bool(ipctk.has_intersections(mesh, X))
    return bool(len(intersecting_faces(coords, faces)))
