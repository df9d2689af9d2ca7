"""The line-drawing pipeline every crease-pattern reader shares.

A line reader (SVG, DXF, ORIPA ``.opx`` and ``.cp``) returns one :class:`LineDrawing` (the
drawn lines in drawing units, their assignments and fold angles, metres per drawing unit, the
notes of what the reader assumed); :func:`pattern_from_drawing` turns it into a
:class:`~holofold.geometry.pattern.CreasePattern` in metres through the planar
arrangement (:func:`~holofold.geometry.arrangement.arrange_lines`), cuts separated
(:func:`~holofold.geometry.cuts.separate_cuts`) and faces split where the model needs it
(:func:`~holofold.geometry.facets.split_faces`); every repair is one :class:`PatternWarning`
line. The readers (:mod:`~holofold.geometry.readers`, the registry by suffix) build on it."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, replace

import numpy as np

from holofold.geometry.arrangement import arrange_lines, default_tolerance
from holofold.geometry.curved import curve_edges
from holofold.geometry.cuts import separate_cuts
from holofold.geometry.errors import FormatError, ParameterError
from holofold.geometry.facets import SPLIT_MODES, split_faces
from holofold.geometry.pattern import MAX_PANELS, CreasePattern
from holofold.geometry.ruling_mesh import curve_edge_mask, curve_points_on, steiner_points

__all__ = [
    "PatternWarning",
    "LineDrawing",
    "MAX_DRAWN_METRES",
    "check_unit",
    "finish_pattern",
    "pattern_from_drawing",
    "pattern_from_lines",
]


class PatternWarning(UserWarning):
    """A crease-pattern file read with a repair or an assumption (named in the message)."""


def _check_split(split: str) -> str:
    if split not in SPLIT_MODES:
        raise ParameterError(f"split = {split!r}; allowed: {', '.join(SPLIT_MODES)}")
    return split


def _outline_cuts_as_border(faces, edges, assignment) -> np.ndarray:
    """The assignments with every cut (C) on the outline (an edge of one face) a border (B):
    a cutter file draws the outline as a cut, which is what a border is."""
    asg = np.asarray(assignment).copy()
    E = np.sort(np.asarray(edges, int).reshape(-1, 2), axis=1)
    if not len(E) or not (asg == "C").any():
        return asg
    sides = np.sort(
        np.array([(f[k], f[(k + 1) % len(f)]) for f in faces for k in range(len(f))], int), axis=1
    )
    pairs, count = np.unique(sides, axis=0, return_counts=True)
    key = {tuple(p): c for p, c in zip(pairs.tolist(), count.tolist(), strict=True)}
    one = np.array([key.get(tuple(e), 0) == 1 for e in E.tolist()])
    asg[(asg == "C") & one] = "B"
    return asg


def finish_pattern(
    xy, faces, edges, assignment, fold_angle, *, name: str, notes=(), split: str = "as-needed",
    meta: dict | None = None, coords3=None, curve_points=None, curve_tol: float = 0.0,
) -> CreasePattern:  # fmt: skip
    """A :class:`CreasePattern` from a flat layout (metres) and its faces: cuts separated,
    faces split as the model needs (``split``), each repair warned about in one line.
    ``curve_points`` (k, 2) m: points along the drawing's curves, at most ``curve_tol`` / 2
    apart; the edges within ``curve_tol`` of them are curve pieces (``split="rulings"``)."""
    split = _check_split(split)
    notes = list(notes)
    xy = np.asarray(xy, float)
    assignment = _outline_cuts_as_border(faces, edges, assignment)
    xy, faces, edges, asg, ang, origin, more = separate_cuts(
        xy, faces, edges, assignment, fold_angle
    )
    notes += more
    n_cut = len(origin) - len(np.unique(origin))
    if n_cut:
        notes.append(f"cuts separated: {n_cut} vertex copies made along them")
    on_curve = None
    if split == "rulings" and curve_points is not None and len(curve_points):
        on_curve = curve_edge_mask(xy, edges, curve_points, curve_tol)
        if coords3 is None:  # rulings from a curve to a border end on points of their own
            xy, faces, edges, asg, ang, on_curve = steiner_points(
                xy, faces, edges, asg, ang, on_curve
            )
    faces, edges, asg, ang, n_split = split_faces(xy, faces, edges, asg, ang, split, on_curve)
    if n_split:
        why = "non-convex" if split == "as-needed" else "with more than 3 vertices"
        why = "non-convex (not fanned whole from their centre)" if split == "as-needed" else why
        why = "with curve pieces (along their rulings) or non-convex" if split == "rulings" else why
        notes.append(f"{n_split} {why} face(s) split into triangles (added edges J)")
    if len(faces) > MAX_PANELS:
        raise FormatError(f"{name}: {len(faces)} panels; at most {MAX_PANELS} are read")
    c3 = np.column_stack([xy, np.zeros(len(xy))]) if coords3 is None else coords3[origin]
    try:
        pattern = CreasePattern(c3, faces, edges, asg, ang, flat=xy, meta=meta or {})
    except ValueError as exc:
        raise FormatError(f"{name}: {exc}") from None
    inside = int((pattern.interior & np.isin(pattern.assignment, ("B", "C"))).sum())
    if inside:
        notes.append(
            f"{inside} border or cut line(s) run inside the sheet (two panels each): folded as "
            "passive creases; are they the outline?"
        )
    for n in notes:
        warnings.warn(f"{name}: {n}", PatternWarning, stacklevel=3)
    return pattern


#: the farthest a drawn crease may lie from the origin, m (a 1 km sheet; 1e300 overflowed scipy)
MAX_DRAWN_METRES = 1e4


def pattern_from_lines(
    segments, assignment, fold_angle, *, name: str, unit: float, tol: float | None = None,
    split: str = "as-needed", meta: dict | None = None, notes=(), curves=(),
) -> CreasePattern:  # fmt: skip
    """The crease pattern of drawn lines (drawing units; ``unit`` metres per drawing unit;
    ``tol`` the merge distance in drawing units, default 2e-3 of the drawing's larger side),
    placed with the lower-left corner of its extent at the origin; ``curves`` (drawing units,
    y up) are kept as the pattern's ``curves`` with the edges that are their pieces, and their
    pieces are meshed along their rulings with ``split="rulings"``."""
    if not (np.isfinite(unit) and unit > 0):
        raise ParameterError(f"unit = {unit!r} must be a length in metres > 0")
    if tol is not None and not (np.isfinite(tol) and tol > 0):
        raise ParameterError(f"tol = {tol!r} must be a distance > 0 in drawing units")
    S = np.asarray(segments, float)
    if S.size and not np.isfinite(S).all():
        raise FormatError(f"{name}: a line has a coordinate that is not a finite number")
    if S.size and np.abs(S).max() * unit > MAX_DRAWN_METRES:
        raise FormatError(
            f"{name}: a line reaches {np.abs(S).max() * unit:.3g} m from the origin, beyond "
            f"{MAX_DRAWN_METRES:g} m; check the drawing's numbers and unit"
        )
    pieces = _curve_pieces(S, assignment, curves, tol) if curves else None
    try:
        arr = arrange_lines(segments, assignment, fold_angle, tol=tol, contract=pieces)
    except FormatError as exc:
        raise FormatError(f"{name}: {exc}") from None
    xy = (arr.vertices - arr.vertices.min(axis=0)) * unit  # lower-left corner at the origin
    if not curves:
        notes = [*notes, *_near_merge(arr, default_tolerance(S) if tol is None else tol)]
    pts, ctol = None, 0.0
    if curves and split == "rulings":
        pts, ctol = curve_points_on(arr.vertices, curves, tol)
        pts, ctol = (pts - arr.vertices.min(axis=0)) * unit, ctol * unit
    pattern = finish_pattern(
        xy, arr.faces, arr.edges, arr.assignment, arr.fold_angle,
        name=name, notes=[*notes, *arr.notes], split=split, meta=meta, curve_points=pts,
        curve_tol=ctol,
    )  # fmt: skip
    if curves:  # curved creases kept for output (metres, the pattern's frame)
        curves = tuple(c.mapped(unit, -arr.vertices.min(axis=0) * unit) for c in curves)
        reach = 2.0 * unit * (default_tolerance(S) if tol is None else tol)
        ec = curve_edges(pattern.flat, pattern.edges, pattern.assignment, curves, tol=reach)
        pattern = replace(pattern, curves=curves, edge_curve=ec)
    return pattern


#: an edge at most this many merge distances long is reported: its ends were likely meant as
#: one point (Origami Simulator merges within 3 drawing units, holofold within ``tol``)
NEAR_MERGE = 2.0


def _near_merge(arr, tol: float) -> list[str]:
    """A note on the edges of an arrangement (drawing units) longer than the merge distance
    ``tol`` but at most :data:`NEAR_MERGE` x it: two ends drawn just apart make a sliver
    panel triangle, which the fold crushes (Origami Simulator's hypar.svg: one corner drawn
    2.95 units off at a merge distance of 1.73, a 0.4 mm high triangle on a 200 mm sheet)."""
    if not len(arr.edges) or not tol > 0:
        return []
    V, E = arr.vertices, arr.edges
    length = np.linalg.norm(V[E[:, 1]] - V[E[:, 0]], axis=1)
    near = np.flatnonzero(length <= NEAR_MERGE * tol)
    if not near.size:
        return []
    k = near[np.argmax(length[near])]
    mid = 0.5 * (V[E[k, 0]] + V[E[k, 1]]) - V.min(axis=0)
    return [
        f"{near.size} edge(s) barely longer than the merge distance {tol:.3g} (at most "
        f"{length[k]:.3g} drawing units, at ({mid[0]:.4g}, {mid[1]:.4g}) from the lower left "
        f"corner): if their ends are meant as one point, read with tol={1.01 * length[k]:.3g} "
        f"(--tol {1.01 * length[k]:.3g}) to merge them; kept, they make thin panel triangles "
        "that a fold may crush"
    ]


def _curve_pieces(S, assignment, curves, tol) -> np.ndarray:
    """(n,) bool: the lines shorter than the merge tolerance that are pieces of a curve."""
    tol = default_tolerance(S) if tol is None else tol
    short = np.flatnonzero(np.linalg.norm(S[:, 1] - S[:, 0], axis=1) <= tol)
    out = np.zeros(len(S), bool)
    if short.size:
        xy = S[short].reshape(-1, 2)
        e = np.arange(2 * short.size).reshape(-1, 2)
        size = float(np.ptp(S.reshape(-1, 2), axis=0).max())
        asg = np.asarray(assignment)[short]
        out[short] = curve_edges(xy, e, asg, curves, tol=1e-9 * size) >= 0
    return out


def check_unit(unit) -> float:
    """``unit`` (metres per drawing unit) as a float, refused unless a finite number > 0."""
    if not (isinstance(unit, int | float) and math.isfinite(unit) and unit > 0):
        raise ParameterError(f"unit = {unit!r} must be a length in metres > 0")
    return float(unit)


def _frozen(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


@dataclass(frozen=True)
class LineDrawing:
    """The lines of a crease-pattern drawing, as a line reader found them.

    Attributes
    ----------
    segments : (n, 2, 2) float
        Drawn lines, drawing units (y up).
    assignment : (n,) str
        FOLD codes (``M``, ``V``, ``F``, ``B``, ``C``, ``J``, ``U``).
    fold_angle : (n,) float
        Target fold angles, degrees (valley > 0).
    unit : float
        Metres per drawing unit (as the file states it, or the reader's assumption).
    name : str
        The source in messages: a file name, ``"<bytes>"`` or a file object's name.
    kind : str
        The format family, kept in the pattern's ``meta["kind"]`` (``"svg"``, ``"dxf"``,
        ``"oripa"``, ``"fold"``).
    notes : tuple of str
        What the reader assumed or left out, each a :class:`PatternWarning` line once the
        pattern is made.
    curves : tuple of :class:`~holofold.geometry.curved.Curve`
        The curves kept, already cut into straight pieces among ``segments`` (drawing units,
        y up as the segments); :func:`pattern_from_drawing` keeps them on the pattern.
    unit_note : str
        The note (one of ``notes``) saying the unit was assumed; :meth:`with_unit` drops it.
    """

    segments: np.ndarray
    assignment: np.ndarray
    fold_angle: np.ndarray
    unit: float
    name: str = "<lines>"
    kind: str = "lines"
    notes: tuple[str, ...] = ()
    curves: tuple = ()
    unit_note: str = ""

    def __post_init__(self):
        S = np.array(self.segments, float)  # copies: the caller's arrays stay writeable
        if S.size == 0:
            S = S.reshape(0, 2, 2)
        if S.ndim != 3 or S.shape[1:] != (2, 2):
            raise ParameterError(f"segments: expected an (n, 2, 2) array, got shape {S.shape}")
        n = len(S)
        asg = np.array(self.assignment, dtype="<U1")
        ang = np.array(self.fold_angle, float)
        if asg.shape != (n,) or ang.shape != (n,):
            raise ParameterError(
                f"assignment {asg.shape} and fold_angle {ang.shape}: one entry per segment ({n})"
            )
        object.__setattr__(self, "segments", _frozen(S))
        object.__setattr__(self, "assignment", _frozen(asg))
        object.__setattr__(self, "fold_angle", _frozen(ang))
        object.__setattr__(self, "unit", check_unit(self.unit))
        object.__setattr__(self, "notes", tuple(str(n) for n in self.notes))
        object.__setattr__(self, "curves", tuple(self.curves))

    def __len__(self) -> int:
        return len(self.segments)

    def with_unit(self, unit: float | None) -> LineDrawing:
        """The same drawing at ``unit`` metres per drawing unit (None: as it is), without the
        note that the unit was assumed."""
        if unit is None:
            return self
        notes = tuple(n for n in self.notes if not self.unit_note or n != self.unit_note)
        return replace(self, unit=check_unit(unit), notes=notes, unit_note="")


def pattern_from_drawing(
    drawing: LineDrawing, *, tol: float | None = None, unit: float | None = None,
    split: str = "as-needed",
) -> CreasePattern:  # fmt: skip
    """The crease pattern of a :class:`LineDrawing` (metres): end points merged within ``tol``
    (drawing units; default 2e-3 of the drawing's larger side), crossings split, faces found,
    cuts separated, faces split as ``split`` asks (:data:`~holofold.geometry.facets.SPLIT_MODES`);
    ``unit`` (metres per drawing unit) overrides the drawing's. Each note and repair is one
    :class:`PatternWarning` line naming ``drawing.name``; ``meta`` holds its kind and name.
    A drawing with curves is split ``"rulings"`` where ``split`` is ``"as-needed"``."""
    d = drawing.with_unit(unit)
    split = "rulings" if d.curves and split == "as-needed" else split
    return pattern_from_lines(
        d.segments, d.assignment, d.fold_angle, name=d.name, unit=d.unit, tol=tol, split=split,
        meta={"kind": d.kind, "source": d.name}, notes=d.notes, curves=d.curves,
    )  # fmt: skip
