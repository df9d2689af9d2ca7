"""The structural model: nodes, bars, rotational springs, triangles, supports (numpy arrays).

A :class:`Structure` is what the element kernels, the assembly and the solvers consume. It is
built from a crease pattern by :mod:`mechanics.hinges` (concentrated hinges or compliant
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
    meta           dict            builder details (node maps, crease tables, profile, ...)

Degrees of freedom are interleaved per node: node ``n`` owns DOFs ``3n, 3n+1, 3n+2`` (x, y, z).
Displacements are ``(nn, 3)`` arrays relative to ``nodes``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from enum import IntEnum
from functools import cached_property
from typing import Any

import numpy as np

__all__ = ["Structure", "SpringRole", "BarType"]


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
    meta: dict[str, Any] = field(default_factory=dict)

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
        s(
            self,
            "bar_type",
            np.full(nb, 1, np.int8)
            if self.bar_type is None
            else _arr(self.bar_type, np.int8, (), "bar_type", nb),
        )
        s(
            self,
            "spring_role",
            np.zeros(ns, np.int8)
            if self.spring_role is None
            else _arr(self.spring_role, np.int8, (), "spring_role", ns),
        )
        s(
            self,
            "spring_crease",
            np.full(ns, -1, np.intp)
            if self.spring_crease is None
            else _arr(self.spring_crease, np.intp, (), "spring_crease", ns),
        )
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
        s(
            self,
            "tri_thickness",
            np.zeros(nt)
            if self.tri_thickness is None
            else _arr(self.tri_thickness, float, (), "tri_thickness", nt),
        )
        s(
            self,
            "tri_crease",
            np.full(nt, -1, np.intp)
            if self.tri_crease is None
            else _arr(self.tri_crease, np.intp, (), "tri_crease", nt),
        )
        s(
            self,
            "tri_panel",
            np.full(nt, -1, np.intp)
            if self.tri_panel is None
            else _arr(self.tri_panel, np.intp, (), "tri_panel", nt),
        )
        s(self, "meta", dict(self.meta))

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

    # ------------------------------------------------------------------ changed copies
    def with_supports(self, supports) -> Structure:
        """A copy with another (nn, 3) bool support mask."""
        return replace(self, supports=np.asarray(supports, bool))

    def with_rest_angles(self, spring_rest) -> Structure:
        """A copy with other spring rest angles (ns,), rad."""
        return replace(self, spring_rest=np.asarray(spring_rest, float))

    def replace(self, **changes) -> Structure:
        """``dataclasses.replace`` for this structure."""
        return replace(self, **changes)
