"""Crease patterns: vertices, creases with FOLD assignments and fold angles, faces.

A :class:`CreasePattern` is the plain data every other layer consumes::

    coords      (nv, 3) float   3-D vertex coordinates, metres (the folded state; z = 0 if flat)
    faces       tuple of (k,) int arrays, one vertex loop per panel (k >= 3)
    edges       (ne, 2) int     vertex pairs, stored (min, max)
    assignment  (ne,) str       FOLD codes: M V B F C J U
    fold_angle  (ne,) float     FOLD convention: degrees in [-180, 180], valley > 0, mountain < 0
    flat        (nv, 2) float or None   the flat crease-pattern layout, metres, where one exists

Edge order matters: the reference simulator (SWOMPS) numbers creases by walking the panels in
order and, within a panel with vertices C1..CN, the edges (C1, CN), (C1, C2), ..., (C_{N-1}, C_N)
(specs/scenarios.md 1.1). :func:`reference_edges` computes exactly that order and
:meth:`CreasePattern.from_faces` uses it, so crease ``i`` of a generated pattern is the
reference's crease ``i + 1`` (0-based here, 1-based there).

Faces are kept in the vertex order they were given (the mechanics layer depends on it). Where a
flat layout exists every face must be counter-clockwise in it (positive signed area), as FOLD
requires. A 3-D-only pattern (for instance a fitted arch strip) need not be consistently
oriented; :func:`orient_faces` gives a consistently oriented copy where one is needed.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import networkx as nx
import numpy as np

from geometry.errors import DegenerateGeometryError, InvalidPatternError

__all__ = [
    "ASSIGNMENTS",
    "CreasePattern",
    "reference_edges",
    "orient_faces",
    "measure_fold_angles",
    "newell_normals",
]

#: FOLD 1.2 edge assignments: mountain, valley, border, flat, cut, join, unassigned.
ASSIGNMENTS = ("M", "V", "B", "F", "C", "J", "U")

_REL_TOL = 1e-12  # relative tolerance for zero lengths and areas


def _as_faces(faces) -> tuple[np.ndarray, ...]:
    out = []
    for k, f in enumerate(faces):
        a = np.asarray(f)
        if a.ndim != 1 or a.size < 3:
            raise InvalidPatternError(f"face {k} must list at least 3 vertex ids, got {f!r}")
        if not np.issubdtype(a.dtype, np.integer):
            if not np.all(np.equal(np.mod(a, 1), 0)):
                raise InvalidPatternError(f"face {k} has non-integer vertex ids {f!r}")
        out.append(a.astype(np.int64))
    return tuple(out)


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
    pairs = []
    for f in faces:
        a = np.concatenate([[f[0]], f[:-1]])
        b = np.concatenate([[f[-1]], f[1:]])
        pairs.append(np.stack([a, b], axis=1))
    p = np.sort(np.concatenate(pairs), axis=1)
    uniq, first, inverse, counts = np.unique(
        p, axis=0, return_index=True, return_inverse=True, return_counts=True
    )
    order = np.argsort(first, kind="stable")
    return uniq[order], counts[order]


def _face_edge_pairs(faces: tuple[np.ndarray, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Directed boundary edges (u -> v, in loop order) of all faces and their face ids."""
    pairs = [np.stack([f, np.roll(f, -1)], axis=1) for f in faces]
    owner = np.repeat(np.arange(len(faces)), [len(f) for f in faces])
    return np.concatenate(pairs), owner


def newell_normals(coords: np.ndarray, faces) -> np.ndarray:
    """Area-weighted face normals (Newell's method), (nf, 3); length = polygon area."""
    faces = _as_faces(faces)
    pairs, owner = _face_edge_pairs(faces)
    a, b = coords[pairs[:, 0]], coords[pairs[:, 1]]
    cr = np.cross(a, b)
    n = np.zeros((len(faces), 3))
    np.add.at(n, owner, cr)
    return 0.5 * n


def orient_faces(faces, n_vertices: int | None = None) -> tuple[np.ndarray, ...]:
    """A consistently oriented copy of ``faces``.

    The first face of each connected component keeps its orientation; every neighbour is
    reversed where needed so that two faces sharing an edge traverse it in opposite directions.
    Raises :class:`InvalidPatternError` for a non-orientable surface (a Moebius strip).
    """
    faces = _as_faces(faces)
    pairs, owner = _face_edge_pairs(faces)
    key = np.sort(pairs, axis=1)
    g = nx.Graph()
    g.add_nodes_from(range(len(faces)))
    uniq, inv = np.unique(key, axis=0, return_inverse=True)
    inv = inv.ravel()
    by_edge: dict[int, list[int]] = {}
    for idx, e in enumerate(inv):
        by_edge.setdefault(int(e), []).append(idx)
    for occ in by_edge.values():
        if len(occ) == 2:
            i, j = occ
            same = pairs[i, 0] == pairs[j, 0]  # traversed in the same direction
            g.add_edge(int(owner[i]), int(owner[j]), same=bool(same))
    flip = np.zeros(len(faces), bool)
    seen = np.zeros(len(faces), bool)
    for comp in nx.connected_components(g):
        root = min(comp)
        seen[root] = True
        for u, v in nx.bfs_edges(g, root):
            flip[v] = flip[u] ^ g.edges[u, v]["same"]
            seen[v] = True
        for u, v, d in g.subgraph(comp).edges(data=True):
            if (flip[u] ^ flip[v]) != d["same"]:
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
    faces = orient_faces(faces)
    normals = newell_normals(coords, faces)
    norms = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = normals / np.where(norms > 0, norms, 1.0)
    pairs, owner = _face_edge_pairs(faces)
    edges = np.asarray(edges, np.int64).reshape(-1, 2)
    # map each directed face edge to its undirected edge id
    lookup = {(int(a), int(b)): i for i, (a, b) in enumerate(np.sort(edges, axis=1))}
    eid = np.array([lookup.get((int(min(a, b)), int(max(a, b))), -1) for a, b in pairs])
    ne = len(edges)
    face_a = np.full(ne, -1)
    face_b = np.full(ne, -1)
    start = np.zeros((ne,), np.int64)
    end = np.zeros((ne,), np.int64)
    for idx in range(len(pairs)):  # one pass over face edges (topology only)
        e = eid[idx]
        if e < 0:
            continue
        if face_a[e] < 0:
            face_a[e] = owner[idx]
            start[e], end[e] = pairs[idx]
        else:
            face_b[e] = owner[idx]
    angle = np.zeros(ne)
    inner = (face_a >= 0) & (face_b >= 0)
    if inner.any():
        na, nb = normals[face_a[inner]], normals[face_b[inner]]
        t = coords[end[inner]] - coords[start[inner]]
        t /= np.linalg.norm(t, axis=1, keepdims=True)
        s = -np.einsum("ij,ij->i", np.cross(na, nb), t)
        c = np.einsum("ij,ij->i", na, nb)
        angle[inner] = np.degrees(np.arctan2(s, c))
    return angle


def _segments_cross(p: np.ndarray, q: np.ndarray, r: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Whether 2-D segments p-q and r-s intersect (touching included), vectorised."""

    def orient(a, b, c):
        return (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (b[..., 1] - a[..., 1]) * (
            c[..., 0] - a[..., 0]
        )

    d1, d2 = orient(r, s, p), orient(r, s, q)
    d3, d4 = orient(p, q, r), orient(p, q, s)
    return (d1 * d2 <= 0) & (d3 * d4 <= 0)


def _check_simple(points2d: list[np.ndarray], label: str) -> list[int]:
    """Indices of faces (given as 2-D loops) that are not simple polygons."""
    bad = []
    sizes = np.array([len(p) for p in points2d])
    for k in np.unique(sizes):
        idx = np.flatnonzero(sizes == k)
        P = np.stack([points2d[i] for i in idx])  # (nf, k, 2)
        Q = np.roll(P, -1, axis=1)
        if k > 3:
            i, j = np.triu_indices(k, 2)
            keep = ~((i == 0) & (j == k - 1))  # adjacent through the wrap-around
            i, j = i[keep], j[keep]
            hit = _segments_cross(P[:, i], Q[:, i], P[:, j], Q[:, j]).any(axis=1)
            bad.extend(idx[hit].tolist())
    return bad


def _polygon_area2d(p: np.ndarray) -> float:
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


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
        assignment = np.asarray(self.assignment, dtype="<U1").reshape(-1)
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

    def _validate(self) -> None:
        nv, ne = len(self.coords), len(self.edges)
        e = self.edges
        # indices
        if ne and (e.min() < 0 or e.max() >= nv):
            k = int(np.flatnonzero((e < 0).any(1) | (e >= nv).any(1))[0])
            raise InvalidPatternError(
                f"edge {k} = {e[k].tolist()} references a vertex outside 0..{nv - 1}"
            )
        for k, f in enumerate(self.faces):
            if f.min() < 0 or f.max() >= nv:
                raise InvalidPatternError(
                    f"face {k} = {f.tolist()} references a vertex outside 0..{nv - 1}"
                )
            if len(np.unique(f)) != len(f):
                raise InvalidPatternError(
                    f"face {k} = {f.tolist()} repeats a vertex (not a simple polygon)"
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
            pairs, owner = _face_edge_pairs(self.faces)
            key = np.sort(pairs, axis=1)
            known = {(int(a), int(b)) for a, b in e}
            for (a, b), o in zip(key, owner, strict=True):
                if (int(a), int(b)) not in known:
                    raise InvalidPatternError(
                        f"face {int(o)} uses edge {[int(a), int(b)]}, which is not in edges"
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
                loops = [self.flat[f] for f in self.faces]
            else:
                normals = newell_normals(self.coords, self.faces)
                loops = []
                for f, n in zip(self.faces, normals, strict=True):
                    loops.append(_project(self.coords[f], n))
            scale2 = max(float(np.ptp(self.coords, axis=0).max()), 1e-300) ** 2
            for k, p in enumerate(loops):
                area = _polygon_area2d(p)
                if abs(area) <= _REL_TOL * scale2:
                    raise DegenerateGeometryError(f"face {k} has zero area")
                if self.flat is not None and area < 0:
                    raise InvalidPatternError(
                        f"face {k} = {self.faces[k].tolist()} is clockwise in the flat layout; "
                        "faces must be counter-clockwise (reverse its vertex order)"
                    )
            bad = _check_simple(loops, "face")
            if bad:
                raise InvalidPatternError(
                    f"face {bad[0]} = {self.faces[bad[0]].tolist()} is not a simple polygon "
                    "(its sides cross)"
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
        if not self.faces:
            return np.zeros(self.n_edges, np.int64)
        pairs, _ = _face_edge_pairs(self.faces)
        key = np.sort(pairs, axis=1)
        lookup = {(int(a), int(b)): i for i, (a, b) in enumerate(self.edges)}
        ids = np.array([lookup[(int(a), int(b))] for a, b in key])
        return np.bincount(ids, minlength=self.n_edges)

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
            asg[mv & (a == 0) & (asg == "F")] = "F"
            new = replace(new, fold_angle=a, assignment=asg)
        return new

    # ------------------------------------------------------------------ networkx view
    def to_networkx(self) -> nx.Graph:
        """The pattern as an undirected graph.

        Nodes are vertex ids with ``coords`` (and ``flat``) attributes; edges carry
        ``index`` (position in :attr:`edges`), ``assignment`` and ``fold_angle``. The graph
        attributes hold ``faces`` (lists) and ``meta``.
        """
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


def _project(points3d: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Project a 3-D loop onto the plane with the given normal, as 2-D coordinates.

    A vanishing normal (a bow-tie loop) falls back to the best-fit plane of the points.
    """
    d = points3d - points3d.mean(axis=0)
    if np.linalg.norm(normal) <= 1e-300 or not np.isfinite(normal).all():
        basis = np.linalg.svd(d, full_matrices=False)[2]
        return np.column_stack([d @ basis[0], d @ basis[1]])
    n = normal / np.linalg.norm(normal)
    helper = np.eye(3)[np.argmin(np.abs(n))]
    u = np.cross(n, helper)
    u /= np.linalg.norm(u)
    w = np.cross(n, u)
    return np.column_stack([d @ u, d @ w])
