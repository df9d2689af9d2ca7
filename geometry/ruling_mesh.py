"""The panels between curved creases meshed along their rulings (issue 36 item 2).

A face whose boundary holds pieces of a discretised curve (:mod:`holofold.geometry.curved`) is
triangulated without new vertices so that its added edges (``J`` facets, bent by the panel's
plate stiffness in :mod:`holofold.mechanics.hinges`) run along the rulings of the developable
surface the panel bends into:

* **Strip** (the face's boundary has two or more runs of curve pieces): the boundary is cut
  into two chains that start at the first vertex of the longest run of curve pieces and end at
  the first vertex of the second longest run. Each chain's vertices are placed at their
  relative arc length along the chain's own curve run (the other vertices of a chain, its
  straight caps, at 0 or 1), and the two chains are stitched: each step adds the triangle
  that advances the chain whose next vertex has the smaller relative arc length. The rulings
  are thus approximated in the flat state by joining points of **equal relative arc length**
  of the two curves (exact for concentric circles, whose rulings are radial); where both next
  vertices have the same relative arc length (a quad of matched points) the quad is split
  along its **shorter diagonal**.
* **Otherwise** (one curve run only: stitching it to straight sides fanned rulings from their
  corners, and Origami Simulator's scale.svg then diverged on its first step, folding to 7 %
  in 30 s with this instead; or where the stitched strip would have a triangle of area <= 0:
  a strip too curved for its rulings to join its two sides inside it): ear clipping
  (manifold3d) followed by Lawson flips of the added diagonals to the constrained Delaunay
  triangulation of the polygon.

Either way every triangle turns counter-clockwise with area > 0, the triangles tile the face
exactly (no vertex is added inside), and a face of n corners gives n - 2 triangles and n - 3
added edges.

:func:`curve_edge_mask` tells which edges of a layout are curve pieces, from points sampled
densely along the drawing's :class:`~holofold.geometry.curved.Curve` objects.
"""

from __future__ import annotations

import math

import numpy as np

from holofold.geometry.errors import ParameterError

__all__ = [
    "curve_samples",
    "curve_points_on",
    "curve_edge_mask",
    "strip_triangles",
    "delaunay_triangles",
    "ruling_triangles",
    "steiner_points",
    "chord_triangles",
]

#: degrees a chord from a curve vertex to its foot on a straight side may turn from the curve's
#: normal there (a guard: wavy_pleats and Improvisation-62 turn up to 44; the partial cuts of
#: Tri-Wing_Boomerang_Tiling and Rotating_Star, refused since they leave vertices out, up to 95)
MAX_RULING_TURN = 60.0
#: the most points :func:`curve_samples` places along all curves together
MAX_SAMPLES = 2_000_000


def curve_samples(curves, spacing: float) -> np.ndarray:
    """Points along every curve at most ``spacing`` apart (the curves' units), (k, 2)."""
    if not spacing > 0:
        raise ParameterError(f"curve sample spacing = {spacing!r} must be > 0")
    coarse = [np.asarray(c.point(np.linspace(0.0, 1.0, 65)), float) for c in curves]
    lengths = [float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()) for p in coarse]
    total = sum(lengths) / spacing
    if total > MAX_SAMPLES:
        spacing *= total / MAX_SAMPLES
    out = [np.zeros((0, 2))]
    for c, L in zip(curves, lengths, strict=True):
        n = max(8, int(np.ceil(1.5 * L / spacing)) + 1)  # 1.5: arc longer than the 64 chords
        out.append(np.asarray(c.point(np.linspace(0.0, 1.0, n)), float))
    return np.concatenate(out)


def curve_points_on(vertices, curves, tol: float | None = None) -> tuple[np.ndarray, float]:
    """Points along ``curves`` in the frame of the layout ``vertices`` (n, 2), and the distance
    within which an edge is taken to lie on them: ``tol`` (default 2e-3 of the layout's larger
    side, the merge distance of :func:`~holofold.geometry.arrangement.arrange_lines`).

    The SVG reader keeps its curves y down while its lines are y up: the frame (y or -y) is the
    one in which more curve end points fall on a vertex."""
    from scipy.spatial import cKDTree

    V = np.asarray(vertices, float).reshape(-1, 2)
    size = float(np.ptp(V, axis=0).max()) if len(V) else 1.0
    tol = 2e-3 * (size or 1.0) if tol is None else float(tol)
    S = curve_samples(curves, tol / 2.0)
    ends = np.concatenate([np.asarray(c.point([0.0, 1.0]), float) for c in curves])
    tree = cKDTree(V)
    flip = np.array([1.0, -1.0])
    hit_up = np.isfinite(tree.query(ends, distance_upper_bound=tol)[0]).sum()
    hit_down = np.isfinite(tree.query(ends * flip, distance_upper_bound=tol)[0]).sum()
    return (S * flip if hit_down > hit_up else S), tol


def curve_edge_mask(xy, edges, samples, tol: float) -> np.ndarray:
    """(ne,) bool: the edges whose two ends and midpoint lie within ``tol`` of a sample point
    (``samples`` (k, 2) in the units of ``xy``; sampled at most ``tol`` / 2 apart)."""
    from scipy.spatial import cKDTree

    xy = np.asarray(xy, float)
    E = np.asarray(edges, np.int64).reshape(-1, 2)
    S = np.asarray(samples, float).reshape(-1, 2)
    if not len(E) or not len(S):
        return np.zeros(len(E), bool)
    tree = cKDTree(S)
    a, b = xy[E[:, 0]], xy[E[:, 1]]
    near = np.ones(len(E), bool)
    for p in (a, b, 0.5 * (a + b)):
        d, _ = tree.query(p, distance_upper_bound=tol)
        near &= np.isfinite(d)
    return near


def _area2(p: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Twice the signed areas of triangles ``tris`` (m, 3) of points ``p``."""
    a, b, c = p[tris[:, 0]], p[tris[:, 1]], p[tris[:, 2]]
    return (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])


def _runs(on_curve: np.ndarray) -> list[tuple[int, int]]:
    """Maximal runs of True sides of a closed loop: (first side, number of sides)."""
    n = len(on_curve)
    if on_curve.all():
        return [(0, n)]
    start = int(np.flatnonzero(~on_curve)[0])
    runs, k = [], 0
    while k < n:
        i = (start + k) % n
        if on_curve[i]:
            m = 0
            while k + m < n and on_curve[(start + k + m) % n]:
                m += 1
            runs.append((i, m))
            k += m
        else:
            k += 1
    return runs


def _chain_params(p: np.ndarray, sides_on_run: np.ndarray) -> np.ndarray:
    """Relative arc length at the vertices of a chain, counting only its sides on its run
    (all sides where none is)."""
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    if sides_on_run.any():
        seg = np.where(sides_on_run, seg, 0.0)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    return s / s[-1] if s[-1] > 0 else s


def strip_triangles(xy, face, on_curve) -> np.ndarray | None:
    """The ruling-aligned triangles of one counter-clockwise face (see the module docstring),
    (n - 2, 3) vertex ids, or None where a stitched triangle would have area <= 0 or the face
    has no curve piece.

    ``on_curve`` (n,) bool: side k (from ``face[k]`` to ``face[k + 1]``) is a curve piece.
    """
    f = np.asarray(face, np.int64)
    n = len(f)
    on = np.asarray(on_curve, bool)
    if n == 3:
        return f[None].copy()
    runs = _runs(on) if on.any() else []
    if len(runs) < 2:  # one curve (or none): no second curve for the rulings to reach
        return None
    p = np.asarray(xy, float)[f]
    seg = np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1)
    runs = sorted(runs, key=lambda r: -seg[[(r[0] + k) % n for k in range(r[1])]].sum())
    (a0, na), (b0, nb) = runs[0], runs[1]
    m_l = (b0 - a0) % n  # sides of the forward chain, from a0 to b0
    L = [(a0 + k) % n for k in range(m_l + 1)]
    R = [(a0 - k) % n for k in range(n - m_l + 1)]
    run_a = {(a0 + k) % n for k in range(na)}
    run_b = {(b0 + k) % n for k in range(nb)}
    sides_l = np.array([L[k] in run_a for k in range(m_l)])  # side L[k] -> L[k+1] is side L[k]
    sides_r = np.array([R[k + 1] in run_b for k in range(n - m_l)])  # R[k] -> R[k+1]: side R[k+1]
    sl = _chain_params(p[L], sides_l)
    sr = _chain_params(p[R], sides_r)
    tris = [(L[0], L[1], R[1])]
    i, j = 1, 1
    il, jr = len(L) - 1, len(R) - 1
    while i < il or j < jr:
        if j == jr:
            adv_l = True
        elif i == il:
            adv_l = False
        elif abs(sl[i + 1] - sr[j + 1]) <= 1e-9:  # matched points: the shorter diagonal
            adv_l = np.hypot(*(p[L[i + 1]] - p[R[j]])) <= np.hypot(*(p[L[i]] - p[R[j + 1]]))
        else:
            adv_l = sl[i + 1] < sr[j + 1]
        if adv_l:
            tris.append((L[i], L[i + 1], R[j]))
            i += 1
        else:
            tris.append((R[j + 1], R[j], L[i]))
            j += 1
    T = np.array(tris, np.int64)
    # the last step joins L[il] = R[jr] = e with itself only if a chain was empty
    T = T[(T[:, 0] != T[:, 1]) & (T[:, 1] != T[:, 2]) & (T[:, 0] != T[:, 2])]
    a2 = _area2(p, T)
    total = 0.5 * float(np.sum(_cross_loop(p)))
    if len(T) != n - 2 or (a2 <= 1e-12 * abs(total)).any():
        return None
    return f[T]


def _cross_loop(p: np.ndarray) -> np.ndarray:
    q = np.roll(p, -1, axis=0)
    return p[:, 0] * q[:, 1] - p[:, 1] * q[:, 0]


def delaunay_triangles(xy, face, max_rounds: int = 50) -> np.ndarray:
    """Ear clipping (manifold3d) of one counter-clockwise face, then Lawson flips of the added
    diagonals towards the constrained Delaunay triangulation, (n - 2, 3) vertex ids."""
    import manifold3d

    f = np.asarray(face, np.int64)
    p = np.asarray(xy, float)[f]
    T = [list(t) for t in np.asarray(manifold3d.triangulate([p]), np.int64)]
    n = len(f)
    boundary = {(k, (k + 1) % n) for k in range(n)} | {((k + 1) % n, k) for k in range(n)}

    def opposite_angle(a, b, c):
        u, v = p[a] - p[c], p[b] - p[c]
        return np.arctan2(abs(u[0] * v[1] - u[1] * v[0]), u @ v)

    for _ in range(max_rounds):
        where: dict = {}
        for t_id, t in enumerate(T):
            for k in range(3):
                where.setdefault((t[k], t[(k + 1) % 3]), (t_id, t[(k + 2) % 3]))
        flipped = False
        done: set = set()
        for (a, b), (t1, c) in list(where.items()):
            if (a, b) in boundary or (b, a) not in where or (min(a, b), max(a, b)) in done:
                continue
            t2, d = where[(b, a)]
            if t1 in done or t2 in done:
                continue
            if opposite_angle(a, b, c) + opposite_angle(b, a, d) <= np.pi + 1e-12:
                continue
            new1, new2 = [c, a, d], [d, b, c]  # both counter-clockwise if the quad is convex
            if (_area2(p, np.array([new1, new2])) <= 0).any():
                continue
            T[t1], T[t2] = new1, new2
            done |= {t1, t2, (min(a, b), max(a, b))}
            flipped = True
        if not flipped:
            break
    return f[np.array(T, np.int64)]


def ruling_triangles(xy, face, on_curve) -> np.ndarray:
    """The triangles of one counter-clockwise face with curve pieces on its boundary:
    :func:`strip_triangles`, else :func:`delaunay_triangles`, (n - 2, 3) vertex ids."""
    T = strip_triangles(xy, face, on_curve)
    if T is None:
        T = chord_triangles(xy, face, on_curve)
    return delaunay_triangles(xy, face) if T is None else T


def _ruling_hits(p: np.ndarray, on: np.ndarray, min_gap: float):
    """The rulings of a face with one curve run, estimated along the curve's normals.

    ``p`` (n, 2) the counter-clockwise corners, ``on`` (n,) bool the curve sides. From every
    inner vertex of the run a ray along the curve's inward normal; where its first crossing of
    the boundary is a straight side, the ruling ends there. Returns ``[(i, k, u)]``: corner
    ``i`` of the run, side ``k`` (from corner k to k + 1) at parameter ``u`` in [0, 1], kept
    in order (the rulings do not cross: going along the run, the ends move back along the
    rest of the boundary, each at least ``min_gap`` from the last and from the corners)."""
    n = len(p)
    runs = _runs(on)
    if len(runs) != 1 or runs[0][1] >= n:
        return []
    a0, m = runs[0]
    q = np.roll(p, -1, axis=0)
    d = q - p
    out = []
    last = np.inf  # position of the last end, along the boundary from the run's end
    end = (a0 + m) % n  # the run's last corner
    for k in range(1, m):
        i = (a0 + k) % n
        t = p[(i + 1) % n] - p[(i - 1) % n]
        nrm = np.array([-t[1], t[0]]) / max(np.hypot(*t), 1e-300)
        # ray p[i] + s nrm against every side p[j] + u d[j], except the two sides at corner i
        den = nrm[0] * d[:, 1] - nrm[1] * d[:, 0]
        w = p - p[i]
        with np.errstate(divide="ignore", invalid="ignore"):
            s = (w[:, 0] * d[:, 1] - w[:, 1] * d[:, 0]) / den
            u = (w[:, 0] * nrm[1] - w[:, 1] * nrm[0]) / den
        ok = np.isfinite(s) & (s > 1e-12) & (u >= -1e-9) & (u <= 1 + 1e-9)
        ok[[i, (i - 1) % n]] = False
        if not ok.any():
            continue
        j = int(np.flatnonzero(ok)[np.argmin(s[ok])])
        if on[j]:
            continue  # the ray meets the curve again first
        L = float(np.hypot(*d[j]))
        uj = float(np.clip(u[j], 0.0, 1.0))
        if uj * L < min_gap or (1 - uj) * L < min_gap:
            continue
        pos = ((j - end) % n) + uj  # along the boundary from the run's end
        if pos >= last - min_gap / max(L, 1e-300):
            continue
        last = pos
        out.append((i, j, uj))
    return out


def _crosses(a, b, p: np.ndarray) -> bool:
    """Whether the open segment a-b properly crosses a side of the closed loop ``p``."""
    q = np.roll(p, -1, axis=0)

    def orient(x, y, z):
        return (y[..., 0] - x[..., 0]) * (z[..., 1] - x[..., 1]) - (y[..., 1] - x[..., 1]) * (
            z[..., 0] - x[..., 0]
        )

    size = float(np.ptp(p, axis=0).max()) or 1.0
    eps = 1e-9 * size * size
    d1, d2 = orient(a, b, p), orient(a, b, q)
    d3, d4 = orient(p, q, a[None]), orient(p, q, b[None])
    return bool(((d1 * d2 < -eps * eps) & (d3 * d4 < -eps * eps)).any())


def _ruling_ends(p: np.ndarray, on: np.ndarray, min_gap: float):
    """Where the rulings from the inner vertices of a face's one curve run end: on the straight
    side that most rays along the curve's inward normals reach first (:func:`_ruling_hits`),
    at the foot of the perpendicular from each vertex (the rulings of the neighbouring strips,
    at equal relative arc length, run near that way; the normals themselves converge at the
    centres of curvature and cross beyond). Returns ``[(i, side, u)]`` in the run's order,
    each end at least ``min_gap`` from the last and from the side's corners, the chords inside
    the face; ``[]`` unless every inner vertex of the run gets an end within
    :data:`MAX_RULING_TURN` of its normal (a strip between the curve and one straight side:
    where only some chords fit, the rest of the face fanned from the chords' ends, and
    Tri-Wing_Boomerang_Tiling stalled at 3 % instead of folding to 100 %)."""
    hits = _ruling_hits(p, on, 0.0)
    if not hits:
        return []
    n = len(p)
    d = np.roll(p, -1, axis=0) - p
    L = np.linalg.norm(d, axis=1)
    count = np.bincount([j for _, j, _ in hits], minlength=n).astype(float)
    j = int(np.argmax(count + L / (L.max() + 1.0)))
    a0, m = _runs(on)[0]
    out, last = [], np.inf
    for k in range(1, m):
        i = (a0 + k) % n
        u = float((p[i] - p[j]) @ d[j]) / (L[j] * L[j])
        if u * L[j] < min_gap or (1 - u) * L[j] < min_gap or u > last - min_gap / L[j]:
            continue
        foot = p[j] + u * d[j]
        if _crosses(p[i], foot, p):
            continue
        last = u
        out.append((i, j, u))
    if len(out) < m - 1:
        return []
    for i, j, u in out:
        t = p[(i + 1) % n] - p[(i - 1) % n]
        c = p[j] + u * d[j] - p[i]
        cos = abs(float(t[0] * c[1] - t[1] * c[0])) / max(np.hypot(*t) * np.hypot(*c), 1e-300)
        if cos < math.cos(math.radians(MAX_RULING_TURN)):
            return []
    return out


def steiner_points(xy, faces, edges, assignment, fold_angle, on_curve, split=("B",)):
    """New vertices on the straight sides of the faces with one curve run where the rulings
    from the curve end (:func:`_ruling_hits`), so that the rulings need not fan from the
    side's corners (a fan is a cone: its apex keeps its distance from every point of the curve,
    which the curve's fold does not, and the panel must stretch).

    Only sides whose assignment is in ``split`` (default the borders ``B``: one face, so no
    other face changes) get points. Returns ``xy, faces, edges, assignment, fold_angle,
    on_curve`` with the new vertices last and each split edge replaced by its pieces (its
    assignment and fold angle kept; not curve pieces)."""
    xy = np.asarray(xy, float)
    E = np.asarray(edges, np.int64).reshape(-1, 2)
    asg = np.asarray(assignment)
    ang = np.asarray(fold_angle, float)
    cm = np.asarray(on_curve, bool)
    key = {(min(a, b), max(a, b)): k for k, (a, b) in enumerate(E.tolist())}
    curve_keys = {k for k, c in zip(key, cm[list(key.values())], strict=True) if c}
    new_on: dict[int, list[float]] = {}  # edge id -> parameters (from E[e, 0]) of new points
    for f in faces:
        f = np.asarray(f, np.int64)
        n = len(f)
        if n <= 3:
            continue
        sides = [(min(a, b), max(a, b)) for a, b in zip(f, np.roll(f, -1), strict=True)]
        on = np.array([s in curve_keys for s in sides])
        if not on.any():
            continue
        p = xy[f]
        seg = np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1)
        gap = 0.5 * float(np.median(seg[on]))
        for _, j, u in _ruling_ends(p, on, gap):
            e = key[sides[j]]
            if asg[e] not in split:
                continue
            uu = u if E[e, 0] == f[j] else 1.0 - u
            new_on.setdefault(e, []).append(uu)
    if not new_on:
        return xy, list(faces), E, asg, ang, cm
    pts, chains = [xy], {}
    nv = len(xy)
    for e, us in new_on.items():
        a, b = E[e]
        us = np.unique(np.round(us, 12))
        ids = np.arange(nv, nv + len(us))
        nv += len(us)
        pts.append(xy[a][None] + us[:, None] * (xy[b] - xy[a])[None])
        chains[e] = [int(a), *ids.tolist(), int(b)]
    keep = np.ones(len(E), bool)
    keep[list(chains)] = False
    add_e, add_a, add_f = [], [], []
    for e, ch in chains.items():
        for x, y in zip(ch[:-1], ch[1:], strict=True):
            add_e.append((x, y))
            add_a.append(asg[e])
            add_f.append(ang[e])
    by_pair = {(ch[0], ch[-1]): ch for ch in chains.values()}
    out_faces = []
    for f in faces:
        g = []
        for a, b in zip(f, np.roll(f, -1), strict=True):
            g.append(int(a))
            if (a, b) in by_pair:
                g.extend(by_pair[(a, b)][1:-1])
            elif (b, a) in by_pair:
                g.extend(by_pair[(b, a)][-2:0:-1])
        out_faces.append(np.array(g, np.int64))
    E2 = np.vstack([E[keep], np.array(add_e, np.int64)])
    return (
        np.vstack(pts), out_faces, E2, np.concatenate([asg[keep], np.array(add_a, asg.dtype)]),
        np.concatenate([ang[keep], np.array(add_f, float)]),
        np.concatenate([cm[keep], np.zeros(len(add_e), bool)]),
    )  # fmt: skip


def chord_triangles(xy, face, on_curve) -> np.ndarray | None:
    """A face with one curve run cut along its rulings that end on points of its straight sides
    (:func:`steiner_points`: a vertex between two collinear sides, at the foot of the
    perpendicular from a vertex of the run), each piece triangulated by
    :func:`delaunay_triangles`; None where there is no such point."""
    f = np.asarray(face, np.int64)
    p = np.asarray(xy, float)[f]
    on = np.asarray(on_curve, bool)
    n = len(f)
    if not on.any():
        return None
    runs = _runs(on)
    if len(runs) != 1 or runs[0][1] >= n:
        return None
    a0, m = runs[0]
    run = [(a0 + k) % n for k in range(1, m)]
    chords = []
    for c in range(n):
        if c in run or c == a0 or c == (a0 + m) % n:
            continue
        prev, nxt = p[(c - 1) % n], p[(c + 1) % n]
        t = nxt - prev
        Lt = float(np.hypot(*t))
        w = p[c] - prev
        if abs(float(w[0] * t[1] - w[1] * t[0])) > 1e-9 * Lt * Lt:
            continue  # a corner, not a point on a straight side
        off = np.abs((p[run] - p[c]) @ t) / Lt
        k = int(np.argmin(off + 1e-9 * np.linalg.norm(p[run] - p[c], axis=1)))
        if off[k] <= 1e-6 * Lt and not _crosses(p[run[k]], p[c], p):
            chords.append((run[k], c))
    if not chords:
        return None
    pieces = [list(range(n))]
    for i, c in chords:
        for k, poly in enumerate(pieces):
            if i in poly and c in poly:
                a, b = poly.index(i), poly.index(c)
                a, b = min(a, b), max(a, b)
                pieces[k : k + 1] = [poly[a : b + 1], poly[b:] + poly[: a + 1]]
                break
    tris = []
    for poly in pieces:
        if len(poly) < 3:
            continue
        t = delaunay_triangles(p, np.array(poly)) if len(poly) > 3 else np.array([poly])
        tris.append(t)
    T = np.concatenate(tris)
    total = 0.5 * float(np.sum(_cross_loop(p)))
    a2 = _area2(p, T)
    tiles = abs(0.5 * a2.sum() - total) <= 1e-9 * abs(total)  # chords inside: no overlap
    if len(T) != n - 2 or (a2 <= 1e-12 * abs(total)).any() or not tiles:
        return None
    return f[T]
