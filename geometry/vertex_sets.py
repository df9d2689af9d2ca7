"""Named sets of a pattern's vertices, for supports and loads: a side, a point, a box, ids.

A set is written as text (the command line and scenario files share it) and selected on the
flat layout (the pattern as drawn; its 3-D coordinates when it has none)::

    side:-x            the border vertices at the smallest x (also +x, -y, +y, left, right,
                       bottom, top), within 1e-3 of the pattern's size
    near:X,Y           the vertex nearest the point (X, Y); near:X,Y,K the K nearest
    box:X0,Y0,X1,Y1    the vertices inside the box (edges included)
    ids:3,8,12         these vertex ids
    boundary           every border vertex
    all                every vertex

Coordinates are metres, or percentages of the layout's bounding box from its lower-left
corner (``near:50%,50%`` the vertex nearest the centre of the box). :func:`parse_vertex_set`
checks the text (one :class:`ParameterError` line naming what is allowed);
:meth:`VertexSet.select` gives the ids, refusing a set that selects nothing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from holofold.geometry.errors import ParameterError
from holofold.geometry.pattern import CreasePattern

__all__ = ["VertexSet", "parse_vertex_set", "VERTEX_SET_KINDS"]

VERTEX_SET_KINDS = ("side", "near", "box", "ids", "boundary", "all")
_SIDES = {"-x": (0, -1), "+x": (0, 1), "-y": (1, -1), "+y": (1, 1), "left": (0, -1),
          "right": (0, 1), "bottom": (1, -1), "top": (1, 1), "x": (0, 1), "y": (1, 1)}  # fmt: skip
_SIDE_TOL = 1e-3
_SYNTAX = "side:-x|+x|-y|+y, near:X,Y[,K], box:X0,Y0,X1,Y1, ids:I,J,..., boundary or all"


@dataclass(frozen=True)
class VertexSet:
    """A named set of vertices (see the module docstring).

    Attributes
    ----------
    kind : str
        One of :data:`VERTEX_SET_KINDS`.
    values : tuple
        The side ``(axis, sign)``, the point and count, the box, or the ids; coordinates as
        ``(value, is_percent)`` pairs.
    text : str
        The text it was read from.
    """

    kind: str
    values: tuple = ()
    text: str = ""

    def __str__(self) -> str:
        return self.text or self.kind

    def select(self, pattern: CreasePattern) -> np.ndarray:
        """The ids of the selected vertices of ``pattern``, ascending (never empty)."""
        xy = pattern.flat if pattern.flat is not None else pattern.coords[:, :2]
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        size = float((hi - lo).max()) or 1.0

        def coord(v, axis):
            value, pct = v
            return lo[axis] + value / 100.0 * (hi[axis] - lo[axis]) if pct else value

        if self.kind == "all":
            ids = np.arange(pattern.n_vertices)
        elif self.kind == "boundary":
            ids = np.unique(pattern.edges[~pattern.interior])
        elif self.kind == "side":
            axis, sign = self.values
            border = np.unique(pattern.edges[~pattern.interior])
            x = xy[border, axis]
            edge = x.max() if sign > 0 else x.min()
            ids = border[np.abs(x - edge) <= _SIDE_TOL * size]
        elif self.kind == "near":
            (px, py), k = self.values[:2], self.values[2]
            p = np.array([coord(px, 0), coord(py, 1)])
            d = np.linalg.norm(xy - p, axis=1)
            ids = np.argsort(d, kind="stable")[: min(k, len(d))]
        elif self.kind == "box":
            x0, y0, x1, y1 = (coord(v, a) for v, a in zip(self.values, (0, 1, 0, 1), strict=True))
            x0, x1 = min(x0, x1), max(x0, x1)
            y0, y1 = min(y0, y1), max(y0, y1)
            eps = 1e-9 * size
            inside = (xy[:, 0] >= x0 - eps) & (xy[:, 0] <= x1 + eps)
            inside &= (xy[:, 1] >= y0 - eps) & (xy[:, 1] <= y1 + eps)
            ids = np.flatnonzero(inside)
        else:  # ids
            ids = np.asarray(self.values, np.intp)
            bad = ids[(ids < 0) | (ids >= pattern.n_vertices)]
            if bad.size:
                top = pattern.n_vertices - 1
                raise ParameterError(f"vertex set {self}: vertex {int(bad[0])} is outside 0..{top}")
        ids = np.unique(np.asarray(ids, np.intp))
        if not ids.size:
            raise ParameterError(
                f"vertex set {self} selects no vertex (the layout spans x {lo[0]:.4g}..{hi[0]:.4g},"
                f" y {lo[1]:.4g}..{hi[1]:.4g} m)"
            )
        return ids


def _number(text: str, what: str, spec: str) -> tuple[float, bool]:
    t = text.strip()
    pct = t.endswith("%")
    try:
        v = float(t[:-1] if pct else t)
    except ValueError:
        raise ParameterError(f"vertex set {spec!r}: {what} {text!r} is not a number") from None
    if not np.isfinite(v):
        raise ParameterError(f"vertex set {spec!r}: {what} must be finite")
    return v, pct


def parse_vertex_set(spec) -> VertexSet:
    """A :class:`VertexSet` from its text (a :class:`VertexSet` is returned as is)."""
    if isinstance(spec, VertexSet):
        return spec
    if not isinstance(spec, str) or not spec.strip():
        raise ParameterError(f"vertex set {spec!r}: expected text such as {_SYNTAX}")
    text = spec.strip()
    kind, _, rest = text.partition(":")
    kind = kind.strip().lower()
    parts = [p for p in rest.split(",")] if rest.strip() else []
    if kind in ("all", "boundary"):
        if parts:
            raise ParameterError(f"vertex set {text!r}: {kind} takes no values")
        return VertexSet(kind, (), text)
    if kind == "side":
        key = rest.strip().lower()
        if key not in _SIDES:
            raise ParameterError(
                f"vertex set {text!r}: side {key!r}; allowed: -x, +x, -y, +y, left, right, "
                "bottom, top"
            )
        return VertexSet("side", _SIDES[key], text)
    if kind == "near":
        if len(parts) not in (2, 3):
            raise ParameterError(f"vertex set {text!r}: expected near:X,Y or near:X,Y,K")
        pt = tuple(_number(p, "coordinate", text) for p in parts[:2])
        k = 1
        if len(parts) == 3:
            kv, pct = _number(parts[2], "count", text)
            if pct or kv != int(kv) or kv < 1:
                raise ParameterError(f"vertex set {text!r}: the count K must be an integer >= 1")
            k = int(kv)
        return VertexSet("near", (*pt, k), text)
    if kind == "box":
        if len(parts) != 4:
            raise ParameterError(f"vertex set {text!r}: expected box:X0,Y0,X1,Y1")
        return VertexSet("box", tuple(_number(p, "coordinate", text) for p in parts), text)
    if kind == "ids":
        try:
            ids = tuple(int(p) for p in parts)
        except ValueError:
            raise ParameterError(f"vertex set {text!r}: ids must be integers") from None
        if not ids:
            raise ParameterError(f"vertex set {text!r}: give at least one id")
        return VertexSet("ids", ids, text)
    raise ParameterError(f"vertex set {text!r}: unknown kind {kind!r}; allowed: {_SYNTAX}")
