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

from dataclasses import dataclass, replace

import numpy as np

from holofold.geometry.arrangement import REL_TOL
from holofold.geometry.errors import ParameterError

__all__ = [
    "Curve",
    "discretise",
    "cut_curves",
    "curve_edges",
    "curve_from_svg_segment",
    "CHORD_DEFAULT",
    "LENGTH_DEFAULT",
]

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

    def mapped(
        self, scale: float = 1.0, shift=(0.0, 0.0), *, flip_y: bool = False, flip_x: bool = False
    ) -> Curve:
        """The curve under p -> scale * (+-x, +-y) + shift (``scale`` > 0; ``flip_y`` mirrors y,
        SVG's y down to y up; ``flip_x`` mirrors x), of the same kind and direction."""
        sx = -1.0 if flip_x else 1.0
        sy = -1.0 if flip_y else 1.0
        sh = np.asarray(shift, float)

        def m(p):
            return (float(scale * sx * p[0] + sh[0]), float(scale * sy * p[1] + sh[1]))

        if self.kind == "bezier":
            return replace(self, points=tuple(m(p) for p in self.points))
        rx, ry = self.radii
        rot, start, sweep = self.rotation, self.start, self.sweep
        if sx * sy < 0:  # one mirror: the frame's handedness flips
            rot, sweep = -rot, -sweep
            start = np.pi - start if flip_x else -start
        elif flip_x:  # both mirrors: a half turn
            rot = rot + np.pi
        return replace(
            self, centre=m(self.centre), radii=(float(scale * rx), float(scale * ry)),
            rotation=float(rot), start=float(start), sweep=float(sweep),
        )  # fmt: skip

    def sub(self, t0: float, t1: float) -> Curve:
        """The part of the curve between parameters ``t0`` < ``t1`` in [0, 1], same kind."""
        if self.kind == "arc":
            return replace(self, start=self.start + t0 * self.sweep, sweep=(t1 - t0) * self.sweep)
        P = np.asarray(self.points, float)

        def split(P, t):  # de Casteljau: the control points of [0, t] and [t, 1]
            left, right, cur = [P[0]], [P[-1]], P
            while len(cur) > 1:
                cur = (1 - t) * cur[:-1] + t * cur[1:]
                left.append(cur[0])
                right.append(cur[-1])
            return np.array(left), np.array(right[::-1])

        _, P = split(P, t0)
        if t1 < 1.0:
            P, _ = split(P, (t1 - t0) / (1.0 - t0))
        return replace(self, points=tuple(map(tuple, P.tolist())))

    def lengths(self, samples: int = 513) -> tuple[np.ndarray, np.ndarray]:
        """(t, s): parameters and the arc length from t = 0 (a polyline of ``samples``
        points), for parameters at given lengths by interpolation."""
        t = np.linspace(0.0, 1.0, samples)
        p = self.point(t)
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
        return t, s


def discretise(
    curve: Curve, *, chord: float, length: float = np.inf, shortest: float = 0.0
) -> np.ndarray:
    """The curve cut into straight pieces, (n + 1, 2) points from t = 0 to t = 1.

    Every piece's curve midpoint lies within ``chord`` of the piece and every piece is at most
    ``length`` long (both in the curve's units, > 0); found by halving parameter intervals. An
    interval whose two halves would be shorter than ``shortest`` (>= 0; the merge tolerance
    of the arrangement, so no piece is cut finer than it can keep) is not halved; this bound
    wins over ``chord`` and ``length``.
    """
    if not chord > 0 or not length > 0 or not shortest >= 0:
        raise ParameterError(
            f"curve chord = {chord}, length = {length}, shortest = {shortest}; chord and "
            "length must be > 0, shortest >= 0"
        )
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
        # halves shorter than ``shortest``: not cut (through the midpoint: a closed loop too)
        fine = min(np.hypot(*(pm - p0)), np.hypot(*(p1 - pm))) < shortest
        # a quarter-step probe guards against an S-curve whose midpoint sits on the chord
        if not fine and (depth < 2 or ((dev > chord or L > length) and depth < _MAX_DEPTH)):
            split(t0, tm, p0, pm, depth + 1)
            split(tm, t1, pm, p1, depth + 1)
        else:
            ts.append(t1)

    P = curve.point([0.0, 1.0])
    split(0.0, 1.0, P[0], P[1], 0)
    return curve.point(np.array(ts))


def cut_curves(kept, segs, codes, angles, *, chord=None, length=None) -> tuple[int, float, float]:
    """Cut the ``kept`` curves into straight pieces appended to ``segs`` (with their
    assignment to ``codes`` and fold angle to ``angles``): chord deviation ``chord`` and piece
    length ``length`` (default :data:`CHORD_DEFAULT` and :data:`LENGTH_DEFAULT` x the larger
    side of the drawing: the curves and the segments already there), no piece finer than the
    merge tolerance; (pieces, chord, length)."""
    pts = [np.asarray(c.point(np.linspace(0, 1, 9))) for c in kept]
    pts += [np.asarray(segs, float).reshape(-1, 2)] if segs else []
    size = float(np.ptp(np.concatenate(pts), axis=0).max()) or 1.0
    chord = CHORD_DEFAULT * size if chord is None else chord
    length = LENGTH_DEFAULT * size if length is None else length
    n = 0
    for c in kept:
        cp = discretise(c, chord=chord, length=length, shortest=REL_TOL * size)
        n += len(cp) - 1
        for a, b in zip(cp[:-1], cp[1:], strict=True):
            segs.append([a, b])
            codes.append(c.assignment)
            angles.append(c.fold_angle)
    return n, chord, length


def curve_edges(xy, edges, assignment, curves, *, tol: float, samples: int = 65) -> np.ndarray:
    """The curve each edge is a straight piece of, (ne,) int, -1 for none.

    An edge is a piece of a curve when both its ends (``xy`` (nv, 2), the curves' units) lie
    within ``tol`` of the curve (a polyline of ``samples`` points), its midpoint within ``tol``
    + 0.15 x its length (a chord's sagitta: a piece spanning up to a radian of arc), and its
    assignment is the curve's (or ``B`` for a cut curve on the outline); the nearest such curve
    wins."""
    xy = np.asarray(xy, float)
    E = np.asarray(edges, int).reshape(-1, 2)
    asg = np.asarray(assignment).reshape(-1)
    out = np.full(len(E), -1, np.int64)
    best = np.full(len(E), np.inf)
    if not len(E) or not curves:
        return out
    from scipy.spatial import cKDTree

    codes = {c.assignment for c in curves} | (
        {"B"} if any(c.assignment == "C" for c in curves) else set()
    )
    pick = np.flatnonzero(np.isin(asg, sorted(codes)))  # only edges of a curve's assignment
    if not pick.size:
        return out
    A, B = xy[E[:, 0]], xy[E[:, 1]]
    probes = np.stack([A, 0.5 * (A + B), B], axis=1)  # (ne, 3, 2)
    t = np.linspace(0.0, 1.0, samples)
    polys = [curve.point(t) for curve in curves]
    step = max(float(np.linalg.norm(np.diff(p, axis=0), axis=1).max()) for p in polys)
    step += 0.3 * float(np.linalg.norm(B[pick] - A[pick], axis=1).max())  # midpoint off it
    # candidates: edges whose midpoint is near a sample of the curve
    tree = cKDTree(probes[pick, 1])
    cand: dict[int, np.ndarray] = {}
    for c, poly in enumerate(polys):
        hits = tree.query_ball_point(poly, tol + 0.5 * step, return_sorted=False)
        ks = np.unique(np.concatenate([np.asarray(h, np.intp) for h in hits]))
        if ks.size:
            cand[c] = pick[ks]
    for c, k in cand.items():
        curve, poly = curves[c], polys[c]
        ok = asg[k] == curve.assignment
        if curve.assignment == "C":
            ok |= asg[k] == "B"
        k = k[ok]
        if not k.size:
            continue
        a, d = poly[:-1], np.diff(poly, axis=0)
        dd = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
        w = probes[k][:, :, None, :] - a[None, None]  # (m, 3, s - 1, 2)
        u = np.clip(np.einsum("mpsj,sj->mps", w, d) / dd, 0.0, 1.0)
        gaps = np.linalg.norm(w - u[..., None] * d, axis=3).min(axis=2)  # (m, 3)
        L = np.linalg.norm(B[k] - A[k], axis=1)
        fits = (gaps[:, [0, 2]].max(axis=1) <= tol) & (gaps[:, 1] <= tol + 0.15 * L)
        gap = gaps.max(axis=1)
        win = fits & (gap < best[k])
        out[k[win]] = c
        best[k[win]] = gap[win]
    return out


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
