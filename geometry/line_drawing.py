"""The line-drawing pipeline every crease-pattern reader shares: drawn lines (drawing units)
to a :class:`~holofold.geometry.pattern.CreasePattern` in metres through the planar
arrangement (:func:`~holofold.geometry.arrangement.arrange_lines`), cuts separated
(:func:`~holofold.geometry.cuts.separate_cuts`) and faces split where the model needs it
(:func:`~holofold.geometry.facets.split_faces`); every repair is one :class:`PatternWarning`
line. The readers (:mod:`~holofold.geometry.readers`, the registry by suffix) build on it."""

from __future__ import annotations

import warnings

import numpy as np

from holofold.geometry.errors import FormatError, ParameterError
from holofold.geometry.pattern import MAX_PANELS, CreasePattern

__all__ = ["PatternWarning", "MAX_DRAWN_METRES", "finish_pattern", "pattern_from_lines"]


class PatternWarning(UserWarning):
    """A crease-pattern file read with a repair or an assumption (named in the message)."""


def _check_split(split: str) -> str:
    from holofold.geometry.facets import SPLIT_MODES

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
    meta: dict | None = None, coords3=None,
) -> CreasePattern:  # fmt: skip
    """A :class:`CreasePattern` from a flat layout (metres) and its faces: cuts separated,
    faces split as the model needs (``split``), each repair warned about in one line."""
    from holofold.geometry.cuts import separate_cuts
    from holofold.geometry.facets import split_faces

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
    faces, edges, asg, ang, n_split = split_faces(xy, faces, edges, asg, ang, split)
    if n_split:
        why = "non-convex" if split == "as-needed" else "with more than 3 vertices"
        why = "non-convex (not fanned whole from their centre)" if split == "as-needed" else why
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
    split: str = "as-needed", meta: dict | None = None, notes=(),
) -> CreasePattern:  # fmt: skip
    """The crease pattern of drawn lines (drawing units; ``unit`` metres per drawing unit;
    ``tol`` the merge distance in drawing units, default 2e-3 of the drawing's larger side),
    placed with the lower-left corner of its extent at the origin."""
    from holofold.geometry.arrangement import arrange_lines

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
    try:
        arr = arrange_lines(segments, assignment, fold_angle, tol=tol)
    except FormatError as exc:
        raise FormatError(f"{name}: {exc}") from None
    xy = (arr.vertices - arr.vertices.min(axis=0)) * unit  # lower-left corner at the origin
    return finish_pattern(
        xy, arr.faces, arr.edges, arr.assignment, arr.fold_angle,
        name=name, notes=[*notes, *arr.notes], split=split, meta=meta,
    )  # fmt: skip
