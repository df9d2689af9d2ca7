"""Thick panels that keep the zero-thickness kinematics: centred, offset and tapered panels.

Every technique here keeps the hinges on the zero-thickness reference surface (the crease lines
of the pattern's folded state, what the mechanics model simulates), so the thick sheet folds
along exactly the zero-thickness path; they differ in where the panel material sits and how it
is cut back so that neighbours do not collide (Lang et al., Appl. Mech. Rev. 70, 010805, 2018):

* ``centred``: slabs of thickness t centred on the reference surface, pulled back W/2 from each
  crease (what holofold did before: the panels of :func:`~holofold.geometry.solid.thick_solid`).
  They collide near a crease as soon as its fold angle passes atan(W / t)-ish.
* ``offset`` (the offset-panel technique, Edmondson et al. 2014): every panel on one side of the
  reference surface, [0, t] along its normal, so the reference surface is one face of every
  panel and the hinges lie at that face. A fold whose inside is the bare face (the hinge side)
  closes to 180 degrees without collision; at a fold whose inside holds the material, each
  panel is bevelled by the plane that bisects that crease's smallest dihedral angle along the
  fold path, so the two neighbours meet flush there and never overlap before. The side is the
  one that bevels less (``side`` +1: material above the flat layout, hinges on the bed side).
* ``tapered`` (Tachi, "Rigid-foldable thick origami", 2011): slabs centred on the reference
  surface, each half bevelled by the bisecting plane of every crease whose inside it faces.

A bevel through the crease line at half the smallest dihedral angle is the largest cut-back that
is exact for rigid panels: the two bevel planes coincide at that state. It cannot stop panels
that share no crease from running into each other (layers of a compact fold):
:func:`path_overlap` measures the overlap of every pair of panels at every state of a fold path,
and :class:`ThickPanels` says how much of the panel volume each technique keeps.

The folded states of a path are the caller's (``pattern`` objects of one topology, e.g. a Miura
sheet at decreasing extensions, :func:`miura_path`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from holofold.geometry.errors import ParameterError, check_range
from holofold.geometry.pattern import CreasePattern, newell_normals, orient_faces
from holofold.geometry.solid import corner_edges, offset_corners

__all__ = [
    "TECHNIQUES",
    "ThickPanels",
    "thick_panels",
    "panel_solids_of",
    "path_overlap",
    "PathOverlap",
    "miura_path",
    "thick_panel_mesh",
]

#: the thickness-accommodation techniques, by name
TECHNIQUES = ("centred", "offset", "tapered")


@dataclass(frozen=True, eq=False)
class ThickPanels:
    """How the panels of a pattern are thickened (one technique, checked once).

    Attributes
    ----------
    technique : str
        One of :data:`TECHNIQUES`.
    thickness : float
        t, m.
    crease_width : float
        W, m (panels pulled back W/2 from every interior crease).
    side : int
        Where the material sits along each panel's normal: +1 on [0, t], -1 on [-t, 0], 0
        centred on [-t/2, t/2].
    bevel : (ne,) float
        Half the smallest dihedral angle of each crease along the path (radians) where a panel
        is bevelled at it, else nan.
    inside : (ne,) int
        The side of the sheet inside each fold: +1 valleys (towards the normal), -1 mountains,
        0 flat.
    kept : float
        Fraction of the slabs' volume left after the bevels (in the flat layout; 1: none).
    """

    technique: str
    thickness: float
    crease_width: float
    side: int
    bevel: np.ndarray
    inside: np.ndarray
    kept: float = 1.0


def _frames(pattern: CreasePattern, crease_width: float):
    faces = orient_faces(pattern.faces)
    half = np.where(pattern.interior, crease_width / 2.0, 0.0)
    side = corner_edges(pattern, faces)
    C = offset_corners(pattern.coords, faces, half[side])
    sizes = np.array([len(f) for f in faces])
    n = newell_normals(pattern.coords, faces)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return faces, side, np.split(C, np.cumsum(sizes)[:-1]), n


def _orientation(pattern: CreasePattern) -> float:
    """+1 if :func:`orient_faces` keeps the pattern's own face order (the flat layout's
    counter-clockwise faces: normals up), else -1 (then valleys fold towards -normal)."""
    faces = orient_faces(pattern.faces)
    return 1.0 if np.array_equal(faces[0], pattern.faces[0]) else -1.0


def _slabs(pattern: CreasePattern, t: float, W: float, side: int, bevel, inside):
    """manifold3d solids of every panel in ``pattern``'s state (m)."""
    import manifold3d as m3d

    faces, corner_edge, corners, n = _frames(pattern, W)
    z0, z1 = {1: (0.0, t), -1: (-t, 0.0), 0: (-t / 2, t / 2)}[side]
    sgn = _orientation(pattern)
    X = pattern.coords
    out = []
    starts = np.concatenate([[0], np.cumsum([len(f) for f in faces])[:-1]])
    for f, (loop, C) in enumerate(zip(faces, corners, strict=True)):
        solid = m3d.Manifold.hull_points(np.vstack([C + z0 * n[f], C + z1 * n[f]]))
        cen = C.mean(axis=0)
        for j in range(len(loop)):
            e = corner_edge[starts[f] + j]
            beta = bevel[e]
            if not np.isfinite(beta):
                continue
            a, b = X[loop[j]], X[loop[(j + 1) % len(loop)]]
            d = (b - a) / np.linalg.norm(b - a)
            u = cen - a
            u -= d * (u @ d) + n[f] * (u @ n[f])
            u /= np.linalg.norm(u)
            s = inside[e] * sgn * n[f]  # towards the inside of this fold
            m = s * np.cos(beta) - u * np.sin(beta)  # points into the cut-away wedge
            solid = solid.trim_by_plane(tuple(-m), float(-m @ a))
        out.append(solid)
    return out


def thick_panels(
    pattern: CreasePattern,
    thickness: float,
    crease_width: float = 0.0,
    technique: str = "centred",
    *,
    path: Sequence[CreasePattern] = (),
) -> ThickPanels:
    """The thick panels of ``pattern`` by ``technique`` (see the module), for folding along
    ``path`` (states of the same pattern; ``pattern`` itself is always one of them).

    Parameters
    ----------
    pattern : CreasePattern
        The target (most folded) state; M/V from its assignment.
    thickness, crease_width : float
        t > 0 and W >= 0, m.
    technique : str
        One of :data:`TECHNIQUES`.
    path : sequence of CreasePattern
        Other states on the way (their fold angles bound the bevels too).
    """
    if technique not in TECHNIQUES:
        known = ", ".join(TECHNIQUES)
        raise ParameterError(f"unknown thickness technique {technique!r}; known: {known}")
    t = check_range("panel thickness", thickness, 0.0, None, low_open=True)
    W = check_range("crease width", crease_width, 0.0, None)
    ne = pattern.n_edges
    interior = pattern.interior
    fold = np.abs(pattern.fold_angle.astype(float))
    for s in path:
        if s.n_edges != ne or not np.array_equal(s.edges, pattern.edges):
            raise ParameterError("the states of a fold path must share the pattern's edges")
        fold = np.maximum(fold, np.abs(s.fold_angle.astype(float)))
    code = pattern.assignment
    inside = np.where(code == "V", 1, np.where(code == "M", -1, 0)) * interior
    dihedral = np.radians(180.0 - fold)  # interior angle between the panels, at its smallest
    half = np.where(inside != 0, dihedral / 2, np.nan)
    if technique == "centred":
        return ThickPanels("centred", t, W, 0, np.full(ne, np.nan), inside.astype(int))
    if technique == "tapered":
        side = 0
        bevel = half
    else:
        # offset: material on the side that is inside the fewer (and gentler) folds
        cost = {}
        for sd in (1, -1):
            cut = inside == sd
            cost[sd] = float(np.sum(np.where(cut, 1.0 / np.maximum(np.tan(half), 1e-9), 0.0)))
        side = 1 if cost[1] <= cost[-1] else -1
        bevel = np.where(inside == side, half, np.nan)
    flat = _flat_state(pattern)
    full = sum(s.volume() for s in _slabs(flat, t, W, side, np.full(ne, np.nan), inside))
    cut = sum(s.volume() for s in _slabs(flat, t, W, side, bevel, inside))
    # bevels only remove material: above 1 is the clipping's round-off, which for slabs under
    # about 1e-8 m (1e-7 of a 0.1 m sheet) exceeds the bevels' volume (a 1 nm slab gave 110 %)
    kept = min(cut / full, 1.0) if full else 1.0
    return ThickPanels(technique, t, W, side, bevel, inside.astype(int), kept)


def _flat_state(pattern: CreasePattern) -> CreasePattern:
    """The pattern in its flat layout (z = 0), or itself if it has none."""
    if pattern.flat is None:
        return pattern
    from dataclasses import replace

    coords = np.column_stack([pattern.flat, np.zeros(pattern.n_vertices)])
    return replace(pattern, coords=coords)


def panel_solids_of(pattern: CreasePattern, panels: ThickPanels) -> list:
    """The manifold3d solids of every panel of ``panels`` in ``pattern``'s state (m)."""
    return _slabs(pattern, panels.thickness, panels.crease_width, panels.side, panels.bevel,
                  panels.inside)  # fmt: skip


@dataclass(frozen=True)
class PathOverlap:
    """Overlap of thick panels at each state of a fold path.

    ``volume`` (n,) summed pairwise intersection volume, m^3; ``fraction`` (n,) that over the
    panels' volume; ``worst`` (n, 2) the pair with the largest intersection (-1 where none).
    """

    volume: np.ndarray
    fraction: np.ndarray
    worst: np.ndarray


def path_overlap(states: Sequence[CreasePattern], panels: ThickPanels) -> PathOverlap:
    """Pairwise overlap of the thick ``panels`` at every state (bounding boxes, then exact
    manifold3d intersections). Intersections below 1e-9 of a panel's volume (two bevels that
    meet flush, rounding) count as none."""
    vols, fracs, worst = [], [], []
    for state in states:
        solids = panel_solids_of(state, panels)
        boxes = np.array([s.bounding_box() for s in solids])  # (n, 6) min xyz, max xyz
        total = sum(s.volume() for s in solids)
        tol = 1e-9 * total / max(len(solids), 1)
        lo, hi = boxes[:, :3], boxes[:, 3:]
        meet = np.all((lo[:, None] <= hi[None]) & (lo[None] <= hi[:, None]), axis=2)
        i, j = np.nonzero(np.triu(meet, 1))
        v, best, pair = 0.0, 0.0, (-1, -1)
        for a, b in zip(i.tolist(), j.tolist(), strict=True):
            x = (solids[a] ^ solids[b]).volume()
            if x > tol:
                v += x
                if x > best:
                    best, pair = x, (a, b)
        vols.append(v)
        fracs.append(v / total if total else 0.0)
        worst.append(pair)
    return PathOverlap(np.array(vols), np.array(fracs), np.array(worst, int).reshape(-1, 2))


def miura_path(pattern: CreasePattern, steps: int = 10) -> list[CreasePattern]:
    """States of a Miura sheet from flat (ext 1) to ``pattern``'s extension, ``steps`` of them
    evenly spaced in extension (the rigid fold path of :func:`~holofold.geometry.miura_sheet`)."""
    from holofold.geometry.miura import miura_sheet

    meta = pattern.meta
    if meta.get("kind") != "miura":
        raise ParameterError("miura_path needs a Miura sheet (meta kind 'miura')")
    exts = np.linspace(1.0, float(meta["ext"]), int(steps))
    return [
        miura_sheet(meta["m"], meta["n"], meta["a"], meta["b"], meta["gamma"], float(e))
        for e in exts
    ]


def _to_trimesh(solid):
    import trimesh

    mesh = solid.to_mesh64()
    return trimesh.Trimesh(
        vertices=np.asarray(mesh.vert_properties)[:, :3],
        faces=np.asarray(mesh.tri_verts).astype(np.int64),
        process=False,
    )


def thick_panel_mesh(pattern: CreasePattern, panels: ThickPanels):
    """The thick panels in ``pattern``'s state as one ``trimesh.Trimesh`` of loose bodies, m."""
    import manifold3d as m3d

    return _to_trimesh(m3d.Manifold.batch_boolean(panel_solids_of(pattern, panels),
                                                  m3d.OpType.Add))  # fmt: skip
