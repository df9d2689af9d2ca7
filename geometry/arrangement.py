"""Crease patterns from drawn lines: the planar arrangement of segments and its faces.

A drawing (SVG, DXF, ORIPA, a FOLD file without faces) is a bag of line segments, each with a
FOLD assignment and a fold angle. :func:`arrange_lines` turns it into a planar graph::

    1. segments shorter than ``tol`` are dropped, or, the pieces of a curve (``contract``),
       contracted: their two ends join one vertex (a chain of short pieces stays connected;
       points merged more than 2 ``tol`` apart are named in a note);
    2. every crossing of two segments, and every end point lying on another segment (a
       T-junction, a collinear overlap), splits the segment there;
    3. points closer than ``tol`` are merged (end points, crossings) into one vertex;
    4. edges drawn twice are kept once (a conflict of assignments is resolved in the order
       C, B, M, V, U, F, J and reported);
    5. a vertex between two collinear edges of one assignment and angle is removed (the
       two edges become one);
    6. edges that end in the middle of a panel (dangling creases, stray border pieces, cuts
       that end inside a panel: slits, which a panel model without a mesh cannot have) are
       removed, repeatedly;
    7. faces are traced around the graph (each half-edge to the next one clockwise at its end
       vertex), the outer face of every connected piece is dropped, and so are faces bounded
       by border lines only that are not the outside of the sheet (holes, Origami
       Simulator's rule);
    8. a piece drawn inside a face of another piece (not connected to it) makes that face a
       face with a hole: it is triangulated with the hole's outline as constraint, the added
       edges marked ``J``.

The result is an :class:`Arrangement`: vertices, edges with assignments and fold angles,
faces as simple counter-clockwise vertex loops (cuts still shared by the faces on both sides:
:func:`holofold.geometry.cuts.separate_cuts` separates them), and one line per problem found
(``notes``). Coordinates are in whatever unit the drawing has; ``tol`` is in that unit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from holofold.geometry.close_pairs import close_pairs
from holofold.geometry.errors import FormatError

__all__ = ["Arrangement", "arrange_lines", "PRIORITY", "REL_TOL", "default_tolerance"]

#: which assignment an edge drawn twice keeps: the first of these among its drawings
PRIORITY = ("C", "B", "M", "V", "U", "F", "J")
#: the default merge tolerance as a fraction of the drawing's larger side
REL_TOL = 2e-3
_BLOCK = 256


@dataclass(frozen=True)
class Arrangement:
    """A planar graph of drawn lines and its faces.

    Attributes
    ----------
    vertices : (nv, 2) float
        Drawing units.
    edges : (ne, 2) int
        Vertex pairs (smaller id first).
    assignment : (ne,) str
        FOLD codes.
    fold_angle : (ne,) float
        Degrees (valley > 0); 0 where none was drawn.
    faces : list of (k,) int
        Counter-clockwise vertex loops.
    notes : tuple of str
        One line per problem repaired or left (merged vertices, dropped lines, conflicts).
    """

    vertices: np.ndarray
    edges: np.ndarray
    assignment: np.ndarray
    fold_angle: np.ndarray
    faces: list
    notes: tuple[str, ...] = ()


def default_tolerance(segments: np.ndarray) -> float:
    """:data:`REL_TOL` x the larger side of the segments' bounding box."""
    pts = np.asarray(segments, float).reshape(-1, 2)
    return REL_TOL * float(np.ptp(pts, axis=0).max()) if len(pts) else 0.0


def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _splits(P: np.ndarray, Q: np.ndarray, tol: float):
    """Split points of every segment: (segment ids, parameters, points), from crossings with
    other segments and from other segments' end points lying on them."""
    n = len(P)
    d = Q - P
    L = np.linalg.norm(d, axis=1)
    lo = np.minimum(P, Q) - tol
    hi = np.maximum(P, Q) + tol
    seg, par, pts = [], [], []
    for s in range(0, n, _BLOCK):
        i = np.arange(s, min(n, s + _BLOCK))
        near = (
            (lo[i, None, 0] <= hi[None, :, 0])
            & (lo[None, :, 0] <= hi[i, None, 0])
            & (lo[i, None, 1] <= hi[None, :, 1])
            & (lo[None, :, 1] <= hi[i, None, 1])
        )
        a, b = np.nonzero(near)
        a = i[a]
        keep = a != b
        a, b = a[keep], b[keep]
        if not a.size:
            continue
        # end points of b on segment a (strictly inside it)
        for E in (P[b], Q[b]):
            w = E - P[a]
            t = np.einsum("ij,ij->i", w, d[a]) / (L[a] ** 2)
            dist = np.abs(_cross(d[a], w)) / L[a]
            inside = (dist <= tol) & (t * L[a] > tol) & ((1 - t) * L[a] > tol)
            seg.append(a[inside])
            par.append(t[inside])
            pts.append(E[inside])
        # proper crossings, inside both segments (once per pair: a < b)
        m = a < b
        a2, b2 = a[m], b[m]
        den = _cross(d[a2], d[b2])
        ok = np.abs(den) > 1e-12 * L[a2] * L[b2]
        a2, b2, den = a2[ok], b2[ok], den[ok]
        w = P[b2] - P[a2]
        t = _cross(w, d[b2]) / den
        u = _cross(w, d[a2]) / den
        inner = (t * L[a2] > tol) & ((1 - t) * L[a2] > tol) & (u * L[b2] > tol)
        inner &= (1 - u) * L[b2] > tol
        X = P[a2[inner]] + t[inner, None] * d[a2[inner]]
        seg += [a2[inner], b2[inner]]
        par += [t[inner], u[inner]]
        pts += [X, X]
    if not seg:
        return np.zeros(0, np.intp), np.zeros(0), np.zeros((0, 2))
    return np.concatenate(seg), np.concatenate(par), np.vstack(pts)


def _cluster(points: np.ndarray, tol: float, extra=None, extra_labels: bool = False):
    """Merge points closer than ``tol``: (label per point, mean point per label[, label per
    extra point, -1 where it joins no point]).

    ``extra`` (2m, 2): the ends of contracted short lines, pairs (2j, 2j + 1); they link the
    clusters they touch (each pair is one point) but do not move the means."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n0 = len(points)
    extra = np.zeros((0, 2)) if extra is None else np.asarray(extra, float).reshape(-1, 2)
    allp = np.vstack([points, extra])
    n = len(allp)
    pairs = close_pairs(allp, tol)
    link = n0 + np.arange(0, len(extra), 2)
    pairs = np.vstack([np.asarray(pairs, np.intp).reshape(-1, 2), np.stack([link, link + 1], 1)])
    g = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    k, label = connected_components(g, directed=False)
    used, label0 = np.unique(label[:n0], return_inverse=True)  # clusters of extras only: gone
    k = len(used)
    remap = np.full(int(label.max()) + 1 if n else 0, -1, np.intp)
    remap[used] = np.arange(k)
    cnt = np.bincount(label0, minlength=k).astype(float)
    mean = np.stack([np.bincount(label0, weights=points[:, c], minlength=k) for c in (0, 1)], 1)
    if extra_labels:
        return label0, mean / cnt[:, None], remap[label[n0:]]
    return label0, mean / cnt[:, None]


def _contraction_notes(points, label, ends, elab, tol) -> list[str]:
    """One line on the short lines contracted, naming the drawn length lost where a chain of
    them made one vertex of points farther apart than 2 ``tol`` (a feature no longer drawn)."""
    notes = [
        f"{len(ends) // 2} curve piece(s) shorter than the merge tolerance {tol:.3g} contracted "
        "(their ends joined into one vertex)"
    ]
    k = int(label.max()) + 1
    lo = np.full((k, 2), np.inf)
    hi = np.full((k, 2), -np.inf)
    ok = elab >= 0
    for lab, pts in ((label, points), (elab[ok], ends[ok])):
        np.minimum.at(lo, lab, pts)
        np.maximum.at(hi, lab, pts)
    span = np.linalg.norm(hi - lo, axis=1)
    touched = np.zeros(k, bool)
    touched[elab[ok]] = True
    big = touched & (span > 2 * tol)
    if big.any():
        k = int(np.argmax(np.where(big, span, -1.0)))
        notes.append(
            f"{int(big.sum())} vertex(es) each merge drawn points up to {span[k]:.3g} apart "
            f"(more than twice the merge tolerance; the largest near ({lo[k, 0]:.4g}, "
            f"{lo[k, 1]:.4g})): a drawn feature that small is not kept; pass a smaller tol"
        )
    return notes


def _rank(codes: np.ndarray) -> np.ndarray:
    order = {c: r for r, c in enumerate(PRIORITY)}
    return np.array([order.get(c, len(PRIORITY)) for c in codes], np.int64)


def arrange_lines(
    segments, assignment, fold_angle, *, tol: float | None = None, contract=None
) -> Arrangement:
    """The planar arrangement of drawn segments (see the module docstring).

    Parameters
    ----------
    segments : (n, 2, 2) float
        End points, drawing units, y up.
    assignment : (n,) str
        FOLD code of every segment.
    fold_angle : (n,) float
        Degrees (valley > 0).
    tol : float, optional
        Merge distance, drawing units (default :func:`default_tolerance`).
    contract : (n,) bool, optional
        The lines that, when shorter than ``tol``, are contracted (their ends joined into one
        vertex) instead of dropped: the straight pieces of a curve, so that a curve cut finer
        than ``tol`` stays connected. Default: none (short lines dropped, with a note).
    """
    S = np.asarray(segments, float).reshape(-1, 2, 2)
    asg = np.asarray(assignment, dtype="<U1").reshape(-1)
    ang = np.asarray(fold_angle, float).reshape(-1)
    if not (len(S) == len(asg) == len(ang)):
        raise ValueError("segments, assignment and fold_angle must have one entry per line")
    if not np.isfinite(S).all():
        raise FormatError("a line has non-finite coordinates")
    notes: list[str] = []
    if tol is None:
        tol = default_tolerance(S)
    if not len(S) or tol <= 0:
        raise FormatError("no lines of length > 0 to make a crease pattern of")
    L = np.linalg.norm(S[:, 1] - S[:, 0], axis=1)
    short = L <= tol
    # zero-length lines (a point drawn as a line) are dropped without a note: before, they
    # stayed when no other line was short and divided by their zero length in _splits
    tiny = short & (L > 1e-9 * tol / REL_TOL)
    # a short piece of a curve is contracted, not dropped: its two ends join the vertex
    # clustering as one point, so a chain of short pieces (a finely cut curve) stays connected
    # instead of breaking into dangling pieces (Origami Simulator's HexSpiralTess)
    pieces = np.zeros(len(S), bool) if contract is None else np.asarray(contract, bool)
    if pieces.shape != (len(S),):
        raise ValueError("contract must have one entry per line")
    n_short = int((tiny & ~pieces).sum())
    if n_short:
        notes.append(f"{n_short} line(s) shorter than the merge tolerance {tol:.3g} dropped")
    ends = S[tiny & pieces].reshape(-1, 2)
    S, asg, ang = S[~short], asg[~short], ang[~short]
    if not len(S):
        raise FormatError("no lines longer than the merge tolerance")
    P, Q = S[:, 0], S[:, 1]
    n = len(S)
    sid, spar, spts = _splits(P, Q, tol)
    points = np.vstack([P, Q, spts])
    label, verts, elab = _cluster(points, tol, extra=ends, extra_labels=True)
    if len(ends):
        notes += _contraction_notes(points, label, ends, elab, tol)
    # every segment: its vertices in order along it
    seg = np.concatenate([np.arange(n), np.arange(n), sid])
    par = np.concatenate([np.zeros(n), np.ones(n), spar])
    order = np.lexsort((par, seg))
    seg, lab = seg[order], label[order]
    same = seg[1:] == seg[:-1]
    a, b = lab[:-1][same], lab[1:][same]
    s_of = seg[:-1][same]
    keep = a != b
    a, b, s_of = a[keep], b[keep], s_of[keep]
    e = np.sort(np.stack([a, b], 1), axis=1)
    e_asg, e_ang = asg[s_of], ang[s_of]
    # edges drawn twice: keep one, by priority
    nv = len(verts)
    key = e[:, 0].astype(np.int64) * nv + e[:, 1]
    rank = _rank(e_asg)
    o = np.lexsort((rank, key))
    key_o = key[o]
    first = np.concatenate([[True], key_o[1:] != key_o[:-1]])
    starts = np.flatnonzero(first)
    grp = np.cumsum(first) - 1
    n_codes = np.zeros(len(starts), np.int64)
    dup_codes = {}
    for g, c in zip(grp, e_asg[o], strict=True):  # only the conflicts are reported
        dup_codes.setdefault(int(g), set()).add(str(c))
    conflicts = [g for g, cs in dup_codes.items() if len(cs) > 1]
    if conflicts:
        kinds = sorted({"/".join(sorted(dup_codes[g], key=PRIORITY.index)) for g in conflicts})
        notes.append(
            f"{len(conflicts)} edge(s) drawn twice with different assignments "
            f"({', '.join(kinds)}); kept the first of {' > '.join(PRIORITY)}"
        )
    del n_codes
    pick = o[starts]
    e, e_asg, e_ang = e[pick], e_asg[pick], e_ang[pick]
    e_ang = np.where(np.isin(e_asg, ("M", "V")), e_ang, 0.0)
    e, e_asg, e_ang, verts, more = _simplify(e, e_asg, e_ang, verts, tol)
    notes += more
    bridges = 0
    while True:  # an edge with one face on both sides separates nothing: drop it, retrace
        faces, more, bridge, all_b, touches_outer = _faces(verts, e, e_asg)
        if not bridge.any():
            break
        bridges += int(bridge.sum())
        keep = ~bridge
        e, e_asg, e_ang, verts, _ = _simplify(e[keep], e_asg[keep], e_ang[keep], verts, tol)
    notes += more
    if bridges:
        notes.append(
            f"{bridges} line(s) with the same panel on both sides dropped (they separate "
            "nothing; a piece they held is joined to the panel around it)"
        )
    e, e_asg, e_ang, faces, more = _fill_holes(verts, e, e_asg, e_ang, faces, all_b, touches_outer)
    notes += more
    if not faces:
        raise FormatError("the lines enclose no panel (no closed outline of border lines)")
    # keep only the vertices and edges the faces use (stray pieces outside every face)
    used_e = _face_edge_ids(e, faces, len(verts))
    unused = np.setdiff1d(np.arange(len(e)), used_e)
    if unused.size:
        notes.append(f"{unused.size} edge(s) on no panel dropped (lines outside the sheet)")
    e, e_asg, e_ang = e[used_e], e_asg[used_e], e_ang[used_e]
    used_v = np.unique(e)
    remap = np.full(len(verts), -1, np.intp)
    remap[used_v] = np.arange(len(used_v))
    return Arrangement(
        vertices=verts[used_v],
        edges=remap[e],
        assignment=e_asg,
        fold_angle=e_ang,
        faces=[remap[f] for f in faces],
        notes=tuple(notes),
    )


def _simplify(e, asg, ang, verts, tol):
    """Remove dangling edges and collinear degree-2 vertices of one kind."""
    notes = []
    nv = len(verts)
    alive = np.ones(len(e), bool)
    dropped = np.zeros(len(e), bool)
    while True:
        deg = np.bincount(e[alive].ravel(), minlength=nv)
        dang = alive & ((deg[e[:, 0]] == 1) | (deg[e[:, 1]] == 1))
        if not dang.any():
            break
        dropped |= dang
        alive &= ~dang
    n_cut = int((dropped & (asg == "C")).sum())
    n_other = int(dropped.sum()) - n_cut
    if n_other:
        notes.append(f"{n_other} dangling line piece(s) that end inside a panel dropped")
    if n_cut:
        notes.append(
            f"{n_cut} cut piece(s) that end inside a panel (slits) left out: a panel is not "
            "meshed, so it cannot be slit"
        )
    e, asg, ang = e[alive], asg[alive], ang[alive]
    # collinear degree-2 vertices joining two edges of one assignment and angle
    merged = 0
    while True:
        deg = np.bincount(e.ravel(), minlength=nv)
        inc = [[] for _ in range(nv)]
        for k in np.flatnonzero((deg[e[:, 0]] == 2) | (deg[e[:, 1]] == 2)):
            for v in e[k]:
                if deg[v] == 2:
                    inc[v].append(k)
        removed = np.zeros(len(e), bool)
        new_e, new_asg, new_ang = [], [], []
        touched = np.zeros(nv, bool)
        for v in np.flatnonzero(deg == 2):
            k1, k2 = inc[v]
            if removed[k1] or removed[k2] or asg[k1] != asg[k2] or ang[k1] != ang[k2]:
                continue
            a = e[k1, 0] if e[k1, 1] == v else e[k1, 1]
            b = e[k2, 0] if e[k2, 1] == v else e[k2, 1]
            if a == b or touched[a] or touched[b]:
                continue
            ab = verts[b] - verts[a]
            off = abs(_cross(ab, verts[v] - verts[a])) / max(np.linalg.norm(ab), 1e-300)
            if off > 1e-3 * tol:
                continue
            removed[[k1, k2]] = True
            touched[[a, b, v]] = True
            new_e.append(sorted((a, b)))
            new_asg.append(asg[k1])
            new_ang.append(ang[k1])
        if not new_e:
            break
        merged += len(new_e)
        e = np.vstack([e[~removed], np.array(new_e, np.intp)])
        asg = np.concatenate([asg[~removed], np.array(new_asg, dtype="<U1")])
        ang = np.concatenate([ang[~removed], np.array(new_ang)])
    if merged:
        pass  # joining collinear pieces of one line is routine, not a problem to report
    return e, asg, ang, verts, notes


def _faces(verts, e, asg):
    """Counter-clockwise face loops (outer faces dropped), notes, the edges with one face on
    both sides (bridges, (ne,) bool) and per face: bounded by border lines only, and sharing
    an edge with an outer face."""
    notes = []
    ne = len(e)
    if not ne:
        return [], notes, np.zeros(0, bool), np.zeros(0, bool), np.zeros(0, bool)
    # half-edges h = 2k (u -> v), 2k + 1 (v -> u); twin(h) = h ^ 1
    src = np.empty(2 * ne, np.intp)
    dst = np.empty(2 * ne, np.intp)
    src[0::2], src[1::2] = e[:, 0], e[:, 1]
    dst[0::2], dst[1::2] = e[:, 1], e[:, 0]
    dv = verts[dst] - verts[src]
    theta = np.arctan2(dv[:, 1], dv[:, 0])
    order = np.lexsort((theta, src))  # outgoing half-edges around each vertex, CCW
    pos = np.empty(2 * ne, np.intp)
    pos[order] = np.arange(2 * ne)
    start = np.searchsorted(src[order], np.arange(len(verts)))
    count = np.bincount(src, minlength=len(verts))
    # next(h: u -> v) = the half-edge leaving v just clockwise of v -> u: faces counter-clockwise
    hh = np.arange(2 * ne)
    v = dst
    nxt = order[start[v] + (pos[hh ^ 1] - start[v] - 1) % count[v]]
    head = src
    code = np.repeat(asg, 2)
    seen = np.zeros(2 * ne, bool)
    face_of = np.empty(2 * ne, np.intp)
    faces, loops_h, all_b = [], [], []
    outer = []  # loop ids of the outer (negative) loops
    n_loops = 0
    for h0 in range(2 * ne):
        if seen[h0]:
            continue
        loop = []
        h = h0
        while not seen[h]:
            seen[h] = True
            loop.append(h)
            h = nxt[h]
        face_of[loop] = n_loops
        n_loops += 1
        vs = head[loop]
        xy = verts[vs]
        area = 0.5 * _cross(xy, np.roll(xy, -1, axis=0)).sum()
        if area <= 0:
            outer.append(n_loops - 1)  # an outer face (or a degenerate loop)
            continue
        faces.append(vs)
        loops_h.append(np.array(loop))
        all_b.append(bool(np.all(code[loop] == "B")))
    bridge = face_of[0::2] == face_of[1::2]
    is_outer = np.zeros(n_loops, bool)
    is_outer[outer] = True
    touches_outer = np.array([bool(is_outer[face_of[h ^ 1]].any()) for h in loops_h], bool)
    return faces, notes, bridge, np.array(all_b, bool), touches_outer


def _loops_of_components(verts, e):
    """The connected piece of every vertex (labels)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    nv = len(verts)
    g = coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(nv, nv))
    return connected_components(g, directed=False)[1]


def _fill_holes(verts, e, asg, ang, faces, all_b, touches_outer):
    """Drop holes; triangulate the faces that contain another piece of the drawing around it.

    A face bounded by border lines only is a hole when it is not the outside of the sheet
    (no side on an outer face) or when its piece lies inside a face of another piece."""
    notes = []
    if not faces:
        return e, asg, ang, faces, notes
    label = _loops_of_components(verts, e)
    face_comp = np.array([label[f[0]] for f in faces])
    comps = np.unique(face_comp)
    areas = np.array([0.5 * _cross(verts[f], np.roll(verts[f], -1, axis=0)).sum() for f in faces])
    container: dict[int, int] = {}
    if len(comps) > 1:
        from matplotlib.path import Path as MplPath

        for c in comps:
            probe = verts[faces[np.flatnonzero(face_comp == c)[0]][0]]
            best = -1
            for k in np.flatnonzero((face_comp != c) & ~(all_b & ~touches_outer)):
                if MplPath(verts[faces[k]]).contains_point(probe) and (
                    best < 0 or areas[k] < areas[best]
                ):
                    best = k
            if best >= 0:
                container[int(c)] = best
    nested = np.array([int(c) in container for c in face_comp], bool)
    hole = all_b & (~touches_outer | nested)
    if hole.any():
        notes.append(f"{int(hole.sum())} face(s) bounded by border lines only left out as holes")
    inner: dict[int, list[np.ndarray]] = {}
    for c, k in container.items():
        members = np.flatnonzero(face_comp == c)
        outline = _outline(verts, e, label == c, faces, members)
        if outline is not None:
            inner.setdefault(k, []).append(outline)
    keep = [k for k in range(len(faces)) if not hole[k]]
    if not inner:
        return e, asg, ang, [faces[k] for k in keep], notes
    import manifold3d

    new_faces = []
    new_e = []
    for k in keep:
        f = faces[k]
        if k not in inner:
            new_faces.append(f)
            continue
        loops = [f] + [h[::-1] for h in inner[k]]  # holes clockwise
        ids = np.concatenate(loops)
        tris = np.asarray(manifold3d.triangulate([verts[lp] for lp in loops]), np.intp)
        for t in ids[tris]:
            new_faces.append(t)
            for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
                new_e.append(sorted((a, b)))
    notes.append(
        f"{sum(len(v) for v in inner.values())} piece(s) drawn inside a panel joined to it by "
        "triangulation (added edges J)"
    )
    have = set(map(tuple, np.sort(e, axis=1).tolist()))
    add = sorted({tuple(x) for x in new_e} - have)
    if add:
        e = np.vstack([e, np.array(add, np.intp)])
        asg = np.concatenate([asg, np.full(len(add), "J")])
        ang = np.concatenate([ang, np.zeros(len(add))])
    return e, asg, ang, new_faces, notes


def _outline(verts, e, in_comp, faces, members):
    """The outer boundary loop (counter-clockwise) of one piece, or None."""
    if len(members):
        used = {}
        for k in members:
            f = faces[k]
            for a, b in zip(f, np.roll(f, -1), strict=True):
                key = (min(a, b), max(a, b))
                used[key] = used.get(key, 0) + 1
        bnd = [k for k, c in used.items() if c == 1]
    else:  # a piece with no face of its own (e.g. a closed border loop, a hole)
        sel = in_comp[e[:, 0]]
        bnd = [tuple(x) for x in e[sel].tolist()]
    if not bnd:
        return None
    nbr: dict[int, list[int]] = {}
    for a, b in bnd:
        nbr.setdefault(a, []).append(b)
        nbr.setdefault(b, []).append(a)
    if any(len(v) != 2 for v in nbr.values()):
        return None  # not a simple loop: leave it
    start = bnd[0][0]
    loop = [start]
    prev, cur = None, start
    while True:
        nxt = [x for x in nbr[cur] if x != prev]
        nxt = nxt[0] if nxt else nbr[cur][0]
        if nxt == start:
            break
        loop.append(nxt)
        prev, cur = cur, nxt
        if len(loop) > len(nbr):
            return None
    loop = np.array(loop, np.intp)
    if 0.5 * _cross(verts[loop], np.roll(verts[loop], -1, axis=0)).sum() < 0:
        loop = loop[::-1]
    return loop


def _face_edge_ids(e, faces, nv):
    keys = e[:, 0].astype(np.int64) * nv + e[:, 1]
    order = np.argsort(keys)
    fv = np.concatenate(faces)
    nxt = np.concatenate([np.roll(f, -1) for f in faces])
    q = np.minimum(fv, nxt).astype(np.int64) * nv + np.maximum(fv, nxt)
    pos = np.minimum(np.searchsorted(keys, q, sorter=order), len(keys) - 1)
    ids = order[pos]
    return np.unique(ids[keys[ids] == q])
