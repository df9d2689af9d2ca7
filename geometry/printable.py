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
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh

from holofold.geometry.errors import (
    DegenerateGeometryError,
    InvalidPatternError,
    ParameterError,
    check_range,
)
from holofold.geometry.pattern import CreasePattern
from holofold.geometry.solid import corner_edges, offset_corners

__all__ = ["PrintableLayout", "printable_layout", "printable_solid", "HINGE_ASSIGNMENTS"]

#: assignments that fold through a compliant hinge
HINGE_ASSIGNMENTS = ("M", "V", "F", "U")


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
    whole = m3d.Manifold.batch_boolean(parts, m3d.OpType.Add)
    mesh = whole.to_mesh64()
    out = trimesh.Trimesh(
        vertices=np.asarray(mesh.vert_properties)[:, :3],
        faces=np.asarray(mesh.tri_verts).astype(np.int64),
        process=False,
    )
    bodies = len(whole.decompose())
    if bodies != 1 or not out.is_watertight:
        raise DegenerateGeometryError(
            f"the printable part of this pattern has {bodies} separate bodies (watertight: "
            f"{out.is_watertight}); every panel must be joined to the others through fold lines"
        )
    out.metadata["layout"] = lay
    out.metadata["name"] = "printable part (flat)"
    return out
