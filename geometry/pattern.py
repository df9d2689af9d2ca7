"""Crease patterns: vertices, creases with FOLD assignments and fold angles, faces.

A :class:`CreasePattern` is the plain data every other layer consumes::

    coords      (nv, 3) float   3-D vertex coordinates, metres (the folded state; z = 0 if flat)
    faces       tuple of (k,) int arrays, one vertex loop per panel (k >= 3)
    edges       (ne, 2) int     vertex pairs, stored (min, max)
    assignment  (ne,) str       FOLD codes: M V B F C J U
    fold_angle  (ne,) float     FOLD convention: degrees in [-180, 180], valley > 0, mountain < 0
    flat        (nv, 2) float or None   the flat crease-pattern layout, metres, where one exists
    curves      tuple of Curve  curved creases as drawn (metres, the flat layout's frame), or ()
    edge_curve  (ne,) int or None   the curve each edge is a straight piece of, -1 for a straight
                                edge; None when there are no curves

Curves are kept only while they match the edges and the flat layout: a copy whose edges change
(``dataclasses.replace`` with new edges) or whose flat layout no longer meets the curves (a
scaled copy) drops them with one warning line.

Edge order matters: the reference simulator (SWOMPS) numbers creases by walking the panels in
order and, within a panel with vertices C1..CN, the edges (C1, CN), (C1, C2), ..., (C_{N-1}, C_N)
(docs/bar-and-hinge.md §1.1). :func:`reference_edges` computes exactly that order and
:meth:`CreasePattern.from_faces` uses it, so crease ``i`` of a generated pattern is the
reference's crease ``i + 1`` (0-based here, 1-based there).

Faces are kept in the vertex order they were given (the mechanics layer depends on it). Where a
flat layout exists every face must be counter-clockwise in it (positive signed area), as FOLD
requires. A 3-D-only pattern (for instance a fitted arch strip) need not be consistently
oriented; :func:`orient_faces` gives a consistently oriented copy where one is needed.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from holofold.geometry.errors import DegenerateGeometryError, InvalidPatternError

if TYPE_CHECKING:  # networkx (0.2 s CPU to import) loads in to_networkx only
    import networkx as nx

__all__ = [
    "ASSIGNMENTS",
    "MAX_PANELS",
    "CreasePattern",
    "non_simple_faces",
    "reference_edges",
    "orient_faces",
    "measure_fold_angles",
    "newell_normals",
]

#: FOLD 1.2 edge assignments: mountain, valley, border, flat, cut, join, unassigned.
ASSIGNMENTS = ("M", "V", "B", "F", "C", "J", "U")

#: the largest pattern (panels) the command line and the file readers take: ``holofold
#: pattern`` generates a 100 x 100 sheet in 2 s and reads its FOLD file back in 1.4 s, and the
#: sheet scenarios refuse more panels per design (docs/limits.md). The Python generators
#: themselves take any size.
MAX_PANELS = 10_000

_REL_TOL = 1e-12  # relative tolerance for zero lengths and areas
#: (flat, curves, edge_curve) object ids already found to meet -> the flat array (weakly held)
_CURVES_MET: weakref.WeakValueDictionary = weakref.WeakValueDictionary()


def _as_faces(faces) -> tuple[np.ndarray, ...]:
    if isinstance(faces, tuple) and all(
        isinstance(f, np.ndarray) and f.dtype == np.int64 and f.ndim == 1 and f.size >= 3
        for f in faces
    ):
        return faces  # already normalised
    out = []
    for k, f in enumerate(faces):
        a = np.asarray(f)
        if a.ndim != 1 or a.size < 3:
            raise InvalidPatternError(f"face {k} must list at least 3 vertex ids, got {f!r}")
        if a.dtype.kind not in "iu":
            if a.dtype.kind != "f" or not np.all(np.equal(np.mod(a, 1), 0)):
                raise InvalidPatternError(f"face {k} has non-integer vertex ids {f!r}")
        out.append(a.astype(np.int64, copy=False))
    return tuple(out)


class _FaceTable:
    """All faces' vertex loops flattened: the topology helpers work on these arrays.

    ``fv`` (N,) vertex ids of all corners, face by face; ``owner`` (N,) face of each corner;
    ``nxt`` (N,) position of the next corner in the same loop; ``starts``/``sizes`` (nf,).
    """

    __slots__ = ("fv", "owner", "nxt", "starts", "sizes")

    def __init__(self, faces: tuple[np.ndarray, ...]):
        self.sizes = np.array([len(f) for f in faces], np.int64)
        self.fv = np.concatenate(faces) if faces else np.zeros(0, np.int64)
        self.starts = np.concatenate([[0], np.cumsum(self.sizes)[:-1]]).astype(np.int64)
        self.owner = np.repeat(np.arange(len(faces)), self.sizes)
        nxt = np.arange(len(self.fv)) + 1
        if len(faces):
            nxt[self.starts + self.sizes - 1] = self.starts
        self.nxt = nxt

    def pairs(self) -> np.ndarray:
        """(N, 2) directed corner-to-next-corner edges, in loop order."""
        return np.stack([self.fv, self.fv[self.nxt]], axis=1)


def _edge_keys(pairs: np.ndarray, nv: int) -> np.ndarray:
    lo, hi = np.minimum(pairs[:, 0], pairs[:, 1]), np.maximum(pairs[:, 0], pairs[:, 1])
    return lo * np.int64(nv) + hi


def reference_edges(faces) -> tuple[np.ndarray, np.ndarray]:
    """Edges in the reference simulator's enumeration order.

    Parameters
    ----------
    faces : sequence of (k,) int
        Panels as vertex loops, 0-based.

    Returns
    -------
    edges : (ne, 2) int
        Each edge stored (min id, max id) in order of first appearance, visiting each face's
        edges as (C1, CN), (C1, C2), (C2, C3), ..., (C_{N-1}, C_N).
    n_faces : (ne,) int
        Number of faces sharing each edge (1 = border, 2 = interior crease).
    """
    faces = _as_faces(faces)
    if not faces:
        return np.zeros((0, 2), np.int64), np.zeros(0, np.int64)
    t = _FaceTable(faces)
    # reference order inside a face: the closing edge (CN, C1) first, then (C1, C2), ...
    perm = np.arange(len(t.fv)) - 1
    perm[t.starts] = t.starts + t.sizes - 1
    p = np.sort(t.pairs()[perm], axis=1)
    nv = int(t.fv.max()) + 1
    _, first, counts = np.unique(p[:, 0] * nv + p[:, 1], return_index=True, return_counts=True)
    order = np.argsort(first, kind="stable")
    return p[first[order]], counts[order]


def newell_normals(coords: np.ndarray, faces) -> np.ndarray:
    """Area-weighted face normals (Newell's method), (nf, 3); length = polygon area."""
    faces = _as_faces(faces)
    t = _FaceTable(faces)
    coords = np.asarray(coords, float)
    cr = np.cross(coords[t.fv], coords[t.fv[t.nxt]])
    n = np.zeros((len(faces), 3))
    for d in range(3):
        n[:, d] = np.bincount(t.owner, weights=cr[:, d], minlength=len(faces))
    return 0.5 * n


def _edge_occurrences(pairs: np.ndarray, owner: np.ndarray, nv: int):
    """For each undirected face edge: first and second occurrence positions (-1 if none).

    Returns ``keys`` (ne_u,) sorted unique keys, ``first`` and ``second`` (ne_u,) positions into
    ``pairs``.
    """
    keys = _edge_keys(pairs, nv)
    order = np.argsort(keys, kind="stable")
    k = keys[order]
    head = np.concatenate([[True], k[1:] != k[:-1]])
    starts = np.flatnonzero(head)
    counts = np.diff(np.concatenate([starts, [len(k)]]))
    first = order[starts]
    second = np.where(counts >= 2, order[np.minimum(starts + 1, len(k) - 1)], -1)
    return k[starts], first, second, counts


def orient_faces(faces, n_vertices: int | None = None) -> tuple[np.ndarray, ...]:
    """A consistently oriented copy of ``faces``.

    The first face of each connected component keeps its orientation; every neighbour is
    reversed where needed so that two faces sharing an edge traverse it in opposite directions.
    Raises :class:`InvalidPatternError` for a non-orientable surface (a Moebius strip).
    """
    faces = _as_faces(faces)
    if not faces:
        return faces
    t = _FaceTable(faces)
    pairs = t.pairs()
    nv = int(t.fv.max()) + 1
    _, first, second, _ = _edge_occurrences(pairs, t.owner, nv)
    two = second >= 0
    i, j = first[two], second[two]
    same = pairs[i, 0] == pairs[j, 0]  # traversed in the same direction
    if not same.any():
        return faces  # already consistent
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import breadth_first_order, connected_components

    nf = len(faces)
    fu, fw = t.owner[i], t.owner[j]
    _, once = np.unique(np.minimum(fu, fw) * nf + np.maximum(fu, fw), return_index=True)
    fu, fw, w = fu[once], fw[once], 1 + same[once]  # weight 1 + same (scipy drops zeros)
    g = csr_matrix((np.concatenate([w, w]), (np.concatenate([fu, fw]), np.concatenate([fw, fu]))),
                   shape=(nf, nf))  # fmt: skip
    n_comp, label = connected_components(g, directed=False)
    flip = np.zeros(nf, bool)
    roots = np.full(n_comp, nf)
    np.minimum.at(roots, label, np.arange(nf))
    for root in roots:  # the first face of each component keeps its orientation
        order, pred = breadth_first_order(g, int(root), directed=False)
        step = np.asarray(g[pred[order[1:]], order[1:]]).ravel() == 2
        for v, u, sm in zip(order[1:].tolist(), pred[order[1:]].tolist(), step.tolist(),
                            strict=True):  # fmt: skip
            flip[v] = flip[u] ^ sm
    bad = (flip[t.owner[i]] ^ flip[t.owner[j]]) != same
    if bad.any():
        u, v = int(t.owner[i][bad][0]), int(t.owner[j][bad][0])
        raise InvalidPatternError(
            f"faces {u} and {v} cannot be oriented consistently (non-orientable surface)"
        )
    return tuple(f[::-1].copy() if fl else f for f, fl in zip(faces, flip, strict=True))


def measure_fold_angles(coords: np.ndarray, faces, edges: np.ndarray) -> np.ndarray:
    """FOLD fold angles (degrees; valley > 0, mountain < 0) of ``edges`` in a 3-D state.

    The angle of an interior edge is the signed angle between the normals of its two faces,
    with faces oriented consistently (:func:`orient_faces`) and "up" the side their normals
    point to; for a flat pattern with counter-clockwise faces that is +z. Border edges get 0.

    Returns
    -------
    (ne,) float
    """
    coords = np.asarray(coords, float)
    edges = np.asarray(edges, np.int64).reshape(-1, 2)
    ne = len(edges)
    angle = np.zeros(ne)
    faces = orient_faces(faces)
    if not faces or not ne:
        return angle
    normals = newell_normals(coords, faces)
    norms = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = normals / np.where(norms > 0, norms, 1.0)
    t = _FaceTable(faces)
    pairs = t.pairs()
    nv = max(int(t.fv.max()), int(edges.max())) + 1
    ukeys, first, second, _ = _edge_occurrences(pairs, t.owner, nv)
    ekeys = _edge_keys(edges, nv)
    pos = np.searchsorted(ukeys, ekeys)
    pos = np.minimum(pos, len(ukeys) - 1)
    found = ukeys[pos] == ekeys
    ia = np.where(found, first[pos], -1)
    ib = np.where(found, second[pos], -1)
    inner = (ia >= 0) & (ib >= 0)
    if inner.any():
        fa, fb = t.owner[ia[inner]], t.owner[ib[inner]]
        na, nb = normals[fa], normals[fb]
        start, end = pairs[ia[inner], 0], pairs[ia[inner], 1]
        tv = coords[end] - coords[start]
        tv /= np.linalg.norm(tv, axis=1, keepdims=True)
        s = -np.einsum("ij,ij->i", np.cross(na, nb), tv)
        c = np.einsum("ij,ij->i", na, nb)
        angle[inner] = np.degrees(np.arctan2(s, c))
    return angle


def _segments_cross(p: np.ndarray, q: np.ndarray, r: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Whether 2-D segments p-q and r-s intersect (touching included), vectorised; collinear
    segments only where they overlap."""

    def orient(a, b, c):
        return (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (b[..., 1] - a[..., 1]) * (
            c[..., 0] - a[..., 0]
        )

    d1, d2 = orient(r, s, p), orient(r, s, q)
    d3, d4 = orient(p, q, r), orient(p, q, s)
    # the bounding boxes must overlap too: collinear segments (all four orientations zero, or
    # rounding noise around zero) cross only where they overlap along their line
    boxes = np.ones(d1.shape, bool)
    for c in (0, 1):
        lo1, hi1 = np.minimum(p[..., c], q[..., c]), np.maximum(p[..., c], q[..., c])
        lo2, hi2 = np.minimum(r[..., c], s[..., c]), np.maximum(r[..., c], s[..., c])
        boxes &= (lo1 <= hi2) & (lo2 <= hi1)
    return (d1 * d2 <= 0) & (d3 * d4 <= 0) & boxes


def _check_simple(t: _FaceTable, pts2d: np.ndarray) -> np.ndarray:
    """Ids of faces that are not simple polygons; ``pts2d`` (N, 2) holds each corner's 2-D point."""
    bad = []
    for k in np.unique(t.sizes):
        if k <= 3:
            continue
        idx = np.flatnonzero(t.sizes == k)
        pos = t.starts[idx][:, None] + np.arange(k)
        P = pts2d[pos]  # (nf_k, k, 2)
        Q = np.roll(P, -1, axis=1)
        i, j = np.triu_indices(k, 2)
        keep = ~((i == 0) & (j == k - 1))  # adjacent through the wrap-around
        i, j = i[keep], j[keep]
        hit = _segments_cross(P[:, i], Q[:, i], P[:, j], Q[:, j]).any(axis=1)
        bad.append(idx[hit])
    return np.sort(np.concatenate(bad)) if bad else np.zeros(0, np.int64)


def non_simple_faces(coords, faces) -> np.ndarray:
    """Ids of the faces that are not simple polygons (two of their sides cross) in their own
    best-fit plane: the check :meth:`CreasePattern.from_faces` makes, alone and vectorised.

    ``coords`` (n, 3) m; ``faces`` a sequence of vertex-id arrays (or an (nf, k) array).
    """
    t = _FaceTable(_as_faces(faces))
    return _check_simple(t, _corner_points_2d(np.asarray(coords, float), t))


def _corner_points_2d(coords: np.ndarray, t: _FaceTable) -> np.ndarray:
    """(N, 2) corners of every face projected onto the face's own (Newell) plane."""
    nf = len(t.sizes)
    p = coords[t.fv]
    cr = np.cross(p, coords[t.fv[t.nxt]])
    n = np.stack([np.bincount(t.owner, weights=cr[:, d], minlength=nf) for d in range(3)], 1)
    cen = np.stack([np.bincount(t.owner, weights=p[:, d], minlength=nf) for d in range(3)], 1)
    cen /= t.sizes[:, None]
    d = p - cen[t.owner]
    norm = np.linalg.norm(n, axis=1)
    ok = norm > 1e-300
    nn = np.where(ok[:, None], n / np.where(ok, norm, 1.0)[:, None], 0.0)
    for f in np.flatnonzero(~ok):  # bow-tie loops: best-fit plane of the points
        rows = t.owner == f
        nn[f] = np.linalg.svd(d[rows], full_matrices=False)[2][2]
    helper = np.eye(3)[np.argmin(np.abs(nn), axis=1)]
    u = np.cross(nn, helper)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    w = np.cross(nn, u)
    return np.stack([np.einsum("ij,ij->i", d, u[t.owner]), np.einsum("ij,ij->i", d, w[t.owner])], 1)


@dataclass(frozen=True, eq=False)
class CreasePattern:
    """A crease pattern with its 3-D state. See the module docstring for the arrays."""

    coords: np.ndarray
    faces: tuple[np.ndarray, ...]
    edges: np.ndarray
    assignment: np.ndarray
    fold_angle: np.ndarray
    flat: np.ndarray | None = None
    meta: dict[str, Any] = field(default_factory=dict)
    curves: tuple = ()
    edge_curve: np.ndarray | None = None

    # ------------------------------------------------------------------ construction
    def __post_init__(self):
        coords = np.asarray(self.coords, dtype=float)
        if coords.ndim != 2 or coords.shape[1] not in (2, 3):
            raise InvalidPatternError(
                f"coords must have shape (nv, 2) or (nv, 3), got {coords.shape}"
            )
        if coords.shape[1] == 2:
            coords = np.column_stack([coords, np.zeros(len(coords))])
        bad = np.flatnonzero(~np.isfinite(coords).all(axis=1))
        if bad.size:
            raise DegenerateGeometryError(f"non-finite coordinates at vertices {bad[:10].tolist()}")
        nv = len(coords)
        flat = None
        if self.flat is not None:
            flat = np.asarray(self.flat, dtype=float)
            if flat.shape != (nv, 2):
                raise InvalidPatternError(f"flat must have shape ({nv}, 2), got {flat.shape}")
            bad = np.flatnonzero(~np.isfinite(flat).all(axis=1))
            if bad.size:
                raise DegenerateGeometryError(
                    f"non-finite flat coordinates at vertices {bad[:10].tolist()}"
                )
        faces = _as_faces(self.faces)
        edges = np.asarray(self.edges)
        if edges.size == 0:
            edges = edges.reshape(0, 2)
        if edges.ndim != 2 or edges.shape[1] != 2:
            raise InvalidPatternError(f"edges must have shape (ne, 2), got {edges.shape}")
        edges = np.sort(edges.astype(np.int64), axis=1)
        ne = len(edges)
        raw = np.asarray(self.assignment, dtype=str).reshape(-1)
        assignment = raw.astype("<U1")
        long = np.flatnonzero(raw != assignment)  # "<U1" alone would truncate "Vx" to "V"
        if long.size:
            k = int(long[0])
            raise InvalidPatternError(
                f"edge {k} has assignment {raw[k]!r}; allowed: {' '.join(ASSIGNMENTS)}"
            )
        fold_angle = np.asarray(self.fold_angle, dtype=float).reshape(-1)
        for name, arr in (("assignment", assignment), ("fold_angle", fold_angle)):
            if arr.shape != (ne,):
                raise InvalidPatternError(
                    f"{name} must have length {ne} (one per edge), got {arr.shape[0]}"
                )
        object.__setattr__(self, "coords", coords)
        object.__setattr__(self, "flat", flat)
        object.__setattr__(self, "faces", faces)
        object.__setattr__(self, "edges", edges)
        object.__setattr__(self, "assignment", assignment)
        object.__setattr__(self, "fold_angle", fold_angle)
        object.__setattr__(self, "meta", dict(self.meta))
        self._validate()
        self._check_curves()

    def _check_curves(self) -> None:
        """Normalise ``curves``/``edge_curve``; drop them (one warning) where they no longer
        match the edges or the flat layout."""
        curves = tuple(self.curves)
        if not curves:
            object.__setattr__(self, "curves", ())
            object.__setattr__(self, "edge_curve", None)
            return
        ec = None if self.edge_curve is None else np.asarray(self.edge_curve)
        ne = len(self.edges)
        why = ""
        if ec is None or ec.shape != (ne,) or ec.dtype.kind not in "iu":
            why = "the edges changed"
        elif ne and (ec.min() < -1 or ec.max() >= len(curves)):
            raise InvalidPatternError(
                f"edge_curve has values outside -1..{len(curves) - 1} (one curve per edge)"
            )
        elif self.flat is not None and not self._curves_meet_flat(curves, ec):
            why = "the flat layout no longer meets them (moved or scaled)"
        if why:
            import warnings

            warnings.warn(f"{len(curves)} curve(s) dropped: {why}", UserWarning, stacklevel=4)
            object.__setattr__(self, "curves", ())
            object.__setattr__(self, "edge_curve", None)
            return
        ec = ec.astype(np.int64)
        ec.flags.writeable = False
        object.__setattr__(self, "curves", curves)
        object.__setattr__(self, "edge_curve", ec)

    def _curves_meet_flat(self, curves, ec) -> bool:
        """The two ends of every curve's first piece lie within 1 % of the sheet of the curve
        (merging and contracting short pieces move vertices by about 0.2 %; a scaled or moved
        layout misses). Checked once per (flat layout, curves) pair of objects."""
        key = (id(self.flat), id(curves), id(self.edge_curve))
        if _CURVES_MET.get(key) is self.flat:
            return True
        size = float(np.ptp(self.flat, axis=0).max()) if len(self.flat) else 0.0
        first = np.full(len(curves), -1, np.int64)
        k = np.flatnonzero(ec >= 0)
        first[ec[k[::-1]]] = k[::-1]  # the first piece of each curve
        has = np.flatnonzero(first >= 0)
        if has.size:
            t = np.linspace(0.0, 1.0, 65)
            poly = np.stack([curves[c].point(t) for c in has])  # (m, 65, 2)
            a, d = poly[:, :-1], np.diff(poly, axis=1)
            dd = np.maximum(np.einsum("msj,msj->ms", d, d), 1e-300)
            for end in (0, 1):
                q = self.flat[self.edges[first[has], end]]
                w = q[:, None, :] - a
                u = np.clip(np.einsum("msj,msj->ms", w, d) / dd, 0.0, 1.0)
                gap = np.linalg.norm(w - u[..., None] * d, axis=2).min(axis=1)
                if (gap > 1e-2 * size).any():
                    return False
        _CURVES_MET[key] = self.flat
        return True

    def _validate(self) -> None:
        nv, ne = len(self.coords), len(self.edges)
        e = self.edges
        # indices
        if ne and (e.min() < 0 or e.max() >= nv):
            k = int(np.flatnonzero((e < 0).any(1) | (e >= nv).any(1))[0])
            raise InvalidPatternError(
                f"edge {k} = {e[k].tolist()} references a vertex outside 0..{nv - 1}"
            )
        t = _FaceTable(self.faces)
        if self.faces:
            out = np.flatnonzero((t.fv < 0) | (t.fv >= nv))
            if out.size:
                k = int(t.owner[out[0]])
                raise InvalidPatternError(
                    f"face {k} = {self.faces[k].tolist()} references a vertex outside 0..{nv - 1}"
                )
            key = t.owner * np.int64(nv) + t.fv
            ks = np.sort(key)
            rep = np.flatnonzero(ks[1:] == ks[:-1])
            if rep.size:
                k = int(ks[rep[0]] // nv)
                raise InvalidPatternError(
                    f"face {k} = {self.faces[k].tolist()} repeats a vertex (not a simple polygon)"
                )
        # edges: circular, duplicate, zero length
        circ = np.flatnonzero(e[:, 0] == e[:, 1])
        if circ.size:
            raise InvalidPatternError(
                f"edge {int(circ[0])} joins vertex {int(e[circ[0], 0])} to itself"
            )
        if ne:
            _, first, counts = np.unique(e, axis=0, return_index=True, return_counts=True)
            if (counts > 1).any():
                dup = e[first[counts > 1][0]]
                raise InvalidPatternError(f"duplicate edge {dup.tolist()}")
            scale = max(float(np.ptp(self.coords, axis=0).max()), 1e-300)
            length = np.linalg.norm(self.coords[e[:, 1]] - self.coords[e[:, 0]], axis=1)
            if self.flat is not None:
                length = np.maximum(
                    length, np.linalg.norm(self.flat[e[:, 1]] - self.flat[e[:, 0]], axis=1)
                )
            zero = np.flatnonzero(length <= _REL_TOL * scale)
            if zero.size:
                k = int(zero[0])
                raise DegenerateGeometryError(f"edge {k} = {e[k].tolist()} has zero length")
        # every face boundary edge must be an edge
        if self.faces:
            fkeys = _edge_keys(t.pairs(), nv)
            ekeys = np.sort(_edge_keys(e, nv))
            pos = np.minimum(np.searchsorted(ekeys, fkeys), max(len(ekeys) - 1, 0))
            missing = np.flatnonzero(
                (ekeys[pos] != fkeys) if len(ekeys) else np.ones_like(fkeys, bool)
            )
            if missing.size:
                i = missing[0]
                u, v = sorted((int(t.fv[i]), int(t.fv[t.nxt[i]])))
                raise InvalidPatternError(
                    f"face {int(t.owner[i])} uses edge {[u, v]}, which is not in edges"
                )
        # assignments and fold angles
        unknown = np.flatnonzero(~np.isin(self.assignment, ASSIGNMENTS))
        if unknown.size:
            k = int(unknown[0])
            raise InvalidPatternError(
                f"edge {k} has assignment {self.assignment[k]!r}; allowed: {' '.join(ASSIGNMENTS)}"
            )
        a = self.fold_angle
        bad = np.flatnonzero(~np.isfinite(a) | (np.abs(a) > 180.0))
        if bad.size:
            k = int(bad[0])
            raise InvalidPatternError(
                f"edge {k} has fold angle {a[k]!r}; allowed: [-180, 180] degrees"
            )
        checks = (
            ("M", a > 0, "a mountain needs a fold angle <= 0"),
            ("V", a < 0, "a valley needs a fold angle >= 0"),
            ("B", a != 0, "a border edge needs fold angle 0"),
            ("F", a != 0, "a flat crease needs fold angle 0"),
            ("C", a != 0, "a cut needs fold angle 0"),
        )
        for code, wrong, why in checks:
            hit = np.flatnonzero((self.assignment == code) & wrong)
            if hit.size:
                k = int(hit[0])
                raise InvalidPatternError(
                    f"edge {k} is {code} with fold angle {a[k]:.6g} deg: {why}"
                )
        # faces: simple polygons, non-zero area, counter-clockwise in the flat layout
        if self.faces:
            if self.flat is not None:
                pts = self.flat[t.fv]
            else:
                pts = _corner_points_2d(self.coords, t)
            bad = _check_simple(t, pts)
            if bad.size:
                k = int(bad[0])
                raise InvalidPatternError(
                    f"face {k} = {self.faces[k].tolist()} is not a simple polygon (its sides cross)"
                )
            nxt = pts[t.nxt]
            area = 0.5 * np.bincount(
                t.owner,
                weights=pts[:, 0] * nxt[:, 1] - nxt[:, 0] * pts[:, 1],
                minlength=len(t.sizes),
            )
            ref = self.flat if self.flat is not None else self.coords
            scale2 = max(float(np.ptp(ref, axis=0).max()), 1e-300) ** 2
            zero = np.flatnonzero(np.abs(area) <= _REL_TOL * scale2)
            if zero.size:
                raise DegenerateGeometryError(f"face {int(zero[0])} has zero area")
            if self.flat is not None and (area < 0).any():
                k = int(np.flatnonzero(area < 0)[0])
                raise InvalidPatternError(
                    f"face {k} = {self.faces[k].tolist()} is clockwise in the flat layout; "
                    "faces must be counter-clockwise (reverse its vertex order)"
                )

    @classmethod
    def from_faces(
        cls,
        coords,
        faces,
        *,
        flat=None,
        assignment=None,
        fold_angle=None,
        meta: dict | None = None,
        flat_tol_deg: float = 1e-9,
    ) -> CreasePattern:
        """Build a pattern whose edges are derived from ``faces`` in reference order.

        Border edges (one face) get ``B``. Unless given, interior fold angles are measured from
        ``coords`` (:func:`measure_fold_angles`) and the assignment follows their sign
        (``V`` > 0, ``M`` < 0, ``F`` within ``flat_tol_deg`` of 0).
        """
        coords = np.asarray(coords, float)
        if coords.ndim == 2 and coords.shape[1] == 2:
            coords = np.column_stack([coords, np.zeros(len(coords))])
        faces = _as_faces(faces)
        edges, n_faces = reference_edges(faces)
        if fold_angle is None:
            if len(edges) and edges.max() < len(coords) and np.isfinite(coords).all():
                fold_angle = measure_fold_angles(coords, faces, edges)
            else:
                fold_angle = np.zeros(len(edges))
            fold_angle = np.where(np.abs(fold_angle) <= flat_tol_deg, 0.0, fold_angle)
            fold_angle = np.where(n_faces == 1, 0.0, fold_angle)
        fold_angle = np.asarray(fold_angle, float)
        if assignment is None:
            assignment = np.where(
                n_faces == 1,
                "B",
                np.where(fold_angle > 0, "V", np.where(fold_angle < 0, "M", "F")),
            )
        return cls(coords, faces, edges, assignment, fold_angle, flat=flat, meta=meta or {})

    # ------------------------------------------------------------------ derived data
    @property
    def n_vertices(self) -> int:
        return len(self.coords)

    @property
    def n_edges(self) -> int:
        return len(self.edges)

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    @property
    def edge_face_count(self) -> np.ndarray:
        """(ne,) int: number of faces using each edge (1 border, 2 interior)."""
        if not self.faces or not self.n_edges:
            return np.zeros(self.n_edges, np.int64)
        t = _FaceTable(self.faces)
        nv = self.n_vertices
        ekeys = _edge_keys(self.edges, nv)
        order = np.argsort(ekeys)
        pos = np.searchsorted(ekeys[order], _edge_keys(t.pairs(), nv))
        return np.bincount(order[np.minimum(pos, len(order) - 1)], minlength=self.n_edges)

    @property
    def interior(self) -> np.ndarray:
        """(ne,) bool: edges shared by two faces (the creases that can fold)."""
        return self.edge_face_count == 2

    @property
    def edge_lengths(self) -> np.ndarray:
        """(ne,) float: 3-D edge lengths, metres."""
        return np.linalg.norm(self.coords[self.edges[:, 1]] - self.coords[self.edges[:, 0]], axis=1)

    @property
    def flat_edge_lengths(self) -> np.ndarray:
        """(ne,) float: edge lengths in the flat layout (raises if there is none)."""
        if self.flat is None:
            raise InvalidPatternError("this pattern has no flat layout")
        return np.linalg.norm(self.flat[self.edges[:, 1]] - self.flat[self.edges[:, 0]], axis=1)

    def measured_fold_angles(self) -> np.ndarray:
        """(ne,) float: fold angles measured from ``coords`` (degrees, FOLD convention)."""
        a = measure_fold_angles(self.coords, self.faces, self.edges)
        return np.where(self.interior, a, 0.0)

    def sector_angles(self) -> list[np.ndarray]:
        """Corner angles of every face in the flat layout (or 3-D if none), radians."""
        pts = self.flat if self.flat is not None else self.coords
        out = []
        for f in self.faces:
            p = pts[f]
            a = np.roll(p, 1, axis=0) - p
            b = np.roll(p, -1, axis=0) - p
            if p.shape[1] == 2:
                cr = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
                crn = np.abs(cr)
            else:
                crn = np.linalg.norm(np.cross(a, b), axis=1)
            out.append(np.arctan2(crn, np.einsum("ij,ij->i", a, b)))
        return out

    def with_coords(self, coords, *, measure: bool = True) -> CreasePattern:
        """A copy in another 3-D state; fold angles re-measured unless ``measure=False``."""
        new = replace(self, coords=np.asarray(coords, float))
        if measure:
            a = new.measured_fold_angles()
            keep = np.isin(self.assignment, ("M", "V", "F", "U"))
            a = np.where(keep, a, 0.0)
            asg = self.assignment.copy()
            mv = np.isin(asg, ("M", "V", "F"))
            asg[mv] = np.where(a[mv] > 0, "V", np.where(a[mv] < 0, "M", asg[mv]))
            new = replace(new, fold_angle=a, assignment=asg)
        return new

    # ------------------------------------------------------------------ networkx view
    def to_networkx(self) -> nx.Graph:
        """The pattern as an undirected graph.

        Nodes are vertex ids with ``coords`` (and ``flat``) attributes; edges carry
        ``index`` (position in :attr:`edges`), ``assignment`` and ``fold_angle``. The graph
        attributes hold ``faces`` (lists) and ``meta``.
        """
        import networkx as nx

        g = nx.Graph(faces=[f.tolist() for f in self.faces], meta=dict(self.meta))
        for v in range(self.n_vertices):
            attrs = {"coords": self.coords[v].tolist()}
            if self.flat is not None:
                attrs["flat"] = self.flat[v].tolist()
            g.add_node(v, **attrs)
        for i, (a, b) in enumerate(self.edges):
            g.add_edge(
                int(a),
                int(b),
                index=i,
                assignment=str(self.assignment[i]),
                fold_angle=float(self.fold_angle[i]),
            )
        return g

    @classmethod
    def from_networkx(cls, g: nx.Graph) -> CreasePattern:
        """Inverse of :meth:`to_networkx` (nodes must be 0..nv-1)."""
        nodes = sorted(g.nodes)
        if nodes != list(range(len(nodes))):
            raise InvalidPatternError("graph nodes must be the integers 0..nv-1")
        coords = np.array([g.nodes[v]["coords"] for v in nodes], float)
        flat = None
        if nodes and all("flat" in g.nodes[v] for v in nodes):
            flat = np.array([g.nodes[v]["flat"] for v in nodes], float)
        data = sorted(g.edges(data=True), key=lambda t: t[2].get("index", 0))
        edges = np.array([[a, b] for a, b, _ in data], np.int64).reshape(-1, 2)
        asg = [d.get("assignment", "U") for *_, d in data]
        ang = [d.get("fold_angle", 0.0) for *_, d in data]
        return cls(
            coords,
            g.graph.get("faces", []),
            edges,
            asg,
            ang,
            flat=flat,
            meta=g.graph.get("meta", {}),
        )
