"""Curved creases as data, and their discretisation into straight pieces.

A :class:`Curve` is one Bezier segment (degree 1-3, control points) or one elliptical arc
(centre, radii, rotation, start angle and sweep), with its assignment and fold angle, in the
reader's units (SVG px, DXF drawing units). :func:`discretise` cuts it into straight pieces by
adaptive recursive subdivision (Origami Simulator's scheme): a parameter interval is halved
while the distance of its curve midpoint from the chord exceeds ``chord`` or the chord is longer
than ``length``.

Defaults (:data:`CHORD_DEFAULT`, :data:`LENGTH_DEFAULT`) are relative to the drawing's larger
side ``size``: chord deviation 1e-3 x size and piece length 0.05 x size (a circle of radius
0.4 x size is cut into ~64 pieces, each deviating 0.1 % of the size from the arc).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from holofold.geometry.errors import ParameterError

__all__ = ["Curve", "discretise", "curve_from_svg_segment", "CHORD_DEFAULT", "LENGTH_DEFAULT"]

#: default chord deviation, relative to the drawing's larger side
CHORD_DEFAULT = 1e-3
#: default largest piece length, relative to the drawing's larger side
LENGTH_DEFAULT = 0.05
#: the deepest subdivision (2^20 pieces per curve at most)
_MAX_DEPTH = 20


@dataclass(frozen=True)
class Curve:
    """One curved crease or line.

    ``kind``: ``"bezier"`` (``points``: (degree + 1, 2) control points) or ``"arc"``
    (``centre`` (2,), ``radii`` (rx, ry), ``rotation`` rad, ``start`` rad, ``sweep`` rad,
    positive counter-clockwise in the curve's own frame); ``assignment``: FOLD code;
    ``fold_angle``: degrees (valley > 0).
    """

    kind: str
    assignment: str
    fold_angle: float = 0.0
    points: tuple = ()
    centre: tuple = (0.0, 0.0)
    radii: tuple = (0.0, 0.0)
    rotation: float = 0.0
    start: float = 0.0
    sweep: float = 0.0

    def point(self, t) -> np.ndarray:
        """Points at parameters ``t`` in [0, 1], (len(t), 2)."""
        t = np.atleast_1d(np.asarray(t, float))
        if self.kind == "bezier":
            P = np.asarray(self.points, float)
            n = len(P) - 1
            from math import comb

            B = np.stack([comb(n, k) * t**k * (1 - t) ** (n - k) for k in range(n + 1)], axis=1)
            return B @ P
        if self.kind == "arc":
            a = self.start + self.sweep * t
            rx, ry = self.radii
            c, s = np.cos(self.rotation), np.sin(self.rotation)
            x, y = rx * np.cos(a), ry * np.sin(a)
            return np.stack([self.centre[0] + c * x - s * y, self.centre[1] + s * x + c * y], 1)
        raise ParameterError(f"curve kind {self.kind!r}; allowed: bezier, arc")


def discretise(curve: Curve, *, chord: float, length: float = np.inf) -> np.ndarray:
    """The curve cut into straight pieces, (n + 1, 2) points from t = 0 to t = 1.

    Every piece's curve midpoint lies within ``chord`` of the piece and every piece is at most
    ``length`` long (both in the curve's units, > 0); found by halving parameter intervals.
    """
    if not chord > 0 or not length > 0:
        raise ParameterError(f"curve chord = {chord}, length = {length}; both must be > 0")
    ts = [0.0]

    def split(t0, t1, p0, p1, depth):
        tm = 0.5 * (t0 + t1)
        pm = curve.point(tm)[0]
        d = p1 - p0
        L = float(np.hypot(*d))
        if L > 0:
            dev = abs(d[0] * (pm - p0)[1] - d[1] * (pm - p0)[0]) / L
        else:
            dev = float(np.hypot(*(pm - p0)))
        # a quarter-step probe guards against an S-curve whose midpoint sits on the chord
        if depth < 2 or ((dev > chord or L > length) and depth < _MAX_DEPTH):
            split(t0, tm, p0, pm, depth + 1)
            split(tm, t1, pm, p1, depth + 1)
        else:
            ts.append(t1)

    P = curve.point([0.0, 1.0])
    split(0.0, 1.0, P[0], P[1], 0)
    return curve.point(np.array(ts))


def curve_from_svg_segment(seg, assignment: str, fold_angle: float) -> Curve | None:
    """A :class:`Curve` of an svgelements segment (CubicBezier, QuadraticBezier, Arc), in
    SVG px with y down as the segment is; None for anything else."""
    import svgelements as se

    def xy(p):
        return (float(p.x), float(p.y))

    if isinstance(seg, se.CubicBezier):
        pts = (xy(seg.start), xy(seg.control1), xy(seg.control2), xy(seg.end))
        return Curve("bezier", assignment, fold_angle, points=pts)
    if isinstance(seg, se.QuadraticBezier):
        pts = (xy(seg.start), xy(seg.control), xy(seg.end))
        return Curve("bezier", assignment, fold_angle, points=pts)
    if isinstance(seg, se.Arc):
        return Curve(
            "arc", assignment, fold_angle, centre=xy(seg.center), radii=(float(seg.rx),
            float(seg.ry)), rotation=float(seg.get_rotation()), start=float(seg.get_start_t()),
            sweep=float(seg.sweep),
        )  # fmt: skip
    return None
