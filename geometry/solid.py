"""Thick panels for 3-D printing: one prism per panel, hinge gaps at the creases.

Each panel is pulled back from every interior crease by half the crease width ``W`` (border
edges stay), then thickened by ``t_p`` about its mid-surface along the panel normal. The
pull-back is done in the panel's own plane: every corner moves to the intersection of its two
offset edge lines, so the gap between neighbouring panels is exactly ``W`` in the flat state. A
warped (non-planar) panel is shrunk in its best-fit plane and keeps its warp; its caps are
fanned from their centre. Panels must be convex (every generator of holofold gives convex
panels); a crease wider than a panel allows raises :class:`ParameterError`.

The prisms are unioned with manifold3d into one watertight solid (disjoint pieces stay
separate bodies of the same mesh), or returned one per panel. When panels overlap in the folded
state (too thick for their hinge gaps at that fold angle) a :class:`SolidWarning` says by how
much.
"""

from __future__ import annotations

import warnings

import lazy_loader
import numpy as np

from holofold.geometry.errors import DegenerateGeometryError, ParameterError
from holofold.geometry.pattern import CreasePattern, newell_normals, orient_faces

# trimesh (with scipy.spatial and scipy.optimize) costs 0.5-1 s to import; it loads on first use
trimesh = lazy_loader.load("trimesh")

__all__ = [
    "shrunk_panels",
    "offset_corners",
    "corner_edges",
    "panel_solids",
    "thick_solid",
    "SolidWarning",
]


class SolidWarning(UserWarning):
    """The thick panels of a folded state overlap (the part would not print as designed)."""


def corner_edges(pattern: CreasePattern, faces) -> np.ndarray:
    """Edge id (N,) of the side leaving each corner of ``faces`` (flattened loops, in order)."""
    fv = np.concatenate(faces)
    sizes = np.array([len(f) for f in faces])
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    nxt = np.arange(len(fv)) + 1
    nxt[starts + sizes - 1] = starts
    nv = np.int64(pattern.n_vertices)
    keys = pattern.edges[:, 0] * nv + pattern.edges[:, 1]
    order = np.argsort(keys)
    side = np.minimum(fv, fv[nxt]) * nv + np.maximum(fv, fv[nxt])
    return order[np.searchsorted(keys[order], side)]


def offset_corners(coords: np.ndarray, faces, inset: np.ndarray) -> np.ndarray:
    """Corners (N, 3) of every polygon after moving each side inwards in the polygon's plane.

    Parameters
    ----------
    coords : (nv, 3) float
        Vertex coordinates, m.
    faces : sequence of (k,) int
        Loops, each counter-clockwise about its own (Newell) normal.
    inset : (N,) float
        Inward offset of the side leaving each corner (flattened loops), m.

    Every corner moves to the intersection of its two offset side lines, so the offset sides stay
    parallel to the old ones at exactly their inset; a warped polygon is offset in its best-fit
    plane and keeps its warp. A straight corner (a T-junction) moves inward by the larger of its
    two insets. Raises :class:`ParameterError` for a polygon that vanishes.
    """
    faces = [np.asarray(f, np.int64) for f in faces]
    fv = np.concatenate(faces)
    sizes = np.array([len(f) for f in faces])
    owner = np.repeat(np.arange(len(faces)), sizes)
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    nxt = np.arange(len(fv)) + 1
    nxt[starts + sizes - 1] = starts
    prev = np.empty_like(nxt)
    prev[nxt] = np.arange(len(fv))
    p = np.asarray(coords, float)[fv]
    n = newell_normals(coords, faces)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    cen = np.stack([np.bincount(owner, weights=p[:, d]) for d in range(3)], 1) / sizes[:, None]
    u = p[starts + 1] - p[starts]
    u -= n * np.einsum("ij,ij->i", u, n)[:, None]
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    v = np.cross(n, u)
    rel = p - cen[owner]
    q = np.column_stack(
        [np.einsum("ij,ij->i", rel, u[owner]), np.einsum("ij,ij->i", rel, v[owner])]
    )
    e = q[nxt] - q
    t = e / np.linalg.norm(e, axis=1, keepdims=True)
    inward = np.column_stack([-t[:, 1], t[:, 0]])  # left of a counter-clockwise side
    d = np.asarray(inset, float)
    # corner j joins side j-1 (into j) and side j (out of j): intersect the offset lines
    a1, d1, o1 = t[prev], inward[prev], d[prev]
    a2, d2, o2 = t, inward, d
    cross = a1[:, 0] * a2[:, 1] - a1[:, 1] * a2[:, 0]
    flat = np.abs(cross) < 1e-12
    back = flat & (np.einsum("ij,ij->i", a1, a2) < 0)
    if back.any():
        raise ParameterError(
            f"panel {int(owner[np.flatnonzero(back)[0]])} folds back on itself at a corner "
            "(two consecutive sides run in opposite directions); cannot offset it"
        )
    diff = o2[:, None] * d2 - o1[:, None] * d1
    s = (diff[:, 0] * a2[:, 1] - diff[:, 1] * a2[:, 0]) / np.where(flat, 1.0, cross)
    shift = o1[:, None] * d1 + s[:, None] * a1
    # a straight corner (a crease ending on the side of this panel, a T-junction) has no
    # intersection of the two offset lines: it moves inward by the larger of the two insets,
    # so the pulled-back panel never reaches over either crease strip
    shift[flat] = np.maximum(o1, o2)[flat, None] * d2[flat]
    q2 = q + shift
    e2 = q2[nxt] - q2
    area = 0.5 * np.bincount(owner, weights=q2[:, 0] * q2[nxt, 1] - q2[nxt, 0] * q2[:, 1])
    bad = (area <= 0) | (np.bincount(owner, weights=np.einsum("ij,ij->i", e2, e) <= 0) > 0)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ParameterError(
            f"crease width up to {2 * d[owner == k].max():.6g} m is wider than panel {k} allows "
            "(the panel vanishes after the hinge-gap pull-back)"
        )
    return p + shift[:, :1] * u[owner] + shift[:, 1:] * v[owner]


def shrunk_panels(pattern: CreasePattern, crease_width) -> list[np.ndarray]:
    """Corner coordinates (k, 3) of every panel after the hinge-gap pull-back.

    ``crease_width`` is a scalar or one value per edge (m); only interior edges are pulled
    back, by half their width.
    """
    W = np.broadcast_to(np.asarray(crease_width, float), (pattern.n_edges,))
    if not np.isfinite(W).all() or (W < 0).any():
        raise ParameterError(f"crease width must be finite and >= 0, got {W.min()!r}")
    half = np.where(pattern.interior, W / 2.0, 0.0)
    faces = orient_faces(pattern.faces)
    corners = offset_corners(pattern.coords, faces, half[corner_edges(pattern, faces)])
    return np.split(corners, np.cumsum([len(f) for f in faces])[:-1])


def _prism(corners: np.ndarray, thickness: float) -> trimesh.Trimesh:
    k = len(corners)
    nrm = newell_normals(corners, [np.arange(k)])[0]
    n = nrm / np.linalg.norm(nrm)
    c = corners.mean(axis=0)
    top = corners + n * thickness / 2
    bot = corners - n * thickness / 2
    verts = np.vstack([top, bot, c + n * thickness / 2, c - n * thickness / 2])
    j = np.arange(k)
    jn = np.roll(j, -1)
    ct, cb = 2 * k, 2 * k + 1
    tris = [
        np.column_stack([j, jn, np.full(k, ct)]),  # top cap, outward +n
        np.column_stack([jn + k, j + k, np.full(k, cb)]),  # bottom cap, outward -n
        np.column_stack([j, j + k, jn + k]),  # sides
        np.column_stack([j, jn + k, jn]),
    ]
    return trimesh.Trimesh(vertices=verts, faces=np.vstack(tris), process=False)


def panel_solids(pattern: CreasePattern, thickness, crease_width) -> list[trimesh.Trimesh]:
    """One closed prism per panel (thickness scalar or per panel, m)."""
    t = np.broadcast_to(np.asarray(thickness, float), (pattern.n_faces,))
    if not np.isfinite(t).all() or (t <= 0).any():
        raise ParameterError(f"panel thickness must be finite and > 0, got {t.min()!r}")
    return [
        _prism(c, float(tk)) for c, tk in zip(shrunk_panels(pattern, crease_width), t, strict=True)
    ]


def thick_solid(
    pattern: CreasePattern, thickness, crease_width, *, union: bool = True
) -> trimesh.Trimesh | list[trimesh.Trimesh]:
    """Printable solid of the folded pattern: the panel prisms unioned with manifold3d.

    With ``union=False`` the list of per-panel prisms is returned instead.
    """
    solids = panel_solids(pattern, thickness, crease_width)
    if not union:
        return solids
    import manifold3d as m3d

    parts = [
        m3d.Manifold(m3d.Mesh(vert_properties=np.asarray(s.vertices, np.float32),
                              tri_verts=np.asarray(s.faces, np.uint32)))
        for s in solids
    ]  # fmt: skip
    whole = m3d.Manifold.batch_boolean(parts, m3d.OpType.Add)
    total = sum(p.volume() for p in parts)
    lost = 1.0 - whole.volume() / total if total > 0 else 0.0
    if lost > 1e-6:
        warnings.warn(
            f"thick panels intersect in this folded state ({100 * lost:.3g} % of their volume "
            "overlaps): use thinner panels or wider creases for a printable part",
            SolidWarning,
            stacklevel=2,
        )
    mesh = whole.to_mesh()
    out = trimesh.Trimesh(
        vertices=np.asarray(mesh.vert_properties)[:, :3], faces=np.asarray(mesh.tri_verts)
    )
    if not out.is_watertight:
        raise DegenerateGeometryError(
            "the thick panels of this folded state overlap so much that their union is not a "
            f"watertight solid ({100 * lost:.3g} % of the volume overlaps); use thinner panels, "
            "wider creases or a less folded state"
        )
    return out
