"""Bar-and-hinge models of a crease pattern: concentrated hinges and compliant creases.

Two builders turn a :class:`~holofold.geometry.pattern.CreasePattern` (in its as-built 3-D
state) and section/material data into a :class:`~holofold.mechanics.structure.Structure`:

* :func:`build_concentrated` -- one rotational spring on every interior crease, panels fanned
  from a centre node (docs/bar-and-hinge.md §3). Used by the single Miura,
  canopy and arch scenarios of the paper.
* :func:`build_compliant` -- creases of finite width W: every panel is shrunk by W/2 next to its
  creases and each crease strip gets 3 nodes, 10 bars, 6 triangles and 8 springs on three spring
  lines (docs/bar-and-hinge.md §4).

Both use the reference simulator's numbering, so node and crease ids of the paper's scripts
carry over (0-based here). Stiffnesses and areas follow docs/bar-and-hinge.md §3.2 and §4.4;
the reference quirks are switched by a :class:`~holofold.mechanics.compat.Profile` (default
:data:`PAPER`). Every spring
rest angle is the dihedral angle measured on the as-built geometry, so the model is exactly
stress free in the state it was built in (docs/bar-and-hinge.md §1.5).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from holofold.geometry.errors import ParameterError, check_range
from holofold.geometry.pattern import CreasePattern
from holofold.mechanics.compat import PAPER, Profile
from holofold.mechanics.springs import dihedral_angle
from holofold.mechanics.structure import (
    COMPLIANT,
    CONCENTRATED,
    BarType,
    CreaseModel,
    SpringRole,
    Structure,
    trusted_structure,
)

__all__ = [
    "build_concentrated",
    "build_concentrated_batch",
    "build_compliant",
    "crease_rest_targets",
    "orient_springs",
]


# --------------------------------------------------------------------------- helpers
def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of (n, 3) arrays (faster than np.cross for small n)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def orient_springs(
    x: np.ndarray, springs: np.ndarray, *, z_only: bool = True, where: np.ndarray | None = None
) -> np.ndarray:
    """Polarity normalisation of docs/bar-and-hinge.md §2.5 (returns a new (ns, 4) array).

    Swaps i and l where the z component of ``(x_j - x_i) x (x_k - x_j)`` is positive, so that
    ``m = r_ij x r_kj`` points to +z (theta > pi when the wings rotate towards +z). With
    ``z_only=False`` a spring whose z component vanishes (relative 1e-12) is judged by the y,
    then the x component instead. ``where`` (ns,) bool limits it to some springs.
    """
    x = np.asarray(x, float)
    return _orient_batch(x[None], springs, z_only, where)[0]


def _orient_batch(x: np.ndarray, springs, z_only: bool, where=None) -> np.ndarray:
    """:func:`orient_springs` of S designs of one connectivity: ``x`` (S, nn, 3), ``springs``
    (ns, 4) -> (S, ns, 4), each design's the one :func:`orient_springs` gives it."""
    springs = np.asarray(springs, dtype=np.intp)
    S = x.shape[0]
    if len(springs) == 0:
        return np.zeros((S, 0, 4), np.intp)
    v = _cross(x[:, springs[:, 1]] - x[:, springs[:, 0]], x[:, springs[:, 2]] - x[:, springs[:, 1]])
    if z_only:
        comp = v[..., 2]
    else:
        tiny = 1e-12 * np.linalg.norm(v, axis=-1)
        vx, vy, vz = v[..., 0], v[..., 1], v[..., 2]
        comp = np.where(np.abs(vz) > tiny, vz, np.where(np.abs(vy) > tiny, vy, vx))
    swap = comp > 0
    if where is not None:
        swap &= np.asarray(where, bool)
    out = np.repeat(springs[None], S, axis=0)
    out[..., 0] = np.where(swap, springs[:, 3], springs[:, 0])
    out[..., 3] = np.where(swap, springs[:, 0], springs[:, 3])
    return out


def _per_item(value, n: int, name: str, where: np.ndarray | None = None) -> np.ndarray:
    """Broadcast a scalar or (n,) array to (n,); check it is finite and > 0 where ``where``."""
    if isinstance(value, int | float) and value > 0 and np.isfinite(value):
        return np.full(n, float(value))
    a = np.asarray(value, dtype=float)
    if a.ndim == 0:
        a = np.full(n, float(a))
    if a.shape != (n,):
        raise ParameterError(f"{name} must be a scalar or have length {n}, got shape {a.shape}")
    sel = np.ones(n, bool) if where is None else where
    bad = np.flatnonzero(sel & ~(np.isfinite(a) & (a > 0)))
    if bad.size:
        k = int(bad[0])
        raise ParameterError(f"{name}[{k}] = {a[k]!r} is outside the allowed range (0, inf)")
    return a


def _scalar(value, name: str, low: float, high: float, *, low_open=False, high_open=False):
    return check_range(name, value, low, high, low_open=low_open, high_open=high_open)


def _flat_faces(pattern: CreasePattern):
    """Concatenated face loops: vertex, face id, position, next and previous corner index."""
    sizes = np.array([len(f) for f in pattern.faces], np.intp)
    verts = np.concatenate(pattern.faces).astype(np.intp)
    start = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    face = np.repeat(np.arange(len(sizes)), sizes)
    pos = np.arange(len(verts)) - start[face]
    nxt = start[face] + (pos + 1) % sizes[face]
    prv = start[face] + (pos - 1) % sizes[face]
    return sizes, verts, start, face, nxt, prv


def _edge_ids(pattern: CreasePattern, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Index in ``pattern.edges`` of the undirected vertex pairs (a, b)."""
    nv = pattern.n_vertices
    keys = pattern.edges[:, 0].astype(np.int64) * nv + pattern.edges[:, 1]
    order = np.argsort(keys)
    q = np.minimum(a, b).astype(np.int64) * nv + np.maximum(a, b)
    pos = np.searchsorted(keys, q, sorter=order)
    pos = np.minimum(pos, len(keys) - 1)
    ids = order[pos]
    if not np.array_equal(keys[ids], q):
        raise ParameterError("a face side is not an edge of the pattern")
    return ids


@dataclass(frozen=True, eq=False)
class PatternTopology:
    """Index arrays of a pattern's faces and edges, the record the builders work over.

    Corners are the face loops concatenated (nc = sum of the face sizes), face by face. All
    arrays are intp except ``interior`` (bool).

    ``sizes`` (nf,) corners per face; ``verts`` (nc,) vertex of each corner; ``face`` (nc,) its
    face; ``nxt``, ``prv`` (nc,) the next and previous corner of its face; ``side`` (nc,) the
    edge joining corner q to the next corner; ``first``, ``last`` (ne,) the first and last face
    visiting each edge (-1 where none); ``interior`` (ne,) edges with two faces;
    ``edge_corners`` (ne, 2) the corners q whose side from the previous corner (``side[prv[q]]``)
    is the edge, the earlier corner first (-1 where the edge has fewer).
    """

    sizes: np.ndarray
    verts: np.ndarray
    face: np.ndarray
    nxt: np.ndarray
    prv: np.ndarray
    side: np.ndarray
    first: np.ndarray
    last: np.ndarray
    interior: np.ndarray
    edge_corners: np.ndarray

    @property
    def n_corners(self) -> int:
        return len(self.verts)


_TOPOLOGY: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def pattern_topology(pattern: CreasePattern) -> PatternTopology:
    """The :class:`PatternTopology` of a pattern (cached per pattern object)."""
    topo = _TOPOLOGY.get(pattern)
    if topo is None:
        sizes, verts, start, face, nxt, prv = _flat_faces(pattern)
        side = _edge_ids(pattern, verts, verts[nxt])
        first, last, count = _edge_faces(pattern, side, face)
        topo = PatternTopology(
            sizes=sizes,
            verts=verts,
            face=face,
            nxt=nxt,
            prv=prv,
            side=side,
            first=first,
            last=last,
            interior=count == 2,
            edge_corners=_edge_corners(side[prv], count),
        )
        _TOPOLOGY[pattern] = topo
    return topo


def _edge_corners(side_in: np.ndarray, count: np.ndarray) -> np.ndarray:
    """(ne, 2): the first two corners q (ascending) with ``side_in[q]`` = the edge, -1 where
    none."""
    ne = len(count)
    order = np.argsort(side_in, kind="stable")  # corners grouped by edge, ascending within
    start = np.concatenate([[0], np.cumsum(count)[:-1]]).astype(np.intp)
    out = np.full((ne, 2), -1, np.intp)
    has1, has2 = count >= 1, count >= 2
    out[has1, 0] = order[start[has1]]
    out[has2, 1] = order[start[has2] + 1]
    return out


def _edge_faces(pattern, side_edge: np.ndarray, side_face: np.ndarray):
    """First and last face visiting each edge, (ne,) each (-1 where none)."""
    ne = pattern.n_edges
    first = np.full(ne, np.iinfo(np.intp).max, np.intp)
    last = np.full(ne, -1, np.intp)
    np.minimum.at(first, side_edge, side_face)
    np.maximum.at(last, side_edge, side_face)
    first[first == np.iinfo(np.intp).max] = -1
    count = np.bincount(side_edge, minlength=ne)
    return first, last, count


def _panel_width(profile, panel_width, crease_width, interior, nf, spoke_len, face_of_spoke):
    """Length scale ``w`` of the panel bending springs, per spoke."""
    if panel_width is not None:
        w = _per_item(panel_width, nf, "panel_width")
        return w[face_of_spoke]
    if profile.panel_spring_width_is_crease_width:
        wi = crease_width[interior]
        w = float(wi.mean()) if wi.size else 1.0
        return np.full(len(spoke_len), w)
    mean_spoke = np.bincount(face_of_spoke, weights=spoke_len, minlength=nf) / np.maximum(
        np.bincount(face_of_spoke, minlength=nf), 1
    )
    return mean_spoke[face_of_spoke]


# --------------------------------------------------------------------------- concentrated
def build_concentrated(
    pattern: CreasePattern,
    *,
    crease_width,
    crease_thickness,
    panel_thickness,
    E_panel: float = 2e9,
    E_crease: float = 2e9,
    nu_panel: float = 0.3,
    nu_crease: float = 0.3,
    panel_width=None,
    profile: Profile = PAPER,
    coords=None,
    supports=None,
) -> Structure:
    """Concentrated-hinge bar-and-hinge model (docs/bar-and-hinge.md §3).

    Parameters
    ----------
    pattern : CreasePattern
        Pattern in its as-built (stress-free) 3-D state, ``nv`` vertices, ``ne`` edges,
        ``nf`` faces.
    crease_width, crease_thickness : float or (ne,) float
        Crease width W and thickness t_c, metres (border edges ignored).
    panel_thickness : float or (nf,) float
        Panel thickness t_p, metres.
    E_panel, E_crease : float
        Young's moduli, Pa. ``E_crease`` enters only the crease springs (the model has no
        crease bars).
    nu_panel, nu_crease : float
        Poisson's ratios (``nu_crease`` is unused here; kept for a uniform signature).
    panel_width : float or (nf,) float, optional
        Length scale ``w`` of the panel bending springs ``k = E_p t_p^3 L / (12 w)``. Default:
        the crease width (``profile.panel_spring_width_is_crease_width``, the paper's
        ``panelW = W``; the mean interior width if W varies) or the panel's mean spoke length.
    profile : Profile
        Quirk switches (:data:`~holofold.mechanics.compat.PAPER` reproduces the published data).
    coords : (nv, 3) float, optional
        Other as-built vertex coordinates for the same faces (default ``pattern.coords``).
        Lets a sweep over fold states (extensions) reuse one validated pattern.
    supports : (nn, 3) or (nv + nf, 3) bool, optional
        Fixed degrees of freedom of the model's nodes, or of the vertices and then the panel
        centres (the rows of panels without a centre must be False; default: none).

    Returns
    -------
    Structure
        Nodes: the ``nv`` vertices, then one centre per panel in panel order
        (``panel_centres``; a triangle panel more slender than
        ``profile.centre_triangle_aspect`` has none, -1, and is one triangle held by its 3
        edge bars). Bars: edge ``i`` is bar ``i`` (type 1), then the spokes panel by panel,
        corner by corner (type 5). Springs: one per interior edge in edge order (role HINGE,
        ``spring_crease`` = edge id; its wing nodes the panels' centres, or a bare triangle's
        opposite corner), then one per spoke (role PANEL). ``creases`` lists the interior
        edges with their hinge springs and end vertices; ``node_vertex`` is the vertex id (-2
        for centres).
    """
    E_panel = _scalar(E_panel, "E_panel", 0.0, None, low_open=True)
    E_crease = _scalar(E_crease, "E_crease", 0.0, None, low_open=True)
    nu_panel = _scalar(nu_panel, "nu_panel", -1.0, 0.5, low_open=True, high_open=True)
    _scalar(nu_crease, "nu_crease", -1.0, 0.5, low_open=True, high_open=True)
    nv, ne, nf = pattern.n_vertices, pattern.n_edges, pattern.n_faces
    interior = pattern_topology(pattern).interior
    W = _per_item(crease_width, ne, "crease_width", interior)
    tc = _per_item(crease_thickness, ne, "crease_thickness", interior)
    tp = _per_item(panel_thickness, nf, "panel_thickness")
    if coords is None:
        X = pattern.coords
    else:
        X = np.asarray(coords, float)
        if X.shape != (nv, 3) or not np.isfinite(X).all():
            raise ParameterError(f"coords must be a finite ({nv}, 3) array, got shape {X.shape}")
    w = None if panel_width is None else _per_item(panel_width, nf, "panel_width")[None]
    (s,) = _concentrated(
        pattern, X[None], W[None], tc[None], tp[None], np.array([E_panel]), np.array([E_crease]),
        nu_panel, w, profile, [supports],
    )  # fmt: skip
    return s


def build_concentrated_batch(
    pattern: CreasePattern,
    coords,
    *,
    crease_width,
    crease_thickness,
    panel_thickness,
    E_panel=2e9,
    E_crease=2e9,
    nu_panel: float = 0.3,
    nu_crease: float = 0.3,
    profile: Profile = PAPER,
    supports=None,
) -> list[Structure]:
    """:func:`build_concentrated` of S designs of one pattern, its arrays computed for all at
    once; each structure is bit for bit the one :func:`build_concentrated` gives the design.

    ``coords`` (S, nv, 3); ``crease_width``, ``crease_thickness``, ``panel_thickness``,
    ``E_panel``, ``E_crease``: a scalar or one per design (S,); ``supports``: None or one
    (nv + nf, 3) mask (or None) per design. A design whose values :func:`build_concentrated`
    refuses raises its error.
    """
    X = np.asarray(coords, float)
    S = X.shape[0]
    nv, ne, nf = pattern.n_vertices, pattern.n_edges, pattern.n_faces
    per = lambda v: np.broadcast_to(np.asarray(v, float), (S,))  # noqa: E731
    W, tc, tp, Ep, Ec = map(
        per, (crease_width, crease_thickness, panel_thickness, E_panel, E_crease)
    )
    ok = X.shape == (S, nv, 3) and np.isfinite(X).all()
    ok = ok and all(np.all(np.isfinite(v) & (v > 0)) for v in (W, tc, tp, Ep, Ec))
    if not ok or not -1.0 < nu_panel < 0.5 or not -1.0 < nu_crease < 0.5:
        return [  # one by one: the error of the first design it refuses
            build_concentrated(
                pattern, coords=X[i], crease_width=float(W[i]), crease_thickness=float(tc[i]),
                panel_thickness=float(tp[i]), E_panel=float(Ep[i]), E_crease=float(Ec[i]),
                nu_panel=nu_panel, nu_crease=nu_crease, profile=profile,
                supports=None if supports is None else supports[i],
            )
            for i in range(S)
        ]  # fmt: skip
    nu_panel = float(nu_panel)
    full = lambda v, n: np.repeat(v[:, None], n, axis=1)  # noqa: E731 - np.full per design
    return _concentrated(
        pattern, X, full(W, ne), full(tc, ne), full(tp, nf), Ep, Ec, nu_panel, None, profile,
        [None] * S if supports is None else list(supports),
    )  # fmt: skip


def _bincount(group: np.ndarray, weights: np.ndarray, n: int) -> np.ndarray:
    """``np.bincount(group, weights[s], minlength=n)`` of every design s, (S, n): one call, the
    same sums (each design's weights added in their order, from 0)."""
    S = weights.shape[0]
    ids = (np.arange(S)[:, None] * n + group[None, :]).ravel()
    return np.bincount(ids, weights=weights.ravel(), minlength=S * n).reshape(S, n)


@dataclass(frozen=True, eq=False)
class ConcentratedLayout:
    """The index arrays of :func:`build_concentrated`'s model of one pattern, the same for every
    design of it (read-only, shared by the structures built from it). ``bars`` (nb, 2),
    ``bar_type`` (nb,) int8, ``quads`` (ns, 4) springs before polarity, ``spring_role`` (ns,)
    int8, ``spring_crease`` (ns,), ``triangles`` (nt, 3), ``tri_crease``, ``tri_panel`` (nt,),
    ``crease_ids`` (nci,) interior edges, ``crease_nodes`` (nci, 2) their end vertices,
    ``panel_centres`` (nf,), ``node_vertex`` (nn,)."""

    bars: np.ndarray
    bar_type: np.ndarray
    quads: np.ndarray
    spring_role: np.ndarray
    spring_crease: np.ndarray
    triangles: np.ndarray
    tri_crease: np.ndarray
    tri_panel: np.ndarray
    crease_ids: np.ndarray
    crease_nodes: np.ndarray
    panel_centres: np.ndarray
    node_vertex: np.ndarray


_LAYOUT: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _frozen(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


def _bare_triangles(pattern: CreasePattern, t: PatternTopology, limit: float) -> np.ndarray:
    """(nf,) bool: triangle panels of aspect (longest side over height, L^2 / (2 A)) above
    ``limit``, measured on the flat layout (else the coordinates); none for ``limit`` inf."""
    bare = np.zeros(len(t.sizes), bool)
    tri = np.flatnonzero(t.sizes == 3)
    if not np.isfinite(limit) or tri.size == 0:
        return bare
    X = pattern.flat if pattern.flat is not None else pattern.coords
    X = np.column_stack([X, np.zeros((len(X), 3 - X.shape[1]))]) if X.shape[1] < 3 else X
    start = np.concatenate([[0], np.cumsum(t.sizes)[:-1]]).astype(np.intp)
    v = t.verts[start[tri][:, None] + np.arange(3)]
    a, b, c = X[v[:, 0]], X[v[:, 1]], X[v[:, 2]]
    area2 = np.linalg.norm(_cross(b - a, c - a), axis=-1)  # twice the area
    L2 = np.max([((b - a) ** 2).sum(-1), ((c - b) ** 2).sum(-1), ((a - c) ** 2).sum(-1)], axis=0)
    with np.errstate(divide="ignore"):
        aspect = np.where(area2 > 0, L2 / np.where(area2 > 0, area2, 1.0), np.inf)
    bare[tri[aspect > limit]] = True
    return bare


def concentrated_layout(
    pattern: CreasePattern, centre_triangle_aspect: float = np.inf
) -> ConcentratedLayout:
    """The :class:`ConcentratedLayout` of a pattern (cached per pattern object and aspect).

    ``centre_triangle_aspect`` (``Profile.centre_triangle_aspect``): a triangle panel whose
    aspect (longest side over height, on the pattern's flat layout, else its coordinates) is
    above it is its own triangle (3 edge bars, no centre node, no spokes, no panel springs; a
    hinge next to it uses the corner opposite the edge as wing node); every other panel gets a
    centre node and a fan (inf: every panel, the reference)."""
    cache = _LAYOUT.get(pattern)
    if cache is None:
        cache = _LAYOUT[pattern] = {}
    key = float(centre_triangle_aspect)
    lay = cache.get(key)
    if lay is not None:
        return lay
    nv, nf = pattern.n_vertices, pattern.n_faces
    t = pattern_topology(pattern)
    verts, face, nxt, prv = t.verts, t.face, t.nxt, t.prv
    centred = ~_bare_triangles(pattern, t, centre_triangle_aspect)
    centre = np.full(nf, -1, np.intp)  # centre node of each panel, -1 for none
    centre[centred] = nv + np.arange(int(centred.sum()))
    qc = centred[face]  # corners of centred panels (the spokes)
    cnode = centre[face]  # centre node of each corner's panel
    # bars: edges, then spokes
    bars = np.vstack([pattern.edges.astype(np.intp), np.column_stack([verts, cnode])[qc]])
    bar_type = np.concatenate(
        [
            np.full(pattern.n_edges, BarType.PANEL_EDGE, np.int8),
            np.full(int(qc.sum()), BarType.PANEL_SPOKE, np.int8),
        ]
    )
    # springs: hinges on interior edges, then panel springs on spokes; the wing node of a
    # hinge is the panel's centre, or in a triangle without one the corner opposite the edge
    cid = np.flatnonzero(t.interior)
    e = pattern.edges[cid].astype(np.intp)
    ec = t.edge_corners[cid]  # the corner ending the edge in the first and in the last panel
    f1, f2 = t.first[cid], t.last[cid]
    w1 = np.where(centred[f1], centre[f1], verts[nxt[ec[:, 0]]])
    w2 = np.where(centred[f2], centre[f2], verts[nxt[ec[:, 1]]])
    hinge = np.column_stack([w1, e[:, 0], e[:, 1], w2])
    panel = np.column_stack([verts[nxt], verts, cnode, verts[prv]])[qc]
    role = np.concatenate(
        [
            np.full(len(cid), SpringRole.HINGE, np.int8),
            np.full(len(panel), SpringRole.PANEL, np.int8),
        ]
    )
    # fan triangles, reference order: (centre, C1, CN), then (centre, Cj, Cj-1); a triangle
    # panel without a centre: (C1, C3, C2) (the fan's orientation), at its first corner
    first = np.zeros(len(verts), bool)
    first[np.concatenate([[0], np.cumsum(t.sizes)[:-1]]).astype(np.intp)] = True
    keep = qc | first
    triangles = np.where(
        qc[:, None],
        np.column_stack([cnode, verts, verts[prv]]),
        np.column_stack([verts, verts[prv], verts[nxt]]),
    )[keep].astype(np.intp)
    fields = dict(
        bars=bars.astype(np.intp),
        bar_type=bar_type,
        quads=np.vstack([hinge, panel]).astype(np.intp),
        spring_role=role,
        spring_crease=np.concatenate([cid, np.full(len(panel), -1)]).astype(np.intp),
        triangles=triangles,
        tri_crease=np.full(len(triangles), -1, np.intp),
        tri_panel=face[keep].astype(np.intp),
        crease_ids=cid,
        crease_nodes=e,
        panel_centres=centre,
        node_vertex=np.concatenate([np.arange(nv), np.full(int(centred.sum()), -2)]).astype(
            np.intp
        ),
    )
    lay = ConcentratedLayout(**{k: _frozen(v) for k, v in fields.items()})
    cache[key] = lay
    return lay


def _concentrated(pattern, X, W, tc, tp, E_panel, E_crease, nu_panel, panel_width, profile, sups):
    """The structures of :func:`build_concentrated` for S designs: ``X`` (S, nv, 3), ``W``,
    ``tc`` (S, ne), ``tp`` (S, nf), ``E_panel``, ``E_crease`` (S,), ``panel_width`` None or
    (S, nf), ``sups`` S supports (or None); values checked by the callers."""
    S = X.shape[0]
    ne, nf = pattern.n_edges, pattern.n_faces
    t = pattern_topology(pattern)
    lay = concentrated_layout(pattern, profile.centre_triangle_aspect)
    sizes, verts, face, nxt = t.sizes, t.verts, t.face, t.nxt
    centred = lay.panel_centres >= 0
    qc = centred[face]  # corners with a spoke
    spoke_face = face[qc]
    side_edge, last, interior = t.side, t.last, t.interior
    bars, cid = lay.bars, lay.crease_ids

    Xv = X[:, verts]
    centres = np.empty((S, nf, 3))
    for c in range(3):  # the mean of each panel's corners, per design
        centres[:, :, c] = _bincount(face, Xv[:, :, c], nf)
    centres = centres / sizes[:, None]
    nodes = np.concatenate([X, centres[:, centred]], axis=1)

    L = np.linalg.norm(nodes[:, bars[:, 1]] - nodes[:, bars[:, 0]], axis=-1)
    edge_len, spoke_len = L[:, :ne], L[:, ne:]

    # panel areas: fan triangles (centre, C_q, C_q+1) (the triangle's own area for one)
    cf = centres[:, face]
    tri_area = 0.5 * np.linalg.norm(_cross(Xv - cf, X[:, verts[nxt]] - cf), axis=-1)
    area = _bincount(face, tri_area, nf)
    # total length of the panel's bars: its sides and its spokes (none in a bare triangle)
    if qc.all():
        perim = _bincount(face, edge_len[:, side_edge] + spoke_len, nf)
    else:
        perim = _bincount(face, edge_len[:, side_edge], nf) + _bincount(spoke_face, spoke_len, nf)
    A_p = 2.0 * tp * area / ((1.0 - nu_panel) * perim)
    bar_area = np.empty((S, len(bars)))
    bar_area[:, ne:] = A_p[:, spoke_face]
    if profile.edge_bar_area_last_panel:
        bar_area[:, :ne] = 2.0 * A_p[:, last]
    else:
        bar_area[:, :ne] = _bincount(side_edge, A_p[:, face], ne)

    k_hinge = E_crease[:, None] * tc[:, cid] ** 3 * edge_len[:, cid] / (12.0 * W[:, cid])
    # edges added by a triangulation (J; the ruling mesh of curved panels): the plate bending
    # of the thinner panel, D = E t^3 / (12 (1 - nu^2)) per unit length over half the distance
    # h1 + h2 (heights 2 A / L of the two panels) between the opposite corners:
    # k = 2 D L / (h1 + h2), exact for cylindrical bending about rungs of a quad strip; the
    # half distance is taken as at least the panel's thickness (a plate does not bend over
    # less than its thickness: a sliver is no stiffer than D L / t)
    jay = np.asarray(pattern.assignment)[cid] == "J"
    if jay.any():
        jc, f1, f2 = cid[jay], t.first[cid[jay]], t.last[cid[jay]]
        Lj = edge_len[:, jc]
        tj = np.minimum(tp[:, f1], tp[:, f2])
        D = E_panel[:, None] * tj**3 / (12.0 * (1 - nu_panel**2))
        half = np.maximum((area[:, f1] + area[:, f2]) / Lj, tj)
        k_hinge[:, jay] = D * Lj / half
    k_panel = E_panel[:, None] * tp[:, spoke_face] ** 3 * spoke_len

    # the checks Structure makes that a valid input can still fail (coordinates that overflow,
    # coincident nodes), once for the batch: the first design refused raises Structure's error
    bad_x = ~np.isfinite(nodes).all(axis=(1, 2))
    bad = np.flatnonzero(bad_x | ~(L > 0).all(axis=1))
    if bad.size:
        i = bad[0]
        if bad_x[i]:
            raise ValueError("nodes contain non-finite coordinates")
        raise ValueError(f"bar {int(np.argmin(L[i]))} has zero rest length")
    nn = nodes.shape[1]
    # per design: spring polarity from its geometry and its rest angles, for all at once
    springs_all = _orient_batch(nodes, lay.quads, profile.polarity_z_only)
    rest_all = dihedral_angle(nodes, springs_all)
    creases = CreaseModel(
        kind=CONCENTRATED, ids=cid, springs=np.arange(len(cid))[:, None], nodes=lay.crease_nodes
    )
    shared = dict(
        bars=bars, bar_type=lay.bar_type, spring_role=lay.spring_role,
        spring_crease=lay.spring_crease, triangles=lay.triangles, tri_crease=lay.tri_crease,
        tri_panel=lay.tri_panel, creases=creases, panel_centres=lay.panel_centres,
        node_vertex=lay.node_vertex, profile=profile,
    )  # fmt: skip
    out = []
    for i in range(S):
        pw = None if panel_width is None else panel_width[i]
        w = _panel_width(profile, pw, W[i], interior, nf, spoke_len[i], spoke_face)
        sup = np.zeros((nn, 3), bool) if sups[i] is None else np.asarray(sups[i], bool)
        sup = _node_supports(sup, nn, pattern.n_vertices, centred)
        out.append(
            trusted_structure(  # the arrays are valid by construction (checked above)
                nodes=nodes[i],
                bar_area=bar_area[i],
                bar_E=np.full(len(bars), E_panel[i]),
                bar_length=L[i],
                springs=springs_all[i],
                spring_k=np.concatenate([k_hinge[i], k_panel[i] / (12.0 * w)]),
                spring_rest=rest_all[i],
                tri_thickness=tp[i, lay.tri_panel],
                supports=sup,
                **shared,
            )
        )
    return out


def _node_supports(sup: np.ndarray, nn: int, nv: int, centred: np.ndarray) -> np.ndarray:
    """(nn, 3) supports from ``sup`` given per node (nn, 3) or per vertex and panel
    (nv + nf, 3): the rows of panels without a centre node dropped (they must be False)."""
    nf = len(centred)
    if sup.shape == (nv + nf, 3) and sup.shape != (nn, 3):
        if sup[nv:][~centred].any():
            raise ValueError("supports fix the centre of a triangle panel, which has none")
        return np.concatenate([sup[:nv], sup[nv:][centred]])
    if sup.shape != (nn, 3):
        raise ValueError(f"supports must have shape ({nn}, 3), got {sup.shape}")
    return sup


# --------------------------------------------------------------------------- compliant
# crease bars 0..9 of a compliant crease: their types and the slots (bars) of its 6 springs
_CREASE_BAR_TYPE = np.array([2, 3, 3, 2, 4, 4, 2, 3, 3, 2], np.int8)
_CREASE_SPRING_BARS = np.array([1, 2, 4, 5, 7, 8], np.intp)
_CREASE_SPRING_ROLE = np.array(
    [
        SpringRole.CREASE_DIAGONAL,
        SpringRole.CREASE_DIAGONAL,
        SpringRole.CREASE_CENTRE,
        SpringRole.CREASE_CENTRE,
        SpringRole.CREASE_DIAGONAL,
        SpringRole.CREASE_DIAGONAL,
    ],  # fmt: skip
    np.int8,
)


def _shrunk_corners(X, t: PatternTopology, W, approximate: bool) -> np.ndarray:
    """(nc, 3) the panel corners moved off their creases by half the crease width
    (docs/bar-and-hinge.md §4.1): along the other side where one side is a crease, by the sum
    of both offsets where both are; corners with collinear sides or no crease stay."""
    verts, nxt, prv = t.verts, t.nxt, t.prv
    e_prev = t.side[prv]  # C(j-1)-C(j)
    e_next = e_prev[nxt]  # C(j)-C(j+1)
    cp, cn = t.interior[e_prev], t.interior[e_next]
    p = X[verts]
    d1 = X[verts[nxt]] - p
    d2 = X[verts[prv]] - p
    with np.errstate(divide="ignore", invalid="ignore"):
        v1 = d1 / np.linalg.norm(d1, axis=1)[:, None]  # towards the next vertex
        v2 = d2 / np.linalg.norm(d2, axis=1)[:, None]  # towards the previous vertex
        sin_b = np.linalg.norm(_cross(v1, v2), axis=1)
        Wp, Wn = W[e_prev][:, None], W[e_next][:, None]
        both = 0.5 * Wn * v2 + 0.5 * Wp * v1
        if not approximate:
            both = both / sin_b[:, None]
        off = np.where(
            (cp & cn)[:, None],
            both,
            np.where(
                cp[:, None], Wp / (2.0 * sin_b[:, None]) * v1, Wn / (2.0 * sin_b[:, None]) * v2
            ),
        )
    moved = (cp | cn) & ~(sin_b <= 1e-12)
    corner = p.copy()
    corner[moved] = p[moved] + off[moved]
    return corner


def build_compliant(
    pattern: CreasePattern,
    *,
    crease_width,
    crease_thickness,
    panel_thickness,
    E_panel: float,
    E_crease: float,
    nu_panel: float,
    nu_crease: float,
    panel_width=None,
    diagonal_rate: float = 4.0,
    split_factor: float = 0.5,
    profile: Profile = PAPER,
) -> Structure:
    """Compliant-crease bar-and-hinge model of finite-width creases (docs/bar-and-hinge.md §4).

    Parameters
    ----------
    pattern : CreasePattern
        As-built pattern (``nv`` vertices, ``ne`` edges, ``nf`` faces); every interior edge
        becomes a compliant crease.
    crease_width, crease_thickness : float or (ne,) float
        Crease width W and thickness t_c, metres (border edges ignored).
    panel_thickness : float or (nf,) float
        Panel thickness t_p, metres.
    E_panel, E_crease : float
        Young's moduli, Pa (panel bars/springs and crease bars/springs).
    nu_panel, nu_crease : float
        Poisson's ratios.
    panel_width : float or (nf,) float, optional
        Length ``w`` of the panel springs ``k = E_p t_p^3 L / (12 w)`` (see
        :func:`build_concentrated`).
    diagonal_rate : float
        Stiffness ratio of the crease diagonal springs to the crease-line springs.
    split_factor : float
        Share f of a crease's fold given to the centre spring line (used by
        :func:`crease_rest_targets`; rest angles here are the measured ones).
    profile : Profile
        Quirk switches.

    Returns
    -------
    Structure
        Nodes: shrunk panel corners panel by panel (one per face corner), then (p1, p2, c) per
        interior crease in crease order, then one centre per panel. Bars: perimeter bars (same
        numbering as the corner nodes), 10 per crease, then the spokes. Springs are ordered by
        the bar they sit on (the reference's slot order). ``creases``: the crease ids, their
        8 springs and 7 nodes (:class:`~holofold.mechanics.structure.CreaseModel`);
        ``node_vertex`` (nn,): vertex id, -1 crease node, -2 centre. With
        ``profile.raw_crease_polarity`` the crease springs keep the reference mesher's raw
        orientation (only panel springs are oriented).
    """
    E_panel = _scalar(E_panel, "E_panel", 0.0, None, low_open=True)
    E_crease = _scalar(E_crease, "E_crease", 0.0, None, low_open=True)
    nu_panel = _scalar(nu_panel, "nu_panel", -1.0, 0.5, low_open=True, high_open=True)
    nu_crease = _scalar(nu_crease, "nu_crease", -1.0, 0.5, low_open=True, high_open=True)
    diagonal_rate = _scalar(diagonal_rate, "diagonal_rate", 0.0, None, low_open=True)
    split_factor = _scalar(split_factor, "split_factor", 0.0, 1.0)
    ne, nf = pattern.n_edges, pattern.n_faces
    t = pattern_topology(pattern)
    sizes, verts, face, nxt, prv = t.sizes, t.verts, t.face, t.nxt, t.prv
    interior = t.interior
    W = _per_item(crease_width, ne, "crease_width", interior)
    tc = _per_item(crease_thickness, ne, "crease_thickness", interior)
    tp = _per_item(panel_thickness, nf, "panel_thickness")
    X = pattern.coords

    # A. shrunk panel copies (one node per corner, numbered like the corners)
    nc0 = len(verts)
    corner = _shrunk_corners(X, t, W, profile.approximate_corner_offset)
    # perimeter bars: bar q joins corner nodes prv[q] and q
    perim = np.sort(np.column_stack([prv, np.arange(nc0)]), axis=1)

    # B. crease regions: 3 nodes, 10 bars, 6 triangles, 6 springs on bars per crease
    cid = np.flatnonzero(interior)
    nci = len(cid)
    b1, b2 = t.edge_corners[cid].T  # earlier panel first (corners are in panel order)
    n11, n12 = perim[b1].T
    n21, n22 = perim[b2].T
    swap = np.linalg.norm(corner[n11] - corner[n21], axis=1) > np.linalg.norm(
        corner[n11] - corner[n22], axis=1
    )
    n21, n22 = np.where(swap, n22, n21), np.where(swap, n21, n22)
    p1 = 0.5 * (corner[n11] + corner[n21])
    p2 = 0.5 * (corner[n12] + corner[n22])
    c = 0.25 * (corner[n11] + corner[n12] + corner[n21] + corner[n22])
    ip1 = nc0 + 3 * np.arange(nci, dtype=np.intp)
    ip2, ic = ip1 + 1, ip1 + 2
    new_nodes = np.stack([p1, p2, c], axis=1).reshape(-1, 3)
    crease_nodes = np.column_stack([n11, n12, n21, n22, ip1, ip2, ic]).astype(np.intp)
    crease_edge_bars = np.column_stack([b1, b2]).astype(np.intp)
    cbars = np.sort(
        np.stack(
            [
                (n11, ip1),
                (n11, ic),
                (n12, ic),
                (n12, ip2),
                (ip1, ic),
                (ip2, ic),
                (n21, ip1),
                (n21, ic),
                (n22, ic),
                (n22, ip2),
            ],  # fmt: skip
            axis=-1,
        ).transpose(1, 2, 0),  # (nci, 10, 2)
        axis=-1,
    ).reshape(-1, 2)
    cbar_type = np.tile(_CREASE_BAR_TYPE, nci)
    # the springs on crease bars 1, 2, 4, 5, 7, 8 of each crease (the reference's slots)
    slot_quads = np.stack(
        [
            (n12, ic, n11, ip1),
            (ip2, ic, n12, n11),
            (n11, ic, ip1, n21),
            (n12, ip2, ic, n22),
            (ip1, ic, n21, n22),
            (ip2, n22, ic, n21),
        ],  # fmt: skip
        axis=-1,
    ).transpose(1, 2, 0)  # (nci, 6, 4)
    ctris = (
        np.stack(
            [
                (ic, ip1, n11),
                (n21, ip1, ic),
                (n21, ic, n22),
                (n22, ip2, ic),
                (n12, ic, ip2),
                (n12, ic, n11),
            ],  # fmt: skip
            axis=-1,
        )
        .transpose(1, 2, 0)
        .reshape(-1, 3)
    )
    n_cnodes = nc0 + 3 * nci

    # C. panel fans (centres of the shrunk panels)
    centres = np.zeros((nf, 3))
    np.add.at(centres, face, corner)
    centres /= sizes[:, None]
    cnode = n_cnodes + face
    nodes = np.vstack([corner, new_nodes, centres])
    spokes = np.column_stack([np.arange(nc0), cnode])
    bars = np.vstack([perim, cbars, spokes]).astype(np.intp)
    L = np.linalg.norm(nodes[bars[:, 1]] - nodes[bars[:, 0]], axis=1)
    nb = len(bars)
    b_crease0 = nc0
    b_spoke0 = nc0 + 10 * nci
    bar_type = np.concatenate(
        [
            np.full(nc0, BarType.PANEL_EDGE, np.int8),
            cbar_type,
            np.full(nc0, BarType.PANEL_SPOKE, np.int8),
        ]
    )

    # springs by slot (bar id)
    cb = b_crease0 + 10 * np.arange(nci)
    slot_spr = np.full((nb, 4), -1, np.intp)
    slot_spr[b1] = np.column_stack([ic, n11, n12, cnode[b1]])
    slot_spr[b2] = np.column_stack([ic, n22, n21, cnode[b2]])
    slot_spr[(cb[:, None] + _CREASE_SPRING_BARS).ravel()] = slot_quads.reshape(-1, 4)
    slot_spr[b_spoke0:] = np.column_stack([prv, np.arange(nc0), cnode, nxt])
    slots = np.flatnonzero(slot_spr[:, 0] >= 0)
    slot_to_spring = np.full(nb, -1, np.intp)
    slot_to_spring[slots] = np.arange(len(slots))
    crease_springs = np.zeros((nci, 8), np.intp)
    crease_springs[:, :2] = slot_to_spring[crease_edge_bars]
    crease_springs[:, 2:] = slot_to_spring[cb[:, None] + _CREASE_SPRING_BARS]
    orient = np.ones(len(slots), bool)
    if profile.raw_crease_polarity:  # the reference's raw crease springs (compat)
        orient[crease_springs.ravel()] = False
    springs = orient_springs(nodes, slot_spr[slots], z_only=profile.polarity_z_only, where=orient)

    # stiffness and areas
    ell = L[crease_edge_bars[:, 0]]
    Wc, tcc = W[cid], tc[cid]
    k1 = E_crease * tcc**3 / (4.0 * Wc)
    spring_k = np.zeros(len(slots))
    role = np.full(len(slots), SpringRole.PANEL, np.int8)
    crease_of = np.full(len(slots), -1, np.intp)
    spring_k[crease_springs[:, :2]] = (k1[:, None] * L[crease_edge_bars]).reshape(nci, 2)
    role[crease_springs[:, :2]] = SpringRole.CREASE_EDGE
    rate = np.where(_CREASE_SPRING_ROLE == SpringRole.CREASE_DIAGONAL, diagonal_rate, 1.0)
    spring_k[crease_springs[:, 2:]] = rate * k1[:, None] * L[cb[:, None] + _CREASE_SPRING_BARS]
    role[crease_springs[:, 2:]] = _CREASE_SPRING_ROLE
    crease_of[crease_springs.ravel()] = np.repeat(cid, 8)
    spk_slots = slots >= b_spoke0
    spoke_len = L[b_spoke0:]
    w = _panel_width(profile, panel_width, W, interior, nf, spoke_len, face)
    spring_k[spk_slots] = E_panel * tp[face] ** 3 * spoke_len / (12.0 * w)

    tri_area = 0.5 * np.linalg.norm(
        np.cross(corner - centres[face], corner[nxt] - centres[face]), axis=1
    )
    area = np.bincount(face, weights=tri_area, minlength=nf)
    per = np.bincount(face, weights=L[:nc0] + spoke_len, minlength=nf)
    A_p = 2.0 * tp * area / ((1.0 - nu_panel) * per)
    bar_area = np.zeros(nb)
    bar_area[:nc0] = A_p[face]
    bar_area[b_spoke0:] = A_p[face]
    A1 = ell * tcc / (2.0 * (1.0 - nu_crease**2))
    A2 = (ell**2 + Wc**2) ** 1.5 * tcc / (4.0 * (1.0 + nu_crease) * ell * Wc)
    bar_area[b_crease0:b_spoke0] = np.where(
        _CREASE_BAR_TYPE == BarType.CREASE_ACROSS, A1[:, None], A2[:, None]
    ).ravel()
    bar_E = np.where(np.isin(bar_type, (1, 5)), E_panel, E_crease)

    triangles = np.vstack([ctris, np.column_stack([cnode, np.arange(nc0), nxt])]).astype(np.intp)
    nct = 6 * nci
    node_vertex = np.concatenate([verts, np.full(3 * nci, -1), np.full(nf, -2)])
    return Structure(
        nodes=nodes,
        bars=bars,
        bar_area=bar_area,
        bar_E=bar_E,
        bar_length=L,
        bar_type=bar_type,
        springs=springs,
        spring_k=spring_k,
        spring_rest=dihedral_angle(nodes, springs),
        spring_role=role,
        spring_crease=crease_of,
        triangles=triangles,
        tri_thickness=np.concatenate([np.repeat(tcc, 6), tp[face]]),
        tri_crease=np.concatenate([np.repeat(cid, 6), np.full(nc0, -1)]),
        tri_panel=np.concatenate([np.full(nct, -1), face]),
        creases=CreaseModel(
            kind=COMPLIANT,
            ids=cid,
            springs=crease_springs,
            nodes=crease_nodes,
            split_factor=split_factor,
        ),
        panel_centres=n_cnodes + np.arange(nf),
        node_vertex=node_vertex,
        profile=profile,
    )


def crease_rest_targets(structure: Structure, crease_angle, *, profile: Profile | None = None):
    """Spring rest angles that make each crease's stress-free fold angle ``crease_angle``.

    Parameters
    ----------
    structure : Structure
        Built by :func:`build_concentrated` or :func:`build_compliant`.
    crease_angle : (ne,) float
        Crease-level rest angle per pattern edge, rad (pi = flat, the spring convention);
        border edges are ignored.
    profile : Profile, optional
        Defaults to the structure's. With ``reset_non_crease_rest_angles`` (the reference,
        docs/bar-and-hinge.md §4.5) every other spring (panel, diagonal) is set to pi; otherwise it
        keeps its current rest angle.

    Returns
    -------
    (ns,) float
        Compliant creases: the two edge springs get ``pi + (1 - f)/2 (theta_c - pi)`` and the
        two centre springs ``pi + f (theta_c - pi)`` (f = ``creases.split_factor``);
        concentrated hinges get ``theta_c``.
    """
    profile = profile or structure.profile
    creases = structure.creases
    if creases is None:
        raise ValueError("the structure has no crease model (build it with holofold.mechanics)")
    theta = np.asarray(crease_angle, float)
    out = (
        np.full(len(structure.springs), np.pi)
        if profile.reset_non_crease_rest_angles
        else structure.spring_rest.copy()
    )
    tc = theta[creases.ids]
    cs = creases.springs
    if creases.compliant:
        f = float(creases.split_factor)
        out[cs[:, 0]] = out[cs[:, 1]] = np.pi + 0.5 * (1.0 - f) * (tc - np.pi)
        out[cs[:, 4]] = out[cs[:, 5]] = np.pi + f * (tc - np.pi)
    else:
        out[cs[:, 0]] = tc
    return out
