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

import numpy as np
import trimesh

from holofold.geometry.errors import DegenerateGeometryError, ParameterError
from holofold.geometry.pattern import CreasePattern, newell_normals, orient_faces

__all__ = ["shrunk_panels", "panel_solids", "thick_solid", "SolidWarning"]


class SolidWarning(UserWarning):
    """The thick panels of a folded state overlap (the part would not print as designed)."""


def _edge_index(pattern: CreasePattern) -> dict[tuple[int, int], int]:
    return {(int(a), int(b)): i for i, (a, b) in enumerate(pattern.edges)}


def shrunk_panels(pattern: CreasePattern, crease_width) -> list[np.ndarray]:
    """Corner coordinates (k, 3) of every panel after the hinge-gap pull-back.

    ``crease_width`` is a scalar or one value per edge (m); only interior edges are pulled
    back, by half their width.
    """
    W = np.broadcast_to(np.asarray(crease_width, float), (pattern.n_edges,))
    if not np.isfinite(W).all() or (W < 0).any():
        raise ParameterError(f"crease width must be finite and >= 0, got {W.min()!r}")
    half = np.where(pattern.interior, W / 2.0, 0.0)
    index = _edge_index(pattern)
    faces = orient_faces(pattern.faces)
    normals = newell_normals(pattern.coords, faces)
    out = []
    for k, (f, nrm) in enumerate(zip(faces, normals, strict=True)):
        p = pattern.coords[f]
        n = nrm / np.linalg.norm(nrm)
        c = p.mean(axis=0)
        u = p[1] - p[0]
        u -= n * (u @ n)
        u /= np.linalg.norm(u)
        v = np.cross(n, u)
        q = np.column_stack([(p - c) @ u, (p - c) @ v])  # in-plane, counter-clockwise
        nxt = np.roll(np.arange(len(f)), -1)
        d = np.array(
            [half[index[tuple(sorted((int(f[j]), int(f[nxt[j]]))))]] for j in range(len(f))]
        )
        e = q[nxt] - q
        t = e / np.linalg.norm(e, axis=1, keepdims=True)
        inward = np.column_stack([-t[:, 1], t[:, 0]])  # left of a counter-clockwise edge
        # corner j joins edge j-1 (into j) and edge j (out of j): intersect the offset lines
        prev = np.roll(np.arange(len(f)), 1)
        a1, d1, o1 = t[prev], inward[prev], d[prev]
        a2, d2, o2 = t, inward, d
        cross = a1[:, 0] * a2[:, 1] - a1[:, 1] * a2[:, 0]
        if (np.abs(cross) < 1e-12).any():
            raise ParameterError(f"panel {k} has collinear consecutive edges; cannot offset it")
        # point = q + o1*d1 + s*a1 = q + o2*d2 + r*a2 -> solve for s
        diff = o2[:, None] * d2 - o1[:, None] * d1
        s = (diff[:, 0] * a2[:, 1] - diff[:, 1] * a2[:, 0]) / cross
        shift = o1[:, None] * d1 + s[:, None] * a1
        q2 = q + shift
        e2 = q2[nxt] - q2
        area = 0.5 * np.sum(q2[:, 0] * q2[nxt, 1] - q2[nxt, 0] * q2[:, 1])
        if area <= 0 or (np.einsum("ij,ij->i", e2, e) <= 0).any():
            raise ParameterError(
                f"crease width up to {2 * d.max():.6g} m is wider than panel {k} allows "
                "(the panel vanishes after the hinge-gap pull-back)"
            )
        out.append(p + shift[:, :1] * u + shift[:, 1:] * v)
    return out


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
