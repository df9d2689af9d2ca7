"""Printability of a folded pattern: overlap volume and clearance of its thick panels.

The thick panels are those of :func:`~holofold.geometry.solid.thick_solid`: every panel pulled
back by W/2 from its interior creases (the hinge gap), its corners moved by +-t/2 along the
panel's mean normal and its caps fanned from its centre, in the folded state
(``pattern.coords``). Two numbers:

* **overlap**: the summed volume of the pairwise intersections of the thick panels, m^3 (0 when
  none intersect: the folded part can exist as designed). Exact (manifold3d booleans).
* **clearance**: the smallest distance between the mid-surfaces (fanned, as the meshes are) of
  two panels that share no vertex, less their half thicknesses, m: the gap between two thick
  panels facing each other; negative when they run into each other; ``inf`` when every pair of
  panels shares a vertex. Where the closest points are not on the faces (an edge or a corner
  of a thick panel) the true gap is larger: the number is a lower bound there.

Fast because almost no pair needs an exact test. Overlap: bounding spheres, then the
separating-axis test of the two prisms vectorised over the pairs (cap normals, side normals,
edge cross products of the hull of each prism's corners), which proves most pairs apart; the
pairs it cannot separate are coloured so that no two panels of one colour may touch, each colour
becomes one manifold3d solid, and the colours are intersected pairwise (a few booleans however
many pairs). Clearance: bounding spheres against the nearest corner distance, then exact
triangle-triangle distances of the fan triangles (vectorised) for the pairs left.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import sparse

from holofold.geometry.close_pairs import close_pairs
from holofold.geometry.errors import ParameterError
from holofold.geometry.pattern import CreasePattern, newell_normals, orient_faces
from holofold.geometry.solid import corner_edges, offset_corners

__all__ = ["Printability", "printability", "panel_overlap", "panel_clearance"]


@dataclass(frozen=True)
class Printability:
    """Overlap and clearance of a folded pattern's thick panels.

    Attributes
    ----------
    overlap : float
        Summed pairwise intersection volume, m^3 (0: none).
    clearance : float
        Smallest mid-surface distance between panels sharing no vertex less their half
        thicknesses, m (negative: they run into each other; inf: no such pair).
    candidates : (n, 2) int
        Panel pairs that no separating axis keeps apart (those that may intersect).
    closest : tuple of int or None
        The pair of panels at the clearance.
    """

    overlap: float
    clearance: float
    candidates: np.ndarray
    closest: tuple[int, int] | None


def _thick_panels(pattern: CreasePattern, thickness, crease_width):
    """Padded prisms: corners (nf, K, 3), top/bottom points (nf, 2K, 3), normals, sizes, t."""
    t = np.broadcast_to(np.asarray(thickness, float), (pattern.n_faces,)).copy()
    if not np.isfinite(t).all() or (t <= 0).any():
        raise ParameterError(f"panel thickness must be finite and > 0, got {t.min()!r}")
    W = np.broadcast_to(np.asarray(crease_width, float), (pattern.n_edges,))
    if not np.isfinite(W).all() or (W < 0).any():
        raise ParameterError(f"crease width must be finite and >= 0, got {W.min()!r}")
    faces = orient_faces(pattern.faces)
    half = np.where(pattern.interior, W / 2.0, 0.0)
    C = offset_corners(pattern.coords, faces, half[corner_edges(pattern, faces)])
    sizes = np.array([len(f) for f in faces])
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    loops = [np.arange(s, s + k) for s, k in zip(starts, sizes, strict=True)]
    n = newell_normals(C, loops)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    K = int(sizes.max())
    idx = starts[:, None] + np.minimum(np.arange(K)[None, :], sizes[:, None] - 1)
    P = C[idx]  # (nf, K, 3), short loops padded with their last corner
    h = (t / 2)[:, None, None] * n[:, None, :]
    pts = np.concatenate([P + h, P - h], axis=1)  # (nf, 2K, 3)
    return P, pts, n, sizes, t


def _unit_rows(a: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    norm = np.linalg.norm(a, axis=-1, keepdims=True)
    ok = norm > 1e-12
    return np.where(ok, a / np.where(ok, norm, 1.0), fallback)


def _sat_gap(P, pts, n, i, j, *, full: bool = True) -> np.ndarray:
    """Largest separation (m) of prisms i and j along the separating-axis candidates (P,).

    Positive: the prisms are apart by at least that much; <= 0: no candidate axis separates
    them (they may intersect). ``full=False`` tries only the cap and side normals (a cheap first
    pass: a pair it separates is apart).
    """
    Pi, Pj = P[i], P[j]
    ei = np.roll(Pi, -1, axis=1) - Pi
    ej = np.roll(Pj, -1, axis=1) - Pj
    ni, nj = n[i][:, None, :], n[j][:, None, :]
    K = Pi.shape[1]
    axes = [ni, nj, np.cross(ei, ni), np.cross(ej, nj)]
    if full:
        axes += [
            np.cross(ei[:, :, None, :], ej[:, None, :, :]).reshape(len(i), K * K, 3),
            np.cross(ni, ej),
            np.cross(ei, nj),
            np.cross(ni, nj),
        ]
    axes = _unit_rows(np.concatenate(axes, axis=1), ni)
    pi = np.matmul(axes, pts[i].transpose(0, 2, 1))  # (P, axes, 2K)
    pj = np.matmul(axes, pts[j].transpose(0, 2, 1))
    gap = np.maximum(pj.min(axis=2) - pi.max(axis=2), pi.min(axis=2) - pj.max(axis=2))
    return gap.max(axis=1)


def _prism_mesh(P: np.ndarray, k: int, normal: np.ndarray, t: float):
    """Vertices and triangles of one panel's prism (corners (k, 3)), as thick_solid builds it."""
    c = P[:k].mean(axis=0)
    h = normal * t / 2
    verts = np.vstack([P[:k] + h, P[:k] - h, c + h, c - h])
    j = np.arange(k)
    jn = np.roll(j, -1)
    tris = np.vstack([
        np.column_stack([j, jn, np.full(k, 2 * k)]),
        np.column_stack([jn + k, j + k, np.full(k, 2 * k + 1)]),
        np.column_stack([j, j + k, jn + k]),
        np.column_stack([j, jn + k, jn]),
    ])  # fmt: skip
    return verts, tris


def _solid(P, sizes, n, t, members) -> object:
    """One manifold3d solid of several disjoint panel prisms."""
    import manifold3d as m3d

    vs, ts, off = [], [], 0
    for k in members:
        v, tr = _prism_mesh(P[k], int(sizes[k]), n[k], float(t[k]))
        vs.append(v)
        ts.append(tr + off)
        off += len(v)
    mesh = m3d.Mesh64(vert_properties=np.vstack(vs), tri_verts=np.vstack(ts).astype(np.uint64))
    return m3d.Manifold(mesh)


def _overlap(P, pts, n, sizes, t, pairs) -> tuple[float, np.ndarray]:
    """Summed intersection volume of the prisms of ``pairs`` (m, 2) that no axis separates."""
    if not len(pairs):
        return 0.0, np.zeros((0, 2), int)
    pairs = pairs[_sat_gap(P, pts, n, pairs[:, 0], pairs[:, 1], full=False) <= 0]
    if len(pairs):
        pairs = pairs[_sat_gap(P, pts, n, pairs[:, 0], pairs[:, 1]) <= 0]
    if not len(pairs):
        return 0.0, pairs
    import networkx as nx  # only where prisms overlap (0.2 s CPU to import)

    g = nx.Graph()
    g.add_edges_from(pairs.tolist())
    colour = nx.greedy_color(g, strategy="largest_first")
    classes: dict[int, list[int]] = {}
    for node, c in colour.items():
        classes.setdefault(c, []).append(node)
    solids = {c: _solid(P, sizes, n, t, members) for c, members in classes.items()}
    touching = {tuple(sorted((colour[a], colour[b]))) for a, b in pairs.tolist()}
    volume = sum((solids[a] ^ solids[b]).volume() for a, b in sorted(touching))
    return float(volume), pairs


def _fan_triangles(P: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """(nf, K, 3, 3) fan triangles (centre, corner l, corner l+1) of the padded corners."""
    nf, K, _ = P.shape
    valid = np.arange(K)[None, :] < sizes[:, None]
    c = (P * valid[:, :, None]).sum(axis=1) / sizes[:, None]
    lo = np.minimum(np.arange(K)[None, :], sizes[:, None] - 1)  # padding repeats the last one
    hi = (lo + 1) % sizes[:, None]
    rows = np.arange(nf)[:, None]
    return np.stack([np.broadcast_to(c[:, None], (nf, K, 3)), P[rows, lo], P[rows, hi]], axis=2)


# Triangle distances on coordinate tuples (x, y, z) of (n,) arrays: numpy on long 1-D arrays
# is several times faster than on (n, 3) rows (no reductions over a length-3 axis).
def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _add(a, b, s=1.0):
    return (a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _norm(a):
    return np.sqrt(_dot(a, a))


def _point_segment(x, a, b):
    ab = _sub(b, a)
    s = np.clip(_dot(_sub(x, a), ab) / np.maximum(_dot(ab, ab), 1e-300), 0.0, 1.0)
    return _norm(_sub(x, _add(a, ab, s)))


def _segment_segment(p1, q1, p2, q2):
    """Distance between segments p1-q1 and p2-q2 (Ericson, Real-Time Collision Detection 5.1.9)."""
    d1, d2, r = _sub(q1, p1), _sub(q2, p2), _sub(p1, p2)
    a, e, f = _dot(d1, d1), _dot(d2, d2), _dot(d2, r)
    c, b = _dot(d1, r), _dot(d1, d2)
    den = a * e - b * b
    ok = den > 1e-300
    s = np.where(ok, np.clip((b * f - c * e) / np.where(ok, den, 1.0), 0.0, 1.0), 0.0)
    tt = (b * s + f) / e
    s = np.where(tt < 0, np.clip(-c / a, 0, 1), np.where(tt > 1, np.clip((b - c) / a, 0, 1), s))
    tt = np.clip(tt, 0.0, 1.0)
    return _norm(_sub(_add(p1, d1, s), _add(p2, d2, tt)))


def _inside(a, b, c, nrm, y):
    """Whether y (in the plane of triangle a, b, c with normal nrm) lies in the triangle."""
    return (
        (_dot(_cross(_sub(b, a), _sub(y, a)), nrm) >= 0)
        & (_dot(_cross(_sub(c, b), _sub(y, b)), nrm) >= 0)
        & (_dot(_cross(_sub(a, c), _sub(y, c)), nrm) >= 0)
    )


def _point_triangle(x, a, b, c, nrm, nn):
    """Distance from points x to triangles (a, b, c) with normals nrm of length nn."""
    h = _dot(_sub(x, a), nrm) / np.maximum(nn, 1e-300)
    y = _add(x, nrm, -h / np.maximum(nn, 1e-300))  # projection onto the plane
    edge = np.minimum(
        np.minimum(_point_segment(x, a, b), _point_segment(x, b, c)), _point_segment(x, c, a)
    )
    return np.where(_inside(a, b, c, nrm, y) & (nn > 0), np.abs(h), edge)


def _segment_crosses(p, q, a, b, c, nrm):
    """Whether segments p-q pass through triangles (a, b, c) with normals nrm."""
    dp, dq = _dot(_sub(p, a), nrm), _dot(_sub(q, a), nrm)
    crosses = (dp * dq <= 0) & (dp != dq)
    lam = dp / np.where(dp != dq, dp - dq, 1.0)
    return crosses & _inside(a, b, c, nrm, _add(p, _sub(q, p), lam))


def _triangle_distance(A, B):
    """Distance between triangles A and B (n, 3, 3); 0 where they intersect."""
    VA = [tuple(A[:, v, d] for d in range(3)) for v in range(3)]
    VB = [tuple(B[:, v, d] for d in range(3)) for v in range(3)]
    nA = _cross(_sub(VA[1], VA[0]), _sub(VA[2], VA[0]))
    nB = _cross(_sub(VB[1], VB[0]), _sub(VB[2], VB[0]))
    lA, lB = _norm(nA), _norm(nB)
    e = [(0, 1), (1, 2), (2, 0)]
    d = np.full(len(A), np.inf)
    hit = np.zeros(len(A), bool)
    for i, j in e:
        for k, m in e:
            d = np.minimum(d, _segment_segment(VA[i], VA[j], VB[k], VB[m]))
        hit |= _segment_crosses(VA[i], VA[j], *VB, nB)
        hit |= _segment_crosses(VB[i], VB[j], *VA, nA)
    for v in range(3):
        d = np.minimum(d, _point_triangle(VA[v], *VB, nB, lB))
        d = np.minimum(d, _point_triangle(VB[v], *VA, nA, lA))
    return np.where(hit, 0.0, d)


def _plane_gap(A, B):
    """Distance of triangles B (n, 3, 3) from the planes of A where B lies on one side, else 0."""
    a0, a1, a2 = (tuple(A[:, v, d] for d in range(3)) for v in range(3))
    nrm = _cross(_sub(a1, a0), _sub(a2, a0))
    ln = np.maximum(_norm(nrm), 1e-300)
    h = np.stack([_dot(_sub(tuple(B[:, v, d] for d in range(3)), a0), nrm) for v in range(3)]) / ln
    lo, hi = h.min(axis=0), h.max(axis=0)
    return np.where(lo > 0, lo, np.where(hi < 0, -hi, 0.0))


def _first_apart(centre: np.ndarray, share, r: float, pairs: np.ndarray) -> float:
    """Distance between the nearest two panel centres of panels sharing no vertex (an upper
    bound of the nearest such pair's mid-surface distance); inf if there is none. The search
    radius starts at ``r`` (> 0; ``pairs`` the centre pairs within it) and doubles until such
    a pair is within it."""
    reach = float(np.linalg.norm(np.ptp(centre, axis=0))) if len(centre) else 0.0
    if not r > 0:
        r, pairs = max(reach, 1.0), close_pairs(centre, max(reach, 1.0))
    while True:
        apart = pairs[np.asarray(share[pairs[:, 0], pairs[:, 1]]).ravel() == 0]
        if len(apart):
            return float(np.linalg.norm(centre[apart[:, 0]] - centre[apart[:, 1]], axis=1).min())
        if r > reach:  # every pair was within reach
            return math.inf
        r *= 2.0
        pairs = close_pairs(centre, r)


def printability(pattern: CreasePattern, panel_thickness, crease_width=0.0) -> Printability:
    """Overlap (m^3) and clearance (m) of the thick panels of ``pattern``'s folded state.

    Parameters
    ----------
    pattern : CreasePattern
        Folded state in ``coords``, m.
    panel_thickness : float or (nf,) float
        t, m (> 0).
    crease_width : float or (ne,) float
        Hinge gap W at interior creases, m (>= 0).
    """
    P, pts, n, sizes, t = _thick_panels(pattern, panel_thickness, crease_width)
    nf = pattern.n_faces
    centre = pts.mean(axis=1)
    radius = np.linalg.norm(pts - centre[:, None, :], axis=2).max(axis=1)
    # --- overlap: pairs whose bounding spheres meet
    near = close_pairs(centre, 2 * float(radius.max()))  # also _first_apart's first search
    pairs = near
    if len(pairs):
        d = np.linalg.norm(centre[pairs[:, 0]] - centre[pairs[:, 1]], axis=1)
        pairs = pairs[d <= radius[pairs[:, 0]] + radius[pairs[:, 1]]]
    volume, maybe = _overlap(P, pts, n, sizes, t, pairs)
    # --- clearance: mid-surface distance of panels sharing no vertex, less half thicknesses
    inc = sparse.csr_matrix(
        (np.ones(int(sizes.sum())), (np.repeat(np.arange(nf), sizes),
                                     np.concatenate(pattern.faces))),
        shape=(nf, pattern.n_vertices),
    )  # fmt: skip
    share = (inc @ inc.T).tocsr()
    far = _first_apart(centre, share, 2 * float(radius.max()), near)
    if not math.isfinite(far):
        return Printability(volume, math.inf, maybe, None)
    mid_r = np.linalg.norm(P - P.mean(axis=1, keepdims=True), axis=2).max(axis=1)
    mid_c = P.mean(axis=1)
    cand = close_pairs(centre, far + 4 * float(radius.max()))
    cand = cand[np.asarray(share[cand[:, 0], cand[:, 1]]).ravel() == 0]
    i, j = cand[:, 0], cand[:, 1]
    half = 0.5 * (t[i] + t[j])
    corner = np.linalg.norm(P[i][:, :, None] - P[j][:, None], axis=3).min(axis=(1, 2)) - half
    lower = np.linalg.norm(mid_c[i] - mid_c[j], axis=1) - mid_r[i] - mid_r[j] - half
    keep = lower <= corner.min()
    i, j, half = i[keep], j[keep], half[keep]
    T = _fan_triangles(P, sizes)  # (nf, K, 3, 3)
    G = T.mean(axis=2)  # triangle centroids (nf, K, 3), on the mid-surface
    rho = np.linalg.norm(T - G[:, :, None], axis=3).max(axis=2)
    dG = np.linalg.norm(G[i][:, :, None] - G[j][:, None], axis=3)  # (n, K, K)
    upper = min(float(corner.min()), float((dG - half[:, None, None]).min()))
    low = dG - rho[i][:, :, None] - rho[j][:, None] - half[:, None, None]
    p, a, b = np.nonzero(low <= upper + 1e-9 * (abs(upper) + float(rho.max())))  # can be closest
    TA, TB = T[i[p], a], T[j[p], b]
    low = np.maximum(low[p, a, b], np.maximum(_plane_gap(TA, TB), _plane_gap(TB, TA)) - half[p])
    keep = low <= upper + 1e-9 * (abs(upper) + float(rho.max()))  # rounding: keep the equal
    p, a, b, low = p[keep], a[keep], b[keep], low[keep]
    order = np.argsort(low)
    p, a, b, low = p[order], a[order], b[order], low[order]
    best, at, done = math.inf, 0, 0
    while done < len(low) and low[done] < best:  # nearest first, in growing chunks
        stop = min(len(low), done + max(4096, done))
        sl = slice(done, stop)
        gap = _triangle_distance(T[i[p[sl]], a[sl]], T[j[p[sl]], b[sl]]) - half[p[sl]]
        k = int(np.argmin(gap))
        if gap[k] < best:
            best, at = float(gap[k]), done + k
        done = stop
    return Printability(volume, best, maybe, (int(i[p[at]]), int(j[p[at]])))


def panel_overlap(pattern: CreasePattern, panel_thickness, crease_width=0.0) -> float:
    """Summed intersection volume of the folded thick panels, m^3 (see :func:`printability`)."""
    return printability(pattern, panel_thickness, crease_width).overlap


def panel_clearance(pattern: CreasePattern, panel_thickness, crease_width=0.0) -> float:
    """Smallest gap between thick panels sharing no vertex, m (see :func:`printability`)."""
    return printability(pattern, panel_thickness, crease_width).clearance
