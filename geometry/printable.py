"""The printable part of a crease pattern: the flat sheet with compliant hinges, one solid.

Print it flat, then fold it. In the plane of the flat layout (``pattern.flat``, m) the part has
three kinds of region:

* **panels**, pulled back by W/2 from every fold line (M, V, F, U edges) exactly as the
  compliant-crease model does it (docs/bar-and-hinge.md §4.1: each corner moves to the
  intersection of its offset sides), by half the cut width from cut lines (C edges), and not at
  all from borders (B) and joins (J, triangulation lines: the two faces print as one panel;
  where a join meets a fold line the union keeps a sliver of order W^2 over the hinge, so the
  volume formula below holds exactly only for patterns without joins);
* **hinge strips**, one per fold line: the quadrilateral between the two pulled-back panel
  sides, of width W, the crease region of the compliant model (§4.2);
* **vertex patches**: at a vertex where fold lines meet, the small polygon between the strips'
  ends and the vertex (the model leaves it empty; a printed hinge needs it, and with it the part
  covers the whole sheet outline). Vertices on a cut get none: the cut stays open.

Panels are ``panel_thickness`` thick, hinges and patches ``crease_thickness``; with
``align="bottom"`` every region starts at z = 0 (one flat face on the print bed), with
``"middle"`` they are centred on z = 0 (the mid-surface of the mechanics model). The prisms are
unioned with manifold3d in double precision; the result has the volume
``panel_area * panel_thickness + hinge_area * crease_thickness`` (:class:`PrintableLayout`).

:func:`folded_printable_solid` is the same part in the folded state (``pattern.coords``): the
thick panels of :func:`~holofold.geometry.solid.thick_solid` (pulled back by W/2 in 3-D, centred
on the mid-surface) and, across every fold line, the hinge bent: a strip of thickness t_c whose
mid-surface is the quadratic Bezier from one panel's edge over the crease line to the other's
(tangent to both panels; its length is W for a flat crease and, for a fold angle theta, about W
(theta/2) cot(theta/2) of the circular arc: 0.79 W at 90 degrees), swept along the crease and
run a quarter of W into both panels (along their sides, so the run-in stays inside them) so that
the union is one body; the strips are the model's quadrilaterals, not clipped at inward corners
of the outline. It is built from convex slabs (manifold3d hulls) and a union, which is robust;
what it cannot give: a part without overlaps when the thick panels of the folded state run into
each other (:func:`~holofold.geometry.clearance.printability` says by how much; the union then
fuses them and a :class:`~holofold.geometry.solid.SolidWarning` says so), the vertex patches
(the bent strips meet at a vertex in a saddle that no simple solid fills: the vertices stay
open, as in the compliant-crease model), and the exact shape of a warped panel's hinge (the
strip spans the warped prisms' edges, sunk into them).
"""

from __future__ import annotations

from dataclasses import dataclass

import lazy_loader
import numpy as np

from holofold.geometry.errors import (
    DegenerateGeometryError,
    InvalidPatternError,
    ParameterError,
    check_range,
)
from holofold.geometry.pattern import CreasePattern
from holofold.geometry.solid import corner_edges, offset_corners
from holofold.geometry.thick import panel_solids_of

# trimesh (with scipy.spatial and scipy.optimize) costs 0.5-1 s to import; it loads on first use
trimesh = lazy_loader.load("trimesh")

__all__ = [
    "PrintableLayout",
    "printable_layout",
    "printable_solid",
    "folded_printable_solid",
    "folded_printable",
    "HINGE_ASSIGNMENTS",
]

#: assignments that fold through a compliant hinge
HINGE_ASSIGNMENTS = ("M", "V", "F", "U")
#: how far each of two panels joined by a ``J`` edge (a panel split into triangles, the ruling
#: mesh of a curved panel) reaches past it into the other, relative to the part's size: they
#: overlap, so their union is one body whether they lie in one plane (touching only, which a
#: union may keep apart) or bend at the join; 1e-6 (0.2 um on a 200 mm sheet) prints as nothing
JOIN_OVERLAP = 1e-6


def _joins(pattern: CreasePattern) -> np.ndarray:
    """(ne,) bool: the interior ``J`` edges (one panel's triangles joined, no hinge)."""
    return pattern.interior & (np.asarray(pattern.assignment) == "J")


def _join_groups(pattern: CreasePattern) -> np.ndarray:
    """(nf,) label of every face: faces joined across interior ``J`` edges share one."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    nf = pattern.n_faces
    e = np.flatnonzero(_joins(pattern))
    side = corner_edges(pattern, pattern.faces)
    owner = np.repeat(np.arange(nf), [len(f) for f in pattern.faces])
    pairs = [owner[side == k] for k in e]
    pairs = np.array([p[:2] for p in pairs if len(p) >= 2], np.intp).reshape(-1, 2)
    g = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(nf, nf))
    return connected_components(g, directed=False)[1]


def _size(xy) -> float:
    return float(np.ptp(np.asarray(xy), axis=0).max())


@dataclass(frozen=True, eq=False)
class PrintableLayout:
    """The regions of a flat printable part, in the plane of the flat layout (m).

    Attributes
    ----------
    panels : tuple of (k, 2) float
        Pulled-back panel polygons, counter-clockwise, one per face.
    hinges : tuple of (k, 2) float
        Hinge strips, counter-clockwise: quadrilaterals, or pentagons starting at a border vertex
        that clips the strip's end (where the sheet's outline turns inwards).
    hinge_edges : (len(hinges),) int
        The fold edge of each strip (a strip clipped at both ends comes in two halves).
    patches : (npatch, 3, 2) float
        Vertex patches as triangles (vertex, corner, next corner), counter-clockwise.
    """

    panels: tuple[np.ndarray, ...]
    hinges: tuple[np.ndarray, ...]
    hinge_edges: np.ndarray
    patches: np.ndarray

    @property
    def panel_area(self) -> float:
        """Total area of the pulled-back panels, m^2."""
        return float(sum(_area(p) for p in self.panels))

    @property
    def hinge_area(self) -> float:
        """Total area of the hinge strips and vertex patches, m^2."""
        return float(sum(_area(h) for h in self.hinges) + _area(self.patches).sum())

    def volume(self, panel_thickness: float, crease_thickness: float) -> float:
        """Volume of the part, m^3: panel area x panel thickness + hinge area x crease thickness."""
        return self.panel_area * panel_thickness + self.hinge_area * crease_thickness


def _area(poly: np.ndarray) -> np.ndarray | float:
    """Signed shoelace area of (..., k, 2) polygons."""
    x, y = poly[..., 0], poly[..., 1]
    return 0.5 * (x * np.roll(y, -1, axis=-1) - np.roll(x, -1, axis=-1) * y).sum(axis=-1)


def printable_layout(
    pattern: CreasePattern, crease_width, *, cut_width: float | None = None
) -> PrintableLayout:
    """The panels, hinge strips and vertex patches of ``pattern``'s flat layout.

    Parameters
    ----------
    pattern : CreasePattern
        Needs a flat layout (faces counter-clockwise in it).
    crease_width : float or (ne,) float
        Hinge width W of each fold line, m (> 0 on fold lines).
    cut_width : float, optional
        Gap printed along cut lines (C edges), m; default the largest crease width given.
    """
    if pattern.flat is None:
        raise InvalidPatternError("a printable part needs the pattern's flat layout")
    ne = pattern.n_edges
    W = np.broadcast_to(np.asarray(crease_width, float), (ne,)).copy()
    interior = pattern.interior
    hinge = interior & np.isin(pattern.assignment, HINGE_ASSIGNMENTS)
    cut = interior & (pattern.assignment == "C")
    if hinge.any():
        worst = W[hinge][np.argmin(np.where(np.isfinite(W[hinge]), W[hinge], -np.inf))]
        check_range("crease_width", worst, 0.0, None, low_open=True)
    gap = float(W[interior].max(initial=0.0)) if cut_width is None else cut_width
    if cut.any():
        gap = check_range("cut_width", gap, 0.0, None, low_open=True)
    half = np.where(hinge, W / 2, np.where(cut, gap / 2, 0.0))
    half[_joins(pattern)] = -JOIN_OVERLAP * _size(pattern.flat)
    faces = pattern.faces  # counter-clockwise in the flat layout (checked by CreasePattern)
    flat3 = np.column_stack([pattern.flat, np.zeros(pattern.n_vertices)])
    side = corner_edges(pattern, faces)
    S = offset_corners(flat3, faces, half[side])[:, :2]  # (N, 2) pulled-back corners
    sizes = np.array([len(f) for f in faces])
    fv = np.concatenate(faces)
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    nxt = np.arange(len(fv)) + 1
    nxt[starts + sizes - 1] = starts

    # the two corner sides of every edge: first and second occurrence (second = -1 on borders)
    order = np.argsort(side, kind="stable")
    first = np.full(ne, -1)
    second = np.full(ne, -1)
    srt = side[order]
    head = np.concatenate([[True], srt[1:] != srt[:-1]])
    first[srt[head]] = order[head]
    tail = np.flatnonzero(~head)
    second[srt[tail]] = order[tail]
    # hinge strip of edge e (a -> b): side a->b of panel 1 (first), b->a of panel 2 (second)
    he = np.flatnonzero(hinge)
    i1, i2 = first[he], second[he]
    a, b = fv[i1], fv[nxt[i1]]
    A, B = pattern.flat[a], pattern.flat[b]
    S1a, S1b, S2a, S2b = S[i1], S[nxt[i1]], S[nxt[i2]], S[i2]
    ends = np.stack([np.stack([A, S2a, S1a], 1), np.stack([B, S1b, S2b], 1)], 1)  # (nh, 2, 3, 2)
    area = _area(ends)
    scale = max(float(np.ptp(pattern.flat, axis=0).max()), 1e-300)
    tiny = 1e-12 * scale**2
    # between a strip's end and its vertex: a patch (area > 0), unless the vertex is on a cut;
    # at a reflex border vertex the strip's end crosses outside the sheet: the vertex clips it
    on_cut = np.zeros(pattern.n_vertices, bool)
    on_cut[pattern.edges[cut].ravel()] = True
    patches = ends[(area > tiny) & ~on_cut[np.stack([a, b], 1)]]
    clip = area < -tiny
    quads = np.stack([S2a, S2b, S1b, S1a], axis=1)
    some = clip.any(axis=1)
    strips = list(quads[~some])
    for k in np.flatnonzero(some):  # rare: a few border vertices
        q = quads[k]
        if clip[k].all():  # both ends: two halves, each star-shaped from its vertex
            m2, m1 = 0.5 * (q[0] + q[1]), 0.5 * (q[2] + q[3])
            strips += [np.array([A[k], q[0], m2, m1, q[3]]), np.array([B[k], q[2], m1, m2, q[1]])]
        elif clip[k, 0]:
            strips.append(np.array([A[k], q[0], q[1], q[2], q[3]]))
        else:
            strips.append(np.array([B[k], q[2], q[3], q[0], q[1]]))
    edge_of = np.concatenate([he[~some], np.repeat(he[some], np.where(clip[some].all(1), 2, 1))])
    panels = tuple(np.split(S, starts[1:]))
    return PrintableLayout(panels, tuple(strips), edge_of, patches)


def _prisms(polys: list[np.ndarray], z0: float, z1: float) -> list:
    """One manifold3d prism per counter-clockwise polygon (k, 2), from z0 to z1.

    Each polygon must be star-shaped from its first corner (convex ones are): its caps are
    fanned from there.
    """
    import manifold3d as m3d

    out = []
    by_k: dict[int, list[np.ndarray]] = {}
    for p in polys:
        by_k.setdefault(len(p), []).append(p)
    for k, group in by_k.items():
        P = np.asarray(group)  # (n, k, 2)
        n = len(P)
        bot = np.concatenate([P, np.full((n, k, 1), z0)], axis=2)
        top = np.concatenate([P, np.full((n, k, 1), z1)], axis=2)
        verts = np.concatenate([bot, top], axis=1)  # (n, 2k, 3)
        c = np.arange(1, k - 1)
        j = np.arange(k)
        jn = np.roll(j, -1)
        tris = np.vstack([
            np.column_stack([np.zeros(k - 2, int), c + 1, c]),  # bottom, facing -z
            np.column_stack([np.full(k - 2, k), k + c, k + c + 1]),  # top, facing +z
            np.column_stack([j, jn, jn + k]),
            np.column_stack([j, jn + k, j + k]),
        ]).astype(np.uint64)  # fmt: skip
        for v in verts:
            out.append(m3d.Manifold(m3d.Mesh64(vert_properties=np.ascontiguousarray(v),
                                               tri_verts=tris)))  # fmt: skip
    return out


def printable_solid(
    pattern: CreasePattern,
    panel_thickness: float,
    crease_thickness: float,
    crease_width,
    *,
    cut_width: float | None = None,
    align: str = "bottom",
) -> trimesh.Trimesh:
    """The flat printable part of ``pattern``: one watertight solid (metres).

    Parameters
    ----------
    pattern : CreasePattern
        With a flat layout; the part lies in its x-y plane.
    panel_thickness, crease_thickness : float
        t_p and t_c, m (> 0).
    crease_width : float or (ne,) float
        Hinge width W, m.
    cut_width : float, optional
        Gap along cut lines, m (default: the largest W).
    align : {"bottom", "middle"}
        Regions start at z = 0 (print bed) or are centred on z = 0.

    Returns
    -------
    trimesh.Trimesh
        ``metadata["layout"]`` holds the :class:`PrintableLayout`. Raises
        :class:`DegenerateGeometryError` if the union is not one watertight body.
    """
    import manifold3d as m3d

    tp = check_range("panel_thickness", panel_thickness, 0.0, None, low_open=True)
    tc = check_range("crease_thickness", crease_thickness, 0.0, None, low_open=True)
    if align not in ("bottom", "middle"):
        raise ParameterError(f"align must be 'bottom' or 'middle', got {align!r}")
    lay = printable_layout(pattern, crease_width, cut_width=cut_width)

    def z(t):
        return (0.0, t) if align == "bottom" else (-t / 2, t / 2)

    parts = _prisms(list(lay.panels), *z(tp))
    parts += _prisms(list(lay.hinges) + list(lay.patches), *z(tc))
    out = _one_body(m3d.Manifold.batch_boolean(parts, m3d.OpType.Add), "printable part (flat)")
    out.metadata["layout"] = lay
    return out


def _one_body(whole, name: str) -> trimesh.Trimesh:
    """The manifold3d solid as a trimesh (float64), refused unless one watertight body
    (slivers of no volume that a union can leave, below 1e-9 of the whole, are dropped)."""
    import manifold3d as m3d

    pieces = whole.decompose()
    keep = [q for q in pieces if q.volume() > 1e-9 * whole.volume()]
    if 0 < len(keep) < len(pieces):
        whole = m3d.Manifold.batch_boolean(keep, m3d.OpType.Add)
    mesh = whole.to_mesh64()
    out = trimesh.Trimesh(
        vertices=np.asarray(mesh.vert_properties)[:, :3],
        faces=np.asarray(mesh.tri_verts).astype(np.int64),
        process=False,
    )
    bodies = len(whole.decompose())
    if bodies != 1 or not out.is_watertight:
        raise DegenerateGeometryError(
            f"the {name} of this pattern has {bodies} separate bodies (watertight: "
            f"{out.is_watertight}); every panel must be joined to the others through fold lines"
        )
    out.metadata["name"] = name
    return out


def folded_printable_solid(
    pattern: CreasePattern,
    panel_thickness: float,
    crease_thickness: float,
    crease_width,
    *,
    segments: int = 6,
    panels=None,
) -> trimesh.Trimesh:
    """The printable part in the folded state, hinges bent (see the module docstring), metres.

    Parameters
    ----------
    pattern : CreasePattern
        Folded state in ``coords``.
    panel_thickness, crease_thickness : float
        t_p and t_c, m (t_c <= t_p: the hinges run inside the panels).
    crease_width : float or (ne,) float
        W, m (> 0 on fold lines).
    segments : int
        Slabs per bent hinge (>= 1).
    panels : ThickPanels, optional
        Thick panels of another technique (:func:`~holofold.geometry.thick.thick_panels`): its
        panel solids, and the hinges at its reference face (offset) instead of the mid-surface.
    """
    import warnings

    import manifold3d as m3d

    from holofold.geometry.pattern import orient_faces
    from holofold.geometry.solid import SolidWarning

    tp = check_range("panel_thickness", panel_thickness, 0.0, None, low_open=True)
    tc = check_range("crease_thickness", crease_thickness, 0.0, tp, low_open=True)
    n_seg = int(check_range("segments", segments, 1, 64))
    ne = pattern.n_edges
    W = np.broadcast_to(np.asarray(crease_width, float), (ne,)).copy()
    hinge = pattern.interior & np.isin(pattern.assignment, HINGE_ASSIGNMENTS)
    if hinge.any():
        check_range("crease_width", float(W[hinge].min()), 0.0, None, low_open=True)
    faces = orient_faces(pattern.faces)
    side = corner_edges(pattern, faces)
    half = np.where(pattern.interior, W / 2, 0.0)
    half[_joins(pattern)] = -JOIN_OVERLAP * _size(pattern.coords)
    S = offset_corners(pattern.coords, faces, half[side])  # (N, 3) pulled back in 3-D
    sizes = np.array([len(f) for f in faces])
    fv = np.concatenate(faces)
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    nxt = np.arange(len(fv)) + 1
    nxt[starts + sizes - 1] = starts
    normals = np.stack([_unit_normal(S[a : a + k]) for a, k in zip(starts, sizes, strict=True)])
    owner = np.repeat(np.arange(len(faces)), sizes)
    prev = np.empty_like(nxt)
    prev[nxt] = np.arange(len(fv))

    parts = []
    shift = 0.0
    if panels is not None:
        parts = panel_solids_of(pattern, panels)
        shift = panels.side * tc / 2  # the hinge's mid-surface, along the panel normal
    for f, (a, k) in enumerate(zip(starts, sizes, strict=True)):  # the thick panels
        if panels is not None:
            break
        c = S[a : a + k]
        h = normals[f] * tp / 2
        parts.append(m3d.Manifold.hull_points(np.vstack([c + h, c - h])))
    # the two corner sides of every hinge edge (faces consistently oriented: opposite ways)
    order = np.argsort(side, kind="stable")
    srt = side[order]
    head = np.concatenate([[True], srt[1:] != srt[:-1]])
    first = np.full(ne, -1)
    second = np.full(ne, -1)
    first[srt[head]] = order[head]
    second[srt[~head]] = order[~head]
    X = pattern.coords
    knots = np.concatenate([[-1.0], np.linspace(0.0, 1.0, n_seg + 1), [2.0]])
    lo = np.concatenate([knots[:-1] - 0.1 / n_seg])  # each slab overlaps its neighbours
    hi = np.concatenate([knots[1:] + 0.1 / n_seg])
    lo[0], hi[-1] = -1.0, 2.0
    for e in np.flatnonzero(hinge):
        i1, i2 = first[e], second[e]
        va, vb = fv[i1], fv[nxt[i1]]
        d = X[vb] - X[va]
        d = d / np.linalg.norm(d)
        n1, n2 = normals[owner[i1]], normals[owner[i2]]
        curves = []
        # each end: panel 1's corner, panel 2's corner, and for each the direction of its
        # other side (into the panel along its boundary: the run-in stays inside the panel)
        for v, c1, o1, c2, o2 in (
            (va, i1, prev[i1], nxt[i2], nxt[nxt[i2]]),
            (vb, nxt[i1], nxt[nxt[i1]], i2, prev[i2]),
        ):
            p1, p2 = S[c1], S[c2]
            ctrl = X[v] + d * ((0.5 * (p1 + p2) - X[v]) @ d)  # on the crease: tangents meet
            g1 = (S[o1] - p1) / np.linalg.norm(S[o1] - p1)
            g2 = (S[o2] - p2) / np.linalg.norm(S[o2] - p2)
            curves.append((p1, ctrl, p2, g1, g2))

        def point(u, c, w=W[e]):
            """Mid-surface point at u: into panel 1 (u < 0), the bend (0..1), panel 2 (u > 1)."""
            p1, ctrl, p2, g1, g2 = c
            u = np.asarray(u, float)[:, None]
            t = np.clip(u, 0.0, 1.0)
            bend = (1 - t) ** 2 * p1 + 2 * t * (1 - t) * ctrl + t**2 * p2
            return (
                bend
                + np.where(u < 0, -u, 0.0) * 0.25 * w * g1
                + np.where(u > 1, u - 1, 0.0) * 0.25 * w * g2
            )

        for u0, u1 in zip(lo, hi, strict=True):
            u = np.array([u0, u1])
            w_ = np.clip(u, 0.0, 1.0)[:, None]
            nrm = (1 - w_) * n1 + w_ * n2
            unit = nrm / np.linalg.norm(nrm, axis=1, keepdims=True)
            h = unit * tc / 2
            A, B = point(u, curves[0]) + shift * unit, point(u, curves[1]) + shift * unit
            parts.append(m3d.Manifold.hull_points(np.vstack([A + h, A - h, B + h, B - h])))
    # a hull of coplanar points (a hinge slab folded flat onto itself) is a body of no volume
    parts = parts[: len(faces)] + [q for q in parts[len(faces) :] if q.volume() > 0]
    # the triangles of one panel (joined by J edges) first: where the panel bends at a join
    # they overlap there by construction, which is not panels running into each other
    groups = _join_groups(pattern)
    whole_panels = [
        m3d.Manifold.batch_boolean([parts[f] for f in np.flatnonzero(groups == g)], m3d.OpType.Add)
        for g in np.unique(groups)
    ]  # fmt: skip
    total_panels = sum(p.volume() for p in whole_panels)
    panels = m3d.Manifold.batch_boolean(whole_panels, m3d.OpType.Add)
    lost = 1.0 - panels.volume() / total_panels
    if lost > 1e-5:  # (the joins reach 1e-6 of the size past each other)
        warnings.warn(
            f"thick panels intersect in this folded state ({100 * lost:.3g} % of their volume "
            "overlaps): the folded part fuses them",
            SolidWarning,
            stacklevel=2,
        )
    whole = m3d.Manifold.batch_boolean([panels, *parts[len(faces) :]], m3d.OpType.Add)
    return _one_body(whole, "printable part (folded)")


def _unit_normal(corners: np.ndarray) -> np.ndarray:
    from holofold.geometry.pattern import newell_normals

    n = newell_normals(corners, [np.arange(len(corners))])[0]
    return n / np.linalg.norm(n)


def folded_printable(pattern, panel_thickness, crease_thickness, crease_width):
    """:func:`folded_printable_solid`, or None with a warning where it cannot be built (hinges
    thicker than the panels, or no single body): for writers of optional files."""
    import warnings

    if crease_thickness > panel_thickness:
        warnings.warn(
            "no folded printable part: the hinges are thicker than the panels",
            UserWarning,
            stacklevel=2,
        )
        return None
    try:
        return folded_printable_solid(pattern, panel_thickness, crease_thickness, crease_width)
    except DegenerateGeometryError as exc:
        warnings.warn(f"no folded printable part: {exc}", UserWarning, stacklevel=2)
        return None
