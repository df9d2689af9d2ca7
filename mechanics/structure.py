"""The structural model: nodes, bars, rotational springs, triangles, supports (numpy arrays).

A :class:`Structure` is what the element kernels, the assembly and the solvers consume. It is
built from a crease pattern by :mod:`holofold.mechanics.hinges` (concentrated hinges or compliant
creases), but any code may build one directly::

    nodes          (nn, 3) float   reference coordinates X, metres
    bars           (nb, 2) int     node pairs (smaller id first)
    bar_area       (nb,) float     cross-section area A, m^2
    bar_E          (nb,) float     Young's modulus, Pa (St Venant-Kirchhoff, Green-Lagrange strain)
    bar_length     (nb,) float     rest length L0, m (defaults to |X_b - X_a|)
    bar_type       (nb,) int8      1 panel edge, 2/3/4 crease (across / diagonal / centre line),
                                   5 panel spoke (centre to corner)
    springs        (ns, 4) int     4-node rotational springs (i, j, k, l); hinge axis j-k
    spring_k       (ns,) float     rotational stiffness, N m / rad
    spring_rest    (ns,) float     rest (stress-free) dihedral angle, rad, in [0, 2 pi); pi = flat
    spring_role    (ns,) int8      see :class:`SpringRole`
    spring_crease  (ns,) int       index of the pattern edge (crease) the spring models, -1 if none
    supports       (nn, 3) bool    True where a degree of freedom is fixed
    triangles      (nt, 3) int     mesh triangles (mass, heat conduction, plotting)
    tri_thickness  (nt,) float     thickness of each triangle, m
    tri_crease     (nt,) int       crease id of a crease-region triangle, -1 for panel triangles
    tri_panel      (nt,) int       panel id of a panel triangle, -1 for crease triangles
    creases        CreaseModel     how the pattern's interior creases are modelled (or None)
    panel_centres  (nf,) int       centre node of each panel, -1 for none (or None)
    node_vertex    (nn,) int       pattern vertex of each node: -1 crease node, -2 panel centre
                                   (or None)
    profile        Profile         the paper-compatibility switches the model was built with

Supports and loads are chosen by node: :meth:`Structure.fixed` fixes the DOFs of named nodes
and :meth:`Structure.vertex_nodes` gives the nodes standing for a pattern vertex.

Degrees of freedom are interleaved per node: node ``n`` owns DOFs ``3n, 3n+1, 3n+2`` (x, y, z).
Displacements are ``(nn, 3)`` arrays relative to ``nodes``.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, replace
from enum import IntEnum
from functools import cached_property

import numpy as np

from holofold.mechanics.compat import PAPER, Profile

__all__ = [
    "Structure",
    "CreaseModel",
    "SpringRole",
    "BarType",
    "CONCENTRATED",
    "COMPLIANT",
    "support_mask",
]

CONCENTRATED = "concentrated"
COMPLIANT = "compliant"


class BarType(IntEnum):
    PANEL_EDGE = 1
    CREASE_ACROSS = 2
    CREASE_DIAGONAL = 3
    CREASE_CENTRE = 4
    PANEL_SPOKE = 5


class SpringRole(IntEnum):
    HINGE = 0  #: concentrated crease hinge (one spring per interior crease)
    PANEL = 1  #: panel bending spring on a spoke
    CREASE_EDGE = 2  #: compliant crease: spring on one of the two crease edge lines
    CREASE_CENTRE = 3  #: compliant crease: spring on the crease centre line
    CREASE_DIAGONAL = 4  #: compliant crease: diagonal (torsion/bending) spring


def _arr(x, dtype, shape_tail, name, n=None):
    a = np.asarray(x, dtype=dtype)
    if a.size == 0:
        a = a.reshape((0, *shape_tail))
    if a.ndim != 1 + len(shape_tail) or a.shape[1:] != tuple(shape_tail):
        raise ValueError(
            f"{name} must have shape (n, {', '.join(map(str, shape_tail))}), got {a.shape}"
        )
    if n is not None and len(a) != n:
        raise ValueError(f"{name} must have {n} rows, got {len(a)}")
    return a


def _set_rows(obj, name: str, dtype, fill, n: int) -> None:
    """Set the frozen field ``name`` of ``obj`` to its (n,) array of ``dtype`` (checked by
    :func:`_arr`), ``fill`` in every row where the field is None."""
    x = getattr(obj, name)
    rows = np.full(n, fill, dtype) if x is None else _arr(x, dtype, (), name, n)
    object.__setattr__(obj, name, rows)


@dataclass(frozen=True, eq=False)
class CreaseModel:
    """How a :class:`Structure` models the pattern's interior creases (docs/bar-and-hinge.md §3-4).

    Attributes
    ----------
    kind : {"concentrated", "compliant"}
        One rotational spring per crease, or a crease strip of finite width.
    ids : (nci,) int
        Pattern edge id of each modelled crease, increasing.
    springs : (nci, 1) or (nci, 8) int
        Spring ids per crease. Concentrated: the hinge spring. Compliant: [edge line 1, edge
        line 2, diagonal N11-c, diagonal N12-c, centre p1-c, centre p2-c, diagonal N21-c,
        diagonal N22-c].
    nodes : (nci, 2) or (nci, 7) int
        Model nodes per crease. Concentrated: the two end vertices of the hinge line.
        Compliant: [N11, N12, N21, N22, p1, p2, c] (the corners of the two shrunk panels on
        the crease, its centre-line end nodes and its centre node).
    split_factor : float
        Compliant: the share f of a crease's fold carried by its centre spring line.
    """

    kind: str
    ids: np.ndarray
    springs: np.ndarray
    nodes: np.ndarray
    split_factor: float = 0.5

    def __post_init__(self):
        if self.kind not in (CONCENTRATED, COMPLIANT):
            raise ValueError(f"kind = {self.kind!r}; allowed: {CONCENTRATED!r}, {COMPLIANT!r}")
        ids = np.asarray(self.ids, np.intp).reshape(-1)
        width = (1, 2) if self.kind == CONCENTRATED else (8, 7)
        springs = np.asarray(self.springs, np.intp).reshape(len(ids), width[0])
        nodes = np.asarray(self.nodes, np.intp).reshape(len(ids), width[1])
        object.__setattr__(self, "ids", ids)
        object.__setattr__(self, "springs", springs)
        object.__setattr__(self, "nodes", nodes)

    @property
    def compliant(self) -> bool:
        return self.kind == COMPLIANT

    def __len__(self) -> int:
        return len(self.ids)


@dataclass(frozen=True, eq=False)
class Structure:
    """Bar-and-hinge model; see the module docstring for every array's meaning and shape."""

    nodes: np.ndarray
    bars: np.ndarray
    bar_area: np.ndarray
    bar_E: np.ndarray
    springs: np.ndarray
    spring_k: np.ndarray
    spring_rest: np.ndarray
    bar_length: np.ndarray | None = None
    bar_type: np.ndarray | None = None
    spring_role: np.ndarray | None = None
    spring_crease: np.ndarray | None = None
    supports: np.ndarray | None = None
    triangles: np.ndarray | None = None
    tri_thickness: np.ndarray | None = None
    tri_crease: np.ndarray | None = None
    tri_panel: np.ndarray | None = None
    creases: CreaseModel | None = None
    panel_centres: np.ndarray | None = None
    node_vertex: np.ndarray | None = None
    profile: Profile = PAPER

    def __post_init__(self):
        s = object.__setattr__
        nodes = _arr(self.nodes, float, (3,), "nodes")
        if not np.isfinite(nodes).all():
            raise ValueError("nodes contain non-finite coordinates")
        nn = len(nodes)
        bars = _arr(self.bars, np.intp, (2,), "bars")
        nb = len(bars)
        if nb and (bars.min() < 0 or bars.max() >= nn):
            raise ValueError(f"bars reference nodes outside 0..{nn - 1}")
        springs = _arr(self.springs, np.intp, (4,), "springs")
        ns = len(springs)
        if ns and (springs.min() < 0 or springs.max() >= nn):
            raise ValueError(f"springs reference nodes outside 0..{nn - 1}")
        s(self, "nodes", nodes)
        s(self, "bars", bars)
        s(self, "springs", springs)
        for name in ("bar_area", "bar_E"):
            s(self, name, np.broadcast_to(np.asarray(getattr(self, name), float), (nb,)).copy())
        for name in ("spring_k", "spring_rest"):
            s(self, name, np.broadcast_to(np.asarray(getattr(self, name), float), (ns,)).copy())
        if self.bar_length is None:
            L0 = np.linalg.norm(nodes[bars[:, 1]] - nodes[bars[:, 0]], axis=1)
        else:
            L0 = np.broadcast_to(np.asarray(self.bar_length, float), (nb,)).copy()
        if nb and not (L0 > 0).all():
            raise ValueError(f"bar {int(np.argmin(L0))} has zero rest length")
        s(self, "bar_length", L0)
        _set_rows(self, "bar_type", np.int8, 1, nb)
        _set_rows(self, "spring_role", np.int8, 0, ns)
        _set_rows(self, "spring_crease", np.intp, -1, ns)
        sup = np.zeros((nn, 3), bool) if self.supports is None else np.asarray(self.supports, bool)
        if sup.shape != (nn, 3):
            raise ValueError(f"supports must have shape ({nn}, 3), got {sup.shape}")
        s(self, "supports", sup)
        tri = (
            np.zeros((0, 3), np.intp)
            if self.triangles is None
            else _arr(self.triangles, np.intp, (3,), "triangles")
        )
        nt = len(tri)
        s(self, "triangles", tri)
        _set_rows(self, "tri_thickness", float, 0, nt)
        _set_rows(self, "tri_crease", np.intp, -1, nt)
        _set_rows(self, "tri_panel", np.intp, -1, nt)
        if self.creases is not None and not isinstance(self.creases, CreaseModel):
            raise TypeError(f"creases must be a CreaseModel, got {type(self.creases).__name__}")
        if self.panel_centres is not None:
            s(self, "panel_centres", np.asarray(self.panel_centres, np.intp).reshape(-1))
        if self.node_vertex is not None:
            s(self, "node_vertex", _arr(self.node_vertex, np.intp, (), "node_vertex", nn))
        if not isinstance(self.profile, Profile):
            raise TypeError(f"profile must be a Profile, got {type(self.profile).__name__}")

    # ------------------------------------------------------------------ sizes and DOFs
    @property
    def n_nodes(self) -> int:
        return len(self.nodes)

    @property
    def n_dof(self) -> int:
        return 3 * len(self.nodes)

    @cached_property
    def bar_dofs(self) -> np.ndarray:
        """(nb, 6) int: global DOFs of each bar, node a then node b."""
        return (3 * self.bars[:, :, None] + np.arange(3)).reshape(-1, 6)

    @cached_property
    def spring_dofs(self) -> np.ndarray:
        """(ns, 12) int: global DOFs of each spring, nodes i, j, k, l."""
        return (3 * self.springs[:, :, None] + np.arange(3)).reshape(-1, 12)

    @cached_property
    def free_dofs(self) -> np.ndarray:
        """(nf,) int: DOFs that are not supported."""
        return np.flatnonzero(~self.supports.ravel())

    def vertex_nodes(self, vertices, panel: int | None = None) -> np.ndarray:
        """Ids of the nodes standing for the pattern vertices ``vertices`` (every copy of a
        vertex in a compliant model, the vertex itself in a concentrated one), ascending;
        with ``panel``, only the copies in that panel's triangles."""
        v = np.atleast_1d(np.asarray(vertices, np.intp))
        nodes = np.unique(v) if self.node_vertex is None else np.flatnonzero(
            np.isin(self.node_vertex, v)
        )  # fmt: skip
        if panel is None:
            return nodes
        return np.intersect1d(nodes, self.triangles[self.tri_panel == panel])

    # ------------------------------------------------------------------ changed copies
    def with_supports(self, supports) -> Structure:
        """A copy with another (nn, 3) bool support mask (the other arrays are shared, not
        checked again: only the supports change)."""
        sup = np.asarray(supports, bool)
        if sup.shape != (self.n_nodes, 3):
            raise ValueError(f"supports must have shape ({self.n_nodes}, 3), got {sup.shape}")
        new = copy.copy(self)
        object.__setattr__(new, "supports", sup)
        new.__dict__.pop("free_dofs", None)  # the one cached property that depends on them
        return new

    def fixed(self, nodes, dofs: str = "xyz") -> Structure:
        """A copy with the ``dofs`` (any of "x", "y", "z") of ``nodes`` fixed, nothing else.

        ``nodes``: node ids, or a sequence of ``(nodes, dofs)`` pairs when the directions
        differ per node group (``dofs`` is then ignored).
        """
        return self.with_supports(support_mask(self.n_nodes, nodes, dofs))

    def with_rest_angles(self, spring_rest) -> Structure:
        """A copy with other spring rest angles (ns,), rad."""
        return replace(self, spring_rest=np.asarray(spring_rest, float))

    def replace(self, **changes) -> Structure:
        """``dataclasses.replace`` for this structure."""
        return replace(self, **changes)


def trusted_structure(**fields) -> Structure:
    """A :class:`Structure` from arrays already in the form its checks leave them in (every
    field given: nodes float (nn, 3), index arrays intp, ``bar_type`` and ``spring_role``
    int8, per-element values float of full length, ``supports`` bool (nn, 3)), built without
    those checks. For the model builders of :mod:`~holofold.mechanics.hinges`, whose arrays
    are valid by construction (tests/test_hinges.py checks the two constructions agree);
    anything else goes through ``Structure(...)``."""
    st = object.__new__(Structure)
    for name in Structure.__dataclass_fields__:
        object.__setattr__(st, name, fields[name])
    return st


_AXIS = {"x": 0, "y": 1, "z": 2}


def support_mask(n_nodes: int, nodes, dofs: str = "xyz") -> np.ndarray:
    """(n_nodes, 3) bool mask fixing the ``dofs`` of ``nodes`` (see :meth:`Structure.fixed`)."""
    groups = nodes if _is_group_list(nodes) else [(nodes, dofs)]
    sup = np.zeros((n_nodes, 3), bool)
    for ids, d in groups:
        ids = np.atleast_1d(np.asarray(ids, np.intp))
        if ids.size and (ids.min() < 0 or ids.max() >= n_nodes):
            raise ValueError(f"support nodes outside 0..{n_nodes - 1}: {ids.tolist()}")
        bad = set(d) - set(_AXIS)
        if bad or not d:
            raise ValueError(f"dofs = {d!r}; allowed: any of 'x', 'y', 'z'")
        sup[np.ix_(ids, [_AXIS[c] for c in d])] = True
    return sup


def _is_group_list(nodes) -> bool:
    return (
        isinstance(nodes, list | tuple)
        and len(nodes) > 0
        and all(isinstance(g, tuple) and len(g) == 2 and isinstance(g[1], str) for g in nodes)
    )
